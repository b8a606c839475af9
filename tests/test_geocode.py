"""Geocoding: ray–terrain intersection (the first crossing), sensor geometries, boresight
calibration (the orthorectification of whole lines: tests/test_orthorectify*.py)."""

import dataclasses

import numpy as np
import pytest
import xarray as xr

from hsgeo import ConvergenceError, InputError, ObservationError
from hsgeo.adjust.checks import check_jacobian
from hsgeo.geocode import DemTerrain, PlaneTerrain, geocode_observations, intersect
from hsgeo.sensors.line import BoresightGCP, CalibratedLine, LinearIFOV, calibrate_boresight
from hsgeo.simulate.pula_flight import observe_gcps, simulate_flight
from hsgeo.simulate.scenarios import load_scenario
from hsgeo.trajectory import Trajectory
from hsgeo.workflows.geocoding import gcp_deviations

CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1


def straight_nav(heading_deg=30.0, H=500.0, T=20.0, v=20.0):
    t = np.linspace(0, T, 401)
    h = np.deg2rad(heading_deg)
    EN = np.outer(v * t, [np.sin(h), np.cos(h)])
    rpy = np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.full(t.size, h)])
    return Trajectory(t, np.column_stack([EN, np.full(t.size, H)]), rpy)


def test_intersect_plane_and_dem_round_trip():
    rng = np.random.default_rng(0)
    O = np.column_stack([rng.uniform(-50, 50, (20, 2)), np.full(20, 800.0)])
    X = np.column_stack([rng.uniform(-200, 200, (20, 2)), np.zeros(20)])
    # tilted terrain as a DEM (bilinear interpolation of a plane is exact)
    E = np.linspace(-400, 400, 81)
    N = np.linspace(-400, 400, 81)
    dem = xr.DataArray(
        10 + 0.05 * E[None, :] - 0.03 * N[:, None], dims=("N", "E"), coords={"N": N, "E": E}
    )
    X[:, 2] = 10 + 0.05 * X[:, 0] - 0.03 * X[:, 1]
    got = intersect(O, 3.7 * (X - O), DemTerrain(dem), tol_m=1e-9)
    np.testing.assert_allclose(got, X, atol=1e-6)
    flat = X.copy()
    flat[:, 2] = 25.0
    np.testing.assert_allclose(intersect(O, flat - O, PlaneTerrain(25.0)), flat, atol=1e-9)


def test_intersect_errors():
    with pytest.raises(ObservationError, match="downwards"):
        intersect([[0, 0, 100.0]], [[0, 0, 1.0]], PlaneTerrain(0))
    with pytest.raises(InputError, match="NaN"):
        intersect([[0, 0, np.nan]], [[0, 0, -1.0]], PlaneTerrain(0))
    E = np.linspace(0, 10, 11)
    dem = xr.DataArray(np.zeros((11, 11)), dims=("N", "E"), coords={"N": E, "E": E})
    with pytest.raises(ObservationError, match="outside the DEM"):
        intersect([[5.0, 5.0, 100.0]], [[1.0, 0, -0.1]], DemTerrain(dem))


@pytest.mark.parametrize("geom", [CAL, LinearIFOV(485.0, 3600.0)])
def test_line_geometry_round_trip(geom):
    zeta = np.linspace(486.8 - 440, 486.8 + 440, 81)
    np.testing.assert_allclose(geom.zeta(geom.tan_angle(zeta)), zeta, atol=1e-7)


def test_geocoding_a_known_point_returns_it():
    """Ray through a known pose and terrain: observe a ground point with the model, geocode it."""
    nav = straight_nav()
    bs = np.deg2rad([0.3, -0.2, 0.5])
    X = np.array([[40.0, 150.0, 12.0], [10.0, 120.0, 12.0], [65.0, 180.0, 12.0]])
    line, zeta = observe_gcps(nav, CAL, bs, 0.0, 12.5, X, np.random.default_rng(0), 0.0, 0.0)
    got = geocode_observations(
        nav,
        CAL,
        line,
        zeta,
        t0_s=0.0,
        line_rate_hz=12.5,
        terrain=PlaneTerrain(12.0),
        boresight_rad=bs,
    )
    np.testing.assert_allclose(got, X, atol=1e-6)


def test_boresight_jacobian_and_recovery():
    nav = straight_nav()
    bs = np.deg2rad([0.4, -0.3, 0.8])
    rng = np.random.default_rng(1)
    along, across = rng.uniform(60, 300, 12), rng.uniform(-50, 50, 12)  # within ±354 px
    h = np.deg2rad(30.0)
    X = np.column_stack(
        [
            along * np.sin(h) + across * np.cos(h),
            along * np.cos(h) - across * np.sin(h),
            np.full(12, 5.0),
        ]
    )
    line, zeta = observe_gcps(nav, CAL, bs, 0.0, 12.5, X, rng, 0.0, 0.0)
    blk = BoresightGCP(
        nav, CAL, line, zeta, X, t0_s=0.0, line_rate_hz=12.5, height_m=5.0, sigma_m=0.1
    )
    assert check_jacobian(blk, {"boresight": bs}, "boresight", 1e-7) < 1e-6
    res = calibrate_boresight(nav, CAL, line, zeta, X, t0_s=0.0, line_rate_hz=12.5, height_m=5.0)
    np.testing.assert_allclose(res.value("boresight"), bs, atol=1e-9)


def test_boresight_truth_within_3_sigma():
    cfg = load_scenario("pula_flight")
    cfg = dataclasses.replace(
        cfg,
        gnss=dataclasses.replace(cfg.gnss, bias_m=0.0),
        imu=dataclasses.replace(cfg.imu, attitude_bias_deg=0.0, heading_drift_deg_per_s=0.0),
    )
    z = []
    for seed in range(8):
        fl, truth = simulate_flight(cfg, seed)
        # the true sensor as the assumed one: only the boresight is tested here
        res = calibrate_boresight(
            fl.recorded_nav,
            truth.sensor,
            fl.line,
            fl.zeta_px,
            fl.gcp_enu_m,
            t0_s=0.0,
            line_rate_hz=fl.line_rate_hz,
            height_m=50.0,
            sigma_m=0.2,
        )
        z.append((res.value("boresight") - truth.boresight_rad) / res.sigma("boresight"))
    assert np.max(np.abs(z)) < 4.0  # 24 deviates, family-wise


def test_flight_observations_are_frozen_and_truth_free():
    fl, truth = simulate_flight(load_scenario("pula_flight"), 3)
    names = {f.name for f in dataclasses.fields(fl)}
    assert fl.__dataclass_params__.frozen and truth.__dataclass_params__.frozen
    assert not names & {"true_nav", "sensor", "boresight_rad"}, names
    assert {"recorded_nav", "line", "zeta_px", "gcp_enu_m", "sensor_nominal"} <= names
    assert isinstance(fl.sensor_nominal, LinearIFOV) and fl.recorded_nav is not truth.true_nav
    assert not np.allclose(fl.recorded_nav.xyz_m, truth.true_nav.xyz_m, atol=0.1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        fl.line = fl.line + 1


def test_gcp_deviations_vanish_with_exact_navigation_and_sensor():
    """Noise-free observations, true navigation and sensor: the workflow returns the boresight
    and zero deviations (the GCPs are where they were surveyed)."""
    nav = straight_nav()
    bs = np.deg2rad([0.4, -0.3, 0.8])
    rng = np.random.default_rng(2)
    along, across = rng.uniform(60, 300, 10), rng.uniform(-50, 50, 10)
    h = np.deg2rad(30.0)
    X = np.column_stack(
        [
            along * np.sin(h) + across * np.cos(h),
            along * np.cos(h) - across * np.sin(h),
            np.full(10, 5.0),
        ]
    )
    line, zeta = observe_gcps(nav, CAL, bs, 0.0, 12.5, X, rng, 0.0, 0.0)
    dev, res = gcp_deviations(nav, CAL, line, zeta, X, height_m=5.0, t0_s=0.0, line_rate_hz=12.5)
    assert dev.shape == (10, 2)
    np.testing.assert_allclose(dev, 0.0, atol=1e-6)
    np.testing.assert_allclose(res.value("boresight"), bs, atol=1e-9)
    # a wrong sensor model shows up as deviations
    dev_nom, _ = gcp_deviations(
        nav, LinearIFOV(485.0, 3600.0), line, zeta, X, height_m=5.0, t0_s=0.0, line_rate_hz=12.5
    )
    assert np.max(np.abs(dev_nom)) > 0.05


def test_zeta_outside_the_model_raises():
    with pytest.raises(ConvergenceError):
        CAL.zeta(np.array([0.2]))  # 700 px from the centre: beyond the calibrated 450 px


# ---------------------------------------------------------------- the first crossing (issue 36)
def _town(cell_m=0.5, seed=0):
    """A DSM of buildings (flat roofs 3–12 m, steps over one cell) on a gentle slope, E, N in
    0…120 m: the heights and the DemTerrain."""
    rng = np.random.default_rng(seed)
    E = np.arange(0.0, 120.0 + cell_m / 2, cell_m)
    N = np.arange(0.0, 120.0 + cell_m / 2, cell_m)
    z = 0.02 * E[None, :] + 0.01 * N[:, None] + np.zeros((N.size, E.size))
    for _ in range(40):
        e, n = rng.uniform(10, 110, 2)
        w, h = rng.uniform(3, 15, 2)
        inside = (np.abs(E[None, :] - e) <= w / 2) & (np.abs(N[:, None] - n) <= h / 2)
        z = np.where(inside, np.maximum(z, rng.uniform(3, 12) + 0.02 * e), z)
    dem = xr.DataArray(z, dims=("N", "E"), coords={"N": N, "E": E})
    return dem, DemTerrain(dem)


def _dense_first_crossing(O, d, terrain, step_m=1e-4, top_m=20.0, bottom_m=-2.0):
    """The first point of each ray below the DSM, sampled every ``step_m`` along the ray from
    height ``top_m`` down to ``bottom_m`` (an independent truth: no bracket, no root finding)."""
    out = np.empty((len(O), 3))
    for k in range(len(O)):
        u = d[k] / np.linalg.norm(d[k])
        s_top = (top_m - O[k, 2]) / u[2]
        s_bot = (bottom_m - O[k, 2]) / u[2]
        s = np.arange(s_top, s_bot, step_m)
        P = O[k] + s[:, None] * u
        below = P[:, 2] <= terrain.height(P[:, 0], P[:, 1], outside="nan")
        assert below.any(), k
        out[k] = P[np.argmax(below)]
    return out


def _rays_at(angle_deg, n, seed, H=100.0):
    """``n`` rays ``angle_deg`` off nadir in random azimuths, aimed at random points of the
    town's middle (so that they stay over the DSM)."""
    rng = np.random.default_rng(seed)
    az = rng.uniform(0, 2 * np.pi, n)
    t = np.tan(np.radians(angle_deg))
    d = np.column_stack([t * np.sin(az), t * np.cos(az), -np.ones(n)])
    target = np.column_stack([rng.uniform(25, 95, (n, 2)), np.zeros(n)])
    return target - H * d, d


@pytest.mark.parametrize("angle_deg", [0.0, 15.0, 30.0, 45.0])
def test_intersect_is_the_first_crossing_on_a_town(angle_deg):
    """Rays 0°, 15°, 30°, 45° off nadir over a DSM of buildings (occluded rays among them):
    the intersection is within 1 mm of the first point of a 0.1 mm dense sampling of the ray,
    and the compiled kernel and the numpy march agree (same tolerance)."""
    from hsgeo._raycast import first_crossing_reference

    dem, terrain = _town()
    O, d = _rays_at(angle_deg, 60, seed=int(angle_deg))
    X = intersect(O, d, terrain)
    truth = _dense_first_crossing(O, d, terrain)
    np.testing.assert_allclose(X, truth, atol=1e-3, rtol=0)
    # the point is on the surface and on the ray
    np.testing.assert_allclose(X[:, 2], terrain.height(X[:, 0], X[:, 1]), atol=1e-9)
    s = first_crossing_reference(
        O, d, lambda E, N: terrain.height(E, N, outside="nan"), terrain.height_range_m, 0.02
    )
    np.testing.assert_allclose(O + s[:, None] * d, X, atol=1e-3, rtol=0)
    if angle_deg >= 30:  # some rays meet a roof or wall above the ground they point at
        ground = intersect(O, d, PlaneTerrain(0.0))
        assert np.sum(np.hypot(*(X - ground)[:, :2].T) > 1.0) >= 5


def test_intersect_the_roof_not_the_ground_behind_it():
    """Issue 36's example: a 10 m building at E 95–105 m, a ray 30° off nadir from 100 m: the
    first crossing is on the roof at E = 102.54 m (the former height iteration went on to the
    ground behind it, E 108.32 m)."""
    E = np.arange(0.0, 200.5, 0.5)
    N = np.arange(0.0, 20.5, 0.5)
    z = np.where((E >= 95) & (E <= 105), 10.0, 0.0)[None, :].repeat(N.size, 0)
    terrain = DemTerrain(xr.DataArray(z, dims=("N", "E"), coords={"N": N, "E": E}))
    t30 = np.tan(np.radians(30.0))
    O = np.array([[102.54 + 90.0 * t30, 10.0, 100.0]])
    d = np.array([[-t30, 0.0, -1.0]])
    X = intersect(O, d, terrain)
    np.testing.assert_allclose(X[0], [102.54, 10.0, 10.0], atol=1e-9)


def test_intersect_steep_wall_and_grazing_corner():
    """A ray 30° off nadir meets a 10 m step (over one 1 m cell) on the wall; a ray that only
    clips a roof's edge (under it for 2 cm) is occluded there, where a march of a quarter cell
    steps over it."""
    E = np.arange(0.0, 101.0)
    z = np.where(E >= 50.0, 10.0, 0.0)[None, :].repeat(21, axis=0)
    dem = DemTerrain(xr.DataArray(z, dims=("N", "E"), coords={"N": np.arange(21.0), "E": E}))
    t30 = np.tan(np.radians(30.0))
    O = np.array([[49.2 - 98.0 * t30, 10.0, 100.0]])
    d = np.array([[0.5, 0.0, -np.sqrt(0.75)]])
    X = intersect(O, d, dem)
    np.testing.assert_allclose(X, _dense_first_crossing(O, d, dem, 1e-5, 12.0), atol=1e-4)
    assert 1.9 < X[0, 2] < 2.1 and 49.0 < X[0, 0] < 50.0  # on the wall, near 2 m
    # a tent over E 49…51 m peaking at 10 m; a nearly horizontal ray (5° below the horizontal)
    # passes 1 cm under its top: it is under the tent for 2 mm along E
    z2 = np.where(E == 50.0, 10.0, 0.0)[None, :].repeat(21, axis=0)
    ridge = DemTerrain(xr.DataArray(z2, dims=("N", "E"), coords={"N": np.arange(21.0), "E": E}))
    d2 = np.array([[np.cos(np.radians(5.0)), 0.0, -np.sin(np.radians(5.0))]])
    O2 = np.array([[50.0 - 30.0 * d2[0, 0], 10.0, 9.99 + 30.0 * np.sin(np.radians(5.0))]])
    X2 = intersect(O2, d2, ridge)
    assert 49.998 < X2[0, 0] < 50.0 and X2[0, 2] > 9.98
    truth = _dense_first_crossing(O2, d2, ridge, 1e-5, top_m=10.5, bottom_m=9.0)
    np.testing.assert_allclose(X2, truth, atol=1e-4)
    from hsgeo._raycast import first_crossing_reference

    s = first_crossing_reference(
        O2, d2, lambda e, n: ridge.height(e, n, outside="nan"), ridge.height_range_m, 0.25
    )
    assert not abs((O2 + s[:, None] * d2)[0, 0] - 50.0) < 0.01  # the march stepped over it


def test_intersect_misses_are_errors_or_nan():
    """A ray that leaves the DEM first, or starts under it: an ObservationError that says which
    (or NaN with ``on_miss="nan"``); a plane above the sensor is an error too."""
    _, terrain = _town()
    O = np.array([[60.0, 60.0, 100.0], [60.0, 60.0, 100.0], [60.0, 60.0, -5.0]])
    d = np.array([[0.0, 0.0, -1.0], [3.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    X = intersect(O, d, terrain, on_miss="nan")
    assert np.all(np.isfinite(X[0])) and np.all(np.isnan(X[1:]))
    with pytest.raises(ObservationError, match="1 rays reach the ground outside the DEM"):
        intersect(O[:2], d[:2], terrain)
    with pytest.raises(ObservationError, match="start under the terrain"):
        intersect(O[[0, 2]], d[[0, 2]], terrain)
    with pytest.raises(ObservationError, match="start under the terrain"):
        intersect([[0.0, 0.0, 10.0]], [[0.0, 0.0, -1.0]], PlaneTerrain(20.0))
    with pytest.raises(InputError, match="on_miss"):
        intersect(O, d, terrain, on_miss="skip")


def test_uneven_dem_marches_to_the_same_crossing():
    """A DEM whose coordinates are not evenly spaced is marched (the numpy reference): the same
    first crossings as the compiled traversal on the evenly spaced DEM it samples."""
    dem, terrain = _town(cell_m=1.0, seed=3)
    keep = np.r_[0:60, 60:121:2]  # E spacing 1 m, then 2 m
    uneven = DemTerrain(dem.isel(E=keep))
    even = DemTerrain(dem.isel(E=slice(0, 60)))
    assert uneven.surface is None and even.surface is not None
    O, d = _rays_at(15.0, 30, seed=5)
    O[:, 0] = np.clip(O[:, 0], 5, 45)  # over E < 59 m, where the two DEMs are the same
    d[:, 0] = np.clip(d[:, 0], -0.05, 0.05)
    np.testing.assert_allclose(intersect(O, d, uneven), intersect(O, d, even), atol=1e-4, rtol=0)
