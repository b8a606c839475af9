"""Retrieved LP observations judged against the simulation's truth (``hsgeo reproduce
lp-observations``).

The workflow (:mod:`hsgeo.workflows.lp_observations`) never sees the truth; this module is where
its matches and observations meet it (GUIDE §1):

* a **match** (two key points of different strips, one band) is judged by transfer: the true
  ground point that key point a sees (:meth:`hsgeo.simulate.lp_campaign.LpTruth.ground_points`,
  the true ray of its line and sub-pixel x meeting the DSM) is projected with the true camera at
  b's line time; its distance from ``(x_b, 0)`` is b's error, and likewise a's; the match's
  error is the larger of the two (px). A true match is off by its key points' localisation and
  the half line of rounding to the nearest line; a false match by metres;
* an **observation** of a tie point (the table that reaches the adjustment: x at the centre of
  its original pixel, y = 0 in its line) is judged against the tie point's true ground point,
  taken as the coordinate-wise median of the ground points that all its observations see
  through the true camera (robust to a false member among ≥ 3; the one place where the truth
  of a feature is not exact: a texture feature has no surveyed centre). Its error is the
  projection of that point at the observation's line time minus ``(x_px, 0)``;
* an observation of a **reference square** is judged against the square's true centre.

References
----------
Jonassen et al. (2024), 002 §3.1 (pixel-centre registration), §4.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "OUTLIER_PX",
    "match_errors_px",
    "observation_errors_px",
    "within_fractions",
    "check_point_errors",
    "joint_point_covariance",
]

#: A match (or observation) this far (px) from its true image position counts as false (ours:
#: a true match is off by its key points' localisation, ≲ 0.5 px, and up to half a line of
#: rounding to the nearest line; a false one by metres on the ground, many pixels).
OUTLIER_PX = 2.0


def _transfer_px(truth, t_from, x_from, t_to, x_to, band) -> np.ndarray:
    """Distance (px) of the projection at ``t_to`` of the ground point seen at ``(t_from,
    x_from)`` from ``(x_to, 0)``.
    """
    g = truth.ground_points(t_from, x_from, band)
    p = truth.camera.project(g, np.asarray(t_to, float), truth.trajectory, band)
    return np.hypot(p[:, 0] - np.asarray(x_to, float), p[:, 1])


def match_errors_px(matches, truth) -> np.ndarray:
    """Error of every match against the truth (module docstring), px.

    Parameters
    ----------
    matches : pandas.DataFrame
        :attr:`hsgeo.workflows.lp_observations.LpResult.matches` (``t_a_s, x_a_px, t_b_s,
        x_b_px, band``), or a subset of its rows.
    truth : hsgeo.simulate.lp_campaign.LpTruth

    Returns
    -------
    (n,) ndarray
        The larger of the two transfer errors of each match (px).
    """
    if len(matches) == 0:
        return np.zeros(0)
    band = matches["band"].to_numpy()
    ta, xa = matches["t_a_s"].to_numpy(float), matches["x_a_px"].to_numpy(float)
    tb, xb = matches["t_b_s"].to_numpy(float), matches["x_b_px"].to_numpy(float)
    eb = _transfer_px(truth, ta, xa, tb, xb, band)
    ea = _transfer_px(truth, tb, xb, ta, xa, band)
    return np.maximum(ea, eb)


def observation_errors_px(
    table, truth, square_ids=(), square_xyz_m=None, *, leave_one_out: bool = False
) -> np.ndarray:
    """Error ``(dx, dy)`` of every observation of the table against its true image position.

    Parameters
    ----------
    table : pandas.DataFrame
        The observation table (``point_id, band, t_s, x_px, y_px``).
    truth : hsgeo.simulate.lp_campaign.LpTruth
    square_ids : sequence of str
        Ids of the reference squares (their rows are judged against ``square_xyz_m``).
    square_xyz_m : (k, 3) array_like, optional
        The squares' true centres (E, N, U, m).
    leave_one_out : bool
        A tie point's observation judged against the median of the ground points of its
        *other* observations (not its own among them): a reference that does not share the
        observation it judges (the median of ≥ 3 leans toward each member; the squares are
        judged against their surveyed centres either way).

    Returns
    -------
    (n, 2) ndarray
        Observed minus true image position, px (x along the line, y across it).
    """
    n = len(table)
    out = np.full((n, 2), np.nan)
    if n == 0:
        return out
    pid = table["point_id"].to_numpy().astype(str)
    band = table["band"].to_numpy()
    t = table["t_s"].to_numpy(float)
    x = table["x_px"].to_numpy(float)
    y = table["y_px"].to_numpy(float)
    P = np.full((n, 3), np.nan)
    sq = {str(s): i for i, s in enumerate(square_ids)}
    is_sq = np.array([p in sq for p in pid], dtype=bool)
    if is_sq.any():
        xyz = np.asarray(square_xyz_m, float)
        P[is_sq] = xyz[[sq[p] for p in pid[is_sq]]]
    tie = np.flatnonzero(~is_sq)
    if tie.size:
        g = truth.ground_points(t[tie], x[tie], band[tie])
        _, inv = np.unique(pid[tie], return_inverse=True)
        order = np.argsort(inv, kind="stable")
        starts = np.r_[0, np.flatnonzero(np.diff(inv[order])) + 1]
        ends = np.r_[starts[1:], tie.size]
        if leave_one_out:
            ref = np.empty((tie.size, 3))
            for a, b in zip(starts, ends, strict=True):
                rows = order[a:b]
                for j in range(rows.size):
                    ref[rows[j]] = np.median(g[np.delete(rows, j)], axis=0)
            P[tie] = ref
        else:
            med = np.array(
                [np.median(g[order[a:b]], axis=0) for a, b in zip(starts, ends, strict=True)]
            )
            P[tie] = med[inv]
    p = truth.camera.project(P, t, truth.trajectory, band)
    out[:, 0] = x - p[:, 0]
    out[:, 1] = y - p[:, 1]
    return out


def within_fractions(err_px, limits=(1.0, 0.5)) -> dict:
    """Share of errors within each limit (px): ``{limit: share}``; ``err_px`` is ``(n,)``
    distances or ``(n, 2)`` components (their length is taken). NaN for no errors.
    """
    e = np.asarray(err_px, float)
    if e.ndim == 2:
        e = np.hypot(e[:, 0], e[:, 1])
    return {lim: float(np.mean(e <= lim)) if e.size else float("nan") for lim in limits}


def check_point_errors(result, point_ids, cp_ids, cp_xyz_true_m):
    """Estimated minus true check-point coordinates ``(k, 3)`` (E, N, H, m) and their rows.

    Parameters
    ----------
    result : hsgeo.adjust.AdjustmentResult
    point_ids : (n_points,) ndarray
        The adjustment's point ids (:attr:`PushbroomInputs.point_ids`).
    cp_ids : sequence of str
        The check points' ids; those the retrieval did not measure are left out.
    cp_xyz_true_m : (len(cp_ids), 3) array_like

    Returns
    -------
    errors : (k, 3) ndarray
    index : (k,) int ndarray
        Rows of the measured check points in ``point_ids``.
    measured : (k,) ndarray of str
    """
    pos = {str(v): i for i, v in enumerate(point_ids)}
    keep = [j for j, c in enumerate(cp_ids) if str(c) in pos]
    idx = np.array([pos[str(cp_ids[j])] for j in keep], dtype=np.int64)
    xyz = np.asarray(cp_xyz_true_m, float)[keep]
    return result.value("points_m")[idx] - xyz, idx, np.asarray(cp_ids)[keep]


def joint_point_covariance(result, index) -> np.ndarray:
    """The joint a-posteriori covariance of some points of an adjustment, ``(3k, 3k)`` (m²,
    ordered point by point, E, N, H within a point):
    :meth:`hsgeo.adjust.AdjustmentResult.point_covariance` with ``joint=True``.

    Without GCPs the check points share one datum error — the whole block shifts together —
    so their heights are strongly correlated: the per-point 3×3 blocks alone make a statistic
    that does not see that shift (a standard deviation, an NMAD) look as uncertain as one that
    does (a mean).
    """
    idx = np.atleast_1d(np.asarray(index, dtype=np.int64))
    return np.asarray(result.point_covariance(index=idx, joint=True), float)
