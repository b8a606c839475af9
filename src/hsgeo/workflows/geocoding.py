"""Orthorectification of a recorded flight line from a user's files (000, ``hsgeo geocode``).

Reads the recorded lines, the navigation and the sensor description, casts every pixel's ray
onto a plane or a DEM (:mod:`hsgeo.geocode`) and writes the orthoimage as NetCDF and, on
request, ENVI.
"""

from __future__ import annotations

from hsgeo.errors import InputError
from hsgeo.geocode import (
    DemTerrain,
    PlaneTerrain,
    geocode_image,
    orthorectify,
    read_lines,
    read_sensor_toml,
    to_map_files,
)

__all__ = ["geocode_files"]


def geocode_files(lines, trajectory, sensor, *, output, dem=None, height_m=None,
                  resolution_m=0.5, envi=None, progress=True):
    """Orthorectify a recorded flight line from files (see ``hsgeo geocode --help``)."""
    import xarray as xr

    from hsgeo.io.navigation import read_trajectory

    if (dem is None) == (height_m is None):
        raise InputError("give exactly one of --dem DEM.nc or --height H (a plane)")
    da, t0, rate = read_lines(lines)
    nav = read_trajectory(trajectory)
    geom, bs = read_sensor_toml(sensor)
    if dem is not None:
        ds = xr.open_dataset(dem)
        if "height" not in ds:
            raise InputError(f"{dem}: no variable 'height' (dimensions N, E in metres)")
        terrain = DemTerrain(ds["height"])
    else:
        terrain = PlaneTerrain(float(height_m))
    ground = geocode_image(nav, geom, da.sizes["line"], da["pixel"].values, t0_s=t0,
                           line_rate_hz=rate, terrain=terrain, boresight_rad=bs,
                           progress=progress)
    ortho = orthorectify(da.values, ground, resolution_m=resolution_m,
                         band_names=da["band"].values,
                         attrs={"source": str(lines), "sensor": str(sensor)})
    return ortho, to_map_files(ortho, output, envi)
