"""Numba scalar cores shared by the numpy and the compiled paths (GUIDE §2).

Each equation that a compiled kernel evaluates is written once here, as an ``@njit`` scalar
function. The compiled kernels call it per observation; the numpy paths call the ``*_rows``
loops below, which call the same scalar function, so both paths run the same arithmetic in the
same order (no ``fastmath``: the results are IEEE-exact and do not depend on the path).

Cores
-----
* :func:`bspline_weights` — uniform cubic B-spline weights and their time derivatives
  (002 §3.3, Fig. 4); :func:`bspline_weights_rows` for arrays.
* :func:`rpy_rotation` — ``R = Rz(yaw) Ry(pitch) Rx(roll)`` and its three derivatives, the
  convention of :func:`hsgeo.rotations.R_from_rpy` / :func:`hsgeo.rotations.dR_drpy` (tested
  against them).
* :func:`pushbroom_camera_point` — 002 eq. (4): ``q = Rᵀ d − l``, ``p^c = β q``.
* :func:`pushbroom_line_distortion` — the line distortion of 002 eq. (3),
  ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``, ``y = ȳ + P2 x̄²``, with its derivatives with respect
  to ``x̄`` (:func:`hsgeo.distortion.distort_pushbroom_line` is its array face).
* :func:`pushbroom_image_mm` — 002 eq. (3): collinearity ``x̄ = c p_x / p_z``, ``ȳ = c p_y / p_z``
  followed by the line distortion (the principal point is added by the caller);
  :func:`pushbroom_image_rows` for arrays.

Numba's on-disk cache of a kernel in another module does not notice edits to this file; after
changing a core, delete the ``__pycache__/*.nbi``/``*.nbc`` files of the modules that call it.
The pushbroom cores are plain ``@njit`` calls, not ``inline="always"``: inlined into the
parallel kernel (numba 0.68) they left the distortion derivatives at zero.

References
----------
Jonassen et al. (2024), 002 eq. (3)–(4), §3.3.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = [
    "bspline_weights",
    "bspline_weights_rows",
    "rpy_rotation",
    "pushbroom_camera_point",
    "pushbroom_line_distortion",
    "pushbroom_line_distortion_rows",
    "pushbroom_line_distortion_dcoeff",
    "pushbroom_line_distortion_dcoeff_rows",
    "pushbroom_image_mm",
    "pushbroom_image_rows",
]


# ----------------------------------------------------------------------- cubic B-spline (002 §3.3)
@njit(cache=True, inline="always")
def bspline_weights(u, inv_dt, w, dw):  # pragma: no cover - compiled
    """Uniform cubic B-spline weights at local coordinate ``u`` and their time derivatives.

    ``B_0 = (1-u)³/6``, ``B_1 = (3u³ - 6u² + 4)/6``, ``B_2 = (-3u³ + 3u² + 3u + 1)/6``,
    ``B_3 = u³/6`` (002 §3.3; see :mod:`hsgeo.trajectory`).

    Parameters
    ----------
    u : float
        Local coordinate in the spline piece (in [0, 1], a little outside when a piece is
        continued).
    inv_dt : float, 1/s
        Inverse node interval; ``dw`` is ``dB_a/du · inv_dt`` (pass 1.0 for ``dB_a/du``).
    w, dw : (4,) ndarray
        Output: the weights of nodes ``k-1 … k+2`` and their derivatives.
    """
    v = 1.0 - u
    w[0] = v * v * v / 6.0
    w[1] = (3.0 * u * u * u - 6.0 * u * u + 4.0) / 6.0
    w[2] = (-3.0 * u * u * u + 3.0 * u * u + 3.0 * u + 1.0) / 6.0
    w[3] = u * u * u / 6.0
    dw[0] = -v * v / 2.0 * inv_dt
    dw[1] = (3.0 * u * u - 4.0 * u) / 2.0 * inv_dt
    dw[2] = (-3.0 * u * u + 2.0 * u + 1.0) / 2.0 * inv_dt
    dw[3] = u * u / 2.0 * inv_dt


@njit(cache=True)
def bspline_weights_rows(u, inv_dt):  # pragma: no cover - compiled
    """:func:`bspline_weights` for a 1-D array ``u`` (m,): returns ``w, dw`` (m, 4) each."""
    m = u.size
    w = np.empty((m, 4))
    dw = np.empty((m, 4))
    for j in range(m):
        bspline_weights(u[j], inv_dt, w[j], dw[j])
    return w, dw


# ----------------------------------------------------------------------- roll-pitch-yaw rotation
@njit(cache=True, inline="always")
def rpy_rotation(ro, pi, ya, R, dR):  # pragma: no cover - compiled
    """``R = Rz(yaw) Ry(pitch) Rx(roll)`` (``R_nav_from_body``) and ``dR[k] = ∂R/∂angle_k``.

    The convention of :func:`hsgeo.rotations.R_from_rpy` and :func:`hsgeo.rotations.dR_drpy`,
    written out element by element for the compiled kernels.

    Parameters
    ----------
    ro, pi, ya : float, rad
        Roll, pitch, yaw.
    R : (3, 3) ndarray
        Output rotation.
    dR : (3, 3, 3) ndarray
        Output derivatives with respect to roll, pitch, yaw (first index).
    """
    cr, sr, cp, sp, cy, sy = np.cos(ro), np.sin(ro), np.cos(pi), np.sin(pi), np.cos(ya), np.sin(ya)
    R[0, 0] = cy * cp
    R[0, 1] = cy * sp * sr - sy * cr
    R[0, 2] = cy * sp * cr + sy * sr
    R[1, 0] = sy * cp
    R[1, 1] = sy * sp * sr + cy * cr
    R[1, 2] = sy * sp * cr - cy * sr
    R[2, 0] = -sp
    R[2, 1] = cp * sr
    R[2, 2] = cp * cr
    # roll
    dR[0, 0, 0] = 0.0
    dR[0, 0, 1] = cy * sp * cr + sy * sr
    dR[0, 0, 2] = -cy * sp * sr + sy * cr
    dR[0, 1, 0] = 0.0
    dR[0, 1, 1] = sy * sp * cr - cy * sr
    dR[0, 1, 2] = -sy * sp * sr - cy * cr
    dR[0, 2, 0] = 0.0
    dR[0, 2, 1] = cp * cr
    dR[0, 2, 2] = -cp * sr
    # pitch
    dR[1, 0, 0] = -cy * sp
    dR[1, 0, 1] = cy * cp * sr
    dR[1, 0, 2] = cy * cp * cr
    dR[1, 1, 0] = -sy * sp
    dR[1, 1, 1] = sy * cp * sr
    dR[1, 1, 2] = sy * cp * cr
    dR[1, 2, 0] = -cp
    dR[1, 2, 1] = -sp * sr
    dR[1, 2, 2] = -sp * cr
    # yaw
    dR[2, 0, 0] = -sy * cp
    dR[2, 0, 1] = -sy * sp * sr - cy * cr
    dR[2, 0, 2] = -sy * sp * cr + cy * sr
    dR[2, 1, 0] = cy * cp
    dR[2, 1, 1] = cy * sp * sr - sy * cr
    dR[2, 1, 2] = cy * sp * cr + sy * sr
    dR[2, 2, 0] = 0.0
    dR[2, 2, 1] = 0.0
    dR[2, 2, 2] = 0.0


# ----------------------------------------------------------------------- pushbroom (002 eq. 3–4)
@njit(cache=True)
def pushbroom_camera_point(R, d, lever, beta, q, p):  # pragma: no cover - compiled
    """Camera coordinates of a point, 002 eq. (4): ``q = Rᵀ d − l``, ``p^c = β q``.

    Parameters
    ----------
    R : (3, 3) ndarray
        ``R_map_from_platform`` at the exposure.
    d : (3,) ndarray, m
        Point minus platform position, map frame.
    lever : (3,) ndarray, m
        Lever arm ``l^p`` in the platform frame.
    beta : (3, 3) ndarray
        Boresight ``β`` (camera from platform).
    q, p : (3,) ndarray
        Output: ``q = Rᵀ d − l`` (platform frame) and ``p^c = β q`` (camera frame), m.
    """
    for a in range(3):  # q = Rᵀ d − l
        q[a] = R[0, a] * d[0] + R[1, a] * d[1] + R[2, a] * d[2] - lever[a]
    for a in range(3):  # p = β q
        p[a] = beta[a, 0] * q[0] + beta[a, 1] * q[1] + beta[a, 2] * q[2]


@njit(cache=True)
def pushbroom_line_distortion(xb, yb, K1, K2, P1, P2):  # pragma: no cover - compiled
    """The line distortion of 002 eq. (3) at the ideal image coordinates ``(x̄, ȳ)``.

    ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``, ``y = ȳ + P2 x̄²`` (mm, principal point excluded).

    Returns
    -------
    x, y : float, mm
    gx, gy : float
        ``∂x/∂x̄`` and ``∂y/∂x̄``.
    """
    x = xb + K1 * xb**3 + K2 * xb**5 + 3 * P1 * xb**2  # 002 eq. (3)
    y = yb + P2 * xb**2
    gx = 1.0 + 3 * K1 * xb**2 + 5 * K2 * xb**4 + 6 * P1 * xb
    gy = 2 * P2 * xb
    return x, y, gx, gy


@njit(cache=True, inline="always")
def pushbroom_line_distortion_dcoeff(xb):  # pragma: no cover - compiled
    """∂(x, y)/∂(K1, K2, P1, P2) of 002 eq. (3) at the ideal ``x̄`` (the one place it is coded).

    ``∂x = (x̄³, x̄⁵, 3 x̄², 0)``, ``∂y = (0, 0, 0, x̄²)``: returns the four non-zero entries
    ``(x̄³, x̄⁵, 3 x̄², x̄²)`` in mm³, mm⁵, mm², mm². The compiled kernel of
    :class:`hsgeo.sensors.pushbroom.PushbroomLines` and
    :func:`hsgeo.distortion.distort_pushbroom_line_jacobian` both call it.
    """
    return xb**3, xb**5, 3 * xb**2, xb**2


@njit(cache=True)
def pushbroom_line_distortion_dcoeff_rows(xb):  # pragma: no cover - compiled
    """:func:`pushbroom_line_distortion_dcoeff` for a 1-D array ``xb`` (m,): ``(m, 4)``."""
    out = np.empty((xb.size, 4))
    for j in range(xb.size):
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = pushbroom_line_distortion_dcoeff(xb[j])
    return out


@njit(cache=True)
def pushbroom_line_distortion_rows(xb, yb, dist):  # pragma: no cover - compiled
    """:func:`pushbroom_line_distortion` for 1-D arrays ``xb, yb`` (m,) and ``dist`` (m, 4).

    Returns ``x, y, gx, gy``, (m,) each.
    """
    m = xb.size
    x = np.empty(m)
    y = np.empty(m)
    gx = np.empty(m)
    gy = np.empty(m)
    for j in range(m):
        x[j], y[j], gx[j], gy[j] = pushbroom_line_distortion(
            xb[j], yb[j], dist[j, 0], dist[j, 1], dist[j, 2], dist[j, 3]
        )
    return x, y, gx, gy


@njit(cache=True)
def pushbroom_image_mm(p0, p1, p2, c, K1, K2, P1, P2):  # pragma: no cover - compiled
    """Image coordinates of a camera point, 002 eq. (3), principal point excluded.

    ``x̄ = c p_x / p_z``, ``ȳ = c p_y / p_z`` (collinearity) and the line distortion
    ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``, ``y = ȳ + P2 x̄²`` (evaluated at the ideal ``x̄``;
    see :mod:`hsgeo.sensors.pushbroom`). The caller adds ``(x0, y0)``.

    Parameters
    ----------
    p0, p1, p2 : float, m
        Camera coordinates ``p^c``.
    c : float, mm
        Principal distance of the band.
    K1, K2, P1, P2 : float
        Distortion, mm⁻², mm⁻⁴, mm⁻¹, mm⁻¹.

    Returns
    -------
    x, y : float, mm
        Distorted image coordinates relative to the principal point.
    xb, yb : float, mm
        Ideal image coordinates ``x̄, ȳ``.
    iz : float, 1/m
        ``1 / p_z``.
    gx, gy : float
        ``∂x/∂x̄`` and ``∂y/∂x̄`` (``∂y/∂ȳ = 1``, ``∂x/∂ȳ = 0``).
    """
    iz = 1.0 / p2
    xb = c * p0 * iz  # 002 eq. (3), collinearity
    yb = c * p1 * iz
    x, y, gx, gy = pushbroom_line_distortion(xb, yb, K1, K2, P1, P2)
    return x, y, xb, yb, iz, gx, gy


@njit(cache=True)
def pushbroom_image_rows(R, d, lever, beta, c, dist, x0, y0):  # pragma: no cover - compiled
    """002 eq. (3)–(4) for arrays of observations (the numpy path's view of the cores).

    Parameters
    ----------
    R : (m, 3, 3) ndarray
        ``R_map_from_platform`` per observation.
    d : (m, 3) ndarray, m
        Point minus platform position.
    lever : (3,) ndarray, m
    beta : (3, 3) ndarray
    c : (m,) ndarray, mm
        Principal distance per observation.
    dist : (4,) ndarray
        ``K1, K2, P1, P2``.
    x0, y0 : float, mm
        Principal point.

    Returns
    -------
    q, p : (m, 3) ndarray, m
        :func:`pushbroom_camera_point` per observation.
    xy : (m, 2) ndarray, mm
        Image coordinates, principal point included.
    xb, yb, iz, gx, gy : (m,) ndarray
        As :func:`pushbroom_image_mm`.
    """
    m = d.shape[0]
    q = np.empty((m, 3))
    p = np.empty((m, 3))
    xy = np.empty((m, 2))
    xb = np.empty(m)
    yb = np.empty(m)
    iz = np.empty(m)
    gx = np.empty(m)
    gy = np.empty(m)
    K1, K2, P1, P2 = dist[0], dist[1], dist[2], dist[3]
    for j in range(m):
        pushbroom_camera_point(R[j], d[j], lever, beta, q[j], p[j])
        x, y, xb[j], yb[j], iz[j], gx[j], gy[j] = pushbroom_image_mm(
            p[j, 0], p[j, 1], p[j, 2], c[j], K1, K2, P1, P2
        )
        xy[j, 0] = x + x0
        xy[j, 1] = y + y0
    return q, p, xy, xb, yb, iz, gx, gy
