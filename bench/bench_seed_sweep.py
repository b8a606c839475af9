"""Any seed, any scale: every chapter's ``hsgeo reproduce`` over many seeds at its smallest size.

For each chapter of :data:`hsgeo.reproduce.CHAPTERS` (the scoreboard excepted: it runs the
others) and each seed of ``--seeds`` (default 0–49), the command ``hsgeo reproduce CHAPTER
--seed S --scale SCALE --json`` runs exactly as a user types it, through
:func:`hsgeo.cli.main` in this one process (one import and one numba cache for all runs; each
run is an independent call), seed by seed across the chapters, so that every chapter has the same
seeds done whenever the sweep is stopped. A run **fails** when it exits non-zero
or when its standard output is not one JSON object with a non-empty ``rows`` list; the
failure's exit status and the first line of its message are kept. ``--scale`` default 0.05 is the
smallest size the LP campaign accepts (:data:`hsgeo.simulate.lp_campaign.MIN_SCALE`); every
other chapter clamps it to its own smallest size or has no size knob.

Each run's CPU seconds (user + system of the process, ``resource.getrusage``), wall seconds and
the machine's load average are recorded. Writes ``bench/results/seed_sweep.json`` (or
``--out``); ``--chapters`` runs some chapters only, and a result file is merged chapter by chapter
into the one already there, so that the sweep can be run in parts on a shared machine.

This is a benchmark (``make bench``), not a test: one seed of the nine chapters costs about
330 CPU-s on this machine's kind (2026-11-28: asf 36, rikola 75, pushbroom-ba 84,
lp-observations 79), so 50 seeds are about 4.6 CPU-hours.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import platform
import resource
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).parent


def _cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _one(chapter: str, seed: int, scale: float) -> dict:
    """One ``hsgeo reproduce`` call in this process: exit status, JSON check, cost."""
    from hsgeo.cli import main

    out, err = io.StringIO(), io.StringIO()
    t0, c0 = time.perf_counter(), _cpu_s()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(
                ["reproduce", chapter, "--seed", str(seed), "--scale", str(scale), "--json"]
            )
        except SystemExit as e:  # argparse and the CLI's own exits
            code = e.code if isinstance(e.code, int) else 1
        except Exception as e:  # a traceback: kept as the failure's message
            code, err = 99, io.StringIO(f"{type(e).__name__}: {e}")
    run = {
        "seed": seed,
        "exit": int(code or 0),
        "cpu_s": round(_cpu_s() - c0, 2),
        "wall_s": round(time.perf_counter() - t0, 2),
    }
    try:
        doc = json.loads(out.getvalue())
        ok_json = isinstance(doc, dict) and bool(doc.get("rows"))
    except json.JSONDecodeError:
        ok_json = False
    run["json"] = ok_json
    run["ok"] = run["exit"] == 0 and ok_json
    if not run["ok"]:
        msg = (err.getvalue().strip() or out.getvalue().strip()).splitlines()
        run["message"] = msg[-1][:400] if msg else ""
    return run


def _summary(runs: list[dict], scale: float) -> dict:
    """One chapter's runs so far: counts, failed seeds, CPU seconds."""
    seeds = [r["seed"] for r in runs]
    failed = [r["seed"] for r in runs if not r["ok"]]
    cpu = sorted(r["cpu_s"] for r in runs)
    return {
        "scale": scale,
        "seeds": seeds,
        "runs": len(runs),
        "failed": len(failed),
        "failed_seeds": failed,
        "cpu_s_median": cpu[len(cpu) // 2],
        "cpu_s_total": round(sum(cpu), 1),
        "load_avg_end": os.getloadavg(),
        "finished_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "failures": [r for r in runs if not r["ok"]],
    }


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def main(argv=None) -> int:
    from hsgeo.reproduce import CHAPTERS

    names = [c for c in CHAPTERS if c != "scoreboard"]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-49", help="seeds, e.g. 0-49 or 3,7,10-12")
    ap.add_argument("--scale", type=float, default=0.05)
    ap.add_argument("--chapters", default=",".join(names), help="comma-separated chapter names")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "seed_sweep.json")
    a = ap.parse_args(argv)
    chapters = [c for c in a.chapters.split(",") if c]
    unknown = sorted(set(chapters) - set(names))
    if unknown:
        ap.error(f"unknown chapter(s) {unknown}; one of {names}")
    seeds = _seeds(a.seeds)
    doc = json.loads(a.out.read_text()) if a.out.exists() else {}
    doc["what"] = __doc__.splitlines()[0]
    doc.setdefault("chapters", {})
    doc["machine"] = {
        "cpus": os.cpu_count(),
        "cpu_model": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "load_avg_start": os.getloadavg(),
    }
    # seed-major: every chapter has seeds 0..k done at any moment the sweep is stopped
    runs: dict[str, list[dict]] = {c: [] for c in chapters}
    for seed in seeds:
        for c in chapters:
            r = _one(c, seed, a.scale)
            runs[c].append(r)
            print(
                f"{c} seed {seed}: {'ok' if r['ok'] else 'FAILED'} ({r['cpu_s']} CPU-s)"
                + ("" if r["ok"] else ": " + r.get("message", "")),
                file=sys.__stderr__,
                flush=True,
            )
            doc["chapters"][c] = _summary(runs[c], a.scale)
            a.out.write_text(json.dumps(doc, indent=1) + "\n")  # after each run
    total = sum(v["failed"] for v in doc["chapters"].values())
    print(
        f"{len(doc['chapters'])} chapters, {total} failed run(s); "
        + ", ".join(f"{c}: {v['failed']}/{v['runs']}" for c, v in doc["chapters"].items())
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
