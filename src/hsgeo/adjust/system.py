"""The linearised, whitened system at one point: parameter layout and row-compressed Jacobian.

:class:`_Layout` maps the free entries of the non-point parameter blocks to the columns of the
reduced system (the points block is kept apart, see :mod:`hsgeo.adjust.schur`).
:func:`_evaluate` evaluates the residual blocks and, on request, assembles the whitened Jacobian
as a row-compressed matrix (:class:`_RowJac`): observation rows first, then the priors as
pseudo-observations ``(x − μ) / σ_prior``. Jacobians that are a weighted sum over items of one
derivative (``Indexed(..., weights=)``, e.g. spline nodes) are kept factored on the compiled
path (:mod:`hsgeo.adjust._fast`).
"""

from __future__ import annotations

import ctypes
import functools
import mmap
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hsgeo.adjust.parameters import Parameters
from hsgeo.adjust.residuals import Indexed, ResidualBlock
from hsgeo.errors import InputError

__all__: list[str] = []


class _Clock:
    """Seconds spent in each phase of one adjustment (``AdjustmentResult.seconds_split``).

    ``t = clock.add("model", t)`` adds the seconds since ``t`` to ``"model"`` and returns now.
    """

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def add(self, key: str, t0: float) -> float:
        now = time.perf_counter()
        self.seconds[key] = self.seconds.get(key, 0.0) + (now - t0)
        return now


class _Layout:
    """Columns of the reduced system: one per free non-point entry, a tied entry sharing the
    column of its target (:meth:`Parameters.tie`).
    """

    def __init__(self, params: Parameters):
        self.params = params
        self.cblocks = [b for b in params.blocks() if not b.points]
        self.colmap: dict[str, np.ndarray] = {}
        ties = params.ties
        tied = {}  # block name → flat indices of its tied entries
        for (name, i), _ in ties.items():
            b = params[name]
            if not b.free.ravel()[i]:
                raise InputError(f"{b.labels()[i]} is tied and fixed: fix its target instead")
            if np.isfinite(b.prior_sigma.ravel()[i]):
                raise InputError(
                    f"{b.labels()[i]} is tied and has a prior: put the prior on its target"
                )
            tied.setdefault(name, []).append(i)
        n = 0
        for b in self.cblocks:
            free = b.free.ravel()
            if b.name in tied:
                free = free.copy()
                free[tied[b.name]] = False
            cm = np.full(b.size, -1, dtype=np.int64)
            cm[free] = np.arange(n, n + free.sum())
            n += int(free.sum())
            self.colmap[b.name] = cm
        for (name, i), (tname, j) in ties.items():
            self.colmap[name][i] = self.colmap[tname][j]  # (-1: the target is fixed)
        #: blocks with a tied entry or a tie target: their Jacobians are not kept factored,
        #: and rows with two entries in one column are merged (see _merge_tied_columns)
        self.tie_blocks = {name for name, _ in ties} | {name for name, _ in ties.values()}
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

    def __init__(
        self, cols: np.ndarray, vals: np.ndarray, n_cols: int, fcol=None, fw=None, fd=None
    ):
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

    def matvec(self, x: np.ndarray) -> np.ndarray:
        from hsgeo.adjust._fast import matvec

        return matvec(*self.arrays, np.ascontiguousarray(x, dtype=np.float64))

    def rmatvec(self, y: np.ndarray, diag: bool = False):
        """``Jᵀ y`` (and ``diag(JᵀJ)`` with ``diag=True``)."""
        from hsgeo.adjust._fast import rmatvec_diag

        g, d = rmatvec_diag(
            *self.arrays, np.ascontiguousarray(y, dtype=np.float64), self.n_cols, diag
        )
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
        return sp.csr_matrix(
            (np.concatenate(v), (np.concatenate(r), np.concatenate(c))), shape=self.shape
        )


#: Use the compiled row-compressed path (True) or the generic scipy.sparse path (False).
@dataclass
class _System:
    """The whitened, linearised problem at one point x."""

    r: np.ndarray  # (M,) whitened residuals, observation rows then prior rows
    Jrc: _RowJac | None  # (M, n_c) row-compressed
    pidx: np.ndarray | None  # (M,) point touched by each row (-1: none)
    Jp: np.ndarray | None  # (M, p)
    n_obs_rows: int  # rows that are observations (the rest are priors)
    #: under a robust loss (see :mod:`hsgeo.adjust.loss`): its scale per block index, and,
    #: at a linearisation (rows scaled by √ρ′), the robust cost ½ Σ ρ (None: ½ ‖r‖²)
    loss_c: dict | None = None
    robust_cost: float | None = None
    #: ``(row0, row1, g, d)`` of rows whose gradient ``Jᵀ r`` and diagonal ``diag(JᵀJ)`` of
    #: the non-point unknowns the fused path accumulated already (see :meth:`gradient_diag`)
    gd_parts: list | None = None
    #: at a linearisation: each block's residuals of every row (its units, the rows left out
    #: included) and the parameter values they were evaluated at (see ``residuals_at``)
    raw: list | None = None
    values_at: list | None = None

    def residuals_at(self, state: list) -> list | None:
        """Each block's residuals of every row if this linearisation was evaluated at the
        parameter values ``state`` (:meth:`_Layout.get_state`), else None.
        """
        if self.raw is None or self.values_at is None or len(state) != len(self.values_at):
            return None
        if all(np.array_equal(a, b) for a, b in zip(self.values_at, state, strict=True)):
            return self.raw
        return None

    def gradient_diag(self) -> tuple[np.ndarray, np.ndarray]:
        """``(J_cᵀ r, diag(J_cᵀ J_c))`` (compiled path): the fused parts' sums, the other rows
        by one pass over them.
        """
        if not self.gd_parts:
            return self.Jrc.rmatvec(self.r, diag=True)
        from hsgeo.adjust._fast import rmatvec_diag

        n_c = self.Jrc.n_cols
        g, d = np.zeros(n_c), np.zeros(n_c)
        row = 0
        spans = sorted(self.gd_parts, key=lambda x: x[0])
        for r0, r1, gp, dp in [*spans, (self.r.size, self.r.size, None, None)]:
            if r0 > row:  # rows between the fused parts
                arr = [a[row:r0] for a in self.Jrc.arrays]
                gr, dr = rmatvec_diag(*arr, np.ascontiguousarray(self.r[row:r0]), n_c, True)
                g += gr
                d += dr
            if gp is not None:
                g += gp
                d += dp
            row = r1
        return g, d

    @property
    def cost(self) -> float:
        if self.robust_cost is not None:
            return self.robust_cost
        with np.errstate(over="ignore"):  # finite residuals too large to square: cost inf
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

    def __init__(
        self,
        J,
        m: int,
        size: int,
        name: str,
        colmap: np.ndarray,
        rows,
        w,
        factored_k: int | None = None,
        compiled: bool = True,
    ):
        self.colmap, self.rows, self.w = colmap, rows, w  # rows: kept rows, or None for all
        self.factored = False
        if isinstance(J, Indexed) and J.factored:
            m_j, q = J.index.shape
            k = J.k
            contiguous = colmap.size and colmap[0] >= 0 and np.all(np.diff(colmap) == 1)
            if (
                compiled
                and factored_k in (None, k)
                and contiguous
                and m_j == m
                and size % k == 0
                and not (J.index.size and int(J.index.max()) >= size // k)
            ):
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
                raise InputError(f"Jacobian w.r.t. {name!r}: item width {k} does not divide {size}")
            if J.index.size and int(J.index.max()) >= size // k:
                raise InputError(f"Jacobian w.r.t. {name!r} indexes past the block's items")
            self.kind, self.J, self.width, self.qk = "indexed", J, q * k, (q, k)
        elif sp.issparse(J):
            c = J.tocsr()
            if c.shape != (m, size):
                raise InputError(
                    f"Jacobian w.r.t. {name!r} has shape {c.shape}, expected {(m, size)}"
                )
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
                    f"Jacobian w.r.t. {name!r} has shape {arr.shape}, expected {(m, size)}"
                )
            self.kind, self.J, self.width = "dense", arr, size

    def _rows(self) -> np.ndarray:
        return np.arange(self.w.size, dtype=np.int64) if self.rows is None else self.rows

    def fill_factored(self, fcol_dst, fw_dst, fd_dst) -> None:
        from hsgeo.adjust._fast import fill_factored

        q, k = self.qk
        fill_factored(
            self.J.index,
            self.J.weights,
            self.J.d,
            self._rows(),
            self.w,
            int(self.colmap[0]),
            fcol_dst[:, :q],
            fw_dst[:, :q],
            fd_dst[:, :k],
        )

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


class _NonFinite(InputError):
    """A residual block returned non-finite residuals (at a trial step: a refused step)."""


def _block_residuals(blk: ResidualBlock, values, jacobian: bool, trial: bool = False):
    """One block's residuals (checked: shape and finite) and Jacobians (``trial``, without
    them: :meth:`ResidualBlock.trial_residuals`).
    """
    if trial and not jacobian:
        r, jac = blk.trial_residuals(values), None
    else:
        r, jac = blk.evaluate(values, jacobian)
    r = np.asarray(r, dtype=np.float64)
    if r.shape != (blk.m,):
        raise InputError(
            f"residual block {blk.name!r} returned {r.shape} residuals, expected ({blk.m},)"
        )
    if not np.all(np.isfinite(r)):
        bad = np.flatnonzero(~np.isfinite(r))[:5].tolist()
        raise _NonFinite(
            f"residual block {blk.name!r} produced non-finite residuals at rows {bad}: "
            "check the observations for NaN, or the initial values (a point behind the "
            "camera, a zero depth)"
        )
    return r, jac


def _point_jacobian(layout: _Layout, ib: int, name: str, J, w, rows_kept, all_kept: bool):
    """The whitened Jacobian w.r.t. the points block, one point per row: ``(pidx, jp)``."""
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
    return pidx, jp


def _prior_rows(layout: _Layout, jacobian: bool, r_parts, slot_parts, pidx_parts, jp_parts):
    """Priors as pseudo-observations (x - μ) / σ, appended to the parts; returns their count."""
    n = 0
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
        n += idx.size
    return n


class _Buffers:
    """The arrays of the row-compressed Jacobian, kept by one solve from one linearisation to
    the next and written again (the solver drops each system before it forms the next).

    A fresh allocation per linearisation relies on the allocator to put the new arrays where
    the old ones were: when it does not (a small array left between them), the process grows
    by another Jacobian's worth of new memory, whose first touch is system time (1×, 2 threads:
    4,000 more faults, 0.56 s, in the second linearisation). Fewer rows (after a rejection)
    take the first rows of the arrays kept (contiguous).
    """

    def __init__(self) -> None:
        self.arrays: dict[str, np.ndarray] = {}
        #: what a fused part wrote into the arrays last (see _fused._FusedPart.fill)
        self.memo: dict = {}

    def empty(self, name: str, shape: tuple, dtype=np.float64) -> np.ndarray:
        a = self.arrays.get(name)
        if a is None or a.dtype != dtype or a.shape[1:] != shape[1:] or a.shape[0] < shape[0]:
            self.arrays.pop(name, None)  # (its memory is free for the new one)
            a = self.arrays[name] = _small_pages_empty(shape, dtype)
        return a[: shape[0]]


#: Arrays from this size on are advised small pages by :func:`_small_pages_empty` (numpy
#: advises huge pages from 4 MiB on).
_SMALL_PAGES_MIN_BYTES = 4 << 20
_PAGE = 4096


@functools.cache
def _madvise():
    """The C library's ``madvise`` and ``MADV_NOHUGEPAGE`` (None where there is none)."""
    advice = getattr(mmap, "MADV_NOHUGEPAGE", None)
    if advice is None or not sys.platform.startswith("linux"):
        return None
    try:
        fn = ctypes.CDLL(None, use_errno=True).madvise
    except (OSError, AttributeError):  # pragma: no cover - a C library without it
        return None
    fn.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int)
    fn.restype = ctypes.c_int
    return fn, advice


def _small_pages_empty(shape: tuple, dtype=np.float64) -> np.ndarray:
    """``np.empty(shape, dtype)``, its whole pages advised ``MADV_NOHUGEPAGE`` before their
    first touch where the platform has it (Linux) and the array has
    :data:`_SMALL_PAGES_MIN_BYTES` or more.

    numpy advises huge pages for its large arrays. On a virtual machine the first touch of a
    huge page the guest has not used lately costs the host's backing of 2 MiB, and the
    Jacobian's arrays are touched first in the first linearisation. Measured on a 2-core
    virtual machine, the first solve of a process, one thread, the Makefile's GLIBC_TUNABLES
    (bench/results/pushbroom_first_touch.json): at the paper's pushbroom size 3.45 CPU-s with
    the advice, 0.24 of them system seconds, against 3.77 and 0.58 with numpy's huge pages (3
    runs each); at 10× the paper 40.9 and 3.2 against 43.6 and 6.6 (one run each). A later
    solve in the same process reuses the memory either way (3.27 and 3.26 CPU-s at 1×); the
    user seconds are the same (the kernels stream these arrays row by row: huge pages' shorter
    page walks gained nothing measurable). Mapping the arrays anew with the advice gained as
    much in the first solve but faulted them in again in every later one (measured ad hoc,
    0.11–0.18 system seconds a later solve at 1×; not kept).
    """
    a = np.empty(shape, dtype=dtype)
    if a.nbytes < _SMALL_PAGES_MIN_BYTES:
        return a
    m = _madvise()
    if m is not None:
        addr = a.ctypes.data
        start = (addr + _PAGE - 1) // _PAGE * _PAGE
        end = (addr + a.nbytes) // _PAGE * _PAGE
        m[0](start, end - start, m[1])  # (a refusal changes the speed only: ignored)
    return a


def _assemble(
    layout: _Layout,
    slot_parts,
    pidx_parts,
    jp_parts,
    M: int,
    factored_k,
    values=None,
    clock=None,
    buffers: _Buffers | None = None,
):
    """One (M, K) row-compressed matrix: each part's slots side by side, padded to the widest;
    returns ``(Jrc, pidx, Jp)``. A :class:`_FusedPart` is evaluated here, into its rows. With
    ``buffers`` the arrays are those kept from the last call (see :class:`_Buffers`).
    """
    from hsgeo.adjust._fused import _FusedPart

    def parts_of(part):
        return [part] if isinstance(part, _FusedPart) else part

    def empty(name, shape, dtype=np.float64):
        if buffers is None:
            return np.empty(shape, dtype=dtype)
        return buffers.empty(name, shape, dtype)

    K = max([sum(sl.width for sl in parts_of(part)) for part in slot_parts] + [1])
    itype = np.int32 if layout.n_c < 2**31 else np.int64
    cols_all = empty("cols", (M, K), itype)
    vals_all = empty("vals", (M, K))
    Q = max([sl.qk[0] for part in slot_parts for sl in parts_of(part) if sl.factored] + [0])
    Kf = factored_k if Q else 0
    # written row range by row range below (a fused part writes its own share: no pass first)
    fcol = empty("fcol", (M, Q), itype)
    fw = empty("fw", (M, Q))
    fd = empty("fd", (M, Kf))
    pidx = empty("pidx", (M,), np.int64)
    Jp = empty("Jp", (M, layout.p))
    row0 = 0
    for part, pi, jp in zip(slot_parts, pidx_parts, jp_parts, strict=True):
        n = pi.size
        rs = slice(row0, row0 + n)
        pidx[rs] = pi
        k0 = 0
        q, kf = part.qk if isinstance(part, _FusedPart) else (0, 0)
        fcol[rs, q:] = -1  # what the part does not write: empty factored slots
        fw[rs, q:] = 0.0
        fd[rs, kf:] = 0.0
        if isinstance(part, _FusedPart):
            part.row_range = (row0, row0 + n)
            memo = buffers.memo if buffers is not None and not layout.tie_blocks else None
            part.fill(
                values, cols_all[rs], vals_all[rs], fcol[rs], fw[rs], fd[rs], Jp[rs], clock, memo
            )
            if part.nonfinite.size:
                raise _NonFinite(
                    f"residual block {part.blk.name!r} produced non-finite residuals at rows "
                    f"{part.nonfinite.tolist()}"
                )
            k0 = part.width
            part = []
        else:
            Jp[rs] = jp
        for sl in part:
            if sl.factored:
                sl.fill_factored(fcol[row0 : row0 + n], fw[row0 : row0 + n], fd[row0 : row0 + n])
                continue
            sl.fill(
                cols_all[row0 : row0 + n, k0 : k0 + sl.width],
                vals_all[row0 : row0 + n, k0 : k0 + sl.width],
            )
            k0 += sl.width
        if k0 < K:  # padding
            cols_all[row0 : row0 + n, k0:] = -1
            vals_all[row0 : row0 + n, k0:] = 0.0
        row0 += n
    if layout.tie_blocks:
        _merge_tied_columns(cols_all, vals_all)
    Jrc = _RowJac(cols_all, vals_all, layout.n_c, *((fcol, fw, fd) if Q else ()))
    return Jrc, pidx, Jp


def _evaluate(
    layout: _Layout,
    blocks: Sequence[ResidualBlock],
    masks,
    jacobian: bool,
    compiled: bool = True,
    clock: _Clock | None = None,
    loss: tuple | None = None,
    fused: bool = True,
    buffers: _Buffers | None = None,
    trial: bool = False,
) -> _System:
    """Whitened residuals (and with ``jacobian`` the row-compressed Jacobian) at the current
    values of ``layout.params``; rows of ``masks[i] == False`` are left out. ``compiled``
    keeps factored Jacobians factored (the compiled kernels' form). ``clock`` takes the
    seconds of the blocks' own evaluation (``model``) and of the assembly (``jacobian``).

    ``loss = (kind, k, scales)``: the observation rows under a robust loss
    (:mod:`hsgeo.adjust.loss`), with the scale of each block index in ``scales`` (None: ``k``
    robust σ of the residuals here); with ``jacobian`` rows are scaled by ``√ρ′`` and the
    system carries the robust cost, otherwise by ``√(ρ/s)`` (``½ ‖r‖²`` is that cost).

    ``fused`` (compiled, no loss): blocks with ``evaluate_into`` write their rows themselves
    (:class:`_FusedPart`), evaluated in :func:`_assemble`. ``buffers``: the Jacobian's arrays
    kept from the caller's last system, written again (:class:`_Buffers`; that system is
    no longer used). ``trial`` (without ``jacobian``): the residuals at a trial point of a
    step (:meth:`ResidualBlock.trial_residuals`).
    """
    from hsgeo.adjust._fused import _FusedPart

    clock = clock or _Clock()
    if not jacobian and loss is None:
        return _residuals_only(layout, blocks, masks, clock, trial)
    t = time.perf_counter()
    values = layout.params.values()
    r_parts, slot_parts, pidx_parts, jp_parts = [], [], [], []
    factored_k = None  # width k of the factored Jacobians (one per row, one k for all)
    offset = 0
    pname = layout.pblock.name if layout.pblock is not None else None
    loss_c, rho_sum = {}, 0.0
    raw: list = []  # each block's residuals of every row (a fused part's: after _assemble)
    for ib, (blk, keep) in enumerate(zip(blocks, masks, strict=True)):
        t = clock.add("jacobian", t)
        spec = None
        if jacobian and fused and compiled and loss is None:
            spec = _FusedPart.spec_of(layout, blk, keep, factored_k)
        if spec is not None:
            part = _FusedPart(layout, blk, ib, keep, 1.0 / blk.sigma, spec)
            factored_k = part.qk[1]
            r_parts.append(part.r_kept)
            slot_parts.append(part)
            pidx_parts.append(part.pidx)
            jp_parts.append(None)
            offset += part.rows.size
            raw.append(part)
            continue
        r, jac = _block_residuals(blk, values, jacobian, trial)
        raw.append(r)
        t = clock.add("model", t)
        w = 1.0 / blk.sigma
        if jacobian:
            rows_kept = np.flatnonzero(keep)
            all_kept = rows_kept.size == blk.m
            rw = r * w if all_kept else r.take(rows_kept) * w.take(rows_kept)
        else:
            # the residuals alone (a trial step): the kept rows by their mask, the same
            # products; the indices and two gathers cost 1.7× as much at 8.8 M rows
            rw = r * w if keep.all() else (r * w)[keep]
        if loss is not None:
            w, rw, loss_c[ib], part = _robust_rows(loss, ib, blk, w, rw, keep, jacobian)
            rho_sum += part
        r_parts.append(rw)
        if jacobian:
            pidx = np.full(rows_kept.size, -1, dtype=np.int64)
            jp = np.zeros((rows_kept.size, layout.p))
            blk_slots = []
            for name, J in jac.items():
                b = layout.params[name]
                if name == pname:
                    pidx, jp = _point_jacobian(layout, ib, name, J, w, rows_kept, all_kept)
                    continue
                if name in layout.tie_blocks and isinstance(J, Indexed):
                    J = J.expanded()
                has_f = any(sl.factored for sl in blk_slots)
                sl = _Slots(
                    J,
                    blk.m,
                    b.size,
                    name,
                    layout.colmap[name],
                    None if all_kept else rows_kept,
                    w,
                    factored_k=-1 if has_f else factored_k,
                    compiled=compiled,
                )
                if sl.factored:
                    factored_k = sl.qk[1]
                blk_slots.append(sl)
            slot_parts.append(blk_slots)
            pidx_parts.append(pidx)
            jp_parts.append(jp)
        offset += rw.size
    n_obs_rows = offset
    offset += _prior_rows(layout, jacobian, r_parts, slot_parts, pidx_parts, jp_parts)
    lc = loss_c if loss is not None else None
    if not jacobian:
        r_all = np.concatenate(r_parts) if r_parts else np.zeros(0)
        clock.add("model", t)
        return _System(r_all, None, None, None, n_obs_rows, lc)
    model0 = clock.seconds.get("model", 0.0)
    Jrc, pidx, Jp = _assemble(
        layout, slot_parts, pidx_parts, jp_parts, offset, factored_k, values, clock, buffers
    )
    # the fused parts' evaluation went to "model": not the assembly's too
    clock.seconds["jacobian"] = clock.seconds.get("jacobian", 0.0) - (
        clock.seconds.get("model", 0.0) - model0
    )
    r_all = np.concatenate(r_parts) if r_parts else np.zeros(0)  # after the fused parts
    robust = None
    if loss is not None:
        prior = r_all[n_obs_rows:]
        robust = 0.5 * (rho_sum + float(prior @ prior))
    gd_parts = [(*sl.row_range, sl.g, sl.d) for sl in slot_parts if isinstance(sl, _FusedPart)]
    raw = [x.r_all if isinstance(x, _FusedPart) else x for x in raw]
    clock.add("jacobian", t)
    sy = _System(r_all, Jrc, pidx, Jp, n_obs_rows, lc, robust, gd_parts)
    sy.raw, sy.values_at = raw, layout.get_state()
    return sy


def _residuals_only(layout: _Layout, blocks, masks, clock: _Clock, trial: bool) -> _System:
    """:func:`_evaluate` without the Jacobian and without a loss: the kept rows' whitened
    residuals, written once into the system's vector (:func:`_fast.kept_whitened`, the same
    products ``r · (1/σ)`` as the linearisation's) instead of a product, a selection and a
    concatenation of new arrays each (at 10× the paper's pushbroom block, 8.8 M rows: 0.17 s of
    wall time a trial step, on the main thread alone).
    """
    from hsgeo.adjust._fast import kept_whitened

    t = time.perf_counter()
    values = layout.params.values()
    priors: list[np.ndarray] = []
    _prior_rows(layout, False, priors, [], [], [])
    kept = [int(np.count_nonzero(keep)) for keep in masks]
    out = np.empty(sum(kept) + sum(p.size for p in priors))
    offset = 0
    for blk, keep, n in zip(blocks, masks, kept, strict=True):
        r, _ = _block_residuals(blk, values, False, trial)
        t = clock.add("model", t)
        sigma = np.broadcast_to(np.asarray(blk.sigma, dtype=np.float64), (blk.m,))
        kept_whitened(r, np.ascontiguousarray(sigma), np.asarray(keep, dtype=bool), out[offset:])
        offset += n
    n_obs_rows = offset
    for p in priors:
        out[offset : offset + p.size] = p
        offset += p.size
    clock.add("model", t)
    return _System(out, None, None, None, n_obs_rows, None)


def _robust_rows(loss, ib: int, blk: ResidualBlock, w, rw, keep, jacobian: bool):
    """One block's rows under the robust loss ``loss = (kind, k, scales)``: the row weights
    ``w`` (all rows) and the kept whitened residuals ``rw`` scaled, the scale, and ``Σ ρ``.
    """
    from hsgeo.adjust.loss import scale, weigh

    kind, k, scales = loss
    c = scales[ib] if scales is not None else scale(rw, k)
    f, part = weigh(kind, rw, blk.group_size, c, jacobian)
    w_all = np.broadcast_to(np.asarray(w, dtype=np.float64), (blk.m,)).copy()
    w_all[keep] *= f  # the Jacobian's rows are whitened with w (see _Slots)
    return w_all, rw * f, c, part


def _merge_tied_columns(cols: np.ndarray, vals: np.ndarray) -> None:
    """Sum the entries of a row that fall in one column (tied parameters) into its first slot.

    In place; the other slots become empty (``-1``, 0). Each row then has each column once, as
    the compiled kernels expect.
    """
    K = cols.shape[1]
    for s in range(K):
        for t in range(s + 1, K):
            dup = (cols[:, t] == cols[:, s]) & (cols[:, s] >= 0)
            if dup.any():
                vals[dup, s] += vals[dup, t]
                cols[dup, t] = -1
                vals[dup, t] = 0.0
