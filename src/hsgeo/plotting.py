"""Plotting helpers (matplotlib only): every function takes an Axes and returns it."""

from __future__ import annotations

import numpy as np

__all__ = ["residual_quiver", "radial_displacement", "z_scores", "image_with_points"]


def residual_quiver(ax, uv_px, residuals_px, *, scale_px: float = 100.0, image_size=None,
                    color="C3", label=None):
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
    ax.quiver(uv[:, 0], uv[:, 1], r[:, 0] * scale_px, r[:, 1] * scale_px, angles="xy",
              scale_units="xy", scale=1, color=color, width=0.003,
              label=(label or "residual") + f" (×{scale_px:g})")
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


def radial_displacement(ax, *, f_px, k=None, K_per_mm=None, pixel_pitch_mm=None, r_max_px=400.0,
                        label=None, **style):
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
            ax.annotate(str(t), (u, v), xytext=(3, 3), textcoords="offset points", fontsize=6,
                        color=color)
    ax.set_axis_off()
    return ax
