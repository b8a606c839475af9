import numpy as np
import pytest

from hsgeo import ConvergenceError, DatumError, InputError, ObservationError
from hsgeo.adjust import adjust, identifiability
from hsgeo.adjust.checks import check_jacobian
from hsgeo.papers import P001_TABLE2
from hsgeo.sensors import line1d as L
from hsgeo.workflows.line_calibration import calibrate

K_NIR = np.array([1.459, -0.1636, 0.00526])  # 000 Table 1


def bench(offset_m=0.05, K=K_NIR, sigma=0.05, seed=None):
    a = np.deg2rad([-45.0, 0.0, 45.0])
    eop = np.column_stack([3 * np.sin(a), -3 * np.cos(a), a])
    pts = np.column_stack([np.arange(-0.26, 0.2601, 0.02), np.zeros(27)])
    pts = np.vstack([pts, [[-0.34, -offset_m], [0.34, -offset_m]]])
    img = np.repeat(np.arange(3), len(pts))
    pt = np.tile(np.arange(len(pts)), 3)
    z = L.project(pts[pt], eop[img], 486.8, 3539.0, K)
    if seed is not None:
        z = z + sigma * np.random.default_rng(seed).standard_normal(z.size)
    return eop, pts, img, pt, z


def test_published_magnitudes_with_100px_normalisation():
    # 001 §3.1/§4: ~4 px max (blue-indigo), ≤ ~11 px visible, > 25 px at 450 px (NIR)
    mx100, at, _ = L.distortion_extremes([P001_TABLE2[0].K1, P001_TABLE2[0].K2, P001_TABLE2[0].K3])
    assert mx100 == pytest.approx(4.0, abs=0.1) and 200 < at < 350
    for row in P001_TABLE2[1:3]:
        assert L.distortion_extremes([row.K1, row.K2, row.K3])[0] < 11.0
    r = P001_TABLE2[3]
    assert L.distortion_extremes([r.K1, r.K2, r.K3])[2] > 25.0
    assert L.distortion_px(486.8 + 450, 486.8, K_NIR) == pytest.approx(27.6, abs=0.05)


def test_tan_zeta_round_trip_and_odd_symmetry():
    z = np.linspace(486.8 - 440, 486.8 + 440, 201)
    t = L.tan_from_zeta(z, 486.8, 3539.0, K_NIR)
    np.testing.assert_allclose(L.zeta_from_tan(t, 486.8, 3539.0, K_NIR), z, atol=1e-8)
    assert np.all(np.diff(t) < 0)  # monotonic: larger ζ, more negative X/Y
    np.testing.assert_allclose(t + t[::-1], 0.0, atol=1e-12)
    # without distortion it is the pinhole: tan = -(ζ-ζ0)/c
    np.testing.assert_allclose(L.tan_from_zeta(z, 486.8, 3539.0, [0, 0, 0]), -(z - 486.8) / 3539.0)


def test_zeta_from_tan_outside_domain_raises():
    with pytest.raises(ConvergenceError, match="outside"):
        L.zeta_from_tan(0.2, 486.8, 3539.0, K_NIR)


def test_project_satisfies_eq2_and_matches_view_direction():
    eop, pts, img, pt, z = bench()
    X, Y = L.camera_xy(pts[pt], eop[img])
    # 000 eq. (2), implicit form
    rhs = 486.8 - 3539.0 * X / Y + L.distortion_px(z, 486.8, K_NIR)
    np.testing.assert_allclose(z, rhs, atol=1e-8)
    np.testing.assert_allclose(L.tan_from_zeta(z, 486.8, 3539.0, K_NIR), X / Y, atol=1e-12)


@pytest.mark.parametrize(
    "name,step", [("eop", 1e-6), ("zeta0_px", 1e-4), ("c_px", 1e-2), ("K", 1e-6), ("xy_m", 1e-6)]
)
def test_jacobians(name, step):
    eop, pts, img, pt, z = bench(seed=1)
    blk = L.LineObservations(img, pt, z, 0.05)
    vals = {
        "eop": eop + [0.01, -0.02, 0.003],
        "zeta0_px": np.array(488.0),
        "c_px": np.array(3500.0),
        "K": K_NIR * 1.1,
        "xy_m": pts,
    }
    assert check_jacobian(blk, vals, name, step) < 1e-6


def test_explicit_form_is_implicit_times_Fprime():
    eop, pts, img, pt, z = bench()
    zobs = z + 0.01
    # implicit residual is -0.01 exactly; the explicit residual F(ζ_obs) is (1-δ') times it
    F = zobs - L.distortion_px(zobs, 486.8, K_NIR) - 486.8
    X, Y = L.camera_xy(pts[pt], eop[img])
    F += 3539.0 * X / Y
    Fp = 1 - L.distortion_derivative(z, 486.8, K_NIR)
    np.testing.assert_allclose(F, 0.01 * Fp, rtol=1e-3)
    assert Fp.min() < 0.75  # the edge observations would be down-weighted without the implicit form


def _params(eop, pts, K=K_NIR, **kw):
    return L.make_parameters(eop, 486.8, 3539.0, K, pts, np.ones(len(pts), bool), **kw)


def test_naive_single_line_bench_is_rank_deficient_and_names_zeta0_and_c():
    eop, pts, img, pt, z = bench(offset_m=0.0, K=np.zeros(3))
    blk = L.LineObservations(img, pt, z, 0.05)
    idf = identifiability(_params(eop, pts, K=np.zeros(3)), blk)
    assert (idf.rank, idf.n_unknowns) == (12, 14)
    with pytest.raises(DatumError) as ei:
        adjust(_params(eop, pts, K=np.zeros(3)), blk)
    assert "zeta0_px" in ei.value.parameters and "c_px" in ei.value.parameters
    # with the published distortion the centre is pinned, the scale is not
    eop, pts, img, pt, z = bench(offset_m=0.0)
    blk = L.LineObservations(img, pt, z, 0.05)
    idf = identifiability(_params(eop, pts), blk)
    assert (idf.rank, idf.n_unknowns) == (13, 14)
    assert "c_px" in idf.deficient_parameters() and "zeta0_px" not in idf.deficient_parameters()


def test_offline_side_signals_or_station_priors_make_it_full_rank():
    eop, pts, img, pt, z = bench(offset_m=0.05)
    assert identifiability(_params(eop, pts), L.LineObservations(img, pt, z, 0.05)).full_rank
    eop, pts, img, pt, z = bench(offset_m=0.0)
    ps = np.tile([0.01, 0.01, np.inf], (3, 1))
    assert identifiability(
        _params(eop, pts, eop_prior_sigma=ps), L.LineObservations(img, pt, z, 0.05)
    ).full_rank


@pytest.mark.parametrize("seed", range(4))
def test_truth_within_3_sigma(seed):
    eop, pts, img, pt, z = bench(seed=seed)
    p = L.make_parameters(
        eop + [0.02, -0.03, 0.01], 485.0, 3600.0, [0, 0, 0], pts, np.ones(len(pts), bool)
    )
    res = calibrate(p, L.LineObservations(img, pt, z, 0.05))
    for name, truth in [("zeta0_px", 486.8), ("c_px", 3539.0), ("K", K_NIR), ("eop", eop)]:
        assert np.all(np.abs(res.value(name) - truth) < 3.5 * res.sigma(name)), name
    lo, hi = res.chi2_interval()
    assert lo < res.sigma0 < hi


def test_single_orientation_bench_is_degenerate():
    eop, pts, img, pt, z = bench(offset_m=0.0, seed=0)
    s = img == 1  # one orientation of the pattern line
    with pytest.raises(DatumError, match="c_px"):
        adjust(_params(eop[1:2], pts), L.LineObservations(img[s] * 0, pt[s], z[s], 0.05))


def test_minimum_observation_rule():
    eop, pts, img, pt, z = bench()
    ctrl = np.ones(len(pts), bool)
    L.check_minimum_observations(img, pt, ctrl)
    keep = ~((img == 1) & (pt > 1))  # image 1 keeps 2 control points
    with pytest.raises(ObservationError, match="image 1 observes 2 control"):
        L.check_minimum_observations(img[keep], pt[keep], ctrl)
    keep = pt < 4  # 4 per image: 12 < 3*3 + 5
    with pytest.raises(ObservationError, match="at least 3 per image plus 5"):
        L.check_minimum_observations(img[keep], pt[keep], ctrl)


def test_bad_input():
    eop, pts, img, pt, z = bench()
    z[3] = np.nan
    with pytest.raises(InputError, match="NaN"):
        L.LineObservations(img, pt, z, 0.05)
    with pytest.raises(InputError, match="one entry per observation"):
        L.LineObservations(img[:-1], pt, np.zeros(pt.size), 0.05)
    with pytest.raises(InputError, match="behind the camera"):
        L.project([[0.0, -5.0]], eop[1], 486.8, 3539.0, K_NIR)
    with pytest.raises(InputError, match="K must be"):
        L.distortion_px(1.0, 0.0, [1.0, 2.0])


def test_resection_recovers_station():
    eop, pts, img, pt, z = bench()
    for i in range(3):
        s = img == i
        r = L.resect(pts[pt[s]], z[s], 486.8, 3539.0, K_NIR)
        assert np.all(np.abs(r.eop - eop[i]) < [0.02, 0.02, 0.01])
