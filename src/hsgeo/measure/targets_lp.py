"""The centres of the white reference squares in LP scenes (002 §4, Fig. 6 and 9).

002 placed seventeen white 1.2 m × 1.2 m squares on the ground (≈ 3–4 px at 0.3–0.4 m GSD)
and used their centres as GCPs and check points. How the paper measured them in the images
is not said; ours, :func:`square_centroid`, for one square in one band of a scene:

1. **Search window** of ``± search_px`` around the position predicted from the navigation and
   the a-priori camera (its error is the boresight's, a few tenths of a degree: ~13 m, ~43 px).
2. **Detection by a box contrast**: the mean over a ``box_px × box_px`` box (the square's size)
   minus the mean over the ring around it out to ``3 box_px`` (both by cumulative sums); its
   local maxima are the candidates (:func:`square_candidates`), the largest is the square
   (:func:`square_centroid`; where several squares may share a window, the caller chooses
   among the candidates, as :mod:`hsgeo.workflows.lp_observations` does). A square brighter
   than its surroundings by a few times the window's noise (its NMAD) is found; a large bright
   area (a roof, a road) has no contrast to its own surroundings at the square's scale.
3. **Intensity-weighted centroid** (:func:`blob_centroid`): in a ``(4 box_px + 1)``-pixel
   window around the detection, the background (median of that window's border) is
   subtracted; the pixels above half the peak that are 8-connected to it, grown by one pixel
   (the partly covered edge pixels), are the blob, and its centroid weighted by the
   background-subtracted DN (negative values as 0)
   is the centre, in scene coordinates ``(u, v)`` (sub-pixel). The centroid is the one of
   :func:`hsgeo.measure.blobs.weighted_blob_centroid`, shared with the orthomosaic's
   measurer (:mod:`hsgeo.measure.squares`); kept apart from it: the detection in a raw scene
   (box contrast among roofs and roads, a predicted position tens of pixels off) and the
   rejections, which a mosaic searched within a few cells of the RTK position does not need.

Rejected (``ok = False``): a contrast below ``min_snr`` times the noise, a blob touching the
window's border or larger than ``max_area_factor`` times the square's area or reaching outside
the scene. The search window is clipped to the scene (pixels outside it, NaN, count as the
window's median). The scene coordinates go back to a line and an x by
:func:`hsgeo.measure.lp_scenes.scene_to_line` (the caller's).

References
----------
Jonassen et al. (2024), 002 §4 (reference squares), Fig. 6.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "square_centroid",
    "square_candidates",
    "blob_centroid",
    "box_contrast",
    "SEARCH_PX",
    "MIN_SNR",
]

#: Half-width of the search window around the predicted position (px): the a-priori boresight
#: error of "a few tenths of a degree" is ~43 px at 0.4° (1875 m, 0.30 m GSD), with a margin.
SEARCH_PX = 70
#: The square's contrast must exceed this many robust σ of the window.
MIN_SNR = 5.0


def box_contrast(image, box_px: int) -> np.ndarray:
    """Mean over a ``box_px`` box minus the mean over the ring to ``3 box_px`` around it.

    Parameters
    ----------
    image : (rows, cols) ndarray
    box_px : int

    Returns
    -------
    (rows, cols) ndarray
        NaN where the outer box leaves the image.
    """
    a = np.asarray(image, dtype=np.float64)
    S = np.zeros((a.shape[0] + 1, a.shape[1] + 1))
    S[1:, 1:] = np.cumsum(np.cumsum(a, axis=0), axis=1)

    def box_sum(h_lo, h_hi):
        # sum over rows r-h_lo … r+h_hi (and columns alike) for every r, c where it fits
        n0, n1 = a.shape
        out = np.full(a.shape, np.nan)
        m0, m1 = n0 - h_lo - h_hi, n1 - h_lo - h_hi
        if m0 <= 0 or m1 <= 0:
            return out
        w = h_lo + h_hi + 1
        out[h_lo : n0 - h_hi, h_lo : n1 - h_hi] = (
            S[w : w + m0, w : w + m1] - S[:m0, w : w + m1] - S[w : w + m0, :m1] + S[:m0, :m1]
        )
        return out

    lo = (box_px - 1) // 2
    hi = box_px - 1 - lo
    inner = box_sum(lo, hi)
    outer = box_sum(lo + box_px, hi + box_px)
    n_in = box_px**2
    n_out = (3 * box_px) ** 2 - n_in
    return inner / n_in - (outer - inner) / n_out


def square_candidates(
    band,
    uv0,
    *,
    box_px: int = 4,
    search_px: int = SEARCH_PX,
    min_snr: float = MIN_SNR,
    max_candidates: int = 6,
) -> tuple[np.ndarray, np.ndarray]:
    """Bright square-sized blobs in the search window: the local maxima of the box contrast.

    Parameters
    ----------
    band : (rows, cols) array_like
        DN of one band of a scene (NaN outside the scene).
    uv0 : (2,) array_like, px
        Predicted scene position ``(u, v)``.
    box_px, search_px, min_snr
        As :func:`square_centroid`.
    max_candidates : int
        The strongest this many are returned.

    Returns
    -------
    uv : (k, 2) int ndarray
        Scene pixels of the candidates (contrast maxima), strongest first.
    snr : (k,) ndarray
        Their contrast over the window's robust σ (NMAD), each ≥ ``min_snr``.
    """
    from scipy.ndimage import maximum_filter

    a = np.asarray(band, dtype=np.float64)
    if a.ndim != 2:
        raise InputError(f"a band of a scene is a 2-D image, got shape {a.shape}")
    none = (np.zeros((0, 2), np.int64), np.zeros(0))
    u0, v0 = np.rint(np.asarray(uv0, float)).astype(int)
    r = int(search_px) + 3 * box_px
    # the window, clipped to the scene; pixels outside the scene (NaN) take the window's median
    r0, r1 = max(u0 - r, 0), min(u0 + r + 1, a.shape[0])
    c0, c1 = max(v0 - r, 0), min(v0 + r + 1, a.shape[1])
    if r1 - r0 < 6 * box_px + 1 or c1 - c0 < 6 * box_px + 1:
        return none
    win = a[r0:r1, c0:c1]
    finite = np.isfinite(win)
    if finite.sum() < 0.5 * win.size:
        return none
    if finite.all():  # a window inside the scene needs no fill: no median to compute
        win = np.ascontiguousarray(win)
    else:
        win = np.where(finite, win, np.median(win[finite]))
    con = box_contrast(win, box_px)
    inner = np.full(con.shape, -np.inf)
    s = slice(3 * box_px, -3 * box_px)
    inner[s, s] = np.nan_to_num(con[s, s], nan=-np.inf)
    noise = 1.4826 * np.median(np.abs(win - np.median(win)))
    snr = inner / noise if noise > 0 else np.where(inner > 0, np.inf, -np.inf)
    peak = (inner == maximum_filter(inner, size=2 * box_px + 1)) & (snr >= min_snr)
    rr, cc = np.nonzero(peak)
    order = np.argsort(-snr[rr, cc], kind="stable")[:max_candidates]
    return np.column_stack([rr[order] + r0, cc[order] + c0]), snr[rr[order], cc[order]]


def blob_centroid(band, uv_peak, *, box_px: int = 4, max_area_factor: float = 4.0):
    """The intensity-weighted centroid of the bright blob at a detection (module docstring,
    step 3).

    Returns
    -------
    uv : (2,) ndarray, px
        ``(u, v)`` in the scene (NaN when the blob is not a square's: touching the window's
        border or larger than ``max_area_factor · box_px²``).
    ok : bool
    """
    from hsgeo.measure.blobs import weighted_blob_centroid

    a = np.asarray(band, dtype=np.float64)
    h = 2 * box_px
    pr, pc = (int(v) for v in uv_peak)
    if pr - h < 0 or pc - h < 0 or pr + h + 1 > a.shape[0] or pc + h + 1 > a.shape[1]:
        return np.full(2, np.nan), False
    sub = a[pr - h : pr + h + 1, pc - h : pc + h + 1]
    if not np.all(np.isfinite(sub)):  # at the scene's edge
        return np.full(2, np.nan), False
    border = np.concatenate([sub[0], sub[-1], sub[1:-1, 0], sub[1:-1, -1]])
    w = sub - np.median(border)
    rc, blob = weighted_blob_centroid(w, np.unravel_index(np.argmax(w), w.shape))
    if (
        rc is None
        or blob[0].any()
        or blob[-1].any()
        or blob[:, 0].any()
        or blob[:, -1].any()
        or blob.sum() > max_area_factor * box_px**2
    ):
        return np.full(2, np.nan), False
    return rc + (pr - h, pc - h), True


def square_centroid(
    band,
    uv0,
    *,
    box_px: int = 4,
    search_px: int = SEARCH_PX,
    min_snr: float = MIN_SNR,
    max_area_factor: float = 4.0,
) -> tuple[np.ndarray, bool, float]:
    """Centre of the strongest bright square near a predicted position (module docstring).

    Where several squares may lie in one window, choose among :func:`square_candidates`
    instead (as :mod:`hsgeo.workflows.lp_observations` does, by the offset common to a strip).

    Parameters
    ----------
    band : (rows, cols) array_like
        DN of one band of a scene (NaN outside the scene).
    uv0 : (2,) array_like, px
        Predicted scene position ``(u, v)``.
    box_px : int
        The square's size in pixels (1.2 m over the GSD, rounded up).
    search_px : int
        Half-width of the search window.
    min_snr : float
        Contrast needed, in robust σ (NMAD) of the window.
    max_area_factor : float
        Largest blob, in units of ``box_px²``.

    Returns
    -------
    uv : (2,) ndarray, px
        The centroid ``(u, v)`` (NaN when not found).
    ok : bool
    snr : float
        The detection's contrast over the window's robust σ (0 when none).
    """
    cand, snr = square_candidates(
        band, uv0, box_px=box_px, search_px=search_px, min_snr=-np.inf, max_candidates=1
    )
    if cand.shape[0] == 0:
        return np.full(2, np.nan), False, 0.0
    if not snr[0] >= min_snr:
        return np.full(2, np.nan), False, float(snr[0])
    uv, ok = blob_centroid(band, cand[0], box_px=box_px, max_area_factor=max_area_factor)
    return uv, ok, float(snr[0])
