"""Independent judges of the LP retrieval (issue 37 item 4): point targets of known centre in
the rendered ground, and retrieved − twin in the σ of the difference."""

from dataclasses import replace

import numpy as np
import pytest

from hsgeo.errors import InputError
from hsgeo.reproduce import lp_targets as J
from hsgeo.simulate import lp_campaign as L
from hsgeo.simulate._lp_ground import make_ground

WL = (450.0, 527.0, 604.0)


def _ground(targets, seed=5, squares=((0.0, 0.0),)):
    cfg = replace(L.LpConfig(), ground_margin_m=4.0, buildings_per_km2=0.0)
    return make_ground(cfg, 8.0, np.array(squares), WL, np.random.default_rng(seed), targets)


def test_targets_are_painted_white_and_nothing_else_moves():
    g0, h0, t0 = _ground(())
    tg = np.array([[5.0, 5.0], [-6.0, 4.0], [1.0, 1.0]])  # the last one too close to a square
    g1, h1, t1 = _ground(tg)
    assert t0.shape == (0, 3)
    np.testing.assert_array_equal(t1[:, :2], tg[:2])  # near the square: not painted
    np.testing.assert_allclose(
        t1[:, 2], [g1.dsm_dataarray().interp(E=e, N=n).item() for e, n in tg[:2]]
    )
    np.testing.assert_array_equal(g0.dsm, g1.dsm)
    np.testing.assert_array_equal(h0, h1)
    E = g1.e0_m + g1.cell_m * np.arange(g1.reflectance.shape[2])
    N = g1.n0_m + g1.cell_m * np.arange(g1.reflectance.shape[1])
    d = np.min(
        [np.maximum(np.abs(E[None, :] - c[0]), np.abs(N[:, None] - c[1])) for c in tg[:2]], axis=0
    )
    far = d > 1.5  # beyond the target and its blur
    np.testing.assert_array_equal(g0.reflectance[:, far], g1.reflectance[:, far])
    for e, n in tg[:2]:
        i, j = int(round((n - g1.n0_m) / g1.cell_m)), int(round((e - g1.e0_m) / g1.cell_m))
        assert np.all(g1.reflectance[:, i, j] > g0.reflectance[:, i, j] + 0.3)


def test_survey_targets_are_grey_unsaturated_on_a_uniform_dark_surround():
    cfg = replace(
        J.target_config(), ground_margin_m=4.0, buildings_per_km2=0.0, motion_blur_m=0.335
    )
    tg = np.array([[5.0, 5.0], [-6.0, 4.0]])
    g, _, t = make_ground(cfg, 8.0, np.array([[0.0, 0.0]]), WL, np.random.default_rng(5), tg)
    g0, _, _ = _ground(())
    np.testing.assert_array_equal(t[:, :2], tg)
    E = g.e0_m + g.cell_m * np.arange(g.reflectance.shape[2])
    N = g.n0_m + g.cell_m * np.arange(g.reflectance.shape[1])
    dn = np.asarray(cfg.dn_per_reflectance[: len(WL)])

    def at(e, n):
        i, j = int(np.argmin(np.abs(N - n))), int(np.argmin(np.abs(E - e)))
        return g.reflectance[:, i, j]

    for e, n in tg:
        centre = at(e, n)
        # bright against the surround in every band, and below the clip at the peak
        assert np.all(centre > 0.3) and np.all(J.TARGET_REFLECTANCE * dn < cfg.dn_max)
        # the surround is uniform where FAST's circle lies at the 1875 m strips (3 px of
        # 0.30 m); at the 2500 m strips' 1.2 m the PSF and the motion blur leak up to ~10 % of
        # the texture's contrast along track in the near infrared (not tested here)
        ring = np.array(
            [
                at(e + 0.9 * np.cos(a), n + 0.9 * np.sin(a))
                for a in np.linspace(0, 2 * np.pi, 16, endpoint=False)
            ]
        )
        np.testing.assert_allclose(ring, cfg.target_surround_reflectance, atol=2e-3)
    # the texture beyond the surround and its blur is the campaign's own
    d = np.min(
        [np.maximum(np.abs(E[None, :] - c[0]), np.abs(N[:, None] - c[1])) for c in tg], axis=0
    )
    far = d > J.TARGET_SURROUND_M / 2 + 1.0
    np.testing.assert_array_equal(g0.reflectance[:, far], g.reflectance[:, far])


def test_target_grid_does_not_move_the_campaigns_draws():
    cfg = J.target_config()
    assert cfg.target_spacing_m == J.TARGET_SPACING_M
    g = np.random.default_rng(4)
    none = L._target_grid(L.LpConfig(), 15.0, g)
    assert none.shape == (0, 2)
    a = np.random.default_rng(4)
    b = np.random.default_rng(4)
    tg = L._target_grid(cfg, 15.0, a)
    assert tg.shape == (49, 2)  # 7 × 7 at 4 m over a 30 m block
    assert np.all(np.abs(tg) <= 15.0)
    assert a.standard_normal() == b.standard_normal()  # the campaign's stream did not move


def test_bad_target_config():
    with pytest.raises(InputError, match="target_spacing_m"):
        L.simulate(0.05, cfg=replace(L.LpConfig(), target_spacing_m=-1.0))
    with pytest.raises(InputError, match="target_side_m"):
        L.simulate(0.05, cfg=replace(L.LpConfig(), target_side_m=0.0))
    with pytest.raises(InputError, match="target_surround_m"):
        L.simulate(0.05, cfg=replace(L.LpConfig(), target_surround_m=-1.0))
    with pytest.raises(InputError, match="target_reflectance"):
        L.simulate(0.05, cfg=replace(L.LpConfig(), target_reflectance=1.5))


def test_twin_rows_judge_in_the_sigma_of_the_difference():
    td = {
        "labels": ["c_mm[0]", "boresight_rad[omega_rad]"],
        "difference": np.array([0.002, 1e-5]),
        "sigma_difference": np.array([0.001, np.nan]),
        "z": np.array([2.0, np.nan]),
        "z_retrieved_sigma": np.array([0.5, 0.1]),
        "n_draws": 16,
    }
    units = {"c_mm[0]": ("mm", 1.0), "boresight_rad[omega_rad]": ("deg", 180 / np.pi)}
    rows = {r.quantity: r for r in J.twin_rows(td, units)}
    assert rows["c_mm[0]"].z == pytest.approx(2.0)
    assert rows["boresight_deg[omega_deg]"].sigma is None
    assert rows["rms_z_sigma_of_difference"].reproduced == pytest.approx(2.0)
    assert rows["rms_z_retrieved_sigma"].reproduced == pytest.approx(np.sqrt((0.25 + 0.01) / 2))


@pytest.fixture(scope="module")
def judged():
    from hsgeo.reproduce.lp_runs import evaluate, exact_twin

    obs, truth = L.simulate(L.MIN_SCALE, rng=0, cfg=J.target_config())
    ev = evaluate(obs, truth, 0, nogcp=False, both=False)
    return obs, truth, ev, exact_twin(ev, obs, truth)


@pytest.mark.slow
def test_targets_found_and_judged_against_their_true_centres(judged):
    obs, truth, ev, _ = judged
    j = J.target_judge(ev["retrieval"].table, truth, obs.square_ids, truth.square_xyz_m)
    assert j["targets"] >= 10
    assert j["targets_found"] >= 3
    assert j["n_observations_on_targets"] >= 9
    assert np.all(j["on_target_distance_m"] <= J.ON_TARGET_M)
    # a survey-style target is found at its centre (white squares over the texture: up to
    # 0.4 m off it), then off by at most 0.71 px of pixel-centre and line rounding plus the key
    # point's localisation: the bar, ≥ 95 % within 1 px (white squares: 98.7 % here,
    # 89.7-99.0 % over 8 campaigns)
    assert np.all(j["on_target_distance_m"] <= 0.3)
    assert j["within_target"][1.0] >= 0.95
    assert j["within_target"][0.5] <= j["within_target"][1.0]
    pp = j["per_tie_point"]
    assert sum(p["n"] for p in pp) == j["n_observations_on_targets"]
    assert len({p["target"] for p in pp}) == j["targets_found"]
    assert all(0 <= p["within_1px"] <= 1 and p["max_error_px"] >= 0 for p in pp)


@pytest.mark.slow
def test_twin_difference_monte_carlo(judged):
    obs, truth, ev, tw = judged
    td = J.twin_difference(ev, obs, truth, tw, n_draws=4, rng=1)
    assert td["n_draws"] + td["failed_draws"] == 4
    assert td["draws"].shape == (td["n_draws"], len(td["labels"]))
    free = np.isfinite(td["sigma_retrieved"]) & (td["sigma_retrieved"] > 0)
    assert np.all(td["sigma_difference"][free] > 0)
    assert np.all(np.isnan(td["sigma_difference"][~free]))
    # no errors to draw from: every draw is the retrieval itself, its difference from the twin
    ev0 = dict(ev, obs_errors_px=np.zeros_like(ev["obs_errors_px"]))
    t0 = J.twin_difference(ev0, obs, truth, tw, n_draws=2, rng=1)
    d = np.broadcast_to(t0["difference"], t0["draws"].shape)
    np.testing.assert_allclose(t0["draws"][:, free], d[:, free], rtol=1e-9, atol=1e-12)
