"""Issue 41's paired figures: this checkout against the issue's own commit, in turn, in one hour.

    python bench/issue41_pairs.py [--commit 8477cad] [--quick]

``make bench`` runs it before ``issue41_audit.py``. The issue's goals are figures of one
machine on one day; this machine's speed moved by a factor of 2.5 between days (8477cad's test
suite: 647 s in the issue, 1,600 s on 2026-11-29, 657 s on 2026-11-30), so the audit reads each
row from runs of this checkout and of the issue's commit alternating on the same machine
(``issue41_audit.py``: the median within the goal and the ratio within goal ÷ issue figure).

The issue's commit is checked out into a temporary git worktree (the repository's history is
enough: nothing is downloaded) and each benchmark's ``--vs`` mode runs both sides in turn, with
this process's environment (``make bench``: the Makefile's ``GLIBC_TUNABLES``, one BLAS thread):

* the paper-size pushbroom solve on the kernels' threads (4 pairs) and on one thread (8 pairs:
  the issue's 3.90 CPU-s is of one thread; two runs of 4 pairs of the same code gave 0.751 and
  0.774 of the issue's commit, either side of the 0.769 asked),
  ``pushbroom_vs_issue_tunables.json``, ``pushbroom_vs_issue_one_thread.json``;
* 10× the paper, 2 pairs and 1 pair on one thread (``pushbroom_vs_issue_10x_tunables.json``,
  ``pushbroom_vs_issue_10x_one_thread.json``; about 4 min);
* orthorectification (``bench_orthomosaic.py --pairs 3 --vs-src``, ``orthomosaic.json``) and
  BAL against Ceres (``bench_bal.py --repeats 5 --vs``, ``bal.json``): their own files, with
  the paired rounds added (a whole ``make bench`` runs them here only, not twice; without the
  issue's commit in the history they run unpaired).

``--quick`` leaves out the 10× pairs. ``make test``'s pair is not here: it clones the
repository twice and takes half an hour (``make_test_fresh_clone.py --role before|after``).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"


def _pairs(vs: Path, quick: bool) -> list[list[str]]:
    pb = [sys.executable, str(HERE / "pushbroom_vs_main.py"), "--vs", str(vs)]

    def out(name: str) -> list[str]:
        return ["--out", str(RESULTS / f"pushbroom_vs_issue{name}.json")]

    jobs = [
        [*pb, "--scale", "1", "--pairs", "4", *out("_tunables")],
        [*pb, "--scale", "1", "--pairs", "8", "--threads", "1", *out("_one_thread")],
    ]
    if not quick:
        jobs += [
            [*pb, "--scale", "10", "--pairs", "2", *out("_10x_tunables")],
            [*pb, "--scale", "10", "--pairs", "1", "--threads", "1", *out("_10x_one_thread")],
        ]
    jobs += [
        [sys.executable, str(HERE / "bench_orthomosaic.py"), "--pairs", "3",
         "--vs-src", str(vs / "src")],
        [sys.executable, str(HERE / "bench_bal.py"), "--repeats", "5", "--vs", str(vs)],
    ]  # fmt: skip
    return jobs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--commit", default="8477cad", help="the issue's commit (default 8477cad)")
    ap.add_argument("--quick", action="store_true", help="without the 10x pairs")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="hsgeo_issue41_") as tmp:
        vs = Path(tmp) / "issue"
        add = ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(vs), args.commit]
        cp = subprocess.run(add, capture_output=True, text=True)
        if cp.returncode != 0:
            # make bench leaves the plain BAL and orthorectification runs to this script: they
            # still run, unpaired (their files then hold no pairs; the pushbroom pair files
            # keep their last runs)
            print(
                f"issue41_pairs: cannot check out {args.commit} ({cp.stderr.strip()}); the "
                "pairs need the repository's history (a full clone, not a shallow one). "
                "Running bench_orthomosaic.py and bench_bal.py unpaired.",
                file=sys.stderr,
            )
            for script in ("bench_orthomosaic.py", "bench_bal.py"):
                subprocess.run([sys.executable, str(HERE / script)], check=True)
            return
        try:
            for cmd in _pairs(vs, args.quick):
                print("  " + " ".join(Path(c).name if c.endswith(".py") else c for c in cmd[1:]),
                      flush=True)  # fmt: skip
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(vs)],
                capture_output=True,
            )


if __name__ == "__main__":
    main()
