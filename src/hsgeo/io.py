"""Reading and writing: OpenCV calibration files, observation tables, scenario outputs."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["read_opencv_storage", "read_csv_table"]


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


def read_csv_table(path, columns: tuple[str, ...]):
    """Read a CSV observation table with required columns; NaN and missing columns are errors.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        df = pd.read_csv(path, comment="#")
    except (pd.errors.ParserError, UnicodeDecodeError, pd.errors.EmptyDataError) as exc:
        raise InputError(f"{path}: not a readable CSV table: {exc}") from None
    df.columns = [c.strip() for c in df.columns]
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise InputError(
            f"{path}: missing columns {missing}; the file has {list(df.columns)} and needs "
            f"{list(columns)}"
        )
    sub = df[list(columns)]
    bad = sub.isna().any(axis=1)
    if bad.any():
        rows = (np.flatnonzero(bad.to_numpy())[:5] + 2).tolist()
        raise InputError(f"{path}: empty or NaN values in lines {rows} (1 = header)")
    return df
