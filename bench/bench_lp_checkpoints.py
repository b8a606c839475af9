"""The LP chapter's check points over campaigns: measured as 002 measured them or by centroid.

For every seed, one rendered block of the 002 campaign (``--scale`` of ``hsgeo reproduce
lp-observations``, default 0.3: 1.1 % of the campaign) is retrieved once and adjusted with and
without the GCPs twice (:func:`hsgeo.reproduce.lp_runs.evaluate`): with the squares as 002
measured them — the matcher's tie points on them, at the pixel centre, in the strips and band
where it found them (:attr:`hsgeo.workflows.lp_observations.LpOptions.squares_as`) — and with
their blob centroids in every strip and band that sees them. Per seed and way: 002 Tables 2
and 3's statistics of the check-point errors, their σ̂ from the check points' joint covariance
and from the per-point blocks alone (:func:`hsgeo.reproduce.lp_observations.stat_sigma`), the
rays per check point; the no-GCP mean height and its σ̂ (joint); the principal distances
against the truth and against the exact twin (with and without GCPs); the observations' share
within 1 px of the median of their own tie point's rays and of the median of the *other* rays
(leave-one-out); and the observations' mean error per strip (flying height, heading), the
observation-level place a height offset would come from, and in thirds of x across the line.
Summaries over the seeds: the spread
of the z of STD and NMAD (against the seeds' mean) with each σ̂. Writes
``bench/results/lp_checkpoints_seeds.json``.

``--table3-only`` (``bench/results/lp_checkpoints_table3_seeds.json``) runs what 002 Table 3
from pixels needs and no more — the rendering, the retrieval and the adjustments with and
without GCPs (:func:`~hsgeo.reproduce.lp_runs.evaluate`, the centroid table, the twin and the
Monte Carlo left out) — and records, per campaign, the no-GCP check points' statistics, their
σ̂ from the joint covariance (the same draws as above: identical numbers), the draws' *mean*
of each statistic (:func:`hsgeo.reproduce.lp_observations.stat_draws`: the value the
covariance predicts for this campaign, whose check points' flying heights and c σ̂ are its
own), each check point's AGL and the principal distances without GCPs against the truth with
their σ̂. Its summary gives the z of STD and NMAD both about the campaigns' mean (the chapter's
z) and about each campaign's own predicted value, and the c errors in their σ̂.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from hsgeo.papers import P002_STATS
from hsgeo.reproduce.lp_judge import observation_errors_px, within_fractions
from hsgeo.reproduce.lp_observations import sim_scale, stat_draws, stat_sigma
from hsgeo.reproduce.lp_runs import _adjust, camera_prior, evaluate, exact_twin, parameter_z
from hsgeo.reproduce.lp_targets import N_DRAWS, twin_difference
from hsgeo.simulate.lp_campaign import simulate
from hsgeo.stats import describe

WAYS = ("tie_point", "centroid")


def _blocks(C) -> np.ndarray:
    k = C.shape[0] // 3
    return np.array([C[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] for i in range(k)])


def _table(E, C, rng) -> dict:
    """Statistics, σ̂ (joint and per-point blocks) and the mean height's joint σ̂."""
    k = len(E)
    h = np.arange(k) * 3 + 2
    return {
        "stats": [[float(describe(E[:, j])[s]) for s in P002_STATS] for j in range(3)],
        "sigma_joint": stat_sigma(C, rng, 1000).tolist(),
        "sigma_blocks": stat_sigma(_blocks(C), rng, 1000).tolist(),
        "mean_h_sigma_joint": float(np.sqrt(C[np.ix_(h, h)].sum()) / k),
        "n": int(k),
    }


def _c(result) -> tuple[np.ndarray, np.ndarray]:
    return result.value("c_mm").ravel(), result.sigma("c_mm").ravel()


def _per_strip(ev, obs) -> list:
    """Mean observation error (x, y px) of the tie points' observations per strip, with the
    strip's flying height and heading from the navigation."""
    tab = ev["retrieval"].table
    e = ev["obs_errors_px"]
    tie = ~ev["is_square"]
    out = []
    for s in obs.strips:
        sel = tie & (tab["strip"].astype(str).to_numpy() == str(s.strip_id))
        t = np.asarray(s.t_s, float)
        p0 = obs.navigation.pose(t[:1])[0][0]
        p1 = obs.navigation.pose(t[-1:])[0][0]
        out.append(
            {
                "strip": str(s.strip_id),
                "height_m": float(p0[2]),
                "heading_deg": float(np.degrees(np.arctan2(p1[0] - p0[0], p1[1] - p0[1]))),
                "n": int(sel.sum()),
                "mean_dx_px": float(np.mean(e[sel, 0])) if sel.any() else None,
                "mean_dy_px": float(np.mean(e[sel, 1])) if sel.any() else None,
            }
        )
    return out


def _across(ev) -> list:
    """Mean observation error (x, y px) of the tie points' observations in thirds of x across
    the line (the column: a c or principal-point error grows with x, a heading error does not)."""
    tab = ev["retrieval"].table
    tie = ~ev["is_square"]
    x = tab["x_px"].to_numpy(float)[tie]
    e = ev["obs_errors_px"][tie]
    q = np.quantile(x, [0.0, 1 / 3, 2 / 3, 1.0])
    b = np.clip(np.searchsorted(q, x, side="right") - 1, 0, 2)
    return [
        {
            "x_mean_px": float(x[b == i].mean()),
            "n": int(np.sum(b == i)),
            "mean_dx_px": float(e[b == i, 0].mean()),
            "mean_dy_px": float(e[b == i, 1].mean()),
        }
        for i in range(3)
        if np.any(b == i)
    ]


def _agl(res, d, obs) -> list:
    """Per no-GCP check point, the mean height above the squares (navigation) of the lines
    that observe it in the table it was adjusted from (``res`` None: the centroid table)."""
    if res is None:
        return []
    tab = res.table  # evaluate's: the check points as tie points, the GCPs by centroid
    pid = tab["point_id"].astype(str).to_numpy()
    z = obs.navigation.pose(tab["t_s"].to_numpy(float))[0][:, 2]
    h0 = float(np.mean(obs.square_xyz_m[:, 2]))
    return [float(np.mean(z[pid == str(c)]) - h0) for c in d["cp_ids_nogcp"]]


def one_seed(seed: int, scale: float) -> dict:
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 37])
    obs, truth = simulate(sim_scale(scale), rng=seed)
    ev = evaluate(obs, truth, seed)
    tw = exact_twin(ev, obs, truth)
    cam = camera_prior(obs, truth.cfg)
    res = ev["retrieval"]
    tie = ~ev["is_square"]
    loo = observation_errors_px(
        res.table, truth, obs.square_ids, truth.square_xyz_m, leave_one_out=True
    )
    out = {
        "seed": seed,
        "within_1px_median": within_fractions(ev["obs_errors_px"][tie])[1.0],
        "within_1px_leave_one_out": within_fractions(loo[tie])[1.0],
        "within_half_px_median": within_fractions(ev["obs_errors_px"][tie])[0.5],
        "within_half_px_leave_one_out": within_fractions(loo[tie])[0.5],
        "rays_per_tie_point": float(res.table.loc[tie].groupby("point_id").size().mean()),
        "per_strip": _per_strip(ev, obs),
        "across_line": _across(ev),
    }
    for way in WAYS:
        d = ev if way == "tie_point" else ev["centroid"]
        out[way] = {
            "gcp_ids": list(d["gcp_ids"]),
            "cp_ids": [str(x) for x in d["cp_ids"]],
            "rays": np.asarray(d["cp_rays"]).tolist(),
            "table2": _table(d["cp_errors_m"], d["cp_cov_m2"], rng),
            "table3": _table(d["cp_errors_nogcp_m"], d["cp_cov_nogcp_m2"], rng),
            "cp_errors_nogcp_m": np.asarray(d["cp_errors_nogcp_m"]).tolist(),
            # the mean flying height above the squares of the strips each no-GCP check point
            # is observed in (issue 37: the no-GCP height offset scales with it)
            "cp_agl_nogcp_m": _agl(ev["retrieval"] if way == "tie_point" else None, d, obs),
        }
    # principal distances: retrieved, twin (with GCPs), and without GCPs both
    c_true = np.asarray(truth.camera.c_mm, float)
    c, s = _c(ev["adjusted"].result)
    ct, st = _c(tw["adjusted"].result)
    c0, s0 = _c(ev["adjusted_nogcp"].result)
    e = ev["obs_errors_px"]
    twin_tab = res.table.copy()
    twin_tab["x_px"] -= e[:, 0]
    twin_tab["y_px"] -= e[:, 1]
    r0t, _, _ = _adjust(replace(res, table=twin_tab), obs, cam, False, ev["gcp_ids"])
    c0t, s0t = _c(r0t.result)
    ids = [str(x) for x in ev["cp_ids_nogcp"]]
    k = [list(map(str, obs.square_ids)).index(i) for i in ids]
    pos = {str(v): j for j, v in enumerate(r0t.point_ids)}
    E0t = r0t.result.value("points_m")[[pos[i] for i in ids]] - truth.square_xyz_m[k]
    out["c"] = {
        "truth_mm": c_true.tolist(),
        "gcp": {
            "value": c.tolist(),
            "sigma": s.tolist(),
            "twin": ct.tolist(),
            "twin_sigma": st.tolist(),
        },
        "nogcp": {
            "value": c0.tolist(),
            "sigma": s0.tolist(),
            "twin": c0t.tolist(),
            "twin_sigma": s0t.tolist(),
        },
    }
    out["twin_nogcp_mean_h_m"] = float(np.mean(E0t[:, 2]))
    # without GCPs, retrieved − twin in the σ of the difference (Monte Carlo over the
    # retrieval's observation errors, each point's with a random sign; lp_targets), with the
    # check points' mean height and the mean c of every draw: the c–H coupling, numerically
    tw0 = {"adjusted": r0t, "parameters": parameter_z(r0t.result, truth.camera)}
    td0 = twin_difference(ev, obs, truth, tw0, n_draws=N_DRAWS, rng=[seed, 41], gcp=False)
    out["nogcp_twin_mc"] = {
        k: (np.asarray(v, float).tolist() if k != "labels" else list(map(str, v)))
        for k, v in td0.items()
        if k not in ("draws", "method", "gcp")
    }
    out["parameters_vs_twin_z"] = float(
        np.sqrt(
            np.mean(
                np.concatenate(
                    [
                        ((v - tw["parameters"][n][1]) / sg) ** 2
                        for n, (_, v, sg, _) in ev["parameters"].items()
                    ]
                )
            )
        )
    )
    out["seconds"] = time.perf_counter() - t0
    return out


def one_seed_table3(seed: int, scale: float) -> dict:
    """002 Table 3 from pixels of one campaign and what its σ̂ predicts (module docstring):
    :func:`~hsgeo.reproduce.lp_runs.evaluate`'s retrieval and its no-GCP adjustment and check
    points (``_adjust`` / ``_check_points`` as ``_squares_judged`` calls them), without the
    adjustment with GCPs and the match judging, which Table 3 does not use."""
    from hsgeo.reproduce.lp_runs import _check_points, gcps_by_centroid, retrieval_inputs
    from hsgeo.workflows.lp_observations import LpOptions, retrieve

    t0, c0 = time.perf_counter(), time.process_time()
    cpu = {}
    obs, truth = simulate(sim_scale(scale), rng=seed)
    res = retrieve(retrieval_inputs(obs), LpOptions(rng=seed, squares_as="tie_point"))
    res = replace(res, table=gcps_by_centroid(res, obs.gcp_ids))
    cpu["simulate_retrieve"] = time.process_time() - c0
    c1 = time.process_time()
    pid = res.table["point_id"].to_numpy().astype(str)
    measured = set(pid) & {str(s) for s in obs.square_ids}
    gcp_ids = [g for g in obs.gcp_ids if g in measured]
    cps = [s for s in obs.square_ids if s not in obs.gcp_ids]
    cam = camera_prior(obs, truth.cfg)
    r0, pin0, _ = _adjust(res, obs, cam, False, gcp_ids)
    E0, cov0, ids0, _ = _check_points(r0, pin0, obs, truth, cps)
    cpu["adjust_nogcp"] = time.process_time() - c1
    d = {"cp_ids_nogcp": list(ids0)}
    t3 = _table(E0, cov0, np.random.default_rng([seed, 37]))
    dr = stat_draws(cov0, np.random.default_rng([seed, 38]), 1000)
    c0_, s0 = _c(r0.result)
    return {
        "seed": seed,
        "table3": t3,
        "table3_draws_mean": dr.mean(axis=0).tolist(),
        "table3_draws_sd": dr.std(axis=0, ddof=1).tolist(),
        "cp_ids_nogcp": [str(x) for x in ids0],
        "cp_errors_nogcp_m": np.asarray(E0).tolist(),
        "cp_agl_nogcp_m": _agl(res, d, obs),
        "c_nogcp": {
            "truth_mm": np.asarray(truth.camera.c_mm, float).tolist(),
            "value": c0_.tolist(),
            "sigma": s0.tolist(),
        },
        "cpu_s": cpu,
        "seconds": time.perf_counter() - t0,
    }


def summary_table3(runs) -> dict:
    """The z of STD and NMAD of the no-GCP heights over the campaigns, two ways, and the
    no-GCP principal distances in their σ̂ (module docstring)."""
    i_std, i_nmad = P002_STATS.index("std"), P002_STATS.index("nmad")
    i_mean = P002_STATS.index("mean")
    S = np.array([r["table3"]["stats"] for r in runs])[:, 2]  # heights: (seeds, 6)
    sg = np.array([r["table3"]["sigma_joint"] for r in runs])[:, 2]
    mu = np.array([r["table3_draws_mean"] for r in runs])[:, 2]
    out = {"n_campaigns": len(runs)}
    for st, i in (("std", i_std), ("nmad", i_nmad)):
        z_pool = (S[:, i] - S[:, i].mean()) / sg[:, i]
        z_own = (S[:, i] - mu[:, i]) / sg[:, i]
        out[f"{st}_h_m"] = S[:, i].tolist()
        out[f"{st}_h_sigma_joint_m"] = sg[:, i].tolist()
        out[f"{st}_h_predicted_m"] = mu[:, i].tolist()
        out[f"{st}_h_z_about_campaigns_mean"] = z_pool.tolist()
        out[f"sd_z_{st}_h_about_campaigns_mean"] = float(np.std(z_pool, ddof=1))
        out[f"{st}_h_z_about_own_prediction"] = z_own.tolist()
        out[f"sd_z_{st}_h_about_own_prediction"] = float(np.std(z_own, ddof=1))
        out[f"rms_z_{st}_h_about_own_prediction"] = float(np.sqrt(np.mean(z_own**2)))
    mh = S[:, i_mean]
    smh = np.array([r["table3"]["mean_h_sigma_joint"] for r in runs])
    out["mean_h_m"] = mh.tolist()
    out["mean_h_z"] = (mh / smh).tolist()
    out["rms_mean_h_z"] = float(np.sqrt(np.mean((mh / smh) ** 2)))
    zc, agl_spread = [], []
    for r in runs:
        v, s_, t = (np.asarray(r["c_nogcp"][k], float) for k in ("value", "sigma", "truth_mm"))
        ok = np.isfinite(s_) & (s_ > 0)
        zc.append(((v - t) / np.where(ok, s_, np.nan)).tolist())
        a = np.asarray(r["cp_agl_nogcp_m"], float)
        agl_spread.append(float(np.std(a, ddof=1)) if a.size > 1 else float("nan"))
    zc_a = np.array(zc, float)
    out["c_z_vs_truth_per_band"] = zc
    out["rms_c_z_vs_truth_bands_0_3"] = float(np.sqrt(np.nanmean(zc_a[:, :4] ** 2)))
    out["rms_c_z_vs_truth_bands_4_6"] = float(np.sqrt(np.nanmean(zc_a[:, 4:] ** 2)))
    out["mean_c_z_vs_truth_bands_4_6"] = float(np.nanmean(zc_a[:, 4:]))
    out["cp_agl_sd_m"] = agl_spread
    return out


def _summary(runs) -> dict:
    out = {}
    i_std, i_nmad = P002_STATS.index("std"), P002_STATS.index("nmad")
    i_mean = P002_STATS.index("mean")
    for way in WAYS:
        for tab in ("table2", "table3"):
            S = np.array([r[way][tab]["stats"] for r in runs])  # (seeds, 3, 6)
            for kind in ("sigma_joint", "sigma_blocks"):
                sg = np.array([r[way][tab][kind] for r in runs])
                z = (S - S.mean(axis=0)) / sg
                out[f"{way}.{tab}.{kind}.sd_z_std_h"] = float(np.std(z[:, 2, i_std], ddof=1))
                out[f"{way}.{tab}.{kind}.sd_z_nmad_h"] = float(np.std(z[:, 2, i_nmad], ddof=1))
                out[f"{way}.{tab}.{kind}.sd_z_per_stat"] = np.std(z, axis=0, ddof=1).tolist()
            out[f"{way}.{tab}.mean_over_seeds"] = S.mean(axis=0).tolist()
            out[f"{way}.{tab}.sd_over_seeds"] = S.std(axis=0, ddof=1).tolist()
            out[f"{way}.{tab}.median_sigma_joint"] = np.median(
                [r[way][tab]["sigma_joint"] for r in runs], axis=0
            ).tolist()
        mh = np.array([r[way]["table3"]["stats"][2][i_mean] for r in runs])
        smh = np.array([r[way]["table3"]["mean_h_sigma_joint"] for r in runs])
        out[f"{way}.table3.mean_h"] = mh.tolist()
        out[f"{way}.table3.mean_h_z"] = (mh / smh).tolist()
        out[f"{way}.rays_mean"] = float(np.mean([np.mean(r[way]["rays"]) for r in runs]))
    for g in ("gcp", "nogcp"):
        v = np.array([r["c"][g]["value"] for r in runs])
        s = np.array([r["c"][g]["sigma"] for r in runs])
        t = np.array([r["c"][g]["twin"] for r in runs])
        tr = np.array([r["c"]["truth_mm"] for r in runs])
        out[f"c_{g}.z_vs_truth"] = ((v - tr) / s).tolist()
        out[f"c_{g}.z_vs_twin"] = ((v - t) / s).tolist()
        out[f"c_{g}.twin_minus_truth_um"] = ((t - tr) * 1e3).tolist()
        out[f"c_{g}.minus_truth_um"] = ((v - tr) * 1e3).tolist()
    out["twin_nogcp_mean_h_m"] = [r["twin_nogcp_mean_h_m"] for r in runs]
    for k in ("within_1px_median", "within_1px_leave_one_out"):
        w = np.array([r[k] for r in runs])
        out[k] = w.tolist()
        out[k + ".seeds_ge_95pct"] = int(np.sum(w >= 0.95))
    out["rms_z_parameters_vs_twin"] = [r["parameters_vs_twin_z"] for r in runs]
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=float, default=0.3)
    ap.add_argument("--seeds", type=int, nargs="+", default=list(range(8)))
    ap.add_argument(
        "--out", default=str(Path(__file__).parent / "results" / "lp_checkpoints_seeds.json")
    )
    ap.add_argument(
        "--merge",
        nargs="+",
        metavar="JSON",
        help="merge the runs of these result files (seeds run in parallel) into --out",
    )
    ap.add_argument(
        "--table3-only",
        action="store_true",
        help="002 Table 3 from pixels and its predicted values only (module docstring)",
    )
    a = ap.parse_args(argv)
    if a.table3_only:
        out = a.out
        if out == ap.get_default("out"):
            out = str(Path(__file__).parent / "results" / "lp_checkpoints_table3_seeds.json")
        t0, runs = time.perf_counter(), []
        if a.merge:  # seeds run in parallel: one run per seed, the first file's
            by_seed = {}
            for f in a.merge:
                for r in json.loads(Path(f).read_text())["runs"]:
                    by_seed.setdefault(r["seed"], r)
            runs = [by_seed[k] for k in sorted(by_seed)]
        todo = [] if a.merge else a.seeds
        for seed in [None, *todo]:
            if seed is not None:
                runs.append(one_seed_table3(seed, a.scale))
                print(f"seed {seed}: {runs[-1]['seconds']:.0f} s", flush=True)
            if not runs:
                continue
            doc = {
                "bench": "lp_checkpoints_table3_seeds",
                "scale": a.scale,
                "sim_scale": sim_scale(a.scale),
                "seeds": [r["seed"] for r in runs],
                "stats": list(P002_STATS),
                "summary": summary_table3(runs),
                "runs": runs,
                "wall_s": time.perf_counter() - t0,
                "machine": platform.platform(),
            }
            Path(out).write_text(json.dumps(doc, indent=1))
        return doc
    if a.merge:
        docs = [json.loads(Path(f).read_text()) for f in a.merge]
        # one run per seed (the first file's, when a seed was run twice)
        by_seed = {}
        for d in docs:
            for r in d["runs"]:
                by_seed.setdefault(r["seed"], r)
        runs = [by_seed[k] for k in sorted(by_seed)]
        return write(runs, docs[0]["scale"], a.out, sum(d["wall_s"] for d in docs))
    t0 = time.perf_counter()
    runs = []
    for seed in a.seeds:
        runs.append(one_seed(seed, a.scale))
        print(f"seed {seed}: {runs[-1]['seconds']:.0f} s", flush=True)
        doc = write(runs, a.scale, a.out, time.perf_counter() - t0)  # after every seed
    return doc


def write(runs, scale, out, wall_s) -> dict:
    """The JSON of the seeds run so far (``runs``), with their summary."""
    doc = {
        "bench": "lp_checkpoints_seeds",
        "scale": scale,
        "sim_scale": sim_scale(scale),
        "seeds": [r["seed"] for r in runs],
        "stats": list(P002_STATS),
        "summary": _summary(runs),
        "runs": runs,
        "wall_s": wall_s,
        "machine": platform.platform(),
    }
    Path(out).write_text(json.dumps(doc, indent=1))
    return doc


if __name__ == "__main__":
    main()
