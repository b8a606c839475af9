"""How long ``hsgeo`` takes to answer before any computation: help, version, a usage error,
a file not found.

    python bench/bench_cli_startup.py [--rounds N] [--vs TREE] [--out FILE]

Each command runs in a fresh process (``python -m hsgeo.cli ...``; the file not found is looked
for in an empty temporary folder) and is timed with ``os.wait4``: CPU seconds (user + system)
and wall seconds, the median of ``--rounds`` runs.
Beside them, in the same rounds, the floor of any Python command: ``python -c pass`` and
``python -c "import numpy"`` (the validators need numpy). ``--vs TREE`` times another checkout
(its ``src``) in turn with this one, command by command, so that both see the same machine
(issue 41: ``hsgeo --help`` took 2.4 s when ``hsgeo.io`` imported every reader).
Results: ``bench/results/cli_startup.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "results" / "cli_startup.json"

#: what a user types first, and what a mistyped option answers
COMMANDS = {
    "hsgeo --help": ["--help"],
    "hsgeo --version": ["--version"],
    "hsgeo orthorectify --help": ["orthorectify", "--help"],
    "hsgeo adjust-pushbroom (missing arguments)": ["adjust-pushbroom"],
    "hsgeo cube -x (unknown option)": ["cube", "-x"],
    # a mistyped file name: the handler imports its workflow before the file is looked for
    "hsgeo adjust-pushbroom (a file not found)": [
        "adjust-pushbroom",
        "{tmp}/obs.csv",
        "--trajectory",
        "{tmp}/nav.csv",
        "--camera",
        "{tmp}/camera.toml",
    ],
}
FLOOR = {"python -c pass": ["-c", "pass"], "python -c 'import numpy'": ["-c", "import numpy"]}


def _time(argv: list[str], src: Path | None) -> tuple[float, float]:
    """CPU and wall seconds of one fresh process (``src``: the checkout whose hsgeo it runs)."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [sys.executable, *argv], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    _, _, ru = os.wait4(p.pid, 0)
    return ru.ru_utime + ru.ru_stime, time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--vs", type=Path, default=None, help="another checkout, timed in turn")
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    trees = {"this": ROOT / "src"}
    if a.vs is not None:
        trees["vs"] = a.vs.resolve() / "src"
    tmp = Path(tempfile.mkdtemp(prefix="cli_startup_"))
    (tmp / "camera.toml").write_text("[sensor]\n", encoding="utf-8")
    jobs = [
        (name, ["-m", "hsgeo.cli", *(x.format(tmp=tmp) for x in args)], True)
        for name, args in COMMANDS.items()
    ]
    jobs += [(name, args, False) for name, args in FLOOR.items()]
    runs: dict = {t: {name: [] for name, _, _ in jobs} for t in trees}
    load = os.getloadavg()
    for _ in range(a.rounds):
        for name, args, needs_src in jobs:
            for tree, src in trees.items():  # in turn: both trees see the same moment
                if not needs_src and tree != "this":
                    continue
                runs[tree][name].append(_time(args, src if needs_src else None))
    summary = {
        tree: {
            name: {
                "cpu_seconds_median": statistics.median(c for c, _ in r),
                "wall_seconds_median": statistics.median(w for _, w in r),
            }
            for name, r in per.items()
            if r
        }
        for tree, per in runs.items()
    }
    doc = {
        "what": __doc__.splitlines()[0],
        "rounds": a.rounds,
        "trees": {t: str(p.parent) for t, p in trees.items()},
        "commit_this": subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip(),
        "machine": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        "load_average_before": load,
        "load_average_after": os.getloadavg(),
        "median": summary,
        "runs_cpu_wall_seconds": runs,
    }
    if a.vs is not None:
        doc["commit_vs"] = subprocess.run(
            ["git", "-C", str(a.vs), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip()
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    for tree, per in summary.items():
        for name, m in per.items():
            print(
                f"{tree:5s} {name:45s} {m['cpu_seconds_median']:6.2f} CPU-s "
                f"{m['wall_seconds_median']:6.2f} s"
            )
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
