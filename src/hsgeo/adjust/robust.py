"""Outlier rejection: standardised residuals tested against a robust σ.

An observation whose residual, whitened and divided by ``√(1 − h)`` (``h`` its leverage on its
point, Baarda's w-test with the points' share of the redundancy), exceeds ``reject_k`` robust
standard deviations (NMAD) is rejected — a whole group (e.g. x and y of one image point) at a
time, and of one point's groups only the largest per test. The solver tests in rounds after
convergence, or in every iteration from a settled iterate on
(``SolverOptions.reject_every_iteration``, as 002 §3.4 does).
"""

from __future__ import annotations

import numpy as np

from hsgeo.adjust.schur import _inv_blocks, _Normal
from hsgeo.adjust.system import _System
from hsgeo.stats import NMAD_SCALE

__all__: list[str] = []


def _leverage(ne: _Normal, sy: _System) -> np.ndarray | None:
    """Each row's leverage on its point, ``h = j_pᵀ V⁻¹ j_p`` (0 for rows without a point),
    from the linearised system ``sy`` at which the normal equations ``ne`` were formed.
    """
    if ne.V is None:
        return None
    from hsgeo.adjust._fast import point_leverage

    if ne.reduced0 is not None:
        Vinv = ne.reduced0[2]
    else:
        Vinv = _inv_blocks(ne.V, ne.options.compiled, ne.options.rank_rtol)
    return point_leverage(sy.Jp, sy.pidx, np.ascontiguousarray(Vinv))


def _reject(blocks, masks, sy: _System, reject_k: float, row_point=None, leverage=None) -> bool:
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
    from hsgeo.adjust._fast import group_scores, standardised

    n = sy.n_obs_rows
    # |r| / √max(1 − h, 0.01) in one compiled pass (numpy's expressions, the same values: at
    # 10× the paper's pushbroom block these lines took 0.5 s on the main thread alone)
    r = standardised(sy.r[:n], np.zeros(0) if leverage is None else leverage[:n])
    r /= max(NMAD_SCALE * float(np.median(r)), 1e-300) if r.size else 1.0  # robust σ about 0
    off = 0
    new_any = False
    for i, b in enumerate(blocks):
        g = b.group_size
        keep = np.asarray(masks[i], dtype=bool)
        nk = int(np.count_nonzero(keep))
        # per group: the largest score of its kept rows (0: none kept)
        score = group_scores(r[off : off + nk], keep, g)
        off += nk
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
