"""The numba scalar cores of hsgeo._kernels against the numpy formulas they replaced."""

import numpy as np

from hsgeo import _kernels as KN
from hsgeo.rotations import R_from_opk, R_from_rpy, dR_drpy


def test_rpy_rotation_equals_rotations_module():
    rng = np.random.default_rng(0)
    R, dR = np.empty((3, 3)), np.empty((3, 3, 3))
    for ro, pi, ya in rng.uniform(-3, 3, (20, 3)):
        KN.rpy_rotation(ro, pi, ya, R, dR)
        np.testing.assert_allclose(R, R_from_rpy(ro, pi, ya), rtol=0, atol=5e-16)
        np.testing.assert_allclose(dR, dR_drpy(ro, pi, ya), rtol=0, atol=5e-16)


def _previous_numpy_pushbroom(R, d, lever, beta, c, dist, x0, y0):
    """002 eq. (3)-(4) as sensors/pushbroom.project wrote them before the shared core."""
    q = np.einsum("mji,mj->mi", R, d) - lever
    p = q @ beta.T
    K1, K2, P1, P2 = dist
    xb = c * p[:, 0] / p[:, 2]
    yb = c * p[:, 1] / p[:, 2]
    x = xb + K1 * xb**3 + K2 * xb**5 + 3 * P1 * xb**2 + x0
    y = yb + P2 * xb**2 + y0
    return q, p, np.column_stack([x, y])


def test_pushbroom_rows_equal_the_previous_numpy_formulas():
    rng = np.random.default_rng(1)
    m = 200
    R = R_from_rpy(*rng.normal(scale=0.05, size=(3, m)))
    d = np.column_stack([rng.uniform(-60, 60, (m, 2)), rng.uniform(-110, -90, m)])
    lever = np.array([0.12, -0.05, -0.3])
    beta = R_from_opk(1e-3, -2e-3, 5e-4) @ np.array([[0.0, -1, 0], [-1, 0, 0], [0, 0, -1]])
    c = rng.uniform(17.0, 17.5, m)
    dist = np.array([-4e-5, 3e-7, 2.5e-5, -3e-5])
    q, p, xy, xb, yb, iz, gx, gy = KN.pushbroom_image_rows(R, d, lever, beta, c, dist, 0.01, -0.02)
    q0, p0, xy0 = _previous_numpy_pushbroom(R, d, lever, beta, c, dist, 0.01, -0.02)
    np.testing.assert_allclose(q, q0, rtol=1e-14, atol=1e-13)
    np.testing.assert_allclose(p, p0, rtol=1e-14, atol=1e-13)
    np.testing.assert_allclose(xy, xy0, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(xb, c * p0[:, 0] / p0[:, 2], rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(iz, 1 / p0[:, 2], rtol=1e-14)
    # the derivatives ∂x/∂x̄, ∂y/∂x̄ against central differences of the distortion
    K1, K2, P1, P2 = dist
    h = 1e-6
    fx = lambda t: t + K1 * t**3 + K2 * t**5 + 3 * P1 * t**2  # noqa: E731
    np.testing.assert_allclose(gx, (fx(xb + h) - fx(xb - h)) / (2 * h), rtol=1e-8)
    np.testing.assert_allclose(
        gy, P2 * ((xb + h) ** 2 - (xb - h) ** 2) / (2 * h), rtol=1e-6, atol=1e-12
    )


def test_scalar_cores_equal_their_rows():
    """The compiled kernel calls the scalar functions; the rows loop over the same ones."""
    R = R_from_rpy(0.01, -0.02, 1.0)
    d = np.array([[3.0, -4.0, -100.0]])
    lever, beta = np.zeros(3), np.eye(3)
    q, p = np.empty(3), np.empty(3)
    KN.pushbroom_camera_point(R, d[0], lever, beta, q, p)
    rows = KN.pushbroom_image_rows(
        R[None], d, lever, beta, np.array([17.0]), np.array([1e-4, 1e-6, 1e-5, 2e-5]), 0.0, 0.0
    )
    np.testing.assert_array_equal(p, rows[1][0])
    x, y, xb, yb, iz, gx, gy = KN.pushbroom_image_mm(*p, 17.0, 1e-4, 1e-6, 1e-5, 2e-5)
    np.testing.assert_array_equal([x, y], rows[2][0])
    np.testing.assert_array_equal([xb, yb, iz, gx, gy], [r[0] for r in rows[3:]])


def test_value_cores_equal_the_formulas():
    """The ``*_values`` cores, which the pushbroom kernel inlines, against the rotations
    module and numpy (the array forms unpack them, so these are the one implementation)."""
    rng = np.random.default_rng(2)
    for ro, pi, ya in rng.uniform(-3, 3, (10, 3)):
        Rv, dRv = KN.rpy_rotation_values(ro, pi, ya)
        np.testing.assert_allclose(
            np.reshape(Rv, (3, 3)), R_from_rpy(ro, pi, ya), rtol=0, atol=5e-16
        )
        np.testing.assert_allclose(
            np.reshape(dRv, (3, 3, 3)), dR_drpy(ro, pi, ya), rtol=0, atol=5e-16
        )
    for u in (-0.1, 0.0, 0.3, 1.0):
        v = np.array(KN.bspline_weights_values(u, 0.5))
        w = np.array(
            [(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]
        )
        dw = np.array([-3 * (1 - u) ** 2, 9 * u**2 - 12 * u, -9 * u**2 + 6 * u + 3, 3 * u**2])
        np.testing.assert_allclose(v[:4], w / 6, rtol=1e-14, atol=1e-15)
        np.testing.assert_allclose(v[4:], dw / 6 * 0.5, rtol=1e-14, atol=1e-15)
    R = R_from_rpy(0.01, -0.02, 1.0)
    d = np.array([3.0, -4.0, -100.0])
    lever = np.array([0.12, -0.05, -0.3])
    beta = R_from_opk(1e-3, -2e-3, 5e-4)
    out = KN.pushbroom_camera_point_values(tuple(R.ravel()), *d, lever, beta)
    q = R.T @ d - lever
    np.testing.assert_allclose(out[:3], q, rtol=1e-14)
    np.testing.assert_allclose(out[3:], beta @ q, rtol=1e-14)
