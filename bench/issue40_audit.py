"""Issue 40's done-means, line by line, from a ``make check-book`` run (issue40_audit.json).

    make check-book && python bench/issue40_audit.py [--junit book/_build/check-book.junit.xml]

``make check-book`` opens every page of the built book (and the student edition's files) in
headless Chromium and writes its pytest results as JUnit XML beside the book
(``book/_build/check-book.junit.xml``). This script maps each line of the issue's done-means to
the checks that assert it (``tests/book/test_rendered.py``, ``tests/book/test_student.py``), and
counts, per line, how many of those checks ran, passed and failed in that run: ``status`` is
``met`` when at least one ran and none failed, ``short`` when one failed, ``not-run`` when none
ran. The scale the book was built at (``book/_build/.scale``: CI builds ``full``, the tests'
quick build ``small``) and the commit are recorded with it: a ``small`` build does not show
the full-scale tables (the engine chapter's 54 fits failed CI's full build once, 20 rows in
small). Two counts are read from the built HTML itself, as the issue states them: images with
alt text over all images, and the LP page's display equations. Nothing is typed here.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import time
import xml.etree.ElementTree as ET
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "book" / "_build"
RESULTS = Path(__file__).resolve().parent / "results"

#: Each done-means line and the check functions (``file::function``) that assert it.
LINES: dict[str, list[str]] = {
    "0 solutions in the student edition's files": [
        "test_student::test_student_files_have_exercises_without_solutions",
    ],
    "≥ 2 typeset equations on the LP page": [
        "test_rendered::test_chapter_typesets_its_equations",
    ],
    "no table over 20 rows or with an all-'—' column": [
        "test_rendered::test_tables_short_and_without_empty_columns",
    ],
    "at 400 px every result table's verdict visible without sideways scroll": [
        "test_rendered::test_result_tables_show_every_column_at_400px",
        "test_rendered::test_no_sideways_scroll_at_400px",
    ],
    "at 1400 px and in print no table wider than its column": [
        "test_rendered::test_tables_fit_their_column_at_1400px",
        "test_rendered::test_tables_fit_the_printed_page",
    ],
    "every image with alt text": ["test_rendered::test_images_have_alt_text"],
    "0 occurrences of 'GUIDE', of name[...] keys, of Python reprs, of hyphen-minus before digits": [
        "test_rendered::test_no_internals_leak",
        "test_rendered::test_no_python_reprs",
        "test_rendered::test_no_glue_slips",
    ],
    "every 'differs' with a cause": ["test_rendered::test_every_differs_has_a_cause"],
    "per-paper statements ≤ 80 words": ["test_rendered::test_per_paper_statements"],
}


def _cases(junit: Path) -> list[dict]:
    """Every test case of the JUnit file: its module, function, parameter and outcome."""
    out = []
    for case in ET.parse(junit).getroot().iter("testcase"):
        module = case.get("classname", "").rsplit(".", 1)[-1]
        name = case.get("name", "")
        func, _, param = name.partition("[")
        if case.find("failure") is not None or case.find("error") is not None:
            outcome = "failed"
        elif case.find("skipped") is not None:
            outcome = "skipped"
        else:
            outcome = "passed"
        out.append({"check": f"{module}::{func}", "param": param.rstrip("]"), "outcome": outcome})
    return out


class _Html(HTMLParser):
    """Counts ``<img>`` (with and without alt text) and display-math blocks of one page."""

    def __init__(self) -> None:
        super().__init__()
        self.images = 0
        self.with_alt = 0
        self.display_math = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images += 1
            self.with_alt += bool((a.get("alt") or "").strip())
        elif tag == "div" and "math" in (a.get("class") or "").split():
            self.display_math += 1


def _html_counts(html_dir: Path) -> dict:
    per_page = {}
    for page in sorted(html_dir.rglob("*.html")):
        rel = page.relative_to(html_dir).as_posix()
        if rel.startswith(("_", "genindex", "search")):
            continue
        p = _Html()
        p.feed(page.read_text(encoding="utf-8"))
        per_page[rel] = (p.images, p.with_alt, p.display_math)
    return {
        "images": sum(v[0] for v in per_page.values()),
        "images_with_alt_text": sum(v[1] for v in per_page.values()),
        "lp_page_display_equations": per_page.get("chapters/lp_observations.html", (0, 0, 0))[2],
        "pages": len(per_page),
    }


def audit(junit: Path) -> dict:
    cases = _cases(junit)
    entries = []
    for line, checks in LINES.items():
        mine = [c for c in cases if c["check"] in checks]
        counts = Counter(c["outcome"] for c in mine)
        failed = sorted(f"{c['check']}[{c['param']}]" for c in mine if c["outcome"] == "failed")
        if not mine or counts["passed"] == 0:
            status = "not-run"
        else:
            status = "short" if failed else "met"
        entries.append(
            {
                "line": line,
                "status": status,
                "evidence": {"checks": checks, "outcomes": dict(counts), "failed": failed},
            }
        )
    shot = RESULTS / "jupyterlab_chapter.png"
    entries.append(
        {
            "line": "a downloaded chapter opened in JupyterLab from the pinned environment shows "
            "its numbers (a screenshot in the note)",
            "status": "met" if shot.is_file() else "not-run",
            "evidence": {"screenshot": str(shot.relative_to(ROOT)) if shot.is_file() else None},
        }
    )
    html = _html_counts(BUILD / "html")
    scale = BUILD / ".scale"
    commit = subprocess.run(
        ["git", "describe", "--always", "--dirty"], capture_output=True, text=True, cwd=ROOT
    ).stdout.strip()
    return {
        "what": "issue 40's done-means from a make check-book run (bench/issue40_audit.py)",
        "commit": commit,
        "book_scale": scale.read_text().strip() if scale.is_file() else None,
        "junit": str(junit.relative_to(ROOT)) if junit.is_relative_to(ROOT) else str(junit),
        "checks_run": dict(Counter(c["outcome"] for c in cases)),
        "html_counts": html,
        "counts": dict(Counter(e["status"] for e in entries)),
        "entries": entries,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--junit", type=Path, default=BUILD / "check-book.junit.xml")
    ap.add_argument("--out", type=Path, default=RESULTS / "issue40_audit.json")
    args = ap.parse_args()
    if not args.junit.is_file():
        raise SystemExit(f"{args.junit}: no check-book results; run `make check-book` first")
    result = audit(args.junit.resolve())
    args.out.write_text(json.dumps(result, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    for e in result["entries"]:
        print(f"{e['status']:8} {e['line']}")
    print(result["counts"], "book scale:", result["book_scale"], "html:", result["html_counts"])


if __name__ == "__main__":
    main()
