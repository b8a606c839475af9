"""Frame-camera models: Jacobians, projections against OpenCV, round trips, bad input."""

import cv2
import numpy as np
import pytest
from toy_models import frame_scene

from hsgeo import InputError
from hsgeo.adjust.checks import check_jacobian
from hsgeo.rotations import R_from_opk, R_from_rotvec, opk_from_R
from hsgeo.sensors.frame import (
    FrameOpenCV,
    FramePhotogrammetric,
    mm_to_pixel,
    pixel_to_mm,
    project_opencv,
)


def scene(seed=0, n=30, n_views=3):
    return frame_scene(np.random.default_rng(seed), n, n_views)


def test_project_opencv_matches_cv2():
    X, poses, view, Xall = scene()
    intr = np.array([800.0, 790.0, 320.0, 240.0])
    dist = np.array([-0.2, 0.1, 1e-3, -2e-3, 0.05])
    uv = project_opencv(poses, view, Xall, intr, dist)
    K = np.array([[800.0, 0, 320], [0, 790, 240], [0, 0, 1]])
    for i in range(poses.shape[0]):
        R_cw = R_from_opk(*poses[i, :3]).T
        rvec, _ = cv2.Rodrigues(R_cw)
        tvec = -R_cw @ poses[i, 3:]
        ref, _ = cv2.projectPoints(X, rvec, tvec, K, dist)
        np.testing.assert_allclose(uv[view == i], ref.reshape(-1, 2), atol=1e-9)


def test_opencv_jacobians():
    X, poses, view, Xall = scene(1)
    intr = np.array([800.0, 790.0, 320.0, 240.0])
    dist = np.array([-0.2, 0.1, 1e-3, -2e-3, 0.05])
    uv = project_opencv(poses, view, Xall, intr, dist) + 0.3
    point = np.tile(np.arange(X.shape[0]), poses.shape[0])
    blk = FrameOpenCV(view, uv, 0.5, point=point)
    vals = {"intrinsics": intr, "distortion": dist, "poses": poses, "points": X}
    for name, h in [("intrinsics", 1e-4), ("distortion", 1e-7), ("poses", 1e-7), ("points", 1e-7)]:
        assert check_jacobian(blk, vals, name, h) < 1e-6, name


def test_photogrammetric_jacobians():
    X, poses, view, Xall = scene(2)
    poses[:, 0] += np.pi  # the photogrammetric camera looks along its -z axis
    rng = np.random.default_rng(0)
    xy = rng.uniform(-3, 3, (Xall.shape[0], 2))
    point = np.tile(np.arange(X.shape[0]), poses.shape[0])
    blk = FramePhotogrammetric(view, xy, 0.003, point=point)
    vals = {
        "interior": np.array([9.0, 0.05, -0.03]),
        "distortion_mm": np.array([-3e-3, 2e-5, -1e-7, 1e-5, -2e-5]),
        "poses": poses,
        "points": X,
    }
    for name, h in [("interior", 1e-6), ("distortion_mm", 1e-9), ("poses", 1e-7), ("points", 1e-7)]:
        assert check_jacobian(blk, vals, name, h) < 1e-6, name


def test_photogrammetric_noise_free_residual_is_zero():
    """Generate measured coordinates by inverting the corrections: the residual vanishes."""
    from hsgeo.distortion import measured_from_ideal_mm
    from hsgeo.sensors.frame import camera_coordinates

    X, poses, view, Xall = scene(3)
    poses[:, 0] += np.pi
    f, x0, y0 = 9.0, 0.05, -0.03
    K, P = np.array([-3e-3, 2e-5, -1e-7]), np.array([1e-5, -2e-5])
    Xc, _, _ = camera_coordinates(poses, view, Xall, False)
    ideal = -f * Xc[:, :2] / Xc[:, 2:3]
    xy = measured_from_ideal_mm(ideal, K, P) + [x0, y0]
    blk = FramePhotogrammetric(view, xy, 0.003, X=Xall)
    r, _ = blk.evaluate(
        {
            "interior": np.array([f, x0, y0]),
            "distortion_mm": np.concatenate([K, P]),
            "poses": poses,
        },
        False,
    )
    assert np.max(np.abs(r)) < 1e-12


def test_pixel_mm_round_trip():
    uv = np.random.default_rng(0).uniform(0, 640, (100, 2))
    xy = pixel_to_mm(uv, (640, 480), 0.0055)
    np.testing.assert_allclose(mm_to_pixel(xy, (640, 480), 0.0055), uv, atol=1e-12)
    np.testing.assert_allclose(pixel_to_mm([[319.5, 239.5]], (640, 480), 0.0055), [[0, 0]])
    assert pixel_to_mm([[319.5, 0.0]], (640, 480), 1.0)[0, 1] > 0  # y up


def test_pose_convention_against_rodrigues():
    rv = np.array([0.3, -0.2, 2.9])
    R_cw = R_from_rotvec(rv)
    np.testing.assert_allclose(R_from_opk(*opk_from_R(R_cw.T)), R_cw.T, atol=1e-12)


def test_bad_input():
    with pytest.raises(InputError, match="NaN"):
        FrameOpenCV(np.array([0, 0]), np.array([[1.0, np.nan], [2, 3]]), 1.0, X=np.zeros((2, 3)))
    with pytest.raises(InputError, match=r"\(n, 2\)"):
        FrameOpenCV(np.array([0]), np.zeros((1, 3)), 1.0, X=np.zeros((1, 3)))
    with pytest.raises(InputError, match="either"):
        FrameOpenCV(np.array([0]), np.zeros((1, 2)), 1.0)
    X, poses, view, Xall = scene()
    blk = FrameOpenCV(view, np.zeros((len(view), 2)), 1.0, X=Xall)
    poses_behind = poses.copy()
    poses_behind[:, 0] -= np.pi
    with pytest.raises(InputError, match="behind"):
        blk.evaluate(
            {
                "intrinsics": np.array([800.0, 800, 320, 240]),
                "distortion": np.zeros(5),
                "poses": poses_behind,
            },
            False,
        )
