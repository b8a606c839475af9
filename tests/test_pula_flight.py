"""The simulated airborne flight (hsgeo.simulate.pula_flight): every seed gives a flight that
images all GCPs within the calibrated swath, deterministically."""

from dataclasses import replace

import numpy as np
import pytest

from hsgeo import ConvergenceError, InputError
from hsgeo.sensors.line import CalibratedLine
from hsgeo.simulate.pula_flight import (
    MAX_FLIGHT_DRAWS,
    gcp_field,
    gcps_in_swath,
    simulate_flight,
    true_sensor,
)
from hsgeo.simulate.scenarios import load_scenario

CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1

# SeedSequence([0, 10054]).generate_state(1)[0]: its first draw has a boresight roll of −1.92°
# (3.8 σ) on top of the roll motion, which put GCP 2 beyond ζ0 − 450 px; simulate_flight raised
# ConvergenceError for it before the redraw rule.
SEED_GCP_OUTSIDE_SWATH = 1519955264


def _flight_seed(seed, i):
    return int(np.random.SeedSequence([seed, i]).generate_state(1)[0])


def test_the_seed_whose_first_draw_lost_a_gcp_now_works():
    assert _flight_seed(0, 10054) == SEED_GCP_OUTSIDE_SWATH
    cfg = load_scenario("pula_flight")
    obs, truth = simulate_flight(cfg, SEED_GCP_OUTSIDE_SWATH)
    assert truth.n_draws == 2
    # independent check: the true sensor's inverse model accepts every GCP's noise-free ζ, and
    # the measured ζ lie within the usable swath (± the measurement noise)
    half = cfg.scanner.usable_half_width_px
    assert np.all(np.abs(obs.zeta_px - cfg.sensor_truth.zeta0_px) < half + 2.0)
    n_lines = truth.true_nav.t_s[-1] * truth.line_rate_hz
    assert np.all((obs.line > 0) & (obs.line < n_lines))
    # deterministic: the same seed gives the same bytes, redraw included
    again, truth2 = simulate_flight(cfg, SEED_GCP_OUTSIDE_SWATH)
    assert again.zeta_px.tobytes() == obs.zeta_px.tobytes()
    assert again.line.tobytes() == obs.line.tobytes()
    assert truth2.boresight_rad.tobytes() == truth.boresight_rad.tobytes()


def test_a_first_draw_is_kept_as_drawn():
    """The rule only replaces rejected draws: a flight accepted at once consumes the stream in
    the same order as the rule-free simulator (trajectory, navigation errors, boresight, noise);
    so its boresight is the stream's draw after the trajectory and navigation errors."""
    from hsgeo.simulate.pula_flight import _recorded, _true_trajectory

    cfg = load_scenario("pula_flight")
    obs, truth = simulate_flight(cfg, 3)
    assert truth.n_draws == 1
    rng = np.random.default_rng(3)
    nav, _, _ = _true_trajectory(cfg, rng)
    rec = _recorded(nav, cfg, rng)
    bs = rng.normal(0, np.deg2rad(cfg.flight.boresight_sigma_deg), 3)
    assert bs.tobytes() == truth.boresight_rad.tobytes()
    assert rec.xyz_m.tobytes() == obs.recorded_nav.xyz_m.tobytes()


def test_gcps_in_swath_agrees_with_the_inverse_model():
    """In the swath ⇔ the calibrated inverse model accepts the direction (ζ within ±450 px)."""
    tan = np.linspace(-0.16, 0.16, 321)  # ±9°; the swath is about ±7.5°
    inside = gcps_in_swath(np.zeros_like(tan), tan, CAL, 450.0)
    accepted = np.empty(tan.size, bool)
    for k in range(tan.size):
        try:
            CAL.zeta(tan[k : k + 1])
            accepted[k] = True
        except ConvergenceError:
            accepted[k] = False
    np.testing.assert_array_equal(inside, accepted)
    assert 0.6 < inside.mean() < 0.95  # both sides of both edges are tried
    # a GCP the scan plane never crosses is not imaged
    assert not gcps_in_swath(np.array([np.nan]), np.array([0.0]), CAL, 450.0)[0]


def test_a_field_that_does_not_fit_the_swath_is_a_clear_error():
    cfg = load_scenario("pula_flight")
    field = replace(cfg.field, across_px=(-600.0, *cfg.field.across_px[1:]))
    cfg = replace(cfg, field=field)
    assert gcp_field(cfg)[1].shape == (10, 3) and true_sensor(cfg).c_px > 0
    with pytest.raises(InputError, match=rf"{MAX_FLIGHT_DRAWS} draws.*across_px"):
        simulate_flight(cfg, 0)
