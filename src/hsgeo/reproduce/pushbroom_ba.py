"""``hsgeo reproduce pushbroom-ba``: 002 Tables 1–3 and Fig. 8 from a simulated campaign.

The campaign (:mod:`hsgeo.simulate.pushbroom_campaign`) is simulated as ``(observations,
truth)``; the observations are adjusted (:mod:`hsgeo.workflows.pushbroom_ba`) twice, with the
four GCPs (002 Tables 1, 2, Fig. 8) and without (Table 3). ``scale`` thins the tie points (1.0: the
paper's 113,758). The node-interval study (:func:`node_interval_study`) is separate because it
runs one adjustment per interval. The statistics of Tables 1–3 have no σ̂ from the adjustment:
their spread comes from repeated campaigns (:func:`table_spread`, 8 seeds at 0.05 of the tie
points when ``scale`` is the paper's; the 13 check points are the same at every scale). This
module is the only place where the adjustment's results meet the campaign's truth (check points,
parameters, gross errors).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from hsgeo.adjust import identifiability
from hsgeo.errors import InputError
from hsgeo.papers import P002, P002_STATS
from hsgeo.report import Reproduction, Row
from hsgeo.simulate.pushbroom_campaign import (
    CampaignConfig,
    CampaignObservations,
    CampaignTruth,
    simulate,
)
from hsgeo.stats import describe, nmad
from hsgeo.workflows.pushbroom_ba import (  # 002's settings, spelled once in the workflow
    FTOL,
    REJECT_K,
    REPORTED_PARAMETERS,
    Y_AS_TIME,
    CameraPrior,
    build_problem,
    solve,
)

__all__ = [
    "run",
    "adjust_campaign",
    "camera_prior",
    "cp_errors",
    "outlier_detection",
    "node_interval_study",
    "check_point_factors",
    "table_spread",
    "FACTORS",
    "study_plan",
]

RAD2DEG = 180 / np.pi


def camera_prior(cfg: CampaignConfig, obs: CampaignObservations) -> CameraPrior:
    """What the operator knows of the camera: the scenario's nominal values (the initial
    principal distance, pixel pitch, calibrated principal point, a-priori σ) and the measured
    lever arm.
    """
    return CameraPrior(
        n_bands=len(cfg.c_offsets_um),
        pixel_mm=cfg.pixel_mm,
        c_mm=cfg.c_nominal_mm,
        x0_mm=cfg.x0_mm,
        y0_mm=cfg.y0_mm,
        lever_arm_m=tuple(obs.lever_arm_m),
        sigma_lever_m=cfg.sigma_lever_m,
        sigma_pos_m=cfg.sigma_pos_m,
        sigma_att_rad=cfg.sigma_att_rad,
        sigma_obs_px=cfg.sigma_obs_px,
        sigma_gcp_m=cfg.sigma_gcp_m,
    )


def adjust_campaign(
    obs: CampaignObservations,
    cfg: CampaignConfig,
    *,
    with_gcp: bool = True,
    node_interval_s: float = 10.0,
    reject_k: float | None = REJECT_K,
    ftol: float = FTOL,
    progress=None,
    truth: CampaignTruth | None = None,
    y_as_time: bool = Y_AS_TIME,
):
    """Set up and adjust one campaign's observations; returns ``(result, params, blocks, info)``.

    ``cfg`` is the scenario (the operator's nominal camera and σ). With ``truth``, the rank of
    the normal equations at the true values is added to ``info`` (``rank_at_truth``,
    ``n_nonpoint_unknowns``); the adjustment itself never sees it.
    """
    t0 = time.perf_counter()
    p, blocks, nodes = build_problem(
        obs.lines,
        obs.n_points,
        camera_prior(cfg, obs),
        node_interval_s=node_interval_s,
        t_span_s=obs.t_span_s,
        node_prior_mean=(obs.node_prior_mean if node_interval_s == cfg.node_interval_s else None),
        gcp_index=obs.gcp_index if with_gcp else None,
        gcp_xyz_m=obs.gcp_xyz_m if with_gcp else None,
        y_as_time=y_as_time,
    )
    info = {"setup_seconds": time.perf_counter() - t0, "nodes": nodes}
    if truth is not None:
        q = p.copy()
        for k, v in truth.values.items():
            if q[k].shape == np.shape(v):
                q.set(k, v)
        ident = identifiability(q, blocks)
        info["rank_at_truth"] = ident.rank
        info["n_nonpoint_unknowns"] = ident.n_unknowns
    res = solve(
        p, blocks, reject_k=reject_k, ftol=ftol, progress=progress, keep_jacobian=True
    )  # the check points' covariance (run)
    info["solver_seconds"] = res.seconds
    return res, p, blocks, info


#: Why the extremes of 002 Table 1 get no verdict (see :func:`_stats_rows`).
EXTREMES_NOT_COMPARABLE = (
    "an extreme of ~440,000 residuals (full size) cannot be given a spread from runs with fewer "
    "observations: the expected extreme grows with their number"
)


def _stats_rows(table, names, data, unit, paper, spread=None, n_runs=None, extremes=True):
    """The rows of one of 002 Tables 1–3: :data:`P002_STATS` of every column of ``data``.

    ``spread`` (``(len(names), 6)``, same order) is the standard deviation of each statistic
    over ``n_runs`` simulated campaigns (:func:`table_spread`); with ``extremes=False`` the
    min/max rows get ``verdict="not testable"`` (:data:`EXTREMES_NOT_COMPARABLE`).
    """
    rows = []
    for i, (nm, col) in enumerate(zip(names, data.T, strict=True)):
        d = describe(col)
        for k, st in enumerate(P002_STATS):
            row = Row(table, f"{st}_{nm}_{unit}", unit, paper=paper[nm][k], reproduced=d[st])
            if spread is not None:
                row.sigma, row.n_runs = float(spread[i, k]), n_runs
            if not extremes and st in ("min", "max"):
                row.verdict, row.reason = "not testable", EXTREMES_NOT_COMPARABLE
            rows.append(row)
    return rows


def _describe_rows(cols) -> np.ndarray:
    """:data:`P002_STATS` of each 1-D array of ``cols``: ``(len(cols), 6)``."""
    return np.array([[describe(c)[st] for st in P002_STATS] for c in cols])


def table_spread(seeds=tuple(range(8)), scale: float = 0.05) -> dict:
    """The spread of every statistic of 002 Tables 1–3 over repeated simulated campaigns.

    For each seed the default campaign (as :func:`run`) is simulated at ``scale`` and adjusted
    with and without the four GCPs, as :func:`check_point_factors` does for its runs; the
    statistics of :data:`P002_STATS` are taken of the reprojection errors x, y (Table 1) and of
    the 13 check points' errors E, N, H (Tables 2, 3).

    Returns
    -------
    dict
        ``"002 Table 1"`` ``(n_seeds, 2, 6)`` (px), ``"002 Table 2"``, ``"002 Table 3"``
        ``(n_seeds, 3, 6)`` (m), ``"sigma"``: table -> ``(n, 6)`` sample standard deviation
        over the seeds (``ddof=1``), ``"seeds"``, ``"scale"``, ``"seconds"``.
    """
    if len(seeds) < 2:
        raise InputError(f"table_spread needs at least 2 seeds for a spread, got {len(seeds)}")
    t0 = time.perf_counter()
    cfg = CampaignConfig()
    out = {"002 Table 1": [], "002 Table 2": [], "002 Table 3": []}
    for seed in seeds:
        obs, truth = simulate(scale, rng=seed, cfg=cfg)
        res = adjust_campaign(obs, cfg)[0]
        res0 = adjust_campaign(obs, cfg, with_gcp=False)[0]
        r_px = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
        out["002 Table 1"].append(_describe_rows(r_px.T))
        out["002 Table 2"].append(_describe_rows(cp_errors(res, truth).T))
        out["002 Table 3"].append(_describe_rows(cp_errors(res0, truth).T))
    out = {k: np.array(v) for k, v in out.items()}
    out["sigma"] = {k: v.std(axis=0, ddof=1) for k, v in out.items()}
    out.update(seeds=tuple(seeds), scale=scale, seconds=time.perf_counter() - t0)
    return out


def cp_errors(res, truth: CampaignTruth) -> np.ndarray:
    """Estimated minus true check-point coordinates ``(13, 3)`` in m (E, N, H)."""
    return res.value("points_m")[truth.cp_index] - truth.values["points_m"][truth.cp_index]


def outlier_detection(res, obs: CampaignObservations, truth: CampaignTruth) -> dict:
    """The rejected observations of ``res`` against the simulated gross errors.

    Returns
    -------
    dict
        ``simulated_outliers``, ``outliers_found`` (rejected gross errors),
        ``false_rejections`` (rejected good observations), ``false_rejections_on_gross_points``
        (of those, on points that also carry a gross error) and
        ``missed_outlier_median_abs_z`` (median over the gross errors kept of their larger
        normalised residual, x or y; NaN if none is kept).
    """
    rej, gross, point = res.outliers(0), truth.outlier, obs.lines.point
    missed = gross & ~rej
    return {
        "simulated_outliers": int(gross.sum()),
        "outliers_found": int((rej & gross).sum()),
        "false_rejections": int((rej & ~gross).sum()),
        "false_rejections_on_gross_points": int(np.isin(point[rej & ~gross], point[gross]).sum()),
        # the gross errors kept: their largest normalised residual (x or y), median
        "missed_outlier_median_abs_z": float(
            np.median(np.abs(res.normalized_residuals(0).reshape(-1, 2)[missed]).max(axis=1))
        )
        if missed.any()
        else float("nan"),
    }


def c_minus_mean(res, truth_c):
    """Per-band principal distance minus the mean of the bands, its σ̂, and the truth (µm)."""
    c = res.value("c_mm")
    n = c.size
    D = np.eye(n) - 1.0 / n
    C, _ = res.covariance_of("c_mm")
    cov = D @ C @ D.T
    return ((c - c.mean()) * 1e3, np.sqrt(np.diag(cov)) * 1e3, (truth_c - truth_c.mean()) * 1e3)


def run(seed: int = 0, scale: float = 1.0, progress=None, plan: dict | None = None) -> Reproduction:
    """The chapter's numbers: 002 Tables 1–3, Fig. 8, the estimated parameters, the node
    interval study and the check-point factors (sizes from :func:`study_plan`, or ``plan``).
    """
    t_start = time.perf_counter()
    plan = study_plan(scale) if plan is None else plan
    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    rows: list[Row] = []
    res, p, blocks, info = adjust_campaign(obs, cfg, with_gcp=True, progress=progress, truth=truth)
    res0, _, _, info0 = adjust_campaign(obs, cfg, with_gcp=False, progress=progress)

    # -- the spread of the tables' statistics over repeated campaigns (at a reduced scale)
    spread = table_spread(
        tuple(seed + k for k in range(plan["spread_seeds"])), plan["spread_scale"]
    )
    ns, sg = len(spread["seeds"]), spread["sigma"]
    # -- 002 Table 1: reprojection errors of the tie points (with GCPs), px; the extremes of
    # fewer observations are not comparable with the full size's (scale < 1 here)
    keep = ~res.outliers(0)
    r_px = res.residuals(0).reshape(-1, 2)[keep]
    same_size = spread["scale"] == scale
    rows += _stats_rows(
        "002 Table 1",
        ("x", "y"),
        r_px,
        "px",
        P002["002 Table 1"],
        sg["002 Table 1"],
        ns,
        extremes=same_size,
    )
    for row in rows:
        # issue 22: the key-point σ per image axis was tuned to the paper's NMADs (a miss
        # beyond 3σ is "differs: tuning missed"); the other statistics follow from our choices
        row.provenance = "tuned" if row.quantity in ("nmad_x_px", "nmad_y_px") else "chosen"
    # -- 002 Tables 2 and 3: check points, m (the same 13 at every scale)
    E_gcp, E_nogcp = cp_errors(res, truth), cp_errors(res0, truth)
    for name, E in (("002 Table 2", E_gcp), ("002 Table 3", E_nogcp)):
        rows += _stats_rows(name, ("e", "n", "h"), E, "m", P002[name], sg[name], ns)
    for row in rows:
        row.provenance = row.provenance or "chosen"
    # -- 002 Fig. 8: principal distance per band minus the mean
    d_um, s_um, t_um = c_minus_mean(res, truth.values["c_mm"])
    for b, wl in enumerate(cfg.wavelengths_nm):
        rows.append(
            Row(
                "002 Fig. 8",
                f"c_minus_mean_band{b}_{wl:.0f}nm_um",
                "um",
                reproduced=d_um[b],
                sigma=s_um[b],
                truth=t_um[b],
            )
        )
    rows.append(
        Row(
            "002 Fig. 8",
            "max_abs_c_minus_mean_um",
            "um",
            paper=P002["fig8_max_abs_diff_um"],
            reproduced=np.max(np.abs(d_um)),
            truth=np.max(np.abs(t_um)),
            provenance="tuned",  # the true per-band offsets were set from the paper's ≤ 11.8 µm
        )
    )
    c_mean = res.value("c_mm").mean()
    half_px = cfg.pixels_per_line / 2
    shift = np.max(np.abs(d_um)) * 1e-3 / c_mean * half_px  # chromatic shift at the line's end
    rows.append(
        Row(
            "002 Fig. 8",
            "chromatic_shift_at_edge_px",
            "px",
            paper=P002["chromatic_shift_px"],
            reproduced=shift,
            truth=np.max(np.abs(t_um)) * 1e-3 / truth.values["c_mm"].mean() * half_px,
            provenance="tuned",  # follows from the tuned per-band offsets
        )
    )
    # -- parameters: boresight, lever arm, distortion, c, nodes (with GCPs)
    par = []
    for name, unit, f in REPORTED_PARAMETERS:
        lab = res.params[name].labels()
        v, s, t = res.value(name).ravel(), res.sigma(name).ravel(), truth.values[name].ravel()
        for j in range(v.size):
            qn = lab[j].replace("_rad", "_deg") if unit == "deg" else lab[j]
            par.append(
                Row("parameters", qn, unit, reproduced=v[j] * f, sigma=s[j] * f, truth=t[j] * f)
            )
    rows += par
    z = np.array([(r.reproduced - r.truth) / r.sigma for r in par])  # camera parameters
    # the node corrections have no exact truth (Gauss–Markov GNSS/INS error): they are compared
    # with the best least-squares spline fit of the true error (CampaignTruth.values), on the
    # nodes that observations touch (the others keep their prior)
    nv, ns_, nt = res.value("nodes"), res.sigma("nodes"), truth.values["nodes"]
    seen = np.unique(truth.nodes.basis(obs.lines.t_s)[0])
    z_nodes = (nv - nt)[seen] / ns_[seen]
    lab = res.params["nodes"].labels()
    for j in range(nv.size):
        rows.append(
            Row(
                "parameters",
                lab[j],
                "m" if j % 6 < 3 else "rad",
                reproduced=nv.ravel()[j],
                sigma=ns_.ravel()[j],
                truth=nt.ravel()[j],
            )
        )

    # -- the node-interval study (with a sweep of the correlation times) and the factors
    sweep = {
        f: node_interval_study(
            seed,
            plan["interval_scale"],
            plan["intervals_s"] if f == 1.0 else plan.get("sweep_intervals_s", plan["intervals_s"]),
            f,
        )
        for f in plan["tau_factors"]
    }
    # the optimum over seeds (GUIDE §4: a distribution rests on ≥ 8 seeds), on the intervals
    # common to every correlation time; the first seed's studies are the sweep's
    common = tuple(plan.get("sweep_intervals_s", plan["intervals_s"]))
    t_opt = time.perf_counter()
    optima = interval_optima(
        tuple(seed + k for k in range(plan["interval_seeds"])),
        plan["interval_scale"],
        common,
        plan["tau_factors"],
        first=sweep,
    )
    t_opt = time.perf_counter() - t_opt
    rows += _interval_rows(sweep[1.0] if 1.0 in sweep else next(iter(sweep.values())), optima)
    fac = check_point_factors(
        tuple(seed + k for k in range(plan["factor_seeds"])), plan["factor_scale"]
    )
    rows += _factor_rows(fac)
    rows += _unmodelled_rows(fac)

    n_lines = int(round(sum(s[1] - s[0] for s in truth.strips) * cfg.line_rate_hz))
    cp_sigma = np.sqrt(np.diagonal(res.point_covariance(index=truth.cp_index), axis1=1, axis2=2))
    meta = {
        "scale": scale,
        "n_tie_points": obs.n_points,
        "n_observations_2d": obs.lines.n,
        "n_unknowns": int(res.n_unknowns),
        "n_nonpoint_unknowns": int(info["n_nonpoint_unknowns"]),
        "rank_at_truth": int(info["rank_at_truth"]),
        "paper_n_unknowns": P002["n_unknowns"],
        "paper_n_observations_2d": P002["n_observations_2d"],
        "n_lines": n_lines,
        "eo_unknowns_per_line": 6 * n_lines,
        "node_unknowns": int(res.params["nodes"].size),
        "sigma0_gcp": res.sigma0,
        "sigma0_nogcp": res0.sigma0,
        "iterations_gcp": res.iterations,
        "iterations_nogcp": res0.iterations,
        "solver_seconds_gcp": info["solver_seconds"],
        "solver_seconds_nogcp": info0["solver_seconds"],
        "rejected_gcp": int(res.outliers(0).sum()),
        **outlier_detection(res, obs, truth),
        "trajectory_error": truth.trajectory_error,
        "n_camera_parameters": int(z.size),
        "share_camera_within_3sigma": float(np.mean(np.abs(z) < 3)),
        "max_abs_z_camera": float(np.max(np.abs(z))),
        "n_nodes_observed": int(seen.size),
        "z_std_nodes_vs_fit": np.std(z_nodes, axis=0).tolist(),
        "share_nodes_within_3sigma_of_fit": float(np.mean(np.abs(z_nodes) < 3)),
        "corr_nodes_with_fit": [
            float(np.corrcoef(nv[seen, j], nt[seen, j])[0, 1]) for j in range(6)
        ],
        "plan": plan,
        "optimum_interval_s": {str(f): optimum_interval(st) for f, st in sweep.items()},
        # per correlation-time factor: the optimum of each seed (intervals common to all)
        "optimum_interval_per_seed_s": {str(f): list(v) for f, v in optima.items()},
        "optimum_intervals_compared_s": list(common),
        "interval_seeds": plan["interval_seeds"],
        "interval_optima_seconds": t_opt,
        "min_factor_seeds": MIN_FACTOR_SEEDS,
        "unmodelled_effect": (
            f"a distortion ripple along the line, {RIPPLE_PX:g} px × sin(2π "
            f"{cfg.distortion_ripple_periods:g} x / {cfg.pixels_per_line} px) less its part "
            "along the model's terms, outside 002 eq. (3); off by default, factor (h)"
        ),
        "ripple_px": RIPPLE_PX,
        "factor_seeds": list(fac["seeds"]),
        "factor_scale": fac["scale"],
        "factor_seconds": fac["seconds"],
        "spread_seeds": list(spread["seeds"]),
        "spread_scale": spread["scale"],
        "spread_seconds": spread["seconds"],
        "cp_sigma_h_m": cp_sigma[:, 2].tolist(),
        "gsd_m": [
            cfg.agl_low_m * cfg.pixel_mm / cfg.c_mean_mm,
            cfg.agl_high_m * cfg.pixel_mm / cfg.c_mean_mm,
        ],
        "total_seconds": time.perf_counter() - t_start,
    }
    extras = {
        "observations": obs,
        "truth": truth,
        "result_gcp": res,
        "result_nogcp": res0,
        "cp_errors_gcp": E_gcp,
        "cp_errors_nogcp": E_nogcp,
        "cp_sigma_m": cp_sigma,
        "residuals_px": r_px,
        "c_minus_mean_um": (d_um, s_um, t_um),
        "z_parameters": z,
        "z_nodes_vs_fit": z_nodes,
        "node_interval": sweep,
        "factors": fac,
        "table_spread": spread,
    }
    return Reproduction("pushbroom-ba", seed, rows, meta, extras)


def study_plan(scale: float) -> dict:
    """Sizes of the node-interval study and the check-point factor runs for a ``scale``.

    At the paper's size (``scale`` ≥ 0.5) the studies run at reduced sizes that keep the
    chapter within about 6 minutes on a 2-core machine; below it (the tests' small scale) they
    are smaller still. The 1 s node interval is left out of the default plan: its ≈ 10,700
    non-point unknowns make a dense reduced normal matrix of 0.9 GB, and one run did not
    finish within 12 minutes on the (shared) 2-core machine; ``node_interval_study`` takes it
    on request.
    """
    if scale >= 0.5:
        return {
            "interval_scale": 0.02,
            "intervals_s": (2.0, 5.0, 10.0, 30.0, 60.0),
            "tau_factors": (0.25, 1.0, 4.0),
            # the sweep leaves out 2 s (≈ 90 s per run, most of the study's time)
            "sweep_intervals_s": (5.0, 10.0, 30.0, 60.0),
            "factor_scale": 0.05,
            "factor_seeds": MIN_FACTOR_SEEDS,
            # the optimum node interval over seeds (≈ 3 s per seed and correlation time)
            "interval_seeds": MIN_FACTOR_SEEDS,
            # 002 Tables 1-3's spread: 2 adjustments per seed, ≈ 3 s each seed at 0.05
            "spread_scale": 0.05,
            "spread_seeds": 8,
        }
    return {
        "interval_scale": min(scale, 0.01),
        "intervals_s": (10.0, 30.0, 60.0),
        "tau_factors": (0.25, 1.0, 4.0),
        "sweep_intervals_s": (10.0, 30.0, 60.0),
        "factor_scale": min(scale, 0.01),
        "factor_seeds": MIN_FACTOR_SEEDS,
        "interval_seeds": MIN_FACTOR_SEEDS,
        "spread_scale": min(scale, 0.01),
        "spread_seeds": 3,
    }


def _scaled_tau(cfg: CampaignConfig, factor: float) -> CampaignConfig:
    """The scenario with every correlation time of the GNSS/INS error multiplied by ``factor``."""
    return replace(
        cfg,
        tau_pos_s=tuple(factor * t for t in cfg.tau_pos_s),
        tau_att_s=tuple(factor * t for t in cfg.tau_att_s),
    )


def node_interval_study(
    seed: int = 0,
    scale: float = 0.02,
    intervals_s=(2.0, 5.0, 10.0, 30.0, 60.0),
    tau_factor: float = 1.0,
) -> list[dict]:
    """Reprojection NMAD, check-point and tie-point errors and solver time per node interval.

    The truth is the default Gauss–Markov GNSS/INS error (its correlation times multiplied by
    ``tau_factor``), not a spline: no interval is exact, and where the errors are smallest is
    an outcome. ``tp_rms_en_m`` / ``tp_rms_h_m`` compare *all* tie points with their truth
    (thousands of points, where the 13 check points give a noisy statistic).

    Returns
    -------
    list of dict, one per interval
    """
    cfg = _scaled_tau(CampaignConfig(), tau_factor)
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    tie = np.setdiff1d(np.arange(obs.n_points), np.r_[obs.gcp_index, truth.cp_index])
    out = []
    for dt in intervals_s:
        res, p, blocks, info = adjust_campaign(obs, cfg, with_gcp=True, node_interval_s=dt)
        E = cp_errors(res, truth)
        T = res.value("points_m")[tie] - truth.values["points_m"][tie]
        r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
        out.append(
            {
                "interval_s": dt,
                "tau_factor": tau_factor,
                "n_nonpoint_unknowns": len(res.labels),
                "nmad_x_px": float(nmad(r[:, 0])),
                "nmad_y_px": float(nmad(r[:, 1])),
                "cp_rms_en_m": float(np.sqrt(np.mean(E[:, :2] ** 2))),
                "cp_rms_h_m": float(np.sqrt(np.mean(E[:, 2] ** 2))),
                "tp_rms_en_m": float(np.sqrt(np.mean(T[:, :2] ** 2))),
                "tp_rms_h_m": float(np.sqrt(np.mean(T[:, 2] ** 2))),
                "sigma0": res.sigma0,
                "seconds": info["solver_seconds"],
                "iterations": res.iterations,
            }
        )
    return out


#: The factor runs of :func:`check_point_factors`: key -> what the run changes. Each is the
#: default campaign (Gauss–Markov GNSS/INS error, residual across the line as a time, exact
#: check-point coordinates, check points seen by a tie point's number of strips, no distortion
#: ripple) with one thing changed; ``combined`` combines (b)–(e).
FACTORS = {
    "spline_truth": "GNSS/INS error = the estimator's 10 s spline (the former truth)",
    "gauss_markov": "(a) GNSS/INS error: Gauss–Markov per axis (the default)",
    "image_y": "(b) residual across the line as the image y of 002 eq. (2)",
    "ref_image": "(c) reference squares measured by their centre, σ 0.5 px",
    "rtk": "(d) RTK error of the check-point coordinates, σ 1 cm",
    "refraction": "(e) atmospheric refraction in the images, not modelled",
    "combined": "(b)–(e) together",
    "all_strips_rays": "(f) check points seen in every covering strip (14–20 rays, as before)",
    "height_offset": "(g) RTK heights of GCPs and check points 10 cm off the trajectory's datum",
    "ripple": "(h) a distortion ripple along the line, not modelled (RIPPLE_PX)",
}
#: (c): the centre of a 1.2 m square in 0.3–0.4 m pixels (3–4 px) picked with ±½ px (ours).
SIGMA_REF_IMAGE_PX = 0.5
#: (g): a common height offset of the RTK reference (GCPs and check points) against the
#: trajectory's datum, m (ours: an antenna-height slip, or a geoid model error, of 10 cm).
HEIGHT_OFFSET_M = -0.10
#: (h), the unmodelled effect of the chapter: the amplitude of the distortion ripple (px) of
#: :func:`hsgeo.simulate.pushbroom_campaign.distortion_ripple_px` (ours: the residual of a
#: polynomial lens model is of a tenth of a pixel). Off in the other runs (see CampaignConfig).
RIPPLE_PX = 0.1
#: Fewest seeds per factor before the chapter says what a factor "reaches" (GUIDE §4).
MIN_FACTOR_SEEDS = 8
_CP_QUANTITIES = ("cp_nmad_e_m", "cp_nmad_n_m", "cp_nmad_h_m", "cp_mean_h_m", "cp_nmad_e_over_n")
_REPROJ_QUANTITIES = ("nmad_x_px", "nmad_y_px")


def _cp_summary(E: np.ndarray) -> np.ndarray:
    ne, nn = nmad(E[:, 0]), nmad(E[:, 1])
    return np.array([ne, nn, nmad(E[:, 2]), np.mean(E[:, 2]), ne / nn])


def check_point_factors(seeds=tuple(range(MIN_FACTOR_SEEDS)), scale: float = 0.05) -> dict:
    """The candidate explanations of 002's check-point errors, one factor at a time.

    For every seed the campaign is simulated and adjusted with the four GCPs once per factor
    of :data:`FACTORS` (the same random draws where a factor changes only itself; (f) changes
    the number of observations, hence every later draw). (d) and (g) need no simulation of
    their own: the check points' reference coordinates of the default run get an RTK error of
    ``cfg.sigma_gcp_m``; (g) shifts the GCP and check-point heights by :data:`HEIGHT_OFFSET_M`.

    Returns
    -------
    dict
        ``"cp"``: key -> ``(n_seeds, 5)`` array of :data:`_CP_QUANTITIES` (m; the last the ratio
        of the E and N NMADs); ``"reprojection"``: key -> ``(n_seeds, 2)`` NMAD x, y (px);
        ``"max_abs_z_distortion"``: key -> per-seed largest |z| of K1, K2, P1, P2;
        ``"mean_z_c"``, ``"mean_c_error_um"``: key -> per-seed mean z and mean error of the
        principal distances; ``"seeds"``, ``"scale"``, ``"seconds"``.
    """
    t0 = time.perf_counter()
    base = CampaignConfig()
    cp = {k: [] for k in FACTORS}
    rp = {k: [] for k in FACTORS}
    zk = {k: [] for k in FACTORS}
    zc = {k: [] for k in FACTORS}
    dc = {k: [] for k in FACTORS}

    def record(key, res, truth, rtk=None):
        E = cp_errors(res, truth)
        if rtk is not None:
            E = E - rtk  # estimate minus an RTK-measured reference
        cp[key].append(_cp_summary(E))
        r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
        rp[key].append([nmad(r[:, 0]), nmad(r[:, 1])])
        dk = (res.value("distortion") - truth.values["distortion"]) / res.sigma("distortion")
        zk[key].append(float(np.max(np.abs(dk))))
        d = res.value("c_mm") - truth.values["c_mm"]
        zc[key].append(float(np.mean(d / res.sigma("c_mm"))))
        dc[key].append(float(np.mean(d) * 1e3))

    dz = np.array([0.0, 0.0, HEIGHT_OFFSET_M])
    for seed in seeds:
        rtk = base.sigma_gcp_m * np.random.default_rng([seed, 15]).standard_normal((13, 3))
        obs, truth = simulate(scale, rng=seed, cfg=base, trajectory_error="spline")
        record("spline_truth", adjust_campaign(obs, base)[0], truth)
        obs, truth = simulate(scale, rng=seed, cfg=base)
        res = adjust_campaign(obs, base)[0]
        record("gauss_markov", res, truth)
        record("rtk", res, truth, rtk)
        record("image_y", adjust_campaign(obs, base, y_as_time=False)[0], truth)
        shifted = replace(obs, gcp_xyz_m=obs.gcp_xyz_m + dz)
        record("height_offset", adjust_campaign(shifted, base)[0], truth, np.tile(dz, (13, 1)))
        for key, cfg in (
            ("ref_image", replace(base, sigma_ref_image_px=SIGMA_REF_IMAGE_PX)),
            ("refraction", replace(base, refraction=True)),
            ("all_strips_rays", replace(base, cp_rays="all strips")),
            ("ripple", replace(base, distortion_ripple_px=RIPPLE_PX)),
        ):
            obs, truth = simulate(scale, rng=seed, cfg=cfg)
            record(key, adjust_campaign(obs, cfg)[0], truth)
        cfg = replace(base, sigma_ref_image_px=SIGMA_REF_IMAGE_PX, refraction=True)
        obs, truth = simulate(scale, rng=seed, cfg=cfg)
        record("combined", adjust_campaign(obs, cfg, y_as_time=False)[0], truth, rtk)
    return {
        "cp": {k: np.array(v) for k, v in cp.items()},
        "reprojection": {k: np.array(v) for k, v in rp.items()},
        "max_abs_z_distortion": {k: np.array(v) for k, v in zk.items()},
        "mean_z_c": zc,
        "mean_c_error_um": dc,
        "seeds": tuple(seeds),
        "scale": scale,
        "seconds": time.perf_counter() - t0,
    }


def _factor_rows(fac: dict) -> list[Row]:
    t2 = P002["002 Table 2"]
    k_nmad, k_mean = P002_STATS.index("nmad"), P002_STATS.index("mean")
    paper = (
        t2["e"][k_nmad],
        t2["n"][k_nmad],
        t2["h"][k_nmad],
        t2["h"][k_mean],
        t2["e"][k_nmad] / t2["n"][k_nmad],  # the E ≫ N asymmetry of 002 Table 2
    )
    rows = []
    for key, v in fac["cp"].items():
        for j, q in enumerate(_CP_QUANTITIES):
            rows.append(
                Row(
                    "002 check-point factors",
                    f"{key}.{q}",
                    "m" if q.endswith("_m") else "1",
                    paper=paper[j],
                    reproduced=float(np.mean(v[:, j])),
                    sigma=float(np.std(v[:, j], ddof=1)) if len(v) > 1 else None,
                    n_runs=len(v),
                    provenance="chosen",
                )
            )
    return rows


def _unmodelled_rows(fac: dict) -> list[Row]:
    """The table ``"unmodelled effect"``: the headline numbers (002 Table 1's NMADs, Table 2's
    check-point NMADs and mean height) with the distortion ripple on (factor run (h)) and off
    (the default run (a)), means over the factor runs' seeds ± their spread; no verdicts.
    """
    rows = []
    for state, key in (("on", "ripple"), ("off", "gauss_markov")):
        cols = np.c_[
            fac["reprojection"][key], fac["cp"][key][:, :4], fac["max_abs_z_distortion"][key]
        ]
        names = (*_REPROJ_QUANTITIES, *_CP_QUANTITIES[:4], "max_abs_z_distortion")
        for j, q in enumerate(names):
            unit = "px" if q.endswith("_px") else ("m" if q.endswith("_m") else "1")
            rows.append(
                Row(
                    "unmodelled effect",
                    f"ripple_{state}.{q}",
                    unit,
                    reproduced=float(np.mean(cols[:, j])),
                    sigma=float(np.std(cols[:, j], ddof=1)) if len(cols) > 1 else None,
                    n_runs=len(cols),
                )
            )
    return rows


def interval_optima(
    seeds, scale: float, intervals_s, tau_factors, first: dict | None = None
) -> dict[float, list[float]]:
    """The optimum node interval (:func:`optimum_interval`) of each seed's campaign, per
    correlation-time factor: ``{tau_factor: [optimum per seed]}``. ``first`` gives studies
    already run (``{tau_factor: study}`` of the first seed) restricted here to ``intervals_s``.
    """
    out: dict[float, list[float]] = {f: [] for f in tau_factors}
    for k, seed in enumerate(seeds):
        for f in tau_factors:
            if k == 0 and first is not None and f in first:
                st = [d for d in first[f] if d["interval_s"] in intervals_s]
            else:
                st = node_interval_study(seed, scale, intervals_s, f)
            out[f].append(optimum_interval(st))
    return out


def _interval_rows(study: list[dict], optima: dict) -> list[Row]:
    rows = []
    for d in study:
        dt = f"{d['interval_s']:g}s"
        rows += [
            Row("node interval", f"reprojection_nmad_x_{dt}_px", "px", reproduced=d["nmad_x_px"]),
            Row("node interval", f"reprojection_nmad_y_{dt}_px", "px", reproduced=d["nmad_y_px"]),
            Row("node interval", f"cp_rms_en_{dt}_m", "m", reproduced=d["cp_rms_en_m"]),
            Row("node interval", f"cp_rms_h_{dt}_m", "m", reproduced=d["cp_rms_h_m"]),
            Row("node interval", f"tp_rms_en_{dt}_m", "m", reproduced=d["tp_rms_en_m"]),
            Row("node interval", f"seconds_{dt}", "s", reproduced=d["seconds"]),
        ]
    for f, opt in optima.items():
        opt = np.asarray(opt, dtype=float)
        rows.append(
            Row(
                "node interval",
                f"optimum_interval_tau_x{f:g}_s",
                "s",
                paper=10.0,  # 002 §4: "the trajectory segmentation time step was set to 10 s"
                reproduced=float(np.median(opt)),
                sigma=float(np.std(opt, ddof=1)) if opt.size > 1 else None,
                n_runs=int(opt.size),
                provenance="chosen",
                # used only when the optimum is the same for every seed (no spread)
                reason=f"the optimum is {opt[0]:g} s for all {opt.size} seeds (no spread)",
            )
        )
    return rows


def optimum_interval(study: list[dict]) -> float:
    """The node interval with the smallest planimetric error of all tie points (s)."""
    return float(min(study, key=lambda d: d["tp_rms_en_m"])["interval_s"])
