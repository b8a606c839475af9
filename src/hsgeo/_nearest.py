"""The nearest swath pixel of every cell of a map grid, compiled (numba): a bucket search.

:func:`nearest_cells` gives each cell centre of a grid its nearest pixel among scattered ground
points (map x, y) within a radius, exactly as a kd-tree's query with ``distance_upper_bound``
would (the same squared Euclidean distance in float64; a tie, two pixels at the very same
distance, goes to the first given): the points are sorted into buckets of one cell (a counting
sort, O(n)), and each cell visits only the buckets within the radius. For a swath of about one
pixel per cell that is tens of nanoseconds per cell, where a kd-tree's build and query cost
about ten times as much (the stage profile, ``bench/results/orthomosaic_stages.json``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["nearest_cells"]


@njit(cache=True)
def _bucket(px, py, x0, y0, res, h, w, pad):  # pragma: no cover - compiled
    """Counting sort of the points into cells of the padded grid: (start, order)."""
    hb, wb = h + 2 * pad, w + 2 * pad
    n = px.size
    key = np.empty(n, np.int64)
    count = np.zeros(hb * wb + 1, np.int64)
    for i in range(n):
        c = math.floor((px[i] - x0) / res + 0.5) + pad
        r = math.floor((y0 - py[i]) / res + 0.5) + pad
        if 0 <= c < wb and 0 <= r < hb:
            k = r * wb + c
            key[i] = k
            count[k + 1] += 1
        else:
            key[i] = -1
    for k in range(hb * wb):
        count[k + 1] += count[k]
    start = count.copy()
    order = np.empty(count[hb * wb], np.int64)
    for i in range(n):  # stable: a bucket's points in their given order
        k = key[i]
        if k >= 0:
            order[count[k]] = i
            count[k] += 1
    return start, order


@njit(cache=True)
def _nearest(px, py, x_m, y_m, res, radius, start, order, pad):  # pragma: no cover - compiled
    h, w = y_m.size, x_m.size
    hb, wb = h + 2 * pad, w + 2 * pad
    x0, y0 = x_m[0], y_m[0]
    r2 = radius * radius
    reach = radius * (1.0 + 1e-9) + 1e-9 * res  # the buckets' range: never short by a rounding
    out = np.full(h * w, -1, np.int64)
    for i in range(h):
        yc = y_m[i]
        r_lo = max(math.floor((y0 - (yc + reach)) / res + 0.5) + pad, 0)
        r_hi = min(math.floor((y0 - (yc - reach)) / res + 0.5) + pad, hb - 1)
        for j in range(w):
            xc = x_m[j]
            c_lo = max(math.floor((xc - reach - x0) / res + 0.5) + pad, 0)
            c_hi = min(math.floor((xc + reach - x0) / res + 0.5) + pad, wb - 1)
            best, best_d2 = -1, r2
            for r in range(r_lo, r_hi + 1):
                for q in range(start[r * wb + c_lo], start[r * wb + c_hi + 1]):
                    p = order[q]
                    dx = px[p] - xc
                    dy = py[p] - yc
                    d2 = dx * dx + dy * dy
                    if d2 < best_d2 or (d2 == best_d2 and best >= 0 and p < best):
                        best, best_d2 = p, d2
            out[i * w + j] = best
    return out


def nearest_cells(x_m, y_m, px_m, py_m, radius_m: float) -> np.ndarray:
    """Index of the nearest point of every cell centre within ``radius_m`` (-1: none).

    Parameters
    ----------
    x_m : (w,) ndarray
        The cell centres' x (evenly spaced, increasing), m.
    y_m : (h,) ndarray
        The cell centres' y (evenly spaced, decreasing: rows from north to south), m.
    px_m, py_m : (n,) ndarray
        The points, in the grid's CRS, m.
    radius_m : float
        Cells farther than this from every point get -1.

    Returns
    -------
    (h * w,) int64 ndarray
        Row-major (``i * w + j``); the first point given wins an exact tie.
    """
    x_m = np.ascontiguousarray(x_m, dtype=np.float64)
    y_m = np.ascontiguousarray(y_m, dtype=np.float64)
    px = np.ascontiguousarray(px_m, dtype=np.float64)
    py = np.ascontiguousarray(py_m, dtype=np.float64)
    h, w = y_m.size, x_m.size
    if px.size == 0 or h == 0 or w == 0:
        return np.full(h * w, -1, np.int64)
    res = float(x_m[1] - x_m[0]) if w > 1 else float(y_m[0] - y_m[1])
    # a point within the radius of a cell lies within `pad` buckets of it (one more for rounding)
    pad = int(math.ceil(radius_m / res)) + 1
    start, order = _bucket(px, py, float(x_m[0]), float(y_m[0]), res, h, w, pad)
    return _nearest(px, py, x_m, y_m, res, float(radius_m), start, order, pad)
