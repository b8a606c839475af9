"""The flight-line format of ``hsgeo geocode``: recorded lines in NetCDF.

A file holds the variable ``radiance`` with dimensions ``(line, pixel)`` or ``(band, line,
pixel)``, the coordinate ``pixel`` (ζ in px, pixel-centre origin), optionally
``wavelength_nm(band)``, and the attributes ``t0_s`` (time of line 0, on the navigation's time
scale) and ``line_rate_hz``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path

__all__ = ["read_lines", "write_lines"]


def open_netcdf(path, variable: str, what: str, remedy: str):
    """Open a NetCDF file that must hold ``variable``; one InputError otherwise.

    Parameters
    ----------
    path : str or Path
    variable : str
        The variable the format requires.
    what : str
        How the file is named in messages (``"DEM "``, or ``""``).
    remedy : str
        What the user should do when the variable is missing.

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    if not Path(path).is_file():
        raise InputError(f"{what}{path} not found; check the path")
    try:
        ds = xr.open_dataset(path)
    except (OSError, ValueError, ImportError) as exc:
        raise InputError(f"{what}{path}: not a readable NetCDF file: {exc}") from None
    if variable not in ds:
        raise InputError(
            f"{what}{path}: no variable {variable!r} (found {list(ds.data_vars)}); {remedy}"
        )
    return ds


def read_lines(path):
    """Read a recorded flight line (module docstring).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    radiance : xarray.DataArray
        ``(band, line, pixel)``, loaded into memory.
    t0_s : float
        Time of line 0 (s).
    line_rate_hz : float
    """
    ds = open_netcdf(path, "radiance", "", "the recorded values must be called radiance")
    da = ds["radiance"]
    if "band" not in da.dims:
        da = da.expand_dims("band")
    if set(da.dims) != {"band", "line", "pixel"}:
        raise InputError(
            f"{path}: radiance must have dimensions (band,) line, pixel; got {da.dims}"
        )
    for a in ("t0_s", "line_rate_hz"):
        if a not in ds.attrs and a not in da.attrs:
            raise InputError(
                f"{path}: attribute {a!r} missing (time of line 0, line rate); "
                "add it to the file's global attributes"
            )
    attrs = {**ds.attrs, **da.attrs}
    out = (
        da.transpose("band", "line", "pixel").load(),
        float(attrs["t0_s"]),
        float(attrs["line_rate_hz"]),
    )
    ds.close()
    return out


def write_lines(
    path, radiance, zeta_px, *, t0_s: float, line_rate_hz: float, wavelength_nm=None, inputs=()
):
    """Write a recorded flight line in the format :func:`read_lines` reads (NetCDF 3).

    Parameters
    ----------
    path : str or Path
    radiance : (line, pixel) or (band, line, pixel) array_like
        Stored as float32.
    zeta_px : (pixel,) array_like
        ζ of each column (px).
    t0_s, line_rate_hz : float
        Time of line 0 (s) and line rate (Hz).
    wavelength_nm : (band,) array_like, optional
    inputs : iterable of path, optional
        Files the command reads; writing over one raises :class:`~hsgeo.InputError`.

    Returns
    -------
    path
        ``path``, written atomically (temporary file, then :func:`os.replace`).
    """
    import xarray as xr

    r = np.asarray(radiance, dtype=np.float32)
    if r.ndim == 2:
        r = r[None]
    da = xr.DataArray(
        r,
        dims=("band", "line", "pixel"),
        coords={"pixel": np.asarray(zeta_px, float)},
        name="radiance",
    )
    if wavelength_nm is not None:
        da = da.assign_coords(wavelength_nm=("band", np.asarray(wavelength_nm, float)))
    ds = da.to_dataset()
    ds.attrs.update(t0_s=float(t0_s), line_rate_hz=float(line_rate_hz))
    with atomic_path(path, inputs) as tmp:
        ds.to_netcdf(tmp, engine="scipy")
    return path
