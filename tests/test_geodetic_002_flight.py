"""The 002 flight through the geodetic path (issue 38): the LP campaign's navigation (a local
east-north-up frame at the 002 site, ETRS89, attitude against that frame's north-east-down)
written as a GNSS/INS delivers it — ETRS89 latitude, longitude, ellipsoidal height per record
(the test's own iterated geodetic inverse in extended precision), attitude against the NED *at
each record* (the test's own ECEF rotation, EPSG method 9837), GPS seconds of week — and read
back with :func:`hsgeo.io.read_navigation` into the site's frame gives the same trajectory, the same
ground points of every strip's lines and the same orthomosaic as the local-frame path.

Measured at the simulator's smallest block (scale 0.05, seed 0): positions 8.7e-10 m of 2.5 km
(before: 6.7e-8 m, the writer used PROJ's one-step ``cart`` inverse; the reader now converts in
extended precision, :meth:`hsgeo.crs.LocalFrame.lonlat_to_enu_precise`: PROJ's float64 forward
alone gives 1.9e-9 m), angles 2.7e-15 rad, ground points 2.5e-9 m, the mosaic bit-identical.
The floor is the file's: a float64 latitude in degrees at 59.7° N steps by 7.1e-15° = 7.9e-10 m
(half a step 4.0e-10 m). The chapter's rows: see the slow test."""

from __future__ import annotations

import numpy as np
import pytest

SCALE = 0.05  # hsgeo.simulate.lp_campaign.MIN_SCALE: a 30 m block


@pytest.fixture(scope="module")
def campaign():
    from hsgeo.simulate.lp_campaign import simulate

    return simulate(SCALE, rng=0)


def _R_ecef_from_enu(lon_deg, lat_deg):
    """East, north, up unit vectors (columns) in geocentric axes at geodetic λ, φ."""
    lam, phi = np.radians(lon_deg), np.radians(lat_deg)
    sl, cl, sp, cp = np.sin(lam), np.cos(lam), np.sin(phi), np.cos(phi)
    z = np.zeros_like(sl)
    e = np.stack([-sl, cl, z], -1)
    n = np.stack([-sp * cl, -sp * sl, cp], -1)
    u = np.stack([cp * cl, cp * sl, sp], -1)
    return np.stack([e, n, u], -1)


def _rpy(R):
    """Roll, pitch, heading (rad) of R_ned_from_body = Rz(heading) Ry(pitch) Rx(roll)."""
    return np.column_stack(
        [
            np.arctan2(R[:, 2, 1], R[:, 2, 2]),
            -np.arcsin(np.clip(R[:, 2, 0], -1, 1)),
            np.arctan2(R[:, 1, 0], R[:, 0, 0]),
        ]
    )


_LD = np.longdouble
_PI = _LD("3.14159265358979323846264338327950288")
_GRS80_A_M, _GRS80_F = _LD(6378137), 1 / _LD("298.257222101")


def _enu_to_geodetic_exact(enu_m, frame):
    """ENU (m) about the frame's origin → latitude, longitude (degrees), ellipsoidal height (m)
    on GRS80, in ``longdouble``: the topocentric inverse (EPSG 9837) and the geocentric inverse
    iterated on latitude (Bowring's fixed point, 8 steps: converged to ≈ 1e-18 rad). The test's
    own code, written from the EPSG guidance; PROJ's ``+inv +proj=cart`` used before is a
    one-step approximation 6.7e-8 m off here."""
    a, f = _GRS80_A_M, _GRS80_F
    e2 = f * (2 - f)

    def cart(lam, phi, h):
        n = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
        return np.stack(
            [(n + h) * np.cos(phi) * np.cos(lam), (n + h) * np.cos(phi) * np.sin(lam),
             (n * (1 - e2) + h) * np.sin(phi)], -1)  # fmt: skip

    lam0 = _LD(repr(float(frame.lon_deg))) * _PI / 180
    phi0 = _LD(repr(float(frame.lat_deg))) * _PI / 180
    x0 = cart(lam0, phi0, _LD(repr(float(frame.h_m))))
    sl, cl, sp, cp = np.sin(lam0), np.cos(lam0), np.sin(phi0), np.cos(phi0)
    R = np.array([[-sl, -sp * cl, cp * cl], [cl, -sp * sl, cp * sl], [0, cp, sp]], dtype=_LD)
    X, Y, Z = (x0 + np.asarray(enu_m, float).astype(_LD) @ R.T).T
    p = np.hypot(X, Y)
    phi = np.arctan2(Z, p * (1 - e2))
    for _ in range(8):
        n = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
        h = p / np.cos(phi) - n
        phi = np.arctan2(Z, p * (1 - e2 * n / (n + h)))
    n = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
    h = p / np.cos(phi) - n
    back = cart(np.arctan2(Y, X), phi, h)  # the forward, to state the inverse's closure
    closure_m = float(np.max(np.abs(back - np.stack([X, Y, Z], -1))))
    assert closure_m < 1e-11, closure_m
    deg = 180 / _PI
    return tuple(np.asarray(v, float) for v in (phi * deg, np.arctan2(Y, X) * deg, h))


def _geodetic_csv(path, traj, frame):
    """The local-frame trajectory as a geodetic navigation CSV (ETRS89, EPSG:4937)."""
    from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

    lat, lon, h = _enu_to_geodetic_exact(traj.xyz_m, frame)
    a = traj.roll_pitch_heading_rad
    R_frame_enu_from_body = R_ENU_FROM_NED @ R_from_rpy(a[:, 0], a[:, 1], a[:, 2])
    R_ecef_from_frame_enu = _R_ecef_from_enu(frame.lon_deg, frame.lat_deg)
    R_rec_ned_from_ecef = R_ENU_FROM_NED.T @ np.swapaxes(_R_ecef_from_enu(lon, lat), -1, -2)
    rph = np.degrees(_rpy(R_rec_ned_from_ecef @ R_ecef_from_frame_enu @ R_frame_enu_from_body))
    t = traj.t_s + 302400.0  # GPS seconds of week: the campaign's clock from mid-week
    table = np.column_stack([t, lat, lon, h, rph])
    with open(path, "w") as f:
        f.write("# crs: EPSG:4937\n")
        f.write("gps_week,gps_sow_s,lat_deg,lon_deg,h_m,roll_deg,pitch_deg,heading_deg\n")
        for row in table:
            f.write("2300," + ",".join(f"{v:.17g}" for v in row) + "\n")
    return path


@pytest.fixture(scope="module")
def geodetic(campaign, tmp_path_factory):
    """The campaign's navigation through the geodetic path, its clock shifted back."""
    from hsgeo.crs import SITE_AAS
    from hsgeo.io import read_navigation
    from hsgeo.trajectory import Trajectory

    obs, _ = campaign
    p = _geodetic_csv(tmp_path_factory.mktemp("nav") / "nav.csv", obs.navigation, SITE_AAS)
    nav = read_navigation(p, frame=SITE_AAS)
    assert nav.frame == SITE_AAS and nav.gps_week == 2300
    assert "ETRS89" in nav.source_crs and nav.time_scale == "GPS seconds of week"
    tr = nav.trajectory
    return Trajectory(tr.t_s - 302400.0, tr.xyz_m, tr.roll_pitch_heading_rad)


def test_the_trajectory_is_the_local_one(campaign, geodetic):
    """Positions to ≤ 1e-9 relative of their size and ≤ 2 steps of the file's latitude
    (7.9e-10 m each; measured 8.7e-10 m of 2500 m: 3.5e-13), attitudes to 1e-12 rad (measured
    2.7e-15 rad), times exact up to the 302400 s shift."""
    obs, _ = campaign
    a, b = obs.navigation, geodetic
    np.testing.assert_allclose(b.t_s, a.t_s, rtol=0, atol=1e-9)
    scale_m = float(np.max(np.abs(a.xyz_m)))
    dpos = float(np.max(np.abs(b.xyz_m - a.xyz_m)))
    dang = float(np.max(np.abs(b.roll_pitch_heading_rad - a.roll_pitch_heading_rad)))
    print(f"positions: max |Δ| {dpos:.3e} m of {scale_m:.1f} m; angles: max |Δ| {dang:.3e} rad")
    assert dpos <= 1e-9 * scale_m and dpos <= 1.6e-9, (dpos, scale_m)
    assert dang < 1e-12, dang


def test_ground_points_and_mosaic_are_the_local_ones(campaign, geodetic):
    """Every strip's lines (every 10th line, every 25th pixel, band 4) geolocated on the DSM
    with the true camera, and the orthomosaic of the strips (002 Fig. 9's, 0.5 m cells) made
    with the a-priori camera: through the geodetic navigation the same ground points to 1e-8 m
    and the same mosaic. Measured: ground points 2.5e-9 m apart at most (4.0e-8 m before the
    exact inverse and the extended-precision reader); as the ground lies within ≈ 17 m of the
    frame's origin that is 1.4e-10 of the largest ground coordinate, 1e-12 of the 2.5 km ray."""
    from hsgeo.crs import SITE_AAS
    from hsgeo.ortho import Strip, geolocate_lines
    from hsgeo.reproduce.lp_mosaic import mosaic_of

    obs, truth = campaign
    worst, worst_m = 0.0, 0.0
    for s in obs.strips:
        x = s.x_px(obs.n_px_full)[::25]
        px = np.column_stack([x, np.zeros(x.size)])
        t = s.t_s[::10]
        g = [
            geolocate_lines(
                Strip(truth.camera, tr, t, px, None, {"band": 3}), truth.terrain, SITE_AAS
            )[0]  # fmt: skip
            for tr in (obs.navigation, geodetic)
        ]
        d_m = float(np.max(np.abs(g[1] - g[0])))
        worst_m = max(worst_m, d_m)
        worst = max(worst, d_m / float(np.max(np.abs(g[0]))))
    print(f"ground points: max |Δ| {worst_m:.3e} m, relative {worst:.3e}")
    assert worst_m <= 1e-8 and worst <= 1e-9, (worst_m, worst)
    m = [
        mosaic_of(obs, truth, obs.camera, tr, resolution_m=0.5, bands_nm=(550.0,)).values
        for tr in (obs.navigation, geodetic)
    ]
    assert m[0].shape == m[1].shape
    np.testing.assert_array_equal(np.isfinite(m[0]), np.isfinite(m[1]))
    ok = np.isfinite(m[0])
    rel = float(np.max(np.abs(m[1][ok] - m[0][ok])) / np.max(np.abs(m[0][ok])))
    print(f"mosaic: {ok.sum()} cells, max relative |Δ| {rel:.3e}")
    assert rel <= 1e-9, rel


@pytest.mark.slow
def test_the_lp_chapter_rows_through_the_geodetic_path(tmp_path, monkeypatch):
    """The lp-observations chapter (scale 0.05, seed 0, without the blur-off rerun) with its
    campaign's navigation replaced by the geodetic path's, against the plain run (paper, σ,
    reproduced and truth, as ``bench/compare_reproductions.py`` compares).

    Measured with the former path (navigation 6.7e-8 m off: PROJ's one-step ``cart`` inverse in
    the writer; 39 min wall under load 14, both runs): 264 rows, largest relative change 2.7e-6,
    on a row near zero — 'square centroids: 002 Table 2 from pixels' mean_n_m 0.0029974245 →
    0.0029974325 m (8e-9 m). With the exact writer and the extended-precision reader the
    navigation is 8.7e-10 m off, and the chapter through it (``hsgeo reproduce`` rows, with
    the blur-off rerun, against main 268652f's seed-0 baseline): 275 rows, largest relative
    change 2.2e-7 (median_e_m 0.00141708534 m, |Δ| 3.1e-10 m), 137 values beyond 1e-9; the
    square centroids' E, N within 3.4e-10 m (below half a latitude step, 4.0e-10 m), pixel rows
    within 1.2e-8 px, but the no-GCP heights (≈ −19 m, a datum-free block) by 6.0e-8 m (3e-9
    relative) and c − truth by 5.0e-7 µm. 1e-9 *relative* is not reachable on such a row through any
    file: it asks 3e-12 m of a 3-mm mean, while a float64 latitude in degrees steps by 7.9e-10 m
    at 59.7° N (the file's floor). The bound asserted stays the former measured order (1e-5), so
    a real change of the path still fails; the rows are judged, in the report of issue 38, by
    their absolute change against that floor."""
    from dataclasses import replace

    import hsgeo.reproduce.lp_observations as chapter
    from hsgeo.crs import SITE_AAS
    from hsgeo.io import read_navigation
    from hsgeo.trajectory import Trajectory

    plain = chapter.run(seed=0, scale=0.05, unmodelled=False, judges=False)
    real = chapter.simulate

    def through_geodetic(*a, **kw):
        obs, truth = real(*a, **kw)
        p = _geodetic_csv(tmp_path / "nav.csv", obs.navigation, SITE_AAS)
        tr = read_navigation(p, frame=SITE_AAS).trajectory
        nav = Trajectory(tr.t_s - 302400.0, tr.xyz_m, tr.roll_pitch_heading_rad)
        return replace(obs, navigation=nav), truth

    monkeypatch.setattr(chapter, "simulate", through_geodetic)
    geo = chapter.run(seed=0, scale=0.05, unmodelled=False, judges=False)
    assert len(plain.rows) == len(geo.rows) > 50
    worst = (0.0, None)
    for a, b in zip(plain.rows, geo.rows, strict=True):  # as bench/compare_reproductions.py
        assert (a.table, a.quantity, a.unit) == (b.table, b.quantity, b.unit)
        for f in ("paper", "paper_sigma", "reproduced", "sigma", "truth"):
            x, y = getattr(a, f), getattr(b, f)
            if x is None or y is None or not (np.isfinite(x) and np.isfinite(y)):
                assert x == y or (x != x and y != y), (a.table, a.quantity, f, x, y)
                continue
            rel = abs(x - y) / max(abs(x), abs(y)) if x != y else 0.0
            if rel > worst[0]:
                worst = (rel, (a.table, a.quantity, f, x, y))
    print(f"{len(plain.rows)} rows; largest relative change {worst}")
    assert worst[0] <= 1e-5, worst
