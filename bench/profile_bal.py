"""Profile hsgeo's adjustment of BAL Ladybug-49 by call, in CPU seconds (issue 41).

``python bench/profile_bal.py`` adjusts the problem of ``bench_bal.py`` (one numba thread, one
BLAS thread, the compiled kernels loaded first on a 5-camera subset) under ``cProfile`` with
``time.process_time`` as its clock and writes ``bench/results/bal_profile.json``: the CPU
seconds and calls of the parts of an iteration (the reduced-matrix kernel, the model, the
assembly, the Cholesky factorisation, the trial steps), per iteration and as shares of the
solve; the iterations and reduced-matrix formations to Ceres' final cost of ``bal.json``;
the inner solver; the CPU model and the BLAS core type.
"""

from __future__ import annotations

import cProfile
import json
import os
import pstats
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: the calls reported: (label, file suffix, function name)
CALLS = [
    ("reduced_matrix_kernel", "adjust/_fast.py", "_reduced_kernel"),
    ("reduced_system", "adjust/schur.py", "_reduced"),
    ("cholesky", "scipy/linalg/_decomp_cholesky.py", "_cholesky"),
    ("model", "sensors/bal.py", "evaluate"),
    ("linearisation", "adjust/solver.py", "linearise"),
    ("trial_steps", "adjust/solver.py", "trial"),
    ("assembly", "adjust/system.py", "_assemble"),
    ("normal_equations", "adjust/schur.py", "_normal_equations"),
    ("datum_check", "adjust/datum.py", "_check_datum"),
    ("sum_of_chunks", "adjust/_fast.py", "_assemble"),
    ("solve_total", "adjust/solver.py", "_adjust"),
]


def _schur_entries(problem) -> int:
    """The entries of the reduced matrix's upper triangle that the points add to, over all
    points: ``Σ_i n_i (n_i + 1) / 2`` with ``n_i`` the free camera columns that point i's
    observations touch (the work of one formation, the same for any Schur elimination).
    """
    import numpy as np

    from hsgeo.workflows.bal import gauge_fix, prepare

    prob, _ = prepare(problem)
    free = np.full(prob.n_cameras, 9)
    for cam, _ in gauge_fix(prob.cameras):
        free[cam] -= 1
    n = np.bincount(prob.point_index, weights=free[prob.camera_index], minlength=prob.n_points)
    return int(np.sum(n * (n + 1) / 2))


def _split(calls: dict, iterations: int) -> dict:
    """CPU seconds per iteration of the parts of the solve (from the cumulative ``calls``)."""

    def cum(label):
        return calls.get(label, {}).get("cpu_seconds", 0.0)

    parts = {
        "reduced_matrix_kernel": cum("reduced_matrix_kernel"),
        "reduced_system_rest (V⁻¹, right-hand side, sum of the chunks)": cum("reduced_system")
        - cum("reduced_matrix_kernel"),
        "cholesky": cum("cholesky"),
        "linearisation (model with Jacobian, assembly, normal equations)": cum("linearisation"),
        "trial_steps (model without Jacobian)": cum("trial_steps"),
        "datum_check (once)": cum("datum_check"),
    }
    parts["other (back-substitution, damping, bookkeeping)"] = cum("solve_total") - sum(
        parts.values()
    )
    return {k: v / max(iterations, 1) for k, v in parts.items()}


def main() -> int:
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    sys.path.insert(0, str(HERE))
    import bench_bal as BB

    from hsgeo.io.bal import ladybug_path, read_bal
    from hsgeo.workflows.bal import BAL_OPTIONS, adjust_bal

    problem = read_bal(ladybug_path())
    adjust_bal(
        problem.select_cameras(range(5)), BAL_OPTIONS.replace(max_iter=2, raise_on_failure=False)
    )
    trace = []
    pr = cProfile.Profile(time.process_time)
    c0 = time.process_time()
    pr.enable()
    fit = adjust_bal(
        problem,
        progress=lambda i: trace.append((i["iteration"], i["cost"], time.process_time() - c0)),
    )
    pr.disable()
    cpu = time.process_time() - c0
    stats = pstats.Stats(pr).stats
    calls = {}
    for label, suffix, name in CALLS:
        hits = [v for (f, _, fn), v in stats.items() if f.endswith(suffix) and fn == name]
        if hits:
            _, ncalls, _, cum, _ = hits[0]
            calls[label] = {
                "calls": ncalls,
                "cpu_seconds": cum,
                "cpu_seconds_per_iteration": cum / max(fit.iterations, 1),
                "share_of_solve": cum / cpu,
            }
    split = _split(calls, fit.iterations)
    entries = _schur_entries(problem)
    prev = HERE / "results" / "bal.json"
    ceres = json.loads(prev.read_text()) if prev.exists() else {}
    target = ceres.get("ceres_final_cost")
    reach = next((t for t in trace if target and t[1] <= target * (1 + 1e-6)), None)
    out = {
        "problem": BB.PROBLEM,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "cpu_seconds": cpu,
        "iterations": fit.iterations,
        "cpu_seconds_per_iteration": cpu / max(fit.iterations, 1),
        "final_cost": fit.final_cost,
        "ceres_final_cost": target,
        "iterations_to_ceres_cost": None if reach is None else reach[0],
        "cpu_seconds_to_ceres_cost": None if reach is None else reach[2],
        "ceres_iterations": ceres.get("ceres_iterations"),
        "ceres_cpu_seconds": ceres.get("ceres_cpu_seconds"),
        "ceres_cpu_seconds_per_iteration": (
            ceres["ceres_cpu_seconds"] / ceres["ceres_iterations"]
            if ceres.get("ceres_iterations")
            else None
        ),
        "inner_solver": "Schur complement on the points (compiled, point by point: "
        "_fast._reduced_kernel; the BAL points have slot columns only, so _fast._slot_point: "
        "the upper triangle of each point's C = YᵀY − Zᵀ V⁻¹ Z added into the reduced matrix "
        "along runs of consecutive columns), the reduced camera system by dense Cholesky "
        "(scipy.linalg.cho_factor); the point blocks damped at every λ "
        "(BAL_OPTIONS.lambda_points_min ≈ 0), so each damping tried forms the reduced matrix "
        "again (a refused step changes the points' damped blocks, not only S's diagonal); "
        "Ceres: DENSE_SCHUR, the same structure",
        "reduced_matrix_formations": calls.get("reduced_matrix_kernel", {}).get("calls"),
        "schur_entries_per_formation": entries,
        "kernel_ns_per_schur_entry": 1e9
        * calls.get("reduced_matrix_kernel", {}).get("cpu_seconds", 0.0)
        / max(calls.get("reduced_matrix_kernel", {}).get("calls", 1) * entries, 1),
        "cpu_seconds_per_iteration_split": split,
        "calls": calls,
        "seconds_split_wall": {k: float(v) for k, v in sorted(fit.result.seconds_split.items())},
        "machine": BB._machine_info(),
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "load_average_1_5_15_at_end": list(os.getloadavg()),
        "notes": "cpu_seconds are cumulative (the call and what it calls), one thread; "
        "CPU seconds on a loaded shared machine are inflated too (shared caches), so the "
        "shares, not the absolute figures, are what this profile measures",
    }
    out["what_remains"] = _what_remains(out)
    path = HERE / "results" / "bal_profile.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))
    return 0


def _what_remains(o: dict) -> str:
    """The profile's account of where the CPU seconds of an iteration go, against Ceres'."""
    sp = o["cpu_seconds_per_iteration_split"]
    total = sum(sp.values())
    parts = ", ".join(f"{k.split(' (')[0]} {1e3 * v:.1f}" for k, v in sp.items())
    ceres = o.get("ceres_cpu_seconds_per_iteration")
    return (
        f"per iteration {1e3 * total:.1f} CPU-ms ({parts}; ms); Ceres "
        + (f"{1e3 * ceres:.1f} CPU-ms per iteration" if ceres else "not measured")
        + f" (bal.json, another run); iterations to Ceres' cost {o['iterations_to_ceres_cost']} "
        f"against Ceres' {o['ceres_iterations']}. The kernel adds "
        f"{o['schur_entries_per_formation']:,} upper-triangle entries per formation at "
        f"{o['kernel_ns_per_schur_entry']:.2f} ns each: the work of any Schur elimination of "
        "these points (Ceres' DENSE_SCHUR adds the same blocks). Within the kernel (stages "
        "of a captured formation timed apart, 2026-11-29, load 7-9, fastest of 7): local "
        "columns 2.4 ms, zeroing C 1.5, YᵀY and Z 4.6, V⁻¹ Z 1.1, C − Zᵀ V⁻¹ Z and its add "
        "into the reduced matrix 15 of 25 ms: three multiply-adds and one add per entry, the "
        "adds along runs of about 9 consecutive columns (a camera's; 65 % of the entries), "
        "too short for the vector loops' 16-wide body; the reduced matrix's memory is not "
        "the limit (writing into an 8-row scratch instead took as long). The rest of an "
        "iteration is spread over many calls of 1-2 ms (model, Jacobian assembly, gradient, "
        "point blocks, Cholesky of the 434 × 434 reduced matrix). The CPU seconds of a loaded "
        "machine are inflated (shared caches)."
    )


if __name__ == "__main__":
    sys.exit(main())
