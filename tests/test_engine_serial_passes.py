"""The engine's serial passes rewritten for speed (issue 41) give the values they replaced."""

import numpy as np
import pytest
from test_engine_fused import _masks
from test_pushbroom import _problem

from hsgeo.adjust._fast import kept_whitened, point_excess
from hsgeo.adjust.solver import _largest
from hsgeo.adjust.system import _evaluate, _Layout
from hsgeo.simulate.pushbroom_campaign import simulate


def test_point_excess_equals_the_numpy_expression_bit_for_bit():
    rng = np.random.default_rng(4)
    m, n_pts = 5000, 300
    r_trial, r, u = (rng.standard_normal(m) * 10.0 ** rng.uniform(-3, 3, m) for _ in range(3))
    pidx = rng.integers(-1, n_pts, m)  # −1: a row without a point (a prior)
    rows = np.flatnonzero(pidx >= 0)
    want = np.bincount(
        pidx[rows], weights=r_trial[rows] ** 2 - (r[rows] + u[rows]) ** 2, minlength=n_pts
    )
    np.testing.assert_array_equal(point_excess(r_trial, r, u, pidx, n_pts), want)


@pytest.mark.parametrize("share", [0.0, 0.3])
def test_kept_whitened_equals_the_numpy_expression_bit_for_bit(share):
    rng = np.random.default_rng(5)
    m = 4001
    r = rng.standard_normal(m) * 10.0 ** rng.uniform(-3, 3, m)
    sigma = 10.0 ** rng.uniform(-2, 1, m)
    keep = rng.random(m) >= share
    out = np.full(m + 3, np.nan)
    kept_whitened(r, sigma, keep, out)
    n = int(keep.sum())
    np.testing.assert_array_equal(out[:n], (r * (1.0 / sigma))[keep])
    assert np.isnan(out[n:]).all()  # nothing written past the kept rows


@pytest.mark.parametrize("seed", range(5))
def test_largest_equals_a_stable_sort_of_all(seed):
    rng = np.random.default_rng(seed)
    v = rng.integers(-3, 6, 400).astype(float)  # many ties
    pos = np.sort(v[v > 0])[::-1]
    for k in (1, 2, 7, pos.size):
        got = _largest(v, k, pos[k - 1])
        np.testing.assert_array_equal(got, np.argsort(-v, kind="stable")[:k])


@pytest.fixture(scope="module")
def tiny():
    return simulate(0.001, rng=3)


@pytest.mark.parametrize("share", [0.0, 0.1])
def test_trial_residuals_equal_the_linearisation_s(tiny, share):
    """The residuals of a trial (no Jacobian: kept rows by their mask) are those of the
    linearisation at the same values (kept rows by their indices), bit for bit."""
    p, blocks, _ = _problem(tiny[0])
    lay = _Layout(p)
    masks = _masks(blocks, share)
    dt0 = blocks[0]._dt_s.copy()
    full = _evaluate(lay, blocks, masks, True, fused=False)
    blocks[0]._dt_s[:] = dt0
    trial = _evaluate(lay, blocks, masks, False)
    np.testing.assert_array_equal(trial.r, full.r)
    assert trial.n_obs_rows == full.n_obs_rows


def test_small_pages_arrays_are_numpy_arrays_advised_small_pages():
    """The Jacobian's kept arrays (system._Buffers): numpy's own arrays of the shape and type
    asked; on Linux the whole pages of a large one are advised small pages (smaps' flags)."""
    import sys
    from pathlib import Path

    from hsgeo.adjust.system import _SMALL_PAGES_MIN_BYTES, _madvise, _small_pages_empty

    small = _small_pages_empty((300, 11), np.int32)
    big = _small_pages_empty((_SMALL_PAGES_MIN_BYTES // 8 + 4096, 2))
    for a, dt in ((small, np.int32), (big, np.float64)):
        assert a.dtype == dt and a.flags.c_contiguous and a.flags.owndata and a.flags.writeable
    assert small.shape == (300, 11) and big.shape == (_SMALL_PAGES_MIN_BYTES // 8 + 4096, 2)
    if _madvise() is None:
        assert not sys.platform.startswith("linux")
        return
    # the mapping that holds the array's middle carries the flag "nh" (no huge pages)
    mid = big.ctypes.data + big.nbytes // 2
    lines = Path("/proc/self/smaps").read_text().splitlines()
    inside = False
    for line in lines:
        head = line.split()[0]
        if "-" in head and all(c in "0123456789abcdef-" for c in head):
            lo, hi = (int(x, 16) for x in head.split("-"))
            inside = lo <= mid < hi
        elif inside and line.startswith("VmFlags:"):
            assert "nh" in line.split()[1:]
            return
    raise AssertionError("no mapping holds the array")
