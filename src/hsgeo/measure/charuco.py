"""ChArUco corners with OpenCV's ArUco module (``cv2.aruco.CharucoDetector``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.io.boards import Board

__all__ = ["detect_charuco"]


def detect_charuco(image, board: Board, min_corners: int = 6, *, length_unit: str = "mm"):
    """Detect the ChArUco corners of one image.

    Parameters
    ----------
    image : str, Path or (H, W[, 3]) uint8 ndarray
    board : Board
        A ChArUco board (``Board.charuco``), lengths in mm.
    min_corners : int
        Fewer detected corners raise :class:`~hsgeo.ObservationError`.
    length_unit : {"mm", "m"}
        Unit of the returned object coordinates and of the board given to OpenCV (which
        interpolates the corners in float32, so the unit moves them by ~3e-5 px: use the unit of
        the reference you compare with).

    Returns
    -------
    ids : (n,) int ndarray
        Corner ids.
    uv_px : (n, 2) ndarray
        Sub-pixel corner positions (OpenCV convention).
    X : (n, 3) ndarray
        The corners' board coordinates (OpenCV's ``getChessboardCorners``, Z = 0), in
        ``length_unit``.
    """
    import cv2

    if board.type != "charuco":
        raise InputError(f"detect_charuco needs a ChArUco board, got type {board.type!r}")
    if isinstance(image, (str, Path)):
        img = cv2.imread(str(image), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise InputError(f"{image}: not a readable image")
    else:
        img = np.asarray(image)
        if img.ndim == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    cvb = board.cv_board(length_unit)
    det = cv2.aruco.CharucoDetector(cvb)
    corners, ids, _, _ = det.detectBoard(img)
    n = 0 if ids is None else len(ids)
    if n < min_corners:
        raise ObservationError(
            f"only {n} ChArUco corners detected (need {min_corners}): is the board "
            f"{board.nx}x{board.ny} {board.dictionary} in the image?"
        )
    ids = ids.ravel().astype(int)
    X = np.asarray(cvb.getChessboardCorners(), dtype=np.float64)[ids]
    return ids, corners.reshape(-1, 2).astype(np.float64), X
