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


def _undetermined_at_the_solution(monkeypatch, names):
    """The workflow's solve, with the result as the engine returns it when the normal matrix at
    the solution does not determine ``names`` (tests/test_engine_undetermined.py makes that
    happen for real; here the command's report of it is tested)."""
    import numpy as np

    from hsgeo.workflows import pushbroom_ba as wf

    real = wf.solve

    def solve(*a, **k):
        res = real(*a, **k)
        res.undetermined_parameters = list(names)
        for n in names:
            i = res.labels.index(n)
            res.covariance[i, :] = res.covariance[:, i] = np.nan
        return res

    monkeypatch.setattr(wf, "solve", solve)


def test_undetermined_at_the_solution_is_named_with_exit_0(tmp_path, capsys, monkeypatch):
    _undetermined_at_the_solution(monkeypatch, ["c_mm[4]"])
    argv = _argv(tmp_path, lambda d: d)
    assert main(argv) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["undetermined_parameters"]["parameters"] == ["c_mm[4]"]
    assert out["parameters"]["c_mm"]["sigma"][4] is None  # strict JSON: null, not NaN
    assert out["fit"]["warnings"] and "c_mm[4]" in out["fit"]["warnings"][0]
    assert cap.err.count("\n") == 1 and "warning" in cap.err and "c_mm[4]" in cap.err
    # the text report names it too
    assert main(argv[:-1]) == 0
    assert "not determined at the solution" in capsys.readouterr().out
    # --strict: exit 2, the JSON still printed, one error line
    assert main([*argv, "--strict"]) == 2
    cap = capsys.readouterr()
    assert json.loads(cap.out)["undetermined_parameters"]["parameters"] == ["c_mm[4]"]
    assert cap.err.count("\n") == 1 and "--strict" in cap.err and "c_mm[4]" in cap.err
