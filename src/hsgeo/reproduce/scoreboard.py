"""The claims scoreboard: every numeric claim of the five papers, with its verdict (issue 13).

One row per claim in the papers' tables that a chapter reproduces (the rows of the chapters'
``reproduce`` tables whose name starts with the paper's number, ``000``–``004``), plus the claims
of the chapters still to be written, marked ``planned``. Verdicts are computed by
:meth:`hsgeo.report.Row.judge` from the numbers, in the style of ReScience C reproductions:
*reproduced*, *differs* (with the reason), *by construction* (the truth is the paper's value,
computed from it or tuned to it: agreement was built in; issue 22), *not testable*, *planned*.
Every verdict is explained in a sentence (:data:`hsgeo.report.VERDICT_MEANING`), counted per
paper and per provenance of the truth, and a verdict a chapter stated against the rule (an
override) is listed with its reason (:func:`overrides`).

The chapters' results are taken from :func:`hsgeo.reproduce.recorded` when the book build
recorded them (``HSGEO_RECORD_DIR``), so that the scoreboard costs nothing extra; otherwise each
chapter is run here.
"""

from __future__ import annotations

import re

from hsgeo.report import PROVENANCES, VERDICTS, Reproduction, Row

__all__ = [
    "PAPER_CHAPTERS",
    "claims",
    "planned_claims",
    "run",
    "counts",
    "counts_by",
    "overrides",
]

#: The chapters whose tables hold claims of the papers.
PAPER_CHAPTERS = ("line-calibration", "geocoding", "pushbroom-ba", "rikola", "mtf", "cube", "asf")

_PAPER_TABLE = re.compile(r"^00[0-4] ")
#: Tables named after a paper that hold experiments rather than claims: the factors table runs
#: counterfactual campaigns against 002 Table 2's values (issue 15); counting its rows would count
#: 002 Table 2's claims again, once per factor.
NOT_CLAIMS = ("002 check-point factors",)


def planned_claims() -> list[Row]:
    """The papers' claims of chapters not written yet (``verdict="planned"``).

    None are left: 001 Table 3 and Fig. 9 are the mtf chapter's, 004's numbers
    (:data:`hsgeo.papers.ASF_004`) the asf chapter's table ``"004 text"``.
    """
    return []


def claims(reps: dict[str, Reproduction]) -> list[Row]:
    """The claim rows of the chapters' results (tables named after a paper), then the planned."""
    out = []
    for chapter in PAPER_CHAPTERS:
        if chapter in reps:
            out += [
                r
                for r in reps[chapter].rows
                if _PAPER_TABLE.match(r.table) and r.table not in NOT_CLAIMS and r.paper is not None
            ]
    return out + planned_claims()


def counts(rows: list[Row]) -> dict[str, int]:
    """Number of claims per verdict, in the order of :data:`hsgeo.report.VERDICTS`."""
    verdicts = [r.judge()[0] for r in rows]
    return {v: verdicts.count(v) for v in VERDICTS}


def counts_by(rows: list[Row], key: str) -> dict[str, dict[str, int]]:
    """Number of claims per verdict within each group: ``key`` is ``"paper"`` (the first three
    characters of the table, ``"000"``…) or ``"provenance"`` (``"none"`` for rows without one,
    e.g. the planned claims).
    """
    groups: dict[str, list[Row]] = {}
    for r in rows:
        g = r.table[:3] if key == "paper" else (r.provenance or "none")
        groups.setdefault(g, []).append(r)
    order = sorted(groups) if key == "paper" else [*PROVENANCES, "none"]
    return {g: counts(groups[g]) for g in order if g in groups}


def overrides(rows: list[Row]) -> list[dict]:
    """The claims whose verdict the chapter stated against :meth:`~hsgeo.report.Row.rule`:
    table, quantity, the stated and the computed verdict, and the chapter's reason.
    """
    return [
        {
            "table": r.table,
            "quantity": r.quantity,
            "verdict": r.verdict,
            "rule": r.rule()[0],
            "reason": r.reason,
        }
        for r in rows
        if r.overridden
    ]


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """The scoreboard as a :class:`Reproduction` whose tables are the papers' tables.

    Each chapter's result comes from the book build's record when there is one (any seed and
    scale: ``meta["sources"]`` says which), else from running the chapter at ``seed``/``scale``.
    """
    from hsgeo.reproduce import recorded
    from hsgeo.reproduce import run as run_chapter

    reps, sources = {}, {}
    for chapter in PAPER_CHAPTERS:
        rep = recorded(chapter)
        how = "recorded by the book build"
        if rep is None:
            rep, how = run_chapter(chapter, seed=seed, scale=scale), "run for the scoreboard"
        reps[chapter] = rep
        sources[chapter] = {"seed": rep.seed, "scale": rep.meta.get("scale"), "source": how}
    rows = claims(reps)
    return Reproduction(
        "scoreboard",
        seed,
        rows,
        meta={
            "sources": sources,
            "counts": counts(rows),
            "counts_by_paper": counts_by(rows, "paper"),
            "counts_by_provenance": counts_by(rows, "provenance"),
            "overrides": overrides(rows),
            "n_claims": len(rows),
        },
    )
