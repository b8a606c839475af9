"""Sphinx extension for the hsgeo book: what every page gets without its author typing it.

- **Math offline**: MathJax 3 is served from the book's own ``_static/mathjax/`` directory. The
  files come from the PyPI package ``django-static-mathjax`` (pinned in ``requirements.lock``;
  it ships MathJax 3.2.2's ``es5`` build as static files, importable as ``mathjax``). They are
  copied into the HTML output when the book is built, so neither the build nor a reader viewing
  the pages needs a network connection. Only what a browser can load is copied: the
  ``tex-mml-chtml`` component (Sphinx's default), its fonts, the lazily loaded TeX extensions,
  the menu, the accessibility and speech components; not the SVG output, the other combined
  components or the TypeScript sources.
- **Notebook downloads**: every page written as a MyST Markdown notebook is converted with
  jupytext into ``_sources/<page>.ipynb`` with the build's outputs and its glued numbers written
  into the text (``hsgeo_notebooks.readable_notebook``: it opens in plain Jupyter), and
  sphinx-book-theme's download menu offers it next to the ``.md`` source.
- **"Run it yourself"**: every chapter page (``chapters/*``) gets a collapsible box saying how
  to run it, with the run time that myst-nb measured when it executed the chapter (or when it
  was put into the execution cache).
- **Run times**: the ``{hsgeo-run-times}`` directive is replaced by a table of every chapter's
  measured run time.
- **Glued values as text**: a ``{glue}`` role in running text whose value is plain text (a
  number or a string) shows as text, like ``{glue:text}``, instead of myst-nb's code box (for a
  value glued in another document) or the Python repr with its quotes (in the same document).
  Chapters glue numbers with ``hsgeo.report.glue_text``, which formats them; a ``np.float64(…)``
  that still reaches a page is reported by ``make check-book``, not hidden here.
- **Student edition**: with ``HSGEO_STUDENT=1`` (``make book-student``) the solutions of the
  exercises are left out of the pages (``RemoveSolutions``) and of every download, the ``.md``
  sources and the ``.ipynb`` notebooks (``strip_solutions``).
- **Version**: every page's footer names the hsgeo version the book was built with
  (``hsgeo.__version__``) and how to cite it (``CITATION.cff``).
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import re
import shutil
import sys
from datetime import UTC, datetime
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.application import Sphinx
from sphinx.errors import ExtensionError
from sphinx.transforms import SphinxTransform
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

sys.path.insert(0, str(Path(__file__).resolve().parent))  # the book's other local module
from hsgeo_notebooks import readable_notebook  # noqa: E402

LOGGER = logging.getLogger(__name__)

#: MathJax component loaded by every page with math, relative to the HTML output's ``_static``.
MATHJAX_COMPONENT = "mathjax/tex-mml-chtml.js"
#: Files and directories of MathJax's ``es5`` build that a browser never loads for our pages.
_MATHJAX_UNUSED = (
    "mml-chtml.js",
    "mml-svg.js",
    "tex-chtml.js",
    "tex-chtml-full.js",
    "tex-chtml-full-speech.js",
    "tex-mml-svg.js",
    "tex-svg.js",
    "tex-svg-full.js",
    "node-main.js",
    "svg",
    "svg.js",
)
#: Pages that are chapters: they get the "Run it yourself" box and appear in the run-time table.
CHAPTER_PREFIX = "chapters/"


def mathjax_source() -> Path:
    """The ``es5`` directory of the installed MathJax 3 (package ``django-static-mathjax``)."""
    spec = importlib.util.find_spec("mathjax")
    if spec is None or not spec.submodule_search_locations:
        raise ExtensionError(
            "MathJax is not installed: run `make venv` (or `pip install "
            "django-static-mathjax==3.2.2.1`), the book serves MathJax from its own files"
        )
    es5 = Path(next(iter(spec.submodule_search_locations))) / "static" / "mathjax" / "es5"
    if not (es5 / "tex-mml-chtml.js").is_file():
        raise ExtensionError(
            f"{es5} has no tex-mml-chtml.js: reinstall django-static-mathjax==3.2.2.1 "
            "(the pin in requirements.lock)"
        )
    return es5


def _version_footer(app: Sphinx, config) -> None:
    """The hsgeo version in every page's footer (sphinx-book-theme's ``extra_footer``)."""
    import hsgeo

    config.version = config.release = hsgeo.__version__
    options = dict(config.html_theme_options or {})
    options["extra_footer"] = (
        f'<p class="hsgeo-version">Built with hsgeo {hsgeo.__version__} '
        "(<code>hsgeo.__version__</code>). To cite it, use <code>CITATION.cff</code> at the "
        "root of the repository; to install it, see the page “Install hsgeo”.</p>"
    )
    config.html_theme_options = options


def _student_edition(app: Sphinx, config) -> None:
    """``make book-student`` (``HSGEO_STUDENT=1``): the exercises without their solutions
    (:class:`RemoveSolutions`), executed from ``make book``'s cache
    (``HSGEO_JUPYTER_CACHE``) instead of a cache of its own.
    """
    if os.environ.get("HSGEO_STUDENT") != "1":
        return
    # not sphinx-exercise's own hide_solutions: it leaves the body and the end marker of the
    # gated form ({solution-start} … {solution-end}) on the page ("unknown node type"); the
    # transform below removes every solution once the gated ones are merged
    cache = os.environ.get("HSGEO_JUPYTER_CACHE")
    if cache:
        config.nb_execution_cache_path = cache


#: A MyST directive fence opening a solution: ```` ```{solution} ````, ``:::{solution-start}`` …
_SOLUTION_OPEN = re.compile(r"^(?P<fence>`{3,}|:{3,})\{(?P<kind>solution(?:-start|-end)?)\}")


def strip_solutions(text: str) -> str:
    """MyST Markdown ``text`` without its exercises' solutions (the student edition's downloads).

    Removes every ``{solution}`` directive block, and every gated solution from its
    ``{solution-start}`` fence to the end of its ``{solution-end}`` fence (the code cells and text
    between them included). A fence closes on a line of the same character at least as long as
    its opener, as in MyST; exercises and everything else are kept byte for byte. An unclosed
    solution is an error, not a silent truncation of the page.
    """
    lines = text.splitlines(keepends=True)
    out: list[str] = []
    i = 0

    def close_of(start: int, fence: str) -> int:
        """Index of the line closing the fence opened at ``start``."""
        for j in range(start + 1, len(lines)):
            body = lines[j].strip()
            if body and set(body) == {fence[0]} and len(body) >= len(fence):
                return j
        raise ValueError(f"line {start + 1}: solution fence {fence!r} is never closed")

    while i < len(lines):
        m = _SOLUTION_OPEN.match(lines[i])
        if m is None:
            out.append(lines[i])
            i += 1
            continue
        end = close_of(i, m["fence"])
        if m["kind"] == "solution-start":
            # through the next {solution-end} block
            for j in range(end + 1, len(lines)):
                m_end = _SOLUTION_OPEN.match(lines[j])
                if m_end is not None and m_end["kind"] == "solution-end":
                    end = close_of(j, m_end["fence"])
                    break
            else:
                raise ValueError(f"line {i + 1}: {{solution-start}} without a {{solution-end}}")
        i = end + 1
        while out and i < len(lines) and not lines[i].strip() and not out[-1].strip():
            i += 1  # no doubled blank line where the solution was
    return "".join(out)


def _student() -> bool:
    return os.environ.get("HSGEO_STUDENT") == "1"


def _strip_sources(app: Sphinx, exception: Exception | None) -> None:
    """Student edition: the ``.md`` downloads (Sphinx's ``_sources`` copies) without solutions."""
    if exception is not None or not _student() or app.builder.format != "html":
        return
    sources = Path(app.outdir) / "_sources"
    for docname in app.env.found_docs:
        for path in sources.glob(f"{docname}.md*"):
            if path.suffix in (".md", ".txt") and path.is_file():
                path.write_text(strip_solutions(path.read_text(encoding="utf-8")), "utf-8")


class RemoveSolutions(SphinxTransform):
    """The student edition (``HSGEO_STUDENT=1``): every exercise's solution is removed, after
    sphinx-exercise has merged the gated ones (its ``MergeGatedSolutions``, priority 10).
    """

    default_priority = 50

    def apply(self, **kwargs) -> None:
        if os.environ.get("HSGEO_STUDENT") != "1":
            return
        from sphinx_exercise.nodes import solution_node

        for node in list(self.document.findall(solution_node)):
            node.parent.remove(node)


def _use_local_mathjax(app: Sphinx, config) -> None:
    mathjax_source()  # fail at start-up, not after executing every chapter
    config.mathjax_path = MATHJAX_COMPONENT


def _copy_mathjax(app: Sphinx, exception: Exception | None) -> None:
    if exception is not None or app.builder.format != "html":
        return
    target = Path(app.outdir) / "_static" / "mathjax"
    shutil.copytree(
        mathjax_source(),
        target,
        ignore=shutil.ignore_patterns(*_MATHJAX_UNUSED),
        dirs_exist_ok=True,
    )
    size_mb = sum(f.stat().st_size for f in target.rglob("*") if f.is_file()) / 1e6
    LOGGER.info(f"[hsgeo] MathJax 3 copied to _static/mathjax ({size_mb:.1f} MB)")


# --- notebook downloads -------------------------------------------------------------------


def _notebook_of(app: Sphinx, docname: str):
    """The page as a notebook (jupytext), or None if it is not a notebook page."""
    import jupytext

    source = Path(app.env.doc2path(docname))
    if source.suffix != ".md":
        return None
    text = source.read_text(encoding="utf-8")
    if _student():
        text = strip_solutions(text)
    if not text.startswith("---") or "kernelspec:" not in text.split("\n---", 1)[0]:
        return None
    nb = jupytext.reads(text, fmt="md:myst")
    if not any(cell.cell_type == "code" for cell in nb.cells):
        return None
    return nb


def _add_ipynb_download(app: Sphinx, pagename: str, templatename, context, doctree) -> None:
    if doctree is None or pagename not in app.env.all_docs:
        return
    nb = _notebook_of(app, pagename)
    if nb is None:
        return
    import jupytext

    nb.metadata.pop("jupytext", None)  # a plain notebook, not paired with a text file
    # with the build's outputs and glued numbers, readable in plain Jupyter (hsgeo_notebooks)
    folder = Path(app.env.mystnb_config.output_folder)
    readable_notebook(nb, folder / f"{pagename}.ipynb", folder / f"{pagename}.glue.json")
    target = Path(app.outdir) / "_sources" / f"{pagename}.ipynb"
    target.parent.mkdir(parents=True, exist_ok=True)
    jupytext.write(nb, target, fmt="ipynb")
    # read by sphinx-book-theme's download menu (header_buttons, priority 501)
    context["ipynb_source"] = f"{pagename}.ipynb"


# --- measured run times -------------------------------------------------------------------


def _exec_data(app: Sphinx, docname: str) -> dict | None:
    from myst_nb.sphinx_ import NbMetadataCollector

    return NbMetadataCollector.get_doc_data(app.env).get(docname, {}).get("exec_data")


def _toc_order(app: Sphinx) -> list[str]:
    """Every document in table-of-contents order (depth first from the root)."""
    env = app.env
    seen: list[str] = []

    def walk(doc: str) -> None:
        if doc in seen:
            return
        seen.append(doc)
        for child in env.toctree_includes.get(doc, []):
            walk(child)

    walk(app.config.root_doc)
    return seen


def _runtime_text(data: dict | None) -> str:
    if not data or data.get("runtime") is None:
        return "not measured (the chapter was not executed in this build)"
    return f"{data['runtime']:.0f} s"


def _scale_text() -> str:
    scale = os.environ.get("HSGEO_SCALE")
    size = "at full size" if not scale else f"with HSGEO_SCALE={scale}"
    return f"{size}, on the machine that built the book ({os.cpu_count()} CPU cores)"


def _built_on(data: dict | None) -> str:
    if not data or not data.get("mtime"):
        return "—"
    return datetime.fromtimestamp(data["mtime"], tz=UTC).strftime("%Y-%m-%d %H:%M UTC")


class RunTimesNode(nodes.General, nodes.Element):
    """Placeholder for the table of chapter run times, filled in when the page is written."""


class RunTimesDirective(SphinxDirective):
    """``{hsgeo-run-times}``: a table of every chapter's measured run time."""

    has_content = False

    def run(self):
        self.env.metadata[self.env.docname]["hsgeo_run_times"] = True
        return [RunTimesNode()]


def _run_times_table(app: Sphinx, fromdocname: str) -> nodes.table:
    table = nodes.table(classes=["colwidths-auto", "hsgeo-run-times"])
    headers = ["chapter", "run time", "executed (or cached)"]
    tgroup = nodes.tgroup(cols=len(headers))
    table += tgroup
    for _ in headers:
        tgroup += nodes.colspec(colwidth=1)
    thead = nodes.thead()
    tgroup += thead
    row = nodes.row()
    for header in headers:
        row += nodes.entry("", nodes.paragraph(text=header))
    thead += row
    tbody = nodes.tbody()
    tgroup += tbody
    total_s = 0.0
    for docname in _toc_order(app):
        if not docname.startswith(CHAPTER_PREFIX):
            continue
        data = _exec_data(app, docname)
        if data and data.get("runtime") is not None:
            total_s += data["runtime"]
        title = app.env.titles[docname].astext() if docname in app.env.titles else docname
        ref = nodes.reference(
            "", title, internal=True, refuri=app.builder.get_relative_uri(fromdocname, docname)
        )
        row = nodes.row()
        row += nodes.entry("", nodes.paragraph("", "", ref))
        row += nodes.entry("", nodes.paragraph(text=_runtime_text(data)))
        row += nodes.entry("", nodes.paragraph(text=_built_on(data)))
        tbody += row
    row = nodes.row()
    row += nodes.entry("", nodes.paragraph(text="all chapters"))
    row += nodes.entry("", nodes.paragraph(text=f"{total_s:.0f} s"))
    row += nodes.entry("", nodes.paragraph(text="—"))
    tbody += row
    return table


def _literal(text: str) -> nodes.literal_block:
    block = nodes.literal_block(text, text)
    block["language"] = "console"
    return block


def _run_box(app: Sphinx, docname: str) -> nodes.admonition:
    name = Path(docname).name
    data = _exec_data(app, docname)
    box = nodes.admonition(classes=["tip", "dropdown", "hsgeo-run-box"])
    box += nodes.title(text="Run it yourself")
    para = nodes.paragraph()
    para += nodes.Text("This page is the MyST Markdown notebook ")
    para += nodes.literal(text=f"book/{docname}.md")
    para += nodes.Text(
        " of the repository you cloned (or the source archive you unpacked); the download "
        "menu at the top of the page offers it as "
    )
    para += nodes.literal(text=f"{name}.ipynb")
    para += nodes.Text(" and as ")
    para += nodes.literal(text=f"{name}.md")
    para += nodes.Text(
        ". To rebuild the whole book, with every chapter executed, run from the repository's root:"
    )
    box += para
    box += _literal("make book   # creates .venv from requirements.lock, then book/_build/html")
    para = nodes.paragraph()
    para += nodes.Text(
        "To run only this chapter, create the environment once, then open the downloaded "
        "notebook (it holds this page's outputs and numbers) in JupyterLab with the "
    )
    para += nodes.literal(text="python3")
    para += nodes.Text(" kernel of ")
    para += nodes.literal(text=".venv")
    para += nodes.Text(" (set ")
    para += nodes.literal(text="HSGEO_SCALE=small")
    para += nodes.Text(" for the reduced size the tests use):")
    box += para
    box += _literal(
        f"make venv\n.venv/bin/jupyter lab {name}.ipynb               # read and run it\n"
        f".venv/bin/jupyter execute --inplace {name}.ipynb   # or run it all"
    )
    if "install" in app.env.all_docs:
        para = nodes.paragraph()
        para += nodes.Text("To install the library elsewhere (with pip, or as a wheel from ")
        para += nodes.literal(text="make dist")
        para += nodes.Text(") and cite it, see ")
        para += nodes.reference(
            "",
            "Install hsgeo",
            internal=True,
            refuri=app.builder.get_relative_uri(docname, "install"),
        )
        para += nodes.Text(".")
        box += para
    para = nodes.paragraph()
    para += nodes.Text("Run time measured when this book was built: ")
    para += nodes.strong(text=_runtime_text(data))
    if data and data.get("mtime"):
        para += nodes.Text(f" (executed {_built_on(data)}, {_scale_text()}).")
    else:
        para += nodes.Text(".")
    box += para
    return box


def _insert_run_box(doctree: nodes.document, box: nodes.Node) -> None:
    section = next(iter(doctree.findall(nodes.section)), None)
    if section is None:
        doctree.insert(0, box)
        return
    index = 0
    for index, child in enumerate(section.children):  # noqa: B007
        if not isinstance(child, nodes.title | nodes.target):
            break
    section.insert(index, box)


# --- a module docstring as part of a page ------------------------------------------------

_PY_ROLE = re.compile(r":(?:py:)?(?:func|class|mod|data|meth|attr|obj|exc):`~?([^`]+)`")


class DocstringDirective(SphinxDirective):
    """``{hsgeo-docstring} module``: the module's docstring, parsed as reStructuredText.

    One source for text that belongs to the code (e.g. ``hsgeo.conventions``): the page shows
    the docstring rendered, not as printed source. Python cross-reference roles become literals
    (the book has no API pages to link to). ``:skip-paragraphs: N`` drops the first N
    paragraphs (the summary written for ``help()``).
    """

    required_arguments = 1
    option_spec = {"skip-paragraphs": directives.nonnegative_int}

    def run(self):
        from docutils.core import publish_doctree

        module = importlib.import_module(self.arguments[0])
        if module.__file__:
            self.env.note_dependency(module.__file__)
        text = _PY_ROLE.sub(r"``\1``", inspect.getdoc(module) or "")
        skip = self.options.get("skip-paragraphs", 0)
        if skip:
            text = "\n\n".join(text.split("\n\n")[skip:])
        doctree = publish_doctree(
            text,
            source_path=f"{self.arguments[0]}.__doc__",
            settings_overrides={"report_level": 5, "halt_level": 5, "file_insertion_enabled": 0},
        )
        problems = list(doctree.findall(nodes.system_message))
        if problems:
            raise self.error(
                f"the docstring of {self.arguments[0]} is not valid reStructuredText: "
                + problems[0].astext()
            )
        box = nodes.container(classes=["hsgeo-docstring"])
        box.extend(child.deepcopy() for child in doctree.children)
        return [box]


# --- glued values in running text -------------------------------------------------------

#: Mime types that make a glued value more than text (rendered by myst-nb as they are).
_RICH_MIME = ("text/html", "text/markdown", "text/latex", "image/", "application/")


class GluedTextAsText(SphinxPostTransform):
    """A cross-document inline ``{glue}`` of a text-only value becomes ``{glue:text}``.

    Runs before myst-nb's ``ReplacePendingGlueReferences`` (priority 5), which would render the
    value's text/plain as inline code.
    """

    default_priority = 4

    def apply(self, **kwargs) -> None:
        from myst_nb.ext.glue.crossref import read_glue_cache
        from myst_nb.ext.glue.utils import PendingGlueReference

        folder = self.env.mystnb_config.output_folder
        for node in list(self.document.findall(PendingGlueReference)):
            if not node.inline or node.gtype == "text":
                continue
            data = read_glue_cache(folder, node.refdoc).get(node.key, {}).get("data", {})
            if "text/plain" in data and not any(m.startswith(_RICH_MIME) for m in data):
                node["gtype"] = "text"
                node["fmt_spec"] = "s"


_QUOTE_PAIRS = ("''", '""', "\u2018\u2019", "\u201c\u201d")


def _glued_text_without_quotes(doctree: nodes.document) -> None:
    """A same-document inline ``{glue}`` of a string shows the string, not its repr."""
    from myst_nb.core.variables import format_plain_text

    for node in list(doctree.findall(nodes.inline)):
        classes = node.get("classes", [])
        if "text_plain" not in classes or "output" not in classes:
            continue
        if not isinstance(node.parent, nodes.TextElement):
            continue  # a cell's output, not running text
        text = node.astext()
        if len(text) >= 2 and text[0] + text[-1] in _QUOTE_PAIRS:
            text = text[1:-1]  # the repr's quotes (made typographic by smartquotes)
        else:
            text = format_plain_text(text, "s")
        # in place: replace_self would merge the old classes into the new node
        node.children = []
        node += nodes.Text(text)
        node["classes"] = ["pasted-text"]


#: Nodes whose text is code or math, kept as written.
_VERBATIM = (nodes.literal, nodes.literal_block, nodes.math, nodes.math_block, nodes.raw)


def _true_minus_signs(doctree: nodes.document) -> None:
    """Running text's numbers get a true minus sign (U+2212), as the tables have (glued values
    and sentences formatted with ``:+.2f`` wrote a hyphen); code, math and raw HTML keep theirs.
    """
    from hsgeo.report import true_minus  # the rule of hsgeo's tables, in one place

    for text in list(doctree.findall(nodes.Text)):
        if true_minus(text.astext()) == text.astext():
            continue
        parent = text.parent
        if parent is None or any(isinstance(a, _VERBATIM) for a in _ancestors(parent)):
            continue
        parent.replace(text, nodes.Text(true_minus(text.astext())))


def _ancestors(node: nodes.Node):
    while node is not None:
        yield node
        node = node.parent


#: An alt text that is a file's path or name (myst-nb's), not a description.
_PATH_LIKE = re.compile(r"^\S*[/\\]\S*$|\.(png|svg|jpe?g)$", re.IGNORECASE)


def _alt_from_captions(doctree: nodes.document) -> None:
    """Every image of a captioned figure without a real alt text (myst-nb writes the output's
    hashed file path) gets its caption as alt text, for screen readers and text browsers.
    """
    for figure in doctree.findall(nodes.figure):
        captions = list(figure.findall(nodes.caption))
        if not captions:
            continue
        text = re.sub(r"\s+", " ", captions[0].astext()).strip()
        for image in figure.findall(nodes.image):
            alt = image.get("alt", "")
            if not alt or alt == image.get("uri") or _PATH_LIKE.search(alt):
                image["alt"] = text


def _resolve(app: Sphinx, doctree: nodes.document, docname: str) -> None:
    _glued_text_without_quotes(doctree)
    _alt_from_captions(doctree)
    _true_minus_signs(doctree)
    for node in list(doctree.findall(RunTimesNode)):
        node.replace_self(_run_times_table(app, docname))
    if docname.startswith(CHAPTER_PREFIX) and app.builder.format == "html":
        _insert_run_box(doctree, _run_box(app, docname))


def _pages_with_run_times(app: Sphinx, env) -> list[str]:
    # The table changes when any chapter is (re-)executed: always rewrite the pages showing it.
    return [doc for doc, meta in env.metadata.items() if meta.get("hsgeo_run_times")]


def setup(app: Sphinx) -> dict:
    """Register the extension (Sphinx entry point)."""
    app.setup_extension("sphinx.ext.mathjax")
    app.add_node(RunTimesNode)
    app.add_directive("hsgeo-run-times", RunTimesDirective)
    app.add_directive("hsgeo-docstring", DocstringDirective)
    app.add_post_transform(GluedTextAsText)
    app.add_transform(RemoveSolutions)
    app.connect("config-inited", _use_local_mathjax)
    app.connect("config-inited", _version_footer)
    app.connect("config-inited", _student_edition)
    app.connect("build-finished", _copy_mathjax)
    app.connect("build-finished", _strip_sources)
    app.connect("html-page-context", _add_ipynb_download, priority=500)
    app.connect("doctree-resolved", _resolve)
    app.connect("env-updated", _pages_with_run_times)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
