"""Finite-difference checks of residual-block Jacobians (used by every model's tests)."""

from __future__ import annotations

import numpy as np

from hsgeo.adjust.residuals import ResidualBlock, to_coo

__all__ = ["analytic_jacobian", "numerical_jacobian", "check_jacobian"]


def analytic_jacobian(block: ResidualBlock, values: dict[str, np.ndarray], name: str) -> np.ndarray:
    """The block's Jacobian w.r.t. parameter ``name`` as a dense ``(m, size)`` array."""
    _, jac = block.evaluate(values, True)
    size = np.asarray(values[name]).size
    out = np.zeros((block.m, size))
    if name not in jac:
        return out
    r, c, v = to_coo(jac[name], block.m, size, name)
    np.add.at(out, (r, c), v)
    return out


def numerical_jacobian(
    block: ResidualBlock, values: dict[str, np.ndarray], name: str, step: float | np.ndarray = 1e-6
) -> np.ndarray:
    """Central finite differences of the residuals w.r.t. every entry of ``values[name]``.

    ``step`` is absolute (scalar or per entry); choose it relative to the parameter's scale.
    """
    base = {k: np.array(v, dtype=float, copy=True) for k, v in values.items()}
    x0 = base[name].ravel().copy()
    steps = np.broadcast_to(np.asarray(step, dtype=float), x0.shape)
    out = np.zeros((block.m, x0.size))
    for i in range(x0.size):
        h = steps[i]
        xp, xm = x0.copy(), x0.copy()
        xp[i] += h
        xm[i] -= h
        base[name] = xp.reshape(np.shape(values[name]))
        rp, _ = block.evaluate(base, False)
        base[name] = xm.reshape(np.shape(values[name]))
        rm, _ = block.evaluate(base, False)
        out[:, i] = (np.asarray(rp) - np.asarray(rm)) / (2 * h)
    return out


def check_jacobian(
    block: ResidualBlock, values: dict[str, np.ndarray], name: str, step=1e-6
) -> float:
    """Largest |analytic − numerical| relative to the largest |numerical| entry (≥ 1e-12)."""
    a = analytic_jacobian(block, values, name)
    n = numerical_jacobian(block, values, name, step)
    return float(np.max(np.abs(a - n)) / max(np.max(np.abs(n)), 1e-12))
