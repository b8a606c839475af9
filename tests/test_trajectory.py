import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy
from hsgeo.trajectory import (
    R_BODY_FROM_PLATFORM,
    SplineNodes,
    Trajectory,
    bspline_basis,
    platform_rpy_from_rph,
    platform_rpy_rate_from_rph_rate,
    rph_from_platform_rpy,
)


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
    rph = np.array([[0, 0, 3.1], [0, 0, -3.1], [0, 0, -3.0]])  # heading wraps through ±π
    tr = Trajectory(t, xyz, rph)
    p, a = tr.pose([0.5])
    np.testing.assert_allclose(p, [[5, 0, 100]])
    assert abs(abs(a[0, 2]) - np.pi) < 0.05  # interpolated across the wrap, not through 0
    # roll and pitch are unwrapped too (a roll record passing ±π)
    tr2 = Trajectory(t, xyz, np.array([[3.1, 0, 0], [-3.1, 0, 0], [-3.0, 0, 0]]))
    assert abs(abs(tr2.pose(0.5)[1][0, 0]) - np.pi) < 0.05
    p, a = tr.pose(1.5)  # a scalar time gives one row
    assert p.shape == (1, 3) and a.shape == (1, 3)
    with pytest.raises(InputError, match="outside"):
        tr.pose([3.0])
    with pytest.raises(InputError, match="increase strictly"):
        Trajectory([0, 0, 1], xyz, rph)
    with pytest.raises(InputError, match="expected"):
        Trajectory(t, xyz[:2], rph)
    with pytest.raises(InputError, match="NaN"):
        Trajectory(t, xyz * np.nan, rph)
    with pytest.raises(InputError, match="at least 2"):
        Trajectory(t[:1], xyz[:1], rph[:1])
    with pytest.raises(AttributeError):  # frozen
        tr.t_s = t


def test_R_map_from_body_is_the_attitude_of_pose_bitwise():
    """R_map_from_body interpolates the attitude only (issue 41): the same bits as from pose()."""
    t = np.linspace(0.0, 10.0, 11)
    rng = np.random.default_rng(5)
    tr = Trajectory(t, rng.normal(size=(11, 3)) * 100, rng.uniform(-3, 3, (11, 3)))
    tq = rng.uniform(0.0, 10.0, 57)
    _, a = tr.pose(tq)
    assert np.array_equal(tr.R_map_from_body(tq), R_ENU_FROM_NED @ R_from_rpy(*a.T))
    with pytest.raises(InputError, match="outside the trajectory"):
        tr.R_map_from_body([10.5])


def test_R_map_from_body_axes():
    """Level, heading 30°: body x points 30° east of north, body z down, in ENU."""
    h = np.deg2rad(30.0)
    tr = Trajectory([0.0, 1.0], np.zeros((2, 3)), [[0, 0, h], [0, 0, h]])
    R = tr.R_map_from_body([0.5])[0]
    np.testing.assert_allclose(R @ [1, 0, 0], [np.sin(h), np.cos(h), 0], atol=1e-15)
    np.testing.assert_allclose(R @ [0, 1, 0], [np.cos(h), -np.sin(h), 0], atol=1e-15)  # right
    np.testing.assert_allclose(R @ [0, 0, 1], [0, 0, -1], atol=1e-15)
    # positive pitch raises the nose: body x gets a positive up component
    tr = Trajectory([0.0, 1.0], np.zeros((2, 3)), [[0, 0.1, 0], [0, 0.1, 0]])
    assert tr.R_map_from_body(0.0)[0, 2, 0] == pytest.approx(np.sin(0.1), abs=1e-15)


def test_platform_angles_give_the_same_rotation_and_rays():
    """R_ENU_FROM_NED R_from_rpy(r, p, h) diag(1, -1, -1) = R_from_rpy(r, -p, pi/2 - h)."""
    rng = np.random.default_rng(3)
    n = 500
    rph = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, n),
            rng.uniform(-1.5, 1.5, n),
            rng.uniform(-4 * np.pi, 4 * np.pi, n),
        ]
    )
    rpy = platform_rpy_from_rph(rph)
    R_map_from_body = R_ENU_FROM_NED @ R_from_rpy(rph[:, 0], rph[:, 1], rph[:, 2])
    R_map_from_platform = R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    np.testing.assert_allclose(
        R_map_from_platform @ R_BODY_FROM_PLATFORM, R_map_from_body, rtol=0, atol=2e-15
    )
    # the same ray: a view direction given in the platform frame and in the body frame
    v_platform = rng.standard_normal((n, 3))
    v_body = v_platform @ R_BODY_FROM_PLATFORM.T
    np.testing.assert_allclose(
        np.einsum("nij,nj->ni", R_map_from_platform, v_platform),
        np.einsum("nij,nj->ni", R_map_from_body, v_body),
        rtol=0,
        atol=1e-14,
    )
    # the platform frame is x forward, y left, z up: level flight north is yaw = 90°
    assert platform_rpy_from_rph([0.0, 0.0, 0.0]).tolist() == [0.0, 0.0, np.pi / 2]
    # round trips (the map is its own inverse)
    np.testing.assert_allclose(rph_from_platform_rpy(rpy), rph, rtol=0, atol=1e-14)
    np.testing.assert_allclose(
        platform_rpy_from_rph(rph_from_platform_rpy(rpy)), rpy, rtol=0, atol=1e-14
    )
    with pytest.raises(InputError, match="shape"):
        platform_rpy_from_rph([1.0, 2.0])


def test_platform_rates_are_the_derivative_of_the_conversion():
    t = np.linspace(0, 10, 101)
    rph = np.column_stack([0.1 * np.sin(t), 0.05 * np.cos(t), 1.0 + 0.02 * t])
    tr = Trajectory(t, np.zeros((t.size, 3)), rph)
    tq = np.array([1.23, 4.56, 7.89])
    _, w = tr.rates(tq)
    h = 1e-6
    num = platform_rpy_from_rph(tr.pose(tq + h)[1]) - platform_rpy_from_rph(tr.pose(tq - h)[1])
    np.testing.assert_allclose(platform_rpy_rate_from_rph_rate(w), num / (2 * h), atol=1e-8)


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
    B = np.stack(
        [(1 - u) ** 3 / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6, u3 / 6],
        axis=-1,
    )
    dB = np.stack(
        [-((1 - u) ** 2) / 2, (3 * u2 - 4 * u) / 2, (-3 * u2 + 2 * u + 1) / 2, u2 / 2], axis=-1
    )
    np.testing.assert_allclose(bspline_basis(u), B, rtol=0, atol=4e-16)
    np.testing.assert_allclose(bspline_basis_derivative(u), dB, rtol=0, atol=4e-16)
    assert bspline_basis(u[:221].reshape(13, 17)).shape == (13, 17, 4)
    assert bspline_basis(0.5).shape == (4,)


def test_trajectory_rates():
    t = np.linspace(0, 10, 11)
    tr = Trajectory(
        t, np.column_stack([2 * t, -t, 0 * t + 5]), np.column_stack([0.1 * t, 0 * t, 0.02 * t])
    )
    v, w = tr.rates(np.array([0.0, 3.3, 10.0]))  # one-sided at the ends
    np.testing.assert_allclose(v, [[2, -1, 0]] * 3, atol=1e-9)
    np.testing.assert_allclose(w, [[0.1, 0, 0.02]] * 3, atol=1e-9)
