"""Binned residual vectors and the other plots of the frame_reference and rikola chapters."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from hsgeo import plotting  # noqa: E402


def test_bin_residuals_against_histogram2d():
    """Bin means equal sums/counts from numpy.histogram2d (an independent binning)."""
    rng = np.random.default_rng(3)
    size = (640, 480)
    uv = rng.uniform([0, 0], size, (2000, 2))
    r = rng.normal(0.0, 0.3, (2000, 2)) + 0.01 * uv / 100
    b = plotting.bin_residuals(uv, r, size, (8, 6))
    edges = (np.linspace(0, size[0], 9), np.linspace(0, size[1], 7))
    n, _, _ = np.histogram2d(uv[:, 0], uv[:, 1], edges)
    sx, _, _ = np.histogram2d(uv[:, 0], uv[:, 1], edges, weights=r[:, 0])
    sy, _, _ = np.histogram2d(uv[:, 0], uv[:, 1], edges, weights=r[:, 1])
    ix = (b["centre_px"][:, 0] / 80).astype(int)
    iy = (b["centre_px"][:, 1] / 80).astype(int)
    np.testing.assert_array_equal(b["count"], n[ix, iy])
    np.testing.assert_allclose(b["mean_px"][:, 0], sx[ix, iy] / n[ix, iy], rtol=1e-12)
    np.testing.assert_allclose(b["mean_px"][:, 1], sy[ix, iy] / n[ix, iy], rtol=1e-12)
    assert b["count"].sum() == 2000 and len(b["count"]) == 48
    # the standard error of a bin mean is about σ/√n
    assert abs(np.median(b["sem_px"] * np.sqrt(b["count"])) / 0.3 - 1) < 0.15


def test_binned_residuals_draws_one_arrow_per_filled_cell():
    uv = np.array([[10.0, 10.0], [12.0, 11.0], [15.0, 9.0], [600.0, 400.0]])
    r = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    fig, ax = plt.subplots()
    plotting.binned_residuals(ax, uv, r, (640, 480), bins=(8, 6), min_count=3)
    (q,) = [c for c in ax.collections if isinstance(c, matplotlib.quiver.Quiver)]
    assert q.N == 1  # the cell with a single residual is left out
    assert ax.get_ylim()[0] == 480 and ax.get_ylim()[1] < 0  # v down, a band for the key
    plt.close(fig)


def test_z_errorbars_and_residuals_by_band():
    fig, (a1, a2) = plt.subplots(2)
    plotting.z_errorbars(a1, ["a", "b"], [0.5, -5.0])
    assert a1.get_xlim()[0] <= -6.5
    plotting.residuals_by_band(a2, [500, 600], [0.1, 0.2], [0.01, 0.02], sensor=[2, 1])
    assert a2.get_xlabel().startswith("central wavelength")
    plt.close(fig)
