import json

import pytest

from hsgeo.cli import main
from hsgeo.reproduce.line_calibration import generate
from hsgeo.simulate.line_lab import LineLabScenario
from hsgeo.simulate.scenarios import ScenarioInfo


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("line")
    generate(LineLabScenario(ScenarioInfo("line_lab", 4)), d)
    return d


def test_calibrate_line_json(files, capsys):
    rc = main(
        [
            "calibrate-line",
            str(files / "line_lab_observations.csv"),
            "--control",
            str(files / "line_lab_control.csv"),
            "--json",
        ]
    )
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    truth = dict(
        line.split(",") for line in (files / "line_lab_truth.csv").read_text().splitlines()[1:]
    )
    for k in ("zeta0_px", "c_px", "K1"):
        p = out["parameters"][k]
        assert abs(p["value"] - float(truth[k])) < 3 * p["sigma"], k
    assert out["residuals"]["rms_px"] < 0.3


def test_calibrate_line_errors(files, tmp_path, capsys):
    bad = tmp_path / "obs.csv"
    lines = (files / "line_lab_observations.csv").read_text().splitlines()
    bad.write_text("\n".join(lines[:1] + [lines[1].rsplit(",", 1)[0] + ",nan"] + lines[2:]))
    assert main(["calibrate-line", str(bad), "--control", str(files / "line_lab_control.csv")]) == 2
    assert "NaN" in capsys.readouterr().err
    few = tmp_path / "few.csv"
    few.write_text(
        "\n".join(
            [ln for ln in lines if not ln.startswith("img1")][:]
            + [ln for ln in lines if ln.startswith("img1")][:2]
        )
    )
    assert main(["calibrate-line", str(few), "--control", str(files / "line_lab_control.csv")]) == 2
    assert "at least 3 per image" in capsys.readouterr().err
    assert main(["calibrate-line", str(tmp_path / "none.csv"), "--control", "x.csv"]) == 2
    assert "not found" in capsys.readouterr().err
