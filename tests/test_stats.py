import numpy as np
import pandas as pd
import pytest

from hsgeo.errors import InputError, ObservationError
from hsgeo.stats import NMAD_SCALE, bias, describe, describe_table, nmad, rms, std


def test_nmad_of_large_normal_sample_is_sigma():
    sigma = 0.37  # px, 002 Table 1 STD of x
    x = np.random.default_rng(20261122).normal(0.5, sigma, 200_000)
    assert nmad(x) == pytest.approx(sigma, rel=0.02)


def test_nmad_hand_computed_example():
    # x = [3, -1, 4, 1, 5, 9, 2]; sorted [-1, 1, 2, 3, 4, 5, 9] -> median = 3
    # |x - 3| = [0, 4, 1, 2, 2, 6, 1]; sorted [0, 1, 1, 2, 2, 4, 6] -> median = 2
    # NMAD = 1.4826 * 2 = 2.9652
    x = [3.0, -1.0, 4.0, 1.0, 5.0, 9.0, 2.0]
    assert nmad(x) == pytest.approx(2.9652, abs=1e-12)
    assert NMAD_SCALE == 1.4826


def test_nmad_robust_to_outlier():
    # median 3, |x - 3| = [2, 1, 0, 1, 97] -> median 1 -> 1.4826
    assert nmad([1.0, 2.0, 3.0, 4.0, 100.0]) == pytest.approx(1.4826)


def test_std_uses_n_minus_1():
    x = np.random.default_rng(3).normal(size=17)
    assert std(x) == pytest.approx(np.std(x, ddof=1), rel=1e-14)
    assert std(x) != pytest.approx(np.std(x, ddof=0), rel=1e-6)


def test_000_table_2_bias_and_sigma():
    # 000 Table 2, Δy column: bias -0.2 m (Σ = -1.95 over 10 GCPs), σ = 0.88 m (Σ v² = 6.98)
    dy_m = [-1.1, -1.27, -0.3, -0.44, -0.61, -1.13, 0.34, 0.61, 1.3, 0.65]
    assert bias(dy_m) == pytest.approx(-0.195)
    assert std(dy_m) == pytest.approx(0.88, abs=0.005)


def test_rms_and_bias_values():
    x = np.array([3.0, -4.0])
    assert rms(x) == pytest.approx(np.sqrt(12.5))
    assert bias(x) == pytest.approx(-0.5)
    # rms² = bias² + (n-1)/n σ²
    y = np.random.default_rng(4).normal(1.0, 2.0, 50)
    assert rms(y) ** 2 == pytest.approx(bias(y) ** 2 + 49 / 50 * std(y) ** 2)


def test_axis_reduction():
    x = np.random.default_rng(5).normal(size=(4, 30))
    np.testing.assert_allclose(std(x, axis=1), np.std(x, axis=1, ddof=1))
    np.testing.assert_allclose(bias(x, axis=-1), x.mean(axis=1))
    np.testing.assert_allclose(
        nmad(x, axis=1),
        NMAD_SCALE * np.median(np.abs(x - np.median(x, axis=1, keepdims=True)), axis=1),
    )
    np.testing.assert_allclose(rms(x, axis=0), np.sqrt(np.mean(x**2, axis=0)))
    assert np.isclose(std(x), np.std(x, ddof=1))  # axis=None pools everything


def test_nan_policy_omit():
    x = np.array([1.0, np.nan, 2.0, 4.0, np.inf])
    assert bias(x, nan_policy="omit") == pytest.approx(7 / 3)
    assert std(x, nan_policy="omit") == pytest.approx(np.std([1, 2, 4], ddof=1))
    assert nmad(x, nan_policy="omit") == pytest.approx(1.4826)
    d = describe(x, nan_policy="omit")
    assert d["n"] == 3
    assert d["max"] == 4.0


def test_describe_keys_and_values():
    x = np.random.default_rng(6).normal(size=101)
    d = describe(x)
    assert list(d) == ["min", "max", "median", "mean", "std", "nmad", "rms", "n"]
    assert d["n"] == 101
    assert d["min"] == x.min()
    assert d["max"] == x.max()
    assert d["median"] == pytest.approx(np.median(x))
    assert d["mean"] == pytest.approx(x.mean())
    assert d["std"] == pytest.approx(x.std(ddof=1))
    assert d["rms"] == pytest.approx(np.sqrt(np.mean(x**2)))


def test_describe_table_layout():
    rng = np.random.default_rng(7)
    cols = {"E": rng.normal(size=13), "N": rng.normal(size=13), "H": rng.normal(size=9)}
    t = describe_table(cols)
    assert isinstance(t, pd.DataFrame)
    assert list(t.columns) == ["E", "N", "H"]
    assert list(t.index) == ["min", "max", "median", "mean", "std", "nmad", "rms", "n"]
    assert t.index.name == "statistic"
    assert t.shape == (8, 3)
    assert t.loc["n", "H"] == 9
    assert t.loc["nmad", "E"] == pytest.approx(nmad(cols["E"]))
    # 002 Table 1 layout (one row per coordinate) is the transpose
    assert list(t.T.columns[:6]) == ["min", "max", "median", "mean", "std", "nmad"]


# ------------------------------------------------------------------ error paths


@pytest.mark.parametrize("fun", [bias, std, rms, nmad, describe])
def test_nan_raises_by_default(fun):
    with pytest.raises(InputError, match="nan_policy='omit'"):
        fun([1.0, np.nan, 3.0])


@pytest.mark.parametrize("fun", [bias, std, rms, nmad, describe])
def test_bad_nan_policy_raises(fun):
    with pytest.raises(InputError, match="nan_policy"):
        fun([1.0, 2.0], nan_policy="propagate")


def test_std_needs_two_finite_values():
    with pytest.raises(ObservationError, match="at least 2"):
        std([1.0])
    with pytest.raises(ObservationError, match="at least 2"):
        std([1.0, np.nan, np.nan], nan_policy="omit")
    with pytest.raises(ObservationError):
        std(np.array([[1.0, 2.0], [3.0, np.nan]]), axis=1, nan_policy="omit")
    with pytest.raises(ObservationError):
        describe([2.0])


@pytest.mark.parametrize("fun", [bias, rms, nmad])
def test_empty_raises(fun):
    with pytest.raises(ObservationError):
        fun([])
    with pytest.raises(ObservationError):
        fun([np.nan], nan_policy="omit")


def test_non_numeric_and_bad_axis_raise():
    with pytest.raises(InputError, match="float"):
        bias(["a", "b"])
    with pytest.raises(InputError, match="axis"):
        std(np.zeros((3, 3)), axis=2)


def test_describe_table_errors_name_the_column():
    with pytest.raises(InputError, match="'N'"):
        describe_table({"E": [1.0, 2.0], "N": [1.0, np.nan]})
    with pytest.raises(ObservationError, match="'E'"):
        describe_table({"E": [1.0]})
    with pytest.raises(InputError, match="non-empty dict"):
        describe_table({})
    with pytest.raises(InputError, match="non-empty dict"):
        describe_table([[1.0, 2.0]])


# -- LRE (log relative error, McCullough 1998) ------------------------------------------------
def test_lre_hand_values():
    from hsgeo.stats import lre

    # |x − c| / |c| = 1e-6 → 6 digits; 5.4e-7 (Misra1a's b1 to 6 digits) → 6.27
    assert lre(1.000001, 1.0) == pytest.approx(6.0, abs=1e-9)
    assert lre(238.942, 238.94212918) == pytest.approx(-np.log10(0.00012918 / 238.94212918))
    assert lre(-2.0, -2.02) == pytest.approx(-np.log10(0.02 / 2.02))  # sign does not matter
    assert lre(2.5e-9, 0.0) == pytest.approx(-np.log10(2.5e-9))  # c = 0: log absolute error


def test_lre_caps_and_floors():
    from hsgeo.stats import lre

    np.testing.assert_array_equal(lre([3.0, 3.0], [3.0, 3.0]), [11.0, 11.0])  # exact: capped
    assert lre(1.0, 1.0, digits=15) == 15.0
    assert lre(0.0, 0.0) == 11.0
    assert lre(5.0, 1.0) == 0.0  # off by 400 %: no correct digit
    assert lre(np.nan, 1.0) == 0.0 and lre(np.inf, 1.0) == 0.0
    with pytest.raises(InputError, match="certified values must be finite"):
        lre(1.0, np.nan)
