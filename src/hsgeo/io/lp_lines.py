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
=================  =========================  ==============================================

Column ``j`` of the file is column ``col0 + j`` of the full line, at ``x_px = col0 + j −
(n_px_full − 1) / 2`` px from the line centre (:mod:`hsgeo.conventions`: pixel-centre origin,
x along the line); the full line's width ``n_px_full`` belongs to the camera, not to the file.

Example (a user's own strip)::

    import numpy as np, xarray as xr
    ds = xr.Dataset(
        {"lines": (("line", "column", "band"), dn.astype("float32")),
         "t_s": ("line", t_s), "wavelength_nm": ("band", [450.0, 527.0])},
        attrs={"col0": 0, "strip_id": "strip_07"},
    )
    ds.to_netcdf("strip_07.nc", engine="h5netcdf")
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_outputs

__all__ = ["LpStrip", "read_lp_lines", "write_lp_lines"]

_DIMS = ("line", "column", "band")


@dataclass(frozen=True)
class LpStrip:
    """The LP image lines of one strip.

    Parameters
    ----------
    lines : (n_lines, n_cols, n_bands) ndarray, float32, DN
        Recorded values; row ``i`` is the line exposed at ``t_s[i]``.
    t_s : (n_lines,) ndarray, s
        Exposure time of each line (the navigation's time scale), strictly increasing.
    col0 : int
        Index of the first stored column in the full line.
    wavelengths_nm : (n_bands,) ndarray, nm
        Centre wavelength of each band.
    strip_id : str
        Name of the strip.

    Raises
    ------
    InputError
        On wrong shapes, non-finite or non-increasing times, a negative ``col0`` or an empty
        ``strip_id``.
    """

    lines: np.ndarray
    t_s: np.ndarray
    col0: int
    wavelengths_nm: np.ndarray
    strip_id: str

    def __post_init__(self):
        who = f"LP strip {self.strip_id!r}"
        lines = np.asarray(self.lines)
        if lines.ndim != 3 or min(lines.shape) < 1:
            raise InputError(
                f"{who}: lines must be (n_lines, n_cols, n_bands) with none empty, got "
                f"shape {lines.shape}"
            )
        lines = lines.astype(np.float32, copy=False)
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

    def x_px(self, n_px_full: int) -> np.ndarray:
        """``(n_cols,)`` x of each stored column, px from the centre of a full line of
        ``n_px_full`` pixels (pixel-centre origin).
        """
        return self.col0 + np.arange(self.n_cols) - (n_px_full - 1) / 2


def write_lp_lines(path, strip: LpStrip, *, overwrite: bool = False):
    """Write one strip in the format of the module docstring (NetCDF-4, h5netcdf).

    Parameters
    ----------
    path : str or Path
        The output file (``.nc``); written atomically.
    strip : LpStrip
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
    ds["lines"].attrs.update(units="DN", long_name="recorded value")
    ds["t_s"].attrs.update(units="s", long_name="exposure time of the line")
    ds["wavelength_nm"].attrs.update(units="nm")
    with atomic_path(p) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return p


def read_lp_lines(path) -> LpStrip:
    """Read one strip written in the format of the module docstring.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    LpStrip

    Raises
    ------
    InputError
        The file is missing or not NetCDF, a variable or attribute is missing, ``lines`` has
        other dimensions, or the times do not increase strictly (the message names the file).
    """
    from hsgeo.io.lines import open_netcdf

    ds = open_netcdf(
        path,
        "lines",
        "LP lines ",
        "the recorded values must be a variable 'lines' with dimensions (line, column, band)",
    )
    name = f"LP lines file {str(path)!r}"
    try:
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
        col0 = np.asarray(ds.attrs["col0"]).item()
        if not isinstance(col0, (int, np.integer)) and not (
            isinstance(col0, float) and col0.is_integer()
        ):
            raise InputError(f"{name}: attribute col0 = {col0!r} must be an integer")
        sid = ds.attrs["strip_id"]
        sid = sid.decode() if isinstance(sid, bytes) else str(sid)
        try:
            strip = LpStrip(
                lines=np.asarray(da.values, dtype=np.float32),
                t_s=np.asarray(ds["t_s"].values, dtype=np.float64),
                col0=int(col0),
                wavelengths_nm=np.asarray(ds["wavelength_nm"].values, dtype=np.float64),
                strip_id=sid,
            )
        except InputError as exc:
            raise InputError(f"{name}: {exc}") from None
    finally:
        ds.close()
    return strip
