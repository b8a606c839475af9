"""What the data cannot determine is left out and named, not a reason to stop (issue 42): a
band without observations keeps its a-priori principal distance (``not_estimated``) and the rest
is adjusted. (A tie point its rays do not determine: tests/test_engine.py,
test_undetermined_point_dropped_and_named.)"""

import json

import pandas as pd

from hsgeo.cli import main
from hsgeo.simulate.pushbroom_campaign import simulate


def _argv(tmp_path, obs_df):
    from test_cli_pushbroom import _write

    obs, _ = simulate(0.002, rng=4)
    _write(tmp_path, obs)
    full = pd.read_parquet(tmp_path / "obs.parquet")
    obs_df(full).to_parquet(tmp_path / "obs2.parquet")
    return [
        "adjust-pushbroom",
        str(tmp_path / "obs2.parquet"),
        "--trajectory",
        str(tmp_path / "nav.csv"),
        "--camera",
        str(tmp_path / "cam.toml"),
        "--gcp",
        str(tmp_path / "gcp.csv"),
        "--json",
    ]


def test_band_without_observations_keeps_its_prior(tmp_path, capsys):
    argv = _argv(tmp_path, lambda d: d[d["band"] != 4])
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["not_estimated"]["parameters"] == ["c_mm[4]"]
    c = out["parameters"]["c_mm"]
    assert c["value"][4] == 40.0 and c["sigma"][4] is None  # the prior, not estimated
    assert all(s is not None and s > 0 for k, s in enumerate(c["sigma"]) if k != 4)
