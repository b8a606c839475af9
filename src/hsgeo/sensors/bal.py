"""Snavely's camera of the BAL data set ("Bundle Adjustment in the Large") as a residual block.

Agarwal, Snavely, Seitz, Szeliski (2010); https://grail.cs.washington.edu/projects/bal/. Each
camera has 9 parameters ``(v, t, f, k1, k2)`` (:data:`hsgeo.io.bal.CAMERA_COLUMNS`): the
rotation vector ``v`` of ``R = R_cam_from_world`` (:func:`hsgeo.rotations.R_from_rotvec`), the
translation ``t``, the focal length ``f`` in px and two radial coefficients. With BAL's sign
conventions (the camera looks down −z, the image y axis points up)::

    P  = R·X + t
    p  = −P_xy / P_z
    p' = f · (1 + k1·|p|² + k2·|p|⁴) · p          residual = p' − observed   (px)

The model is not :class:`~hsgeo.sensors.frame.FrameOpenCV`'s: the distortion has no tangential
or k3 term, the pose is a rotation vector with ``t`` (not a projection centre and ω, φ, κ),
and every camera has its own f, k1, k2.
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
from numba import njit

from hsgeo.adjust import Indexed, ResidualBlock
from hsgeo.errors import InputError
from hsgeo.rotations import R_from_rotvec, dR_drotvec

__all__ = ["SnavelyReprojection", "camera_points", "in_front"]


def camera_points(cameras: np.ndarray, points: np.ndarray, cam: np.ndarray, pt: np.ndarray):
    """``P = R·X + t`` of each observation (BAL camera frame; in front of the camera: P_z < 0).

    Parameters
    ----------
    cameras : (n_cameras, 9) ndarray
    points : (n_points, 3) ndarray
    cam, pt : (n,) int ndarray
        Camera and point of each observation.

    Returns
    -------
    P : (n, 3) ndarray
    """
    R = R_from_rotvec(cameras[:, :3])
    return np.einsum("nij,nj->ni", R[cam], points[pt]) + cameras[cam, 3:6]


def in_front(cameras: np.ndarray, points: np.ndarray, cam: np.ndarray, pt: np.ndarray):
    """Whether each observed point lies in front of its camera (``P_z < 0``, BAL's −z view).

    An observation of a point behind its camera cannot be a real image of it; COLMAP (and so
    Ceres through pycolmap) leaves such observations out of its problem.

    Returns
    -------
    keep : (n,) bool ndarray
    """
    return camera_points(cameras, points, cam, pt)[:, 2] < 0.0


class SnavelyReprojection(ResidualBlock):
    """Reprojection residuals of BAL cameras (px), see the module docstring.

    Parameter blocks (roles, default names): ``cameras`` ``(n_cameras, 9)``, ``points``
    ``(n_points, 3)`` (a ``points=True`` block, eliminated by the Schur complement).

    Parameters
    ----------
    camera_index, point_index : (n,) int ndarray
        Camera and point of each observation.
    xy_px : (n, 2) ndarray
        Observed image coordinates, px from the image centre, y up.
    sigma_px : float or (n, 2) ndarray, default 1.0
        A-priori σ; with 1 px the engine's cost ``½ Σ (r/σ)²`` is Ceres' ``½ Σ r²``.
    blocks : mapping, optional
        Parameter-block names by role (see :class:`~hsgeo.adjust.ResidualBlock`).
    """

    name = "image points (BAL / Snavely)"
    group_size = 2
    BLOCKS = MappingProxyType({"cameras": "cameras", "points": "points"})

    def __init__(self, camera_index, point_index, xy_px, sigma_px=1.0, *, blocks=None, name=None):
        xy = np.asarray(xy_px, dtype=np.float64)
        cam = np.asarray(camera_index)
        pt = np.asarray(point_index)
        if xy.ndim != 2 or xy.shape[1] != 2:
            raise InputError(f"BAL observations: image coordinates must be (n, 2), got {xy.shape}")
        for label, idx in (("camera_index", cam), ("point_index", pt)):
            if idx.shape != (xy.shape[0],) or not np.issubdtype(idx.dtype, np.integer):
                raise InputError(
                    f"BAL observations: {label} must be (n,) integers matching {xy.shape[0]} "
                    "image points"
                )
        if not np.all(np.isfinite(xy)):
            raise InputError("BAL observations: image coordinates contain NaN or inf")
        super().__init__(
            np.broadcast_to(np.asarray(sigma_px, float), xy.shape).ravel(),
            name=name,
            blocks=blocks,
        )
        self.cam = cam.astype(np.int64)
        self.pt = pt.astype(np.int64)
        self.xy = xy

    def evaluate(self, values, jacobian):
        cams = values[self.blocks["cameras"]]
        X = values[self.blocks["points"]]
        R = R_from_rotvec(cams[:, :3])  # per camera: the rotations module's Rodrigues
        n = self.xy.shape[0]
        r2 = np.empty((n, 2))
        if not jacobian:
            none = np.empty((0, 2, 9)), np.empty((0, 2, 3))
            _snavely(
                R, np.empty((0, 3, 3, 3)), cams, X, self.cam, self.pt, self.xy, r2, *none, False
            )
            return r2.ravel(), None
        d_cam = np.empty((n, 2, 9))
        d_X = np.empty((n, 2, 3))
        dR = dR_drotvec(cams[:, :3])
        _snavely(R, dR, cams, X, self.cam, self.pt, self.xy, r2, d_cam, d_X, True)
        jac = {
            self.blocks["cameras"]: Indexed(np.repeat(self.cam, 2), d_cam.reshape(2 * n, 9)),
            self.blocks["points"]: Indexed(np.repeat(self.pt, 2), d_X.reshape(2 * n, 3)),
        }
        return r2.ravel(), jac


@njit(cache=True)
def _snavely(R, dR, cams, X, cam, pt, xy, r2, d_cam, d_X, jacobian):  # pragma: no cover - compiled
    """Residuals (and Jacobians) of Snavely's camera, one observation at a time.

    ``R`` (n_cameras, 3, 3) and ``dR`` (n_cameras, 3, 3, 3) come from
    :func:`~hsgeo.rotations.R_from_rotvec` and :func:`~hsgeo.rotations.dR_drotvec`.
    """
    B = np.empty((2, 3))
    for o in range(xy.shape[0]):
        c = cam[o]
        q = pt[o]
        P0 = cams[c, 3]
        P1 = cams[c, 4]
        P2 = cams[c, 5]
        for j in range(3):
            P0 += R[c, 0, j] * X[q, j]
            P1 += R[c, 1, j] * X[q, j]
            P2 += R[c, 2, j] * X[q, j]
        iz = 1.0 / P2
        p0 = -P0 * iz  # BAL: p = −P/P_z
        p1 = -P1 * iz
        f = cams[c, 6]
        k1 = cams[c, 7]
        k2 = cams[c, 8]
        n2 = p0 * p0 + p1 * p1
        rad = 1.0 + n2 * (k1 + k2 * n2)
        fr = f * rad
        r2[o, 0] = fr * p0 - xy[o, 0]
        r2[o, 1] = fr * p1 - xy[o, 1]
        if not jacobian:
            continue
        # ∂p'/∂p = f (r I + 2 (k1 + 2 k2 |p|²) p pᵀ);  ∂p/∂P = −(1/P_z) [I | p]
        g = 2.0 * f * (k1 + 2.0 * k2 * n2)
        a00 = fr + g * p0 * p0
        a01 = g * p0 * p1
        a11 = fr + g * p1 * p1
        B[0, 0] = -a00 * iz
        B[0, 1] = -a01 * iz
        B[0, 2] = -(a00 * p0 + a01 * p1) * iz
        B[1, 0] = -a01 * iz
        B[1, 1] = -a11 * iz
        B[1, 2] = -(a01 * p0 + a11 * p1) * iz
        for a in range(2):
            for k in range(3):
                # ∂P/∂v_k = (∂R/∂v_k) X;  ∂P/∂X = R;  ∂P/∂t = I
                acc = 0.0
                accx = 0.0
                for i in range(3):
                    dPi = 0.0
                    for j in range(3):
                        dPi += dR[c, k, i, j] * X[q, j]
                    acc += B[a, i] * dPi
                    accx += B[a, i] * R[c, i, k]
                d_cam[o, a, k] = acc
                d_cam[o, a, 3 + k] = B[a, k]
                d_X[o, a, k] = accx
        d_cam[o, 0, 6] = rad * p0
        d_cam[o, 1, 6] = rad * p1
        d_cam[o, 0, 7] = f * n2 * p0
        d_cam[o, 1, 7] = f * n2 * p1
        d_cam[o, 0, 8] = f * n2 * n2 * p0
        d_cam[o, 1, 8] = f * n2 * n2 * p1
