"""The chapter's pushbroom adjustment, this checkout against a previous main, in turn (A B A B …).

    python bench/pushbroom_vs_main.py --vs /path/to/previous-main [--scale 1] [--pairs 4]
        [--threads N] [--out FILE]

Each run is one fresh process of this script's ``--child`` mode with the other checkout's
``src`` first on the path: it runs that checkout's own ``bench_pushbroom_ba.case_scaling`` (the
same problem, the compiled kernels loaded) and times the solve by wrapping the checkout's
``hsgeo.workflows.pushbroom_ba.solve`` (wall, CPU seconds of all its threads, system seconds,
minor faults; peak RSS of the process), so that any checkout whose bench has
``case_scaling`` can be the other side, also one from before these figures were recorded (the
issue's own commit).
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


def _child(root: Path, scale: float, seed: int, as_command: bool = False) -> dict:
    """In a fresh process with ``root/src`` first on the path: that checkout's scaling case,
    its solve timed from outside (the checkout's own bench need not report CPU seconds).
    ``as_command``: first what that checkout's ``hsgeo`` command does to its process
    (``hsgeo.terminal.keep_freed_memory``, where it exists)."""
    import resource

    kept = None
    if as_command:
        import hsgeo.terminal as T

        kept = T.keep_freed_memory() if hasattr(T, "keep_freed_memory") else None

    sys.path.insert(0, str(root / "bench"))
    import hsgeo.workflows.pushbroom_ba as W

    if not Path(W.__file__).resolve().is_relative_to(root.resolve()):
        raise SystemExit(f"hsgeo imported from {W.__file__}, not from {root}")
    solve, got = W.solve, {}

    def timed(*a, **k):
        r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        res = solve(*a, **k)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        got.clear()  # the last call is the timed solve (the first loads the compiled kernels)
        got.update(
            wall_seconds=wall,
            solver_cpu_seconds=(r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            solver_system_seconds=r1.ru_stime - r0.ru_stime,
            solver_minor_faults=r1.ru_minflt - r0.ru_minflt,
            iterations=res.iterations,
            sigma0=res.sigma0,
            n_observations=getattr(res, "n_observations", None),
            final_cost=float(res.cost_history[-1]),
        )
        return res

    W.solve = timed
    import bench_pushbroom_ba as B

    B.case_scaling(scale, seed)
    got["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    got["kept_freed_memory"] = kept
    return got


def _run(root: Path, scale: float, seed: int, threads: int | None, as_command=False) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PYTHONPATH"] = str(root / "src")
    if threads:
        env["NUMBA_NUM_THREADS"] = str(threads)
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", str(root)]
    cmd += ["--scale", str(scale), "--seed", str(seed), "--vs", "-"]
    cmd += ["--as-command"] if as_command else []
    load = os.getloadavg()
    cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    row = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x.startswith("RESULT "))
    row["load_average_1_5_15_before"] = load
    return row


def _cpu() -> dict:
    """The CPU as the kernel reports it: a VM's model name alone ("AMD EPYC") does not tell
    machines apart; family, model and stepping do better."""
    info = {}
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        k, _, v = line.partition(":")
        k = k.strip()
        if k in ("model name", "cpu family", "model", "stepping", "cpu MHz") and k not in info:
            info[k] = v.strip()
    info["cores"] = os.cpu_count()
    return info


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vs", required=True, help="a checkout of the previous main")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--pairs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=None, help="NUMBA_NUM_THREADS (default: all)")
    ap.add_argument("--child", type=Path, default=None, help=argparse.SUPPRESS)
    ap.add_argument(
        "--as-command",
        action="store_true",
        help="each side's process set up as its hsgeo command sets up its own (memory kept)",
    )
    ap.add_argument("--out", default=str(HERE / "results" / "pushbroom_vs_main.json"))
    args = ap.parse_args(argv)
    if args.child is not None:
        got = _child(args.child, args.scale, args.seed, args.as_command)
        print("RESULT " + json.dumps(got), flush=True)
        return 0
    this, other = HERE.parent, Path(args.vs).resolve()
    runs: dict[str, list] = {"this": [], "previous_main": []}
    for i in range(args.pairs):
        for side, root in (("previous_main", other), ("this", this)):
            print(f"pair {i + 1}/{args.pairs}: {side} ...", file=sys.stderr, flush=True)
            runs[side].append(_run(root, args.scale, args.seed, args.threads, args.as_command))

    def med(side, k):
        return statistics.median(r[k] for r in runs[side])

    ratios = {
        k: statistics.median(
            a[k] / b[k] for a, b in zip(runs["this"], runs["previous_main"], strict=True) if b[k]
        )
        for k in FIGURES
    }
    out = {
        "what": "the chapter's pushbroom adjustment (each checkout's bench_pushbroom_ba."
        "case_scaling, its solve timed from outside after the compiled kernels were loaded), "
        "this checkout and the other in turn, each run a fresh process; OPENBLAS_NUM_THREADS=1",
        "scale": args.scale,
        "pairs": args.pairs,
        "commit_this": _commit(this),
        "commit_previous_main": _commit(other),
        "median_this": {k: med("this", k) for k in FIGURES + ("peak_rss_mb",)},
        "median_previous_main": {k: med("previous_main", k) for k in FIGURES + ("peak_rss_mb",)},
        "median_ratio_this_over_previous_main": ratios,
        "runs": runs,
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "numba_threads": args.threads or os.environ.get("NUMBA_NUM_THREADS", "default"),
        "cpu": _cpu(),
        "as_command": args.as_command,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: out[k] for k in ("median_this", "median_previous_main")}, indent=1))
    print(json.dumps(ratios, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
