"""Issue 37's done-means lines measured on today's main: ``bench/results/issue37_audit.json``.

    python bench/issue37_audit.py --runs DIR [DIR ...]

``DIR`` holds ``hsgeo reproduce CHAPTER --seed S --scale 0.05 --json`` outputs (``mtf.json``,
``rikola.json``; the seed is read from each). The other evidence is read from ``bench/results``:
``scoreboard_counts.json`` (bench/scoreboard_counts.py), ``asf_texture_bar.json``
(bench/asf_texture_bar.py), ``mtf_edge_independent.json`` (bench/bench_mtf_edge_independent.py)
and ``rikola_drift.json`` (bench/bench_rikola_drift.py). One entry per done-means line (and the
two "what to build" items the audit was asked about): the line, ``status`` (met / short /
not-measured) and the evidence (files and numbers). Lines on the LP chapter's check points and
twin are not measured here (their chapter's helpers own them).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def _load(name: str) -> dict:
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def scoreboard() -> dict:
    d = _load("scoreboard_counts.json")
    now = [a for a in d["audits"] if not a["chapters_missing"]]
    ok = bool(now) and all(a["bar_met"] for a in now)
    return {
        "line": "The scoreboard has one row per published number; no 'reproduced' rests on fewer "
        "than 8 runs or on σ > half the paper's value",
        "status": "met" if ok else "short",
        "evidence": {
            "file": "bench/results/scoreboard_counts.json",
            "per_output_folder": [
                {
                    "directory": a["directory"],
                    "n_published_numbers": a["n_published_numbers"],
                    "n_published_numbers_twice": a["n_published_numbers_twice"],
                    "n_context_rows_not_counted": a["n_context_rows_not_counted"],
                    "reproduced": a["now"]["counts"]["reproduced"],
                    "reproduced_on_fewer_than_8_runs": a["reproduced_on_fewer_than_8_runs"],
                    "reproduced_with_sigma_over_half_paper": a[
                        "reproduced_with_sigma_over_half_paper"
                    ],
                    "max_sigma_over_paper_of_a_reproduced": max(
                        (r["sigma_over_paper"] or 0.0 for r in a["reproduced"]), default=None
                    ),
                }
                for a in now
            ],
            "tests": "tests/test_report.py::test_no_reproduced_rests_on_few_runs_or_a_sigma_"
            "over_half_the_paper (every combination of runs, σ, provenance: a 'reproduced' has "
            "≥ 8 runs and σ ≤ half the paper; none may be stated or read from an old file "
            "otherwise); tests/test_scoreboard.py::test_each_published_number_is_judged_once_by_"
            "its_owner",
        },
    }


def counts_note() -> dict:
    d = _load("scoreboard_counts.json")
    out = []
    for a in d["audits"]:
        out.append(
            {
                "directory": a["directory"],
                "chapters_missing": a["chapters_missing"],
                "before_counting_stored_verdicts": a["stored_verdicts_counted_as_before_issue37"],
                "now": {
                    k: a["now"][k] for k in ("n_claims", "counts", "by_paper", "by_provenance")
                },
            }
        )
    return {
        "line": "The note gives the scoreboard counts before and after, by paper and provenance",
        "status": "met",
        "evidence": {
            "file": "bench/results/scoreboard_counts.json (the counts for the lead's note)",
            "counts": out,
        },
    }


def asf() -> dict:
    d = _load("asf_texture_bar.json")
    s = d["summary"]
    ok = (
        s["no_registration"]["min"] > 1.0 and max(s["one_px_E"]["max"], s["one_px_N"]["max"]) <= 1.0
    )
    return {
        "line": "With realistic runway texture, no registration gives an ASF error > 1 % and 1-px "
        "registration ≤ 1 %",
        "status": "met" if ok else "short",
        "evidence": {
            "file": "bench/results/asf_texture_bar.json (rerun on 268652f: identical runs)",
            "n_seeds": len(d["runs"]),
            "max_error_percent": s,
            "test": "tests/test_asf.py::test_lambertian_runway_asf_within_1_percent_for_any_seed "
            "(slow, 8 seeds: unregistered > 1 %, 1 px along or across ≤ 1 %)",
        },
    }


def mtf(runs: list[dict]) -> dict:
    per_seed = []
    nb = _load("mtf_edge_independent.json")["noise_bias_sigma_1px_angle_5_deg"]["runs"]
    # the named cause measured: noise raises the edge MTF at 0.2–0.4 cy/px (z > 3 at each)
    noise_up = all(
        z > 3 for r in nb for f, z in zip(r["f_cy_px"], r["z"], strict=True) if 0.19 < f < 0.41
    )
    ok = True
    for rep in runs:
        b = rep["meta"]["bias"]
        rows = {r["quantity"]: r for r in rep["rows"] if r["table"] == "slanted edge"}
        edge = b["slanted edge"]
        left = edge["unexplained"]
        above = all(rows[q]["reproduced"] - rows[q]["truth"] - edge["rows"][q][2] > 0 for q in left)
        t3 = [r for r in rep["rows"] if r["table"] == "001 Table 3" and r["verdict"] == "differs"]
        named_t3 = all("our definition of the determined GSD" in r["reason"] for r in t3)
        big = [q for q in left if rows[q]["truth"] > 0.05]
        ok = ok and above and named_t3 and noise_up
        per_seed.append(
            {
                "seed": rep["seed"],
                "n_runs": rep["meta"]["n_runs"],
                "within_3_sigma_of_the_mean": {
                    t: f"{v['n_within_3']} of {v['n']}" for t, v in b.items()
                },
                "within_3_sigma_after_the_noise_free_bias": {
                    t: f"{v['n_within_3_bias']} of {v['n']}" for t, v in b.items()
                },
                "slanted_edge_rows_left": left,
                "left_all_above_truth_named_noise_bias": above,
                "true_mtf_of_rows_left": [round(rows[q]["truth"], 4) for q in left],
                "rows_left_at_true_mtf_over_0.05": big,
                "table3_differs": len(t3),
                "table3_differs_name_our_gsd_definition": named_t3,
            }
        )
    return {
        "line": "MTF rows within 3σ of the mean ≥ 95 % or their biases named",
        "status": "met" if ok else "short",
        "evidence": {
            "files": "hsgeo reproduce mtf --scale 0.05 --json (8 runs) at the seeds listed; "
            "meta['bias'] from reproduce.mtf.method_bias, glued by bias_sentence",
            "per_seed": per_seed,
            "noise_bias_on_independent_edges": {
                "file": "bench/results/mtf_edge_independent.json",
                "runs": nb,
                "upward_at_0.2_to_0.4_cy_px": noise_up,
                "test": "tests/test_measure_mtf.py::test_noise_raises_the_slanted_edge_mtf_at_"
                "mid_frequencies",
            },
            "caveat": "within 3σ of the mean is below 95 % for the slanted edge (15-22 of 34) "
            "and for the bars' Fig. 9 rows (21-22 of 26); after the method's noise-free bias "
            "the rows left lie all above their truth and the chapter names them the noise's "
            "upward bias, which an independent generator's edges show (z 4.5-11 at 0.2-0.4 "
            "cy/px); the chapter does not measure that bias at its own noise level row by row "
            "(no paired noisy/noise-free run), so the size of each row's excess is named, not "
            "accounted for",
        },
    }


def mtf_edge() -> dict:
    d = _load("mtf_edge_independent.json")
    return {
        "line": "`mtf-edge` within 0.02 of the known MTF at 0.1–0.4 cy/px on an edge rendered by "
        "an independent generator",
        "status": "met" if d["bar_met"] else "short",
        "evidence": {
            "file": "bench/results/mtf_edge_independent.json",
            "max_abs_error": d["max_abs_error"],
            "per_edge": d["edges_100x80"],
            "masked_chips": d["masked_chips_200x200_sigma_0.8_angle_5"],
            "tests": "tests/test_measure_mtf.py::test_slanted_edge_within_0_02_of_an_independent_"
            "generator, ::test_mtf_edge_workflow_within_0_02_of_an_independent_generator, "
            "::test_masked_target_chip_found_without_roi (generator: tests/edge_reference.py)",
        },
    }


def rikola(runs: list[dict]) -> dict:
    d = _load("rikola_drift.json")["summary"]
    today = []
    ok = d["max_abs_x0_z_with_drift"] <= 3.0
    for rep in runs:
        rows = {r["quantity"]: r for r in rep["rows"] if r["table"] == "joint model"}
        tuned = [
            {
                "quantity": r["quantity"],
                "paper": r["paper"],
                "reproduced": r["reproduced"],
                "verdict": r["verdict"],
                "reason": r["reason"][:60],
            }
            for r in rep["rows"]
            if r["provenance"] == "tuned" and r["sigma"] is None and r["paper"] is not None
        ]
        x0 = {q: rows[q]["z"] for q in ("x0_sensor1_mm", "x0_sensor2_mm") if q in rows}
        ok = ok and all(abs(z) <= 3 for z in x0.values())
        ok = ok and all(
            t["verdict"] == "differs"
            for t in tuned
            if t["paper"] and abs(t["reproduced"] - t["paper"]) > 0.1 * abs(t["paper"])
        )
        today.append({"seed": rep["seed"], "joint_x0_z": x0, "tuned_rows_without_sigma": tuned})
    return {
        "line": "(what to build, rules without holes) the joint Rikola model with the drift "
        "recovers x0 within 3σ̂; a tuned row without σ missing by > 10 % is 'tuned, missed'",
        "status": "met" if ok else "short",
        "evidence": {
            "file": "bench/results/rikola_drift.json (8 seeds) and hsgeo reproduce rikola "
            "--scale 0.05 today",
            "bench_summary": {
                k: d[k]
                for k in (
                    "n_seeds",
                    "share_within_3_with_drift",
                    "rms_z_with_drift",
                    "max_abs_x0_z_with_drift",
                    "seeds_all_within_3",
                )
            },
            "today": today,
            "tests": "tests/test_report.py::test_a_tuning_without_sigma_that_misses_by_more_than_"
            "ten_percent_missed, ::test_a_paper_valued_truth_recovered_beyond_three_sigma_is_a_"
            "failed_recovery; tests/test_rikola.py::test_joint_model_recovers_the_truth_with_the_"
            "eop_drift_on (slow, seed 0)",
        },
    }


def lp_blur(lp_runs: list[dict]) -> dict:
    """Met when a ``hsgeo reproduce lp-observations --json`` output carries the third
    campaign's rows (``stamp_start.*``, stamped at the start of the exposure) and they move
    the tie observations along the track (RMS y error up by ≥ 0.1 px on the blur-on run)."""
    moved = []
    for d in lp_runs:
        q = {r["quantity"]: r["reproduced"] for r in d["rows"] if r["table"] == "unmodelled effect"}
        a, b = q.get("stamp_start.rms_y_error_px"), q.get("motion_blur_on.rms_y_error_px")
        if a is not None and b is not None:
            moved.append({"seed": d["seed"], "rms_y_start_px": a, "rms_y_middle_px": b})
    ok = bool(moved) and all(m["rms_y_start_px"] - m["rms_y_middle_px"] >= 0.1 for m in moved)
    return {
        "line": "(what to build, bars that can fail) the LP blur time-stamped at the start of "
        "exposure, so that it moves key points, or another effect that does",
        "status": "met" if ok else "short",
        "evidence": {
            "files": "src/hsgeo/simulate/lp_campaign.py LpConfig.exposure_stamp ('start' renders "
            "each line half an integration late: squares cross 0.5 line early, x unmoved — "
            "tests/test_lp_campaign.py::test_a_start_of_exposure_stamp_moves_the_squares_half_a_"
            "blur); src/hsgeo/reproduce/lp_observations.py run(): the unmodelled-effect table's "
            "third campaign, stamped at the start (rows stamp_start.*, with the tie "
            "observations' rms_x/rms_y_error_px), shown in the chapter's table beside the blur "
            "on/off columns",
            "runs_with_stamp_start_rows": moved,
            "why_short": None
            if ok
            else "no lp-observations.json among --runs carries stamp_start rows (the chapter's "
            "run was not repeated on this branch), or they do not move the key points",
        },
    }


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, nargs="+", required=True)
    ap.add_argument("--out", type=Path, default=RESULTS / "issue37_audit.json")
    args = ap.parse_args()
    mtf_runs = [
        json.loads((d / "mtf.json").read_text(encoding="utf-8"))
        for d in args.runs
        if (d / "mtf.json").is_file() and (d / "mtf.json").stat().st_size
    ]
    rik = [
        json.loads((d / "rikola.json").read_text(encoding="utf-8"))
        for d in args.runs
        if (d / "rikola.json").is_file() and (d / "rikola.json").stat().st_size
    ]
    lp = [
        json.loads((d / "lp-observations.json").read_text(encoding="utf-8"))
        for d in args.runs
        if (d / "lp-observations.json").is_file() and (d / "lp-observations.json").stat().st_size
    ]
    entries = [
        *lp_lines(),
        scoreboard(),
        asf(),
        mtf(mtf_runs),
        mtf_edge(),
        counts_note(),
        rikola(rik),
        lp_blur(lp),
    ]
    out = {
        "what": "issue 37's done-means lines measured on main 226bb30 + branch lp37 "
        "(the LP judges mended)",
        "command": "python bench/issue37_audit.py --runs " + " ".join(map(str, args.runs)),
        "summary": {
            s: sum(e["status"] == s for e in entries) for s in ("met", "short", "not-measured")
        },
        "entries": entries,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    args.out.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps(out["summary"]))
    for e in entries:
        print(e["status"], "|", e["line"][:90])


if __name__ == "__main__":
    main()
