"""BRISK key points of rotation-compensated LP scenes, matched within one band (002 §3.1).

002 §3.1 detects and describes key points in each rotation-compensated LP image scene with
BRISK (Leutenegger et al. 2011) and matches descriptors only between the same spectral bands
("the radiometric inter-band differences make it challenging to retrieve reliable observations
between spectral bands"). This module is that step, with OpenCV's BRISK (``cv2.BRISK_create``)
and a brute-force Hamming matcher:

* :func:`to_uint8` — BRISK works on 8-bit images; a band of a scene (float DN) is stretched
  linearly between its 0.5 and 99.5 percentiles (of the finite pixels) onto 0 … 255 and
  clipped. A percentile stretch rather than min–max: one saturated roof or a hot pixel would
  otherwise compress the grass and fields, where most key points are, into a few grey levels.
  Pixels outside the scene (NaN, from the rotation compensation's shift at the scene's edges)
  become 0 and are masked out of the detection with a margin (:data:`EDGE_MARGIN_PX`), so no
  key point is described across the artificial edge.
* :func:`detect_brisk` — key points and their 512-bit descriptors of one band.
* :func:`match_hamming` — matches between two sets of descriptors of the *same band*:
  mutual nearest neighbours (cross-check) **and** Lowe's ratio test (best / second-best Hamming
  distance < ``ratio``). Both, because they remove different false matches: the ratio test
  drops key points whose descriptor is ambiguous in the other scene (the repeated rows of a
  field, the corners of identical roofs), the cross-check drops many-to-one matches that the
  ratio test lets through when the other scene's key point is distinctive but not the same
  feature. RANSAC (:mod:`hsgeo.measure.lp_ransac`) is then left with few gross errors, which
  it needs: 002's LP fundamental matrix takes 11 correspondences per sample.

Coordinates are scene pixels ``(u, v)``: ``u`` the row (along-track, the line within the scene),
``v`` the column, pixel-centre origin (OpenCV's key point ``pt = (x, y) = (v, u)``).

References
----------
Jonassen et al. (2024), 002 §3.1. Leutenegger, Chli & Siegwart (2011), BRISK, ICCV.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "Keypoints",
    "to_uint8",
    "detect_brisk",
    "match_hamming",
    "STRETCH_PERCENTILES",
    "EDGE_MARGIN_PX",
    "BRISK_THRESHOLD",
    "BRISK_OCTAVES",
    "RATIO",
]

#: The percentiles of a band mapped to 0 and 255 (:func:`to_uint8`).
STRETCH_PERCENTILES = (0.5, 99.5)
#: Pixels this close to a pixel outside the scene (NaN) take no key point: BRISK's smallest
#: sampling pattern reaches about this far.
EDGE_MARGIN_PX = 12
#: BRISK's FAST/AGAST score threshold (OpenCV's default 30, on the 8-bit stretch).
BRISK_THRESHOLD = 30
#: BRISK's scale-space octaves. 0: the full-resolution layer only (OpenCV's default is 3). The
#: scenes of one campaign differ in scale by at most the ratio of its flying heights (002: 2500 /
#: 1875 m = 1.33), which BRISK's descriptor tolerates, and a key point found on a coarser octave
#: is located to a fraction of *that* octave's pixel: on the rendered campaign of
#: :mod:`hsgeo.simulate.lp_campaign` (scale 0.1, seed 0) 80 % of the observations were within
#: 1 px of their true image position with 3 octaves, 94 % with 0.
BRISK_OCTAVES = 0
#: Lowe's ratio: a match is kept when best / second-best Hamming distance is below it. 0.5
#: rather than Lowe's 0.8: on the rendered campaign (scale 0.1, seeds 0–3; scale 0.25, seed 0)
#: the share of observations within 1 px of their true image position rose from 95–96 % (0.7)
#: and 94.9 % (0.7, scale 0.25) to 96–97 % and 95.8 %, and there were *more* tie points in
#: 4 of 5 runs (fewer components joined through an ambiguous match and dropped as
#: contradictory); 80 % with 0.8 and 3 octaves.
RATIO = 0.5


@dataclass(frozen=True)
class Keypoints:
    """Key points of one band of one scene.

    Attributes
    ----------
    uv : (n, 2) ndarray, px
        Scene coordinates ``(u, v)``: row, column (pixel-centre origin).
    descriptors : (n, 64) uint8 ndarray
        BRISK descriptors (512 bits).
    response : (n,) ndarray
        Detector score.
    size_px : (n,) ndarray
        Diameter of the key point's neighbourhood.
    """

    uv: np.ndarray
    descriptors: np.ndarray
    response: np.ndarray
    size_px: np.ndarray

    @property
    def n(self) -> int:
        """Number of key points."""
        return int(self.uv.shape[0])

    def subset(self, keep) -> Keypoints:
        """The key points selected by ``keep`` (boolean mask or indices)."""
        return Keypoints(
            self.uv[keep], self.descriptors[keep], self.response[keep], self.size_px[keep]
        )


def to_uint8(band, percentiles=STRETCH_PERCENTILES) -> tuple[np.ndarray, np.ndarray]:
    """A band as an 8-bit image by a linear percentile stretch, and its valid-pixel mask.

    Parameters
    ----------
    band : (rows, cols) array_like
        DN of one band of a scene; NaN outside the scene.
    percentiles : (float, float)
        The percentiles of the finite pixels mapped to 0 and 255 (:data:`STRETCH_PERCENTILES`).

    Returns
    -------
    image : (rows, cols) uint8 ndarray
    valid : (rows, cols) bool ndarray
        Finite pixels.
    """
    a = np.asarray(band, dtype=np.float64)
    if a.ndim != 2:
        raise InputError(f"a band of a scene is a 2-D image, got shape {a.shape}")
    valid = np.isfinite(a)
    if not valid.any():
        return np.zeros(a.shape, np.uint8), valid
    lo, hi = np.percentile(a[valid], percentiles)
    scale = 255.0 / (hi - lo) if hi > lo else 0.0
    out = np.where(valid, (a - lo) * scale, 0.0)
    return np.clip(np.rint(out), 0, 255).astype(np.uint8), valid


def _detection_mask(valid: np.ndarray) -> np.ndarray:
    """Valid pixels at least :data:`EDGE_MARGIN_PX` from an invalid one, as OpenCV's 8-bit mask."""
    if valid.all():
        return np.full(valid.shape, 255, np.uint8)
    from scipy.ndimage import binary_erosion

    inner = binary_erosion(valid, iterations=EDGE_MARGIN_PX, border_value=1)
    return np.where(inner, 255, 0).astype(np.uint8)


@functools.lru_cache(maxsize=8)
def _brisk(threshold: int, octaves: int):
    """One BRISK detector per setting: creating one builds its sampling pattern (~30 ms, more
    than detecting in a 200-line scene).
    """
    import cv2

    return cv2.BRISK_create(thresh=threshold, octaves=octaves)


def detect_brisk(
    band,
    *,
    threshold: int = BRISK_THRESHOLD,
    octaves: int = BRISK_OCTAVES,
    percentiles=STRETCH_PERCENTILES,
) -> Keypoints:
    """BRISK key points and descriptors of one band of a scene (``cv2.BRISK_create``).

    Parameters
    ----------
    band : (rows, cols) array_like
        DN; NaN outside the scene (no key point within :data:`EDGE_MARGIN_PX` of it).
    threshold, octaves : int
        BRISK's detection threshold and octaves (:data:`BRISK_THRESHOLD`,
        :data:`BRISK_OCTAVES`).
    percentiles : (float, float)
        The 8-bit stretch (:func:`to_uint8`).

    Returns
    -------
    Keypoints
        In scene coordinates ``(u, v)`` = (row, column).
    """
    img, valid = to_uint8(band, percentiles)
    kps, desc = _brisk(int(threshold), int(octaves)).detectAndCompute(img, _detection_mask(valid))
    if not kps or desc is None:
        return Keypoints(np.zeros((0, 2)), np.zeros((0, 64), np.uint8), np.zeros(0), np.zeros(0))
    pt = np.array([k.pt for k in kps], dtype=np.float64)
    return Keypoints(
        pt[:, ::-1].copy(),  # OpenCV (x, y) = (column, row) -> (u, v)
        np.ascontiguousarray(desc, dtype=np.uint8),
        np.array([k.response for k in kps], dtype=np.float64),
        np.array([k.size for k in kps], dtype=np.float64),
    )


def match_hamming(
    desc1, desc2, *, ratio: float | None = RATIO, cross_check: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Match binary descriptors of one band by Hamming distance (brute force).

    Parameters
    ----------
    desc1, desc2 : (n1, 64), (n2, 64) uint8 array_like
        Descriptors of the same band in two scenes.
    ratio : float or None
        Lowe's ratio test: keep a match when its Hamming distance is below ``ratio`` times the
        second-nearest one's (:data:`RATIO`); None: no ratio test.
    cross_check : bool
        Keep only mutual nearest neighbours.

    Returns
    -------
    i1, i2 : (m,) int ndarray
        Indices of the matched descriptors in ``desc1`` and ``desc2``.
    distance : (m,) ndarray
        Their Hamming distances (bits).
    """
    import cv2

    d1 = np.ascontiguousarray(desc1, dtype=np.uint8)
    d2 = np.ascontiguousarray(desc2, dtype=np.uint8)
    empty = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
    if d1.ndim != 2 or d2.ndim != 2 or d1.shape[1] != d2.shape[1]:
        raise InputError(f"descriptors of different kinds: shapes {d1.shape} and {d2.shape}")
    if d1.shape[0] == 0 or d2.shape[0] == 0:
        return empty
    # cv2.batchDistance is the brute-force search BFMatcher.knnMatch and .match run (the same
    # nearest neighbours, ties broken alike), returned as arrays instead of a Python object per
    # match: the list comprehensions over those objects cost as much as the search (issue 41)
    k = 2 if ratio is not None and d2.shape[0] >= 2 else 1
    dk, nk = cv2.batchDistance(d1, d2, cv2.CV_32S, normType=cv2.NORM_HAMMING, K=k)
    found = nk[:, 0] >= 0
    i1 = np.flatnonzero(found).astype(np.int64)
    i2 = nk[found, 0].astype(np.int64)
    dist = dk[found, 0].astype(np.float64)
    keep = np.ones(i1.size, bool)
    if k == 2:
        second = np.where(nk[found, 1] >= 0, dk[found, 1], np.inf)
        keep &= dist < ratio * second
    if cross_check and keep.any():
        # nearest neighbour in desc1 of the desc2 that are still matched (not of all desc2:
        # the same answer at a fraction of the brute-force cost)
        cand = np.unique(i2[keep])
        _, back = cv2.batchDistance(d2[cand], d1, cv2.CV_32S, normType=cv2.NORM_HAMMING, K=1)
        nn21 = np.full(d2.shape[0], -1, np.int64)
        nn21[cand] = back[:, 0]
        keep &= nn21[i2] == i1
    return i1[keep], i2[keep], dist[keep]
