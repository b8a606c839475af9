"""The scoreboard's counts from saved ``hsgeo reproduce CHAPTER --json`` outputs (issue 37).

    python bench/scoreboard_counts.py DIR [DIR ...] [--rejudge] [--old] [--out FILE]

``DIR`` holds ``<chapter>.json`` of every chapter. ``--old`` counts as the scoreboard did before
issue 37: every claim row of every chapter (a number two chapters reproduce counted twice), each
with the verdict stored in its file. Without it, one row per published number
(:func:`hsgeo.reproduce.scoreboard.claims_with_chapters`, the owner's row), rows another chapter
owns marked as context; ``--rejudge`` recomputes the verdicts the files stored from their numbers
with the current rules (a chapter's override is kept), for files written by older code. Prints
the counts by verdict, by paper and by provenance as JSON. With ``--out`` (issue 37's evidence),
for every ``DIR`` both the counts before issue 37 (``--old``) and now, the number of published
numbers (distinct published table and quantity), the "reproduced" rows with their runs and σ,
and the checks of issue 37's bar: no published number twice, no "reproduced" on fewer than 8
runs or with σ over half the paper's value; written to ``FILE`` as JSON.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

from hsgeo.report import MIN_RUNS, SIGMA_OVER_PAPER, Reproduction
from hsgeo.reproduce import paper_chapters
from hsgeo.reproduce.scoreboard import (
    _PAPER_TABLE,
    NOT_CLAIMS,
    claims_with_chapters,
    counts,
    counts_by,
    mark_context,
    published_table,
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


def _claim_rows(reps: dict[str, Reproduction], old: bool) -> list:
    if not old:
        return [r for _, r in claims_with_chapters(reps)]
    rows = []
    for c in paper_chapters():
        for r in reps.get(c, Reproduction(c, 0, [])).rows:
            if _PAPER_TABLE.match(r.table) and r.table not in NOT_CLAIMS and r.paper is not None:
                rows.append(dataclasses.replace(r, judged_in=None))
    return rows


def summary(rows: list, reps: dict[str, Reproduction]) -> dict:
    return {
        "chapters": sorted(reps),
        "n_claims": len(rows),
        "counts": counts(rows),
        "by_paper": counts_by(rows, "paper"),
        "by_provenance": counts_by(rows, "provenance"),
    }


def stored_counts(directory: Path) -> dict:
    """The scoreboard as the files' stored verdicts give it, counted as before issue 37: every
    chapter's claim rows (a number two chapters reproduce counted twice, "context" rows as the
    verdict their chapter's numbers alone would give), by verdict, paper and provenance.
    """
    rows = []
    for chapter in paper_chapters():
        path = directory / f"{chapter}.json"
        if not path.is_file() or path.stat().st_size == 0:
            continue
        for r in json.loads(path.read_text(encoding="utf-8"))["rows"]:
            if (
                _PAPER_TABLE.match(r["table"])
                and r["table"] not in NOT_CLAIMS
                and r["paper"] is not None
            ):
                v = r["verdict"]
                if v == "context":  # "judged in the X chapter; here: V, ..."
                    v = r["reason"].split("here: ", 1)[1].split(",", 1)[0]
                v = {"tuned": "by construction"}.get(v, v)
                prov = r.get("provenance") or "none"
                if prov == "tuned":
                    prov = "tuned (missed)" if v == "differs" else "tuned (met)"
                rows.append((v, r["table"][:3], prov))

    def by(i):
        out: dict[str, dict[str, int]] = {}
        for row in rows:
            g = out.setdefault(row[i], {})
            g[row[0]] = g.get(row[0], 0) + 1
        return dict(sorted(out.items()))

    verdicts = [r[0] for r in rows]
    return {
        "n_claims": len(rows),
        "counts": {v: verdicts.count(v) for v in sorted(set(verdicts))},
        "by_paper": by(1),
        "by_provenance": by(2),
    }


def audit(directory: Path) -> dict:
    """Issue 37's scoreboard bar on the outputs in ``directory``: before and after, and checks."""
    before = load(directory, False)
    rows_old = _claim_rows(before, old=True)
    reps = load(directory, False)
    pairs = claims_with_chapters(reps)
    rows = [r for _, r in pairs]
    keys = [(published_table(r.table), r.quantity) for r in rows]
    reproduced = [
        {
            "chapter": c,
            "table": r.table,
            "quantity": r.quantity,
            "paper": r.paper,
            "reproduced": r.reproduced,
            "sigma": r.sigma,
            "n_runs": r.n_runs,
            "sigma_over_paper": (r.sigma / abs(r.paper)) if r.sigma and r.paper else None,
            "reason": r.judge()[1],
        }
        for c, r in pairs
        if r.judge()[0] == "reproduced"
    ]
    few = [d for d in reproduced if d["n_runs"] is not None and d["n_runs"] < MIN_RUNS]
    wide = [
        d
        for d in reproduced
        if d["sigma_over_paper"] is not None and d["sigma_over_paper"] > SIGMA_OVER_PAPER
    ]
    n_context = sum(
        1 for c in reps for r in reps[c].rows if r.paper is not None and r.judge()[0] == "context"
    )
    return {
        "directory": str(directory),
        "chapters_missing": [c for c in paper_chapters() if c not in reps],
        "stored_verdicts_counted_as_before_issue37": stored_counts(directory),
        "current_rules_counted_as_before_issue37": summary(rows_old, before),
        "now": summary(rows, reps),
        "n_published_numbers": len(set(keys)),
        "n_published_numbers_twice": len(keys) - len(set(keys)),
        "n_context_rows_not_counted": n_context,
        "reproduced": reproduced,
        "reproduced_on_fewer_than_8_runs": len(few),
        "reproduced_with_sigma_over_half_paper": len(wide),
        "bar_met": not few and not wide and len(keys) == len(set(keys)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("directory", type=Path, nargs="+")
    ap.add_argument("--rejudge", action="store_true")
    ap.add_argument("--old", action="store_true")
    ap.add_argument("--out", type=Path, help="write the audit of every DIR to this JSON file")
    args = ap.parse_args()
    if args.out is not None:
        out = {
            "what": "issue 37's scoreboard bar: one row per published number, no 'reproduced' on "
            "fewer than 8 runs or with σ > half the paper's value; counts before issue 37 "
            "(every chapter's claim rows, a number two chapters reproduce counted twice) and now",
            "command": "python bench/scoreboard_counts.py "
            + " ".join(str(d) for d in args.directory)
            + " --out "
            + str(args.out),
            "audits": [audit(d) for d in args.directory],
            "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        args.out.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
        return
    reps = load(args.directory[0], args.rejudge and not args.old)
    rows = _claim_rows(reps, args.old)
    print(json.dumps(summary(rows, reps), indent=1))


if __name__ == "__main__":
    main()
