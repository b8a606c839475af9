"""``hsgeo orthorectify`` on one recorded flight line (what ``hsgeo geocode`` did): the 000 line
scanner and the 002 camera file, NetCDF and ENVI outputs with a CRS GDAL reads, the in-memory
core the command runs."""

import numpy as np
import pytest
import xarray as xr

from hsgeo import InputError
from hsgeo.crs import SITE_AAS, LocalFrame
from hsgeo.geocode import PlaneTerrain
from hsgeo.io import write_lines
from hsgeo.io.navigation import write_trajectory
from hsgeo.ortho import Strip, ground_points
from hsgeo.sensors import as_sensor
from hsgeo.sensors.line import CalibratedLine
from hsgeo.trajectory import Trajectory
from hsgeo.workflows.orthorectify import OrthoInputs, OrthoOptions, orthorectify

CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1


def straight_nav(heading_deg=0.0, H=500.0, T=10.0, v=20.0):
    t = np.linspace(0, T, 401)
    h = np.deg2rad(heading_deg)
    EN = np.outer(v * t, [np.sin(h), np.cos(h)])
    rpy = np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.full(t.size, h)])
    return Trajectory(t, np.column_stack([EN, np.full(t.size, H)]), rpy)


def test_orthorectify_places_pixels_where_they_belong():
    """Every pixel's value is its own E and N: each cell of the local frame's grid holds
    values within the radius of influence of its own position (nearest neighbour)."""
    nav = straight_nav()
    zeta = np.arange(100.0, 900.0)
    t = np.arange(100) / 10.0
    sensor = as_sensor(CAL)
    g = ground_points(sensor, nav, t, zeta, PlaneTerrain(0.0))
    vals = np.stack([g[..., 0], g[..., 1]], axis=-1)
    line = OrthoInputs((Strip(sensor, nav, t, zeta, vals),), PlaneTerrain(0.0))
    da = orthorectify(line, OrthoOptions(resolution_m=0.5, crs=SITE_AAS.local_crs())).compute()
    X, Y = np.meshgrid(da["x"], da["y"])
    ok = np.isfinite(da.values[0])
    assert ok.mean() > 0.5
    # nearest neighbour: within half the largest pixel spacing (along track 2 m here)
    assert np.max(np.abs(da.values[0][ok] - X[ok])) < 1.5
    assert np.max(np.abs(da.values[1][ok] - Y[ok])) < 1.5


def _line_setup(tmp_path, n_lines: int, out="o.nc") -> tuple:
    """A straight north-bound line of ``n_lines`` lines whose every pixel records its own east
    coordinate, its navigation and the 000 calibrated sensor written to ``tmp_path``; the
    ``hsgeo orthorectify`` command line (height 3 m, local-frame CRS, quiet)."""
    nav = straight_nav()
    write_trajectory(tmp_path / "nav.csv", nav)
    zeta = np.arange(200.0, 800.0, 2.0)
    g = ground_points(as_sensor(CAL), nav, np.arange(n_lines) / 8.0, zeta, PlaneTerrain(3.0))
    write_lines(tmp_path / "lines.nc", g[..., 0], zeta, t0_s=0.0, line_rate_hz=8.0)
    (tmp_path / "sensor.toml").write_text(
        "[sensor]\nmodel = 'calibrated'\nzeta0_px = 486.8\nc_px = 3539.0\n"
        "K = [1.459, -0.1636, 0.00526]\n"
    )
    argv = ["orthorectify", str(tmp_path / "lines.nc"), "--trajectory", str(tmp_path / "nav.csv")]
    argv += ["--sensor", str(tmp_path / "sensor.toml"), "--height", "3", "--resolution", "0.5"]
    argv += ["--crs", SITE_AAS.local_crs(), "--quiet"]
    return argv, nav, zeta


def test_a_line_end_to_end_and_the_core_it_runs(tmp_path):
    from hsgeo.cli import main
    from hsgeo.io import read_envi, read_lines, read_scanning_sensor
    from hsgeo.workflows.orthorectify import line_strip

    argv, nav, zeta = _line_setup(tmp_path, n_lines=80)
    assert main([*argv, "-o", str(tmp_path / "o.nc")]) == 0
    assert main([*argv, "-o", str(tmp_path / "o.hdr")]) == 0
    ds = xr.open_dataset(tmp_path / "o.nc")
    X = np.broadcast_to(ds["x"].values, ds["radiance"].shape[1:])
    v = ds["radiance"].values[0]
    ok = np.isfinite(v)
    # nearest neighbour: a cell holds a pixel no farther than the radius of influence (about
    # half the diagonal of the 2.5 m × 0.28 m pixel spacing), and mostly much closer
    err = np.abs(v[ok] - X[ok])
    assert err.max() <= ds["radiance"].attrs["radius_of_influence_m"] < 2.5
    assert np.median(err) < 0.1
    data, hdr = read_envi(tmp_path / "o")
    assert data.shape == ds["radiance"].shape and hdr["map_info"][2] == 0.5
    np.testing.assert_array_equal(data, ds["radiance"].values)
    # the in-memory core the command runs: the same grid and values, no files
    da, t0, rate = read_lines(tmp_path / "lines.nc")
    strip, _ = line_strip(
        da, t0, rate, read_scanning_sensor(tmp_path / "sensor.toml"), nav, name="lines"
    )
    core = orthorectify(
        OrthoInputs((strip,), PlaneTerrain(3.0)),
        OrthoOptions(resolution_m=0.5, crs=SITE_AAS.local_crs()),
    ).compute()
    np.testing.assert_array_equal(core.values, ds["radiance"].values)
    bad = [*argv, "-o", str(tmp_path / "x.nc")]
    bad[bad.index("--sensor") + 1] = str(tmp_path / "missing.toml")
    assert main(bad) == 2
    assert not (tmp_path / "x.nc").exists()


def test_the_002_camera_file_on_a_line(tmp_path):
    """``--sensor camera.toml`` (the 002 camera file): the LINES pixel is x px from the line
    centre; the orthoimage of an image whose value is the pixel's own E (geocoded by the camera
    the file describes) holds each cell's E to within the radius of influence, and the file's
    c_band_mm / distortion / boresight are the camera's."""
    from hsgeo.cli import main
    from hsgeo.io import read_pushbroom_camera
    from hsgeo.sensors.pushbroom import PushbroomCamera

    nav = straight_nav()
    write_trajectory(tmp_path / "nav.csv", nav)
    (tmp_path / "camera.toml").write_text(
        "[camera]\nn_bands = 2\npixel_mm = 0.0065\nc_mm = 40.0\nc_band_mm = [36.0, 40.0]\n"
        "x0_mm = 0.01\ndistortion = [-4.0e-5, 3.0e-7, 2.5e-5, -3.0e-5]\n"
        "boresight_deg = [0.2, -0.1, 0.3]\nlever_arm_m = [0.1, 0.0, -0.2]\n"
    )
    cam = PushbroomCamera(
        (36.0, 40.0),
        0.0065,
        (-4.0e-5, 3.0e-7, 2.5e-5, -3.0e-5),
        0.01,
        0.0,
        tuple(np.deg2rad([0.2, -0.1, 0.3])),
        (0.1, 0.0, -0.2),
    )
    got = read_pushbroom_camera(tmp_path / "camera.toml")
    assert got.c_mm == cam.c_mm and got.distortion == cam.distortion
    np.testing.assert_allclose(got.beta, cam.beta, atol=1e-15)
    x = np.arange(-600.0, 600.0, 4.0)
    xy = np.column_stack([x, np.zeros_like(x)])
    g = ground_points(cam, nav, np.arange(80) / 8.0, xy, PlaneTerrain(3.0), band=1)
    write_lines(tmp_path / "lines.nc", g[..., 0], x, t0_s=0.0, line_rate_hz=8.0)
    args = ["orthorectify", str(tmp_path / "lines.nc"), "--trajectory", str(tmp_path / "nav.csv")]
    args += ["--sensor", str(tmp_path / "camera.toml"), "--height", "3", "--quiet"]
    args += ["--resolution", "0.5", "--crs", SITE_AAS.local_crs()]
    assert main(args + ["-o", str(tmp_path / "o.nc"), "--band", "1"]) == 0
    ds = xr.open_dataset(tmp_path / "o.nc")
    X = np.broadcast_to(ds["x"].values, ds["radiance"].shape[1:])
    v = ds["radiance"].values[0]
    ok = np.isfinite(v)
    assert ok.mean() > 0.5
    assert np.abs(v[ok] - X[ok]).max() <= ds["radiance"].attrs["radius_of_influence_m"]
    # band 0 (c 10 % shorter): the same pixels cover an 11 % wider swath
    assert main(args + ["-o", str(tmp_path / "b0.nc"), "--band", "0"]) == 0
    d0 = xr.open_dataset(tmp_path / "b0.nc")

    def swath_m(d):
        return np.ptp(d["x"].values[np.isfinite(d["radiance"].values[0]).any(axis=0)])

    np.testing.assert_allclose(swath_m(d0) / swath_m(ds), 40.0 / 36.0, rtol=0.02)
    assert main(args + ["-o", str(tmp_path / "x.nc"), "--band", "2"]) == 2


def test_the_outputs_carry_the_crs_asked_for(tmp_path):
    """``--site`` and ``--crs``: the NetCDF and the ENVI file carry that CRS (here the local
    frame's plane about the site); GDAL reads it from both, and a cell's x, y are its position
    in that CRS (pyproj: the ENU point of a cell centre has the same E, N)."""
    import rasterio
    from pyproj import CRS

    from hsgeo.cli import main
    from hsgeo.crs import lonlat_to_crs

    frame = LocalFrame(45.0, 13.9, 20.0)
    argv = _line_setup(tmp_path, n_lines=40)[0]
    argv[argv.index("--crs") + 1] = frame.local_crs()
    argv += ["--site", "45.0,13.9,20"]
    assert main([*argv, "-o", str(tmp_path / "o.nc")]) == 0
    assert main([*argv, "-o", str(tmp_path / "o.hdr")]) == 0
    ds = xr.open_dataset(tmp_path / "o.nc")
    corner = (float(ds["x"].values[0]) - 0.25, float(ds["y"].values[0]) + 0.25)
    for path in (f"netcdf:{tmp_path / 'o.nc'}:radiance", str(tmp_path / "o")):
        with rasterio.open(path) as src:
            assert CRS.from_wkt(src.crs.to_wkt()) == CRS.from_user_input(frame.local_crs())
            np.testing.assert_allclose((src.transform.c, src.transform.f), corner)
            assert (src.transform.a, src.transform.e) == (0.5, -0.5)
    E, N = float(ds["x"].values[3]), float(ds["y"].values[5])
    lon, lat, _ = frame.enu_to_lonlat(E, N, 3.0)
    np.testing.assert_allclose(lonlat_to_crs(frame.local_crs(), lon, lat), (E, N), atol=1e-3)


def test_terrain_is_one_of_dsm_or_height(tmp_path):
    from hsgeo.workflows.orthorectify import orthorectify_files

    _line_setup(tmp_path, n_lines=20)
    with pytest.raises(InputError, match="exactly one"):
        orthorectify_files(
            [tmp_path / "lines.nc"],
            tmp_path / "nav.csv",
            tmp_path / "sensor.toml",
            output=tmp_path / "y.nc",
        )
