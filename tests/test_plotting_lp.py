"""The LP-observations chapter's figures (hsgeo.plotting_lp): what they draw is what they were
given."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hsgeo import plotting_lp  # noqa: E402


def test_error_histogram_is_a_density_with_the_share_beyond():
    fig, ax = plt.subplots()
    e = np.r_[np.full(90, 0.25), np.full(10, 5.0)]
    plotting_lp.error_histogram(ax, {"a": e, "empty": []}, limit_px=3.0, bins=30)
    (patch,) = ax.patches
    assert "10.0 % beyond 3 px" in ax.get_legend().get_texts()[0].get_text()
    # a step histogram of density: the total area is 1 (beyond-limit values in the last bin)
    xy = patch.get_xy()
    heights = xy[1:-1:2, 1]
    assert np.isclose(np.sum(heights[:30] * 0.1), 1.0)
    plt.close(fig)


def test_band_counts_bars_and_red_edge():
    fig, ax = plt.subplots()
    wl = [450, 527, 604, 681, 758, 835, 912]
    plotting_lp.band_counts(ax, wl, {"kp": np.arange(1, 8) * 10, "obs": np.arange(1, 8)})
    assert len(ax.patches) >= 14
    heights = sorted(p.get_height() for p in ax.patches if p.get_width() < 50)
    assert heights[-1] == 70 and heights[0] == 1
    assert ax.get_yscale() == "log"
    plt.close(fig)


def test_scene_length_tradeoff_normalises_each_to_200_lines():
    fig, ax = plt.subplots()
    plotting_lp.scene_length_tradeoff(ax, [100, 200, 300], [50, 100, 120], [352431, 441587, 385166])
    paper, ours = ax.get_lines()[:2]
    assert np.allclose(ours.get_ydata(), [0.5, 1.0, 1.2])
    assert np.isclose(paper.get_ydata()[1], 1.0) and np.isclose(paper.get_ydata()[0], 0.7981, 1e-3)
    plt.close(fig)
