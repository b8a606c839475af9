"""The scaling figure of the pushbroom chapter (hsgeo.plotting.solver_scaling)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from hsgeo import InputError, plotting  # noqa: E402

ROWS = [
    {"scale": 10.0, "n_observations": 4_400_000, "solver_seconds": 80.0, "peak_rss_mb": 9000.0,
     "peak_rss_mb_before_solve": 1800.0},
    {"scale": 1.0, "n_observations": 440_000, "solver_seconds": 4.0, "peak_rss_mb": 950.0,
     "peak_rss_mb_before_solve": 500.0},
    {"scale": 0.1, "n_observations": 44_000, "solver_seconds": 0.5, "peak_rss_mb": 400.0,
     "peak_rss_mb_before_solve": 350.0},
    {"scale": 3.0, "timeout_seconds": 3600},  # a case that timed out is left out
]  # fmt: skip
GOALS = {"scale": 10, "solver_seconds_max": 30, "peak_rss_mb_max": 10240}


def _line(ax, label_start):
    (line,) = [ln for ln in ax.get_lines() if ln.get_label().startswith(label_start)]
    return line


def test_solver_scaling_draws_rows_linear_line_and_goals():
    fig, axes = plt.subplots(1, 2)
    plotting.solver_scaling(axes, ROWS, goals=GOALS)
    ax_t, ax_m = axes
    assert ax_t.get_xscale() == ax_t.get_yscale() == "log" == ax_m.get_yscale()
    # the rows sorted by observations, the timed-out one left out
    t = _line(ax_t, "solver time")
    np.testing.assert_array_equal(t.get_xdata(), [44_000, 440_000, 4_400_000])
    np.testing.assert_array_equal(t.get_ydata(), [0.5, 4.0, 80.0])
    # linear growth through the 1× point: slope 1 in log-log, 4 s at 440,000 observations
    lin = _line(ax_t, "linear growth")
    x, y = np.asarray(lin.get_xdata(), float), np.asarray(lin.get_ydata(), float)
    slope = np.diff(np.log(y)) / np.diff(np.log(x))
    np.testing.assert_allclose(slope, 1.0)
    np.testing.assert_allclose(np.interp(np.log(440_000), np.log(x), np.log(y)), np.log(4.0))
    # the goals as horizontal lines
    assert _line(ax_t, "goal").get_ydata()[0] == 30
    assert _line(ax_m, "goal").get_ydata()[0] == 10240
    np.testing.assert_array_equal(_line(ax_m, "peak RSS (process)").get_ydata(), [400, 950, 9000])
    np.testing.assert_array_equal(_line(ax_m, "peak RSS before").get_ydata(), [350, 500, 1800])
    assert {a.get_text() for a in ax_t.texts} == {"0.1×", "1×", "10×"}
    plt.close(fig)


def test_solver_scaling_needs_the_reference_row():
    fig, axes = plt.subplots(1, 2)
    with pytest.raises(InputError, match="no row at scale 1"):
        plotting.solver_scaling(axes, [r for r in ROWS if r["scale"] != 1.0])
    plt.close(fig)
