"""The browser checks themselves, on pages whose answer is known.

1. Hand-written HTML pages, each with exactly one defect (raw TeX, an uncaptioned image, NaN in
   a table, a page wider than the screen, a clipped box, a missing notebook, no exercise, a
   network request): the matching check must report it, and must pass the repaired page.
2. A synthetic chapter built with the book's real configuration, extension and CSS (equations,
   a captioned figure, an exercise with its solution, a wide table, a wide DataFrame, a long
   output line, a long display equation): every check must pass on it at 400 px and 1400 px.
   This is the end-to-end test of the infrastructure that every chapter relies on.

Run by ``make check-book`` (needs Chromium; see ``conftest.py``).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from pagecheck import (
    NARROW_PX,
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
PNG_1PX = (
    "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk"
    "YPhfDwAChwGA60e6kgAAAABJRU5ErkJggg=="
)


def _page(tmp_path: Path, name: str, body: str) -> Path:
    path = tmp_path / f"{name}.html"
    path.write_text(
        "<!doctype html><html><head><meta charset='utf-8'>"
        "<meta name='viewport' content='width=device-width, initial-scale=1'></head>"
        f"<body><main>{body}</main></body></html>",
        encoding="utf-8",
    )
    return path


def _table(n_rows: int) -> str:
    rows = "".join(f"<tr><td>q{i}</td><td>{i}</td></tr>" for i in range(n_rows))
    return f"<table><thead><tr><th>q</th><th>v</th></tr></thead><tbody>{rows}</tbody></table>"


def _figure_png(panel_columns: int) -> str:
    """A figure of ``panel_columns`` panels side by side, glued as a chapter glues one
    (hsgeo.report's PNG with its panel grid), as a data: URL in a <figure>."""
    import base64

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from hsgeo.report import _GluedFigure

    fig, _ = plt.subplots(1, panel_columns, figsize=(2 * panel_columns, 1.5))
    png = _GluedFigure(fig)._repr_png_()
    plt.close(fig)
    src = "data:image/png;base64," + base64.b64encode(png).decode()
    return (
        f'<figure><img src="{src}" alt="panels" style="max-width: 100%">'
        "<figcaption>Fig. 1: panels.</figcaption></figure>"
    )


def _verdicts(*rows: tuple[str, str]) -> str:
    body = "".join(
        f"<tr><td>c{i}</td><td>{v}</td><td>{w}</td></tr>" for i, (v, w) in enumerate(rows)
    )
    return (
        "<table><thead><tr><th>claim</th><th>verdict</th><th>why</th></tr></thead>"
        f"<tbody>{body}</tbody></table>"
    )


# (check, defective body, repaired body)
CASES = {
    "raw-tex": (
        problems_equations,
        r"<p>The line \(\zeta = c\) and \[x^2\]</p>",
        "<p>The line ζ = c</p>",
    ),
    "math-not-typeset": (
        problems_equations,
        '<p><span class="math">x</span></p>',
        "<p>x</p>",
    ),
    "uncaptioned-image": (
        problems_captions,
        f'<div class="cell"><div class="cell_output"><img src="{PNG_1PX}"></div></div>',
        f'<figure><img src="{PNG_1PX}"><figcaption>Fig. 1: a pixel.</figcaption></figure>',
    ),
    "empty-caption": (
        problems_captions,
        f'<figure><img src="{PNG_1PX}"><figcaption> </figcaption></figure>',
        f'<figure><img src="{PNG_1PX}"><figcaption>Fig. 1</figcaption></figure>',
    ),
    "image-alt-is-a-path": (
        problems_alt_text,
        f'<figure><img src="{PNG_1PX}" alt="../_images/3f2a9c.png"><figcaption>Fig. 1</figcaption>'
        "</figure>",
        f'<figure><img src="{PNG_1PX}" alt="Fig. 1: E/N of a pixel"><figcaption>Fig. 1'
        "</figcaption></figure>",
    ),
    "nan-in-table": (
        problems_nan,
        "<table><tr><th>c</th><td>NaN</td></tr></table>",
        "<table><tr><th>c (nanometre)</th><td>—</td></tr></table>",
    ),
    "page-too-wide": (
        problems_page_width,
        '<div style="width: 900px">wide</div>',
        '<div style="max-width: 100%; overflow-x: auto"><div style="width: 900px">w</div></div>',
    ),
    "clipped-output": (
        problems_clipped,
        '<pre style="width: 200px; overflow: hidden">' + "x" * 300 + "</pre>",
        '<pre style="width: 200px; overflow-x: auto">' + "x" * 300 + "</pre>",
    ),
    "no-exercise": (
        problems_exercises,
        '<div class="exercise">Do it.</div>',
        '<div class="exercise">Do it.</div><div class="solution">Done.</div>',
    ),
    "numbered-across-the-book": (
        problems_numbering,
        '<h1><span class="section-number">4. </span>MTF</h1>'
        '<div class="exercise"><p><span class="caption-number">Exercise 21 </span></p></div>',
        '<h1><span class="section-number">4. </span>MTF</h1>'
        '<div class="exercise"><p><span class="caption-number">Exercise 4.1 </span></p></div>',
    ),
    "chapter-without-number": (
        problems_numbering,
        '<h1>MTF</h1><figure><span class="caption-number">Fig. 1 </span></figure>',
        '<h1><span class="section-number">4. </span>MTF</h1>'
        '<figure><span class="caption-number">Fig. 4.1 </span></figure>',
    ),
    "numpy-repr": (
        problems_leaks,
        "<p>the largest deviation is np.float64(1.25)σ̂</p>",
        "<p>the largest deviation is 1.25σ̂</p>",
    ),
    "tmp-path-and-warning": (
        problems_leaks,
        '<div class="cell_output"><pre>/tmp/x.py:3: RuntimeWarning: overflow</pre></div>',
        '<div class="cell_output"><pre>done</pre></div>',
    ),
    "issue-number": (
        problems_leaks,
        "<figure><figcaption>Red: the goals of issue 14.</figcaption></figure>",
        "<figure><figcaption>Red: the goals of the solver study.</figcaption></figure>",
    ),
    "traceback": (
        problems_leaks,
        '<div class="cell_output"><pre>Traceback (most recent call last):</pre></div>',
        "<p>no error</p>",
    ),
    "repeated-word": (
        problems_glue_slips,
        "<p>See Exercise Exercise 9.</p>",
        "<p>See Exercise 9.</p>",
    ),
    "range-with-equal-ends": (
        problems_glue_slips,
        "<p>precision estimates of 1.3–1.3 µm</p>",
        "<p>precision estimates of 1.3–1.35 µm and 13–130 px</p>",
    ),
    "developers-guide": (
        problems_glue_slips,
        "<p>not testable (GUIDE §4)</p>",
        "<p>not testable (fewer than 8 runs)</p>",
    ),
    "internal-key": (
        problems_glue_slips,
        "<p>lever_arm_m[z_m] is 0.1 m</p>",
        "<p>the lever arm's z is 0.1 m; <code>lever_arm_m[z_m]</code> in code</p>",
    ),
    "hyphen-minus": (
        problems_glue_slips,
        "<p>f moves by -0.8 σ̂</p>",
        "<p>f moves by −0.8 σ̂ over 2-3 s in EPSG:25832+5941 on 2026-11-28</p>",
    ),
    "unpadded-cells": (
        problems_cell_padding,
        '<table><tr><td style="padding:0">657</td><td style="padding:0">20</td></tr></table>',
        '<table><tr><td style="padding:0 6px">657</td>'
        '<td style="padding:0 6px">20</td></tr></table>',
    ),
    "result-table-scrolls": (
        problems_result_tables,
        '<table class="hsgeo-table" style="display:block; overflow-x:auto; max-width:100%">'
        "<tr>"
        + '<td style="white-space:nowrap">'
        + "0.0052 (24 runs) " * 3
        + "</td>" * 1
        + '<td data-label="verdict">within 1σ̂</td></tr></table>',
        '<table class="hsgeo-table"><tr><td>c</td><td data-label="verdict">within 1σ̂</td></tr>'
        "</table>",
    ),
    "version-footer": (
        problems_version_footer,
        "<footer>Built by hand</footer>",
        "<footer>Built with hsgeo 0.1.0</footer>",
    ),
    "too-few-display-equations": (
        problems_display_equations,
        '<p>The LP camera has no equation.</p><mjx-container display="true">u</mjx-container>',
        '<mjx-container display="true">u</mjx-container>'
        '<mjx-container display="true">v</mjx-container>',
    ),
    "table-over-20-rows": (
        problems_long_tables,
        _table(21),
        _table(20) + "<details><summary>all rows</summary>" + _table(56) + "</details>",
    ),
    "all-dash-column": (
        problems_long_tables,
        "<table><thead><tr><th>q</th><th>observation level</th></tr></thead><tbody>"
        "<tr><td>a</td><td>—</td></tr><tr><td>b</td><td>—</td></tr></tbody></table>",
        "<table><thead><tr><th>q</th><th>observation level</th></tr></thead><tbody>"
        "<tr><td>a</td><td>—</td></tr><tr><td>b</td><td>0.12</td></tr></tbody></table>",
    ),
    "array-repr": (
        problems_reprs,
        "<p>the shifts are array([0.1, 0.2]) px</p>",
        "<p>the shifts are 0.1 and 0.2 px</p>",
    ),
    "numpy-scalar-repr": (
        problems_reprs,
        '<div class="cell_output"><pre>np.float64(0.34)</pre></div>',
        '<div class="cell_output"><pre>0.34</pre></div>',
    ),
    "hsgeo-object-repr": (
        problems_reprs,
        "<p>&lt;hsgeo.report.Reproduction object at 0x7f&gt;</p>",
        "<p>the reproduction of lp-observations</p>",
    ),
    "dict-repr": (
        problems_reprs,
        "<p>counts {'all': 42682}</p>",
        "<p>counts: 42,682 in all (a set {a, b} in words is fine)</p>",
    ),
    "differs-without-cause": (
        problems_differs_cause,
        _verdicts(("differs", "12.4σ from the paper (σ̂)")),
        _verdicts(
            ("differs", "check points measured as 002 measured them: the matcher's tie points"),
            ("reproduced", "within 2σ of the paper (σ̂)"),
        ),
    ),
    "differs-without-any-reason": (
        problems_differs_cause,
        _verdicts(("differs", "—")),
        _verdicts(("not testable", "—")),
    ),
    "statement-over-80-words": (
        problems_statements,
        '<p class="hsgeo-statement">' + "word " * 81 + "</p>",
        '<p class="hsgeo-statement">' + "word " * 80 + "</p>",
    ),
    "figure-of-three-panel-columns": (
        problems_panels,
        _figure_png(3),
        _figure_png(2),
    ),
    "table-wider-than-its-column": (
        problems_wide_tables,
        '<table style="width: 1800px"><tr><td>claim</td><td>differs</td></tr></table>',
        "<table><tr><td>claim</td><td>differs</td></tr></table>",
    ),
    "network-request": (
        problems_offline,
        '<img src="https://example.org/logo.png" alt="">',
        "<p>offline</p>",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_check_reports_the_defect_and_passes_the_repair(browser, tmp_path, case):
    check, defective, repaired = CASES[case]
    narrow = (problems_page_width, problems_result_tables, problems_panels)
    width = NARROW_PX if check in narrow else WIDE_PX
    bad = page_facts(browser, _page(tmp_path, "bad", defective), width)
    good = page_facts(browser, _page(tmp_path, "good", repaired), width)
    assert check(bad), f"{case}: the defect was not reported"
    assert check(good) == [], f"{case}: the repaired page was reported"


def test_ipynb_check(browser, tmp_path):
    (tmp_path / "nb.ipynb").write_text("{}", encoding="utf-8")
    missing = page_facts(browser, _page(tmp_path, "a", '<a href="gone.ipynb">nb</a>'), WIDE_PX)
    absent = page_facts(browser, _page(tmp_path, "b", "<p>no link</p>"), WIDE_PX)
    good = page_facts(browser, _page(tmp_path, "c", '<a href="nb.ipynb">nb</a>'), WIDE_PX)
    assert problems_ipynb(missing) and problems_ipynb(absent)
    assert problems_ipynb(good) == []


# --- a synthetic chapter built with the book's configuration --------------------------------

DEMO_CHAPTER = r"""---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---

# A synthetic chapter

The line scanner maps $\zeta$ to a direction; in display,

$$
\zeta = \zeta_0 - c\,\frac{r_{11}(X - X_0) + r_{21}(Y - Y_0) + r_{31}(Z - Z_0)}
{r_{13}(X - X_0) + r_{23}(Y - Y_0) + r_{33}(Z - Z_0)}
+ \Delta\zeta_{\mathrm{distortion}}(\zeta - \zeta_0; k_1, k_2, k_3, k_4, k_5, k_6, k_7)
+ \Delta\zeta_{\mathrm{other}}
$$

and a long path in text: `data_synthetic/generated/a_very_long_file_name_without_breaks.parquet`.
A sentence formatted with a hyphen for a minus: z moves by -0.8 σ̂ in 2-3 s, `x = -1` in code.

| quantity | unit | paper | reproduced | σ̂ | truth | z | verdict | note | more |
|---|---|---|---|---|---|---|---|---|---|
| principal dist. c | px | 3539.0 | 3538.21 | 0.93 | 3539.00 | −0.85 | within 1σ̂ | a note | text |

```{code-cell} ipython3
import numpy as np
import pandas as pd

pd.DataFrame(np.arange(40.0).reshape(2, 20), columns=[f"column_{i}" for i in range(20)])
```

```{code-cell} ipython3
print("a long output line " * 20)
```

```{code-cell} ipython3
:tags: [remove-cell]
from hsgeo.report import glue_text

glue_text("demo_c", 3538.214, 0.93, unit="px")
```

The principal distance is {glue:text}`demo_c`.

```{code-cell} ipython3
from hsgeo.report import styled

styled(pd.DataFrame({
    "quantity": ["principal distance c", "principal point x0"], "unit": ["px", "px"],
    "paper": ["3539.0", "12.1"], "reproduced": ["3538.21 (24 runs)", "12.05 (24 runs)"],
    "σ̂": ["0.0052 (24 runs)", "0.0041 (24 runs)"], "truth": ["3539.00", "12.10"],
    "z": ["−0.85", "−1.20"], "verdict": ["within 1σ̂", "within 2σ̂"],
    "provenance": ["the paper's value, simulated", "the paper's value, simulated"],
}))
```

```{code-cell} ipython3
---
mystnb:
  figure:
    caption: A captioned figure from a code cell.
---
import matplotlib.pyplot as plt

fig, ax = plt.subplots(figsize=(4, 2))
ax.plot([0, 1], [0, 1])
```

```{exercise}
:label: ex-demo

Give the stations σ = 1 cm and recompute σ(c).
```

```{solution} ex-demo
:class: dropdown

Recompute with `sigma_m=0.01`; σ(c) grows.
```
"""


@pytest.fixture(scope="module")
def demo_book(tmp_path_factory) -> Path:
    """Build a two-page book (intro + synthetic chapter) with the book's config, _ext, _static."""
    root = tmp_path_factory.mktemp("demo") / "book"
    root.mkdir()
    for name in ("_config.yml", "references.bib"):
        shutil.copy(BOOK / name, root / name)
    for name in ("_ext", "_static"):
        shutil.copytree(BOOK / name, root / name, ignore=shutil.ignore_patterns("__pycache__"))
    (root / "_toc.yml").write_text(
        "format: jb-book\nroot: intro\nchapters:\n  - file: chapters/demo\n", encoding="utf-8"
    )
    (root / "intro.md").write_text("# Demo\n\nSee {doc}`chapters/demo`.\n", encoding="utf-8")
    (root / "chapters").mkdir()
    (root / "chapters" / "demo.md").write_text(DEMO_CHAPTER, encoding="utf-8")
    jupyter_book = Path(sys.executable).with_name("jupyter-book")
    result = subprocess.run(
        [str(jupyter_book), "build", str(root), "-W", "-n", "--keep-going"],
        capture_output=True,
        text=True,
        env={**os.environ, "HSGEO_SCALE": "small"},
        timeout=900,
    )
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return root / "_build" / "html"


@pytest.mark.parametrize("width", [NARROW_PX, WIDE_PX])
def test_synthetic_chapter_passes_every_check(browser, demo_book, width):
    facts = page_facts(browser, demo_book / "chapters" / "demo.html", width)
    problems = (
        problems_equations(facts)
        + problems_offline(facts)
        + problems_captions(facts)
        + problems_alt_text(facts)
        + problems_nan(facts)
        + problems_page_width(facts)
        + problems_clipped(facts)
        + problems_ipynb(facts)
        + problems_md_source(facts)
        + problems_exercises(facts)
        + problems_leaks(facts)
        + problems_glue_slips(facts)
        + problems_cell_padding(facts)
        + problems_version_footer(facts)
        + problems_result_tables(facts)
        + problems_long_tables(facts)
        + problems_reprs(facts)
        + problems_differs_cause(facts)
        + problems_statements(facts)
    )
    assert problems == []
    # the checks saw what they check, so passing is not vacuous
    assert facts["mathjax_output"] >= 2 and facts["figures"] >= 1
    assert facts["exercises"] >= 1 and facts["solutions"] >= 1
    assert facts["ipynb_links"]
    assert facts["table_cells"] >= 10  # the padding check measured the tables
    assert facts["result_tables"] >= 1  # and a report table, as cards at 400 px


def test_synthetic_chapter_infrastructure(demo_book):
    """MathJax shipped locally, notebook download converted, run box and run time present."""
    html = (demo_book / "chapters" / "demo.html").read_text(encoding="utf-8")
    assert 'src="../_static/mathjax/tex-mml-chtml.js"' in html
    assert (demo_book / "_static" / "mathjax" / "tex-mml-chtml.js").is_file()
    assert list((demo_book / "_static" / "mathjax").rglob("*.woff"))
    assert "cdn.jsdelivr.net" not in html
    import nbformat

    nb = nbformat.read(demo_book / "_sources" / "chapters" / "demo.ipynb", as_version=4)
    assert [c.cell_type for c in nb.cells].count("code") == 5
    # the download opens in plain Jupyter with its numbers: outputs and glued values
    assert sum(bool(c.get("outputs")) for c in nb.cells if c.cell_type == "code") >= 4
    text = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    assert "The principal distance is 3538.21 px." in text
    assert "{glue" not in text and "{exercise}" not in text and "**Exercise" in text
    assert "Run it yourself" in html and "Run time measured when this book was built" in html
    assert "moves by \u22120.8 σ̂ in 2-3 s" in html  # a true minus in the prose only
    assert '<span class="pre">-1</span>' in html  # code keeps its hyphen
