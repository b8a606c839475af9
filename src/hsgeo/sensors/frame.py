"""Frame cameras: collinearity with Brown distortion, in two forms.

**OpenCV form** (:class:`FrameOpenCV`): the camera frame has x right, y down, z forward; the
distortion is applied to the *normalised ideal* coordinates ``(X_c/Z_c, Y_c/Z_c)`` and the
intrinsics are in pixels::

    (x_d, y_d) = distort_opencv(X_c/Z_c, Y_c/Z_c; k1, k2, p1, p2, k3)
    u = fx·x_d + cx,   v = fy·y_d + cy

**Photogrammetric form** (:class:`FramePhotogrammetric`, 003 Table 3; Fraser 1997): the camera
frame has x right, y up, z backward (the camera looks along −z); image coordinates are in mm
from the image centre, and the corrections are a function of the *measured* coordinates reduced
to the principal point, x̄ = x − x0::

    x̄ + δx(x̄, ȳ) = −f·X_c/Z_c,    ȳ + δy(x̄, ȳ) = −f·Y_c/Z_c          (collinearity)

with Brown's δ (``hsgeo.distortion.brown_correction``). The residual is the left side minus the
right side, evaluated at the observation, in mm. The two forms are different models, not just
different units: one distorts the ideal ray, the other corrects the measured point.

Both share the exterior orientation of view ``i``, a row ``(ω, φ, κ, X0, Y0, Z0)`` of the
``poses`` block: ``R_world_from_cam = R_from_opk(ω, φ, κ)`` and the projection centre ``X0`` in
world units, so that ``X_c = R_world_from_camᵀ (X − X0)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from hsgeo.adjust import Indexed, ResidualBlock
from hsgeo.distortion import (
    brown_correction,
    brown_correction_jacobian,
    distort_opencv,
    distort_opencv_jacobian,
    undistort_opencv,
)
from hsgeo.errors import InputError, ObservationError
from hsgeo.rotations import R_from_opk, dR_dopk
from hsgeo.sensors.mount import Mount, unit

__all__ = [
    "FrameCamera",
    "body_frames",
    "POSE_COLUMNS",
    "camera_coordinates",
    "project_opencv",
    "pixels_opencv",
    "normalised_opencv",
    "FrameOpenCV",
    "FramePhotogrammetric",
    "pixel_to_mm",
    "mm_to_pixel",
    "OPENCV_INTRINSICS",
    "OPENCV_DISTORTION",
    "PHOTOGRAMMETRIC_INTERIOR",
    "PHOTOGRAMMETRIC_DISTORTION",
]

POSE_COLUMNS = ("omega_rad", "phi_rad", "kappa_rad", "X0", "Y0", "Z0")
OPENCV_INTRINSICS = ("fx_px", "fy_px", "cx_px", "cy_px")
OPENCV_DISTORTION = ("k1", "k2", "p1", "p2", "k3")
PHOTOGRAMMETRIC_INTERIOR = ("f_mm", "x0_mm", "y0_mm")
PHOTOGRAMMETRIC_DISTORTION = ("K1_per_mm2", "K2_per_mm4", "K3_per_mm6", "P1_per_mm", "P2_per_mm")


def camera_coordinates(poses: np.ndarray, view: np.ndarray, X: np.ndarray, jacobian: bool):
    """World points in the camera frame of their views.

    Parameters
    ----------
    poses : (n_views, 6) ndarray
        ``(ω, φ, κ)`` in rad of ``R_world_from_cam`` and the projection centre.
    view : (n,) int ndarray
        The view of each point.
    X : (n, 3) ndarray
        World coordinates.
    jacobian : bool

    Returns
    -------
    Xc : (n, 3) ndarray
        ``R_world_from_camᵀ (X − X0)``.
    dXc_dpose : (n, 3, 6) ndarray or None
    dXc_dX : (n, 3, 3) ndarray or None
        ``R_world_from_camᵀ`` per point.
    """
    R = R_from_opk(poses[:, 0], poses[:, 1], poses[:, 2])  # (n_views, 3, 3)
    Rt = np.swapaxes(R, 1, 2)[view]
    dX = X - poses[view, 3:6]
    Xc = np.einsum("nij,nj->ni", Rt, dX)
    if not jacobian:
        return Xc, None, None
    dR = dR_dopk(poses[:, 0], poses[:, 1], poses[:, 2])[view]  # (n, 3 angles, 3, 3)
    d_ang = np.einsum("nkji,nj->nik", dR, dX)  # (dR_k)ᵀ dX  -> (n, 3, 3 angles)
    d_pose = np.concatenate([d_ang, -Rt], axis=2)
    return Xc, d_pose, Rt


def _check_views(name, view, xy, X):
    view = np.asarray(view)
    xy = np.asarray(xy, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"{name}: image coordinates must be (n, 2), got {xy.shape}")
    if view.shape != (xy.shape[0],) or not np.issubdtype(view.dtype, np.integer):
        raise InputError(f"{name}: view must be (n,) integers matching {xy.shape[0]} points")
    if X is not None:
        X = np.asarray(X, dtype=np.float64)
        if X.shape != (xy.shape[0], 3):
            raise InputError(f"{name}: object points must be (n, 3), got {X.shape}")
        if not np.all(np.isfinite(X)):
            raise InputError(f"{name}: object points contain NaN or inf")
    if not np.all(np.isfinite(xy)):
        bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))[:5].tolist()
        raise InputError(f"{name}: image coordinates contain NaN or inf (rows {bad})")
    return view.astype(np.int64), xy, X


class _FrameBase(ResidualBlock):
    """Shared bookkeeping: which view and which object point each observation belongs to."""

    group_size = 2
    BLOCKS = MappingProxyType({"poses": "poses", "points": "points"})

    def __init__(self, view, xy, sigma, X=None, point=None, *, blocks=None, name=None):
        view, xy, X = _check_views(type(self).__name__, view, xy, X)
        if (X is None) == (point is None):
            raise InputError(
                "give either known object points X (n, 3) or point indices into "
                "a points block, not both"
            )
        super().__init__(
            np.broadcast_to(np.asarray(sigma, float), xy.shape).ravel(), name=name, blocks=blocks
        )
        self.view, self.xy, self.X = view, xy, X
        self.point = None if point is None else np.asarray(point, dtype=np.int64)

    def _world(self, values):
        return self.X if self.point is None else values[self.blocks["points"]][self.point]

    def _pack(self, r2, d_pose, d_X, extra):
        """Interleave (n, 2) residuals and Jacobians into rows x0, y0, x1, y1, …."""
        n = r2.shape[0]
        jac = dict(extra)
        jac[self.blocks["poses"]] = Indexed(np.repeat(self.view, 2), d_pose.reshape(2 * n, 6))
        if self.point is not None:
            jac[self.blocks["points"]] = Indexed(np.repeat(self.point, 2), d_X.reshape(2 * n, 3))
        return r2.ravel(), jac


def _dproj(Xc):
    """∂(X/Z, Y/Z)/∂Xc, (n, 2, 3)."""
    x, y, z = Xc[:, 0], Xc[:, 1], Xc[:, 2]
    iz = 1.0 / z
    zero = np.zeros_like(z)
    return np.stack(
        [np.stack([iz, zero, -x * iz * iz], axis=1), np.stack([zero, iz, -y * iz * iz], axis=1)],
        axis=1,
    )


def pixels_opencv(xy_n, intrinsics, dist):
    """OpenCV's pixel map, the one place it is coded: normalised ideal coordinates
    ``(X_c/Z_c, Y_c/Z_c)`` ``(n, 2)`` → pixels ``u = fx·x_d + cx``, ``v = fy·y_d + cy`` with
    ``(x_d, y_d) = distort_opencv(xy_n, dist)``.

    Returns
    -------
    uv_px : (n, 2) ndarray
    xy_d : (n, 2) ndarray
        The distorted normalised coordinates (for the derivatives w.r.t. fx, fy).
    """
    xd = distort_opencv(xy_n, dist)
    fx, fy, cx, cy = intrinsics
    return np.column_stack([fx * xd[:, 0] + cx, fy * xd[:, 1] + cy]), xd


def normalised_opencv(uv_px, intrinsics, dist) -> np.ndarray:
    """The inverse of :func:`pixels_opencv`: pixels ``(n, 2)`` → normalised ideal coordinates
    (undistorted by :func:`hsgeo.distortion.undistort_opencv`).
    """
    fx, fy, cx, cy = intrinsics
    uv = np.atleast_2d(np.asarray(uv_px, dtype=float))
    xd = np.column_stack([(uv[:, 0] - cx) / fx, (uv[:, 1] - cy) / fy])
    return undistort_opencv(xd, dist) if any(dist) else xd


def project_opencv(poses, view, X, intrinsics, dist):
    """Pixel coordinates of world points in the OpenCV form (see the module docstring).

    Returns
    -------
    uv_px : (n, 2) ndarray
    """
    Xc, _, _ = camera_coordinates(
        np.asarray(poses, float), np.asarray(view), np.asarray(X, float), False
    )
    return pixels_opencv(Xc[:, :2] / Xc[:, 2:3], intrinsics, dist)[0]


class FrameOpenCV(_FrameBase):
    """Reprojection residuals of a frame camera in OpenCV's form (pixels).

    Parameter blocks: ``intrinsics`` ``(fx, fy, cx, cy)`` in px, ``distortion``
    ``(k1, k2, p1, p2, k3)``, ``poses`` ``(n_views, 6)``, and optionally a points block.

    Parameters
    ----------
    view : (n,) int ndarray
    uv_px : (n, 2) ndarray
        Measured pixel coordinates (OpenCV convention: origin at the centre of the top-left
        pixel, x right, y down).
    sigma_px : float or (n, 2) ndarray
    X : (n, 3) ndarray, optional
        Known object points; or ``point`` indices into the points block.
    blocks : mapping, optional
        Parameter-block names by role (``poses``, ``points``, ``intrinsics``, ``distortion``;
        the defaults are the role names), see :class:`~hsgeo.adjust.ResidualBlock`.
    """

    name = "image points (OpenCV form)"
    BLOCKS = MappingProxyType(
        {**_FrameBase.BLOCKS, "intrinsics": "intrinsics", "distortion": "distortion"}
    )

    def __init__(self, view, uv_px, sigma_px=1.0, X=None, point=None, **kw):
        super().__init__(view, uv_px, sigma_px, X, point, **kw)

    def evaluate(self, values, jacobian):
        poses = values[self.blocks["poses"]]
        fx, fy, cx, cy = values[self.blocks["intrinsics"]]
        dist = values[self.blocks["distortion"]]
        Xc, d_pose, d_X = camera_coordinates(poses, self.view, self._world(values), jacobian)
        if np.any(Xc[:, 2] <= 0):
            raise InputError(
                f"{int(np.sum(Xc[:, 2] <= 0))} object points lie behind or in the plane of the "
                "camera: check the initial poses"
            )
        xn = Xc[:, :2] / Xc[:, 2:3]
        J_xy, J_dist = distort_opencv_jacobian(xn, dist)
        uv, xd = pixels_opencv(xn, (fx, fy, cx, cy), dist)
        r2 = uv - self.xy
        if not jacobian:
            return r2.ravel(), None
        n = r2.shape[0]
        F = np.array([fx, fy])
        d_intr = np.zeros((n, 2, 4))
        d_intr[:, 0, 0] = xd[:, 0]
        d_intr[:, 1, 1] = xd[:, 1]
        d_intr[:, 0, 2] = 1.0
        d_intr[:, 1, 3] = 1.0
        d_dist = F[None, :, None] * J_dist
        d_Xc = F[None, :, None] * np.einsum("nab,nbc->nac", J_xy, _dproj(Xc))
        dp = np.einsum("nac,nck->nak", d_Xc, d_pose)
        dX = np.einsum("nac,nck->nak", d_Xc, d_X)
        extra = {
            self.blocks["intrinsics"]: d_intr.reshape(2 * n, 4),
            self.blocks["distortion"]: d_dist.reshape(2 * n, 5),
        }
        return self._pack(r2, dp, dX, extra)


def body_frames(poses, view) -> tuple[np.ndarray, np.ndarray]:
    """Position and ``R_world_from_body`` of the body at each pixel's or point's exposure.

    The one reading of a frame sensor's poses (:class:`FrameCamera`,
    :class:`hsgeo.sensors.rikola.RikolaCamera`).

    Parameters
    ----------
    poses : (n_views, 6) array_like
        Rows ``(ω, φ, κ, X0, Y0, Z0)`` with ``R_world_from_body = R_from_opk(ω, φ, κ)``.
    view : (n,) array_like of int
        The pose of each pixel or point.

    Returns
    -------
    xyz_body : (n, 3) ndarray
    R_world_from_body : (n, 3, 3) ndarray
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    view = np.asarray(view, dtype=np.int64)
    R = R_from_opk(poses[:, 0], poses[:, 1], poses[:, 2])[view]  # R_world_from_body
    return poses[view, 3:6], R


def pixel_to_mm(uv_px, image_size, pixel_pitch_mm):
    """Pixel coordinates to mm from the image centre with y up (photogrammetric image frame).

    Pixels in OpenCV's convention: x right, y down, origin at the centre of the top-left pixel.

    Parameters
    ----------
    uv_px : (..., 2) ndarray
    image_size : (width_px, height_px)
    pixel_pitch_mm : float
    """
    uv = np.asarray(uv_px, dtype=np.float64)
    w, h = image_size
    return np.stack(
        [(uv[..., 0] - (w - 1) / 2) * pixel_pitch_mm, -(uv[..., 1] - (h - 1) / 2) * pixel_pitch_mm],
        axis=-1,
    )


def mm_to_pixel(xy_mm, image_size, pixel_pitch_mm):
    """Inverse of :func:`pixel_to_mm`."""
    xy = np.asarray(xy_mm, dtype=np.float64)
    w, h = image_size
    return np.stack(
        [xy[..., 0] / pixel_pitch_mm + (w - 1) / 2, -xy[..., 1] / pixel_pitch_mm + (h - 1) / 2],
        axis=-1,
    )


class FramePhotogrammetric(_FrameBase):
    """Collinearity residuals in the photogrammetric form (mm), 003 Table 3 style.

    Parameter blocks: ``interior`` ``(f, x0, y0)`` in mm, ``distortion_mm``
    ``(K1, K2, K3, P1, P2)`` in mm⁻², mm⁻⁴, mm⁻⁶, mm⁻¹, mm⁻¹, ``poses`` ``(n_views, 6)`` with the
    camera frame x right, y up, z backward; optionally a points block.

    Parameters
    ----------
    view : (n,) int ndarray
    xy_mm : (n, 2) ndarray
        Measured image coordinates in mm from the image centre, y up (:func:`pixel_to_mm`).
    sigma_mm : float or (n, 2) ndarray
    X, point : see :class:`FrameOpenCV`.
    blocks : mapping, optional
        Parameter-block names by role (``poses``, ``points``, ``interior``, ``distortion``;
        defaults ``poses``, ``points``, ``interior``, ``distortion_mm``).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """

    name = "image points (photogrammetric form)"
    BLOCKS = MappingProxyType(
        {**_FrameBase.BLOCKS, "interior": "interior", "distortion": "distortion_mm"}
    )

    def __init__(self, view, xy_mm, sigma_mm, X=None, point=None, **kw):
        super().__init__(view, xy_mm, sigma_mm, X, point, **kw)

    def evaluate(self, values, jacobian):
        poses = values[self.blocks["poses"]]
        f, x0, y0 = values[self.blocks["interior"]]
        KP = values[self.blocks["distortion"]]
        Xc, d_pose, d_X = camera_coordinates(poses, self.view, self._world(values), jacobian)
        if np.any(Xc[:, 2] >= 0):
            raise InputError(
                f"{int(np.sum(Xc[:, 2] >= 0))} object points lie behind the camera (the "
                "photogrammetric camera looks along −z): check the initial poses"
            )
        xbar = self.xy - np.array([x0, y0])
        delta = brown_correction(xbar, KP[:3], KP[3:])
        q = Xc[:, :2] / Xc[:, 2:3]
        r2 = xbar + delta + f * q  # 003 collinearity with corrections at the observation
        if not jacobian:
            return r2.ravel(), None
        n = r2.shape[0]
        J_xy, J_K, J_P = brown_correction_jacobian(xbar, KP[:3], KP[3:])
        d_int = np.zeros((n, 2, 3))
        d_int[:, :, 0] = q
        d_int[:, :, 1:3] = -(np.eye(2)[None] + J_xy)  # ∂/∂(x0, y0) through x̄ = x − x0
        d_dist = np.concatenate([J_K, J_P], axis=2)
        d_Xc = f * _dproj(Xc)
        dp = np.einsum("nac,nck->nak", d_Xc, d_pose)
        dX = np.einsum("nac,nck->nak", d_Xc, d_X)
        extra = {
            self.blocks["interior"]: d_int.reshape(2 * n, 3),
            self.blocks["distortion"]: d_dist.reshape(2 * n, 5),
        }
        return self._pack(r2, dp, dX, extra)


# ----------------------------------------------------------------------------------------------
# The sensor interface (hsgeo.sensors.mount): pixels ↔ rays of a frame camera
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class FrameCamera:
    """A frame camera in OpenCV's form as a sensor: ``project`` and ``rays`` at given poses.

    Parameters
    ----------
    intrinsics : (4,) sequence
        ``fx_px, fy_px, cx_px, cy_px``.
    dist : (5,) sequence
        ``k1, k2, p1, p2, k3`` (OpenCV order; :func:`hsgeo.distortion.distort_opencv`).
    mount : Mount
        The camera on its body (a rig): ``R_body_from_sensor`` takes OpenCV camera vectors
        (x right, y down, z forward) to the body. The identity mount makes the poses the
        camera's own.
    image_size : (int, int) or None
        Width and height of the frames, px (None: not known; a frame of any size is taken).

    The poses are rows ``(ω, φ, κ, X0, Y0, Z0)`` of the body (``R_world_from_body =
    R_from_opk(ω, φ, κ)``, the ``poses`` block of :class:`FrameOpenCV`), ``view`` the pose of
    each pixel or point.
    """

    intrinsics: tuple
    dist: tuple = (0.0, 0.0, 0.0, 0.0, 0.0)
    mount: Mount = field(default_factory=Mount)
    image_size: tuple | None = None

    def _frames(self, poses, view):
        return body_frames(poses, view)

    def sensor_directions(self, uv_px) -> np.ndarray:
        """Camera-frame directions ``(n, 3)`` (x right, y down, z forward; not normalised) of
        pixels ``(n, 2)``: the inverse of OpenCV's pixel map (:func:`normalised_opencv`).
        """
        xn = normalised_opencv(uv_px, self.intrinsics, self.dist)
        return np.column_stack([xn, np.ones(len(xn))])

    def rays(self, uv_px, poses, view) -> tuple[np.ndarray, np.ndarray]:
        """Origins and unit directions (world frame) of the rays of pixels ``(n, 2)``."""
        X0, R = self._frames(poses, view)
        d_cam = self.sensor_directions(uv_px)
        return self.mount.origins(X0, R), unit(self.mount.directions(R, d_cam))

    def rays_along(self, uv_px, t_s, trajectory) -> tuple[np.ndarray, np.ndarray]:
        """The rays of pixels ``(n, 2)`` exposed at times ``t_s`` on a body ``trajectory``:
        the body's pose at each time composed with the mount, as every scanning sensor does
        (:meth:`hsgeo.sensors.mount.Mount.rays_along`).
        """
        return self.mount.rays_along(self.sensor_directions(uv_px), t_s, trajectory)

    def project(self, xyz_world, poses, view) -> np.ndarray:
        """Pixels ``(n, 2)`` of world points seen from the poses ``view``."""
        X0, R = self._frames(poses, view)
        Xc = self.mount.to_sensor(xyz_world, X0, R)
        if np.any(Xc[:, 2] <= 0):
            raise ObservationError("points behind the frame camera (Z_c ≤ 0)")
        return pixels_opencv(Xc[:, :2] / Xc[:, 2:3], self.intrinsics, self.dist)[0]
