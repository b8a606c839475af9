"""Orthorectification of a recorded flight line from a user's files (000, ``hsgeo geocode``).

Reads the recorded lines, the navigation and the sensor description, casts every pixel's ray
onto a plane or a DEM (:mod:`hsgeo.geocode`) and writes the orthoimage as NetCDF and, on
request, ENVI.
"""

from __future__ import annotations

from hsgeo.errors import InputError
from hsgeo.geocode import DemTerrain, PlaneTerrain, geocode_image, orthorectify
from hsgeo.io import read_dem, read_lines, read_sensor_toml, refuse_inputs, to_map_files

__all__ = ["geocode_files"]


def geocode_files(lines, trajectory, sensor, *, output, dem=None, height_m=None,
                  resolution_m=0.5, envi=None, progress=True):
    """Orthorectify a recorded flight line from files (see ``hsgeo geocode --help``).

    The outputs are written atomically and never over one of the input files.
    """
    from hsgeo.navigation import Navigation

    if (dem is None) == (height_m is None):
        raise InputError("give exactly one of --dem DEM.nc or --height H (a plane)")
    inputs = (lines, trajectory, sensor, dem)
    for out in (output, envi):  # before the work, not after it
        if out is not None:
            refuse_inputs(out, inputs)
    da, t0, rate = read_lines(lines)
    nav = Navigation.read_csv(trajectory)
    geom, bs = read_sensor_toml(sensor)
    if dem is not None:
        terrain = DemTerrain(read_dem(dem))
    else:
        terrain = PlaneTerrain(float(height_m))
    ground = geocode_image(nav, geom, da.sizes["line"], da["pixel"].values, t0_s=t0,
                           line_rate_hz=rate, terrain=terrain, boresight_rad=bs,
                           progress=progress)
    ortho = orthorectify(da.values, ground, resolution_m=resolution_m,
                         band_names=da["band"].values,
                         attrs={"source": str(lines), "sensor": str(sensor)})
    return ortho, to_map_files(ortho, output, envi, inputs=inputs)
