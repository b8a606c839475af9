"""The LM loop's options added for the NIST StRD problems (issue 14): xtol, Moré's damping
diagonal, and trial steps that leave the model's domain."""

import numpy as np
import pytest
from scipy.optimize import least_squares
from toy_models import Exponential

from hsgeo.adjust import Parameters, ResidualBlock, SolverOptions, adjust
from hsgeo.errors import InputError


def _exp_problem():
    t = np.linspace(0.0, 4.0, 30)
    rng = np.random.default_rng(3)
    y = 2.0 * np.exp(-0.7 * t) + 0.01 * rng.standard_normal(t.size)
    return t, y


def _scipy_reference(t, y):
    sol = least_squares(
        lambda b: b[0] * np.exp(-b[1] * t) - y, [1.0, 0.1], method="lm", xtol=1e-15,
        ftol=1e-15, gtol=1e-15,
    )  # fmt: skip
    return sol.x


@pytest.mark.parametrize("damping", ["current", "max"])
def test_xtol_reaches_the_reference_to_more_digits(damping):
    t, y = _exp_problem()
    ref = _scipy_reference(t, y)
    p = Parameters()
    p.add("Ak", [1.0, 0.1])
    loose = adjust(p, [Exponential(t, y, 1.0)], damping_diagonal=damping).value("Ak")
    tight = adjust(p, [Exponential(t, y, 1.0)], xtol=1e-13, damping_diagonal=damping)
    assert tight.converged
    err_tight = np.max(np.abs(tight.value("Ak") - ref) / np.abs(ref))
    err_loose = np.max(np.abs(loose - ref) / np.abs(ref))
    assert err_tight < 1e-9
    assert err_tight <= err_loose


def test_damping_diagonal_max_keeps_the_solution_and_rejects_unknown_values():
    t, y = _exp_problem()
    p = Parameters()
    p.add("Ak", [1.0, 0.1])
    a = adjust(p, [Exponential(t, y, 1.0)], xtol=1e-13)
    b = adjust(p, [Exponential(t, y, 1.0)], xtol=1e-13, damping_diagonal="max")
    np.testing.assert_allclose(b.value("Ak"), a.value("Ak"), rtol=1e-9)
    np.testing.assert_allclose(b.covariance, a.covariance, rtol=1e-8)
    with pytest.raises(InputError, match="damping_diagonal"):
        SolverOptions(damping_diagonal="largest")
    with pytest.raises(InputError, match="xtol"):
        SolverOptions(xtol=-1.0)


class _Sqrt(ResidualBlock):
    """y = sqrt(a) t: NaN for a < 0, where a full Gauss–Newton step from a = 4 lands."""

    name = "sqrt"
    BLOCKS = {"a": "a"}

    def __init__(self, t, y):
        super().__init__(np.ones(t.size))
        self.t, self.y = t, y

    def evaluate(self, values, jacobian):
        a = values["a"][0]
        with np.errstate(invalid="ignore"):
            s = np.sqrt(a)
        r = s * self.t - self.y
        return r, ({"a": (0.5 / s * self.t)[:, None]} if jacobian else None)


def test_a_trial_step_outside_the_model_domain_is_refused_not_an_error():
    t = np.linspace(1.0, 2.0, 5)
    y = 0.01 * t  # a = 1e-4: the Gauss–Newton step from a = 4 overshoots to a < 0
    p = Parameters()
    p.add("a", [4.0])
    res = adjust(p, [_Sqrt(t, y)], xtol=1e-12)
    assert res.converged
    assert res.value("a")[0] == pytest.approx(1e-4, rel=1e-9)
    p0 = Parameters()
    p0.add("a", [-1.0])  # non-finite at the initial values: still the user's error
    with pytest.raises(InputError, match="non-finite residuals"):
        adjust(p0, [_Sqrt(t, y)])


def test_geodesic_acceleration_reaches_the_same_minimum():
    t, y = _exp_problem()
    ref = _scipy_reference(t, y)
    p = Parameters()
    p.add("Ak", [1.0, 0.1])
    res = adjust(p, [Exponential(t, y, 1.0)], xtol=1e-13, geodesic=0.75)
    assert res.converged
    np.testing.assert_allclose(res.value("Ak"), ref, rtol=1e-9)
    with pytest.raises(InputError, match="geodesic"):
        SolverOptions(geodesic=0.0)


def test_geodesic_acceleration_refuses_a_points_block():
    from toy_models import Bearings, bearing_scene

    S, P, st, pt, th = bearing_scene(0)
    p = Parameters()
    p.add("stations", S)
    p.add("points", P, points=True)
    with pytest.raises(InputError, match="geodesic is not available with a points block"):
        adjust(p, [Bearings(st, pt, th, 1e-3)], geodesic=0.75)


class _CountedSqrt(_Sqrt):
    """_Sqrt that counts its evaluations, the trial ones apart."""

    def __init__(self, t, y):
        super().__init__(t, y)
        self.calls = {"linearisation": 0, "residuals": 0, "trial": 0}

    def evaluate(self, values, jacobian):
        self.calls["linearisation" if jacobian else "residuals"] += 1
        return super().evaluate(values, jacobian)

    def trial_residuals(self, values):
        self.calls["trial"] += 1
        return super().evaluate(values, False)[0]


def test_the_solver_costs_its_trial_steps_with_trial_residuals():
    """A trial step's cost comes from ``ResidualBlock.trial_residuals`` (a block may stop an
    internal iteration earlier there), never from ``evaluate`` without the Jacobian.
    """
    t = np.linspace(1.0, 2.0, 5)
    blk = _CountedSqrt(t, 0.01 * t)
    p = Parameters()
    p.add("a", [4.0])
    res = adjust(p, [blk], xtol=1e-12)
    assert res.converged
    assert blk.calls["trial"] >= res.iterations > 0
    # the result's residuals of every row are the final linearisation's (at the solution)
    assert blk.calls["residuals"] == 0
    np.testing.assert_array_equal(
        res.residuals(blk.name), _Sqrt(t, 0.01 * t).evaluate(res.params.values(), False)[0]
    )


class _LowTrial(_CountedSqrt):
    """A block whose trial residuals understate the cost (half the residuals)."""

    def trial_residuals(self, values):
        self.calls["trial"] += 1
        return 0.5 * super().evaluate(values, False)[0]


def test_a_trial_cost_below_the_exact_cost_switches_to_exact_trials():
    """The first accepted trial whose cost the linearisation at its point finds too low (by
    more than 1e-9 relative) ends the use of trial_residuals for the solve; the minimum is
    the same.
    """
    t = np.linspace(1.0, 2.0, 5)
    blk = _LowTrial(t, 0.01 * t)
    p = Parameters()
    p.add("a", [2e-4])  # near enough that the first trial is accepted
    res = adjust(p, [blk], xtol=1e-12)
    assert res.converged
    assert res.value("a")[0] == pytest.approx(1e-4, rel=1e-9)
    assert blk.calls["trial"] == 1
    assert blk.calls["residuals"] > 1  # the later trials, and the result's residuals


def test_start_trial_gets_the_step_s_linear_prediction_of_the_residuals():
    """Before a trial (ahead of the first settled iterate) a block's ``start_trial`` is given
    ``J h`` on its rows, in the units of sigma: the first step's prediction of the change of
    its residuals (a bundle of bearings, adjusted from perturbed values)."""
    from toy_models import Bearings, bearing_scene

    class _Told(Bearings):
        def __init__(self, *a):
            super().__init__(*a)
            self.log = []

        def evaluate(self, values, jacobian):
            r, jac = super().evaluate(values, jacobian)
            self.log.append(("evaluate" if jacobian else "residuals", r.copy()))
            return r, jac

        def trial_residuals(self, values):
            r = super().evaluate(values, False)[0]
            self.log.append(("trial", r.copy()))
            return r

        def start_trial(self, change):
            self.log.append(("start", np.array(change, dtype=float)))

    S, P, st, pt, th = bearing_scene(0)
    rng = np.random.default_rng(1)
    p = Parameters()
    p.add("stations", S + np.column_stack([rng.normal(0, 0.3, (len(S), 2)), np.zeros(len(S))]))
    p.fix("stations", index=[0, 1])
    p.add("points", P + rng.normal(0, 0.3, P.shape), points=True)
    blk = _Told(st, pt, th, 1e-3)
    res = adjust(p, [blk], hold_points=True)
    assert res.converged
    kinds = [k for k, _ in blk.log]
    i = kinds.index("start")
    assert kinds[i - 1] == "evaluate" and kinds[i + 1] == "trial"
    change = blk.log[i][1]
    actual = blk.log[i + 1][1] - blk.log[i - 1][1]
    assert change.shape == (blk.m,) and np.all(np.isfinite(change))
    # the linear prediction of the first step's change, to its second-order remainder
    assert np.linalg.norm(change - actual) < 0.05 * np.linalg.norm(actual)


def test_the_result_s_residuals_come_from_the_linearisation_only_at_its_values():
    """``_all_residuals`` takes every row's residuals from a linearisation evaluated at the
    current values (the rows left out included), and evaluates the blocks again otherwise."""
    from hsgeo.adjust.solver import _all_residuals
    from hsgeo.adjust.system import _evaluate, _Layout

    t = np.linspace(1.0, 2.0, 5)
    blk = _CountedSqrt(t, 0.01 * t)
    p = Parameters()
    p.add("a", [4.0])
    lay = _Layout(p)
    mask = np.array([True, False, True, True, True])  # a row left out
    sy = _evaluate(lay, [blk], [mask], True)
    calls = dict(blk.calls)
    got = _all_residuals(lay, [blk], sy)
    assert blk.calls == calls  # nothing evaluated
    np.testing.assert_array_equal(got[blk.name], _Sqrt(t, 0.01 * t).evaluate({"a": [4.0]}, 0)[0])
    lay.apply(np.array([-1.0]), None)  # the values moved since the linearisation
    got = _all_residuals(lay, [blk], sy)
    assert blk.calls["residuals"] == calls["residuals"] + 1
    np.testing.assert_array_equal(got[blk.name], _Sqrt(t, 0.01 * t).evaluate({"a": [3.0]}, 0)[0])


def test_start_trials_gives_each_block_its_kept_rows_in_its_units():
    """The system's whitened J h (kept rows only, block after block) goes to each block that
    takes it, times σ, NaN on the rows left out; a block without start_trial is skipped."""
    from hsgeo.adjust.solver import _Solve

    class _Takes(_Sqrt):
        def start_trial(self, change):
            self.got = np.array(change)

    t = np.linspace(1.0, 2.0, 4)
    a, b, c = _Takes(t, t), _Sqrt(t, t), _Takes(t, t)
    a.sigma = np.array([1.0, 2.0, 3.0, 4.0])
    c.sigma = np.full(4, 0.5)
    solve = _Solve.__new__(_Solve)
    solve.blocks = [a, b, c]
    solve.masks = [np.array([True, False, True, True]), np.ones(4, bool), np.ones(4, bool)]
    change = np.arange(11.0)  # 3 + 4 + 4 kept rows
    solve._start_trials(change)
    np.testing.assert_array_equal(a.got, [0.0 * 1.0, np.nan, 1.0 * 3.0, 2.0 * 4.0])
    np.testing.assert_array_equal(c.got, 0.5 * np.arange(7.0, 11.0))
