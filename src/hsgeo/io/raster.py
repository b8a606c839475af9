"""Map rasters: an orthoimage as NetCDF and/or ENVI with map info."""

from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np

from hsgeo.io._files import atomic_path, refuse_inputs
from hsgeo.io.envi import write_envi
from hsgeo.io.lines import open_netcdf

__all__ = ["to_map_files", "read_dem", "MAP_FORMATS"]

#: The extensions of the orthoimage written by ``-o`` (NetCDF 3 through xarray's scipy engine,
#: the CRS in rioxarray's ``spatial_ref`` variable); ``--envi`` writes ENVI with map info and the
#: CRS as WKT, which GIS programs read. (The orthomosaic writes GeoTIFF: hsgeo.io.geotiff.)
MAP_FORMATS = {".nc": "NetCDF", ".nc4": "NetCDF", ".cdf": "NetCDF", ".netcdf": "NetCDF"}


def to_map_files(da, path_nc=None, path_envi=None, *, inputs=()) -> list:
    """Write an orthorectified raster as NetCDF 3 and/or ENVI BSQ with map info.

    NetCDF is written with xarray's scipy engine (no further dependency).

    Parameters
    ----------
    da : xarray.DataArray
        ``(band, N, E)`` from :func:`hsgeo.geocode.orthorectify` (attribute ``resolution_m``,
        cell-centre coordinates ``E``, ``N`` in m).
    path_nc, path_envi : str or Path, optional
        The NetCDF file and the ENVI data file (its header is ``path_envi + ".hdr"``).
    inputs : iterable of path, optional
        The files the command read: none of them is overwritten (:class:`~hsgeo.InputError`
        before anything is written).

    Returns
    -------
    list of path
        The paths written, each atomically (temporary file, then :func:`os.replace`).
    """
    inputs = [p for p in inputs if p is not None]
    for p in (path_nc, path_envi):
        if p is not None:
            refuse_inputs(p, inputs)
    if path_envi is not None:
        refuse_inputs(Path(str(path_envi) + ".hdr"), inputs)
    out = []
    with contextlib.ExitStack() as stack:  # all files or none: a failing ENVI removes the .nc
        if path_nc is not None:
            tmp = stack.enter_context(atomic_path(path_nc, inputs))
            da.to_dataset(name=da.name or "radiance").to_netcdf(tmp, engine="scipy")
            out.append(path_nc)
        if path_envi is not None:
            out += _write_map_envi(da, path_envi, inputs)
    return out


def _write_map_envi(da, path_envi, inputs) -> list:
    out = []
    if path_envi is not None:
        res = float(da.attrs["resolution_m"])
        E0 = float(da["E"].values[0]) - res / 2
        N0 = float(da["N"].values[0]) + res / 2
        out += list(
            write_envi(
                path_envi,
                da.values.astype(np.float32),
                map_info=(E0, N0, res, res),
                band_names=[str(b) for b in da["band"].values],
                description="hsgeo orthorectified line-scanner image",
                crs_wkt=_crs_wkt(da),
                inputs=inputs,
            )
        )
    return out


def _crs_wkt(da):
    """The raster's CRS as WKT (rioxarray's ``spatial_ref``, or the ``crs`` attribute), or None."""
    crs = da.rio.crs if hasattr(da, "rio") else None
    if crs is None and "crs" in da.attrs:
        from pyproj import CRS
        from pyproj.exceptions import CRSError

        try:
            crs = CRS.from_user_input(da.attrs["crs"])
        except CRSError:
            return None
    return None if crs is None else crs.to_wkt()


def read_dem(path):
    """A DEM for :class:`hsgeo.geocode.DemTerrain`: NetCDF with ``height(N, E)`` in metres.

    Returns
    -------
    xarray.DataArray
        The variable ``height``, loaded into memory.
    """
    from hsgeo.errors import InputError

    ds = open_netcdf(path, "height", "DEM ", "it needs height(N, E) in metres")
    h = ds["height"].load()
    ds.close()
    if set(h.dims) != {"N", "E"} or "N" not in h.coords or "E" not in h.coords:
        raise InputError(
            f"DEM file {str(path)!r}: height must have dimensions N, E with coordinates in "
            f"metres, got dimensions {h.dims}; rename them (northing N, easting E)"
        )
    if h.sizes["N"] < 2 or h.sizes["E"] < 2:
        raise InputError(f"DEM file {str(path)!r}: needs at least 2 x 2 cells, got {h.shape}")
    for c in ("N", "E"):
        v = np.asarray(h[c].values, dtype=float)
        step = np.diff(v)
        if not np.all(np.isfinite(v)):
            raise InputError(
                f"DEM file {str(path)!r}: the coordinate {c} has NaN or infinite values; give "
                "the cell centres in metres"
            )
        if not (np.all(step > 0) or np.all(step < 0)):
            i = int(np.flatnonzero(~(step * np.sign(step[0] or 1.0) > 0))[0])
            raise InputError(
                f"DEM file {str(path)!r}: the coordinate {c} is not strictly increasing or "
                f"decreasing (values {i + 1} and {i + 2}: {v[i]:.6g}, {v[i + 1]:.6g} m); give "
                "each grid row and column once, in order"
            )
    if not np.all(np.isfinite(h.values)):
        raise InputError(
            f"DEM file {str(path)!r}: height has {int(np.sum(~np.isfinite(h.values)))} NaN or "
            "infinite cell(s); fill them before geocoding"
        )
    return h
