"""The one configuration loader (hsgeo.io.config.read_dataclass): a frozen dataclass is the
schema of a TOML file; every scenario file is read into its dataclass."""

import dataclasses
import shutil
from dataclasses import dataclass, field

import pytest

from hsgeo import InputError
from hsgeo.io.config import Key, load_dataclass, read_dataclass
from hsgeo.simulate.scenarios import SCENARIOS, data_dir, load_scenario, scenario_class


@dataclass(frozen=True)
class _Flight:
    height_agl_m: float
    speed_m_s: float = 15.0
    start_EN_m: tuple[float, ...] = field(
        default=(0.0, 0.0), metadata={"key": Key("floats", length=2)}
    )
    gcp_id: tuple[int, ...] = ()
    n_lines: int = field(default=10, metadata={"key": Key("int", positive=True)})
    reverse: bool = False


@dataclass(frozen=True)
class _Noise:
    sigma_px: float = 0.3


@dataclass(frozen=True)
class _Scenario:
    flight: _Flight
    noise: _Noise = _Noise()
    drift: _Noise | None = None
    name: str = "x"


def _write(tmp_path, text):
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_a_file_becomes_its_frozen_dataclass_with_the_defaults(tmp_path):
    p = _write(tmp_path, "[flight]\nheight_agl_m = 1000\ngcp_id = [2, 3]\nreverse = true\n")
    s = read_dataclass(p, _Scenario, "scenario file")
    assert s == _Scenario(_Flight(1000.0, gcp_id=(2, 3), reverse=True))
    assert isinstance(s.flight.height_agl_m, float) and s.flight.start_EN_m == (0.0, 0.0)
    assert s.noise == _Noise() and s.drift is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.flight.speed_m_s = 1.0  # type: ignore[misc]
    assert read_dataclass(
        _write(tmp_path, "[flight]\nheight_agl_m = 1.0\n[drift]\nsigma_px = 2.0\n"), _Scenario
    ).drift == _Noise(2.0)


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            "[flight]\nheigth_agl_m = 1.0\n",
            "[flight] heigth_agl_m: unknown key; did you mean 'height_agl_m'?",
        ),
        (
            "[flight]\nheight_agl_m = 1.0\n[noize]\nsigma_px = 1.0\n",
            "[noize]: unknown table; did you mean 'noise'?",
        ),
        ("[noise]\nsigma_px = 1.0\n", "[flight] height_agl_m: missing"),
        ('[flight]\nheight_agl_m = "high"\n', "[flight] height_agl_m: expected a number"),
        ("[flight]\nheight_agl_m = 1e12\n", "[flight] height_agl_m: 1000000000000.0 is outside"),
        ("[flight]\nheight_agl_m = 1.0\nstart_EN_m = [1.0]\n", "start_EN_m: needs 2 numbers"),
        ("[flight]\nheight_agl_m = 1.0\ngcp_id = [1.5]\n", "gcp_id[0]: expected a whole number"),
        ("[flight]\nheight_agl_m = 1.0\nn_lines = 0\n", "n_lines: must be positive"),
        ("[flight]\nheight_agl_m = 1.0\nreverse = 1\n", "reverse: expected true or false"),
        ("flight = 3\n", "flight: must be a table [flight]"),
        ("[flight]\nheight_agl_m = nan\n", "height_agl_m: must be a finite number"),
    ],
)
def test_every_problem_names_the_file_and_the_key(tmp_path, text, needle):
    p = _write(tmp_path, text)
    with pytest.raises(InputError) as e:
        read_dataclass(p, _Scenario, "scenario file")
    msg = str(e.value)
    assert msg.startswith(f"scenario file {p}: ") and needle in msg, msg


def test_all_problems_at_once():
    with pytest.raises(InputError) as e:
        load_dataclass(_Scenario, {"flight": {"heigt_agl_m": 1.0, "speed_m_s": "x"}}, "f.toml")
    msg = str(e.value)
    assert "heigt_agl_m: unknown key" in msg and "speed_m_s: expected a number" in msg
    assert "height_agl_m: missing" in msg


def test_every_scenario_file_loads_into_its_dataclass():
    stems = sorted(p.stem for p in data_dir().glob("*.toml"))
    assert len(stems) >= 5
    for stem in stems:
        cfg = load_scenario(stem)
        assert type(cfg) is scenario_class(cfg.scenario.generator)
        assert dataclasses.is_dataclass(cfg) and type(cfg).__dataclass_params__.frozen
    assert set(SCENARIOS) >= {load_scenario(s).scenario.generator for s in stems}


def test_the_file_wins_over_the_defaults_and_the_defaults_are_the_papers():
    from hsgeo.papers import P000_TABLE1_CALIBRATED as T1
    from hsgeo.papers import RIKOLA_CAMERA
    from hsgeo.simulate.pula_flight import FlightSensorTruth
    from hsgeo.simulate.rikola import BenchCameraRikola

    assert FlightSensorTruth() == load_scenario("pula_flight").sensor_truth
    assert FlightSensorTruth().K == (T1.K1, T1.K2, T1.K3)
    from hsgeo.sensors.rikola import RikolaCamera

    cam = load_scenario("rikola_bench").camera
    assert cam.pixel_mm == RIKOLA_CAMERA["pixel_mm"] == BenchCameraRikola.pixel_mm
    assert RikolaCamera.pixel_mm == RIKOLA_CAMERA["pixel_mm"]
    assert RikolaCamera.image_size == (RIKOLA_CAMERA["width_px"], RIKOLA_CAMERA["height_px"])
    assert load_scenario("line_lab").lab.even_distortion_px == 0.0  # the file's, not the default


def test_a_typo_in_a_scenario_file_is_a_clear_error(tmp_path, monkeypatch):
    d = tmp_path / "data_synthetic"
    d.mkdir()
    text = (data_dir() / "pula_flight.toml").read_text(encoding="utf-8")
    (d / "pula_flight.toml").write_text(text.replace("height_agl_m", "heigth_agl_m"))
    shutil.copy(data_dir() / "frame_bench.toml", d / "frame_bench.toml")
    (d / "other.toml").write_text('[scenario]\ngenerator = "pula_flite"\nseed = 1\n')
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"pula_flight.toml: \[flight\] heigth_agl_m: unknown key; "
                       r"did you mean 'height_agl_m'\?"):  # fmt: skip
        load_scenario("pula_flight")
    with pytest.raises(InputError, match="generator: unknown scenario generator 'pula_flite'; "
                       "did you mean 'pula_flight'"):  # fmt: skip
        load_scenario("other")
    assert load_scenario("frame_bench").board.nx == 9


def test_row_is_frozen_and_built_by_keyword():
    from hsgeo.report import Row

    with pytest.raises(TypeError):
        Row("t", "q", "m")  # type: ignore[misc]
    r = Row(table="t", quantity="q", unit="m", paper=1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.paper = 2.0  # type: ignore[misc]
    assert dataclasses.replace(r, paper=2.0).paper == 2.0 and r.paper == 1.0


def test_the_solver_constants_are_options():
    import hsgeo.adjust.solver as SV
    from hsgeo.adjust import SolverOptions

    o = SolverOptions()
    assert (o.hold_max, o.thrown_share, o.thrown_ratio) == (3, 0.25, 1000.0)
    assert not any(hasattr(SV, n) for n in ("HOLD_MAX", "THROWN_SHARE", "THROWN_RATIO"))
    for bad in ({"hold_max": -1}, {"thrown_share": 0.0}, {"thrown_ratio": float("inf")}):
        with pytest.raises(InputError, match=next(iter(bad))):
            SolverOptions(**bad)


def test_no_configuration_is_read_as_a_raw_dict():
    """Scenarios are dataclasses: no ``cfg["…"]`` in the package (issue's measure: 55 → 0)."""
    from pathlib import Path

    import hsgeo

    src = Path(hsgeo.__file__).parent
    hits = [
        f"{p.relative_to(src)}:{i}"
        for p in sorted(src.rglob("*.py"))
        for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if 'cfg["' in line
    ]
    assert not hits, hits


@dataclass(frozen=True)
class _Checked:
    n_views: int = 3

    def __post_init__(self):
        if self.n_views < 2:
            raise InputError(f"n_views must be at least 2, got {self.n_views}")


@dataclass(frozen=True)
class _Outer:
    inner: _Scenario
    checked: _Checked = _Checked()


def test_nested_tables_and_the_dataclass_own_checks_are_named():
    with pytest.raises(InputError) as e:
        load_dataclass(
            _Outer,
            {
                "inner": {"flight": {"height_agl_m": 1.0, "sped_m_s": 2.0}},
                "checked": {"n_views": 1},
            },
            "f.toml",
        )
    msg = str(e.value)
    assert "[inner.flight] sped_m_s: unknown key; did you mean 'speed_m_s'?" in msg, msg
    assert "[checked] n_views must be at least 2, got 1" in msg, msg


def _same(a, b) -> bool:
    """Equal values of equal types, field by field (arrays by their elements)."""
    import numpy as np

    if dataclasses.is_dataclass(a):
        return type(a) is type(b) and all(
            _same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
        )
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and np.array_equal(a, b)
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(map(_same, a, b))
    return type(a) is type(b) and a == b


#: Each chapter's scenario file, the table its chapter reads and that table's dataclass.
CHAPTER_SCENARIOS = {
    "pushbroom_campaign": ("campaign", "hsgeo.simulate.pushbroom_campaign_types:CampaignConfig"),
    "asf_runway": ("scene", "hsgeo.simulate.asf_runway:RunwayScene"),
    "cube_survey": ("survey", "hsgeo.simulate.cube_survey:CubeSurvey"),
    "mtf_bench": ("bench", "hsgeo.simulate.mtf_target:MtfBench"),
}


@pytest.mark.parametrize("stem", sorted(CHAPTER_SCENARIOS))
def test_a_chapter_scenario_file_is_its_dataclass_and_repeats_no_paper_value(stem):
    """The chapter reads its scenario from data_synthetic/<stem>.toml: the file's values are the
    dataclass's defaults (so the chapter's rows are those of the defaults, bit for bit), and the
    file leaves out every field whose default is a paper's value (written once, in papers.py)."""
    import importlib
    import inspect
    import re
    import tomllib

    table, target = CHAPTER_SCENARIOS[stem]
    module, name = target.split(":")
    cls = getattr(importlib.import_module(module), name)
    cfg = load_scenario(stem)
    assert _same(getattr(cfg, table), cls()), f"{stem}.toml [{table}] differs from {name}()"
    keys = tomllib.loads((data_dir() / f"{stem}.toml").read_text(encoding="utf-8"))[table]
    assert len(keys) >= 5, f"{stem}.toml [{table}] states only {sorted(keys)}"
    src = inspect.getsource(cls)
    from_papers = set(
        re.findall(r"^    (\w+): [^=\n]+= [^\n]*\b(?:P00\d\w*|ASF_004\w*)\[", src, re.M)
    )
    assert from_papers, f"{name} takes no default from hsgeo.papers"
    assert not from_papers & set(keys), f"{stem}.toml repeats the paper's {from_papers & set(keys)}"


def test_a_misspelt_key_of_a_chapter_scenario_is_named_with_a_suggestion(tmp_path, monkeypatch):
    d = tmp_path / "data_synthetic"
    d.mkdir()
    text = (data_dir() / "pushbroom_campaign.toml").read_text(encoding="utf-8")
    (d / "pushbroom_campaign.toml").write_text(text.replace("turn_s =", "trun_s ="))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"pushbroom_campaign.toml: \[campaign\] trun_s: unknown "
                       r"key; did you mean 'turn_s'\?"):  # fmt: skip
        load_scenario("pushbroom_campaign")


#: A paper's value and the modules whose dataclasses take it from hsgeo.papers (or, where the
#: import contracts keep papers out of a workflow's reach, from the sensor that types it once:
#: hsgeo.sensors.rikola.RikolaCamera): none of them may spell it again (the Rikola pitch was once
#: typed in four places).
WRITTEN_ONCE = {
    "0.0055": ("hsgeo.io.sensor_file", "hsgeo.simulate.rikola"),
    "1017": ("hsgeo.io.sensor_file", "hsgeo.simulate.rikola"),
    "0.0065": ("hsgeo.simulate.pushbroom_campaign_types",),
    "40.3": ("hsgeo.simulate.pushbroom_campaign_types",),
    "1875": ("hsgeo.simulate.pushbroom_campaign_types",),
    "113758": ("hsgeo.simulate.pushbroom_campaign_types",),
    "441587": ("hsgeo.simulate.pushbroom_campaign_types",),
}


@pytest.mark.parametrize("literal", sorted(WRITTEN_ONCE))
def test_the_paper_s_defaults_are_written_once_in_papers(literal):
    import importlib
    import inspect
    import re

    import hsgeo.papers

    assert re.search(rf"(?<![\w.]){re.escape(literal)}(?![\w])", inspect.getsource(hsgeo.papers))
    for name in WRITTEN_ONCE[literal]:
        code = "\n".join(
            line.split("#", 1)[0]
            for line in inspect.getsource(importlib.import_module(name)).splitlines()
        )
        hits = re.findall(rf"(?<![\w.]){re.escape(literal)}(?![\w])", code)
        assert not hits, f"{name} spells the paper's {literal}; take it from hsgeo.papers"


def test_a_scenario_that_writes_files_needs_its_seed(tmp_path, monkeypatch):
    """[scenario] seed is optional for a chapter's in-memory scenario only: ``hsgeo data`` names
    the file and the key of a generator's scenario without one (before writing anything)."""
    from hsgeo.reproduce.data import generate_all

    d = tmp_path / "data_synthetic"
    d.mkdir()
    text = (data_dir() / "mtf_bench.toml").read_text(encoding="utf-8")
    (d / "mtf_bench.toml").write_text(text.replace("seed = 20261124\n", ""))
    shutil.copy(data_dir() / "cube_survey.toml", d / "cube_survey.toml")  # no seed: in-memory
    monkeypatch.chdir(tmp_path)
    assert load_scenario("cube_survey").scenario.seed is None
    with pytest.raises(InputError, match=r"mtf_bench.toml: \[scenario\] seed: missing"):
        generate_all(out=tmp_path / "gen")
    assert not any((tmp_path / "gen").iterdir())


#: Chapters whose pages read the scene from their scenario file through the library (the
#: chapter's reproduce module names it: SCENARIO), never by building the dataclass themselves.
CHAPTER_PAGES_READING_THEIR_SCENARIO = {
    "asf": ("hsgeo.reproduce.asf", "hsgeo.simulate.asf_runway:RunwayScene"),
    "mtf": ("hsgeo.reproduce.mtf", "hsgeo.simulate.mtf_target:MtfBench"),
}


@pytest.mark.parametrize("page", sorted(CHAPTER_PAGES_READING_THEIR_SCENARIO))
def test_a_chapter_page_reads_its_scene_from_the_scenario_file(page):
    """The page's scene is the run's: ``load_scenario(SCENARIO)`` of its reproduce module (the
    scenario file), not a ``RunwayScene()`` / ``MtfBench()`` of its own."""
    import importlib
    import re
    from pathlib import Path

    module, target = CHAPTER_PAGES_READING_THEIR_SCENARIO[page]
    stem = importlib.import_module(module).SCENARIO
    assert stem in CHAPTER_SCENARIOS and CHAPTER_SCENARIOS[stem][1] == target
    text = (Path(__file__).parents[1] / "book" / "chapters" / f"{page}.md").read_text("utf-8")
    cells = "\n".join(re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S))
    name = target.split(":")[1]
    assert not re.search(rf"\b{name}\(", cells), f"{page}.md builds {name}() itself"
    table = CHAPTER_SCENARIOS[stem][0]
    assert re.search(rf"load_scenario\(SCENARIO\)\.{table}\b", cells), (
        f"{page}.md does not read load_scenario(SCENARIO).{table}"
    )
    src = inspect_source(module)
    assert "load_scenario(SCENARIO)" in src and f'load_scenario("{stem}")' not in src


def inspect_source(module: str) -> str:
    import importlib
    import inspect

    return inspect.getsource(importlib.import_module(module))


def test_the_lp_campaign_scenario_file_is_lpconfig_and_repeats_no_paper_value():
    """data_synthetic/lp_campaign.toml: [lp] is LpConfig() (so a chapter reading it flies the
    campaign of the defaults, bit for bit) and leaves 002's values (the geometry, the 1.2 m
    squares of 002 §4, the tuned mount motion, the blur from 002's speed) to the dataclass."""
    import tomllib

    from hsgeo.simulate.lp_campaign import LpConfig

    cfg = load_scenario("lp_campaign")
    assert _same(cfg.lp, LpConfig())
    keys = tomllib.loads((data_dir() / "lp_campaign.toml").read_text(encoding="utf-8"))["lp"]
    assert len(keys) >= 5
    assert not {"campaign", "square_side_m", "mount_motion_rad", "motion_blur_m"} & set(keys)
    with pytest.raises(InputError, match="dn_per_reflectanse: unknown key; did you mean"):
        load_dataclass(type(cfg), {"scenario": {"generator": "lp_campaign"},
                                   "lp": {"dn_per_reflectanse": [1.0]}}, "f")  # fmt: skip
