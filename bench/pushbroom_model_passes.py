"""The pushbroom model's evaluations in the chapter's adjustment, call by call (issue 41).

    python bench/pushbroom_model_passes.py [--scale 1] [--seed 0] [--out FILE]

Adjusts the scaling benchmark's problem (``bench_pushbroom_ba._problem``, the chapter's
settings) on one numba thread and one BLAS thread, with :func:`_lines_kernel` (002 eq. 2–4, the
crossing time by Newton) wrapped from outside: for each call, whether it formed the derivatives
(a linearisation) or only the residuals (a trial), its CPU seconds, and how far each
observation's crossing time moved from where its Newton started (``|Δt|``, s). An observation
whose time moved by less than the call's tolerance (``NEWTON_TOL_S``; a trial's
``TRIAL_TOL_S`` since issue 41) was evaluated in one pass; the others took two or more. What
this measures is where design B of issue 29 (the trial evaluated with its derivatives, reused
as the next linearisation) would save: a linearisation right after an
accepted trial evaluates the model at the trial's own crossing times once more. Nothing in the
library is changed; it writes ``bench/results/pushbroom_model_passes.json``.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=str(HERE / "results" / "pushbroom_model_passes.json"))
    args = ap.parse_args()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import numba
    import numpy as np

    numba.set_num_threads(1)
    sys.path.insert(0, str(HERE))
    import bench_pushbroom_ba as B

    import hsgeo.sensors._pushbroom_kernel as K
    import hsgeo.sensors.pushbroom as PB
    from hsgeo.workflows.pushbroom_ba import solve

    calls = []
    kernel = PB._lines_kernel
    names = K._ARGS

    def wrapped(*a):
        dts = a[names.index("dt_start")]
        before = dts.copy()
        c0 = time.process_time()
        kernel(*a)
        cpu = time.process_time() - c0
        row = {"derivatives": bool(a[names.index("jac")]), "cpu_s": cpu,
               "observations": int(a[names.index("pidx")].size)}  # fmt: skip
        if a[names.index("timed")]:
            moved = np.abs(dts - before)
            row["share_one_pass"] = float((moved < a[names.index("tol_s")]).mean())
            q = np.quantile(moved, [0.5, 0.9, 0.99])
            row["moved_s_quantiles_50_90_99"] = [float(v) for v in q]
        calls.append(row)

    obs, p, blocks = B._problem(args.scale, args.seed)
    del obs
    gc.collect()
    B._load_compiled_kernels(args.seed)
    PB._lines_kernel = wrapped
    try:
        res = solve(p, blocks)
    finally:
        PB._lines_kernel = kernel
    lin = [c for c in calls if c["derivatives"]]
    tri = [c for c in calls if not c["derivatives"]]
    # a linearisation whose observations all start at their crossing time (the trial just
    # before found it): the model pass it repeats is what design B would save
    repeat = [c for c in lin if c.get("share_one_pass", 0.0) == 1.0]
    one_pass = [c for c in tri if c.get("share_one_pass", 0.0) == 1.0]
    out = {
        "what": __doc__.splitlines()[0],
        "scale": args.scale,
        "seed": args.seed,
        "iterations": res.iterations,
        "calls": calls,
        "linearisations_cpu_s": sum(c["cpu_s"] for c in lin),
        "trials_cpu_s": sum(c["cpu_s"] for c in tri),
        "linearisations_at_a_trials_crossing_times": len(repeat),
        "one_pass_trial_cpu_s_median": (
            float(np.median([c["cpu_s"] for c in one_pass])) if one_pass else None
        ),
        "design_B_saves_at_most_cpu_s": (
            len(repeat) * float(np.median([c["cpu_s"] for c in one_pass])) if one_pass else None
        ),
        "note": "one numba thread; the first linearisation starts every Newton at the line time "
        "(several passes); design_B_saves_at_most_cpu_s: one residual pass (the median "
        "CPU-s of a trial that took one pass) per linearisation that repeats a trial's "
        "crossing times, before the cost of writing the trial's derivatives to a second set "
        "of arrays",
        "date_utc": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()),
        "loadavg": os.getloadavg(),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    print(json.dumps({k: v for k, v in out.items() if k != "calls"}, indent=1))


if __name__ == "__main__":
    main()
