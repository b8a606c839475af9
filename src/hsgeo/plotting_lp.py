"""Figures of the LP-observations chapter (002 §3.1, §4): matplotlib only; every function takes
an Axes and returns it, and computes nothing the chapter reports.

Kept apart from :mod:`hsgeo.plotting` (already past the ~600-line mark; GUIDE §2: "plotting/
per chapter when big"); 002 Fig. 3 stays there as :func:`hsgeo.plotting.plot_lp_compensation`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["error_histogram", "band_counts", "scene_length_tradeoff"]


def error_histogram(ax, errors_px: dict, *, limit_px: float = 3.0, bins: int = 60):
    """Distribution of retrieved observations' distances from their true image positions.

    Parameters
    ----------
    ax : matplotlib Axes
    errors_px : dict of str to (n,) array_like
        Label -> distances (px); each drawn as a step histogram normalised to a density, with
        the share beyond ``limit_px`` in the label.
    limit_px : float
        Right end of the axis (px); the ½ px and 1 px marks are drawn.
    bins : int

    Returns
    -------
    ax
    """
    edges = np.linspace(0.0, limit_px, bins + 1)
    for k, (label, e) in enumerate(errors_px.items()):
        e = np.asarray(e, float)
        e = e[np.isfinite(e)]
        if e.size == 0:
            continue
        beyond = float(np.mean(e > limit_px))
        ax.hist(
            np.minimum(e, limit_px),
            bins=edges,
            density=True,
            histtype="step",
            lw=1.3,
            color=f"C{k}",
            label=f"{label} (n = {e.size:,}; {100 * beyond:.1f} % beyond {limit_px:g} px)",
        )
    for v, ls in ((0.5, ":"), (1.0, "--")):
        ax.axvline(v, color="0.3", ls=ls, lw=0.9)
    ax.set_xlim(0.0, limit_px)
    ax.set_xlabel("distance from the true image position (px)")
    ax.set_ylabel("density (1/px)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2))
    return ax


def band_counts(ax, wavelength_nm, counts: dict, *, red_edge_nm: float = 750.0, log=True):
    """Counts per band (grouped bars) against wavelength, the red edge shaded beyond.

    Parameters
    ----------
    ax : matplotlib Axes
    wavelength_nm : (n_bands,) array_like
    counts : dict of str to (n_bands,) array_like
        Label -> count per band (key points, matches, observations …).
    red_edge_nm : float
        002 §5.3: "the red-edge spectral region at ~750 nm".
    log : bool
        Logarithmic count axis.

    Returns
    -------
    ax
    """
    wl = np.asarray(wavelength_nm, float)
    k = len(counts)
    step = float(np.min(np.diff(wl))) if wl.size > 1 else 50.0
    w = 0.8 * step / max(k, 1)
    for i, (label, c) in enumerate(counts.items()):
        ax.bar(
            wl + (i - (k - 1) / 2) * w, np.asarray(c, float), width=w, label=label, color=f"C{i}"
        )
    ax.axvspan(red_edge_nm, wl.max() + step, color="C2", alpha=0.08, lw=0)
    ax.axvline(red_edge_nm, color="C2", lw=0.8, ls="--")
    ax.text(
        red_edge_nm + 0.02 * step,
        0.97,
        "above the red edge",
        transform=ax.get_xaxis_transform(),
        va="top",
        fontsize=7,
        color="C2",
    )
    if log:
        ax.set_yscale("log")
    ax.set_xlim(wl.min() - step / 2, wl.max() + step / 2)
    ax.set_xticks(wl)
    ax.set_xlabel("band centre (nm)")
    ax.set_ylabel("count")
    ax.legend(fontsize=7, loc="upper left")
    return ax


def scene_length_tradeoff(ax, lines, ours, paper, *, reference: int = 200):
    """Observations per scene length, each relative to its own count at ``reference`` lines.

    Parameters
    ----------
    ax : matplotlib Axes
    lines : (k,) array_like
        Lines per scene (002 §4: 100, 200, 300).
    ours, paper : (k,) array_like
        Observation counts (any scale: each is divided by its own value at ``reference``).

    Returns
    -------
    ax
    """
    lines = np.asarray(lines, float)
    i = int(np.flatnonzero(lines == reference)[0])
    for vals, style, label in ((paper, "C3s--", "002 §4"), (ours, "C0o-", "from pixels (ours)")):
        v = np.asarray(vals, float)
        ax.plot(lines, v / v[i], style, ms=6, label=label)
    ax.axhline(1.0, color="0.6", lw=0.7)
    ax.set_xticks(lines)
    ax.set_xlabel("lines per scene")
    ax.set_ylabel(f"observations / those at {reference} lines")
    ax.legend(fontsize=8)
    return ax
