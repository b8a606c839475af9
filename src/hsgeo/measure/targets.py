"""Target observations of a set of views and bands: the output of every target detector.

:func:`hsgeo.measure.boards.observe_files` (a user's images) and the Rikola chapter's detection
of rendered images both return :class:`Observations`; the calibrations of
:mod:`hsgeo.workflows.rikola` take them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.sensors.frame import pixel_to_mm

__all__ = ["Observations"]


@dataclass
class Observations:
    """Target observations of a set of cubes and bands (one row per target and image).

    Attributes
    ----------
    cube, band, target : (n,) int ndarrays
        Cube index, band number (1–25) and target id.
    corners_px : (n, 4, 2) ndarray
        Detected corners (OpenCV pixel convention).
    corners_obj : (n, 4, 3) ndarray
        Object coordinates of the corners.
    image_size : (int, int)
    pixel_mm : float
    """

    cube: np.ndarray
    band: np.ndarray
    target: np.ndarray
    corners_px: np.ndarray
    corners_obj: np.ndarray
    image_size: tuple[int, int]
    pixel_mm: float

    @property
    def centroids_px(self) -> np.ndarray:
        return self.corners_px.mean(axis=1)

    @property
    def centroids_mm(self) -> np.ndarray:
        return pixel_to_mm(self.centroids_px, self.image_size, self.pixel_mm)

    def select(self, mask) -> Observations:
        m = np.asarray(mask, bool)
        return Observations(
            self.cube[m],
            self.band[m],
            self.target[m],
            self.corners_px[m],
            self.corners_obj[m],
            self.image_size,
            self.pixel_mm,
        )
