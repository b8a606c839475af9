"""Self-calibration against OpenCV on real data, and against the truth on a simulated bench."""

import dataclasses

import cv2
import numpy as np
import pytest

from hsgeo import InputError, ObservationError
from hsgeo.reproduce.frame_reference import charuco_views, chessboard_views, opencv_calibrate
from hsgeo.simulate.frame_bench import simulate
from hsgeo.simulate.scenarios import load_scenario
from hsgeo.workflows.frame_calibration import View, calibrate_opencv, calibrate_photogrammetric


@pytest.fixture(scope="module")
def chessboard():
    return chessboard_views()


def test_chessboard_matches_opencv_file(chessboard):
    # reference: OpenCV's out_camera_data.yml (flags 14): fx = 657.46697810243404 px,
    # k1 -0.41802327018241026, k2 0.50715243805833121, k3 -0.57843596847939704
    views, size, ref = chessboard
    cal = calibrate_opencv(
        views, size, fix_principal_point=True, square_pixels=True, zero_tangent=True
    )
    v = cal.values()
    assert abs(v["fx_px"] - 657.46697810243404) < 0.01
    for k in ("k1", "k2", "k3"):
        assert abs(v[k] - ref[k]) < 1e-3
    assert v["cx_px"] == 319.5 and v["cy_px"] == 239.5 and v["p1"] == 0.0
    assert cal.rms_px == pytest.approx(0.38441346462381665, abs=1e-5)


def test_sigma_equals_opencv_std_deviations(chessboard):
    """hsgeo's σ̂ of the intrinsics against cv2.calibrateCameraExtended's stdDeviationsIntrinsics."""
    views, size, _ = chessboard
    cal = calibrate_opencv(views, size)
    obj = [v.X.astype(np.float32) for v in views]
    img = [v.uv_px.astype(np.float32) for v in views]
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-15)
    out = cv2.calibrateCameraExtended(obj, img, size, None, None, criteria=crit)
    std_cv = out[5].ravel()[:9]  # fx fy cx cy k1 k2 p1 p2 k3
    s = cal.sigmas()
    ours = np.array(
        [s[k] for k in ("fx_px", "fy_px", "cx_px", "cy_px", "k1", "k2", "p1", "p2", "k3")]
    )
    np.testing.assert_allclose(ours, std_cv, rtol=1e-3)


def test_charuco_within_0p2_percent_of_calibrate_camera():
    views, size, _ = charuco_views()
    assert [v.X.shape[0] for v in views] == [24, 24, 24, 24]
    cal = calibrate_opencv(views, size)
    K, dist, rms = opencv_calibrate(views, size)
    v = cal.values()
    for name, ref in [
        ("fx_px", K[0, 0]),
        ("fy_px", K[1, 1]),
        ("cx_px", K[0, 2]),
        ("cy_px", K[1, 2]),
    ]:
        assert abs(v[name] / ref - 1) < 0.002, name
    assert cal.rms_px == pytest.approx(rms, rel=1e-4)


def test_photogrammetric_form_differs_but_fits(chessboard):
    views, size, _ = chessboard
    pg = calibrate_photogrammetric(
        views, size, 0.006, fix_principal_point=True, zero_decentering=True
    )
    f_px = pg.values()["f_mm"] / 0.006
    assert 600 < f_px < 700 and pg.rms_px < 0.5
    # the pixel pitch only scales the mm units
    pg2 = calibrate_photogrammetric(
        views, size, 0.01, fix_principal_point=True, zero_decentering=True
    )
    assert pg2.values()["f_mm"] / 0.01 == pytest.approx(f_px, rel=1e-7)


def _views(sim):
    return [
        View(sim.X_mm[sim.point[sim.view == i]], sim.uv_px[sim.view == i])
        for i in range(sim.n_views)
    ]


def test_simulated_bench_observations_are_frozen_and_truth_free():
    sim, truth = simulate(load_scenario("frame_bench"), 0)
    names = {f.name for f in dataclasses.fields(sim)}
    assert sim.__dataclass_params__.frozen and truth.__dataclass_params__.frozen
    assert not names & {"poses", "intrinsics", "distortion", "uv_true_px"}, names
    assert sim.n_views == truth.poses.shape[0] and sim.uv_px.shape == truth.uv_true_px.shape
    assert 0 < np.std(sim.uv_px - truth.uv_true_px) < 3 * sim.sigma_px
    with pytest.raises(dataclasses.FrozenInstanceError):
        sim.uv_px = truth.uv_true_px


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_simulated_bench_truth_within_3_sigma(seed):
    cfg = load_scenario("frame_bench")
    sim, sim_truth = simulate(cfg, seed)
    cal = calibrate_opencv(_views(sim), sim.image_size_px, sigma_px=sim.sigma_px)
    truth = np.concatenate([sim_truth.intrinsics, sim_truth.distortion])
    est, sig = np.array(list(cal.values().values())), np.array(list(cal.sigmas().values()))
    assert np.all(np.abs(est - truth) < 3 * sig)
    lo, hi = cal.result.chi2_interval(0.001)
    assert lo < cal.result.sigma0 < hi


def test_simulated_bench_noise_free():
    cfg = load_scenario("frame_bench")
    cfg = dataclasses.replace(cfg, camera=dataclasses.replace(cfg.camera, sigma_px=0.0))
    sim, sim_truth = simulate(cfg, 5)
    cal = calibrate_opencv(_views(sim), (640, 480))
    truth = np.concatenate([sim_truth.intrinsics, sim_truth.distortion])
    np.testing.assert_allclose(np.array(list(cal.values().values())), truth, atol=1e-6)


def test_bad_views():
    X = np.zeros((10, 3))
    with pytest.raises(ObservationError, match="at least 2 views"):
        calibrate_opencv([View(X, np.zeros((10, 2)))], (640, 480))
    with pytest.raises(InputError, match="NaN"):
        calibrate_opencv([View(X, np.full((10, 2), np.nan))] * 3, (640, 480))
    with pytest.raises(ObservationError, match="at least 4"):
        calibrate_opencv([View(X[:3], np.zeros((3, 2)))] * 3, (640, 480))
