"""Datum and identifiability: which parameters the data determine.

Before the first step the solver checks the datum (:func:`_check_datum`): a free parameter
without observations, a point whose own normal block is singular, or a rank-deficient reduced
normal matrix raises :class:`~hsgeo.DatumError` naming the parameters involved.
:func:`identifiability` runs the same analysis without adjusting (e.g. at the simulated truth,
to check a calibration design).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from hsgeo.adjust.options import SolverOptions
from hsgeo.adjust.parameters import Parameters
from hsgeo.adjust.residuals import ResidualBlock
from hsgeo.adjust.schur import _coupled, _Normal, _normal, _reduced
from hsgeo.adjust.system import _evaluate, _Layout
from hsgeo.adjust.threads import engine_threads
from hsgeo.errors import DatumError

__all__ = ["identifiability", "Identifiability"]


@dataclass
class Identifiability:
    """Rank of the reduced normal matrix at a given point (see :func:`identifiability`).

    Attributes
    ----------
    rank, n_unknowns : int
        Numerical rank and size of the reduced (non-point) normal matrix.
    null_space : list of list of (str, float)
        For each null-space direction, the parameters involved and their weight, largest first.
    undetermined_points : list of int
        Points whose own normal block is singular (too few or degenerate rays).
    unobserved : list of str
        Free parameters that no observation touches.
    singular_values : ndarray
        Eigenvalues of the scaled reduced normal matrix (ascending).
    """

    rank: int
    n_unknowns: int
    null_space: list
    undetermined_points: list
    unobserved: list
    singular_values: np.ndarray

    @property
    def full_rank(self) -> bool:
        return self.rank == self.n_unknowns and not self.undetermined_points and not self.unobserved

    def deficient_parameters(self) -> list[str]:
        """Names involved in any deficiency, each once, in order of appearance."""
        out: list[str] = list(self.unobserved)
        for vec in self.null_space:
            for name, _ in vec:
                if name not in out:
                    out.append(name)
        return out

    def message(self) -> str:
        parts = []
        if self.unobserved:
            parts.append(
                "no observation depends on "
                + ", ".join(self.unobserved[:10])
                + (" …" if len(self.unobserved) > 10 else "")
            )
        if self.undetermined_points:
            ids = self.undetermined_points
            parts.append(
                f"{len(ids)} point(s) not determined by their observations (too few or "
                f"degenerate rays), e.g. point index {ids[:5]}"
            )
        for vec in self.null_space[:5]:
            parts.append(
                "the data do not determine the combination of "
                + ", ".join(f"{n} ({w:+.2f})" for n, w in vec[:12])
            )
        head = (
            f"the normal equations are rank deficient (rank {self.rank} of {self.n_unknowns} "
            "non-point unknowns): "
        )
        tail = (
            ". Fix one of these parameters, give it a prior σ, or add observations or geometry "
            "that see it (a missing datum)."
        )
        return head + "; ".join(parts) + tail


#: A parameter takes part in a datum defect when its component in a unit null vector of the
#: unit-diagonal scaled normal matrix exceeds this. Numerically null components are ~1e-10; a
#: larger threshold (0.1) hid parameters with small but real components, e.g. the principal
#: distance of a 1D camera seeing collinear points (component 0.08, line-calibration chapter).
_NULL_COMPONENT_MIN = 1e-3


def _undetermined_points(layout: _Layout, ne: _Normal, rtol: float) -> list[int]:
    """The free points whose 3 × 3 block is singular to ``rtol`` (unit-diagonal scaled)."""
    undetermined: list[int] = []
    if ne.V is not None and layout.n_pts:
        # unit diagonal: λ_max ≤ p and λ_min ≥ det / λ_max^(p−1), so det ≥ rtol·p^p proves
        # λ_min ≥ rtol·λ_max; only the other blocks need their eigenvalues
        p = ne.V.shape[-1]
        if p == 3:  # one compiled pass (at 10× the paper's pushbroom block, 1.1 M points,
            # numpy's took 0.55 s on the main thread alone)
            from hsgeo.adjust._fast import point_blocks_doubt

            V = np.ascontiguousarray(ne.V, dtype=np.float64)
            bad, doubt, dv = point_blocks_doubt(V, rtol * p**p)
            doubt = np.flatnonzero(doubt)
            Vs_doubt = V[doubt] / dv[doubt][:, :, None] / dv[doubt][:, None, :]
        else:
            dv = np.sqrt(np.maximum(np.diagonal(ne.V, axis1=1, axis2=2), 0.0))
            dz = dv == 0
            dv = np.where(dz, 1.0, dv)
            Vs = ne.V / dv[:, :, None] / dv[:, None, :]
            bad = dz.any(axis=1)
            doubt = np.flatnonzero(~(np.linalg.det(Vs) >= rtol * p**p) & ~bad)
            Vs_doubt = Vs[doubt]
        if doubt.size:
            ev = np.linalg.eigvalsh(Vs_doubt)
            bad[doubt] = ev[:, 0] < rtol * np.maximum(ev[:, -1], 1e-300)
        undetermined = np.flatnonzero(bad & layout.pfree.any(axis=1)).tolist()
    return undetermined


def _scaled_reduced(layout: _Layout, ne: _Normal):
    """The reduced matrix scaled to unit diagonal, and the labels of zero-diagonal columns."""
    S, _, _, _ = _reduced(layout, ne, 0.0)
    d = np.diag(S).copy()
    unobserved = [layout.labels_c[i] for i in np.flatnonzero(d <= 0)]
    d = np.sqrt(np.where(d > 0, d, 1.0))
    Ss = S / d[:, None]  # (S may be the normal equations' own: a new array, one)
    Ss /= d[None, :]
    return Ss, unobserved


def _analyse(layout: _Layout, ne: _Normal, rtol: float) -> Identifiability:
    undetermined = _undetermined_points(layout, ne, rtol)
    if layout.n_c == 0:
        return Identifiability(0, 0, [], undetermined, [], np.zeros(0))
    if undetermined:
        return Identifiability(layout.n_c, layout.n_c, [], undetermined, [], np.zeros(0))
    Ss, unobserved = _scaled_reduced(layout, ne)
    ev = np.linalg.eigvalsh(Ss)
    thresh = rtol * max(float(ev[-1]), 1e-300)
    null = np.flatnonzero(ev < thresh)
    if null.size:  # the null vectors name the parameters involved
        ev, evec = np.linalg.eigh(Ss)
        null = np.flatnonzero(ev < thresh)
    vecs = []
    for j in null:
        v = evec[:, j]
        order = np.argsort(-np.abs(v))
        vecs.append(
            [(layout.labels_c[i], float(v[i])) for i in order if abs(v[i]) > _NULL_COMPONENT_MIN]
        )
    rank = int(layout.n_c - null.size)
    return Identifiability(rank, layout.n_c, vecs, [], unobserved, ev)


def identifiability(
    params: Parameters, blocks: Sequence[ResidualBlock] | ResidualBlock, *, rtol: float = 1e-11
) -> Identifiability:
    """Rank of the design at the current parameter values, without adjusting.

    Evaluate it at the simulated truth before trusting a calibration design: a parameter the
    data cannot see must be fixed, constrained by a prior, or given better geometry.

    Parameters
    ----------
    params : Parameters
    blocks : ResidualBlock or sequence of them
    rtol : float
        Eigenvalues of the unit-diagonal scaled reduced normal matrix below ``rtol`` times the
        largest count as zero.

    Returns
    -------
    Identifiability

    Notes
    -----
    The blocks are evaluated as fresh copies (:meth:`ResidualBlock.fresh`): a check at the
    truth never leaves state (a Newton start) in the blocks an adjustment then uses.
    """
    blocks = [blocks] if isinstance(blocks, ResidualBlock) else list(blocks)
    blocks = [b.fresh() for b in blocks]
    layout = _Layout(params)
    masks = [np.ones(b.m, dtype=bool) for b in blocks]
    options = SolverOptions(rank_rtol=rtol)
    with engine_threads(options.threads, sum(b.m for b in blocks), options.blas_threads):
        sy = _evaluate(layout, blocks, masks, jacobian=True, compiled=options.compiled)
        return _analyse(layout, _normal(layout, sy, options), options.rank_rtol)


def _surely_full_rank(
    layout: _Layout, ne: _Normal, rtol: float, points_checked: bool = False
) -> bool:
    """A sufficient test of full rank, at the cost of one Cholesky factorisation.

    With the unit-diagonal scaled reduced matrix ``Ss`` and ``b ≥ λ_max`` its largest absolute
    row sum (Gershgorin), a Cholesky factorisation of ``Ss − rtol·b·I`` exists only if
    ``λ_min > rtol·b ≥ rtol·λ_max``: :func:`_analyse`'s eigenvalue test then passes too. False
    means "not proven" (the eigenvalues decide). The eigendecomposition costs several times a
    Cholesky factorisation: seconds for the ~3000 unknowns of a long pushbroom block.
    ``points_checked``: the caller found no undetermined point in ``ne`` already (the test of
    100,000 point blocks is not repeated).
    """
    if not points_checked and _undetermined_points(layout, ne, rtol):
        return False
    if layout.n_c == 0:
        return True
    Ss, unobserved = _scaled_reduced(layout, ne)
    if unobserved:
        return False
    b = float(np.abs(Ss).sum(axis=1).max())
    keep = _coupled(Ss)
    if keep is not None:  # the uncoupled columns: 1 × 1 blocks of the unit diagonal
        if not 1.0 - rtol * b > 0.0:
            return False
        Ss = Ss[np.ix_(keep, keep)]
    Ss[np.diag_indices_from(Ss)] -= rtol * b
    try:
        sla.cholesky(Ss, lower=True, overwrite_a=True, check_finite=False)
    except (np.linalg.LinAlgError, sla.LinAlgError):
        return False
    return True


def _check_datum(layout: _Layout, ne: _Normal, rtol: float, points_checked: bool = False) -> None:
    """Raise :class:`~hsgeo.DatumError` if the normal equations at ``ne`` are rank deficient
    (``points_checked``: no point block of ``ne`` is singular, the caller tested them).
    """
    if _surely_full_rank(layout, ne, rtol, points_checked):
        return
    ident = _analyse(layout, ne, rtol)
    if not ident.full_rank:
        raise DatumError(
            ident.message(), ident.deficient_parameters(), ident.rank, ident.n_unknowns
        )
