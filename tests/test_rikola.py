"""The Rikola chapter's library: centroid model (Jacobians, round trip), simulator, ArUco
measurement, per-band and joint calibration on a small rendered bench."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hsgeo.adjust.checks import check_jacobian
from hsgeo.errors import InputError, ObservationError
from hsgeo.measure.aruco import detect_targets, detection_rate, make_detector, to_uint8
from hsgeo.papers import RIKOLA_BANDS, RIKOLA_TABLE4_ROP_DEG, RIKOLA_TABLE4_ROP_MEAN_DEG
from hsgeo.reproduce.rikola import observe
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.sensors.frame import FramePhotogrammetric, mm_to_pixel
from hsgeo.sensors.rikola import JointCentroids, TargetCentroids, project_measured_mm
from hsgeo.simulate.rikola import Plate, Renderer, make_truth
from hsgeo.simulate.scenarios import load_scenario
from hsgeo.workflows.rikola import (
    calibrate_band,
    calibrate_joint,
    detect_targets_in_images,
    gap_regression,
    relative_orientation,
)


@pytest.fixture(scope="module")
def cfg():
    return load_scenario("rikola_bench")


@pytest.fixture(scope="module")
def truth(cfg):
    return make_truth(cfg, np.random.default_rng([7, 0]), n_cubes=8)


@pytest.fixture(scope="module")
def bench(cfg, truth):
    """8 cubes × 6 bands rendered and measured (about 10 s)."""
    bands = [2, 5, 10, 12, 16, 20]
    obs, _, _, expected = observe(cfg, truth, 7, range(8), bands)
    return obs, bands, sum(expected.values())


def test_paper_tables():
    assert RIKOLA_BANDS.shape == (25,)
    assert np.all(RIKOLA_BANDS["sensor"][:10] == 2) and np.all(RIKOLA_BANDS["sensor"][10:] == 1)
    # the "Average" row of 003 Table 4 is the mean of its ten rows
    np.testing.assert_allclose(
        RIKOLA_TABLE4_ROP_DEG.mean(axis=0), RIKOLA_TABLE4_ROP_MEAN_DEG, atol=2e-5
    )


def _values(truth, band):
    return {
        "interior": truth.interior(band),
        "distortion_mm": truth.KP,
        "poses": truth.poses[:3].copy(),
    }


def test_target_centroids_jacobian(truth):
    plate = Plate()
    corners = np.repeat(plate.corners()[[0, 20, 40]], 3, axis=0)
    view = np.tile([0, 1, 2], 3)
    vals = _values(truth, 20)
    xy = np.zeros((9, 2))
    blk = TargetCentroids(view, corners, xy, 0.001)
    vals["distortion_mm"] = truth.KP + [1e-4, 1e-6, 1e-7, 1e-5, 1e-5]
    for name, step in (
        ("interior", 1e-6),
        ("distortion_mm", [1e-7, 1e-9, 1e-11, 1e-8, 1e-8]),
        ("poses", 1e-6),
    ):
        assert check_jacobian(blk, vals, name, step) < 1e-6, name


def test_joint_centroids_jacobian(truth):
    plate = Plate()
    n = 12
    corners = plate.corners()[np.arange(n) * 4 % 54]
    cube = np.arange(n) % 3
    band_index = np.array([1, 4, 19, 14] * 3)  # bands 2, 5, 20, 15
    blk = JointCentroids(
        cube,
        band_index,
        corners,
        np.zeros((n, 2)),
        0.001,
        RIKOLA_BANDS["gap_nm"],
        RIKOLA_BANDS["sensor"],
    )
    vals = {
        "poses": truth.poses[:3].copy(),
        "gap_model": truth.gap_model.copy(),
        "df_mm": np.full(25, 1e-3),
        "pp_mm": truth.pp_mm.copy(),
        "distortion_mm": truth.KP + [1e-4, 1e-6, 1e-7, 1e-5, 1e-5],
        "sensor2_rotation": truth.rotation_rad.copy(),
        "sensor2_offset_mm": np.array([0.5, -0.3, 1.0]),
    }
    steps = {
        "gap_model": np.array([1e-8, 1e-6, 1e-8, 1e-6]),
        "df_mm": 1e-6,
        "pp_mm": 1e-6,
        "distortion_mm": [1e-7, 1e-9, 1e-11, 1e-8, 1e-8],
        "poses": 1e-6,
        "sensor2_rotation": 1e-7,
        "sensor2_offset_mm": 1e-4,
    }
    for name, step in steps.items():
        assert check_jacobian(blk, vals, name, step) < 1e-6, name


def test_joint_equals_per_band_at_truth(truth):
    """The joint model with the truth reproduces the per-band model with the band's truth."""
    plate = Plate()
    corners = plate.corners()[:10]
    for band in (5, 20):
        vals = _values(truth, band)
        vals["poses"] = np.array([truth.band_pose(0, band)])
        pb = TargetCentroids(np.zeros(10, int), corners, np.zeros((10, 2)), 1.0).predict(vals)
        s = truth.sensor(band) - 1
        df = truth.f_mm - (
            truth.gap_model[RIKOLA_BANDS["sensor"] - 1, 0] * RIKOLA_BANDS["gap_nm"]
            + truth.gap_model[RIKOLA_BANDS["sensor"] - 1, 1]
        )
        jv = {
            "poses": truth.poses[:1],
            "gap_model": truth.gap_model,
            "df_mm": df,
            "pp_mm": truth.pp_mm,
            "distortion_mm": truth.KP,
            "sensor2_rotation": truth.rotation_rad,
            "sensor2_offset_mm": truth.offset_mm,
        }
        jb = JointCentroids(
            np.zeros(10, int),
            np.full(10, band - 1),
            corners,
            np.zeros((10, 2)),
            1.0,
            RIKOLA_BANDS["gap_nm"],
            RIKOLA_BANDS["sensor"],
        ).predict(jv)
        np.testing.assert_allclose(jb, pb, atol=1e-12)
        assert s in (0, 1)


def test_projection_round_trip_with_frame_photogrammetric(truth):
    """A measured point predicted by inverting the correction satisfies FramePhotogrammetric's
    collinearity (residual zero) — the two forms are the same camera."""
    X = Plate().centres()[:20]
    pose = truth.band_pose(0, 20)
    Xc = (X - pose[3:]) @ R_from_opk(*pose[:3])
    f, x0, y0 = truth.interior(20)
    xy = project_measured_mm(Xc, f, np.array([x0, y0]), truth.KP)
    blk = FramePhotogrammetric(np.zeros(20, int), xy, 0.001, X=X)
    r, _ = blk.evaluate(
        {"interior": truth.interior(20), "distortion_mm": truth.KP, "poses": pose[None]}, False
    )
    assert np.max(np.abs(r)) < 1e-10


def test_bad_inputs():
    with pytest.raises(InputError):
        TargetCentroids(np.zeros(3, int), np.zeros((3, 3, 3)), np.zeros((3, 2)), 1.0)
    with pytest.raises(InputError):
        TargetCentroids(np.zeros(3, int), np.zeros((3, 4, 3)), np.full((3, 2), np.nan), 1.0)
    with pytest.raises(InputError):
        JointCentroids(
            np.zeros(2, int),
            np.array([0, 30]),
            np.zeros((2, 4, 3)),
            np.zeros((2, 2)),
            1.0,
            RIKOLA_BANDS["gap_nm"],
            RIKOLA_BANDS["sensor"],
        )
    with pytest.raises(InputError):
        make_detector("DICT_NOPE")
    with pytest.raises(InputError):
        make_detector(refine="magic")
    with pytest.raises(InputError):
        detect_targets(np.zeros((10, 10), np.float32))
    with pytest.raises(InputError):
        to_uint8(np.zeros((2, 2, 2)))
    with pytest.raises(InputError):
        detection_rate(1, 0)
    with pytest.raises(InputError):
        gap_regression([1.0, 2.0], [1.0, 2.0])


def test_truth_and_render_deterministic(cfg, truth):
    t2 = make_truth(cfg, np.random.default_rng([7, 0]), n_cubes=8)
    np.testing.assert_array_equal(t2.poses, truth.poses)
    np.testing.assert_array_equal(t2.f_mm, truth.f_mm)
    r = Renderer(cfg, truth)
    a, b = r.render(0, 20, 3), r.render(0, 20, 3)
    assert a.dtype == np.uint16 and a.shape == (648, 1017)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, r.render(0, 20, 4))
    # sensor II band poses carry the misalignment: R_I_from_II = R_S1 R_S2^-1 (003 eq. (1))
    ang, _ = relative_orientation(truth.band_pose(0, 20), truth.band_pose(0, 5))
    np.testing.assert_allclose(ang, truth.rotation_rad, atol=1e-12)


def test_rendered_image_is_measured_without_the_truth(cfg, truth):
    """The simulator gives pixels only; the truth-free detection fills no truth-derived field
    (``expected`` is left for reproduce), and its corners lie where the truth projects them."""
    r = Renderer(cfg, truth)
    img = r.render(0, 5, 7)
    assert isinstance(img, np.ndarray) and img.dtype == np.uint16
    plate, cam = r.plate, cfg["camera"]
    size = (int(cam["width_px"]), int(cam["height_px"]))
    obs, cmp_ = detect_targets_in_images(
        [((0, 5), img)],
        plate.corners(),
        plate.ids,
        size,
        float(cam["pixel_mm"]),
        dictionary=plate.dictionary,
    )
    assert cmp_ is None and len(obs.target) > 10
    assert "expected" not in {f.name for f in dataclasses.fields(obs)}
    true_px = mm_to_pixel(truth.project(0, 5, plate.corners()[obs.target]), size, cam["pixel_mm"])
    assert np.median(np.abs(obs.corners_px - true_px)) < 0.5


def test_detection_every_band(bench):
    obs, bands, n_expected = bench
    assert detection_rate(len(obs.cube), n_expected) > 0.99
    assert set(np.unique(obs.band)) == set(bands)


def test_per_band_calibration_truth_within_3_sigma(bench, truth):
    obs, _, _ = bench
    for band in (5, 20):
        cal = calibrate_band(obs, band)
        tr = np.r_[truth.interior(band), truth.KP]
        est = np.array([v for v, _ in cal.iop.values()])
        sig = np.array([s for _, s in cal.iop.values()])
        assert np.all(np.abs(est - tr) < 3.5 * sig), (band, (est - tr) / sig)
        P = np.array([truth.band_pose(int(c), band) for c in cal.cubes])
        assert np.all(np.abs(cal.value("poses") - P) < 4 * cal.sigma("poses"))
        lo, hi = cal.result.chi2_interval(0.001)
        assert 0.7 < cal.result.sigma0 < 1.5


def test_joint_model_recovers_truth(bench, truth):
    obs, bands, _ = bench
    cals = {b: calibrate_band(obs, b) for b in bands}
    j = calibrate_joint(obs, init=cals, scatter_mm=tuple(truth.scatter_mm))
    R = j.result
    for name, tr in (
        ("gap_model", truth.gap_model),
        ("pp_mm", truth.pp_mm),
        ("distortion_mm", truth.KP),
        ("sensor2_rotation", truth.rotation_rad),
    ):
        z = (j.value(name) - tr) / j.sigma(name)
        assert np.all(np.abs(z) < 3.5), (name, z)
    np.testing.assert_array_equal(R.value("sensor2_offset_mm"), 0.0)  # held (one lens)
    assert 1.0 <= j.clusters["deff"] < 5.0
    with pytest.raises(ObservationError):
        calibrate_joint(obs, exclude_bands=[2, 5, 10])


def test_design_effect_recovers_cluster_correlation():
    from hsgeo.workflows.rikola import design_effect

    rng = np.random.default_rng(1)
    cl = np.repeat(np.arange(4000), 6)
    r = (0.01 * rng.standard_normal((4000, 2)))[cl] + 0.02 * rng.standard_normal((cl.size, 2))
    d = design_effect(r, cl)
    assert abs(d["rho"] - 0.2) < 0.03 and abs(d["deff"] - 2.0) < 0.15
    assert design_effect(r[:5], np.arange(5))["deff"] == 1.0


def test_gap_regression_exact_line():
    g = np.array([500.0, 550.0, 600.0, 650.0])
    out = gap_regression(g, 8.4e-5 * g + 8.6633 + np.array([1e-3, -1e-3, -1e-3, 1e-3]))
    assert abs(out["a"] - 8.4e-5) < 1e-12 and 0 < out["r2"] < 1
    R = R_from_opk(0.1, -0.2, 0.3)
    assert np.allclose(opk_from_R(R), [0.1, -0.2, 0.3])


def test_chapter_parameters_are_the_scenario_and_the_paper(cfg):
    """The rikola chapter's first cell (parameters only) states the values the simulation
    reads from rikola_bench.toml, and those are the paper's (003 Tables 1, 3, 4)."""
    from pathlib import Path

    jupytext = pytest.importorskip("jupytext")
    from hsgeo.papers import RIKOLA_TABLE3, RIKOLA_TABLE4_GAP_MODEL

    md = Path(__file__).resolve().parents[1] / "book" / "chapters" / "rikola.md"
    cell = next(c for c in jupytext.read(md, fmt="md:myst").cells if c.cell_type == "code")
    p: dict = {}
    exec(compile(cell.source, "rikola.md parameters", "exec"), p)  # noqa: S102
    cam, gm = cfg["camera"], cfg["gap_model"]
    assert (cam["width_px"], cam["height_px"], cam["pixel_mm"]) == (
        p["width_px"],
        p["height_px"],
        p["pixel_mm"],
    )
    for s in (1, 2):
        a, b = gm[f"a_sensor{s}_mm_per_nm"], gm[f"b_sensor{s}_mm"]
        assert (a, b) == (p[f"a_sensor{s}_mm_per_nm"], p[f"b_sensor{s}_mm"])
        assert (a, b) == (
            RIKOLA_TABLE4_GAP_MODEL[s]["a_mm_per_nm"][0],
            RIKOLA_TABLE4_GAP_MODEL[s]["b_mm"][0],
        )
    assert tuple(cam["pp_sensor1_mm"]) == p["pp_sensor1_mm"]
    assert tuple(cam["pp_sensor2_mm"]) == p["pp_sensor2_mm"]
    assert p["pp_sensor1_mm"] == tuple(RIKOLA_TABLE3[20][k][0] for k in ("x0_mm", "y0_mm"))
    assert p["pp_sensor2_mm"] == tuple(RIKOLA_TABLE3[5][k][0] for k in ("x0_mm", "y0_mm"))
    k1 = np.mean([RIKOLA_TABLE3[b]["K1_per_mm2"][0] for b in (5, 20)])
    assert cam["K1_per_mm2"] == p["K1_per_mm2"] == pytest.approx(k1, rel=1e-12)
    assert (cam["P1_per_mm"], cam["P2_per_mm"]) == (p["P1_per_mm"], p["P2_per_mm"])
    mis = cfg["misalignment"]
    rop = tuple(mis[k] for k in ("domega_deg", "dphi_deg", "dkappa_deg"))
    assert rop == p["rop_deg"] == tuple(RIKOLA_TABLE4_ROP_MEAN_DEG)
    assert cfg["geometry"]["n_cubes"] == p["n_cubes_paper"] == 20
    assert cfg["measure"]["sigma_px"] == p["sigma_px"]
    assert p["scale"] == 1.0 and isinstance(p["SEED"], int)
