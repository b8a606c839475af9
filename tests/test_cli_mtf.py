"""``hsgeo mtf`` and ``hsgeo mtf-edge`` on files of the simulated bench."""

from __future__ import annotations

import json

import numpy as np
import pytest
from mtf_inputs import write_bar_inputs, write_edge_image

from hsgeo.cli import main
from hsgeo.simulate import mtf_target as T


def test_mtf_on_profiles(tmp_path, capsys):
    write_bar_inputs(tmp_path)
    argv = ["mtf", str(tmp_path / "profiles.csv"), "--bars", str(tmp_path / "bars.toml")]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    bench = T.MtfBench()
    for p in out["profiles"]:
        f, m = np.array(p["frequency_cy_px"]), np.array(p["mtf"])
        assert f.size == m.size > 10
        assert np.abs(m - T.mtf_true(bench, p["row"], f)).max() < 0.05
        assert abs(p["gsd_mm"] - bench.gsd_mm) < 0.002
    assert abs(out["profiles"][0]["borderline_cy_px"] - 0.3) < 0.02  # line 100 (tuned optics)
    assert main(argv) == 0
    assert "row 1000" in capsys.readouterr().out


@pytest.mark.parametrize("bits", [8, 16])
def test_mtf_edge_with_and_without_roi(tmp_path, capsys, bits):
    write_edge_image(tmp_path / "edge.png", bits=bits)
    for extra in ([], ["--roi", "10,10,150,190"]):
        assert main(["mtf-edge", str(tmp_path / "edge.png"), "--json", *extra]) == 0
        out = json.loads(capsys.readouterr().out)
        f, m = np.array(out["frequency_cy_px"]), np.array(out["mtf"])
        assert f.size == m.size and abs(out["edge_angle_deg"] - 5.0) < 0.2
        assert out["lsf_fwhm_px"] > 1.0
        k = f <= 0.5
        tol = 0.05 if bits == 16 else 0.08  # a 128-px square ROI: noisier than the chapter's
        truth = T.mtf_true(T.MtfBench(), 1000, f[k], 5.0)
        assert np.abs(m[k] - truth).max() < tol
    assert main(["mtf-edge", str(tmp_path / "edge.png")]) == 0
    assert "LSF FWHM" in capsys.readouterr().out


def test_mtf_on_the_generated_data(capsys):
    """``make data``'s mtf_bench files: ``hsgeo mtf`` against the written truth."""
    import pandas as pd

    from hsgeo.simulate.scenarios import data_dir

    g = data_dir() / "generated"
    argv = ["mtf", str(g / "mtf_bench_profiles.csv"), "--bars", str(g / "mtf_bench_bars.toml")]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    truth = pd.read_csv(g / "mtf_bench_truth.csv")
    for p in out["profiles"]:
        t = np.interp(p["frequency_cy_px"], truth["f_cy_px"], truth[f"mtf_row{p['row']}"])
        assert np.abs(np.array(p["mtf"]) - t).max() < 0.05


def test_mtf_edge_on_a_masked_chip(tmp_path, capsys):
    """A 16-bit chip with 0 outside a rotated knife-edge target (tests/edge_reference.py, not
    rendered by hsgeo): found and measured without --roi; a region reaching the fill is refused
    with the reason, on standard error and, with --json, as JSON."""
    import cv2
    import edge_reference as ER

    img, _ = ER.masked_target_chip(seed=3)
    cv2.imwrite(str(tmp_path / "chip.png"), img.astype(np.uint16))
    assert main(["mtf-edge", str(tmp_path / "chip.png"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    f, m = np.array(out["frequency_cy_px"]), np.array(out["mtf"])
    k = (f >= 0.1) & (f <= 0.4)
    assert np.abs(m[k] - ER.known_mtf(f[k], 0.8, 5.0, 8)).max() < 0.02
    assert out["lsf_fwhm_px"] > 1.0
    rc = main(["mtf-edge", str(tmp_path / "chip.png"), "--roi", "70,20,130,180", "--json"])
    assert rc == 2
    cap = capsys.readouterr()
    err = json.loads(cap.out)["error"]
    assert "fill" in err and "chip.png" in err and "fill" in cap.err
