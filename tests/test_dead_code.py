"""No dead names: vulture finds nothing unused in src/hsgeo beyond its whitelist, and every
whitelisted name is still used by the file its line names (a whitelist cannot go stale).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
WHITELIST = ROOT / "vulture_whitelist.py"
ENTRY = re.compile(r"^(_\.)?(\w+)  # ([\w./-]+): \S.*$")


def _entries() -> list[tuple[bool, str, str]]:
    """``(attribute?, name, file)`` of every whitelist line (after the module docstring)."""
    body = WHITELIST.read_text(encoding="utf-8").split('"""', 2)[2]
    out = []
    for line in body.splitlines():
        if line.strip() and not line.startswith("#"):
            m = ENTRY.match(line)
            assert m, f"vulture_whitelist.py: write 'name  # file: reason', got {line!r}"
            out.append((bool(m.group(1)), m.group(2), m.group(3)))
    return out


SRC = "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "src/hsgeo").rglob("*.py"))


def entry_problem(attribute: bool, name: str, path: str) -> str | None:
    """Why a whitelist line is wrong, or None."""
    if not re.search(rf"\b{name}\b", SRC):
        return f"{name} is no longer in src/hsgeo: drop its line"
    if not (ROOT / path).is_file():
        return f"{path} does not exist"
    text = (ROOT / path).read_text(encoding="utf-8")
    # reflection: the protocol's or the registry's file names it; outside the package: an
    # attribute read, a name called or imported
    use = rf"\.{name}\b" if attribute and not path.startswith("src/") else rf"\b{name}\b"
    if not re.search(use, text):
        return f"{path} does not use {name}: delete the name, or say who uses it"
    return None


def test_vulture_finds_no_dead_name():
    run = subprocess.run(
        [sys.executable, "-m", "vulture", "src/hsgeo", str(WHITELIST), "--min-confidence", "60"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0 and not run.stdout, (
        "unused names (delete them, or whitelist a name used by reflection or only by the "
        f"tests, bench or book in vulture_whitelist.py with the file using it):\n{run.stdout}"
        f"{run.stderr}"
    )


@pytest.mark.parametrize("attribute,name,path", _entries(), ids=lambda x: str(x))
def test_every_whitelisted_name_is_used_where_its_line_says(attribute, name, path):
    assert entry_problem(attribute, name, path) is None


def test_a_stale_whitelist_line_is_caught():
    assert "does not use" in entry_problem(True, "n_groups", "tests/test_engine.py")
    assert "no longer in src" in entry_problem(False, "image_mm_gone", "tests/test_engine.py")
    assert "does not exist" in entry_problem(False, "run", "tests/no_such_file.py")
