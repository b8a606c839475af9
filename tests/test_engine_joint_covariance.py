"""The joint covariance of a set of points (``point_covariance(index, joint=True)``)."""

import numpy as np
import pytest
from toy_models import Bearings, bearing_scene

from hsgeo import InputError
from hsgeo.adjust import Parameters, adjust


def _problem(seed=3, n_control=2, sigma_ctrl=1e-3):
    S, P, st, pt, th = bearing_scene(seed, n_stations=5, n_points=12)
    rng = np.random.default_rng(seed)
    p = Parameters()
    p.add("stations", S + rng.normal(0, [2, 2, 0.02], S.shape), columns=("x_m", "y_m", "h_rad"))
    p.add("points", P + rng.normal(0, 1.0, P.shape), points=True, columns=("x_m", "y_m"))
    for j in range(n_control):
        p.set_prior("points", sigma_ctrl, index=j, mean=P[j])
    return p, Bearings(st, pt, th, 1e-3), st, pt, n_control, sigma_ctrl


def _dense_covariance(r, blk, st, pt, n_control, sigma_ctrl):
    """σ0²·N⁻¹ of the full normal matrix at the solution, formed densely (points last)."""
    S, P = r.value("stations"), r.value("points")
    _, d = Bearings.model(S, P, st, pt)
    q = (d**2).sum(axis=1)
    dP = np.column_stack([-d[:, 1] / q, d[:, 0] / q])
    ns, npt, m = S.shape[0], P.shape[0], st.size
    J = np.zeros((m + 2 * n_control, 3 * ns + 2 * npt))
    rows = np.arange(m)
    for k in range(2):
        J[rows, 3 * st + k] = -dP[:, k] / blk.sigma
        J[rows, 3 * ns + 2 * pt + k] = dP[:, k] / blk.sigma
    J[rows, 3 * st + 2] = -1.0 / blk.sigma
    for j in range(n_control):  # the control points' priors
        for k in range(2):
            J[m + 2 * j + k, 3 * ns + 2 * j + k] = 1.0 / sigma_ctrl
    return r.sigma0**2 * np.linalg.inv(J.T @ J)[3 * ns :, 3 * ns :]


@pytest.mark.parametrize("compiled", [True, False])
def test_joint_point_covariance_is_the_dense_inverse(compiled):
    p, blk, st, pt, nc, sc = _problem()
    r = adjust(p, blk, ftol=1e-14, keep_jacobian=True, compiled=compiled)
    dense = _dense_covariance(r, blk, st, pt, nc, sc)
    idx = np.array([7, 2, 9, 4])
    sel = (idx[:, None] * 2 + np.arange(2)).ravel()
    joint = r.point_covariance(index=idx, joint=True)
    assert joint.shape == (8, 8)
    np.testing.assert_allclose(joint, dense[np.ix_(sel, sel)], rtol=1e-6, atol=1e-12)
    # the cross terms matter here (a shared datum through two control points) …
    off = joint[:2, 2:4]
    assert np.abs(off).max() > 0.1 * np.sqrt(joint[0, 0] * joint[2, 2])
    # … and the diagonal blocks are those of the per-point covariance
    blocks = r.point_covariance(index=idx)
    for i in range(idx.size):
        np.testing.assert_allclose(
            joint[2 * i : 2 * i + 2, 2 * i : 2 * i + 2], blocks[i], rtol=1e-9, atol=1e-15
        )
    # the whole matrix, all points
    everything = r.point_covariance(index=np.arange(12), joint=True)
    np.testing.assert_allclose(everything, dense, rtol=1e-6, atol=1e-12)


def test_joint_point_covariance_repeats_and_fixed_coordinates():
    p, blk, *_ = _problem()
    p["points"].free[5, 1] = False
    r = adjust(p, blk, ftol=1e-14, keep_jacobian=True)
    j = r.point_covariance(index=[3, 5, 3], joint=True)
    np.testing.assert_array_equal(j[0:2, 0:2], j[4:6, 4:6])
    assert np.isnan(j[3]).all() and np.isnan(j[:, 3]).all()
    assert np.isfinite(j[2, 2])


def test_joint_point_covariance_needs_index_and_jacobian():
    p, blk, *_ = _problem()
    with pytest.raises(InputError, match="index="):
        adjust(p, blk, keep_jacobian=True).point_covariance(joint=True)
    with pytest.raises(InputError, match="keep_jacobian=True"):
        adjust(p, blk).point_covariance(index=[0, 1], joint=True)
