"""BRISK key points and Hamming matching (hsgeo.measure.keypoints); the reference squares'
centroids (hsgeo.measure.targets_lp)."""

import cv2
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter
from scipy.ndimage import shift as nd_shift

from hsgeo.errors import InputError
from hsgeo.measure.keypoints import detect_brisk, match_hamming, to_uint8
from hsgeo.measure.targets_lp import box_contrast, square_centroid


def _texture(rng, shape=(260, 300)):
    """Multi-scale smooth random texture (fields, edges at several scales)."""
    return sum(gaussian_filter(rng.normal(size=shape), s) * s for s in (1.0, 2.0, 4.0, 8.0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_brisk_recovers_a_known_shift(seed):
    """An image and its copy shifted by a known sub-pixel offset (cubic-spline resampling):
    the matched key points' median displacement is the offset to < 0.5 px (in fact ~0.05),
    and most single matches are within 1 px of it."""
    rng = np.random.default_rng(seed)
    img = _texture(rng)
    d = rng.uniform(-8, 8, 2)  # (du, dv) = (rows, columns)
    moved = nd_shift(img, d, order=3, mode="nearest")
    a, b = img[20:220, 20:280], moved[20:220, 20:280]
    k1, k2 = detect_brisk(a), detect_brisk(b)
    assert k1.n > 300 and k2.n > 300
    i1, i2, dist = match_hamming(k1.descriptors, k2.descriptors)
    assert i1.size > 200
    off = k2.uv[i2] - k1.uv[i1]
    assert np.all(np.abs(np.median(off, axis=0) - d) < 0.5)
    assert np.mean(np.linalg.norm(off - d, axis=1) < 1.0) > 0.85
    assert np.all(dist >= 0) and np.all(dist <= 512)


def test_scene_coordinates_are_row_column():
    """u is the row, v the column: a lone bright blob is found where it was put."""
    img = np.zeros((120, 160))
    img[40:52, 100:112] = 1.0
    img = gaussian_filter(img, 1.0) + 0.01 * gaussian_filter(
        np.random.default_rng(0).normal(size=img.shape), 1
    )
    k = detect_brisk(img, threshold=10)
    assert k.n > 0
    near = np.linalg.norm(k.uv - [45.5, 105.5], axis=1) < 10
    assert near.any()
    assert not np.any(np.linalg.norm(k.uv - [105.5, 45.5], axis=1) < 10)


def test_nan_edges_take_no_keypoints():
    rng = np.random.default_rng(3)
    img = _texture(rng, (200, 200))
    img[:, :30] = np.nan
    k = detect_brisk(img)
    assert k.n > 50
    assert k.uv[:, 1].min() >= 30 + 12 - 1.0  # sub-pixel refinement may move half a px


def test_to_uint8_stretch():
    a = np.linspace(0.0, 1000.0, 9999).reshape(101, 99)
    img, valid = to_uint8(a)
    assert img.dtype == np.uint8 and valid.all()
    assert img.min() == 0 and img.max() == 255
    assert abs(int(img.ravel()[a.size // 2]) - 128) <= 1
    with pytest.raises(InputError):
        to_uint8(np.zeros(5))


def test_matching_ratio_and_cross_check():
    """Hand-made descriptors: an ambiguous one (two equally near) fails the ratio test; a
    many-to-one match fails the cross-check; a clean pair survives both."""
    rng = np.random.default_rng(5)
    base = rng.integers(0, 256, (4, 64), dtype=np.uint8)
    d1 = base.copy()
    d2 = np.vstack([base[0], base[1], base[1], rng.integers(0, 256, (1, 64), dtype=np.uint8)])
    i1, i2, _ = match_hamming(d1, d2)
    assert list(zip(i1.tolist(), i2.tolist(), strict=True)) == [(0, 0)]
    i1, i2, _ = match_hamming(d1, d2, ratio=None, cross_check=False)
    assert 1 in i1.tolist()  # without the ratio test the ambiguous one is matched
    with pytest.raises(InputError):
        match_hamming(d1, d2[:, :32])
    assert match_hamming(d1[:0], d2)[0].size == 0


def _square_image(rng, centre_uv, gsd_m=0.33, n=200, ss=8):
    """A 1.2 m white square rendered by area integration (8 × 8 sub-pixels), a textured
    background, a Gaussian PSF (σ 0.5 px) and noise."""
    side = 1.2 / gsd_m
    yy, xx = (np.mgrid[0 : n * ss, 0 : n * ss] + 0.5) / ss - 0.5
    sq = (np.abs(yy - centre_uv[0]) < side / 2) & (np.abs(xx - centre_uv[1]) < side / 2)
    cover = sq.reshape(n, ss, n, ss).mean(axis=(1, 3))
    img = 100 + 20 * gaussian_filter(rng.normal(size=(n, n)), 2) + 300 * cover
    return gaussian_filter(img, 0.5) + rng.normal(0, 2, (n, n))


def _bf_reference(d1, d2, ratio, cross_check):
    """The matching as OpenCV's BFMatcher does it (knnMatch, then match back), object by object."""
    bf = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=False)
    k = 2 if ratio is not None and d2.shape[0] >= 2 else 1
    out = []
    for m in bf.knnMatch(d1, d2, k=k):
        second = m[1].distance if len(m) > 1 else np.inf
        if k == 1 or m[0].distance < ratio * second:
            out.append((m[0].queryIdx, m[0].trainIdx, m[0].distance))
    if cross_check and out:
        cand = np.unique([o[1] for o in out])
        back = {int(cand[b.queryIdx]): b.trainIdx for b in bf.match(d2[cand], d1)}
        out = [o for o in out if back[o[1]] == o[0]]
    return out


@pytest.mark.parametrize("seed", range(8))
def test_matching_is_opencvs_brute_force_matcher(seed):
    """The same matches, ties included, as OpenCV's BFMatcher (knnMatch, match), on descriptors
    built to tie: few distinct 64-byte words with a few bits flipped."""
    rng = np.random.default_rng(seed)
    words = rng.integers(0, 256, (40, 4), dtype=np.uint8)
    for n1, n2 in ((1, 1), (1, 2), (30, 1), (300, 250), (120, 400)):
        d1 = np.repeat(words[rng.integers(0, 40, n1)], 16, axis=1)
        d2 = np.repeat(words[rng.integers(0, 40, n2)], 16, axis=1)
        d2 ^= (rng.random(d2.shape) < 0.02) * rng.integers(0, 256, d2.shape, dtype=np.uint8)
        for ratio, cross in ((0.8, True), (0.8, False), (None, True), (None, False)):
            i1, i2, dist = match_hamming(d1, d2, ratio=ratio, cross_check=cross)
            got = list(zip(i1.tolist(), i2.tolist(), dist.tolist(), strict=True))
            assert got == _bf_reference(d1, d2, ratio, cross), (n1, n2, ratio, cross)


def test_square_centroid_on_rendered_squares():
    """The centre of a rendered 1.2 m square (3.6 px) from a prediction 10 px off: within
    0.15 px in each coordinate (measured: σ ≈ 0.04 px, max ≈ 0.11 px over 100 squares)."""
    rng = np.random.default_rng(1)
    err = []
    for _ in range(100):
        c = rng.uniform(90, 110, 2)
        img = _square_image(rng, c)
        uv, ok, snr = square_centroid(img, c + rng.normal(0, 10, 2))
        assert ok and snr > 5
        err.append(uv - c)
    err = np.array(err)
    assert np.all(np.abs(err) < 0.15)
    assert np.all(np.abs(err.mean(axis=0)) < 0.03)


def test_square_centroid_rejects():
    rng = np.random.default_rng(2)
    flat = 100 + rng.normal(0, 2, (200, 200))
    uv, ok, _ = square_centroid(flat, (100, 100))
    assert not ok and np.all(np.isnan(uv))
    img = _square_image(rng, (100.0, 100.0))
    assert not square_centroid(img, (10, 100))[1]  # the window (clipped) misses the square
    big = flat.copy()
    big[80:120, 80:120] += 300  # a roof: no contrast at the square's scale in its middle
    uv, ok, _ = square_centroid(big, (100, 100), search_px=5)
    assert not ok


def test_box_contrast_peaks_on_a_box():
    a = np.zeros((40, 40))
    a[18:22, 10:14] = 1.0
    c = box_contrast(a, 4)
    assert np.unravel_index(np.nanargmax(c), c.shape) == (19, 11)
