"""workflows._initial.pose_from_pnp: the one solvePnP initial pose (frame and Rikola)."""

import cv2
import numpy as np
import pytest

from hsgeo.errors import InputError, ObservationError
from hsgeo.rotations import R_from_opk, R_photogrammetric_from_opencv_cam, rotvec_from_R
from hsgeo.workflows._initial import pose_from_pnp


def _scene():
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-0.5, 0.5, (30, 2)), rng.uniform(-0.1, 0.1, 30)])
    opk = np.array([0.05, -0.03, 0.4])  # photogrammetric R_world_from_cam
    X0 = np.array([0.1, -0.05, 2.0])  # above the board, looking down (−z of the camera)
    K = np.array([[1500.0, 0, 511.5], [0, 1500.0, 511.5], [0, 0, 1]])
    R_cv_from_world = (R_from_opk(*opk) @ R_photogrammetric_from_opencv_cam().T).T
    rvec = rotvec_from_R(R_cv_from_world)
    tvec = -R_cv_from_world @ X0
    uv, _ = cv2.projectPoints(X, rvec, tvec, K, np.zeros(5))
    return X, uv.reshape(-1, 2), K, opk, X0


def test_recovers_the_photogrammetric_pose():
    X, uv, K, opk, X0 = _scene()
    pose = pose_from_pnp(X, uv, K)
    np.testing.assert_allclose(pose[:3], opk, atol=1e-8)
    np.testing.assert_allclose(pose[3:], X0, atol=1e-8)


def test_opencv_frame_differs_by_the_flip():
    X, uv, K, opk, X0 = _scene()
    pose = pose_from_pnp(X, uv, K, frame="opencv")
    R_world_from_cv = R_from_opk(*pose[:3])
    np.testing.assert_allclose(
        R_world_from_cv @ R_photogrammetric_from_opencv_cam().T, R_from_opk(*opk), atol=1e-8
    )
    np.testing.assert_allclose(pose[3:], X0, atol=1e-8)


def test_errors():
    X, uv, K, *_ = _scene()
    with pytest.raises(ObservationError, match="cube 7: 3 points"):
        pose_from_pnp(X[:3], uv[:3], K, what="cube 7")
    with pytest.raises(InputError, match="frame"):
        pose_from_pnp(X, uv, K, frame="ned")
