"""An independent slanted-edge generator, from first principles (issues 37 and 42).

Nothing of hsgeo is used: a straight knife edge at ``angle_deg`` from the columns, blurred by a
Gaussian PSF of ``sigma_px`` (its edge spread function is the normal CDF of the signed distance
from the edge, analytic), integrated over each square pixel's aperture by averaging an
``ss`` × ``ss`` grid of sample points inside it, then Gaussian noise and rounding to whole DN.

Its MTF perpendicular to the edge is known in closed form: the Gaussian's
``exp(-2 π² σ² f²)`` times the sampled square aperture's response along the edge normal,
``A(f cos θ) A(f sin θ)`` with ``A(u) = sin(π u) / (ss sin(π u / ss))`` (the mean of ``ss``
equally spaced points across one pixel).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtr


def aperture(u, ss):
    u = np.asarray(u, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.sin(np.pi * u) / (ss * np.sin(np.pi * u / ss))
    return np.where(np.abs(u) < 1e-12, 1.0, a)


def known_mtf(f_cy_px, sigma_px, angle_deg, ss=16):
    """The generator's MTF perpendicular to the edge at ``f_cy_px``."""
    f = np.asarray(f_cy_px, dtype=float)
    t = math.radians(angle_deg)
    g = np.exp(-2.0 * np.pi**2 * sigma_px**2 * f**2)
    return g * np.abs(aperture(f * math.cos(t), ss) * aperture(f * math.sin(t), ss))


def signed_distance(shape, angle_deg, centre=None, ss=16):
    """Per sample point (rows*ss, cols*ss): signed distance (px) from the edge line through
    ``centre`` (x, y; default the image centre) at ``angle_deg`` from the columns."""
    rows, cols = shape
    cx, cy = centre if centre is not None else (cols / 2.0, rows / 2.0)
    u = (np.arange(cols * ss) + 0.5) / ss
    v = (np.arange(rows * ss) + 0.5) / ss
    x, y = np.meshgrid(u, v)
    t = math.radians(angle_deg)
    return (x - cx) * math.cos(t) - (y - cy) * math.sin(t)


def slanted_edge_image(
    shape=(100, 80),
    angle_deg=5.0,
    sigma_px=0.7,
    dark=400.0,
    bright=3000.0,
    noise=6.0,
    seed=0,
    ss=16,
    centre=None,
):
    """A rendered knife edge (float DN, whole numbers), bright on the +distance side."""
    d = signed_distance(shape, angle_deg, centre, ss)
    fine = dark + (bright - dark) * ndtr(d / sigma_px)
    rows, cols = shape
    img = fine.reshape(rows, ss, cols, ss).mean(axis=(1, 3))
    rng = np.random.default_rng(seed)
    return np.round(img + rng.normal(0.0, noise, img.shape))


def masked_target_chip(
    shape=(200, 200),
    angle_deg=5.0,
    sigma_px=0.8,
    target_px=(70, 140),
    dark=600.0,
    bright=2600.0,
    noise=5.0,
    seed=0,
    ss=8,
):
    """A knife-edge target rotated by ``angle_deg`` inside a chip whose pixels outside the target
    (a ``target_px`` = (width, height) rectangle, sides parallel and perpendicular to the edge,
    centred on the chip) are set to 0, as calibration sites deliver them. Returns the image and
    a boolean mask of the target's pixels (pixel centres inside the rectangle)."""
    rows, cols = shape
    img = slanted_edge_image(shape, angle_deg, sigma_px, dark, bright, noise, seed, ss)
    t = math.radians(angle_deg)
    x, y = np.meshgrid(np.arange(cols) + 0.5 - cols / 2, np.arange(rows) + 0.5 - rows / 2)
    along_n = x * math.cos(t) - y * math.sin(t)  # across the edge
    along_e = x * math.sin(t) + y * math.cos(t)  # along the edge
    inside = (np.abs(along_n) <= target_px[0] / 2) & (np.abs(along_e) <= target_px[1] / 2)
    return np.where(inside, img, 0.0), inside
