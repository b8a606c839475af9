"""``hsgeo reproduce pushbroom-ba``: 002 Tables 1–3 and Fig. 8 from a simulated campaign.

The campaign (:mod:`hsgeo.simulate.pushbroom_campaign`) is simulated as ``(observations,
truth)``; the observations are adjusted (:mod:`hsgeo.workflows.pushbroom_ba`) twice, with the
four GCPs (002 Tables 1, 2, Fig. 8) and without (Table 3). ``scale`` thins the tie points (1.0: the
paper's 113,758). The node-interval study (:func:`node_interval_study`) is separate because it
runs one adjustment per interval. This module is the only place where the adjustment's
results meet the campaign's truth (check points, parameters, gross errors).
"""

from __future__ import annotations

import time

import numpy as np

from hsgeo.adjust import adjust, identifiability
from hsgeo.papers import P002, P002_STATS
from hsgeo.report import Reproduction, Row
from hsgeo.simulate.pushbroom_campaign import (
    CampaignConfig,
    CampaignObservations,
    CampaignTruth,
    simulate,
)
from hsgeo.stats import describe
from hsgeo.workflows.pushbroom_ba import CameraPrior, build_problem

__all__ = [
    "run",
    "adjust_campaign",
    "camera_prior",
    "cp_errors",
    "outlier_detection",
    "node_interval_study",
    "y_model_comparison",
]

RAD2DEG = 180 / np.pi
#: The reject threshold, in robust σ of the standardised residuals (ours: about the largest
#: residual / NMAD ratio of 002 Table 1, ≈ 6, with a margin).
REJECT_K = 5.0
#: Relative cost decrease at which the iteration stops: at full size 1e-6 of the cost is
#: ≈ 0.3, below half a unit of χ², i.e. far below any statistical effect.
FTOL = 1e-6
#: Model the residual across the line as a time (see
#: hsgeo.workflows.pushbroom_ba.build_problem): with
#: the image y of 002 eq. (2) the principal distance and the pitch corrections are biased (the
#: chapter shows by how much).
Y_AS_TIME = True


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
    res = adjust(
        p,
        blocks,
        reject_k=reject_k,
        ftol=ftol,
        progress=progress,
        reject_every_iteration=True,  # 002 §3.4
        keep_jacobian=True,
    )  # the check points' covariance (run)
    info["solver_seconds"] = res.seconds
    return res, p, blocks, info


def _stats_rows(table, names, data, unit, paper):
    rows = []
    for nm, col in zip(names, data.T, strict=True):
        d = describe(col)
        for k, st in enumerate(P002_STATS):
            rows.append(Row(table, f"{st}_{nm}_{unit}", unit, paper=paper[nm][k], reproduced=d[st]))
    return rows


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


def run(seed: int = 0, scale: float = 1.0, progress=None) -> Reproduction:
    """The chapter's numbers: 002 Tables 1–3, Fig. 8 and the estimated parameters."""
    t_start = time.perf_counter()
    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    rows: list[Row] = []
    res, p, blocks, info = adjust_campaign(obs, cfg, with_gcp=True, progress=progress, truth=truth)
    res0, _, _, info0 = adjust_campaign(obs, cfg, with_gcp=False, progress=progress)

    # -- 002 Table 1: reprojection errors of the tie points (with GCPs), px
    keep = ~res.outliers(0)
    r_px = res.residuals(0).reshape(-1, 2)[keep]
    rows += _stats_rows("002 Table 1", ("x", "y"), r_px, "px", P002["002 Table 1"])
    # -- 002 Tables 2 and 3: check points, m
    E_gcp, E_nogcp = cp_errors(res, truth), cp_errors(res0, truth)
    rows += _stats_rows("002 Table 2", ("e", "n", "h"), E_gcp, "m", P002["002 Table 2"])
    rows += _stats_rows("002 Table 3", ("e", "n", "h"), E_nogcp, "m", P002["002 Table 3"])
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
        )
    )
    # -- parameters: boresight, lever arm, distortion, c, nodes (with GCPs)
    par = []
    for name, unit, f in [
        ("boresight_rad", "deg", RAD2DEG),
        ("lever_arm_m", "m", 1.0),
        ("distortion", "", 1.0),
        ("c_mm", "mm", 1.0),
    ]:
        lab = res.params[name].labels()
        v, s, t = res.value(name).ravel(), res.sigma(name).ravel(), truth.values[name].ravel()
        for j in range(v.size):
            qn = lab[j].replace("_rad", "_deg") if unit == "deg" else lab[j]
            par.append(
                Row("parameters", qn, unit, reproduced=v[j] * f, sigma=s[j] * f, truth=t[j] * f)
            )
    nv, ns_, nt = res.value("nodes"), res.sigma("nodes"), truth.values["nodes"]
    lab = res.params["nodes"].labels()
    for j in range(nv.size):
        par.append(
            Row(
                "parameters",
                lab[j],
                "m" if j % 6 < 3 else "rad",
                reproduced=nv.ravel()[j],
                sigma=ns_.ravel()[j],
                truth=nt.ravel()[j],
            )
        )
    rows += par
    z = np.array([(r.reproduced - r.truth) / r.sigma for r in par])

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
        "share_params_within_3sigma": float(np.mean(np.abs(z) < 3)),
        "z_std_parameters": float(np.std(z)),
        "z_std_nodes": np.std((nv - nt) / ns_, axis=0).tolist(),
        "max_abs_z_camera": float(np.max(np.abs(z[: len(par) - nv.size]))),
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
    }
    return Reproduction("pushbroom-ba", seed, rows, meta, extras)


def y_model_comparison(seed: int = 0, scale: float = 0.3) -> list[dict]:
    """Principal-distance bias, pitch-node z spread and CP errors without GCPs: image y vs time."""
    from hsgeo.stats import nmad

    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    out = []
    for yt in (False, True):
        res, _, _, info = adjust_campaign(obs, cfg, with_gcp=False, y_as_time=yt)
        E = cp_errors(res, truth)
        dc = res.value("c_mm") - truth.values["c_mm"]
        zn = (res.value("nodes") - truth.values["nodes"]) / res.sigma("nodes")
        out.append(
            {
                "y_residual": "time" if yt else "image y (002 eq. 2)",
                "mean_c_error_um": float(dc.mean() * 1e3),
                "mean_z_c": float(np.mean(dc / res.sigma("c_mm"))),
                "std_z_pitch_nodes": float(np.std(zn[:, 4])),
                "nmad_e_m": float(nmad(E[:, 0])),
                "nmad_n_m": float(nmad(E[:, 1])),
                "nmad_h_m": float(nmad(E[:, 2])),
                "sigma0": res.sigma0,
                "iterations": res.iterations,
                "seconds": info["solver_seconds"],
            }
        )
    return out


def node_interval_study(
    seed: int = 0, scale: float = 0.05, intervals_s=(2.0, 5.0, 10.0, 30.0, 60.0)
):
    """CP errors, reprojection NMAD, unknowns and run time for several node intervals.

    The true trajectory error is a spline with nodes every 10 s (002's choice); intervals that
    nest it (5, 2 s) can represent it exactly and only add unknowns; coarser ones cannot.
    Returns a list of dicts (one per interval).
    """
    from hsgeo.stats import nmad

    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    out = []
    for dt in intervals_s:
        res, p, blocks, info = adjust_campaign(obs, cfg, with_gcp=True, node_interval_s=dt)
        E = cp_errors(res, truth)
        r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
        out.append(
            {
                "interval_s": dt,
                "n_nonpoint_unknowns": len(res.labels),
                "nmad_x_px": float(nmad(r[:, 0])),
                "nmad_y_px": float(nmad(r[:, 1])),
                "nmad_e_m": float(nmad(E[:, 0])),
                "nmad_n_m": float(nmad(E[:, 1])),
                "nmad_h_m": float(nmad(E[:, 2])),
                "rms_en_m": float(np.sqrt(np.mean(E[:, :2] ** 2))),
                "sigma0": res.sigma0,
                "seconds": info["solver_seconds"],
                "iterations": res.iterations,
            }
        )
    return out
