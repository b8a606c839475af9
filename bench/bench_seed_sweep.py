"""Any seed, any scale: every chapter's ``hsgeo reproduce`` over many seeds at its smallest size.

    nice -n 15 python bench/bench_seed_sweep.py [--seeds 0-49] [--chapters a,b] [--scale 0.05]

For each chapter of :data:`hsgeo.reproduce.CHAPTERS` (the scoreboard excepted: it runs the
others) and each seed of ``--seeds`` (default 0–49), the command ``hsgeo reproduce CHAPTER
--seed S --scale SCALE --json`` runs exactly as a user types it, through
:func:`hsgeo.cli.main` in this one process (one import and one numba cache for all runs; each
run is an independent call), seed by seed across the chapters. A run **fails** when it exits
non-zero or when its standard output is not one JSON object with a non-empty ``rows`` list; the
failure's exit status, the last line of its message and, for an exception, its traceback are
kept.

**Resumable.** Every run is one record ``{chapter, seed, scale, commit, exit, ok, cpu_s, ...}``
in ``runs`` of the result file (``bench/results/seed_sweep.json`` or ``--out``), written after
each run (atomically), so that the sweep can be stopped at any moment and continued by a later
session: a (chapter, seed, scale) already recorded is skipped (``--redo`` runs it again and
replaces it). ``commit`` is the code's ``git describe --always --dirty`` at the run, so runs
of older code stay distinguishable; ``chapters`` summarises per chapter (distinct seeds done,
failures, commits).

**The smallest scale** is 0.05 for every chapter: below it no chapter gets any smaller (each
clamps ``scale`` to its own floor or has no size knob; the LP campaign refuses less than
:data:`hsgeo.simulate.lp_campaign.MIN_SCALE`). What each chapter's knob reaches is measured by
``bench/profile_smallest_scale.py`` (``bench/results/smallest_scale.json``).

This is a benchmark (``make bench``), not a test: one seed of the nine chapters costs about
400 CPU-s in one warm process (2026-11-28: lp-observations 126, rikola 95, pushbroom-ba 93,
asf 38, the other five 50 together), so 50 seeds are about 5.5 CPU-hours.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import platform
import resource
import subprocess
import sys
import time
import traceback
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).parent


def _cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def code_commit() -> str:
    """The code the runs measure: ``git describe --always --dirty`` of the repository."""
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=7"],
            cwd=HERE,
            capture_output=True,
            text=True,
            check=True,
        )
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def one_run(chapter: str, seed: int, scale: float) -> dict:
    """One ``hsgeo reproduce`` call in this process: exit status, JSON check, cost."""
    from hsgeo.cli import main

    out, err = io.StringIO(), io.StringIO()
    tb = None
    t0, c0 = time.perf_counter(), _cpu_s()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(
                ["reproduce", chapter, "--seed", str(seed), "--scale", str(scale), "--json"]
            )
        except SystemExit as e:  # argparse and the CLI's own exits
            code = e.code if isinstance(e.code, int) else 1
        except Exception:  # a traceback (the CLI re-raises a bug): kept whole
            code, tb = 99, traceback.format_exc()
    run = {
        "chapter": chapter,
        "seed": seed,
        "scale": scale,
        "exit": int(code or 0),
        "cpu_s": round(_cpu_s() - c0, 2),
        "wall_s": round(time.perf_counter() - t0, 2),
        "load_avg_1min": round(os.getloadavg()[0], 2),
        "finished_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }
    try:
        doc = json.loads(out.getvalue())
        ok_json = isinstance(doc, dict) and bool(doc.get("rows"))
    except json.JSONDecodeError:
        ok_json = False
    run["json"] = ok_json
    run["ok"] = run["exit"] == 0 and ok_json
    if not run["ok"]:
        lines = (err.getvalue().strip() or out.getvalue().strip()).splitlines()
        run["message"] = lines[-1][:400] if lines else ""
        if tb is not None:
            run["traceback"] = tb[-4000:]
    return run


def summarise(runs: list[dict]) -> dict:
    """Per chapter: distinct seeds done (per scale), failures with their messages, commits."""
    out: dict[str, dict] = {}
    for c in sorted({r["chapter"] for r in runs}):
        rc = [r for r in runs if r["chapter"] == c]
        cpu = sorted(r["cpu_s"] for r in rc if r.get("cpu_s") is not None)
        fails = [r for r in rc if not r["ok"]]
        out[c] = {
            "runs": len(rc),
            "seeds_by_scale": {
                str(s): sorted(r["seed"] for r in rc if r["scale"] == s)
                for s in sorted({r["scale"] for r in rc})
            },
            "failed": len(fails),
            "failures": [
                {
                    k: r[k]
                    for k in ("seed", "scale", "commit", "exit", "message", "traceback")
                    if k in r
                }
                for r in fails
            ],  # fmt: skip
            "commits": dict(
                sorted(
                    {
                        k: sum(r["commit"] == k for r in rc) for k in {r["commit"] for r in rc}
                    }.items()
                )
            ),
            "cpu_s_median": cpu[len(cpu) // 2] if cpu else None,
            "cpu_s_total": round(sum(cpu), 1),
        }
    return out


def parse_seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def _record(path: Path, doc: dict, run: dict) -> dict:
    """Add ``run`` to the result file, merged with what other sweeps wrote meanwhile (the
    file is re-read under a lock: several sweeps, e.g. one per group of chapters, may share
    it). Returns the document written."""
    import fcntl

    key = (run["chapter"], run["seed"], run["scale"])
    with open(path.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if path.exists():
            disk = json.loads(path.read_text(encoding="utf-8"))
            doc = {**disk, **{k: v for k, v in doc.items() if k not in ("runs", "chapters")}}
            doc["runs"] = disk.get("runs", [])
        doc["runs"] = [x for x in doc["runs"] if (x["chapter"], x["seed"], x["scale"]) != key]
        doc["runs"].append(run)
        doc["chapters"] = summarise(doc["runs"])
        doc["n_runs"] = len(doc["runs"])
        doc["n_failed"] = sum(not x["ok"] for x in doc["runs"])
        tmp = path.with_suffix(".json.part")
        tmp.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
        os.replace(tmp, path)
    return doc


def main(argv=None) -> int:
    from hsgeo.reproduce import CHAPTERS

    names = [c for c in CHAPTERS if c != "scoreboard"]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-49", help="seeds, e.g. 0-49 or 3,7,10-12")
    ap.add_argument("--scale", type=float, default=0.05)
    ap.add_argument("--chapters", default=",".join(names), help="comma-separated chapter names")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "seed_sweep.json")
    ap.add_argument("--redo", action="store_true", help="run recorded (chapter, seed) again")
    ap.add_argument(
        "--commit",
        default=None,
        help="the code's commit when run from an exported copy (default: git describe here)",
    )
    a = ap.parse_args(argv)
    chapters = [c for c in a.chapters.split(",") if c]
    unknown = sorted(set(chapters) - set(names))
    if unknown:
        ap.error(f"unknown chapter(s) {unknown}; one of {names}")
    doc = json.loads(a.out.read_text(encoding="utf-8")) if a.out.exists() else {}
    doc["what"] = __doc__.splitlines()[0]
    doc.setdefault("runs", [])
    doc["machine"] = {
        "cpus": os.cpu_count(),
        "cpu_model": platform.processor() or platform.machine(),
        "python": platform.python_version(),
    }
    commit = a.commit or code_commit()
    done = {(r["chapter"], r["seed"], r["scale"]) for r in doc["runs"]}
    # seed-major: every chapter asked for has seeds 0..k done whenever the sweep is stopped
    for seed in parse_seeds(a.seeds):
        for c in chapters:
            if (c, seed, a.scale) in done and not a.redo:
                continue
            if not a.redo and a.out.exists():  # another sweep on the same file did it
                disk = json.loads(a.out.read_text(encoding="utf-8"))
                if any((x["chapter"], x["seed"], x["scale"]) == (c, seed, a.scale)
                       for x in disk.get("runs", [])):  # fmt: skip
                    continue
            r = {"commit": commit, **one_run(c, seed, a.scale)}
            doc = _record(a.out, doc, r)
            print(
                f"{c} seed {seed}: {'ok' if r['ok'] else 'FAILED'} ({r['cpu_s']} CPU-s)"
                + ("" if r["ok"] else ": " + r.get("message", "")),
                file=sys.__stderr__,
                flush=True,
            )
    s = summarise(json.loads(a.out.read_text(encoding="utf-8"))["runs"])
    print(", ".join(f"{c}: {v['failed']} failed of {v['runs']}" for c, v in s.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
