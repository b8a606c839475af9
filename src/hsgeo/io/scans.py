"""The files of ``hsgeo asf``: georegistered scans (NetCDF) and the runway polygon (CSV).

**Georegistered scan** (NetCDF 3 or 4), one flight line of a whiskbroom scanner after
geocoding (:func:`hsgeo.workflows.asf.georegister`):

* ``reflectance(band, line, pixel)`` — reflectance (or radiance) of each sample; a 2-D
  ``(line, pixel)`` variable is one band;
* ``E_m(line, pixel)``, ``N_m(line, pixel)`` — the ground point of each sample in the map frame
  (east, north, metres), the same frame as the runway file;
* ``scan_angle_deg(pixel)`` — the scan angle of each column, degrees, positive to the right of
  the heading, strictly monotone.

**Runway** (CSV or Parquet, :func:`hsgeo.io.tables.read_table`): the corners of the runway
polygon in order, columns ``E_m, N_m`` (at least 3 rows).
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path
from hsgeo.io.lines import open_netcdf

__all__ = ["read_geoscan", "write_geoscan", "read_runway"]


def read_geoscan(path, role: str = "SCAN"):
    """Read a georegistered scan (module docstring).

    Returns
    -------
    values : (bands, lines, pixels) ndarray
    scan_angle_rad : (pixels,) ndarray
    E_m, N_m : (lines, pixels) ndarray
    """
    ds = open_netcdf(
        path, "reflectance", f"{role} ", "the sample values must be called reflectance"
    )
    name = f"{role} file {str(path)!r}"
    try:
        da = ds["reflectance"]
        if "band" not in da.dims:
            da = da.expand_dims("band")
        if set(da.dims) != {"band", "line", "pixel"}:
            raise InputError(
                f"{name}: reflectance must have dimensions (band,) line, pixel; got {da.dims}"
            )
        v = np.asarray(da.transpose("band", "line", "pixel").values, dtype=float)
        out = [v]
        if "scan_angle_deg" not in ds:
            raise InputError(
                f"{name}: no variable scan_angle_deg(pixel) (the scan angle of each column, "
                "degrees, positive to the right of the heading); add it"
            )
        a = np.asarray(ds["scan_angle_deg"].values, dtype=float)
        if a.shape != (v.shape[2],) or not np.all(np.isfinite(a)):
            raise InputError(
                f"{name}: scan_angle_deg must hold {v.shape[2]} finite values (one per pixel), "
                f"got shape {a.shape}"
            )
        d = np.diff(a)
        if not (np.all(d > 0) or np.all(d < 0)):
            raise InputError(f"{name}: scan_angle_deg must increase or decrease strictly")
        if np.abs(a).max() >= 90:
            raise InputError(f"{name}: scan_angle_deg must lie within ±90° (degrees, not px?)")
        out.append(np.deg2rad(a))
        for c in ("E_m", "N_m"):
            if c not in ds:
                raise InputError(
                    f"{name}: no variable {c}(line, pixel) (the ground point of each sample, "
                    "m): georegister the scan first (hsgeo.workflows.asf.georegister)"
                )
            x = np.asarray(ds[c].transpose("line", "pixel").values, dtype=float)
            if x.shape != v.shape[1:]:
                raise InputError(
                    f"{name}: {c} has shape {x.shape}, reflectance {v.shape[1:]} (line, pixel)"
                )
            if not np.all(np.isfinite(x)):
                raise InputError(f"{name}: {c} has NaN or infinite values; every sample needs "
                                 "a ground point")  # fmt: skip
            out.append(x)
        if v.shape[1] < 2 or v.shape[2] < 2:
            raise InputError(f"{name}: a scan needs at least 2 lines of 2 pixels")
    finally:
        ds.close()
    return tuple(out)


def write_geoscan(path, values, scan_angle_rad, E_m, N_m, *, inputs=()):
    """Write a georegistered scan in the format :func:`read_geoscan` reads (NetCDF 3)."""
    import xarray as xr

    v = np.asarray(values, dtype=np.float32)
    if v.ndim == 2:
        v = v[None]
    ds = xr.Dataset(
        {
            "reflectance": (("band", "line", "pixel"), v),
            "E_m": (("line", "pixel"), np.asarray(E_m, float)),
            "N_m": (("line", "pixel"), np.asarray(N_m, float)),
            "scan_angle_deg": (("pixel",), np.rad2deg(np.asarray(scan_angle_rad, float))),
        }
    )
    ds["E_m"].attrs["units"] = "m"
    ds["N_m"].attrs["units"] = "m"
    ds["scan_angle_deg"].attrs["units"] = "degree"
    with atomic_path(path, inputs) as tmp:
        ds.to_netcdf(tmp, engine="scipy")
    return path


def read_runway(path) -> np.ndarray:
    """The runway polygon ``(k, 2)`` (E, N), m, from a table with columns ``E_m, N_m``."""
    from hsgeo.io.tables import read_table

    t = read_table(path, ["E_m", "N_m"], what="RUNWAY")
    P = t[["E_m", "N_m"]].to_numpy(float)
    if P.shape[0] < 3:
        raise InputError(
            f"RUNWAY file {str(path)!r}: {P.shape[0]} corner(s); the runway polygon needs at "
            "least 3 corners (E_m, N_m), in order around it"
        )
    x, y = P[:, 0], P[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    if not area > 0:
        raise InputError(
            f"RUNWAY file {str(path)!r}: the corners enclose no area; give them in order "
            "around the runway"
        )
    return P
