"""The files of ``hsgeo asf``: georegistered scans (NetCDF) and the runway polygon (CSV).

**Georegistered scan** (NetCDF 3 or 4), one flight line of a whiskbroom scanner after
geocoding (:func:`hsgeo.workflows.asf.georegister`):

* ``reflectance(band, line, pixel)`` — reflectance (or radiance) of each sample; a 2-D
  ``(line, pixel)`` variable is one band;
* ``E_m(line, pixel)``, ``N_m(line, pixel)`` — the ground point of each sample in the map frame
  (east, north, metres), the same frame as the runway file;
* ``scan_angle_deg(pixel)`` — the scan angle of each column, degrees, positive to the right of
  the heading, strictly monotone.

**Raw scan** (NetCDF): the flight-line format of :mod:`hsgeo.io.lines` —
``radiance(band, line, pixel)``, the coordinate ``pixel`` (the detector pixel ζ of each column)
and the attributes ``t0_s`` and ``line_rate_hz`` — georegistered by ``hsgeo asf`` itself with
the sensor file and the navigation (:func:`read_raw_scan`).

**Runway** (CSV or Parquet, :func:`hsgeo.io.tables.read_table`): the corners of the runway
polygon in order around it, columns ``E_m, N_m`` (at least 3 corners; a last row repeating the
first, as a closed ring is often written, is dropped).

**Panoramic sensor** (TOML, :func:`hsgeo.io.read_sensor`, model ``panoramic``)::

    [sensor]
    model = "panoramic"
    n_px = 716                 # pixels per scan line
    ifov_deg = 0.12            # angular pixel size, degrees
    active_fraction = 0.2389   # share of the line period the mirror sweeps the pixels
    boresight_deg = [0, 0, 0]  # roll, pitch, heading of R_body_from_sensor
    lever_arm_m = [0, 0, 0]    # sensor origin on the body (x forward, y right, z down), m
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path
from hsgeo.io.lines import open_netcdf

__all__ = [
    "read_geoscan",
    "write_geoscan",
    "read_raw_scan",
    "read_runway",
    "read_panoramic_sensor",
    "write_panoramic_sensor",
]


def read_geoscan(path, role: str = "SCAN"):
    """Read a georegistered scan (module docstring).

    Returns
    -------
    values : (bands, lines, pixels) ndarray
    scan_angle_rad : (pixels,) ndarray
    E_m, N_m : (lines, pixels) ndarray
    """
    ds = open_netcdf(
        path,
        "reflectance",
        f"{role} ",
        "the sample values of a georegistered scan must be called reflectance; a raw scan "
        "(radiance, t0_s, line_rate_hz) needs --sensor and --trajectory to be georegistered",
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
        _check_values(v, name, "reflectance")
        out = [v]
        if "scan_angle_deg" not in ds:
            raise InputError(
                f"{name}: no variable scan_angle_deg(pixel) (the scan angle of each column, "
                "degrees, positive to the right of the heading); add it"
            )
        if ds["scan_angle_deg"].dims != ("pixel",):
            raise InputError(
                f"{name}: scan_angle_deg must have the one dimension pixel; got "
                f"{ds['scan_angle_deg'].dims}"
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
            if set(ds[c].dims) != {"line", "pixel"}:
                raise InputError(
                    f"{name}: {c} must have dimensions (line, pixel), as reflectance; got "
                    f"{ds[c].dims}: rename its dimensions or write the scan again"
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


def _check_values(v, name: str, var: str) -> None:
    """Samples must be finite and not negative (a ratio of radiances)."""
    bad = ~np.isfinite(v)
    if bad.any():
        b, line, px = (int(i[0]) for i in np.nonzero(bad))
        raise InputError(
            f"{name}: {var} has {int(bad.sum())} NaN or infinite value(s) (first at band "
            f"{b}, line {line}, pixel {px}); every sample needs a value"
        )
    neg = v < 0
    if neg.any():
        b, line, px = (int(i[0]) for i in np.nonzero(neg))
        raise InputError(
            f"{name}: {var} has {int(neg.sum())} negative value(s) (smallest {v.min():.4g}, "
            f"first at band {b}, line {line}, pixel {px}); the ASF is a ratio of radiances: "
            "give radiances or reflectances ≥ 0 (a dark level subtracted twice, or an offset?)"
        )


def read_raw_scan(path, role: str = "SCAN"):
    """Read a raw scan of a whiskbroom scanner (the :mod:`hsgeo.io.lines` format).

    Returns
    -------
    values : (bands, lines, pixels) ndarray
    zeta_px : (pixels,) ndarray
    t0_s, line_rate_hz : float
    """
    from hsgeo.io.lines import read_lines

    try:
        da, t0_s, rate = read_lines(path)
    except InputError as e:
        raise InputError(f"{role} {e}") from None
    v = np.asarray(da.values, dtype=float)
    _check_values(v, f"{role} file {str(path)!r}", "radiance")
    return v, np.asarray(da["pixel"].values, float), t0_s, rate


def read_panoramic_sensor(path):
    """The scanner of ``hsgeo asf --sensor``: a sensor file of the panoramic model, read by
    :func:`hsgeo.io.read_sensor` (any other model is refused with the reason).
    """
    from hsgeo.io.sensor_file import read_sensor
    from hsgeo.sensors.panoramic import PanoramicScanner

    sensor = read_sensor(path)
    name = f"SENSOR file {str(path)!r}"
    if not isinstance(sensor, PanoramicScanner):
        raise InputError(
            f"{name} describes a {type(sensor).__name__}: the ASF from crossing flights is "
            'measured with a whiskbroom scanner; give a sensor file with model = "panoramic"'
        )
    if sensor.n_px * sensor.ifov_deg < 5.0:
        raise InputError(
            f"{name}: n_px × ifov_deg = {sensor.n_px * sensor.ifov_deg:.3g}°: a scan this narrow "
            "cannot give an ASF; is ifov_deg in radians instead of degrees?"
        )
    return sensor


def write_panoramic_sensor(path, sensor, *, inputs=()):
    """Write a panoramic scanner's sensor file (:func:`hsgeo.io.sensor_file.sensor_toml`)."""
    from hsgeo.io.sensor_file import sensor_toml
    from hsgeo.rotations import rpy_from_R

    values = {
        "n_px": int(sensor.n_px),
        "ifov_deg": float(sensor.ifov_deg),
        "active_fraction": float(sensor.active_fraction),
        "boresight_deg": [
            float(x) for x in np.rad2deg(rpy_from_R(sensor.mount.R_body_from_sensor))
        ],
        "lever_arm_m": [float(x) for x in sensor.mount.lever_arm_m],
    }
    with atomic_path(path, inputs) as tmp:
        tmp.write_text(sensor_toml("panoramic", values))
    return path


def read_runway(path) -> np.ndarray:
    """The runway polygon ``(k, 2)`` (E, N), m, from a table with columns ``E_m, N_m``.

    A last corner repeating the first (a closed ring) is dropped; corners not in order around
    the runway (two edges crossing) are refused.
    """
    from hsgeo.io.tables import read_table

    t = read_table(path, ["E_m", "N_m"], what="RUNWAY", unique_rows=False)
    P = t[["E_m", "N_m"]].to_numpy(float)
    if P.shape[0] >= 4 and np.array_equal(P[0], P[-1]):
        P = P[:-1]  # a closed ring: its last corner repeats the first
    for j in range(1, P.shape[0]):
        same = np.flatnonzero(np.all(P[:j] == P[j], axis=1))
        if same.size:
            csv = not str(path).lower().endswith((".parquet", ".pq"))
            where, k = ("line", 2) if csv else ("row", 1)
            raise InputError(
                f"RUNWAY file {str(path)!r}: {where} {j + k} repeats the corner of {where} "
                f"{same[0] + k} ({P[j, 0]:g}, {P[j, 1]:g}); give each corner once, in order "
                "around the runway"
            )
    if P.shape[0] < 3:
        raise InputError(
            f"RUNWAY file {str(path)!r}: {P.shape[0]} corner(s); the runway polygon needs at "
            "least 3 corners (E_m, N_m), in order around it"
        )
    crossing = _crossing_edges(P)
    if crossing is not None:
        i, j = crossing
        raise InputError(
            f"RUNWAY file {str(path)!r}: the polygon's edges from corner {i + 1} and from "
            f"corner {j + 1} (data rows {i + 1}–{(i + 1) % len(P) + 1} and "
            f"{j + 1}–{(j + 1) % len(P) + 1}) cross each other: the corners are not in order "
            "around the runway (two swapped?); list them in order around it"
        )
    x, y = P[:, 0], P[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    if not area > 0:
        raise InputError(
            f"RUNWAY file {str(path)!r}: the corners enclose no area; give them in order "
            "around the runway"
        )
    return P


def _crossing_edges(P):
    """The first pair of non-adjacent edges of a polygon that cross, or None."""
    n = len(P)

    def orient(a, b, c):
        return np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    for i in range(n):
        a, b = P[i], P[(i + 1) % n]
        for j in range(i + 2, n):
            if (j + 1) % n == i:
                continue
            c, d = P[j], P[(j + 1) % n]
            if orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0:
                return i, j
    return None
