"""One least-squares engine for every problem in hsgeo.

Gauss–Newton with Levenberg–Marquardt damping on the whitened observation equations
``r_w = (f(x) - l) / σ``, minimising ``½ Σ r_w²`` over the free parameters:

* the Jacobian is assembled sparse from the residual blocks (no dense ``m × n`` matrix);
* priors enter as pseudo-observations ``(x - μ) / σ_prior``;
* per-point unknowns (the ``points=True`` block) are eliminated by the Schur complement:
  with ``N = [[N_cc, W], [Wᵀ, V]]`` and ``V`` block diagonal (one ``p × p`` block per point), the
  reduced system ``S Δc = -(g_c - W V⁻¹ g_p)`` with ``S = N_cc - W V⁻¹ Wᵀ`` is solved densely
  (Cholesky) and the points follow as ``Δp = -V⁻¹ (g_p + Wᵀ Δc)``;
* damping is Marquardt's ``N + λ diag(N)`` with Nielsen's update of λ;
* convergence: relative decrease of the cost and the predicted decrease both below ``ftol``, or
  the cost below ``atol`` (noise-free data);
* before the first step the datum is checked: a parameter without observations, a point that is
  not determined, or a rank-deficient reduced normal matrix raises :class:`~hsgeo.DatumError`
  naming the parameters involved;
* after convergence, optional rounds of outlier rejection remove observations whose normalised
  residual exceeds ``reject_k`` robust standard deviations, and the adjustment is repeated;
* the a-posteriori σ0 and the covariance of the non-point parameters (points on request) are in
  the :class:`~hsgeo.adjust.result.AdjustmentResult`.

References
----------
Triggs, McLauchlan, Hartley, Fitzgibbon (2000): Bundle adjustment — a modern synthesis.
Madsen, Nielsen, Tingleff (2004): Methods for non-linear least squares problems, §3.2.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from hsgeo.adjust.parameters import Parameters
from hsgeo.adjust.residuals import Indexed, ResidualBlock, to_coo
from hsgeo.errors import ConvergenceError, DatumError, InputError, ObservationError

__all__ = ["adjust", "identifiability", "Identifiability"]


# ----------------------------------------------------------------------------------------------
# Layout: which parameter entries are columns of the reduced system, and the points block.
# ----------------------------------------------------------------------------------------------
class _Layout:
    def __init__(self, params: Parameters):
        self.params = params
        self.cblocks = [b for b in params.blocks() if not b.points]
        self.colmap: dict[str, np.ndarray] = {}
        n = 0
        for b in self.cblocks:
            free = b.free.ravel()
            cm = np.full(b.size, -1, dtype=np.int64)
            cm[free] = np.arange(n, n + free.sum())
            n += int(free.sum())
            self.colmap[b.name] = cm
        self.n_c = n
        self.labels_c = params.free_labels([b.name for b in self.cblocks])
        pb = params.points_block
        self.pblock = pb
        if pb is not None:
            self.n_pts, self.p = pb.shape
            self.pfree = pb.free.copy()
        else:
            self.n_pts, self.p = 0, 0
            self.pfree = np.zeros((0, 0), dtype=bool)

    @property
    def n_unknowns(self) -> int:
        return self.n_c + int(self.pfree.sum())

    def apply(self, dc: np.ndarray, dp: np.ndarray | None) -> None:
        for b in self.cblocks:
            cm = self.colmap[b.name]
            sel = cm >= 0
            if sel.any():
                v = b.value.ravel().copy()
                v[sel] += dc[cm[sel]]
                b.value = v.reshape(b.shape)
        if self.pblock is not None and dp is not None:
            self.pblock.value = self.pblock.value + np.where(self.pfree, dp, 0.0)

    def get_state(self):
        return [b.value.copy() for b in self.params.blocks()]

    def set_state(self, state):
        for b, v in zip(self.params.blocks(), state, strict=True):
            b.value = v.copy()


@dataclass
class _System:
    """The whitened, linearised problem at one point x."""

    r: np.ndarray  # (M,) whitened residuals, observation rows then prior rows
    Jc: sp.csr_matrix | None  # (M, n_c)
    pidx: np.ndarray | None  # (M,) point touched by each row (-1: none)
    Jp: np.ndarray | None  # (M, p)
    n_obs_rows: int  # rows that are observations (the rest are priors)

    @property
    def cost(self) -> float:
        return 0.5 * float(self.r @ self.r)


def _evaluate(layout: _Layout, blocks: Sequence[ResidualBlock], masks, jacobian: bool) -> _System:
    values = layout.params.values()
    r_parts, rows_c, cols_c, vals_c, pidx_parts, jp_parts = [], [], [], [], [], []
    offset = 0
    pname = layout.pblock.name if layout.pblock is not None else None
    for blk, keep in zip(blocks, masks, strict=True):
        r, jac = blk.evaluate(values, jacobian)
        r = np.asarray(r, dtype=np.float64)
        if r.shape != (blk.m,):
            raise InputError(
                f"residual block {blk.name!r} returned {r.shape} residuals, expected ({blk.m},)"
            )
        if not np.all(np.isfinite(r)):
            bad = np.flatnonzero(~np.isfinite(r))[:5].tolist()
            raise InputError(
                f"residual block {blk.name!r} produced non-finite residuals at rows {bad}: "
                "check the observations for NaN, or the initial values (a point behind the "
                "camera, a zero depth)"
            )
        w = 1.0 / blk.sigma
        rows_kept = np.flatnonzero(keep)
        newrow = np.full(blk.m, -1, dtype=np.int64)
        newrow[rows_kept] = np.arange(offset, offset + rows_kept.size)
        r_parts.append(r[rows_kept] * w[rows_kept])
        if jacobian:
            pidx = np.full(rows_kept.size, -1, dtype=np.int64)
            jp = np.zeros((rows_kept.size, layout.p))
            for name, J in jac.items():
                b = layout.params[name]
                if name == pname:
                    if not isinstance(J, Indexed) or J.index.shape[1] != 1 or J.k != layout.p:
                        raise InputError(
                            f"the Jacobian w.r.t. the points block {name!r} must be "
                            f"Indexed((m,), (m, {layout.p})): each row touches one point"
                        )
                    pidx = J.index[rows_kept, 0]
                    jp = J.d[rows_kept, 0, :] * w[rows_kept, None]
                    jp = np.where(pidx[:, None] >= 0, jp * layout.pfree[np.maximum(pidx, 0)], 0.0)
                    continue
                rr, cc, vv = to_coo(J, blk.m, b.size, name)
                gc = layout.colmap[name][cc]
                nr = newrow[rr]
                sel = (gc >= 0) & (nr >= 0)
                rows_c.append(nr[sel])
                cols_c.append(gc[sel])
                vals_c.append(vv[sel] * w[rr[sel]])
            pidx_parts.append(pidx)
            jp_parts.append(jp)
        offset += rows_kept.size
    n_obs_rows = offset

    # priors as pseudo-observations (x - μ) / σ
    for b in layout.params.blocks():
        hp = b.has_prior
        if not hp.any():
            continue
        idx = np.flatnonzero(hp.ravel())
        s = b.prior_sigma.ravel()[idx]
        r_parts.append((b.value.ravel()[idx] - b.prior_mean.ravel()[idx]) / s)
        if jacobian:
            nr = np.arange(offset, offset + idx.size)
            if b.points:
                pt, comp = np.divmod(idx, layout.p)
                jp = np.zeros((idx.size, layout.p))
                jp[np.arange(idx.size), comp] = 1.0 / s
                pidx_parts.append(pt)
                jp_parts.append(jp)
            else:
                rows_c.append(nr)
                cols_c.append(layout.colmap[b.name][idx])
                vals_c.append(1.0 / s)
                pidx_parts.append(np.full(idx.size, -1, dtype=np.int64))
                jp_parts.append(np.zeros((idx.size, layout.p)))
        offset += idx.size

    r_all = np.concatenate(r_parts) if r_parts else np.zeros(0)
    if not jacobian:
        return _System(r_all, None, None, None, n_obs_rows)
    M = offset
    if rows_c:
        Jc = sp.csr_matrix(
            (np.concatenate(vals_c), (np.concatenate(rows_c), np.concatenate(cols_c))),
            shape=(M, layout.n_c),
        )
    else:
        Jc = sp.csr_matrix((M, layout.n_c))
    pidx = np.concatenate(pidx_parts) if pidx_parts else np.full(M, -1)
    Jp = np.concatenate(jp_parts) if jp_parts else np.zeros((M, layout.p))
    return _System(r_all, Jc, pidx, Jp, n_obs_rows)


# ----------------------------------------------------------------------------------------------
# Normal equations and the Schur-reduced step
# ----------------------------------------------------------------------------------------------
@dataclass
class _Normal:
    Ncc: np.ndarray  # (n_c, n_c) dense
    gc: np.ndarray  # (n_c,)
    V: np.ndarray | None  # (n_pts, p, p)
    gp: np.ndarray | None  # (n_pts, p)
    W: sp.csr_matrix | None  # (n_c, n_pts * p)


def _normal(layout: _Layout, sy: _System) -> _Normal:
    Jc = sy.Jc
    Ncc = (Jc.T @ Jc).toarray() if layout.n_c else np.zeros((0, 0))
    gc = Jc.T @ sy.r
    if layout.pblock is None:
        return _Normal(Ncc, gc, None, None, None)
    n_pts, p = layout.n_pts, layout.p
    rows = np.flatnonzero(sy.pidx >= 0)
    pi = sy.pidx[rows]
    jp = sy.Jp[rows]
    # V_i = Σ_rows jpᵀ jp, g_p,i = Σ jpᵀ r  (sparse aggregation instead of a Python loop)
    agg = sp.csr_matrix((np.ones(rows.size), (pi, np.arange(rows.size))), shape=(n_pts, rows.size))
    V = (agg @ (jp[:, :, None] * jp[:, None, :]).reshape(rows.size, p * p)).reshape(n_pts, p, p)
    gp = agg @ (jp * sy.r[rows, None])
    # fixed point entries: unit diagonal, zero gradient -> zero update
    # (their Jacobian columns were zeroed in _evaluate, so V has zero rows/columns there)
    fixed = ~layout.pfree
    ii = np.nonzero(fixed)
    V[ii[0], ii[1], ii[1]] = 1.0
    gp[fixed] = 0.0
    Jp_sp = sp.csr_matrix(
        (jp.ravel(), (np.repeat(rows, p), (pi[:, None] * p + np.arange(p)).ravel())),
        shape=(sy.r.size, n_pts * p),
    )
    W = (Jc.T @ Jp_sp).tocsr()
    return _Normal(Ncc, gc, V, gp, W)


def _damped(A: np.ndarray, lam: float) -> np.ndarray:
    """A + λ·diag(A) on the last two axes (Marquardt), with a floor on zero diagonals."""
    if lam == 0.0:
        return A
    A = A.copy()
    d = np.diagonal(A, axis1=-2, axis2=-1)
    floor = 1e-12 * max(float(np.max(d)) if d.size else 1.0, 1e-300)
    idx = np.arange(A.shape[-1])
    A[..., idx, idx] += lam * np.maximum(d, floor)
    return A


def _block_diag(Vinv: np.ndarray) -> sp.csr_matrix:
    n, p, _ = Vinv.shape
    rows = np.repeat(np.arange(n * p), p)
    cols = (np.arange(n)[:, None, None] * p + np.zeros((1, p, 1), dtype=int) + np.arange(p)).ravel()
    return sp.csr_matrix((Vinv.ravel(), (rows, cols)), shape=(n * p, n * p))


def _reduced(layout: _Layout, ne: _Normal, lam: float):
    """S, rhs and the pieces for back-substitution, at damping λ."""
    S = _damped(ne.Ncc, lam)
    rhs = ne.gc.copy()
    if ne.V is None:
        return S, rhs, None, None
    Vd = _damped(ne.V, lam)
    try:
        Vinv = np.linalg.inv(Vd)
    except np.linalg.LinAlgError:
        Vinv = np.linalg.pinv(Vd)
    WVinv = (ne.W @ _block_diag(Vinv)).tocsr()
    if layout.n_c:
        S = S - (WVinv @ ne.W.T).toarray()
        rhs = rhs - WVinv @ ne.gp.ravel()
    return S, rhs, Vinv, WVinv


def _step(layout: _Layout, ne: _Normal, lam: float):
    S, rhs, Vinv, _ = _reduced(layout, ne, lam)
    if layout.n_c:
        try:
            dc = -sla.cho_solve(sla.cho_factor(S, check_finite=False), rhs, check_finite=False)
        except (np.linalg.LinAlgError, sla.LinAlgError):
            dc = -np.linalg.lstsq(S, rhs, rcond=None)[0]
    else:
        dc = np.zeros(0)
    dp = None
    if Vinv is not None:
        b = ne.gp + (ne.W.T @ dc).reshape(layout.n_pts, layout.p)
        dp = -np.einsum("nij,nj->ni", Vinv, b)
    return dc, dp


def _predicted_decrease(layout, ne: _Normal, lam, dc, dp) -> float:
    """L(0) - L(h) = ½ hᵀ(λ D h - g) for the damped Gauss–Newton step h (Madsen et al. eq. 3.14)."""
    Dc = np.maximum(np.diag(ne.Ncc), 0.0) if layout.n_c else np.zeros(0)
    pred = 0.5 * float(dc @ (lam * Dc * dc - ne.gc))
    if dp is not None:
        Dp = np.maximum(np.diagonal(ne.V, axis1=1, axis2=2), 0.0)
        pred += 0.5 * float(np.sum(dp * (lam * Dp * dp - ne.gp)))
    return pred


# ----------------------------------------------------------------------------------------------
# Datum / identifiability
# ----------------------------------------------------------------------------------------------
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
        return (
            self.rank == self.n_unknowns and not self.undetermined_points and not self.unobserved
        )

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
                "no observation depends on " + ", ".join(self.unobserved[:10])
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


def _analyse(layout: _Layout, ne: _Normal, rtol: float) -> Identifiability:
    undetermined: list[int] = []
    if ne.V is not None and layout.n_pts:
        dv = np.sqrt(np.maximum(np.diagonal(ne.V, axis1=1, axis2=2), 0.0))
        dz = dv == 0
        dv = np.where(dz, 1.0, dv)
        Vs = ne.V / dv[:, :, None] / dv[:, None, :]
        ev = np.linalg.eigvalsh(Vs)
        bad = (ev[:, 0] < rtol * np.maximum(ev[:, -1], 1e-300) ** 1) | dz.any(axis=1)
        undetermined = np.flatnonzero(bad & layout.pfree.any(axis=1)).tolist()
    if layout.n_c == 0:
        return Identifiability(0, 0, [], undetermined, [], np.zeros(0))
    if undetermined:
        return Identifiability(layout.n_c, layout.n_c, [], undetermined, [], np.zeros(0))
    S, _, _, _ = _reduced(layout, ne, 0.0)
    d = np.diag(S).copy()
    unobserved = [layout.labels_c[i] for i in np.flatnonzero(d <= 0)]
    d = np.sqrt(np.where(d > 0, d, 1.0))
    Ss = S / d[:, None] / d[None, :]
    ev, evec = np.linalg.eigh(Ss)
    thresh = rtol * max(float(ev[-1]), 1e-300)
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
    """
    blocks = [blocks] if isinstance(blocks, ResidualBlock) else list(blocks)
    layout = _Layout(params)
    masks = [np.ones(b.m, dtype=bool) for b in blocks]
    sy = _evaluate(layout, blocks, masks, jacobian=True)
    return _analyse(layout, _normal(layout, sy), rtol)


# ----------------------------------------------------------------------------------------------
# The driver
# ----------------------------------------------------------------------------------------------
def _progress_printer(progress):
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress

    def show(info):
        print(
            f"  iter {info['iteration']:3d}  cost {info['cost']:.6e}  λ {info['lambda']:.1e}"
            f"  {info['seconds']:.2f} s" + (f"  rejected {info['rejected']}" if info.get(
                "rejected") else ""),
            file=sys.stderr,
            flush=True,
        )

    return show


def _robust_scale(sy: _System) -> float:
    r = np.abs(sy.r[: sy.n_obs_rows])
    return max(1.4826 * float(np.median(r)), 1e-300) if r.size else 1.0


def adjust(
    params: Parameters,
    blocks: Sequence[ResidualBlock] | ResidualBlock,
    *,
    max_iter: int = 50,
    ftol: float = 1e-10,
    atol: float = 1e-24,
    lambda0: float = 1e-6,
    reject_k: float | None = None,
    max_reject_rounds: int = 10,
    check_datum: bool = True,
    rank_rtol: float = 1e-11,
    raise_on_failure: bool = True,
    progress: bool | Callable | None = None,
):
    """Adjust ``params`` to the observations of ``blocks`` by least squares.

    Parameters
    ----------
    params : Parameters
        Initial values, free/fixed flags and priors. Not modified: the estimate is in the result.
    blocks : ResidualBlock or sequence of them
        The observation equations.
    max_iter : int
        Maximum number of accepted Gauss–Newton/LM steps per rejection round.
    ftol : float
        Convergence when the relative decrease of the cost, and the predicted one, fall below it.
    atol : float
        Convergence when the cost (½ Σ r_w²) per observation falls below it (noise-free data).
    lambda0 : float
        Initial Marquardt damping (relative to diag N); small means Gauss–Newton first.
    reject_k : float, optional
        Reject observations whose whitened residual exceeds ``reject_k`` robust σ (NMAD of the
        whitened residuals) after convergence, and adjust again; repeated until none is rejected
        or ``max_reject_rounds``. A whole group (e.g. x and y of one point) is rejected together.
    check_datum : bool
        Check the rank before the first step and raise :class:`~hsgeo.DatumError` if deficient.
    rank_rtol : float
        Relative eigenvalue threshold of the datum check (see :func:`identifiability`).
    raise_on_failure : bool
        Raise :class:`~hsgeo.ConvergenceError` (carrying the result) if the iteration does not
        converge; otherwise return the result with ``converged=False``.
    progress : bool or callable, optional
        Print iteration, cost and λ to stderr (True) or call ``progress(info_dict)``.

    Returns
    -------
    AdjustmentResult
    """
    from hsgeo.adjust.result import AdjustmentResult

    blocks = [blocks] if isinstance(blocks, ResidualBlock) else list(blocks)
    if not blocks:
        raise ObservationError("no residual blocks given: nothing to adjust")
    params = params.copy()
    layout = _Layout(params)
    if layout.n_unknowns == 0:
        raise ObservationError(
            "every parameter is fixed: there is nothing to estimate (free some with "
            "Parameters.free())"
        )
    masks = [np.ones(b.m, dtype=bool) for b in blocks]
    show = _progress_printer(progress)
    history: list[float] = []
    t0 = time.perf_counter()
    total_iter = 0
    rounds = 0
    converged = False
    message = ""
    while True:
        sy = _evaluate(layout, blocks, masks, jacobian=True)
        dof = sy.r.size - layout.n_unknowns
        if dof < 0 or (dof == 0 and sy.n_obs_rows < layout.n_unknowns):
            raise ObservationError(
                f"fewer observations ({sy.r.size} residual components incl. priors) than "
                f"unknowns ({layout.n_unknowns}): add observations, fix parameters or add priors"
            )
        ne = _normal(layout, sy)
        if check_datum and rounds == 0:
            ident = _analyse(layout, ne, rank_rtol)
            if not ident.full_rank:
                raise DatumError(
                    ident.message(), ident.deficient_parameters(), ident.rank, ident.n_unknowns
                )
        lam, nu = lambda0, 2.0
        cost = sy.cost
        history.append(cost)
        converged = False
        for _ in range(max_iter):
            total_iter += 1
            state = layout.get_state()
            while True:
                dc, dp = _step(layout, ne, lam)
                pred = _predicted_decrease(layout, ne, lam, dc, dp)
                layout.apply(dc, dp)
                trial = _evaluate(layout, blocks, masks, jacobian=False)
                actual = cost - trial.cost
                rho = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
                if rho > 0 and np.isfinite(trial.cost):
                    lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                    nu = 2.0
                    break
                layout.set_state(state)
                lam *= nu
                nu *= 2.0
                if lam > 1e16:
                    break
            if lam > 1e16:
                # no step decreases the cost: we are at the minimum to machine precision
                converged = pred <= 1e3 * ftol * max(cost, 1e-300) or cost <= atol * sy.r.size
                message = "no further decrease possible" if converged else (
                    "the damping grew without bound: the cost could not be decreased"
                )
                break
            new_cost = trial.cost
            history.append(new_cost)
            if show:
                show(
                    {
                        "iteration": total_iter,
                        "cost": new_cost,
                        "lambda": lam,
                        "seconds": time.perf_counter() - t0,
                        "rejected": int(sum((~m).sum() for m in masks)),
                    }
                )
            small = (cost - new_cost) <= ftol * cost and pred <= ftol * cost
            cost = new_cost
            sy = _evaluate(layout, blocks, masks, jacobian=True)
            ne = _normal(layout, sy)
            if small or cost <= atol * sy.r.size:
                converged = True
                message = "relative decrease of the cost below ftol" if small else (
                    "cost below atol (noise-free data)"
                )
                break
        else:
            message = f"not converged within max_iter={max_iter} iterations"
        if not converged or reject_k is None or rounds >= max_reject_rounds:
            break
        # -- outlier rejection: whole groups whose whitened residual exceeds reject_k robust σ
        scale = _robust_scale(sy)
        full = _evaluate(layout, blocks, [np.ones(b.m, dtype=bool) for b in blocks], False)
        new_any = False
        off = 0
        for i, b in enumerate(blocks):
            rw = full.r[off : off + b.m] / scale
            off += b.m
            bad = (np.abs(rw) > reject_k).reshape(-1, b.group_size).any(axis=1)
            bad = np.repeat(bad, b.group_size)
            newly = bad & masks[i]
            if newly.any():
                masks[i] = masks[i] & ~bad
                new_any = True
        rounds += 1
        if not new_any:
            break

    result = AdjustmentResult._build(
        layout=layout,
        blocks=blocks,
        masks=masks,
        system=sy,
        normal=ne,
        converged=converged,
        message=message,
        iterations=total_iter,
        history=history,
        seconds=time.perf_counter() - t0,
        reject_rounds=rounds,
    )
    if not converged and raise_on_failure:
        raise ConvergenceError(
            f"the adjustment did not converge: {message} (last cost {history[-1]:.6g}). "
            "Check the initial values, increase max_iter, or look for gross errors; "
            "the last iterate is in the exception's .result.",
            result,
        )
    return result
