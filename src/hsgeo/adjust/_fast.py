"""Compiled kernels of the engine's normal equations and Schur complement (numba).

Kept as one file: one concern, the compiled kernels of the reduced normal equations; they
share the row-compressed layout and the chunking described below.

The engine keeps the whitened Jacobian of the non-point unknowns *row-compressed*: every row
``i`` has ``K`` slots ``(cols[i, s], vals[i, s])`` (``cols = -1``: empty slot). Bundle problems
have few non-zeros per row (a pushbroom observation touches 4 spline nodes × 6 + 11 camera
columns) but very many rows, so this avoids building scipy.sparse matrices of tens of millions
of entries, and the Schur complement

    S = N_cc − Σ_i W_i V_i⁻¹ W_iᵀ,   W_i = Σ_{rows r of point i} J_c,rᵀ J_p,r

is accumulated point by point from the rows grouped by point, without ever forming ``W``
(GUIDE §9: for the pushbroom problem the cost is in forming the reduced system, not in solving
it). Only the upper triangle is accumulated; the kernels run over the rows / points in
``n_chunks`` independent chunks (their number set by the size of the problem, never by the
threads: :mod:`hsgeo.adjust.threads`) and sum the per-chunk matrices in a fixed order.

The generic scipy.sparse path in :mod:`hsgeo.adjust.schur` computes the same quantities;
``tests/test_engine.py`` checks that the two agree.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hsgeo.adjust.threads import chunks, over_items

__all__ = [
    "normal_cc",
    "reduced_points",
    "factored_tiles",
    "schur_pattern",
    "point_covariance",
    "locality_orders",
]


def _chunks(n: int, per_chunk: int) -> int:
    # the number of partial sums depends on the size alone, never on the threads (the same
    # bits for any thread count; hsgeo.adjust.threads)
    return chunks(n, per_chunk)


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


@njit(cache=True, inline="always")
def _expand_row(i, cols, vals, fcol, fw, fd, cl, v):  # pragma: no cover - compiled
    """The non-zero entries of row i (slots, then the factored group) into cl, v; their count."""
    n = 0
    for s in range(cols.shape[1]):
        c = cols[i, s]
        if c >= 0 and vals[i, s] != 0.0:
            cl[n] = c
            v[n] = vals[i, s]
            n += 1
    kf = fd.shape[1]
    for a in range(fcol.shape[1]):
        c0 = fcol[i, a]
        if c0 >= 0:
            wa = fw[i, a]
            for j in range(kf):
                cl[n] = c0 + j
                v[n] = wa * fd[i, j]
                n += 1
    return n


@njit(cache=True, parallel=True)
def _normal_cc_kernel(
    cols, vals, fcol, fw, fd, row_order, n_c, n_chunks
):  # pragma: no cover - compiled
    K = cols.shape[1] + fcol.shape[1] * fd.shape[1]
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
            nl = _expand_row(i, cols, vals, fcol, fw, fd, cl, v)
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


@njit(cache=True, inline="always")
def _has_group(fcol, r):  # pragma: no cover - compiled
    """Whether row r has a factored group (any of its items set)."""
    has_f = False
    for a in range(fcol.shape[1]):
        if fcol[r, a] >= 0:
            has_f = True
    return has_f


@njit(cache=True, inline="always")
def _local_columns(cols, fcol, fw, order, a0, a1, grow, pos, gl):  # pragma: no cover
    """The groups (a row of each in ``grow``) and the distinct slot columns (``gl``, their local
    numbers in ``pos``) of the rows ``order[a0:a1]`` of one point; their counts (ng, nl).
    """
    Q = fcol.shape[1]
    ng = 0
    nl = 0
    for rr in range(a0, a1):
        r = order[rr]
        if _has_group(fcol, r):
            same = ng > 0
            if same:
                r0 = grow[ng - 1]
                for a in range(Q):
                    if fcol[r, a] != fcol[r0, a] or fw[r, a] != fw[r0, a]:
                        same = False
                        break
            if not same:
                grow[ng] = r
                ng += 1
        for s in range(cols.shape[1]):
            c = cols[r, s]
            if c >= 0 and pos[c] < 0:
                pos[c] = nl
                gl[nl] = c
                nl += 1
    return ng, nl


@njit(cache=True, inline="always")
def _point_normals_local(
    cols, vals, fcol, fd, jp, order, a0, a1, grow, ng, pos, L, C, Z, li, lv
):  # pragma: no cover - compiled
    """``C = Yᵀ Y`` and ``Z = Yᵀ J_p`` of one point on its L local columns, the whole of ``C``
    (its rows on loops without a branch: forming only the triangle that the expansion reads,
    with a test per entry, together with a signed start in :func:`_schur_row`, took 17.2
    against 13.1 CPU-s a formation at 10× the paper's pushbroom block, one thread;
    bench/results/schur_kernel_vs_issue.json).
    """
    K = cols.shape[1]
    kf = fd.shape[1]
    p = jp.shape[1]
    for a in range(L):
        Crow = C[a]
        for b in range(L):
            Crow[b] = 0.0
        for k in range(p):
            Z[k, a] = 0.0
    g = -1
    for rr in range(a0, a1):
        r = order[rr]
        n = 0
        if g + 1 < ng and grow[g + 1] == r:
            g += 1
        if _has_group(fcol, r):
            for j in range(kf):
                li[n] = g * kf + j
                lv[n] = fd[r, j]
                n += 1
        for s in range(K):
            c = cols[r, s]
            if c >= 0 and vals[r, s] != 0.0:
                li[n] = ng * kf + pos[c]
                lv[n] = vals[r, s]
                n += 1
        for e in range(n):
            la = li[e]
            va = lv[e]
            for k in range(p):
                Z[k, la] += va * jp[r, k]
            Crow = C[la]
            for e2 in range(n):
                Crow[li[e2]] += va * lv[e2]


@njit(cache=True, inline="always")
def _schur_row(C, Z, T, a, b0, L):  # pragma: no cover - compiled
    """``C[a, b0:L] −= T[a] Z[:, b0:L]``: row ``a`` of ``C − Z V_i⁻¹ Zᵀ`` (``T = Zᵀ V_i⁻¹``)
    from column ``b0`` on, in place; the loop runs on unsigned offsets (numba's negative-index
    test on a signed start kept it scalar).
    """
    Crow = C[a]
    ub0 = np.uint64(b0)
    uL = np.uint64(L)
    for k in range(Z.shape[0]):
        t = T[a, k]
        Zk = Z[k]
        for b in range(ub0, uL):
            Crow[b] -= t * Zk[b]


@njit(cache=True, inline="always")
def _schur_rows(Z, T, Vinv, i, L):  # pragma: no cover - compiled
    """``T = Zᵀ V_i⁻¹`` on the L local columns."""
    p = Z.shape[0]
    for a in range(L):
        for k in range(p):
            acc = 0.0
            for j in range(p):
                acc += Z[j, a] * Vinv[i, j, k]
            T[a, k] = acc


@njit(cache=True, inline="always")
def _group_tiles(C, fcol, fw, grow, g, h, kf, tile_of, slot_of, tiles, R):  # pragma: no cover
    """The block C[g, h] of groups g ≤ h added into the tiles of their items; the number of
    tiles outside the pattern (nothing of theirs is written).
    """
    Q = fcol.shape[1]
    kk = kf * kf
    misses = 0
    rg = grow[g]
    rh = grow[h]
    half = 0.5 if h == g else 1.0
    # the block C[g, h] (kf × kf, contiguous); the tile of item a of g against item b of h is
    # fw_g[a] fw_h[b] C[g, h]
    for j in range(kf):
        for l in range(kf):
            R[j * kf + l] = C[g * kf + j, h * kf + l]
    # items of h on consecutive tiles (spline nodes): one contiguous segment of Q·kf² values in
    # each tile row
    tb0 = tile_of[fcol[rh, 0]] if fcol[rh, 0] >= 0 else -1
    run = tb0 >= 0
    for b in range(1, Q):
        cb = fcol[rh, b]
        if cb < 0 or tile_of[cb] != tb0 + b:
            run = False
    for a in range(Q):
        ca = fcol[rg, a]
        if ca < 0:
            continue
        wa = fw[rg, a]
        ta = tile_of[ca]
        if run:
            # g = h: C[g, g] is symmetric, so the tiles b < a are the transposes of a < b and
            # follow from A + Aᵀ (the tile a = b halved)
            b0 = a if h == g else 0
            s0 = slot_of[ta, tb0] * kk  # the Q slots (ta, tb0 + b) follow
            if s0 < 0:
                misses += 1
                continue
            Tseg = tiles[s0 : s0 + Q * kk]
            for b in range(b0, Q):
                sc = wa * fw[rh, b] * (0.5 if (h == g and b == a) else 1.0)
                # unsigned offsets: no negative-index wraparound test, which keeps the loop
                # vectorised
                ob = np.uint64(b * kk)
                for e in range(kk):
                    Tseg[ob + np.uint64(e)] += sc * R[e]
            continue
        for b in range(Q):
            cb = fcol[rh, b]
            if cb < 0:
                continue
            sc = half * wa * fw[rh, b]
            s0 = slot_of[ta, tile_of[cb]] * kk
            if s0 < 0:
                misses += 1
                continue
            Tseg = tiles[s0 : s0 + kk]
            for e in range(kk):
                Tseg[e] += sc * R[e]
    return misses


@njit(cache=True, inline="always")
def _slot_blocks(C, fcol, fw, grow, g, ng, kf, nl, sl, A):  # pragma: no cover
    """The block of group g against the slot columns, added into A (column ``sl[e]`` for the
    slot column e).
    """
    rg = grow[g]
    for a in range(fcol.shape[1]):
        ca = fcol[rg, a]
        if ca < 0:
            continue
        wa = fw[rg, a]
        for j in range(kf):
            Arow = A[ca + j]
            Crow = C[g * kf + j]
            for e in range(nl):
                Arow[sl[e]] += wa * Crow[ng * kf + e]


@njit(cache=True, inline="always")
def _slot_slot(C, Z, T, ng, kf, gl, nl, sl, run_e, run_n, nr, A):  # pragma: no cover
    """The slot columns against each other (one triangle, the diagonal halved) into A, each
    row of ``C − Z V_i⁻¹ Zᵀ`` formed (:func:`_schur_row`) just before it is added: runs of
    consecutive positions are contiguous segments of A's rows, which vectorise.
    """
    G = ng * kf
    L = G + nl
    for e in range(nl):
        a = G + e
        _schur_row(C, Z, T, a, a, L)
        Crow = C[a]
        Crow[a] *= 0.5
        Arow = A[gl[e]]
        for q in range(nr):
            f0 = run_e[q]
            f1 = f0 + run_n[q]
            if f1 <= e:
                continue
            if f0 < e:
                f0 = e
            o = sl[f0] - f0
            for f in range(f0, f1):
                Arow[o + f] += Crow[G + f]


@njit(cache=True, inline="always")
def _same_slots(cols, r, q):  # pragma: no cover - compiled
    """Whether rows r and q have the same slot columns (the x and y of one observation)."""
    for s in range(cols.shape[1]):
        if cols[r, s] != cols[q, s]:
            return False
    return True


@njit(cache=True, inline="always")
def _slot_point(cols, vals, jp, order, a0, a1, scratch, Vinv, i, A):  # pragma: no cover
    """``J_c,iᵀ J_c,i − W_i V_i⁻¹ W_iᵀ`` of a point whose rows have slot columns only (one
    triangle, the diagonal halved) added into A.

    On the nl local columns (in the order the rows bring them, as on the groups' path):
    ``Z = Yᵀ J_p`` (p × nl) and ``Yᵀ Y`` per run of rows with the same columns (an
    observation's x and y), ``T = V_i⁻¹ Z``, the upper triangle of ``C = Yᵀ Y − Tᵀ Z`` in
    ``Cs`` (row stride nl), and C's rows added into A along the runs of consecutive positions
    (a camera's columns). The loops along the local columns run on unsigned offsets: numba's
    negative-index test on a signed index kept them scalar. About ``(p + 1)·nl²/2``
    operations against ``(2p + 1)·nl²`` on the groups' path; on BAL Ladybug-49 the kernel
    took 2.1–2.4× less CPU time than previous main's, with the same bits (the same
    operations on each entry, in the same order, into the same triangle of A;
    bench/results/bal.json).
    """
    pos, gl, sl, run_end, li, si, yv, nl, Z, T, Cs = scratch
    K = cols.shape[1]
    p = jp.shape[1]
    u = np.uint64(nl)
    for k in range(p):
        Zk = Z[k]
        for a in range(u):
            Zk[a] = 0.0
    # the upper triangle of C: zero, then Yᵀ Y and Z
    for e in range(nl):
        b = np.uint64(e) * u
        for f in range(np.uint64(e), u):
            Cs[b + f] = 0.0
    rr = a0
    while rr < a1:
        r = order[rr]
        q1 = rr + 1
        while q1 < a1 and _same_slots(cols, r, order[q1]):
            q1 += 1
        n = 0
        for s in range(K):
            c = cols[r, s]
            if c >= 0:
                li[n] = pos[c]
                si[n] = s
                n += 1
        l0 = li[0] if n else 0
        block = True  # the row's columns are consecutive local columns (a camera's)
        for e in range(n):
            if li[e] != l0 + e:
                block = False
        un = np.uint64(n)
        ul0 = np.uint64(l0)
        for q in range(rr, q1):
            rq = order[q]
            for e in range(n):
                yv[e] = vals[rq, si[e]]
            for k in range(p):
                w = jp[rq, k]
                Zk = Z[k]
                if block:
                    for e in range(un):
                        Zk[ul0 + e] += yv[e] * w
                else:
                    for e in range(n):
                        Z[k, li[e]] += yv[e] * w
            for e in range(n):
                ye = yv[e]
                if block:
                    b = (ul0 + np.uint64(e)) * u + ul0
                    for f in range(np.uint64(e), un):
                        Cs[b + f] += ye * yv[f]
                else:
                    la = li[e]
                    for e2 in range(e, n):
                        lb = li[e2]
                        w = ye * yv[e2]
                        if lb == la and e2 != e:
                            w += w  # a column twice in the row: (e, e2) and (e2, e)
                        if la <= lb:
                            Cs[np.uint64(la) * u + np.uint64(lb)] += w
                        else:
                            Cs[np.uint64(lb) * u + np.uint64(la)] += w
        rr = q1
    # T = (Zᵀ V_i⁻¹)ᵀ, V_i⁻¹ read as the groups' path reads it (the same bits when a
    # pseudo-inverse is not exactly symmetric)
    for k in range(p):
        Tk = T[k]
        for a in range(u):
            Tk[a] = 0.0
        for j in range(p):
            w = Vinv[i, j, k]
            Zj = Z[j]
            for a in range(u):
                Tk[a] += w * Zj[a]
    # C − Tᵀ Z (upper triangle) into A, row by row along the runs of consecutive positions;
    # the diagonal halved (A + Aᵀ)
    run_end[nl - 1] = nl
    for f in range(nl - 2, -1, -1):
        run_end[f] = run_end[f + 1] if sl[f + 1] == sl[f] + 1 else f + 1
    for e in range(nl):
        b = np.uint64(e) * u
        ue = np.uint64(e)
        if p == 3:
            t0 = T[0, e]
            t1 = T[1, e]
            t2 = T[2, e]
            Z0 = Z[0]
            Z1 = Z[1]
            Z2 = Z[2]
            for f in range(ue, u):
                Cs[b + f] = ((Cs[b + f] - t0 * Z0[f]) - t1 * Z1[f]) - t2 * Z2[f]
        else:
            for k in range(p):
                t = T[k, e]
                Zk = Z[k]
                for f in range(ue, u):
                    Cs[b + f] -= t * Zk[f]
        Arow = A[gl[e]]
        Arow[sl[e]] += 0.5 * Cs[b + ue]
        f0 = e + 1
        while f0 < nl:
            f1 = run_end[f0]
            oa = np.uint64(sl[f0])
            oc = b + np.uint64(f0)
            for f in range(np.uint64(f1 - f0)):
                Arow[oa + f] += Cs[oc + f]
            f0 = f1


def _reduced_kernel(*args, buffers=None):
    """A with ``A + Aᵀ = Σ_i (J_c,iᵀ J_c,i − W_i V_i⁻¹ W_iᵀ)`` over the points, in two
    compact parts (see :func:`reduced_points`), and the number of units that fell outside the
    pattern (tile or column not in ``slot_of``/``sc_of``: the pattern is stale; nothing of
    theirs is written).

    Rows of point i are ``order[ptr[i]:ptr[i+1]]``; points are visited in ``pt_order``.

    Per point, the rows are compressed to *local* columns: each run of consecutive rows with
    the same factored group (the same items and weights, e.g. the x and y of one observation
    on the same spline nodes) is one *group* of ``kf`` local columns holding ``fd``; every
    distinct slot column is one local column. On the ``L`` local columns (≈ 6 per observation
    plus the camera's) the point's normal-matrix and Schur terms form a small dense matrix
    ``C = Yᵀ Y − Z V⁻¹ Zᵀ`` (``Y`` the compressed rows, ``Z = Yᵀ J_p``), which is then expanded
    into the global columns: group g's local column j stands for the columns ``fcol[a] + j``
    with weight ``fw[a]``, so the block of groups (g, h) adds ``fw_g[a] fw_h[b] C[gj, hl]`` at
    ``(fcol_g[a] + j, fcol_h[b] + l)``. This is exact: the weights factor out of every product.
    These group × group blocks go to the second output, *tiles* ``(n_slots·kf²,)``: the
    ``kf × kf`` block of the items ``t = tile_of[fcol]`` and ``u`` (row-major) is slot
    ``slot_of[t, u]``, the slots of the pairs that occur numbered row by row
    (:func:`schur_pattern`), so an item's blocks against consecutive items (spline nodes) are
    one contiguous segment, which vectorises; written into rows of S it ran scalar, at about
    one cycle a value, and a dense ``n_tiles² kf²`` array outgrew the caches on long blocks
    (at 10× the paper's pushbroom campaign most item pairs never meet). The blocks against
    slot columns go to the first output ``(n_c, n_sc)``, column ``sc_of[c]`` for column c. Only
    one triangle of the pairs of local units is written (the diagonal units halved), hence
    ``A + Aᵀ``; of ``C − Z V⁻¹ Zᵀ`` only that triangle (and the groups' diagonal blocks) is
    formed (:func:`_schur_row`, on unsigned offsets, which vectorise).

    A point without groups (frame cameras: BAL) takes :func:`_slot_point`, which forms the
    same entries in the same order without the groups' bookkeeping, on loops that vectorise.

    ``fastmath`` without ``reassoc``: every entry is computed in the order written (contracted
    multiply-adds allowed), so the bits do not depend on how the compiler vectorised a loop;
    with reassociation the fused updates of :func:`_slot_point` came out in another order.

    ``args``: the point rows ``cols, vals, fcol, fw, fd, jp, order, ptr, pt_order, Vinv``
    (:func:`_reduced_chunk`'s arguments of those names), then ``n_c, capg, capc, tile_of,
    slot_of, n_slots, sc_of, n_sc, n_chunks``.
    """
    rows = args[:10]
    n_c, capg, capc, tile_of, slot_of, n_slots, sc_of, n_sc, n_chunks = args[10:]
    n_pts = rows[7].size - 1  # ptr
    kk = rows[4].shape[1] ** 2  # fd
    out = _zeros(buffers, "out", (n_chunks, n_c, n_sc))
    out_t = _zeros(buffers, "out_t", (n_chunks, n_slots * kk))
    misses = over_items(
        _reduced_chunk, n_pts, n_chunks, *rows, capg, capc, tile_of, slot_of, sc_of, out, out_t
    )
    return out, out_t, int(sum(misses))


def _zeros(buffers: dict | None, name: str, shape: tuple) -> np.ndarray:
    """``np.zeros(shape)``, in the array of that shape kept in ``buffers`` (a dict) if it has
    one (zeroed again: the formations of one solve reuse their memory, which a fresh
    allocation may not find where the last one was, and then touches first again).
    """
    if buffers is None:
        return np.zeros(shape)
    a = buffers.get(name)
    if a is None or a.shape != shape:
        a = buffers[name] = np.zeros(shape)
    else:
        a.fill(0.0)
    return a


@njit(cache=True, nogil=True, fastmath={"nnan", "ninf", "nsz", "arcp", "contract", "afn"})
def _reduced_chunk(
    ch,
    step,
    cols,
    vals,
    fcol,
    fw,
    fd,
    jp,
    order,
    ptr,
    pt_order,
    Vinv,
    capg,
    capc,
    tile_of,
    slot_of,
    sc_of,
    out,
    out_t,
):  # pragma: no cover - compiled
    """Chunk ``ch`` of :func:`_reduced_kernel`: the points ``pt_order[ch·step : (ch+1)·step]``
    into ``out[ch]`` and ``out_t[ch]``; the number of units outside the pattern. Run on the
    kernels' threads by :func:`~hsgeo._chunks.over_chunks`, not as the body of a
    ``prange`` loop: numba's parallel passes over this body took two thirds of the kernel's
    compile time on a fresh cache (24 of 36 s; issue 41).
    """
    A = out[ch]
    tiles = out_t[ch]
    i0 = ch * step
    i1 = min(ptr.size - 1, i0 + step)
    n_c = A.shape[0]
    K = cols.shape[1]
    kf = fd.shape[1]
    p = jp.shape[1]
    Lmax = capg * kf + capc
    kk = kf * kf
    n_miss = 0
    pos = np.full(n_c, -1, dtype=np.int64)
    gl = np.empty(capc, dtype=np.int64)  # global column of each local slot column
    sl = np.empty(capc, dtype=np.int64)  # its position among the slot columns (sc_of)
    run_e = np.empty(capc, dtype=np.int64)  # runs of consecutive positions (_runs)
    run_s = np.empty(capc, dtype=np.int64)  # each run's first position (unused here)
    run_n = np.empty(capc, dtype=np.int64)
    grow = np.empty(capg, dtype=np.int64)  # a row of each group (its items and weights)
    Lc = Lmax if capg > 0 else 0
    C = np.zeros((Lc, Lc))  # the groups' local matrix (none without groups: BAL)
    Z = np.zeros((p, Lmax))
    T = np.zeros((Lmax, p))
    # a point with slot columns only (_slot_point): V_i⁻¹ Z, its local matrix (row
    # stride nl, grown as needed), a row's slots and values
    Tz = np.zeros((p, capc))
    Cs = np.empty(0)
    si = np.empty(K, dtype=np.int64)
    yv = np.empty(K)
    R = np.zeros(kk)
    li = np.empty(K + kf, dtype=np.int64)
    lv = np.empty(K + kf)
    for ii in range(i0, i1):
        i = pt_order[ii]
        a0, a1 = ptr[i], ptr[i + 1]
        if a1 == a0:
            continue
        ng, nl = _local_columns(cols, fcol, fw, order, a0, a1, grow, pos, gl)
        L = ng * kf + nl
        G = ng * kf
        miss = 0
        for e in range(nl):
            sl[e] = sc_of[gl[e]]
            if sl[e] < 0:
                miss += 1
        if ng == 0:  # slot columns only (frame cameras): straight into A
            if miss:
                n_miss += miss
            elif nl > 0:
                if nl * nl > Cs.size:
                    Cs = np.empty(min(max(nl * nl, 2 * Cs.size), capc * capc))
                sp = (pos, gl, sl, run_e, li, si, yv, nl, Z, Tz, Cs)
                _slot_point(cols, vals, jp, order, a0, a1, sp, Vinv, i, A)
            for e in range(nl):
                pos[gl[e]] = -1
            continue
        _point_normals_local(
            cols, vals, fcol, fd, jp, order, a0, a1, grow, ng, pos, L, C, Z, li, lv
        )
        _schur_rows(Z, T, Vinv, i, L)
        for a in range(G):  # the groups' rows of C − Z V⁻¹ Zᵀ, as the expansion reads them
            _schur_row(C, Z, T, a, (a // kf) * kf, L)
        for e in range(nl):
            pos[gl[e]] = -1
        if miss:  # the pattern is stale: the caller computes it again
            n_miss += miss
            continue
        # expand into the global columns: group × group into the tiles, group × slot
        # columns and slot × slot columns into A
        for g in range(ng):
            for h in range(g, ng):
                n_miss += _group_tiles(C, fcol, fw, grow, g, h, kf, tile_of, slot_of, tiles, R)
            _slot_blocks(C, fcol, fw, grow, g, ng, kf, nl, sl, A)
        nr = _runs(sl, nl, run_e, run_s, run_n)
        _slot_slot(C, Z, T, ng, kf, gl, nl, sl, run_e, run_n, nr, A)
    return n_miss


@njit(cache=True)
def _symmetrise_upper(U: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """``U + Uᵀ`` with ``U``'s own diagonal, in place (the kernels write each pair of columns
    once, in either triangle): the values of the numpy expression (a sum is the same both ways
    round), in tiles of 64 × 64 so that the transposed reads stay in cache; the numpy
    expression took 2.2 of the 50 CPU-s of ``hsgeo reproduce pushbroom-ba --scale 0.01``
    (issue 41).
    """
    n = U.shape[0]
    for r0 in range(0, n, 64):
        for c0 in range(r0, n, 64):
            for r in range(r0, min(r0 + 64, n)):
                for c in range(max(c0, r + 1), min(c0 + 64, n)):
                    v = U[r, c] + U[c, r]
                    U[r, c] = v
                    U[c, r] = v
    return U


def locality_orders(
    J, n_c: int, order: np.ndarray | None, ptr: np.ndarray | None, rows: np.ndarray | None = None
):
    """Row and point processing orders that keep consecutive updates in nearby rows of S.

    ``rows`` (default all) are sorted by their smallest column (``J`` a row-compressed
    Jacobian, ``hsgeo.adjust.system._RowJac``): consecutive rows then touch mostly the same
    rows of the dense matrix, which stay in cache (the kernels are limited by memory latency,
    not arithmetic).
    """
    big = np.int64(n_c)
    rows = np.arange(J.cols.shape[0], dtype=np.int64) if rows is None else rows
    cols = J.cols[rows]
    c = np.where(cols >= 0, cols, big)
    rmin = c.min(axis=1) if cols.shape[1] else np.full(cols.shape[0], big)
    if J.fcol.shape[1]:
        fc = J.fcol[rows]
        rmin = np.minimum(rmin, np.where(fc >= 0, fc, big).min(axis=1))
    row_order = rows[np.argsort(rmin, kind="stable")].astype(np.int64)
    if order is None or ptr is None or ptr.size < 2:
        return row_order, None
    # (sorting the points by the segments that see them was tried and gave no measurable gain)
    return row_order, np.arange(ptr.size - 1, dtype=np.int64)


def normal_cc(arrays, n_c: int, row_order=None) -> np.ndarray:
    """``J_cᵀ J_c`` (dense ``n_c × n_c``) of a row-compressed Jacobian's ``arrays``."""
    cols = arrays[0]
    if n_c == 0 or cols.shape[0] == 0:
        return np.zeros((n_c, n_c))
    if row_order is None:
        row_order = np.arange(cols.shape[0], dtype=np.int64)
    row_order = np.asarray(row_order, dtype=np.int64)
    nch = _chunks(row_order.size, 10000)
    parts = _normal_cc_kernel(*arrays, row_order, n_c, nch)
    return _symmetrise_upper(parts.sum(axis=0) if nch > 1 else parts[0])


def factored_tiles(fcol: np.ndarray, kf: int, n_c: int):
    """Tiles of the factored columns: ``tile_of[c]`` numbers each distinct item start column c.

    Item t owns the columns ``starts[t] + (0 … kf−1)``; ``tile_of`` is −1 elsewhere. Distinct
    items never share columns, so the tiles of two items are disjoint ``kf × kf`` blocks of S.
    """
    used = np.zeros(n_c + 1, dtype=bool)
    used[fcol.ravel()] = True  # (−1, no item, lands on the extra last entry)
    starts = np.flatnonzero(used[:n_c])
    tile_of = np.full(n_c, -1, dtype=np.int64)
    tile_of[starts] = np.arange(starts.size)
    return tile_of, starts


@njit(cache=True, nogil=True)
def _pair_marks_chunk(ch, step, fcol, order, ptr, tile_of, marks):  # pragma: no cover
    """Chunk ``ch`` of :func:`_pair_marks`: the points ``ch·step … (ch+1)·step − 1`` into
    ``marks[ch]`` (run on the kernels' threads by :func:`~hsgeo._chunks.over_items`).

    Of a point's rows only those whose items differ from the row before count (an
    observation's y row repeats its x row's), and each pair of them once: the marks are set
    in both orders (about a quarter of the pairs of all rows: 0.052 against 0.020 CPU-s on the
    first formation's inputs at the paper's pushbroom block, one thread; the same marks).
    """
    Q = fcol.shape[1]
    mark = marks[ch]
    ds = np.empty(0, dtype=np.int64)
    for i in range(ch * step, min(ptr.size - 1, (ch + 1) * step)):
        n = ptr[i + 1] - ptr[i]
        if n > ds.size:
            ds = np.empty(2 * n, dtype=np.int64)
        nd = 0
        for r1 in range(ptr[i], ptr[i + 1]):
            ra = order[r1]
            if r1 > ptr[i]:
                rp = order[r1 - 1]
                same = True
                for a in range(Q):
                    if fcol[ra, a] != fcol[rp, a]:
                        same = False
                if same:  # the y row after the x row of one observation: nothing new
                    continue
            ds[nd] = ra
            nd += 1
        for x in range(nd):
            ra = ds[x]
            for y in range(x, nd):
                rb = ds[y]
                for a in range(Q):
                    if fcol[ra, a] < 0:
                        continue
                    t = tile_of[fcol[ra, a]]
                    for b in range(Q):
                        if fcol[rb, b] >= 0:
                            u = tile_of[fcol[rb, b]]
                            mark[t, u] = True
                            mark[u, t] = True
    return 0


def _pair_marks(fcol, order, ptr, tile_of, n_tiles):
    """The item pairs ``(t, u)`` that some point's rows couple (both orders): the points in
    chunks on the kernels' threads, their marks joined (one pass on one thread took 0.52 s
    of the main thread's time at 10× the paper's pushbroom block; issue 41).
    """
    n_pts = ptr.size - 1
    n_chunks = _chunks(n_pts, 2000)
    marks = np.zeros((n_chunks, n_tiles, n_tiles), dtype=np.bool_)
    over_items(_pair_marks_chunk, n_pts, n_chunks, fcol, order, ptr, tile_of, marks)
    return marks.any(axis=0)


@njit(cache=True)
def _slot_columns(cols, order, n_c):  # pragma: no cover - compiled
    """The columns that the slots of the rows ``order`` touch."""
    used = np.zeros(n_c, dtype=np.bool_)
    for r in order:
        for s in range(cols.shape[1]):
            if cols[r, s] >= 0:
                used[cols[r, s]] = True
    return used


def schur_pattern(arrays, order, ptr, n_c: int):
    """Where :func:`reduced_points` accumulates: the factored items' tiles and slot columns.

    Returns ``(tile_of, starts, slot_of, slot_t, slot_u, sc_cols, sc_of)``: the items
    (:func:`factored_tiles`); ``slot_of[t, u]`` the slot of the tile of items t and u (−1 if no
    point couples them), numbered row by row, and ``(slot_t, slot_u)`` the items of each slot;
    ``sc_cols`` the slot columns of the rows with a point and ``sc_of[c]`` the position of
    column c among them (−1 if none). One pass over the points' rows; the pattern only changes
    with the rows (the observations kept) or the items they touch.
    """
    cols, _, fcol, _, fd = arrays
    kf = fd.shape[1]
    tile_of, starts = factored_tiles(fcol, kf, n_c)
    n_t = starts.size
    if n_t and order.size:
        mark = _pair_marks(fcol, order, ptr, tile_of, n_t)
    else:
        mark = np.zeros((n_t, n_t), dtype=bool)
    slot_t, slot_u = np.nonzero(mark)  # row-major: consecutive items' slots follow
    slot_of = np.full((n_t, n_t), -1, dtype=np.int64)
    slot_of[slot_t, slot_u] = np.arange(slot_t.size)
    sc_cols = np.flatnonzero(_slot_columns(cols, order, n_c))
    sc_of = np.full(n_c, -1, dtype=np.int64)
    sc_of[sc_cols] = np.arange(sc_cols.size)
    return tile_of, starts, slot_of, slot_t, slot_u, sc_cols, sc_of


def reduced_points(arrays, jp, order, ptr, Vinv, n_c: int, pt_order=None, cache=None) -> np.ndarray:
    """``Σ_i (J_c,iᵀ J_c,i − W_i V_i⁻¹ W_iᵀ)`` (dense ``n_c × n_c``) over the points' rows.

    The kernel accumulates into compact arrays (the tiles of the item pairs that occur, and the
    columns against the slot columns: :func:`schur_pattern`), which are scattered into S here.
    ``cache``: an object whose ``pattern`` attribute keeps the pattern from one call to the
    next (None: computed for this call); a pattern that no longer covers the rows is computed
    again (the kernel counts what falls outside it).
    """
    n_pts = ptr.size - 1
    if n_c == 0 or n_pts == 0:
        return np.zeros((n_c, n_c))
    if pt_order is None:
        pt_order = np.arange(n_pts, dtype=np.int64)
    cols, _, fcol, _, fd = arrays
    kf = fd.shape[1]
    pattern = getattr(cache, "pattern", None)
    fresh = pattern is None
    if fresh:
        pattern = schur_pattern(arrays, order, ptr, n_c)
    tile_of, starts, slot_of, slot_t, slot_u, sc_cols, sc_of = pattern
    max_rows = int(np.max(np.diff(ptr))) if n_pts else 0
    capg = max_rows if fcol.shape[1] else 0
    capc = int(min(n_c, max(1, max_rows * cols.shape[1])))
    nch = _chunks(n_pts, 2000)
    parts, tparts, misses = _reduced_kernel(
        *arrays,
        jp,
        order,
        ptr,
        pt_order,
        Vinv,
        n_c,
        capg,
        capc,
        tile_of,
        slot_of,
        slot_t.size,
        sc_of,
        sc_cols.size,
        nch,
        buffers=getattr(cache, "kernel_out", None),
    )
    if misses:
        if fresh:  # pragma: no cover - the pattern is computed from these very rows
            raise RuntimeError("reduced_points: the Schur pattern does not cover its own rows")
        cache.pattern = None
        return reduced_points(arrays, jp, order, ptr, Vinv, n_c, pt_order, cache)
    if cache is not None:
        cache.pattern = pattern
    return _assemble(parts, tparts, sc_cols, starts, slot_t, slot_u, n_c, kf)


@njit(cache=True)
def _assemble(parts, tparts, sc_cols, starts, slot_t, slot_u, n_c, kf):  # pragma: no cover
    """S = A + Aᵀ from the kernel's compact parts (summed over the chunks in a fixed order):
    the columns against the slot columns, and each slot's ``kf × kf`` tile (row-major) at the
    columns of its two items.
    """
    A = np.zeros((n_c, n_c))
    for ch in range(parts.shape[0]):
        P = parts[ch]
        for r in range(n_c):
            for e in range(sc_cols.size):
                A[r, sc_cols[e]] += P[r, e]
        T = tparts[ch]
        for s in range(slot_t.size):
            r0 = starts[slot_t[s]]
            c0 = starts[slot_u[s]]
            for j in range(kf):
                for l in range(kf):
                    A[r0 + j, c0 + l] += T[(s * kf + j) * kf + l]
    # A + Aᵀ in place, in tiles of 64 × 64 (as _symmetrise_upper), the diagonal doubled
    for r in range(n_c):
        A[r, r] = A[r, r] + A[r, r]
    return _symmetrise_upper(A)


@njit(cache=True, nogil=True)
def _point_cov_chunk(
    ch, step, cols, vals, fcol, fw, fd, jp, order, ptr, points, Vinv, S_inv, cap, out
):  # pragma: no cover
    """V_i⁻¹ + V_i⁻¹ W_iᵀ S⁻¹ W_i V_i⁻¹ for the points ``points[ch·step : (ch+1)·step]``, on
    each point's local columns, into ``out`` (chunks on the kernels' threads,
    :func:`~hsgeo._chunks.over_chunks`: numba's parallel passes over a ``prange`` loop cost
    8 s of compile time on a fresh cache, issue 41).
    """
    K = cols.shape[1] + fcol.shape[1] * fd.shape[1]
    p = jp.shape[1]
    n_c = S_inv.shape[0]
    n = points.size
    pos = np.full(n_c, -1, dtype=np.int64)
    cl = np.empty(cap, dtype=np.int64)
    Z = np.zeros((p, cap))
    A = np.zeros((p, cap))
    rc = np.empty(K, dtype=np.int64)
    rv = np.empty(K)
    for q in range(ch * step, min(n, (ch + 1) * step)):
        i = points[q]
        nl = 0
        for rr in range(ptr[i], ptr[i + 1]):
            r = order[rr]
            ne = _expand_row(r, cols, vals, fcol, fw, fd, rc, rv)
            for s in range(ne):
                c = rc[s]
                if pos[c] < 0:
                    pos[c] = nl
                    cl[nl] = c
                    for k in range(p):
                        Z[k, nl] = 0.0
                    nl += 1
                la = pos[c]
                for k in range(p):
                    Z[k, la] += rv[s] * jp[r, k]
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


def point_covariance(arrays, jp, order, ptr, points, Vinv, S_inv) -> np.ndarray:
    """Unscaled covariance ``V⁻¹ + V⁻¹ Wᵀ S⁻¹ W V⁻¹`` of the listed points, ``(n, p, p)``."""
    points = np.asarray(points, dtype=np.int64)
    if points.size == 0:
        return np.zeros((0, jp.shape[1], jp.shape[1]))
    cols, _, fcol, _, fd = arrays
    max_rows = int(np.max(np.diff(ptr)[points]))
    width = cols.shape[1] + fcol.shape[1] * fd.shape[1]
    cap = int(min(S_inv.shape[0], max(1, max_rows * width)))
    p = jp.shape[1]
    out = np.zeros((points.size, p, p))
    over_items(
        _point_cov_chunk,
        points.size,
        min(points.size, 64),
        *arrays,
        jp,
        order,
        ptr,
        points,
        Vinv,
        S_inv,
        cap,
        out,
    )
    return out


@njit(cache=True, parallel=True)
def rmatvec_diag(cols, vals, fcol, fw, fd, y, n_c, want_diag):  # pragma: no cover - compiled
    """``Jᵀ y`` and (optionally) ``diag(JᵀJ)`` of a row-compressed matrix, in one pass."""
    M, K = cols.shape
    n_chunks = 8 if M > 80000 else 1
    gs = np.zeros((n_chunks, n_c))
    ds = np.zeros((n_chunks, n_c))
    step = (M + n_chunks - 1) // n_chunks
    for ch in prange(n_chunks):
        _rmatvec_rows(
            cols,
            vals,
            fcol,
            fw,
            fd,
            y,
            want_diag,
            ch * step,
            min(M, (ch + 1) * step),
            gs[ch],
            ds[ch],
        )
    g = gs[0].copy()
    d = ds[0].copy()
    for ch in range(1, n_chunks):  # fixed order: the same bits for any thread count
        g += gs[ch]
        d += ds[ch]
    return g, d


@njit(cache=True, inline="always")
def _rmatvec_rows(cols, vals, fcol, fw, fd, y, want_diag, i0, i1, g, d):  # pragma: no cover
    K = cols.shape[1]
    Q, kf = fcol.shape[1], fd.shape[1]
    for i in range(i0, i1):
        yi = y[i]
        for s in range(K):
            c = cols[i, s]
            if c >= 0:
                v = vals[i, s]
                g[c] += v * yi
                if want_diag:
                    d[c] += v * v
        for a in range(Q):
            c0 = fcol[i, a]
            if c0 >= 0:
                wa = fw[i, a]
                for j in range(kf):
                    v = wa * fd[i, j]
                    g[c0 + j] += v * yi
                    if want_diag:
                        d[c0 + j] += v * v


@njit(cache=True, inline="always")
def _row_dot(cols, vals, fcol, fw, fd, x, i):  # pragma: no cover - compiled
    """Row ``i`` of ``J x`` (its slots, then its factored groups)."""
    acc = 0.0
    for s in range(cols.shape[1]):
        c = cols[i, s]
        if c >= 0:
            acc += vals[i, s] * x[c]
    for a in range(fcol.shape[1]):
        c0 = fcol[i, a]
        if c0 >= 0:
            t = 0.0
            for j in range(fd.shape[1]):
                t += fd[i, j] * x[c0 + j]
            acc += fw[i, a] * t
    return acc


@njit(cache=True, parallel=True)
def matvec(cols, vals, fcol, fw, fd, x):  # pragma: no cover - compiled
    """``J x`` of a row-compressed matrix."""
    M = cols.shape[0]
    out = np.zeros(M)
    for i in prange(M):
        out[i] = _row_dot(cols, vals, fcol, fw, fd, x, i)
    return out


@njit(cache=True, parallel=True)
def point_rows_dot(jp, pidx, y):  # pragma: no cover - compiled
    """``u_i = J_p,i · y[pidx_i]`` (0 for rows without a point): ``J_p y`` row by row."""
    M, p = jp.shape
    u = np.zeros(M)
    for i in prange(M):
        q = pidx[i]
        if q >= 0:
            acc = 0.0
            for k in range(p):
                acc += jp[i, k] * y[q, k]
            u[i] = acc
    return u


@njit(cache=True, parallel=True)
def point_leverage(jp, pidx, Vinv):  # pragma: no cover - compiled
    """``h_i = J_p,iᵀ V⁻¹ J_p,i`` of each row on its point (0 for rows without a point)."""
    M, p = jp.shape
    h = np.zeros(M)
    for i in prange(M):
        q = pidx[i]
        if q >= 0:
            acc = 0.0
            for j in range(p):
                t = 0.0
                for k in range(p):
                    t += Vinv[q, j, k] * jp[i, k]
                acc += jp[i, j] * t
            h[i] = acc
    return h


@njit(cache=True)
def rows_by_point(pidx, n_pts):  # pragma: no cover - compiled
    """``(order, ptr)``: the rows with a point (``pidx ≥ 0``) grouped by point, each point's
    in row order (the rows of point i are ``order[ptr[i]:ptr[i + 1]]``); numpy's stable
    argsort of the rows' points and the cumulative sum of their counts, by counting: two
    passes over the rows instead of a sort (at the paper's pushbroom size 0.0026 against
    0.073 CPU-s for rows in random order; tests/test_engine_serial_passes.py).
    """
    ptr = np.zeros(n_pts + 1, dtype=np.int64)
    for r in range(pidx.size):
        if pidx[r] >= n_pts:
            raise ValueError("a row's point index is not below the number of points")
        if pidx[r] >= 0:
            ptr[pidx[r] + 1] += 1
    for i in range(n_pts):
        ptr[i + 1] += ptr[i]
    pos = ptr[:-1].copy()
    order = np.empty(ptr[n_pts], dtype=np.int64)
    for r in range(pidx.size):
        i = pidx[r]
        if i >= 0:
            order[pos[i]] = r
            pos[i] += 1
    return order, ptr


@njit(cache=True)
def scatter_points(jp, pidx, u, n_pts):  # pragma: no cover - compiled
    """``J_pᵀ u`` as ``(n_pts, p)``: row i adds ``u_i J_p,i`` to its point."""
    M, p = jp.shape
    out = np.zeros((n_pts, p))
    for i in range(M):
        q = pidx[i]
        if q >= 0:
            for k in range(p):
                out[q, k] += u[i] * jp[i, k]
    return out


@njit(cache=True)
def kept_whitened(r, sigma, keep, out):  # pragma: no cover - compiled
    """``out[:n] = (r · (1/σ))[keep]``, ``n`` the kept rows, in one pass: the products of
    numpy's ``r * (1.0 / sigma)``, bit for bit (see ``system._residuals_only``).
    """
    t = 0
    for i in range(r.size):
        if keep[i]:
            out[t] = r[i] * (1.0 / sigma[i])
            t += 1


@njit(cache=True, parallel=True)
def matvec_points(cols, vals, fcol, fw, fd, x, jp, pidx, y):  # pragma: no cover - compiled
    """``J_c x + J_p y`` row by row in one pass: :func:`matvec` plus :func:`point_rows_dot`,
    the same sums added (bit for bit), without the two vectors and their sum as new arrays.
    """
    M = cols.shape[0]
    p = jp.shape[1]
    out = np.zeros(M)
    for i in prange(M):
        acc = _row_dot(cols, vals, fcol, fw, fd, x, i)
        q = pidx[i]
        u = 0.0
        if q >= 0:
            for k in range(p):
                u += jp[i, k] * y[q, k]
        out[i] = acc + u
    return out


@njit(cache=True, parallel=True)
def subtract_point_rows(u, jp, pidx, y, held):  # pragma: no cover - compiled
    """``u_i −= J_p,i · y[pidx_i]`` for the rows of the points ``held`` (a mask), in place:
    ``u − point_rows_dot(jp, pidx, y)`` bit for bit when ``y`` is zero at every other point,
    without a pass over their rows' derivatives.
    """
    p = jp.shape[1]
    for i in prange(pidx.size):
        q = pidx[i]
        if q >= 0 and held[q]:
            acc = 0.0
            for k in range(p):
                acc += jp[i, k] * y[q, k]
            u[i] -= acc


@njit(cache=True, parallel=True)
def point_blocks_doubt(V, thresh):  # pragma: no cover - compiled
    """For 3 × 3 point blocks ``V``: ``bad`` (a zero diagonal entry), ``doubt`` (the others
    whose unit-diagonal scaled determinant is not ``≥ thresh``: their eigenvalues decide) and
    the scales ``dv = √max(diag V, 0)`` (1 where 0), as ``datum._undetermined_points`` forms
    them with numpy (the scaled entries ``V_ij / dv_i / dv_j`` the same; the determinant by
    cofactors, not LU: the two differ by rounding, ~1e-16, far below the threshold,
    ``27 rank_rtol`` = 2.7e-10 by default).
    """
    n = V.shape[0]
    bad = np.zeros(n, dtype=np.bool_)
    doubt = np.zeros(n, dtype=np.bool_)
    dv = np.empty((n, 3))
    for q in prange(n):
        zero = False
        for k in range(3):
            d = np.sqrt(max(V[q, k, k], 0.0))
            if d == 0.0:
                zero = True
                d = 1.0
            dv[q, k] = d
        if zero:
            bad[q] = True
            continue
        a = V[q, 0, 0] / dv[q, 0] / dv[q, 0]
        b = V[q, 0, 1] / dv[q, 0] / dv[q, 1]
        c = V[q, 0, 2] / dv[q, 0] / dv[q, 2]
        d_ = V[q, 1, 0] / dv[q, 1] / dv[q, 0]
        e = V[q, 1, 1] / dv[q, 1] / dv[q, 1]
        f = V[q, 1, 2] / dv[q, 1] / dv[q, 2]
        g = V[q, 2, 0] / dv[q, 2] / dv[q, 0]
        h = V[q, 2, 1] / dv[q, 2] / dv[q, 1]
        k_ = V[q, 2, 2] / dv[q, 2] / dv[q, 2]
        det = a * (e * k_ - f * h) - b * (d_ * k_ - f * g) + c * (d_ * h - e * g)
        doubt[q] = not det >= thresh
    return bad, doubt, dv


@njit(cache=True, parallel=True)
def standardised(r, h):  # pragma: no cover - compiled
    """``|r| / √max(1 − h, 0.01)`` (``|r|`` if ``h`` is empty): numpy's values of that
    expression in one pass (the outlier test, :func:`hsgeo.adjust.robust._reject`).
    """
    out = np.empty(r.size)
    if h.size == 0:
        for i in prange(r.size):
            out[i] = abs(r[i])
    else:
        for i in prange(r.size):
            out[i] = abs(r[i]) / np.sqrt(max(1.0 - h[i], 1e-2))
    return out


@njit(cache=True)
def group_scores(r_kept, keep, g):  # pragma: no cover - compiled
    """Per group of ``g`` rows of a block, the largest of its kept rows' scores (0 if none is
    kept); ``r_kept`` holds the kept rows' scores in order, ``keep`` the block's row mask.
    """
    m = keep.size
    out = np.zeros(m // g)
    t = 0
    for i in range(m):
        if keep[i]:
            v = r_kept[t]
            t += 1
            j = i // g
            if v > out[j]:
                out[j] = v
    return out


@njit(cache=True)
def point_excess(r_trial, r, u, pidx, n_pts):  # pragma: no cover - compiled
    """Per point, the sum over its rows of ``r_trial² − (r + u)²``: the excess of the actual
    over the linearly predicted squared residual of a step (``u = J h``), rows without a point
    left out. The values of numpy's ``np.bincount(pidx[rows], weights=r_trial[rows] ** 2 −
    (r[rows] + u[rows]) ** 2)`` (the same products, summed in row order) in one pass without
    the gathered copies: at 10× the paper's pushbroom block they and the bincount took 0.62
    of the 1.33 s that ``_hold_points`` spent on the main thread over the solve's 3 calls
    (py-spy samples; issue 41).
    """
    out = np.zeros(n_pts)
    for i in range(pidx.size):
        q = pidx[i]
        if q >= 0:
            a = r_trial[i]
            b = r[i] + u[i]
            out[q] += a * a - b * b
    return out


# ----------------------------------------------------------------------------------------------
# Filling the row-compressed arrays from the residual blocks' Jacobians (system._Slots)
# ``rows[t]`` is the block row written to destination row t; ``w`` the whitening weights 1/σ;
# ``cm`` the block's column map (-1: fixed entry, written as an empty slot).
# ----------------------------------------------------------------------------------------------
@njit(cache=True, parallel=True)
def fill_indexed(index, d, rows, w, cm, cols_dst, vals_dst):  # pragma: no cover - compiled
    """Slots of an ``Indexed(index (m, q), d (m, q, k))`` Jacobian."""
    q = index.shape[1]
    k = d.shape[2]
    for t in prange(rows.size):
        i = rows[t]
        wi = w[i]
        for a in range(q):
            it = index[i, a]
            for j in range(k):
                c = cm[it * k + j] if it >= 0 else -1
                cols_dst[t, a * k + j] = c
                vals_dst[t, a * k + j] = d[i, a, j] * wi if c >= 0 else 0.0


@njit(cache=True, parallel=True)
def fill_dense(J, rows, w, cm, cols_dst, vals_dst):  # pragma: no cover - compiled
    """Slots of a dense ``(m, size)`` Jacobian."""
    k = J.shape[1]
    for t in prange(rows.size):
        i = rows[t]
        wi = w[i]
        for j in range(k):
            c = cm[j]
            cols_dst[t, j] = c
            vals_dst[t, j] = J[i, j] * wi if c >= 0 else 0.0


@njit(cache=True, parallel=True)
def fill_factored(
    index, weights, d, rows, w, c0, fcol_dst, fw_dst, fd_dst
):  # pragma: no cover - compiled
    """The factored group of ``Indexed(index (m, q), d (m, k), weights (m, q))``."""
    q = index.shape[1]
    k = d.shape[1]
    for t in prange(rows.size):
        i = rows[t]
        for a in range(q):
            it = index[i, a]
            fcol_dst[t, a] = c0 + it * k if it >= 0 else -1
            fw_dst[t, a] = weights[i, a] if it >= 0 else 0.0
        wi = w[i]
        for j in range(k):
            fd_dst[t, j] = d[i, j] * wi


@njit(cache=True, parallel=True)
def point_normals(order, ptr, jp, r):  # pragma: no cover - compiled
    """``V_i = Σ jpᵀ jp`` and ``g_p,i = Σ jpᵀ r`` over the rows of each point, point by point
    (its rows ``order[ptr[i]:ptr[i + 1]]``, ascending: the sums of a pass over the rows in
    their order, bit for bit, on any number of threads).
    """
    n_pts = ptr.size - 1
    p = jp.shape[1]
    V = np.zeros((n_pts, p, p))
    g = np.zeros((n_pts, p))
    for i in prange(n_pts):
        for s in range(ptr[i], ptr[i + 1]):
            t = order[s]
            for a in range(p):
                ja = jp[t, a]
                g[i, a] += ja * r[t]
                for b in range(p):
                    V[i, a, b] += ja * jp[t, b]
    return V, g


@njit(cache=True, parallel=True)
def inv3(V, rtol):  # pragma: no cover - compiled
    """Inverses of ``(n, 3, 3)`` blocks by cofactors; ``ok`` False where (nearly) singular:
    unless the determinant of the unit-diagonal scaled block is at least ``27·rtol``, which
    proves its smallest eigenvalue at least ``rtol`` times its largest (those blocks are left
    to an eigendecomposition, see ``schur._inv_blocks``).
    """
    n = V.shape[0]
    out = np.zeros_like(V)
    ok = np.zeros(n, dtype=np.bool_)
    for i in prange(n):
        a, b, c = V[i, 0, 0], V[i, 0, 1], V[i, 0, 2]
        d, e, f = V[i, 1, 0], V[i, 1, 1], V[i, 1, 2]
        g, h, k = V[i, 2, 0], V[i, 2, 1], V[i, 2, 2]
        A = e * k - f * h
        B = f * g - d * k
        C = d * h - e * g
        det = a * A + b * B + c * C
        if not (a > 0.0 and e > 0.0 and k > 0.0 and det >= 27.0 * rtol * (a * e * k)):
            continue
        ok[i] = True
        r = 1.0 / det
        out[i, 0, 0] = A * r
        out[i, 0, 1] = (c * h - b * k) * r
        out[i, 0, 2] = (b * f - c * e) * r
        out[i, 1, 0] = B * r
        out[i, 1, 1] = (a * k - c * g) * r
        out[i, 1, 2] = (c * d - a * f) * r
        out[i, 2, 0] = C * r
        out[i, 2, 1] = (b * g - a * h) * r
        out[i, 2, 2] = (a * e - b * d) * r
    return out, ok
