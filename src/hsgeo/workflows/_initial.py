"""Initial exterior orientation of a frame camera from ``cv2.solvePnP``, for adjustments.

One function shared by the frame-camera and Rikola workflows (the initial values of their
bundle adjustments): OpenCV's iterative PnP without distortion, converted to the project's
``(ω, φ, κ, X0, Y0, Z0)`` pose of :mod:`hsgeo.sensors.frame`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import InputError, ObservationError
from hsgeo.rotations import R_from_rotvec, R_photogrammetric_from_opencv_cam, opk_from_R

__all__ = ["pose_from_pnp"]


def pose_from_pnp(
    X_m: ArrayLike,
    uv_px: ArrayLike,
    K_px: ArrayLike,
    *,
    frame: str = "photogrammetric",
    what: str = "view",
) -> NDArray:
    """Pose of a camera from ≥ 4 object points and their pixels (``cv2.solvePnP``, no distortion).

    Parameters
    ----------
    X_m : (n, 3) array_like, m
        Object points (world frame).
    uv_px : (n, 2) array_like, px
        Their image coordinates (OpenCV convention: origin at the centre of the top-left
        pixel, v down).
    K_px : (3, 3) array_like
        Camera matrix ``[[f, 0, cx], [0, f, cy], [0, 0, 1]]`` in pixels.
    frame : {"photogrammetric", "opencv"}
        The camera frame of the returned angles: ``R_world_from_cam`` of the photogrammetric
        camera (x right, y up, z backward) or of OpenCV's (x right, y down, z forward); see
        :func:`hsgeo.rotations.R_photogrammetric_from_opencv_cam`.
    what : str
        How to name the camera in an error message (e.g. ``"view 3"``, ``"cube 2"``).

    Returns
    -------
    pose : (6,) ndarray
        ``(ω, φ, κ)`` in rad with ``R_world_from_cam = R_from_opk(ω, φ, κ)``, and the
        projection centre ``(X0, Y0, Z0)`` in m.

    Raises
    ------
    InputError
        On an unknown ``frame``.
    ObservationError
        If OpenCV finds no pose (fewer than 4 points, or degenerate ones).
    """
    import cv2

    if frame not in ("photogrammetric", "opencv"):
        raise InputError(f"frame must be 'photogrammetric' or 'opencv', got {frame!r}")
    X = np.asarray(X_m, dtype=np.float64)
    uv = np.asarray(uv_px, dtype=np.float64)
    if len(X) < 4:
        raise ObservationError(f"{what}: {len(X)} points; a pose needs at least 4")
    ok, rvec, tvec = cv2.solvePnP(
        X, uv, np.asarray(K_px, dtype=np.float64), np.zeros(5), flags=cv2.SOLVEPNP_ITERATIVE
    )
    if not ok:
        raise ObservationError(f"{what}: no initial pose from solvePnP (degenerate points?)")
    R_opencv_cam_from_world = R_from_rotvec(rvec.ravel())
    X0 = -R_opencv_cam_from_world.T @ tvec.ravel()
    R_world_from_cam = R_opencv_cam_from_world.T
    if frame == "photogrammetric":
        R_world_from_cam = R_world_from_cam @ R_photogrammetric_from_opencv_cam().T
    return np.concatenate([opk_from_R(R_world_from_cam), X0])
