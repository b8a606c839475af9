"""Geocoding of a recorded flight line (000): orthorectification and GCP deviations.

:func:`geocode_files` (``hsgeo geocode``) reads the recorded lines, the navigation and the sensor
description, casts every pixel's ray onto a plane or a DEM (:mod:`hsgeo.geocode`) and writes the
orthoimage as NetCDF and, on request, ENVI. :func:`gcp_deviations` geocodes GCP observations
after a GCP calibration of the boresight (as PARGE does, 000 Tables 2–3).
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError
from hsgeo.geocode import (
    DemTerrain,
    LineGeometry,
    PlaneTerrain,
    calibrate_boresight,
    geocode_image,
    geocode_observations,
    orthorectify,
)
from hsgeo.io import read_dem, read_lines, read_sensor_toml, refuse_inputs, to_map_files

__all__ = ["geocode_files", "gcp_deviations"]


def geocode_files(
    lines,
    trajectory,
    sensor,
    *,
    output,
    dem=None,
    height_m=None,
    resolution_m=0.5,
    envi=None,
    progress=True,
):
    """Orthorectify a recorded flight line from files (see ``hsgeo geocode --help``).

    The outputs are written atomically and never over one of the input files.
    """
    from hsgeo.io.navigation import read_trajectory

    if (dem is None) == (height_m is None):
        raise InputError("give exactly one of --dem DEM.nc or --height H (a plane)")
    inputs = (lines, trajectory, sensor, dem)
    for out in (output, envi):  # before the work, not after it
        if out is not None:
            refuse_inputs(out, inputs)
    da, t0, rate = read_lines(lines)
    nav = read_trajectory(trajectory)
    geom, bs = read_sensor_toml(sensor)
    if dem is not None:
        terrain = DemTerrain(read_dem(dem))
    else:
        terrain = PlaneTerrain(float(height_m))
    ground = geocode_image(
        nav,
        geom,
        da.sizes["line"],
        da["pixel"].values,
        t0_s=t0,
        line_rate_hz=rate,
        terrain=terrain,
        boresight_rad=bs,
        progress=progress,
    )
    ortho = orthorectify(
        da.values,
        ground,
        resolution_m=resolution_m,
        band_names=da["band"].values,
        attrs={"source": str(lines), "sensor": str(sensor)},
    )
    return ortho, to_map_files(ortho, output, envi, inputs=inputs)


def gcp_deviations(
    nav,
    sensor: LineGeometry,
    line,
    zeta_px,
    gcp_enu_m,
    *,
    height_m: float,
    t0_s: float,
    line_rate_hz: float,
    sigma_m: float = 0.3,
):
    """GCP deviations (geocoded − surveyed) after a GCP calibration of the boresight.

    The boresight is calibrated on the GCPs (:func:`hsgeo.geocode.calibrate_boresight`, the
    "GCP-calibrated auxiliary data" of PARGE), then every GCP observation is geocoded onto the
    plane ``height_m`` with it.

    Parameters
    ----------
    nav : Trajectory
        The recorded navigation.
    sensor : LineGeometry
        The assumed sensor model (nominal or calibrated).
    line : (n,) array_like
        Measured (fractional) line of each GCP.
    zeta_px : (n,) array_like
        Measured pixel of each GCP, px.
    gcp_enu_m : (n, 3) array_like
        Surveyed GCP coordinates, E, N, U in m.
    height_m : float
        Height of the flat terrain, m.
    t0_s, line_rate_hz : float
        Time of line 0 (s) and the line rate (Hz).
    sigma_m : float
        A-priori σ of a GCP's horizontal position in the boresight calibration, m.

    Returns
    -------
    dev_EN_m : (n, 2) ndarray
        Geocoded minus surveyed E, N, m (000 Tables 2–3: Δy, Δx).
    result : AdjustmentResult
        The boresight calibration.
    """
    gcp_enu_m = np.asarray(gcp_enu_m, dtype=float)
    kw = {"t0_s": t0_s, "line_rate_hz": line_rate_hz}
    res = calibrate_boresight(
        nav, sensor, line, zeta_px, gcp_enu_m, height_m=height_m, sigma_m=sigma_m, **kw
    )
    X = geocode_observations(
        nav,
        sensor,
        line,
        zeta_px,
        terrain=PlaneTerrain(height_m),
        boresight_rad=res.value("boresight"),
        **kw,
    )
    return X[:, :2] - gcp_enu_m[:, :2], res
