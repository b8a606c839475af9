"""hsgeo.radiometry: the dark fit against numpy.polyfit, hot pixels, the reflectance relation,
patch means whose σ̂ covers the truth, vegetation indices (GUIDE §6 kinds 1, 4, 5)."""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo import radiometry as R
from hsgeo.errors import InputError


def _dark(seed, shape=(6, 7), n_per=3):
    rng = np.random.default_rng(seed)
    t = np.repeat([0.01, 0.1, 0.3, 0.6], n_per)
    a = rng.uniform(2, 20, shape)
    b = rng.uniform(45, 55, shape)
    frames = a[None] * t[:, None, None] + b[None] + 1.5 * rng.standard_normal((t.size, *shape))
    return frames, t, a, b


def test_fit_dark_matches_polyfit_with_covariance():
    """Reference: numpy.polyfit(deg=1, cov='unscaled') per pixel (an independent implementation)."""
    frames, t, _, _ = _dark(0)
    m = R.fit_dark(iter(frames), t)  # a generator: read once
    for i, j in [(0, 0), (3, 4), (5, 6)]:
        p, cov = np.polyfit(t, frames[:, i, j], 1, cov=True)
        assert m.a_dn_per_s[i, j] == pytest.approx(p[0], rel=1e-10)
        assert m.b_dn[i, j] == pytest.approx(p[1], rel=1e-10)
        assert m.sigma_a_dn_per_s[i, j] == pytest.approx(np.sqrt(cov[0, 0]), rel=1e-8)
        assert m.sigma_b_dn[i, j] == pytest.approx(np.sqrt(cov[1, 1]), rel=1e-8)
        assert m.cov_ab[i, j] == pytest.approx(cov[0, 1], rel=1e-8)
        res = frames[:, i, j] - np.polyval(p, t)  # σ0: the residuals' σ, n − 2 dof
        assert m.sigma0_dn[i, j] == pytest.approx(np.sqrt(res @ res / (t.size - 2)), rel=1e-8)
    assert m.predict(0.2).shape == (6, 7)


@pytest.mark.parametrize("seed", range(8))
def test_fit_dark_within_3_sigma_of_the_truth(seed):
    frames, t, a, b = _dark(seed, shape=(40, 50))
    m = R.fit_dark(frames, t)
    za = (m.a_dn_per_s - a) / m.sigma_a_dn_per_s
    zb = (m.b_dn - b) / m.sigma_b_dn
    # t with 10 degrees of freedom: P(|t| ≤ 3) = 0.987
    assert np.mean(np.abs(za) <= 3) > 0.97
    assert np.mean(np.abs(zb) <= 3) > 0.97


def test_fit_dark_errors():
    frames, t, _, _ = _dark(0)
    with pytest.raises(InputError, match="one exposure time"):
        R.fit_dark(frames, np.full(t.size, 0.1))
    with pytest.raises(InputError, match="one size"):
        R.fit_dark([frames[0], frames[1][:, :3], frames[2]], t[[0, 3, 6]])
    with pytest.raises(InputError, match="at least 3"):
        R.fit_dark(frames[:2], [0.1, 0.2])


def test_hot_pixels_found_and_no_false_alarms():
    frames, t, a, b = _dark(3, shape=(50, 60))
    hot = np.zeros(a.shape, bool)
    hot[[3, 20, 40], [5, 30, 59]] = True
    frames = frames + (hot * 2000.0)[None] * t[:, None, None]
    found = R.find_hot_pixels(R.fit_dark(frames, t))
    assert np.array_equal(found, hot)


def test_reflectance_relation_and_incident_mean():
    """001 §2.1: r = G_ref E_ref F(α) / (G_inc E_inc F(θ)), by hand."""
    e_ref = np.array([[100.0, 200.0], [50.0, 25.0]])  # rows × samples
    e_inc = np.array([400.0, 100.0])
    r = R.reflectance(e_ref, e_inc, g_ref=2.0, g_inc=[1.0, 4.0], f_alpha=0.5, f_theta=[1.0, 0.8])
    want = np.array(
        [
            [2 * 100 * 0.5 / (400 * 1.0), 2 * 200 * 0.5 / (400 * 0.8)],
            [2 * 50 * 0.5 / (4 * 100 * 1.0), 2 * 25 * 0.5 / (4 * 100 * 0.8)],
        ]
    )
    np.testing.assert_allclose(r, want)
    inc = np.array([[1.0, 2.0, 300.0], [3.0, 5.0, 4.0]])
    assert R.incident_mean(inc, hot=np.array([[0, 0, 1], [0, 0, 0]], bool)).tolist() == [1.5, 4.0]


def test_layout_and_eq8():
    assert (R.frame_layout(1).n_reflected, R.frame_layout(1).n_incident) == (1170, 110)
    assert R.frame_layout(1).frame_rate_hz == 12.5
    with pytest.raises(InputError, match="--binning"):
        R.frame_layout(3)
    assert R.eq8_speed_m_s(0.0014, 24.0) == pytest.approx(0.0336)


def test_bin_rows_and_fwhm():
    x = np.arange(12.0).reshape(1, 12, 1)
    assert R.bin_rows(x, 5, axis=1).ravel().tolist() == [2.0, 7.0]
    lam, fw = R.band_fwhm_nm(430 + 0.88 * np.arange(10), np.full(10, 4.4), 5)
    assert lam[0] == pytest.approx(430 + 0.88 * 2)
    assert fw[0] == pytest.approx(np.hypot(4.4, 4.4))


def test_patch_mean_sigma_covers_shared_column_and_line_errors():
    """Coverage over 400 patches with column, line and pixel errors: σ̂ must be honest."""
    rng = np.random.default_rng(5)
    z, sig = [], []
    for _ in range(400):
        y = (
            0.3
            + 0.01 * rng.standard_normal((1, 30))  # a column's shared error (dark fit)
            + 0.005 * rng.standard_normal((20, 1))  # a line's shared error (incident)
            + 0.02 * rng.standard_normal((20, 30))
        )
        m, s = R.patch_mean(y)
        z.append((m - 0.3) / s)
        sig.append(s)
    z = np.abs(np.array(z))
    assert 0.62 < np.mean(z <= 1) < 0.76
    assert np.mean(z <= 3) > 0.98
    naive = 0.02 / np.sqrt(600)  # the independent-noise σ would be far too small
    assert np.median(sig) > 2 * naive


def test_vegetation_indices_by_hand_and_delta_method():
    lam = np.array([470.0, 531.0, 570.0, 670.0, 705.0, 720.0, 740.0, 750.0, 800.0])
    s = np.array([0.04, 0.09, 0.10, 0.05, 0.20, 0.30, 0.40, 0.42, 0.45])
    assert R.vegetation_index("NDVI", lam, s) == pytest.approx((0.45 - 0.05) / 0.50)
    assert R.vegetation_index("SR", lam, s) == pytest.approx(9.0)
    assert R.vegetation_index("EVI", lam, s) == pytest.approx(2.5 * 0.40 / (0.45 + 0.30 - 0.30 + 1))
    assert R.vegetation_index("PRI", lam, s) == pytest.approx(-0.01 / 0.19)
    assert R.vegetation_index("VOG1", lam, s) == pytest.approx(0.40 / 0.30)
    assert R.vegetation_index("NDVI705", lam, s) == pytest.approx(0.22 / 0.62)
    # the delta-method σ against the spread of 4000 perturbed spectra
    sig = np.full(lam.size, 0.002)
    rng = np.random.default_rng(1)
    for name in R.INDICES:
        v, sv = R.vegetation_index(name, lam, s, sigma=sig)
        mc = R.vegetation_index(name, lam, s + sig * rng.standard_normal((4000, lam.size)))
        assert sv == pytest.approx(np.std(mc), rel=0.1), name
    with pytest.raises(InputError, match="needs reflectance"):
        R.vegetation_index("NDVI", lam[:4], s[:4])


def test_every_index_formula_names_the_wavelengths_it_uses():
    for name, ix in R.INDICES.items():
        assert ix.name == name and ix.source
        shown = {float(w) for w in __import__("re").findall(r"R(\d+)", ix.formula)}
        assert shown == set(ix.wavelengths_nm), (name, ix.formula)
