import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.io.config import load_dataclass
from hsgeo.papers import P000_TABLE1_CALIBRATED, P001_TABLE2
from hsgeo.reproduce.line_calibration import (
    IOP_NAMES,
    calibrate_simulated,
    generate,
    simulate_observations,
)
from hsgeo.sensors import line1d
from hsgeo.simulate import line_lab as LL
from hsgeo.simulate.line_lab import LineLabScenario
from hsgeo.simulate.scenarios import ScenarioInfo

LAB = LL.LineLab()


def test_truth_at_published_lines():
    for r in P001_TABLE2[:3]:
        t = LL.true_iop(r.row_px)
        assert float(t["zeta0_px"]) == pytest.approx(r.zeta0_px)
        assert float(t["c_px"]) == pytest.approx(r.c_px)
        np.testing.assert_allclose(t["K"], [r.K1, r.K2, r.K3])
    t = LL.true_iop(1000)
    assert float(t["c_px"]) == P000_TABLE1_CALIBRATED.c_px
    assert LL.wavelength_nm(1000) == pytest.approx(870.0)


def test_recording_is_frozen_and_truth_free():
    import dataclasses

    rec, truth = LL.record(LAB, 1000, 3)
    names = {f.name for f in dataclasses.fields(rec)}
    assert rec.__dataclass_params__.frozen and truth.__dataclass_params__.frozen
    assert not names & {"eop", "iop", "eop_true", "iop_true"}, names
    assert rec.frames_dn.dtype == np.uint16 and rec.frames_dn.shape[0] == truth.eop.shape[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        rec.row = 5


def test_render_is_12bit_and_reproducible():
    e = LL.stations(LAB)[1]
    a = LL.render_rows(LAB, e, [100, 1000], 5)
    b = LL.render_rows(LAB, e, [100, 1000], 5)
    assert a.dtype == np.uint16 and a.shape == (2, 1280) and a.max() <= 4095
    assert np.array_equal(a, b)
    with pytest.raises(InputError):
        LL.render_rows(LAB, e, [2000], 0)


@pytest.mark.parametrize("row", [100, 1000])
def test_measured_minima_match_projection(row):
    sim = simulate_observations(LAB, row, 3)
    t = sim["iop_true"]
    z = line1d.project(
        sim["xy_m"][sim["point"]],
        sim["eop_true"][sim["image"]],
        float(t["zeta0_px"]),
        float(t["c_px"]),
        t["K"],
    )
    err = sim["zeta_px"] - z
    assert np.abs(err).max() < 0.5 and abs(err.mean()) < 0.03


@pytest.mark.parametrize("seed", [0, 11])
@pytest.mark.parametrize("row", [100, 300, 500, 1000])
def test_calibration_within_3_sigma_of_truth(seed, row):
    res, sim = calibrate_simulated(LAB, row, seed)
    t = sim["iop_true"]
    truth = np.r_[t["zeta0_px"], t["c_px"], t["K"]]
    est = np.r_[res.value("zeta0_px"), res.value("c_px"), res.value("K")]
    sig = np.r_[res.sigma("zeta0_px"), res.sigma("c_px"), res.sigma("K")]
    for q, e, s, tr in zip(IOP_NAMES, est, sig, truth, strict=True):
        assert abs(e - tr) < 3 * s, q
    z = (res.value("eop") - sim["eop_true"]) / res.sigma("eop")
    assert np.all(np.abs(z) < 3.5)


def test_generate_writes_cli_files(tmp_path):
    cfg = LineLabScenario(ScenarioInfo("line_lab", 1))
    paths = generate(cfg, tmp_path)
    assert [p.name for p in paths] == [
        "line_lab_observations.csv",
        "line_lab_control.csv",
        "line_lab_truth.csv",
    ]
    assert paths[0].read_text().splitlines()[0] == "image,point,zeta_px"
    with pytest.raises(InputError, match=r"line-lab settings: bogus: unknown key"):
        load_dataclass(LL.LineLab, {"bogus": 1}, "line-lab settings")
    with pytest.raises(InputError, match="distance_mm: unknown key; did you mean 'distance_m'"):
        load_dataclass(LL.LineLab, {"distance_mm": 3.0})
    lab = load_dataclass(LL.LineLab, {"azimuths_deg": [-45.0, 0.0]})
    assert lab.azimuths_deg == (-45.0, 0.0)
