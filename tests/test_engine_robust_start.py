"""The robust start (``SolverOptions.robust_start``, issue 29) and the time split of a solve:
the losses against their closed forms and finite differences, the IRLS rows against the loss's
own gradient, and the minimum reached against least squares from the start (compiled and
generic paths)."""

import numpy as np
import pytest
from test_engine import _bearing_params, line_data
from toy_models import Bearings, Line, bearing_scene

from hsgeo.adjust import Parameters, SolverOptions, adjust
from hsgeo.adjust.loss import rho, scale, weigh
from hsgeo.errors import InputError


@pytest.mark.parametrize("kind", ["cauchy", "huber"])
def test_loss_derivative_matches_finite_differences_and_closed_form(kind):
    s = np.array([0.01, 0.5, 3.0, 8.99, 9.01, 40.0, 1e4])
    c = 3.0
    r, d = rho(kind, s, c)
    h = 1e-6 * np.maximum(s, 1.0)
    r_p, _ = rho(kind, s + h, c)
    r_m, _ = rho(kind, s - h, c)
    np.testing.assert_allclose(d, (r_p - r_m) / (2 * h), rtol=1e-6)
    if kind == "cauchy":
        np.testing.assert_allclose(r, 9.0 * np.log(1.0 + s / 9.0), rtol=1e-12)
    else:
        expect = np.where(s <= 9.0, s, 6.0 * np.sqrt(s) - 9.0)
        np.testing.assert_allclose(r, expect, rtol=1e-15)
    # small residuals: the loss is least squares
    r0, d0 = rho(kind, np.array([1e-10]), c)
    np.testing.assert_allclose([r0[0], d0[0]], [1e-10, 1.0], rtol=1e-9)


def test_irls_rows_give_the_loss_gradient_and_the_trial_rows_its_cost():
    rng = np.random.default_rng(0)
    rw = rng.standard_normal(40)
    rw[5] = 30.0  # a gross error
    c = scale(rw, 3.0)
    f_lin, total = weigh("cauchy", rw, 2, c, linearise=True)
    f_cost, total2 = weigh("cauchy", rw, 2, c, linearise=False)
    s = (rw.reshape(-1, 2) ** 2).sum(axis=1)
    r, d = rho("cauchy", s, c)
    assert total == pytest.approx(r.sum()) and total2 == pytest.approx(r.sum())
    # ½ d/dr_i Σ ρ(s) = ρ'(s) r_i = f² r_i (the IRLS rows' gradient)
    np.testing.assert_allclose(f_lin**2 * rw, np.repeat(d, 2) * rw, rtol=1e-14)
    np.testing.assert_allclose(np.sum((f_cost * rw) ** 2), r.sum(), rtol=1e-12)
    assert f_lin[5] < 0.2 < 0.9 < np.median(f_lin)  # the gross error's group down-weighted


def test_robust_start_reaches_the_least_squares_minimum_of_a_line():
    t, y = line_data(1)
    y = y.copy()
    y[[3, 11]] += 5.0  # gross errors: the robust start down-weights them, the end is LS
    p = Parameters()
    p.add("ab", [0.0, 0.0], columns=("a", "b"))
    A = np.column_stack([np.ones_like(t), t])
    x, *_ = np.linalg.lstsq(A, y, rcond=None)
    for kind in ("cauchy", "huber"):
        res = adjust(p, Line(t, y, 0.1), robust_start=kind, ftol=1e-15)
        assert res.converged
        np.testing.assert_allclose(res.value("ab"), x, rtol=0, atol=1e-9)
        # the covariance and σ0 are those of least squares (the loss is gone at the end)
        ls = adjust(p, Line(t, y, 0.1))
        np.testing.assert_allclose(res.sigma0, ls.sigma0, rtol=1e-9)
        np.testing.assert_allclose(res.covariance, ls.covariance, rtol=1e-8)


@pytest.mark.parametrize("compiled", [True, False])
def test_robust_start_reaches_the_same_bundle_minimum(compiled):
    S, P, st, pt, th = bearing_scene(4)
    th = th.copy()
    th[[2, 17, 40]] += 0.05  # three gross errors (50 σ)
    p, blk = _bearing_params(S, P, st, pt, th)
    ref = adjust(p, blk, ftol=1e-14, compiled=compiled, keep_jacobian=True)
    rob = adjust(p, blk, ftol=1e-14, compiled=compiled, robust_start="cauchy")
    np.testing.assert_allclose(rob.cost_history[-1], ref.cost_history[-1], rtol=1e-9)
    # the same minimum, by other steps: equal to a small fraction of σ (as test_engine does)
    for name in ("points", "stations"):
        np.testing.assert_array_less(
            np.abs(rob.value(name) - ref.value(name)), 1e-4 * ref.sigma(name) + 1e-12
        )
    # with the rejection in every iteration the robust start finds the gross errors the
    # least-squares start finds
    a = adjust(p, blk, reject_k=5.0, reject_every_iteration=True, compiled=compiled)
    b = adjust(
        p, blk, reject_k=5.0, reject_every_iteration=True, compiled=compiled,
        robust_start="cauchy",
    )  # fmt: skip
    found = [{2, 17, 40} & set(np.flatnonzero(r.outliers(0)).tolist()) for r in (a, b)]
    assert found[1] >= found[0] and len(found[0]) >= 2


def test_seconds_split_adds_up_and_options_are_checked():
    S, P, st, pt, th = bearing_scene(1)
    p, blk = _bearing_params(S, P, st, pt, th)
    res = adjust(p, blk)
    split = res.seconds_split
    assert {"model", "jacobian", "formation", "solve", "other"} <= set(split)
    assert all(v >= 0 for v in split.values())
    np.testing.assert_allclose(sum(split.values()), res.seconds, rtol=1e-6)
    with pytest.raises(InputError, match="robust_start"):
        SolverOptions(robust_start="tukey")
    with pytest.raises(InputError, match="robust_start_k"):
        SolverOptions(robust_start_k=0.0)


def test_an_accepted_step_that_threw_a_point_is_taken_with_it_held():
    """An accepted step whose excess over the linear prediction sits on one point (a point
    thrown where its model is far from linear, as Gauss–Newton steps from poor initial values
    do to weakly intersected pushbroom tie points, issue 29) is taken with that point held:
    the point stays where it was, every other point takes its step, and the cost is that of
    the held step. The throw is simulated by inflating the point's residuals in the trial."""
    from hsgeo.adjust.options import SolverOptions as SO
    from hsgeo.adjust.schur import _predicted_decrease, _step
    from hsgeo.adjust.solver import _Solve

    S, P, st, pt, th = bearing_scene(0, n_stations=6, n_points=40, coverage=4)
    P0 = P + np.random.default_rng(1).normal(0, 3.0, P.shape)
    p = Parameters()
    p.add("stations", S.copy())
    p.add("points", P0.copy(), points=True)
    p.fix("stations")
    solve = _Solve(p, [Bearings(st, pt, th, 1e-3)], SO(), None)
    sy, ne = solve.linearise()
    cost = sy.cost
    dc, dp = _step(solve.layout, ne, 0.0)
    pred = _predicted_decrease(solve.layout, ne, 0.0, dc, dp)
    state = solve.layout.get_state()
    solve.layout.apply(dc, dp)
    good = solve.trial()
    # a step that threw nothing is taken as it is, the parameters at it
    same = solve._hold_thrown(sy, ne, good, state, cost, dc, dp, (good, 0, pred, 1))
    assert same[0] is good
    np.testing.assert_allclose(solve.layout.pblock.value, P0 + dp, rtol=1e-12)
    thrown = type(good)(good.r.copy(), None, None, None, good.n_obs_rows)
    thrown.r[pt == 7] = 50.0  # point 7's rays far off: 5000 against the step's ~40
    assert thrown.cost < cost  # (still a decrease: the step is accepted)
    out = solve._hold_thrown(sy, ne, thrown, state, cost, dc, dp, (thrown, 0, pred, 1))
    pts = solve.layout.pblock.value
    np.testing.assert_array_equal(pts[7], P0[7])  # held where it was
    others = np.arange(40) != 7
    np.testing.assert_allclose(pts[others], (P0 + dp)[others], rtol=1e-12)
    assert out[0].cost < thrown.cost
    np.testing.assert_allclose(out[0].cost, solve.trial().cost, rtol=1e-12)
