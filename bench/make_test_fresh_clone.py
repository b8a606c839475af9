"""``make test`` on a fresh clone, timed: one record added to make_test_runs.json.

    python bench/make_test_fresh_clone.py [--commit REV] [--busy-cores N] [--workdir DIR]
        [--role before|after] [--note TEXT]

Clones this repository at ``REV`` (default HEAD) into an empty folder, runs the README's test
command (``make test``) there exactly as CI does, and records the wall time of the whole command
(venv included) and of its pytest part (from pytest's own summary line), the children's user and
system CPU seconds (``os.wait4``), the peak resident memory of the largest child, the test counts,
and the load average before and after. ``--busy-cores N`` runs N busy loops beside it (one core
busy: the issue's second condition), each a ``python -c 'while 1: pass'`` at the same priority,
killed at the end.

``--role`` marks the record as the "before" (the commit the issue measured) or "after" figure
of issue 41's done-means, which ``issue41_audit.py`` puts side by side; give it only to a run
that had the machine to itself (apart from its own busy loops).

The figure depends on the machine's load: a record carries it; compare records taken at the
same load (or the same busy-core count on an otherwise idle machine).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUT = HERE / "results" / "make_test_runs.json"
_SUMMARY = re.compile(
    r"^=* ?(?P<body>\d+ (?:passed|failed)[^\n]*?) in (?P<secs>[0-9.]+)s(?: \([0-9:]+\))?(?: =+)?$",
    re.M,
)


def _counts(text: str) -> dict:
    """Test counts and pytest's own seconds from the last summary line of the output."""
    found = list(_SUMMARY.finditer(text))
    if not found:
        return {}
    m = found[-1]
    out = {"pytest_seconds": float(m.group("secs"))}
    for n, word in re.findall(r"(\d+) (passed|failed|skipped|errors?|xfailed|xpassed)", m["body"]):
        out[word.rstrip("s") if word.startswith("error") else word] = int(n)
    return out


_DURATION = re.compile(
    r"^(?P<s>[0-9.]+)s (?P<phase>call|setup|teardown) +(?P<test>\S.*?)\s*$", re.M
)


def _slowest(text: str) -> list[dict]:
    """pytest's ``--durations`` table (the Makefile asks for the slowest 40), as records."""
    return [
        {"seconds": float(m["s"]), "phase": m["phase"], "test": m["test"]}
        for m in _DURATION.finditer(text)
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--commit", default="HEAD")
    ap.add_argument("--busy-cores", type=int, default=0)
    ap.add_argument("--workdir", type=Path, default=None)
    ap.add_argument("--note", default="")
    ap.add_argument("--role", choices=("before", "after"), default=None)
    args = ap.parse_args()
    rev = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", args.commit],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    work = args.workdir or Path(tempfile.mkdtemp(prefix="make_test_"))
    clone = work / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    subprocess.run(["git", "-C", str(clone), "checkout", "-q", rev], check=True)
    busy = [
        subprocess.Popen([sys.executable, "-c", "while 1: pass"]) for _ in range(args.busy_cores)
    ]
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    log = work / "make_test.log"
    try:
        with log.open("w") as fh:
            p = subprocess.Popen(["make", "test"], cwd=clone, stdout=fh, stderr=subprocess.STDOUT)
            _, status, ru = os.wait4(p.pid, 0)
    finally:
        for b in busy:
            b.kill()
            b.wait()
    wall = time.perf_counter() - t0
    text = log.read_text(errors="replace")
    rec = {
        "commit": rev,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "command": "make test (README), fresh clone",
        "busy_cores": args.busy_cores,
        "exit_status": os.waitstatus_to_exitcode(status),
        "wall_seconds_with_venv": wall,
        "user_cpu_seconds": ru.ru_utime,
        "system_cpu_seconds": ru.ru_stime,
        "peak_rss_mib_largest_child": ru.ru_maxrss / 1024,
        "loadavg_start": list(load0),
        "loadavg_end": list(os.getloadavg()),
        "cpus": os.cpu_count(),
        "note": args.note,
        **({"role": args.role} if args.role else {}),
        **_counts(text),
        "slowest": _slowest(text),
        "failed_tests": re.findall(r"^(?:FAILED|ERROR) (\S+)", text, re.M),
    }
    runs = json.loads(OUT.read_text(encoding="utf-8")) if OUT.is_file() else {"runs": []}
    runs["runs"].append(rec)
    OUT.write_text(json.dumps(runs, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps(rec, indent=1))


if __name__ == "__main__":
    main()
