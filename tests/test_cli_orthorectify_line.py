"""``hsgeo orthorectify`` on one recorded flight line (what ``hsgeo geocode`` did): the 000 line
scanner and the 002 camera file, NetCDF and ENVI outputs with a CRS GDAL reads, the in-memory
core the command runs."""

import numpy as np
import pytest
import xarray as xr
from ortho_inputs import SITE_ARGS

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
    da = orthorectify(
        line, OrthoOptions(resolution_m=0.5, crs=SITE_AAS.local_crs(), frame=SITE_AAS)
    ).compute()
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
    argv += ["--crs", SITE_AAS.local_crs(), *SITE_ARGS, "--quiet"]
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
        OrthoOptions(resolution_m=0.5, crs=SITE_AAS.local_crs(), frame=SITE_AAS),
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
    args += ["--resolution", "0.5", "--crs", SITE_AAS.local_crs(), *SITE_ARGS]
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

    frame = LocalFrame(45.0, 13.9, 20.0, datum_epsg=4937)  # ETRS89, as --nav-crs of SITE_ARGS
    argv = _line_setup(tmp_path, n_lines=40)[0]
    argv[argv.index("--crs") + 1] = frame.local_crs()
    argv[argv.index("--site") + 1] = "45.0,13.9,20"
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
    np.testing.assert_allclose(
        lonlat_to_crs(frame.local_crs(), lon, lat, frame.datum_epsg), (E, N), atol=1e-3
    )


def test_terrain_is_one_of_dsm_or_height(tmp_path):
    from hsgeo.workflows.orthorectify import orthorectify_files

    _line_setup(tmp_path, n_lines=20)
    with pytest.raises(InputError, match="exactly one"):
        orthorectify_files(
            [tmp_path / "lines.nc"],
            tmp_path / "nav.csv",
            tmp_path / "sensor.toml",
            output=tmp_path / "y.nc",
            site=(59.665, 10.775, 0.0),
        )


def test_a_local_enu_navigation_needs_its_site(tmp_path, capsys):
    """No site is a default (issue 38): a local-ENU navigation without ``--site`` is refused
    before any work, exit 2, naming the option; with ``--json`` the same line as JSON."""
    import json

    from hsgeo.cli import main

    argv = _line_setup(tmp_path, n_lines=20)[0]
    i = argv.index("--site")
    argv = argv[:i] + argv[i + 2 :]  # --site and its value out; --nav-crs stays (--site's datum)
    assert main([*argv, "-o", str(tmp_path / "o.nc")]) == 2
    err = capsys.readouterr().err
    assert "--site LAT,LON[,H] is needed" in err and "nav.csv" in err and "Traceback" not in err
    assert not (tmp_path / "o.nc").exists()
    assert main([*argv, "-o", str(tmp_path / "o.nc"), "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] is False and out["exit_status"] == 2 and "--site" in out["error"]


def test_a_local_enu_flight_in_sydney_lands_where_pyproj_puts_it(tmp_path):
    """``--site=-33.9,151.2`` (no --nav-crs: WGS 84): the output CRS is WGS 84 / UTM 56S
    (EPSG:32756, :func:`hsgeo.crs.default_output_crs` of the site, as a geodetic navigation's
    centre gets) and every cell holds the pixel whose ground point pyproj alone (topocentric
    about the site on WGS 84 → geographic → EPSG:32756) puts nearest to it."""
    from pyproj import CRS, Transformer
    from pyproj.enums import TransformDirection

    from hsgeo.cli import main

    argv, nav, zeta = _line_setup(tmp_path, n_lines=40)
    i = argv.index("--crs")
    argv = argv[:i] + argv[i + 2 :]  # the default output CRS
    i = argv.index("--site")
    argv[i : i + 2] = ["--site=-33.9,151.2"]  # a negative value: in the option's word
    i = argv.index("--nav-crs")
    argv = argv[:i] + argv[i + 2 :]  # the site's datum: WGS 84 by default
    assert main([*argv, "-o", str(tmp_path / "o.nc"), "--json"]) == 0
    ds = xr.open_dataset(tmp_path / "o.nc")
    assert CRS.from_wkt(ds["spatial_ref"].attrs["crs_wkt"]) == CRS.from_epsg(32756)
    # pyproj alone: the cell centres in EPSG:32756 -> WGS 84 -> the site's ENU
    to_ll = Transformer.from_crs(32756, 4979, always_xy=True)
    enu = Transformer.from_pipeline(
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=cart "
        "+ellps=WGS84 +step +proj=topocentric +lat_0=-33.9 +lon_0=151.2 +h_0=0 +ellps=WGS84"
    )
    X, Y = np.meshgrid(ds["x"].values, ds["y"].values)
    v = ds["radiance"].values[0]
    ok = np.isfinite(v)
    assert ok.sum() > 1000
    lon, lat, _ = to_ll.transform(X[ok], Y[ok], np.full(ok.sum(), 3.0))
    E, N, U = enu.transform(lon, lat, np.full(lon.size, 3.0))
    # each cell's value is the east coordinate of the pixel nearest to its centre (within the
    # radius of influence: half the diagonal of the 2.5 m × 0.28 m pixel spacing)
    err = np.abs(v[ok] - E)
    assert err.max() <= ds["radiance"].attrs["radius_of_influence_m"] < 2.5
    assert np.median(err) < 0.1
    # and the grid is where the ground points are: the line's first and last pixel of the
    # first line, by pyproj alone, inside the grid
    g = ground_points(as_sensor(CAL), nav, np.array([0.0]), zeta[[0, -1]], PlaneTerrain(3.0))
    lon, lat, _ = enu.transform(
        g[0, :, 0], g[0, :, 1], g[0, :, 2], direction=TransformDirection.INVERSE
    )
    x, y = Transformer.from_crs(4979, 32756, always_xy=True).transform(lon, lat)
    r = float(ds["radiance"].attrs["resolution_m"])
    assert ds["x"].values.min() - r < x.min() and x.max() < ds["x"].values.max() + r
    assert ds["y"].values.min() - r < y.min() and y.max() < ds["y"].values.max() + r
