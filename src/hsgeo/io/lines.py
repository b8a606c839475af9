"""The flight-line format of ``hsgeo geocode``: recorded lines in NetCDF.

A file holds the variable ``radiance`` with dimensions ``(line, pixel)`` or ``(band, line,
pixel)``, the coordinate ``pixel`` (ζ in px, pixel-centre origin), optionally
``wavelength_nm(band)``, and the attributes ``t0_s`` (time of line 0, on the navigation's time
scale) and ``line_rate_hz``.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path

__all__ = ["read_lines", "write_lines", "line_file_kind", "read_band_widths", "open_netcdf"]


def open_netcdf(path, variable: str, what: str, remedy: str):
    """Open a NetCDF file that must hold ``variable``; one InputError otherwise.

    Parameters
    ----------
    path : str or Path
    variable : str or None
        The variable the format requires (None: any).
    what : str
        How the file is named in messages (``"DEM "``, or ``""``).
    remedy : str
        What the user should do when the variable is missing.

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    from hsgeo.io._files import check_input_file

    role = f"{what.strip() or 'LINES'} file"
    path = check_input_file(path, role)
    src = path
    if not path.is_file():  # a pipe (/dev/stdin, <(...)): read once, opened from memory
        import io

        from hsgeo.io._files import _read_bytes

        src = io.BytesIO(_read_bytes(path))
    if src is path:
        with open(path, "rb") as fh:
            magic = fh.read(8)
    else:
        magic = src.getvalue()[:8]
    # the engine from the file's signature, not xarray's guess (whose errors advise installing
    # packages): classic NetCDF 'CDF\x01|2|5' -> scipy, NetCDF-4 (HDF5) -> h5netcdf
    if magic[:3] == b"CDF":
        engine = "scipy"
    elif magic == b"\x89HDF\r\n\x1a\n":
        engine = "h5netcdf"
    else:
        raise InputError(
            f"{role} {str(path)!r} is not a NetCDF file (it does not start with a NetCDF or "
            "HDF5 signature); give the NetCDF file"
        )
    try:
        ds = xr.open_dataset(src, engine=engine)
    except ImportError:
        raise InputError(
            f"{role} {str(path)!r} is NetCDF-4 (HDF5): reading it needs the h5netcdf and h5py "
            "packages (pip install h5netcdf h5py), or save the file as NetCDF 3 classic"
        ) from None
    except TypeError:  # scipy's reader on a dimension of length 0 (read as 'unlimited')
        raise InputError(
            f"{role} {str(path)!r}: not a readable NetCDF file; the likely causes: a dimension "
            "of length 0 (no lines or no pixels recorded), a file cut short, or a file written "
            "by a program that does not follow NetCDF 3; give a file with data"
        ) from None
    except Exception as exc:  # noqa: BLE001 - any reader error becomes an InputError
        msg = " ".join(str(exc).split())[:200]
        raise InputError(
            f"{role} {str(path)!r}: not a readable NetCDF file ({msg}); give an intact file"
        ) from None
    if variable is not None and variable not in ds:
        raise InputError(
            f"{what}{path}: no variable {variable!r} (found {list(ds.data_vars)}); {remedy}"
        )
    return ds


def line_file_kind(path) -> str:
    """Which line format a NetCDF file holds: ``"radiance"`` (a recorded flight line, this
    module) or ``"lp"`` (LP line files, :mod:`hsgeo.io.lp_lines`), from its variables.
    """
    ds = open_netcdf(
        path,
        None,
        "",
        "a recorded flight line (variable radiance) or LP lines (variable lines) are needed",
    )
    try:
        names = set(ds.variables)
    finally:
        ds.close()
    if "radiance" in names:
        return "radiance"
    if "lines" in names:
        return "lp"
    raise InputError(
        f"LINES file {str(path)!r}: neither a recorded flight line (variable radiance(band, "
        "line, pixel)) nor LP lines (variable lines(line, column, band)); its variables: "
        f"{', '.join(sorted(names)) or 'none'}"
    )


def read_band_widths(path):
    """The full width at half maximum of each band, nm (``fwhm_nm(band)`` of a LINES file), or
    None when the file has none.
    """
    ds = open_netcdf(path, None, "", "")
    try:
        if "fwhm_nm" not in ds.variables:
            return None
        fw = np.asarray(ds["fwhm_nm"].values, dtype=float)
    finally:
        ds.close()
    if fw.ndim != 1 or not np.all(np.isfinite(fw) & (fw > 0)):
        raise InputError(
            f"LINES file {str(path)!r}: fwhm_nm must be one positive width per band (nm), got "
            f"{fw!r}"
        )
    return fw


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
    from hsgeo.validate import check_range

    ds = open_netcdf(path, "radiance", "", "the recorded values must be called radiance")
    name = f"LINES file {str(path)!r}"
    try:
        da = ds["radiance"]
        if "band" not in da.dims:
            da = da.expand_dims("band")
        if set(da.dims) != {"band", "line", "pixel"}:
            raise InputError(
                f"{name}: radiance must have dimensions (band,) line, pixel; got {da.dims}"
            )
        if "pixel" not in da.coords:
            raise InputError(
                f"{name}: no coordinate 'pixel' (ζ of each column, px); add it: without it the "
                "columns' positions in the image are unknown"
            )
        attrs = {**ds.attrs, **da.attrs}
        values = {}
        for a, doc in (("t0_s", "time of line 0, s"), ("line_rate_hz", "line rate, Hz")):
            if a not in attrs:
                raise InputError(
                    f"{name}: attribute {a!r} missing ({doc}); add it to the file's global "
                    "attributes"
                )
            try:
                v = float(np.asarray(attrs[a]).item())
            except (TypeError, ValueError):
                v = None
            if v is None or not np.isfinite(v) or (a == "line_rate_hz" and not v > 0):
                need = "a positive number" if a == "line_rate_hz" else "a finite number"
                raise InputError(
                    f"{name}: attribute {a} = {attrs[a]!r} must be {need} ({doc}); correct it"
                )
            values[a] = v
        check_range(values["t0_s"], -1e10, 1e10, f"{name}: attribute t0_s")
        da = da.transpose("band", "line", "pixel")
        if da.sizes["line"] < 2 or da.sizes["pixel"] < 2:
            raise InputError(
                f"{name}: radiance has {da.sizes['line']} line(s) of {da.sizes['pixel']} "
                "pixel(s); an image needs at least 2 lines and 2 pixels"
            )
        zeta = np.asarray(da["pixel"].values, dtype=float)
        if not np.all(np.isfinite(zeta)):
            raise InputError(f"{name}: the coordinate pixel (ζ, px) has NaN or infinite values")
        check_range(zeta, -1e6, 1e6, f"{name}: coordinate pixel (ζ, px)")
        d = np.diff(zeta)
        if not (np.all(d > 0) or np.all(d < 0)):
            i = int(np.flatnonzero(~(d * np.sign(d[0]) > 0))[0])
            raise InputError(
                f"{name}: the coordinate pixel (ζ, px) must increase or decrease strictly; "
                f"columns {i} and {i + 1} have {zeta[i]:g} and {zeta[i + 1]:g}"
            )
        out = (da.load(), values["t0_s"], values["line_rate_hz"])
    finally:
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
