"""CITATION.cff (issue 28): the fields Citation File Format 1.2.0 requires, and the version of
the package. (Checked once against the CFF 1.2.0 schema with ``cffconvert --validate`` 2.0.0;
the schema is not installed in the project's environment.)"""

from __future__ import annotations

import tomllib
from pathlib import Path

import yaml

import hsgeo

ROOT = Path(__file__).resolve().parents[1]


def test_citation_cff_has_the_required_fields_and_the_package_version():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors"):
        assert cff[key], key
    assert all("name" in a or "family-names" in a for a in cff["authors"])
    assert cff["type"] == "software"
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert cff["version"] == hsgeo.__version__ == pyproject["project"]["version"]
    assert cff["license"] == "BSD-3-Clause"
