"""ArUco coded targets: detection, corner refinement and the target centroid (003 §3.1–3.2).

The paper locates the ArUco targets automatically in every band, measures their corners with
sub-pixel precision (Garrido-Jurado et al. 2014) and — because the corner positions move with the
band's exposure — replaces the four corners of a target by their centroid, one virtual point per
target (003 §3.2). Here the detection is OpenCV's ``cv2.aruco.ArucoDetector``; the corners are
refined either on the thresholded contour (``"contour"``: straight lines fitted to the edge
pixels and intersected, the paper's description) or on the grey values (``"subpix"``:
``cv2.cornerSubPix``).

Pixel coordinates follow OpenCV: origin at the centre of the top-left pixel, x right, y down.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError

__all__ = ["Detection", "make_detector", "detect_targets", "to_uint8", "detection_rate"]

_REFINE = {
    "none": "CORNER_REFINE_NONE",
    "subpix": "CORNER_REFINE_SUBPIX",
    "contour": "CORNER_REFINE_CONTOUR",
    "apriltag": "CORNER_REFINE_APRILTAG",
}


@dataclass(frozen=True)
class Detection:
    """The targets found in one image.

    Attributes
    ----------
    ids : (n,) int ndarray, sorted
    corners_px : (n, 4, 2) ndarray
        Corners in ArUco order (top-left, top-right, bottom-right, bottom-left of the marker).
    """

    ids: np.ndarray
    corners_px: np.ndarray

    @property
    def centroids_px(self) -> np.ndarray:
        """(n, 2) centroid of each target's four corners: the paper's virtual point (003 §3.2)."""
        return self.corners_px.mean(axis=1)

    def __len__(self) -> int:
        return int(self.ids.size)


def make_detector(dictionary: str = "DICT_4X4_100", refine: str = "subpix", win_size: int = 5):
    """A ``cv2.aruco.ArucoDetector`` for a predefined dictionary.

    Parameters
    ----------
    dictionary : str
        OpenCV name, e.g. ``"DICT_4X4_100"``.
    refine : {"subpix", "contour", "apriltag", "none"}
        Corner refinement method.
    win_size : int
        Half window of the sub-pixel refinement (px).
    """
    import cv2

    if not hasattr(cv2.aruco, str(dictionary)):
        raise InputError(
            f"unknown ArUco dictionary {dictionary!r}; use an OpenCV name such as "
            "DICT_4X4_100 or DICT_6X6_250"
        )
    if refine not in _REFINE:
        raise InputError(f"refine must be one of {sorted(_REFINE)}, got {refine!r}")
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    p = cv2.aruco.DetectorParameters()
    p.cornerRefinementMethod = getattr(cv2.aruco, _REFINE[refine])
    p.cornerRefinementWinSize = int(win_size)
    p.cornerRefinementMaxIterations = 100
    p.cornerRefinementMinAccuracy = 0.001
    return cv2.aruco.ArucoDetector(d, p)


def to_uint8(image, scale: float = 1.0 / 16.0) -> np.ndarray:
    """Raw DN to the 8-bit image the detector reads, with one fixed scale for every band (so a
    darker band is also a lower-contrast image, as in the camera's 8-bit previews).
    """
    img = np.asarray(image)
    if img.ndim != 2:
        raise InputError(f"expected a single-band image (height, width), got shape {img.shape}")
    return np.clip(np.rint(img.astype(np.float64) * scale), 0, 255).astype(np.uint8)


def detect_targets(image, detector=None, *, valid_ids=None) -> Detection:
    """Detect ArUco targets in an 8-bit grey image.

    Parameters
    ----------
    image : (height, width) uint8 ndarray
    detector : cv2.aruco.ArucoDetector, optional
        Default :func:`make_detector` ().
    valid_ids : array_like, optional
        Keep only these ids (drop false detections of ids that are not on the board).

    Returns
    -------
    Detection
    """
    img = np.asarray(image)
    if img.ndim != 2 or img.dtype != np.uint8:
        raise InputError(
            f"detect_targets needs a (height, width) uint8 image, got {img.shape} "
            f"{img.dtype}; convert raw DN with to_uint8()"
        )
    det = make_detector() if detector is None else detector
    corners, ids, _ = det.detectMarkers(img)
    if ids is None or len(ids) == 0:
        return Detection(np.zeros(0, dtype=np.int64), np.zeros((0, 4, 2)))
    ids = np.asarray(ids, dtype=np.int64).ravel()
    c = np.asarray(corners, dtype=np.float64).reshape(-1, 4, 2)
    keep = np.ones(ids.size, bool)
    if valid_ids is not None:
        keep &= np.isin(ids, np.asarray(valid_ids))
    # an id seen twice is ambiguous: drop it
    u, counts = np.unique(ids[keep], return_counts=True)
    keep &= ~np.isin(ids, u[counts > 1])
    order = np.argsort(ids[keep], kind="stable")
    return Detection(ids[keep][order], c[keep][order])


def detection_rate(found: int, expected: int) -> float:
    """Fraction of the targets expected in view that were detected."""
    if expected <= 0:
        raise InputError("detection_rate: no targets expected in view")
    return float(found) / float(expected)
