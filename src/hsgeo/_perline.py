"""A trajectory whose poses at a line block's pixel times are computed once per line.

:func:`hsgeo.ortho.geolocate_lines` hands the sensor's ``rays`` the time of every pixel (each
line's time repeated for its pixels); the sensor asks its trajectory for the poses at those
times. :class:`PerLine` answers from the line times alone (the poses were a third of
the orthomosaic's CPU time, ``bench/results/orthomosaic_stages.json``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["PerLine"]


class PerLine:
    """A trajectory whose poses at the pixels' times are computed once per line.

    ``pose`` and ``R_map_from_body`` at ``t_px`` (each of the ``m`` line times repeated for
    its ``k`` pixels, as :meth:`Strip.line_pixels` gives them) are evaluated at the line times
    and repeated: the same numbers (the interpolation is element by element) for 1/k of the
    work; any other times, and everything else, go to the trajectory itself.
    """

    def __init__(self, trajectory, t_lines_s, t_px_s, k: int):
        self._trajectory, self._t_lines, self._t_px, self._k = trajectory, t_lines_s, t_px_s, k

    def __getattr__(self, name):
        return getattr(self._trajectory, name)

    def _ours(self, t_s) -> bool:
        return t_s is self._t_px or (
            np.shape(t_s) == self._t_px.shape and np.array_equal(t_s, self._t_px)
        )

    def pose(self, t_s):
        if not self._ours(t_s):
            return self._trajectory.pose(t_s)
        return tuple(np.repeat(a, self._k, axis=0) for a in self._trajectory.pose(self._t_lines))

    def R_map_from_body(self, t_s):
        if not self._ours(t_s):
            return self._trajectory.R_map_from_body(t_s)
        return np.repeat(self._trajectory.R_map_from_body(self._t_lines), self._k, axis=0)
