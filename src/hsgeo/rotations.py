"""Rotation conventions, named for what they do.

Every function takes and returns arrays with arbitrary leading batch dimensions ``...``.
Angles are in radians (degrees only at the edges: tables, CLI).

Conventions
-----------
* **Photogrammetric ω-φ-κ** (:func:`R_from_opk`): ``R = Rx(ω) @ Ry(φ) @ Rz(κ)`` with *active*
  elementary rotations. The result is ``R_world_from_cam``: its columns are the camera axes
  expressed in world coordinates, and ``xyz_world = R @ xyz_cam``.
* **Aerospace roll-pitch-yaw** (:func:`R_from_rpy`): ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``,
  which is ``R_nav_from_body``. Whether the navigation frame is north-east-down or
  east-north-up is the caller's business; the algebra is the same.
* **North-east-down to east-north-up** (:data:`R_ENU_FROM_NED`): the fixed swap of the first
  two axes and sign change of the third; a GNSS/INS attitude ``R_ned_from_body`` becomes
  ``R_map_from_body = R_ENU_FROM_NED @ R_ned_from_body`` in the east-north-up map frame.
* **Rotation vector** (:func:`R_from_rotvec`): axis times angle, Rodrigues' formula, identical
  to OpenCV's ``cv2.Rodrigues``.
* **Camera frames** (:func:`R_photogrammetric_from_opencv_cam`): OpenCV's camera frame
  (x right, y down, z forward along the view) and the photogrammetric one (x right, y up,
  z backward) differ by ``diag(1, −1, −1)``.

The elementary active rotations are::

    Rx(a) = [[1, 0, 0], [0, cos a, -sin a], [0, sin a, cos a]]
    Ry(a) = [[cos a, 0, sin a], [0, 1, 0], [-sin a, 0, cos a]]
    Rz(a) = [[cos a, -sin a, 0], [sin a, cos a, 0], [0, 0, 1]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import InputError
from hsgeo.validate import finite_array

__all__ = [
    "R_ENU_FROM_NED",
    "R_from_opk",
    "opk_from_R",
    "dR_dopk",
    "R_from_rpy",
    "rpy_from_R",
    "dR_drpy",
    "R_from_rotvec",
    "rotvec_from_R",
    "dR_drotvec",
    "skew",
    "R_small",
    "R_photogrammetric_from_opencv_cam",
    "ORTHONORMALITY_TOL",
]

#: The fixed rotation from north-east-down to east-north-up (E = N_ned[1], N = N_ned[0],
#: U = −D); a proper rotation (det +1) and its own inverse.
R_ENU_FROM_NED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
R_ENU_FROM_NED.setflags(write=False)
R_ENU_FROM_NED.setflags(write=False)

#: Tolerance on max |RᵀR − I| accepted by the ``*_from_R`` functions.
ORTHONORMALITY_TOL = 1e-6

# Below this cos(φ) (or cos(pitch)) the decomposition is treated as gimbal lock.
_GIMBAL_EPS = 1e-12


# --------------------------------------------------------------------------- validation


_as_float = finite_array  # the boundary check shared by every module


def _as_vectors(a: ArrayLike, name: str, n: int) -> NDArray[np.float64]:
    """Finite float array of shape (..., n)."""
    arr = _as_float(a, name)
    if arr.ndim < 1 or arr.shape[-1] != n:
        raise InputError(f"{name} must have shape (..., {n}), got {arr.shape}.")
    return arr


def _as_angles(*angles: ArrayLike, names: tuple[str, ...]) -> list[NDArray[np.float64]]:
    """Finite float arrays broadcast to one common shape."""
    arrs = [_as_float(a, nm) for a, nm in zip(angles, names, strict=True)]
    try:
        return list(np.broadcast_arrays(*arrs))
    except ValueError as exc:
        shapes = ", ".join(f"{nm}{a.shape}" for nm, a in zip(names, arrs, strict=True))
        raise InputError(
            f"angle arrays do not broadcast: {shapes}; give them one common shape."
        ) from exc


def _as_rotation(R: ArrayLike, name: str = "R") -> NDArray[np.float64]:
    """Finite (..., 3, 3) array that is a proper rotation to ORTHONORMALITY_TOL."""
    R = _as_float(R, name)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise InputError(f"{name} must have shape (..., 3, 3), got {R.shape}.")
    RtR = np.swapaxes(R, -1, -2) @ R
    dev = np.max(np.abs(RtR - np.eye(3)), axis=(-2, -1), initial=0.0)
    if np.any(dev > ORTHONORMALITY_TOL):
        raise InputError(
            f"{name} is not orthonormal: max |RᵀR − I| = {float(np.max(dev)):.3g} > "
            f"{ORTHONORMALITY_TOL:g}; pass a rotation matrix (re-orthonormalise, e.g. by SVD)."
        )
    det = np.linalg.det(R)
    if np.any(det <= 0.0):
        raise InputError(
            f"{name} has determinant {float(np.min(det)):.3g}: a reflection, not a rotation; "
            "flip the sign of one axis to make det(R) = +1."
        )
    return R


# --------------------------------------------------------------------------- elementary


def _stack33(rows: list[list[NDArray[np.float64]]]) -> NDArray[np.float64]:
    """Build a (..., 3, 3) array from a nested list of (...) arrays of one shape.

    The entries are copied into one array (the values of ``np.stack`` of the rows' stacks, in
    a third of its time: the nested stacks made the elementary rotations 4 of the 105 CPU-s of
    ``hsgeo reproduce lp-observations --scale 0.3``, issue 41).
    """
    flat = [x for r in rows for x in r]
    out = np.empty(np.shape(flat[0]) + (3, 3), dtype=np.result_type(*flat))
    for k, x in enumerate(flat):
        out[..., k // 3, k % 3] = x
    return out


def _Rx(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return _stack33([[o, z, z], [z, c, -s], [z, s, c]])


def _Ry(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return _stack33([[c, z, s], [z, o, z], [-s, z, c]])


def _Rz(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return _stack33([[c, -s, z], [s, c, z], [z, z, o]])


def _dRx(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, z = np.cos(a), np.sin(a), np.zeros_like(a)
    return _stack33([[z, z, z], [z, -s, -c], [z, c, -s]])


def _dRy(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, z = np.cos(a), np.sin(a), np.zeros_like(a)
    return _stack33([[-s, z, c], [z, z, z], [-c, z, -s]])


def _dRz(a: NDArray[np.float64]) -> NDArray[np.float64]:
    c, s, z = np.cos(a), np.sin(a), np.zeros_like(a)
    return _stack33([[-s, -c, z], [c, -s, z], [z, z, z]])


# --------------------------------------------------------------------------- ω-φ-κ


def R_from_opk(omega_rad: ArrayLike, phi_rad: ArrayLike, kappa_rad: ArrayLike) -> NDArray:
    """Rotation matrix from photogrammetric ω-φ-κ angles.

    ``R = Rx(ω) @ Ry(φ) @ Rz(κ)`` with active elementary rotations (see module docstring).

    Parameters
    ----------
    omega_rad, phi_rad, kappa_rad : (...) array_like, rad
        Rotation angles about the x, y and z axes; broadcast against each other.

    Returns
    -------
    R_world_from_cam : (..., 3, 3) ndarray
        Rotation taking camera coordinates to world coordinates (``xyz_world = R @ xyz_cam``);
        its columns are the camera axes expressed in world coordinates. The transpose is
        ``R_cam_from_world``.

    Raises
    ------
    InputError
        If an angle is NaN/inf or the angle arrays do not broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> R = R_from_opk(0.0, 0.0, np.pi / 2)
    >>> np.round(R @ [1.0, 0.0, 0.0], 12)
    array([0., 1., 0.])
    """
    om, ph, ka = _as_angles(
        omega_rad, phi_rad, kappa_rad, names=("omega_rad", "phi_rad", "kappa_rad")
    )
    return _Rx(om) @ _Ry(ph) @ _Rz(ka)


def opk_from_R(R: ArrayLike) -> NDArray:
    """Photogrammetric ω-φ-κ angles from a rotation matrix (inverse of :func:`R_from_opk`).

    ``φ = asin(R[0, 2])`` (computed as ``atan2(R[0, 2], hypot(R[0, 0], R[0, 1]))``, which is
    the same for a rotation and better conditioned near ±90°),
    ``ω = atan2(−R[1, 2], R[2, 2])``, ``κ = atan2(−R[0, 1], R[0, 0])``.

    Parameters
    ----------
    R : (..., 3, 3) array_like
        ``R_world_from_cam`` as returned by :func:`R_from_opk`.

    Returns
    -------
    opk_rad : (..., 3) ndarray, rad
        ``(ω, φ, κ)`` with ω, κ in (−π, π] and φ in [−π/2, π/2]. At gimbal lock
        (|φ| = 90°) only ω ± κ is determined; κ = 0 is returned then.

    Raises
    ------
    InputError
        If ``R`` is not (..., 3, 3), contains NaN/inf, is not orthonormal to 1e-6 or has
        determinant −1.
    """
    R = _as_rotation(R)
    phi = np.arctan2(R[..., 0, 2], np.hypot(R[..., 0, 0], R[..., 0, 1]))
    omega = np.arctan2(-R[..., 1, 2], R[..., 2, 2])
    kappa = np.arctan2(-R[..., 0, 1], R[..., 0, 0])
    # Gimbal lock: cos φ = 0; set κ = 0, then R = Rx(ω) Ry(±90°) and ω = atan2(R21, R11).
    lock = np.hypot(R[..., 0, 0], R[..., 0, 1]) < _GIMBAL_EPS
    omega = np.where(lock, np.arctan2(R[..., 2, 1], R[..., 1, 1]), omega)
    kappa = np.where(lock, 0.0, kappa)
    return np.stack([omega, phi, kappa], axis=-1)


def dR_dopk(omega_rad: ArrayLike, phi_rad: ArrayLike, kappa_rad: ArrayLike) -> NDArray:
    """Analytic derivatives of :func:`R_from_opk` with respect to ω, φ and κ.

    Parameters
    ----------
    omega_rad, phi_rad, kappa_rad : (...) array_like, rad
        As in :func:`R_from_opk`.

    Returns
    -------
    dR : (..., 3, 3, 3) ndarray, 1/rad
        ``dR[..., k, :, :] = ∂R/∂(angle k)`` for k = 0 (ω), 1 (φ), 2 (κ).

    Raises
    ------
    InputError
        If an angle is NaN/inf or the angle arrays do not broadcast.
    """
    om, ph, ka = _as_angles(
        omega_rad, phi_rad, kappa_rad, names=("omega_rad", "phi_rad", "kappa_rad")
    )
    Rx, Ry, Rz = _Rx(om), _Ry(ph), _Rz(ka)
    d_omega = _dRx(om) @ Ry @ Rz
    d_phi = Rx @ _dRy(ph) @ Rz
    d_kappa = Rx @ Ry @ _dRz(ka)
    return np.stack([d_omega, d_phi, d_kappa], axis=-3)


# --------------------------------------------------------------------------- roll-pitch-yaw


def R_from_rpy(roll_rad: ArrayLike, pitch_rad: ArrayLike, yaw_rad: ArrayLike) -> NDArray:
    """Rotation matrix from aerospace roll-pitch-yaw (Tait-Bryan z-y'-x'') angles.

    ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)`` with active elementary rotations.

    Parameters
    ----------
    roll_rad, pitch_rad, yaw_rad : (...) array_like, rad
        Rotation angles about the body x, y and z axes; broadcast against each other.

    Returns
    -------
    R_nav_from_body : (..., 3, 3) ndarray
        Rotation taking body coordinates to the navigation frame
        (``xyz_nav = R @ xyz_body``). Whether the navigation frame is north-east-down or
        east-north-up is the caller's business: the formula is the same, the meaning of the
        angles (and the sign of yaw) is not.

    Raises
    ------
    InputError
        If an angle is NaN/inf or the angle arrays do not broadcast.
    """
    ro, pi, ya = _as_angles(
        roll_rad, pitch_rad, yaw_rad, names=("roll_rad", "pitch_rad", "yaw_rad")
    )
    return _Rz(ya) @ _Ry(pi) @ _Rx(ro)


def rpy_from_R(R: ArrayLike) -> NDArray:
    """Roll-pitch-yaw angles from a rotation matrix (inverse of :func:`R_from_rpy`).

    ``pitch = asin(−R[2, 0])``, ``roll = atan2(R[2, 1], R[2, 2])``,
    ``yaw = atan2(R[1, 0], R[0, 0])``.

    Parameters
    ----------
    R : (..., 3, 3) array_like
        ``R_nav_from_body`` as returned by :func:`R_from_rpy`.

    Returns
    -------
    rpy_rad : (..., 3) ndarray, rad
        ``(roll, pitch, yaw)`` with roll, yaw in (−π, π] and pitch in [−π/2, π/2]. At gimbal
        lock (|pitch| = 90°) yaw = 0 is returned and roll carries the determined combination.

    Raises
    ------
    InputError
        If ``R`` is not (..., 3, 3), contains NaN/inf, is not orthonormal to 1e-6 or has
        determinant −1.
    """
    R = _as_rotation(R)
    cos_pitch = np.hypot(R[..., 0, 0], R[..., 1, 0])
    pitch = np.arctan2(-R[..., 2, 0], cos_pitch)
    roll = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    yaw = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    # Gimbal lock: set yaw = 0, then R = Ry(±90°) Rx(roll) and roll = atan2(−R12, R11).
    lock = cos_pitch < _GIMBAL_EPS
    roll = np.where(lock, np.arctan2(-R[..., 1, 2], R[..., 1, 1]), roll)
    yaw = np.where(lock, 0.0, yaw)
    return np.stack([roll, pitch, yaw], axis=-1)


def dR_drpy(roll_rad: ArrayLike, pitch_rad: ArrayLike, yaw_rad: ArrayLike) -> NDArray:
    """Analytic derivatives of :func:`R_from_rpy` with respect to roll, pitch and yaw.

    Parameters
    ----------
    roll_rad, pitch_rad, yaw_rad : (...) array_like, rad
        As in :func:`R_from_rpy`.

    Returns
    -------
    dR : (..., 3, 3, 3) ndarray, 1/rad
        ``dR[..., k, :, :] = ∂R/∂(angle k)`` for k = 0 (roll), 1 (pitch), 2 (yaw).

    Raises
    ------
    InputError
        If an angle is NaN/inf or the angle arrays do not broadcast.
    """
    ro, pi, ya = _as_angles(
        roll_rad, pitch_rad, yaw_rad, names=("roll_rad", "pitch_rad", "yaw_rad")
    )
    Rx, Ry, Rz = _Rx(ro), _Ry(pi), _Rz(ya)
    d_roll = Rz @ Ry @ _dRx(ro)
    d_pitch = Rz @ _dRy(pi) @ Rx
    d_yaw = _dRz(ya) @ Ry @ Rx
    return np.stack([d_roll, d_pitch, d_yaw], axis=-3)


# --------------------------------------------------------------------------- rotation vector


def skew(v: ArrayLike) -> NDArray:
    """Skew-symmetric (cross-product) matrix of a 3-vector.

    Parameters
    ----------
    v : (..., 3) array_like
        Vector ``(x, y, z)``.

    Returns
    -------
    S : (..., 3, 3) ndarray
        ``[[0, −z, y], [z, 0, −x], [−y, x, 0]]``, so that ``S @ u = v × u``.

    Raises
    ------
    InputError
        If ``v`` is not (..., 3) or contains NaN/inf.
    """
    v = _as_vectors(v, "v", 3)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return _stack33([[o, -z, y], [z, o, -x], [-y, x, o]])


def R_small(dtheta_rad: ArrayLike) -> NDArray:
    """First-order (small-angle) rotation ``I + skew(dθ)``.

    Not orthonormal: the error is O(|dθ|²). Use :func:`R_from_rotvec` for the exact rotation.

    Parameters
    ----------
    dtheta_rad : (..., 3) array_like, rad
        Small rotation vector.

    Returns
    -------
    R : (..., 3, 3) ndarray
        ``I + skew(dθ)``.

    Raises
    ------
    InputError
        If ``dtheta_rad`` is not (..., 3) or contains NaN/inf.
    """
    return np.eye(3) + skew(dtheta_rad)


def R_photogrammetric_from_opencv_cam() -> NDArray:
    """The rotation from OpenCV's camera frame to the photogrammetric camera frame.

    OpenCV: x right, y down, z forward (along the view). Photogrammetric: x right, y up,
    z backward (the camera looks along −z). The rotation is ``diag(1, −1, −1)`` (half a turn
    about x); it is its own inverse, so it is also ``R_opencv_from_photogrammetric_cam``.

    Returns
    -------
    R : (3, 3) ndarray
        A new array each call (safe to modify).

    Examples
    --------
    A world-from-camera rotation in OpenCV's frame becomes the photogrammetric one with
    ``R_world_from_photo = R_world_from_opencv @ R_photogrammetric_from_opencv_cam().T``:

    >>> R_photogrammetric_from_opencv_cam() @ [0.0, 0.0, 1.0]  # the view direction
    array([ 0.,  0., -1.])
    """
    return np.diag([1.0, -1.0, -1.0])


def R_from_rotvec(rotvec: ArrayLike) -> NDArray:
    """Rotation matrix from a rotation vector (Rodrigues' formula).

    ``R = I + (sin θ / θ) S + ((1 − cos θ) / θ²) S²`` with ``θ = |v|`` and ``S = skew(v)``;
    Taylor series of the two coefficients are used for θ < 1e-4, so the result is accurate
    to machine precision for small angles. Same convention as ``cv2.Rodrigues``.

    Parameters
    ----------
    rotvec : (..., 3) array_like, rad
        Rotation axis times rotation angle.

    Returns
    -------
    R : (..., 3, 3) ndarray
        The active rotation by θ about ``v / θ``.

    Raises
    ------
    InputError
        If ``rotvec`` is not (..., 3) or contains NaN/inf.
    """
    v = _as_vectors(rotvec, "rotvec", 3)
    theta = np.linalg.norm(v, axis=-1)
    small = theta < 1e-4
    t = np.where(small, 1.0, theta)  # safe divisor
    t2 = theta * theta
    # sin θ / θ and (1 − cos θ)/θ² = 2 sin²(θ/2)/θ² (no cancellation), Taylor for small θ
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / t)
    b = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, 2.0 * np.sin(0.5 * t) ** 2 / (t * t))
    S = skew(v)
    return np.eye(3) + a[..., None, None] * S + b[..., None, None] * (S @ S)


def dR_drotvec(rotvec: ArrayLike) -> NDArray:
    """Analytic derivatives of :func:`R_from_rotvec` with respect to the vector's components.

    ``∂R/∂v_k = skew(J_l[:, k]) R`` with the left Jacobian of SO(3),
    ``J_l(v) = I + ((1 − cos θ)/θ²) S + ((θ − sin θ)/θ³) S²`` (``S = skew(v)``), because
    ``R(v + δ) ≈ R_from_rotvec(J_l δ) R(v)`` to first order (Barfoot 2017, *State Estimation
    for Robotics*, eq. 7.86). Taylor series of the coefficients for θ < 1e-4.

    Parameters
    ----------
    rotvec : (..., 3) array_like, rad

    Returns
    -------
    dR : (..., 3, 3, 3) ndarray, 1/rad
        ``dR[..., k, :, :] = ∂R/∂v_k``.

    Raises
    ------
    InputError
        If ``rotvec`` is not (..., 3) or contains NaN/inf.
    """
    v = _as_vectors(rotvec, "rotvec", 3)
    theta = np.linalg.norm(v, axis=-1)
    small = theta < 1e-4
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    b = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, 2.0 * np.sin(0.5 * t) ** 2 / (t * t))
    c = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / t**3)
    S = skew(v)
    J = np.eye(3) + b[..., None, None] * S + c[..., None, None] * (S @ S)
    R = R_from_rotvec(v)
    cols = skew(np.swapaxes(J, -1, -2))  # (..., 3 (k), 3, 3): skew of column k of J
    return cols @ R[..., None, :, :]


def rotvec_from_R(R: ArrayLike) -> NDArray:
    """Rotation vector from a rotation matrix (inverse of :func:`R_from_rotvec`).

    The angle is ``θ = atan2(s, c)`` with ``c = (tr R − 1)/2`` and ``s = |w|``,
    ``w = vee(R − Rᵀ)/2 = sin θ · n``. For θ ≤ 90° the vector is ``(θ / s) w`` (with the
    Taylor limit at s = 0); for θ > 90° the axis comes from the symmetric part,
    ``((R + Rᵀ)/2 − c I)/(1 − c) = n nᵀ``, with the sign taken from ``w``. This is accurate
    near 0 and near π.

    Parameters
    ----------
    R : (..., 3, 3) array_like
        Rotation matrix.

    Returns
    -------
    rotvec : (..., 3) ndarray, rad
        Axis times angle, with angle θ in [0, π]. At exactly θ = π both ``±π n`` are valid;
        one of them is returned.

    Raises
    ------
    InputError
        If ``R`` is not (..., 3, 3), contains NaN/inf, is not orthonormal to 1e-6 or has
        determinant −1.
    """
    R = _as_rotation(R)
    w = 0.5 * np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        axis=-1,
    )
    s = np.linalg.norm(w, axis=-1)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    theta = np.arctan2(s, np.clip(c, -1.0, 1.0))

    # Branch 1 (θ ≤ 90°): v = θ/sin θ · w; θ/sin θ → 1 + θ²/6 as s → 0.
    tiny = s < 1e-8
    ratio = np.where(tiny, 1.0 + theta * theta / 6.0, theta / np.where(tiny, 1.0, s))
    v_small = ratio[..., None] * w

    # Branch 2 (θ > 90°): n nᵀ from the symmetric part; 1 − c ≥ 1 here.
    big = c < 0.0
    one_minus_c = np.where(big, 1.0 - c, 1.0)
    B = (0.5 * (R + np.swapaxes(R, -1, -2)) - c[..., None, None] * np.eye(3)) / one_minus_c[
        ..., None, None
    ]
    diag = np.diagonal(B, axis1=-2, axis2=-1)
    i = np.argmax(diag, axis=-1)
    col = np.take_along_axis(B, i[..., None, None], axis=-1)[..., 0]  # column i = n * n_i
    n_i = np.sqrt(np.maximum(np.take_along_axis(diag, i[..., None], axis=-1), 1e-300))
    n = col / n_i
    sign = np.where(np.sum(n * w, axis=-1) < 0.0, -1.0, 1.0)
    v_big = (sign * theta)[..., None] * n

    return np.where(big[..., None], v_big, v_small)
