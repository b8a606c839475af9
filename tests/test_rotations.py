import cv2
import numpy as np
import pytest

from hsgeo.errors import InputError
from hsgeo.rotations import (
    R_ENU_FROM_NED,
    R_from_opk,
    R_from_rotvec,
    R_from_rpy,
    R_small,
    dR_dopk,
    dR_drpy,
    opk_from_R,
    rotvec_from_R,
    rpy_from_R,
    skew,
)

RNG_SEED = 20261122


def _random_angles(n=200, seed=RNG_SEED):
    """Random angles avoiding gimbal lock: |middle angle| < 80°."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(-np.pi, np.pi, n)
    b = rng.uniform(-np.deg2rad(80), np.deg2rad(80), n)
    c = rng.uniform(-np.pi, np.pi, n)
    return a, b, c


def _assert_rotation(R):
    I = np.broadcast_to(np.eye(3), R.shape)
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, I, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)


# ------------------------------------------------------------------ shapes and definitions


def test_opk_elementary_definition():
    w, p, k = 0.3, -0.2, 1.1
    cw, sw, cp, sp, ck, sk = np.cos(w), np.sin(w), np.cos(p), np.sin(p), np.cos(k), np.sin(k)
    Rx = np.array([[1, 0, 0], [0, cw, -sw], [0, sw, cw]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[ck, -sk, 0], [sk, ck, 0], [0, 0, 1]])
    np.testing.assert_allclose(R_from_opk(w, p, k), Rx @ Ry @ Rz, atol=1e-15)
    np.testing.assert_allclose(R_from_rpy(w, p, k), Rz @ Ry @ Rx, atol=1e-15)


def test_R_world_from_cam_columns_are_camera_axes():
    # κ = 90°: camera x axis points along world y.
    R = R_from_opk(0.0, 0.0, np.pi / 2)
    np.testing.assert_allclose(R[:, 0], [0, 1, 0], atol=1e-15)


def test_batch_shapes_and_broadcasting():
    rng = np.random.default_rng(1)
    w = rng.normal(size=(4, 5))
    R = R_from_opk(w, 0.1, rng.normal(size=(5,)))
    assert R.shape == (4, 5, 3, 3)
    assert opk_from_R(R).shape == (4, 5, 3)
    assert dR_dopk(w, 0.1, 0.2).shape == (4, 5, 3, 3, 3)
    assert R_from_rpy(w, w, w).shape == (4, 5, 3, 3)
    assert rpy_from_R(R).shape == (4, 5, 3)
    assert dR_drpy(w, w, w).shape == (4, 5, 3, 3, 3)
    v = rng.normal(size=(4, 5, 3))
    assert R_from_rotvec(v).shape == (4, 5, 3, 3)
    assert rotvec_from_R(R).shape == (4, 5, 3)
    assert skew(v).shape == (4, 5, 3, 3)
    assert R_small(v).shape == (4, 5, 3, 3)
    assert R_from_opk(0.1, 0.2, 0.3).shape == (3, 3)
    assert R_from_opk(0.1, 0.2, 0.3).dtype == np.float64


# ------------------------------------------------------------------ round trips


def test_opk_round_trip_and_orthonormality():
    w, p, k = _random_angles()
    R = R_from_opk(w, p, k)
    _assert_rotation(R)
    np.testing.assert_allclose(opk_from_R(R), np.stack([w, p, k], -1), atol=1e-12)


def test_rpy_round_trip_and_orthonormality():
    r, p, y = _random_angles(seed=7)
    R = R_from_rpy(r, p, y)
    _assert_rotation(R)
    np.testing.assert_allclose(rpy_from_R(R), np.stack([r, p, y], -1), atol=1e-12)


def test_R_ENU_FROM_NED_maps_the_axes_and_is_its_own_inverse():
    _assert_rotation(R_ENU_FROM_NED)
    np.testing.assert_array_equal(R_ENU_FROM_NED @ R_ENU_FROM_NED, np.eye(3))
    np.testing.assert_array_equal(R_ENU_FROM_NED @ [1.0, 0, 0], [0, 1.0, 0])  # north
    np.testing.assert_array_equal(R_ENU_FROM_NED @ [0, 1.0, 0], [1.0, 0, 0])  # east
    np.testing.assert_array_equal(R_ENU_FROM_NED @ [0, 0, 1.0], [0, 0, -1.0])  # down
    with pytest.raises(ValueError):  # a constant: read-only
        R_ENU_FROM_NED[0, 0] = 1.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_gimbal_lock_returns_equivalent_angles(sign):
    R = R_from_opk(0.4, sign * np.pi / 2, 0.3)
    np.testing.assert_allclose(R_from_opk(*opk_from_R(R)), R, atol=1e-12)
    assert opk_from_R(R)[2] == 0.0
    R = R_from_rpy(0.4, sign * np.pi / 2, 0.3)
    np.testing.assert_allclose(R_from_rpy(*rpy_from_R(R)), R, atol=1e-12)


def test_rotvec_round_trip_random():
    rng = np.random.default_rng(RNG_SEED)
    axis = rng.normal(size=(300, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    theta = rng.uniform(0, np.pi * 0.999, 300)
    v = axis * theta[:, None]
    R = R_from_rotvec(v)
    _assert_rotation(R)
    np.testing.assert_allclose(rotvec_from_R(R), v, atol=1e-12)


@pytest.mark.parametrize("theta", [0.0, 1e-14, 1e-10, 1e-6, 1e-4, 1.0001e-4, 1e-3])
def test_rotvec_round_trip_near_zero(theta):
    axis = np.array([0.3, -0.5, 0.8])
    v = theta * axis / np.linalg.norm(axis)
    R = R_from_rotvec(v)
    _assert_rotation(R)
    np.testing.assert_allclose(rotvec_from_R(R), v, atol=1e-18, rtol=1e-10)
    # first order agrees with R_small to O(θ²)
    np.testing.assert_allclose(R, R_small(v), atol=theta**2)


@pytest.mark.parametrize("eps", [0.0, 1e-12, 1e-8, 1e-5, 1e-2])
def test_rotvec_round_trip_near_pi(eps):
    axis = np.array([-0.2, 0.6, 0.77])
    axis /= np.linalg.norm(axis)
    v = (np.pi - eps) * axis
    R = R_from_rotvec(v)
    _assert_rotation(R)
    v_back = rotvec_from_R(R)
    if eps == 0.0:  # ±π n are the same rotation
        assert np.allclose(v_back, v, atol=1e-10) or np.allclose(v_back, -v, atol=1e-10)
    else:
        np.testing.assert_allclose(v_back, v, atol=1e-10)
    np.testing.assert_allclose(R_from_rotvec(v_back), R, atol=1e-14)


# ------------------------------------------------------------------ reference: OpenCV


def test_rotvec_against_cv2_rodrigues():
    rng = np.random.default_rng(3)
    axis = rng.normal(size=(50, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    theta = np.concatenate([[0.0, 1e-9, 1e-6], rng.uniform(0, np.pi * 0.99, 47)])
    v = axis * theta[:, None]
    R = R_from_rotvec(v)
    for vi, Ri, ti in zip(v, R, theta, strict=True):
        R_cv, _ = cv2.Rodrigues(vi.reshape(3, 1))
        np.testing.assert_allclose(Ri, R_cv, atol=1e-14)
        v_cv, _ = cv2.Rodrigues(Ri)
        if ti < 1e-5:
            # OpenCV's matrix -> vector returns exactly 0 when sin θ < 1e-5 (a threshold in
            # modules/calib3d/src/calibration.cpp); ours keeps the small angle.
            np.testing.assert_array_equal(v_cv.ravel(), 0.0)
            np.testing.assert_allclose(rotvec_from_R(Ri), vi, atol=1e-15)
        else:
            np.testing.assert_allclose(rotvec_from_R(Ri), v_cv.ravel(), atol=1e-12)


# ------------------------------------------------------------------ Jacobians


def _central_difference(fun, angles, h=1e-6):
    out = []
    for k in range(3):
        up = [a.copy() for a in angles]
        dn = [a.copy() for a in angles]
        up[k] = up[k] + h
        dn[k] = dn[k] - h
        out.append((fun(*up) - fun(*dn)) / (2 * h))
    return np.stack(out, axis=-3)


@pytest.mark.parametrize(("R_fun", "dR_fun"), [(R_from_opk, dR_dopk), (R_from_rpy, dR_drpy)])
def test_dR_against_finite_differences(R_fun, dR_fun):
    angles = [np.asarray(a) for a in _random_angles(n=50, seed=11)]
    np.testing.assert_allclose(dR_fun(*angles), _central_difference(R_fun, angles), atol=1e-9)


def test_skew_is_cross_product():
    rng = np.random.default_rng(5)
    v, u = rng.normal(size=(2, 10, 3))
    np.testing.assert_allclose((skew(v) @ u[..., None])[..., 0], np.cross(v, u), atol=1e-15)
    np.testing.assert_allclose(skew(v), -np.swapaxes(skew(v), -1, -2))


# ------------------------------------------------------------------ error paths


@pytest.mark.parametrize("fun", [R_from_opk, R_from_rpy, dR_dopk, dR_drpy])
def test_nan_angle_raises(fun):
    with pytest.raises(InputError, match="non-finite"):
        fun(0.1, np.nan, 0.2)


@pytest.mark.parametrize("fun", [R_from_opk, R_from_rpy])
def test_non_broadcasting_angles_raise(fun):
    with pytest.raises(InputError, match="broadcast"):
        fun(np.zeros(3), np.zeros(4), 0.0)


@pytest.mark.parametrize("fun", [R_from_rotvec, skew, R_small])
def test_vector_wrong_shape_raises(fun):
    with pytest.raises(InputError, match=r"\(\.\.\., 3\)"):
        fun(np.zeros((4, 2)))
    with pytest.raises(InputError, match="non-finite"):
        fun([0.0, np.nan, 0.0])


@pytest.mark.parametrize("fun", [opk_from_R, rpy_from_R, rotvec_from_R])
def test_bad_rotation_raises(fun):
    with pytest.raises(InputError, match=r"\(\.\.\., 3, 3\)"):
        fun(np.eye(2))
    with pytest.raises(InputError, match="non-finite"):
        fun(np.full((3, 3), np.nan))
    with pytest.raises(InputError, match="orthonormal"):
        fun(np.eye(3) * 1.01)
    with pytest.raises(InputError, match="reflection"):
        fun(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match="float"):
        fun([["a", "b", "c"]] * 3)


def test_R_photogrammetric_from_opencv_cam():
    from hsgeo.rotations import R_photogrammetric_from_opencv_cam

    F = R_photogrammetric_from_opencv_cam()
    np.testing.assert_array_equal(F @ F, np.eye(3))  # its own inverse
    assert np.linalg.det(F) == 1.0  # a rotation, not a reflection
    # OpenCV's view direction (+z) is the photogrammetric −z; y down is y up
    np.testing.assert_array_equal(F @ [0, 0, 1], [0, 0, -1])
    np.testing.assert_array_equal(F @ [0, 1, 0], [0, -1, 0])
    F[0, 0] = 5.0  # a fresh array each call
    assert R_photogrammetric_from_opencv_cam()[0, 0] == 1.0


@pytest.mark.parametrize("scale", [1e-7, 1e-3, 0.5, 3.0])
def test_dR_drotvec_matches_finite_differences(scale):
    """∂R/∂v of the rotation vector against central differences of R_from_rotvec."""
    from hsgeo.rotations import dR_drotvec

    rng = np.random.default_rng(7)
    v = rng.normal(size=(4, 3))
    v = scale * v / np.linalg.norm(v, axis=1, keepdims=True)
    d = dR_drotvec(v)
    h = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = (R_from_rotvec(v + e) - R_from_rotvec(v - e)) / (2 * h)
        np.testing.assert_allclose(d[:, k], fd, atol=2e-9)


def test_R_from_rotvec_matches_scipy():
    """Rodrigues' formula against scipy.spatial.transform.Rotation (an independent code)."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    v = rng.normal(size=(20, 3)) * np.array([[1e-6], [0.1], [1.0], [3.0]]).repeat(5, 0)
    np.testing.assert_allclose(R_from_rotvec(v), Rotation.from_rotvec(v).as_matrix(), atol=1e-14)
