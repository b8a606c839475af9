"""A datum defect that appears during the iterations leaves the estimable part estimated and
names what the data do not determine (issue 42): no DatumError at the covariance unless
``SolverOptions.strict_covariance``."""

import numpy as np
import pytest
from toy_models import Line

from hsgeo import DatumError
from hsgeo.adjust import Parameters, ResidualBlock, adjust
from hsgeo.adjust.schur import _estimable_inverse


class Hinge(ResidualBlock):
    """y = a + b t + max(k, 0) t²: the derivative by k vanishes once k < 0, so a step that
    takes k below zero leaves it undetermined at the solution (it is not at the start)."""

    name = "hinge"
    BLOCKS = {"abk": "abk"}

    def __init__(self, t, y, sigma, blocks=None):
        super().__init__(np.broadcast_to(sigma, np.shape(y)), blocks=blocks)
        self.t, self.y = np.asarray(t, float), np.asarray(y, float)

    def evaluate(self, values, jacobian):
        a, b, k = values[self.blocks["abk"]]
        r = a + b * self.t + max(k, 0.0) * self.t**2 - self.y
        if not jacobian:
            return r, None
        dk = (k > 0) * self.t**2
        return r, {self.blocks["abk"]: np.column_stack([np.ones_like(self.t), self.t, dk])}


def _data():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 10, 50)
    return t, 1.5 + 0.3 * t - 0.02 * t**2 + 0.1 * rng.standard_normal(t.size)


def _hinge_params():
    p = Parameters()
    p.add("abk", [0.0, 0.0, 0.5], columns=("a", "b", "k"))
    return p


def test_defect_at_the_solution_names_the_parameter_and_keeps_the_rest():
    t, y = _data()
    res = adjust(_hinge_params(), Hinge(t, y, 0.1))
    assert res.value("abk")[2] < 0  # the step took k where nothing depends on it
    assert res.undetermined_parameters == ["abk[k]"]
    s = res.sigma("abk")
    assert np.isnan(s[2]) and np.all(np.isfinite(s[:2]))
    assert np.all(np.isnan(res.covariance[2])) and np.all(np.isnan(res.covariance[:, 2]))
    # the estimable part: the straight line fitted alone (k contributes nothing at k < 0)
    q = Parameters()
    q.add("ab", [0.0, 0.0])
    ref = adjust(q, Line(t, y, 0.1))
    # (to the convergence tolerance: 1e-3 σ)
    np.testing.assert_allclose(
        res.value("abk")[:2], ref.value("ab"), rtol=0, atol=1e-3 * float(s[:2].min())
    )
    np.testing.assert_allclose(res.covariance[:2, :2], ref.covariance, rtol=1e-6)
    assert res.dof == ref.dof == t.size - 2  # the undetermined k takes no redundancy
    assert res.sigma0 == pytest.approx(ref.sigma0, rel=1e-6)
    assert "not determined at the solution" in res.report() and "abk[k]" in res.report()


def test_strict_covariance_raises_naming_the_parameter():
    t, y = _data()
    with pytest.raises(DatumError, match=r"abk\[k\]") as ei:
        adjust(_hinge_params(), Hinge(t, y, 0.1), strict_covariance=True)
    assert ei.value.parameters == ["abk[k]"]


def test_estimable_inverse_is_a_generalised_inverse_that_names_the_defect():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(40, 10))
    A[:, 5] = A[:, 2] + A[:, 7]  # one defect among columns 2, 5 and 7
    D = np.diag(10.0 ** np.arange(-2.5, 2.5, 0.5))  # columns in very different units
    S = D @ A.T @ A @ D
    S[:, 9] = S[9, :] = 0.0  # a parameter no observation is left on
    G, bad, defect = _estimable_inverse(S, 1e-11)
    assert bad.tolist() == [2, 5, 7, 9] and defect == 2
    np.testing.assert_allclose(S @ G @ S, S, atol=1e-8 * np.abs(S).max())
    # estimable parameters: the covariance of any minimal constraint (here column 5 fixed)
    keep = [0, 1, 2, 3, 4, 6, 7, 8]
    ref = np.linalg.inv(S[np.ix_(keep, keep)])
    est = [0, 1, 3, 4, 6, 8]
    sel = [keep.index(i) for i in est]
    np.testing.assert_allclose(G[np.ix_(est, est)], ref[np.ix_(sel, sel)], rtol=1e-7)
