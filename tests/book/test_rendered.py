"""The built book as a reader meets it: every page opened offline in headless Chromium.

Run by ``make check-book`` after ``make book`` (``make test`` does not collect it, see
``conftest.py``). Every page of ``book/_toc.yml`` is opened from ``book/_build/html`` (or
``$HSGEO_BOOK_HTML``) as a ``file://`` URL with the network blocked, once 400 px and once
1400 px wide, and each check is its own test so that a failure names the page and the check.
Chapter pages (``chapters/*``) must also offer an ``.ipynb`` download and an exercise with a
solution.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
import yaml
from pagecheck import (
    NARROW_PX,
    PRINT_PX,
    WIDE_PX,
    page_facts,
    problems_alt_text,
    problems_captions,
    problems_cell_padding,
    problems_clipped,
    problems_differs_cause,
    problems_display_equations,
    problems_equations,
    problems_exercises,
    problems_glue_slips,
    problems_ipynb,
    problems_leaks,
    problems_long_tables,
    problems_md_source,
    problems_nan,
    problems_numbering,
    problems_offline,
    problems_page_width,
    problems_panels,
    problems_reprs,
    problems_result_tables,
    problems_statements,
    problems_version_footer,
    problems_wide_tables,
)

pytestmark = pytest.mark.book

BOOK = Path(__file__).resolve().parents[2] / "book"
HTML = Path(os.environ.get("HSGEO_BOOK_HTML", BOOK / "_build" / "html"))


def _toc_docs() -> list[str]:
    toc = yaml.safe_load((BOOK / "_toc.yml").read_text(encoding="utf-8"))
    docs = [toc["root"]]

    def walk(node) -> None:
        if isinstance(node, dict):
            if "file" in node:
                docs.append(str(node["file"]).removesuffix(".md"))
            for key in ("parts", "chapters", "sections"):
                for child in node.get(key, []) or []:
                    walk(child)

    walk(toc)
    return docs


DOCS = _toc_docs()
CHAPTERS = [doc for doc in DOCS if doc.startswith("chapters/")]
#: Chapters that must typeset their equations (issue 40: the LP chapter teaches four).
EQUATION_CHAPTERS = ["chapters/lp_observations"]
#: Pages with one statement per paper (the scoreboard and the landing page).
STATEMENT_PAGES = ["scoreboard", "intro"]
N_PAPERS = 5
_FACTS: dict[tuple[str, int], dict] = {}


@pytest.fixture
def facts(browser, request):
    """The measured facts of one page at one width (each page is opened once per width)."""
    doc, width_px, media = request.param
    key = (doc, width_px, media)
    if key not in _FACTS:
        path = HTML / f"{doc}.html"
        if not path.is_file():
            pytest.fail(f"{path} is missing: build the book first (`make book`)")
        _FACTS[key] = page_facts(browser, path, width_px, media)
    return _FACTS[key]


def _params(docs: list[str], width_px: int, media: str = "screen"):
    return pytest.mark.parametrize(
        "facts", [(doc, width_px, media) for doc in docs], ids=docs, indirect=True
    )


def _check(problems: list[str], facts: dict) -> None:
    assert not problems, f"{facts['path']}:\n  " + "\n  ".join(problems)


@_params(DOCS, WIDE_PX)
def test_equations_typeset(facts):
    _check(problems_equations(facts), facts)


@_params(DOCS, WIDE_PX)
def test_offline(facts):
    _check(problems_offline(facts), facts)


@_params(DOCS, WIDE_PX)
def test_figures_captioned(facts):
    _check(problems_captions(facts), facts)


@_params(DOCS, WIDE_PX)
def test_images_have_alt_text(facts):
    _check(problems_alt_text(facts), facts)


@_params(DOCS, WIDE_PX)
def test_no_nan_in_tables(facts):
    _check(problems_nan(facts), facts)


@_params(DOCS, WIDE_PX)
def test_nothing_clipped_at_1400px(facts):
    _check(problems_clipped(facts), facts)


@_params(DOCS, WIDE_PX)
def test_tables_fit_their_column_at_1400px(facts):
    """No table wider than the text column (784 px), the verdict of a result table in view."""
    _check(problems_wide_tables(facts) + problems_result_tables(facts), facts)


@_params(DOCS, PRINT_PX, "print")
def test_tables_fit_the_printed_page(facts):
    """Printed on A4, no table wider than the page's text (a sideways scroll is not printed)."""
    _check(problems_wide_tables(facts) + problems_result_tables(facts), facts)


@_params(DOCS, NARROW_PX)
def test_no_sideways_scroll_at_400px(facts):
    _check(problems_page_width(facts), facts)


@_params(DOCS, NARROW_PX)
def test_result_tables_show_every_column_at_400px(facts):
    """σ̂, truth, z and the verdict of every result table in view on a phone (cards)."""
    _check(problems_result_tables(facts), facts)


@_params(DOCS, NARROW_PX)
def test_nothing_clipped_at_400px(facts):
    _check(problems_clipped(facts), facts)


@_params(DOCS, WIDE_PX)
def test_no_internals_leak(facts):
    """No numpy repr, /tmp/ path, issue number, Python warning or traceback on the page."""
    _check(problems_leaks(facts), facts)


@_params(DOCS, WIDE_PX)
def test_no_glue_slips(facts):
    """No repeated word ("Exercise Exercise") and no range with equal ends ("1.3–1.3")."""
    _check(problems_glue_slips(facts), facts)


@_params(DOCS, WIDE_PX)
def test_table_cells_are_padded(facts):
    _check(problems_cell_padding(facts), facts)


@_params(DOCS, WIDE_PX)
def test_version_in_the_footer(facts):
    _check(problems_version_footer(facts), facts)


@_params(CHAPTERS, WIDE_PX)
def test_chapter_ipynb_download(facts):
    _check(problems_ipynb(facts), facts)


@_params(CHAPTERS, WIDE_PX)
def test_chapter_md_download(facts):
    _check(problems_md_source(facts), facts)


@_params(CHAPTERS, WIDE_PX)
def test_chapter_exercise_with_solution(facts):
    _check(problems_exercises(facts), facts)


@_params(CHAPTERS, WIDE_PX)
def test_chapter_numbered_within(facts):
    """Figures, tables and exercises numbered within their chapter (Exercise 4.2)."""
    _check(problems_numbering(facts), facts)


def test_every_chapter_is_in_the_toc():
    """The chapter checks cover every chapter file (a new chapter cannot escape them)."""
    on_disk = sorted(f"chapters/{p.stem}" for p in (BOOK / "chapters").glob("*.md"))
    assert sorted(CHAPTERS) == on_disk


#: Pages whose tables are not yet on the table rule (tables of over 20 rows in view, columns
#: that are all "—"): none since hsgeo.report drops all-"—" columns and puts a table of more
#: than 20 rows under a toggle; kept (empty) so that a page can be named while it is mended.
TABLE_RULE_PENDING: list[str] = []


def test_the_pages_pending_a_rule_exist():
    assert set(TABLE_RULE_PENDING) | set(DIFFERS_CAUSE_PENDING) <= set(DOCS)


@_params([d for d in DOCS if d not in TABLE_RULE_PENDING], WIDE_PX)
def test_tables_short_and_without_empty_columns(facts):
    """No table in view over 20 rows (a long one goes under a toggle), no all-"—" column."""
    _check(problems_long_tables(facts), facts)


@_params(DOCS, WIDE_PX)
def test_no_python_reprs(facts):
    """No ``array(``, ``np.float64(``, ``<hsgeo.`` or ``{'`` in the prose or the outputs."""
    _check(problems_reprs(facts), facts)


#: Pages that may still show a "differs" whose reason is only its distance: none since the
#: pushbroom chapter's check-point factor runs name their cause (what the factor does not
#: produce of 002 Table 2, and which run does); kept (empty) for a page being mended.
DIFFERS_CAUSE_PENDING: list[str] = []


@_params([d for d in DOCS if d not in DIFFERS_CAUSE_PENDING], WIDE_PX)
def test_every_differs_has_a_cause(facts):
    _check(problems_differs_cause(facts), facts)


@_params(DOCS, NARROW_PX)
def test_figures_legible_on_a_phone(facts):
    """No figure of more than two panel columns, none with panels under 150 px at 400 px."""
    _check(problems_panels(facts), facts)


@_params(EQUATION_CHAPTERS, WIDE_PX)
def test_chapter_typesets_its_equations(facts):
    """At least two display equations typeset by MathJax."""
    _check(problems_display_equations(facts, minimum=2), facts)


@_params(STATEMENT_PAGES, WIDE_PX)
def test_per_paper_statements(facts):
    """One statement per paper, each of at most 80 words."""
    _check(problems_statements(facts, minimum=N_PAPERS), facts)


def test_search_shows_snippets_offline(browser):
    """The search page, read from disk with the network blocked, lists results for a word of
    the chapters with a snippet of text under each (book/_ext/hsgeo_search.py)."""
    context = browser.new_context(viewport={"width": WIDE_PX, "height": 900}, offline=True)
    try:
        page = context.new_page()
        page.goto((HTML / "search.html").as_uri() + "?q=boresight")
        page.wait_for_selector("#search-results li", timeout=30_000)
        page.wait_for_timeout(1500)  # the snippets come after the titles
        n_results = page.locator("#search-results li").count()
        n_snippets = page.locator("#search-results li p.context").count()
    finally:
        context.close()
    assert n_results >= 3, f"{n_results} search results for 'boresight'"
    assert n_snippets == n_results, f"{n_snippets} of {n_results} results with a snippet"
