"""The recipes of CONTRIBUTING.md, enforced: every registry is enumerated, so a step left out
fails here with the step named.

- chapters (:data:`hsgeo.reproduce.CHAPTERS`): each has its module with ``run(seed, scale)``, its
  page in the book's table of contents, its row in ``book/intro.md``, a page that takes its
  numbers from ``run("<name>", ...)``; every chapter page in the table of contents is registered;
  and a skeleton chapter, wired with the recipe's files only (at most five), is seen by
  ``hsgeo reproduce``, recorded, judged by the scoreboard and linked to its page;
- sensors (:data:`hsgeo.io.sensor_file.MODELS`): an example, a class in ``hsgeo.sensors``, the
  README names the model (the template itself is tests/test_sensor_registry.py);
- the README's tables: every command of ``hsgeo``, every module of the package in the layer
  table, every workflow there and in :mod:`hsgeo.workflows`' table.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import json
import pkgutil
import re
import shutil
import sys
from pathlib import Path

import pytest
import yaml

import hsgeo
import hsgeo.workflows
from hsgeo.io.sensor_file import MODELS
from hsgeo.reproduce import CHAPTERS, Chapter, chapter_names, paper_chapters

ROOT = Path(__file__).resolve().parents[1]
BOOK = ROOT / "book"
README = (ROOT / "README.md").read_text(encoding="utf-8")
CONTRIBUTING = (ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8")


def _toc_files(node) -> list[str]:
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


def wiring_problems(name: str, chapter: Chapter, book: Path = BOOK) -> list[str]:
    """What the chapter recipe still lacks for chapter ``name`` in the book at ``book``."""
    problems = []
    try:
        module = importlib.import_module(f"hsgeo.reproduce.{chapter.module}")
    except ImportError as exc:
        return [f"step 1: hsgeo.reproduce.{chapter.module} cannot be imported ({exc})"]
    run = getattr(module, "run", None)
    if run is None or list(inspect.signature(run).parameters)[:2] != ["seed", "scale"]:
        problems.append(f"step 1: hsgeo.reproduce.{chapter.module} has no run(seed, scale)")
    page = book / f"{chapter.page}.md"
    toc = yaml.safe_load((book / "_toc.yml").read_text(encoding="utf-8"))
    if not page.is_file():
        problems.append(f"step 3: no page {page.relative_to(book.parent)}")
    elif f'run("{name}"' not in page.read_text(encoding="utf-8"):
        problems.append(f'step 3: {chapter.page}.md does not call run("{name}", ...)')
    if chapter.page not in _toc_files(toc):
        problems.append(f"step 4: book/_toc.yml does not list {chapter.page}")
    if chapter.claims:
        intro = (book / "intro.md").read_text(encoding="utf-8")
        row = re.search(rf"^\| {re.escape(name)} \|.*$", intro, re.M)
        if row is None or f"{{doc}}`{chapter.page}`" not in row.group(0):
            problems.append(f"step 5: book/intro.md has no row for {name} linking {chapter.page}")
    return problems


# ---- chapters -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(CHAPTERS))
def test_every_registered_chapter_is_wired(name):
    assert wiring_problems(name, CHAPTERS[name]) == []


def test_every_chapter_page_of_the_toc_is_registered():
    toc = yaml.safe_load((BOOK / "_toc.yml").read_text(encoding="utf-8"))
    pages = {c.page for c in CHAPTERS.values()}
    unregistered = [f for f in _toc_files(toc) if f.startswith("chapters/") and f not in pages]
    assert not unregistered, f"add these pages to hsgeo.reproduce.CHAPTERS: {unregistered}"


def test_the_intro_lists_only_registered_chapters():
    intro = (BOOK / "intro.md").read_text(encoding="utf-8")
    table = intro[intro.index("| chapter | paper |") :].split("\n\n")[0]
    names = re.findall(r"^\| ([a-z0-9-]+) \|", table, re.M)[1:]  # after the header
    assert len(names) == len(set(names))
    assert set(names) == {n for n in CHAPTERS if CHAPTERS[n].page.startswith("chapters/")}


def test_a_wiring_check_fails_when_a_step_is_left_out(tmp_path):
    book = _book_copy(tmp_path)
    (book / "chapters" / "geocoding.md").unlink()
    toc = (book / "_toc.yml").read_text().replace("      - file: chapters/mtf\n", "")
    (book / "_toc.yml").write_text(toc)
    assert wiring_problems("geocoding", CHAPTERS["geocoding"], book)[0].startswith("step 3")
    assert wiring_problems("mtf", CHAPTERS["mtf"], book)[0].startswith("step 4")
    assert wiring_problems("asf", Chapter("no_such_module"), book)[0].startswith("step 1")


def _book_copy(tmp_path: Path) -> Path:
    book = tmp_path / "book"
    (book / "chapters").mkdir(parents=True)
    for name in ("_toc.yml", "intro.md"):
        shutil.copy(BOOK / name, book / name)
    for page in BOOK.glob("chapters/*.md"):
        shutil.copy(page, book / "chapters" / page.name)
    return book


def _recipe_files(section: str) -> list[str]:
    """The files of a recipe's numbered steps in CONTRIBUTING.md."""
    text = CONTRIBUTING.split(f"## {section}\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"^\d+\. `([^`]+)`", text, re.M)


SKELETON_MODULE = '''
from hsgeo.report import Reproduction, Row


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """A chapter reproducing one number of a paper, for the test (a chosen truth)."""
    row = Row(
        table="003 Table 9",
        quantity="c_mm",
        unit="mm",
        paper=8.7,
        paper_sigma=0.01,
        reproduced=8.71 + 1e-3 * seed,
        sigma=0.004,
        truth=8.71,
        provenance="chosen",
    )
    return Reproduction("skeleton", seed, [row])
'''


def test_a_skeleton_chapter_needs_five_files_and_everything_sees_it(tmp_path, monkeypatch, capsys):
    """Wire a chapter with the recipe's files only (in a temporary folder) and check that the
    command, the record, the scoreboard and its links all see it."""
    from hsgeo.cli import main
    from hsgeo.reproduce.scoreboard import claims_with_chapters, compact_table

    steps = _recipe_files("A chapter")
    assert 0 < len(steps) <= 5, steps
    book = _book_copy(tmp_path)
    edited = []
    for step in steps:
        path = step.replace("<module>", "skeleton")
        if path.startswith("src/hsgeo/reproduce/") and path.endswith("skeleton.py"):
            module_file = tmp_path / "skeleton.py"  # step 1: the chapter's module
            module_file.write_text(SKELETON_MODULE)
            spec = importlib.util.spec_from_file_location("hsgeo.reproduce.skeleton", module_file)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            monkeypatch.setitem(sys.modules, "hsgeo.reproduce.skeleton", module)
        elif path == "src/hsgeo/reproduce/__init__.py":  # step 2: the registry entry
            for other in list(CHAPTERS):  # (only the skeleton: the scoreboard runs no other)
                if other != "scoreboard":
                    monkeypatch.delitem(CHAPTERS, other)
            monkeypatch.setitem(CHAPTERS, "skeleton", Chapter("skeleton"))
        elif path == "book/chapters/skeleton.md":  # step 3: the page
            (book / "chapters" / "skeleton.md").write_text(
                '# A skeleton\n\n```{code-cell} ipython3\nrep = run("skeleton", seed=0)\n```\n'
            )
        elif path == "book/_toc.yml":  # step 4
            toc = (book / "_toc.yml").read_text()
            (book / "_toc.yml").write_text(
                toc.replace(
                    "      - file: chapters/asf\n",
                    "      - file: chapters/asf\n      - file: chapters/skeleton\n",
                )
            )
        elif path == "book/intro.md":  # step 5
            intro = (book / "intro.md").read_text()
            row = "| skeleton | 003 | a test | in this book ({doc}`chapters/skeleton`) |\n"
            i = intro.index("| asf |")
            (book / "intro.md").write_text(intro[:i] + row + intro[i:])
        else:
            pytest.fail(f"the chapter recipe names a file the skeleton does not know: {step}")
        edited.append(path)
    assert len(set(edited)) == len(steps)
    assert wiring_problems("skeleton", CHAPTERS["skeleton"], book) == []

    # the command knows it, runs it and records it
    assert "skeleton" in chapter_names() and paper_chapters() == ("skeleton",)
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    assert "skeleton" in capsys.readouterr().out
    monkeypatch.setenv("HSGEO_RECORD_DIR", str(tmp_path / "records"))
    assert main(["reproduce", "skeleton", "--seed", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["chapter"] == "skeleton" and out["rows"][0]["reproduced"] == pytest.approx(8.712)
    assert (tmp_path / "records" / "skeleton.json").is_file()

    # the scoreboard reads the record, judges the claim, and links it to the chapter's page
    assert main(["reproduce", "scoreboard", "--json"]) == 0
    board = json.loads(capsys.readouterr().out)
    assert board["meta"]["sources"]["skeleton"]["source"] == "recorded by the book build"
    assert [(r["table"], r["quantity"]) for r in board["rows"]] == [("003 Table 9", "c_mm")]
    assert board["rows"][0]["verdict"] == "reproduced"
    rep = module.run(seed=2)
    html = compact_table(claims_with_chapters({"skeleton": rep}))._repr_html_()
    assert 'href="chapters/skeleton.html"' in html


# ---- sensors --------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(MODELS))
def test_every_sensor_model_has_an_example_a_class_and_a_readme_entry(name):
    model = MODELS[name]
    assert model.example, f"{name}: the registry's template needs an example"
    assert model.cls.__module__.startswith("hsgeo.sensors."), model.cls
    assert model.kind in ("scanning", "frame")
    assert f"`{name}`" in README, f"README.md: name the sensor model `{name}`"


def test_the_sensor_recipe_names_the_registry():
    assert "hsgeo.io.sensor_file.MODELS" in CONTRIBUTING and _recipe_files("A sensor model")


# ---- the README's tables ----------------------------------------------------------------------
def test_the_readme_shows_every_command():
    from hsgeo.cli_parsers import SUBCOMMANDS

    for handler, _ in SUBCOMMANDS:
        command = handler.removeprefix("_cmd_").replace("_", "-")
        assert f"hsgeo {command}" in README, f"README.md does not show `hsgeo {command}`"


def _layer_table() -> str:
    return README[README.index("| layer | modules | may use |") :].split("\n\n")[0]


def test_the_readme_layer_table_names_every_module():
    table = _layer_table()
    for info in pkgutil.iter_modules(hsgeo.__path__):
        if info.name == "data":
            continue
        spelled = f"`{info.name}/`" if info.ispkg else f"`{info.name}`"
        assert spelled in table, f"README.md's layer table does not name {spelled}"


def test_every_workflow_is_in_both_tables():
    row = next(line for line in _layer_table().splitlines() if line.startswith("| pipelines"))
    listed = set(re.search(r"`workflows/` \(([^)]*)\)", row).group(1).split(", "))
    doc_table = set(re.findall(r"^``(\w+)``", hsgeo.workflows.__doc__, re.M))
    public = {m.name for m in pkgutil.iter_modules(hsgeo.workflows.__path__) if m.name[0] != "_"}
    assert listed == public, "README.md's pipelines row against hsgeo/workflows/"
    assert doc_table == public, "hsgeo.workflows' table against hsgeo/workflows/"


def test_contributing_is_linked_from_the_readme():
    assert "CONTRIBUTING.md" in README


def test_the_readme_lists_every_make_target():
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    targets = re.findall(r"^([a-z][a-z-]*):.*## ", makefile, re.M)
    assert "test" in targets
    missing = [t for t in targets if f"| `make {t}` |" not in README]
    assert not missing, f"README.md's Targets table lacks: {missing}"
