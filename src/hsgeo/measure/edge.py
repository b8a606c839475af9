"""The slanted-edge MTF (ISO 12233:2017 Annex D, the method of sfrmat, mtf_mapper, Imatest).

Steps: (1) orient the region so that the edge runs roughly vertically; (2) in every row, the
centroid of the derivative across the edge (Hamming-windowed) locates the edge; (3) a straight
line fitted to the centroids gives the edge angle; (4) every pixel's signed distance from the
line, perpendicular to the edge, is binned into bins of 1/``oversample`` px: the oversampled
edge spread function (ESF); (5) derivative, Hamming window, FFT, normalisation and the
finite-difference correction (:func:`hsgeo.mtf.mtf_from_esf`).

Frequencies are in cycles per pixel perpendicular to the edge.

A region is measured only if it is what the method assumes (real chips deliver the
area outside the target set to 0, and an edge measured across that fill gave an LSF narrower
than a pixel and a wrong MTF with no warning): one straight edge between two plateaus, no fill,
nodata or clipped level, and a line spread function at least one pixel wide (the pixel aperture
alone makes it 1 px). :func:`check_region` says what fails; :func:`find_edge_roi` searches a
masked chip for a region that passes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.mtf import mtf_from_esf

__all__ = [
    "EdgeMeasurement",
    "check_region",
    "find_edge_roi",
    "slanted_edge",
    "MIN_HALF_WIDTH_PX",
    "FULL_SPAN_PX",
    "PLATEAU_TOLERANCE",
    "MIN_LSF_FWHM_PX",
]


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


#: the least half-width of the ESF on each side of the edge, px (the plateaus must be reached)
MIN_HALF_WIDTH_PX = 4.0
#: the ESF span (px each side) that every row must cover to be used alone; see _binned_esf
FULL_SPAN_PX = 16.0
#: a pixel deviates from "one edge between two plateaus" by more than this share of the step
#: (on a plateau; in the transition, where a slightly curved edge moves values, 0.25)
PLATEAU_TOLERANCE = 0.1
#: the least FWHM of a real imaged edge's LSF, px: the square pixel aperture alone gives 1 px
MIN_LSF_FWHM_PX = 1.0


def _noise(img: np.ndarray) -> float:
    """Robust noise of a region (px-to-px differences along the rows and the columns)."""
    d = np.concatenate([np.diff(img, axis=0).ravel(), np.diff(img, axis=1).ravel()])
    d = d[d != 0] if np.count_nonzero(d) > d.size // 4 else d
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0))


def _constant_blocks(img: np.ndarray, noise: float) -> tuple[int, float]:
    """Pixels of 3 × 3 blocks of one value at the region's minimum or maximum, in a region whose
    noise would never make them (fill, nodata, or a clipped level): (count, value).
    """
    if not noise >= 1.0:  # a noise-free image: equal neighbours say nothing
        return 0, float("nan")
    from scipy.ndimage import binary_erosion

    for v in (img.min(), img.max()):
        n = int(binary_erosion(img == v, np.ones((3, 3), bool)).sum())
        if n:
            return int((img == v).sum()), float(v)
    return 0, float("nan")


def _orient(img: np.ndarray) -> tuple[np.ndarray, bool]:
    gx = np.abs(np.diff(img, axis=1)).mean()
    gy = np.abs(np.diff(img, axis=0)).mean()
    vertical = bool(gx >= gy)
    return (img if vertical else img.T), vertical


def _edge_line(img: np.ndarray, vertical: bool) -> tuple[float, float]:
    """The edge line ``column = a + b row`` (two centroid passes, ISO 12233 D.3)."""
    rows = img.shape[0]
    y = np.arange(rows, dtype=float)
    mean_d = np.abs(np.convolve(np.diff(img.mean(axis=0)), np.ones(3) / 3, mode="same"))
    c = _centroids(img, np.full(rows, float(np.argmax(mean_d)) + 0.5))
    ok = np.isfinite(c)
    if ok.sum() < max(rows // 2, 2):
        raise ObservationError("no edge in the region: most rows have no brightness step")
    a, b = np.polynomial.polynomial.polyfit(y[ok], c[ok], 1)
    c = _centroids(img, a + b * y)  # second pass with a window on the first line (ISO 12233)
    ok = np.isfinite(c)
    if ok.sum() < max(rows // 2, 2):
        raise ObservationError("no edge in the region: most rows have no brightness step")
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
    return float(a), float(b)


def _binned_esf(img, a, b, oversample, half_width_px):
    """The ESF on bins of 1/oversample px within ``half_width_px`` of the edge, over the span
    that the region covers without a gap on both sides; also every pixel's distance and bin.
    """
    rows, cols = img.shape
    y = np.arange(rows, dtype=float)
    cos_t = np.cos(np.arctan(b))
    dist = (np.arange(cols)[None, :] - (a + b * y)[:, None]) * cos_t  # perpendicular distance
    d = 1.0 / oversample
    lo = np.floor(dist.min() / d)
    idx = (np.floor(dist / d) - lo).astype(np.int64)
    n = int(idx.max()) + 1
    cnt = np.bincount(idx.ravel(), minlength=n)
    tot = np.bincount(idx.ravel(), weights=img.ravel(), minlength=n)
    centre = int(round(-lo))  # the bin of distance [0, d)
    if not 0 <= centre < n:  # the step found is no edge across this region (a fill boundary)
        raise ObservationError(
            "no edge in the region: the brightness step found does not cross it (fill or "
            "nodata beside the target?); choose a region inside the target across its edge"
        )
    limit = int(np.floor(half_width_px / d))
    left = 0
    while left < limit and centre - left - 1 >= 0 and cnt[centre - left - 1] > 0:
        left += 1
    right = 0
    while right < limit and centre + right + 1 < n and cnt[centre + right + 1] > 0:
        right += 1
    # the span that every row covers (each bin sampled along the whole edge) when it reaches
    # FULL_SPAN_PX; in a narrower region the wider span that some rows cover without a gap
    # (symmetric about the edge): a short LSF is truncated by its window, which on the
    # independent edges of tests/edge_reference.py cost 0.028 in MTF at ±7.5 px, 0.008 at ±11
    c_rows = a + b * y
    every = int(np.floor(min(c_rows.min(), cols - 1 - c_rows.max(), half_width_px) * cos_t / d))
    half = every if every * d >= FULL_SPAN_PX else max(every, min(left, right))
    if half * d < MIN_HALF_WIDTH_PX:
        raise ObservationError(
            f"the region reaches only {half * d:.1f} px from the edge on one side (at least "
            f"{MIN_HALF_WIDTH_PX:g} px on both sides are needed); widen it across the edge"
        )
    keep = slice(centre - half, centre + half)
    cnt, tot = cnt[keep], tot[keep]
    esf = np.full(cnt.size, np.nan)
    esf[cnt > 0] = tot[cnt > 0] / cnt[cnt > 0]
    good = np.isfinite(esf)
    esf = np.interp(np.arange(esf.size), np.flatnonzero(good), esf[good])
    return esf, dist, idx - (centre - half), d


def check_region(img, esf, dist, bins, contrast, noise, where: str = "") -> None:
    """Refuse a region that is not one straight edge between two plateaus.

    Every pixel is compared with the ESF at its distance from the edge: a pixel off by more than
    ``max(6 σ, PLATEAU_TOLERANCE × step)`` on a plateau (0.25 × step in the transition) is
    something else — fill or nodata, a second edge, a spot; before that, any pixel of the
    whole region (also beyond the ESF's window) below the dark plateau or above the bright one
    by more than the plateau's tolerance is fill, nodata or a dead or hot pixel (a
    region reaching the fill by a few pixels, or beyond the window, was measured). Then both
    ends of the ESF must be flat (the plateaus reached).

    Raises
    ------
    ObservationError
        Naming what fails and where (rows and columns of the region).
    """
    k = max(esf.size // 10, 2)
    dark, bright = sorted((esf[:k].mean(), esf[-k:].mean()))
    tol_plateau = max(6.0 * noise, PLATEAU_TOLERANCE * contrast)
    beyond = (img < dark - tol_plateau) | (img > bright + tol_plateau)  # the whole region
    if beyond.any():
        rr, cc = np.nonzero(beyond)
        raise ObservationError(
            f"{int(beyond.sum())} px of the region{where} lie below its dark plateau or above "
            f"its bright one (rows {rr.min()}–{rr.max()}, columns {cc.min()}–{cc.max()} of the "
            "region, counted along the edge): fill or nodata outside the target, or a dead or "
            "hot pixel; choose a region inside the target without them"
        )
    inside = (bins >= 0) & (bins < esf.size)
    expected = np.full(img.shape, np.nan)
    expected[inside] = esf[bins[inside]]
    r = img - expected
    tol_edge = max(6.0 * noise, 0.25 * contrast)
    tol = np.where(np.abs(dist) > 2.0, tol_plateau, tol_edge)
    bad = inside & (np.abs(r) > tol)
    n_bad = int(bad.sum())
    if n_bad > max(3, 0.002 * inside.sum()):
        rr, cc = np.nonzero(bad)
        raise ObservationError(
            f"{n_bad} px of the region{where} do not belong to one straight edge between two "
            f"plateaus (rows {rr.min()}–{rr.max()}, columns {cc.min()}–{cc.max()} of the "
            "region, counted along the edge): fill or nodata outside the target, a second edge "
            "or a spot; choose a region inside the target with only the edge in it"
        )
    for name, end, nxt in (
        ("one", esf[:k], esf[k : 2 * k]),
        ("the other", esf[-k:], esf[-2 * k : -k]),
    ):
        if abs(end.mean() - nxt.mean()) > max(PLATEAU_TOLERANCE * contrast, 4 * noise):
            raise ObservationError(
                f"the region{where} does not reach a plateau on {name} side of the edge (the "
                "edge spread still changes at its end); widen the region across the edge"
            )


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
        about 2–40°), too few rows to cover a phase cycle, fewer than
        :data:`MIN_HALF_WIDTH_PX` on a side of the edge, fill / nodata / a clipped level, more
        than one edge or no plateau (:func:`check_region`), or an LSF narrower than
        :data:`MIN_LSF_FWHM_PX`.
    """
    img = np.asarray(image, dtype=float)
    if img.ndim != 2 or min(img.shape) < 8:
        raise InputError(
            f"the edge region must be a 2-D image of at least 8 × 8 px, got {img.shape}"
        )
    if not np.all(np.isfinite(img)):
        raise InputError("the edge region holds NaN or infinite values")
    img, vertical = _orient(img)
    contrast = np.percentile(img, 95) - np.percentile(img, 5)
    noise = _noise(img)
    if not contrast > 10 * max(noise, 1e-12):
        raise ObservationError("no edge in the region: its two sides have the same brightness")
    n_const, value = _constant_blocks(img, noise)
    if n_const:
        raise ObservationError(
            f"{n_const} px of the region hold the same value {value:g} in blocks that its noise "
            f"(σ ≈ {noise:.2g}) would never make: fill or nodata outside the target, or a "
            "clipped (saturated) level; choose a region inside the target, exposed below "
            "saturation"
        )
    a, b = _edge_line(img, vertical)
    esf, dist, bins, d = _binned_esf(img, a, b, oversample, half_width_px)
    step = abs(esf[-max(esf.size // 10, 2) :].mean() - esf[: max(esf.size // 10, 2)].mean())
    check_region(img, esf, dist, bins, max(step, contrast * 0.5), noise)
    f, m, lsf = mtf_from_esf(esf, d, correct=correct)
    fwhm = _fwhm(lsf, d)
    if not fwhm >= MIN_LSF_FWHM_PX:
        raise ObservationError(
            f"the line spread function is {fwhm:.2f} px wide (FWHM), narrower than a pixel, "
            "which no imaged edge is: the region's edge is a boundary of fill or a mask, or the "
            "image was resampled or sharpened; choose a region on the target's own edge"
        )
    sel = f <= 1.0 + 1e-12
    angle = float(np.degrees(np.arctan(b)))
    return EdgeMeasurement(f[sel], m[sel], angle, vertical, fwhm, esf, lsf)


def _quick_roi(img: np.ndarray, size: int) -> tuple[int, int, int, int] | None:
    """A square around the strongest gradients (the whole image's one edge), or None."""
    gx = np.zeros_like(img)
    gy = np.zeros_like(img)
    gx[:, 1:-1] = img[:, 2:] - img[:, :-2]
    gy[1:-1, :] = img[2:, :] - img[:-2, :]
    g = np.hypot(gx, gy)
    thr = np.percentile(g, 99)
    if not thr > 8 * (np.median(g) + 1e-12):
        return None
    ys, xs = np.nonzero(g >= thr)
    cy, cx = int(np.median(ys)), int(np.median(xs))
    h = min(size, img.shape[0], img.shape[1]) // 2
    y0 = int(np.clip(cy - h, 0, img.shape[0] - 2 * h))
    x0 = int(np.clip(cx - h, 0, img.shape[1] - 2 * h))
    return x0, y0, x0 + 2 * h, y0 + 2 * h


def _passes(region) -> float:
    """A region's score (its pixels × contrast-to-noise) if :func:`slanted_edge` accepts it,
    else 0.
    """
    try:
        slanted_edge(region)
    except (ObservationError, InputError):
        return 0.0
    noise = max(_noise(region), 1e-6)
    return float(region.size * (np.percentile(region, 95) - np.percentile(region, 5)) / noise)


def find_edge_roi(image, size: int = 128) -> tuple[int, int, int, int]:
    """A region ``(x0, y0, x1, y1)`` holding one slanted edge that :func:`slanted_edge` accepts.

    First the ``size`` square around the strongest gradients (an image of one edge); if that
    region fails (a chip with fill outside a rotated target, several edges), windows of
    64–24 px across by twice that along, in both orientations, are tried on a grid of steps
    of a quarter window, and the accepted one with most pixels × contrast / noise is returned.

    Raises :class:`~hsgeo.errors.ObservationError` when no region qualifies.
    """
    img = np.asarray(image, dtype=float)
    if img.ndim != 2 or min(img.shape) < 16:
        raise InputError(f"the image must be 2-D and at least 16 × 16 px, got {img.shape}")
    quick = _quick_roi(img, size)
    if quick is not None:
        x0, y0, x1, y1 = quick
        if _passes(img[y0:y1, x0:x1]) > 0:
            return quick
    rows, cols = img.shape
    tried = 0
    for across in (64, 48, 32, 24):
        best, best_roi = 0.0, None
        for h, w in ((2 * across, across), (across, 2 * across)):
            h, w = min(h, rows), min(w, cols)
            sy = max(h // 4, rows // 24, 1)
            sx = max(w // 4, cols // 24, 1)
            for y0 in range(0, rows - h + 1, sy):
                for x0 in range(0, cols - w + 1, sx):
                    tried += 1
                    score = _passes(img[y0 : y0 + h, x0 : x0 + w])
                    if score > best:
                        best, best_roi = score, (x0, y0, x0 + w, y0 + h)
        if best_roi is not None:
            return best_roi
    raise ObservationError(
        f"found no region holding one slanted edge between two plateaus without fill ({tried} "
        "windows tried); give the region with --roi x0,y0,x1,y1"
    )
