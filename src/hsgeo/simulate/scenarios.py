"""The scenarios of ``data_synthetic/*.toml``: where they are and how to load them.

Each ``data_synthetic/<name>.toml`` has a ``[scenario]`` table with ``generator`` (the simulator
it configures, a key of :data:`SCENARIOS`) and, if that simulator writes files
(:mod:`hsgeo.reproduce.data`, which writes ``data_synthetic/generated/``), their ``seed``; the
rest of the file is the scenario's configuration, every value citing its source. A chapter's
in-memory scenario (the 002 campaign and its LP ground, the 004 runway, the 001 survey and
bench) is such a file too, read by its chapter. :func:`load_scenario` reads it into the frozen
dataclass of its generator (:data:`SCENARIOS`) with the one loader of configurations,
:func:`hsgeo.io.config.read_dataclass` (unknown keys are errors with a suggestion); change a
value with :func:`dataclasses.replace`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path

from hsgeo.errors import InputError

__all__ = ["data_dir", "load_scenario", "scenario_class", "ScenarioInfo", "SCENARIOS"]

#: scenario generator name -> ``"module:Class"``: the frozen dataclass its file is read into.
SCENARIOS = {
    "asf_runway": "hsgeo.simulate.asf_runway:AsfRunwayScenario",
    "cube_survey": "hsgeo.simulate.cube_survey:CubeSurveyScenario",
    "frame_bench": "hsgeo.simulate.frame_bench:FrameBenchScenario",
    "line_lab": "hsgeo.simulate.line_lab:LineLabScenario",
    "lp_campaign": "hsgeo.simulate.scenario_lp_campaign:LpCampaignScenario",
    "mtf_bench": "hsgeo.simulate.mtf_target:MtfBenchScenario",
    "pula_flight": "hsgeo.simulate.pula_flight:PulaFlightScenario",
    "pushbroom_campaign": "hsgeo.simulate.pushbroom_campaign_types:PushbroomCampaignScenario",
    "rikola": "hsgeo.simulate.rikola:RikolaBenchScenario",
}


@dataclass(frozen=True)
class ScenarioInfo:
    """The ``[scenario]`` table of every scenario file.

    Attributes
    ----------
    generator : str
        Which simulator the file configures (a key of :data:`SCENARIOS`).
    seed : int, optional
        Seed of the data that ``make data`` writes (required of a scenario whose generator
        writes files, :data:`hsgeo.reproduce.data.GENERATORS`); a chapter's scenario, which
        writes none, takes its seed from ``hsgeo reproduce --seed``.
    """

    generator: str
    seed: int | None = None


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


def scenario_class(generator: str) -> type:
    """The frozen dataclass of a generator's scenario files (:data:`SCENARIOS`)."""
    from hsgeo.io.config import did_you_mean

    if generator not in SCENARIOS:
        raise InputError(
            f"unknown scenario generator {generator!r}{did_you_mean(generator, SCENARIOS)} "
            f"(known: {', '.join(SCENARIOS)})"
        )
    module, name = SCENARIOS[generator].split(":")
    return getattr(importlib.import_module(module), name)


def load_scenario(name: str):
    """The configuration of ``data_synthetic/<name>.toml``: a frozen dataclass of its
    generator (:data:`SCENARIOS`), read by :func:`hsgeo.io.config.read_dataclass`.
    """
    path = data_dir() / f"{name}.toml"
    if not path.is_file():
        known = sorted(p.stem for p in data_dir().glob("*.toml"))
        raise InputError(f"no scenario {name!r} in {data_dir()}; known: {known}")
    from hsgeo.io.config import load_dataclass, read_toml

    raw = read_toml(path, "scenario")
    info = raw.get("scenario")
    if not isinstance(info, dict) or not isinstance(info.get("generator"), str):
        raise InputError(
            f"scenario file {path}: missing [scenario] table with a 'generator' entry; add "
            f"[scenario] generator = one of {', '.join(repr(g) for g in SCENARIOS)}"
        )
    where = f"scenario file {path}"
    try:
        cls = scenario_class(info["generator"])
    except InputError as exc:
        raise InputError(f"{where}: [scenario] generator: {exc}") from None
    return load_dataclass(cls, raw, where)
