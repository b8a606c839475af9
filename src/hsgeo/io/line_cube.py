"""Recorded lines in either format, chosen by suffix: hsgeo's NetCDF LP strip
(:mod:`hsgeo.io.lp_lines`, ``.nc``) or a line scanner's ENVI cube (:mod:`hsgeo.io.envi_read`,
any other name) with its line times.

:func:`read_line_cube` gives a lazy ``(line, sample, band)`` DataArray; :func:`open_line_strip`
gives the :class:`~hsgeo.io.lp_lines.LpStrip` that ``hsgeo lp-observations`` and ``hsgeo
orthomosaic`` take, so that a front end reads either format through one call;
:func:`read_line_strips` reads a command's LINES (one times file per ENVI cube) into memory.

**No-data.** A value equal to the header's ``data ignore value`` becomes NaN (the values are
float32 in both results); ``info["ignore_value"]`` keeps the header's value.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["NETCDF_SUFFIXES", "open_line_strip", "read_line_cube", "read_line_strips"]

#: Suffixes read as hsgeo's NetCDF lines; every other name is read as an ENVI cube.
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf")


class _Window:
    """The memory map behind an object that is not an ndarray: Dask then reads it a chunk at a
    time when computed (given an ndarray, even a memmap, ``from_array`` copies it whole into
    the graph: 4.7 s and the cube's size in memory for 800 MB, measured).
    """

    def __init__(self, arr):
        self._arr, self.shape, self.dtype, self.ndim = arr, arr.shape, arr.dtype, arr.ndim

    def __getitem__(self, key):
        return np.array(self._arr[key])


def _lazy_float32(cube, lines_per_chunk: int):
    """The cube ``(line, sample, band)`` as a Dask array of float32, no-data → NaN."""
    import dask.array as da

    st = cube.data_path.stat()
    name = f"envi-{cube.data_path.resolve()}-{st.st_size}-{st.st_mtime_ns}"
    arr = da.from_array(
        _Window(cube.lsb), chunks=(int(lines_per_chunk), -1, -1), name=name, asarray=True
    )
    out = arr.astype(np.float32)
    if cube.ignore_value is not None:  # compared in float64: exact for every stored type
        out = da.where(arr == np.float64(cube.ignore_value), np.float32(np.nan), out)
    return out


def _x_start(cube) -> int:
    """``col0`` of an ENVI cube: its header's ``x start`` − 1 (ENVI's 1-based image coordinate
    of the first sample: a cube holding columns of a wider line), 0 without it.
    """
    v = cube.header.get("x start")
    if v is None:
        return 0
    try:
        x = float(v.strip().strip("{}"))
    except ValueError:
        x = float("nan")
    if not (np.isfinite(x) and x == int(x) and x >= 1):
        raise InputError(
            f"ENVI header {str(cube.header_path)!r}: x start = {v!r} must be a whole number "
            "≥ 1 (the 1-based column of the first sample in the full line)"
        )
    return int(x) - 1


def read_line_cube(path, times=None, *, lines_per_chunk: int = 256):
    """Read recorded lines (ENVI cube, or hsgeo's NetCDF lines by suffix), lazily.

    Parameters
    ----------
    path : str or Path
        An ENVI cube (binary file, ``.hdr`` or bare name; :func:`hsgeo.io.envi_read.find_envi`)
        or a NetCDF file of :mod:`hsgeo.io.lp_lines` (suffix in :data:`NETCDF_SUFFIXES`).
    times : str, Path or array_like, optional
        For an ENVI cube: the times file (one time per line; plain numbers or a CSV with a
        ``t_s`` column) or the times; default the header's start time and line period
        (:func:`hsgeo.io.envi_read.line_times`). Not allowed for NetCDF lines (their ``t_s``).
    lines_per_chunk : int
        Lines per Dask chunk.

    Returns
    -------
    cube : xarray.DataArray
        ``(line, sample, band)`` float32 backed by Dask over a memory map (nothing read yet),
        no-data as NaN; coordinates ``t_s(line)``, ``sample(sample)`` (0-based column),
        ``wavelength_nm(band)`` and ``fwhm_nm(band)`` (NaN when the file has none).
    info : dict
        ``format`` ("envi" or "netcdf"), ``data_path``, ``header_path`` (ENVI), ``header``
        (ENVI entries), ``ignore_value``, ``interleave``, ``col0``, ``strip_id``,
        ``n_px_full``. An ENVI cube's ``col0`` is its header's ``x start`` − 1 (ENVI's 1-based
        column of the first sample; 0 without it), its ``n_px_full`` the samples without
        ``x start`` (the cube is the full line), None with it (the full line not said).

    Raises
    ------
    InputError
        As :func:`hsgeo.io.envi_read.open_envi`, :func:`~hsgeo.io.envi_read.line_times` and
        :func:`hsgeo.io.lp_lines.open_lp_lines`.
    """
    import xarray as xr

    if int(lines_per_chunk) < 1:
        raise InputError(f"lines_per_chunk must be a positive integer, got {lines_per_chunk!r}")
    p = Path(path)
    if p.suffix.lower() in NETCDF_SUFFIXES:
        from hsgeo.io.lp_lines import open_lp_lines

        if times is not None:
            raise InputError(
                f"LP lines file {str(p)!r} carries its own line times (t_s); drop the times file"
            )
        strip = open_lp_lines(p, lines_per_chunk)
        data, t = strip.lines, strip.t_s
        wl, fw = strip.wavelengths_nm, None
        info = {
            "format": "netcdf",
            "data_path": p,
            "header_path": None,
            "header": {},
            "ignore_value": None,
            "interleave": None,
            "col0": strip.col0,
            "strip_id": strip.strip_id,
            "n_px_full": strip.n_px_full,
        }
    else:
        from hsgeo.io.envi_read import line_times, open_envi

        cube = open_envi(p)
        t = line_times(cube, times)
        data = _lazy_float32(cube, lines_per_chunk)
        wl, fw = cube.wavelength_nm, cube.fwhm_nm
        col0 = _x_start(cube)
        info = {
            "format": "envi",
            "data_path": cube.data_path,
            "header_path": cube.header_path,
            "header": cube.header,
            "ignore_value": cube.ignore_value,
            "interleave": cube.interleave,
            "col0": col0,
            "strip_id": cube.data_path.stem,
            "n_px_full": int(data.shape[1]) if "x start" not in cube.header else None,
        }
    n_b = int(data.shape[2])
    nan = np.full(n_b, np.nan)
    out = xr.DataArray(
        data,
        dims=("line", "sample", "band"),
        coords={
            "t_s": ("line", np.asarray(t, float)),
            "sample": np.arange(int(data.shape[1])),
            "wavelength_nm": ("band", nan if wl is None else np.asarray(wl, float)),
            "fwhm_nm": ("band", nan if fw is None else np.asarray(fw, float)),
        },
        name="lines",
    )
    return out, info


def open_line_strip(path, times=None, *, lines_per_chunk: int = 256):
    """Recorded lines of either format as an :class:`~hsgeo.io.lp_lines.LpStrip` (lazy).

    Parameters
    ----------
    path, times, lines_per_chunk
        As :func:`read_line_cube`.

    Returns
    -------
    LpStrip
        Its ``lines`` a Dask array; for an ENVI cube ``col0`` and ``n_px_full`` as
        :func:`read_line_cube` says (without ``x start``: 0 and the samples), ``strip_id`` the
        file's name without extension. A cube without wavelengths is refused
        (the LP strip needs one per band).
    """
    p = Path(path)
    if p.suffix.lower() in NETCDF_SUFFIXES and times is None:
        from hsgeo.io.lp_lines import open_lp_lines

        return open_lp_lines(p, lines_per_chunk)
    from hsgeo.io.lp_lines import LpStrip

    cube, info = read_line_cube(p, times, lines_per_chunk=lines_per_chunk)
    wl = cube["wavelength_nm"].values
    if not np.all(np.isfinite(wl)):
        raise InputError(
            f"ENVI header {str(info['header_path'])!r} has no wavelength entry; add "
            "'wavelength = {...}' and 'wavelength units = Nanometers' (one per band)"
        )
    try:
        return LpStrip(
            lines=cube.data,
            t_s=cube["t_s"].values,
            col0=info["col0"],
            wavelengths_nm=wl,
            strip_id=info["strip_id"],
            n_px_full=info["n_px_full"],
        )
    except InputError as exc:
        raise InputError(f"ENVI file {str(info['data_path'])!r}: {exc}") from None


def read_line_strips(paths, line_times=None, *, option: str = "--line-times"):
    """A command's recorded lines, each file hsgeo's NetCDF or an ENVI cube, into memory.

    Parameters
    ----------
    paths : sequence of str or Path
        The files (:func:`read_line_cube`: NetCDF by suffix, any other name an ENVI cube).
    line_times : sequence of (str, Path or None), optional
        One times file per file of ``paths``, in their order (None: every ENVI cube's header
        start time and line period; NetCDF lines carry their own ``t_s``).
    option : str
        The command's option of the times files, for the messages.

    Returns
    -------
    list of LpStrip
        With numpy lines (float32, the ENVI ``data ignore value`` as NaN).

    Raises
    ------
    InputError
        A count of times files unlike the files', or as :func:`open_line_strip`.
    """
    paths = list(paths)
    times = [None] * len(paths) if line_times is None else list(line_times)
    if len(times) != len(paths):
        raise InputError(
            f"{option} is given {len(times)} time(s) for {len(paths)} line files; give one times "
            f"file per ENVI cube, in the order of the line files (or no {option}: the headers' "
            "start time and line period)"
        )
    out = []
    for p, t in zip(paths, times, strict=True):
        if Path(p).suffix.lower() in NETCDF_SUFFIXES and t is None:
            from hsgeo.io.lp_lines import read_lp_lines

            out.append(read_lp_lines(p))
            continue
        from dataclasses import replace

        strip = open_line_strip(p, t)
        out.append(replace(strip, lines=np.asarray(strip.lines.compute(), dtype=np.float32)))
    return out
