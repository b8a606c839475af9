"""A user's first run of a command: compiling the kernels, against the same command run again.

    python bench/bench_first_run.py [--vs /path/to/previous-main] [--rounds 2]
        [--command bal|pushbroom] [--out FILE]

hsgeo's kernels are compiled by numba on their first call and cached on disk (``cache=True``),
so the first run of a command on a new installation, a fresh clone or after an upgrade waits for
the compiler: every user meets this wait, and every ``make test`` on a fresh clone meets it in
each of its test processes. Each run here is a fresh process of the ``hsgeo`` command of one
checkout (its ``src`` first on the path) with ``NUMBA_CACHE_DIR`` set to a new empty folder
(cold: everything it calls is compiled), then the same command once more on that cache (warm:
loaded). Checkouts run in turn (this one, then ``--vs``), ``rounds`` times, so that the shared
machine's drift falls on both; wall seconds and the CPU seconds of the process (user and
system, all its threads) are recorded, and the cold run's numba compile seconds by function
(numba's ``numba:compile`` events, outermost calls only).

Commands: ``bal``, ``hsgeo adjust-bal`` on the BAL Ladybug-49 file shipped with hsgeo (the
README's example; the engine's frame-camera path); ``pushbroom``, ``hsgeo reproduce
pushbroom-ba --scale 0.1`` (the simulated campaign, its rendering and the pushbroom engine).
Writes ``bench/results/first_run.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

COMMANDS = {
    "bal": [
        "adjust-bal",
        "{root}/src/hsgeo/data/reference/bal-ladybug/problem-49-7776-pre.txt.bz2",
    ],
    "pushbroom": ["reproduce", "pushbroom-ba", "--scale", "0.1"],
}

# run in the child: numba's compile events of the outermost compilations, then the command
_CHILD = r"""
import json, os, sys, time, atexit
from numba.core import event
spans, depth, t0 = {}, [0], {}
class L(event.Listener):
    def on_start(self, e):
        depth[0] += 1
        if depth[0] == 1:
            t0["t"] = time.perf_counter()
    def on_end(self, e):
        depth[0] -= 1
        if depth[0] == 0:
            f = e.data["dispatcher"].py_func
            k = f.__module__ + "." + f.__qualname__
            spans[k] = spans.get(k, 0.0) + time.perf_counter() - t0["t"]
event.register("numba:compile", L())
out = sys.argv[1]
atexit.register(lambda: json.dump(spans, open(out, "w")))
from hsgeo import cli
sys.argv = ["hsgeo", *sys.argv[2:]]
raise SystemExit(cli.main(sys.argv[1:]))
"""


def _commit(root: Path) -> str | None:
    cp = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True
    )
    return cp.stdout.strip() or None


def _run(root: Path, argv: list[str], cache: Path, work: Path) -> dict:
    env = {
        **os.environ,
        "PYTHONPATH": str(root / "src"),
        "NUMBA_CACHE_DIR": str(cache),
        "MPLBACKEND": "Agg",
    }
    spans = work / "compile.json"
    load = os.getloadavg()[0]
    r0 = os.times()
    t = time.perf_counter()
    cp = subprocess.run(
        [sys.executable, "-c", _CHILD, str(spans), *(a.format(root=root) for a in argv)],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
    )
    wall = time.perf_counter() - t
    r1 = os.times()
    if cp.returncode != 0:
        raise SystemExit(
            f"{' '.join(argv)} in {root} failed ({cp.returncode}):\n{cp.stderr[-2000:]}"
        )
    compiled = json.loads(spans.read_text()) if spans.is_file() else {}
    return {
        "wall_seconds": round(wall, 3),
        "cpu_seconds": round(
            (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system), 3
        ),
        "compile_seconds": round(sum(compiled.values()), 3),
        "compile_seconds_by_function": {
            k: round(v, 3) for k, v in sorted(compiled.items(), key=lambda kv: -kv[1]) if v >= 0.5
        },
        "loadavg_1min_before": load,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vs", type=Path, action="append", default=[], help="another checkout")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--command", choices=sorted(COMMANDS), action="append")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "first_run.json")
    args = ap.parse_args(argv)
    roots = [ROOT, *[p.resolve() for p in args.vs]]
    commands = args.command or sorted(COMMANDS)
    runs = []
    for name in commands:
        for rnd in range(args.rounds):
            for root in roots:
                with tempfile.TemporaryDirectory(prefix="hsgeo-first-run-") as tmp:
                    cache = Path(tmp) / "numba-cache"
                    cold = _run(root, COMMANDS[name], cache, Path(tmp))
                    warm = _run(root, COMMANDS[name], cache, Path(tmp))
                row = {"command": name, "round": rnd, "checkout": str(root),
                       "commit": _commit(root), "cold": cold, "warm": warm}  # fmt: skip
                runs.append(row)
                print(
                    f"{name:9s} {row['commit']}: cold {cold['wall_seconds']:7.1f} s wall "
                    f"({cold['compile_seconds']:.1f} s compiling), warm "
                    f"{warm['wall_seconds']:6.1f} s",
                    flush=True,
                )
    summary = {}
    for name in commands:
        for root in roots:
            rows = [r for r in runs if r["command"] == name and r["checkout"] == str(root)]
            summary.setdefault(name, {})[_commit(root) or str(root)] = {
                f"{phase}_{fig}_median": statistics.median(r[phase][fig] for r in rows)
                for phase in ("cold", "warm")
                for fig in ("wall_seconds", "cpu_seconds", "compile_seconds")
            }
    out = {
        "what": (
            "a command's first run on an empty numba cache (cold: its kernels compiled) and the "
            "same command again (warm), checkouts in turn; CPU seconds of the process"
        ),
        "commands": {k: "hsgeo " + " ".join(COMMANDS[k]) for k in commands},
        "cpus": os.cpu_count(),
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "summary": summary,
        "runs": runs,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
