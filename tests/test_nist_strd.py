"""NIST StRD: the reader, the 27 models' Jacobians, LRE, and the certified fits (issue 14).

The truth is NIST's certified values (11 digits): every parameter must have LRE ≥ 6 and every
standard deviation LRE ≥ 3 (McCullough 1998's yardstick for a reliable solver).
"""

import numpy as np
import pytest

from hsgeo.adjust.checks import check_jacobian
from hsgeo.errors import InputError
from hsgeo.io.nist_strd import NIST_STRD_NAMES, nist_strd_dir, read_nist_strd
from hsgeo.nist import MODELS, NistModel, covariance_sigma, fit_hsgeo

ALL = [n for group in NIST_STRD_NAMES.values() for n in group]
LOWER = list(NIST_STRD_NAMES["lower"])
HARDER = list(NIST_STRD_NAMES["average"]) + list(NIST_STRD_NAMES["higher"])


# -- the reader ---------------------------------------------------------------------------------
def test_reader_misra1a_against_the_file():
    p = read_nist_strd("Misra1a")
    assert p.name == "Misra1a" and p.difficulty == "lower"
    np.testing.assert_array_equal(p.starts, [[500.0, 1e-4], [250.0, 5e-4]])
    np.testing.assert_array_equal(p.certified, [2.3894212918e02, 5.5015643181e-04])
    np.testing.assert_array_equal(p.certified_sigma, [2.7070075241e00, 7.2668688436e-06])
    assert p.rss == 1.2455138894e-01 and p.dof == 12
    assert p.x.shape == (14, 1) and p.y[0] == 10.07 and p.x[-1, 0] == 760.0
    assert p.model == "y = b1*(1-exp[-b2*x]) + e"


@pytest.mark.parametrize("name", ALL)
def test_reader_every_file_is_consistent(name):
    p = read_nist_strd(name)
    assert p.starts.shape == (2, p.n_params)
    assert p.y.size == p.dof + p.n_params
    assert np.sqrt(p.rss / p.dof) == pytest.approx(p.residual_sd, rel=1e-9)


def test_reader_nelson_has_two_predictors_and_rat43_erratum():
    assert read_nist_strd("Nelson").x.shape == (128, 2)
    assert read_nist_strd("rat43").dof == 11  # the file says 9: NIST's erratum


def test_reader_errors(tmp_path):
    with pytest.raises(InputError, match="not one of the 27"):
        read_nist_strd("Misra9z")
    src = (nist_strd_dir() / "Misra1a.dat").read_text()
    bad = tmp_path / "bad.dat"
    bad.write_text(src.replace("  b2 =     0.0001", "  b3 =     0.0001"))
    with pytest.raises(InputError, match=r"line 42: expected 'b2 ="):
        read_nist_strd(bad)
    bad.write_text(src.replace("      81.78E0     760.0E0", "      81.78E0"))
    with pytest.raises(InputError, match=r"line 74: expected 2 numbers"):
        read_nist_strd(bad)
    bad.write_text(src.replace("1.0187876330E-01", "1.1187876330E-01"))
    with pytest.raises(InputError, match="residual standard deviation"):
        read_nist_strd(bad)
    bad.write_text(src.replace("Data              (lines 61 to 74)", ""))
    with pytest.raises(InputError, match="'Data   \\(lines A to B\\)'"):
        read_nist_strd(bad)


# -- the models ---------------------------------------------------------------------------------
def test_every_problem_has_a_model():
    assert sorted(MODELS) == sorted(ALL)


@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize("where", ["start1", "start2", "certified"])
def test_model_jacobian_against_finite_differences(name, where):
    p = read_nist_strd(name)
    b = p.certified if where == "certified" else p.starts[int(where[-1]) - 1]
    blk = NistModel(p)
    _, J = blk.evaluate({"b": b}, True)
    # central differences of the model in extended precision, step relative to each parameter
    f = MODELS[name]
    bl, xl = b.astype(np.longdouble), p.x.astype(np.longdouble)
    fd = np.empty_like(J["b"])
    for i in range(b.size):
        e = np.zeros_like(bl)
        e[i] = np.longdouble(1e-6) * abs(bl[i])
        fd[:, i] = (f(bl + e, xl)[0] - f(bl - e, xl)[0]) / (2 * e[i])
    scale = np.maximum(np.abs(fd).max(axis=0), 1e-300)
    np.testing.assert_allclose(J["b"] / scale, fd / scale, atol=1e-6)


def test_model_jacobian_engine_check():
    # the engine's own check (absolute step 1e-6) on Gauss1, whose parameters are all O(1–100)
    p = read_nist_strd("Gauss1")
    assert check_jacobian(NistModel(p), {"b": p.starts[0]}, "b") < 1e-6


def test_covariance_sigma_matches_the_normal_equations():
    rng = np.random.default_rng(0)
    J = rng.standard_normal((20, 3))
    sig = covariance_sigma(J, rss=17.0)
    np.testing.assert_allclose(sig, np.sqrt(17.0 / 17 * np.diag(np.linalg.inv(J.T @ J))))


# -- the certified fits -------------------------------------------------------------------------
def _assert_certified(name, start):
    f = fit_hsgeo(name, start)
    assert f.converged, f.message
    assert f.lre_params_min >= 6.0, (f.lre_params, f.params)
    assert f.lre_sigma_min >= 3.0, (f.lre_sigma, f.sigma)


@pytest.mark.parametrize("start", [1, 2])
@pytest.mark.parametrize("name", LOWER)
def test_lower_difficulty_certified(name, start):
    _assert_certified(name, start)


@pytest.mark.slow
@pytest.mark.parametrize("start", [1, 2])
@pytest.mark.parametrize("name", HARDER)
def test_average_and_higher_difficulty_certified(name, start):
    _assert_certified(name, start)
