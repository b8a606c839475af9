"""The fused path of the engine (``SolverOptions.fused``): a residual block that writes its
whitened derivatives straight into the row-compressed arrays of :mod:`hsgeo.adjust.system`.

On the generic path a block returns its Jacobian, and :class:`~hsgeo.adjust.system._Slots`
copies it (whitened, rows kept) into the engine's ``(M, K)`` arrays: every derivative is
written twice and read once in between. A block with ``fused_spec()`` and ``evaluate_into``
(:class:`hsgeo.sensors.pushbroom.PushbroomLines`) is instead evaluated once the arrays are
allocated, into its own rows of them; the engine writes the column indices (static for a
given set of kept rows) and the block's whitened residuals in one compiled pass
(:func:`_fused_columns`): at the paper's pushbroom size the numpy expressions it replaced made
≈ 100 MB of temporaries per linearisation, new memory whose first touch costs system time.
The numbers are those of the generic path bit for bit (the same products, in the same rows);
``tests/test_engine_fused.py``.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, prange

from hsgeo.adjust.residuals import ResidualBlock

__all__: list[str] = []


class _FusedPart:
    """A residual block that writes its own whitened rows into the row-compressed arrays.

    The block (e.g. :class:`~hsgeo.sensors.pushbroom.PushbroomLines`) has ``fused_spec()``
    (which blocks its derivatives go to, in which slots) and ``evaluate_into(values, dst,
    w_row, r, jp, vals, fw, fd)``; it is evaluated when :func:`_assemble` has allocated the
    arrays, so its derivatives are written once, where the kernels read them, instead of into
    a Jacobian of its own that :class:`_Slots` copies (``SolverOptions.fused``). The column
    indices are the engine's (from the layout), as on the generic path.
    """

    def __init__(self, layout, blk: ResidualBlock, ib: int, keep, w, spec: dict):
        self.blk, self.spec, self.layout = blk, spec, layout
        pair = keep[0::2]
        self.dst = np.where(pair, np.cumsum(pair) - 1, -1).astype(np.int64)
        self.rows = np.flatnonzero(keep)
        self.w = np.ascontiguousarray(np.broadcast_to(np.asarray(w, dtype=np.float64), (blk.m,)))
        _, fidx, k = spec["factored"]
        self.qk = (fidx.shape[1], k)
        self.factored = True
        self.width = sum(
            layout.params[name].size if index is None else 1 for name, index in spec["slots"]
        )
        pidx = spec["points"][1]
        layout.row_point[ib] = pidx
        self.pidx = pidx.take(self.rows)
        self.r_kept = np.empty(self.rows.size)  # filled by fill (the _System's residuals)
        #: after fill: the gradient and diagonal of the non-point unknowns over these rows,
        #: accumulated by the block's pass (see _System.gd_parts), and the rows' range
        self.g = self.d = None
        self.row_range = (0, 0)
        self.r_all: np.ndarray | None = None  # after fill: the residuals of every row

    @staticmethod
    def spec_of(layout, blk: ResidualBlock, keep, factored_k) -> dict | None:
        """The block's ``fused_spec()`` if the fused path applies to it here, else None."""
        if not hasattr(blk, "evaluate_into") or blk.group_size != 2:
            return None
        keep = np.asarray(keep, dtype=bool)
        if not np.array_equal(keep[0::2], keep[1::2]):
            return None
        spec = blk.fused_spec()
        pname, _ = spec["points"]
        fname, fidx, k = spec["factored"]
        names = [pname, fname] + [nm for nm, _ in spec["slots"]]
        pb = layout.pblock
        if pb is None or pname != pb.name or layout.p != 3 or not layout.pfree.all():
            return None
        if any(nm in layout.tie_blocks for nm in names) or factored_k not in (None, k):
            return None
        cm = layout.colmap[fname]
        size = layout.params[fname].size
        contiguous = cm.size and cm[0] >= 0 and np.all(np.diff(cm) == 1)
        if not contiguous or size % k or (fidx.size and int(fidx.max()) >= size // k):
            return None
        return spec

    def fill(self, values, cols, vals, fcol, fw, fd, jp, clock, memo=None) -> None:
        """Evaluate the block into the part's rows of the arrays (see :func:`_assemble`).

        ``memo`` (a dict kept with the arrays, :class:`~hsgeo.adjust.system._Buffers`): the
        column indices this part wrote last, by the arrays and rows they went to; when this
        call writes the same columns to the same rows, only what the block's evaluation
        overwrote is set again (:func:`_fused_refresh`).
        """
        t = time.perf_counter()
        blk, layout = self.blk, self.layout
        r = np.empty(blk.m)
        w = self.width
        q, k = self.qk
        dense = [layout.colmap[nm] for nm, index in self.spec["slots"] if index is None]
        indexed = [layout.colmap[nm] for nm, index in self.spec["slots"] if index is not None]
        cols_of = (
            np.concatenate(dense).astype(np.int64),
            indexed[0].astype(np.int64),
            int(layout.colmap[self.spec["factored"][0]][0]),
        )
        gd = np.zeros((2, 64 if blk.m > 12800 else 1, layout.n_c))
        blk.evaluate_into(
            values, self.dst, self.w, r, jp, vals[:, :w], fw[:, :q], fd[:, :k], gd, cols_of
        )
        # the chunks summed in a fixed order: the same bits for any number of threads
        self.g, self.d = gd.sum(axis=1)
        clock.add("model", t)  # (the rest is the caller's "jacobian")
        self.nonfinite = np.flatnonzero(~np.isfinite(r))[:5]  # checked by system._assemble
        self.r_all = r  # every row's residual (the system's raw, see _System.residuals_at)
        fname, fidx, _ = self.spec["factored"]
        # the slots' columns: a dense block's columns are the same in every row (-1 in
        # plan_col: an indexed slot, its column looked up per row in ix_cm)
        plan_col, plan_ix, ix_index, ix_cm, ix_off = [], [], [], [], [0]
        for name, index in self.spec["slots"]:
            cm = layout.colmap[name]
            if index is None:
                plan_col += cm.tolist()
                plan_ix += [-1] * cm.size
            else:
                plan_col.append(-1)
                plan_ix.append(len(ix_index))
                ix_index.append(np.asarray(index, dtype=np.int64))
                ix_cm.append(cm)
                ix_off.append(ix_off[-1] + cm.size)
        ix = ix_index[0][None, :] if len(ix_index) == 1 else np.stack(ix_index)
        if not ix_index:
            ix = np.zeros((0, blk.m), dtype=np.int64)
        cm_all = np.concatenate(ix_cm).astype(np.int64) if ix_cm else np.zeros(0, dtype=np.int64)
        key = (
            _where(cols),  # (the arrays' first row and row layout; not their number of rows)
            _where(fcol),
            id(fidx),
            tuple(id(a) for a in ix_index),
            tuple(plan_col),
            tuple(plan_ix),
            tuple(cm_all.tolist()),
            tuple(ix_off),
            int(layout.colmap[fname][0]),
            k,
        )
        same = memo is not None and memo.get("key") == key and memo["fidx"] is fidx
        kept = None
        if same and not np.array_equal(memo["rows"], self.rows):
            # fewer rows (observations rejected since): the indices of the rows still kept,
            # moved up to their new places, are what _fused_columns would write there
            kept = _kept_positions(memo["rows"], self.rows)
            same = kept is not None
        if same:
            if kept is not None:
                _compact_rows(kept, cols, fcol[:, :q])
            # the same columns in the same rows: the slots that can be empty (a fixed entry)
            # and the empty factored slots get their zeros again, and the residuals
            empty = [
                s
                for s in range(w)
                if (plan_ix[s] < 0 and plan_col[s] < 0)
                or (plan_ix[s] >= 0 and (ix_cm[plan_ix[s]] < 0).any())
            ]
            if memo is not None:
                memo["rows"] = self.rows
            _fused_refresh(
                self.rows,
                r,
                self.w,
                cols,
                vals[:, :w],
                fcol[:, :q],
                fw[:, :q],
                np.asarray(empty, dtype=np.int64),
                self.r_kept,
            )
            return
        _fused_columns(
            self.rows,
            np.asarray(fidx, dtype=np.int64),
            int(layout.colmap[fname][0]),
            k,
            np.asarray(plan_col, dtype=np.int64),
            np.asarray(plan_ix, dtype=np.int64),
            ix,
            cm_all,
            np.asarray(ix_off, dtype=np.int64),
            r,
            self.w,
            cols,
            vals[:, :w],
            fcol[:, :q],
            fw[:, :q],
            self.r_kept,
        )
        if memo is not None:
            memo.update(key=key, fidx=fidx, rows=self.rows)


def _where(a: np.ndarray) -> tuple:
    """Where an array's rows are: its address, the shape of a row, strides and type (not the
    number of rows: fewer rows after a rejection are the first rows of the same arrays).
    """
    return (a.__array_interface__["data"][0], a.shape[1:], a.strides, a.dtype.str)


def _kept_positions(before: np.ndarray, now: np.ndarray) -> np.ndarray | None:
    """Where each of the rows ``now`` was among ``before`` (both increasing), or None if
    ``now`` is not a subset of ``before``.
    """
    if now.size > before.size:
        return None
    at = np.searchsorted(before, now)
    if at.size and (at[-1] >= before.size or not np.array_equal(before[at], now)):
        return None
    return at.astype(np.int64)


@njit(cache=True)
def _compact_rows(at, cols, fcol):  # pragma: no cover - compiled
    """Row ``at[t]`` of the index arrays to row t, in place (``at`` increasing, ``at[t] ≥ t``:
    a row is read before it is written over), one pass on one thread: at the paper's
    pushbroom size after a rejection 0.003-0.004 against 0.015-0.019 CPU-s for writing the indices
    again (_fused_columns).
    """
    for t in range(at.size):
        s = at[t]
        if s != t:
            for j in range(cols.shape[1]):
                cols[t, j] = cols[s, j]
            for j in range(fcol.shape[1]):
                fcol[t, j] = fcol[s, j]


@njit(cache=True, parallel=True)
def _fused_refresh(rows, r, w, cols, vals, fcol, fw, empty, rk):  # pragma: no cover - compiled
    """:func:`_fused_columns` where the column indices are in place already (written by it for
    the same rows): the zeros of the empty slots among ``empty`` and of the empty factored
    slots, which the block's evaluation overwrote, and the whitened residuals; the same arrays
    as :func:`_fused_columns` writes, without writing the indices again (at 10× the paper's
    pushbroom block ≈ 1 GB per linearisation).
    """
    q = fcol.shape[1]
    for t in prange(rows.size):
        i = rows[t]
        for a in range(q):
            if fcol[t, a] < 0:
                fw[t, a] = 0.0
        for e in range(empty.size):
            s = empty[e]
            if cols[t, s] < 0:
                vals[t, s] = 0.0
        rk[t] = r[i] * w[i]


@njit(cache=True, parallel=True)
def _fused_columns(
    rows, fidx, fc0, k, plan_col, plan_ix, ix_index, ix_cm, ix_off, r, w, cols, vals, fcol, fw, rk
):  # pragma: no cover - compiled
    """The engine's share of a fused part's rows, in one pass without temporaries: destination
    row t is block row ``rows[t]``; its factored group's columns ``fc0 + k·item`` (``-1`` and a
    zero weight where the item is -1), its slots' columns (``plan_col[s]``, or for an indexed
    slot ``ix_cm[ix_off[j] + ix_index[j, row]]`` with ``j = plan_ix[s]``; a fixed entry's slot
    empty, its value zeroed) and its whitened residual ``rk[t] = r · w``.
    """
    q = fcol.shape[1]
    width = plan_col.size
    for t in prange(rows.size):
        i = rows[t]
        for a in range(q):
            it = fidx[i, a]
            if it >= 0:
                fcol[t, a] = fc0 + it * k
            else:
                fcol[t, a] = -1
                fw[t, a] = 0.0
        for s in range(width):
            j = plan_ix[s]
            c = plan_col[s] if j < 0 else ix_cm[ix_off[j] + ix_index[j, i]]
            cols[t, s] = c
            if c < 0:
                vals[t, s] = 0.0
        rk[t] = r[i] * w[i]
