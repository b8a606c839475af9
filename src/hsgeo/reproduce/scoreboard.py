"""The claims scoreboard: every numeric claim of the five papers, with its verdict (issue 13).

One row per claim in the papers' tables that a chapter reproduces (the rows of the chapters'
``reproduce`` tables whose name starts with the paper's number, ``000``–``004``), plus the claims
of the chapters still to be written, marked ``planned``. Verdicts are computed by
:meth:`hsgeo.report.Row.judge` from the numbers, in the style of ReScience C reproductions:
*reproduced*, *differs* (with the reason), *tuned* (the simulation took the paper's value as its
truth, so only the recovery is an outcome), *not testable*, *planned*.

The chapters' results are taken from :func:`hsgeo.reproduce.recorded` when the book build
recorded them (``HSGEO_RECORD_DIR``), so that the scoreboard costs nothing extra; otherwise each
chapter is run here.
"""

from __future__ import annotations

import re

from hsgeo import papers
from hsgeo.report import VERDICTS, Reproduction, Row

__all__ = ["PAPER_CHAPTERS", "claims", "planned_claims", "run", "counts"]

#: The chapters whose tables hold claims of the papers.
PAPER_CHAPTERS = ("line-calibration", "geocoding", "pushbroom-ba", "rikola", "cube")

_PAPER_TABLE = re.compile(r"^00[0-4] ")
#: Tables named after a paper that hold experiments rather than claims: the factors table runs
#: counterfactual campaigns against 002 Table 2's values (issue 15); counting its rows would count
#: 002 Table 2's claims again, once per factor.
NOT_CLAIMS = ("002 check-point factors",)


def planned_claims() -> list[Row]:
    """The papers' claims of chapters not written yet (``verdict="planned"``)."""
    rows = []
    for pixel, gsd_mm in papers.GSD_001_TABLE3_MM["actual"].items():
        rows.append(
            Row(
                "001 Table 3",
                f"GSDv at line {pixel} px",
                "mm",
                paper=gsd_mm,
                verdict="planned",
                reason="MTF chapter (bar targets) not written yet",
            )
        )
    rows.append(
        Row(
            "001 Table 3",
            "theoretical GSDv, binning 1",
            "mm",
            paper=papers.GSD_001_TABLE3_MM["theoretical"],
            verdict="planned",
            reason="MTF chapter (bar targets) not written yet",
        )
    )
    for quantity, (value, unit) in papers.ASF_004.items():
        rows.append(
            Row(
                "004 text",
                quantity,
                unit,
                paper=value,
                verdict="planned",
                reason="ASF chapter (crossing flight lines) not written yet",
            )
        )
    return rows


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
        meta={"sources": sources, "counts": counts(rows), "n_claims": len(rows)},
    )
