"""The slanted-edge MTF (ISO 12233:2017 Annex D, the method of sfrmat, mtf_mapper, Imatest).

Steps: (1) orient the region so that the edge runs roughly vertically; (2) in every row, the
centroid of the derivative across the edge (Hamming-windowed) locates the edge; (3) a straight
line fitted to the centroids gives the edge angle; (4) every pixel's signed distance from the
line, perpendicular to the edge, is binned into bins of 1/``oversample`` px: the oversampled
edge spread function (ESF); (5) derivative, Hamming window, FFT, normalisation and the
finite-difference correction (:func:`hsgeo.mtf.mtf_from_esf`).

Frequencies are in cycles per pixel perpendicular to the edge.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.mtf import mtf_from_esf

__all__ = ["EdgeMeasurement", "slanted_edge", "find_edge_roi"]


@dataclass(frozen=True)
class EdgeMeasurement:
    """A slanted-edge MTF.

    Attributes
    ----------
    f_cy_px, mtf : (M,) ndarray
        Frequency (cy/px, perpendicular to the edge, up to 1 cy/px) and the MTF.
    edge_angle_deg : float
        Angle of the edge from the column axis (after orientation), degrees.
    vertical : bool
        True when the edge runs along the columns (the MTF is the horizontal one).
    lsf_fwhm_px : float
        Full width at half maximum of the line spread function, px.
    esf, lsf : ndarray
        The binned ESF and the windowed LSF (bins of 1/oversample px).
    """

    f_cy_px: np.ndarray
    mtf: np.ndarray
    edge_angle_deg: float
    vertical: bool
    lsf_fwhm_px: float
    esf: np.ndarray
    lsf: np.ndarray


def _hamming(n: int, centre: np.ndarray) -> np.ndarray:
    """Hamming windows of length ``n`` centred at ``centre`` (one per row), shape (rows, n)."""
    x = np.arange(n)[None, :]
    c = np.asarray(centre, dtype=float)[:, None]
    half = np.maximum(c, n - 1 - c)
    return 0.54 + 0.46 * np.cos(np.pi * (x - c) / half)


def _centroids(img: np.ndarray, window_centre) -> np.ndarray:
    """Centroid (column, px) of each row's Hamming-windowed derivative across the edge (signed,
    so that noise averages out; upright whatever the edge's polarity).
    """
    d = np.zeros_like(img)
    d[:, 1:-1] = 0.5 * (img[:, 2:] - img[:, :-2])
    if d.sum() < 0:
        d = -d
    d = d * _hamming(img.shape[1], window_centre)
    s = d.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = (d * np.arange(img.shape[1])).sum(axis=1) / s
    c[~(s > 0)] = np.nan
    return c


def _fwhm(lsf: np.ndarray, bin_px: float) -> float:
    i = int(np.argmax(lsf))
    half = lsf[i] / 2.0
    left = i
    while left > 0 and lsf[left] > half:
        left -= 1
    right = i
    while right < lsf.size - 1 and lsf[right] > half:
        right += 1
    if left == 0 or right == lsf.size - 1:
        return float("nan")
    xl = left + (half - lsf[left]) / (lsf[left + 1] - lsf[left])
    xr = right - 1 + (lsf[right - 1] - half) / (lsf[right - 1] - lsf[right])
    return float((xr - xl) * bin_px)


def slanted_edge(
    image, *, oversample: int = 4, correct: bool = True, half_width_px: float = 32.0
) -> EdgeMeasurement:
    """The ISO 12233 slanted-edge MTF of a region holding one straight edge.

    Parameters
    ----------
    image : (rows, cols) array_like
        The region (dark-subtracted or not: the MTF is normalised at zero frequency).
    oversample : int
        Bins per pixel of the ESF (4 in ISO 12233).
    correct : bool
        Apply the finite-difference and bin corrections (:func:`hsgeo.mtf.mtf_from_esf`).
    half_width_px : float
        The ESF is kept within this distance of the edge (a wide region adds only noise to
        the LSF's tails; mtf_mapper keeps ±16 px).

    Raises
    ------
    ObservationError
        No edge, an edge too close to 0° or 45° (aliasing-free oversampling needs a slant of
        about 2–40°), or too few rows to cover a phase cycle.
    """
    img = np.asarray(image, dtype=float)
    if img.ndim != 2 or min(img.shape) < 8:
        raise InputError(
            f"the edge region must be a 2-D image of at least 8 × 8 px, got {img.shape}"
        )
    if not np.all(np.isfinite(img)):
        raise InputError("the edge region holds NaN or infinite values")
    gx = np.abs(np.diff(img, axis=1)).mean()
    gy = np.abs(np.diff(img, axis=0)).mean()
    vertical = bool(gx >= gy)
    if not vertical:
        img = img.T
    rows, cols = img.shape
    contrast = np.percentile(img, 95) - np.percentile(img, 5)
    noise = 1.4826 * np.median(np.abs(np.diff(img, axis=0))) / np.sqrt(2.0)
    if not contrast > 10 * max(noise, 1e-12):
        raise ObservationError("no edge in the region: its two sides have the same brightness")
    y = np.arange(rows, dtype=float)
    mean_d = np.abs(np.convolve(np.diff(img.mean(axis=0)), np.ones(3) / 3, mode="same"))
    c = _centroids(img, np.full(rows, float(np.argmax(mean_d)) + 0.5))
    ok = np.isfinite(c)
    if ok.sum() < rows // 2:
        raise ObservationError("no edge in the region: most rows have no brightness step")
    a, b = np.polynomial.polynomial.polyfit(y[ok], c[ok], 1)
    c = _centroids(img, a + b * y)  # second pass with a window on the first line (ISO 12233)
    ok = np.isfinite(c)
    a, b = np.polynomial.polynomial.polyfit(y[ok], c[ok], 1)
    angle = float(np.degrees(np.arctan(b)))
    if abs(angle) < 1.0 or abs(angle) > 40.0:
        raise ObservationError(
            f"the edge is slanted by {angle:.1f}° from the "
            f"{'columns' if vertical else 'rows'}; the slanted-edge method needs 1°–40° "
            "(tilt the target about 5°)"
        )
    if rows * abs(b) < 1.0:
        raise ObservationError(
            f"the region's {rows} rows shift the edge by less than one pixel; use a taller region"
        )
    cos_t = np.cos(np.arctan(b))
    dist = (np.arange(cols)[None, :] - (a + b * y)[:, None]) * cos_t  # perpendicular distance
    d = 1.0 / oversample
    lo = np.floor(dist.min() / d)
    idx = (np.floor(dist / d) - lo).astype(np.int64).ravel()
    n = int(idx.max()) + 1
    cnt = np.bincount(idx, minlength=n)
    tot = np.bincount(idx, weights=img.ravel(), minlength=n)
    # keep the span that every row covers (whole pixels on both sides of the edge)
    c_rows = a + b * y
    half = int(np.floor(min(c_rows.min(), cols - 1 - c_rows.max(), half_width_px) * cos_t / d))
    centre = int(round(-lo))
    keep = slice(max(centre - half, 0), min(centre + half, n))
    cnt, tot = cnt[keep], tot[keep]
    if cnt.size < 16 * oversample or np.mean(cnt == 0) > 0.2:
        raise ObservationError("the region is too narrow across the edge; widen it")
    esf = np.full(cnt.size, np.nan)
    esf[cnt > 0] = tot[cnt > 0] / cnt[cnt > 0]
    good = np.isfinite(esf)
    esf = np.interp(np.arange(esf.size), np.flatnonzero(good), esf[good])
    f, m, lsf = mtf_from_esf(esf, d, correct=correct)
    sel = f <= 1.0 + 1e-12
    return EdgeMeasurement(f[sel], m[sel], angle, vertical, _fwhm(lsf, d), esf, lsf)


def find_edge_roi(image, size: int = 128) -> tuple[int, int, int, int]:
    """A square region ``(x0, y0, x1, y1)`` centred on the strongest straight edge of ``image``.

    Raises :class:`~hsgeo.errors.ObservationError` when the image holds no clear edge.
    """
    img = np.asarray(image, dtype=float)
    if img.ndim != 2 or min(img.shape) < 16:
        raise InputError(f"the image must be 2-D and at least 16 × 16 px, got {img.shape}")
    gx = np.zeros_like(img)
    gy = np.zeros_like(img)
    gx[:, 1:-1] = img[:, 2:] - img[:, :-2]
    gy[1:-1, :] = img[2:, :] - img[:-2, :]
    g = np.hypot(gx, gy)
    thr = np.percentile(g, 99)
    noise = np.median(g) + 1e-12
    if not thr > 8 * noise:
        raise ObservationError(
            "found no clear edge in the image; give the region with --roi x0,y0,x1,y1"
        )
    ys, xs = np.nonzero(g >= thr)
    cy, cx = int(np.median(ys)), int(np.median(xs))
    h = min(size, img.shape[0], img.shape[1]) // 2
    y0 = int(np.clip(cy - h, 0, img.shape[0] - 2 * h))
    x0 = int(np.clip(cx - h, 0, img.shape[1] - 2 * h))
    return x0, y0, x0 + 2 * h, y0 + 2 * h
