"""``hsgeo orthorectify`` of a flight near Sydney on a geodetic navigation (an SBET, WGS 84):
the local frame from the data, the output in the UTM zone of its centre (EPSG:32756), a DSM
GeoTIFF read through hsgeo.io.read_terrain; every pixel's ground position computed with pyproj
alone (PROJ's topocentric frame at the aircraft, the ray met with the ellipsoidal height of the
ground); bad inputs → one line, exit 2."""

import json

import numpy as np
import pytest
from test_geodetic_geolocation import _sbet

from hsgeo.cli import main
from hsgeo.io import write_lines
from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy
from hsgeo.sensors import as_sensor
from hsgeo.sensors.line import CalibratedLine
from hsgeo.trajectory import Trajectory

LAT0, LON0 = -33.9, 151.2
H_GROUND_M = 30.0  # the ground: ellipsoidal height (WGS 84)
RATE_HZ = 50.0  # the navigation's and the lines' rate
GSD_M = 0.4  # ≈ the ground pixel spacing along (0.4 m) and across (0.34 m) track
CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1
ZETA_PX = np.arange(200.0, 800.0, 4.0)
SENSOR_TOML = (
    "[sensor]\nmodel = 'calibrated'\nzeta0_px = 486.8\nc_px = 3539.0\n"
    "K = [1.459, -0.1636, 0.00526]\n"
)


def _flight(n=160):
    """A 64 m line north-east-bound at 20 m/s, 300 m above the ground, rolling and pitching."""
    from pyproj import Geod

    g = Geod(ellps="WGS84")
    s = (np.arange(n) - n / 2) * 20.0 / RATE_HZ
    lon, lat, back = (np.asarray(v) for v in g.fwd([LON0] * n, [LAT0] * n, [60.0] * n, s))
    az = (back + 180.0) % 360.0
    i = np.arange(n)
    rph = np.column_stack([1.5 * np.sin(i / 9.0), 0.8 * np.cos(i / 13.0), az + 2.0])
    h = H_GROUND_M + 300.0 + 0.5 * np.sin(i / 21.0)
    t = 300000.0 + i / RATE_HZ
    return t, lat, lon, h, rph


def _ground_truth(fl, k):
    """Longitude, latitude of every pixel of the lines at records ``k``, with pyproj alone."""
    from pyproj import Transformer

    t, lat, lon, h, rph = fl
    still = Trajectory(np.array([0.0, 1.0]), np.zeros((2, 3)), np.zeros((2, 3)))
    _, d0 = as_sensor(CAL).rays(ZETA_PX, np.zeros(ZETA_PX.size), still)
    body = d0 @ still.R_map_from_body(np.array([0.0]))[0]  # (R^T d) row-wise: the body rays
    out = np.empty((k.size, ZETA_PX.size, 2))
    for j, kk in enumerate(k):
        topo = Transformer.from_pipeline(
            "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
            "+step +proj=cart +ellps=WGS84 +step +proj=topocentric "
            f"+lat_0={float(lat[kk])!r} +lon_0={float(lon[kk])!r} +h_0={float(h[kk])!r} "
            "+ellps=WGS84"
        )
        v = body @ (R_ENU_FROM_NED @ R_from_rpy(*np.radians(rph[kk]))).T  # ENU at the aircraft
        s = (h[kk] - H_GROUND_M) / -v[:, 2]
        for _ in range(6):  # along the ray to the ellipsoidal height of the ground
            p = s[:, None] * v
            glon, glat, gh = topo.transform(*p.T, direction="INVERSE")
            s = s - (np.asarray(gh) - H_GROUND_M) / v[:, 2]
        assert np.max(np.abs(np.asarray(gh) - H_GROUND_M)) < 1e-4
        out[j] = np.column_stack([glon, glat])
    return out


def _dsm(path, crs="EPSG:32756"):
    """The flat ground as a GeoTIFF in UTM 56S (a 2D CRS: heights of unknown datum), 10 m."""
    import rasterio
    from pyproj import Transformer
    from rasterio.transform import from_origin

    x0, y0 = Transformer.from_crs(4979, 32756, always_xy=True).transform(LON0, LAT0)
    transform = from_origin(round(x0) - 1000.0, round(y0) + 1000.0, 10.0, 10.0)
    z = np.full((200, 200), H_GROUND_M, np.float32)
    with rasterio.open(path, "w", driver="GTiff", width=200, height=200, count=1,
                       dtype="float32", crs=crs, transform=transform) as dst:  # fmt: skip
        dst.write(z, 1)
    return path


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    """SBET, lines (band 0, 1: each pixel's own UTM x, y from pyproj, less a reference), DSM,
    sensor; and the reference."""
    from pyproj import Transformer

    d = tmp_path_factory.mktemp("geodetic")
    fl = _flight()
    _sbet(d / "nav.out", *fl)
    k = np.arange(20, fl[0].size - 20)
    ll = _ground_truth(fl, k)
    x, y = Transformer.from_crs(4979, 32756, always_xy=True).transform(ll[..., 0], ll[..., 1])
    ref = (round(float(np.mean(x))), round(float(np.mean(y))))
    rad = np.stack([np.asarray(x) - ref[0], np.asarray(y) - ref[1]])  # float32: metres, mm
    write_lines(d / "lines.nc", rad, ZETA_PX, t0_s=float(fl[0][k[0]]), line_rate_hz=RATE_HZ)
    (d / "sensor.toml").write_text(SENSOR_TOML)
    _dsm(d / "dsm.tif")
    argv = ["orthorectify", str(d / "lines.nc"), "--trajectory", str(d / "nav.out")]
    argv += ["--sensor", str(d / "sensor.toml"), "--dsm", str(d / "dsm.tif")]
    argv += ["--resolution", str(GSD_M), "--quiet"]
    return d, argv, ref


def _geodetic_csv(d):
    """The flight's navigation as a geodetic CSV (GPS seconds of week, '# crs: EPSG:4979')."""
    t, lat, lon, h, rph = _flight()
    rows = ["# crs: EPSG:4979", "gps_sow_s,lat_deg,lon_deg,h_m,roll_deg,pitch_deg,heading_deg"]
    for k in range(t.size):
        v = (t[k], lat[k], lon[k], h[k], rph[k, 0], rph[k, 1], rph[k, 2] % 360.0)
        rows.append(",".join(repr(float(x)) for x in v))
    (d / "nav.csv").write_text("\n".join(rows) + "\n")
    return d / "nav.csv"


@pytest.mark.parametrize("nav", ["sbet", "csv"])
def test_sydney_flight_lands_in_utm_56s_where_pyproj_puts_it(flight, capsys, nav):
    import rioxarray

    d, argv, ref = flight
    argv = list(argv)
    if nav == "sbet":
        argv += ["--nav-crs", "EPSG:4979", "--gps-week", "2345"]
    else:  # the CRS from the file's '# crs:' line
        argv[argv.index("--trajectory") + 1] = str(_geodetic_csv(d))
    o = d / f"o_{nav}.tif"
    rc = main([*argv, "--vertical", "ellipsoidal", "--json", "-o", str(o)])
    assert rc == 0, capsys.readouterr().err
    out = json.loads(capsys.readouterr().out)
    assert out["crs"] == "EPSG:32756" and "WGS 84" in out["navigation"]
    m = rioxarray.open_rasterio(o).astype(float)
    assert m.rio.crs.to_epsg() == 32756
    X, Y = np.meshgrid(m["x"].values, m["y"].values)
    ok = np.isfinite(m.values[0])
    assert ok.sum() > 5000
    dx = m.values[0][ok] + ref[0] - X[ok]  # where the pixel landed less where pyproj puts it
    dy = m.values[1][ok] + ref[1] - Y[ok]
    # nearest neighbour: each cell holds a pixel within the radius of influence; the offsets
    # average out to the geolocation error, which must stay under 0.25 GSD
    e = np.hypot(dx, dy)
    assert e.max() <= m.attrs["radius_of_influence_m"] < 1.0, e.max()
    bias = np.hypot(np.mean(dx), np.mean(dy))
    assert bias < 0.25 * GSD_M and np.median(e) < 0.25, (bias, np.median(e))


def test_etrs89_navigation_outside_europe_maps_to_the_given_crs(flight, capsys):
    """ETRS89 has no UTM zone at Sydney: the navigation is read into the frame of --crs."""
    d, argv, _ = flight
    nav = _geodetic_csv(d)
    etrs = d / "nav_etrs89.csv"
    etrs.write_text(nav.read_text().replace("EPSG:4979", "EPSG:4937"))
    argv = list(argv)
    argv[argv.index("--trajectory") + 1] = str(etrs)
    o = d / "o_etrs89.tif"
    rc = main([*argv, "--vertical", "ellipsoidal", "--crs", "EPSG:32756", "--json", "-o", str(o)])
    assert rc == 0, capsys.readouterr().out
    assert json.loads(capsys.readouterr().out)["crs"] == "EPSG:32756"


@pytest.mark.parametrize(
    "extra, expect",
    [
        (["--vertical", "ellipsoidal"], "--nav-crs"),  # an SBET names no datum
        (["--nav-crs", "EPSG:4979"], "--vertical"),  # the DSM's 2D CRS: heights unknown
        (["--nav-crs", "4979", "--vertical", "ellipsoidal", "--site=-33.9,151.2"], "--site"),
    ],
)
def test_bad_input_one_line_exit_2(flight, capsys, extra, expect):
    d, argv, _ = flight
    out = d / "bad.tif"
    assert main([*argv, *extra, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert expect in err and "\n" not in err and "Traceback" not in err, err
    assert not out.exists()


def _truncated_sbet(d):
    p = d / "cut.out"
    p.write_bytes((d / "nav.out").read_bytes()[:-20])  # the last record cut short
    return ["--trajectory", str(p), "--nav-crs", "EPSG:4979", "--vertical", "ellipsoidal"]


def _void_under_the_line(d):
    import rasterio

    p = d / "void.tif"
    with rasterio.open(d / "dsm.tif") as src:
        z, profile = src.read(1), src.profile
    z[90:110, 90:110] = -9999.0  # ±100 m about the line's centre
    profile["nodata"] = -9999.0
    with rasterio.open(p, "w", **profile) as dst:
        dst.write(z, 1)
    return ["--dsm", str(p), "--nav-crs", "EPSG:4979", "--vertical", "ellipsoidal"]


def _geodetic_csv_cut(d):
    p = d / "cut.csv"
    rows = _geodetic_csv(d).read_text().splitlines()
    rows[40] = ",".join(rows[40].split(",")[:4])  # a record without its attitude
    p.write_text("\n".join(rows) + "\n")
    return ["--trajectory", str(p), "--vertical", "ellipsoidal"]


@pytest.mark.parametrize(
    "make, expect",
    [
        (_truncated_sbet, r"cut\.out.*truncated"),
        (_void_under_the_line, r"void\.tif.*void.*(Fill|fill)"),
        (_geodetic_csv_cut, r"cut\.csv.*line"),
    ],
    ids=["truncated-sbet", "dsm-void-under-the-line", "geodetic-csv-short-row"],
)
def test_bad_new_formats_one_line_exit_2(flight, capsys, make, expect):
    """The new formats broken as users break them, through the command: a truncated SBET, a DSM
    with a void under the line, a geodetic CSV row cut short → one line naming the file and the
    problem, exit 2, no output."""
    import re

    d, argv, _ = flight
    argv = list(argv)
    extra = make(d)
    for opt in ("--trajectory", "--dsm"):  # replaced, not repeated
        if opt in extra:
            i = argv.index(opt)
            argv[i + 1] = extra[extra.index(opt) + 1]
            j = extra.index(opt)
            extra = extra[:j] + extra[j + 2 :]
    out = d / "bad_new.tif"
    assert main([*argv, *extra, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert re.search(expect, err) and "\n" not in err and "Traceback" not in err, err
    assert not out.exists()
