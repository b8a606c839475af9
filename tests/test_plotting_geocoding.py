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
