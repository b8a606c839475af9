"""The pushbroom line form of 002 eq. (3): distort, Jacobian, undistort."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo._kernels import pushbroom_line_distortion_dcoeff_rows, pushbroom_line_distortion_rows
from hsgeo.distortion._common import _as_float, _as_last, _broadcast, _newton_invert, _stack22
from hsgeo.errors import InputError

__all__: list[str] = [
    "distort_pushbroom_line",
    "distort_pushbroom_line_jacobian",
    "undistort_pushbroom_line",
]

# --------------------------------------------------------------------------- 002 line form


def _check_line_002(xy: ArrayLike, dist: ArrayLike, xy_name: str):
    """(..., 2) coordinates and (..., 4) coefficients, broadcast against each other."""
    xy = _as_last(xy, xy_name, 2, "x, y in mm")
    dist = _as_float(dist, "dist")
    if dist.ndim < 1 or dist.shape[-1] != 4:
        raise InputError(
            f"dist must have shape (..., 4) = (K1, K2, P1, P2) in mm^-2, mm^-4, mm^-1, mm^-1 "
            f"(002 eq. (3)), got {dist.shape}."
        )
    return _broadcast((xy, 1, xy_name), (dist, 1, "dist"))


def _line_002_terms(xy: NDArray, dist: NDArray):
    """x, y, ∂x/∂x̄, ∂y/∂x̄ (each (...)) from the compiled core, and x̄ (...)."""
    shape = xy.shape[:-1]
    flat = xy.reshape(-1, 2)
    xb = np.ascontiguousarray(flat[:, 0])
    yb = np.ascontiguousarray(flat[:, 1])
    x, y, gx, gy = pushbroom_line_distortion_rows(xb, yb, np.ascontiguousarray(dist.reshape(-1, 4)))
    return tuple(a.reshape(shape) for a in (x, y, gx, gy, xb))


def distort_pushbroom_line(xy_mm: ArrayLike, dist: ArrayLike) -> NDArray:
    """The line distortion of a pushbroom camera (002 eq. (3)), applied to ideal coordinates.

    ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``, ``y = ȳ + P2 x̄²``: the polynomial of 002 eq. (3)
    evaluated at the ideal image coordinate ``x̄`` along the line (see
    :mod:`hsgeo.sensors.pushbroom`). The same compiled core
    (:func:`hsgeo._kernels.pushbroom_line_distortion`) serves the adjustment.

    Parameters
    ----------
    xy_mm : (..., 2) array_like, mm
        Ideal image coordinates ``(x̄, ȳ)`` relative to the principal point (x along the line).
    dist : (4,) or (..., 4) array_like
        ``(K1, K2, P1, P2)`` in mm⁻², mm⁻⁴, mm⁻¹, mm⁻¹.

    Returns
    -------
    xy_d_mm : (..., 2) ndarray, mm
        Distorted image coordinates relative to the principal point.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 4.

    Examples
    --------
    >>> distort_pushbroom_line([2.0, 0.1], [1e-3, 0.0, 1e-4, 2e-4]).round(7).tolist()
    [2.0092, 0.1008]
    """
    xy, dist = _check_line_002(xy_mm, dist, "xy_mm")
    x, y, _, _, _ = _line_002_terms(xy, dist)
    return np.stack([x, y], axis=-1)


def distort_pushbroom_line_jacobian(xy_mm: ArrayLike, dist: ArrayLike) -> tuple[NDArray, NDArray]:
    """Jacobian of :func:`distort_pushbroom_line`.

    Parameters
    ----------
    xy_mm : (..., 2) array_like, mm
        Ideal image coordinates ``(x̄, ȳ)``.
    dist : (4,) or (..., 4) array_like
        ``(K1, K2, P1, P2)``.

    Returns
    -------
    J_xy : (..., 2, 2) ndarray
        ``∂(x, y)/∂(x̄, ȳ) = [[1 + 3K1x̄² + 5K2x̄⁴ + 6P1x̄, 0], [2P2x̄, 1]]``.
    J_dist : (..., 2, 4) ndarray
        ``∂(x, y)/∂(K1, K2, P1, P2)`` in mm³, mm⁵, mm², mm².

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 4.
    """
    xy, dist = _check_line_002(xy_mm, dist, "xy_mm")
    return _line_002_jacobian(xy, dist)


def _line_002_jacobian(xy: NDArray, dist: NDArray) -> tuple[NDArray, NDArray]:
    _, _, gx, gy, xb = _line_002_terms(xy, dist)
    zero, one = np.zeros_like(xb), np.ones_like(xb)
    J_xy = _stack22(gx, zero, gy, one)
    # ∂(x, y)/∂(K1, K2, P1, P2): the compiled core the adjustment's kernel calls too
    d = pushbroom_line_distortion_dcoeff_rows(np.ascontiguousarray(xb.ravel()))
    d = d.reshape(xb.shape + (4,))
    J_dist = np.zeros(xb.shape + (2, 4))
    J_dist[..., 0, :3] = d[..., :3]
    J_dist[..., 1, 3] = d[..., 3]
    return J_xy, J_dist


def undistort_pushbroom_line(
    xy_d_mm: ArrayLike, dist: ArrayLike, tol: float = 1e-12, max_iter: int = 50
) -> NDArray:
    """Invert :func:`distort_pushbroom_line` by Newton iteration (2×2, analytic Jacobian).

    Parameters
    ----------
    xy_d_mm : (..., 2) array_like, mm
        Distorted image coordinates relative to the principal point.
    dist : (4,) or (..., 4) array_like
        ``(K1, K2, P1, P2)``.
    tol : float, optional
        Convergence threshold in mm on ``max |distort(xy) − xy_d|`` per point.
    max_iter : int, optional
        Maximum number of Newton iterations.

    Returns
    -------
    xy_mm : (..., 2) ndarray, mm
        Ideal coordinates with ``distort_pushbroom_line(xy_mm, dist) ≈ xy_d_mm``.

    Raises
    ------
    InputError
        On NaN/inf, wrong shapes or a coefficient count other than 4.
    ConvergenceError
        If a point does not converge, or converges where ``∂x/∂x̄ ≤ 0`` (the folded part of
        the polynomial); ``.result`` holds the last iterate.
    """
    xy, dist = _check_line_002(xy_d_mm, dist, "xy_d_mm")

    def forward(u):
        x, y, _, _, _ = _line_002_terms(u, dist)
        return np.stack([x, y], axis=-1), _line_002_jacobian(u, dist)[0]

    return _newton_invert(forward, np.array(xy), tol, max_iter, "undistort_pushbroom_line")
