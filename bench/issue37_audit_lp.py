"""Issue 37's four LP lines (the check points' σ̂, the independent judges) for
``bench/issue37_audit.py``: read from the LP benches' result files in ``bench/results``
(bench_lp_checkpoints.py, its ``--table3-only``, bench_lp_judges.py, its ``--targets-only``)
through the chapter's own :func:`hsgeo.reproduce.lp_campaigns.checkpoint_campaigns`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def _trace() -> dict | None:
    """bench/lp_checkpoint_trace.py's record (one campaign traced point by point), if run."""
    f = sorted(RESULTS.glob("lp_checkpoint_trace_seed*.json"))
    if not f:
        return None
    d = json.loads(f[0].read_text(encoding="utf-8"))
    return {
        "file": str(f[0].relative_to(RESULTS.parent.parent)),
        "seed": d["seed"],
        "check_points": [
            {k: p[k] for k in ("id", "h_error_m", "agl_m", "strips", "ground_offset_from_centre_m")}
            for p in d["check_points"]
        ],
        "fit_k_h_per_agl": d["fit_k_h_per_agl"],
        "std_h_m": d["std_h_m"],
        "std_h_after_agl_m": d["std_h_after_agl_m"],
        "farthest_over_nmad": d["farthest_over_nmad"],
        "farthest_after_agl_over_nmad": d["farthest_after_agl_over_nmad"],
    }


def _within_line(full_doc: dict) -> dict:
    """The within-1-px line from ``lp_judges_targets_seeds.json`` (bench_lp_judges.py
    --targets-only: the mended targets, the judge alone), the full bench's shares on the same
    campaigns beside it (``lp_judges_seeds.json``, ``full_doc``), and the white targets'
    numbers (``lp_judges_white_targets_seeds.json``) as "before"."""
    f = RESULTS / "lp_judges_targets_seeds.json"
    old = json.loads((RESULTS / "lp_judges_white_targets_seeds.json").read_text(encoding="utf-8"))[
        "summary"
    ]
    before = {
        "file": "bench/results/lp_judges_white_targets_seeds.json (white 2-px targets over the "
        "texture)",
        "within_1px_vs_targets_per_seed": old["within_1px_vs_targets_per_seed"],
        "seeds_meeting_95pct": old["seeds_meeting_95pct_vs_targets"],
    }
    if not f.is_file():
        return {
            "line": "the within-1-px share against an independent reference is ≥ 95 % in ≥ 7 "
            "of 8 campaigns",
            "status": "short",
            "evidence": {
                "before": before,
                "why_short": f"{f.name} not written (run bench/bench_lp_judges.py --targets-only)",
            },
        }
    d = json.loads(f.read_text(encoding="utf-8"))
    j, runs = d["summary"], d["runs"]
    n, met = j["n_seeds"], j["seeds_meeting_95pct_vs_targets"]
    return {
        "line": "the within-1-px share against an independent reference is ≥ 95 % in ≥ 7 of 8 "
        "campaigns",
        "status": "met" if n >= 8 and met >= 7 else "short",
        "evidence": {
            "file": str(f.relative_to(RESULTS.parent.parent)),
            "target": d.get("target_config"),
            "n_campaigns": n,
            "seeds_meeting_95pct_vs_point_targets": met,
            "within_1px_vs_targets_per_seed": j["within_1px_vs_targets_per_seed"],
            "within_half_px_vs_targets_per_seed": j["within_half_px_vs_targets_per_seed"],
            "observations_on_targets_per_seed": j["observations_on_targets_per_seed"],
            "targets_found_per_seed": j["targets_found_per_seed"],
            "error_vs_target_px_quantiles_50_90_99_100_per_seed": [
                r["error_vs_target_px_quantiles_50_90_99_100"] for r in runs
            ],
            "on_target_distance_m_quantiles_50_90_100": j[
                "on_target_distance_m_quantiles_50_90_100"
            ],
            # the same observations against the median of their own tie point's rays and
            # against the others' (leave-one-out)
            "within_1px_same_observations_vs_median_per_seed": j[
                "within_1px_same_observations_vs_median_per_seed"
            ],
            "within_1px_same_observations_vs_leave_one_out_per_seed": j[
                "within_1px_same_observations_vs_leave_one_out_per_seed"
            ],
            "before": before,
            "full_bench_same_campaigns": {
                "file": "bench/results/lp_judges_seeds.json",
                "within_1px_vs_targets_per_seed": full_doc["summary"][
                    "within_1px_vs_targets_per_seed"
                ],
                "target_config": full_doc.get("target_config"),
            },
            "what_was_mended": "the reference, not the bar: the white 2-px squares painted over "
            "the texture clip at dn_max in all seven bands and take the texture's asymmetry, so "
            "BRISK found them up to 0.4 m from their recorded centre (the old failing seeds' "
            "tie points sat 0.17-0.42 m off it while their rays agreed with each other); the "
            "targets are now made as survey targets are — a 0.6 m square of reflectance 0.45 "
            "(unsaturated) centred on a uniform 3 m dark square wider than FAST's 3-px circle "
            "in every strip — so the image is symmetric about the recorded centre and the "
            "detector fires there (src/hsgeo/reproduce/lp_targets.py TARGET_REFLECTANCE, "
            "TARGET_SURROUND_M; LpConfig.target_reflectance / target_surround_m)",
            "what_the_judge_shares_with_what_it_judges": "the renderer's camera model and true "
            "trajectory (they drew the pixels and project the reference: the truth, by design); "
            "which tie points are judged (those whose own observations' median true ground "
            "point lies within ON_TARGET_M = 0.6 m of a target: the on-target distances' "
            "quantiles above show the gap below 0.6 m). Not shared: the reference position, "
            "the target's centre fixed before any pixel is rendered, which no observation, "
            "median or adjustment moves",
            "cost": {
                "cpu_s_per_seed": j["cpu_s_per_seed"],
                "note": "the judge alone (render, retrieve, judge: 11-15 CPU-s per seed); the "
                "full bench (220-580 s wall per seed on the loaded machine) adds the adjustment, "
                "the twin and 2 x 16 Monte Carlo adjustments, which the within-1-px share does "
                "not use",
            },
            "tried_before_choosing_on_seeds_4_and_7": {
                "white_2px_over_texture (before)": [0.918, 0.897],
                "white_on_1.8m_dark_surround": [0.974, 0.970],
                "grey_0.45_on_1.8m_dark_surround": [0.906, 1.0],
                "grey_0.45_on_3m_dark_surround (chosen)": [1.0, 1.0],
                "why": "on 1.8 m the 2500 m strips' FAST circle (1.2 m) reaches the bright "
                "near-infrared grass past the surround: seed 4's failing tie points were all "
                "from those strips, 0.54-0.57 m off the centre",
            },
        },
    }


def _sd_z_line(cp: dict, cp_file: Path, sd: dict, n: int, ok_sd: bool) -> dict:
    """The SD-of-z line: the chapter's z (about the campaigns' mean, from
    lp_checkpoints_seeds.json through checkpoint_campaigns) and, from
    ``lp_checkpoints_table3_seeds.json`` (bench_lp_checkpoints.py --table3-only) when written,
    the same statistics about each campaign's own predicted value, with the no-GCP c errors in
    their σ̂ — what the σ̂ carries and whether the c error exceeds it."""
    f = RESULTS / "lp_checkpoints_table3_seeds.json"
    t3 = json.loads(f.read_text(encoding="utf-8")) if f.is_file() else None
    ev: dict = {
        "file": str(cp_file.relative_to(RESULTS.parent.parent)),
        "n_campaigns": n,
        "sd_z_std_h_table3_joint": sd["std"],
        "sd_z_nmad_h_table3_joint": sd["nmad"],
        "h_farthest_over_nmad": cp["h_farthest_over_nmad"],
        "h_farthest_m": cp["h_farthest_m"],
        "traced": _trace(),
        **{
            k: cp[k]
            for k in (
                "agl_k",
                "std_h_m",
                "std_h_after_agl_m",
                "h_farthest_after_agl_over_nmad",
                "agl_mix_campaigns",
            )
            if k in cp
        },
    }
    if t3 is not None:
        sm = t3["summary"]
        ev["table3_bench"] = {
            "file": str(f.relative_to(RESULTS.parent.parent)),
            "n_campaigns": sm["n_campaigns"],
            **{
                k: sm[k]
                for k in (
                    "std_h_m",
                    "std_h_sigma_joint_m",
                    "std_h_predicted_m",
                    "std_h_z_about_campaigns_mean",
                    "sd_z_std_h_about_campaigns_mean",
                    "std_h_z_about_own_prediction",
                    "sd_z_std_h_about_own_prediction",
                    "rms_z_std_h_about_own_prediction",
                    "nmad_h_m",
                    "nmad_h_sigma_joint_m",
                    "nmad_h_predicted_m",
                    "sd_z_nmad_h_about_campaigns_mean",
                    "sd_z_nmad_h_about_own_prediction",
                    "rms_z_nmad_h_about_own_prediction",
                    "mean_h_m",
                    "mean_h_z",
                    "rms_mean_h_z",
                    "c_z_vs_truth_per_band",
                    "rms_c_z_vs_truth_bands_0_3",
                    "rms_c_z_vs_truth_bands_4_6",
                    "mean_c_z_vs_truth_bands_4_6",
                    "cp_agl_sd_m",
                )
            },
        }
    ev.update(_sd_z_findings(cp, t3))
    if t3 is not None:
        # the status from the table-3 bench, with each campaign's z about its own predicted
        # value: the campaigns do not share one expected STD (their check points' flying
        # heights and bands differ), so the campaigns' mean is not E[x] of any of them; the
        # z about the mean is kept beside it (evidence) and the bar is not moved
        sm = t3["summary"]
        n = sm["n_campaigns"]
        ok_sd = all(
            abs(sm[f"sd_z_{k}_h_about_own_prediction"] - 1.0) <= 0.3 for k in ("std", "nmad")
        )
        ev["z_used_for_status"] = (
            "about each campaign's own predicted value (the mean of the joint draws, "
            "stat_draws): z = (x − E_draws[x]) / σ_draws[x]; the chapter's z about the "
            "campaigns' mean is in table3_bench and the finding"
        )
    return {
        "line": "Over 8 campaigns: the z of std_h and nmad_h from pixels has a standard "
        "deviation of 1 ± 0.3",
        "status": "met" if ok_sd and n >= 8 else "short",
        "evidence": ev,
    }


def _sd_z_findings(cp: dict, t3: dict | None) -> dict:
    """What the table-3 bench's numbers say about the SD of z (computed here, not typed):

    * do the draws carry the c uncertainty seen from two flying heights? Without GCPs a c
      error u moves a check point's height by −AGL·u/c, so the STD of the heights gains
      |u|·SD(AGL)/c, half-normal in u: its spread is √(1 − 2/π)·(σ̂_c/c)·SD(AGL). Beside the
      joint draws' σ̂ of the STD per campaign with check points at two heights;
    * is the c error larger than its σ̂ (c − truth in σ̂, by band group);
    * how much of the SD of z is the z's centre (the campaigns' mean, whose expected value the
      campaigns do not share) against each campaign's own predicted value.
    """
    if t3 is None:
        return {
            "why_short": "bench/results/lp_checkpoints_table3_seeds.json not written (run "
            "bench/bench_lp_checkpoints.py --table3-only --scale 0.05)"
        }
    sm, runs = t3["summary"], t3["runs"]
    i_std = t3["stats"].index("std")
    mixed = []
    for r in runs:
        a = np.asarray(r["cp_agl_nogcp_m"], float)
        sd_a = float(np.std(a, ddof=1)) if a.size > 1 else 0.0
        if sd_a < 100.0:
            continue
        c = np.asarray(r["c_nogcp"]["value"], float)
        sc = np.asarray(r["c_nogcp"]["sigma"], float)
        ok = np.isfinite(sc) & (sc > 0)
        pred = float(np.sqrt(1 - 2 / np.pi) * np.mean(sc[ok] / c[ok]) * sd_a)
        got = float(r["table3"]["sigma_joint"][2][i_std])
        mixed.append(
            {
                "seed": r["seed"],
                "sd_agl_m": sd_a,
                "sigma_c_over_c": float(np.mean(sc[ok] / c[ok])),
                "sigma_std_h_from_c_alone_m": pred,
                "sigma_std_h_joint_draws_m": got,
                "ratio": got / pred if pred > 0 else None,
            }
        )
    ratios = [m["ratio"] for m in mixed if m["ratio"] is not None]
    sd_pool = (sm["sd_z_std_h_about_campaigns_mean"], sm["sd_z_nmad_h_about_campaigns_mean"])
    sd_own = (sm["sd_z_std_h_about_own_prediction"], sm["sd_z_nmad_h_about_own_prediction"])
    z_pool = np.asarray(sm["std_h_z_about_campaigns_mean"], float)
    worst = int(np.argmax(np.abs(z_pool)))
    return {
        "draws_carry_c_and_agl": {
            "campaigns_with_check_points_at_two_heights": mixed,
            "ratio_joint_over_c_alone_range": [min(ratios), max(ratios)] if ratios else None,
        },
        "c_error_in_its_sigma": {
            "rms_z_bands_0_3": sm["rms_c_z_vs_truth_bands_0_3"],
            "rms_z_bands_4_6": sm["rms_c_z_vs_truth_bands_4_6"],
            "mean_z_bands_4_6": sm["mean_c_z_vs_truth_bands_4_6"],
            "rms_z_mean_h": sm["rms_mean_h_z"],
        },
        "finding": (
            f"The joint draws carry the c uncertainty and each check point's AGL: where a "
            f"campaign's check points are seen from two heights ({len(mixed)} of "
            f"{len(runs)}), the draws' σ of the STD of the heights is "
            + (f"{min(ratios):.2f}–{max(ratios):.2f}" if ratios else "—")
            + " times the half-normal spread that σ̂_c alone gives, √(1 − 2/π)·(σ̂_c/c)·SD(AGL) "
            "(a formula that leaves out the bands' separate c and the points' own noise, which "
            "the draws hold). "
            f"The c error is larger than its σ̂ in the near-infrared bands 4–6 "
            f"(RMS z {sm['rms_c_z_vs_truth_bands_4_6']:.2f}, mean "
            f"{sm['mean_c_z_vs_truth_bands_4_6']:+.2f}; bands 0–3: RMS "
            f"{sm['rms_c_z_vs_truth_bands_0_3']:.2f}), and so is the no-GCP mean height "
            f"(RMS z {sm['rms_mean_h_z']:.2f}): the σ̂ of what c moves is too small by about "
            f"that factor. Most of the SD of z is the z's centre: about the campaigns' mean "
            f"(the chapter's z) it is {sd_pool[0]:.2f} (STD) and {sd_pool[1]:.2f} (NMAD); about "
            f"each campaign's own predicted value (the draws' mean: its own flying heights "
            f"and σ̂_c) {sd_own[0]:.2f} and {sd_own[1]:.2f}. The campaigns do not share one "
            f"expected STD — seed {runs[worst]['seed']}'s z about the mean, "
            f"{z_pool[worst]:+.1f}, is its STD of "
            f"{sm['std_h_m'][worst]:.2f} m against a mean of "
            f"{float(np.mean(sm['std_h_m'])):.2f} m in a σ̂ of "
            f"{sm['std_h_sigma_joint_m'][worst]:.2f} m"
        ),
        "why_short": None
        if all(abs(v - 1) <= 0.3 for v in sd_own) and len(runs) >= 8
        else f"the SD of z about each campaign's own prediction is {sd_own[0]:.2f} / "
        f"{sd_own[1]:.2f} over {len(runs)} campaigns",
    }


def lp_lines() -> list[dict]:
    """The LP chapter's four lines from the two 8-campaign benches (bench_lp_checkpoints.py,
    bench_lp_judges.py), read through the chapter's own function for the first."""
    from hsgeo.reproduce.lp_campaigns import checkpoint_campaigns

    cp_file, jd_file = RESULTS / "lp_checkpoints_seeds.json", RESULTS / "lp_judges_seeds.json"
    cp_doc = json.loads(cp_file.read_text(encoding="utf-8"))
    cp = checkpoint_campaigns(cp_doc)
    jd_doc = json.loads(jd_file.read_text(encoding="utf-8"))
    jd = jd_doc["summary"]
    sd = {k: cp[f"table3.{k}_h"]["sd_z"] for k in ("std", "nmad")}
    n = cp["n_campaigns"]
    ok_sd = all(abs(v - 1.0) <= 0.3 for v in sd.values())
    rms = jd["rms_z_sigma_of_difference"]
    h_in, c_in = cp["mean_h_nogcp_within"], cp["c_within"]
    mc = "c_within_mc" in cp  # the bench's no-GCP Monte Carlo of retrieved − twin
    return [
        _sd_z_line(cp, cp_file, sd, n, ok_sd),
        _within_line(jd_doc),
        {
            "line": "RMS z of retrieved − twin is 1 ± 0.25",
            "status": "met" if abs(rms - 1.0) <= 0.25 else "short",
            "evidence": {
                "file": str(jd_file.relative_to(RESULTS.parent.parent)),
                "rms_z_sigma_of_difference": rms,
                "rms_z_retrieved_sigma": jd["rms_z_retrieved_sigma"],
            },
        },
        {
            "line": "|mean H| without GCPs and c − c_twin within 3σ̂ in ≥ 7 of 8 campaigns, or "
            "a named cause that reproduces the offset",
            # a bar that can hardly fail is not met: σ̂ of the mean height is metres to tens of
            # metres at the bench's block size, and c − c_twin is judged with the retrieved σ̂
            # met: c − c_twin within 3σ of the *difference* (Monte Carlo) in ≥ 7 of 8, and the
            # named cause — the c–H coupling the draws show — leaves a mean-height residual
            # within 3σ of the draws' scatter about their regression in ≥ 7 of 8, with |corr|
            # ≥ 0.9 (a bar of centimetres to decimetres, not tens of metres)
            "status": "met"
            if n >= 8
            and mc
            and cp["c_within_mc"] >= 7
            and cp["mean_h_residual_within"] >= 7
            and np.median(np.abs(cp["coupling_corr"])) >= 0.9
            else "short",
            "evidence": {
                "file": str(cp_file.relative_to(RESULTS.parent.parent)),
                "n_campaigns": n,
                "mean_h_within_3sigma": h_in,
                "c_minus_twin_within_3sigma_retrieved_sigma": c_in,
                "mean_h_sigma_m": cp["mean_h_nogcp_sigma_m"],
                "corr_mean_h_with_c_error": cp["corr_mean_h_c"],
                **{
                    k: cp.get(k)
                    for k in (
                        "c_within_mc",
                        "c_minus_twin_nogcp_z_mc",
                        "mean_h_minus_twin_m",
                        "mean_h_minus_twin_sigma_m",
                        "mean_h_minus_twin_within",
                        "coupling_corr",
                        "coupling_slope_m_per_um",
                        "mean_h_predicted_from_c_m",
                        "mean_h_residual_m",
                        "mean_h_residual_sigma_m",
                        "mean_h_residual_within",
                    )
                    if k in cp
                },
                "why_short": (
                    None
                    if n >= 8
                    and cp["c_within_mc"] >= 7
                    and cp["mean_h_residual_within"] >= 7
                    and np.median(np.abs(cp["coupling_corr"])) >= 0.9
                    else f"{n} campaigns with the Monte Carlo; c within in "
                    f"{cp['c_within_mc']}, mean-height residual after the c coupling within in "
                    f"{cp['mean_h_residual_within']}"
                )
                if mc
                else "within 3σ̂ in every campaign, but σ̂ of the mean height is "
                + f"{min(cp['mean_h_nogcp_sigma_m']):.0f}–{max(cp['mean_h_nogcp_sigma_m']):.0f} m "
                "at this block size (002's offset: 1.13 m), so the bar can hardly fail; the "
                "bench file predates the no-GCP Monte Carlo of retrieved − twin "
                "(bench_lp_checkpoints.py nogcp_twin_mc): re-run it",
            },
        },
    ]
