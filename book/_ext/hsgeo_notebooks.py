"""The chapters' ``.ipynb`` downloads as a reader opens them in Jupyter: with their numbers.

A chapter is a MyST Markdown notebook. Converted as it is (jupytext), its download has no outputs
and its text is full of MyST that plain JupyterLab shows raw: ``{glue:text}`rms``` instead of
the number, ``{cite:t}``, ``{term}``, exercise fences. :func:`readable_notebook` makes the
download a reader can use offline without extensions:

- the code cells carry the outputs and execution counts of the build's own execution (myst-nb's
  executed notebook in ``jupyter_execute/``), matched by their source, so a cell left out (a
  solution in the student edition) takes no other cell's output;
- every glued value is written into the text (myst-nb's glue cache of the page), formatted as
  the page shows it;
- roles become their text (``{term}`GSD``` → GSD, ``{cite:t}`key``` → [key]), directive fences
  become a bold title line (``{exercise}`` → **Exercise: …**), targets and options go.

Kept apart from ``hsgeo_book.py`` (the extension proper) because it is plain text work on
notebooks, tested without building a book (``tests/test_book_student.py``).
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

#: ``{role}`content``` in MyST Markdown.
_ROLE = re.compile(r"\{(?P<role>[\w:.-]+)\}`(?P<body>[^`]*)`")
#: A directive's opening fence, ``` ```{name} args ``` or ``:::{name} args``.
_FENCE_OPEN = re.compile(r"^(?P<fence>`{3,}|:{3,})\{(?P<name>[\w:-]+)\}\s*(?P<args>.*)$")
#: ``(label)=`` target lines.
_TARGET = re.compile(r"^\([\w:.-]+\)=\s*$")
#: Directive titles a reader sees; other directives get their name, capitalised.
_TITLES = {"exercise": "Exercise", "solution": "Solution", "solution-start": "Solution"}


def glue_texts(glue_json: Path) -> dict[str, object]:
    """The glued values of a page (myst-nb's ``<page>.glue.json``): key → Python value
    (a string, a number) read from its ``text/plain``; keys without text are left out.
    """
    if not glue_json.is_file():
        return {}
    out: dict[str, object] = {}
    for key, output in json.loads(glue_json.read_text(encoding="utf-8")).items():
        plain = output.get("data", {}).get("text/plain")
        if plain is None:
            continue
        plain = "".join(plain) if isinstance(plain, list) else plain
        try:
            out[key] = ast.literal_eval(plain)
        except (ValueError, SyntaxError):
            out[key] = plain
    return out


def _glued(body: str, glue: dict[str, object]) -> str:
    key, _, spec = body.partition(":")
    if key not in glue:
        return body
    value = glue[key]
    if spec and isinstance(value, (int, float)):
        try:
            return format(value, spec)
        except ValueError:
            pass
    return str(value)


def _role_text(match: re.Match, glue: dict[str, object]) -> str:
    role, body = match["role"], match["body"]
    if role.startswith("glue"):
        return _glued(body, glue)
    if role == "math":
        return f"${body}$"
    if role.startswith("cite"):
        return "[" + ", ".join(k.strip() for k in body.split(",")) + "]"
    if role == "download":
        return body
    # {term}`text <target>`, {ref}`text <label>`, {doc}`path`: the text when given
    m = re.match(r"^(?P<text>.*?)\s*<(?P<target>[^>]+)>$", body)
    return m["text"] if m and m["text"] else body


def glue_images(glue_json: Path) -> dict[str, str]:
    """The glued figures of a page: key → base64 PNG (myst-nb's ``<page>.glue.json``)."""
    if not glue_json.is_file():
        return {}
    out = {}
    for key, output in json.loads(glue_json.read_text(encoding="utf-8")).items():
        png = output.get("data", {}).get("image/png")
        if png:
            out[key] = "".join(png) if isinstance(png, list) else png
    return out


def readable_markdown(text: str, glue: dict[str, object], images: dict | None = None) -> str:
    """A markdown cell's MyST as plain Markdown: glued values, role texts, titled directives;
    a ``{glue:figure}`` becomes the figure itself (an attachment, ``images`` key → PNG).
    """
    lines: list[str] = []
    closing: list[str] = []  # fences of the directives open at this point
    in_options = False
    for line in text.splitlines():
        m = _FENCE_OPEN.match(line)
        if m:
            if m["name"] == "solution-end":
                closing.append(m["fence"])
                in_options = True
                continue
            if m["name"].startswith("glue") and images and m["args"].strip() in images:
                lines.append(f"![{m['args'].strip()}](attachment:{m['args'].strip()}.png)")
                closing.append(m["fence"])
                in_options = True
                continue
            title = _TITLES.get(m["name"], m["name"].replace("-", " ").capitalize())
            args = _ROLE.sub(lambda r: _role_text(r, glue), m["args"]).strip()
            if m["name"] in ("solution", "solution-start"):
                args = ""  # the exercise's label
            lines.append(f"**{title}{': ' + args if args else ''}**")
            closing.append(m["fence"])
            in_options = True
            continue
        stripped = line.strip()
        if in_options and re.match(r"^:[\w-]+:", stripped):
            continue
        in_options = False
        if closing and stripped and set(stripped) == {closing[-1][0]}:
            if len(stripped) >= len(closing[-1]):
                closing.pop()
                continue
        if _TARGET.match(stripped):
            continue
        lines.append(_ROLE.sub(lambda r: _role_text(r, glue), line))
    return "\n".join(lines).strip("\n")


def attach_outputs(nb, executed) -> int:
    """Copy outputs and execution counts from the ``executed`` notebook into ``nb``'s code
    cells whose source equals an executed cell's (in order). Returns the number of cells matched.
    """
    done = [c for c in executed.cells if c.cell_type == "code"]
    start = matched = 0
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        for j in range(start, len(done)):
            if done[j].source == cell.source:
                cell.outputs = done[j].get("outputs", [])
                cell.execution_count = done[j].get("execution_count")
                start, matched = j + 1, matched + 1
                break
    return matched


def readable_notebook(nb, executed_ipynb: Path, glue_json: Path):
    """``nb`` (a chapter read by jupytext) with the build's outputs and readable text."""
    import nbformat

    if executed_ipynb.is_file():
        attach_outputs(nb, nbformat.read(executed_ipynb, as_version=4))
    glue, images = glue_texts(glue_json), glue_images(glue_json)
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            cell.source = readable_markdown(cell.source, glue, images)
            used = [k for k in images if f"(attachment:{k}.png)" in cell.source]
            if used:
                cell["attachments"] = {f"{k}.png": {"image/png": images[k]} for k in used}
    nb.cells = [c for c in nb.cells if c.cell_type != "markdown" or c.source.strip()]
    return nb
