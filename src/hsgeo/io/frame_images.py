"""Frames of a frame camera for ``hsgeo orthorectify``: the images and their times.

**A frame** is one image file per exposure, as frame cameras and their software write them:

* an ENVI file (``name.raw``/``.dat``/… with ``name.hdr``, or the bare name; one band for a
  monochrome frame, the bands of a cube: the Rikola's bands in the order of the sensor file's
  ``bands``), read memory-mapped by :func:`hsgeo.io.envi_read.open_envi` (the header's lines
  are the image rows, its samples the columns, its wavelengths carried along);
* a TIFF or GeoTIFF (``.tif``/``.tiff``; one band or several, e.g. RGB), read by rasterio; a
  GeoTIFF's georeferencing is ignored (the frame is placed by its exposure and the sensor).

Pixel ``(u, v)``: column ``u`` right, row ``v`` down, origin at the centre of the top-left pixel
(OpenCV's convention, that of :class:`hsgeo.sensors.frame.FrameCamera` and of
:func:`hsgeo.sensors.frame.pixel_to_mm` for the Rikola).

**The exposure table** (``--frame-times``, CSV or Parquet, :func:`read_frame_times`): columns

* ``file``: the frame's file name, with or without its folder, as the binary file, the header
  or the bare name (``f0001.raw``, ``f0001.hdr`` and ``f0001`` all name one ENVI frame);
* ``time_s``: the exposure's time, s, on the navigation's time scale;
* ``band`` (optional, Rikola only): a band number of the sensor file's ``bands``; then one row
  per band of each frame, each band at its own exposure time (the Rikola's Fabry–Pérot
  interferometer exposes its bands one after the other).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["FRAME_TIFF_SUFFIXES", "frame_key", "open_frame", "read_frame_times"]

FRAME_TIFF_SUFFIXES = (".tif", ".tiff")


def frame_key(name) -> str:
    """The name a frame is matched by in the exposure table: the file name without its folder,
    without ``.hdr`` and without an ENVI or TIFF extension (``f1.raw.hdr`` → ``f1``).
    """
    from hsgeo.io.envi_read import DATA_EXTS

    n = Path(str(name).strip()).name
    if n.lower().endswith(".hdr"):
        n = n[:-4]
    stem, suffix = Path(n).stem, Path(n).suffix.lower()
    return stem if suffix in (*DATA_EXTS[1:], *FRAME_TIFF_SUFFIXES) else n


def read_frame_times(path) -> dict:
    """The exposure table (module docstring): ``{(frame_key, band or None): time_s}``.

    Raises
    ------
    InputError
        A missing ``file`` or ``time_s`` column, an empty or non-numeric time, a ``band`` that
        is not a whole number, a frame (and band) given twice: naming the file, line and column.
    """
    from hsgeo.io.tables import read_table

    df = read_table(path, ["file", "time_s"], "--frame-times exposure", text_columns=("file",))
    has_band = "band" in df.columns
    if has_band:
        b = np.asarray(df["band"], dtype=object)
        ok = [_whole(x) for x in b]
        if not all(ok):
            i = ok.index(False)
            raise InputError(
                f"--frame-times {str(path)!r}: column band, row {i + 1} holds {b[i]!r}; give a "
                "whole band number of the sensor file's bands (or leave the column out: one "
                "time per frame)"
            )
    out: dict = {}
    for i, row in enumerate(df.itertuples(index=False)):
        key = (frame_key(row.file), int(float(row.band)) if has_band else None)
        if key in out:
            what = f"frame {row.file!r}" + (f", band {key[1]}" if has_band else "")
            raise InputError(
                f"--frame-times {str(path)!r}: {what} is given twice (row {i + 1}, column "
                "file); give one exposure time per frame" + (" and band" if has_band else "")
            )
        out[key] = float(row.time_s)
    return out


def _whole(x) -> bool:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return False
    return bool(np.isfinite(v) and v.is_integer() and v > 0)


def open_frame(path, rows_per_chunk: int = 256):
    """One frame: its values ``(rows, columns, bands)`` (float32; a Dask array over the memory
    map for ENVI, NaN for the header's ``data ignore value``) and what it holds.

    Returns
    -------
    values : (rows, columns, bands) array
    info : dict
        ``files`` (the paths the frame is read from), ``wavelength_nm``, ``fwhm_nm`` (or None).

    Raises
    ------
    InputError
        As :func:`hsgeo.io.envi_read.open_envi`, or a TIFF rasterio cannot read.
    """
    p = Path(path)
    if p.suffix.lower() in FRAME_TIFF_SUFFIXES:
        import warnings

        import rasterio
        from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

        from hsgeo.io._files import check_input_file

        check_input_file(p, "frame")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                with rasterio.open(p) as src:
                    v = src.read().astype(np.float32)
                    nod = src.nodata
        except RasterioIOError as exc:
            raise InputError(f"frame {str(p)!r} is not a readable TIFF: {exc}") from None
        if nod is not None:
            v[v == np.float32(nod)] = np.nan
        return v.transpose(1, 2, 0), {"files": [p], "wavelength_nm": None, "fwhm_nm": None}
    from hsgeo.io.envi_read import open_envi
    from hsgeo.io.line_cube import _lazy_float32

    cube = open_envi(p)
    values = _lazy_float32(cube, rows_per_chunk)
    return values, {
        "files": [cube.data_path, cube.header_path],
        "wavelength_nm": cube.wavelength_nm,
        "fwhm_nm": cube.fwhm_nm,
    }
