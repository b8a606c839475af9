"""Plotting helpers (matplotlib only): every function takes an Axes and returns it.

Kept as one file: one concern, matplotlib figures that take and return an Axes and compute
nothing a chapter reports. The split into ``plotting/`` per chapter (GUIDE §2) was left for
later: its 003 (Rikola) functions were being changed in parallel.
"""

from __future__ import annotations

import numpy as np

from hsgeo.papers import RIKOLA_BANDS
from hsgeo.sensors.rikola import focal_from_gap_mm

__all__ = [
    "residual_quiver",
    "radial_displacement",
    "z_scores",
    "image_with_points",
    "plot_band_image",
    "plot_corner_bias",
    "plot_tracks",
    "plot_band_eops",
    "plot_gap_model",
    "plot_principal_points",
    "plot_distortion_effects",
    "residuals_vs_position",
    "residual_spread_vs_wavelength",
    "scale_bar",
    "deviation_quiver",
    "displacement_vs_pixel",
    "solver_scaling",
    "plot_lp_compensation",
    "plot_lp_mosaic",
    "verdict_bars",
    "stats_vs_paper",
    "checkpoint_heights",
    "per_band_values",
    "against_interval",
]


def residual_quiver(
    ax, uv_px, residuals_px, *, scale_px: float = 100.0, image_size=None, color="C3", label=None
):
    """Residual vectors drawn at their points, magnified ``scale_px`` times; y axis downwards.

    Parameters
    ----------
    ax : matplotlib Axes
    uv_px : (n, 2) ndarray
    residuals_px : (n, 2) ndarray
        Model − observation in px.
    scale_px : float
        Magnification of the vectors (stated in the legend).
    """
    uv, r = np.asarray(uv_px), np.asarray(residuals_px)
    ax.quiver(
        uv[:, 0],
        uv[:, 1],
        r[:, 0] * scale_px,
        r[:, 1] * scale_px,
        angles="xy",
        scale_units="xy",
        scale=1,
        color=color,
        width=0.003,
        label=(label or "residual") + f" (×{scale_px:g})",
    )
    ax.plot(uv[:, 0], uv[:, 1], ".", color="0.4", ms=2)
    if image_size is not None:
        ax.set_xlim(0, image_size[0])
        ax.set_ylim(image_size[1], 0)
    else:
        ax.invert_yaxis()
    ax.set_aspect("equal")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")
    return ax


def radial_displacement(
    ax, *, f_px, k=None, K_per_mm=None, pixel_pitch_mm=None, r_max_px=400.0, label=None, **style
):
    """Radial displacement measured − ideal (px) against the measured radius (px).

    Give ``k = (k1, k2, k3)`` for OpenCV's form (distortion of normalised ideal coordinates), or
    ``K_per_mm = (K1, K2, K3)`` with ``pixel_pitch_mm`` for the photogrammetric form (corrections
    as a function of the measured radius).
    """
    if k is not None:
        r_n = np.linspace(0, r_max_px / f_px * 1.2, 400)
        r_d = r_n * (1 + k[0] * r_n**2 + k[1] * r_n**4 + k[2] * r_n**6)
        rho, disp = f_px * r_d, f_px * (r_d - r_n)
        keep = rho <= r_max_px
        ax.plot(rho[keep], disp[keep], label=label, **style)
    else:
        rho = np.linspace(0, r_max_px, 400)
        rmm = rho * pixel_pitch_mm
        delta_mm = rmm * (K_per_mm[0] * rmm**2 + K_per_mm[1] * rmm**4 + K_per_mm[2] * rmm**6)
        ax.plot(rho, -delta_mm / pixel_pitch_mm, label=label, **style)
    ax.set_xlabel("radius from the image centre (px)")
    ax.set_ylabel("measured − ideal (px)")
    ax.axhline(0, color="0.7", lw=0.8)
    return ax


def z_scores(ax, names, estimate, truth, sigma):
    """(estimate − truth)/σ̂ per parameter, with the ±3 band."""
    z = (np.asarray(estimate) - np.asarray(truth)) / np.asarray(sigma)
    y = np.arange(len(names))
    ax.axvspan(-3, 3, color="0.92")
    ax.axvline(0, color="0.6", lw=0.8)
    ax.plot(z, y, "o", color="C0")
    ax.set_yticks(y, names)
    ax.set_xlabel("(estimate − truth) / σ̂")
    ax.set_xlim(min(-4, z.min() - 0.5), max(4, z.max() + 0.5))
    return ax


def image_with_points(ax, image, uv_px, *, labels=None, color="C1"):
    """An image (grey or RGB) with points marked (and optionally numbered)."""
    img = np.asarray(image)
    ax.imshow(img if img.ndim == 3 else img, cmap="gray")
    uv = np.asarray(uv_px)
    ax.plot(uv[:, 0], uv[:, 1], "+", color=color, ms=8, mew=1.5)
    if labels is not None:
        for (u, v), t in zip(uv, labels, strict=True):
            ax.annotate(
                str(t), (u, v), xytext=(3, 3), textcoords="offset points", fontsize=6, color=color
            )
    ax.set_axis_off()
    return ax


# ---- 003 (Rikola)
_SENSOR_COLOR = {1: "C3", 2: "C0"}


def plot_band_image(ax, image, detection=None, title=""):
    """A raw band (DN) with the detected corners and centroids."""
    ax.imshow(image, cmap="gray", vmin=0, vmax=4095)
    if detection is not None:
        c = detection.corners_px
        ax.plot(c[..., 0].ravel(), c[..., 1].ravel(), "+", color="C1", ms=4)
        ax.plot(*detection.centroids_px.T, "x", color="C2", ms=4)
    ax.set_title(title)
    ax.set_axis_off()
    return ax


def plot_corner_bias(ax, biases, white_dn, label, marker="o"):
    """Mean outward corner displacement (px) against the band's white level (DN)."""
    bands = sorted(biases)
    x = [white_dn[b] for b in bands]
    y = [biases[b]["outward_px"] for b in bands]
    ax.plot(x, y, marker, label=label)
    ax.set_xlabel("white level of the band (DN)")
    ax.set_ylabel("corner displacement outward (px)")
    return ax


def plot_tracks(axes, tracks, sensor):
    """Centroid column and row of five targets against the air gap (003 Fig. 3–4)."""
    gap = dict(zip(RIKOLA_BANDS["band"], RIKOLA_BANDS["gap_nm"], strict=True))
    sens = dict(zip(RIKOLA_BANDS["band"], RIKOLA_BANDS["sensor"], strict=True))
    for ax, (lab, (tid, track)) in zip(axes, tracks.items(), strict=False):
        bs = [b for b in sorted(track) if sens[b] == sensor]
        if not bs:
            continue
        col = np.array([track[b][0] for b in bs])
        row = np.array([track[b][1] for b in bs])
        g = [gap[b] for b in bs]
        ax.plot(g, col - col.mean(), "o-", color="C0", label="column")
        ax.plot(g, row - row.mean(), "s-", color="C3", label="row")
        ax.set_title(f"{lab} (target {tid})", fontsize=9)
        ax.set_xlabel("gap (nm)")
    axes[0].set_ylabel("− mean (px)")
    axes[0].legend(fontsize=8)
    return axes


def plot_band_eops(axes, cals, cube):
    """Exterior orientation of one cube estimated band by band (003 Fig. 5)."""
    bands = sorted(cals)
    P = np.array([cals[b].pose(cube) for b in bands])
    S = np.array([np.sqrt(np.diag(cals[b].pose_covariance(cube))) for b in bands])
    names = ["ω (°)", "φ (°)", "κ (°)", "X0 (mm)", "Y0 (mm)", "Z0 (mm)"]
    for i, ax in enumerate(axes.ravel()):
        v, s = P[:, i], S[:, i]
        if i < 3:
            v, s = np.rad2deg(v), np.rad2deg(s)
        col = [_SENSOR_COLOR[RIKOLA_BANDS["sensor"][b - 1]] for b in bands]
        ax.errorbar(bands, v - v.mean(), yerr=s, fmt="none", ecolor="0.6")
        ax.scatter(bands, v - v.mean(), c=col, s=12)
        ax.set_title(names[i] + " − mean", fontsize=9)
        ax.set_xlabel("band")
    return axes


def plot_gap_model(ax, gaps, f_hat, f_sig, regression, sensor, truth_ab=None):
    """Per-band focal length against air gap with the fitted line (003 Fig. 6)."""
    c = _SENSOR_COLOR[sensor]
    ax.errorbar(
        gaps, f_hat, yerr=f_sig, fmt="o", color=c, label=f"sensor {'I' if sensor == 1 else 'II'}"
    )
    g = np.linspace(min(gaps) - 10, max(gaps) + 10, 2)
    ax.plot(g, focal_from_gap_mm(g, regression["a"], regression["b"]), "-", color=c)  # 003 eq. (2)
    if truth_ab is not None:
        ax.plot(g, focal_from_gap_mm(g, truth_ab[0], truth_ab[1]), ":", color=c)
    ax.set_xlabel("FPI air gap (nm)")
    ax.set_ylabel("f (mm)")
    return ax


def plot_principal_points(ax, cals, truth_pp=None):
    """Principal point per band against the gap (003 Fig. 7)."""
    for b in sorted(cals):
        s = RIKOLA_BANDS["sensor"][b - 1]
        g = RIKOLA_BANDS["gap_nm"][b - 1]
        v, e = cals[b].value("interior"), cals[b].sigma("interior")
        ax.errorbar(g, v[1], yerr=e[1], fmt="o", color=_SENSOR_COLOR[s], ms=4)
        ax.errorbar(g, v[2], yerr=e[2], fmt="s", color=_SENSOR_COLOR[s], ms=4, mfc="none")
    if truth_pp is not None:
        for s in (1, 2):
            for k in (0, 1):
                ax.axhline(truth_pp[s - 1, k], color=_SENSOR_COLOR[s], lw=0.7, ls=":")
    ax.set_xlabel("FPI air gap (nm)")
    ax.set_ylabel("x0 (o), y0 (□) (mm)")
    return ax


def plot_distortion_effects(axes, bands, own, ref, diff, dec):
    """003 Fig. 8 (a)–(c) and Fig. 9: radial effect at the image corner with each band's
    coefficients, with the reference band's scaled by f, their difference, and decentering.
    """
    col = [_SENSOR_COLOR[RIKOLA_BANDS["sensor"][b - 1]] for b in bands]
    axes[0].scatter(bands, own, c=col, s=14)
    axes[0].set_title("(a) radial, own coefficients (px)", fontsize=9)
    axes[1].scatter(bands, ref, c=col, s=14)
    axes[1].set_title("(b) reference band, f scaled (px)", fontsize=9)
    axes[2].scatter(bands, diff, c=col, s=14)
    axes[2].set_title("(c) (a) − (b) (px)", fontsize=9)
    axes[3].plot(bands, dec[:, 0], "o", label="δx")
    axes[3].plot(bands, dec[:, 1], "s", label="δy")
    axes[3].set_title("decentering at the corner (px)", fontsize=9)
    axes[3].legend(fontsize=8)
    for ax in axes:
        ax.set_xlabel("band")
    return axes


# ---- scoreboard ----


def verdict_bars(ax, per_paper):
    """Horizontal stacked bars: claims per paper (rows of ``per_paper``) by verdict (columns).

    ``per_paper`` is a pandas DataFrame of counts, one column per verdict in
    :data:`hsgeo.report.VERDICTS` order. Returns ``ax``.
    """
    colours = {
        "reproduced": "#1b9e77",
        "differs": "#d95f02",
        "by construction": "#7570b3",
        "not testable": "#999999",
        "planned": "#e6ab02",
    }
    left = None
    papers_ = [str(p) for p in per_paper.index]
    for verdict in per_paper.columns:
        n = per_paper[verdict].to_numpy()
        ax.barh(papers_, n, left=left, color=colours.get(verdict), label=verdict)
        left = n if left is None else left + n
    ax.set_xlabel("claims")
    ax.set_ylabel("paper")
    ax.invert_yaxis()
    ax.legend(loc="lower right", fontsize=9, frameon=False)


# ---- chapters frame_reference and rikola: residuals binned over the image and
# ---- against wavelength, z-scores with ±1 bars, the relative orientation per band pair
__all__ += ["iop_against_wavelength", "gcp_deviation_map"]
__all__ += ["bin_residuals", "binned_residuals", "z_errorbars", "rop_per_pair", "residuals_by_band"]


def bin_residuals(uv_px, residuals_px, image_size, bins=(8, 6)):
    """Mean residual vector per cell of a ``bins[0] × bins[1]`` grid over the image.

    Parameters
    ----------
    uv_px : (n, 2) ndarray
        Image positions (column, row) in px.
    residuals_px : (n, 2) ndarray
        Residuals in px.
    image_size : (width, height) in px
    bins : (nx, ny)

    Returns
    -------
    dict with ``centre_px`` (m, 2), ``mean_px`` (m, 2), ``sem_px`` (m,) (standard error of
    the mean vector's components, pooled over x and y), ``count`` (m,), for the m non-empty
    cells.
    """
    uv, r = np.asarray(uv_px, float), np.asarray(residuals_px, float)
    w, h = image_size
    ix = np.clip((uv[:, 0] / w * bins[0]).astype(int), 0, bins[0] - 1)
    iy = np.clip((uv[:, 1] / h * bins[1]).astype(int), 0, bins[1] - 1)
    cell = iy * bins[0] + ix
    out = {"centre_px": [], "mean_px": [], "sem_px": [], "count": []}
    for c in np.unique(cell):
        rc = r[cell == c]
        n = len(rc)
        sd = float(np.sqrt(np.mean(rc.var(axis=0, ddof=1)))) if n > 1 else np.nan
        out["centre_px"].append(
            ((c % bins[0] + 0.5) * w / bins[0], (c // bins[0] + 0.5) * h / bins[1])
        )
        out["mean_px"].append(rc.mean(axis=0))
        out["sem_px"].append(sd / np.sqrt(n))
        out["count"].append(n)
    return {k: np.asarray(v) for k, v in out.items()}


def binned_residuals(
    ax, uv_px, residuals_px, image_size, *, bins=(8, 6), key_px=None, color="C3", min_count=3
):
    """Mean residual vector per grid cell, drawn at the cell centre (y axis downwards).

    The arrows are in px, magnified by a common factor; the key arrow gives the scale
    (``key_px``, default: about the largest mean). Cells with fewer than ``min_count``
    residuals are left out. Returns the Axes; the binned values are in
    :func:`bin_residuals`.
    """
    b = bin_residuals(uv_px, residuals_px, image_size, bins)
    keep = b["count"] >= min_count
    c, m = b["centre_px"][keep], b["mean_px"][keep]
    w, h = image_size
    big = float(np.max(np.hypot(*m.T))) if len(m) else 1.0
    if key_px is None:
        key_px = float(f"{big:.1g}") if big > 0 else 1.0
    scale = 0.8 * min(w / bins[0], h / bins[1]) / max(big, key_px)  # longest arrow: 0.8 cell
    for x in np.linspace(0, w, bins[0] + 1):
        ax.axvline(x, color="0.88", lw=0.6, zorder=0)
    for y in np.linspace(0, h, bins[1] + 1):
        ax.axhline(y, color="0.88", lw=0.6, zorder=0)
    q = ax.quiver(
        c[:, 0],
        c[:, 1],
        m[:, 0] * scale,
        m[:, 1] * scale,
        angles="xy",
        scale_units="xy",
        scale=1,
        color=color,
        width=0.006,
        pivot="middle",
    )
    # the key sits in a band above the image (v < 0), inside the axes
    ax.axhline(0, color="0.5", lw=0.8, zorder=0)
    ax.quiverkey(
        q,
        0.78,
        1 - 0.07 / 1.14,
        key_px * scale,
        f"{key_px:g} px",
        labelpos="E",
        coordinates="axes",
        fontproperties={"size": 9},
    )
    ax.set_xlim(0, w)
    ax.set_ylim(h, -0.14 * h)
    ax.set_aspect("equal")
    ax.set_xlabel("column u (px)")
    ax.set_ylabel("row v (px)")
    return ax


def z_errorbars(ax, names, z):
    """(estimate − truth)/σ̂ per parameter with ±1 (that is ±σ̂) error bars; shaded ±3."""
    z = np.asarray(z, float)
    y = np.arange(len(names))
    ax.axvspan(-3, 3, color="0.93", label="±3σ̂")
    ax.axvline(0, color="0.6", lw=0.8)
    ax.errorbar(z, y, xerr=1.0, fmt="o", color="C0", capsize=2, label="estimate ± σ̂")
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    ax.set_xlabel("(estimate − truth) / σ̂")
    lim = max(4.0, float(np.nanmax(np.abs(z))) + 1.5)
    ax.set_xlim(-lim, lim)
    return ax


def rop_per_pair(axes, pairs, rop_deg, rop_sigma_deg, paper_deg=None, truth_deg=None):
    """Relative orientation (dω, dφ, dκ) per band pair ± σ̂, with the paper's (003 Table 4)."""
    x = np.arange(len(pairs))
    labels = [f"{a}&{b}" for a, b in pairs]
    names = ["dω (°)", "dφ (°)", "dκ (°)"]
    for i, ax in enumerate(axes):
        ax.errorbar(
            x,
            rop_deg[:, i],
            yerr=rop_sigma_deg[:, i],
            fmt="o",
            color="C0",
            capsize=2,
            label="this run, cube 0 ± σ̂",
        )
        if paper_deg is not None:
            ax.plot(x, paper_deg[: len(x), i], "s", mfc="none", color="C1", label="003 Table 4")
        if truth_deg is not None:
            ax.axhline(truth_deg[i], color="0.4", ls=":", lw=1, label="truth")
        ax.set_ylabel(names[i])
        ax.set_xticks(x, labels, fontsize=8)
    axes[-1].set_xlabel("band pair (sensor II & sensor I)")
    axes[0].legend(fontsize=8, ncol=3, loc="upper center", bbox_to_anchor=(0.5, 1.45))
    return axes


def residuals_by_band(ax, wavelength_nm, value, sigma=None, sensor=None, *, marker="o", label=""):
    """A per-band residual statistic (px) against the band's central wavelength, ± σ̂ if given;
    coloured by sensor (I red, II blue).
    """
    wl, v = np.asarray(wavelength_nm, float), np.asarray(value, float)
    cols = [_SENSOR_COLOR[int(s)] for s in sensor] if sensor is not None else ["C0"] * len(wl)
    if sigma is not None:
        ax.errorbar(wl, v, yerr=sigma, fmt="none", ecolor="0.6", capsize=2)
    ax.scatter(wl, v, c=cols, marker=marker, s=22, zorder=3)
    if label:  # a grey proxy: the colours stand for the sensors, the marker for the series
        ax.scatter([], [], color="0.35", marker=marker, s=22, label=label)
    ax.set_xlabel("central wavelength of the band (nm)")


# -- line_calibration and geocoding chapters ---------------------------------------------------


def residuals_vs_position(ax, zeta_px, residual_px, *, label=None, color=None, n_bins=0):
    """Residuals (model − observation) of a line calibration against image position ζ.

    Parameters
    ----------
    ax : matplotlib Axes
    zeta_px, residual_px : (n,) ndarray
        Observed image coordinates and their residuals [px].
    n_bins : int
        When > 0, also draw the mean residual in this many equal-width bins of ζ (a line).
    """
    z, r = np.asarray(zeta_px, float), np.asarray(residual_px, float)
    pts = ax.plot(z, r, ".", ms=3, alpha=0.5, color=color, label=label)[0]
    if n_bins > 0:
        edges = np.linspace(z.min(), z.max(), n_bins + 1)
        k = np.clip(np.digitize(z, edges) - 1, 0, n_bins - 1)
        cnt = np.bincount(k, minlength=n_bins)
        mean = np.bincount(k, r, minlength=n_bins) / np.maximum(cnt, 1)
        mid = 0.5 * (edges[1:] + edges[:-1])
        ax.plot(mid[cnt > 0], mean[cnt > 0], "-", color=pts.get_color(), lw=1.5)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("image position ζ (px)")
    ax.set_ylabel("residual (px)")
    return ax


def residual_spread_vs_wavelength(ax, wavelength_nm, residuals_px, *, sigma_px=None):
    """RMS and mean of each spectral line's residuals against its wavelength.

    Parameters
    ----------
    wavelength_nm : (m,) array
    residuals_px : sequence of m (n_i,) arrays
    sigma_px : float, optional
        The a-priori σ of one observation, drawn as a dotted line.
    """
    lam = np.asarray(wavelength_nm, float)
    rms = np.array([np.sqrt(np.mean(np.square(r))) for r in residuals_px])
    mean = np.array([np.mean(r) for r in residuals_px])
    ax.plot(lam, rms, "o-", label="RMS of the residuals")
    ax.plot(lam, mean, "s--", label="mean residual")
    if sigma_px is not None:
        ax.axhline(sigma_px, color="k", ls=":", lw=1, label=f"a-priori σ = {sigma_px:g} px")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("residual (px)")
    ax.legend()
    return ax


def scale_bar(ax, length_m: float, *, loc="lower left", label=None):
    """A map scale bar of ``length_m`` metres (axes in metres, equal aspect)."""
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    bar = AnchoredSizeBar(
        ax.transData,
        length_m,
        label or f"{length_m:g} m",
        loc,
        pad=0.4,
        frameon=False,
        size_vertical=0.0,
    )
    ax.add_artist(bar)
    return ax


def deviation_quiver(
    ax,
    en_m,
    dev_en_m,
    *,
    magnify: float,
    color="C0",
    label=None,
    key_m: float = 1.0,
    key_xy=(0.6, 0.06),
):
    """Deviation vectors (geocoded − reference, E and N in m) drawn at their points on a map.

    Parameters
    ----------
    en_m : (n, 2) ndarray
        Map positions E, N [m].
    dev_en_m : (n, 2) ndarray
        Deviations ΔE (= Δy), ΔN (= Δx) [m].
    magnify : float
        Vectors are drawn ``magnify`` times their length (map metres per deviation metre).
    key_m : float
        Length of the key vector [m], drawn at ``key_xy`` (axes fraction); 0 for none.
    """
    p, d = np.asarray(en_m, float), np.asarray(dev_en_m, float)
    q = ax.quiver(
        p[:, 0],
        p[:, 1],
        d[:, 0],
        d[:, 1],
        angles="xy",
        scale_units="xy",
        scale=1.0 / magnify,
        color=color,
        width=0.006,
        label=label,
    )
    if key_m:
        ax.quiverkey(q, *key_xy, key_m, f"{key_m:g} m deviation", labelpos="E", color=color)
    ax.set_aspect("equal")
    ax.margins(0.15)
    ax.set_xlabel("E = y (m)")
    ax.set_ylabel("N = x (m)")
    return ax


def gcp_deviation_map(
    ax,
    track_en_m,
    gcp_en_m,
    gcp_ids,
    dev_sim_en_m,
    paper_en_m,
    dev_paper_en_m,
    *,
    magnify: float,
    sim_label: str,
    paper_label: str,
):
    """The GCP deviations of a simulated flight (blue, at every GCP) and a paper's table (black,
    at its GCPs ``paper_en_m``) drawn ``magnify`` times enlarged on the map, with the flight
    line, the GCPs labelled by id and a 100 m scale bar (:func:`deviation_quiver`).
    """
    gcp = np.asarray(gcp_en_m, float)
    ax.plot(*np.asarray(track_en_m, float).T, color="0.75", lw=1, label="flight line")
    ax.plot(*gcp.T, "^", color="0.3", ms=5)
    deviation_quiver(ax, gcp, dev_sim_en_m, magnify=magnify, color="C0", label=sim_label, key_m=0)
    deviation_quiver(
        ax, paper_en_m, dev_paper_en_m, magnify=magnify, color="k", label=paper_label, key_m=1.0
    )
    for g, (e, n) in zip(gcp_ids, gcp, strict=True):
        ax.annotate(str(g), (e, n), xytext=(-12, 4), textcoords="offset points", fontsize=9)
    scale_bar(ax, 100.0, label="100 m (map)")
    ax.legend(loc="upper left")
    return ax


def displacement_vs_pixel(ax, zeta_px, displacement_m, *, label=None, color=None):
    """Median and 5–95 % band over lines of a displacement [m] against across-track pixel.

    Parameters
    ----------
    zeta_px : (n_px,) ndarray
    displacement_m : (n_lines, n_px) ndarray
    """
    d = np.asarray(displacement_m, float)
    lo, med, hi = np.percentile(d, [5, 50, 95], axis=0)
    line = ax.plot(zeta_px, med, color=color, label=label)[0]
    ax.fill_between(zeta_px, lo, hi, color=line.get_color(), alpha=0.25, lw=0)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("across-track pixel ζ (px)")
    ax.set_ylabel("displacement (m)")
    return ax


# ---- chapter pushbroom_ba: 002 Tables 1-3 against the paper with ±σ̂ spread, the
# ---- check-point heights, the per-band principal distances, the node-interval study, factors


def iop_against_wavelength(ax, wavelength_nm, value, sigma, paper, deg: int):
    """An interior-orientation parameter per spectral row (± σ̂) against its wavelength, the
    paper's values (+) and a trend of degree ``deg`` fitted with weights 1/σ̂ (001 Table 2).
    """
    lam = np.asarray(wavelength_nm, float)
    v, s = np.asarray(value, float), np.asarray(sigma, float)
    ax.errorbar(lam, v, s, fmt="o", capsize=3, label="reproduced ± σ̂")
    ax.plot(lam, paper, "k+", ms=12, mew=1.5, label="paper (001 Table 2)")
    fit = np.polyfit(lam, v, deg, w=1 / s)
    ll = np.linspace(lam[0], lam[-1], 50)
    ax.plot(ll, np.polyval(fit, ll), "C1-", lw=1, label=f"weighted trend (degree {deg})")
    ax.set_xlabel("wavelength (nm)")
    ax.legend()
    ax.grid(alpha=0.3)
    return ax


def stats_vs_paper(ax, labels, reproduced, sigma, paper, *, unit="m"):
    """Statistics (e.g. NMAD, mean) of a table, ± their σ̂ (spread over runs), beside the
    paper's values (open squares); one row per statistic, labels on the y axis.
    """
    y = np.arange(len(labels))
    ax.axvline(0, color="0.7", lw=0.8)
    ax.errorbar(reproduced, y, xerr=sigma, fmt="o", color="C0", capsize=3, label="this run ± σ̂")
    ax.plot(paper, y, "s", mfc="none", color="C1", ms=7, label="paper")
    ax.set_yticks(y, labels)
    ax.invert_yaxis()
    ax.set_xlabel(f"value ({unit})")
    ax.legend(fontsize=9)
    return ax


def checkpoint_heights(ax, errors_m, sigma_m, label="height error ± σ̂"):
    """Height error of each check point (m) with its ±σ̂ from the adjustment."""
    k = np.arange(len(errors_m))
    ax.axhline(0, color="0.6", lw=0.8)
    ax.errorbar(k, errors_m, yerr=sigma_m, fmt="o", capsize=3, label=label)
    ax.set_xticks(k, [str(i + 1) for i in k])
    ax.set_xlabel("check point")
    ax.set_ylabel("H estimated − true (m)")
    ax.legend(fontsize=9)
    return ax


def per_band_values(ax, wavelength_nm, value, sigma, truth=None, paper_bound=None, *, ylabel=""):
    """A per-band estimate ± σ̂ against wavelength, the truth (×) and ± a paper's bound (dashed)."""
    ax.axhline(0, color="0.6", lw=0.8)
    ax.errorbar(wavelength_nm, value, yerr=sigma, fmt="o", capsize=3, label="reproduced ± σ̂")
    if truth is not None:
        ax.plot(wavelength_nm, truth, "x", color="k", label="truth")
    if paper_bound is not None:
        for s in (-1, 1):
            ax.axhline(
                s * paper_bound, color="C1", ls="--", lw=1, label="paper's bound" if s > 0 else None
            )
    ax.set_xlabel("band centre (nm)")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=9)
    return ax


def against_interval(ax, studies, key, ylabel, *, scale=1.0, paper_interval_s=10.0):
    """One quantity of the node-interval study against the interval (log axis, ticks at the
    intervals run, no minor labels), one line per study (dict label -> list of dicts).
    """
    from matplotlib.ticker import NullFormatter

    ticks = sorted({d["interval_s"] for st in studies.values() for d in st})
    for label, st in studies.items():
        x = [d["interval_s"] for d in st]
        ax.plot(x, [scale * d[key] for d in st], "o-", label=label)
    ax.set_xscale("log")
    ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.axvline(paper_interval_s, color="0.7", lw=0.8)
    ax.set_xlabel("node interval (s)")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=9)
    return ax


def solver_scaling(axes, rows, *, goals=None, reference_scale: float = 1.0):
    """Solver time and peak memory against the number of observations (log-log), two panels.

    Parameters
    ----------
    axes : (2,) sequence of matplotlib Axes
        Left: solver seconds, with the line of linear growth through the row at
        ``reference_scale``. Right: the process's peak RSS (MB) and, where the rows have it,
        the peak before the solve (the simulation and the set-up).
    rows : sequence of dict
        Rows of ``bench/results/pushbroom_scaling.json``: ``scale``, ``n_observations``,
        ``solver_seconds``, ``peak_rss_mb`` (optional ``peak_rss_mb_before_solve``); rows
        without ``solver_seconds`` (a timed-out case) are left out.
    goals : dict, optional
        ``solver_seconds_max`` (s) and ``peak_rss_mb_max`` (MB), drawn as dashed lines.
    reference_scale : float
        The scale the linear-growth line passes through.

    Returns
    -------
    (2,) sequence of Axes
    """
    from hsgeo.errors import InputError

    rows = sorted((r for r in rows if "solver_seconds" in r), key=lambda r: r["n_observations"])
    ref = [r for r in rows if r["scale"] == reference_scale]
    if not ref:
        raise InputError(
            f"no row at scale {reference_scale:g} for the line of linear growth: run the "
            "scaling benchmark with that scale (bench_pushbroom_ba.py --scaling)"
        )
    n = np.array([r["n_observations"] for r in rows], dtype=float)
    t_s = np.array([r["solver_seconds"] for r in rows])
    ax_t, ax_m = axes
    ax_t.plot(n, t_s, "o-", color="C0", label="solver time")
    n_line = np.array([n.min(), n.max()])
    ax_t.plot(
        n_line,
        ref[0]["solver_seconds"] * n_line / ref[0]["n_observations"],
        ":",
        color="0.4",
        label=f"linear growth through {reference_scale:g}×",
    )
    ax_m.plot(n, [r["peak_rss_mb"] for r in rows], "o-", color="C0", label="peak RSS (process)")
    before = [r.get("peak_rss_mb_before_solve") for r in rows]
    if all(b is not None for b in before):
        ax_m.plot(n, before, "s--", color="C2", mfc="none", label="peak RSS before the solve")
    goals = goals or {}
    for ax, key, unit in ((ax_t, "solver_seconds_max", "s"), (ax_m, "peak_rss_mb_max", "MB")):
        if goals.get(key) is not None:
            ax.axhline(goals[key], color="C3", ls="--", lw=1, label=f"goal ≤ {goals[key]:g} {unit}")
    for ax, y in ((ax_t, t_s), (ax_m, [r["peak_rss_mb"] for r in rows])):
        for r, xi, yi in zip(rows, n, y, strict=True):
            ax.annotate(
                f"{r['scale']:g}×",
                (xi, yi),
                textcoords="offset points",
                xytext=(4, -10),
                fontsize=8,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("2-D observations")
        ax.legend(fontsize=8)
    ax_t.set_ylabel("solver time (s)")
    ax_m.set_ylabel("peak memory (MB)")
    return axes


# ---- 002 LP observations (Fig. 3)
def plot_lp_compensation(axes, strip, scene, *, band: int = 0, columns=None, vmax=None):
    """002 Fig. 3: a subset of an LP scene before (the original lines) and after the rotation
    compensation in x (:func:`hsgeo.measure.lp_scenes.make_scenes`).

    Parameters
    ----------
    axes : two matplotlib Axes
        Before, after.
    strip : hsgeo.io.lp_lines.LpStrip
        The strip the scene was cut from.
    scene : hsgeo.measure.lp_scenes.LpScene
    band : int
    columns : slice, optional
        Columns of the scene to show (default: all).
    vmax : float, optional
        Upper end of the grey scale (default: the 99.5th percentile of the shown scene).

    Returns
    -------
    the two Axes. The platform moves downwards in both (rows are lines in time order).
    """
    cols = columns if columns is not None else slice(None)
    rows = slice(scene.line0, scene.line0 + scene.n_lines)
    before = strip.lines[rows, cols, band]
    after = scene.image[:, cols, band]
    hi = vmax if vmax is not None else float(np.percentile(after, 99.5))
    lo = float(np.percentile(after, 0.5))
    c0 = (cols.start or 0) if isinstance(cols, slice) else 0
    extent = (c0 - 0.5, c0 + after.shape[1] - 0.5, scene.n_lines - 0.5, -0.5)
    for ax, img, title in (
        (axes[0], before, "(a) original LP lines"),
        (axes[1], after, "(b) rotation-compensated in x"),
    ):
        ax.imshow(img, cmap="gray", vmin=lo, vmax=hi, extent=extent, interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("scene column v (px)")
    axes[0].set_ylabel("scene row u (line)")
    return axes


# ---- 002 Fig. 9: the orthomosaic with the reference squares
def _true_colour(mosaic, lo_hi=None):
    """``(y, x, 3)`` in [0, 1] from a ``(band, y, x)`` mosaic (R, G, B), a 1–99 % stretch."""
    rgb = np.moveaxis(np.asarray(mosaic.values, float)[:3], 0, -1)
    lo, hi = lo_hi or (np.nanpercentile(rgb, 1), np.nanpercentile(rgb, 99))
    out = np.clip((rgb - lo) / max(hi - lo, 1e-12), 0.0, 1.0)
    return np.where(np.isfinite(out), out, 1.0), (lo, hi)  # no data: white


def plot_lp_mosaic(
    axes, mosaics, rtk_xy_m, *, titles=None, insets=4, inset_half_m: float = 2.4, square_ids=None
):
    """002 Fig. 9: true-colour mosaics with the RTK positions of the squares, a few of them
    enlarged in insets (each with its RTK centre as a cross).

    Parameters
    ----------
    axes : sequence of matplotlib Axes
        One per mosaic (e.g. adjusted, raw).
    mosaics : sequence of xarray.DataArray
        ``(band, y, x)`` R, G, B in a map CRS with cell-centre ``x``, ``y`` in m
        (:func:`hsgeo.reproduce.lp_mosaic.fig9`).
    rtk_xy_m : (k, 2) ndarray
        The squares' RTK positions in the same CRS, m.
    titles : sequence of str, optional
    insets : int
        Squares enlarged (the first ``insets`` inside the mosaic, spread over it).
    inset_half_m : float
        Half width of an inset, m.
    square_ids : sequence of str, optional
        Labels of the squares.

    Returns
    -------
    the Axes.
    """
    P = np.asarray(rtk_xy_m, float)
    lo_hi = None
    for i, (ax, m) in enumerate(zip(axes, mosaics, strict=True)):
        img, lo_hi = _true_colour(m, lo_hi)  # the same stretch in every panel
        x, y = m["x"].values, m["y"].values
        dx, dy = abs(x[1] - x[0]), abs(y[1] - y[0])
        ext = (x.min() - dx / 2, x.max() + dx / 2, y.min() - dy / 2, y.max() + dy / 2)
        ax.imshow(img if y[0] > y[-1] else img[::-1], extent=ext, interpolation="nearest")
        inside = (P[:, 0] > ext[0]) & (P[:, 0] < ext[1]) & (P[:, 1] > ext[2]) & (P[:, 1] < ext[3])
        ax.plot(P[inside, 0], P[inside, 1], "o", mfc="none", mec="C3", ms=9, mew=1.0)
        if square_ids is not None:
            for k in np.flatnonzero(inside):
                ax.annotate(
                    str(square_ids[k]),
                    P[k],
                    xytext=(5, 5),
                    textcoords="offset points",
                    color="C3",
                    fontsize=7,
                )
        pick = np.flatnonzero(inside)
        pick = pick[np.linspace(0, pick.size - 1, min(insets, pick.size)).astype(int)]
        for j, k in enumerate(pick):
            ins = ax.inset_axes([0.02 + 0.245 * j, 0.02, 0.22, 0.22])
            ins.imshow(img if y[0] > y[-1] else img[::-1], extent=ext, interpolation="nearest")
            ins.set_xlim(P[k, 0] - inset_half_m, P[k, 0] + inset_half_m)
            ins.set_ylim(P[k, 1] - inset_half_m, P[k, 1] + inset_half_m)
            ins.plot(*P[k], "+", color="C3", ms=10, mew=1.2)
            ins.set_xticks([])
            ins.set_yticks([])
            if square_ids is not None:
                ins.set_title(str(square_ids[k]), fontsize=6, pad=1)
            ax.indicate_inset_zoom(ins, edgecolor="C3")
        ax.set_xlabel("E (m, EPSG:25832)")
        ax.set_ylabel("N (m)")
        ax.ticklabel_format(useOffset=False, style="plain")
        if titles is not None:
            ax.set_title(titles[i], fontsize=9)
    return axes
