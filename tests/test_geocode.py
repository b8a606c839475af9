"""Geocoding: ray–terrain intersection, sensor geometries, boresight calibration (the
orthorectification of whole lines: tests/test_orthorectify*.py)."""

import dataclasses

import numpy as np
import pytest
import xarray as xr

from hsgeo import ConvergenceError, InputError, ObservationError
from hsgeo.adjust.checks import check_jacobian
from hsgeo.geocode import (
    BoresightGCP,
    DemTerrain,
    PlaneTerrain,
    calibrate_boresight,
    geocode_observations,
    intersect,
)
from hsgeo.sensors.line import CalibratedLine, LinearIFOV
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
    cfg["gnss"]["bias_m"] = 0.0
    cfg["imu"]["attitude_bias_deg"] = 0.0
    cfg["imu"]["heading_drift_deg_per_s"] = 0.0
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


def test_intersect_on_a_wall_where_the_fixed_point_iteration_cycles(monkeypatch):
    """A ray 30° off nadir meets a 10 m wall (a DSM step over one cell): the height iteration
    jumps between roof and ground (|slope · tan 30°| = 5.8 > 1); the march and bisection find
    the first crossing, against a dense sampling of the ray (an independent truth)."""
    import xarray as xr

    from hsgeo import geocode
    from hsgeo.geocode import DemTerrain, intersect

    calls = []
    march = geocode._march_bisect
    monkeypatch.setattr(
        geocode, "_march_bisect", lambda O, *a, **k: calls.append(len(O)) or march(O, *a, **k)
    )
    E = np.arange(0.0, 101.0)
    z = np.where(E >= 50.0, 10.0, 0.0)[None, :].repeat(21, axis=0)
    dem = DemTerrain(xr.DataArray(z, dims=("N", "E"), coords={"N": np.arange(21.0), "E": E}))
    t30 = np.tan(np.radians(30.0))
    O = np.array([[49.2 - 98.0 * t30, 10.0, 100.0], [49.2 - 98.0 * t30 + 20.0, 10.0, 100.0]])
    d = np.array([[0.5, 0.0, -np.sqrt(0.75)]] * 2)
    X = intersect(O, d, dem, tol_m=1e-6)
    assert calls == [1]  # the first ray only: the iteration did not converge there
    # dense sampling: the first point of the ray below the DSM
    h = np.linspace(12.0, -1.0, 1_300_001)
    P = O[0] + ((h - O[0, 2]) / d[0, 2])[:, None] * d[0]
    first = np.argmax(h <= dem.height(P[:, 0], P[:, 1]))
    np.testing.assert_allclose(X[0], P[first], atol=2e-5)
    assert 1.9 < X[0, 2] < 2.1 and 49.0 < X[0, 0] < 50.0  # on the wall, near the expected 2 m
    # the second ray meets the flat roof: the iteration converges there as before
    np.testing.assert_allclose(X[1, 2], 10.0, atol=1e-6)
    np.testing.assert_allclose(X[1], O[1] + (10.0 - 100.0) / d[1, 2] * d[1], atol=1e-6)
