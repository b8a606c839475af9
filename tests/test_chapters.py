"""Execute every chapter of the book (GUIDE §6, kind 6).

The chapters are the MyST Markdown notebooks listed in ``book/_toc.yml``. Each one is read with
jupytext and executed with nbclient in its own directory, at reduced size
(``HSGEO_SCALE=small``), one test per chapter. Pages without code cells are skipped. A failing
cell fails the test with the cell's source and traceback in the message.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest
import yaml

jupytext = pytest.importorskip("jupytext")
nbclient = pytest.importorskip("nbclient")
import nbformat  # noqa: E402
import repro_cache  # noqa: E402
from nbclient.exceptions import CellExecutionError  # noqa: E402

from hsgeo.reproduce import chapter_names  # noqa: E402

BOOK = Path(__file__).resolve().parents[1] / "book"
TIMEOUT_S = 1800
SUFFIXES = (".md", ".ipynb")
_ANSI = re.compile(r"\x1b\[[0-9;]*m")
# run first in each chapter's kernel: hsgeo.reproduce.run shares its results with the tests,
# and a kernel another process of the session is compiling is waited for, not compiled again
SHARE_CELL = (
    f"import sys\nsys.path.insert(0, {str(Path(__file__).resolve().parent)!r})\n"
    "import compile_lock, repro_cache\ncompile_lock.install()\nrepro_cache.install()\n"
    "del sys.path[0]"
)


def _toc_files(node) -> list[str]:
    """All ``file:`` entries of a sphinx-external-toc tree, in order."""
    found: list[str] = []
    if isinstance(node, dict):
        if "file" in node:
            found.append(node["file"])
        for key in ("parts", "chapters", "sections"):
            for child in node.get(key, []) or []:
                found.extend(_toc_files(child))
    elif isinstance(node, list):
        for child in node:
            found.extend(_toc_files(child))
    return found


def _resolve(entry: str) -> Path:
    path = BOOK / entry
    if path.suffix in SUFFIXES and path.is_file():
        return path
    for suffix in SUFFIXES:
        candidate = path.with_name(path.name + suffix)
        if candidate.is_file():
            return candidate
    raise FileNotFoundError(f"book/_toc.yml lists {entry!r}, but no {entry}.md exists in book/")


def _read(path: Path):
    # MyST for .md pages: only {code-cell} directives are code, never a fenced example.
    return jupytext.read(path, fmt="md:myst" if path.suffix == ".md" else None)


def _has_code_cells(path: Path) -> bool:
    nb = _read(path)
    return any(cell.cell_type == "code" for cell in nb.cells)


def _chapters() -> list[Path]:
    toc = yaml.safe_load((BOOK / "_toc.yml").read_text(encoding="utf-8"))
    entries = [toc["root"], *_toc_files(toc)]
    return [_resolve(entry) for entry in entries]


CHAPTERS = _chapters()


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_executes(
    path: Path,
    monkeypatch: pytest.MonkeyPatch,
    tmp_path_factory: pytest.TempPathFactory,
    repro_cache_dir: Path,
) -> None:
    if not _has_code_cells(path):
        pytest.skip(f"{path.relative_to(BOOK)} has no code cells")
    # The kernel inherits this process's environment: reduced size, headless plotting,
    # one BLAS thread (as in the Makefile).
    monkeypatch.setenv("HSGEO_SCALE", "small")
    # as in `make book`: chapters record their results, the scoreboard (last in the toc) reads them
    records = tmp_path_factory.getbasetemp() / "reproduce"
    monkeypatch.setenv("HSGEO_RECORD_DIR", str(records))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")
    # a chapter run that a test also runs (same seed and scale) is computed once per session
    # (tests/repro_cache.py)
    monkeypatch.setenv(repro_cache.ENV, str(repro_cache_dir))
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        if var not in os.environ:
            monkeypatch.setenv(var, "1")

    nb = _read(path)
    nb.cells.insert(0, nbformat.v4.new_code_cell(SHARE_CELL))
    client = nbclient.NotebookClient(
        nb,
        timeout=TIMEOUT_S,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
    )
    failure = None
    try:
        client.execute()
    except CellExecutionError as err:
        failure = _ANSI.sub("", str(err))  # the cell's source, output and traceback
    if failure is not None:
        pytest.fail(f"{path.relative_to(BOOK)}: a cell failed\n{failure}", pytrace=False)
    # a chapter gets its numbers through hsgeo.reproduce.run(chapter, ...), which records them
    # for the scoreboard page (otherwise the scoreboard computes the chapter a second time)
    chapter = path.stem.replace("_", "-")
    if path.parent.name == "chapters" and chapter in chapter_names():
        assert (records / f"{chapter}.json").is_file(), (
            f"{path.relative_to(BOOK)} does not call hsgeo.reproduce.run({chapter!r}, ...)"
        )
        # issue 22 (GUIDE §4): every row with a verdict says where its truth comes from
        rows = json.loads((records / f"{chapter}.json").read_text(encoding="utf-8"))["rows"]
        missing = [r["quantity"] for r in rows if r["verdict"] and not r.get("provenance")]
        assert not missing, f"{chapter}: verdict rows without a provenance: {missing[:5]}"
