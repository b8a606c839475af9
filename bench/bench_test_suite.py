"""What the test suite costs, file by file, in CPU seconds (issue 41: ``make test`` ≤ 8 min).

Each named test file runs as its own ``python -m pytest -q FILE`` process; the operating
system's accounting of the finished process (``os.wait4``: user + system CPU seconds of pytest
and every child it waited for, wall seconds, peak resident memory) is recorded with the load
average at start and end. With ``--base DIR`` (a clone of the previous main) every file runs
in both trees in turn, base then ours, ``--repeat`` times (paired, alternating runs), each tree
from its own ``src`` (``PYTHONPATH``), so a figure and its comparison share the machine's
state. ``--warmup`` runs each tree once untimed first, so the compiled-kernel cache (numba
``cache=True``, ``__pycache__`` beside the sources) is warm; without it a fresh clone's first
run includes the kernels' compilation (``make bench`` runs each heavy file once, no warm-up).

``python bench/bench_test_suite.py [--base DIR] [--repeat N] [FILE ...]`` writes
``bench/results/test_suite_cost.json`` (``--out`` elsewhere); ``make bench`` runs it with the
heavy files below. It never asserts a time: the figures are for a reader.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
# the files that cost most (a per-file measurement of issue 41; cheap files are left out so the
# benchmark stays a few minutes)
HEAVY = [
    "tests/test_bad_input.py",
    "tests/test_chapters.py",
    "tests/test_reproduce_pushbroom.py",
    "tests/test_reproduce_lp_observations.py",
    "tests/test_reproduce_asf.py",
    "tests/test_pushbroom_campaign.py",
    "tests/test_engine_threads.py",
    "tests/test_rikola.py",
    "tests/test_bal.py",
    "tests/test_cube.py",
    "tests/test_asf.py",
    "tests/test_nist_strd.py",
]
WHAT = (
    "CPU seconds (user + system, os.wait4) of one `python -m pytest -q FILE` process per test "
    "file or selection; base = a clone of the previous main, ours = this tree, run in turn"
)
_SUMMARY = re.compile(r"(\d+) (passed|failed|skipped|errors?|xfailed|xpassed|deselected)")


def run_file(tree: Path, test: str, marker: str | None, select: str | None = None) -> dict:
    """One ``pytest -q`` process on ``tree/test``: CPU, wall, peak memory and load average."""
    env = {**os.environ, "PYTHONPATH": str(tree / "src"), "OPENBLAS_NUM_THREADS": "1"}
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", test]
    if marker:
        argv += ["-m", marker]
    if select:
        argv += ["-k", select]
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        argv, cwd=tree, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    out = proc.stdout.read()
    _, status, ru = os.wait4(proc.pid, 0)
    wall_s = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    tail = out.strip().splitlines()[-1] if out.strip() else ""
    counts = {k: int(n) for n, k in _SUMMARY.findall(tail)}
    return {
        "cpu_s": round(ru.ru_utime + ru.ru_stime, 2),
        "user_s": round(ru.ru_utime, 2),
        "sys_s": round(ru.ru_stime, 2),
        "wall_s": round(wall_s, 2),
        "peak_rss_mib": round(ru.ru_maxrss / 1024, 1),
        "loadavg_1min_start": round(load0, 2),
        "loadavg_1min_end": round(os.getloadavg()[0], 2),
        "exit": proc.returncode,
        "counts": counts,
    }


def _median(runs: list[dict], key: str) -> float:
    return round(statistics.median(r[key] for r in runs), 2)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", default=HEAVY, help="test files (default: the heavy ones)")
    ap.add_argument("--base", type=Path, help="a clone of the previous main, run in turn with ours")
    ap.add_argument("--repeat", type=int, default=1, help="paired runs per file (default 1)")
    ap.add_argument(
        "--warmup", action="store_true", help="one untimed run per tree first (kernel cache warm)"
    )
    ap.add_argument("-m", dest="marker", help="a pytest -m expression, e.g. 'not slow'")
    ap.add_argument("-k", dest="select", help="a pytest -k expression (the tests a change touched)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "test_suite_cost.json")
    args = ap.parse_args(argv)

    trees = {"ours": ROOT} if args.base is None else {"base": args.base, "ours": ROOT}
    for test in args.files:
        if args.warmup:
            for tree in trees.values():
                # untimed: the compiled-kernel cache warm
                run_file(tree, test, args.marker, args.select)
        row = {
            "started_utc": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
            "loadavg_at_start": [round(x, 2) for x in os.getloadavg()],
            "trees": {k: str(v) for k, v in trees.items()},
            "marker": args.marker,
            "select": args.select,
            "warmup": args.warmup,
        }
        runs: dict[str, list[dict]] = {k: [] for k in trees}
        for _ in range(args.repeat):
            for name, tree in trees.items():
                if (tree / test).is_file():
                    runs[name].append(run_file(tree, test, args.marker, args.select))
        for name, rs in runs.items():
            if rs:
                row[name] = {
                    "cpu_s_median": _median(rs, "cpu_s"),
                    "wall_s_median": _median(rs, "wall_s"),
                    "runs": rs,
                }
        if runs.get("base") and runs.get("ours"):
            row["cpu_ratio_ours_over_base"] = round(
                statistics.median(
                    o["cpu_s"] / b["cpu_s"]
                    for o, b in zip(runs["ours"], runs["base"], strict=False)
                ),
                3,
            )
        row["loadavg_at_end"] = [round(x, 2) for x in os.getloadavg()]
        key = test + (f" -m {args.marker!r}" if args.marker else "")
        key += f" -k {args.select!r}" if args.select else ""
        _record(args.out, key, row)
        summary = {k: row[k]["cpu_s_median"] for k in trees if k in row}
        print(key, json.dumps(summary), row.get("cpu_ratio_ours_over_base"), flush=True)
    return 0


def _record(out: Path, key: str, row: dict) -> None:
    """Add (or replace) one measured entry of ``out``, keeping the others."""
    doc = {"what": WHAT, "cpus": os.cpu_count(), "entries": {}}
    if out.is_file():
        doc = json.loads(out.read_text(encoding="utf-8"))
    doc["entries"][key] = row
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".json.part")
    tmp.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    shutil.move(tmp, out)


if __name__ == "__main__":
    sys.exit(main())
