"""Issue 41's table, figure by figure, from the committed benches (issue41_audit.json).

    python bench/issue41_audit.py

Reads what ``make bench`` and the fresh-clone test timing wrote (``orthomosaic.json``,
``orthomosaic_stages.json``, ``pushbroom_ba.json``, ``pushbroom_scaling.json``,
``pushbroom_profile.json``, ``bal.json``, ``bal_profile.json``, ``make_test_runs.json``) and puts
each figure of the issue's table beside its goal: ``status`` is ``met``, ``short`` (with the
measured profile's account of what remains, where one exists) or ``not-measured``. Whether each
figure also stands beside the previous main in a paired run (the done-means) is recorded per row
(``paired_with_previous_main``). Nothing is measured here: the figures are the files'.
"""

from __future__ import annotations

import calendar
import json
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"


def _load(name: str) -> dict:
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def ortho() -> dict:
    o = _load("orthomosaic.json")
    s = _load("orthomosaic_stages.json")
    by = {r["path"]: r for r in o["rows"]}
    vs = o.get("vs_main") or {}
    goal = o["goal_chunked_output_px_per_cpu_s"]
    now = by["chunked_1"]["output_px_per_cpu_s"]
    gdal = by["gdal_warp_geoloc"]["output_px_per_cpu_s"]
    gdal_alone = by["gdal_warp_geoloc"]["output_px_per_warp_cpu_s"]
    return {
        "line": "orthorectification, chunked: ≥ 1 M cells per CPU-s, memory bounded as now, "
        "ahead of GDAL's warper on the same swath",
        "status": "met" if now >= goal and now > gdal else "short",
        "figure_cells_per_cpu_s": now,
        "figure_load_average_1_5_15": by["chunked_1"]["load_average_1_5_15"],
        "goal_cells_per_cpu_s": goal,
        "in_memory_cells_per_cpu_s": by["in_memory"]["output_px_per_cpu_s"],
        "paired_with_previous_main": vs.get("pairs", 0),
        "paired_this_median_cells_per_cpu_s": vs.get("this_median_output_px_per_cpu_s"),
        "previous_main_cells_per_cpu_s": vs.get("vs_median_output_px_per_cpu_s"),
        "ratio_over_previous_main": vs.get("ratio_this_over_vs_px_per_cpu_s_median"),
        "paired_load_average_1_5_15_each_run": vs.get("load_average_1_5_15_each_run"),
        "peer_gdal_cells_per_cpu_s": gdal,
        "peer_gdal_warp_alone_cells_per_cpu_s": gdal_alone,
        "peer_gdal_share_cells_equal_to_ours": by["gdal_warp_geoloc"].get(
            "share_cells_equal_to_ours"
        ),
        "ahead_of_gdal": now > gdal,
        "ahead_of_gdal_warp_alone": now > gdal_alone,
        "memory_over_start_mib": {
            "this": by["chunked_1"]["peak_rss_over_start_mib"],
            "paired_this_median": vs.get("this_median_peak_rss_over_start_mib"),
            "paired_previous_main_median": vs.get("vs_median_peak_rss_over_start_mib"),
        },
        "every_run": _ortho_runs(),
        "profile": {
            "file": "bench/results/orthomosaic_stages.json",
            "stages_cpu_s_previous_main": s["previous_main"]["stages_cpu_s_median"],
            "stages_cpu_s_this": s["this_branch"]["stages_cpu_s_median"],
            "approximation": s["approximation"],
            "what_remains": s["what_remains"],
        },
    }


def _ortho_runs() -> list[dict]:
    """Every committed run of bench_orthomosaic.py (``orthomosaic_run*.json``, then the
    latest, ``orthomosaic.json``): the spread that the machine's load puts on the figures."""
    out = []
    for f in [*sorted(RESULTS.glob("orthomosaic_run*.json")), RESULTS / "orthomosaic.json"]:
        o = json.loads(f.read_text(encoding="utf-8"))
        by = {r["path"]: r for r in o["rows"]}
        vs = o.get("vs_main") or {}
        out.append(
            {
                "file": f.name,
                "chunked_1_cells_per_cpu_s": by["chunked_1"]["output_px_per_cpu_s"],
                "paired_this_median": vs.get("this_median_output_px_per_cpu_s"),
                "paired_previous_main_median": vs.get("vs_median_output_px_per_cpu_s"),
                "gdal_cells_per_cpu_s": by["gdal_warp_geoloc"]["output_px_per_cpu_s"],
                "gdal_warp_alone_cells_per_cpu_s": by["gdal_warp_geoloc"].get(
                    "output_px_per_warp_cpu_s"
                ),
                "load_average_1_5_15": by["chunked_1"]["load_average_1_5_15"],
            }
        )
    return out


#: the issue's figures for the pushbroom rows and where they came from (its table): the code is
#: that of 8477cad, the main the issue was filed on (src/hsgeo/adjust, sensors and the workflow
#: unchanged since 5792f1c), measured on the machine of session 14
ISSUE_PUSHBROOM = {
    "commit": "8477cad",
    "paper_wall_s": 2.41,  # pushbroom_scaling.json of 7ac204e (0a52e4c), 2 threads
    "paper_cpu_s": 3.90,  # pushbroom_profile.json of dca2771, one thread
    "ten_wall_s": 38.5,  # pushbroom_scaling.json of 5792f1c
    "ten_cpu_s": 50.2,
}


def _vs_issue(name: str, goals: dict) -> dict | None:
    """The paired runs against the issue's own commit on today's machine (``name``, written by
    ``pushbroom_vs_main.py --vs <checkout of 8477cad>``): each goal read as the ratio it asks
    of the issue's figure (goal / the issue's figure), against the measured median ratio."""
    if not (RESULTS / name).exists():
        return None
    v = _load(name)
    r = v["median_ratio_this_over_previous_main"]
    rows = {}
    for k, (goal, figure) in goals.items():
        asked = goal / figure
        rows[k] = {
            "goal_over_issue_figure": asked,
            "measured_ratio_this_over_issue_commit": r[k],
            "met_as_ratio": r[k] <= asked,
        }
    return {
        "file": f"bench/results/{name}",
        "pairs": v["pairs"],
        "commits_this_issue": [v["commit_this"], v["commit_previous_main"]],
        "median_this": v["median_this"],
        "median_issue_commit": v["median_previous_main"],
        "ratios": rows,
        "load_average_each_run": [
            r["load_average_1_5_15_before"] for side in v["runs"].values() for r in side
        ],
        "cpu": v.get("cpu"),
        "numba_threads": v.get("numba_threads"),
    }


def _kept_stages(prof: dict) -> float | None:
    """CPU seconds (one thread) of the stages the profile says stay: the three reduced-matrix
    formations and the LP model's evaluations, to set beside the 3.0-CPU-s goal (what the rest
    of the solve may take at most)."""
    w = (prof.get("what_remains_at_1x") or {}).get("cpu_seconds")
    if not w:
        return None
    return w["reduced_matrix_kernel"] + w["model_linearisation"] + w["model_trial"]


def pushbroom() -> list[dict]:
    b = _load("pushbroom_ba.json")
    sc = _load("pushbroom_scaling.json")
    prof = _load("pushbroom_profile.json")
    rows = {r["scale"]: r for r in sc["rows"]}
    one, ten = rows[1.0], rows[10.0]
    goals = sc["goals"]
    designs = {k: v["cpu_seconds"] for k, v in prof["designs_at_1x"].items()}
    outcomes = {k: v.get("outcome") for k, v in prof["designs_at_1x"].items()}
    wall1, cpu1 = b["solver_seconds"], one["solver_cpu_seconds"]
    wall1_file = "bench/results/pushbroom_ba.json (solver_seconds, best of 3)"
    cpu1_file = f"bench/results/pushbroom_scaling.json (scale 1, {sc['commit']})"
    # the verdicts: paired runs against the issue's commit in the same hour, under the
    # Makefile's GLIBC_TUNABLES (the condition of the issue's own figures: make bench), read
    # both ways: this checkout's median within the goal, and its ratio to the issue's commit
    # within what the goal asks of the issue's figure. The issue's CPU figure (3.90) is of
    # one thread (a profile), so the CPU goal reads the one-thread pair.
    vs1 = _vs_issue(
        "pushbroom_vs_issue_tunables.json",
        {"wall_seconds": (2.0, ISSUE_PUSHBROOM["paper_wall_s"])},
    )
    vs1_cpu = _vs_issue(
        "pushbroom_vs_issue_one_thread.json",
        {"solver_cpu_seconds": (3.0, ISSUE_PUSHBROOM["paper_cpu_s"])},
    )
    if vs1 is not None:
        wall1 = vs1["median_this"]["wall_seconds"]
        wall1_file = vs1["file"] + " (median of this checkout's runs)"
    if vs1_cpu is not None:
        cpu1 = vs1_cpu["median_this"]["solver_cpu_seconds"]
        cpu1_file = vs1_cpu["file"] + " (median of this checkout's runs, one thread)"
    met1 = bool(
        vs1
        and vs1_cpu
        and wall1 <= goals["paper_size_solver_seconds_max"]
        and cpu1 <= 3.0
        and vs1["ratios"]["wall_seconds"]["met_as_ratio"]
        and vs1_cpu["ratios"]["solver_cpu_seconds"]["met_as_ratio"]
    )
    vs10 = _vs_issue(
        "pushbroom_vs_issue_10x_tunables.json",
        {"wall_seconds": (30.0, ISSUE_PUSHBROOM["ten_wall_s"])},
    )
    ten_wall, ten_cpu, ten_rss = (
        ten["solver_seconds"],
        ten["solver_cpu_seconds"],
        ten["peak_rss_mb"],
    )
    if vs10 is not None:
        m = vs10["median_this"]
        ten_wall, ten_cpu, ten_rss = m["wall_seconds"], m["solver_cpu_seconds"], m["peak_rss_mb"]
    met10 = bool(
        vs10
        and ten_wall <= goals["solver_seconds_max"]
        and ten_rss <= goals["peak_rss_mb_max"]
        and vs10["ratios"]["wall_seconds"]["met_as_ratio"]
    )
    vs = _load("pushbroom_vs_main.json") if (RESULTS / "pushbroom_vs_main.json").exists() else {}
    return [
        {
            "line": "pushbroom adjustment, paper size: ≤ 2.0 s wall, ≤ 3.0 CPU-s",
            "status": "met" if met1 else "short",
            "verdict_from": "paired runs against the issue's commit in one hour, under the "
            "Makefile's GLIBC_TUNABLES: the wall median (two threads) ≤ 2.0 s and its ratio ≤ "
            "2.0 / 2.41; the one-thread CPU median ≤ 3.0 s and its ratio ≤ 3.0 / 3.90",
            "figure_wall_s": wall1,
            "figure_wall_s_file": wall1_file,
            "figure_cpu_s": cpu1,
            "figure_cpu_s_file": cpu1_file,
            "goal_wall_s": goals["paper_size_solver_seconds_max"],
            "goal_cpu_s": 3.0,
            "figure_load_average_1_5_15": sc["machine"]["loadavg_at_start"],
            "paired_with_previous_main": vs.get("pairs", 0),
            # both sides under the Makefile's GLIBC_TUNABLES (the condition of the issue's own
            # figures: make bench)
            "paired_with_issue_commit": vs1,
            "paired_with_issue_commit_one_thread": vs1_cpu,
            "paired_with_issue_commit_glibc_defaults": _vs_issue(
                "pushbroom_vs_issue.json",
                {
                    "wall_seconds": (2.0, ISSUE_PUSHBROOM["paper_wall_s"]),
                    "solver_cpu_seconds": (3.0, ISSUE_PUSHBROOM["paper_cpu_s"]),
                },
            ),
            "issue_figures": ISSUE_PUSHBROOM,
            "paired": {
                "file": "bench/results/pushbroom_vs_main.json (bench/pushbroom_vs_main.py)",
                "scale": vs.get("scale"),
                "commits_this_previous_main": [
                    vs.get("commit_this"),
                    vs.get("commit_previous_main"),
                ],
                "median_this": vs.get("median_this"),
                "median_previous_main": vs.get("median_previous_main"),
                "median_ratio_this_over_previous_main": vs.get(
                    "median_ratio_this_over_previous_main"
                ),
                "load_average_each_run": [
                    r["load_average_1_5_15_before"]
                    for side in ("this", "previous_main")
                    for r in vs.get("runs", {}).get(side, [])
                ],
            },
            "profile": {
                "file": "bench/results/pushbroom_profile.json",
                "designs_cpu_s_at_1x": designs,
                "designs_outcome": outcomes,
                "what_remains_at_1x": prof.get("what_remains_at_1x"),
                "formations_and_model_cpu_s_one_thread": _kept_stages(prof),
                "profile_cpu_s_one_thread": prof["rows"][0]["user_seconds"]
                + prof["rows"][0]["system_seconds"],
                "profile_load_average_1_5_15": prof.get("loadavg"),
                "kernel_stages_probe": _stages_probe(),
                "kernel_tiles_probe": _tiles_probe(),
                "first_touch_probe": _first_touch_probe(),
            },
        },
        {
            "line": "pushbroom adjustment, 10× the paper: ≤ 30 s wall, ≤ 10 GB",
            "status": "met" if met10 else "short",
            "verdict_from": "paired runs against the issue's commit in one hour, under the "
            "Makefile's GLIBC_TUNABLES: the wall median ≤ 30 s and its ratio ≤ 30 / 38.5, the "
            "peak memory ≤ 10 GB",
            "figure_wall_s": ten_wall,
            "figure_cpu_s": ten_cpu,
            "figure_peak_rss_mb": ten_rss,
            "figure_file": vs10["file"] if vs10 else "bench/results/pushbroom_scaling.json",
            "goal_wall_s": goals["solver_seconds_max"],
            "goal_peak_rss_mb": goals["peak_rss_mb_max"],
            "cpu_time_exponent": sc["cpu_time_exponent"],
            "commit": sc["commit"],
            "paired_with_previous_main": 0,
            # both sides under the Makefile's GLIBC_TUNABLES, the condition of the issue's own
            # 38.5 s (make bench, 5792f1c's pushbroom_scaling.json)
            "paired_with_issue_commit": vs10,
            "paired_with_issue_commit_glibc_defaults": _vs_issue(
                "pushbroom_vs_issue_10x.json",
                {"wall_seconds": (30.0, ISSUE_PUSHBROOM["ten_wall_s"])},
            ),
            # each side's process set up as its own hsgeo command does (this one keeps freed
            # memory, hsgeo.terminal.keep_freed_memory; 8477cad's did not)
            "paired_with_issue_commit_as_command": _vs_issue(
                "pushbroom_vs_issue_10x_command.json",
                {"wall_seconds": (30.0, ISSUE_PUSHBROOM["ten_wall_s"])},
            ),
            "profile": _profile_10x(prof),
            "kernel_tiles_probe": _tiles_probe(),
        },
    ]


def _tiles_probe() -> dict | None:
    """What the reduced-matrix kernel's tiles cost (schur_tiles_probe.py): the kernel as is
    against its tiles folded into L1, per row at each scale, and the share of distinct group
    pairs (whether blocks could be summed before their expansion)."""
    try:
        d = _load("schur_tiles_probe.json")
    except FileNotFoundError:
        return None
    v = d["variants"]
    per_row = {sc: {k: round(x["cpu_ns_per_row"]) for k, x in row.items()} for sc, row in v.items()}
    out = {"file": "bench/results/schur_tiles_probe.json", "cpu_ns_per_row": per_row}
    if "1x" in v and "10x" in v:
        out["tiles_share_of_kernel"] = {
            sc: 1
            - v[sc]["tiles_in_l1"]["median_cpu_seconds"] / v[sc]["as_is"]["median_cpu_seconds"]
            for sc in ("1x", "10x")
        }
        out["growth_per_row_1x_to_10x"] = {
            k: v["10x"][k]["cpu_ns_per_row"] / v["1x"][k]["cpu_ns_per_row"] for k in v["1x"]
        }
    out["group_pairs"] = d.get("group_pairs_at_smallest_scale")
    return out


def _stages_probe() -> dict | None:
    """What each stage of the reduced-matrix kernel costs at 1× (schur_stage_probe.py: the
    kernel's source with the stage taken out, CPU seconds per formation, one thread)."""
    try:
        d = _load("schur_stage_probe.json")
    except FileNotFoundError:
        return None
    return {
        "file": "bench/results/schur_stage_probe.json",
        "scale": d["scale"],
        "formation_cpu_s": d["median_cpu_seconds"]["as_is"],
        "stage_cpu_s": d["stage_cpu_seconds"],
        "stage_share_of_kernel": d["stage_share_of_kernel"],
        "cpu": d.get("cpu"),
        "date_utc": d.get("date_utc"),
    }


def _first_touch_probe() -> dict | None:
    """The first touch of the solve's memory (pushbroom_first_touch.py: two solves in one
    process, the second reusing the first one's pages), with numpy's huge pages and without."""
    try:
        d = _load("pushbroom_first_touch.json")
    except FileNotFoundError:
        return None
    return {
        "file": "bench/results/pushbroom_first_touch.json",
        "summary": d["summary"],
        "transparent_hugepage": d.get("transparent_hugepage"),
        "cpu": d.get("cpu"),
        "date_utc": d.get("date_utc"),
    }


def _profile_10x(prof: dict) -> dict | None:
    """The 10× row of the profile (one thread) and what remains in it, beside the same calls
    of the issue's commit profiled on the same machine (``pushbroom_profile_8477cad.json``)."""
    ten = next((r for r in prof["rows"] if r["scale"] == 10.0), None)
    if ten is None:
        return None
    out = {
        "file": "bench/results/pushbroom_profile.json",
        "profile_cpu_s_one_thread": ten["user_seconds"] + ten["system_seconds"],
        "system_s": ten["system_seconds"],
        "what_remains_at_10x": prof.get("what_remains_at_10x"),
        "profile_load_average_1_5_15": prof.get("loadavg"),
    }
    f = RESULTS / "pushbroom_profile_8477cad.json"
    if f.exists():
        old = next((r for r in _load(f.name)["rows"] if r["scale"] == 10.0), None)
        if old is not None:
            out["issue_commit"] = {
                "file": f"bench/results/{f.name}",
                "profile_cpu_s_one_thread": old["user_seconds"] + old["system_seconds"],
                "system_s": old["system_seconds"],
                "cpu_s_by_call_this_issue_commit": {
                    k: [v["cpu_seconds"], old["calls"][k]["cpu_seconds"]]
                    for k, v in ten["calls"].items()
                    if k in old["calls"]
                },
            }
    return out


def bal() -> dict:
    b = _load("bal.json")
    p = _load("bal_profile.json")
    ratio = b["ceres_cpu_seconds"] / b["hsgeo_cpu_seconds_to_ceres_cost"]
    return {
        "line": "BAL Ladybug-49 to Ceres' final cost, one thread each: ≥ 1.5× Ceres in CPU-s",
        "status": "met" if ratio >= 1.5 else "short",
        "figure_ratio_ceres_over_hsgeo_cpu_s": ratio,
        "hsgeo_cpu_s_to_ceres_cost": b["hsgeo_cpu_seconds_to_ceres_cost"],
        "ceres_cpu_s": b["ceres_cpu_seconds"],
        "iterations": {
            "hsgeo_to_ceres_cost": b["hsgeo_iterations_to_ceres_cost"],
            "ceres": b["ceres_iterations"],
        },
        "goal_ratio": 1.5,
        "ratio_each_pair": b.get("cpu_speedup_to_ceres_cost_each_run"),
        "machine": b["machine"],
        "cpu_model": b.get("cpu_model"),
        "blas_core_type": sorted(
            {f"{x['internal_api']} {x['version']} {x['architecture']}" for x in b["blas_hsgeo"]}
        )
        if b.get("blas_hsgeo")
        else None,
        "glibc_tunables": b.get("glibc_tunables"),
        "load_average": b["load_average"],
        "load_average_1_5_15_each_run": b.get("load_average_1_5_15_each_run"),
        "paired_with_previous_main": (b.get("vs_main") or {}).get("pairs", 0),
        "previous_main": b.get("vs_main"),
        "profile": {
            "file": "bench/results/bal_profile.json",
            "reduced_matrix_kernel_share": p["calls"]["reduced_matrix_kernel"]["share_of_solve"],
            "reduced_matrix_formations": p["reduced_matrix_formations"],
            "cpu_seconds_per_iteration_split": p.get("cpu_seconds_per_iteration_split"),
            "what_remains": p.get("what_remains"),
        },
    }


def _suite_profile() -> dict:
    """The newest entry of test_suite_cost.json that names what remains (``what_remains``)."""
    entries = _load("test_suite_cost.json")["entries"]
    named = [(k, e) for k, e in entries.items() if isinstance(e, dict) and "what_remains" in e]
    if not named:
        return {"file": "bench/results/test_suite_cost.json", "what_remains": None}
    key, e = named[-1]
    return {
        "file": f"bench/results/test_suite_cost.json, entry {key!r}",
        "slowest_40_by_file_seconds": e.get("slowest_40_by_file_seconds"),
        "what_remains": e["what_remains"],
    }


#: the issue's figure for ``make test`` (its table: pytest 10 min 47 s, 2,558 tests, one pytest
#: process, on the machine of the day it was filed)
ISSUE_MAKE_TEST_S = 647.0
#: two runs pair when the second began within this many seconds of the first one's end
PAIR_GAP_S = 900.0


def _stamp(r: dict) -> float:
    """A run's end (``date_utc`` is written when it ends), in seconds."""
    return calendar.timegm(time.strptime(r["date_utc"], "%Y-%m-%dT%H:%M:%SZ"))


def _make_test_pairs(runs: list[dict], busy_cores: int) -> list[dict]:
    """Back-to-back runs of the issue's commit (``role`` before) and of a later main (after) on
    the same machine state and load (``busy_cores``), one right after the other: the ratio
    after / before is what the same machine says of the change. This machine's speed moved by
    a factor of 2.5 between days (the issue's 647 s for 8477cad's suite; the same commit's
    1,600 s on 2026-11-29), so a figure of one day beside a goal of another is not a verdict."""
    got = [r for r in runs if r.get("role") and r.get("busy_cores", 0) == busy_cores]
    out = []
    for a, b in zip(got, got[1:], strict=False):
        if {a["role"], b["role"]} != {"before", "after"}:
            continue
        gap = _stamp(b) - (b.get("wall_seconds_with_venv") or 0.0) - _stamp(a)
        if gap > PAIR_GAP_S:
            continue
        bef, aft = (a, b) if a["role"] == "before" else (b, a)
        out.append(
            {
                "before": {k: bef.get(k) for k in ("commit", "date_utc", "pytest_seconds",
                                                   "passed", "failed", "loadavg_start")},
                "after": {k: aft.get(k) for k in ("commit", "date_utc", "pytest_seconds",
                                                  "passed", "failed", "loadavg_start")},
                "ratio_after_over_before": aft["pytest_seconds"] / bef["pytest_seconds"],
                "gap_between_runs_s": round(gap, 1),
            }
        )  # fmt: skip
    return out


def make_test() -> dict:
    d = _load("make_test_runs.json")
    runs = [r for r in d["runs"] if r.get("pytest_seconds") and r.get("exit_status") == 0]
    idle = [r for r in runs if r.get("busy_cores", 0) == 0]
    busy = [r for r in runs if r.get("busy_cores", 0) == 1]
    last = idle[-1] if idle else None
    goal = d["goal_pytest_seconds"]
    # the done-means' four figures: before (the issue's commit) and after, each idle and with
    # one core busy, from runs that had the machine to themselves (``--role``); the latest of each
    table = {}
    for role in ("before", "after"):
        for busy_cores, cond in ((0, "idle"), (1, "one_core_busy")):
            # a run that completed (pytest's summary line), failed tests included: the before
            # commit is measured as it stands today (its failures are listed with its figures)
            got = [
                r
                for r in d["runs"]
                if r.get("role") == role
                and r.get("busy_cores") == busy_cores
                and r.get("pytest_seconds")
            ]
            table[f"{role}_{cond}"] = (
                {
                    k: got[-1].get(k)
                    for k in (
                        "commit",
                        "date_utc",
                        "pytest_seconds",
                        "wall_seconds_with_venv",
                        "user_cpu_seconds",
                        "system_cpu_seconds",
                        "passed",
                        "failed",
                        "skipped",
                        "exit_status",
                        "loadavg_start",
                    )
                }
                if got
                else None
            )
    # the verdict: the latest back-to-back pair on an idle machine, read both ways: the after
    # run within the goal in seconds, and the ratio after / before within what the goal asks of
    # the issue's figure (goal / 647 s), so that neither a fast hour nor a slow one decides it
    pairs_idle, pairs_busy = _make_test_pairs(d["runs"], 0), _make_test_pairs(d["runs"], 1)
    asked = goal / ISSUE_MAKE_TEST_S
    last_pair = pairs_idle[-1] if pairs_idle else None
    met = bool(
        last_pair
        and last_pair["after"]["pytest_seconds"] <= goal
        and last_pair["ratio_after_over_before"] <= asked
        and pairs_busy
    )
    return {
        "line": "make test on a fresh clone: ≤ 8 min, no test removed for speed; reported idle "
        "and with one core busy, before and after",
        "status": "met" if met else "short",
        "verdict_from": "the latest idle pair (paired_idle[-1]): its after run ≤ "
        "goal_pytest_seconds and its ratio after / before ≤ goal_over_issue_figure; a "
        "one-core-busy pair reported",
        "goal_over_issue_figure": asked,
        "paired_idle": pairs_idle,
        "paired_one_core_busy": pairs_busy,
        "before_and_after": table,
        "reported_idle_and_busy_before_and_after": all(v is not None for v in table.values()),
        "latest_idle": last,
        "latest_one_core_busy": busy[-1] if busy else None,
        "goal_pytest_seconds": goal,
        "file": "bench/results/make_test_runs.json (bench/make_test_fresh_clone.py)",
        "profile": _suite_profile(),
        "first_run": _first_run(),
    }


def _first_run() -> dict | None:
    """A user's first run of a command on an empty kernel cache (bench_first_run.py): the
    compile wait that every fresh clone's test processes and every new installation meet."""
    try:
        d = _load("first_run.json")
    except FileNotFoundError:
        return None
    return {"file": "bench/results/first_run.json", "commands": d.get("commands"),
            "summary": d.get("summary"), "note": d.get("note")}  # fmt: skip


def main() -> None:
    entries = [ortho(), *pushbroom(), bal(), make_test()]
    out = {
        "what": "issue 41's table, each figure beside its goal (bench/issue41_audit.py)",
        "summary": {s: sum(e["status"] == s for e in entries) for s in ("met", "short")},
        "entries": entries,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    path = RESULTS / "issue41_audit.json"
    path.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps(out["summary"]))
    for e in entries:
        print(e["status"], "|", e["line"][:90])


if __name__ == "__main__":
    main()
