"""The chapter's pushbroom adjustment, this checkout against a previous main, in turn (A B A B …).

    python bench/pushbroom_vs_main.py --vs /path/to/previous-main [--scale 1] [--pairs 4]

Each run is one fresh process of ``bench_pushbroom_ba.py --child scaling`` of its own checkout
(its own ``src`` first on the path): the same problem, the compiled kernels loaded, then the
solve timed (wall, CPU seconds of all its threads, system seconds, minor faults, peak RSS).
Runs alternate so that a drift of the shared machine's speed falls on both; the load average
is recorded before each run. Writes ``bench/results/pushbroom_vs_main.json``: every run, the
medians of each side and the median of the pairwise ratios (this / previous main).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
FIGURES = ("wall_seconds", "solver_cpu_seconds", "solver_system_seconds", "solver_minor_faults")


def _commit(root: Path) -> str | None:
    cp = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True
    )
    return cp.stdout.strip() or None


def _run(root: Path, scale: float, seed: int) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PYTHONPATH"] = str(root / "src")
    script = root / "bench" / "bench_pushbroom_ba.py"
    cmd = [sys.executable, str(script), "--child", "scaling", "--scale", str(scale)]
    cmd += ["--seed", str(seed)]
    load = os.getloadavg()
    cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    out = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x.startswith("RESULT "))
    keep = FIGURES + ("peak_rss_mb", "iterations", "sigma0", "n_observations")
    row = {k: out[k] for k in keep}
    row["load_average_1_5_15_before"] = load
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vs", required=True, help="a checkout of the previous main")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--pairs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=str(HERE / "results" / "pushbroom_vs_main.json"))
    args = ap.parse_args(argv)
    this, other = HERE.parent, Path(args.vs).resolve()
    runs: dict[str, list] = {"this": [], "previous_main": []}
    for i in range(args.pairs):
        for side, root in (("previous_main", other), ("this", this)):
            print(f"pair {i + 1}/{args.pairs}: {side} ...", file=sys.stderr, flush=True)
            runs[side].append(_run(root, args.scale, args.seed))

    def med(side, k):
        return statistics.median(r[k] for r in runs[side])

    ratios = {
        k: statistics.median(
            a[k] / b[k] for a, b in zip(runs["this"], runs["previous_main"], strict=True) if b[k]
        )
        for k in FIGURES
    }
    out = {
        "what": "the chapter's pushbroom adjustment (bench_pushbroom_ba.py --child scaling: "
        "the solve after the compiled kernels were loaded), this checkout and the previous "
        "main in turn, each run a fresh process; numba's default threads (the cores), "
        "OPENBLAS_NUM_THREADS=1",
        "scale": args.scale,
        "pairs": args.pairs,
        "commit_this": _commit(this),
        "commit_previous_main": _commit(other),
        "median_this": {k: med("this", k) for k in FIGURES + ("peak_rss_mb",)},
        "median_previous_main": {k: med("previous_main", k) for k in FIGURES + ("peak_rss_mb",)},
        "median_ratio_this_over_previous_main": ratios,
        "runs": runs,
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "numba_threads": os.environ.get("NUMBA_NUM_THREADS", "default"),
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: out[k] for k in ("median_this", "median_previous_main")}, indent=1))
    print(json.dumps(ratios, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
