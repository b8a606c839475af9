"""``hsgeo calibrate-frame``: board files, the real ChArUco photographs, a rendered ArUco bench."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hsgeo.cli import main
from hsgeo.errors import InputError
from hsgeo.io import read_board

ROOT = Path(__file__).resolve().parents[1]
CHARUCO = ROOT / "src/hsgeo/data/reference/opencv-charuco/images"
BOARD = ROOT / "src/hsgeo/data/reference/opencv-charuco/board.toml"


def test_charuco_photographs_match_opencv(capsys):
    """The four tutorial photographs: RMS and principal distance agree with OpenCV's own
    calibration of the same images (SOURCE.md: RMS 0.1878 px, fx, fy 457.3, 461.3 px)."""
    assert (
        main(
            [
                "calibrate-frame",
                *map(str, sorted(CHARUCO.glob("*.jpg"))),
                "--board",
                str(BOARD),
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    rows = {r["quantity"]: r for r in out["rows"]}
    assert abs(out["meta"]["band 1"]["rms_px"] - 0.1878) < 0.01
    f = rows["f"]
    assert abs(f["reproduced"] - 459.3) < 3 * f["sigma"]
    assert abs(rows["x0"]["reproduced"] - (317.22 - 319.5)) < 3 * rows["x0"]["sigma"]
    # the workflow's own result type (no report rows) carries the same numbers, in plain types
    from hsgeo.workflows.frame_calibration import FrameFilesResult, calibrate_frame_files

    res = calibrate_frame_files(sorted(map(str, CHARUCO.glob("*.jpg"))), BOARD)
    assert isinstance(res, FrameFilesResult)
    d = json.loads(json.dumps(res.to_dict(), allow_nan=False))
    assert [(e["name"], e["value"], e["sigma"]) for e in d["estimates"]] == [
        (r["quantity"], r["reproduced"], r["sigma"]) for r in out["rows"]
    ]
    assert d["meta"] == out["meta"]
    # and the in-memory core's result in plain types
    from hsgeo.reproduce.frame_reference import charuco_views
    from hsgeo.workflows.frame_calibration import calibrate_opencv

    views, size, _ = charuco_views()
    cal = json.loads(json.dumps(calibrate_opencv(views, size).to_dict(), allow_nan=False))
    assert cal["form"] == "opencv" and abs(cal["rms_px"] - 0.1878) < 0.01
    assert set(cal["values"]) == set(cal["sigmas"]) >= {"fx_px", "k1"}


def test_rendered_aruco_grid_recovers_truth(tmp_path, capsys):
    import cv2

    from hsgeo.measure.aruco import to_uint8
    from hsgeo.simulate.rikola import Renderer, make_truth
    from hsgeo.simulate.scenarios import load_scenario

    cfg = load_scenario("rikola_bench")
    truth = make_truth(cfg, np.random.default_rng([5, 0]), n_cubes=6)
    r = Renderer(cfg, truth)
    files = []
    for c in range(6):
        p = tmp_path / f"cube{c}_band20.png"
        cv2.imwrite(str(p), to_uint8(r.render(c, 20, 5)))
        files.append(str(p))
    board = tmp_path / "plate.toml"
    board.write_text(
        '[board]\ntype = "aruco_grid"\ndictionary = "DICT_4X4_100"\n'
        "markers_x = 9\nmarkers_y = 6\nmarker_mm = 60.0\nseparation_mm = 20.0\n"
        "[camera]\npixel_mm = 0.0055\n"
    )
    assert (
        main(
            [
                "calibrate-frame",
                *files,
                "--board",
                str(board),
                "--band-regex",
                r"band(\d+)",
                "--sigma-px",
                "0.02",
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    rows = {r["quantity"]: r for r in out["rows"]}
    for q, t in zip(("f", "x0", "y0"), truth.interior(20), strict=True):
        assert abs(rows[q]["reproduced"] - t) < 3.5 * rows[q]["sigma"], q


def test_bad_board_files(tmp_path, capsys):
    with pytest.raises(InputError, match="not found"):
        read_board(tmp_path / "none.toml")
    p = tmp_path / "b.toml"
    p.write_text('[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 5\n')
    with pytest.raises(InputError, match="missing"):
        read_board(p)
    p.write_text('[board]\ntype = "hexagons"\n')
    with pytest.raises(InputError, match="type"):
        read_board(p)
    p.write_text("[board\n")
    with pytest.raises(InputError, match="malformed"):
        read_board(p)
    assert (
        main(["calibrate-frame", str(CHARUCO / "img_00.jpg"), "--board", str(BOARD), "--joint"])
        == 2
    )
    assert "--band-regex" in capsys.readouterr().err


def test_rikola_files_front_end_recovers_truth(tmp_path):
    """calibrate_rikola_files: image files named by cube and band, a board file → per-band
    interior orientation and the relative orientation of the sensors within 3.5σ̂ of the truth."""
    import cv2

    from hsgeo.measure.aruco import to_uint8
    from hsgeo.simulate.rikola import Renderer, make_truth
    from hsgeo.simulate.scenarios import load_scenario
    from hsgeo.workflows.rikola import RikolaOptions, calibrate_rikola_files

    cfg = load_scenario("rikola_bench")
    truth = make_truth(cfg, np.random.default_rng([5, 0]), n_cubes=6, eop_drift=False)
    r = Renderer(cfg, truth)
    files = []
    for c in range(6):
        for b in (10, 20):
            p = tmp_path / f"cube{c}_band{b}.png"
            cv2.imwrite(str(p), to_uint8(r.render(c, b, 5)))
            files.append(p)
    board = tmp_path / "plate.toml"
    board.write_text(
        '[board]\ntype = "aruco_grid"\ndictionary = "DICT_4X4_100"\n'
        "markers_x = 9\nmarkers_y = 6\nmarker_mm = 60.0\nseparation_mm = 20.0\n"
        "[camera]\npixel_mm = 0.0055\n"
    )
    res = calibrate_rikola_files(
        files,
        board,
        band_regex=r"band(\d+)",
        cube_regex=r"cube(\d+)",
        options=RikolaOptions(joint=False),
    )
    assert res.pairs == [(10, 20)] and res.joint is None
    for b in (10, 20):
        iop = res.bands[b].iop
        for q, t in zip(("f_mm", "x0_mm", "y0_mm"), truth.interior(b), strict=True):
            assert abs(iop[q][0] - t) < 3.5 * iop[q][1], (b, q)
    z = (res.relative["rop_mean"] - truth.rotation_rad) / res.relative["rop_mean_sigma"]
    assert np.all(np.abs(z) < 3.5), z
    d = json.loads(json.dumps(res.to_dict(), allow_nan=False))
    assert d["tables"]["relative orientation"][0]["unit"] == "deg"
