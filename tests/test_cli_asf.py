"""``hsgeo asf`` on a small simulated runway flight: the recovered ASF against the truth."""

import json

import numpy as np
import pytest
from asf_inputs import true_asf_normalised, write_asf_inputs

from hsgeo.cli import main


@pytest.fixture(scope="module")
def asf_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("asf")
    info = write_asf_inputs(d)
    return d, info


def test_asf_command_recovers_the_true_asf(asf_dir, capsys):
    d, info = asf_dir
    rc = main([
        "asf", str(d / "cross.nc"), str(d / "along.nc"), "--runway", str(d / "runway.csv"),
        "--json",
    ])  # fmt: skip
    out = capsys.readouterr()
    assert rc == 0, out.err
    res = json.loads(out.out)
    asf = np.array(res["asf"], float)
    tr = info["truth"]
    n = asf.shape[1]
    ref = true_asf_normalised(tr)[:, :n] if tr.asf.shape[1] == n else None
    assert ref is not None
    usable = np.array(res["usable"])
    assert usable.all()
    assert np.nanmax(np.abs(asf - ref)[:, usable]) < 0.01
    shift = np.array(res["registration"]["shift_m"])
    assert np.all(np.abs(shift - tr.shift_m) < 0.1)


def test_asf_command_prints_a_table(asf_dir, capsys):
    d, _ = asf_dir
    rc = main(["asf", str(d / "cross.nc"), str(d / "along.nc"), "--runway", str(d / "runway.csv")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "registration" in out and "columns usable" in out and "scan_angle_deg" in out
