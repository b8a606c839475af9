"""The scenarios of ``data_synthetic/*.toml``: where they are and how to load them.

Each ``data_synthetic/<name>.toml`` has a ``[scenario]`` table with ``generator`` (see
:mod:`hsgeo.reproduce.data`, which writes ``data_synthetic/generated/``) and ``seed``; the rest of
the file is the scenario's configuration, every value citing its source.
"""

from __future__ import annotations

from pathlib import Path

from hsgeo.errors import InputError

__all__ = ["data_dir", "load_scenario"]


def data_dir() -> Path:
    """The scenarios' folder: the repository's ``data_synthetic/`` (found from the working
    directory or, for an editable install, from the package's source tree), else the copy an
    installed wheel carries in ``hsgeo/data/scenarios`` (``setup.py``), so ``hsgeo reproduce``
    and ``hsgeo data`` work from any folder. A folder counts only if it holds scenario TOMLs (a
    ``./data_synthetic/generated`` written by ``hsgeo data`` outside the repository is not one).
    """
    here = Path(__file__).resolve()
    packaged = here.parents[1] / "data" / "scenarios"
    for base in [Path.cwd(), *Path.cwd().parents, here.parents[3]]:
        d = base / "data_synthetic"
        if d.is_dir() and any(d.glob("*.toml")):
            return d
    if packaged.is_dir() and any(packaged.glob("*.toml")):
        return packaged
    raise InputError(
        "data_synthetic/ not found and this hsgeo was installed without its scenarios "
        f"({packaged}): reinstall it from a wheel built by `make dist`, or run from the hsgeo "
        "repository"
    )


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
