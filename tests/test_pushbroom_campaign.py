"""The GNSS/INS error model of the 002 campaign simulator (hsgeo.simulate.pushbroom_campaign)."""

import json
from pathlib import Path

import numpy as np
import pytest
from fingerprint import arrays, assert_same, fingerprint

from hsgeo import InputError
from hsgeo.simulate.error_processes import RIDGE, gauss_markov, spline_fit
from hsgeo.simulate.pushbroom_campaign import simulate
from hsgeo.trajectory import SplineNodes


def test_gauss_markov_is_the_exact_first_order_recursion():
    """Regressing x[k+1] on x[k] gives φ = exp(−Δt/τ) and the innovation σ√(1−φ²); the
    stationary variance is σ² (the theory of the continuous process, sampled exactly)."""
    dt, tau, sig = 0.1, np.array([0.5, 5.0]), np.array([2.0, 0.01])
    x = gauss_markov(200_000, dt, tau, sig, rng=1)
    phi = np.exp(-dt / tau)
    for j in range(2):
        a, b = x[:-1, j], x[1:, j]
        slope = a @ b / (a @ a)
        n_eff = x.shape[0] * (1 - phi[j]) / (1 + phi[j])  # independent samples for the variance
        assert abs(slope - phi[j]) < 4 * np.sqrt((1 - phi[j] ** 2) / x.shape[0])
        innov = np.std(b - phi[j] * a)
        assert abs(innov / (sig[j] * np.sqrt(1 - phi[j] ** 2)) - 1) < 0.01
        assert abs(np.var(x[:, j]) / sig[j] ** 2 - 1) < 4 * np.sqrt(2 / n_eff)
    # stationary from the first sample: the first values have the same spread as the rest
    starts = np.array([gauss_markov(1, dt, [30.0], [1.0], rng=s)[0, 0] for s in range(2000)])
    assert abs(np.std(starts) - 1) < 0.05
    with pytest.raises(InputError, match="positive"):
        gauss_markov(10, dt, [0.0], [1.0], rng=0)


def test_spline_fit_equals_a_dense_least_squares_solution():
    """Against numpy's lstsq on the design matrix built column by column from
    SplineNodes.evaluate (unit node values), with the documented ridge rows appended."""
    nodes = SplineNodes(0.0, 95.0, 10.0)
    t = np.arange(0.0, 95.0, 0.1)
    rng = np.random.default_rng(0)
    v = np.column_stack([np.sin(t / 7.0), rng.standard_normal(t.size)])
    A = np.column_stack(
        [nodes.evaluate(np.eye(nodes.n_nodes)[:, [j]], t)[:, 0] for j in range(nodes.n_nodes)]
    )
    Aa = np.vstack([A, np.sqrt(RIDGE) * np.eye(nodes.n_nodes)])
    ref = np.linalg.lstsq(Aa, np.vstack([v, np.zeros((nodes.n_nodes, 2))]), rcond=None)[0]
    np.testing.assert_allclose(spline_fit(nodes, t, v), ref, atol=1e-10)
    # a spline is fitted by itself (up to the ridge)
    c = rng.standard_normal((nodes.n_nodes, 1))
    got = spline_fit(nodes, t, nodes.evaluate(c, t))
    np.testing.assert_allclose(got[3:-3], c[3:-3], atol=0.05 * np.abs(c).max())


def test_default_truth_is_gauss_markov_not_the_estimators_spline():
    obs, truth = simulate(0.001, rng=3)
    assert truth.trajectory_error == "gauss-markov"
    t = obs.lines.t_s
    err = truth.nav_error(t)
    fit = truth.nodes.evaluate(truth.values["nodes"], t)
    # the attitude error has structure the 10 s spline cannot follow (τ = 20 s roll, pitch)
    resid = np.std(err[:, 3:5] - fit[:, 3:5], axis=0) / np.std(err[:, 3:5], axis=0)
    assert np.all(resid > 0.1), resid
    # while the spline truth is the spline exactly
    obs_s, truth_s = simulate(0.001, rng=3, trajectory_error="spline")
    e_s = truth_s.nav_error(obs_s.lines.t_s)
    f_s = truth_s.nodes.evaluate(truth_s.values["nodes"], obs_s.lines.t_s)
    np.testing.assert_allclose(e_s, f_s, atol=1e-15)


def test_error_model_options():
    with pytest.raises(InputError, match="trajectory_error must be one of"):
        simulate(0.001, rng=0, trajectory_error="random-walk")
    with pytest.raises(InputError, match="noise_free=True needs trajectory_error='spline'"):
        simulate(0.001, rng=0, noise_free=True)


def test_refraction_moves_image_points_radially_by_the_standard_amount():
    """K of the ARDC model at H = 1.965 km, h = 0.09 km, by hand from the formula:
    2410·1.965/(1.965² − 6·1.965 + 250) − 2410·0.09²/((0.09² − 6·0.09 + 250)·1.965) = 19.52 µrad;
    the image point moves outward by K(r + r³/c²): ≤ 0.02 px at the line's end (5.85 mm)."""
    from dataclasses import replace

    from hsgeo.simulate.error_processes import refraction_k
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    assert abs(refraction_k(1965.0, 90.0) * 1e6 - 19.52) < 0.01
    cfg = CampaignConfig()
    (o0, t0), (o1, t1) = (
        simulate(0.001, rng=3),
        simulate(0.001, rng=3, cfg=replace(cfg, refraction=True)),
    )
    np.testing.assert_array_equal(o0.lines.t_s, o1.lines.t_s)  # same draws otherwise
    dx = t1.xy_true_px[:, 0] - t0.xy_true_px[:, 0]
    x = t0.xy_true_px[:, 0] - cfg.x0_mm / cfg.pixel_mm
    assert np.all(np.sign(dx[np.abs(x) > 50]) == np.sign(x[np.abs(x) > 50]))  # outward
    assert 0.01 < np.max(np.abs(dx)) < 0.03


def test_reference_squares_measured_by_their_centre():
    from dataclasses import replace

    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    cfg = CampaignConfig()
    (o0, _), (o1, t1) = (
        simulate(0.001, rng=4),
        simulate(0.001, rng=4, cfg=replace(cfg, sigma_ref_image_px=0.5)),
    )
    ref = o1.lines.point < 17
    np.testing.assert_array_equal(o0.lines.xy_px[~ref], o1.lines.xy_px[~ref])  # tie points
    assert not np.array_equal(o0.lines.xy_px[ref], o1.lines.xy_px[ref])
    good = ref & ~t1.outlier
    err = o1.lines.xy_px[good, 0] - t1.xy_true_px[good, 0]
    # N(0, 0.5²) then registered at the pixel centre: σ = √(0.25 + 1/12) ≈ 0.58 px
    assert 0.4 < np.std(err) < 0.75, np.std(err)


def test_check_points_see_as_many_strips_as_tie_points():
    """002 §4: the CPs are "tie points with known coordinates" (issue 22): by default they get
    a tie point's ray count; cp_rays="all strips" keeps every covering strip (the GCPs always)."""
    from dataclasses import replace

    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    cfg = CampaignConfig()
    counts = {}
    for mode in ("tie points", "all strips"):
        obs, truth = simulate(0.01, rng=2, cfg=replace(cfg, cp_rays=mode))
        n = np.bincount(obs.lines.point, minlength=obs.n_points)
        strips = [np.unique(truth.strip[obs.lines.point == i]).size for i in range(17)]
        counts[mode] = (n, strips)
    n_tie, s_tie = counts["tie points"]
    n_all, s_all = counts["all strips"]
    assert n_tie[4:17].min() >= 3 and n_tie[4:17].mean() < 6  # a tie point's 3–6 rays
    assert n_all[4:17].min() >= 10  # every covering strip: 14–20 rays
    np.testing.assert_array_equal(s_tie[:4], s_all[:4])  # the GCPs: every covering strip
    assert n_all[:4].min() >= 10
    with pytest.raises(InputError, match="cp_rays"):
        simulate(0.001, rng=0, cfg=replace(cfg, cp_rays="some"))


def test_distortion_ripple_is_added_along_the_line_only():
    """The unmodelled distortion residual (issue 22) moves x only, by the ripple function, and
    is orthogonal over the line to what the estimator absorbs (1, x, x², x³, x⁵)."""
    from dataclasses import replace

    from hsgeo.simulate.pushbroom_campaign import distortion_ripple_px
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    off = replace(CampaignConfig(), distortion_ripple_px=0.0)
    o0, t0 = simulate(0.002, rng=3, cfg=off)
    on = replace(off, distortion_ripple_px=0.2)
    o1, t1 = simulate(0.002, rng=3, cfg=on)
    d = t1.xy_true_px - t0.xy_true_px
    np.testing.assert_array_equal(d[:, 1], 0.0)
    np.testing.assert_allclose(d[:, 0], distortion_ripple_px(t0.xy_true_px[:, 0], on), atol=1e-12)
    x = np.linspace(-900, 900, 4001)
    r = distortion_ripple_px(x, on)
    u = x / 900
    for n in (0, 1, 2, 3, 5):  # no share of the model's terms (up to the grid's discretisation)
        assert abs(np.mean(r * u**n)) < 2e-3 * np.sqrt(np.mean(r**2)), n
    assert 0.1 < np.max(np.abs(r)) < 0.4  # of the amplitude's size


# Fingerprints (tests/fingerprint.py) of simulate()'s arrays written by main's code at 2366fb0,
# whose simulator is e7c3c51's for scale ≤ 1 (before simulate() accepted scale > 1): the
# chapters' numbers depend on it staying the same. Integer arrays compare exactly, float arrays
# to 1e-9 (a sha256 of float bytes failed on another CPU generation with the same code).
FINGERPRINTS_2366FB0 = json.loads(
    (Path(__file__).parent / "data" / "pushbroom_campaign_2366fb0.json").read_text()
)


#: The options of main at 2366fb0 (issue 22 changed the defaults: a key-point σ per axis, check
#: points seen by as many strips as a tie point, and a distortion ripple).
MAIN_2366FB0 = {
    "sigma_keypoint_px": (0.35, 0.35),
    "cp_rays": "all strips",
    "distortion_ripple_px": 0.0,
}


def _main_cfg():
    from dataclasses import replace

    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    return replace(CampaignConfig(), **MAIN_2366FB0)


@pytest.mark.parametrize("key", sorted(FINGERPRINTS_2366FB0))
def test_former_options_give_the_former_simulation(key):
    scale, seed, noise_free = key.split("-")
    kw = {"noise_free": True, "trajectory_error": "spline"} if noise_free == "True" else {}
    obs, truth = simulate(float(scale), rng=int(seed), cfg=_main_cfg(), **kw)
    assert_same(fingerprint(obs, truth), FINGERPRINTS_2366FB0[key])


def test_chunked_rows_give_the_same_bits(monkeypatch):
    """The simulator's row-wise work in chunks (odd sizes, tails included) is bit-identical."""
    import hsgeo.simulate.pushbroom_campaign as pc

    whole = simulate(0.01, rng=0, cfg=_main_cfg())
    monkeypatch.setattr(pc, "CHUNK_ROWS", 997)
    chunked = simulate(0.01, rng=0, cfg=_main_cfg())
    assert chunked[0].lines.n > 4 * 997
    for name, a in arrays(*whole).items():
        np.testing.assert_array_equal(arrays(*chunked)[name], a, err_msg=name)


def test_long_block_beyond_the_paper():
    """scale > 1: a block scale × 600 m long (north) at the paper's tie-point density, the same
    24 strips lengthened by 600 m · (scale − 1), the same per-point statistics (002 §4)."""
    from dataclasses import replace

    from hsgeo.simulate.pushbroom_campaign import block_length_m
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    cfg0 = CampaignConfig()
    cfg = replace(cfg0, n_tie_points_full=4000)  # few tie points: fast, same geometry
    scale = 2.5
    obs, truth = simulate(scale, rng=1, cfg=cfg)
    assert block_length_m(cfg, scale) == 1500.0 and block_length_m(cfg, 0.3) == 600.0
    tie = truth.values["points_m"][17:]
    assert obs.n_points == 17 + round(4000 * scale)
    assert np.all(np.abs(tie[:, 0]) <= 300) and np.all(np.abs(tie[:, 1]) <= 750)
    assert np.max(tie[:, 1]) > 740 and np.min(tie[:, 1]) < -740  # uniform over the long block
    # the reference squares stay in the central 600 m
    assert np.all(np.abs(truth.values["points_m"][:17, :2]) < 300)
    # 24 strips, each 2 · 480 m + 600 m · 1.5 long, turns of 60 s between them
    assert len(truth.strips) == 24
    lengths_m = np.array([p[1] - p[0] for p in truth.strips]) * cfg.speed_m_s
    np.testing.assert_allclose(lengths_m, 2 * cfg.strip_half_length_m + 600 * (scale - 1))
    plan = np.array(truth.strips)
    gaps = plan[1:, 0] - plan[:-1, 1]
    np.testing.assert_allclose(gaps, cfg.turn_s)
    # each tie point in ≥ 3 different strips; on average 441587 / 113758 observations (002 §4):
    # 3 + Poisson(0.88), truncated at the strips that cover the point
    pts = obs.lines.point
    n_strips = np.array([np.unique(truth.strip[pts == i]).size for i in range(obs.n_points)])
    n_obs = np.bincount(pts, minlength=obs.n_points)
    assert np.all(n_strips >= 3) and np.array_equal(n_strips, n_obs)
    extra = cfg0.obs_per_point_mean - 3
    assert abs(n_obs[17:].mean() - cfg0.obs_per_point_mean) < 4 * np.sqrt(extra / tie.shape[0])
    assert abs(truth.outlier.mean() - 0.003) < 4 * np.sqrt(0.003 / obs.lines.n)
    # every observation in a strip's imaged time, in a line of 200 Hz
    t0 = np.array([p[0] for p in truth.strips])[truth.strip]
    t1 = np.array([p[1] for p in truth.strips])[truth.strip]
    assert np.all((obs.lines.t_s >= t0) & (obs.lines.t_s <= t1))


def test_long_block_noise_free_is_identifiable_and_recovers_the_truth():
    """A 3× longer block held by 4 GCPs in its central 600 m and the GNSS/INS priors: full rank
    at the truth, and the noise-free adjustment returns the truth (as at scale ≤ 1)."""
    from dataclasses import replace

    from test_pushbroom import _problem

    from hsgeo.adjust import adjust, identifiability
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    cfg = replace(CampaignConfig(), n_tie_points_full=100)
    obs, truth = simulate(3.0, rng=11, noise_free=True, trajectory_error="spline", cfg=cfg)
    assert np.ptp(truth.values["points_m"][:, 1]) > 1700
    p, blocks, _ = _problem(obs, y_as_time=True)
    assert identifiability(p, blocks).full_rank
    res = adjust(p, blocks, ftol=1e-15)
    for k, v in truth.values.items():
        np.testing.assert_allclose(res.value(k), v, rtol=0, atol=1e-7, err_msg=k)


@pytest.mark.parametrize("scale", [0.0, -1.0, float("nan"), float("inf")])
def test_scale_must_be_positive(scale):
    with pytest.raises(InputError, match="scale must be a positive number"):
        simulate(scale, rng=0)
