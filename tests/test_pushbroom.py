import dataclasses

import numpy as np
import pytest
from priors import campaign_prior

from hsgeo import InputError
from hsgeo.adjust import adjust, identifiability
from hsgeo.adjust.checks import analytic_jacobian, check_jacobian
from hsgeo.sensors.pushbroom import PushbroomLines, PushbroomObservations
from hsgeo.simulate.pushbroom_campaign import simulate
from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig, CampaignObservations
from hsgeo.stats import nmad
from hsgeo.workflows.pushbroom_ba import build_problem

CFG = CampaignConfig()


def _problem(obs, with_gcp=True, node_interval_s=10.0, y_as_time=False):
    cam = campaign_prior(x0_mm=CFG.x0_mm, lever_arm_m=tuple(obs.lever_arm_m))
    return build_problem(
        obs.lines,
        obs.n_points,
        cam,
        node_interval_s=node_interval_s,
        t_span_s=obs.t_span_s,
        node_prior_mean=obs.node_prior_mean,
        gcp_index=obs.gcp_index if with_gcp else None,
        gcp_xyz_m=obs.gcp_xyz_m if with_gcp else None,
        y_as_time=y_as_time,
    )


@pytest.fixture(scope="module")
def tiny():
    return simulate(0.001, rng=3)


#: What a simulation knows and an adjustment must not see.
TRUTH_ONLY = {
    "outlier",
    "xy_true_px",
    "strip",
    "strips",
    "truth",
    "values",
    "nodes",
    "cp_index",
    "node_err",
    "cfg",
    "scale",
}


def test_observations_are_frozen_and_truth_free(tiny):
    obs, truth = tiny
    for o in (obs, obs.lines):
        assert dataclasses.is_dataclass(o) and o.__dataclass_params__.frozen
        names = {f.name for f in dataclasses.fields(o)}
        assert not names & TRUTH_ONLY, names & TRUTH_ONLY
        with pytest.raises(dataclasses.FrozenInstanceError):
            o.n_points = 0
    assert {f.name for f in dataclasses.fields(obs.lines)} == {
        "point",
        "band",
        "t_s",
        "xy_px",
        "xyz_nav_m",
        "rpy_nav_rad",
        "xyz_rate_nav_m_s",
        "rpy_rate_nav_rad_s",
    }
    # the truth-only quantities are on the truth side, and differ from what was observed
    assert truth.__dataclass_params__.frozen
    assert truth.outlier.shape == (obs.lines.n,) and truth.outlier.any()
    assert not np.array_equal(obs.lines.xy_px, truth.xy_true_px)
    with pytest.raises(TypeError):
        truth.values["c_mm"] = 0.0  # read-only mapping


def test_observations_validate_shapes(tiny):
    o = tiny[0].lines
    with pytest.raises(InputError, match="xy_px has shape"):
        dataclasses.replace(o, xy_px=o.xy_px[:-1])
    with pytest.raises(InputError, match="both GNSS/INS rates"):
        dataclasses.replace(o, rpy_rate_nav_rad_s=None)
    with pytest.raises(InputError, match="non-negative integers"):
        dataclasses.replace(o, band=o.band.astype(float))
    with pytest.raises(InputError, match="PushbroomObservations"):
        build_problem(dataclasses.asdict(o), tiny[0].n_points, campaign_prior(7))


@pytest.mark.parametrize("y_as_time", [False, True])
def test_model_is_exact_at_truth_noise_free(y_as_time):
    obs, truth = simulate(0.001, rng=5, noise_free=True, trajectory_error="spline")
    _, blocks, _ = _problem(obs, y_as_time=y_as_time)
    r, _ = blocks[0].evaluate(truth.values, False)
    assert np.max(np.abs(r)) < 1e-9


@pytest.mark.parametrize(
    "name,step",
    [
        ("points_m", 1e-3),
        ("boresight_rad", 1e-7),
        ("lever_arm_m", 1e-4),
        ("distortion", [1e-7, 1e-9, 1e-7, 1e-7]),
        ("c_mm", 1e-5),
    ],
)
@pytest.mark.parametrize("y_as_time", [False, True])
def test_jacobians_against_finite_differences(tiny, name, step, y_as_time):
    _, blocks, _ = _problem(tiny[0], y_as_time=y_as_time)
    vals = dict(tiny[1].values)
    # away from zero corrections (1 cm, 0.1 mrad: the crossing time stays within T_MAX)
    vals["nodes"] = vals["nodes"] + np.r_[0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4]
    assert check_jacobian(blocks[0], vals, name, step) < 1e-6


@pytest.mark.parametrize("y_as_time", [False, True])
def test_node_jacobian_against_finite_differences(tiny, y_as_time):
    """Every correction of the nodes that the first observations touch."""
    _, blocks, _ = _problem(tiny[0], y_as_time=y_as_time)
    b = blocks[0]
    vals = dict(tiny[1].values)
    vals["nodes"] = vals["nodes"] + np.r_[0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4]
    A = analytic_jacobian(b, vals, "nodes")
    nodes = np.unique(b._basis[0][:3])
    # the time residual divides by a difference over 1 ms: larger steps keep its round-off
    # (~1e-11 px) small against the step
    steps = [1e-3] * 3 + [1e-6] * 3 if y_as_time else [1e-4] * 3 + [1e-7] * 3
    for j in nodes:
        for k, h in enumerate(steps):
            vp, vm = dict(vals), dict(vals)
            vp["nodes"], vm["nodes"] = vals["nodes"].copy(), vals["nodes"].copy()
            vp["nodes"][j, k] += h
            vm["nodes"][j, k] -= h
            num = (b.evaluate(vp, False)[0] - b.evaluate(vm, False)[0]) / (2 * h)
            col = A[:, j * 6 + k]
            tol = 1e-5 if y_as_time else 1e-6
            assert np.max(np.abs(col - num)) <= tol * max(np.max(np.abs(num)), 1e-12)


def _time_shifted(obs: CampaignObservations, a_s):
    """Every noise-free observation twice, attributed to the lines at t + a and t − a.

    The image coordinates stay those of time t; the navigation pose moves with its rates. This
    is an observation error purely in time, exactly symmetric: an unbiased model must return
    the truth (up to O(a³)), whatever the size of σ̂.
    """
    o = obs.lines
    m = o.n
    sgn = np.r_[np.ones(m), -np.ones(m)]

    def two(x):
        return np.concatenate([x, x])

    vel, rate = two(o.xyz_rate_nav_m_s), two(o.rpy_rate_nav_rad_s)
    lines = PushbroomObservations(
        point=two(o.point),
        band=two(o.band),
        t_s=two(o.t_s) + a_s * sgn,
        xy_px=two(o.xy_px),
        xyz_nav_m=two(o.xyz_nav_m) + a_s * sgn[:, None] * vel,
        rpy_nav_rad=two(o.rpy_nav_rad) + a_s * sgn[:, None] * rate,
        xyz_rate_nav_m_s=vel,
        rpy_rate_nav_rad_s=rate,
    )
    return dataclasses.replace(obs, lines=lines)


@pytest.mark.parametrize("y_as_time", [True, False])
def test_symmetric_time_errors_do_not_bias(y_as_time):
    """The regression test of the pitch bias at full size (issue: z std of pitch ≈ 3).

    A time error of ±half a line (≈ ±0.55 px across the line) on every observation: with the
    residual as a time the estimate is the truth; the image y of 002 eq. (2) (and the former
    depth-scaled y) is biased by a fixed amount, which at full size (σ̂ 10× smaller than here)
    is several σ̂.
    """
    obs, truth = simulate(0.005, rng=2, noise_free=True, trajectory_error="spline")
    p, blocks, _ = _problem(_time_shifted(obs, 2.5e-3), y_as_time=y_as_time)
    res = adjust(p, blocks, ftol=1e-12)
    zn = (res.value("nodes") - truth.values["nodes"]) / res.sigma("nodes")
    zc = np.concatenate(
        [
            (res.value(k) - truth.values[k]) / res.sigma(k)
            for k in ["boresight_rad", "lever_arm_m", "distortion", "c_mm"]
        ]
    )
    if y_as_time:
        assert np.max(np.abs(zn)) < 0.01 and np.max(np.abs(zc)) < 0.01
    else:  # the probe is sensitive: the image form shows its bias
        assert np.max(np.abs(zc)) > 0.2


def test_noise_free_recovers_truth():
    obs, truth = simulate(0.001, rng=11, noise_free=True, trajectory_error="spline")
    p, blocks, _ = _problem(obs, y_as_time=True)
    assert identifiability(p, blocks).full_rank
    res = adjust(p, blocks, ftol=1e-15)
    for k, v in truth.values.items():
        np.testing.assert_allclose(res.value(k), v, rtol=0, atol=1e-7, err_msg=k)


@pytest.mark.parametrize("trajectory_error", ["spline", "gauss-markov"])
def test_truth_within_3_sigma_small_scale(trajectory_error):
    obs, truth = simulate(0.01, rng=0, trajectory_error=trajectory_error)
    p, blocks, _ = _problem(obs, y_as_time=True)
    res = adjust(p, blocks, reject_k=5.0, reject_every_iteration=True)
    for k in ["boresight_rad", "lever_arm_m", "distortion", "c_mm"]:
        z = (res.value(k) - truth.values[k]) / res.sigma(k)
        assert np.max(np.abs(z)) < 3.5, (k, z)  # 17 values: family-wise ≈ 1 % false alarms
    z = (res.value("nodes") - truth.values["nodes"]) / res.sigma("nodes")
    if trajectory_error == "spline":
        # the estimator's own model: ~1,000 node corrections with an exact truth; a few
        # |z| > 3 are expected (0.27 %), so assert the coverage and the spread of z
        assert np.mean(np.abs(z) < 3) >= 0.99
        assert 0.8 <= np.std(z) <= 1.2, np.std(z, axis=0)
    else:
        # Gauss–Markov truth: no exact node values. The roll and pitch corrections of the nodes
        # that observations touch (the ones the images see) follow the best spline fit of the
        # true error over the strips: measured at this size (seed 0) correlations 0.73 and 0.81,
        # |z| < 3 for 97 % and 96 % (the part of the error the spline cannot represent is in
        # the residuals, so σ̂ is somewhat optimistic)
        seen = np.unique(truth.nodes.basis(obs.lines.t_s)[0][:, 1:3])
        fit, est = truth.values["nodes"][seen, 3:5], res.value("nodes")[seen, 3:5]
        for j in range(2):
            assert np.corrcoef(est[:, j], fit[:, j])[0, 1] > 0.5
        assert np.mean(np.abs(z[seen, 3:5]) < 3) >= 0.85
    r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
    assert np.all((nmad(r, axis=0) > 0.2) & (nmad(r, axis=0) < 0.5))
    cp = res.value("points_m")[truth.cp_index] - truth.values["points_m"][truth.cp_index]
    assert np.all(nmad(cp[:, :2], axis=0) < 0.15)  # half the 0.3 m GSD
    # most simulated gross errors are found
    assert np.mean(res.outliers(0)[truth.outlier]) > 0.75  # 3 px ones can hide


def test_bad_input(tiny):
    o = tiny[0].lines
    _, blocks, nodes = _problem(tiny[0])
    with pytest.raises(InputError, match="shape"):
        PushbroomLines(
            o.point, o.band[:-1], o.t_s, o.xy_px, o.xyz_nav_m, o.rpy_nav_rad, nodes, 0.0065
        )
    with pytest.raises(InputError, match="pixel pitch"):
        PushbroomLines(o.point, o.band, o.t_s, o.xy_px, o.xyz_nav_m, o.rpy_nav_rad, nodes, 0.0)
    with pytest.raises(InputError, match="scale"):
        simulate(0.0)
    point = o.point.copy()
    point[point == 5] = 6  # point 5 unobserved
    with pytest.raises(InputError, match="fewer than two"):
        build_problem(dataclasses.replace(o, point=point), tiny[0].n_points, campaign_prior(7))


def test_same_seed_same_bits():
    (a, ta), (b, tb) = simulate(0.001, rng=7), simulate(0.001, rng=7)
    assert np.array_equal(a.lines.xy_px, b.lines.xy_px)
    assert np.array_equal(ta.values["nodes"], tb.values["nodes"])


def test_compiled_schur_equals_generic_on_pushbroom(tiny):
    from hsgeo.adjust import SolverOptions
    from hsgeo.adjust.schur import _normal, _reduced
    from hsgeo.adjust.system import _evaluate, _Layout

    p, blocks, _ = _problem(tiny[0])
    lay = _Layout(p)
    sy = _evaluate(lay, blocks, [np.ones(b.m, bool) for b in blocks], True)
    got = {}
    for compiled in (True, False):
        ne = _normal(lay, sy, SolverOptions(compiled=compiled))
        S, rhs, _, _ = _reduced(lay, ne, 1e-4)
        got[compiled] = (S, rhs)
    for a, b in zip(got[True], got[False], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.max(np.abs(b)))


def test_point_covariance_subset_equals_all(tiny):
    p, blocks, _ = _problem(tiny[0])
    res = adjust(p, blocks, reject_k=5.0, keep_jacobian=True)
    cp_index = tiny[1].cp_index
    sub = res.point_covariance(index=cp_index)
    full = res.point_covariance()[cp_index]
    np.testing.assert_allclose(sub, full, rtol=1e-12)


def test_time_residual_is_the_crossing_time_by_bisection(tiny):
    """The compiled time residual against the crossing time found by bisection with numpy."""
    from hsgeo.sensors.pushbroom import project

    _, blocks, nodes = _problem(tiny[0], y_as_time=True)
    b = blocks[0]
    vals = dict(tiny[1].values)
    vals["nodes"] = vals["nodes"] + 0.002
    vals["boresight_rad"] = vals["boresight_rad"] + 1e-4
    r, _ = b.evaluate(vals, False)
    o = tiny[0].lines
    k = 1.0 / b.pixel_mm

    def xy_at(dt):
        t = o.t_s + dt
        xyz = o.xyz_nav_m + dt[:, None] * o.xyz_rate_nav_m_s
        rpy = o.rpy_nav_rad + dt[:, None] * o.rpy_rate_nav_rad_s
        xy, _ = project(
            vals, b.blocks, nodes, t, xyz, rpy, b.point, b.band, b.beta0, b.x0_mm, b.y0_mm
        )
        return xy * k - b.xy_px

    lo, hi = np.full(b.point.size, -0.25), np.full(b.point.size, 0.25)
    assert np.all(xy_at(lo)[:, 1] < 0) and np.all(xy_at(hi)[:, 1] > 0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        neg = xy_at(mid)[:, 1] < 0
        lo, hi = np.where(neg, mid, lo), np.where(neg, hi, mid)
    t_star = 0.5 * (lo + hi)
    # same spline piece as the line time (the model continues the piece of t_e)
    same = nodes.basis(o.t_s + t_star)[0][:, 0] == nodes.basis(o.t_s)[0][:, 0]
    assert same.mean() > 0.95
    np.testing.assert_allclose(r[1::2][same], -b.y_rate_ref_px_s * t_star[same], atol=1e-6)
    np.testing.assert_allclose(r[0::2][same], xy_at(t_star)[same, 0], atol=1e-6)


def test_compiled_block_equals_numpy_block(tiny):
    _, blocks, _ = _problem(tiny[0], y_as_time=False)
    b = blocks[0]
    vals = dict(tiny[1].values)
    vals["nodes"] = vals["nodes"] + 0.01
    r1, j1 = b.evaluate(vals, True)
    r2, j2 = b.evaluate_numpy(vals, True)
    np.testing.assert_allclose(r1, r2, rtol=0, atol=1e-9)
    for k in j2:
        a, c = j1[k], j2[k]
        if hasattr(c, "d"):
            a = a.expanded()  # the compiled block returns the node Jacobian factored
            np.testing.assert_array_equal(a.index, c.index)
            a, c = a.d, c.d
        np.testing.assert_allclose(a, c, rtol=1e-9, atol=1e-9 * np.max(np.abs(c)), err_msg=k)


@pytest.mark.parametrize("lam", [0.0, 1e-3])
@pytest.mark.parametrize("fix_node", [False, True])
def test_factored_node_jacobian_compiled_equals_generic(tiny, lam, fix_node):
    """The compiled path's factored spline Jacobian forms the same normal equations as scipy.

    ``fix_node`` fixes one node entry, which makes the engine expand the factored Jacobian
    into ordinary slots (non-contiguous columns). The x and y rows have different σ, so that
    each row's whitening weight is its own (the compiled kernel whitens the pair's two rows in
    one step).
    """
    from hsgeo.adjust import SolverOptions
    from hsgeo.adjust.schur import _normal, _reduced, _step
    from hsgeo.adjust.system import _evaluate, _Layout

    p, blocks, _ = _problem(tiny[0], y_as_time=True)
    m = blocks[0].m
    blocks[0].sigma = np.where(np.arange(m) % 2 == 0, 0.5, 0.8) * (1 + np.arange(m) / m)
    if fix_node:
        p.fix("nodes", index=(3, 4))
    lay = _Layout(p)
    out = {}
    for compiled in (True, False):
        sy = _evaluate(lay, blocks, [np.ones(b.m, bool) for b in blocks], True, compiled=compiled)
        assert (sy.Jrc.fcol.shape[1] == 4) == (compiled and not fix_node)
        ne = _normal(lay, sy, SolverOptions(compiled=compiled))
        S_, rhs, _, _ = _reduced(lay, ne, lam)
        dc, dp = _step(lay, ne, lam)
        out[compiled] = (S_, rhs, dc, dp, ne.Ncc)
    for a, b in zip(out[True], out[False], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.max(np.abs(b)))


def test_time_residual_needs_rates_and_reference(tiny):
    o = tiny[0].lines
    _, _, nodes = _problem(tiny[0])
    args = (o.point, o.band, o.t_s, o.xy_px, o.xyz_nav_m, o.rpy_nav_rad, nodes, 0.0065)
    with pytest.raises(InputError, match="both"):
        PushbroomLines(*args, xyz_rate_m_s=o.xyz_rate_nav_m_s)
    with pytest.raises(InputError, match="y_rate_ref_px_s"):
        PushbroomLines(*args, xyz_rate_m_s=o.xyz_rate_nav_m_s, rpy_rate_rad_s=o.rpy_rate_nav_rad_s)
    with pytest.raises(InputError, match="shape"):
        PushbroomLines(
            *args,
            xyz_rate_m_s=o.xyz_rate_nav_m_s[:-1],
            rpy_rate_rad_s=o.rpy_rate_nav_rad_s,
            y_rate_ref_px_s=220.0,
        )
    no_rates = dataclasses.replace(o, xyz_rate_nav_m_s=None, rpy_rate_nav_rad_s=None)
    with pytest.raises(InputError, match="rates"):
        build_problem(no_rates, tiny[0].n_points, campaign_prior(7), y_as_time=True)


@pytest.mark.parametrize("trajectory_error", ["spline", "gauss-markov"])
def test_simulated_navigation_rates_are_the_derivative_of_the_poses(trajectory_error):
    """The simulator's GNSS/INS rates against central differences of its poses."""
    from hsgeo.simulate import pushbroom_campaign as pc

    obs, truth = simulate(0.001, rng=1, trajectory_error=trajectory_error)
    o, cfg, h = obs.lines, truth.cfg, 1e-5
    poses = []
    for dt in (h, -h):
        t = o.t_s + dt
        xyz, rpy = pc._true_pose(truth.strips, truth.strip, t, cfg.mount_motion_rad, cfg.speed_m_s)
        d = truth.nav_error(t)
        poses.append((xyz - d[:, :3], rpy - d[:, 3:]))
    np.testing.assert_allclose(o.xyz_rate_nav_m_s, (poses[0][0] - poses[1][0]) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(
        o.rpy_rate_nav_rad_s, (poses[0][1] - poses[1][1]) / (2 * h), atol=1e-9
    )


def test_crossing_time_held_at_the_bound_is_a_fixed_point(tiny):
    """An observation whose crossing time is held at ±T_MAX stops its Newton there (a further
    pass would evaluate at the same time): its residuals equal those of an evaluation started
    at the bound, and the other observations' equal those of a start at their crossing time.
    """
    from hsgeo.sensors._pushbroom_kernel import T_MAX

    _, blocks, _ = _problem(tiny[0], y_as_time=True)
    vals = dict(tiny[1].values)
    pts = np.array(vals["points_m"], dtype=float)
    pts[::3, 1] += 40.0  # a third of the points 40 m along track: their times run to the bound
    vals["points_m"] = pts
    a = blocks[0].fresh()
    r_a, _ = a.evaluate(vals, False)
    held = np.abs(a._dt_s) >= T_MAX
    assert 0 < held.mean() < 1  # the case is exercised
    b = blocks[0].fresh()
    b._dt_s[:] = a._dt_s
    r_b, _ = b.evaluate(vals, False)
    rows = np.repeat(held, 2)
    np.testing.assert_array_equal(r_a[rows], r_b[rows])
    np.testing.assert_array_equal(b._dt_s[held], a._dt_s[held])
    np.testing.assert_allclose(r_a[~rows], r_b[~rows], rtol=0, atol=1e-9)


def test_trial_residuals_stop_the_newton_earlier_within_its_error(tiny):
    """``trial_residuals`` stops the crossing time's Newton at a correction below TRIAL_TOL_S:
    a small step from the last crossing times is one pass where ``evaluate`` takes two, and
    its residuals differ from the converged ones by the second-order remainder only.
    """
    from hsgeo.sensors._pushbroom_kernel import NEWTON_TOL_S, TRIAL_TOL_S

    _, blocks, _ = _problem(tiny[0], y_as_time=True)
    vals = dict(tiny[1].values)
    a = blocks[0].fresh()
    a.evaluate(vals, True)  # the crossing times at the truth
    b = blocks[0].fresh()
    b._dt_s[:] = a._dt_s
    step = dict(vals)
    step["points_m"] = np.asarray(vals["points_m"], dtype=float) + np.array([0.0, 0.005, 0.0])
    start = a._dt_s.copy()
    r_exact, _ = a.evaluate(step, False)
    r_trial = b.trial_residuals(step)
    moved = np.abs(a._dt_s - start)
    assert np.all((moved > NEWTON_TOL_S) & (moved < TRIAL_TOL_S))  # one pass in the trial
    assert not np.array_equal(r_trial, r_exact)
    # the remainder ½ ÿ e², e < 1e-4 s: far below a micro-pixel
    np.testing.assert_allclose(r_trial, r_exact, rtol=0, atol=1e-6)
    # the corrected times: where evaluate's second pass would start, within its tolerance
    np.testing.assert_allclose(b._dt_s, a._dt_s, rtol=0, atol=NEWTON_TOL_S)


def test_start_trial_starts_the_newton_at_the_predicted_crossing_times(tiny):
    """``start_trial`` moves each crossing time's Newton start from the linearisation's time
    by ``−Δr_y / ẏ_ref``: given the step's exact change of the time residuals, the start is the
    step's converged crossing time; a predicted move above TRIAL_PREDICTION_MAX_S, a row left
    out (NaN) and a time held at ±T_MAX keep the start where the last evaluation ended.
    """
    from hsgeo.sensors._pushbroom_kernel import NEWTON_TOL_S, T_MAX, TRIAL_PREDICTION_MAX_S

    _, blocks, _ = _problem(tiny[0], y_as_time=True)
    vals = dict(tiny[1].values)
    a = blocks[0].fresh()
    r_lin, _ = a.evaluate(vals, True)  # the linearisation: its crossing times kept
    at_lin = a._dt_s.copy()
    step = dict(vals)
    step["points_m"] = np.asarray(vals["points_m"], dtype=float) + np.array([0.0, 0.3, 0.0])
    b = blocks[0].fresh()
    b._dt_s[:] = a._dt_s
    r_step, _ = b.evaluate(step, False)  # converged at the step
    change = r_step - r_lin
    m = a.point.size
    change[1] = np.nan  # observation 0: a row left out
    change[3] = -a.y_rate_ref_px_s * 2 * TRIAL_PREDICTION_MAX_S  # observation 1: too far
    a._dt_s[:] = 0.123  # where a refused trial ended
    a._dt_lin_s[2] = T_MAX  # observation 2: held at the bound
    a.start_trial(change)
    kept = np.arange(m) >= 3
    assert np.all(np.abs(b._dt_s - at_lin)[kept] > 10 * NEWTON_TOL_S)  # the step moved them
    np.testing.assert_allclose(a._dt_s[kept], b._dt_s[kept], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a._dt_s[:3], 0.123)


def test_take_selects_every_column_alike(tiny):
    lines = tiny[0].lines
    rows = np.array([5, 0, 3])
    sub = lines.take(rows)
    assert sub.n == 3 and sub.has_rates == lines.has_rates
    for name in ("point", "band", "t_s", "xy_px", "xyz_nav_m", "rpy_nav_rad", "xyz_rate_nav_m_s"):
        np.testing.assert_array_equal(getattr(sub, name), getattr(lines, name)[rows])
    mask = np.zeros(lines.n, bool)
    mask[rows] = True
    np.testing.assert_array_equal(lines.take(mask).point, lines.point[np.sort(rows)])
    with pytest.raises(InputError, match="mask"):
        lines.take(mask[:-1])


def test_adjustment_does_not_depend_on_the_order_of_the_rows(tiny):
    """The initial points come from each point's rays chosen by their directions, not by their
    rows: the observation table in another order gives the same initial points, bit for bit,
    and the same adjustment (when it was each point's first row, the paper-size campaign in a
    random order rejected 2 more residual rows and ended with points up to 84 m apart)."""
    from hsgeo.workflows.pushbroom_ba import solve

    obs = tiny[0]
    lines = obs.lines
    shuffled = lines.take(np.random.default_rng(5).permutation(lines.n))
    np.testing.assert_array_equal(np.sort(shuffled.t_s), np.sort(lines.t_s))
    runs = []
    for o in (obs, dataclasses.replace(obs, lines=shuffled)):
        p, blocks, _ = _problem(o, y_as_time=True)
        P0 = p.values()["points_m"].copy()
        res = solve(p, blocks)
        runs.append((P0, res))
    (P0a, a), (P0b, b) = runs
    np.testing.assert_array_equal(P0a, P0b)
    assert a.n_observations == b.n_observations
    np.testing.assert_allclose(a.cost_history[-1], b.cost_history[-1], rtol=1e-9)
    np.testing.assert_allclose(
        a.params.values()["points_m"], b.params.values()["points_m"], rtol=0, atol=1e-6
    )
