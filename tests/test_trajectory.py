import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.trajectory import SplineNodes, Trajectory, bspline_basis


def test_basis_partition_of_unity_and_continuity():
    u = np.linspace(0, 1, 101)
    B = bspline_basis(u)
    np.testing.assert_allclose(B.sum(axis=1), 1.0, atol=1e-15)
    assert np.all(B >= 0)
    # C0 and C1 continuity across a knot: weights at u=1 equal the next interval's at u=0
    np.testing.assert_allclose(bspline_basis(1.0)[1:], bspline_basis(0.0)[:3], atol=1e-15)
    h = 1e-6
    d_end = (bspline_basis(1.0) - bspline_basis(1.0 - h)) / h
    d_start = (bspline_basis(h) - bspline_basis(0.0)) / h
    np.testing.assert_allclose(d_end[1:], d_start[:3], atol=1e-5)


def test_spline_reproduces_linear_and_is_local():
    sn = SplineNodes(0.0, 95.0, 10.0)
    assert sn.n_nodes == 13
    t = np.linspace(0, 95, 500)
    # a cubic B-spline reproduces linear functions when the nodes sample them at node times
    nodes = np.column_stack([2.0 + 0.5 * sn.t_nodes_s, np.full(sn.n_nodes, -1.0)])
    expect = np.column_stack([2 + 0.5 * t, -np.ones_like(t)])
    np.testing.assert_allclose(sn.evaluate(nodes, t), expect, atol=1e-12)
    idx, w = sn.basis(t)
    assert idx.shape == (500, 4) and np.all(idx[:, 3] - idx[:, 0] == 3)
    assert idx.min() == 0 and idx.max() == sn.n_nodes - 1
    # moving one node changes the curve only within ±2 intervals of its time
    bump = np.zeros((sn.n_nodes, 1))
    bump[6, 0] = 1.0
    v = sn.evaluate(bump, t)[:, 0]
    assert np.all(v[np.abs(t - sn.t_nodes_s[6]) >= 20.0] == 0.0)


def test_spline_errors():
    with pytest.raises(InputError, match="interval"):
        SplineNodes(0.0, 10.0, 0.0)
    sn = SplineNodes(0.0, 10.0, 2.0)
    with pytest.raises(InputError, match="outside"):
        sn.basis([11.0])
    with pytest.raises(InputError, match="node values"):
        sn.evaluate(np.zeros((3, 6)), [1.0])


def test_trajectory_interpolation_and_errors():
    t = np.array([0.0, 1.0, 2.0])
    xyz = np.array([[0, 0, 100], [10, 0, 100], [20, 0, 100]], float)
    rpy = np.array([[0, 0, 3.1], [0, 0, -3.1], [0, 0, -3.0]])  # yaw wraps through ±π
    tr = Trajectory(t, xyz, rpy)
    p, a = tr.pose([0.5])
    np.testing.assert_allclose(p, [[5, 0, 100]])
    assert abs(abs(a[0, 2]) - np.pi) < 0.05  # interpolated across the wrap, not through 0
    assert tr.R_map_from_platform([1.5]).shape == (1, 3, 3)
    with pytest.raises(InputError, match="outside"):
        tr.pose([3.0])
    with pytest.raises(InputError, match="increasing"):
        Trajectory([0, 0, 1], xyz, rpy)
    with pytest.raises(InputError, match="expected"):
        Trajectory(t, xyz[:2], rpy)


def test_spline_rate_against_differences():
    sn = SplineNodes(0.0, 35.0, 10.0)
    rng = np.random.default_rng(0)
    c = rng.standard_normal((sn.n_nodes, 2))
    t = np.r_[rng.uniform(0.01, 34.99, 200), 10.0, 20.0, 0.0, 35.0]
    h = 1e-5
    tp, tm = np.clip(t + h, 0, 35), np.clip(t - h, 0, 35)
    num = (sn.evaluate(c, tp) - sn.evaluate(c, tm)) / (tp - tm)[:, None]
    np.testing.assert_allclose(sn.evaluate_rate(c, t), num, atol=1e-6)  # one-sided at the ends


def test_compiled_spline_weights_equal_the_basis():
    """The kernel's scalar core is what the numpy basis returns (one implementation)."""
    from hsgeo._kernels import bspline_weights
    from hsgeo.trajectory import bspline_basis_derivative

    w, dw = np.empty(4), np.empty(4)
    for u in (-0.01, 0.0, 0.3, 0.999, 1.02):  # the kernel also continues a piece a little
        bspline_weights(u, 1.0, w, dw)
        np.testing.assert_array_equal(w, bspline_basis(u))
        np.testing.assert_array_equal(dw, bspline_basis_derivative(u))
        bspline_weights(u, 0.1, w, dw)
        np.testing.assert_allclose(dw, 0.1 * bspline_basis_derivative(u), rtol=0, atol=1e-15)


def test_spline_basis_against_the_polynomials():
    """The shared core against the previous numpy formulas (002 §3.3), to the last bits."""
    from hsgeo.trajectory import bspline_basis_derivative

    u = np.r_[np.linspace(-0.05, 1.05, 221), 0.0, 1.0]
    u2, u3 = u * u, u * u * u
    B = np.stack([(1 - u) ** 3 / 6, (3 * u3 - 6 * u2 + 4) / 6,
                  (-3 * u3 + 3 * u2 + 3 * u + 1) / 6, u3 / 6], axis=-1)
    dB = np.stack([-((1 - u) ** 2) / 2, (3 * u2 - 4 * u) / 2, (-3 * u2 + 2 * u + 1) / 2,
                   u2 / 2], axis=-1)
    np.testing.assert_allclose(bspline_basis(u), B, rtol=0, atol=4e-16)
    np.testing.assert_allclose(bspline_basis_derivative(u), dB, rtol=0, atol=4e-16)
    assert bspline_basis(u[:221].reshape(13, 17)).shape == (13, 17, 4)
    assert bspline_basis(0.5).shape == (4,)


def test_trajectory_rates():
    t = np.linspace(0, 10, 11)
    tr = Trajectory(t, np.column_stack([2 * t, -t, 0 * t + 5]),
                    np.column_stack([0.1 * t, 0 * t, 0.02 * t]))
    v, w = tr.rates(np.array([0.0, 3.3, 10.0]))
    np.testing.assert_allclose(v, [[2, -1, 0]] * 3, atol=1e-9)
    np.testing.assert_allclose(w, [[0.1, 0, 0.02]] * 3, atol=1e-9)
