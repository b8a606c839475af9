"""Map rasters: the one writer of orthoimages and mosaics (format by suffix), and DEMs (NetCDF).

:func:`write_raster` writes a ``(band, y, x)`` DataArray with a CRS (:func:`hsgeo.workflows.
orthorectify.orthorectify`, numpy- or Dask-backed) in the format its suffix names
(:data:`RASTER_FORMATS`):

* ``.tif`` / ``.tiff`` — Cloud-Optimized GeoTIFF (:func:`hsgeo.io.geotiff.write_cog`, tile by
  tile), each band's wavelength and FWHM in GDAL's standard keys: the ``IMAGERY`` metadata
  domain's ``CENTRAL_WAVELENGTH_UM`` / ``FWHM_UM`` and the ENVI-style band items
  ``wavelength`` / ``wavelength_units`` / ``fwhm`` that spectral tools read;
* ``.nc`` — CF-1.8 NetCDF-4 (h5netcdf): ``x``/``y`` with ``axis``, ``standard_name`` and units,
  the CRS in a ``grid_mapping`` variable (``spatial_ref``: CF grid-mapping attributes and the
  full WKT, written by rioxarray), float32 values, the cube in ``(band, y, x)``; the ``band``
  coordinate is each band's centre wavelength in nm (``standard_name = radiation_wavelength``;
  GDAL's netCDF driver reports it as the band's ``NETCDF_DIM_band``), ``fwhm(band)`` in nm and
  ``band_name(band)`` beside it; rioxarray and GDAL read it without help;
* ``.hdr`` — ENVI BSQ (the data file beside the header, without extension; written in blocks
  of rows) with ``map info``, the CRS as WKT, ``band names``, ``wavelength``, ``fwhm`` and
  ``wavelength units``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_outputs
from hsgeo.io.lines import open_netcdf

__all__ = [
    "write_raster",
    "read_dem",
    "raster_outputs",
    "RASTER_FORMATS",
    "RASTER_WRITERS",
    "raster_formats_text",
    "envi_data_path",
    "cf_dataset",
]

#: The formats :func:`write_raster` writes, by the output's suffix.
RASTER_FORMATS = {
    ".tif": "Cloud-Optimized GeoTIFF",
    ".tiff": "Cloud-Optimized GeoTIFF",
    ".nc": "NetCDF (CF-1.8)",
    ".hdr": "ENVI (header; the data file beside it has no extension)",
}
_ENVI = (".hdr",)


def raster_formats_text() -> str:
    """The formats of :data:`RASTER_FORMATS` in words, for a command's help
    (``.tif / .tiff: Cloud-Optimized GeoTIFF; .nc: NetCDF (CF-1.8); ...``).
    """
    by: dict[str, list[str]] = {}
    for suffix, name in RASTER_FORMATS.items():
        by.setdefault(name, []).append(suffix)
    return "; ".join(f"{' / '.join(sfx)}: {name}" for name, sfx in by.items())


def envi_data_path(path_hdr) -> Path:
    """The ENVI data file of the header ``path_hdr``: the same name without ``.hdr``."""
    p = Path(path_hdr)
    return p.with_name(p.name[: -len(p.suffix)])


def raster_outputs(path, formats=None, option: str = "-o/--output") -> list:
    """The files :func:`write_raster` makes for ``path``, as :func:`hsgeo.io._files.
    check_outputs` takes them (the ENVI data file beside its header included).
    """
    out = [(path, option, formats or RASTER_FORMATS)]
    if Path(path).suffix.lower() in _ENVI:
        out.append((envi_data_path(path), f"{option} (the ENVI data file of {str(path)!r})"))
    return out


def write_raster(
    da, path, *, overwrite: bool = False, inputs=(), option: str = "-o/--output", progress=None
) -> list:
    """Write a map raster in the format of its suffix (module docstring), atomically.

    Parameters
    ----------
    da : xarray.DataArray
        ``(band, y, x)`` with a CRS and transform (``da.rio``), numpy- or Dask-backed; band
        coordinates ``wavelength_nm`` and ``fwhm_nm`` (nm) optional, carried into the file.
    path : str or Path
        ``.tif`` / ``.tiff``, ``.nc`` or ``.hdr``; an existing file is replaced only with
        ``overwrite``.
    inputs : iterable of path
        The files the command read: never overwritten.
    progress : callable, optional
        ``progress(done, total)`` after each batch of tiles (COG) or row of tiles.

    Returns
    -------
    list of Path
        The files written.
    """
    inputs = [p for p in inputs if p is not None]
    check_outputs(raster_outputs(path, RASTER_FORMATS, option), inputs, overwrite=overwrite)
    if da.dims != ("band", "y", "x"):
        raise InputError(f"a map raster must have dimensions (band, y, x), got {da.dims}")
    if da.rio.crs is None:
        raise InputError("the raster has no CRS: write one with da.rio.write_crs")
    write = RASTER_WRITERS[Path(path).suffix.lower()]
    return write(da, Path(path), inputs, progress, option)


def _rows(da, progress):
    """The raster's rows of tiles, computed one after the other: ``(r0, r1, block)``."""
    import dask.array as dsa

    data = da.data if isinstance(da.data, dsa.Array) else dsa.from_array(np.asarray(da.values))
    edges = np.concatenate([[0], np.cumsum(data.chunks[1])])
    for i in range(len(data.chunks[1])):
        r0, r1 = int(edges[i]), int(edges[i + 1])
        yield r0, r1, np.asarray(data[:, r0:r1, :].compute(), dtype=np.float32)
        if progress is not None:
            progress(i + 1, len(data.chunks[1]))


def _band_values(da, key):
    return None if key not in da.coords else np.asarray(da[key].values, dtype=float)


def cf_dataset(da, values=None):
    """The CF-1.8 dataset of a map raster (module docstring), ``values`` its float32 data
    (default ``da``'s, computed).
    """
    import rioxarray  # noqa: F401  (the .rio accessor)
    import xarray as xr

    v = np.asarray(da.values if values is None else values, dtype=np.float32)
    n = v.shape[0]
    wl, fw = _band_values(da, "wavelength_nm"), _band_values(da, "fwhm_nm")
    if wl is not None:  # the band coordinate is the centre wavelength: GDAL's NETCDF_DIM_band
        band = (
            "band",
            wl,
            {"units": "nm", "standard_name": "radiation_wavelength", "long_name": "band centre"},
        )
    else:
        band = ("band", np.arange(1, n + 1, dtype=np.int32), {"long_name": "band number"})
    coords = {
        "band": band,
        "y": ("y", np.asarray(da["y"].values, float)),
        "x": ("x", np.asarray(da["x"].values, float)),
        "band_name": ("band", np.array([str(b) for b in da["band"].values], dtype=object)),
    }
    if fw is not None:
        coords["fwhm"] = (
            "band",
            fw,
            {"units": "nm", "long_name": "full width at half maximum of the band"},
        )
    attrs = {k: val for k, val in da.attrs.items() if k not in ("grid_mapping",)}
    out = xr.DataArray(
        v,
        dims=("band", "y", "x"),
        coords=coords,
        name=da.name or "radiance",
        attrs={"long_name": str(da.name or "radiance"), **attrs},
    )
    out = out.rio.write_crs(da.rio.crs).rio.write_transform(da.rio.transform())
    ds = out.to_dataset()
    ds = ds.rio.write_coordinate_system()
    name = out.name
    gm = ds[name].encoding.pop("grid_mapping", None) or "spatial_ref"
    ds[name].attrs["grid_mapping"] = gm  # an attribute, so that no encoding given drops it
    for c, name in (("x", "easting"), ("y", "northing")):
        ds[c].attrs.update(units="m", long_name=name)
    ds.attrs.update(
        Conventions="CF-1.8",
        title="hsgeo orthorectified image",
        source="hsgeo orthorectify",
    )
    return ds


def _write_cog(da, path, inputs, progress, option) -> list:
    """Cloud-Optimized GeoTIFF, tile by tile (:func:`hsgeo.io.geotiff.write_cog`)."""
    from hsgeo.io.geotiff import write_cog

    return [write_cog(da, path, overwrite=True, inputs=inputs, option=option, progress=progress)]


def _write_netcdf(da, path, inputs, progress, option) -> list:
    """CF-1.8 NetCDF-4 (h5netcdf), atomically."""
    v = np.empty(da.shape, dtype=np.float32)
    for r0, r1, block in _rows(da, progress):
        v[:, r0:r1, :] = block
    ds = cf_dataset(da, v)
    enc = {ds_name: {"_FillValue": None} for ds_name in ("x", "y", "band")}
    enc[da.name or "radiance"] = {"_FillValue": np.float32(np.nan), "dtype": "float32"}
    if "fwhm" in ds:
        enc["fwhm"] = {"_FillValue": None}
    with atomic_path(path, inputs) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf", encoding=enc)
    return [path]


def _write_envi(da, path_hdr, inputs, progress, option) -> list:
    """ENVI BSQ float32 in blocks of rows, with map info and the CRS (WKT)."""
    from hsgeo.io.envi import EnviWriter

    t = da.rio.transform()
    if t.b != 0 or t.d != 0:
        raise InputError("ENVI map info needs a north-up raster (no rotation)")
    names = [str(b) for b in da["band"].values]
    with EnviWriter(
        envi_data_path(path_hdr),
        da.shape,
        np.float32,
        map_info=(float(t.c), float(t.f), float(t.a), float(-t.e)),
        band_names=names,
        wavelength_nm=_band_values(da, "wavelength_nm"),
        fwhm_nm=_band_values(da, "fwhm_nm"),
        data_ignore_value=float("nan"),
        description="hsgeo orthorectified image",
        crs_wkt=da.rio.crs.to_wkt(),
        inputs=inputs,
    ) as w:
        for r0, r1, block in _rows(da, progress):
            w[r0:r1, :, :] = block.transpose(1, 2, 0)
    return [w.path, w.header_path]


#: The writer of each suffix of :data:`RASTER_FORMATS`: ``write(da, path, inputs, progress,
#: option) -> list of Path`` (the files written). A new format is one entry here and one in
#: :data:`RASTER_FORMATS` (CONTRIBUTING.md); tests/test_raster_formats.py reads every one back
#: with GDAL.
RASTER_WRITERS = {
    ".tif": _write_cog,
    ".tiff": _write_cog,
    ".nc": _write_netcdf,
    ".hdr": _write_envi,
}


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
