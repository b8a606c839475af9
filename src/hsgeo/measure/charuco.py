"""ChArUco corners with OpenCV's ArUco module (``cv2.aruco.CharucoDetector``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError, ObservationError

__all__ = ["CharucoBoardSpec", "detect_charuco"]


@dataclass(frozen=True)
class CharucoBoardSpec:
    """A ChArUco board: squares_x × squares_y squares, sizes in metres, an ArUco dictionary name.

    The corners' object coordinates are OpenCV's (``board.getChessboardCorners()``), Z = 0.
    """

    squares_x: int = 5
    squares_y: int = 7
    square_m: float = 0.04
    marker_m: float = 0.02
    dictionary: str = "DICT_6X6_250"

    def board(self):
        """The ``cv2.aruco.CharucoBoard``."""
        import cv2

        if not hasattr(cv2.aruco, self.dictionary):
            raise InputError(f"unknown ArUco dictionary {self.dictionary!r} (e.g. DICT_6X6_250)")
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        return cv2.aruco.CharucoBoard((self.squares_x, self.squares_y), self.square_m,
                                      self.marker_m, d)


def detect_charuco(image, spec: CharucoBoardSpec, min_corners: int = 6):
    """Detect the ChArUco corners of one image.

    Parameters
    ----------
    image : str, Path or (H, W[, 3]) uint8 ndarray
    spec : CharucoBoardSpec
    min_corners : int
        Fewer detected corners raise :class:`~hsgeo.ObservationError`.

    Returns
    -------
    ids : (n,) int ndarray
        Corner ids.
    uv_px : (n, 2) ndarray
        Sub-pixel corner positions (OpenCV convention).
    X_m : (n, 3) ndarray
        The corners' board coordinates.
    """
    import cv2

    if isinstance(image, (str, Path)):
        img = cv2.imread(str(image), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise InputError(f"{image}: not a readable image")
    else:
        img = np.asarray(image)
        if img.ndim == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    board = spec.board()
    det = cv2.aruco.CharucoDetector(board)
    corners, ids, _, _ = det.detectBoard(img)
    n = 0 if ids is None else len(ids)
    if n < min_corners:
        raise ObservationError(
            f"only {n} ChArUco corners detected (need {min_corners}): is the board "
            f"{spec.squares_x}x{spec.squares_y} {spec.dictionary} in the image?"
        )
    ids = ids.ravel().astype(int)
    X = np.asarray(board.getChessboardCorners(), dtype=np.float64)[ids]
    return ids, corners.reshape(-1, 2).astype(np.float64), X
