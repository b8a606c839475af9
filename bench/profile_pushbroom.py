"""Profile the chapter's pushbroom adjustment by call, in CPU seconds (issue 29).

``python bench/profile_pushbroom.py 1 3 10`` adjusts the scaling benchmark's problem at each
scale (one fresh process each, ``NUMBA_NUM_THREADS=1`` so that the compiled kernels' CPU
seconds are the calling thread's, the Makefile's ``GLIBC_TUNABLES``), under ``cProfile`` with
``time.process_time`` as its clock: unlike wall seconds, CPU seconds do not grow when other
processes take the cores of a shared host. Writes ``bench/results/pushbroom_profile.json``:
per scale the calls and CPU seconds per call of the kernels that take the time, the user and
system seconds and page faults of the solve, and each call's CPU seconds per observation
relative to the 1× row (1: linear growth).

``--from-pstats DIR`` builds the JSON from ``cpu_<scale>.pstat`` dumps (with their ``.txt``
first line) of an earlier run instead of profiling again.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: the calls reported: (label, file suffix, function name)
CALLS = [
    ("reduced_matrix_kernel", "adjust/_fast.py", "_reduced_kernel"),
    ("model_linearisation", "sensors/pushbroom.py", "evaluate_into"),
    ("model_trial", "sensors/pushbroom.py", "trial_residuals"),
    ("assembly_fused_fill", "adjust/_fused.py", "fill"),
    ("jacobian_matvec", "adjust/_fast.py", "matvec"),
    ("jacobian_rmatvec_diag", "adjust/_fast.py", "rmatvec_diag"),
    ("cholesky", "scipy/linalg/_decomp_cholesky.py", "_cholesky"),
    ("datum_check", "adjust/datum.py", "_check_datum"),
    ("hold_points", "adjust/solver.py", "_hold_points"),
    ("rejection", "adjust/robust.py", "_reject"),
    ("solve_total", "workflows/pushbroom_ba.py", "solve"),
]


def _child(scale: float, seed: int, dump: Path) -> dict:
    import cProfile
    import gc
    import resource

    sys.path.insert(0, str(HERE))
    import bench_pushbroom_ba as B

    from hsgeo.workflows.pushbroom_ba import solve

    obs, p, blocks = B._problem(scale, seed)
    n_obs = obs.lines.n
    del obs
    gc.collect()
    B._load_compiled_kernels(seed)
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    pr = cProfile.Profile(time.process_time)
    t0 = time.perf_counter()
    pr.enable()
    res = solve(p, blocks)  # the chapter's settings (002 §3.4 rejection)
    pr.disable()
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    pr.dump_stats(str(dump))
    return {
        "scale": scale,
        "n_observations": n_obs,
        "iterations": res.iterations,
        "wall_seconds": wall,
        "user_seconds": r1.ru_utime - r0.ru_utime,
        "system_seconds": r1.ru_stime - r0.ru_stime,
        "minor_faults": r1.ru_minflt - r0.ru_minflt,
        "peak_rss_gb": r1.ru_maxrss / 2**20,
    }


def _first_touch() -> dict:
    """This machine's cost of new memory: the system seconds of filling a fresh 1 GiB array
    (its pages faulted in and zeroed by the kernel), measured in a fresh process. On a virtual
    machine whose host hands back the guest's freed pages this is seconds per GiB, and a solve
    pays it once for every GiB of its peak."""
    code = (
        "import resource, numpy as np\n"
        "r0 = resource.getrusage(resource.RUSAGE_SELF)\n"
        "a = np.ones(2**27)\n"
        "r1 = resource.getrusage(resource.RUSAGE_SELF)\n"
        "print(r1.ru_stime - r0.ru_stime, r1.ru_minflt - r0.ru_minflt)\n"
    )
    out = []
    for _ in range(3):
        cp = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True
        )
        sys_s, faults = cp.stdout.split()
        out.append({"system_seconds_per_gib": float(sys_s), "minor_faults": int(faults)})
    return {
        "runs": out,
        "median_system_seconds_per_gib": sorted(r["system_seconds_per_gib"] for r in out)[1],
        "what": "a fresh process fills np.ones(2**27) (1 GiB): the system seconds and page "
        "faults of its first touch, three processes",
    }


def _calls(pstat: Path) -> dict:
    """CPU seconds (cumulative) and calls of :data:`CALLS` in a profile dump."""
    import pstats

    stats = pstats.Stats(str(pstat)).stats
    out = {}
    for label, suffix, name in CALLS:
        hits = [v for (f, _, fn), v in stats.items() if f.endswith(suffix) and fn == name]
        if hits:
            _, ncalls, _, cum, _ = hits[0]
            out[label] = {"calls": ncalls, "cpu_seconds": cum, "cpu_seconds_per_call": cum / ncalls}
    return out


#: What became of the three designs (measured in session 18, 1×, on a loaded 2-core machine).
DESIGN_OUTCOMES = {
    "A_arrays_kept_column_indices_once": "built differently: the fused part's column indices, "
    "factored columns and whitened residuals are written by one compiled pass "
    "(adjust._fused._fused_columns, ≈ 0.02-0.03 CPU-s per linearisation) instead of numpy "
    "expressions with ≈ 100 MB of temporaries; keeping them between linearisations would "
    "save at most that pass (≈ 0.1 CPU-s a solve), not built",
    "B_trial_with_derivatives_double_buffered": "not built: the second set of arrays "
    "(≈ 270 MB at 1×) is new memory whose first touch costs system time on these machines "
    "(0.25-0.95 s for 283 MB measured), more than the ≤ 0.3 CPU-s of trial evaluations "
    "it would save (session 14: 2× system time)",
    "C_one_reduced_matrix_formation_fewer": "measured, not built: chord steps from the "
    "first iterate with the initial values' matrix are refused at 1× (cost 7.375e5 → "
    "9.553e6), so the matrix is formed there anyway and a trial is lost; the formation at "
    "the final iterate is the convergence test's and the covariance's. Three formations "
    "(initial values: datum check and first step; first iterate; final iterate) stay",
}


def _designs(row: dict) -> dict | None:
    """Upper bounds, from the 1× row's calls, of what three designs for the paper-size goal
    would save (CPU seconds and share of the solve); what became of each:
    :data:`DESIGN_OUTCOMES`."""
    c = row["calls"]
    need = ("solve_total", "assembly_fused_fill", "model_linearisation", "model_trial")
    if not all(k in c for k in need + ("reduced_matrix_kernel",)):
        return None
    total = c["solve_total"]["cpu_seconds"]
    lin, trial = c["model_linearisation"], c["model_trial"]
    # A: the arrays kept between linearisations with the same kept rows, the column indices
    # (and the padding) written once: at most fill's own seconds
    a = c["assembly_fused_fill"]["cpu_seconds"] - lin["cpu_seconds"]
    # B: each trial evaluated with derivatives into a second set of arrays, which becomes the
    # next linearisation when the step is accepted and no row is rejected: saves one
    # evaluation without derivatives a linearisation after the first
    b = min(trial["calls"], lin["calls"] - 1) * trial["cpu_seconds_per_call"]
    # C: one reduced-matrix formation fewer (changes the iterates: not to 1e-9)
    cc = c["reduced_matrix_kernel"]["cpu_seconds_per_call"]
    return {
        name: {"cpu_seconds": v, "share_of_solve": v / total, "outcome": DESIGN_OUTCOMES[name]}
        for name, v in (
            ("A_arrays_kept_column_indices_once", a),
            ("B_trial_with_derivatives_double_buffered", b),
            ("C_one_reduced_matrix_formation_fewer", cc),
        )
    }


def _remains(row: dict) -> dict | None:
    """Where the 1× solve's CPU seconds go, by share: the three reduced-matrix formations
    (the compiled Schur kernel), the LP model's evaluations (with and without derivatives),
    the system time (first touch of new memory) and the rest."""
    c = row["calls"]
    if "solve_total" not in c:
        return None
    total = row["user_seconds"] + row["system_seconds"]
    parts = {
        "reduced_matrix_kernel": c.get("reduced_matrix_kernel", {}).get("cpu_seconds", 0.0),
        "model_linearisation": c.get("model_linearisation", {}).get("cpu_seconds", 0.0),
        "model_trial": c.get("model_trial", {}).get("cpu_seconds", 0.0),
    }
    parts["system_time_first_touch"] = row["system_seconds"]
    parts["rest"] = max(total - sum(parts.values()), 0.0)
    return {
        "cpu_seconds": parts,
        "share": {k: v / total for k, v in parts.items()},
        "why": "the reduced matrix is formed 3 times (fewer is design C, measured above); its "
        "kernel's internals are the BAL benchmark's (adjust._fast._reduced_kernel). The model "
        "is 002 eq. (2)-(4) with the crossing time by Newton, evaluated once per "
        "linearisation and once per trial (PushbroomLines.trial_residuals, to 1e-4 s: one "
        "pass for most observations from the third trial on; the passes of each call: "
        "pushbroom_model_passes.json); error_model="
        "'numpy' or fastmath on it changed its CPU seconds by < 3 % (measured). The system "
        "time is the first touch of the ≈ 270 MB of row-compressed arrays of one "
        "linearisation (their format is the kernels'), advised small pages since 38ed0da "
        "(its cost with and without: pushbroom_first_touch.json); keeping freed memory "
        "(the Makefile's GLIBC_TUNABLES, the command's "
        "keep_freed_memory) did not lower it at 1× (pushbroom_malloc.json: these pages are "
        "the peak's, touched once), at 10× it did",
    }


def _remains_10x(row: dict, one: dict | None, touch: dict | None) -> dict | None:
    """Where the 10× solve's CPU seconds go, beside the 1× row: the same parts, each part's
    growth per observation, and the system time against this machine's first-touch cost of
    the solve's peak memory."""
    if "solve_total" not in row["calls"] or one is None:
        return None
    parts = _remains(row)
    n = row["n_observations"] / one["n_observations"]
    growth = {}
    base = (_remains(one) or {}).get("cpu_seconds", {})
    for k, v in parts["cpu_seconds"].items():
        v1 = base.get(k)
        if v1:
            growth[k] = v / v1 / n
    kernel = row["calls"].get("reduced_matrix_kernel", {})
    first = None
    if touch is not None:
        per = sorted(r["system_seconds_per_gib"] for r in touch["runs"])
        first = {
            "peak_gib": row["peak_rss_gb"],
            "machine_system_seconds_per_gib_min_median_max": [per[0], per[len(per) // 2], per[-1]],
            "predicted_system_seconds_min_max": [
                per[0] * row["peak_rss_gb"],
                per[-1] * row["peak_rss_gb"],
            ],
            "measured_system_seconds": row["system_seconds"],
            "note": "the first touch of a GiB costs this virtual machine from a tenth of a "
            "second to seconds, by the host's state (pages the guest touched lately are cheaper)"
            "; perf record of the 10x solve put 98 % of its kernel samples in clear_page_erms "
            "under do_huge_pmd_anonymous_page (bench/results/pushbroom_10x_perf_system.txt)",
        }
    return {
        "cpu_seconds": parts["cpu_seconds"],
        "share": parts["share"],
        "growth_per_observation_over_1x": growth,
        "first_touch_of_peak": first,
        "why": "the parts of the 1× account at ten times the observations: the reduced "
        f"matrix, {kernel.get('calls', 0)} formations, grows "
        f"{growth.get('reduced_matrix_kernel', float('nan')):.2f}× per observation (the tiles "
        "of the item pairs that occur outgrow the caches: their cost held in L1, at 1× and "
        "10×, is in schur_tiles_probe.json); the model's evaluations grow linearly, with "
        "the extra linearisation and "
        "trials of the 10× solve (a refused step "
        "retried with the thrown points held); the system time is the kernel zeroing the "
        "pages of the peak memory on their first touch, at this machine's cost per GiB "
        "(first_touch_of_peak), lower with a lower peak or with small pages for the "
        "Jacobian's arrays (pushbroom_first_touch.json)",
    }


def _summary(rows: list[dict], touch: dict | None = None) -> dict:
    one = next((r for r in rows if r["scale"] == 1.0), None)
    ten = next((r for r in rows if r["scale"] == 10.0), None)
    for r in rows:
        if one is None:
            break
        n = r["n_observations"] / one["n_observations"]
        for label, c in r["calls"].items():
            if label in one["calls"]:
                c["per_call_per_observation_per_1x"] = (
                    c["cpu_seconds_per_call"] / one["calls"][label]["cpu_seconds_per_call"] / n
                )
    designs = _designs(one) if one is not None else None
    return {
        "designs_at_1x": designs,
        "what_remains_at_1x": _remains(one) if one is not None else None,
        "what_remains_at_10x": _remains_10x(ten, one, touch) if ten is not None else None,
        "first_touch": touch,
        "problem": "the scaling benchmark's rows (bench_pushbroom_ba.py --scaling), adjusted "
        "as in the chapter, profiled by call with cProfile(time.process_time), one numba "
        "thread, one BLAS thread, with the GLIBC_TUNABLES of glibc_tunables (the Makefile's "
        "under make bench; empty: glibc's defaults)",
        "rows": rows,
        "notes": "cpu_seconds are cumulative (the call and what it calls); "
        "per_call_per_observation_per_1x: CPU seconds per call per observation relative to "
        "the 1x row (1: linear growth); model_linearisation is the LP kernel with derivatives "
        "(fused path), model_trial without (PushbroomLines.trial_residuals, the solver's trial "
        "steps)",
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scales", nargs="*", type=float, default=[1.0, 3.0, 10.0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--dump", default="/tmp/hsgeo_profile")
    ap.add_argument("--from-pstats", help="build the JSON from an earlier run's dumps")
    ap.add_argument("--out", default=str(HERE / "results" / "pushbroom_profile.json"))
    args = ap.parse_args(argv)
    if args.child:
        out = _child(args.scales[0], args.seed, Path(args.dump))
        print("RESULT " + json.dumps(out), flush=True)
        return 0
    rows = []
    for s in args.scales:
        if args.from_pstats:
            d = Path(args.from_pstats)
            row = json.loads((d / f"cpu_{s}.json").read_text())
            dump = d / f"cpu_{s}.pstat"
        else:
            dump = Path(f"{args.dump}_{s}.pstat")
            env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
            env["OMP_NUM_THREADS"] = "1"
            env["PYTHONPATH"] = str(HERE.parent / "src") + os.pathsep + env.get("PYTHONPATH", "")
            cmd = [sys.executable, __file__, str(s), "--child", "--dump", str(dump)]
            cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            row = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x[:7] == "RESULT ")
        row["calls"] = _calls(dump)
        rows.append(row)
    out = _summary(rows, _first_touch())
    out["date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    out["loadavg"] = os.getloadavg()
    out["glibc_tunables"] = os.environ.get("GLIBC_TUNABLES", "")
    sys.path.insert(0, str(HERE))
    from bench_pushbroom_ba import _commit

    out["commit"] = _commit()
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
