"""Lens-distortion models, each with matching forward, inverse and Jacobian.

One implementation per equation; the sensor models call these (or, in compiled kernels, the
same scalar core in :mod:`hsgeo._kernels`). Four forms are provided; all take arbitrary leading
batch dimensions ``...``.

1. **Odd radial series in one dimension** for line scanners (000 eq. (2)):
   ``δ(d) = K1 u³ + K2 u⁵ + K3 u⁷ + …``, ``u = d / norm`` — :func:`odd_radial_1d`,
   :func:`odd_radial_1d_jacobian`, :func:`ideal_from_measured_1d` (undistort, ``d − δ(d)``),
   :func:`measured_from_ideal_1d` (distort: 000 eq. (2) is implicit in the measured ``d``).
2. **OpenCV form**: distortion *applied* to normalised ideal coordinates
   (``x = X/Z``, ``y = Y/Z``), coefficients ``(k1, k2, p1, p2, k3)`` in OpenCV order —
   :func:`distort_opencv`, :func:`undistort_opencv`, :func:`distort_opencv_jacobian`.
3. **Photogrammetric form** (Brown 1971, Fraser 1997; 003 Table 3): a *correction* computed
   from measured, principal-point-reduced image coordinates in mm, added to obtain the ideal
   coordinates — :func:`brown_correction`, :func:`brown_correction_jacobian`,
   :func:`ideal_from_measured_mm`, :func:`measured_from_ideal_mm`.
4. **Pushbroom line form** (002 eq. (3)): ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``,
   ``y = ȳ + P2 x̄²`` at the ideal coordinates in mm — :func:`distort_pushbroom_line`,
   :func:`distort_pushbroom_line_jacobian`, :func:`undistort_pushbroom_line`.

The two 2D forms are not the same parameterisation:

* direction: OpenCV maps ideal → distorted, the photogrammetric form maps measured
  (distorted) → ideal, so the coefficients have opposite signs to first order;
* units: OpenCV coefficients are dimensionless (normalised coordinates), Brown's K_i are in
  mm^(−2i) and P_i in mm⁻¹ (to first order ``K1 ≈ −k1 / c_mm²``, ``P1 ≈ −p2 / c_mm``);
* roles: Brown's ``P1`` multiplies ``(r² + 2x̄²)`` in δx, which is OpenCV's ``p2`` term;
  Brown's ``P2`` is OpenCV's ``p1``.

References
----------
.. [1] Brown, D. C. (1971). Close-range camera calibration. Photogrammetric Engineering 37(8).
.. [2] Fraser, C. S. (1997). Digital camera self-calibration. ISPRS J. Photogramm. Remote
   Sens. 52(4), 149-159.
.. [3] Miljković, Gajski, Vela (2017). Spatial calibration of the hyperspectral line scanner
   by the bundle block adjusting method. Geodetski list 2017/2, eq. (2) (paper 000).
.. [4] Tommaselli et al. A study on the variations of inner orientation parameters of a
   hyperspectral frame camera. ISPRS Archives, Table 3 (paper 003).
.. [5] Jonassen et al. (2024), eq. (3) (paper 002).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo._kernels import pushbroom_line_distortion_rows
from hsgeo.errors import ConvergenceError, InputError
from hsgeo.validate import finite_array

__all__ = [
    "odd_radial_1d",
    "odd_radial_1d_jacobian",
    "ideal_from_measured_1d",
    "measured_from_ideal_1d",
    "distort_opencv",
    "undistort_opencv",
    "distort_opencv_jacobian",
    "brown_correction",
    "brown_correction_jacobian",
    "ideal_from_measured_mm",
    "measured_from_ideal_mm",
    "distort_pushbroom_line",
    "distort_pushbroom_line_jacobian",
    "undistort_pushbroom_line",
]


# --------------------------------------------------------------------------- validation


_as_float = finite_array  # the boundary check shared by every module


def _as_last(a: ArrayLike, name: str, n: int, what: str) -> NDArray[np.float64]:
    """Finite float array of shape (..., n)."""
    arr = _as_float(a, name)
    if arr.ndim < 1 or arr.shape[-1] != n:
        raise InputError(f"{name} must have shape (..., {n}) ({what}), got {arr.shape}.")
    return arr


def _broadcast(*arrays: tuple[NDArray[np.float64], int, str]) -> list[NDArray[np.float64]]:
    """Broadcast the batch dimensions of (array, n_trailing, name) triples."""
    try:
        batch = np.broadcast_shapes(*(a.shape[: a.ndim - k] for a, k, _ in arrays))
    except ValueError as exc:
        shapes = ", ".join(f"{nm}{a.shape}" for a, _, nm in arrays)
        raise InputError(
            f"batch dimensions do not broadcast: {shapes}; give them compatible leading shapes."
        ) from exc
    return [np.broadcast_to(a, batch + a.shape[a.ndim - k :]) for a, k, _ in arrays]


def _stack22(a, b, c, d) -> NDArray[np.float64]:
    """(..., 2, 2) array [[a, b], [c, d]]."""
    return np.stack([np.stack([a, b], axis=-1), np.stack([c, d], axis=-1)], axis=-2)


def _newton_invert(
    forward: Callable[[NDArray], tuple[NDArray, NDArray]],
    target: NDArray[np.float64],
    tol: float,
    max_iter: int,
    what: str,
) -> NDArray[np.float64]:
    """Solve ``forward(u)[0] = target`` for u (..., 2) by Newton iteration.

    ``forward`` returns the value (..., 2) and its Jacobian (..., 2, 2). Starts at
    ``u = target``. Raises ConvergenceError when a point does not reach ``|F|∞ ≤ tol``
    within ``max_iter`` iterations, or lands where J is not positive definite (the folded,
    non-monotonic part of the model, where the inverse is not the physical one).
    """
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol must be a positive finite number, got {tol!r}.")
    if int(max_iter) < 1:
        raise InputError(f"max_iter must be >= 1, got {max_iter!r}.")
    u = np.array(target, dtype=np.float64, copy=True)
    # Divergent iterates may overflow; they are detected below as non-finite.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for _ in range(int(max_iter)):
            f, J = forward(u)
            F = f - target
            done = np.all(np.abs(F) <= tol, axis=-1)
            if np.all(done):
                break
            det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
            bad = ~np.isfinite(det) | (det == 0.0)
            det = np.where(bad, 1.0, det)
            # Δu = J⁻¹ F for a 2×2 matrix
            du0 = (J[..., 1, 1] * F[..., 0] - J[..., 0, 1] * F[..., 1]) / det
            du1 = (-J[..., 1, 0] * F[..., 0] + J[..., 0, 0] * F[..., 1]) / det
            du = np.stack([du0, du1], axis=-1)
            du = np.where((bad | done)[..., None], 0.0, du)
            u = np.where(bad[..., None], np.nan, u - du)
        f, J = forward(u)
        det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
        trace = J[..., 0, 0] + J[..., 1, 1]
        # J is symmetric for the radial models (det > 0 and trace > 0 <=> positive definite)
        # and lower triangular with J11 = 1 for the 002 line form (<=> ∂x/∂x̄ > 0): either way
        # the solution lies on the monotonic (physical) branch.
        ok = np.all(np.abs(f - target) <= tol, axis=-1) & (det > 0.0) & (trace > 0.0)
    if not np.all(ok):
        n_bad = int(np.size(ok) - np.count_nonzero(ok))
        raise ConvergenceError(
            f"{what}: Newton iteration did not converge to |residual| <= {tol:g} for "
            f"{n_bad} of {np.size(ok)} point(s) in {int(max_iter)} iterations. The points are "
            "probably outside the region where the distortion model is monotonic (check the "
            "coefficients and the image extent), or raise max_iter / tol.",
            result=u,
        )
    return u


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
    x2 = xb**2
    J_dist = np.stack(
        [
            np.stack([xb**3, xb**5, 3.0 * x2, zero], axis=-1),
            np.stack([zero, zero, zero, x2], axis=-1),
        ],
        axis=-2,
    )
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
