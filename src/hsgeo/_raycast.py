"""The ray–terrain intersection: the FIRST crossing of a ray with a bilinear height grid.

One intersection for every geocoding command and every simulator's renderer (GUIDE §2,
:func:`hsgeo.geocode.intersect` is its face). A terrain on a regular grid (heights ``z[i, j]`` at
``E = e0 + j·de``, ``N = n0 + i·dn``, bilinear in each cell, as
:class:`hsgeo.geocode.DemTerrain` and GDAL's bilinear resampling read it) is a surface that is
exactly a quadratic in the ray parameter ``s`` inside each cell: with ``u, v`` the position in
the cell and ``h = a + b u + c v + d u v``, the height of the ray above the surface along the
ray is ``f(t) = A + B t + C t²``. :func:`first_crossing` walks the cells the ray passes over in
order (Amanatides & Woo's grid traversal, on two levels: blocks of ``block`` cells whose
highest node the ray may pass above whole, then the cells of a block it does not) and returns
the smallest root of the quadratic in the first cell where there is one. No step size, no
tolerance: the first crossing to rounding (≈ 1e-12 m), however steep the wall, however wide the
angle, and a ray that grazes a roof's corner is occluded by it. (The one margin: each ray is
followed :data:`FLOOR_MARGIN` of its heights under the grid's lowest node, so that a crossing AT
the lowest height, a flat DSM or a lake, is not lost to the rounding of the ray's height there.)

:func:`first_crossing_reference` is the numpy reference: a dense march down the ray and a
bisection of the first bracket (any ``height(E, N)``; it misses a dip of the ray under the
surface shorter than its step, which the tests keep larger). Tests compare the two and both
against a dense sampling of the ray.

The traversal is inlined (``inline="always"``) into the kernels that call it: a plain call per
ray cost the LP renderer ~30 % more CPU (measured, ``bench/bench_intersect.py``); the results
of the inlined and called forms were the same.

Status codes of the kernels: :data:`HIT`, :data:`OUTSIDE` (the ray leaves the grid, or enters it
below its surface, before it meets the surface), :data:`BELOW` (the ray's origin is under the
surface).

References
----------
Amanatides, J., Woo, A. (1987). A fast voxel traversal algorithm for ray tracing. Eurographics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from hsgeo._chunks import over_items

__all__ = [
    "HIT",
    "OUTSIDE",
    "BELOW",
    "GridSurface",
    "first_crossing",
    "first_crossing_rows",
    "cast_chords",
    "bilinear",
    "first_crossing_reference",
    "FLOOR_MARGIN",
]

HIT, OUTSIDE, BELOW = 0, 1, 2
_INF = np.inf


@dataclass(frozen=True, eq=False)
class GridSurface:
    """Heights on a regular grid, prepared for :func:`first_crossing`.

    Attributes
    ----------
    z : (n_rows, n_cols) float64 ndarray, m
        Heights; row ``i`` at ``N = n0_m + i·dn_m``, column ``j`` at ``E = e0_m + j·de_m``
        (rows northward, columns eastward; ``de_m, dn_m > 0``).
    e0_m, n0_m, de_m, dn_m : float, m
    block : int
        Cells per block of :attr:`block_max`.
    block_max : (n_block_rows, n_block_cols) float64 ndarray, m
        The highest node of each block of ``block × block`` cells (its far edges included).
    z_min, z_max : float, m
    """

    z: np.ndarray
    e0_m: float
    n0_m: float
    de_m: float
    dn_m: float
    block: int
    block_max: np.ndarray
    z_min: float
    z_max: float

    @classmethod
    def from_heights(cls, z, e0_m, n0_m, de_m, dn_m, block: int = 8) -> GridSurface:
        """The surface of heights ``z`` (rows northward) with its block maxima."""
        z = np.ascontiguousarray(z, dtype=np.float64)
        nr, nc = z.shape
        if nr < 2 or nc < 2:
            raise ValueError(f"a height grid needs at least 2 x 2 nodes, got {z.shape}")
        # cells of block (I, J): rows I·B … I·B+B-1, nodes I·B … I·B+B (the far edge included)
        nbr, nbc = -(-(nr - 1) // block), -(-(nc - 1) // block)
        zp = np.pad(z, ((0, nbr * block + 1 - nr), (0, nbc * block + 1 - nc)), mode="edge")
        core = zp[:-1, :-1].reshape(nbr, block, nbc, block).max(axis=(1, 3))
        far_r = zp[block::block, :-1].reshape(nbr, nbc, block).max(axis=2)  # row I·B+B
        far_c = zp[:-1, block::block].reshape(nbr, block, nbc).max(axis=1)  # column J·B+B
        corner = zp[block::block, block::block]
        bmax = np.maximum(np.maximum(core, far_r), np.maximum(far_c, corner))
        return cls(
            z,
            float(e0_m),
            float(n0_m),
            float(de_m),
            float(dn_m),
            int(block),
            np.ascontiguousarray(bmax),
            float(z.min()),
            float(z.max()),
        )

    def args(self) -> tuple:
        """The kernels' grid arguments, in their order."""
        return (
            self.z,
            self.e0_m,
            self.n0_m,
            self.de_m,
            self.dn_m,
            self.block_max,
            self.block,
            self.z_min,
            self.z_max,
        )


# ------------------------------------------------------------------------------ compiled cores
@njit(cache=True, inline="always")
def bilinear(z, x, y):  # pragma: no cover - compiled
    """Bilinear height at grid coordinates (column ``x``, row ``y``), clamped to the grid."""
    nr, nc = z.shape
    x = min(max(x, 0.0), nc - 1.0)
    y = min(max(y, 0.0), nr - 1.0)
    j = min(int(x), nc - 2)
    i = min(int(y), nr - 2)
    u = x - j
    v = y - i
    return (1.0 - v) * ((1.0 - u) * z[i, j] + u * z[i, j + 1]) + v * (
        (1.0 - u) * z[i + 1, j] + u * z[i + 1, j + 1]
    )


@njit(cache=True, inline="always")
def _cell_root(c00, c01, c10, c11, i, j, px, py, oz, qx, qy, dz, sa, sb):  # pragma: no cover
    """Smallest ``s`` in ``[sa, sb]`` where the ray meets the bilinear patch of cell (i, j)
    (corner heights ``c00 = z[i, j]``, ``c01 = z[i, j + 1]``, ``c10 = z[i + 1, j]``,
    ``c11 = z[i + 1, j + 1]``; -1 if none): the root of ``f(t) = A + B t + C t²``, ``t = s − sa``.
    """
    b = c01 - c00
    c = c10 - c00
    d = c00 - c01 - c10 + c11
    ua = px + sa * qx - j
    va = py + sa * qy - i
    A = oz + sa * dz - (c00 + b * ua + c * va + d * ua * va)
    if A <= 0.0:
        return sa
    B = dz - (b + d * va) * qx - (c + d * ua) * qy
    C = -d * qx * qy
    T = sb - sa
    t = _INF
    if C == 0.0:
        if B < 0.0:
            t = -A / B
    else:
        disc = B * B - 4.0 * A * C
        if disc >= 0.0:
            q = -0.5 * (B + np.copysign(np.sqrt(disc), B))
            if q != 0.0:
                r1 = q / C
                r2 = A / q
                if 0.0 <= r1 < t:
                    t = r1
                if 0.0 <= r2 < t:
                    t = r2
    if t <= T:
        return sa + t
    if A + T * (B + C * T) <= 0.0:  # a root at the segment's end, lost to rounding
        return sb
    return -1.0


@njit(cache=True, inline="always")
def _exit(p, q, iq, k):  # pragma: no cover - compiled
    """Ray parameter where the coordinate ``p + s q`` leaves the interval ``[k, k + 1]``
    (``iq = 1 / q``).
    """
    if q > 0.0:
        return (k + 1 - p) * iq
    if q < 0.0:
        return (k - p) * iq
    return _INF


@njit(cache=True, inline="always")
def _index(p, q, s, lo, hi):  # pragma: no cover - compiled
    """Index of the interval ``[k, k + 1]`` that ``p + s q`` enters at ``s``, in ``[lo, hi]``."""
    x = p + s * q
    k = int(np.floor(x))
    if q < 0.0 and x == k:
        k -= 1
    return min(max(k, lo), hi)


#: The floor of a ray's traversal lies this share of the largest height magnitude (at least
#: 1 m) under the grid's lowest node: ≈ 4,500 times float64's rounding of those heights, 1e-12
#: m at heights of 1 m, 1e-8 m at 10 km.
FLOOR_MARGIN = 1e-12


@njit(cache=True, inline="always")
def _floor_margin(oz, zmin):  # pragma: no cover - compiled
    """How far under the lowest node ``zmin`` a ray from height ``oz`` is followed, m."""
    return FLOOR_MARGIN * max(1.0, abs(oz), abs(zmin))


@njit(cache=True, inline="always")
def first_crossing(
    ox, oy, oz, dx, dy, dz, z, e0, n0, de, dn, bmax, blk, zmin, zmax
):  # pragma: no cover - compiled
    """The first crossing of the ray ``O + s D`` with the bilinear surface of a height grid.

    Parameters
    ----------
    ox, oy, oz : float, m
        Ray origin (E, N, U).
    dx, dy, dz : float
        Ray direction (any length, ``dz < 0``).
    z, e0, n0, de, dn, bmax, blk, zmin, zmax
        The grid (:meth:`GridSurface.args`).

    Returns
    -------
    s : float
        Ray parameter of the crossing (NaN unless :data:`HIT`).
    status : int
        :data:`HIT`, :data:`OUTSIDE` or :data:`BELOW`.
    """
    nr, nc = z.shape
    px = (ox - e0) / de
    py = (oy - n0) / dn
    qx = dx / de
    qy = dy / dn
    # the heights the surface spans: from where the ray is at its top to where it is at its floor
    s0 = 0.0 if oz <= zmax else (zmax - oz) / dz
    if (zmin - oz) / dz < 0.0:  # the origin is under the lowest node
        over = 0.0 <= px <= nc - 1.0 and 0.0 <= py <= nr - 1.0
        return np.nan, BELOW if over else OUTSIDE
    # the floor a rounding margin under the lowest node: a crossing AT the lowest height (a flat
    # DSM, a lake at its lowest) is where ``oz + s dz`` rounds to either side of zmin, and a
    # floor at zmin itself lost such rays as OUTSIDE (every ray of a flat DSM at 0.3 m;
    # tests/test_raycast_flat.py); the crossing found is the cell's root, not the floor, so a
    # ray that met the surface before meets it at the same s (but one within rounding of the
    # old floor, which was returned as the floor itself)
    s1 = (zmin - _floor_margin(oz, zmin) - oz) / dz
    # the part of the ray over the grid (slabs)
    lo, hi = s0, s1
    if qx == 0.0:
        if px < 0.0 or px > nc - 1.0:
            return np.nan, OUTSIDE
    else:
        a = -px / qx
        b = (nc - 1.0 - px) / qx
        lo = max(lo, min(a, b))
        hi = min(hi, max(a, b))
    if qy == 0.0:
        if py < 0.0 or py > nr - 1.0:
            return np.nan, OUTSIDE
    else:
        a = -py / qy
        b = (nr - 1.0 - py) / qy
        lo = max(lo, min(a, b))
        hi = min(hi, max(a, b))
    if lo > hi:
        return np.nan, OUTSIDE
    if lo == 0.0 or lo > s0:  # (at lo == s0 > 0 the ray is at the top: above the surface)
        f_lo = oz + lo * dz - bilinear(z, px + lo * qx, py + lo * qy)
        if f_lo < 0.0:
            if lo == 0.0:
                return np.nan, BELOW
            return np.nan, OUTSIDE  # entered the grid through its edge, under the surface
    nbr, nbc = bmax.shape
    # blocks
    bpx = px / blk
    bpy = py / blk
    bqx = qx / blk
    bqy = qy / blk
    iqx = 1.0 / qx if qx != 0.0 else _INF
    iqy = 1.0 / qy if qy != 0.0 else _INF
    J = _index(bpx, bqx, lo, 0, nbc - 1)
    I = _index(bpy, bqy, lo, 0, nbr - 1)
    sa = lo
    while True:
        sxe = _exit(bpx, bqx, iqx * blk, J)
        sye = _exit(bpy, bqy, iqy * blk, I)
        se = min(sxe, sye, hi)
        if oz + se * dz <= bmax[I, J]:  # the ray may meet a cell of this block
            s = _block_cells(z, I, J, blk, px, py, oz, qx, qy, iqx, iqy, dz, sa, se)
            if s >= 0.0:
                return s, HIT
        if se >= hi:
            break
        if sxe <= sye:
            J += 1 if bqx > 0.0 else -1
        if sye <= sxe:
            I += 1 if bqy > 0.0 else -1
        if J < 0 or J >= nbc or I < 0 or I >= nbr:
            break
        sa = se
    return np.nan, OUTSIDE


@njit(cache=True, inline="always")
def _block_cells(z, I, J, blk, px, py, oz, qx, qy, iqx, iqy, dz, sa, se):  # pragma: no cover
    """The first crossing in the cells of block (I, J) between ``sa`` and ``se`` (-1: none)."""
    nr, nc = z.shape
    j_lo = J * blk
    j_hi = min(j_lo + blk, nc - 1) - 1
    i_lo = I * blk
    i_hi = min(i_lo + blk, nr - 1) - 1
    j = _index(px, qx, sa, j_lo, j_hi)
    i = _index(py, qy, sa, i_lo, i_hi)
    while True:
        sxe = _exit(px, qx, iqx, j)
        sye = _exit(py, qy, iqy, i)
        sb = min(sxe, sye, se)
        c00 = z[i, j]
        c01 = z[i, j + 1]
        c10 = z[i + 1, j]
        c11 = z[i + 1, j + 1]
        if oz + sb * dz <= max(max(c00, c01), max(c10, c11)):
            s = _cell_root(c00, c01, c10, c11, i, j, px, py, oz, qx, qy, dz, sa, sb)
            if s >= 0.0:
                return s
        if sb >= se:
            return -1.0
        if sxe <= sye:
            j += 1 if qx > 0.0 else -1
        if sye <= sxe:
            i += 1 if qy > 0.0 else -1
        if j < j_lo or j > j_hi or i < i_lo or i > i_hi:
            return -1.0
        sa = sb


#: Rays below which :func:`first_crossing_rows` runs on one thread: numba's parallel loop costs
#: more CPU than it saves there (measured, CPU time per ray on 2 cores: 2,300 rays 1.4–3.5 µs in
#: parallel vs 64–93 ns on one thread; 230,400 rays, a line block of the orthomosaic, 102–106
#: vs 70–90 ns), and Dask already runs the blocks' tasks side by side.
PARALLEL_MIN_RAYS = 1 << 20


def first_crossing_rows(O, D, z, e0, n0, de, dn, bmax, blk, zmin, zmax, s, status):
    """:func:`first_crossing` of rays ``O[k] + s D[k]`` ((n, 3) each) into ``s``, ``status``:
    on one thread below :data:`PARALLEL_MIN_RAYS` rays, else in 64 chunks on the kernels'
    threads (:func:`hsgeo._chunks.over_chunks`; the same values). One compiled function
    serves both: a serial loop and a ``prange`` loop around the inlined crossing were two
    compilations of it, 9.6 and 11.7 s on a fresh cache (issue 41).
    """
    n = O.shape[0]
    n_chunks = 64 if n >= PARALLEL_MIN_RAYS else 1
    over_items(_rows_chunk, n, n_chunks, O, D, z, e0, n0, de, dn, bmax, blk, zmin, zmax, s, status)


@njit(cache=True, nogil=True)
def _rows_chunk(
    ch, step, O, D, z, e0, n0, de, dn, bmax, blk, zmin, zmax, s, status
):  # pragma: no cover
    for k in range(ch * step, min(O.shape[0], (ch + 1) * step)):
        s[k], status[k] = first_crossing(
            O[k, 0], O[k, 1], O[k, 2], D[k, 0], D[k, 1], D[k, 2], z, e0, n0, de, dn, bmax, blk,
            zmin, zmax,
        )  # fmt: skip


def cast_chords(O, d, u_top, u_bottom, to_map, to_enu, surface: GridSurface):
    """The first crossing of rays with a DSM on a map CRS's grid, by their chords (compiled
    arithmetic around the caller's CRS transforms; :func:`hsgeo.geocode.intersect`).

    Each ray's chord between local heights ``u_top`` and ``u_bottom`` (from the ray's own
    origin where that is under ``u_top``) goes to the map CRS (``to_map``, ENU columns → x, y,
    h columns), is cast on ``surface``, and the crossing comes back (``to_enu``) and is taken
    to the nearest point of the ray: the numbers of the numpy steps this replaces, in the same
    order (bit for bit), without their temporaries.

    Returns
    -------
    X : (n, 3) ndarray
        Crossings (E, N, U), NaN where the status is not :data:`HIT`.
    status : (n,) int8 ndarray
    """
    O = np.ascontiguousarray(O, dtype=np.float64)
    d = np.ascontiguousarray(d, dtype=np.float64)
    n = O.shape[0]
    ends = _chord_ends(
        O,
        d,
        np.ascontiguousarray(np.broadcast_to(u_top, (n,)), dtype=np.float64),
        np.ascontiguousarray(np.broadcast_to(u_bottom, (n,)), dtype=np.float64),
    )
    m0 = [np.asarray(v, np.float64) for v in to_map(ends[0], ends[1], ends[2])]
    m1 = [np.asarray(v, np.float64) for v in to_map(ends[3], ends[4], ends[5])]
    A, B = _chord_rows(*m0, *m1)
    s = np.empty(n)
    status = np.empty(n, np.int8)
    X = np.full((n, 3), np.nan)
    if n:
        first_crossing_rows(A, B, *surface.args(), s, status)
    idx = np.flatnonzero(status == HIT)
    if idx.size:
        Mh = _along(A, B, s, idx)
        E, N, U = (np.ascontiguousarray(v, np.float64) for v in to_enu(Mh[0], Mh[1], Mh[2]))
        _onto_rays(O, d, idx, E, N, U, X)
    return X, status


@njit(cache=True)
def _chord_ends(O, d, u_top, u_bottom):  # pragma: no cover - compiled
    """(6, n): x, y, z of the chords' top ends, then of their bottom ends."""
    n = O.shape[0]
    P = np.empty((6, n))
    for k in range(n):
        a = (u_top[k] - O[k, 2]) / d[k, 2]
        b = (u_bottom[k] - O[k, 2]) / d[k, 2]
        above = O[k, 2] > u_top[k]
        for j in range(3):
            P[j, k] = O[k, j] + a * d[k, j] if above else O[k, j]
            P[3 + j, k] = O[k, j] + b * d[k, j]
    return P


@njit(cache=True)
def _chord_rows(x0, y0, z0, x1, y1, z1):  # pragma: no cover - compiled
    """The chords as rays: origins ``(n, 3)`` and directions (end − origin)."""
    n = x0.size
    A = np.empty((n, 3))
    B = np.empty((n, 3))
    for k in range(n):
        A[k, 0], A[k, 1], A[k, 2] = x0[k], y0[k], z0[k]
        B[k, 0], B[k, 1], B[k, 2] = x1[k] - x0[k], y1[k] - y0[k], z1[k] - z0[k]
    return A, B


@njit(cache=True)
def _along(A, B, s, idx):  # pragma: no cover - compiled
    """(3, m): the chords' points ``A + s B`` of rows ``idx``."""
    M = np.empty((3, idx.size))
    for i in range(idx.size):
        k = idx[i]
        for j in range(3):
            M[j, i] = A[k, j] + s[k] * B[k, j]
    return M


@njit(cache=True)
def _onto_rays(O, d, idx, E, N, U, X):  # pragma: no cover - compiled
    """Rows ``idx`` of ``X``: the nearest point of each ray to (E, N, U)."""
    for i in range(idx.size):
        k = idx[i]
        q0, q1, q2 = E[i] - O[k, 0], N[i] - O[k, 1], U[i] - O[k, 2]
        # summed as numpy's einsum("ij,ij->i") did before (its two SIMD lanes: 0 + 2, then 1)
        num = (q0 * d[k, 0] + q2 * d[k, 2]) + q1 * d[k, 1]
        den = (d[k, 0] * d[k, 0] + d[k, 2] * d[k, 2]) + d[k, 1] * d[k, 1]
        t = num / den
        for j in range(3):
            X[k, j] = O[k, j] + t * d[k, j]


# ------------------------------------------------------------------------------ numpy reference
def first_crossing_reference(
    origin_m, direction, height, z_range_m, step_m: float, tol_m: float = 1e-7
):
    """The first crossing by a dense march down each ray and a bisection (numpy reference).

    Parameters
    ----------
    origin_m, direction : (n, 3) ndarray
        Rays (E, N, U; ``direction[:, 2] < 0``).
    height : callable
        ``height(E, N) -> U`` of the surface, NaN where it is unknown (outside the grid).
    z_range_m : (float, float)
        The surface's lowest and highest height, m.
    step_m : float
        The march's step, m, along the ray's horizontal and vertical travel alike: a dip of the
        ray under the surface shorter than it can be missed.
    tol_m : float
        The bisection's end: the bracket's length along the ray, m.

    Returns
    -------
    s : (n,) ndarray
        Ray parameter of the first crossing (NaN: the ray meets no known surface, or its origin
        is under the surface).
    """
    O = np.asarray(origin_m, dtype=float)
    D = np.asarray(direction, dtype=float)
    zmin, zmax = float(z_range_m[0]), float(z_range_m[1])
    s0 = np.where(O[:, 2] > zmax, (zmax - O[:, 2]) / D[:, 2], 0.0)
    s1 = (zmin - O[:, 2]) / D[:, 2]
    ds = step_m / np.maximum(np.hypot(D[:, 0], D[:, 1]), -D[:, 2])
    n_steps = int(np.ceil(np.max((s1 - s0) / ds))) + 1 if O.shape[0] else 0

    def f(s, k):  # the ray's height above the surface (NaN outside the surface)
        P = O[k] + s[:, None] * D[k]
        return P[:, 2] - height(P[:, 0], P[:, 1])

    a = s0.copy()
    b = np.full_like(a, np.nan)
    fa = f(a, np.arange(a.size))
    dead = ~(fa > 0) & np.isfinite(fa)  # the origin (or the top) under the surface
    todo = ~dead
    for m in range(1, n_steps + 1):
        k = np.flatnonzero(todo)
        if not k.size:
            break
        sk = np.minimum(s0[k] + m * ds[k], s1[k])
        fk = f(sk, k)
        hit = fk <= 0
        b[k[hit]] = sk[hit]
        a[k[~hit]] = sk[~hit]
        todo[k[hit | (sk >= s1[k])]] = False
    k = np.flatnonzero(np.isfinite(b))
    lo, hi = a[k], b[k]
    while k.size and np.max((hi - lo) * np.linalg.norm(D[k], axis=1)) > tol_m:
        mid = 0.5 * (lo + hi)
        up = ~(f(mid, k) <= 0)  # NaN (outside the surface): above
        lo, hi = np.where(up, mid, lo), np.where(up, hi, mid)
    out = np.full(O.shape[0], np.nan)
    out[k] = hi
    return out
