"""The shared parts of the distortion models: boundary checks, broadcasting and a 2-D Newton
inversion.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import ConvergenceError, InputError
from hsgeo.validate import finite_array

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
