"""The student edition (``make book-student``, built by ``make check-book``): every page and
every download has the exercises and none of their solutions (issue 40).

Read from the built files of ``book/_build/html-student``: each chapter's HTML, its ``.md``
source and its ``.ipynb`` download. The full edition is the control: its files must show the
solutions the student files lack, so a check that looks in the wrong place fails.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.book

BOOK = Path(__file__).resolve().parents[2] / "book"
FULL = Path(os.environ.get("HSGEO_BOOK_HTML", BOOK / "_build" / "html"))
STUDENT = Path(os.environ.get("HSGEO_STUDENT_HTML", BOOK / "_build" / "html-student"))
CHAPTERS = sorted(p.stem for p in (BOOK / "chapters").glob("*.md"))
SOLUTION_MD = re.compile(r"\{solution(?:-start|-end)?\}")
SOLUTION_HTML = re.compile(r'class="[^"]*\bsolution\b')


def _files(root: Path, chapter: str) -> dict[str, str]:
    base = root / "chapters"
    out = {"html": (base / f"{chapter}.html").read_text(encoding="utf-8")}
    sources = root / "_sources" / "chapters"
    md = [p for p in sources.glob(f"{chapter}.md*") if p.suffix in (".md", ".txt")]
    assert md, f"{sources}: no .md download of {chapter}"
    out["md"] = md[0].read_text(encoding="utf-8")
    nb = json.loads((sources / f"{chapter}.ipynb").read_text(encoding="utf-8"))
    out["ipynb"] = "\n".join("".join(c["source"]) for c in nb["cells"])
    return out


@pytest.fixture(scope="module")
def built():
    if not (STUDENT / "index.html").is_file():
        pytest.fail(f"{STUDENT}: the student edition is not built (make book-student)")
    return {c: (_files(FULL, c), _files(STUDENT, c)) for c in CHAPTERS}


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_student_files_have_exercises_without_solutions(built, chapter):
    full, student = built[chapter]
    assert SOLUTION_MD.search(full["md"]), "control: the full .md has its solutions"
    assert "**Solution" in full["ipynb"], "control: the full .ipynb has its solutions"
    assert SOLUTION_HTML.search(full["html"]), "control: the full page has its solutions"
    assert not SOLUTION_MD.search(student["md"]), "the student .md download has a solution"
    assert not SOLUTION_MD.search(student["ipynb"]), "the student .ipynb has a solution"
    assert "**Solution" not in student["ipynb"], "the student .ipynb has a solution"
    assert not SOLUTION_HTML.search(student["html"]), "the student page has a solution"
    n_ex = full["md"].count("{exercise}")
    assert n_ex >= 3 and student["md"].count("{exercise}") == n_ex
    assert student["ipynb"].count("**Exercise") == full["ipynb"].count("**Exercise") >= n_ex
