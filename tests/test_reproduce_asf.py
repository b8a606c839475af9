"""``hsgeo reproduce asf``: the tables, strict JSON, the claims' verdicts, determinism."""

import json

import numpy as np
import pytest

from hsgeo.papers import ASF_004
from hsgeo.reproduce import run
from hsgeo.reproduce.asf import TUNED_CHANNEL, asf_at_shift
from hsgeo.simulate.asf_runway import ASF_PEAK_TO_PEAK_PERCENT, RunwayScene, simulate_runway


@pytest.fixture(scope="module")
def rep():
    return run("asf", seed=5, scale=0.3)


def test_tables_and_json(rep):
    assert rep.tables() == [
        "004 ASF",
        "004 variation",
        "004 text",
        "004 registration",
        "004 BRDF leak",
        "unmodelled effect",
    ]
    d = json.loads(rep.to_json())
    assert d["chapter"] == "asf" and d["seed"] == 5
    assert [r["quantity"] for r in d["rows"] if r["table"] == "004 text"] == list(ASF_004)
    for r in rep.rows:
        if r.judge()[0] is not None:
            assert r.provenance is not None, r.quantity


def test_the_done_criterion_and_the_leak(rep):
    """Within 1 % on a Lambertian runway; the BRDF's odd part leaks into one crossing and is
    removed by two opposite crossings, its even part stays (004's stated limit). The per-angle
    rows' σ is the noise's spread only: the joints leave a systematic error of a few tenths of a
    per cent in single columns (the two scans' footprints differ), so more than the noise's
    share of them lie beyond 3σ (seed 5: 82 % within, was > 90 % on a runway without joints)."""
    assert rep.meta["max_abs_error_percent"] < 1.0
    assert rep.meta["n_usable"] == rep.meta["n_px"] == 716
    leak = {r.quantity: r for r in rep.rows_of("004 BRDF leak")}
    one = leak["odd part: max error, BRDF, one crossing"]
    two = leak["odd part: max error, BRDF, two opposite crossings"]
    even2 = leak["even part: max error, BRDF, two opposite crossings"]
    assert one.reproduced > 3 * two.reproduced
    assert abs(one.reproduced - one.truth) < 0.5 and abs(even2.reproduced - even2.truth) < 0.5
    assert even2.reproduced > 1.0
    z = [r.z for r in rep.rows_of("004 ASF") if r.z is not None]
    assert len(z) == 44 and np.mean(np.abs(z) <= 3) > 0.75


def test_simulation_is_deterministic():
    a, ta = simulate_runway(RunwayScene(), 9, reverse=False)
    b, tb = simulate_runway(RunwayScene(), 9, reverse=False)
    assert np.array_equal(a.cross.values, b.cross.values)
    assert np.array_equal(a.along.values, b.along.values)
    c, _ = simulate_runway(RunwayScene(), 10, reverse=False)
    assert not np.array_equal(a.cross.values, c.cross.values)


def test_provenance_of_the_built_in_agreements(rep):
    """Channel 1's variation was set to 004's 15 %: tuned, by construction, never reproduced;
    the nadir GSD (0.63 m from the paper's own 300 m and 0.12°) is not the paper's 0.7 m."""
    text = {r.quantity: r for r in rep.rows_of("004 text")}
    var = text["ASF variation, largest channel"]
    # at this test's scale the spread comes from fewer than 8 runs: "not testable" (report's
    # rule); at the chapter's scale the tuned agreement is "by construction"; never "reproduced"
    assert var.provenance == "tuned"
    expect = "by construction" if (var.n_runs or 0) >= 8 else "not testable"
    assert var.judge()[0] == expect
    prov = [r.provenance for r in rep.rows_of("004 variation")]
    assert prov[TUNED_CHANNEL] == "tuned" and prov.count("tuned") == 1
    assert ASF_PEAK_TO_PEAK_PERCENT[TUNED_CHANNEL] == ASF_004["ASF variation, largest channel"][0]
    gsd = text["nadir GSD at 300 m"]
    assert gsd.judge()[0] == "differs" and abs(gsd.reproduced - 0.628) < 0.001
    assert not any(r.judge()[0] == "reproduced" for r in rep.rows_of("004 text"))


def test_asf_at_shift_places_the_along_image(rep):
    """Placed at the true offset, the along image gives the ASF within 1 % of the truth and within
    0.1 % of the registered result; placed 2 px off along the runway, the error grows."""
    X = rep.extras
    gc, ga, P, truth = X["cross"], X["along"], X["runway_polygon_m"], X["truth"]
    true_n, reg = X["true_normalised"], X["results"][0]
    at = asf_at_shift(gc, ga, P, truth.shift_m)
    assert np.max(np.abs(at.asf - true_n)) < 0.01
    assert np.max(np.abs(at.asf - reg.asf)) < 0.001
    off = asf_at_shift(gc, ga, P, truth.shift_m + [2 * reg.registration.gsd_m, 0.0])
    assert np.max(np.abs(off.asf - true_n)) > 1.2 * np.max(np.abs(at.asf - true_n))


def test_unmodelled_effects_carry_their_noise_spread(rep):
    """Every unmodelled-effect row has a spread over the noise runs; the BRDF and the missing
    registration move the headline error by far more than that spread."""
    u = {r.quantity.split(", ", 1)[1]: r for r in rep.rows_of("unmodelled effect")}
    assert all(r.sigma is not None and 0 < r.sigma < 0.2 for r in u.values())
    base = u["none (Lambertian runway, registered)"]
    assert base.reproduced == rep.meta["max_abs_error_percent_runs"][0]
    from hsgeo.reproduce.asf import path_label

    path = path_label(RunwayScene())
    for k in ("BRDF of the runway (one crossing)", "no registration (navigation only)", path):
        assert u[k].reproduced - base.reproduced > 5 * max(u[k].sigma, base.sigma)
    # the residual path radiance is zero at nadir and 3 % of the runway at 43°: it enters the
    # ASF almost in full
    assert 2.0 < u[path].reproduced < 4.0
    assert u[path].reproduced > 1.0 > base.reproduced


def test_the_chapter_runs_the_users_workflow(rep):
    """Run 0 is hsgeo asf's workflow on the raw scans with the recorded navigation of all flights
    in one record: the same numbers as the command on the same files would give."""
    from hsgeo.reproduce.asf import flights_inputs
    from hsgeo.workflows.asf_flights import asf_from_flights

    obs, _ = simulate_runway(RunwayScene(), 5)
    inp = flights_inputs(obs)
    assert inp.trajectory.t_s[0] <= obs.cross.t0_s and inp.trajectory.t_s[-1] > obs.along.t0_s
    res = asf_from_flights(inp)
    np.testing.assert_array_equal(res.cross.asf, rep.extras["results"][0].asf)
