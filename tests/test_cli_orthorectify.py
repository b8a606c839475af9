"""``hsgeo orthorectify``: LP line files (strips) -> COG / NetCDF / ENVI; the camera file read in
full; the mosaic rules; outputs GIS and spectral tools read without help; bad input -> one line,
exit 2."""

import json

import numpy as np
import pytest
from ortho_inputs import GSD_M, SITE_ARGS, squares_xy, write_ortho_inputs

from hsgeo.cli import main


def _argv(f, out, *extra, adjustment=True):
    argv = [
        "orthorectify",
        *map(str, f["lines"]),
        "--trajectory",
        str(f["nav"]),
        *SITE_ARGS,
        "--sensor",
        str(f["camera"]),
        "--dsm",
        str(f["dsm"]),
        "--resolution",
        "0.3",
        "-o",
        str(out),
    ]
    if adjustment and "adjustment" in f:
        argv += ["--adjustment", str(f["adjustment"])]
    return argv + list(extra)


@pytest.fixture(scope="module")
def adjusted(tmp_path_factory):
    d = tmp_path_factory.mktemp("ortho_adj")
    return d, write_ortho_inputs(d, adjusted=True)


def _square_errors(path):
    import rioxarray

    from hsgeo.measure.squares import square_centroids

    m = rioxarray.open_rasterio(path)
    m = m.assign_coords(band=[str(b) for b in m.attrs.get("long_name", m["band"].values)])
    xy, _ = square_centroids(m, squares_xy(), search_m=3.0)
    return np.hypot(*(xy - squares_xy()).T)


def test_adjustment_puts_the_squares_in_place(adjusted, capsys):
    """Lines rendered along the true trajectory, the navigation file lacking known node
    corrections (1.2 m E, -0.9 m N, ...): with --adjustment the squares lie within 1 GSD (RMS)
    of their positions, without it about 1.5 m off."""
    d, f = adjusted
    rc = main(_argv(f, d / "adj.tif", "--json", "--bands", "640,550,460"))
    assert rc == 0, capsys.readouterr().err
    out = json.loads(capsys.readouterr().out)
    assert out["crs"] == "EPSG:25832" and out["bands"] == ["640 nm", "550 nm", "460 nm"]
    assert out["adjusted"] and out["strips"] == ["s1", "s2"]
    assert out["line_pixels"] == 300  # the files' n_px_full attribute (io.lp_lines)
    err = _square_errors(d / "adj.tif")
    assert np.sqrt(np.mean(err**2)) < GSD_M
    assert main(_argv(f, d / "raw.tif", "--bands", "640,550,460", adjustment=False)) == 0
    raw = _square_errors(d / "raw.tif")
    assert np.all(raw > 1.0)


@pytest.mark.parametrize(
    "edit, expect",
    [
        ("exists", "exists"),
        ("band", "--bands 1200: no band"),
        ("dsm_small", "outside --dsm"),
        ("dsm_crs", "EPSG:32632"),
        ("scheduler", "--scheduler"),
        ("nav_short", "navigation"),
        ("line_pixels", "do not fit a line of 299 px (from --line-pixels)"),
    ],
)
def test_bad_input_one_line_exit_2(adjusted, tmp_path, capsys, monkeypatch, edit, expect):
    from ortho_inputs import dsm

    from hsgeo.io.geotiff import write_geotiff
    from hsgeo.io.navigation import read_trajectory, write_trajectory
    from hsgeo.trajectory import Trajectory

    _, f = adjusted
    f = dict(f)
    out = tmp_path / "m.tif"
    extra = []
    if edit == "exists":
        out.write_bytes(b"keep me")
    elif edit == "band":
        extra = ["--bands", "640,1200"]
    elif edit == "dsm_small":
        z, g = dsm(pad_m=40.0)
        f["dsm"] = write_geotiff(tmp_path / "small.tif", z, g.transform, 25832)
    elif edit == "dsm_crs":
        z, g = dsm()
        f["dsm"] = write_geotiff(tmp_path / "utm_wgs84.tif", z, g.transform, 32632)
    elif edit == "scheduler":
        monkeypatch.setattr("hsgeo.workflows.orthorectify.SCHEDULER_TIMEOUT_S", 1.0)
        extra = ["--scheduler", "tcp://127.0.0.1:9"]
    elif edit == "line_pixels":  # the option overrides the files' n_px_full (300)
        extra = ["--line-pixels", "299"]
    elif edit == "nav_short":
        nav = read_trajectory(f["nav"])
        keep = nav.t_s < nav.t_s[-1] / 2
        short = Trajectory(nav.t_s[keep], nav.xyz_m[keep], nav.roll_pitch_heading_rad[keep])
        f["nav"] = write_trajectory(tmp_path / "short.csv", short)
        f.pop("adjustment")
    rc = main(_argv(f, out, *extra))
    err = capsys.readouterr().err
    assert rc == 2
    assert len(err.strip().splitlines()) == 1, err
    assert expect in err, err
    assert "Traceback" not in err
    if edit == "exists":
        assert out.read_bytes() == b"keep me"
    else:
        assert not out.exists()


def test_overwrite_replaces(adjusted, tmp_path, capsys):
    _, f = adjusted
    out = tmp_path / "m.tif"
    out.write_bytes(b"old")
    assert main(_argv(f, out, "--overwrite", "--bands", "640")) == 0
    import rasterio

    with rasterio.open(out) as src:
        assert src.count == 1 and src.descriptions == ("640 nm",)


def test_a_failed_scheduler_leaves_no_default_client(adjusted, tmp_path, capsys):
    """A --scheduler that does not answer is refused, and the next mosaic in the same process
    is computed here (a failed Client made the default made every later compute wait on it)."""
    from distributed.client import _get_global_client

    _, f = adjusted
    assert main(_argv(f, tmp_path / "a.tif", "--scheduler", "nowhere", "--bands", "640")) == 2
    assert "--scheduler nowhere" in capsys.readouterr().err
    assert _get_global_client() is None
    assert main(_argv(f, tmp_path / "b.tif", "--bands", "640", "--resolution", "1")) == 0


@pytest.fixture(scope="module")
def full_camera(tmp_path_factory):
    d = tmp_path_factory.mktemp("ortho_full_camera")
    return d, write_ortho_inputs(d, full_camera_file=True)


def test_the_camera_file_is_read_in_full(full_camera, capsys):
    """Issue 36: lines rendered with a camera of 0.3° boresight, distortion and c per band;
    its camera file without --adjustment puts the squares within 1 GSD (RMS), while the camera
    that drops those keys (c = 40 mm, no distortion, no boresight: what `orthomosaic` made of
    the file) puts none of them within 1 m."""
    d, f = full_camera
    assert main(_argv(f, d / "full.tif", "--bands", "640,550,460")) == 0, capsys.readouterr()
    err = _square_errors(d / "full.tif")
    assert np.sqrt(np.mean(err**2)) < GSD_M, err
    bare = d / "bare.toml"
    bare.write_text("[camera]\nn_bands = 4\npixel_mm = 0.0065\nc_mm = 40.0\n")
    g = dict(f, camera=bare)
    assert main(_argv(g, d / "bare.tif", "--bands", "640,550,460")) == 0
    bare_err = _square_errors(d / "bare.tif")  # ≈ 9.8 m off: nothing, or not the square, in 3 m
    assert not np.any(bare_err < 1.0), bare_err


@pytest.fixture(scope="module")
def three_formats(full_camera):
    """The same strips written as COG, CF NetCDF and ENVI (all four bands, FWHM in the files)."""
    import xarray as xr

    d, f = full_camera
    lines = []
    for k, p in enumerate(f["lines"]):  # the LP files with a fwhm_nm(band) added
        ds = xr.load_dataset(p)
        ds["fwhm_nm"] = ("band", [10.0, 11.0, 12.0, 13.0])
        q = d / f"fw{k}.nc"
        ds.to_netcdf(q, engine="h5netcdf")
        lines.append(q)
    g = dict(f, lines=lines)
    out = {}
    for suffix in (".tif", ".nc", ".hdr"):
        out[suffix] = d / f"ortho{suffix}"
        assert main(_argv(g, out[suffix], "--resolution", "0.6", "--quiet")) == 0
    return out


@pytest.mark.parametrize("suffix", [".tif", ".nc", ".hdr"])
def test_gdal_reads_the_wavelengths_from_its_standard_keys(three_formats, suffix):
    import rasterio
    from ortho_inputs import WAVELENGTH_NM

    path = three_formats[suffix]
    if suffix == ".hdr":
        path = path.with_suffix("")  # GDAL opens the ENVI data file, its header beside it
    elif suffix == ".nc":
        path = f"NETCDF:{path}:radiance"
    with rasterio.open(path) as src:
        assert src.count == 4
        assert src.crs.to_epsg() == 25832
        for b, (w, fw) in enumerate(
            zip(WAVELENGTH_NM, (10.0, 11.0, 12.0, 13.0), strict=True), start=1
        ):
            img = src.tags(b, ns="IMAGERY")
            items = src.tags(b)
            if suffix == ".nc":  # the netCDF driver: the band's coordinate value, its units
                assert float(items["NETCDF_DIM_band"]) == pytest.approx(w)
                assert src.tags()["band#units"] == "nm"
                assert src.tags()["band#standard_name"] == "radiation_wavelength"
                continue
            assert float(img["CENTRAL_WAVELENGTH_UM"]) == pytest.approx(w / 1e3)
            assert float(img["FWHM_UM"]) == pytest.approx(fw / 1e3)
            assert float(items["wavelength"]) == pytest.approx(w)
            assert items["wavelength_units"].lower() in ("nm", "nanometers")


def test_the_netcdf_is_cf_and_rioxarray_reprojects_it(three_formats):
    """x/y with axis and standard_name, the CRS in a grid_mapping (full WKT), float32, the cube
    in (band, y, x), wavelengths and FWHM in nm; rioxarray finds x/y and the CRS by itself."""
    import rioxarray  # noqa: F401
    import xarray as xr
    from ortho_inputs import WAVELENGTH_NM
    from pyproj import CRS

    ds = xr.open_dataset(three_formats[".nc"], decode_coords="all")
    assert ds.attrs["Conventions"] == "CF-1.8"
    v = ds["radiance"]
    assert v.dims == ("band", "y", "x") and v.dtype == np.float32
    assert ds["x"].attrs["axis"] == "X" and ds["y"].attrs["axis"] == "Y"
    assert ds["x"].attrs["standard_name"] == "projection_x_coordinate"
    assert ds["x"].attrs["units"] == "m" and ds["y"].attrs["units"] == "m"
    gm = ds[v.encoding["grid_mapping"]]
    assert CRS.from_wkt(gm.attrs["crs_wkt"]) == CRS.from_epsg(25832)
    np.testing.assert_allclose(ds["band"].values, WAVELENGTH_NM)
    assert ds["band"].attrs["units"] == "nm"
    assert ds["band"].attrs["standard_name"] == "radiation_wavelength"
    np.testing.assert_allclose(ds["fwhm"].values, [10.0, 11.0, 12.0, 13.0])
    assert v.rio.crs.to_epsg() == 25832
    w = v.rio.reproject("EPSG:4326")
    assert w.rio.crs.to_epsg() == 4326 and np.isfinite(w.values).any()
