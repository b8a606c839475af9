"""The engine's serial passes rewritten for speed (issue 41) give the values they replaced."""

import numpy as np
import pytest
from test_engine_fused import _masks
from test_pushbroom import _problem

from hsgeo.adjust._fast import (
    group_scores,
    kept_whitened,
    matvec,
    matvec_points,
    point_blocks_doubt,
    point_excess,
    point_rows_dot,
    standardised,
    subtract_point_rows,
)
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


def test_matvec_points_equals_matvec_plus_point_rows_bit_for_bit(tiny):
    p, blocks, _ = _problem(tiny[0])
    lay = _Layout(p)
    sy = _evaluate(lay, blocks, _masks(blocks, 0.1), True)
    rng = np.random.default_rng(6)
    x = rng.standard_normal(lay.n_c)
    y = rng.standard_normal((lay.n_pts, 3))
    want = matvec(*sy.Jrc.arrays, x) + point_rows_dot(sy.Jp, sy.pidx, y)
    np.testing.assert_array_equal(matvec_points(*sy.Jrc.arrays, x, sy.Jp, sy.pidx, y), want)


def test_point_blocks_doubt_equals_the_numpy_test():
    """The compiled point-block test flags the blocks numpy's determinant test flagged: zero
    diagonals as bad, singular and near-singular blocks as doubtful, regular ones as neither.
    """
    rng = np.random.default_rng(7)
    n = 3000
    A = rng.standard_normal((n, 3, 3)) * 10.0 ** rng.uniform(-3, 3, (n, 1, 1))
    V = A @ A.transpose(0, 2, 1)
    V[::7, 2, :] = V[::7, 1, :] * 2.0  # singular: rows (and columns) dependent
    V[::7, :, 2] = V[::7, :, 1] * 2.0
    V[::7, 2, 2] = 4.0 * V[::7, 1, 1]
    V[3::11] *= np.array([1.0, 1.0, 0.0])[:, None] * np.array([1.0, 1.0, 0.0])  # a zero diagonal
    thresh = 1e-11 * 27
    bad, doubt, dv = point_blocks_doubt(V, thresh)
    d = np.sqrt(np.maximum(np.diagonal(V, axis1=1, axis2=2), 0.0))
    dz = d == 0
    d = np.where(dz, 1.0, d)
    Vs = V / d[:, :, None] / d[:, None, :]
    want_bad = dz.any(axis=1)
    want_doubt = ~(np.linalg.det(Vs) >= thresh) & ~want_bad
    np.testing.assert_array_equal(bad, want_bad)
    np.testing.assert_array_equal(doubt & ~bad, want_doubt)
    np.testing.assert_array_equal(dv, d)
    assert want_bad.sum() > 100 and want_doubt.sum() > 100 and (~want_bad & ~want_doubt).sum()


@pytest.mark.parametrize("g", [1, 2, 3])
def test_rejection_scores_equal_the_numpy_expressions_bit_for_bit(g):
    """The outlier test's standardised residuals and per-group maxima, compiled, against the
    numpy expressions they replaced (hsgeo.adjust.robust._reject).
    """
    rng = np.random.default_rng(8)
    m = 3 * 1000
    r = rng.standard_normal(m) * 10.0 ** rng.uniform(-2, 2, m)
    h = rng.uniform(0.0, 1.2, m)  # leverages above 0.99 take the floor 1e-2
    np.testing.assert_array_equal(
        standardised(r, h), np.abs(r) / np.sqrt(np.maximum(1.0 - h, 1e-2))
    )
    np.testing.assert_array_equal(standardised(r, np.zeros(0)), np.abs(r))
    keep = rng.random(m) > 0.3
    keep[: 2 * g] = False  # whole groups without a kept row
    score_rows = np.abs(rng.standard_normal(int(keep.sum())))
    full = np.zeros(m)
    full[np.flatnonzero(keep)] = score_rows
    want = full[0::g].copy()
    for k in range(1, g):
        want = np.maximum(want, full[k::g])
    np.testing.assert_array_equal(group_scores(score_rows, keep, g), want)


def test_subtract_point_rows_equals_point_rows_dot_bit_for_bit():
    rng = np.random.default_rng(9)
    m, n_pts = 6000, 400
    jp = rng.standard_normal((m, 3))
    pidx = rng.integers(-1, n_pts, m)
    u = rng.standard_normal(m)
    held = rng.choice(n_pts, 5, replace=False)
    y = np.zeros((n_pts, 3))
    y[held] = rng.standard_normal((5, 3))
    mask = np.zeros(n_pts, dtype=bool)
    mask[held] = True
    want = u - point_rows_dot(jp, pidx, y)
    got = u.copy()
    subtract_point_rows(got, jp, pidx, y, mask)
    np.testing.assert_array_equal(got, want)
    assert not np.array_equal(got, u)


def test_pair_marks_equal_every_pair_of_a_point_s_rows():
    """The Schur pattern's item pairs, from each point's distinct rows once per pair, are the
    pairs of every two rows of a point (both orders), as the kernel reads them."""
    from hsgeo.adjust._fast import _pair_marks

    rng = np.random.default_rng(8)
    n_pts, q, n_tiles = 400, 4, 60
    rows = []
    for i in range(n_pts):
        for _ in range(rng.integers(0, 6)):
            t0 = rng.integers(0, n_tiles - q)
            f = 6 * (t0 + np.arange(q))
            f[rng.random(q) < 0.1] = -1  # an item not set
            rows.append((i, f))
            if rng.random() < 0.7:
                rows.append((i, f.copy()))  # the y row of the x row before it
    rng.shuffle(rows)
    pidx = np.array([i for i, _ in rows])
    fcol = np.array([f for _, f in rows], dtype=np.int32)
    order = np.argsort(pidx, kind="stable").astype(np.int64)
    ptr = np.concatenate([[0], np.cumsum(np.bincount(pidx, minlength=n_pts))]).astype(np.int64)
    tile_of = np.full(6 * n_tiles, -1, dtype=np.int64)
    tile_of[::6] = np.arange(n_tiles)
    want = np.zeros((n_tiles, n_tiles), dtype=bool)
    for i in range(n_pts):
        mine = order[ptr[i] : ptr[i + 1]]
        for ra in mine:
            for rb in mine:
                for ca in fcol[ra][fcol[ra] >= 0]:
                    for cb in fcol[rb][fcol[rb] >= 0]:
                        want[tile_of[ca], tile_of[cb]] = True
    np.testing.assert_array_equal(_pair_marks(fcol, order, ptr, tile_of, n_tiles), want)


def test_rows_by_point_equals_a_stable_argsort_and_the_counts():
    from hsgeo.adjust._fast import rows_by_point

    rng = np.random.default_rng(9)
    n_pts = 500
    pidx = rng.integers(-1, n_pts, 20000)  # −1: a row without a point (a prior)
    pidx[:50] = 7  # a point with many rows
    rows = np.flatnonzero(pidx >= 0)
    want_order = rows[np.argsort(pidx[rows], kind="stable")]
    want_ptr = np.concatenate([[0], np.cumsum(np.bincount(pidx[rows], minlength=n_pts))])
    order, ptr = rows_by_point(pidx, n_pts)
    np.testing.assert_array_equal(order, want_order)
    np.testing.assert_array_equal(ptr, want_ptr)
    with pytest.raises(ValueError, match="point index"):
        rows_by_point(np.array([0, 5]), 5)
