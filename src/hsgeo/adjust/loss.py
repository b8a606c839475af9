"""Robust losses of a group's squared whitened residual ``s`` (Ceres' ``LossFunction``).

``ρ(s)`` replaces ``s`` in the cost ``½ Σ ρ(s)``; the solver linearises it as iteratively
reweighted least squares: each group's rows are scaled by ``√ρ'(s)`` (the gradient is exact,
and the model ``ρ(s) + ρ'(s) (‖r + J h‖² − s)`` bounds the cost from above since both losses
are concave in ``s``, so a step the model accepts decreases the cost). The scale ``c`` is in
the units of the whitened residuals: ``k`` robust σ (NMAD about zero) of the residuals at the
linearisation point (see ``SolverOptions.robust_start``).

References
----------
S. Agarwal, K. Mierle et al.: Ceres Solver, ``LossFunction`` (``CauchyLoss``: ``ρ(s) = c²
log(1 + s/c²)``; ``HuberLoss``: ``ρ(s) = s`` for ``s ≤ c²``, ``2c√s − c²`` beyond).
B. Triggs et al. (2000): Bundle adjustment — a modern synthesis, §3.3 (robustified costs).
"""

from __future__ import annotations

import numpy as np

from hsgeo.stats import NMAD_SCALE

__all__: list[str] = ["rho", "scale", "weigh"]


def rho(kind: str, s: np.ndarray, c: float) -> tuple[np.ndarray, np.ndarray]:
    """``ρ(s)`` and ``ρ'(s)`` of the loss ``kind`` with scale ``c`` (``s``: squared norms)."""
    c2 = c * c
    if kind == "cauchy":
        u = s / c2
        return c2 * np.log1p(u), 1.0 / (1.0 + u)
    if kind == "huber":
        root = np.sqrt(s)
        outer = s > c2
        r = np.where(outer, 2.0 * c * root - c2, s)
        d = np.where(outer, c / np.where(outer, root, 1.0), 1.0)
        return r, d
    raise ValueError(f"unknown loss {kind!r}")


def scale(rw: np.ndarray, k: float) -> float:
    """``k`` robust σ (NMAD about zero) of the whitened residuals ``rw`` (at least 1e-300)."""
    if not rw.size:
        return 1.0
    return max(k * NMAD_SCALE * float(np.median(np.abs(rw))), 1e-300)


def weigh(kind: str, rw: np.ndarray, g: int, c: float, linearise: bool):
    """The rows of one block under the loss: ``(row factor, Σ ρ)``.

    ``rw``: the whitened residuals of the kept rows (groups of ``g`` rows). With
    ``linearise`` the factor is ``√ρ'(s)`` (rows and their Jacobian scaled: the IRLS system);
    otherwise ``√(ρ(s)/s)``, so that ``½ ‖factor · rw‖²`` is the robust cost itself.
    """
    s = np.einsum("ij,ij->i", rw.reshape(-1, g), rw.reshape(-1, g))
    r, d = rho(kind, s, c)
    if linearise:
        f = np.sqrt(d)
    else:
        f = np.sqrt(np.where(s > 0, r / np.where(s > 0, s, 1.0), 1.0))
    return np.repeat(f, g), float(r.sum())
