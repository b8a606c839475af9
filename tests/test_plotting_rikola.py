"""The Rikola gap plot draws 003 eq. (2) through the sensor module's one implementation."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hsgeo.plotting import plot_gap_model  # noqa: E402


def test_gap_plot_lines_are_f_of_gap():
    fig, ax = plt.subplots()
    try:
        gaps = [1000.0, 1200.0, 1500.0]
        plot_gap_model(
            ax, gaps, [8.70, 8.72, 8.74], [0.01] * 3, {"a": 8e-5, "b": 8.62}, 1, (9e-5, 8.61)
        )
        fitted, truth = ax.lines[-2], ax.lines[-1]
        g = np.asarray(fitted.get_xdata())
        np.testing.assert_allclose(g, [990.0, 1510.0])
        # f = a·gap + b (003 eq. (2)), typed here independently of the code under test
        np.testing.assert_allclose(fitted.get_ydata(), 8e-5 * g + 8.62, rtol=1e-15)
        np.testing.assert_allclose(truth.get_ydata(), 9e-5 * g + 8.61, rtol=1e-15)
    finally:
        plt.close(fig)
