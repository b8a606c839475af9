"""``make bench``: speed on a busy machine (issue 20) → ``bench/results/busy_machine.json``.

Three commands, each timed as a whole fresh process (wall seconds, median of ``--repeats``),
on an idle machine and with one core kept busy by another process (a spinning Python loop,
what a browser, a second ``make`` or a CI neighbour does), with the threads a user gets by
default (``NUMBA_NUM_THREADS`` and ``OPENBLAS_NUM_THREADS`` unset) against one thread
(both set to 1):

* ``line_calibration``: ``hsgeo reproduce line-calibration --seed 9173 --scale 0.1 --json``
  (252 small adjustments);
* ``frame_calibration``: ``hsgeo reproduce frame-reference --json`` (OpenCV's samples);
* ``pushbroom_solve``: the paper-size pushbroom adjustment of ``bench_pushbroom_ba.py``
  (its solver seconds; 442,000 observations).

``--previous DIR``: also time the default-threads rows with the code of another checkout's
``src`` (e.g. the previous main), in the same run: the before and after of the issue.

``threshold``: the engine's own choice, ``SolverOptions.threads``, on frame-camera bundle
blocks of growing size, adjusted in one process on one thread and on two, idle and busy: the
smallest size at which two threads are faster on the idle machine is what
``hsgeo.adjust.threads.PARALLEL_MIN_ROWS`` should be near.
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
SRC = HERE.parent / "src"

COMMANDS = {
    "line_calibration": [
        "-m",
        "hsgeo.cli",
        "reproduce",
        "line-calibration",
        "--seed",
        "9173",
        "--scale",
        "0.1",
        "--json",
    ],
    "frame_calibration": ["-m", "hsgeo.cli", "reproduce", "frame-reference", "--json"],
    "pushbroom_solve": [
        str(HERE / "bench_pushbroom_ba.py"),
        "--child",
        "ours",
        "--scale",
        "1",
        "--reject",
    ],
}


class Busy:
    """One core kept busy by another process while the block runs."""

    def __enter__(self):
        self.p = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(0.5)
        return self

    def __exit__(self, *exc):
        self.p.kill()
        self.p.wait()


def _env(threads: str, src: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    if threads == "one":
        env.update(NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PYTHONPATH"] = str(src)
    return env


def _time(name: str, threads: str, src: Path, timeout: float) -> dict:
    t0 = time.perf_counter()
    cp = subprocess.run(
        [sys.executable, *COMMANDS[name]],
        env=_env(threads, src),
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    wall = time.perf_counter() - t0
    if cp.returncode != 0:
        raise RuntimeError(f"{name} ({threads}) failed:\n{cp.stderr[-2000:]}")
    out = {"process_seconds": wall}
    for line in cp.stdout.splitlines():  # bench_pushbroom_ba's child prints its result
        if line.startswith("RESULT "):
            res = json.loads(line[7:])
            out["solver_seconds"] = res["solver_seconds"]
    return out


def commands(repeats: int, previous: Path | None, timeout: float) -> list[dict]:
    rows = []
    codes = [("this", SRC)] + ([("previous", previous / "src")] if previous else [])
    for code, src in codes:
        for name in COMMANDS:
            _time(name, "default", src, timeout)  # warm numba's on-disk cache of this code
            for load in ("idle", "busy"):
                for threads in ("default", "one"):
                    if code == "previous" and threads == "one":
                        continue  # one thread was never the problem
                    runs = []
                    for _ in range(repeats if code == "this" else 1):
                        load0 = os.getloadavg()[0]
                        if load == "busy":
                            with Busy():
                                runs.append(_time(name, threads, src, timeout))
                        else:
                            runs.append(_time(name, threads, src, timeout))
                        runs[-1]["loadavg_1min_at_start"] = load0
                    key = "solver_seconds" if "solver_seconds" in runs[0] else "process_seconds"
                    row = {
                        "command": name,
                        "code": code,
                        "load": load,
                        "threads": threads,
                        "seconds_key": key,
                        "median_seconds": statistics.median(r[key] for r in runs),
                        "runs": runs,
                    }
                    rows.append(row)
                    print(json.dumps({k: v for k, v in row.items() if k != "runs"}), flush=True)
    return rows


def threshold_child(sizes: list[int], repeats: int) -> list[dict]:
    from bench_engine import make_problem as _block  # the engine benchmark's frame block

    from hsgeo.adjust import adjust

    p, b = _block(2000)
    adjust(p, b, threads=1)  # load the compiled kernels
    adjust(p, b, threads=2)
    out = []
    for n in sizes:
        p, b = _block(n)
        row = {"n_points": n, "rows": int(b.m)}
        for t in (1, 2):
            secs = []
            for _ in range(repeats):
                res = adjust(p, b, threads=t)
                secs.append(res.seconds)
            row[f"seconds_{t}_thread{'s' if t > 1 else ''}"] = statistics.median(secs)
        out.append(row)
    return out


def threshold(sizes: list[int], repeats: int) -> dict:
    res = {}
    for load in ("idle", "busy"):
        cmd = [sys.executable, __file__, "--threshold-child", ",".join(map(str, sizes))]
        cmd += ["--repeats", str(repeats)]
        env = _env("default", SRC)
        if load == "busy":
            with Busy():
                cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
        else:
            cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
        res[load] = json.loads(cp.stdout.splitlines()[-1])
        print(load, json.dumps(res[load]), flush=True)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--previous", type=Path, help="a checkout whose src/ to time as 'previous'")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--only", choices=("commands", "threshold"))
    ap.add_argument("--threshold-child")
    ap.add_argument("--out", default=str(HERE / "results" / "busy_machine.json"))
    args = ap.parse_args(argv)
    if args.threshold_child:
        sizes = [int(s) for s in args.threshold_child.split(",")]
        print(json.dumps(threshold_child(sizes, args.repeats)))
        return 0
    from hsgeo.adjust.threads import PARALLEL_MIN_ROWS

    out = {
        "cpus": os.cpu_count(),
        "loadavg_at_start": os.getloadavg(),
        "started_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "parallel_min_rows": PARALLEL_MIN_ROWS,
    }
    if args.only != "threshold":
        out["commands"] = commands(args.repeats, args.previous, args.timeout)
    if args.only != "commands":
        out["threshold"] = threshold([2000, 6000, 15000, 30000, 60000], args.repeats)
    out["loadavg_at_end"] = os.getloadavg()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
