"""The wheel is the product too (issue 42): every third-party import of ``src/hsgeo`` is a
declared dependency, and the wheel carries the scenarios and instrument files that ``hsgeo
reproduce`` and ``hsgeo data`` read, so they work from any folder.

``make check-wheel`` (CI) installs the wheel alone into a fresh venv and runs the README's
commands from an empty folder; these tests are its quick part.
"""

from __future__ import annotations

import ast
import importlib.metadata as md
import re
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "hsgeo"

#: imports that only the book's chapters reach (hsgeo.report.glue_*), declared in the ``book``
#: extra: module -> extra.
OPTIONAL = {"myst_nb": "book", "IPython": "book"}
#: packages used by name rather than imported: (pattern in the source, distribution). xarray
#: loads ``engine="h5netcdf"`` itself, pandas loads pyarrow for Parquet.
USED_BY_NAME = [
    (re.compile(r"""engine\s*=\s*["']h5netcdf["']"""), "h5netcdf"),
    (re.compile(r"""engine\s*=\s*["']h5netcdf["']"""), "h5py"),
    (re.compile(r"\b(read|to)_parquet\b"), "pyarrow"),
]


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _requirement_name(req: str) -> str:
    return _norm(re.split(r"[<>=!~ ;\[]", req.strip(), maxsplit=1)[0])


def _declared() -> tuple[set[str], dict[str, set[str]]]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    deps = {_requirement_name(r) for r in project["dependencies"]}
    extras = {
        k: {_requirement_name(r) for r in v}
        for k, v in project.get("optional-dependencies", {}).items()
    }
    return deps, extras


def _top_level_imports() -> dict[str, set[str]]:
    """Top-level module -> files importing it, every import in src/hsgeo (inside functions too)."""
    found: dict[str, set[str]] = {}
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            for name in names:
                top = name.split(".")[0]
                if top not in sys.stdlib_module_names and top != "hsgeo":
                    found.setdefault(top, set()).add(str(path.relative_to(ROOT)))
    return found


def test_every_third_party_import_is_a_declared_dependency():
    deps, extras = _declared()
    dists = md.packages_distributions()
    undeclared = []
    for module, files in sorted(_top_level_imports().items()):
        assert module in dists, f"{module} (imported in {sorted(files)}) is not installed"
        owners = {_norm(d) for d in dists[module]}
        allowed = deps | extras.get(OPTIONAL.get(module, ""), set())
        if not owners & allowed:
            undeclared.append(f"{module} ({'/'.join(sorted(owners))}) in {sorted(files)[:3]}")
    assert not undeclared, "imported but not in pyproject.toml's dependencies: " + "; ".join(
        undeclared
    )


def test_packages_used_by_name_are_declared():
    deps, _ = _declared()
    text = "\n".join(p.read_text() for p in SRC.rglob("*.py"))
    missing = sorted({dist for pattern, dist in USED_BY_NAME if pattern.search(text)} - deps)
    assert not missing, f"used through xarray/pandas but not declared: {missing}"


def test_every_declared_dependency_is_pinned_in_the_lock_and_environment():
    deps, _ = _declared()
    lock = {
        _requirement_name(line)
        for line in (ROOT / "requirements.lock").read_text().splitlines()
        if line and not line.startswith("#")
    }
    assert deps <= lock, f"not pinned in requirements.lock: {sorted(deps - lock)}"
    env = (ROOT / "environment.yml").read_text()
    # the environment installs the whole lock; the packages hsgeo imports itself are also named
    for dist in ("h5netcdf", "pykdtree", "pillow", "affine"):
        assert dist in env, f"{dist} not named in environment.yml"


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("dist")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--quiet", "--disable-pip-version-check"]
        + ["--no-deps", "--no-build-isolation", "-w", str(out), str(ROOT)],
        check=True,
        capture_output=True,
    )
    (whl,) = out.glob("hsgeo-*.whl")
    return whl


def test_the_wheel_carries_the_scenarios_and_instruments(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    scen = ROOT / "data_synthetic"
    expected = [f"hsgeo/data/scenarios/{p.name}" for p in scen.glob("*.toml")]
    expected += ["hsgeo/data/scenarios/MANIFEST.sha256"]
    expected += [f"hsgeo/data/scenarios/generated/{p.name}" for p in (scen / "generated").iterdir()]
    expected += [
        f"hsgeo/data/{p.relative_to(SRC / 'data')}"
        for p in (SRC / "data").rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    ]
    missing = sorted(set(expected) - names)
    assert not missing, f"not in {wheel.name}: {missing}"


def test_scenarios_found_in_the_package_outside_the_repository(tmp_path, monkeypatch):
    """Outside the repository (and without the source tree) ``data_dir`` is the wheel's copy."""
    from hsgeo.simulate import scenarios

    pkg = tmp_path / "site" / "hsgeo"
    (pkg / "simulate").mkdir(parents=True)
    (pkg / "data" / "scenarios").mkdir(parents=True)
    (pkg / "data" / "scenarios" / "pula_flight.toml").write_text(
        (ROOT / "data_synthetic" / "pula_flight.toml").read_text()
    )
    fake = pkg / "simulate" / "scenarios.py"
    fake.write_text("")
    empty = tmp_path / "empty"
    empty.mkdir()
    monkeypatch.chdir(empty)
    monkeypatch.setattr(scenarios, "__file__", str(fake))
    assert scenarios.data_dir() == pkg / "data" / "scenarios"
    assert scenarios.load_scenario("pula_flight").scenario.generator == "pula_flight"
    (pkg / "data" / "scenarios" / "pula_flight.toml").unlink()
    with pytest.raises(scenarios.InputError, match="make dist"):
        scenarios.data_dir()


def test_scale_option_message_names_the_range():
    from hsgeo.cli import main

    with pytest.raises(SystemExit) as e:
        main(["reproduce", "mtf", "--scale", "small"])
    assert e.value.code == 2


def test_scale_message_text(capsys):
    from hsgeo.cli import main

    with pytest.raises(SystemExit):
        main(["reproduce", "mtf", "--scale", "small"])
    err = capsys.readouterr().err
    assert "in (0, 1]" in err and "-inf" not in err, err
