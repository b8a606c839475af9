"""The photogrammetric (Brown 1971, Fraser 1997; 003 Table 3) correction in mm: correction,
Jacobian, ideal from measured and measured from ideal.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.distortion._common import _as_float, _as_last, _broadcast, _newton_invert, _stack22
from hsgeo.errors import InputError

__all__: list[str] = [
    "brown_correction",
    "brown_correction_jacobian",
    "ideal_from_measured_mm",
    "measured_from_ideal_mm",
]

# --------------------------------------------------------------------------- photogrammetric


def _check_brown(xy: ArrayLike, K: ArrayLike, P: ArrayLike, xy_name: str):
    xy = _as_last(xy, xy_name, 2, "x, y in mm")
    K = _as_float(K, "K")
    P = _as_float(P, "P")
    if K.ndim < 1 or K.shape[-1] != 3:
        raise InputError(
            f"K must have shape (..., 3) = (K1, K2, K3) in mm^-2, mm^-4, mm^-6, got {K.shape}; "
            "pad missing coefficients with zeros."
        )
    if P.ndim < 1 or P.shape[-1] != 2:
        raise InputError(f"P must have shape (..., 2) = (P1, P2) in mm^-1, got {P.shape}.")
    return _broadcast((xy, 1, xy_name), (K, 1, "K"), (P, 1, "P"))


def _brown_terms(xy: NDArray, K: NDArray, P: NDArray):
    """Correction δ (..., 2), its Jacobian (..., 2, 2) and (x, y, r²)."""
    x, y = xy[..., 0], xy[..., 1]
    K1, K2, K3 = K[..., 0], K[..., 1], K[..., 2]
    P1, P2 = P[..., 0], P[..., 1]
    r2 = x * x + y * y
    s = r2 * (K1 + r2 * (K2 + r2 * K3))  # K1 r² + K2 r⁴ + K3 r⁶
    g = K1 + r2 * (2.0 * K2 + 3.0 * K3 * r2)  # ∂s/∂(r²)
    # Brown (1971), Fraser (1997) eq. (2); 003 Table 3
    dx = x * s + P1 * (r2 + 2.0 * x * x) + 2.0 * P2 * x * y
    dy = y * s + 2.0 * P1 * x * y + P2 * (r2 + 2.0 * y * y)
    J = _stack22(
        s + 2.0 * x * x * g + 6.0 * P1 * x + 2.0 * P2 * y,
        2.0 * x * y * g + 2.0 * P1 * y + 2.0 * P2 * x,
        2.0 * x * y * g + 2.0 * P1 * y + 2.0 * P2 * x,
        s + 2.0 * y * y * g + 2.0 * P1 * x + 6.0 * P2 * y,
    )
    return np.stack([dx, dy], axis=-1), J, (x, y, r2)


def brown_correction(xy_bar_mm: ArrayLike, K: ArrayLike, P: ArrayLike) -> NDArray:
    """Brown radial + decentering correction of measured image coordinates.

    ``δx = x̄ (K1 r² + K2 r⁴ + K3 r⁶) + P1 (r² + 2x̄²) + 2 P2 x̄ ȳ``,
    ``δy = ȳ (K1 r² + K2 r⁴ + K3 r⁶) + 2 P1 x̄ ȳ + P2 (r² + 2ȳ²)``, ``r² = x̄² + ȳ²``
    (Brown 1971; Fraser 1997; the parameterisation of 003 Table 3). The ideal (corrected)
    coordinate is ``x̄ + δx``.

    Parameters
    ----------
    xy_bar_mm : (..., 2) array_like, mm
        Measured image coordinates reduced to the principal point, ``x̄ = x − x0``.
    K : (3,) or (..., 3) array_like
        ``(K1, K2, K3)`` in mm⁻², mm⁻⁴, mm⁻⁶.
    P : (2,) or (..., 2) array_like
        ``(P1, P2)`` in mm⁻¹.

    Returns
    -------
    delta_mm : (..., 2) ndarray, mm
        Correction ``(δx, δy)``.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or wrong coefficient counts.

    Notes
    -----
    Relative to OpenCV (:func:`distort_opencv`) Brown's ``P1`` plays the role of OpenCV's
    ``p2`` and ``P2`` that of ``p1``. The direction is opposite (a correction of measured
    coordinates instead of a distortion of ideal ones), so the signs flip to first order, and
    the units differ (mm powers here, normalised coordinates there): to first order
    ``K1 ≈ −k1 / c_mm²``, ``P1 ≈ −p2 / c_mm``, ``P2 ≈ −p1 / c_mm``.
    """
    xy, K, P = _check_brown(xy_bar_mm, K, P, "xy_bar_mm")
    return _brown_terms(xy, K, P)[0]


def brown_correction_jacobian(
    xy_bar_mm: ArrayLike, K: ArrayLike, P: ArrayLike
) -> tuple[NDArray, NDArray, NDArray]:
    """Jacobian of :func:`brown_correction`.

    Parameters
    ----------
    xy_bar_mm : (..., 2) array_like, mm
        Principal-point-reduced measured image coordinates.
    K : (3,) or (..., 3) array_like
        ``(K1, K2, K3)`` in mm⁻², mm⁻⁴, mm⁻⁶.
    P : (2,) or (..., 2) array_like
        ``(P1, P2)`` in mm⁻¹.

    Returns
    -------
    J_xy : (..., 2, 2) ndarray
        ``∂δ/∂(x̄, ȳ)`` (dimensionless). The Jacobian of the ideal coordinates
        ``x̄ + δ`` is ``I + J_xy``.
    J_K : (..., 2, 3) ndarray
        ``∂δ/∂(K1, K2, K3)`` in mm³, mm⁵, mm⁷.
    J_P : (..., 2, 2) ndarray
        ``∂δ/∂(P1, P2)`` in mm².

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or wrong coefficient counts.
    """
    xy, K, P = _check_brown(xy_bar_mm, K, P, "xy_bar_mm")
    _, J_xy, (x, y, r2) = _brown_terms(xy, K, P)
    r4 = r2 * r2
    r6 = r4 * r2
    J_K = np.stack(
        [np.stack([x * r2, x * r4, x * r6], axis=-1), np.stack([y * r2, y * r4, y * r6], axis=-1)],
        axis=-2,
    )
    J_P = _stack22(r2 + 2.0 * x * x, 2.0 * x * y, 2.0 * x * y, r2 + 2.0 * y * y)
    return J_xy, J_K, J_P


def ideal_from_measured_mm(xy_bar_mm: ArrayLike, K: ArrayLike, P: ArrayLike) -> NDArray:
    """Ideal (distortion-free) image coordinates from measured ones: ``x̄ + δ(x̄)``.

    Parameters
    ----------
    xy_bar_mm : (..., 2) array_like, mm
        Principal-point-reduced measured image coordinates.
    K : (3,) or (..., 3) array_like
        ``(K1, K2, K3)`` in mm⁻², mm⁻⁴, mm⁻⁶.
    P : (2,) or (..., 2) array_like
        ``(P1, P2)`` in mm⁻¹.

    Returns
    -------
    xy_ideal_mm : (..., 2) ndarray, mm
        Corrected coordinates, principal-point-reduced.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or wrong coefficient counts.
    """
    xy, K, P = _check_brown(xy_bar_mm, K, P, "xy_bar_mm")
    return xy + _brown_terms(xy, K, P)[0]


def measured_from_ideal_mm(
    xy_ideal_mm: ArrayLike,
    K: ArrayLike,
    P: ArrayLike,
    tol: float = 1e-12,
    max_iter: int = 50,
) -> NDArray:
    """Measured image coordinates from ideal ones (inverse of :func:`ideal_from_measured_mm`).

    Solves ``x̄ + δ(x̄) = xy_ideal`` by Newton iteration with Jacobian ``I + J_xy``.

    Parameters
    ----------
    xy_ideal_mm : (..., 2) array_like, mm
        Ideal (distortion-free) principal-point-reduced image coordinates, e.g. from
        collinearity.
    K : (3,) or (..., 3) array_like
        ``(K1, K2, K3)`` in mm⁻², mm⁻⁴, mm⁻⁶.
    P : (2,) or (..., 2) array_like
        ``(P1, P2)`` in mm⁻¹.
    tol : float, optional
        Convergence threshold in mm on ``max |x̄ + δ(x̄) − xy_ideal|`` per point.
    max_iter : int, optional
        Maximum number of Newton iterations.

    Returns
    -------
    xy_bar_mm : (..., 2) ndarray, mm
        Measured (distorted) principal-point-reduced image coordinates.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or wrong coefficient counts.
    ConvergenceError
        If a point does not converge, or converges where ``I + J_xy`` is not positive
        definite (outside the monotonic region of the model); ``.result`` holds the last
        iterate.
    """
    xy, K, P = _check_brown(xy_ideal_mm, K, P, "xy_ideal_mm")

    def forward(u):
        delta, J, _ = _brown_terms(u, K, P)
        return u + delta, np.eye(2) + J

    return _newton_invert(forward, np.array(xy), tol, max_iter, "measured_from_ideal_mm")
