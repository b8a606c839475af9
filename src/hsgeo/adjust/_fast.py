"""Compiled kernels of the engine's normal equations and Schur complement (numba).

The engine keeps the whitened Jacobian of the non-point unknowns *row-compressed*: every row
``i`` has ``K`` slots ``(cols[i, s], vals[i, s])`` (``cols = -1``: empty slot). Bundle problems
have few non-zeros per row (a pushbroom observation touches 4 spline nodes × 6 + 11 camera
columns) but very many rows, so this avoids building scipy.sparse matrices of tens of millions
of entries, and the Schur complement

    S = N_cc − Σ_i W_i V_i⁻¹ W_iᵀ,   W_i = Σ_{rows r of point i} J_c,rᵀ J_p,r

is accumulated point by point from the rows grouped by point, without ever forming ``W``
(GUIDE §9: for the pushbroom problem the cost is in forming the reduced system, not in solving
it). Only the upper triangle is accumulated; the kernels run over the rows / points in
``n_chunks`` independent chunks (one per thread) and sum the per-chunk matrices.

The generic scipy.sparse path in :mod:`hsgeo.adjust.engine` computes the same quantities;
``tests/test_engine.py`` checks that the two agree.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

__all__ = ["normal_cc", "reduced_points", "point_covariance", "locality_orders", "n_threads"]


def n_threads() -> int:
    return int(numba.get_num_threads())


@njit(cache=True, inline="always")
def _runs(cl, nl, run_l, run_c, run_n):  # pragma: no cover - compiled
    """Split the column list cl[:nl] into runs of consecutive column numbers."""
    nr = 0
    a = 0
    while a < nl:
        b = a + 1
        while b < nl and cl[b] == cl[b - 1] + 1:
            b += 1
        run_l[nr] = a
        run_c[nr] = cl[a]
        run_n[nr] = b - a
        nr += 1
        a = b
    return nr


@njit(cache=True, parallel=True)
def _normal_cc_kernel(cols, vals, row_order, n_c, n_chunks):  # pragma: no cover - compiled
    K = cols.shape[1]
    M = row_order.size
    out = np.zeros((n_chunks, n_c, n_c))
    step = (M + n_chunks - 1) // n_chunks
    for ch in prange(n_chunks):
        N = out[ch]
        cl = np.empty(K, dtype=np.int64)
        v = np.empty(K)
        run_l = np.empty(K, dtype=np.int64)
        run_c = np.empty(K, dtype=np.int64)
        run_n = np.empty(K, dtype=np.int64)
        for ii in range(ch * step, min(M, (ch + 1) * step)):
            i = row_order[ii]
            nl = 0
            for s in range(K):
                c = cols[i, s]
                if c >= 0 and vals[i, s] != 0.0:
                    cl[nl] = c
                    v[nl] = vals[i, s]
                    nl += 1
            nr = _runs(cl, nl, run_l, run_c, run_n)
            for a in range(nl):
                ca = cl[a]
                va = v[a]
                for q in range(nr):
                    c0 = run_c[q]
                    L = run_n[q]
                    if c0 + L <= ca:
                        continue
                    j0 = ca - c0 if ca > c0 else 0
                    l0 = run_l[q]
                    for j in range(j0, L):
                        N[ca, c0 + j] += va * v[l0 + j]
    return out


@njit(cache=True, parallel=True, fastmath=True)
def _reduced_kernel(cols, vals, jp, order, ptr, pt_order, Vinv, n_c, cap,
                    n_chunks):  # pragma: no cover - compiled
    """Σ_i (J_c,iᵀ J_c,i − W_i V_i⁻¹ W_iᵀ) over the points (upper triangle).

    Rows of point i are ``order[ptr[i]:ptr[i+1]]``; points are visited in ``pt_order``. Per
    point, the normal-matrix and Schur contributions are formed on the point's local columns
    (a small dense block, in cache) and scattered once into the dense result.
    """
    n_pts = ptr.size - 1
    K = cols.shape[1]
    p = jp.shape[1]
    out = np.zeros((n_chunks, n_c, n_c))
    step = (n_pts + n_chunks - 1) // n_chunks
    for ch in prange(n_chunks):
        S = out[ch]
        pos = np.full(n_c, -1, dtype=np.int64)
        cl = np.empty(cap, dtype=np.int64)
        G = np.zeros((cap, cap))
        Z = np.zeros((p, cap))  # W_iᵀ on the local columns, transposed: contiguous per k
        T = np.zeros((cap, p))  # Z V⁻¹
        la = np.empty(K, dtype=np.int64)
        for ii in range(ch * step, min(n_pts, (ch + 1) * step)):
            i = pt_order[ii]
            a0, a1 = ptr[i], ptr[i + 1]
            if a1 == a0:
                continue
            nl = 0
            # local column list: union over the point's rows (a row repeating the previous
            # row's columns, e.g. the y of an x, adds nothing)
            for rr in range(a0, a1):
                r = order[rr]
                if rr > a0:
                    rp = order[rr - 1]
                    same = True
                    for s in range(K):
                        if cols[r, s] != cols[rp, s]:
                            same = False
                            break
                    if same:
                        continue
                for s in range(K):
                    c = cols[r, s]
                    if c >= 0 and pos[c] < 0:
                        pos[c] = 0
                        cl[nl] = c
                        nl += 1
            cl[:nl].sort()
            for a in range(nl):
                pos[cl[a]] = a
                for k in range(p):
                    Z[k, a] = 0.0
                for b in range(a, nl):
                    G[a, b] = 0.0
            # G = J_cᵀ J_c and Z = W_iᵀ on the local columns
            for rr in range(a0, a1):
                r = order[rr]
                for s in range(K):
                    c = cols[r, s]
                    la[s] = pos[c] if c >= 0 else -1
                for s in range(K):
                    l1 = la[s]
                    if l1 < 0:
                        continue
                    v = vals[r, s]
                    for k in range(p):
                        Z[k, l1] += v * jp[r, k]
                    for s2 in range(K):
                        l2 = la[s2]
                        if l2 >= l1:
                            G[l1, l2] += v * vals[r, s2]
            # T = Z V⁻¹
            for a in range(nl):
                for k in range(p):
                    acc = 0.0
                    for j in range(p):
                        acc += Z[j, a] * Vinv[i, j, k]
                    T[a, k] = acc
            # scatter G − T Zᵀ (upper triangle) into S
            for a in range(nl):
                ca = cl[a]
                Srow = S[ca]
                Grow = G[a]
                if p == 3:
                    t0, t1, t2 = T[a, 0], T[a, 1], T[a, 2]
                    Z0, Z1, Z2 = Z[0], Z[1], Z[2]
                    for b in range(a, nl):
                        Srow[cl[b]] += Grow[b] - (t0 * Z0[b] + t1 * Z1[b] + t2 * Z2[b])
                else:
                    for b in range(a, nl):
                        acc = 0.0
                        for k in range(p):
                            acc += T[a, k] * Z[k, b]
                        Srow[cl[b]] += Grow[b] - acc
            for a in range(nl):
                pos[cl[a]] = -1
    return out


def _symmetrise_upper(U: np.ndarray) -> np.ndarray:
    d = np.diag(U).copy()
    S = U + U.T
    S[np.diag_indices_from(S)] = d
    return S


def locality_orders(cols: np.ndarray, n_c: int, order: np.ndarray | None, ptr: np.ndarray | None):
    """Row and point processing orders that keep consecutive updates in nearby rows of S.

    Rows are sorted by their smallest column, points by the smallest and largest column of
    their rows: consecutive points then touch mostly the same rows of the dense matrix, which
    stay in cache (the kernels are limited by memory latency, not arithmetic).
    """
    big = np.int64(n_c)
    c = np.where(cols >= 0, cols, big)
    rmin = c.min(axis=1) if cols.shape[1] else np.full(cols.shape[0], big)
    row_order = np.argsort(rmin, kind="stable").astype(np.int64)
    if order is None or ptr is None or ptr.size < 2:
        return row_order, None
    # (sorting the points by the segments that see them was tried and gave no measurable gain)
    return row_order, np.arange(ptr.size - 1, dtype=np.int64)


def normal_cc(cols: np.ndarray, vals: np.ndarray, n_c: int, row_order=None) -> np.ndarray:
    """``J_cᵀ J_c`` (dense ``n_c × n_c``) of a row-compressed Jacobian."""
    if n_c == 0 or cols.shape[0] == 0:
        return np.zeros((n_c, n_c))
    if row_order is None:
        row_order = np.arange(cols.shape[0], dtype=np.int64)
    row_order = np.asarray(row_order, dtype=np.int64)
    nch = max(1, min(n_threads(), row_order.size // 10000 + 1))
    parts = _normal_cc_kernel(cols, vals, row_order, n_c, nch)
    return _symmetrise_upper(parts.sum(axis=0) if nch > 1 else parts[0])


def reduced_points(cols, vals, jp, order, ptr, Vinv, n_c: int, pt_order=None) -> np.ndarray:
    """``Σ_i (J_c,iᵀ J_c,i − W_i V_i⁻¹ W_iᵀ)`` (dense ``n_c × n_c``) over the points' rows."""
    n_pts = ptr.size - 1
    if n_c == 0 or n_pts == 0:
        return np.zeros((n_c, n_c))
    if pt_order is None:
        pt_order = np.arange(n_pts, dtype=np.int64)
    max_rows = int(np.max(np.diff(ptr))) if n_pts else 0
    cap = int(min(n_c, max(1, max_rows * cols.shape[1])))
    nch = max(1, min(n_threads(), n_pts // 2000 + 1))
    parts = _reduced_kernel(cols, vals, jp, order, ptr, pt_order, Vinv, n_c, cap, nch)
    return _symmetrise_upper(parts.sum(axis=0) if nch > 1 else parts[0])


@njit(cache=True, parallel=True)
def _point_cov_kernel(cols, vals, jp, order, ptr, points, Vinv, S_inv, cap):  # pragma: no cover
    """V_i⁻¹ + V_i⁻¹ W_iᵀ S⁻¹ W_i V_i⁻¹ for the listed points, on each point's local columns."""
    K = cols.shape[1]
    p = jp.shape[1]
    n_c = S_inv.shape[0]
    n = points.size
    out = np.zeros((n, p, p))
    n_chunks = min(n, 64)
    step = (n + n_chunks - 1) // n_chunks
    for ch in prange(n_chunks):
        pos = np.full(n_c, -1, dtype=np.int64)
        cl = np.empty(cap, dtype=np.int64)
        Z = np.zeros((p, cap))
        A = np.zeros((p, cap))
        for q in range(ch * step, min(n, (ch + 1) * step)):
            i = points[q]
            nl = 0
            for rr in range(ptr[i], ptr[i + 1]):
                r = order[rr]
                for s in range(K):
                    c = cols[r, s]
                    if c >= 0:
                        if pos[c] < 0:
                            pos[c] = nl
                            cl[nl] = c
                            for k in range(p):
                                Z[k, nl] = 0.0
                            nl += 1
                        la = pos[c]
                        for k in range(p):
                            Z[k, la] += vals[r, s] * jp[r, k]
            for k in range(p):
                for a in range(nl):
                    acc = 0.0
                    for j in range(p):
                        acc += Vinv[i, k, j] * Z[j, a]
                    A[k, a] = acc
            for k in range(p):
                for j in range(p):
                    acc = Vinv[i, k, j]
                    for a in range(nl):
                        t = 0.0
                        ca = cl[a]
                        for b in range(nl):
                            t += S_inv[ca, cl[b]] * A[j, b]
                        acc += A[k, a] * t
                    out[q, k, j] = acc
            for a in range(nl):
                pos[cl[a]] = -1
    return out


def point_covariance(cols, vals, jp, order, ptr, points, Vinv, S_inv) -> np.ndarray:
    """Unscaled covariance ``V⁻¹ + V⁻¹ Wᵀ S⁻¹ W V⁻¹`` of the listed points, ``(n, p, p)``."""
    points = np.asarray(points, dtype=np.int64)
    if points.size == 0:
        return np.zeros((0, jp.shape[1], jp.shape[1]))
    max_rows = int(np.max(np.diff(ptr)[points]))
    cap = int(min(S_inv.shape[0], max(1, max_rows * cols.shape[1])))
    return _point_cov_kernel(cols, vals, jp, order, ptr, points, Vinv, S_inv, cap)


@njit(cache=True)
def rmatvec_diag(cols, vals, y, n_c, want_diag):  # pragma: no cover - compiled
    """``Jᵀ y`` and (optionally) ``diag(JᵀJ)`` of a row-compressed matrix, in one pass."""
    g = np.zeros(n_c)
    d = np.zeros(n_c)
    M, K = cols.shape
    for i in range(M):
        yi = y[i]
        for s in range(K):
            c = cols[i, s]
            if c >= 0:
                v = vals[i, s]
                g[c] += v * yi
                if want_diag:
                    d[c] += v * v
    return g, d


@njit(cache=True)
def matvec(cols, vals, x):  # pragma: no cover - compiled
    """``J x`` of a row-compressed matrix."""
    M, K = cols.shape
    out = np.zeros(M)
    for i in range(M):
        acc = 0.0
        for s in range(K):
            c = cols[i, s]
            if c >= 0:
                acc += vals[i, s] * x[c]
        out[i] = acc
    return out
