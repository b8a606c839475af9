"""The fused path (``SolverOptions.fused``): a block that writes its whitened derivatives
straight into the engine's row-compressed arrays against the generic path (the block's own
Jacobian, copied by the engine), and the fused derivatives against finite differences.
"""

import numpy as np
import pytest
from test_pushbroom import _problem

from hsgeo.adjust import adjust
from hsgeo.adjust._fused import _FusedPart
from hsgeo.adjust.system import _evaluate, _Layout
from hsgeo.simulate.pushbroom_campaign import simulate


@pytest.fixture(scope="module")
def tiny():
    return simulate(0.001, rng=3)


def _masks(blocks, share, seed=0):
    """Masks with ``share`` of the observations (both rows) left out."""
    rng = np.random.default_rng(seed)
    masks = [np.ones(b.m, bool) for b in blocks]
    pairs = masks[0].reshape(-1, 2)
    pairs[rng.random(pairs.shape[0]) < share] = False
    return masks


def _both(lay, blocks, masks):
    """The system by the fused and by the generic path, from the same Newton start."""
    dt0 = blocks[0]._dt_s.copy()  # the time residual's Newton start moves with each evaluation
    out = []
    for fused in (True, False):
        blocks[0]._dt_s[:] = dt0
        out.append(_evaluate(lay, blocks, masks, True, fused=fused))
    return out


@pytest.mark.parametrize("y_as_time", [False, True])
@pytest.mark.parametrize("share", [0.0, 0.1])
@pytest.mark.parametrize("fixed", [False, True])
def test_fused_system_equals_generic(tiny, y_as_time, share, fixed):
    """The same arrays, bit for bit (the same products, written once instead of twice), with
    rejected observations and with fixed entries (empty slots) in a dense and an indexed block.
    """
    p, blocks, _ = _problem(tiny[0], y_as_time=y_as_time)
    if fixed:
        p.fix("distortion", index=1)
        p.fix("c_mm", index=0)
    lay = _Layout(p)
    masks = _masks(blocks, share)
    assert _FusedPart.spec_of(lay, blocks[0], masks[0], None) is not None
    a, b = _both(lay, blocks, masks)
    for name in ("cols", "vals", "fcol", "fw", "fd"):
        np.testing.assert_array_equal(getattr(a.Jrc, name), getattr(b.Jrc, name), err_msg=name)
    np.testing.assert_array_equal(a.Jp, b.Jp)
    np.testing.assert_array_equal(a.pidx, b.pidx)
    np.testing.assert_array_equal(a.r, b.r)
    assert a.n_obs_rows == b.n_obs_rows
    # the gradient and diagonal accumulated in the block's pass against a pass over the rows
    assert a.gd_parts and not b.gd_parts
    for x, y in zip(a.gradient_diag(), b.gradient_diag(), strict=True):
        np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12 * np.max(np.abs(y)))
    if fixed:
        assert (a.Jrc.cols == -1).any() and np.all(a.Jrc.vals[a.Jrc.cols < 0] == 0.0)


def test_fused_path_falls_back_where_it_cannot_apply(tiny):
    """A fixed spline node (non-contiguous node columns) or a mask that splits an observation
    takes the generic path: no fused part, and the same system as with ``fused=False``.
    """
    p, blocks, _ = _problem(tiny[0])
    p.fix("nodes", index=(3, 4))
    lay = _Layout(p)
    masks = _masks(blocks, 0.0)
    assert _FusedPart.spec_of(lay, blocks[0], masks[0], None) is None
    p2, blocks2, _ = _problem(tiny[0])
    split = _masks(blocks2, 0.0)
    split[0][1] = False
    assert _FusedPart.spec_of(_Layout(p2), blocks2[0], split[0], None) is None
    a, b = _both(lay, blocks, masks)
    np.testing.assert_array_equal(a.Jrc.tocsr().toarray(), b.Jrc.tocsr().toarray())


@pytest.mark.parametrize("y_as_time", [False, True])
def test_fused_derivatives_against_finite_differences(tiny, y_as_time):
    """Columns of the fused whitened Jacobian (camera, node and point unknowns) against central
    differences of the whitened residuals, with rejected observations left out.
    """
    p, blocks, _ = _problem(tiny[0], y_as_time=y_as_time)
    # at the truth moved off zero corrections (1 cm, 0.1 mrad), as test_pushbroom's checks:
    # the crossing times stay within T_MAX there (the start leaves a few at the bound)
    vals = dict(tiny[1].values)
    vals["nodes"] = vals["nodes"] + np.r_[0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4]
    for name, v in vals.items():
        p[name].value = v
    lay = _Layout(p)
    masks = _masks(blocks, 0.1, seed=2)
    sy = _evaluate(lay, blocks, masks, True, fused=True)
    assert sy.Jrc.fcol.shape[1] == 4  # the node group kept factored
    J = sy.Jrc.tocsr().toarray()
    n = sy.n_obs_rows
    rng = np.random.default_rng(1)
    cols = np.unique(np.r_[np.arange(11), rng.choice(lay.n_c, 12, replace=False)])
    state = lay.get_state()
    for c in cols:
        jmax = float(np.max(np.abs(J[:n, c])))
        h = min(1e-6, 1e-3 / jmax) if jmax > 0 else 1e-6  # a residual change of ≲ 1e-3
        rs = []
        for s in (1.0, -1.0):
            lay.set_state(state)
            dc = np.zeros(lay.n_c)
            dc[c] = s * h
            lay.apply(dc, None)
            rs.append(_evaluate(lay, blocks, masks, False).r[:n])
        lay.set_state(state)
        fd = (rs[0] - rs[1]) / (2 * h)
        # atol: the rounding of map coordinates (~1e5 m, ~1e-11 m) over 2h, in whitened px
        np.testing.assert_allclose(J[:n, c], fd, rtol=1e-5, atol=max(1e-6, 1e-5 * jmax))
    pts = rng.choice(lay.n_pts, 3, replace=False)
    for i in pts:
        for a in range(3):
            rows = np.flatnonzero(sy.pidx[:n] == i)
            h = 1e-4  # m
            rs = []
            for s in (1.0, -1.0):
                lay.set_state(state)
                dp = np.zeros((lay.n_pts, 3))
                dp[i, a] = s * h
                lay.apply(np.zeros(lay.n_c), dp)
                rs.append(_evaluate(lay, blocks, masks, False).r[:n])
            lay.set_state(state)
            fd = (rs[0] - rs[1]) / (2 * h)
            np.testing.assert_allclose(sy.Jp[rows, a], fd[rows], rtol=1e-5, atol=1e-6)
            others = np.setdiff1d(np.arange(n), rows)
            assert np.max(np.abs(fd[others])) < 1e-8


@pytest.mark.parametrize("y_as_time", [False, True])
def test_fused_adjustment_equals_generic(tiny, y_as_time):
    """The whole adjustment with rejection: the same minimum to 1e-9 and the same rejected set."""
    res = {}
    for fused in (True, False):
        p, blocks, _ = _problem(tiny[0], y_as_time=y_as_time)
        res[fused] = adjust(p, blocks, reject_k=5.0, reject_every_iteration=True, fused=fused)
    a, b = res[True], res[False]
    for blk in a.params.blocks():
        np.testing.assert_allclose(
            blk.value, b.params[blk.name].value, rtol=1e-9, atol=1e-12, err_msg=blk.name
        )
    np.testing.assert_allclose(a.sigma0, b.sigma0, rtol=1e-9)
    np.testing.assert_array_equal(a.outliers(), b.outliers())
    assert a.outliers().any()  # the rejection was exercised
    assert a.iterations == b.iterations


@pytest.mark.parametrize("fixed", [False, True])
def test_fused_columns_kept_in_the_buffers_give_the_same_arrays(tiny, fixed, monkeypatch):
    """A linearisation into the arrays of the last one, with the same rows, writes only what
    the block's evaluation overwrote (_fused_refresh): the same arrays bit for bit as a fresh
    fill, with empty slots (fixed entries) in a dense and an indexed block; fewer rows (a
    rejection) move the indices of the rows still kept up (_compact_rows), the same arrays
    again; rows not among the last ones write the columns again.
    """
    import hsgeo.adjust._fused as F
    from hsgeo.adjust.system import _Buffers

    writes = []
    columns = F._fused_columns
    monkeypatch.setattr(F, "_fused_columns", lambda *a: writes.append(1) or columns(*a))
    p, blocks, _ = _problem(tiny[0], y_as_time=True)
    if fixed:
        p.fix("distortion", index=1)
        p.fix("c_mm", index=0)
    lay = _Layout(p)
    buffers = _Buffers()
    masks = _masks(blocks, 0.1)
    dt0 = blocks[0]._dt_s.copy()
    _evaluate(lay, blocks, masks, True, buffers=buffers)  # writes the columns
    compacted = []
    compact = F._compact_rows
    monkeypatch.setattr(F, "_compact_rows", lambda *a: compacted.append(1) or compact(*a))
    # the same rows: a refresh; fewer rows (those left out at 0.1 are left out at 0.2):
    # compacted; then more rows: the columns written again
    for share, written, moved in ((0.1, 0, 0), (0.2, 0, 1), (0.05, 1, 0)):
        masks = _masks(blocks, share)
        blocks[0]._dt_s[:] = dt0
        before, before_c = len(writes), len(compacted)
        kept = _evaluate(lay, blocks, masks, True, buffers=buffers)
        assert len(writes) - before == written
        assert len(compacted) - before_c == moved
        blocks[0]._dt_s[:] = dt0
        fresh = _evaluate(lay, blocks, masks, True)
        for name in ("cols", "vals", "fcol", "fw", "fd"):
            np.testing.assert_array_equal(
                getattr(kept.Jrc, name), getattr(fresh.Jrc, name), err_msg=name
            )
        np.testing.assert_array_equal(kept.r, fresh.r)
        np.testing.assert_array_equal(kept.gradient_diag()[0], fresh.gradient_diag()[0])
