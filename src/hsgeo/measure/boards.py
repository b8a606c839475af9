"""Observations of calibration boards (ChArUco or ArUco grid) from image files.

The board is a :class:`hsgeo.io.boards.Board` (lengths in mm), usually read from the board file
(``--board BOARD.toml`` of ``hsgeo calibrate-frame``, :func:`hsgeo.io.read_board`)::

    [board]
    type = "charuco"          # or "aruco_grid"
    dictionary = "DICT_6X6_250"
    # charuco: squares and the marker inside a white square, lengths in mm
    squares_x = 5
    squares_y = 7
    square_mm = 40.0
    marker_mm = 20.0
    # aruco_grid instead: markers_x, markers_y, marker_mm, separation_mm (first id 0)

    [camera]                  # optional
    pixel_mm = 0.0055         # pixel pitch; without it the "mm" of the results are pixels

Object coordinates are OpenCV's board frame (x right, y down, z into the board, mm). A ChArUco
board gives chessboard corners (one point each); an ArUco grid gives targets whose four corners
are averaged into one virtual point, as in 003 §3.2.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.io.boards import Board

__all__ = ["observe_files", "NOMINAL_PIXEL_MM", "MAX_HOMOGRAPHY_RMS_SHARE"]

NOMINAL_PIXEL_MM = 0.005


def _not_found(board: Board, what: str) -> str:
    """The board/image mismatch, in the board file's terms."""
    keys = "squares_x, squares_y" if board.type == "charuco" else "markers_x, markers_y"
    return (
        f"the board was not found ({what} of a {board.nx} x {board.ny} {board.type} board of "
        f"{board.dictionary}): the board file does not match the board in the images (check "
        f"its type, dictionary, {keys}), or the board is not visible in this image"
    )


def _number(pattern: str | None, name: str, default: int) -> int:
    if pattern is None:
        return default
    m = re.search(pattern, name)
    if m is None or not m.groups():
        raise InputError(f"file name {name!r} does not match {pattern!r} (with one group)")
    return int(m.group(1))


def observe_files(
    paths,
    board: Board,
    *,
    band_regex: str | None = None,
    cube_regex: str | None = None,
    refine: str = "subpix",
):
    """Detect the board in image files and return :class:`hsgeo.measure.targets.Observations`.

    Parameters
    ----------
    paths : sequence of path
    board : Board
    band_regex, cube_regex : str, optional
        Regular expressions with one group that take the band number and the cube (view)
        number from a file name; by default all images are band 1 and each is its own view.
    """
    import cv2

    from hsgeo.measure.aruco import detect_targets, make_detector
    from hsgeo.measure.charuco import detect_charuco
    from hsgeo.measure.targets import Observations

    paths = [Path(p) for p in paths]
    if not paths:
        raise InputError("no image files given")
    if board.type != "charuco":
        det = make_detector(board.dictionary, refine=refine)
        obj_all = np.asarray(board.cv_board().getObjPoints(), float)
    rows = {k: [] for k in ("cube", "band", "target", "corners", "obj")}
    size = None
    for i, p in enumerate(paths):
        img = cv2.imread(str(p), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise InputError(f"{p}: not an image OpenCV can read")
        if size is None:
            size = (img.shape[1], img.shape[0])
        elif size != (img.shape[1], img.shape[0]):
            raise InputError(f"{p}: size {img.shape[::-1]} differs from the first image's {size}")
        band = _number(band_regex, p.name, 1)
        cube = _number(cube_regex, p.name, i)
        if board.type == "charuco":  # the one ChArUco detection (hsgeo.measure.charuco)
            try:
                ids, cc, X = detect_charuco(img, board, min_corners=6)
            except ObservationError:
                raise ObservationError(
                    f"{p}: {_not_found(board, 'fewer than 6 ChArUco corners')}"
                ) from None
            ids = ids.astype(np.int64)
            px = np.repeat(cc.reshape(-1, 1, 2), 4, axis=1)
            obj = np.repeat(X[:, None, :], 4, axis=1)
        else:
            d = detect_targets(img, det, valid_ids=np.arange(len(obj_all)))
            if len(d) < 4:
                raise ObservationError(f"{p}: {_not_found(board, 'fewer than 4 ArUco targets')}")
            ids, px, obj = d.ids, d.corners_px, obj_all[d.ids]
        _check_board_layout(p, px.reshape(-1, 2), obj.reshape(-1, 3), img.shape, board)
        rows["cube"].append(np.full(len(ids), cube))
        rows["band"].append(np.full(len(ids), band))
        rows["target"].append(ids)
        rows["corners"].append(px)
        rows["obj"].append(obj)
    # without a pixel pitch, a nominal 5 µm keeps the mm quantities of order one (the
    # results are converted to pixels by the caller)
    pixel = board.pixel_mm if board.pixel_mm is not None else NOMINAL_PIXEL_MM
    cat = {k: np.concatenate(v) for k, v in rows.items()}
    return Observations(
        cat["cube"].astype(np.int64),
        cat["band"].astype(np.int64),
        cat["target"].astype(np.int64),
        cat["corners"],
        cat["obj"],
        size,
        pixel,
    )


#: The largest RMS (share of the image diagonal) of a plane-to-image homography through one
#: image's detected points that a real lens leaves: beyond it the points are not where the board
#: description puts them.
MAX_HOMOGRAPHY_RMS_SHARE = 0.02


def _check_board_layout(path, uv_px, X, shape, board) -> None:
    """The detected points lie in the image as a plane's points do (a homography fits them):
    a board description other than the photographed one would otherwise fail later as 'did
    not converge', which names no cause.
    """
    import cv2

    if uv_px.shape[0] < 5 or not np.allclose(X[:, 2], 0):
        return
    H, _ = cv2.findHomography(X[:, :2].astype(np.float64), uv_px.astype(np.float64), 0)
    if H is None:
        return
    q = cv2.perspectiveTransform(X[:, None, :2].astype(np.float64), H)[:, 0]
    rms = float(np.sqrt(np.mean(np.sum((q - uv_px) ** 2, axis=1))))
    if rms > MAX_HOMOGRAPHY_RMS_SHARE * float(np.hypot(*shape)):
        raise InputError(
            f"{path}: the detected markers do not lie as the board file places them (a "
            f"plane-to-image fit leaves {rms:.3g} px RMS, over {MAX_HOMOGRAPHY_RMS_SHARE:.0%} of "
            f"the image diagonal); the likely causes: a board type other than the photographed "
            f"one (the file says {board.type}), its rows and columns swapped or miscounted, or "
            "the marker and square sizes"
        )
