"""OpenCV FileStorage files (YAML/XML calibration output)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["read_opencv_storage"]


def read_opencv_storage(path, required: tuple[str, ...] = ()) -> dict:
    """Read an OpenCV FileStorage YAML/XML file (camera calibration output) into a dict.

    Matrices (``!!opencv-matrix``) become float64 arrays, numbers floats, strings str.

    Parameters
    ----------
    path : str or Path
    required : tuple of str
        Keys that must be present; a missing one raises :class:`~hsgeo.InputError`.
    """
    import cv2

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except (cv2.error, SystemError) as exc:  # cv2 wraps parse errors in SystemError
        cause = exc.__cause__ or exc
        raise InputError(
            f"{path}: not a readable OpenCV FileStorage file (YAML/XML): "
            f"{str(cause).strip().splitlines()[-1]}"
        ) from None
    if not fs.isOpened():
        raise InputError(f"{path}: OpenCV could not open it as FileStorage YAML/XML")
    out = {}
    root = fs.root()
    for key in root.keys():
        node = fs.getNode(key)
        if node.isMap() and not node.empty() and node.mat() is not None:
            out[key] = np.asarray(node.mat(), dtype=np.float64)
        elif node.isReal() or node.isInt():
            out[key] = float(node.real())
        elif node.isString():
            out[key] = node.string()
        else:
            m = node.mat()
            if m is not None:
                out[key] = np.asarray(m, dtype=np.float64)
    fs.release()
    missing = [k for k in required if k not in out]
    if missing:
        raise InputError(f"{path}: missing entries {missing} (found: {sorted(out)})")
    return out
