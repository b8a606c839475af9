"""The 004 panoramic (whiskbroom) scanner: the sensor interface's round trip, its Jacobian against
finite differences, a level flight by hand, and geocoding through hsgeo.geocode with no
panoramic code in geocode."""

import inspect

import numpy as np
import pytest

import hsgeo.geocode as geocode
from hsgeo import InputError
from hsgeo.geocode import PlaneTerrain, geocode_rays
from hsgeo.sensors.mount import Mount, Sensor
from hsgeo.sensors.panoramic import PanoramicScanner
from hsgeo.trajectory import Trajectory

MOUNT = Mount.from_rpy(np.deg2rad([0.4, -0.3, 0.8]), lever_arm_m=(0.3, -0.2, 0.5))


def wavy_nav(H=300.0, T=30.0, v=60.0):
    t = np.linspace(0.0, T, 3001)
    h = np.deg2rad(40.0)
    xyz = np.column_stack([v * t * np.sin(h), v * t * np.cos(h), H + 2 * np.sin(0.3 * t)])
    rph = np.column_stack(
        [0.03 * np.sin(0.7 * t), 0.02 * np.cos(0.5 * t), h + 0.01 * np.sin(0.2 * t)]
    )
    return Trajectory(t, xyz, rph)


def test_the_daedalus_numbers_of_004():
    s = PanoramicScanner()
    assert s.n_px == 716 and s.ifov_deg == 0.12
    # pixel 0 looks right of the heading, at about +43°; the last pixel at about −43°
    assert np.rad2deg(s.scan_angle_rad(0)) == pytest.approx(42.9, abs=0.01)
    assert np.rad2deg(s.scan_angle_rad(715)) == pytest.approx(-42.9, abs=0.01)
    assert isinstance(s, Sensor)


@pytest.mark.parametrize("mount", [Mount(), MOUNT])
def test_round_trip_and_line_time(mount):
    rng = np.random.default_rng(3)
    s = PanoramicScanner(mount=mount)
    nav = wavy_nav()
    n = 300
    zeta = rng.uniform(0, 715, n)
    t = rng.uniform(1, 29, n)
    o, d = s.rays(zeta, t, nav)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-15)
    X = o + rng.uniform(200, 800, n)[:, None] * d
    px = s.project(X, t, nav)
    np.testing.assert_allclose(px[:, 0], zeta, rtol=0, atol=1e-9)
    np.testing.assert_allclose(px[:, 1], 0.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(s.line_time(X, nav, t + 0.3), t, rtol=0, atol=1e-8)


def test_jacobian_against_finite_differences():
    rng = np.random.default_rng(5)
    s = PanoramicScanner(mount=MOUNT)
    nav = wavy_nav()
    n = 50
    t = rng.uniform(1, 29, n)
    o, d = s.rays(rng.uniform(0, 715, n), t, nav)
    X = o + 400 * d + rng.normal(0, 5, (n, 3))  # also off the scan plane
    J = s.project_jacobian(X, t, nav)
    h = 1e-4
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = (s.project(X + e, t, nav) - s.project(X - e, t, nav)) / (2 * h)
        np.testing.assert_allclose(J[:, :, k], fd, rtol=1e-6, atol=1e-8)


def test_level_flight_by_hand():
    """Independent: flying due north at 300 m, level, pixel ζ looks at θ = (357.5 − ζ)·0.12°
    to the right (east), so its ground point is E = 300·tan θ; the along-track offset of a point
    1 m north of the line is asin(1/r)/δ pixels."""
    nav = Trajectory([0.0, 10.0], [[0, 0, 300.0], [0, 500, 300.0]], np.zeros((2, 3)))
    s = PanoramicScanner()
    zeta = np.array([0.0, 100.0, 357.5, 600.0, 715.0])
    th = np.deg2rad((357.5 - zeta) * 0.12)
    g = geocode_rays(s, zeta, np.full(5, 4.0), nav, PlaneTerrain(0.0))
    np.testing.assert_allclose(g[:, 0], 300.0 * np.tan(th), atol=1e-9)
    np.testing.assert_allclose(g[:, 1], 200.0, atol=1e-9)
    # ground sampling: 0.12° at 300 m is 0.63 m at nadir (004: "about 0.7 m"), /cos² off nadir
    dE = np.diff(300.0 * np.tan(np.deg2rad((357.5 - np.arange(716)) * 0.12)))
    assert abs(dE[357]) == pytest.approx(300 * np.deg2rad(0.12), rel=1e-4)
    assert abs(dE[0]) / abs(dE[357]) == pytest.approx(1 / np.cos(np.deg2rad(42.9)) ** 2, rel=1e-2)
    X = np.array([[50.0, 201.0, 0.0]])
    r = np.linalg.norm(X[0] - [0, 200.0, 300.0])
    assert s.project(X, [4.0], nav)[0, 1] == pytest.approx(np.arcsin(1 / r) / s.ifov_rad, 1e-9)


def test_geocoding_a_scan_needs_no_panoramic_code_in_geocode():
    """A whole scan (every sample at its own time) geocoded by hsgeo.geocode, which names no
    panoramic sensor; each ground point projects back to its own pixel."""
    src = inspect.getsource(geocode)
    assert "panoramic" not in src.lower() and "Panoramic" not in src
    nav = wavy_nav()
    s = PanoramicScanner(mount=MOUNT)
    lines = np.repeat(np.arange(20), 716)
    zeta = np.tile(np.arange(716.0), 20)
    t = s.times(lines, zeta, 2.0, 10.0)
    assert np.all(np.diff(t) > 0)
    g = geocode_rays(s, zeta, t, nav, PlaneTerrain(5.0))
    np.testing.assert_allclose(g[:, 2], 5.0)
    px = s.project(g, t, nav)
    np.testing.assert_allclose(px[:, 0], zeta, atol=1e-9)
    np.testing.assert_allclose(px[:, 1], 0.0, atol=1e-9)


def test_bad_parameters():
    with pytest.raises(InputError, match="n_px"):
        PanoramicScanner(n_px=1)
    with pytest.raises(InputError, match="ifov"):
        PanoramicScanner(ifov_deg=1.0)
