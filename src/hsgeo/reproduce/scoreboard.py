"""The claims scoreboard: every numeric claim of the five papers, with its verdict.

One row per published number (GUIDE §4): the rows of the chapters' ``reproduce`` tables whose
name starts with the paper's number, ``000``–``004``, one per (published table, quantity). A
number that more than one chapter reproduces is judged by the chapter that owns it
(:data:`OWNERS`, with the reason); the other chapters show it as context (verdict ``context``,
:attr:`hsgeo.report.Row.judged_in`, set by :func:`mark_context` when a chapter runs), and the
scoreboard lists them beside the owner without counting them. The claims of chapters still to
be written are marked ``planned``. Verdicts are computed by
:meth:`hsgeo.report.Row.judge` from the numbers, in the style of ReScience C reproductions:
*reproduced*, *differs* (with the reason), *by construction* (the truth is the paper's value,
computed from it or tuned to it: agreement was built in), *not testable*, *planned*.
Every verdict is explained in a sentence (:data:`hsgeo.report.VERDICT_MEANING`), counted per
paper and per provenance of the truth, and a verdict a chapter stated against the rule (an
override) is listed with its reason (:func:`overrides`).

The chapters' results are taken from :func:`hsgeo.reproduce.recorded` when the book build
recorded them (``HSGEO_RECORD_DIR``), so that the scoreboard costs nothing extra; otherwise each
chapter is run here.
"""

from __future__ import annotations

import re
from dataclasses import replace

from hsgeo.report import (
    _MINUS,
    VERDICTS,
    Reproduction,
    Row,
    _format_paper,
    _unbroken,
    format_value,
)
from hsgeo.reproduce import CHAPTERS, paper_chapters
from hsgeo.vocabulary import display_unit, quantity_label

__all__ = [
    "claims_with_reasons",
    "claims",
    "planned_claims",
    "run",
    "counts",
    "counts_by",
    "overrides",
    "PAPERS",
    "PROVENANCE_GROUPS",
    "provenance_group",
    "claims_with_chapters",
    "paper_paragraph",
    "compact_table",
    "OWNERS",
    "PUBLISHED",
    "published_table",
    "owner",
    "mark_context",
    "NAMED",
    "NOT_CLAIMS",
    "context_chapters",
    "ClaimTable",
]

#: The papers as the scoreboard names them (../shared/papers/README.md).
PAPERS = {
    "000": "Miljković, Gajski and Vela (2017): spatial calibration of the ImSpector line scanner",
    "001": "Krtalić, Miljković, Gajski and Racetin (2019): distortion, sharpness and cube of the "
    "ImSpector system",
    "002": "Jonassen, Ressl, Pfeifer, Kjørsvik and Gjevestad (2024): bundle adjustment of aerial "
    "pushbroom lines",
    "003": "Tommaselli, Santos, Berveglieri, Oliveira and Honkavaara: inner orientation of the "
    "Rikola frame camera",
    "004": "the angular sensitivity of the DAEDALUS AADS 1268 whiskbroom scanner",
}

#: The provenance groups the scoreboard counts by: the provenances of
#: :data:`hsgeo.report.PROVENANCES` with ``tuned`` split by whether the tuning met its target
#: (a missed tuning is a finding), and ``none`` for rows without a simulation (the planned claims).
PROVENANCE_GROUPS = ("paper", "derived", "chosen", "tuned (met)", "tuned (missed)", "none")

#: How many claims a paragraph names per verdict before it says "and n more".
NAMED = 6

_PAPER_TABLE = re.compile(r"^00[0-4] ")
#: Tables named after a paper that hold experiments rather than claims: the factors table runs
#: counterfactual campaigns against 002 Table 2's values; counting its rows would count
#: 002 Table 2's claims again, once per factor.
NOT_CLAIMS = ("002 check-point factors",)


#: A chapter's table whose name says more than the published table it reproduces -> that table.
PUBLISHED = {
    "002 Table 1 from pixels": "002 Table 1",
    "002 Table 2 from pixels": "002 Table 2",
    "002 Table 3 from pixels": "002 Table 3",
}

#: The chapter that owns (judges) a published table that more than one chapter reproduces, and
#: why. 002 measured its Tables 1–3 from pixels: the tie points are key points matched in the LP
#: lines and registered at the pixel centre (002 §3.1), the check points tie points with known
#: coordinates (§4, §5.3). The lp-observations chapter measures them from rendered LP lines, as
#: the paper did; the pushbroom-ba chapter draws the tie points' image positions from the
#: projection of known points plus noise tuned to 002 Table 1, a model of the measurement, and
#: shows the three tables as context.
OWNERS = {
    "002 Table 1": (
        "lp-observations",
        "002 §3.1 measured its tie points from pixels, while the pushbroom-ba chapter "
        "simulates their image positions",
    ),
    "002 Table 2": (
        "lp-observations",
        "002 §4 and §5.3: its check points are tie points measured from pixels",
    ),
    "002 Table 3": (
        "lp-observations",
        "002 §4 and §5.3: its check points are tie points measured from pixels",
    ),
}


def published_table(table: str) -> str:
    """The published table a chapter's table reproduces (:data:`PUBLISHED`, else itself)."""
    return PUBLISHED.get(table, table)


def owner(table: str) -> str | None:
    """The chapter that owns the claims of ``table`` (a chapter's or the paper's name), or None
    when any chapter that reproduces it may judge it (a table only one chapter reproduces).
    """
    hit = OWNERS.get(published_table(table))
    return hit[0] if hit else None


def mark_context(chapter: str, rep: Reproduction) -> Reproduction:
    """Mark the rows of ``rep`` whose published number another chapter owns as context
    (:attr:`hsgeo.report.Row.judged_in`); :func:`hsgeo.reproduce.run` calls it for every chapter.
    Returns ``rep``.
    """
    rows = []
    for r in rep.rows:
        own = owner(r.table) if _PAPER_TABLE.match(r.table) else None
        if own is not None and own != chapter and r.paper is not None:
            r = replace(r, judged_in=own)
        rows.append(r)
    rep.rows[:] = rows
    return rep


def planned_claims() -> list[Row]:
    """The papers' claims of chapters not written yet (``verdict="planned"``).

    None are left: 001 Table 3 and Fig. 9 are the mtf chapter's, 004's numbers
    (:data:`hsgeo.papers.ASF_004`) the asf chapter's table ``"004 text"``.
    """
    return []


def claims_with_chapters(reps: dict[str, Reproduction]) -> list[tuple[str | None, Row]]:
    """``(chapter, row)`` for every published number of the chapters' results (tables named
    after a paper, with a paper value), once: the owner's row (:data:`OWNERS`) where more than one
    chapter reproduces it, else the first chapter's; then ``(None, row)`` for the planned claims.
    """
    found: dict[tuple[str, str], list[tuple[str, Row]]] = {}
    for chapter in paper_chapters():
        if chapter in reps:
            for r in reps[chapter].rows:
                if (
                    _PAPER_TABLE.match(r.table)
                    and r.table not in NOT_CLAIMS
                    and r.paper is not None
                ):
                    found.setdefault((published_table(r.table), r.quantity), []).append(
                        (chapter, r)
                    )
    out = []
    for key, pairs in found.items():
        own = owner(key[0])
        mine = [p for p in pairs if p[0] == own]
        if mine:
            out.append(mine[0])
        else:  # the owner did not reproduce this number: the first chapter's row judges it
            chapter, r = pairs[0]
            out.append((chapter, replace(r, judged_in=None)))
    return out + [(None, r) for r in planned_claims()]


def context_chapters(reps: dict[str, Reproduction], table: str, quantity: str) -> list[str]:
    """The chapters other than the owner that show the published number as context."""
    key = (published_table(table), quantity)
    own = [
        c for c, r in claims_with_chapters(reps) if (published_table(r.table), r.quantity) == key
    ]
    return [
        c
        for c in paper_chapters()
        if c in reps
        and c not in own
        and any((published_table(r.table), r.quantity) == key for r in reps[c].rows)
    ]


def claims(reps: dict[str, Reproduction]) -> list[Row]:
    """The claim rows of the chapters' results (tables named after a paper), then the planned."""
    return [r for _, r in claims_with_chapters(reps)]


def provenance_group(row: Row) -> str:
    """The row's group in :data:`PROVENANCE_GROUPS`: its provenance, ``tuned`` split into
    ``tuned (met)`` and ``tuned (missed)`` by its verdict, ``none`` without a provenance.
    """
    if row.provenance == "tuned":
        return "tuned (missed)" if row.judge()[0] == "differs" else "tuned (met)"
    return row.provenance or "none"


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
        g = r.table[:3] if key == "paper" else provenance_group(r)
        groups.setdefault(g, []).append(r)
    order = sorted(groups) if key == "paper" else PROVENANCE_GROUPS
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


def _claim_label(r: Row) -> str:
    """A claim in a reader's words: its quantity and the part of the paper it comes from."""
    return f"{quantity_label(r.quantity)} ({published_table(r.table)[4:]})"


def _named(rows: list[Row]) -> str:
    """The claims' labels as a list in prose ("a, b and c"; "a, b, … and 3 more")."""
    names = [_claim_label(r) for r in rows[:NAMED]]
    if len(rows) > NAMED:
        names.append(f"{len(rows) - NAMED} more")
    return _listed(names)


def _listed(parts: list[str]) -> str:
    return parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]


def _count_words(n: int, verdict: str) -> str:
    verb = {
        "reproduced": "reproduced",
        "differs": "differs" if n == 1 else "differ",
        "by construction": ("agrees" if n == 1 else "agree") + " by construction",
        "not testable": ("is" if n == 1 else "are") + " not testable",
        "planned": ("is" if n == 1 else "are") + " planned",
    }[verdict]
    return f"{n} {verb}"


def paper_paragraph(rows: list[Row], paper: str) -> str:
    """One paragraph on paper ``paper``'s claims, computed from the rows' verdicts: how many
    claims and how they were judged, which were reproduced, which differ and why, what agreement
    was built in (by provenance), and what could not be judged. The scoreboard page glues it.
    """
    mine = [r for r in rows if r.table.startswith(paper)]
    if not mine:
        return f"No claim of paper {paper} is in the book yet."
    by = {v: [r for r in mine if r.judge()[0] == v] for v in VERDICTS}
    head = _listed([_count_words(len(by[v]), v) for v in VERDICTS if by[v]])
    out = [f"Of its {len(mine)} claim{'s' if len(mine) > 1 else ''}, {head}."]
    if by["reproduced"]:
        out.append(f"Reproduced as independent outcomes: {_named(by['reproduced'])}.")
    if by["differs"]:
        reasons: dict[str, list[Row]] = {}  # claims that differ for the same reason, together
        for r in by["differs"]:
            reasons.setdefault(r.judge()[1], []).append(r)
        why = "; ".join(f"{_named(rs)}: {reason}" for reason, rs in reasons.items())
        out.append(f"{'Differs' if len(by['differs']) == 1 else 'Differ'}: {why}.")
    if by["by construction"]:
        prov = {}
        for r in by["by construction"]:
            key = r.provenance or ("paper" if r.truth_is_paper() else "none")
            prov[key] = prov.get(key, 0) + 1
        words = {
            "paper": "took the paper's value as truth",
            "derived": "computed their truth from the paper's values",
            "tuned": "were tuned to meet the paper",
            "chosen": "have a chosen truth equal to the paper's value",
            "none": "have no stated provenance",
        }
        parts = [f"{n} {words[k]}" for k, n in prov.items()]
        n = len(by["by construction"])
        out.append(
            f"Agreement was built in for {n} claim{'s' if n > 1 else ''} "
            f"({_listed(parts)}): for {'them' if n > 1 else 'it'} only the recovery of the "
            "truth is an outcome."
        )
    if by["not testable"]:
        out.append(f"Not testable: {_named(by['not testable'])}.")
    if by["planned"]:
        reasons = sorted({r.judge()[1] for r in by["planned"]})
        out.append(f"Planned: {'; '.join(reasons)}.")
    return " ".join(out)


def _pm(value, sigma) -> str:
    text = format_value(value, sigma)
    if text != "—" and sigma is not None and format_value(sigma, sigma, sig=2) != "—":
        text += f" ± {format_value(sigma, sigma, sig=2)}"
    return text


def _signed(z: float) -> str:
    """A z-score with one decimal and its sign (0.0 without one)."""
    return "0.0" if abs(z) < 0.05 else f"{z:+.1f}".replace("-", _MINUS)


class ClaimTable:
    """The scoreboard's compact table of claims: :attr:`data` (a DataFrame of display strings)
    and an HTML form that a phone can read: on a narrow screen every claim becomes a card whose
    cells carry their column's name (``data-label``, book/_static/hsgeo.css), on a wide one a
    table with one or two short lines per claim. The claim links to the chapter computing it.
    """

    COLUMNS = ("claim", "paper", "reproduced ± σ", "z", "verdict")

    def __init__(self, data, chapters: list[str | None], provenance: list[str]):
        self.data = data
        self.chapters = chapters
        self.provenance = provenance

    def _repr_html_(self) -> str:
        from html import escape

        # a column whose every cell is "—" is left out (no z where no claim has one)
        numbers = [
            c
            for c in ("paper", "reproduced ± σ", "z")
            if not len(self.data) or not (self.data[c] == "—").all()
        ]
        head = "".join(
            f'<th class="{"hsgeo-num" if c in numbers else "hsgeo-text"}">{escape(c)}</th>'
            for c in self.COLUMNS
            if c in numbers or c in ("claim", "verdict")
        )
        body = []
        rows = zip(self.data.iterrows(), self.chapters, self.provenance, strict=True)
        for (_, rec), chapter, prov in rows:
            doc = CHAPTERS[chapter].page if chapter in CHAPTERS else None
            claim = escape(rec["claim"])
            if doc:
                claim = f'<a href="{doc}.html" title="computed in {chapter}">{claim}</a>'
            if rec["unit"] not in ("—", ""):
                claim += f'<br><span class="hsgeo-unit">in {escape(rec["unit"])}</span>'
            cells = [f'<td class="hsgeo-text hsgeo-claim" data-label="claim">{claim}</td>']
            for c in numbers:
                cells.append(f'<td class="hsgeo-num" data-label="{c}">{_unbroken(rec[c])}</td>')
            cells.append(
                f'<td class="hsgeo-text" data-label="verdict">'
                f'<span class="hsgeo-verdict">{escape(rec["verdict"])}</span>'
                f'<br><span class="hsgeo-provenance">{escape(prov)}</span></td>'
            )
            body.append("<tr>" + "".join(cells) + "</tr>")
        return (
            '<table class="hsgeo-table hsgeo-claims">'
            f"<thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"
        )


def _owner_words(r: Row, chapter: str | None) -> str:
    """Why ``chapter`` judges the row: the ownership rule of :data:`OWNERS`, or the only one."""
    hit = OWNERS.get(published_table(r.table))
    if hit is None:
        return "the only chapter reproducing it"
    return f"owner: {hit[1]}"


def compact_table(pairs: list[tuple[str | None, Row]], paper: str | None = None) -> ClaimTable:
    """The claims as the scoreboard page shows them (:class:`ClaimTable`): claim (a link to its
    chapter, its unit under it) | paper | reproduced ± σ | z against the paper | verdict, with the
    provenance of the truth under the verdict; one claim per row. ``pairs`` is the output of
    :func:`claims_with_chapters`; ``paper`` keeps one paper's claims. ``data`` also holds the
    ``provenance`` and ``chapter`` columns.
    """
    import pandas as pd

    recs, chapters, provs = [], [], []
    for chapter, r in pairs:
        if paper is not None and not r.table.startswith(paper):
            continue
        shown = _format_paper(r.paper)
        if r.paper_sigma is not None and _format_paper(r.paper_sigma) != "—":
            shown += f" ± {_format_paper(r.paper_sigma)}"
        zp = None if r.judge()[0] == "not testable" else r.z_paper  # no z on "not testable"
        recs.append(
            {
                "claim": _claim_label(r),
                "unit": display_unit(r.quantity, r.unit),
                "paper": shown,
                "reproduced ± σ": _pm(r.reproduced, r.sigma),
                "z": "—" if zp is None else _signed(zp),
                "verdict": r.judge()[0],
                "provenance": provenance_group(r),
                "chapter": chapter or "—",
                "owner": _owner_words(r, chapter),
            }
        )
        chapters.append(chapter)
        provs.append(provenance_group(r))
    cols = ["claim", "unit", "paper", "reproduced ± σ", "z", "verdict", "provenance", "chapter"]
    cols.append("owner")
    return ClaimTable(pd.DataFrame(recs, columns=cols), chapters, provs)


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """The scoreboard as a :class:`Reproduction` whose tables are the papers' tables.

    Each chapter's result comes from the book build's record when there is one (any seed and
    scale: ``meta["sources"]`` says which), else from running the chapter at ``seed``/``scale``.
    """
    from hsgeo.reproduce import recorded
    from hsgeo.reproduce import run as run_chapter

    reps, sources = {}, {}
    for chapter in paper_chapters():
        rep = recorded(chapter)
        how = "recorded by the book build"
        if rep is None:
            rep, how = run_chapter(chapter, seed=seed, scale=scale), "run for the scoreboard"
        reps[chapter] = rep
        sources[chapter] = {"seed": rep.seed, "scale": rep.meta.get("scale"), "source": how}
    pairs = claims_with_chapters(reps)
    rows = [r for _, r in pairs]
    contexts = [
        context_chapters(reps, r.table, r.quantity) if c is not None else [] for c, r in pairs
    ]
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
            "chapters": [c for c, _ in pairs],
            "context": contexts,
            "owners": {t: {"chapter": c, "why": why} for t, (c, why) in OWNERS.items()},
            "n_context_rows": sum(len(c) for c in contexts),
            "paragraphs": {p: paper_paragraph(rows, p) for p in PAPERS},
        },
    )


def claims_with_reasons(board: Reproduction, paper: str):
    """Every claim of one paper (tables named ``"000 …"`` for ``paper="000"``) with its verdict,
    the sentence that explains it and the chapter that judges it (with the chapters that show it
    as context): a DataFrame with columns claim, verdict, why, judged in.
    """
    import pandas as pd

    chapters = board.meta.get("chapters") or [None] * len(board.rows)
    context = board.meta.get("context") or [[]] * len(board.rows)
    recs = []
    for r, c, ctx in zip(board.rows, chapters, context, strict=True):
        if not r.table.startswith(paper):
            continue
        where = c or "—"
        if ctx:
            where += f" (context in {', '.join(ctx)})"
        recs.append((_claim_label(r), *r.judge(), where))
    return pd.DataFrame(recs, columns=["claim", "verdict", "why", "judged in"])
