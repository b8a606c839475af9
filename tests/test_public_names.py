"""``__all__`` complete: every public module of hsgeo has an ``__all__`` that lists every public
name the module defines at its top level (a function, a class, a constant — whatever does not
start with ``_``), and names nothing that does not exist. A name that is not for users starts
with ``_``; a module whose name starts with ``_`` is private as a whole.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

import hsgeo

PACKAGE = Path(hsgeo.__file__).resolve().parent


def _modules() -> list[tuple[str, Path]]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if any(p.startswith("_") and p != "__init__" for p in parts):
            continue  # a private module (or inside one)
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out.append((name, path))
    return out


def defined_names(source: str) -> list[str]:
    """The public names a module's top level defines (def, class, assignment)."""
    names: list[str] = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.append(node.target.id)
    return [n for n in dict.fromkeys(names) if not n.startswith("_")]


MODULES = _modules()


@pytest.mark.parametrize(("name", "path"), MODULES, ids=[m for m, _ in MODULES])
def test_all_lists_every_public_name(name, path):
    module = importlib.import_module(name)
    listed = getattr(module, "__all__", None)
    assert listed is not None, f"{name} has no __all__"
    missing = [n for n in defined_names(path.read_text(encoding="utf-8")) if n not in listed]
    assert not missing, f"{name}: add to __all__ (or rename with a leading _): {missing}"
    absent = [n for n in listed if not hasattr(module, n)]
    assert not absent, f"{name}.__all__ names what the module does not have: {absent}"
    assert len(set(listed)) == len(listed), f"{name}.__all__ lists a name twice"


def test_the_check_sees_every_kind_of_definition():
    src = "import os\nA = 1\nB: int = 2\n_c = 3\ndef f(): pass\nclass K: pass\nx, y = 1, 2\n"
    assert defined_names(src) == ["A", "B", "f", "K", "x", "y"]


#: Modules whose ``__all__`` re-exports names a sibling module defines: a package's facade
#: (its ``__init__``) only. A module split in two keeps no re-export of the other's names.
FACADES = {
    "hsgeo",
    "hsgeo.adjust",
    "hsgeo.distortion",
    "hsgeo.io",
    "hsgeo.nist",
    "hsgeo.sensors",
}


@pytest.mark.parametrize(("name", "path"), MODULES, ids=[m for m, _ in MODULES])
def test_no_module_re_exports_a_sibling_s_name(name, path):
    """One import path per name: a module's ``__all__`` lists what it defines (or what a private
    module of its own defines), never a public sibling's name, except the facades above."""
    if name in FACADES:
        return
    module = importlib.import_module(name)
    foreign = []
    for n in getattr(module, "__all__", []):
        obj = getattr(module, n)
        if not (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue  # a constant: its type's module is not its home
        home = obj.__module__
        if not isinstance(home, str) or not home.startswith("hsgeo") or home == name:
            continue
        if not any(p.startswith("_") for p in home.split(".")):  # a private module's is its own
            foreign.append(f"{n} (from {home})")
    assert not foreign, f"{name}.__all__ re-exports: {foreign}; import them from their module"


def re_exported(source: str, listed) -> list[str]:
    """Names of ``listed`` (a module's ``__all__``) that the module binds by a top-level
    ``from hsgeo.<public module> import name``: a second import path (constants included)."""
    out = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("hsgeo"):
            if any(p.startswith("_") for p in node.module.split(".")):
                continue  # a private module's names are its importer's own
            out += [
                f"{a.name} (from {node.module})"
                for a in node.names
                if (a.asname or a.name) in listed
            ]
    return out


@pytest.mark.parametrize(("name", "path"), MODULES, ids=[m for m, _ in MODULES])
def test_no_module_re_exports_an_imported_name(name, path):
    """The import statements themselves: a constant (``R_ENU_FROM_NED``) re-exported by a module
    is a second import path as much as a function is (the check above sees classes and functions
    only)."""
    if name in FACADES:
        return
    listed = getattr(importlib.import_module(name), "__all__", [])
    again = re_exported(path.read_text(encoding="utf-8"), listed)
    assert not again, f"{name}.__all__ re-exports {again}; import them from their module"


def test_the_import_check_sees_a_re_exported_constant():
    src = "from hsgeo.rotations import R_ENU_FROM_NED\nfrom hsgeo._kernels import k\nA = 1\n"
    assert re_exported(src, ["R_ENU_FROM_NED", "k", "A"]) == [
        "R_ENU_FROM_NED (from hsgeo.rotations)"
    ]


#: The first author of each paper, as a References entry names it.
FIRST_AUTHOR = {
    "000": "Miljković",
    "001": "Krtalić",
    "002": "Jonassen",
    "003": "Tommaselli",
    "004": "Meister",
}
_CITE = re.compile(r"(?<![\w.])(00[0-4])(?=[ ,;:)'’]|$)", re.M)


def _cited(package: str) -> list[tuple[str, str, list[str]]]:
    """``(module, name, papers)`` of every public class and function of ``package``'s modules
    whose docstring cites a paper (``000`` … ``004``)."""
    pkg = importlib.import_module(package)
    out = []
    for info in pkgutil.iter_modules(pkg.__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{package}.{info.name}")
        for n in module.__all__:
            obj = getattr(module, n)
            if (inspect.isclass(obj) or inspect.isfunction(obj)) and (
                obj.__module__ == module.__name__
            ):
                papers = sorted(set(_CITE.findall(inspect.getdoc(obj) or "")))
                if papers:
                    out.append((module.__name__, n, papers))
    return out


CITED = _cited("hsgeo.workflows") + _cited("hsgeo.sensors")


@pytest.mark.parametrize(("module", "name", "papers"), CITED, ids=[f"{m}.{n}" for m, n, _ in CITED])
def test_a_docstring_citing_a_paper_has_its_references(module, name, papers):
    doc = inspect.getdoc(getattr(importlib.import_module(module), name))
    assert "References\n----------" in doc, f"{module}.{name}: add a numpydoc References section"
    refs = doc.split("References\n----------", 1)[1].split("\n\n")[0]
    for p in papers:
        assert FIRST_AUTHOR[p] in refs and f"(paper {p})" in refs, (module, name, p)
