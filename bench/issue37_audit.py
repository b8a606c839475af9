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


def lp_blur() -> dict:
    return {
        "line": "(what to build, bars that can fail) the LP blur time-stamped at the start of "
        "exposure, so that it moves key points, or another effect that does",
        "status": "short",
        "evidence": {
            "files": "src/hsgeo/simulate/lp_campaign.py LpConfig.exposure_stamp ('start' renders "
            "each line half an integration late: squares cross 0.5 line early, x unmoved — "
            "tests/test_lp_campaign.py::test_a_start_of_exposure_stamp_moves_the_squares_half_a_"
            "blur); book/chapters/lp_observations.md names it and leaves it as an exercise",
            "why_short": "the default stays 'middle' and the chapter's unmodelled-effect table "
            "still runs the symmetric blur (it moves no key point); the LP chapter is owned by "
            "the lp helpers, not changed here",
        },
    }


def lp_lines() -> list[dict]:
    """The LP chapter's four lines from the two 8-campaign benches (bench_lp_checkpoints.py,
    bench_lp_judges.py), read through the chapter's own function for the first."""
    from hsgeo.reproduce.lp_campaigns import checkpoint_campaigns

    cp_file, jd_file = RESULTS / "lp_checkpoints_seeds.json", RESULTS / "lp_judges_seeds.json"
    cp = checkpoint_campaigns(json.loads(cp_file.read_text(encoding="utf-8")))
    jd = json.loads(jd_file.read_text(encoding="utf-8"))["summary"]
    sd = {k: cp[f"table3.{k}_h"]["sd_z"] for k in ("std", "nmad")}
    n = cp["n_campaigns"]
    ok_sd = all(abs(v - 1.0) <= 0.3 for v in sd.values())
    within = jd["seeds_meeting_95pct_vs_targets"]
    rms = jd["rms_z_sigma_of_difference"]
    h_in, c_in = cp["mean_h_nogcp_within"], cp["c_within"]
    return [
        {
            "line": "Over 8 campaigns: the z of std_h and nmad_h from pixels has a standard "
            "deviation of 1 ± 0.3",
            "status": "met" if ok_sd and n >= 8 else "short",
            "evidence": {
                "file": str(cp_file.relative_to(RESULTS.parent.parent)),
                "n_campaigns": n,
                "sd_z_std_h_table3_joint": sd["std"],
                "sd_z_nmad_h_table3_joint": sd["nmad"],
                "why": "one check point metres from the rest in 5 of 8 campaigns (farthest "
                "over NMAD: " + ", ".join(f"{v:.1f}" for v in cp["h_farthest_over_nmad"]) + "): "
                "the STD takes it whole; no covariance predicts a blunder",
            },
        },
        {
            "line": "the within-1-px share against an independent reference is ≥ 95 % in ≥ 7 "
            "of 8 campaigns",
            "status": "met" if within >= 7 else "short",
            "evidence": {
                "file": str(jd_file.relative_to(RESULTS.parent.parent)),
                "seeds_meeting_95pct_vs_point_targets": within,
                "within_1px_vs_targets_per_seed": jd["within_1px_vs_targets_per_seed"],
            },
        },
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
            "status": "met"
            if h_in >= 7 and c_in >= 7 and max(cp["mean_h_nogcp_sigma_m"]) < 1.13
            else "short",
            "evidence": {
                "file": str(cp_file.relative_to(RESULTS.parent.parent)),
                "mean_h_within_3sigma": h_in,
                "c_minus_twin_within_3sigma": c_in,
                "mean_h_sigma_m": cp["mean_h_nogcp_sigma_m"],
                "corr_mean_h_with_c_error": cp["corr_mean_h_c"],
                "why_short": "within 3σ̂ in every campaign, but σ̂ of the mean height is "
                + f"{min(cp['mean_h_nogcp_sigma_m']):.0f}–{max(cp['mean_h_nogcp_sigma_m']):.0f} m "
                "at this block size (002's offset: 1.13 m), so the bar can hardly fail; "
                "c − c_twin is judged with the retrieved σ̂, not the difference's",
            },
        },
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, nargs="+", required=True)
    ap.add_argument("--out", type=Path, default=RESULTS / "issue37_audit.json")
    args = ap.parse_args()
    mtf_runs = [json.loads((d / "mtf.json").read_text(encoding="utf-8")) for d in args.runs]
    rik = [
        json.loads((d / "rikola.json").read_text(encoding="utf-8"))
        for d in args.runs
        if (d / "rikola.json").is_file() and (d / "rikola.json").stat().st_size
    ]
    entries = [
        *lp_lines(),
        scoreboard(),
        asf(),
        mtf(mtf_runs),
        mtf_edge(),
        counts_note(),
        rikola(rik),
        lp_blur(),
    ]
    out = {
        "what": "issue 37's done-means lines measured on main 268652f (+ this branch's mends)",
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
