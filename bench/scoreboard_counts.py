"""The scoreboard's counts from saved ``hsgeo reproduce CHAPTER --json`` outputs (issue 37).

    python bench/scoreboard_counts.py DIR [--rejudge] [--old]

``DIR`` holds ``<chapter>.json`` of every chapter. ``--old`` counts as the scoreboard did before
issue 37: every claim row of every chapter (a number two chapters reproduce counted twice), each
with the verdict stored in its file. Without it, one row per published number
(:func:`hsgeo.reproduce.scoreboard.claims_with_chapters`, the owner's row), rows another chapter
owns marked as context; ``--rejudge`` recomputes the verdicts the files stored from their numbers
with the current rules (a chapter's override is kept), for files written by older code. Prints
the counts by verdict, by paper and by provenance as JSON.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from hsgeo.report import Reproduction
from hsgeo.reproduce import paper_chapters
from hsgeo.reproduce.scoreboard import (
    _PAPER_TABLE,
    NOT_CLAIMS,
    claims_with_chapters,
    counts,
    counts_by,
    mark_context,
)


def load(directory: Path, rejudge: bool) -> dict[str, Reproduction]:
    reps = {}
    for chapter in paper_chapters():
        path = directory / f"{chapter}.json"
        if not path.is_file() or path.stat().st_size == 0:  # absent, or still being written
            continue
        d = json.loads(path.read_text(encoding="utf-8"))
        rep = Reproduction.from_json(path.read_text(encoding="utf-8"))
        if rejudge:
            for i, (row, raw) in enumerate(zip(rep.rows, d["rows"], strict=True)):
                if not raw.get("override") and row.verdict != "planned":
                    # a reason the chapter set for its differs/not testable stays with the row
                    keep = raw.get("verdict") in ("differs", "not testable") and not raw.get(
                        "reason", ""
                    ).startswith(("tuning missed", "recovery failed"))
                    reason = (raw.get("reason") or "") if keep else ""
                    rep.rows[i] = dataclasses.replace(row, verdict=None, reason=reason)
        reps[chapter] = mark_context(chapter, rep)
    return reps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("directory", type=Path)
    ap.add_argument("--rejudge", action="store_true")
    ap.add_argument("--old", action="store_true")
    args = ap.parse_args()
    reps = load(args.directory, args.rejudge and not args.old)
    if args.old:
        rows = []
        for c in paper_chapters():
            for r in reps.get(c, Reproduction(c, 0, [])).rows:
                if (
                    _PAPER_TABLE.match(r.table)
                    and r.table not in NOT_CLAIMS
                    and r.paper is not None
                ):
                    rows.append(dataclasses.replace(r, judged_in=None))
    else:
        rows = [r for _, r in claims_with_chapters(reps)]
    out = {
        "chapters": sorted(reps),
        "n_claims": len(rows),
        "counts": counts(rows),
        "by_paper": counts_by(rows, "paper"),
        "by_provenance": counts_by(rows, "provenance"),
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
