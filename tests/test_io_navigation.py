"""The navigation file (hsgeo.io.navigation): format, round trip, old-format and error messages."""

import numpy as np
import pandas as pd
import pytest

from hsgeo import InputError
from hsgeo.io.navigation import NAV_COLUMNS, read_trajectory, write_trajectory
from hsgeo.trajectory import Trajectory


def _traj(n=11):
    t = np.linspace(0, 10, n)
    rng = np.random.default_rng(0)
    return Trajectory(
        t,
        np.column_stack([t, 2 * t, np.full(n, 100.0)]) + rng.normal(0, 1, (n, 3)),
        np.column_stack([0.01 * t, -0.02 * t, np.full(n, 3.1)]) + rng.normal(0, 0.1, (n, 3)),
    )


def test_round_trip_is_lossless_and_the_header_is_the_format(tmp_path):
    tr = _traj()
    p = write_trajectory(tmp_path / "nav.csv", tr)
    assert p.read_text().splitlines()[0] == ",".join(NAV_COLUMNS)
    back = read_trajectory(p)
    np.testing.assert_array_equal(back.t_s, tr.t_s)
    np.testing.assert_array_equal(back.xyz_m, tr.xyz_m)
    # degrees at the edge: deg2rad(rad2deg(x)) is x to the last bit or one ulp
    np.testing.assert_allclose(
        back.roll_pitch_heading_rad, tr.roll_pitch_heading_rad, rtol=2e-16, atol=0
    )
    # degrees in the file, to the last bit (%.17g)
    table = np.loadtxt(p, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 4:], np.rad2deg(tr.roll_pitch_heading_rad))
    assert not list(tmp_path.glob(".*tmp"))  # no temporary file left


def test_parquet_and_extra_columns(tmp_path):
    tr = _traj()
    df = pd.DataFrame(
        np.column_stack([tr.t_s, tr.xyz_m, np.rad2deg(tr.roll_pitch_heading_rad)]),
        columns=list(NAV_COLUMNS),
    )
    df["quality"] = 1
    df.to_parquet(tmp_path / "nav.parquet")
    back = read_trajectory(tmp_path / "nav.parquet")
    np.testing.assert_array_equal(back.xyz_m, tr.xyz_m)
    pos, _ = back.pose([2.5])
    np.testing.assert_allclose(pos, tr.pose([2.5])[0])


def test_never_overwrites_an_input(tmp_path):
    tr = _traj()
    src = write_trajectory(tmp_path / "in.csv", tr)
    before = src.read_bytes()
    with pytest.raises(InputError, match="is an input of the command and would be overwritten"):
        write_trajectory(tmp_path / "in.csv", tr, inputs=[src])
    assert src.read_bytes() == before


def test_old_pushbroom_format_gets_the_conversion(tmp_path):
    pd.DataFrame(
        np.zeros((3, 7)) + np.arange(3)[:, None],
        columns=["t_s", "E_m", "N_m", "H_m", "roll_rad", "pitch_rad", "yaw_rad"],
    ).to_csv(tmp_path / "old.csv", index=False)
    with pytest.raises(InputError) as e:
        read_trajectory(tmp_path / "old.csv")
    msg = str(e.value)
    for col in NAV_COLUMNS:
        assert col in msg
    assert "heading_deg = 90 - degrees(yaw_rad)" in msg
    assert "pitch_deg = -degrees(pitch_rad)" in msg


def test_errors_name_the_file_and_the_remedy(tmp_path):
    tr = _traj()
    p = write_trajectory(tmp_path / "nav.csv", tr)
    df = pd.read_csv(p)
    df.drop(columns="heading_deg").to_csv(tmp_path / "a.csv", index=False)
    with pytest.raises(InputError, match="heading_deg"):
        read_trajectory(tmp_path / "a.csv")
    d = df.copy()
    d.loc[3, "E_m"] = np.nan
    d.to_csv(tmp_path / "b.csv", index=False)
    with pytest.raises(InputError, match=r"line 5, column E_m"):
        read_trajectory(tmp_path / "b.csv")
    df.iloc[::-1].to_csv(tmp_path / "c.csv", index=False)
    with pytest.raises(InputError, match="c.csv.*increase strictly"):
        read_trajectory(tmp_path / "c.csv")
    d = df.astype({"U_m": object})
    d.loc[2, "U_m"] = "high"
    d.to_csv(tmp_path / "d.csv", index=False)
    with pytest.raises(InputError, match="column U_m: 'high' is not a number"):
        read_trajectory(tmp_path / "d.csv")
    with pytest.raises(InputError, match="missing.csv' not found"):
        read_trajectory(tmp_path / "missing.csv")
    (tmp_path / "e.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="not a readable"):
        read_trajectory(tmp_path / "e.parquet")


# ---- navigation as delivered: geodetic CSV, geocentric CSV, the Applanix SBET ----------------
def _flight(lat0=60.0, lon0=10.0, az_deg=90.0, length_m=30000.0, h_m=2000.0, n=601):
    """A straight 30 km line on the WGS 84 ellipsoid (pyproj.Geod), heading = the geodesic's
    azimuth + 2° of crab, small roll and pitch: (t, lat, lon, h, roll, pitch, heading) degrees."""
    from pyproj import Geod

    g = Geod(ellps="WGS84")
    s = np.linspace(-length_m / 2, length_m / 2, n)
    lon, lat, back = g.fwd(np.full(n, lon0), np.full(n, lat0), np.full(n, az_deg), s)
    az = (np.asarray(back) + 180.0) % 360.0
    t = 345600.0 + s / 60.0  # GPS seconds of week (Thursday), 60 m/s
    i = np.arange(n)
    roll = 1.5 * np.sin(i / 37.0)
    pitch = 0.8 * np.cos(i / 53.0)
    heading = az + 2.0 + 0.3 * np.sin(i / 29.0)
    h = h_m + 5.0 * np.sin(i / 71.0)
    return t, np.asarray(lat), np.asarray(lon), h, roll, pitch, heading


def _write_geodetic_csv(path, flight, crs="EPSG:4979", week=2400):
    t, lat, lon, h, roll, pitch, heading = flight
    table = np.column_stack([np.full(t.size, week), t, lat, lon, h, roll, pitch, heading])
    with open(path, "w") as f:
        if crs:
            f.write(f"# crs: {crs}\n")
        f.write("gps_week,gps_sow_s,lat_deg,lon_deg,h_m,roll_deg,pitch_deg,heading_deg\n")
        for row in table:
            f.write(f"{int(row[0])}," + ",".join(f"{v:.17g}" for v in row[1:]) + "\n")
    return path


def _write_sbet(path, flight, wander_rad=None):
    """An SBET by the documented layout, with the test's own struct code (an independent
    writer): 17 little-endian doubles; platform heading = true heading + wander angle."""
    import struct

    t, lat, lon, h, roll, pitch, heading = flight
    n = t.size
    if wander_rad is None:
        wander_rad = 0.4 + 0.002 * np.arange(n)
    with open(path, "wb") as f:
        for k in range(n):
            hd = np.radians(heading[k]) + wander_rad[k]
            f.write(
                struct.pack(
                    "<17d",
                    t[k], np.radians(lat[k]), np.radians(lon[k]), h[k],
                    55.0, -20.0, 0.1,
                    np.radians(roll[k]), np.radians(pitch[k]), hd, wander_rad[k],
                    0.01, 0.02, -9.81, 0.001, 0.002, 0.003,
                )
            )  # fmt: skip
    return path


def test_sbet_gives_the_trajectory_of_the_equivalent_csv(tmp_path):
    from hsgeo.io.navigation import read_navigation

    fl = _flight()
    a = read_navigation(_write_geodetic_csv(tmp_path / "nav.csv", fl))
    b = read_navigation(_write_sbet(tmp_path / "sbet_01.out", fl), crs="EPSG:4979", gps_week=2400)
    assert a.frame == b.frame
    assert a.frame.datum_epsg == 4979 and a.frame.map_epsg == 32632  # WGS 84 / UTM 32N
    assert a.time_scale == b.time_scale == "GPS seconds of week" and a.gps_week == 2400
    np.testing.assert_array_equal(a.trajectory.t_s, b.trajectory.t_s)
    np.testing.assert_allclose(b.trajectory.xyz_m, a.trajectory.xyz_m, atol=1e-3, rtol=0)
    dang = np.degrees(b.trajectory.roll_pitch_heading_rad - a.trajectory.roll_pitch_heading_rad)
    assert np.max(np.abs(dang)) < 1e-6
    # the frame is the centre of the line: positions ±15 km east-west, U the height minus the
    # Earth's curvature drop d² / 2R (R the prime-vertical radius at 60° N, 6394 km)
    E, N, U = a.trajectory.xyz_m.T
    assert abs(E.mean()) < 50 and np.ptp(E) > 29000 and abs(N).max() < 100
    assert abs(U[0] - (fl[3][0] - 15000**2 / (2 * 6.394e6))) < 0.2


def test_geocentric_csv_and_seconds_of_day(tmp_path):
    """X, Y, Z on EPSG:4978 give the trajectory of lat, lon, h on EPSG:4979; seconds of day
    continue past midnight."""
    from pyproj import Transformer

    from hsgeo.io.navigation import read_navigation

    fl = _flight(lat0=-33.9, lon0=151.2, az_deg=30.0)
    t, lat, lon, h, roll, pitch, heading = fl
    X, Y, Z = Transformer.from_crs(4979, 4978, always_xy=True).transform(lon, lat, h)
    sod = t % 86400.0  # the line passes midnight: 86150 s … 86399.9 s, then 0 s …
    assert sod.min() < 500 and sod.max() > 86000
    df = pd.DataFrame(
        dict(sod_s=sod, X_m=X, Y_m=Y, Z_m=Z, roll_deg=roll, pitch_deg=pitch, heading_deg=heading)
    )
    df.to_csv(tmp_path / "ecef.csv", index=False, float_format="%.17g")
    b = read_navigation(tmp_path / "ecef.csv", crs="EPSG:4978")
    a = read_navigation(_write_geodetic_csv(tmp_path / "geo.csv", fl))
    assert b.time_scale == "seconds of day" and b.frame.map_epsg == 32756  # WGS 84 / UTM 56S
    np.testing.assert_allclose(b.trajectory.t_s, a.trajectory.t_s - 3 * 86400.0, atol=1e-9)
    np.testing.assert_allclose(b.trajectory.xyz_m, a.trajectory.xyz_m, atol=1e-3, rtol=0)
    dang = np.degrees(b.trajectory.roll_pitch_heading_rad - a.trajectory.roll_pitch_heading_rad)
    assert np.max(np.abs(dang)) < 1e-6


def test_the_local_enu_file_stays_readable(tmp_path):
    from hsgeo.io.navigation import read_navigation

    tr = _traj()
    nav = read_navigation(write_trajectory(tmp_path / "nav.csv", tr))
    assert nav.frame is None and nav.source_crs == "local ENU"
    np.testing.assert_array_equal(nav.trajectory.xyz_m, tr.xyz_m)


def _miss_of_the_ray(nav, fl, k, body_dir, R_map_from_body=None):
    """Distance (m) between the ray of record k in the frame and the point 2 km along the same
    body ray computed with PROJ alone (the aircraft's own topocentric frame at the record)."""
    from pyproj import Transformer

    from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

    t, lat, lon, h, roll, pitch, heading = fl
    a = np.radians([roll[k], pitch[k], heading[k]])
    d_enu_local = R_ENU_FROM_NED @ R_from_rpy(*a) @ body_dir
    d_enu_local = 2000.0 * d_enu_local / np.linalg.norm(d_enu_local)
    topo = Transformer.from_pipeline(
        f"+proj=pipeline +step +inv +proj=topocentric +lat_0={float(lat[k])!r} "
        f"+lon_0={float(lon[k])!r} +h_0={float(h[k])!r} +ellps=WGS84 "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    plon, plat, ph = topo.transform(*d_enu_local)
    P = np.ravel(nav.frame.lonlat_to_enu(plon, plat, ph))
    tr = nav.trajectory
    R = tr.R_map_from_body(tr.t_s[k])[0] if R_map_from_body is None else R_map_from_body
    d = R @ body_dir
    d = d / np.linalg.norm(d)
    v = P - tr.xyz_m[k]
    return float(np.linalg.norm(v - (v @ d) * d))


def test_each_records_ned_is_carried_into_the_frame(tmp_path):
    """At 60° N, 15 km east of the frame's origin on an east-west line: the aircraft's north is
    turned by the meridian convergence (≈ 0.23°) and its down tilted by ≈ 0.13° against the
    frame's. Carried exactly, a ray meets PROJ's own point 2 km along it to < 1 mm; taking the
    attitude as if it were against the frame's NED misses it by ≈ 5 m at nadir (the tilt) and
    ≈ 8 m 29° to the left (tilt and convergence add up there)."""
    from hsgeo.io.navigation import read_navigation
    from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

    fl = _flight(lat0=60.0, lon0=10.0, az_deg=90.0)
    nav = read_navigation(_write_geodetic_csv(tmp_path / "nav.csv", fl))
    k = fl[0].size - 1  # the east end, 15 km from the origin
    lat, lon = fl[1][k], fl[2][k]
    R_frame_from_ned = nav.frame.R_enu_from_ned_at(lon, lat)
    north = R_frame_from_ned @ [1.0, 0.0, 0.0]
    convergence = np.degrees(np.arctan2(north[0], north[1]))
    down = R_frame_from_ned @ [0.0, 0.0, 1.0]
    tilt = np.degrees(np.arccos(-down[2]))
    assert 0.20 < abs(convergence) < 0.25, convergence
    assert 0.12 < tilt < 0.15, tilt
    a = np.radians([fl[4][k], fl[5][k], fl[6][k]])
    R_naive = R_ENU_FROM_NED @ R_from_rpy(*a)  # the per-record rotation ignored
    s, c = np.sin(0.5), np.cos(0.5)
    naive = []
    for body_dir in ([0.0, 0.0, 1.0], [0.0, -s, c], [0.0, s, c]):
        assert _miss_of_the_ray(nav, fl, k, np.array(body_dir)) < 1e-3
        naive.append(_miss_of_the_ray(nav, fl, k, np.array(body_dir), R_naive))
    assert 4.0 < naive[0] < 6.0, naive  # nadir, 2 km: the tilt, 2000 m × 0.134°
    assert 7.0 < naive[1] < 10.0, naive  # to the left: tilt and convergence add up
