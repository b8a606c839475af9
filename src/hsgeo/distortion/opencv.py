"""OpenCV's distortion form (k1, k2, p1, p2, k3) on normalised coordinates: distort, Jacobian,
undistort.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.distortion._common import _as_float, _as_last, _broadcast, _newton_invert, _stack22
from hsgeo.errors import InputError

__all__: list[str] = ["distort_opencv", "distort_opencv_jacobian", "undistort_opencv"]

# --------------------------------------------------------------------------- OpenCV form


def _check_opencv(xy: ArrayLike, dist: ArrayLike, xy_name: str) -> tuple[NDArray, NDArray]:
    xy = _as_last(xy, xy_name, 2, "x, y")
    dist = _as_float(dist, "dist")
    if dist.ndim < 1 or dist.shape[-1] != 5:
        raise InputError(
            f"dist must have shape (..., 5) = (k1, k2, p1, p2, k3) in OpenCV order, got "
            f"{dist.shape}; pad missing coefficients with zeros (e.g. k3 = 0)."
        )
    return tuple(_broadcast((xy, 1, xy_name), (dist, 1, "dist")))


def _opencv_terms(xy: NDArray, dist: NDArray):
    """Distorted coordinates and the 2×2 Jacobian; also the pieces the dist-Jacobian needs."""
    x, y = xy[..., 0], xy[..., 1]
    k1, k2, p1, p2, k3 = (dist[..., i] for i in range(5))
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))  # 1 + k1 r² + k2 r⁴ + k3 r⁶
    g = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)  # ∂radial/∂(r²)
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    J = _stack22(
        radial + 2.0 * x * x * g + 2.0 * p1 * y + 6.0 * p2 * x,
        2.0 * x * y * g + 2.0 * p1 * x + 2.0 * p2 * y,
        2.0 * x * y * g + 2.0 * p1 * x + 2.0 * p2 * y,
        radial + 2.0 * y * y * g + 6.0 * p1 * y + 2.0 * p2 * x,
    )
    return np.stack([xd, yd], axis=-1), J, (x, y, r2)


def distort_opencv(xy_n: ArrayLike, dist: ArrayLike) -> NDArray:
    """Apply OpenCV's Brown-Conrady distortion to normalised ideal coordinates.

    ``x_d = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²)``,
    ``y_d = y (1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y``, ``r² = x² + y²``
    (the model of ``cv2.projectPoints`` with five coefficients).

    Parameters
    ----------
    xy_n : (..., 2) array_like
        Normalised ideal coordinates ``(X/Z, Y/Z)`` (dimensionless).
    dist : (5,) or (..., 5) array_like
        ``(k1, k2, p1, p2, k3)`` in OpenCV order (dimensionless).

    Returns
    -------
    xy_d : (..., 2) ndarray
        Distorted normalised coordinates. Pixels are ``K_cam @ [x_d, y_d, 1]``.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 5.

    See Also
    --------
    brown_correction : photogrammetric form (note P1 ↔ p2, P2 ↔ p1, opposite direction).
    """
    xy, dist = _check_opencv(xy_n, dist, "xy_n")
    return _opencv_terms(xy, dist)[0]


def distort_opencv_jacobian(xy_n: ArrayLike, dist: ArrayLike) -> tuple[NDArray, NDArray]:
    """Jacobian of :func:`distort_opencv`.

    Parameters
    ----------
    xy_n : (..., 2) array_like
        Normalised ideal coordinates.
    dist : (5,) or (..., 5) array_like
        ``(k1, k2, p1, p2, k3)`` in OpenCV order.

    Returns
    -------
    J_xy : (..., 2, 2) ndarray
        ``∂(x_d, y_d)/∂(x, y)``.
    J_dist : (..., 2, 5) ndarray
        ``∂(x_d, y_d)/∂(k1, k2, p1, p2, k3)``.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 5.
    """
    xy, dist = _check_opencv(xy_n, dist, "xy_n")
    _, J_xy, (x, y, r2) = _opencv_terms(xy, dist)
    r4 = r2 * r2
    r6 = r4 * r2
    J_dist = np.stack(
        [
            np.stack([x * r2, x * r4, 2.0 * x * y, r2 + 2.0 * x * x, x * r6], axis=-1),
            np.stack([y * r2, y * r4, r2 + 2.0 * y * y, 2.0 * x * y, y * r6], axis=-1),
        ],
        axis=-2,
    )
    return J_xy, J_dist


def undistort_opencv(
    xy_d: ArrayLike, dist: ArrayLike, tol: float = 1e-14, max_iter: int = 50
) -> NDArray:
    """Invert :func:`distort_opencv` by Newton iteration with the analytic 2×2 Jacobian.

    Parameters
    ----------
    xy_d : (..., 2) array_like
        Distorted normalised coordinates.
    dist : (5,) or (..., 5) array_like
        ``(k1, k2, p1, p2, k3)`` in OpenCV order.
    tol : float, optional
        Convergence threshold on ``max |distort(xy_n) − xy_d|`` per point (normalised
        units).
    max_iter : int, optional
        Maximum number of Newton iterations.

    Returns
    -------
    xy_n : (..., 2) ndarray
        Normalised ideal coordinates with ``distort_opencv(xy_n, dist) ≈ xy_d``.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 5.
    ConvergenceError
        If a point does not converge, or converges where J is not positive definite (outside
        the monotonic region of the model); ``.result`` holds the last iterate.
    """
    xy, dist = _check_opencv(xy_d, dist, "xy_d")

    def forward(u):
        f, J, _ = _opencv_terms(u, dist)
        return f, J

    return _newton_invert(forward, np.array(xy), tol, max_iter, "undistort_opencv")
