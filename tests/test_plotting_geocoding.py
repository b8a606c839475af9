"""Plot helpers of the line-calibration and geocoding chapters: they draw what they are given."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hsgeo import plotting as hp  # noqa: E402


def test_deviation_quiver_draws_vectors_magnified_in_map_units():
    fig, ax = plt.subplots()
    en = np.array([[0.0, 0.0], [100.0, 50.0]])
    dev = np.array([[1.0, -0.5], [0.2, 0.3]])
    hp.deviation_quiver(ax, en, dev, magnify=40.0, key_m=1.0)
    hp.scale_bar(ax, 100.0)
    q = ax.collections[0]
    assert np.allclose(q.U, dev[:, 0]) and np.allclose(q.V, dev[:, 1])
    assert q.scale == 1 / 40.0  # one deviation metre spans 40 map metres
    assert ax.get_aspect() == 1.0
    plt.close(fig)


def test_binned_residuals_and_displacement_band():
    fig, ax = plt.subplots()
    z = np.linspace(0, 900, 200)
    r = np.where(z < 450, 0.1, -0.1)
    hp.residuals_vs_position(ax, z, r, n_bins=2)
    binned = ax.lines[1].get_ydata()
    assert np.allclose(binned, [0.1, -0.1])  # the mean of each half
    ax.clear()
    d = np.tile(np.arange(5.0), (101, 1)) + np.linspace(-1, 1, 101)[:, None]
    hp.displacement_vs_pixel(ax, np.arange(5), d)
    assert np.allclose(ax.lines[0].get_ydata(), np.arange(5.0))  # the median over lines
    plt.close(fig)


def test_iop_against_wavelength_draws_values_paper_and_the_weighted_trend():
    lam = np.array([450.0, 550.0, 650.0, 750.0, 850.0])
    v = 3500.0 + 0.002 * (lam - 600.0) ** 2  # exactly quadratic: the trend passes through it
    fig, ax = plt.subplots()
    hp.iop_against_wavelength(ax, lam, v, np.full(5, 0.5), v + 1.0, 2)
    paper, trend = ax.get_lines()[-2:]
    np.testing.assert_allclose(paper.get_ydata(), v + 1.0)
    np.testing.assert_allclose(trend.get_xdata()[[0, -1]], [450.0, 850.0])
    np.testing.assert_allclose(trend.get_ydata(), 3500.0 + 0.002 * (trend.get_xdata() - 600.0) ** 2)
    assert "degree 2" in trend.get_label() and ax.get_xlabel() == "wavelength (nm)"
    plt.close(fig)


def test_gcp_deviation_map_draws_both_deviations_and_labels_every_gcp():
    gcp = np.array([[0.0, 0.0], [100.0, 50.0], [200.0, -30.0]])
    dev_sim = np.array([[0.1, 0.0], [0.0, -0.2], [0.05, 0.05]])
    fig, ax = plt.subplots()
    hp.gcp_deviation_map(
        ax,
        [[-50.0, 0.0], [250.0, 0.0]],
        gcp,
        [7, 8, 9],
        dev_sim,
        gcp[:2],
        dev_sim[:2] * 3,
        magnify=40.0,
        sim_label="sim",
        paper_label="000 Table 2",
    )
    sim_q, paper_q = ax.collections[:2]
    np.testing.assert_allclose(sim_q.U, dev_sim[:, 0])
    np.testing.assert_allclose(paper_q.V, 3 * dev_sim[:2, 1])
    assert sim_q.scale == 1 / 40.0 and len(paper_q.U) == 2
    assert [t.get_text() for t in ax.texts] == ["7", "8", "9"]
    assert {t.get_text() for t in ax.get_legend().get_texts()} >= {
        "flight line",
        "sim",
        "000 Table 2",
    }
    plt.close(fig)
