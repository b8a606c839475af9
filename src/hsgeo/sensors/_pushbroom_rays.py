"""The rays of LP pixels grouped by line: one rotation per line, one direction per column.

002 eq. (4) read backwards gives each pixel's ray (see :class:`hsgeo.sensors.pushbroom.
PushbroomCamera`)::

    origin    = x + R l^p                       R = R_map_from_platform (the line's pose)
    direction = R βᵀ (x̄, ȳ, c_b) / |(x̄, ȳ, c_b)|

The pose is a property of the line (every pixel of an LP line is exposed at the line's time)
and the camera-frame direction ``(x̄, ȳ, c_b)`` of the detector column and band (the undistorted
image coordinate of 002 eq. (3) and the band's principal distance). So the line's
``R_map_from_camera = R βᵀ`` and origin are formed once per line, the unit camera direction once
per column (or once per pixel when the lines do not share their pixels), and
:func:`rays_by_line` combines them: one 3×3 matrix-vector product per pixel, written straight
into the outputs. Replaces per-pixel (n, 3, 3) rotation stacks, a per-pixel undistortion and
three (n, 3) temporaries (330 ns per ray in the orthomosaic's profile).

References
----------
Jonassen et al. (2024), 002 eq. (3)–(4).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["line_runs", "rays_by_line"]


@njit(cache=True, nogil=True)
def rays_by_line(starts, origin_m, R_map_from_cam, u_cam, per_column, origins_out, dirs_out):
    """Origins and directions of pixels grouped in lines (002 eq. (4) read backwards).

    Parameters
    ----------
    starts : (m + 1,) int64 ndarray
        Pixels ``starts[i] … starts[i + 1] − 1`` belong to line ``i``.
    origin_m : (m, 3) ndarray, m
        Projection centre of each line, ``x + R l^p``.
    R_map_from_cam : (m, 3, 3) ndarray
        ``R_map_from_platform βᵀ`` of each line.
    u_cam : (k, 3) or (n, 3) ndarray
        Unit camera-frame direction ``(x̄, ȳ, c_b) / |·|`` of each column (``per_column``: pixel
        ``p`` of line ``i`` is column ``p − starts[i]``) or of each pixel.
    per_column : bool
    origins_out, dirs_out : (n, 3) ndarray
        Out: each pixel's origin and unit direction ``R_map_from_cam u_cam`` in the map frame.
    """
    for i in range(starts.size - 1):  # pragma: no cover - compiled
        a, b = starts[i], starts[i + 1]
        ox, oy, oz = origin_m[i, 0], origin_m[i, 1], origin_m[i, 2]
        C = R_map_from_cam[i]
        c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
        c10, c11, c12 = C[1, 0], C[1, 1], C[1, 2]
        c20, c21, c22 = C[2, 0], C[2, 1], C[2, 2]
        for p in range(a, b):
            j = p - a if per_column else p
            x, y, z = u_cam[j, 0], u_cam[j, 1], u_cam[j, 2]
            origins_out[p, 0] = ox
            origins_out[p, 1] = oy
            origins_out[p, 2] = oz
            dirs_out[p, 0] = c00 * x + c01 * y + c02 * z  # 002 eq. (4): R βᵀ p^c
            dirs_out[p, 1] = c10 * x + c11 * y + c12 * z
            dirs_out[p, 2] = c20 * x + c21 * y + c22 * z


def line_runs(t_s: np.ndarray) -> np.ndarray:
    """Starts of the runs of equal consecutive times, ``(m + 1,)`` (the last is ``t_s.size``).

    The pixels of one LP line share its time: each run is a line, whose pose is computed once.
    """
    n = t_s.size
    if n == 0:
        return np.zeros(1, dtype=np.int64)
    cut = np.flatnonzero(t_s[1:] != t_s[:-1]) + 1
    return np.concatenate(([0], cut, [n])).astype(np.int64)
