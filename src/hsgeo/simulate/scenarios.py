"""``make data``: generate ``data_synthetic/generated/`` from the scenario TOMLs, bit for bit.

Each ``data_synthetic/<name>.toml`` has a ``[scenario]`` table with ``generator`` (a module under
``hsgeo.simulate`` with a ``generate(config: dict, outdir: Path) -> list[Path]`` function) and
``seed``; the rest of the file is the scenario's configuration, every value citing its source.
The SHA-256 of every generated file is listed in ``data_synthetic/MANIFEST.sha256``; ``--verify``
fails when a file differs, which shows a reader that the data are reproducible bit for bit.
Generated files are text (CSV with ``%.17g``) so that they are byte-identical across runs.
"""

from __future__ import annotations

import hashlib
import importlib
import sys
from pathlib import Path

from hsgeo.errors import InputError

__all__ = ["data_dir", "load_scenario", "generate_all"]


def data_dir() -> Path:
    """The repository's ``data_synthetic/`` (found from the working directory or the package)."""
    for base in [Path.cwd(), *Path.cwd().parents, Path(__file__).resolve().parents[3]]:
        d = base / "data_synthetic"
        if d.is_dir():
            return d
    raise InputError("data_synthetic/ not found: run from the hsgeo repository")


def load_scenario(name: str) -> dict:
    """The configuration of ``data_synthetic/<name>.toml`` as a dict."""
    path = data_dir() / f"{name}.toml"
    if not path.is_file():
        known = sorted(p.stem for p in data_dir().glob("*.toml"))
        raise InputError(f"no scenario {name!r} in {data_dir()}; known: {known}")
    from hsgeo.io import read_toml

    cfg = read_toml(path, "scenario")
    if "scenario" not in cfg or "generator" not in cfg["scenario"]:
        raise InputError(f"{path}: missing [scenario] table with a 'generator' entry")
    return cfg


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def generate_all(verify: bool = False, update: bool = False) -> int:
    """Generate every scenario; compare with (or rewrite) the manifest. Returns an exit status."""
    ddir = data_dir()
    out = ddir / "generated"
    out.mkdir(exist_ok=True)
    sums: dict[str, str] = {}
    for toml in sorted(ddir.glob("*.toml")):
        cfg = load_scenario(toml.stem)
        mod = importlib.import_module(f"hsgeo.simulate.{cfg['scenario']['generator']}")
        for path in mod.generate(cfg, out):
            sums[str(path.relative_to(ddir))] = _sha256(path)
            print(f"  generated {path.relative_to(ddir.parent)}", file=sys.stderr)
    manifest = ddir / "MANIFEST.sha256"
    text = "".join(f"{h}  {p}\n" for p, h in sorted(sums.items()))
    if update or not manifest.exists():
        manifest.write_text(text)
        print(f"wrote {manifest} ({len(sums)} files)", file=sys.stderr)
        return 0
    expected = {}
    for line in manifest.read_text().splitlines():
        h, p = line.split(maxsplit=1)
        expected[p] = h
    bad = [p for p in sorted(set(expected) | set(sums)) if expected.get(p) != sums.get(p)]
    if bad:
        print("data_synthetic: generated files differ from MANIFEST.sha256: " + ", ".join(bad)
              + "\n  (if the change is deliberate: hsgeo data --update-manifest)", file=sys.stderr)
        return 1 if verify else 0
    print(f"data_synthetic: {len(sums)} files match MANIFEST.sha256", file=sys.stderr)
    return 0
