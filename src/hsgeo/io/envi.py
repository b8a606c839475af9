"""ENVI files: band-sequential (BSQ) binary data with a ``.hdr`` text header."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, refuse_inputs

__all__ = ["write_envi", "read_envi"]

_ENVI_TYPES = {
    np.dtype("uint8"): 1,
    np.dtype("int16"): 2,
    np.dtype("int32"): 3,
    np.dtype("float32"): 4,
    np.dtype("float64"): 5,
    np.dtype("uint16"): 12,
}


def write_envi(
    path,
    data,
    *,
    map_info=None,
    band_names=None,
    wavelength_nm=None,
    description: str = "hsgeo",
    inputs=(),
) -> tuple[Path, Path]:
    """Write a band-sequential ENVI file ``path`` and its header ``path.hdr``.

    Parameters
    ----------
    path : str or Path
        The binary file (conventionally without extension or ``.bsq``).
    data : (bands, lines, samples) or (lines, samples) ndarray
        Any of uint8, int16, int32, uint16, float32, float64; written little-endian.
    map_info : (E_ul, N_ul, dE, dN), optional
        Map coordinates of the upper-left corner of the upper-left pixel and the cell sizes,
        written as an ENVI ``map info`` in an arbitrary metric frame.
    band_names : sequence of str, optional
    wavelength_nm : (bands,) array_like, optional
    description : str
    inputs : iterable of path, optional
        Files the command reads; writing over one raises :class:`~hsgeo.InputError`.

    Returns
    -------
    (Path, Path)
        The data file and its header, each written atomically (temporary file, then
        :func:`os.replace`).
    """
    path = Path(path)
    arr = np.asarray(data)
    if arr.ndim == 2:
        arr = arr[None]
    if arr.ndim != 3:
        raise InputError(f"ENVI data must be (bands, lines, samples), got {np.shape(data)}")
    if arr.dtype not in _ENVI_TYPES:
        raise InputError(
            f"ENVI cannot store dtype {arr.dtype}; use one of {sorted(str(t) for t in _ENVI_TYPES)}"
        )
    hpath = path.with_name(path.name + ".hdr")
    refuse_inputs(hpath, inputs)
    b, lines, samples = arr.shape
    hdr = [
        "ENVI",
        f"description = {{{description}}}",
        f"samples = {samples}",
        f"lines = {lines}",
        f"bands = {b}",
        "header offset = 0",
        "file type = ENVI Standard",
        f"data type = {_ENVI_TYPES[arr.dtype]}",
        "interleave = bsq",
        "byte order = 0",
    ]
    if map_info is not None:
        e, n, de, dn = map_info
        hdr.append(f"map info = {{Arbitrary, 1, 1, {e!r}, {n!r}, {de!r}, {dn!r}, 0, units=Meters}}")
    if band_names is not None:
        hdr.append("band names = {" + ", ".join(str(x) for x in band_names) + "}")
    if wavelength_nm is not None:
        hdr.append("wavelength units = Nanometers")
        hdr.append("wavelength = {" + ", ".join(repr(float(x)) for x in wavelength_nm) + "}")
    # both files or neither: the data and the header are renamed into place only after both
    # were written
    with atomic_path(path, inputs) as tmp, atomic_path(hpath, inputs) as htmp:
        arr.astype(arr.dtype.newbyteorder("<"), copy=False).tofile(tmp)
        htmp.write_text("\n".join(hdr) + "\n")
    return path, hpath


def read_envi(path) -> tuple[np.ndarray, dict]:
    """Read a BSQ/BIL/BIP ENVI file written by :func:`write_envi` (or ENVI itself).

    Returns
    -------
    data : (bands, lines, samples) ndarray
    header : dict
        Header entries (strings; ``map info`` parsed to floats under ``map_info``).
    """
    path = Path(path)
    hpath = path.with_name(path.name + ".hdr")
    if not hpath.is_file():
        raise InputError(f"{hpath}: ENVI header not found next to {path}")
    text = hpath.read_text()
    if not text.startswith("ENVI"):
        raise InputError(f"{hpath}: not an ENVI header (first line must be 'ENVI')")
    hdr: dict = {}
    key, buf = None, ""
    for line in text.splitlines()[1:]:
        if key is not None:
            buf += " " + line.strip()
            if "}" in line:
                hdr[key], key = buf.strip(), None
            continue
        if "=" not in line:
            continue
        k, v = (s.strip() for s in line.split("=", 1))
        if v.startswith("{") and "}" not in v:
            key, buf = k.lower(), v
        else:
            hdr[k.lower()] = v
    try:
        b, lines, samples = int(hdr["bands"]), int(hdr["lines"]), int(hdr["samples"])
        dtype = {v: k for k, v in _ENVI_TYPES.items()}[int(hdr["data type"])]
    except (KeyError, ValueError) as exc:
        raise InputError(
            f"{hpath}: missing or bad entry ({exc}); need samples, lines, bands, data type"
        ) from None
    if hdr.get("byte order", "0") == "1":
        dtype = dtype.newbyteorder(">")
    raw = np.fromfile(path, dtype=dtype, offset=int(hdr.get("header offset", 0)))
    if raw.size != b * lines * samples:
        raise InputError(f"{path}: {raw.size} values, the header says {b}×{lines}×{samples}")
    inter = hdr.get("interleave", "bsq").lower()
    shape = {"bsq": (b, lines, samples), "bil": (lines, b, samples), "bip": (lines, samples, b)}
    if inter not in shape:
        raise InputError(f"{hpath}: unknown interleave {inter!r}")
    data = raw.reshape(shape[inter])
    data = {"bsq": data, "bil": data.transpose(1, 0, 2), "bip": data.transpose(2, 0, 1)}[inter]
    if "map info" in hdr:
        parts = [p.strip() for p in hdr["map info"].strip("{}").split(",")]
        hdr["map_info"] = tuple(float(x) for x in parts[3:7])
    return data, hdr
