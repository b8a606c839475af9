"""Tie points from pairwise key-point matches: connected components and 002 §4's filter.

Matches between scenes link key points two by two; a tie point is a set of key points that
are linked through matches, directly or not: the connected components of the match graph
(union–find; here :func:`scipy.sparse.csgraph.connected_components`, which computes the same
partition in compiled code, in one pass over the edges).

A component is then checked and filtered (:func:`link_tie_points`):

* **one observation per strip**: an LP strip sees a ground point in one line only (there is no
  forward overlap, 002 §5.1). Two key points of one strip in a component are the same
  observation found twice (BRISK detects one corner at two scales) when they lie within
  ``tol_lines`` lines and ``tol_px`` along the line — the first is kept — and a contradiction
  otherwise (two matches chained different features): the whole
  component is dropped;
* **seen in ≥ ``min_lines`` lines of ≥ ``min_strips`` strips** (002 §4: "only tie points
  observed in three or more LP image lines were used …, which required three overlapping
  flight strips").

Matches are found within one band, so one ground feature found in k bands becomes k tie points
whose observations coincide: the same line of the same strip, and (registered at the pixel
centre) the same pixel. They are one measurement repeated, not k: their errors are the same
line rounding and nearly the same pixel rounding. :func:`one_band_per_feature` groups such
tie points into features and keeps one of each (ours; 002 does not say how it treated them).

References
----------
Jonassen et al. (2024), 002 §4.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = ["link_tie_points", "components", "one_band_per_feature"]


def components(n_nodes: int, a, b) -> np.ndarray:
    """Connected components of the graph with edges ``a[k] — b[k]`` on ``n_nodes`` nodes.

    Returns
    -------
    (n_nodes,) int ndarray
        Component label of each node (isolated nodes get their own).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    if a.shape != b.shape or (
        a.size and (min(a.min(), b.min()) < 0 or max(a.max(), b.max()) >= n_nodes)
    ):
        raise InputError(f"edges must be pairs of node indices in 0…{n_nodes - 1}")
    g = coo_matrix((np.ones(a.size, np.int8), (a, b)), shape=(n_nodes, n_nodes))
    _, label = connected_components(g, directed=False)
    return label


def link_tie_points(
    n_nodes: int,
    a,
    b,
    strip,
    line,
    x_px,
    *,
    min_lines: int = 3,
    min_strips: int = 3,
    tol_lines: int = 1,
    tol_px: float = 1.0,
) -> tuple[np.ndarray, dict]:
    """Tie points from matches: components, one observation per strip, ≥ lines and strips.

    Parameters
    ----------
    n_nodes : int
        Number of key points (nodes).
    a, b : (m,) int array_like
        The matches (surviving RANSAC), as node pairs.
    strip, line : (n_nodes,) int array_like
        Strip and line (within the strip) of each key point.
    x_px : (n_nodes,) array_like, px
        Position along the line of each key point.
    min_lines, min_strips : int
        002 §4: 3 and 3.
    tol_lines, tol_px : int, float
        Two key points of one strip in a component closer than this are one observation.

    Returns
    -------
    point : (n_nodes,) int ndarray
        Tie point of each key point (0 … n_points − 1, in order of first node), −1 for key
        points that are no observation (unmatched, dropped, a strip's duplicate).
    stats : dict
        ``n_components`` (with ≥ 2 key points), ``n_contradictory``, ``n_too_few`` (components
        dropped by the filter), ``n_points``.
    """
    strip = np.asarray(strip, dtype=np.int64)
    line = np.asarray(line, dtype=np.int64)
    x = np.asarray(x_px, dtype=np.float64)
    if not (strip.shape == line.shape == x.shape == (n_nodes,)):
        raise InputError("strip, line and x_px need one value per node")
    label = components(n_nodes, a, b)
    size = np.bincount(label)
    used = size[label] >= 2
    nodes = np.flatnonzero(used)
    # sort the used nodes by (component, strip, node): duplicates of a strip are neighbours
    order = nodes[np.lexsort((nodes, strip[nodes], label[nodes]))]
    lab, st = label[order], strip[order]
    same = np.r_[False, (lab[1:] == lab[:-1]) & (st[1:] == st[:-1])]
    # a strip's later key point: a duplicate within tolerance of the first, or a contradiction
    first = order[np.maximum.accumulate(np.where(~same, np.arange(order.size), 0))]
    near = (np.abs(line[order] - line[first]) <= tol_lines) & (
        np.abs(x[order] - x[first]) <= tol_px
    )
    bad_comp = np.unique(lab[same & ~near])
    keep = ~same & ~np.isin(lab, bad_comp)
    kept = order[keep]
    # count strips and distinct lines per component
    n_strips = np.bincount(label[kept], minlength=label.max() + 1)
    ok_comp = n_strips >= max(min_strips, 1)
    if min_lines > min_strips:  # one observation per strip: lines = strips otherwise
        key = np.unique(np.column_stack([label[kept], strip[kept], line[kept]]), axis=0)
        ok_comp &= np.bincount(key[:, 0], minlength=label.max() + 1) >= min_lines
    else:
        ok_comp &= n_strips >= min_lines
    final = kept[ok_comp[label[kept]]]
    point = np.full(n_nodes, -1, np.int64)
    comps, inv = np.unique(label[final], return_inverse=True)
    # number the points in order of their first node
    first_node = np.full(comps.size, n_nodes, np.int64)
    np.minimum.at(first_node, inv, final)
    rank = np.empty(comps.size, np.int64)
    rank[np.argsort(first_node, kind="stable")] = np.arange(comps.size)
    point[final] = rank[inv]
    n_comp = int(np.sum(size >= 2))
    return point, {
        "n_components": n_comp,
        "n_contradictory": int(bad_comp.size),
        "n_too_few": int(n_comp - bad_comp.size - comps.size),
        "n_points": int(comps.size),
    }


def one_band_per_feature(point, strip, line, x_px, *, score=None, tol_px: float = 1.0):
    """One tie point per ground feature: of the tie points (each in one band) whose
    observations coincide, the one with the lowest ``score`` (then the most observations;
    module docstring).

    Two tie points are the same feature when an observation of one and an observation of the
    other lie in the same line of the same strip within ``tol_px`` along it (the band's own
    principal distance moves a feature by a pixel or less near the line's ends); the relation
    is closed transitively (connected components). The pairs are found through bins of width
    2·``tol_px`` (and the same bins shifted by ``tol_px``), each observation linked to the
    first of its bin: on the pixel-centre grid that is every pair within ``tol_px``; with
    sub-pixel x a pair within ``tol_px`` whose bins' first observations are farther may stay
    unlinked unless a third observation links them.

    Parameters
    ----------
    point : (m,) int array_like
        Tie point of each observation (0 … n_points − 1).
    strip, line : (m,) int array_like
        Strip and line (within the strip) of each observation.
    x_px : (m,) array_like, px
        Position along the line.
    score : (n_points,) array_like, optional
        Per tie point, lower is better (e.g. the mean Hamming distance of its matches: the
        band whose descriptors agree best between strips); default: all equal.
    tol_px : float
        Largest distance along the line of two coinciding observations (< 2).

    Returns
    -------
    keep : (n_points,) bool ndarray
        The tie point kept for its feature (ties: the most observations, then the lowest
        index).
    feature : (n_points,) int ndarray
        Feature of each tie point (0 … n_features − 1).
    """
    point = np.asarray(point, dtype=np.int64)
    strip = np.asarray(strip, dtype=np.int64)
    line = np.asarray(line, dtype=np.int64)
    x = np.asarray(x_px, dtype=np.float64)
    if not (point.shape == strip.shape == line.shape == x.shape) or point.ndim != 1:
        raise InputError("point, strip, line and x_px need one value per observation")
    if not 0 < tol_px < 2:
        raise InputError(f"tol_px must be in (0, 2), got {tol_px!r}")
    n = int(point.max()) + 1 if point.size else 0
    if point.size and point.min() < 0:
        raise InputError("tie point indices must be ≥ 0")
    # observations within tol_px of each other share a bin of width 2·tol_px, or of the same
    # bins shifted by tol_px: two bin keys per observation, linked to its tie point
    cells = []
    for shift in (0.0, tol_px):
        b = np.floor((x + shift) / (2 * tol_px)).astype(np.int64)
        cells.append(np.column_stack([strip, line, b, np.full_like(b, int(shift > 0))]))
    _, cell = np.unique(np.concatenate(cells), axis=0, return_inverse=True)
    cell = cell.ravel()
    point2 = np.r_[point, point]  # the tie point of each bin entry
    # the bins over-link up to 2·tol_px apart; keep only the pairs within tol_px: link each
    # observation to the first of its bin (sorted by x) when within tol_px of it, else alone
    xs = np.r_[x, x]
    order = np.lexsort((xs, cell))
    c, pnt, xo = cell[order], point2[order], xs[order]
    start = np.r_[True, c[1:] != c[:-1]]
    head = np.maximum.accumulate(np.where(start, np.arange(c.size), 0))
    ok = ~start & (xo - xo[head] <= tol_px)
    feature = components(max(n, 1), pnt[head[ok]], pnt[ok])[:n]
    _, feature = np.unique(feature, return_inverse=True)
    n_obs = np.bincount(point, minlength=n)
    score = np.zeros(n) if score is None else np.asarray(score, dtype=np.float64)
    if score.shape != (n,) or np.isnan(score).any():
        raise InputError(f"score needs one number per tie point ({n}), not NaN")
    order = np.lexsort((np.arange(n), -n_obs, score, feature))
    first = np.r_[True, feature[order][1:] != feature[order][:-1]] if n else np.zeros(0, bool)
    keep = np.zeros(n, bool)
    keep[order[first]] = True
    return keep, feature.astype(np.int64)
