import cv2
import numpy as np
import pytest

from hsgeo.distortion import (
    brown_correction,
    brown_correction_jacobian,
    distort_opencv,
    distort_opencv_jacobian,
    ideal_from_measured_mm,
    measured_from_ideal_mm,
    odd_radial_1d,
    odd_radial_1d_jacobian,
    undistort_opencv,
)
from hsgeo.errors import ConvergenceError, InputError

# Typical coefficients of a wide-ish lens in OpenCV order (k1, k2, p1, p2, k3).
DIST = np.array([-0.28, 0.09, 1.2e-3, -8e-4, -0.012])
# 003 Table 3, band 5 (sensor II): K in mm^-2, mm^-4, mm^-6; P in mm^-1.
K_003 = np.array([-4.14e-3, -2.05e-6, -6.35e-7])
P_003 = np.array([2.32e-5, 3.09e-5])


def _xy_normalised(n=500, seed=1, half=0.6):
    return np.random.default_rng(seed).uniform(-half, half, size=(n, 2))


def _xy_mm(n=500, seed=2):
    # Rikola sensor ~ 5.6 mm x 5.6 mm -> principal-point-reduced coordinates within ±2.8 mm
    return np.random.default_rng(seed).uniform(-2.8, 2.8, size=(n, 2))


def _central_diff(fun, x, h):
    """Numerical Jacobian of fun: (..., m) -> (..., p); returns (..., p, m)."""
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(x.shape[-1]):
        e = np.zeros(x.shape[-1])
        e[j] = h
        cols.append((fun(x + e) - fun(x - e)) / (2 * h))
    return np.stack(cols, axis=-1)


# ------------------------------------------------------------------ 1D odd radial (000 eq. 2)


def test_odd_radial_1d_values_and_shapes():
    d = np.array([[0.0, 1.0], [2.0, -2.0]])
    K = [1e-3, 1e-5, 1e-7]
    expected = 1e-3 * d**3 + 1e-5 * d**5 + 1e-7 * d**7
    np.testing.assert_allclose(odd_radial_1d(d, K), expected, rtol=1e-15)
    assert odd_radial_1d(d, K).shape == (2, 2)
    # odd in d; any number of coefficients
    np.testing.assert_allclose(odd_radial_1d(-d, K), -odd_radial_1d(d, K))
    assert odd_radial_1d(3.0, [2.0]) == pytest.approx(54.0)
    # batch of coefficient sets broadcast against d
    Kb = np.array([[1e-3, 0.0], [0.0, 1e-5]])
    np.testing.assert_allclose(odd_radial_1d(2.0, Kb), [8e-3, 32e-5])


@pytest.mark.parametrize("n_coef", [1, 3, 4])
def test_odd_radial_1d_jacobian_finite_differences(n_coef):
    rng = np.random.default_rng(n_coef)
    d = rng.uniform(-1.5, 1.5, 40)  # normalised distance, caller's choice
    K = rng.normal(scale=0.1, size=n_coef)
    dd, dK = odd_radial_1d_jacobian(d, K)
    assert dd.shape == (40,)
    assert dK.shape == (40, n_coef)
    h = 1e-6
    np.testing.assert_allclose(
        dd, (odd_radial_1d(d + h, K) - odd_radial_1d(d - h, K)) / (2 * h), atol=1e-9
    )
    num_dK = _central_diff(lambda k: odd_radial_1d(d, k)[..., None], K, h)[:, 0, :]
    np.testing.assert_allclose(dK, num_dK, atol=1e-9)


# ------------------------------------------------------------------ OpenCV form


def test_distort_opencv_against_cv2_projectPoints():
    xy = _xy_normalised()
    obj = np.column_stack([xy, np.ones(len(xy))])  # points at z = 1
    img, _ = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), np.eye(3), DIST)
    np.testing.assert_allclose(distort_opencv(xy, DIST), img[:, 0, :], atol=1e-13)


def test_distort_opencv_against_cv2_projectPoints_random_coefficients():
    rng = np.random.default_rng(9)
    xy = _xy_normalised(seed=4)
    obj = np.column_stack([xy, np.ones(len(xy))])
    for _ in range(5):
        dist = rng.normal(scale=[0.2, 0.1, 1e-3, 1e-3, 0.05])
        img, _ = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), np.eye(3), dist)
        np.testing.assert_allclose(distort_opencv(xy, dist), img[:, 0, :], atol=1e-13)


def test_undistort_opencv_round_trip():
    xy = _xy_normalised().reshape(25, 20, 2)  # batch dims preserved
    xy_d = distort_opencv(xy, DIST)
    xy_back = undistort_opencv(xy_d, DIST)
    assert xy_back.shape == xy.shape
    np.testing.assert_allclose(xy_back, xy, atol=1e-13)
    np.testing.assert_allclose(distort_opencv(xy_back, DIST), xy_d, atol=1e-14)


def test_undistort_opencv_against_cv2_undistortPoints():
    xy = _xy_normalised(n=100)
    xy_d = distort_opencv(xy, DIST)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-15)
    ref = cv2.undistortPointsIter(xy_d[:, None, :], np.eye(3), DIST, None, None, crit)
    # OpenCV uses a fixed-point iteration; agreement to its tolerance
    np.testing.assert_allclose(undistort_opencv(xy_d, DIST), ref[:, 0, :], atol=1e-9)


def test_distort_opencv_jacobian_finite_differences():
    xy = _xy_normalised(n=60, seed=5)
    J_xy, J_dist = distort_opencv_jacobian(xy, DIST)
    assert J_xy.shape == (60, 2, 2)
    assert J_dist.shape == (60, 2, 5)
    h = 1e-6
    np.testing.assert_allclose(
        J_xy, _central_diff(lambda u: distort_opencv(u, DIST), xy, h), atol=1e-9
    )
    num = _central_diff(lambda c: distort_opencv(xy, c), DIST, h)
    np.testing.assert_allclose(J_dist, num, atol=1e-9)


def test_undistort_opencv_outside_monotonic_region_raises():
    # strong barrel: x(1 + k1 x²) has its maximum 2/(3*sqrt(3)) at x = 1/sqrt(3) for k1 = -1
    dist = [-1.0, 0.0, 0.0, 0.0, 0.0]
    with pytest.raises(ConvergenceError, match="monotonic") as info:
        undistort_opencv([[0.5, 0.0]], dist)
    assert info.value.result is not None
    # inside the region it works
    np.testing.assert_allclose(
        distort_opencv(undistort_opencv([[0.3, 0.0]], dist), dist), [[0.3, 0.0]], atol=1e-14
    )


# ------------------------------------------------------------------ photogrammetric form


def test_brown_correction_formula_and_opencv_correspondence():
    xy = _xy_mm(n=50)
    x, y = xy[:, 0], xy[:, 1]
    K1, K2, K3 = K_003
    P1, P2 = P_003
    r2 = x**2 + y**2
    radial = K1 * r2 + K2 * r2**2 + K3 * r2**3
    dx = x * radial + P1 * (r2 + 2 * x**2) + 2 * P2 * x * y
    dy = y * radial + 2 * P1 * x * y + P2 * (r2 + 2 * y**2)
    np.testing.assert_allclose(
        brown_correction(xy, K_003, P_003), np.column_stack([dx, dy]), rtol=1e-13, atol=1e-18
    )
    # P1 <-> p2, P2 <-> p1: the correction equals OpenCV's distortion minus identity with
    # (k1, k2, p1, p2, k3) = (K1, K2, P2, P1, K3) in the same units.
    dist_cv = np.array([K1, K2, P2, P1, K3])
    np.testing.assert_allclose(
        brown_correction(xy, K_003, P_003), distort_opencv(xy, dist_cv) - xy, atol=1e-15
    )


def test_brown_ideal_measured_round_trip():
    xy_bar = _xy_mm().reshape(10, 50, 2)
    ideal = ideal_from_measured_mm(xy_bar, K_003, P_003)
    np.testing.assert_allclose(ideal, xy_bar + brown_correction(xy_bar, K_003, P_003))
    back = measured_from_ideal_mm(ideal, K_003, P_003)
    assert back.shape == xy_bar.shape
    np.testing.assert_allclose(back, xy_bar, atol=1e-12)


def test_brown_correction_jacobian_finite_differences():
    xy = _xy_mm(n=40, seed=8)
    J_xy, J_K, J_P = brown_correction_jacobian(xy, K_003, P_003)
    assert J_xy.shape == (40, 2, 2)
    assert J_K.shape == (40, 2, 3)
    assert J_P.shape == (40, 2, 2)
    np.testing.assert_allclose(
        J_xy, _central_diff(lambda u: brown_correction(u, K_003, P_003), xy, 1e-5), atol=1e-10
    )
    np.testing.assert_allclose(
        J_K, _central_diff(lambda k: brown_correction(xy, k, P_003), K_003, 1e-7), rtol=1e-6
    )
    np.testing.assert_allclose(
        J_P,
        _central_diff(lambda p: brown_correction(xy, K_003, p), P_003, 1e-7),
        rtol=1e-6,
        atol=1e-9,
    )


def test_measured_from_ideal_outside_monotonic_region_raises():
    K = [-0.1, 0.0, 0.0]  # x(1 - 0.1 x²) is monotonic only for |x| < 1.83 mm
    with pytest.raises(ConvergenceError):
        measured_from_ideal_mm([[3.0, 0.0]], K, [0.0, 0.0])


# ------------------------------------------------------------------ error paths


@pytest.mark.parametrize(
    "call",
    [
        lambda: odd_radial_1d([1.0, np.nan], [1e-3]),
        lambda: odd_radial_1d_jacobian([1.0], [np.inf]),
        lambda: distort_opencv([[np.nan, 0.0]], DIST),
        lambda: undistort_opencv([[0.1, 0.0]], [np.nan, 0, 0, 0, 0]),
        lambda: distort_opencv_jacobian([[0.1, np.nan]], DIST),
        lambda: brown_correction([[np.nan, 0.0]], K_003, P_003),
        lambda: brown_correction_jacobian([[0.0, 0.0]], [np.nan, 0, 0], P_003),
        lambda: ideal_from_measured_mm([[0.0, 0.0]], K_003, [0.0, np.nan]),
        lambda: measured_from_ideal_mm([[np.nan, 0.0]], K_003, P_003),
    ],
)
def test_nan_raises(call):
    with pytest.raises(InputError, match="non-finite"):
        call()


@pytest.mark.parametrize(
    "call",
    [
        lambda: distort_opencv(np.zeros((4, 3)), DIST),
        lambda: undistort_opencv(np.zeros(4), DIST),
        lambda: brown_correction(np.zeros((4, 1)), K_003, P_003),
        lambda: measured_from_ideal_mm(np.zeros((2, 3)), K_003, P_003),
        lambda: distort_opencv(np.zeros((4, 2)), np.zeros((3, 5))),  # batch mismatch
    ],
)
def test_wrong_shape_raises(call):
    with pytest.raises(InputError, match="shape|broadcast"):
        call()


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: distort_opencv([[0.1, 0.1]], [0.1, 0.0, 0.0, 0.0]), "k1, k2, p1, p2, k3"),
        (lambda: distort_opencv_jacobian([[0.1, 0.1]], np.zeros(8)), "k1, k2, p1, p2, k3"),
        (lambda: undistort_opencv([[0.1, 0.1]], np.zeros(14)), "k1, k2, p1, p2, k3"),
        (lambda: brown_correction([[1.0, 1.0]], [1e-3, 0.0], P_003), "K1, K2, K3"),
        (lambda: brown_correction_jacobian([[1.0, 1.0]], K_003, [0.0]), "P1, P2"),
        (lambda: odd_radial_1d([1.0], []), "n >= 1"),
    ],
)
def test_wrong_coefficient_count_raises(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_bad_newton_settings_raise():
    with pytest.raises(InputError, match="tol"):
        undistort_opencv([[0.1, 0.1]], DIST, tol=0.0)
    with pytest.raises(InputError, match="max_iter"):
        measured_from_ideal_mm([[0.1, 0.1]], K_003, P_003, max_iter=0)


# ------------------------------------------------------------------ 1D: norm, distort/undistort


K_000 = np.array([1.459, -0.1636, 0.00526])  # 000 Table 1, px at u = d / 100 px


def test_odd_radial_1d_norm_is_the_line_scanner_polynomial():
    d = np.linspace(-450, 450, 91)
    u = d / 100.0
    expected = K_000[0] * u**3 + K_000[1] * u**5 + K_000[2] * u**7  # 000 eq. (2)
    np.testing.assert_allclose(
        odd_radial_1d(d, K_000, norm=100.0), expected, rtol=1e-14, atol=1e-13
    )
    # the Horner core to the last bits of the formula the line-scanner solver used
    u2 = u * u
    np.testing.assert_array_equal(
        odd_radial_1d(d, K_000, norm=100.0), u * u2 * (K_000[0] + u2 * (K_000[1] + u2 * K_000[2]))
    )


@pytest.mark.parametrize("norm", [1.0, 100.0])
def test_odd_radial_1d_jacobian_with_norm_finite_differences(norm):
    d = np.linspace(-4.4, 4.4, 37) * norm
    K = K_000 if norm == 100.0 else K_000 * 1e-2
    dd, dK = odd_radial_1d_jacobian(d, K, norm)
    h = 1e-5 * norm
    num = (odd_radial_1d(d + h, K, norm) - odd_radial_1d(d - h, K, norm)) / (2 * h)
    np.testing.assert_allclose(dd, num, rtol=1e-8, atol=1e-10)
    num_dK = _central_diff(lambda k: odd_radial_1d(d, k, norm)[..., None], K, 1e-6)[:, 0, :]
    np.testing.assert_allclose(dK, num_dK, rtol=1e-8, atol=1e-8)


def test_1d_distort_undistort_round_trip():
    from hsgeo.distortion import ideal_from_measured_1d, measured_from_ideal_1d

    d = np.linspace(-440, 440, 177)
    t = ideal_from_measured_1d(d, K_000, 100.0)
    np.testing.assert_allclose(t, d - odd_radial_1d(d, K_000, 100.0), rtol=0, atol=1e-12)
    back, Fp = measured_from_ideal_1d(t, K_000, 100.0)
    np.testing.assert_allclose(back, d, rtol=0, atol=1e-8)
    np.testing.assert_allclose(Fp, 1 - odd_radial_1d_jacobian(d, K_000, 100.0)[0], atol=1e-9)
    # beyond the fold the inverse is not the physical one
    with pytest.raises(ConvergenceError, match="folded"):
        measured_from_ideal_1d(2000.0, K_000, 100.0)  # d − δ(d) never reaches it
    with pytest.raises(InputError, match="norm"):
        odd_radial_1d(1.0, K_000, norm=0.0)


# ------------------------------------------------------------------ 002 line form


DIST_002 = np.array([-4e-5, 3e-7, 2.5e-5, -3e-5])  # K1 mm^-2, K2 mm^-4, P1, P2 mm^-1


def test_pushbroom_line_values_and_jacobian():
    from hsgeo.distortion import distort_pushbroom_line, distort_pushbroom_line_jacobian

    xy = np.random.default_rng(3).uniform(-8, 8, (4, 25, 2))
    x, y = xy[..., 0], xy[..., 1]
    K1, K2, P1, P2 = DIST_002
    out = distort_pushbroom_line(xy, DIST_002)
    assert out.shape == xy.shape
    # 002 eq. (3)
    np.testing.assert_allclose(
        out[..., 0], x + K1 * x**3 + K2 * x**5 + 3 * P1 * x**2, rtol=1e-15, atol=1e-15
    )
    np.testing.assert_allclose(out[..., 1], y + P2 * x**2, rtol=1e-15, atol=1e-15)
    J_xy, J_d = distort_pushbroom_line_jacobian(xy, DIST_002)
    assert J_xy.shape == (4, 25, 2, 2) and J_d.shape == (4, 25, 2, 4)
    num = _central_diff(lambda v: distort_pushbroom_line(v, DIST_002), xy, 1e-6)
    np.testing.assert_allclose(J_xy, num, atol=1e-8)
    num_d = _central_diff(lambda k: distort_pushbroom_line(xy, k), DIST_002, 1e-8)
    np.testing.assert_allclose(J_d, num_d, rtol=1e-6, atol=1e-6)


def test_pushbroom_line_round_trip_and_errors():
    from hsgeo.distortion import distort_pushbroom_line, undistort_pushbroom_line

    xy = np.random.default_rng(4).uniform(-8, 8, (300, 2))
    back = undistort_pushbroom_line(distort_pushbroom_line(xy, DIST_002), DIST_002)
    np.testing.assert_allclose(back, xy, rtol=0, atol=1e-11)
    with pytest.raises(InputError, match="K1, K2, P1, P2"):
        distort_pushbroom_line(xy, DIST_002[:3])
    with pytest.raises(InputError):
        distort_pushbroom_line([[np.nan, 0.0]], DIST_002)
    with pytest.raises(ConvergenceError):  # far on the folded part of a strong polynomial
        undistort_pushbroom_line([[-60.0, 0.0]], [1e-2, 0.0, 0.0, 0.0], max_iter=5)
