"""Residual blocks: the observation equations the engine adjusts.

A residual block computes, for its ``m`` residual components, the model minus the observation
``r = f(x) - l`` and, on request, the Jacobian ``∂r/∂x`` for each parameter block it depends on.
It carries the a-priori standard deviation of each component (``sigma``) and how many components
form one observation (``group_size``: 1 for a line scanner's ζ, 2 for image x, y), which is the unit
of outlier rejection.

Jacobians come in one of three forms, keyed by parameter-block name:

* :class:`Indexed` ``(index, d)``: row ``j`` touches the items ``index[j]`` of the block viewed as
  an ``(n_items, k)`` array, with derivatives ``d[j]`` — per-image exterior orientations, per-point
  coordinates, spline nodes (``index`` of shape ``(m, q)`` when a row touches ``q`` items). The
  engine needs this form for the points block. ``Indexed(index, d, weights=w)`` is the factored
  form of a row that touches ``q`` items through one ``k``-vector ``d[j]`` scaled by the weights
  ``w[j]``: the derivative w.r.t. item ``index[j, a]`` is ``w[j, a] · d[j]``. That is the chain rule
  through an interpolation, e.g. trajectory corrections on spline nodes, ``∂r/∂c_a = B_a(t) ∂r/∂δ``;
  the engine's compiled path uses the factorisation to form the reduced normal equations with a
  fraction of the work (:mod:`hsgeo.adjust._fast`).
* a dense ``(m, block.size)`` array, for small global blocks (focal length, distortion).
* a ``scipy.sparse`` matrix ``(m, block.size)``.

Subclass :class:`ResidualBlock` and implement :meth:`~ResidualBlock.evaluate`. A block whose
model iterates internally may also implement :meth:`~ResidualBlock.trial_residuals`, the
residuals with which the solver costs a trial step (the solver checks each accepted trial's cost
against the linearisation that follows, and costs its trials with ``evaluate`` from the first
that falls short).

A residual block names the parameter blocks it depends on in one way: the mapping
``blocks`` from *role* (what the model calls the block: ``"poses"``, ``"intrinsics"``) to the
*name* of the parameter block in :class:`~hsgeo.adjust.Parameters`. A subclass declares its
roles and default names in the class attribute ``BLOCKS``; an instance renames any of them
with the constructor argument ``blocks={"poses": "poses_band3"}``. ``evaluate`` reads
``values[self.blocks[role]]`` and keys its Jacobians by the same names.
"""

from __future__ import annotations

import copy
import difflib
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from hsgeo.errors import InputError

__all__ = ["Indexed", "ResidualBlock", "to_coo"]


@dataclass(frozen=True)
class Indexed:
    """A Jacobian whose row ``j`` touches items ``index[j]`` of an ``(n_items, k)`` block.

    Parameters
    ----------
    index : (m,) or (m, q) int ndarray
        Item (row of the block viewed as ``(n_items, k)``) touched by each residual row; ``-1``
        for a row that touches none.
    d : (m, k) or (m, q, k) float ndarray
        The derivatives of each residual row with respect to the ``k`` entries of its item(s);
        with ``weights``, ``(m, k)``: the derivative shared by the ``q`` items.
    weights : (m, q) float ndarray, optional
        Factored form: the derivative w.r.t. item ``index[j, a]`` is ``weights[j, a] * d[j]``.
    """

    index: np.ndarray
    d: np.ndarray
    weights: np.ndarray | None = None

    def __post_init__(self):
        idx = np.asarray(self.index)
        d = np.asarray(self.d, dtype=np.float64)
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=np.float64)
            idx2 = idx[:, None] if idx.ndim == 1 else idx
            w = w[:, None] if w.ndim == 1 else w
            if d.ndim != 2 or w.shape != idx2.shape or d.shape[0] != idx2.shape[0]:
                raise InputError(
                    f"factored Indexed Jacobian: index {np.shape(self.index)}, weights "
                    f"{np.shape(self.weights)} and derivative {np.shape(self.d)} do not match "
                    "((m, q), (m, q) and (m, k))"
                )
            object.__setattr__(self, "index", idx2.astype(np.int64, copy=False))
            object.__setattr__(self, "d", d)
            object.__setattr__(self, "weights", w)
            return
        if idx.ndim == 1:
            idx = idx[:, None]
            d = d[:, None, :] if d.ndim == 2 else d
        if d.ndim != 3 or d.shape[:2] != idx.shape:
            raise InputError(
                f"Indexed Jacobian: index shape {np.shape(self.index)} and derivative shape "
                f"{np.shape(self.d)} do not match ((m,) with (m, k), or (m, q) with (m, q, k))"
            )
        object.__setattr__(self, "index", idx.astype(np.int64, copy=False))
        object.__setattr__(self, "d", d)

    @property
    def k(self) -> int:
        return self.d.shape[-1]

    @property
    def factored(self) -> bool:
        return self.weights is not None

    def expanded(self) -> Indexed:
        """The same Jacobian with ``d`` of shape ``(m, q, k)`` (no factorisation)."""
        if self.weights is None:
            return self
        return Indexed(self.index, self.weights[:, :, None] * self.d[:, None, :])


def to_coo(jac, m: int, size: int, name: str):
    """Rows, block-local columns and values of a Jacobian in any accepted form.

    Returns
    -------
    rows, cols, vals : 1-D ndarrays
    """
    if isinstance(jac, Indexed):
        jac = jac.expanded()
        m_j, q, k = jac.d.shape
        if m_j != m:
            raise InputError(f"Jacobian w.r.t. {name!r} has {m_j} rows, residuals have {m}")
        if size % k:
            raise InputError(f"Jacobian w.r.t. {name!r}: item width {k} does not divide {size}")
        valid = jac.index >= 0
        if np.any(jac.index[valid] >= size // k):
            raise InputError(f"Jacobian w.r.t. {name!r} indexes past the block's items")
        rows = np.broadcast_to(np.arange(m)[:, None, None], (m, q, k))
        cols = jac.index[:, :, None] * k + np.arange(k)
        keep = np.broadcast_to(valid[:, :, None], (m, q, k))
        return rows[keep], cols[keep], jac.d[keep]
    if sp.issparse(jac):
        c = jac.tocoo()
        if c.shape != (m, size):
            raise InputError(f"Jacobian w.r.t. {name!r} has shape {c.shape}, expected {(m, size)}")
        return c.row.astype(np.int64), c.col.astype(np.int64), c.data
    arr = np.asarray(jac, dtype=np.float64)
    if arr.shape != (m, size):
        raise InputError(f"Jacobian w.r.t. {name!r} has shape {arr.shape}, expected {(m, size)}")
    rows, cols = np.nonzero(np.ones_like(arr, dtype=bool))
    return rows, cols, arr.ravel()


class ResidualBlock:
    """Base class of observation equations.

    Attributes
    ----------
    name : str
        Name used in reports (``"image points"``, ``"GCP"``).
    sigma : (m,) ndarray
        A-priori standard deviation of each residual component, in the residual's units.
    group_size : int
        Components per observation (consecutive rows), the unit of outlier rejection.
    blocks : mapping of str to str
        Parameter-block name of each role the residuals depend on (read-only): the class's
        ``BLOCKS`` with the constructor's ``blocks`` applied.

    Parameters
    ----------
    sigma : array_like
        A-priori σ of each residual component.
    name : str, optional
        Overrides the class's ``name``.
    group_size : int, optional
        Overrides the class's ``group_size``.
    blocks : mapping of str to str, optional
        Parameter-block names by role, replacing the defaults of ``BLOCKS`` for the roles
        given (e.g. ``{"poses": "poses_band3"}``).
    """

    name: str = "residuals"
    group_size: int = 1
    #: The roles of the parameter blocks the residuals depend on, with their default names.
    BLOCKS: ClassVar[Mapping[str, str]] = MappingProxyType({})

    def __init__(
        self,
        sigma,
        name: str | None = None,
        group_size: int | None = None,
        blocks: Mapping[str, str] | None = None,
    ):
        if name is not None:
            self.name = name
        self.blocks = self._block_names(blocks)
        if group_size is not None:
            self.group_size = int(group_size)
        s = np.asarray(sigma, dtype=np.float64).ravel()
        if s.size == 0:
            raise InputError(f"residual block {self.name!r} has no observations")
        if not np.all(np.isfinite(s)) or np.any(s <= 0):
            raise InputError(
                f"residual block {self.name!r}: a-priori σ must be finite and positive "
                "(check the observation file's sigma column)"
            )
        if s.size % self.group_size:
            raise InputError(
                f"residual block {self.name!r}: {s.size} components are not a multiple of the "
                f"group size {self.group_size}"
            )
        self.sigma = s

    def _block_names(self, blocks: Mapping[str, str] | None) -> Mapping[str, str]:
        names = dict(type(self).BLOCKS)
        for role, block in (blocks or {}).items():
            if role not in names:
                close = difflib.get_close_matches(str(role), list(names), n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise InputError(
                    f"residual block {self.name!r} has no parameter role {role!r}{hint}; its "
                    f"roles are {', '.join(names) or '(none)'}"
                )
            if not isinstance(block, str) or not block:
                raise InputError(
                    f"residual block {self.name!r}: the parameter block of role {role!r} must "
                    f"be named by a non-empty string, got {block!r}"
                )
            names[role] = block
        return MappingProxyType(names)

    @property
    def m(self) -> int:
        """Number of residual components."""
        return self.sigma.size

    def fresh(self) -> ResidualBlock:
        """A copy of this block in the state it was built in, for checks (e.g. at the truth).

        A block that keeps state between evaluations (a Newton start, a cache) overrides this
        to give the copy its own initial state; evaluating the copy then never changes what an
        adjustment of this block computes. The observations are shared, not copied.
        """
        return copy.copy(self)

    def evaluate(self, values: dict[str, np.ndarray], jacobian: bool):
        """Model minus observation, and optionally the Jacobian.

        Parameters
        ----------
        values : dict of str to ndarray
            Current parameter values by block name (do not modify).
        jacobian : bool
            Whether to compute the Jacobian.

        Returns
        -------
        r : (m,) ndarray
            Residuals ``f(x) - l`` in the units of ``sigma``.
        jac : dict of str to Jacobian, or None
            ``∂r/∂(block)`` for each block the residuals depend on (see the module docstring).
        """
        raise NotImplementedError

    def trial_residuals(self, values: dict[str, np.ndarray]) -> np.ndarray:
        """The residuals at the solver's trial point of a step, whose cost only decides whether
        the step is taken (and, rejecting in each iteration, which rows are outliers).

        A block whose model iterates internally (a Newton on a crossing time) may stop earlier
        here, with an error of second order in what its iteration still moves; the residuals
        of a linearisation are always :meth:`evaluate`'s. The solver compares an accepted
        trial's cost with the exact cost of the linearisation at its point, and costs every
        later trial with :meth:`evaluate` once a trial's falls short by more than 1e-9
        relative. The default is ``evaluate(values, False)[0]``.
        """
        return self.evaluate(values, False)[0]

    def start_trial(self, change: np.ndarray) -> None:
        """Before the solver's trial point of a step: ``change`` (m,), the step's linear
        prediction of this block's residuals' change from the last linearisation
        (``J h``, in the units of ``sigma``; NaN on the rows the solver leaves out).

        A block whose model iterates internally (a Newton on a crossing time) may start its
        next :meth:`trial_residuals` there instead of where its last evaluation ended: with a
        large step the iteration then needs fewer passes. It changes where the iteration
        starts, not where it stops. The solver gives it when it has ``J h`` at hand (before the
        first settled iterate, for its test of points thrown by the step). The default does
        nothing.
        """
