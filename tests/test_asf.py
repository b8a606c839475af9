"""The 004 ASF: the ratio of radiometry, the workflow's parts, and the recovery of the true ASF
from the simulated runway flights over seeds."""

import functools

import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.radiometry import asf_ratio, combine_opposite_crossings, even_odd_parts
from hsgeo.simulate.asf_runway import RunwayScene, simulate_runway, true_asf
from hsgeo.workflows.asf import (
    AsfInputs,
    AsfOptions,
    GroundSampler,
    asf_from_scans,
    georegister,
    inside_polygon,
)

TH = np.deg2rad((357.5 - np.arange(716)) * 0.12)


def test_asf_ratio_of_a_constructed_pair():
    """Independent: cross = ASF(θ)·ρ, along = ρ (ρ varying by 20 % over the width and along
    the runway): the ratio is ASF/ASF(nadir window) exactly, and σ̂ is 0 without noise."""
    rng = np.random.default_rng(1)
    rho = 0.1 * (1 + 0.1 * rng.uniform(-1, 1, (3, 40, 716)))
    asf = 1 + 0.05 * np.sin(TH)[None] + 0.1 * TH[None] ** 2 * np.arange(1, 4)[:, None]
    inside = np.ones((40, 716), bool)
    inside[:5] = False
    r = asf_ratio(rho * asf[:, None], rho, inside, TH, nadir_halfwidth_rad=np.deg2rad(1.0))
    near = np.abs(TH) <= np.deg2rad(1.0)
    np.testing.assert_allclose(r.asf, asf / asf[:, near].mean(axis=1, keepdims=True), rtol=1e-12)
    np.testing.assert_allclose(r.sigma, 0.0, atol=1e-12)
    assert np.all(r.n_samples == 35)


def test_asf_ratio_sigma_matches_the_scatter_over_noise():
    """σ̂ from the width agrees with the spread over 200 noise realisations (within 15 %)."""
    rng = np.random.default_rng(2)
    rho = np.full((1, 50, 716), 0.1)
    inside = np.ones((50, 716), bool)
    runs, sig = [], []
    for _ in range(200):
        c = rho * (1 + 0.01 * rng.standard_normal(rho.shape))
        r = asf_ratio(c, rho, inside, TH, nadir_halfwidth_rad=np.deg2rad(1.0))
        runs.append(r.asf[0, 100] * r.nadir[0])
        sig.append(r.sigma[0, 100] * r.nadir[0])
    assert np.std(runs) == pytest.approx(np.mean(sig), rel=0.15)


def test_asf_ratio_needs_nadir():
    inside = np.zeros((10, 716), bool)
    inside[:, :100] = True
    x = np.ones((1, 10, 716))
    with pytest.raises(InputError, match="nadir"):
        asf_ratio(x, x, inside, TH, nadir_halfwidth_rad=np.deg2rad(1.0))


def test_even_odd_parts_and_two_crossings():
    asf = true_asf(TH)
    even, odd = even_odd_parts(asf)
    np.testing.assert_allclose(even * odd, asf, rtol=1e-14)
    np.testing.assert_allclose(even, even[:, ::-1], rtol=1e-14)
    np.testing.assert_allclose(odd * odd[:, ::-1], 1.0, rtol=1e-14)
    b_even = 1 + 0.04 * np.sin(TH) ** 2
    b_odd = 1 + 0.02 * np.sin(TH)
    a, b = asf * b_even * b_odd, asf * b_even / b_odd
    est, bo = combine_opposite_crossings(a, b)
    np.testing.assert_allclose(est, asf * b_even, rtol=1e-14)
    np.testing.assert_allclose(bo, np.broadcast_to(b_odd, asf.shape), rtol=1e-14)


def test_true_asf_is_shaped_as_chosen():
    a = true_asf(TH)
    pp = 100 * (a.max(axis=1) - a.min(axis=1))
    assert pp.max() == pytest.approx(15.0, abs=0.2) and np.argmax(pp) == 0
    np.testing.assert_allclose(true_asf([0.0])[:, 0], 1.0)


def test_inside_polygon_with_margin():
    P = np.array([[-10, -2], [10, -2], [10, 2], [-10, 2]], float)
    E = np.array([0, 0, 0, 9.5, 11, 0])
    N = np.array([0, 1.5, 1.0, 0, 0, -3])
    np.testing.assert_array_equal(inside_polygon(E, N, P), [1, 1, 1, 1, 0, 0])
    np.testing.assert_array_equal(inside_polygon(E, N, P, 0.8), [1, 0, 1, 0, 0, 0])


def test_ground_sampler_inverts_the_georegistration():
    _, _, _, g = _flights(3)  # g: the along scan, georegistered
    sm = GroundSampler(g)
    rng = np.random.default_rng(0)
    lp = np.stack([rng.uniform(5, 900, 500), rng.uniform(2, 95, 500)])
    from scipy.ndimage import map_coordinates

    E = map_coordinates(g.E_m, lp, order=1)
    N = map_coordinates(g.N_m, lp, order=1)
    np.testing.assert_allclose(sm.locate(E, N), lp, atol=1e-6)
    assert np.all(np.isnan(sm.locate([5000.0], [0.0])))


@functools.cache
def _flights(seed: int):
    """The default runway's two flights for ``seed`` and their georegistered scans, simulated
    once in this module (≈ 2 CPU-s each; the 1 % test over 8 seeds and the registration test
    over 10 share seeds 0-7, issue 41). Read only: no test changes them."""
    obs, tr = simulate_runway(RunwayScene(), seed, reverse=False)
    return obs, tr, _georeg(obs.cross), _georeg(obs.along)


@pytest.fixture(scope="module", autouse=True)
def _free_flights():
    yield
    _flights.cache_clear()


def _georeg(s):
    return georegister(s.values, s.zeta_px, s.t0_s, s.line_rate_hz, s.sensor, s.trajectory)


def _recover(seed, geo=False):
    obs, tr, gc, ga = _flights(seed)
    res = asf_from_scans(AsfInputs(gc, ga, obs.runway_polygon_m))
    near = np.abs(tr.scan_angle_rad) <= np.deg2rad(1.0)
    truth = tr.asf / tr.asf[:, near].mean(axis=1, keepdims=True)
    if geo:
        return res, tr, truth, (gc, ga, obs.runway_polygon_m)
    return res, tr, truth


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(8))
def test_lambertian_runway_asf_within_1_percent_for_any_seed(seed):
    """Issue 27's 'done': over a Lambertian runway the recovered ASF lies within 1 % of the truth
    at every usable scan angle in every channel; every column usable; registration within
    0.1 m of the true offset between the two flights' navigation errors. Issue 37.6: a bar that
    can fail — with the runway's sub-metre structure (joints, centre-line dashes), the along
    image left where the navigation puts it misses the bar, one pixel of registration error
    along or across the runway does not."""
    from dataclasses import replace

    from hsgeo.reproduce.asf import asf_at_shift

    res, tr, truth, g = _recover(seed, geo=True)
    assert res.usable.all()
    assert np.max(np.abs(res.asf - truth)) < 0.01
    assert np.all(np.abs(res.registration.shift_m - tr.shift_m) < 0.1)
    gc, ga, P = g
    none = asf_from_scans(AsfInputs(gc, ga, P), replace(AsfOptions(), register=False))
    assert np.max(np.abs(none.asf - truth)) > 0.01
    px = res.registration.gsd_m
    for d in ((px, 0.0), (0.0, px)):
        off = asf_at_shift(gc, ga, P, tr.shift_m + np.array(d))
        assert np.max(np.abs(off.asf - truth)) <= 0.01


def test_lambertian_runway_asf_one_seed_and_z():
    """One seed in the quick suite: within 1 %, and the errors are consistent with σ̂."""
    res, tr, truth = _recover(11)
    assert np.max(np.abs(res.asf - truth)) < 0.01
    z = (res.asf - truth) / res.sigma
    assert np.std(z) < 2.0


def test_rendered_edge_moves_continuously_with_its_position():
    """The simulator's footprint: a sharp edge (a step of the ground across the track) moved by
    tenths of a line changes the rendered image by exactly as much as a box footprint says —
    the sum over lines of a column falls linearly with the edge's position (slope 1 line per
    line spacing), not in steps of 1/subsamples of a line (rays on a fixed grid quantised it,
    which biased the registration across the runway)."""
    from hsgeo.simulate.asf_runway import _flight, _render

    scene = RunwayScene()
    true, _, t0 = _flight(scene, 0.0, (0.0, -5.0), 16, (0.0, 0.0, 0.0))
    zeta = np.arange(208.0, 508.0)
    dl = scene.speed_m_s / scene.line_rate_hz
    c = np.linspace(0.0, 2 * dl, 21)
    sums = []
    for i, ci in enumerate(c):

        def step(E, N, ci=ci):
            return np.tile((N > ci).astype(float), (scene.n_channels, 1))

        ones = np.ones((scene.n_channels, zeta.size))
        img, _ = _render(scene, step, true, np.arange(16), zeta, t0, ones, np.random.default_rng(i))
        sums.append(img[0].sum(axis=0).mean())
    sums = np.array(sums)
    slope, icpt = np.polyfit(c, sums, 1)
    assert slope == pytest.approx(-1 / dl, rel=0.03)
    assert np.max(np.abs(sums - (icpt + slope * c))) < 0.06


@pytest.mark.slow
def test_registration_shift_agrees_with_the_truth_over_seeds():
    """The landmark registration against the true offset of the navigation errors, over 10
    seeds: z = (shift − truth)/σ̂ has mean within ±1 in E and N, |z| ≤ 3 in all seeds but at
    most one (before the footprint's rays were jittered, z across the runway was ≈ −4 in every
    seed)."""
    from hsgeo.workflows.asf import register

    z = []
    for seed in range(10):
        obs, tr, gc, ga = _flights(seed)
        r = register(gc, ga, obs.runway_polygon_m)
        z.append((r.shift_m - tr.shift_m) / r.sigma_m)
    z = np.array(z)
    assert np.all(np.abs(z.mean(axis=0)) < 1.0), z
    assert np.all(np.sum(np.abs(z) > 3, axis=0) <= 1), z


def test_georegister_scan_uses_the_scans_own_geometry():
    """The scan's sensor and trajectory, as the explicit call; other values keep the geometry."""
    from hsgeo.reproduce.asf import georegister_scan

    obs, _, _, _ = _flights(3)
    s = obs.along
    g = georegister_scan(s)
    ref = georegister(s.values, s.zeta_px, s.t0_s, s.line_rate_hz, s.sensor, s.trajectory)
    np.testing.assert_array_equal(g.E_m, ref.E_m)
    np.testing.assert_array_equal(g.N_m, ref.N_m)
    np.testing.assert_array_equal(g.values, s.values)
    g2 = georegister_scan(s, values=2 * s.values)
    np.testing.assert_array_equal(g2.values, 2 * s.values)
    np.testing.assert_array_equal(g2.E_m, ref.E_m)
    # the ground points lie where the sensor looks: nadir columns under the trajectory
    sm = GroundSampler(g)
    lp = sm.locate(g.E_m[::20, ::50].ravel(), g.N_m[::20, ::50].ravel())
    assert np.all(np.isfinite(lp))


def test_subpixel_features_are_integrated_over_the_footprint():
    """The joints and the centre-line dashes cover exactly their share of a pixel's footprint,
    wherever the footprint sits (the jittered rays would hit a 6 mm joint by chance)."""
    from hsgeo.simulate.asf_runway import _field, _periodic_overlap

    # one joint (6 mm every 5 m) in any window of 5 m, two in 10 m, whatever the phase
    a0 = np.linspace(-7.3, 4.1, 50)
    np.testing.assert_allclose(_periodic_overlap(a0, a0 + 5.0, 0.4, 5.0, 0.006), 0.006)
    np.testing.assert_allclose(_periodic_overlap(a0, a0 + 10.0, 0.4, 5.0, 0.006), 0.012)
    # a window inside one dash (30 m of 50) is all paint, inside a gap none
    assert _periodic_overlap(np.array([1.0]), np.array([2.0]), 0.0, 50.0, 30.0)[0] == 1.0
    assert _periodic_overlap(np.array([31.0]), np.array([32.0]), 0.0, 50.0, 30.0)[0] == 0.0
    scene = RunwayScene()
    f = _field(scene, np.random.default_rng(0))
    E = np.linspace(-100, 100, 40001)
    paint, joint = f.subpixel(E, np.zeros_like(E), np.full(E.size, 0.63), np.full(E.size, 0.63))
    # along the centre line, the mean shares: the dashes' duty cycle × the pixel inside the line,
    # and the joints' width per spacing
    assert paint.mean() == pytest.approx(0.6 * min(0.9 / 0.63, 1.0), rel=0.02)
    assert joint.mean() == pytest.approx(scene.joint_width_m / scene.joint_spacing_m, rel=0.02)
    far = f.subpixel(E, np.full(E.size, 40.0), np.full(E.size, 0.63), np.full(E.size, 0.63))
    assert np.all(far[0] == 0) and np.all(far[1] == 0)  # off the runway: grass
