"""GeoTIFFs with a CRS: the orthomosaic as a Cloud-Optimized GeoTIFF, and DSMs.

:func:`write_cog` writes a Dask-backed ``(band, y, x)`` DataArray (:func:`hsgeo.ortho.orthomosaic`)
tile by tile: batches of output tiles are computed (on whatever scheduler is active: threads,
or a ``dask.distributed`` client) and written by this process into a tiled GeoTIFF through
rasterio windows, so that at most a batch of tiles is in memory and no worker needs the file;
GDAL's COG driver (inside the rasterio wheel) then copies it into a Cloud-Optimized GeoTIFF
with overviews (streaming, block by block). CRS, transform, band descriptions (names) and each
band's wavelength and FWHM in GDAL's standard keys (:func:`_band_wavelength_tags`) go into the
file, which QGIS and GDAL open as it is.

Why not ``rioxarray``'s ``to_raster``: with Dask it writes from the workers through a lock on
one file, which a cluster of several machines cannot share; here the client writes.
"""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_input_file, check_outputs

__all__ = [
    "write_cog",
    "read_dsm",
    "write_geotiff",
    "check_dsm_bands",
    "GEOTIFF_FORMATS",
    "GDAL_CACHE_MB",
    "COG_COMPRESSION",
]

GEOTIFF_FORMATS = {".tif": "GeoTIFF", ".tiff": "GeoTIFF"}
#: GDAL's block cache while writing, MiB (its default, 5 % of the RAM, would grow with it).
GDAL_CACHE_MB = 64
#: The COG's compression: DEFLATE at level 1 with the floating-point predictor. On the bench's
#: 3-band float32 mosaic (1.2 M cells, bench/results/orthomosaic.json) the COG copy with its
#: overviews took 0.45 CPU-s at 10.3 MB, where DEFLATE level 6 (before) took 0.71 s at 9.5 MB
#: and Zstandard level 1 0.30 s at 10.3 MB: DEFLATE because every reader opens it unaided
#: (libtiff alone, older GDAL and ArcGIS, browser COG viewers), Zstandard not; the same values
#: (lossless) either way.
COG_COMPRESSION = {"COMPRESS": "DEFLATE", "LEVEL": 1, "PREDICTOR": "YES"}


def write_cog(
    da,
    path,
    *,
    overwrite: bool = False,
    inputs=(),
    option: str = "-o/--output",
    progress=None,
    batch_tiles: int = 4,
    overview_resampling: str = "AVERAGE",
) -> Path:
    """Write a ``(band, y, x)`` raster with a CRS as a Cloud-Optimized GeoTIFF, atomically.

    Parameters
    ----------
    da : xarray.DataArray
        ``(band, y, x)`` with a CRS and transform (``da.rio``), numpy- or Dask-backed;
        coordinate ``wavelength_nm`` (band) optional.
    path : str or Path
        ``.tif`` / ``.tiff``; an existing file is replaced only with ``overwrite=True``.
    inputs : iterable of path
        The files the command read: never overwritten.
    progress : callable, optional
        ``progress(done_tiles, total_tiles)`` after each batch.
    batch_tiles : int
        Tiles computed at once (memory: ``batch_tiles`` × one tile of all bands).

    Returns
    -------
    Path
    """
    import dask
    import dask.array as dsa
    import rasterio
    import rasterio.shutil
    from rasterio.windows import Window

    path = Path(path)
    inputs = [p for p in inputs if p is not None]
    check_outputs([(path, option, GEOTIFF_FORMATS)], inputs, overwrite=overwrite)
    if da.dims != ("band", "y", "x"):
        raise InputError(f"a map raster must have dimensions (band, y, x), got {da.dims}")
    crs, transform = da.rio.crs, da.rio.transform()
    if crs is None:
        raise InputError("the raster has no CRS: write one with da.rio.write_crs")
    data = (
        da.data
        if isinstance(da.data, dsa.Array)
        else dsa.from_array(np.asarray(da.values), chunks=(-1, 512, 512))
    )
    n_b, ny, nx = data.shape
    r_off = np.concatenate([[0], np.cumsum(data.chunks[1])])
    c_off = np.concatenate([[0], np.cumsum(data.chunks[2])])
    keys = [(i, j) for i in range(len(data.chunks[1])) for j in range(len(data.chunks[2]))]
    names = [str(b) for b in da["band"].values]
    wl = da["wavelength_nm"].values if "wavelength_nm" in da.coords else None
    fw = da["fwhm_nm"].values if "fwhm_nm" in da.coords else None
    fd, stage = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".stage.tif", dir=path.parent)
    os.close(fd)
    env = rasterio.Env(GDAL_CACHEMAX=GDAL_CACHE_MB * 2**20)  # GDAL's block cache: bounded
    try:
        env.__enter__()
        profile = dict(
            driver="GTiff",
            width=nx,
            height=ny,
            count=n_b,
            dtype="float32",
            crs=crs,
            transform=transform,
            nodata=np.nan,
            tiled=True,
            blockxsize=512,
            blockysize=512,
            BIGTIFF="IF_SAFER",
        )
        with rasterio.open(stage, "w", **profile) as dst:
            for k in range(0, len(keys), max(1, batch_tiles)):
                batch = keys[k : k + batch_tiles]
                arrays = dask.compute(*[data.blocks[:, i, j] for i, j in batch])
                for (i, j), a in zip(batch, arrays, strict=True):
                    w = Window(c_off[j], r_off[i], a.shape[2], a.shape[1])
                    dst.write(np.asarray(a, dtype=np.float32), window=w)
                if progress is not None:
                    progress(min(len(keys), k + batch_tiles), len(keys))
            for b in range(n_b):
                dst.set_band_description(b + 1, names[b])
                _band_wavelength_tags(dst, b + 1, wl, fw)
            dst.update_tags(**{str(k): str(v) for k, v in da.attrs.items()})
        with atomic_path(path, inputs) as tmp:
            rasterio.shutil.copy(
                stage,
                tmp,
                driver="COG",
                **COG_COMPRESSION,
                BLOCKSIZE=512,
                OVERVIEWS="AUTO",
                OVERVIEW_RESAMPLING=overview_resampling,
                BIGTIFF="IF_SAFER",
            )
    finally:
        env.__exit__(None, None, None)
        Path(stage).unlink(missing_ok=True)
    return path


def _band_wavelength_tags(dst, band: int, wl, fw) -> None:
    """A band's wavelength and FWHM in GDAL's standard keys: the ``IMAGERY`` domain's
    ``CENTRAL_WAVELENGTH_UM`` / ``FWHM_UM`` (GDAL RFC 100), and the ENVI-style band items
    ``wavelength`` / ``wavelength_units`` / ``fwhm`` (what GDAL's ENVI driver reports).
    """
    if wl is not None:
        w_nm = float(wl[band - 1])
        dst.update_tags(band, ns="IMAGERY", CENTRAL_WAVELENGTH_UM=f"{w_nm / 1e3:.9g}")
        dst.update_tags(band, wavelength=f"{w_nm:.9g}", wavelength_units="nm")
        dst.update_tags(band, wavelength_nm=f"{w_nm:.6g}")  # hsgeo's own key, as before
    if fw is not None:
        f_nm = float(fw[band - 1])
        dst.update_tags(band, ns="IMAGERY", FWHM_UM=f"{f_nm / 1e3:.9g}")
        dst.update_tags(band, fwhm=f"{f_nm:.9g}")


def write_geotiff(
    path, values, transform, epsg: int, *, overwrite: bool = False, inputs=(), nodata=None
) -> Path:
    """A single-band GeoTIFF (a DSM), atomically. ``values``: ``(rows, cols)``, north first."""
    import rasterio

    path = Path(path)
    check_outputs([(path, "output", GEOTIFF_FORMATS)], inputs, overwrite=overwrite)
    v = np.asarray(values, dtype=np.float32)
    with atomic_path(path, inputs) as tmp:
        with rasterio.open(
            tmp,
            "w",
            driver="GTiff",
            width=v.shape[1],
            height=v.shape[0],
            count=1,
            dtype="float32",
            crs=f"EPSG:{epsg}",
            transform=transform,
            nodata=nodata,
        ) as dst:
            dst.write(v, 1)
    return path


@contextmanager
def _no_georeference_warning():
    """Rasterio's NotGeoreferencedWarning silenced (a file without a CRS is refused in words)."""
    import warnings

    from rasterio.errors import NotGeoreferencedWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        yield


def check_dsm_bands(src, name: str) -> None:
    """A DSM is one band of heights (band 1 of a three-band raster was read as the
    heights, silently).
    """
    if src.count != 1:
        raise InputError(
            f"{name}: the raster has {src.count} bands; a DSM has one, the heights in metres "
            "(is it an image? extract the height band: gdal_translate -b N)"
        )


def read_dsm(path, option: str = "--dsm"):
    """A DSM GeoTIFF: heights (m, above the ellipsoid) and its grid.

    Returns
    -------
    height_m : (rows, cols) float ndarray
        North first; nodata cells are NaN.
    grid : hsgeo.mapgrid.MapGrid
    """
    import rasterio
    from rasterio.errors import RasterioIOError

    from hsgeo.mapgrid import MapGrid

    p = check_input_file(path, f"{option} DSM")
    try:
        with _no_georeference_warning(), rasterio.open(p) as src:  # refused below, in words
            if src.driver not in ("GTiff", "COG", "VRT"):
                raise InputError(
                    f"{option} {p}: not a GeoTIFF (GDAL reads it as {src.driver}); give the "
                    "DSM as a GeoTIFF (gdal_translate -of GTiff), or a NetCDF DEM as .nc"
                )
            if src.crs is None or src.crs.to_epsg() is None:
                raise InputError(
                    f"{option} {p}: the DSM has no CRS with an EPSG code (got {src.crs}); "
                    "assign one (gdal_edit.py -a_srs EPSG:25832)"
                )
            t = src.transform
            if t.b != 0 or t.d != 0 or t.a <= 0 or t.e >= 0 or not np.isclose(t.a, -t.e):
                raise InputError(
                    f"{option} {p}: the DSM must be north-up with square cells, got the "
                    f"transform {tuple(t)[:6]}; warp it (gdalwarp)"
                )
            check_dsm_bands(src, f"{option} {p}")
            z = src.read(1, masked=True).astype(float).filled(np.nan)
            z = z * src.scales[0] + src.offsets[0]  # a scaled-integer DSM: heights in metres
            grid = MapGrid(t.c, t.f, t.a, src.width, src.height, f"EPSG:{src.crs.to_epsg()}")
    except RasterioIOError as exc:
        raise InputError(f"{option} {p}: not a raster GDAL can read ({exc})") from None
    return z, grid
