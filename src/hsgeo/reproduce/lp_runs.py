"""One LP campaign from pixels: retrieved, adjusted, judged (``hsgeo reproduce lp-observations``).

:func:`evaluate` runs the user's pipeline on a rendered campaign
(:func:`hsgeo.simulate.lp_campaign.simulate`): the observations are retrieved from the pixels
(:func:`hsgeo.workflows.lp_observations.retrieve`, 002's 200-line scenes by default), adjusted
with and without the GCPs (:func:`hsgeo.workflows.pushbroom_ba.adjust_pushbroom`, the same
settings as ``hsgeo adjust-pushbroom``), and only then judged against the truth
(:mod:`hsgeo.reproduce.lp_judge`): the matches before and after RANSAC, the observations that
reach the adjustment and those it keeps, the check points and the camera parameters.
:func:`scene_length_counts` retrieves again with other scene lengths (002 §4: 100, 200, 300).
"""

from __future__ import annotations

import time

import numpy as np

from hsgeo.reproduce.lp_judge import (
    OUTLIER_PX,
    check_point_errors,
    joint_point_covariance,
    match_errors_px,
    observation_errors_px,
    within_fractions,
)
from hsgeo.stats import nmad
from hsgeo.workflows.lp_observations import LpInputs, LpOptions, retrieve, to_pushbroom_inputs
from hsgeo.workflows.pushbroom_ba import (
    REPORTED_PARAMETERS,
    CameraPrior,
    PushbroomOptions,
)

__all__ = [
    "camera_prior",
    "retrieval_inputs",
    "evaluate",
    "scene_length_counts",
    "parameter_z",
    "headline",
    "exact_twin",
    "MATCH_SAMPLE",
    "gcps_by_centroid",
]

#: Matches judged against the truth: a random sample of at most this many (the shares' standard
#: error is then below 0.2 percentage points; every match at the chapter's sizes is ~10⁵–10⁶).
MATCH_SAMPLE = 60_000


def camera_prior(obs, cfg) -> CameraPrior:
    """What the operator knows of the camera and the GNSS/INS (the pushbroom chapter's priors):
    the nominal c and pixel pitch, the calibrated principal point (the truth plus a
    calibration error, :attr:`hsgeo.simulate.lp_campaign.LpConfig.sigma_pp_calibration_px`),
    the tape-measured lever arm, the a-priori σ
    of the campaign (:class:`hsgeo.simulate.pushbroom_campaign_types.CampaignConfig`; 002 §4's
    ½ px for the observations).
    """
    c = cfg.campaign
    return CameraPrior(
        n_bands=len(obs.camera.c_mm),
        pixel_mm=c.pixel_mm,
        c_mm=c.c_nominal_mm,
        x0_mm=float(obs.camera.x0_mm),  # the calibrated principal point (not the truth)
        y0_mm=float(obs.camera.y0_mm),
        lever_arm_m=tuple(obs.camera.lever_arm_m),
        sigma_lever_m=c.sigma_lever_m,
        sigma_pos_m=c.sigma_pos_m,
        sigma_att_rad=c.sigma_att_rad,
        sigma_obs_px=c.sigma_obs_px,
        sigma_gcp_m=c.sigma_gcp_m,
    )


def retrieval_inputs(obs, squares: bool = True) -> LpInputs:
    """The retrieval's inputs from the operator's side of a campaign; without ``squares`` the
    mean terrain height is taken from the squares' surveyed heights and no square is measured.
    """
    if squares:
        return LpInputs(
            tuple(obs.strips),
            obs.navigation,
            obs.camera,
            tuple(obs.square_ids),
            obs.square_xyz_m,
            None,
            obs.n_px_full,
        )
    h = float(np.mean(obs.square_xyz_m[:, 2]))
    return LpInputs(tuple(obs.strips), obs.navigation, obs.camera, (), None, h, obs.n_px_full)


def parameter_z(result, camera_true) -> dict:
    """Estimate, σ̂, truth and z of every reported camera parameter (:data:`REPORTED_PARAMETERS`)
    against the true camera: ``{block: (labels, value, sigma, truth)}`` in the model's units.
    """
    out = {}
    for name, _, _ in REPORTED_PARAMETERS:
        t = np.asarray(getattr(camera_true, name), float).ravel()
        out[name] = (
            result.params[name].labels(),
            result.value(name).ravel(),
            result.sigma(name).ravel(),
            t,
        )
    return out


def _judge_matches(res, truth, rng) -> dict:
    """Match errors on a random sample: all matches (before RANSAC), LP and frame inliers."""
    m = res.matches
    n = len(m)
    pick = np.sort(rng.choice(n, MATCH_SAMPLE, replace=False)) if n > MATCH_SAMPLE else None
    sub = m.iloc[pick] if pick is not None else m
    err = match_errors_px(sub, truth)
    lp = sub["inlier_lp"].to_numpy(bool)
    fr = sub["inlier_frame"].to_numpy(bool)
    return {
        "errors_px": err,
        "inlier_lp": lp,
        "inlier_frame": fr,
        "n_matches": n,
        "n_judged": int(err.size),
        "before": within_fractions(err),
        "after_lp": within_fractions(err[lp]),
        "after_frame": within_fractions(err[fr]),
        "outlier_before": float(np.mean(err > OUTLIER_PX)) if err.size else float("nan"),
        "outlier_lp": float(np.mean(err[lp] > OUTLIER_PX)) if lp.any() else float("nan"),
        "outlier_frame": float(np.mean(err[fr] > OUTLIER_PX)) if fr.any() else float("nan"),
    }


def _adjust(res, obs, cam, with_gcp: bool, gcp_ids):
    """``hsgeo adjust-pushbroom``'s adjustment of the retrieved table (with or without the
    GCPs), as :func:`~hsgeo.workflows.pushbroom_ba.adjust_pushbroom` sets it up; a band with no
    observation in the table keeps its a-priori principal distance, fixed (no observation sees
    it: 002's matcher finds no tie point in it on a small rendered block).
    """
    from hsgeo.sensors.pushbroom import BLOCK_NAMES
    from hsgeo.workflows.pushbroom_ba import PushbroomResult, build_problem, solve

    pin = to_pushbroom_inputs(
        res,
        obs.navigation,
        cam,
        gcp_ids if with_gcp else (),
        obs.square_xyz_m[[list(obs.square_ids).index(g) for g in gcp_ids]] if with_gcp else None,
    )
    opt = PushbroomOptions(keep_jacobian=True)
    t0 = time.perf_counter()
    o = pin.observations
    p, blocks, nodes = build_problem(
        o,
        pin.n_points,
        pin.camera,
        node_interval_s=opt.node_interval_s,
        gcp_index=pin.gcp_index,
        gcp_xyz_m=pin.gcp_xyz_m,
        t_span_s=pin.t_span_s,
        node_prior_mean=pin.node_prior_mean,
        y_as_time=opt.y_as_time,
    )
    seen = np.unique(np.asarray(res.table["band"], np.int64))
    unseen = np.setdiff1d(np.arange(cam.n_bands), seen)
    if unseen.size:
        p.fix(BLOCK_NAMES["c"], index=unseen)
    r = solve(
        p,
        blocks,
        reject_k=opt.reject_k,
        ftol=opt.ftol,
        keep_jacobian=True,
        raise_on_failure=opt.raise_on_failure,
    )
    ids = np.arange(pin.n_points) if pin.point_ids is None else pin.point_ids
    out = PushbroomResult(r, p, blocks, nodes, ids, int(o.point.size), opt.node_interval_s, 0.0)
    return out, pin, time.perf_counter() - t0


def _check_points(r, pin, obs, truth, cp_ids):
    """Errors ``(k, 3)`` of the check points ``cp_ids`` the table measured and the adjustment
    determined, their joint covariance ``(3k, 3k)``
    (:func:`~hsgeo.reproduce.lp_judge.joint_point_covariance`), their ids, and the ids of the
    measured check points the adjustment could not determine (a covariance that is not finite:
    e.g. a square seen along one ray only, :attr:`hsgeo.adjust.AdjustmentResult.
    undetermined_parameters`), which are left out of the statistics and named.
    """
    k = [list(obs.square_ids).index(s) for s in cp_ids]
    E, idx, measured = check_point_errors(r.result, pin.point_ids, cp_ids, truth.square_xyz_m[k])
    if not idx.size:
        return E, np.zeros((0, 0)), measured, []
    cov = joint_point_covariance(r.result, idx)
    ok = np.all(np.isfinite(np.diag(cov).reshape(-1, 3)), axis=1)
    undetermined = [str(m) for m in measured[~ok]]
    if not ok.all():
        keep = np.repeat(ok, 3)
        E, measured, cov = E[ok], measured[ok], cov[np.ix_(keep, keep)]
    return E, cov, measured, undetermined


def _rays(table, ids) -> np.ndarray:
    """Observations (rays: one per strip) of each id in the table."""
    n = table["point_id"].astype(str).value_counts()
    return np.array([int(n.get(str(i), 0)) for i in ids], dtype=np.int64)


def _squares_judged(res, obs, truth, cam, nogcp: bool) -> dict:
    """The retrieval's table adjusted with the GCPs it measured (and without any), its check
    points judged: ``adjusted``, ``pin``, ``gcp_ids``, ``cp_ids``, ``cp_errors_m``,
    ``cp_cov_m2`` (joint), ``cp_undetermined_ids`` (measured but not determined by the
    adjustment: left out), ``cp_rays`` and the same ``_nogcp`` (002 Table 3's check points:
    the same 13), ``seconds``.
    """
    pid = res.table["point_id"].to_numpy().astype(str)
    measured = set(pid) & {str(s) for s in obs.square_ids}
    gcp_ids = [g for g in obs.gcp_ids if g in measured]
    cps = [s for s in obs.square_ids if s not in obs.gcp_ids]
    r, pin, sec = _adjust(res, obs, cam, True, gcp_ids)
    E, cov, cp_ids, lost = _check_points(r, pin, obs, truth, cps)
    out = {
        "adjusted": r,
        "pin": pin,
        "gcp_ids": gcp_ids,
        "cp_ids": list(cp_ids),
        "cp_errors_m": E,
        "cp_cov_m2": cov,
        "cp_undetermined_ids": lost,
        "cp_rays": _rays(res.table, cp_ids),
        "gcp_rays": _rays(res.table, gcp_ids),
        "seconds": {"adjust_gcp": sec},
    }
    if nogcp:
        r0, pin0, out["seconds"]["adjust_nogcp"] = _adjust(res, obs, cam, False, gcp_ids)
        E0, cov0, ids0, lost0 = _check_points(r0, pin0, obs, truth, cps)
        out.update(
            adjusted_nogcp=r0,
            cp_errors_nogcp_m=E0,
            cp_cov_nogcp_m2=cov0,
            cp_ids_nogcp=list(ids0),
            cp_undetermined_nogcp_ids=lost0,
        )
    return out


def gcps_by_centroid(res, gcp_ids):
    """The retrieval's table (squares as the matcher found them) with the GCPs' rows taken from
    the centroid table: the GCPs, the datum, measured alike in both ways of measuring the
    check points (every strip and band that sees them), so that the two ways differ only in
    the check points; 002 does not say how its four GCPs were measured, and on a small rendered
    block the matcher finds few of the corner squares.
    """
    import pandas as pd

    tab = res.tables_by_squares.get("tie_point")
    cen = res.tables_by_squares.get("centroid")
    if tab is None or cen is None:
        return res.table
    g = [str(x) for x in gcp_ids]
    out = pd.concat(
        [tab[~tab["point_id"].astype(str).isin(g)], cen[cen["point_id"].astype(str).isin(g)]],
        ignore_index=True,
    )
    return out


def evaluate(obs, truth, seed: int, *, nogcp: bool = True, progress=None, both: bool = True):
    """Retrieve (200-line scenes), adjust with (and without) the GCPs, judge against the truth.

    The check points are measured as 002 measured them (the matcher's tie points on them,
    :attr:`~hsgeo.workflows.lp_observations.LpOptions.squares_as`), the GCPs by their
    centroids (:func:`gcps_by_centroid`); with ``both`` the same
    retrieval's table with the squares' blob centroids (every strip and band that sees them)
    is adjusted and judged too (``ev["centroid"]``, :func:`_squares_judged`).

    Returns
    -------
    dict
        ``retrieval`` (:class:`~hsgeo.workflows.lp_observations.LpResult`), ``matches``
        (:func:`_judge_matches`), ``obs_errors_px`` ``(n, 2)`` of the table's rows,
        ``is_square`` ``(n,)``, ``rejected`` ``(n,)`` (by the adjustment with GCPs),
        ``adjusted`` / ``adjusted_nogcp`` (:class:`PushbroomResult`), ``cp_errors_m`` /
        ``cp_errors_nogcp_m`` ``(k, 3)``, ``cp_cov_m2`` / ``cp_cov_nogcp_m2`` ``(3k, 3k)``
        (joint), ``cp_ids``, ``cp_rays``, ``gcp_ids`` (the GCPs measured), ``residuals_px``
        (tie points kept), ``parameters`` (:func:`parameter_z`), ``centroid`` (the same for
        the centroid table, with ``both``), ``timings_s``.
    """
    from dataclasses import replace

    rng = np.random.default_rng([seed, 25])
    T = {}
    t0 = time.perf_counter()
    # the chapter's check points as 002 measured them (the command's default is the centroids)
    opts = LpOptions(rng=seed, squares_as="tie_point")
    res = retrieve(retrieval_inputs(obs), opts, progress=progress)
    res = replace(res, table=gcps_by_centroid(res, obs.gcp_ids))
    T["retrieve"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    mj = _judge_matches(res, truth, rng)
    table = res.table
    pid = table["point_id"].to_numpy().astype(str)
    is_sq = np.isin(pid, np.asarray(obs.square_ids, str))
    oerr = observation_errors_px(table, truth, obs.square_ids, truth.square_xyz_m)
    T["judge"] = time.perf_counter() - t0
    cam = camera_prior(obs, truth.cfg)
    sj = _squares_judged(res, obs, truth, cam, nogcp)
    r = sj["adjusted"]
    T.update(sj["seconds"])
    rejected = np.asarray(r.result.outliers(0), bool)
    keep = ~rejected & ~is_sq
    out = {
        "retrieval": res,
        "matches": mj,
        "obs_errors_px": oerr,
        "is_square": is_sq,
        "rejected": rejected,
        "residuals_px": r.result.residuals(0).reshape(-1, 2)[keep],
        "parameters": parameter_z(r.result, truth.camera),
        "timings_s": T,
        **{k: v for k, v in sj.items() if k not in ("seconds", "pin")},
    }
    if both and "centroid" in res.tables_by_squares:
        t0 = time.perf_counter()
        rc = replace(res, table=res.tables_by_squares["centroid"])
        out["centroid"] = _squares_judged(rc, obs, truth, cam, nogcp)
        T["centroid_squares"] = time.perf_counter() - t0
    return out


def exact_twin(ev: dict, obs, truth) -> dict:
    """The retrieval's exact twin, adjusted with the same settings: the pseudo-truth.

    The same observations (tie points and squares, the same lines and bands) moved to their true
    image position (:func:`hsgeo.reproduce.lp_judge.observation_errors_px`: the point's true
    ground point projected with the true camera at the observation's line time), adjusted with
    the same GCPs and options as ``ev["adjusted"]``. What the adjustment's estimates then miss
    of the truth is what its model cannot represent even from perfect observations (the
    GNSS/INS error's Gauss–Markov process seen through the spline's nodes, GUIDE §4
    "unmodelled effect"): the pseudo-truth the retrieved estimates are judged against.

    Returns
    -------
    dict
        ``adjusted`` (:class:`PushbroomResult`), ``parameters`` (:func:`parameter_z`: the
        twin's estimates, their σ̂ and the generating truth), ``seconds``.
    """
    from dataclasses import replace

    res = ev["retrieval"]
    err = ev["obs_errors_px"]
    table = res.table.copy()
    table["x_px"] = table["x_px"].to_numpy(float) - err[:, 0]
    table["y_px"] = table["y_px"].to_numpy(float) - err[:, 1]
    cam = camera_prior(obs, truth.cfg)
    r, _, sec = _adjust(replace(res, table=table), obs, cam, True, ev["gcp_ids"])
    return {"adjusted": r, "parameters": parameter_z(r.result, truth.camera), "seconds": sec}


def scene_length_counts(obs, lengths, seed: int, progress=None) -> dict:
    """Retrieve the tie points with scenes of each number of lines (no squares measured):
    ``{n_lines: LpResult}`` (002 §4: 100, 200 and 300 lines).
    """
    inp = retrieval_inputs(obs, squares=False)
    out = {}
    for n in lengths:
        out[int(n)] = retrieve(
            inp, LpOptions(n_lines_per_scene=int(n), rng=seed), progress=progress
        )
    return out


def headline(ev: dict) -> dict:
    """The numbers the unmodelled-effect table follows (one evaluated campaign); the camera
    parameters against the generating camera (the blur-off run has no exact twin).
    """
    e = ev["obs_errors_px"][~ev["is_square"]]
    w = within_fractions(e)
    r = ev["residuals_px"]
    E = ev["cp_errors_m"]
    z = np.concatenate([(v - t) / s for _, v, s, t in ev["parameters"].values()])
    z = z[np.isfinite(z)]  # a band's c fixed (no observation) has no σ̂
    return {
        "tie_observations": float((~ev["is_square"]).sum()),
        "within_1px_fraction": w[1.0],
        "within_half_px_fraction": w[0.5],
        # where the key points are, not only how sharp: the RMS of the tie observations' error
        # along the line (x) and across it (y, the track: a time-stamp offset moves it)
        "rms_x_error_px": float(np.sqrt(np.nanmean(e[:, 0] ** 2))),
        "rms_y_error_px": float(np.sqrt(np.nanmean(e[:, 1] ** 2))),
        "outlier_fraction_after_ransac": ev["matches"]["outlier_lp"],
        "nmad_x_px": float(nmad(r[:, 0])),
        "nmad_y_px": float(nmad(r[:, 1])),
        "cp_nmad_e_m": float(nmad(E[:, 0])),
        "cp_nmad_n_m": float(nmad(E[:, 1])),
        "cp_nmad_h_m": float(nmad(E[:, 2])),
        "parameters_within_3sigma_of_generating_fraction": float(np.mean(np.abs(z) <= 3)),
        "max_abs_z_of_generating": float(np.max(np.abs(z))),
    }
