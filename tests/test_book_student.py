"""The student edition's downloads keep the exercises and lose every solution (issue 40).

``book/_ext/hsgeo_book.strip_solutions`` writes the ``.md`` and ``.ipynb`` downloads of
``make book-student``; here it runs over every page of the book's sources (no build needed), and
over small hand-written pages whose fences it must respect.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext")

BOOK = Path(__file__).resolve().parents[1] / "book"
_spec = importlib.util.spec_from_file_location("hsgeo_book", BOOK / "_ext" / "hsgeo_book.py")
pytest.importorskip("sphinx")
hsgeo_book = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(hsgeo_book)
strip_solutions = hsgeo_book.strip_solutions

PAGES = sorted(p for p in BOOK.rglob("*.md") if "_build" not in p.parts)
WITH_SOLUTIONS = [p for p in PAGES if "{solution" in p.read_text(encoding="utf-8")]


def test_the_book_has_solutions_to_strip():
    assert len(WITH_SOLUTIONS) >= 9, [p.name for p in WITH_SOLUTIONS]


@pytest.mark.parametrize("page", WITH_SOLUTIONS, ids=lambda p: p.stem)
def test_page_keeps_exercises_loses_solutions(page):
    text = page.read_text(encoding="utf-8")
    out = strip_solutions(text)
    assert "{solution" not in out
    labels = re.findall(r"^:label: (\S+)", text, flags=re.M)
    exercise_labels = [lab for lab in labels if lab.startswith("ex-")]
    for lab in exercise_labels:
        assert f":label: {lab}" in out, lab
    assert out.count("{exercise}") == text.count("{exercise}")
    # every line kept is the source's, in order: only solution blocks went
    src = iter(text.splitlines())
    assert all(any(line == s for s in src) for line in out.splitlines())
    # and the page is still a notebook jupytext reads, with fewer code cells when a gated
    # solution held code
    nb_in = jupytext.reads(text, fmt="md:myst")
    nb_out = jupytext.reads(out, fmt="md:myst")
    n_code = sum(c.cell_type == "code" for c in nb_in.cells)
    n_code_out = sum(c.cell_type == "code" for c in nb_out.cells)
    gated = re.findall(r"\{solution-start\}.*?\{solution-end\}", text, flags=re.S)
    assert n_code_out == n_code - sum(g.count("{code-cell}") for g in gated)
    assert all("{solution" not in "".join(c.source) for c in nb_out.cells)


def test_fences_are_respected():
    page = (
        "text before\n\n"
        "````{exercise} One\n:label: ex-a\n\nDo it.\n````\n\n"
        "````{solution} ex-a\n:class: dropdown\n\n```python\nx = 1\n```\n\nThe answer.\n````\n\n"
        ":::{solution-start} ex-a\n:::\n\n```{code-cell} ipython3\nprint(2)\n```\n\nWhy.\n\n"
        ":::{solution-end}\n:::\n\ntext after\n"
    )
    out = strip_solutions(page)
    assert out == "text before\n\n````{exercise} One\n:label: ex-a\n\nDo it.\n````\n\ntext after\n"


def test_unclosed_solution_is_an_error():
    with pytest.raises(ValueError, match="never closed"):
        strip_solutions("````{solution} ex-a\nThe answer.\n```\n")
    with pytest.raises(ValueError, match="without a"):
        strip_solutions("````{solution-start} ex-a\n````\n\nsecret\n")
