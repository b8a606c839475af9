"""The odd radial series in one dimension of the line scanners (000 eq. (2)): distortion,
Jacobian, undistort and distort.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.distortion._common import _as_float, _broadcast
from hsgeo.errors import ConvergenceError, InputError

__all__: list[str] = [
    "odd_radial_1d",
    "odd_radial_1d_jacobian",
    "ideal_from_measured_1d",
    "measured_from_ideal_1d",
]

# --------------------------------------------------------------------------- 1D odd radial


def _check_K_1d(
    d: ArrayLike, K: ArrayLike, norm: float = 1.0, d_name: str = "d"
) -> tuple[NDArray, NDArray, NDArray]:
    d = _as_float(d, d_name)
    K = _as_float(K, "K")
    if K.ndim < 1 or K.shape[-1] < 1:
        raise InputError(
            f"K must have shape (..., n) with n >= 1 coefficients (K1, K2, ...), got {K.shape}."
        )
    if not (np.isfinite(norm) and norm > 0):
        raise InputError(f"norm must be a positive finite length, got {norm!r}.")
    d, K = _broadcast((d, 0, d_name), (K, 1, "K"))
    exponents = 2 * np.arange(1, K.shape[-1] + 1) + 1  # 3, 5, 7, ...
    return d, K, exponents


def _odd_series(u: NDArray, K: NDArray) -> NDArray:
    """``Σ_i K_i u^(2i+1)`` by Horner's rule in u² (no checks; K (..., n) broadcasts with u).

    000 eq. (2). For three coefficients this is ``u·u²·(K1 + u²(K2 + u² K3))``.
    """
    u2 = u * u
    n = K.shape[-1]
    acc = K[..., n - 1]
    for i in range(n - 2, -1, -1):
        acc = K[..., i] + u2 * acc
    return u * u2 * acc


def _odd_series_du(u: NDArray, K: NDArray) -> NDArray:
    """``d/du Σ_i K_i u^(2i+1) = Σ_i (2i+1) K_i u^(2i)`` by Horner's rule (no checks).

    000 eq. (2). For three coefficients ``u²(3K1 + u²(5K2 + 7K3 u²))``.
    """
    u2 = u * u
    n = K.shape[-1]
    acc = (2 * n + 1) * K[..., n - 1]
    for i in range(n - 2, -1, -1):
        acc = (2 * i + 3) * K[..., i] + u2 * acc
    return u2 * acc


def _odd_series_dK(u: NDArray, n: int) -> NDArray:
    """``∂/∂K_i Σ_i K_i u^(2i+1) = u^(2i+1)``, shape (..., n) (no checks). 000 eq. (2)."""
    return u[..., None] ** (2 * np.arange(1, n + 1) + 1)


def odd_radial_1d(d: ArrayLike, K: ArrayLike, norm: float = 1.0) -> NDArray:
    """Odd radial distortion series along a line sensor.

    ``δ = Σ_i K_i u^(2i+1) = K1 u³ + K2 u⁵ + K3 u⁷ + …`` with ``u = d / norm`` (000 eq. (2),
    where ``d = ζ_T − ζ_0``).

    Parameters
    ----------
    d : (...) array_like
        Distance from the principal point along the line. Its unit (pixels, mm) is the
        caller's choice.
    K : (n,) or (..., n) array_like
        Coefficients ``K1, K2, …`` (any n >= 1); batch dimensions broadcast with ``d``. They
        are in the unit of ``d`` per ``u^(2i+1)``: with ``norm = 1`` in unit^(−2i), with 000's
        ``norm = 100 px`` in pixels (:mod:`hsgeo.sensors.line1d`).
    norm : float, optional
        The unit of ``u``, in the unit of ``d`` (default 1: ``u = d``).

    Returns
    -------
    delta : (...) ndarray
        Distortion, in the unit of ``d``.

    Raises
    ------
    InputError
        On NaN/inf, empty ``K``, a non-positive ``norm`` or non-broadcasting shapes.

    Examples
    --------
    >>> round(float(odd_radial_1d(2.0, [1e-3, 1e-5])), 12)
    0.00832
    >>> round(float(odd_radial_1d(450.0, [1.459, -0.1636, 0.00526], norm=100.0)), 2)
    27.61
    """
    d, K, _ = _check_K_1d(d, K, norm)
    return _odd_series(d / norm, K)


def odd_radial_1d_jacobian(
    d: ArrayLike, K: ArrayLike, norm: float = 1.0
) -> tuple[NDArray, NDArray]:
    """Jacobian of :func:`odd_radial_1d` with respect to d and K.

    Parameters
    ----------
    d : (...) array_like
        Distance from the principal point (caller's unit).
    K : (n,) or (..., n) array_like
        Coefficients ``K1, K2, …``.
    norm : float, optional
        The unit of ``u = d / norm`` (see :func:`odd_radial_1d`).

    Returns
    -------
    d_delta_d_d : (...) ndarray
        ``∂δ/∂d = Σ_i (2i+1) K_i u^(2i) / norm`` (dimensionless).
    d_delta_dK : (..., n) ndarray
        ``∂δ/∂K_i = u^(2i+1)``.

    Raises
    ------
    InputError
        On NaN/inf, empty ``K``, a non-positive ``norm`` or non-broadcasting shapes.
    """
    d, K, _ = _check_K_1d(d, K, norm)
    u = d / norm
    return _odd_series_du(u, K) / norm, _odd_series_dK(u, K.shape[-1])


def ideal_from_measured_1d(d: ArrayLike, K: ArrayLike, norm: float = 1.0) -> NDArray:
    """Undistort a measured coordinate along a line: ``d − δ(d)`` (000 eq. (2)).

    In 000 eq. (2), ``ζ = ζ0 − c X/Y + δ(ζ − ζ0)``: the measured distance ``d = ζ − ζ0`` minus
    the distortion is the ideal (pinhole) distance ``−c X/Y``.

    Parameters
    ----------
    d : (...) array_like
        Measured distance from the principal point (caller's unit).
    K : (n,) or (..., n) array_like
        Coefficients ``K1, K2, …`` (see :func:`odd_radial_1d`).
    norm : float, optional
        The unit of ``u = d / norm``.

    Returns
    -------
    d_ideal : (...) ndarray
        Ideal distance, in the unit of ``d``.

    Raises
    ------
    InputError
        On NaN/inf, empty ``K``, a non-positive ``norm`` or non-broadcasting shapes.
    """
    d, K, _ = _check_K_1d(d, K, norm)
    return d - _odd_series(d / norm, K)


def _measured_from_ideal_1d(
    t: NDArray, K: NDArray, norm: float, max_iter: int, tol: float, max_step: float
) -> tuple[NDArray, NDArray]:
    """Newton for ``d − δ(d) = t`` (no checks, no convergence test); returns d and 1 − δ'(d)."""
    d = np.array(t, dtype=np.float64, copy=True)
    for _ in range(max_iter):
        u = d / norm
        delta = _odd_series(u, K)
        Fp = 1.0 - _odd_series_du(u, K) / norm
        Fp = np.where(np.abs(Fp) < 1e-6, 1e-6, Fp)
        step = (d - delta - t) / Fp
        d = d - np.clip(step, -max_step, max_step)
        if np.all(np.abs(step) < tol):
            break
    u = d / norm
    Fp = 1.0 - _odd_series_du(u, K) / norm
    return d, Fp


def measured_from_ideal_1d(
    d_ideal: ArrayLike,
    K: ArrayLike,
    norm: float = 1.0,
    *,
    tol: float = 1e-10,
    max_iter: int = 50,
    max_step: float | None = None,
    check: bool = True,
) -> tuple[NDArray, NDArray]:
    """Distort an ideal coordinate along a line: solve ``d − δ(d) = d_ideal`` for d.

    The inverse of :func:`ideal_from_measured_1d` (000 eq. (2) is implicit in the measured
    coordinate), by Newton's method from ``d = d_ideal``.

    Parameters
    ----------
    d_ideal : (...) array_like
        Ideal distance from the principal point (caller's unit), e.g. ``−c X/Y``.
    K : (n,) or (..., n) array_like
        Coefficients ``K1, K2, …`` (see :func:`odd_radial_1d`).
    norm : float, optional
        The unit of ``u = d / norm``.
    tol : float, optional
        Stop when every Newton step is below ``tol`` (unit of ``d``).
    max_iter : int, optional
        Most Newton iterations.
    max_step : float, optional
        Largest Newton step (unit of ``d``); default ``2 norm`` (200 px for 000's 100 px).
    check : bool, optional
        Raise :class:`~hsgeo.errors.ConvergenceError` if a point did not converge or landed
        where ``1 − δ'(d) ≤ 0`` (the folded part of the polynomial). With ``False`` the last
        iterate is returned as it is (inside an adjustment, for trial steps).

    Returns
    -------
    d : (...) ndarray
        Measured distance, unit of ``d_ideal``.
    d_ideal_d_d : (...) ndarray
        ``1 − ∂δ/∂d`` at ``d`` (the derivative of the ideal with respect to the measured
        distance; its inverse is ``∂d/∂d_ideal``).

    Raises
    ------
    InputError
        On NaN/inf, empty ``K``, a non-positive ``norm``/``tol``/``max_iter``/``max_step``.
    ConvergenceError
        With ``check``, as described above; ``.result`` holds the last iterate.
    """
    t, K, _ = _check_K_1d(d_ideal, K, norm, "d_ideal")
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol must be a positive finite number, got {tol!r}.")
    if int(max_iter) < 1:
        raise InputError(f"max_iter must be >= 1, got {max_iter!r}.")
    step = 2.0 * norm if max_step is None else float(max_step)
    if not (np.isfinite(step) and step > 0):
        raise InputError(f"max_step must be a positive finite number, got {max_step!r}.")
    d, Fp = _measured_from_ideal_1d(t, K, float(norm), int(max_iter), float(tol), step)
    if check:
        resid = d - _odd_series(d / norm, K) - t
        bad = ~(np.abs(resid) <= max(tol, 1e-9 * norm)) | ~(Fp > 0)
        if np.any(bad):
            raise ConvergenceError(
                f"measured_from_ideal_1d: {int(np.sum(bad))} of {bad.size} point(s) did not "
                f"converge or fall on the folded part of the odd polynomial (1 − δ' ≤ 0); "
                "restrict the points to the calibrated extent of the line or check K.",
                result=d,
            )
    return d, Fp
