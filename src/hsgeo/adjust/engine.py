"""One least-squares engine for every problem in hsgeo.

Gauss–Newton with Levenberg–Marquardt damping on the whitened observation equations
``r_w = (f(x) - l) / σ``, minimising ``½ Σ r_w²`` over the free parameters:

* the Jacobian is assembled sparse from the residual blocks (no dense ``m × n`` matrix);
* priors enter as pseudo-observations ``(x - μ) / σ_prior``;
* per-point unknowns (the ``points=True`` block) are eliminated by the Schur complement:
  with ``N = [[N_cc, W], [Wᵀ, V]]`` and ``V`` block diagonal (one ``p × p`` block per point), the
  reduced system ``S Δc = -(g_c - W V⁻¹ g_p)`` with ``S = N_cc - W V⁻¹ Wᵀ`` is solved densely
  (Cholesky) and the points follow as ``Δp = -V⁻¹ (g_p + Wᵀ Δc)``;
* damping is Marquardt's ``N + λ diag(N)`` with Nielsen's update of λ (the point blocks are
  damped only above ``LAMBDA_POINTS_MIN``, so one reduced matrix per linearisation point serves
  the datum check, the damped retries and the covariance);
* convergence: the decrease the Gauss–Newton step predicts at the current point is below
  ``ftol`` times the cost (the reduced matrix just formed then gives the covariance), or the
  cost is below ``atol`` (noise-free data);
* before the first step the datum is checked: a parameter without observations, a point that is
  not determined, or a rank-deficient reduced normal matrix raises :class:`~hsgeo.DatumError`
  naming the parameters involved;
* optional outlier rejection removes observations whose standardised residual (divided by
  ``√(1 − h)``, ``h`` the leverage on its point) exceeds ``reject_k`` robust standard
  deviations, one observation per point and test: in rounds after convergence, or in every
  iteration from a settled iterate on (``reject_every_iteration``, as 002 §3.4 does);
* from a settled iterate on, the compiled path takes chord steps (the last reduced matrix
  reused) and forms the matrix again at the final iterate;
* Jacobians that are a weighted sum over items of one derivative (``Indexed(..., weights=)``,
  e.g. spline nodes) are kept factored by the compiled path (:mod:`hsgeo.adjust._fast`);
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
from hsgeo.adjust.residuals import Indexed, ResidualBlock
from hsgeo.errors import ConvergenceError, DatumError, InputError, ObservationError
from hsgeo.stats import NMAD_SCALE

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
        #: the point of each row of residual block i (from its Jacobian), for _reject
        self.row_point: dict[int, np.ndarray] = {}

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


class _RowJac:
    """A row-compressed sparse matrix: row ``i`` has entries ``vals[i, s]`` at ``cols[i, s]``.

    ``cols = -1`` marks an empty slot. Optionally each row also has one *factored* group
    (from an :class:`~hsgeo.adjust.Indexed` Jacobian with ``weights``): entries
    ``fw[i, a] * fd[i, j]`` at columns ``fcol[i, a] + j`` (``fcol = -1``: none). See
    :mod:`hsgeo.adjust._fast`.
    """

    def __init__(self, cols: np.ndarray, vals: np.ndarray, n_cols: int, fcol=None, fw=None,
                 fd=None):
        self.cols, self.vals, self.n_cols = cols, vals, n_cols
        M = cols.shape[0]
        if fcol is None:
            fcol = np.full((M, 0), -1, dtype=cols.dtype)
            fw = np.zeros((M, 0))
            fd = np.zeros((M, 0))
        self.fcol, self.fw, self.fd = fcol, fw, fd

    @property
    def arrays(self):
        """``(cols, vals, fcol, fw, fd)`` for the compiled kernels."""
        return self.cols, self.vals, self.fcol, self.fw, self.fd

    @property
    def shape(self):
        return (self.cols.shape[0], self.n_cols)

    def _safe_cols(self):
        # index n_cols (an appended zero) for the empty slots
        return np.where(self.cols >= 0, self.cols, self.n_cols)

    def matvec(self, x: np.ndarray) -> np.ndarray:
        from hsgeo.adjust._fast import matvec

        return matvec(*self.arrays, np.ascontiguousarray(x, dtype=np.float64))

    def rmatvec(self, y: np.ndarray, diag: bool = False):
        """``Jᵀ y`` (and ``diag(JᵀJ)`` with ``diag=True``)."""
        from hsgeo.adjust._fast import rmatvec_diag

        g, d = rmatvec_diag(*self.arrays, np.ascontiguousarray(y, dtype=np.float64),
                            self.n_cols, diag)
        return (g, d) if diag else g

    def tocsr(self) -> sp.csr_matrix:
        M = self.cols.shape[0]
        keep = self.cols >= 0
        rows = np.broadcast_to(np.arange(M)[:, None], self.cols.shape)
        r, c, v = [rows[keep]], [self.cols[keep]], [self.vals[keep]]
        kf = self.fd.shape[1]
        if self.fcol.shape[1] and kf:
            fc = self.fcol[:, :, None] + np.arange(kf)  # (M, q, kf)
            fv = self.fw[:, :, None] * self.fd[:, None, :]
            fk = np.broadcast_to((self.fcol >= 0)[:, :, None], fc.shape)
            r.append(np.broadcast_to(np.arange(M)[:, None, None], fc.shape)[fk])
            c.append(fc[fk])
            v.append(fv[fk])
        return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                             shape=self.shape)


#: Use the compiled row-compressed path (True) or the generic scipy.sparse path (False).
#: Both compute the same normal equations; the tests compare them.
FAST = True

#: Relative cost decrease at which an intermediate outlier-rejection round stops (see adjust).
REJECT_ROUND_FTOL = 1e-4


@dataclass
class _System:
    """The whitened, linearised problem at one point x."""

    r: np.ndarray  # (M,) whitened residuals, observation rows then prior rows
    Jrc: _RowJac | None  # (M, n_c) row-compressed
    pidx: np.ndarray | None  # (M,) point touched by each row (-1: none)
    Jp: np.ndarray | None  # (M, p)
    n_obs_rows: int  # rows that are observations (the rest are priors)

    @property
    def cost(self) -> float:
        return 0.5 * float(self.r @ self.r)

    @property
    def Jc(self) -> sp.csr_matrix:
        """The Jacobian of the non-point unknowns as scipy.sparse (generic path)."""
        return self.Jrc.tocsr()


class _Slots:
    """One block Jacobian's share of the row-compressed matrix, written on request.

    Writing straight into the final ``(M, K)`` arrays avoids intermediate copies of what can be
    tens of millions of entries (GUIDE §9).
    """

    def __init__(self, J, m: int, size: int, name: str, colmap: np.ndarray, rows, w,
                 factored_k: int | None = None):
        self.colmap, self.rows, self.w = colmap, rows, w  # rows: kept rows, or None for all
        self.factored = False
        if isinstance(J, Indexed) and J.factored:
            m_j, q = J.index.shape
            k = J.k
            contiguous = colmap.size and colmap[0] >= 0 and np.all(np.diff(colmap) == 1)
            if (FAST and factored_k in (None, k) and contiguous and m_j == m and size % k == 0
                    and not (J.index.size and int(J.index.max()) >= size // k)):
                # kept factored: one group of q items × k columns per row (see _RowJac)
                self.kind, self.J, self.width, self.qk = "factored", J, 0, (q, k)
                self.factored = True
                return
            J = J.expanded()  # generic path, fixed entries, or a second factored Jacobian
        if isinstance(J, Indexed):
            m_j, q, k = J.d.shape
            if m_j != m:
                raise InputError(f"Jacobian w.r.t. {name!r} has {m_j} rows, residuals have {m}")
            if size % k:
                raise InputError(
                    f"Jacobian w.r.t. {name!r}: item width {k} does not divide {size}")
            if J.index.size and int(J.index.max()) >= size // k:
                raise InputError(f"Jacobian w.r.t. {name!r} indexes past the block's items")
            self.kind, self.J, self.width, self.qk = "indexed", J, q * k, (q, k)
        elif sp.issparse(J):
            c = J.tocsr()
            if c.shape != (m, size):
                raise InputError(
                    f"Jacobian w.r.t. {name!r} has shape {c.shape}, expected {(m, size)}")
            nnz = np.diff(c.indptr)
            K = int(nnz.max()) if m else 0
            slot = np.arange(c.indices.size) - np.repeat(c.indptr[:-1], nnz)
            rr = np.repeat(np.arange(m), nnz)
            cols = np.full((m, K), -1, dtype=np.int64)
            vals = np.zeros((m, K))
            cols[rr, slot] = colmap[c.indices]
            vals[rr, slot] = c.data
            self.kind, self.J, self.width = "dense_slots", (cols, vals), K
        else:
            arr = np.asarray(J, dtype=np.float64)
            if arr.shape != (m, size):
                raise InputError(
                    f"Jacobian w.r.t. {name!r} has shape {arr.shape}, expected {(m, size)}")
            self.kind, self.J, self.width = "dense", arr, size

    def _rows(self) -> np.ndarray:
        return np.arange(self.w.size, dtype=np.int64) if self.rows is None else self.rows

    def fill_factored(self, fcol_dst, fw_dst, fd_dst) -> None:
        from hsgeo.adjust._fast import fill_factored

        q, k = self.qk
        fill_factored(self.J.index, self.J.weights, self.J.d, self._rows(), self.w,
                      int(self.colmap[0]), fcol_dst[:, :q], fw_dst[:, :q], fd_dst[:, :k])

    def fill(self, cols_dst: np.ndarray, vals_dst: np.ndarray) -> None:
        from hsgeo.adjust._fast import fill_dense, fill_indexed

        cm = self.colmap
        if self.kind == "indexed":
            fill_indexed(self.J.index, self.J.d, self._rows(), self.w, cm, cols_dst, vals_dst)
        elif self.kind == "dense":
            fill_dense(self.J, self._rows(), self.w, cm, cols_dst, vals_dst)
        else:
            cols, vals = self.J
            rows = self._rows()
            cols_dst[:] = cols[rows]
            np.multiply(vals[rows], self.w[rows, None], out=vals_dst)
            vals_dst[cols_dst < 0] = 0.0


class _PriorSlots:
    width = 1
    factored = False

    def __init__(self, cols, vals):
        self.cols, self.vals = cols, vals

    def fill(self, cols_dst, vals_dst):
        cols_dst[:, 0] = self.cols
        vals_dst[:, 0] = self.vals


def _evaluate(layout: _Layout, blocks: Sequence[ResidualBlock], masks, jacobian: bool) -> _System:
    values = layout.params.values()
    r_parts, slot_parts, pidx_parts, jp_parts = [], [], [], []
    factored_k = None  # width k of the factored Jacobians (one per row, one k for all)
    offset = 0
    pname = layout.pblock.name if layout.pblock is not None else None
    for ib, (blk, keep) in enumerate(zip(blocks, masks, strict=True)):
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
        all_kept = rows_kept.size == blk.m
        r_parts.append(r * w if all_kept else r.take(rows_kept) * w.take(rows_kept))
        if jacobian:
            pidx = np.full(rows_kept.size, -1, dtype=np.int64)
            jp = np.zeros((rows_kept.size, layout.p))
            blk_slots = []
            for name, J in jac.items():
                b = layout.params[name]
                if name == pname:
                    if isinstance(J, Indexed):
                        J = J.expanded()
                    if not isinstance(J, Indexed) or J.index.shape[1] != 1 or J.k != layout.p:
                        raise InputError(
                            f"the Jacobian w.r.t. the points block {name!r} must be "
                            f"Indexed((m,), (m, {layout.p})): each row touches one point"
                        )
                    pidx, jp = J.index[:, 0], J.d[:, 0, :]
                    layout.row_point[ib] = pidx
                    if all_kept:
                        jp = jp * w[:, None]
                    else:
                        pidx = pidx.take(rows_kept)
                        jp = jp.take(rows_kept, axis=0) * w.take(rows_kept)[:, None]
                    if not layout.pfree.all():
                        jp = jp * layout.pfree[np.maximum(pidx, 0)]
                    if (pidx < 0).any():
                        jp = np.where(pidx[:, None] >= 0, jp, 0.0)
                    continue
                has_f = any(sl.factored for sl in blk_slots)
                sl = _Slots(J, blk.m, b.size, name, layout.colmap[name],
                            None if all_kept else rows_kept, w,
                            factored_k=-1 if has_f else factored_k)
                if sl.factored:
                    factored_k = sl.qk[1]
                blk_slots.append(sl)
            slot_parts.append(blk_slots)
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
            if b.points:
                pt, comp = np.divmod(idx, layout.p)
                jp = np.zeros((idx.size, layout.p))
                jp[np.arange(idx.size), comp] = 1.0 / s
                slot_parts.append([])
                pidx_parts.append(pt)
                jp_parts.append(jp)
            else:
                slot_parts.append([_PriorSlots(layout.colmap[b.name][idx], 1.0 / s)])
                pidx_parts.append(np.full(idx.size, -1, dtype=np.int64))
                jp_parts.append(np.zeros((idx.size, layout.p)))
        offset += idx.size

    r_all = np.concatenate(r_parts) if r_parts else np.zeros(0)
    if not jacobian:
        return _System(r_all, None, None, None, n_obs_rows)
    M = offset
    # one (M, K) row-compressed matrix: each part's slots side by side, padded to the widest
    K = max([sum(sl.width for sl in part) for part in slot_parts] + [1])
    itype = np.int32 if layout.n_c < 2**31 else np.int64
    cols_all = np.empty((M, K), dtype=itype)
    vals_all = np.empty((M, K))
    Q = max([sl.qk[0] for part in slot_parts for sl in part if sl.factored] + [0])
    Kf = factored_k if Q else 0
    fcol = np.full((M, Q), -1, dtype=itype)
    fw = np.zeros((M, Q))
    fd = np.zeros((M, Kf))
    row0 = 0
    for part, pi in zip(slot_parts, pidx_parts, strict=True):
        n = pi.size
        k0 = 0
        for sl in part:
            if sl.factored:
                sl.fill_factored(fcol[row0 : row0 + n], fw[row0 : row0 + n], fd[row0 : row0 + n])
                continue
            sl.fill(cols_all[row0 : row0 + n, k0 : k0 + sl.width],
                    vals_all[row0 : row0 + n, k0 : k0 + sl.width])
            k0 += sl.width
        if k0 < K:  # padding
            cols_all[row0 : row0 + n, k0:] = -1
            vals_all[row0 : row0 + n, k0:] = 0.0
        row0 += n
    pidx = np.concatenate(pidx_parts) if pidx_parts else np.full(M, -1)
    Jp = np.concatenate(jp_parts) if jp_parts else np.zeros((M, layout.p))
    Jrc = _RowJac(cols_all, vals_all, layout.n_c, *((fcol, fw, fd) if Q else ()))
    return _System(r_all, Jrc, pidx, Jp, n_obs_rows)


# ----------------------------------------------------------------------------------------------
# Normal equations and the Schur-reduced step
# ----------------------------------------------------------------------------------------------
@dataclass
class _Normal:
    _Ncc: np.ndarray | None  # (n_c, n_c) dense (on the compiled path: built on request)
    gc: np.ndarray  # (n_c,)
    V: np.ndarray | None  # (n_pts, p, p)
    gp: np.ndarray | None  # (n_pts, p)
    _W: sp.csr_matrix | None = None  # (n_c, n_pts * p), generic path (built on request)
    sy: _System | None = None  # the rows, for the compiled path
    order: np.ndarray | None = None  # rows sorted by point
    ptr: np.ndarray | None = None  # rows of point i: order[ptr[i]:ptr[i + 1]]
    n_pts: int = 0
    pt_order: np.ndarray | None = None  # order in which the kernel visits the points
    Ncc_free: np.ndarray | None = None  # J_cᵀ J_c of the rows without a point (compiled path)
    diag_cc: np.ndarray | None = None  # diag(N_cc)
    reduced0: tuple | None = None  # (S, rhs, V⁻¹) with undamped point blocks, see _reduced
    S_chord: np.ndarray | None = None  # a reduced matrix formed at an earlier point, see adjust

    @property
    def compiled_schur(self) -> bool:
        """The reduced matrix is formed point by point by the compiled kernel."""
        return self.V is not None and self.sy is not None and self._W is None and self._Ncc is None

    def exact(self) -> None:
        """Drop a chord matrix: the next reduced system is formed at this point."""
        if self.S_chord is not None:
            self.S_chord = None
            self.reduced0 = None

    @property
    def Ncc(self) -> np.ndarray:
        """``J_cᵀ J_c`` (dense)."""
        if self._Ncc is None:
            from hsgeo.adjust._fast import normal_cc

            self._Ncc = normal_cc(self.sy.Jrc.arrays, self.sy.Jrc.n_cols)
        return self._Ncc

    @property
    def W(self) -> sp.csr_matrix | None:
        """``J_cᵀ J_p`` as scipy.sparse (built on first use on the compiled path)."""
        if self._W is None and self.V is not None:
            self._W = _W_sparse(self.sy, self.n_pts)
        return self._W

    def Wt_dot(self, dc: np.ndarray) -> np.ndarray:
        """``Wᵀ dc`` as ``(n_pts, p)``."""
        if self._W is not None or self.sy is None:
            return (self.W.T @ dc).reshape(self.n_pts, -1)
        from hsgeo.adjust._fast import scatter_points

        return scatter_points(self.sy.Jp, self.sy.pidx, self.sy.Jrc.matvec(dc), self.n_pts)

    def W_dot(self, y: np.ndarray) -> np.ndarray:
        """``W y`` for ``y`` of shape ``(n_pts, p)``."""
        if self._W is not None or self.sy is None:
            return self.W @ y.ravel()
        from hsgeo.adjust._fast import point_rows_dot

        return self.sy.Jrc.rmatvec(point_rows_dot(self.sy.Jp, self.sy.pidx,
                                                  np.ascontiguousarray(y)))


def _W_sparse(sy: _System, n_pts: int) -> sp.csr_matrix:
    p = sy.Jp.shape[1]
    rows = np.flatnonzero(sy.pidx >= 0)
    pi = sy.pidx[rows]
    jp = sy.Jp[rows]
    Jp_sp = sp.csr_matrix(
        (jp.ravel(), (np.repeat(rows, p), (pi[:, None] * p + np.arange(p)).ravel())),
        shape=(sy.r.size, n_pts * p),
    )
    return (sy.Jc.T @ Jp_sp).tocsr()


#: The last sparsity structure seen by _normal and its processing orders (one entry).
_ORDER_CACHE: dict = {}


def _normal(layout: _Layout, sy: _System) -> _Normal:
    order = ptr = pt_order = None
    if FAST:
        from hsgeo.adjust._fast import locality_orders, normal_cc

        key = _ORDER_CACHE.get("key")
        if (key is not None and key[0] == layout.n_c and key[1] == layout.n_pts
                and key[3] == sy.Jrc.cols.shape and np.array_equal(key[2], sy.pidx)):
            # same rows and points as the previous iteration: reuse the processing orders
            # (order and ptr depend only on pidx; row_order is a permutation of the rows that
            # only affects speed, so a changed column pattern cannot make it wrong)
            order, ptr, row_order, pt_order = _ORDER_CACHE["value"]
        else:
            if layout.pblock is not None:
                pi_all = sy.pidx
                rows_p = np.flatnonzero(pi_all >= 0)
                order = rows_p[np.argsort(pi_all[rows_p], kind="stable")].astype(np.int64)
                ptr = np.concatenate(
                    [[0], np.cumsum(np.bincount(pi_all[rows_p], minlength=layout.n_pts))]
                ).astype(np.int64)
            # the rows without a point (priors) form N_cc directly; the others go through the
            # Schur kernel point by point
            rows_np = np.flatnonzero(sy.pidx < 0) if layout.pblock is not None else None
            row_order, pt_order = locality_orders(sy.Jrc, layout.n_c, order, ptr, rows_np)
            _ORDER_CACHE["key"] = (layout.n_c, layout.n_pts, sy.pidx.copy(), sy.Jrc.cols.shape)
            _ORDER_CACHE["value"] = (order, ptr, row_order, pt_order)
        Jrc = sy.Jrc
        gc, diag_cc = Jrc.rmatvec(sy.r, diag=True)
        if layout.pblock is None:
            Ncc = normal_cc(Jrc.arrays, layout.n_c, row_order)
            return _Normal(Ncc, gc, None, None, diag_cc=diag_cc)
        Ncc_free = normal_cc(Jrc.arrays, layout.n_c, row_order)
        Ncc = None
    else:
        Jc = sy.Jc
        Ncc = (Jc.T @ Jc).toarray() if layout.n_c else np.zeros((0, 0))
        gc = Jc.T @ sy.r
    if layout.pblock is None:
        return _Normal(Ncc, gc, None, None)
    n_pts, p = layout.n_pts, layout.p
    if FAST:
        from hsgeo.adjust._fast import point_normals

        V, gp = point_normals(sy.pidx, sy.Jp, sy.r, n_pts)
    else:
        rows = np.flatnonzero(sy.pidx >= 0)
        pi = sy.pidx[rows]
        jp = sy.Jp[rows]
        # V_i = Σ_rows jpᵀ jp, g_p,i = Σ jpᵀ r  (sparse aggregation instead of a Python loop)
        agg = sp.csr_matrix((np.ones(rows.size), (pi, np.arange(rows.size))),
                            shape=(n_pts, rows.size))
        V = (agg @ (jp[:, :, None] * jp[:, None, :]).reshape(rows.size, p * p)).reshape(
            n_pts, p, p)
        gp = agg @ (jp * sy.r[rows, None])
    # fixed point entries: unit diagonal, zero gradient -> zero update
    # (their Jacobian columns were zeroed in _evaluate, so V has zero rows/columns there)
    fixed = ~layout.pfree
    ii = np.nonzero(fixed)
    V[ii[0], ii[1], ii[1]] = 1.0
    gp[fixed] = 0.0
    if not FAST:
        return _Normal(Ncc, gc, V, gp, _W_sparse(sy, n_pts), n_pts=n_pts)
    return _Normal(Ncc, gc, V, gp, None, sy, order, ptr, n_pts, pt_order, Ncc_free, diag_cc)


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


def _inv_blocks(Vd: np.ndarray) -> np.ndarray:
    if FAST and Vd.ndim == 3 and Vd.shape[1:] == (3, 3):
        from hsgeo.adjust._fast import inv3

        out, ok = inv3(np.ascontiguousarray(Vd))
        if not ok.all():
            out[~ok] = np.linalg.pinv(Vd[~ok])
        return out
    try:
        return np.linalg.inv(Vd)
    except np.linalg.LinAlgError:
        # some blocks are singular (e.g. a point whose observations were all rejected):
        # pseudo-inverse for those only
        d = np.abs(np.linalg.det(Vd))
        scale = np.max(np.abs(Vd), axis=(1, 2)) ** Vd.shape[-1]
        bad = ~(d > 1e-12 * scale)
        out = np.empty_like(Vd)
        out[~bad] = np.linalg.inv(Vd[~bad])
        out[bad] = np.linalg.pinv(Vd[bad])
        return out


def _block_diag(Vinv: np.ndarray) -> sp.csr_matrix:
    n, p, _ = Vinv.shape
    rows = np.repeat(np.arange(n * p), p)
    cols = (np.arange(n)[:, None, None] * p + np.zeros((1, p, 1), dtype=int) + np.arange(p)).ravel()
    return sp.csr_matrix((Vinv.ravel(), (rows, cols)), shape=(n * p, n * p))


#: Below this damping λ the point blocks are not damped (only the reduced system is): the
#: reduced matrix of the undamped points is then formed once per linearisation point and
#: shared by the datum check, every damped trial step and the covariance (see _reduced).
LAMBDA_POINTS_MIN = 1e-4


def _lambda_points(lam: float) -> float:
    return lam if lam > LAMBDA_POINTS_MIN else 0.0


def _reduced(layout: _Layout, ne: _Normal, lam: float):
    """S, rhs and the pieces for back-substitution, at damping λ.

    Marquardt damping ``λ diag(N)`` is added to the reduced system; the points' blocks ``V``
    are damped too only when ``λ > LAMBDA_POINTS_MIN`` (at smaller λ, damping a 3 × 3 point
    block by a factor ``1 + λ`` changes nothing but the cost of re-forming ``S``).
    """
    rhs = ne.gc.copy()
    lam_p = _lambda_points(lam)
    if ne.compiled_schur:
        # compiled path: S = N_cc − Σ W_i V_i⁻¹ W_iᵀ accumulated point by point from the rows
        # grouped by point; neither W nor the full N_cc is formed
        from hsgeo.adjust._fast import reduced_points

        cached = ne.reduced0 if lam_p == 0.0 else None
        if cached is None:
            Vinv = _inv_blocks(_damped(ne.V, lam_p))
            sy = ne.sy
            if ne.S_chord is not None and lam_p == 0.0:
                S0 = ne.S_chord  # a chord step: the matrix of an earlier point (see adjust)
            else:
                S0 = ne.Ncc_free + reduced_points(sy.Jrc.arrays, sy.Jp, ne.order, ne.ptr,
                                                  Vinv, layout.n_c, ne.pt_order)
            r0 = rhs - ne.W_dot(np.einsum("nij,nj->ni", Vinv, ne.gp)) if layout.n_c else rhs
            if lam_p == 0.0:  # keep the undamped one (datum check, steps, covariance)
                ne.reduced0 = (S0, r0, Vinv)
        else:
            S0, r0, Vinv = cached
        S = S0.copy()
        rhs = r0.copy()
        if lam != 0.0 and layout.n_c:
            d = ne.diag_cc
            floor = 1e-12 * max(float(np.max(d)), 1e-300)
            S[np.diag_indices_from(S)] += lam * np.maximum(d, floor)
        return S, rhs, Vinv, None
    S = _damped(ne.Ncc, lam)
    if ne.V is None:
        return S, rhs, None, None
    Vinv = _inv_blocks(_damped(ne.V, lam_p))
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
        b = ne.gp + ne.Wt_dot(dc)
        dp = -np.einsum("nij,nj->ni", Vinv, b)
    return dc, dp


def _predicted_decrease(layout, ne: _Normal, lam, dc, dp) -> float:
    """L(0) - L(h) = ½ hᵀ(λ D h - g) for the damped Gauss–Newton step h (Madsen et al. eq. 3.14)."""
    if not layout.n_c:
        Dc = np.zeros(0)
    else:
        Dc = np.maximum(ne.diag_cc if ne.diag_cc is not None else np.diag(ne.Ncc), 0.0)
    pred = 0.5 * float(dc @ (lam * Dc * dc - ne.gc))
    if dp is not None:
        Dp = np.maximum(np.diagonal(ne.V, axis1=1, axis2=2), 0.0)
        pred += 0.5 * float(np.sum(dp * (_lambda_points(lam) * Dp * dp - ne.gp)))
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
        # unit diagonal: λ_max ≤ p and λ_min ≥ det / λ_max^(p−1), so det ≥ rtol·p^p proves
        # λ_min ≥ rtol·λ_max; only the other blocks need their eigenvalues
        p = Vs.shape[-1]
        bad = dz.any(axis=1)
        doubt = np.flatnonzero(~(np.linalg.det(Vs) >= rtol * p**p) & ~bad)
        if doubt.size:
            ev = np.linalg.eigvalsh(Vs[doubt])
            bad[doubt] = ev[:, 0] < rtol * np.maximum(ev[:, -1], 1e-300)
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


#: An iterate is *settled* (near its minimum) when the last step decreased the cost by less than
#: this share of it, or when its actual decrease matched the predicted one to within this share
#: of the new cost. The mismatch ``|actual − predicted|`` is the part of the decrease the
#: linearised model did not explain; a Gauss–Newton step from the new point removes a decrease
#: of that order (its gradient comes from the same second-order terms), so a small mismatch
#: shows the new point near its minimum one iteration before the decrease itself does. From a
#: settled iterate on, each-iteration rejection tests the residuals and the steps are chord
#: steps (see :func:`adjust`).
SETTLED = 1e-2


def _settled(actual: float, pred: float, new_cost: float) -> bool:
    return max(min(actual, abs(actual - pred)), 0.0) <= SETTLED * new_cost


#: Chord steps end when their predicted decrease falls below this share of ``ftol · cost``:
#: they converge linearly, so the margin leaves the final iterate as close to the minimum as
#: the quadratically converging Gauss–Newton steps would.
CHORD_END = 1e-3


def _leverage(ne: _Normal) -> np.ndarray | None:
    """Each row's leverage on its point, ``h = j_pᵀ V⁻¹ j_p`` (0 for rows without a point)."""
    if ne.V is None:
        return None
    from hsgeo.adjust._fast import point_leverage

    Vinv = ne.reduced0[2] if ne.reduced0 is not None else _inv_blocks(ne.V)
    return point_leverage(ne.sy.Jp, ne.sy.pidx, np.ascontiguousarray(Vinv))


def _reject(blocks, masks, sy: _System, reject_k: float, row_point=None,
            leverage=None) -> bool:
    """Reject the kept groups whose residual in ``sy`` exceeds ``reject_k`` robust σ.

    With ``leverage`` (of each row of ``sy`` on its point, see :func:`_leverage`) the residuals
    are standardised first, ``r / √(1 − h)`` (Baarda's w-test with the points' share of the
    redundancy): a ray of a point seen three times has a residual shrunk by its point. Of one
    point's groups only the one with the largest is rejected in a test: a gross error drags
    its point, so the point's other observations show large residuals too (swamping); they
    are tested again at the next iterate, without it. ``row_point[i]`` is the point of each
    row of block ``i`` (blocks without points: every group on its own). ``masks`` is updated
    in place; returns True if any group was rejected.
    """
    r = np.abs(sy.r[: sy.n_obs_rows])
    if leverage is not None:
        r = r / np.sqrt(np.maximum(1.0 - leverage[: sy.n_obs_rows], 1e-2))
    r /= max(NMAD_SCALE * float(np.median(r)), 1e-300) if r.size else 1.0  # robust σ about 0
    off = 0
    new_any = False
    for i, b in enumerate(blocks):
        g = b.group_size
        kept = np.flatnonzero(masks[i])
        score = np.zeros(b.m)
        score[kept] = r[off : off + kept.size]
        off += kept.size
        score = score.reshape(-1, g).max(axis=1)  # per group
        cand = np.flatnonzero(score > reject_k)
        if not cand.size:
            continue
        if row_point is not None and i in row_point:
            pt = row_point[i][cand * g]
            on = pt >= 0
            c, pc = cand[on], pt[on]
            o = np.lexsort((-score[c], pc))  # by point, the largest residual first
            c, pc = c[o], pc[o]
            first = np.ones(c.size, dtype=bool)
            first[1:] = pc[1:] != pc[:-1]
            cand = np.concatenate([cand[~on], c[first]])
        bad = np.zeros(b.m // g, dtype=bool)
        bad[cand] = True
        masks[i] &= ~np.repeat(bad, g)
        new_any = True
    return new_any


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
    reject_every_iteration: bool = False,
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
        Reject observations whose standardised residual (whitened, and divided by
        ``√(1 − h)`` with ``h`` the observation's leverage on its point) exceeds ``reject_k``
        robust σ (NMAD of those residuals) after convergence, and adjust again; repeated until
        none is rejected or ``max_reject_rounds``. A whole group (e.g. x and y of one
        observation) is rejected together, and of one point's groups only the largest per test
        (see ``_reject``).
    reject_every_iteration : bool
        With ``reject_k``: test the residuals after every iteration (once the iterate has
        settled, see ``SETTLED``) instead of in rounds after convergence, as 002 §3.4 does
        ("observation outliers are identified and rejected in each iteration"); the adjustment
        has converged when the predicted decrease is below ``ftol`` and the last test rejected
        nothing.
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

    Notes
    -----
    Levenberg–Marquardt on the Schur-reduced normal equations (the points eliminated). When
    the reduced matrix is formed point by point by the compiled kernel (the costly part of an
    iteration), the steps after a settled iterate (``SETTLED``) are *chord steps* (C. T.
    Kelley, *Iterative Methods for Linear and Nonlinear Equations*, SIAM 1995, ch. 5): they
    reuse the last reduced matrix formed, with the gradient and the points' blocks of the
    current iterate, so they still descend to the same minimum, linearly. Where they have
    converged (to ``CHORD_END · ftol``), or when one fails to decrease the cost, the matrix is
    formed again; convergence is only declared with the matrix of the final iterate, which
    also gives the covariance.
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
    each = reject_k is not None and reject_every_iteration
    # rounds mode: while outliers are still being rejected, a round only needs to get close to
    # its minimum (the residuals that decide the rejection do not change at 1e-4 relative
    # cost); once a rejection pass finds nothing new, the iteration continues to ``ftol``
    final = reject_k is None or each
    while True:
        tol = ftol if final else max(ftol, REJECT_ROUND_FTOL)
        sy = ne = None  # free the previous round's Jacobian first (peak memory)
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
        rejecting = False  # each-iteration mode: rejection has started
        tested = False  # each-iteration mode: the current point passed the rejection test
        n_iter = 0
        while True:
            if cost <= atol * sy.r.size:
                converged, message = True, "cost below atol (noise-free data)"
                break
            dc, dp = _step(layout, ne, lam)
            pred = _predicted_decrease(layout, ne, lam, dc, dp)
            chord_done = ne.S_chord is not None and pred <= CHORD_END * tol * cost
            if lam <= LAMBDA_POINTS_MIN and chord_done:
                # the chord steps have converged (they converge linearly, hence the margin):
                # form the reduced matrix here to confirm it, and for the covariance
                ne.exact()
                dc, dp = _step(layout, ne, lam)
                pred = _predicted_decrease(layout, ne, lam, dc, dp)
            if lam <= LAMBDA_POINTS_MIN and pred <= tol * cost and ne.S_chord is None:
                if each and not tested:
                    # converged before any rejection test (e.g. at the initial values)
                    if _reject(blocks, masks, sy, reject_k, layout.row_point,
                               _leverage(ne)):
                        break  # adjust again with the new masks (next pass of the outer loop)
                    tested = True
                # the Gauss–Newton step would decrease the cost by less than ftol: this is the
                # minimum, and the reduced system just formed gives its covariance
                converged, message = True, "predicted decrease of the cost below ftol"
                break
            if n_iter >= max_iter:
                message = f"not converged within max_iter={max_iter} iterations"
                break
            n_iter += 1
            total_iter += 1
            state = layout.get_state()
            while True:
                layout.apply(dc, dp)
                trial = _evaluate(layout, blocks, masks, jacobian=False)
                actual = cost - trial.cost
                rho = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
                if rho > 0 and np.isfinite(trial.cost):
                    lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                    nu = 2.0
                    break
                layout.set_state(state)
                if ne.S_chord is not None:
                    ne.exact()  # the chord step failed: retry with the matrix of this point
                else:
                    lam *= nu
                    nu *= 2.0
                    if lam > 1e16:
                        break
                dc, dp = _step(layout, ne, lam)
                pred = _predicted_decrease(layout, ne, lam, dc, dp)
            if lam > 1e16:
                # no step decreases the cost: we are at the minimum to machine precision
                converged = pred <= 1e3 * tol * max(cost, 1e-300) or cost <= atol * sy.r.size
                message = "no further decrease possible" if converged else (
                    "the damping grew without bound: the cost could not be decreased"
                )
                break
            new_cost = trial.cost
            history.append(new_cost)
            tested = False
            settled = _settled(actual, pred, new_cost)
            if each and (rejecting or settled):
                # 002 §3.4: outliers are rejected in each iteration, on the residuals at the
                # new point, from the first settled iterate (SETTLED):
                # before that, residuals reflect the initial values, not gross errors
                rejecting = True
                tested = not _reject(blocks, masks, trial, reject_k, layout.row_point,
                                     _leverage(ne))
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
            # chord steps (Kelley 1995, ch. 5): from a settled iterate on, the reduced matrix
            # barely changes, so the next steps reuse the last one formed (the gradient and
            # the points' blocks are always those of the current point); it is formed again
            # where the convergence test passes, or when a chord step fails
            chord = (ne.reduced0[0] if settled and ne.compiled_schur and ne.reduced0 is not None
                     else None)
            sy = ne = trial = None  # free the old Jacobian before forming the new one
            sy = _evaluate(layout, blocks, masks, jacobian=True)
            ne = _normal(layout, sy)
            if chord is not None and ne.compiled_schur:
                ne.S_chord = chord
            cost = sy.cost  # (lower than new_cost when observations were just rejected)
        if not converged:
            if each and not message:
                rounds += 1  # a rejection at convergence: adjust again
                continue
            break
        if final:
            break
        if rounds >= max_reject_rounds:
            final = True
            continue
        # -- outlier rejection round (see _reject)
        new_any = _reject(blocks, masks, sy, reject_k, layout.row_point, _leverage(ne))
        rounds += 1
        if not new_any:
            if tol <= ftol:
                break
            final = True

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
