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
import hsgeo_notebooks  # noqa: E402  (book/_ext, put on sys.path by hsgeo_book)

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


# --- the downloads' text, readable in plain Jupyter ----------------------------------------


def test_readable_markdown_writes_glued_values_and_role_texts():
    md = (
        "(sec-x)=\n## Results\n\n"
        "The RMS is {glue:text}`rms` px ({glue:text}`z:.1f` σ̂), see {term}`GSD`, "
        "{term}`ground distance <GSD>`, {cite:t}`Muller2002` and {numref}`fig-a`; "
        "{math}`\\sigma_0`.\n\n"
        "````{exercise} ★ The borderline\n:label: ex-a\n\nCompute it.\n```python\nx = 1\n```\n"
        "````\n\n"
        ":::{admonition} What was tuned\n:class: note\nNothing.\n:::"
    )
    out = hsgeo_notebooks.readable_markdown(md, {"rms": "0.34", "z": -0.8123})
    assert "The RMS is 0.34 px (-0.8 σ̂), see GSD, ground distance, [Muller2002] and fig-a" in out
    assert "$\\sigma_0$" in out
    assert "**Exercise: ★ The borderline**" in out and ":label:" not in out
    assert "```python\nx = 1\n```" in out  # a code block inside the exercise kept
    assert "**Admonition: What was tuned**" in out and ":class:" not in out
    assert "{" not in out.replace("{glue", "") and "(sec-x)=" not in out
    assert "````" not in out and ":::" not in out


def test_outputs_attach_by_source_so_a_removed_cell_takes_none():
    import nbformat
    from nbformat.v4 import new_code_cell, new_notebook, new_output

    executed = new_notebook(
        cells=[
            new_code_cell("a = 1", outputs=[new_output("stream", text="one")], execution_count=1),
            new_code_cell("secret()", outputs=[new_output("stream", text="42")], execution_count=2),
            new_code_cell("a + 1", outputs=[new_output("stream", text="two")], execution_count=3),
        ]
    )
    student = new_notebook(cells=[new_code_cell("a = 1"), new_code_cell("a + 1")])
    assert hsgeo_notebooks.attach_outputs(student, executed) == 2
    assert [c.outputs[0]["text"] for c in student.cells] == ["one", "two"]
    assert [c.execution_count for c in student.cells] == [1, 3]
    assert nbformat.validate(student) is None


def test_glued_figure_becomes_an_attached_image(tmp_path):
    import json

    from nbformat.v4 import new_markdown_cell, new_notebook

    glue = tmp_path / "p.glue.json"
    glue.write_text(json.dumps({"fig_a": {"data": {"image/png": "iVBORw0K", "text/plain": "<F>"}}}))
    md = "````{glue:figure} fig_a\n:name: fig-a\n\nThe caption.\n````"
    nb = hsgeo_notebooks.readable_notebook(
        new_notebook(cells=[new_markdown_cell(md)]), tmp_path / "none.ipynb", glue
    )
    cell = nb.cells[0]
    assert cell.source == "![fig_a](attachment:fig_a.png)\n\nThe caption."
    assert cell.attachments == {"fig_a.png": {"image/png": "iVBORw0K"}}
