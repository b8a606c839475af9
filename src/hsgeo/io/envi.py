"""ENVI files: binary data (BSQ, BIL or BIP) with a ``.hdr`` text header, written whole or in
blocks of lines (:class:`EnviWriter`), read back by :func:`read_envi`.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, output_group, refuse_inputs

__all__ = ["write_envi", "read_envi", "EnviWriter"]

_ENVI_TYPES = {
    np.dtype("uint8"): 1,
    np.dtype("int16"): 2,
    np.dtype("int32"): 3,
    np.dtype("float32"): 4,
    np.dtype("float64"): 5,
    np.dtype("uint16"): 12,
}


def _header(
    shape_bls,
    dtype,
    *,
    interleave="bsq",
    map_info=None,
    band_names=None,
    wavelength_nm=None,
    fwhm_nm=None,
    data_ignore_value=None,
    default_bands=None,
    description="hsgeo",
    crs_wkt=None,
) -> str:
    """The text of an ENVI header for data of shape (bands, lines, samples)."""
    b, lines, samples = shape_bls
    hdr = [
        "ENVI",
        f"description = {{{description}}}",
        f"samples = {samples}",
        f"lines = {lines}",
        f"bands = {b}",
        "header offset = 0",
        "file type = ENVI Standard",
        f"data type = {_ENVI_TYPES[np.dtype(dtype)]}",
        f"interleave = {interleave}",
        "byte order = 0",
    ]
    if map_info is not None:
        e, n, de, dn = map_info
        hdr.append(f"map info = {{Arbitrary, 1, 1, {e!r}, {n!r}, {de!r}, {dn!r}, 0, units=Meters}}")
    if crs_wkt is not None:  # ENVI's key for the CRS (WKT), which GDAL reads
        hdr.append("coordinate system string = {" + " ".join(str(crs_wkt).split()) + "}")
    if band_names is not None:
        hdr.append("band names = {" + ", ".join(str(x) for x in band_names) + "}")
    if wavelength_nm is not None:
        hdr.append("wavelength units = Nanometers")
        hdr.append("wavelength = {" + ", ".join(repr(float(x)) for x in wavelength_nm) + "}")
    if fwhm_nm is not None:
        hdr.append("fwhm = {" + ", ".join(repr(float(x)) for x in fwhm_nm) + "}")
    if data_ignore_value is not None:
        hdr.append(f"data ignore value = {data_ignore_value!r}")
    if default_bands is not None:
        hdr.append("default bands = {" + ", ".join(str(int(x) + 1) for x in default_bands) + "}")
    return "\n".join(hdr) + "\n"


def _check_dtype(dtype):
    dtype = np.dtype(dtype)
    if dtype not in _ENVI_TYPES:
        raise InputError(
            f"ENVI cannot store dtype {dtype}; use one of {sorted(str(t) for t in _ENVI_TYPES)}"
        )
    return dtype


def write_envi(
    path,
    data,
    *,
    map_info=None,
    band_names=None,
    wavelength_nm=None,
    fwhm_nm=None,
    data_ignore_value=None,
    default_bands=None,
    interleave: str = "bsq",
    description: str = "hsgeo",
    crs_wkt: str | None = None,
    inputs=(),
) -> tuple[Path, Path]:
    """Write an ENVI file ``path`` and its header ``path.hdr``.

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
    wavelength_nm, fwhm_nm : (bands,) array_like, optional
        Band centres and widths (header ``wavelength``, ``fwhm``; nanometres).
    data_ignore_value : float, optional
        The value that marks a pixel without data (header ``data ignore value``).
    default_bands : sequence of int, optional
        0-based bands a viewer shows as red, green, blue (written 1-based, as ENVI counts).
    interleave : {"bsq", "bil", "bip"}
        Order of the values in the file: band-sequential (the paper's, 001 §2.4),
        band-interleaved by line, by pixel.
    description : str
    crs_wkt : str, optional
        The CRS of ``map_info`` as WKT (header ``coordinate system string``).
    inputs : iterable of path, optional
        Files the command reads; writing over one raises :class:`~hsgeo.InputError`.

    Returns
    -------
    (Path, Path)
        The data file and its header, each written atomically (temporary file, then
        :func:`os.replace`).
    """
    arr = np.asarray(data)
    if arr.ndim == 2:
        arr = arr[None]
    if arr.ndim != 3:
        raise InputError(f"ENVI data must be (bands, lines, samples), got {np.shape(data)}")
    with EnviWriter(
        path,
        arr.shape,
        arr.dtype,
        interleave=interleave,
        map_info=map_info,
        band_names=band_names,
        wavelength_nm=wavelength_nm,
        fwhm_nm=fwhm_nm,
        data_ignore_value=data_ignore_value,
        default_bands=default_bands,
        description=description,
        crs_wkt=crs_wkt,
        inputs=inputs,
    ) as w:
        w[:, :, :] = arr.transpose(1, 2, 0)
    return w.path, w.header_path


class EnviWriter:
    """An ENVI file written in blocks of lines (a cube that never sits in memory whole).

    Use as a context manager; assign blocks in (line, sample, band) order, e.g. as the target
    of :func:`dask.array.store`: ``w[l0:l1, :, :] = block``. The data and the header are
    written to temporary files and moved into place only when the block ends without an
    exception (both files or neither).

    Parameters
    ----------
    path : str or Path
    shape_bls : (bands, lines, samples)
    dtype : numpy dtype
    interleave : {"bsq", "bil", "bip"}
    **header
        ``map_info``, ``band_names``, ``wavelength_nm``, ``fwhm_nm``, ``data_ignore_value``,
        ``default_bands``, ``description`` as for :func:`write_envi`; ``inputs``: files the
        command reads (never written over).
    """

    def __init__(self, path, shape_bls, dtype, *, interleave="bsq", inputs=(), **header):
        self.path = Path(path)
        self.header_path = self.path.with_name(self.path.name + ".hdr")
        refuse_inputs(self.header_path, inputs)
        if interleave not in ("bsq", "bil", "bip"):
            raise InputError(f"unknown ENVI interleave {interleave!r}; use bsq, bil or bip")
        self.interleave = interleave
        self.dtype = _check_dtype(dtype).newbyteorder("<")
        self.shape_bls = tuple(int(x) for x in shape_bls)
        self._header = _header(self.shape_bls, dtype, interleave=interleave, **header)
        self._inputs = inputs
        self._stack = None
        self._fh = None

    def __enter__(self):
        import contextlib

        self._stack = contextlib.ExitStack()
        self._stack.enter_context(output_group())  # the data and the header, or neither
        tmp = self._stack.enter_context(atomic_path(self.path, self._inputs))
        htmp = self._stack.enter_context(atomic_path(self.header_path, self._inputs))
        self._fh = open(tmp, "wb")  # noqa: SIM115 - closed in __exit__
        b, lines, samples = self.shape_bls
        self._fh.truncate(b * lines * samples * self.dtype.itemsize)
        htmp.write_text(self._header)
        return self

    def __exit__(self, exc_type, exc, tb):
        self._fh.close()
        return self._stack.__exit__(exc_type, exc, tb)

    def __setitem__(self, key, block):
        b, n_lines, samples = self.shape_bls
        key = key if isinstance(key, tuple) else (key,)
        lines = key[0].indices(n_lines) if isinstance(key[0], slice) else None
        full = all(
            k == slice(None) or (isinstance(k, slice) and k.indices(n) == (0, n, 1))
            for k, n in zip(key[1:], (samples, b), strict=False)
        )
        if lines is None or lines[2] != 1 or not full:
            raise InputError("EnviWriter takes whole lines: w[l0:l1, :, :] = block")
        l0, l1 = lines[0], lines[1]
        block = np.asarray(block, dtype=self.dtype).reshape(l1 - l0, samples, b)
        size = self.dtype.itemsize
        fd = self._fh.fileno()
        if self.interleave == "bip":  # (line, sample, band): one contiguous run
            os.pwrite(fd, np.ascontiguousarray(block).tobytes(), l0 * samples * b * size)
        elif self.interleave == "bil":  # (line, band, sample)
            data = np.ascontiguousarray(block.transpose(0, 2, 1)).tobytes()
            os.pwrite(fd, data, l0 * b * samples * size)
        else:  # bsq (band, line, sample): one run per band
            per_band = np.ascontiguousarray(block.transpose(2, 0, 1))
            for k in range(b):
                os.pwrite(fd, per_band[k].tobytes(), (k * n_lines + l0) * samples * size)


def read_envi(path) -> tuple[np.ndarray, dict]:
    """Read a BSQ/BIL/BIP ENVI file written by :func:`write_envi` (or ENVI, or a line scanner).

    The reading is :func:`hsgeo.io.envi_read.open_envi`'s: the header ``name.hdr`` or
    ``name.ext.hdr``, either byte order, a ``header offset``, the size checked.

    Parameters
    ----------
    path : str or Path
        The binary file, its header, or the name without extension.

    Returns
    -------
    data : (bands, lines, samples) ndarray
        A read-only view of a :class:`numpy.memmap` (nothing is read until used; copy it to
        change it). ``data ignore value`` is not applied (see ``header``).
    header : dict
        Header entries (strings); ``map info`` parsed to floats under ``map_info``;
        ``wavelength_nm``, ``fwhm_nm`` in nm (converted from ``wavelength units``).
    """
    from hsgeo.io.envi_read import open_envi

    cube = open_envi(path)
    hdr = dict(cube.header)
    if cube.wavelength_nm is not None:
        hdr["wavelength_nm"] = cube.wavelength_nm
    if cube.fwhm_nm is not None:
        hdr["fwhm_nm"] = cube.fwhm_nm
    if "map info" in hdr:
        parts = [p.strip() for p in hdr["map info"].strip("{}").split(",")]
        try:
            hdr["map_info"] = tuple(float(x) for x in parts[3:7])
        except ValueError:
            raise InputError(
                f"{cube.header_path}: map info {hdr['map info']!r} unreadable"
            ) from None
    return cube.bls, hdr
