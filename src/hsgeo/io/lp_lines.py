"""LP image lines of one strip (002 §3.1): :class:`LpStrip` and its NetCDF file.

An **LP strip** is the stack of image lines one flight strip recorded, each line a separate
exposure with its own time (002 Fig. 2). The file format (NetCDF-4 through xarray and h5netcdf;
a NetCDF-3 classic file with the same content reads too), so that a user can write their own:

=================  =========================  ==============================================
name               dimensions / kind          meaning
=================  =========================  ==============================================
``lines``          ``(line, column, band)``   the recorded values (DN), float32 (any float or
                                              integer type reads)
``t_s``            ``(line,)``                exposure time of each line, s, on the time scale
                                              of the navigation file; strictly increasing
``wavelength_nm``  ``(band,)``                centre wavelength of each band, nm
``col0``           global attribute (int)     index of the first stored column in the full
                                              line (a file may store only some columns)
``strip_id``       global attribute (str)     the strip's name (unique within a campaign)
``n_px_full``      global attribute (int),    pixels of the camera's full line; optional
                   optional
=================  =========================  ==============================================

Column ``j`` of the file is column ``col0 + j`` of the full line, at ``x_px = col0 + j −
(n_px_full − 1) / 2`` px from the line centre (:mod:`hsgeo.conventions`: pixel-centre origin,
x along the line). **The full line's width** ``n_px_full``, one convention for every command
that reads these files (``hsgeo lp-observations``, ``hsgeo orthorectify``, see
:func:`full_line_px`): the command's ``--line-pixels`` option when given (it overrides the
files); else the file's ``n_px_full`` attribute; else :data:`DEFAULT_N_PX_FULL` = 1800 px, the
002 camera's (§4). :func:`write_lp_lines` writes the attribute when the strip carries it.

Example (a user's own strip)::

    import numpy as np, xarray as xr
    ds = xr.Dataset(
        {"lines": (("line", "column", "band"), dn.astype("float32")),
         "t_s": ("line", t_s), "wavelength_nm": ("band", [450.0, 527.0])},
        attrs={"col0": 0, "strip_id": "strip_07"},
    )
    ds.to_netcdf("strip_07.nc", engine="h5netcdf")

:func:`read_lp_lines` reads the lines into memory (numpy); :func:`open_lp_lines` opens them
lazily (a Dask array read ``lines_per_chunk`` lines at a time, for a strip larger than memory,
as the orthomosaic does); both check the file the same way and return an :class:`LpStrip`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_outputs

__all__ = [
    "DEFAULT_N_PX_FULL",
    "LpStrip",
    "full_line_px",
    "open_lp_lines",
    "read_lp_lines",
    "write_lp_lines",
]

#: Pixels of a full line when neither the command nor the file says (002 §4: 1800).
DEFAULT_N_PX_FULL = 1800

_DIMS = ("line", "column", "band")


@dataclass(frozen=True)
class LpStrip:
    """The LP image lines of one strip.

    Parameters
    ----------
    lines : (n_lines, n_cols, n_bands) ndarray or dask.array.Array, float32, DN
        Recorded values; row ``i`` is the line exposed at ``t_s[i]`` (a Dask array from
        :func:`open_lp_lines`: read when computed).
    t_s : (n_lines,) ndarray, s
        Exposure time of each line (the navigation's time scale), strictly increasing.
    col0 : int
        Index of the first stored column in the full line.
    wavelengths_nm : (n_bands,) ndarray, nm
        Centre wavelength of each band.
    strip_id : str
        Name of the strip.
    n_px_full : int, optional
        Pixels of the camera's full line, when the file says (module docstring).

    Raises
    ------
    InputError
        On wrong shapes, non-finite or non-increasing times, a negative ``col0``, an empty
        ``strip_id``, or stored columns beyond ``n_px_full``.
    """

    lines: np.ndarray
    t_s: np.ndarray
    col0: int
    wavelengths_nm: np.ndarray
    strip_id: str
    n_px_full: int | None = None

    def __post_init__(self):
        who = f"LP strip {self.strip_id!r}"
        lines = self.lines if _is_dask(self.lines) else np.asarray(self.lines)
        if lines.ndim != 3 or min(lines.shape) < 1:
            raise InputError(
                f"{who}: lines must be (n_lines, n_cols, n_bands) with none empty, got "
                f"shape {lines.shape}"
            )
        lines = (
            lines.astype(np.float32) if _is_dask(lines) else lines.astype(np.float32, copy=False)
        )
        t = np.asarray(self.t_s, dtype=np.float64)
        w = np.atleast_1d(np.asarray(self.wavelengths_nm, dtype=np.float64))
        if t.shape != (lines.shape[0],):
            raise InputError(f"{who}: t_s has shape {t.shape}, expected ({lines.shape[0]},)")
        if not np.all(np.isfinite(t)):
            raise InputError(f"{who}: t_s contains NaN or inf")
        if np.any(np.diff(t) <= 0):
            i = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise InputError(
                f"{who}: line times must increase strictly (lines {i} and {i + 1}: "
                f"{t[i]:.6f}, {t[i + 1]:.6f} s); sort the lines by time and drop duplicates"
            )
        if w.shape != (lines.shape[2],):
            raise InputError(
                f"{who}: wavelengths_nm has shape {w.shape}, expected ({lines.shape[2]},) "
                "(one per band)"
            )
        col0 = int(self.col0)
        if col0 != self.col0 or col0 < 0:
            raise InputError(f"{who}: col0 must be a non-negative integer, got {self.col0!r}")
        if not isinstance(self.strip_id, str) or not self.strip_id:
            raise InputError("an LP strip needs a non-empty strip_id (str)")
        n_full = self.n_px_full
        if n_full is not None:
            if int(n_full) != n_full or int(n_full) < col0 + lines.shape[1]:
                raise InputError(
                    f"{who}: n_px_full = {n_full!r} must be an integer of at least col0 + "
                    f"columns = {col0 + lines.shape[1]} (the stored columns within the full line)"
                )
            object.__setattr__(self, "n_px_full", int(n_full))
        object.__setattr__(self, "lines", lines)
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "wavelengths_nm", w)
        object.__setattr__(self, "col0", col0)

    @property
    def n_lines(self) -> int:
        return int(self.lines.shape[0])

    @property
    def n_cols(self) -> int:
        return int(self.lines.shape[1])

    @property
    def n_bands(self) -> int:
        return int(self.lines.shape[2])

    def x_px(self, n_px_full: int | None = None) -> np.ndarray:
        """``(n_cols,)`` x of each stored column, px from the centre of a full line of
        ``n_px_full`` pixels (pixel-centre origin; default: :func:`full_line_px` of this strip).
        """
        n = full_line_px([self]) if n_px_full is None else n_px_full
        return self.col0 + np.arange(self.n_cols) - (n - 1) / 2


def _is_dask(a) -> bool:
    return type(a).__module__.startswith("dask.")


def full_line_px(strips, override: int | None = None, option: str = "--line-pixels") -> int:
    """The full line's width for these strips (module docstring: the one convention).

    Parameters
    ----------
    strips : sequence of LpStrip
    override : int, optional
        The command's option (``--line-pixels``); it overrides the files' attribute.
    option : str
        The option's name, for the message.

    Returns
    -------
    int
        ``override``; else the strips' common ``n_px_full``; else :data:`DEFAULT_N_PX_FULL`.

    Raises
    ------
    InputError
        The files disagree, or a strip's columns do not fit the line.
    """
    named = {s.n_px_full for s in strips if s.n_px_full is not None}
    if override is None and len(named) > 1:
        raise InputError(
            f"the LP line files give different full-line widths (attribute n_px_full: "
            f"{sorted(named)} px): lines of one camera are needed, or give {option}"
        )
    n = int(override) if override is not None else (named.pop() if named else DEFAULT_N_PX_FULL)
    for s in strips:
        if s.col0 + s.n_cols > n:
            raise InputError(
                f"LP strip {s.strip_id!r}: columns {s.col0}…{s.col0 + s.n_cols - 1} do not fit "
                f"a line of {n} px ({'from ' + option if override is not None else 'n_px_full'}"
                f"); give the camera's full line with {option}"
            )
    return n


def write_lp_lines(path, strip: LpStrip, *, overwrite: bool = False):
    """Write one strip in the format of the module docstring (NetCDF-4, h5netcdf).

    Parameters
    ----------
    path : str or Path
        The output file (``.nc``); written atomically.
    strip : LpStrip
        Its lines may be a Dask array (written chunk by chunk).
    overwrite : bool
        Replace an existing file (otherwise :class:`~hsgeo.InputError`).

    Returns
    -------
    Path
    """
    import xarray as xr

    if not isinstance(strip, LpStrip):
        raise InputError(f"write_lp_lines needs an LpStrip, got {type(strip).__name__}")
    (p,) = check_outputs([(path, "LP lines file", {".nc": "NetCDF"})], overwrite=overwrite)
    ds = xr.Dataset(
        {
            "lines": (_DIMS, strip.lines),
            "t_s": ("line", strip.t_s),
            "wavelength_nm": ("band", strip.wavelengths_nm),
        },
        attrs={"col0": int(strip.col0), "strip_id": strip.strip_id},
    )
    if strip.n_px_full is not None:
        ds.attrs["n_px_full"] = int(strip.n_px_full)
    ds["lines"].attrs.update(units="DN", long_name="recorded value")
    ds["t_s"].attrs.update(units="s", long_name="exposure time of the line")
    ds["wavelength_nm"].attrs.update(units="nm")
    with atomic_path(p) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return p


def read_lp_lines(path) -> LpStrip:
    """Read one strip written in the format of the module docstring, into memory.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    LpStrip
        With numpy lines.

    Raises
    ------
    InputError
        The file is missing or not NetCDF, a variable or attribute is missing, ``lines`` has
        other dimensions, or the times neither increase nor decrease strictly (the message
        names the file). Lines stored in decreasing time are returned in increasing time.
    """
    return _read(path, None)


def open_lp_lines(path, lines_per_chunk: int = 256) -> LpStrip:
    """Open one strip lazily: as :func:`read_lp_lines`, its lines a Dask array.

    Parameters
    ----------
    path : str or Path
    lines_per_chunk : int
        Lines per Dask chunk (every column and band in one chunk).

    Returns
    -------
    LpStrip
        ``lines`` a ``dask.array.Array`` of ``(n_lines, n_cols, n_bands)`` float32, read from
        the file when computed (the file stays open until then).
    """
    if int(lines_per_chunk) < 1:
        raise InputError(f"lines_per_chunk must be a positive integer, got {lines_per_chunk!r}")
    return _read(path, int(lines_per_chunk))


def _read(path, lines_per_chunk):
    from hsgeo.io.lines import open_netcdf

    ds = open_netcdf(
        path,
        "lines",
        "LP lines ",
        "the recorded values must be a variable 'lines' with dimensions (line, column, band)",
    )
    try:
        strip = _strip_of(ds, f"LP lines file {str(path)!r}", lines_per_chunk)
    except BaseException:
        ds.close()
        raise
    if lines_per_chunk is None:
        ds.close()
    return strip


def _int_attr(ds, att, name):
    v = np.asarray(ds.attrs[att]).item()
    if not isinstance(v, (int, np.integer)) and not (isinstance(v, float) and v.is_integer()):
        raise InputError(f"{name}: attribute {att} = {v!r} must be an integer")
    return int(v)


def _strip_of(ds, name, lines_per_chunk):
    da = ds["lines"]
    if tuple(da.dims) != _DIMS:
        if set(da.dims) == set(_DIMS):
            da = da.transpose(*_DIMS)
        else:
            raise InputError(
                f"{name}: lines must have dimensions (line, column, band), got {da.dims}; "
                "rename the dimensions"
            )
    for var, dim in (("t_s", "line"), ("wavelength_nm", "band")):
        if var not in ds.variables:
            raise InputError(
                f"{name}: no variable {var!r} ({dim},); add it (module hsgeo.io.lp_lines)"
            )
        if tuple(ds[var].dims) != (dim,):
            raise InputError(f"{name}: {var} must have dimension ({dim},), got {ds[var].dims}")
    for att in ("col0", "strip_id"):
        if att not in ds.attrs:
            raise InputError(
                f"{name}: global attribute {att!r} missing; add it (module hsgeo.io.lp_lines)"
            )
    col0 = _int_attr(ds, "col0", name)
    n_full = _int_attr(ds, "n_px_full", name) if "n_px_full" in ds.attrs else None
    sid = ds.attrs["strip_id"]
    sid = sid.decode() if isinstance(sid, bytes) else str(sid)
    t_s = np.asarray(ds["t_s"].values, dtype=np.float64)
    if t_s.size > 1 and np.all(np.diff(t_s) < 0):
        # lines stored last first (once refused): each line keeps its own time
        da, t_s = da.isel(line=slice(None, None, -1)), t_s[::-1].copy()
    if lines_per_chunk is None:
        lines = np.asarray(da.values, dtype=np.float32)
    else:
        lines = da.chunk({"line": lines_per_chunk, "column": -1, "band": -1}).data
    try:
        return LpStrip(
            lines=lines,
            t_s=t_s,
            col0=col0,
            wavelengths_nm=np.asarray(ds["wavelength_nm"].values, dtype=np.float64),
            strip_id=sid,
            n_px_full=n_full,
        )
    except InputError as exc:
        raise InputError(f"{name}: {exc}") from None
