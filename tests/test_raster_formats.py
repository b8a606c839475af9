"""The raster writers by suffix (hsgeo.io.raster.RASTER_FORMATS and RASTER_WRITERS): every
suffix has a writer, every writer's file is read back by GDAL (through rioxarray/rasterio) with
the same values, CRS and geotransform, and the command that writes rasters names every suffix
in its help. A format added to one registry and not the other, or a writer GDAL cannot read,
fails here (the recipe in CONTRIBUTING.md, "An output format").
"""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo.io.raster import RASTER_FORMATS, RASTER_WRITERS, envi_data_path, write_raster


def test_every_suffix_has_a_writer_and_a_name():
    assert set(RASTER_WRITERS) == set(RASTER_FORMATS)
    for suffix, name in RASTER_FORMATS.items():
        assert suffix.startswith(".") and suffix == suffix.lower() and name.strip(), suffix
        assert callable(RASTER_WRITERS[suffix])


def _raster():
    import rioxarray  # noqa: F401  (the .rio accessor)
    import xarray as xr
    from affine import Affine

    rng = np.random.default_rng(3)
    v = rng.normal(100.0, 10.0, (3, 7, 9)).astype(np.float32)
    v[1, 2, 3] = np.nan  # a cell no pixel reached
    x = 500_000.0 + 0.5 + np.arange(9)
    y = 6_000_000.0 - 0.5 - np.arange(7)
    da = xr.DataArray(
        v,
        dims=("band", "y", "x"),
        coords={
            "band": ["b1", "b2", "b3"],
            "y": y,
            "x": x,
            "wavelength_nm": ("band", [460.0, 550.0, 640.0]),
            "fwhm_nm": ("band", [10.0, 11.0, 12.0]),
        },
        name="radiance",
    )
    da = da.rio.write_crs("EPSG:32633")
    return da.rio.write_transform(Affine(1.0, 0.0, 500_000.0, 0.0, -1.0, 6_000_000.0))


@pytest.mark.parametrize("suffix", sorted(RASTER_FORMATS))
def test_every_writer_round_trips_through_gdal(suffix, tmp_path):
    import rasterio

    da = _raster()
    path = tmp_path / f"out{suffix}"
    written = write_raster(da, path)
    assert path in written and all(p.is_file() for p in written)
    gdal_path = envi_data_path(path) if suffix == ".hdr" else path
    if suffix == ".nc":
        gdal_path = f"netcdf:{path}:radiance"
    with rasterio.open(gdal_path) as src:
        assert src.count == 3 and (src.height, src.width) == (7, 9)
        assert src.crs.to_epsg() == 32633, suffix
        assert tuple(src.transform)[:6] == pytest.approx((1.0, 0.0, 500_000.0, 0.0, -1.0, 6e6))
        got = src.read()
    np.testing.assert_array_equal(got, da.values)  # NaN where NaN, every value exact (float32)


def test_the_orthorectify_help_names_every_suffix(capsys):
    from hsgeo.cli import main

    with pytest.raises(SystemExit):
        main(["orthorectify", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for suffix, name in RASTER_FORMATS.items():
        assert f"OUT{suffix}" in text, suffix
        assert " ".join(name.split()) in text, name


def test_the_cog_is_deflate_with_the_float_predictor_and_lossless(tmp_path):
    """The COG's compression (hsgeo.io.geotiff.COG_COMPRESSION): DEFLATE (every reader's) level 1
    with the floating-point predictor, every value as written, tiled 512 with overviews."""
    import rasterio

    from hsgeo.io.geotiff import COG_COMPRESSION

    rng = np.random.default_rng(5)
    da = _raster()
    big = np.repeat(np.repeat(da.values, 90, axis=1), 90, axis=2)  # 630 x 810: overviews
    big = big + rng.normal(0.0, 0.01, big.shape).astype(np.float32)
    res = (da.x.values[1] - da.x.values[0]) / 90
    da = (
        type(da)(big, dims=da.dims, coords={"band": da.band.values})
        .assign_coords(
            x=500_000.0 + res / 2 + res * np.arange(big.shape[2]),
            y=6_000_000.0 - res / 2 - res * np.arange(big.shape[1]),
        )
        .rio.write_crs("EPSG:32633")
    )
    path = tmp_path / "m.tif"
    write_raster(da, path)
    with rasterio.open(path) as src:
        assert COG_COMPRESSION["COMPRESS"] == "DEFLATE"
        assert src.compression.name.upper() == "DEFLATE"
        assert src.tags(ns="IMAGE_STRUCTURE").get("PREDICTOR") == "3"  # floating point
        assert src.block_shapes[0] == (512, 512) and src.overviews(1)
        np.testing.assert_array_equal(src.read(), big)
