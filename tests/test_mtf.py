"""The Coltman CTF ↔ MTF series, bar targets, ESF → MTF (hsgeo.mtf)."""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo import mtf as M
from hsgeo.errors import InputError


def _gauss(sigma):
    return lambda f: M.mtf_gaussian(f, sigma) * M.mtf_pixel(f)


def _square_wave_ctf(mtf, f, n=4096):
    """Independent truth: filter one period of a unit square wave harmonic by harmonic (FFT of
    the sampled square wave, multiplied by the MTF at each harmonic), then its modulation."""
    x = (np.arange(n) + 0.5) / n  # one period, in units of the period
    sq = np.where(np.mod(x + 0.25, 1.0) < 0.5, 1.0, 0.0)  # white centred at x = 0
    spec = np.fft.rfft(sq)
    h = np.arange(spec.size)
    out = np.fft.irfft(spec * mtf(h * f), n)
    return (out.max() - out.min()) / (out.max() + out.min())


def test_inverse_coefficients_are_coltmans():
    k, c = M.coltman_mtf_coefficients(35)
    b = dict(zip(k.tolist(), np.round(c * k).astype(int).tolist(), strict=True))
    # Coltman (1954): + C(f) + C(3f)/3 − C(5f)/5 + C(7f)/7 + C(11f)/11 − C(13f)/13 − C(15f)/15
    # − C(17f)/17 + C(19f)/19 + C(21f)/21 ...; 9, 25, 27 are not square-free
    assert [b[i] for i in (1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 25, 27)] == [
        1, 1, -1, 1, 0, 1, -1, -1, -1, 1, 1, 0, 0,
    ]  # fmt: skip


@pytest.mark.parametrize("sigma", [0.5, 1.1, 2.0])
def test_forward_series_against_a_filtered_square_wave(sigma):
    m = _gauss(sigma)
    f = np.array([0.02, 0.05, 0.1, 0.2, 0.3, 0.45])
    ctf_series = M.ctf_from_mtf(m, f, k_max=999)
    ctf_wave = np.array([_square_wave_ctf(m, fi) for fi in f])
    np.testing.assert_allclose(ctf_series, ctf_wave, atol=2e-3)


@pytest.mark.parametrize("sigma", [0.3, 0.5, 1.1])
def test_round_trip_mtf_ctf_mtf(sigma):
    m = _gauss(sigma)
    f = np.linspace(0.01, 0.6, 25)

    def ctf(x):
        return M.ctf_from_mtf(m, x, k_max=999)

    back = M.mtf_from_ctf(ctf, f, k_max=199)
    np.testing.assert_allclose(back, m(f), atol=5e-3)


@pytest.mark.parametrize("sigma", [0.477, 1.1])
def test_printed_forward_equation_is_off_by_pi_over_4_squared(sigma):
    """001 eq. (6) as printed: where MTF(3f) ≈ 0 it returns (π/4)² = 0.617 of the CTF, and its
    largest error over 0.02–0.5 cy/px is more than 0.3 (the series itself: < 1e-3)."""
    m = _gauss(sigma)
    f = np.linspace(0.02, 0.5, 25)
    right = M.ctf_from_mtf(m, f, k_max=999)
    printed = M.ctf_from_mtf_printed(m, f)
    assert np.max(np.abs(printed - right)) > 0.3
    np.testing.assert_allclose(printed[-1] / right[-1], (np.pi / 4) ** 2, rtol=2e-3)
    wave = np.array([_square_wave_ctf(m, fi) for fi in f[::6]])
    np.testing.assert_allclose(right[::6], wave, atol=2e-3)


def test_printed_inverse_is_truncated():
    m = _gauss(0.3)
    f = np.array([0.03])

    def ctf(x):
        return M.ctf_from_mtf(m, x, k_max=999)

    full = M.mtf_from_ctf(ctf, f)
    printed = M.mtf_from_ctf_printed(ctf, f)
    assert abs(full[0] - m(f)[0]) < 5e-3
    assert abs(printed[0] - m(f)[0]) > abs(full[0] - m(f)[0])


def test_bar_target_layout():
    t = M.BarTarget.geometric(20.88, 0.92, 2 ** (1 / 6), min_group_mm=12.0)
    assert t.n_groups == 28
    assert t.pair_mm[0] == 20.88 and abs(t.pair_mm[-1] - 0.92) < 0.005
    assert t.n_pairs[0] == 2 and t.pair_mm[-1] * t.n_pairs[-1] >= 12.0
    x = t.group_start_mm()[3] + np.array([0.1, 0.6]) * t.pair_mm[3]
    np.testing.assert_array_equal(t.reflectance(x), [0.90, 0.04])
    assert t.reflectance(np.array([-1.0, t.length_mm() + 1]))[0] == 0.90
    with pytest.raises(InputError):
        M.BarTarget((1.0, -1.0), (2, 2))
    with pytest.raises(InputError):
        M.BarTarget((1.0,), (2, 2))


def test_mtf_from_esf_of_a_gaussian_edge():
    from scipy.special import ndtr

    sigma, d = 0.8, 0.25
    x = (np.arange(-256, 256) + 0.5) * d
    # ESF of a Gaussian blur averaged over each bin's box (the binning of the slanted edge)
    fine = np.linspace(-0.5, 0.5, 41)[:, None] * d
    esf = ndtr((x + fine) / sigma).mean(axis=0)
    f, m, _ = M.mtf_from_esf(esf, d)
    keep = f <= 1.0
    np.testing.assert_allclose(m[keep], M.mtf_gaussian(f[keep], sigma), atol=0.01)


def test_crossing_frequency():
    f = np.linspace(0, 1, 101)
    assert abs(M.crossing_frequency(f, 1 - f, 0.1) - 0.9) < 1e-9
    assert np.isnan(M.crossing_frequency(f, np.ones_like(f), 0.1))


@pytest.mark.parametrize("sigma", [0.3, 0.477, 1.1])
def test_band_limited_round_trip(sigma):
    """A CTF of the harmonics below Nyquist, inverted with the same cut, gives the MTF back."""
    m = _gauss(sigma)
    fm = np.geomspace(0.02, 0.52, 200)
    ctf = M.ctf_band_limited(m, fm)
    f = np.linspace(0.03, 0.49, 30)
    back = M.mtf_from_ctf_samples(fm, ctf, f, nyquist_cy_px=0.5)
    np.testing.assert_allclose(back, m(f), atol=1e-3)
    # at the bar target's spacing (2^(1/6)) the interpolation costs at most a few hundredths
    groups = 0.4838 / (20.88 / 2 ** (np.arange(28) / 6))
    coarse = M.mtf_from_ctf_samples(groups, M.ctf_band_limited(m, groups), f, nyquist_cy_px=0.5)
    assert np.abs(coarse - m(f)).max() < 0.06
