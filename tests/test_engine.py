import types

import numpy as np
import pytest
from scipy.optimize import least_squares
from toy_models import Bearings, Exponential, Line, bearing_scene, frame_scene

from hsgeo import ConvergenceError, DatumError, InputError, ObservationError
from hsgeo.adjust import Parameters, SolverOptions, adjust, identifiability
from hsgeo.adjust.checks import check_jacobian


def line_data(seed, n=50, sigma=0.1):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 10, n)
    return t, 1.5 + 0.3 * t + sigma * rng.standard_normal(n)


def test_linear_matches_lstsq():
    t, y = line_data(1)
    p = Parameters()
    p.add("ab", [0.0, 0.0], columns=("a", "b"))
    res = adjust(p, Line(t, y, 0.1))
    A = np.column_stack([np.ones_like(t), t])
    x, rss, *_ = np.linalg.lstsq(A, y, rcond=None)
    np.testing.assert_allclose(res.value("ab"), x, rtol=0, atol=1e-10)
    s0sq = rss[0] / (t.size - 2)
    np.testing.assert_allclose(res.covariance, s0sq * np.linalg.inv(A.T @ A), rtol=1e-8)
    np.testing.assert_allclose(res.sigma0, np.sqrt(s0sq) / 0.1, rtol=1e-10)
    assert res.converged and res.dof == t.size - 2
    assert p.value("ab").tolist() == [0.0, 0.0]  # input untouched
    # the correlation of intercept and slope: t̄ > 0, so they are anti-correlated
    C = s0sq * np.linalg.inv(A.T @ A)
    rho = C[0, 1] / np.sqrt(C[0, 0] * C[1, 1])
    np.testing.assert_allclose(res.correlation(), [[1.0, rho], [rho, 1.0]], rtol=1e-8)
    assert rho < -0.8


def test_nonlinear_matches_scipy():
    rng = np.random.default_rng(3)
    t = np.linspace(0, 4, 60)
    y = 5.0 * np.exp(-0.7 * t) + 0.02 * rng.standard_normal(t.size)
    p = Parameters()
    p.add("Ak", [1.0, 0.1])
    res = adjust(p, Exponential(t, y, 0.02))
    ref = least_squares(
        lambda x: x[0] * np.exp(-x[1] * t) - y, [1.0, 0.1], xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    np.testing.assert_allclose(res.value("Ak"), ref.x, rtol=1e-8)


def _bearing_params(S, P, st, pt, th, points=True, n_control=2, sigma_ctrl=1e-3, seed=0):
    rng = np.random.default_rng(seed)
    p = Parameters()
    p.add(
        "stations", S + rng.normal(0, [2, 2, 0.02], S.shape), columns=("x_m", "y_m", "heading_rad")
    )
    p.add("points", P + rng.normal(0, 1.0, P.shape), points=points, columns=("x_m", "y_m"))
    for j in range(n_control):
        p.set_prior("points", sigma_ctrl, index=j, mean=P[j])
    return p, Bearings(st, pt, th, 1e-3)


def test_bearing_jacobians():
    S, P, st, pt, th = bearing_scene(0)
    blk = Bearings(st, pt, th, 1e-3)
    vals = {"stations": S, "points": P}
    assert check_jacobian(blk, vals, "stations") < 1e-7
    assert check_jacobian(blk, vals, "points") < 1e-7


def test_schur_equals_plain_solution():
    S, P, st, pt, th = bearing_scene(5)
    p1, blk = _bearing_params(S, P, st, pt, th, points=True)
    p2, _ = _bearing_params(S, P, st, pt, th, points=False)
    # both at the minimum, by different steps (the Schur path takes chord steps once settled):
    # equal to a small fraction of σ
    r1 = adjust(p1, blk, ftol=1e-14, keep_jacobian=True)
    r2 = adjust(p2, blk, ftol=1e-14)
    for name in ("points", "stations"):
        np.testing.assert_array_less(
            np.abs(r1.value(name) - r2.value(name)), 1e-4 * r2.sigma(name) + 1e-12
        )
    np.testing.assert_allclose(r1.sigma("stations"), r2.sigma("stations"), rtol=1e-6)
    # point covariance from the Schur back-substitution equals the plain inverse
    np.testing.assert_allclose(r1.sigma("points"), r2.sigma("points"), rtol=1e-6)
    assert r1.sigma0 == pytest.approx(r2.sigma0, rel=1e-9)


@pytest.mark.parametrize("seed", range(5))
def test_truth_within_3_sigma_and_sigma0_chi2(seed):
    S, P, st, pt, th = bearing_scene(seed)
    p, blk = _bearing_params(S, P, st, pt, th, seed=seed)
    res = adjust(p, blk, keep_jacobian=True)
    z_st = (res.value("stations") - S) / res.sigma("stations")
    z_pt = (res.value("points") - P) / res.sigma("points")
    # max over ~100 normal deviates: 4 sigma keeps the family-wise false alarm rate < 1 %
    assert np.max(np.abs(z_st)) < 4 and np.max(np.abs(z_pt)) < 4.5
    lo, hi = res.chi2_interval(alpha=0.001)
    assert lo < res.sigma0 < hi


def test_noise_free_recovers_truth():
    S, P, st, pt, th = bearing_scene(2, sigma_rad=0.0)
    p, blk = _bearing_params(S, P, st, pt, th)
    res = adjust(p, blk)
    np.testing.assert_allclose(res.value("points"), P, atol=1e-8)
    np.testing.assert_allclose(res.value("stations"), S, atol=1e-8)


def test_missing_datum_names_parameters():
    S, P, st, pt, th = bearing_scene(1)
    p, blk = _bearing_params(S, P, st, pt, th, n_control=0)
    with pytest.raises(DatumError) as ei:
        adjust(p, blk)
    assert "rank deficient" in str(ei.value) and ei.value.parameters
    assert any(n.startswith("stations[") for n in ei.value.parameters)
    ident = identifiability(p, blk)
    assert ident.n_unknowns - ident.rank == 4  # 2 translations, rotation, scale


def test_unobserved_parameter_is_named():
    t, y = line_data(0)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    p.add("unused", 1.0)
    with pytest.raises(DatumError, match="unused"):
        adjust(p, Line(t, y, 0.1))


def test_undetermined_point():
    S, P, st, pt, th = bearing_scene(4)
    keep = ~((pt == 7) & (st != st[pt == 7][0]))  # point 7 seen from one station only
    p, _ = _bearing_params(S, P, st, pt, th)
    with pytest.raises(DatumError, match="point"):
        adjust(p, Bearings(st[keep], pt[keep], th[keep], 1e-3))


def test_undetermined_point_dropped_and_named():
    """With drop_undetermined_points the point seen once is left out and named; the rest is
    estimated as without it (issue 42), and its observation is not counted as an outlier."""
    S, P, st, pt, th = bearing_scene(4)
    keep = ~((pt == 7) & (st != st[pt == 7][0]))  # point 7 seen from one station only
    p, _ = _bearing_params(S, P, st, pt, th)
    res = adjust(p, Bearings(st[keep], pt[keep], th[keep], 1e-3), drop_undetermined_points=True)
    assert res.converged and res.dropped_points == [7]
    assert not res.outliers(0).any()
    assert res.n_observations == int(keep.sum()) - 1
    # the same adjustment with point 7's observation removed and the point fixed
    q, _ = _bearing_params(S, P, st, pt, th)
    q.fix("points", index=[7])
    k2 = keep & (pt != 7)
    ref = adjust(q, Bearings(st[k2], pt[k2], th[k2], 1e-3))
    np.testing.assert_allclose(res.value("stations"), ref.value("stations"), rtol=1e-9, atol=1e-12)
    assert res.sigma0 == pytest.approx(ref.sigma0, rel=1e-9)


def test_fixed_entries_and_priors():
    S, P, st, pt, th = bearing_scene(6)
    p, blk = _bearing_params(S, P, st, pt, th, n_control=0)
    p.fix("points", index=[0, 1], value=P[:2])  # two fixed points give the datum
    res = adjust(p, blk, keep_jacobian=True)
    np.testing.assert_array_equal(res.value("points")[:2], P[:2])
    assert np.all(np.isnan(res.sigma("points")[:2]))
    assert np.all(np.abs(res.value("points")[2:] - P[2:]) < 5 * res.sigma("points")[2:])
    t, y = line_data(2)
    q = Parameters()
    q.add("ab", [0.0, 0.0])
    q.set_prior("ab", 1e-9, index=1, mean=0.25)
    assert adjust(q, Line(t, y, 0.1)).value("ab")[1] == pytest.approx(0.25, abs=1e-8)


def test_outliers_are_rejected():
    t, y = line_data(7, n=200)
    bad = np.array([5, 50, 120, 180])
    y[bad] += np.array([2.0, -1.5, 3.0, 1.2])
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    res = adjust(p, Line(t, y, 0.1), reject_k=4.0)
    assert set(np.flatnonzero(res.outliers("line"))) == set(bad)
    assert res.value("ab") == pytest.approx([1.5, 0.3], abs=0.05)


def test_bad_input_errors():
    t, y = line_data(0, n=5)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    y_nan = y.copy()
    y_nan[2] = np.nan
    with pytest.raises(InputError, match="non-finite"):
        adjust(p, Line(t, y_nan, 0.1))
    with pytest.raises(ObservationError, match="fewer observations"):
        adjust(p, Line(t[:1], y[:1], 0.1))
    p.fix("ab")
    with pytest.raises(ObservationError, match="fixed"):
        adjust(p, Line(t, y, 0.1))
    with pytest.raises(InputError, match="non-finite"):
        Parameters().add("x", [np.nan])
    with pytest.raises(InputError, match="σ"):
        Line(t, y, -1.0)
    with pytest.raises(InputError, match="no parameter named"):
        p["nope"]


def test_nonconvergence_is_reported():
    rng = np.random.default_rng(3)
    t = np.linspace(0, 4, 60)
    y = 5.0 * np.exp(-0.7 * t) + 0.02 * rng.standard_normal(t.size)
    p = Parameters()
    p.add("Ak", [1.0, 3.0])
    with pytest.raises(ConvergenceError) as ei:
        adjust(p, Exponential(t, y, 0.02), max_iter=2)
    assert ei.value.result is not None and not ei.value.result.converged
    res = adjust(p, Exponential(t, y, 0.02), max_iter=2, raise_on_failure=False)
    assert not res.converged


def test_report_and_html():
    t, y = line_data(0)
    p = Parameters()
    p.add("ab", [0.0, 0.0], columns=("a", "b"))
    res = adjust(p, Line(t, y, 0.1))
    txt = res.report()
    assert "ab[a]" in txt and "sigma0" in txt
    assert "<table" in res._repr_html_()
    assert list(res.to_frame().columns) == ["value", "sigma", "free", "prior_sigma"]


def test_progress_callback():
    t, y = line_data(0)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    seen = []
    adjust(p, Line(t, y, 0.1), progress=seen.append)
    assert seen and {"iteration", "cost", "lambda", "seconds"} <= set(seen[0])


@pytest.mark.parametrize("lam", [0.0, 1e-3])
def test_compiled_path_equals_generic_path(lam):
    """The row-compressed numba path forms the same reduced system as the scipy.sparse path."""
    from hsgeo.adjust.schur import _normal, _reduced, _step
    from hsgeo.adjust.system import _evaluate, _Layout

    S, P, st, pt, th = bearing_scene(8)
    p, blk = _bearing_params(S, P, st, pt, th, seed=8)
    p.fix("stations", index=(0, 2))  # a fixed entry: an empty slot in the compressed rows
    p.fix("points", index=(5, 1))  # and a fixed point coordinate
    lay = _Layout(p)
    sy = _evaluate(lay, [blk], [np.ones(blk.m, bool)], True)
    out = {}
    for compiled in (True, False):
        ne = _normal(lay, sy, SolverOptions(compiled=compiled))
        assert ne.compiled_schur == compiled
        S_, rhs, Vinv, _ = _reduced(lay, ne, lam)
        dc, dp = _step(lay, ne, lam)
        out[compiled] = (S_, rhs, dc, dp, ne.Ncc, ne.W.toarray())
    for a, b in zip(out[True], out[False], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-8 * np.max(np.abs(b)))
    r_slow = adjust(p, blk, ftol=1e-14, compiled=False, keep_jacobian=True)
    r_fast = adjust(p, blk, ftol=1e-14, compiled=True, keep_jacobian=True)
    # (the compiled path takes chord steps once settled: the same minimum by other steps)
    np.testing.assert_array_less(
        np.abs(r_fast.value("points") - r_slow.value("points")),
        1e-4 * np.nan_to_num(r_slow.sigma("points")) + 1e-12,
    )
    # (covariances at points 1e-4 σ apart: equal to ~1e-6)
    np.testing.assert_allclose(
        r_fast.covariance, r_slow.covariance, rtol=1e-6, atol=1e-6 * np.abs(r_slow.covariance).max()
    )
    np.testing.assert_allclose(r_fast.sigma("points"), r_slow.sigma("points"), rtol=1e-6)


def test_factored_indexed_expands_and_checks_shapes():
    from hsgeo.adjust import Indexed

    rng = np.random.default_rng(0)
    idx = np.array([[0, 1], [2, 3], [1, 2]])
    w = rng.random((3, 2))
    d = rng.random((3, 4))
    J = Indexed(idx, d, weights=w)
    assert J.factored and J.k == 4
    np.testing.assert_array_equal(J.expanded().d, w[:, :, None] * d[:, None, :])
    with pytest.raises(InputError, match="factored"):
        Indexed(idx, d, weights=w[:, :1])


def test_outliers_rejected_every_iteration_like_rounds():
    """Rejecting in every iteration (002 §3.4) finds the same gross errors as rounds."""
    rng = np.random.default_rng(4)
    t = np.linspace(0, 10, 200)
    y = 1.5 + 0.3 * t + rng.normal(0, 0.1, t.size)
    bad = rng.choice(t.size, 8, replace=False)
    y[bad] += rng.choice([-1, 1], 8) * rng.uniform(1.0, 3.0, 8)
    p = Parameters()
    p.add("ab", np.zeros(2))
    r_rounds = adjust(p, Line(t, y, 0.1), reject_k=4.0)
    r_each = adjust(p, Line(t, y, 0.1), reject_k=4.0, reject_every_iteration=True)
    assert set(np.flatnonzero(r_each.outliers(0))) == set(bad)
    np.testing.assert_array_equal(r_each.outliers(0), r_rounds.outliers(0))
    # both stop at the minimum to ftol (1e-10 of the cost): a difference ≪ σ, not to the last bit
    np.testing.assert_allclose(
        r_each.value("ab"), r_rounds.value("ab"), rtol=0, atol=1e-3 * np.min(r_rounds.sigma("ab"))
    )


def _dense_schur(Jc, jp, pidx, n_pts):
    """The reduced (Schur) matrix by its dense formula, point by point, with V_i + I as each
    point's block: (V⁻¹, S) = Σ_i Jcᵢᵀ Jcᵢ − Wᵢ V_i⁻¹ Wᵢᵀ, Wᵢ = Jcᵢᵀ jpᵢ."""
    p = jp.shape[1]
    V = np.zeros((n_pts, p, p))
    np.add.at(V, pidx, jp[:, :, None] * jp[:, None, :])
    Vinv = np.linalg.inv(V + np.eye(p))
    S_ref = np.zeros((Jc.shape[1], Jc.shape[1]))
    for i in range(n_pts):
        r = pidx == i
        W = Jc[r].T @ jp[r]
        S_ref += Jc[r].T @ Jc[r] - W @ Vinv[i] @ W.T
    return Vinv, S_ref


@pytest.mark.parametrize("consecutive", [True, False])
def test_reduced_kernel_equals_dense_schur(consecutive):
    """The compiled Schur kernel (tiles for the factored items) against the dense formula.

    Items start at columns with gaps between them (unused items) and, in the second case, a
    row's items are not on consecutive columns, so both expansion paths are exercised.
    """
    from hsgeo.adjust import _fast
    from hsgeo.adjust._fast import reduced_points
    from hsgeo.adjust.system import _RowJac

    rng = np.random.default_rng(3)
    kf, q, n_pts, p = 2, 3, 40, 3
    item_start = np.array([0, 2, 4, 8, 10, 14, 16])  # items 3 and 6 unused: gaps at 6 and 12
    slot_cols = np.array([18, 19, 20])
    n_c = 21
    rows_per_pt = rng.integers(2, 6, n_pts)
    pidx = np.repeat(np.arange(n_pts), rows_per_pt)
    M = pidx.size
    first = rng.integers(0, item_start.size - q + 1, M)
    items = (
        first[:, None] + np.arange(q)
        if consecutive
        else np.stack([rng.choice(item_start.size, q, replace=False) for _ in range(M)])
    )
    fcol = item_start[items].astype(np.int32)
    fw = rng.random((M, q))
    fd = rng.normal(size=(M, kf))
    cols = np.tile(slot_cols, (M, 1)).astype(np.int32)
    cols[rng.random(M) < 0.3, 1] = -1  # empty slots
    vals = rng.normal(size=cols.shape)
    jp = rng.normal(size=(M, p))
    J = _RowJac(cols, vals, n_c, fcol, fw, fd)
    Jc = J.tocsr().toarray()
    Vinv, S_ref = _dense_schur(Jc, jp, pidx, n_pts)
    order = np.arange(M, dtype=np.int64)
    ptr = np.concatenate([[0], np.cumsum(rows_per_pt)]).astype(np.int64)
    S = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c)
    np.testing.assert_allclose(S, S_ref, rtol=1e-12, atol=1e-12 * np.abs(S_ref).max())
    # a pattern kept from other rows (the first point: fewer item pairs and perhaps no empty
    # slots) no longer covers these rows: it is noticed and computed again, same S
    cache = types.SimpleNamespace(pattern=None)
    reduced_points(J.arrays, jp, order[: ptr[1]], ptr[:2], Vinv, n_c, cache=cache)
    stale = cache.pattern
    assert stale[3].size < _fast.schur_pattern(J.arrays, order, ptr, n_c)[3].size
    S2 = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c, cache=cache)
    np.testing.assert_array_equal(S2, S)
    assert cache.pattern is not stale
    # the kernel's output arrays kept in the cache: zeroed and written again, the same S
    cache = types.SimpleNamespace(pattern=None, kernel_out={})
    S3 = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c, cache=cache)
    kept = dict(cache.kernel_out)
    S4 = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c, cache=cache)
    assert kept and all(cache.kernel_out[k] is v for k, v in kept.items())
    np.testing.assert_array_equal(S3, S)
    np.testing.assert_array_equal(S4, S)


def test_reduced_kernel_slot_points_equal_dense_schur():
    """Points whose rows have slot columns only (frame cameras: ``_fast._slot_point``) against
    the dense formula, in one call with points that have factored groups too.

    The slot points see cameras in any order (their local columns sorted by the kernel), an
    observation's x and y rows share their columns, some rows list their columns out of order
    or share columns with the other observations of the point (intrinsics: not a camera's
    consecutive block), some slots are empty, one row has a column twice, and one point sees
    every camera (its local matrix outgrows the first one's).
    """
    from hsgeo.adjust._fast import reduced_points
    from hsgeo.adjust.system import _RowJac

    rng = np.random.default_rng(7)
    n_cam, k_cam, n_shared, kf, q, p = 9, 6, 2, 2, 2, 3
    shared = n_cam * k_cam + np.arange(n_shared)  # columns every observation touches
    item_start = shared[-1] + 1 + kf * np.arange(4)
    n_c = int(item_start[-1] + kf)
    cams = [rng.choice(n_cam, rng.integers(2, 5), replace=False) for _ in range(30)]
    cams.append(rng.permutation(n_cam))  # a point seen by every camera, in shuffled order
    rows_cols, pidx, groups = [], [], []
    for i, cs in enumerate(cams):
        for c in cs:
            cc = list(c * k_cam + np.arange(k_cam))
            if i % 3 == 0:
                cc += list(shared)
            if i % 4 == 1:
                cc = cc[::-1]  # columns out of order within the row
            for _ in range(2):  # x and y
                rows_cols.append(cc + [-1] * (k_cam + n_shared - len(cc)))
                pidx.append(i)
                groups.append(i % 5 == 2)  # some points also have factored groups
    cols = np.array(rows_cols, dtype=np.int32)
    M = cols.shape[0]
    cols[rng.random(M) < 0.1, 0] = -1  # empty slots
    cols[5, -1] = cols[5, 1]  # a column twice in a row (its entries add up)
    vals = rng.normal(size=cols.shape)
    groups = np.array(groups)
    fcol = np.where(groups[:, None], item_start[rng.integers(0, 4, (M, 1)) + [[0]]], -1)
    fcol = np.concatenate([fcol, np.full((M, q - 1), -1)], axis=1).astype(np.int32)
    fw = rng.random((M, q))
    fd = rng.normal(size=(M, kf))
    jp = rng.normal(size=(M, p))
    pidx = np.array(pidx)
    n_pts = len(cams)
    J = _RowJac(cols, vals, n_c, fcol, fw, fd)
    Jc = J.tocsr().toarray()
    Vinv, S_ref = _dense_schur(Jc, jp, pidx, n_pts)
    order = np.argsort(pidx, kind="stable").astype(np.int64)
    ptr = np.concatenate([[0], np.cumsum(np.bincount(pidx, minlength=n_pts))]).astype(np.int64)
    S = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c)
    np.testing.assert_allclose(S, S_ref, rtol=1e-12, atol=1e-12 * np.abs(S_ref).max())
    # the points visited in another order: the same matrix to rounding
    pt_order = rng.permutation(n_pts).astype(np.int64)
    S2 = reduced_points(J.arrays, jp, order, ptr, Vinv, n_c, pt_order)
    np.testing.assert_allclose(S2, S, rtol=1e-12, atol=1e-12 * np.abs(S_ref).max())


def test_spd_inverse_against_numpy_and_singular():
    from hsgeo.adjust.schur import _spd_inverse

    rng = np.random.default_rng(1)
    A = rng.normal(size=(30, 12))
    N = A.T @ A
    np.testing.assert_allclose(_spd_inverse(N, 1e-11), np.linalg.inv(N), rtol=1e-10, atol=1e-12)
    # columns in very different units (1e6 apart) invert as well as in the same units
    D = np.diag(10.0 ** np.arange(-3, 3, 0.5))
    np.testing.assert_allclose(_spd_inverse(D @ N @ D, 1e-11) @ (D @ N @ D), np.eye(12), atol=1e-9)
    B = A.copy()
    B[:, 5] = B[:, 2] + B[:, 7]  # rank 11, every diagonal entry positive
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        _spd_inverse(B.T @ B, 1e-11)
    N[:, 3] = N[3, :] = 0.0
    with pytest.raises(np.linalg.LinAlgError, match="zero or negative diagonal"):
        _spd_inverse(N, 1e-11)


def test_chord_steps_end_with_the_covariance_of_the_final_point(monkeypatch):
    """Chord steps reuse an earlier reduced matrix; the result's must be that of its estimate."""
    from hsgeo.adjust import schur
    from hsgeo.adjust.system import _evaluate, _Layout

    S, P, st, pt, th = bearing_scene(8)
    p, blk = _bearing_params(S, P, st, pt, th, seed=8)
    chords = []
    orig = schur._reduced

    def spy(layout, ne, lam):
        chords.append(ne.S_chord is not None)
        return orig(layout, ne, lam)

    monkeypatch.setattr(schur, "_reduced", spy)  # (a probe: the solver's settings are options)
    r = adjust(p, blk)
    monkeypatch.undo()
    assert any(chords), "no chord step was taken: the test does not exercise them"
    lay = _Layout(r.params)
    ne = schur._normal(lay, _evaluate(lay, [blk], [np.ones(blk.m, bool)], True), SolverOptions())
    S_final = schur._reduced(lay, ne, 0.0)[0]
    np.testing.assert_allclose(
        r.covariance,
        r.sigma0**2 * np.linalg.inv(S_final),
        rtol=1e-9,
        atol=1e-12 * np.abs(r.covariance).max(),
    )


def test_chord_steps_from_the_first_iterate_still_converge():
    """Chord steps from far from the minimum (forced: every iterate counts as settled): failed
    ones fall back to the matrix of the current point, and the adjustment reaches the same
    minimum."""
    S, P, st, pt, th = bearing_scene(8)
    p, blk = _bearing_params(S, P, st, pt, th, seed=8)
    ref = adjust(p, blk, ftol=1e-14, keep_jacobian=True)
    r = adjust(p, blk, ftol=1e-14, settled=np.inf)
    assert r.converged
    for name in ("points", "stations"):
        np.testing.assert_array_less(
            np.abs(r.value(name) - ref.value(name)), 1e-4 * np.nan_to_num(ref.sigma(name)) + 1e-12
        )


@pytest.mark.parametrize("each", [False, True])
def test_gross_errors_rejected_without_swamping_their_points(each):
    """A gross error drags its point: its point's other rays get large residuals too. Only the
    largest standardised residual per point is rejected per test, so the gross errors go and
    the good rays of their points stay (five bearings per 2-D point: a redundancy of 3)."""
    S, P, st, pt, th = bearing_scene(11, n_points=60, coverage=5)
    rng = np.random.default_rng(2)
    # one gross error on each of 6 points (not the control points)
    gross = np.array(
        [
            rng.choice(np.flatnonzero(pt == j))
            for j in rng.choice(np.arange(2, 60), 6, replace=False)
        ]
    )
    th = th.copy()
    th[gross] += rng.choice([-1, 1], gross.size) * rng.uniform(0.02, 0.05, gross.size)
    p, blk = _bearing_params(S, P, st, pt, th, n_control=2, seed=11)
    # the swamping is real: with the gross errors in, other rays of their points exceed 5 σ
    r0 = adjust(p, blk)
    z = np.abs(r0.residuals(0)) / 1e-3 / (1.4826 * np.median(np.abs(r0.residuals(0)) / 1e-3))
    others = np.isin(pt, pt[gross]) & ~np.isin(np.arange(pt.size), gross)
    assert (z[others] > 5).sum() >= 3  # rejecting every ray above 5 σ would take these too
    r = adjust(p, blk, reject_k=5.0, reject_every_iteration=each)
    rejected = set(np.flatnonzero(r.outliers(0)).tolist())
    assert set(gross.tolist()) <= rejected
    # (a ray of a near-opposite pair of stations can carry the same error as its partner: the
    # geometry may leave one such pair undecided)
    assert len(rejected - set(gross.tolist())) <= 1


def test_point_leverage_kernel_equals_einsum():
    from hsgeo.adjust._fast import point_leverage

    rng = np.random.default_rng(5)
    jp = rng.normal(size=(50, 3))
    pidx = rng.integers(-1, 10, 50)
    A = rng.normal(size=(10, 3, 3))
    Vinv = A @ A.transpose(0, 2, 1)
    ref = np.where(pidx >= 0, np.einsum("ij,ijk,ik->i", jp, Vinv[np.maximum(pidx, 0)], jp), 0.0)
    np.testing.assert_allclose(point_leverage(jp, pidx, Vinv), ref, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("ftol", 0.0, "ftol must be a finite positive"),
        ("ftol", float("nan"), "ftol must be a finite positive"),
        ("max_iter", -1, "max_iter must be a non-negative integer"),
        ("max_iter", 2.5, "max_iter must be a non-negative integer"),
        ("reject_k", -3.0, "reject_k must be None"),
        ("settled", -0.1, "settled must be a number"),
        ("compiled", "yes", "compiled must be True or False"),
        ("lambda0", 1e20, "exceeds lambda_max"),
    ],
)
def test_solver_options_validate(field, value, match):
    with pytest.raises(InputError, match=match):
        SolverOptions(**{field: value})
    t, y = line_data(0)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    with pytest.raises(InputError, match=match):  # the same check through adjust's keywords
        adjust(p, Line(t, y, 0.1), **{field: value})


def test_unknown_solver_option_names_the_closest():
    t, y = line_data(0)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    with pytest.raises(InputError, match="'reject_kk'. Did you mean 'reject_k'") as ei:
        adjust(p, Line(t, y, 0.1), reject_kk=4.0)
    assert "max_iter" in str(ei.value)  # the valid names are listed
    with pytest.raises(InputError, match="must be a SolverOptions"):
        adjust(p, Line(t, y, 0.1), {"ftol": 1e-8})


def test_options_and_keywords_give_the_same_result():
    t, y = line_data(3)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    opts = SolverOptions(ftol=1e-6, max_iter=7)
    a = adjust(p, Line(t, y, 0.1), opts)
    b = adjust(p, Line(t, y, 0.1), ftol=1e-6, max_iter=7)
    c = adjust(p, Line(t, y, 0.1), SolverOptions(ftol=1e-3), ftol=1e-6, max_iter=7)
    assert a.cost_history == b.cost_history == c.cost_history
    np.testing.assert_array_equal(a.value("ab"), b.value("ab"))
    assert SolverOptions().replace(ftol=1e-6, max_iter=7) == opts
    with pytest.raises(AttributeError):
        opts.ftol = 1.0  # frozen


def test_point_covariance_needs_the_kept_jacobian():
    S, P, st, pt, th = bearing_scene(3)
    p, blk = _bearing_params(S, P, st, pt, th, seed=3)
    r = adjust(p, blk)
    assert np.isfinite(r.sigma("stations")).any()  # non-point σ without the Jacobian
    with pytest.raises(InputError, match="keep_jacobian=True"):
        r.point_covariance()
    kept = adjust(p, blk, keep_jacobian=True)
    np.testing.assert_array_equal(kept.covariance, r.covariance)
    assert kept.point_covariance().shape == (P.shape[0], 2, 2)


def test_residual_block_roles_are_renamed_by_blocks():
    """One convention: ``blocks`` maps a role to a parameter-block name (class defaults)."""
    t, y = line_data(5)
    p = Parameters()
    p.add("ab", [0.0, 0.0])
    q = Parameters()
    q.add("line_coefficients", [0.0, 0.0])
    assert dict(Line(t, y, 0.1).blocks) == {"ab": "ab"}
    blk = Line(t, y, 0.1, blocks={"ab": "line_coefficients"})
    assert blk.blocks["ab"] == "line_coefficients"
    ref, got = adjust(p, Line(t, y, 0.1)), adjust(q, blk)
    np.testing.assert_array_equal(got.value("line_coefficients"), ref.value("ab"))
    with pytest.raises(InputError, match="no parameter role 'a_b'.*did you mean 'ab'"):
        Line(t, y, 0.1, blocks={"a_b": "x"})
    with pytest.raises(InputError, match="non-empty string"):
        Line(t, y, 0.1, blocks={"ab": ""})
    with pytest.raises(TypeError):
        blk.blocks["ab"] = "other"  # read-only


def test_sensor_blocks_declare_their_roles():
    from hsgeo.sensors.frame import FrameOpenCV, FramePhotogrammetric
    from hsgeo.sensors.line import BoresightGCP
    from hsgeo.sensors.line1d import LineObservations
    from hsgeo.sensors.pushbroom import BLOCK_NAMES, PushbroomLines
    from hsgeo.sensors.rikola import JointCentroids, TargetCentroids

    assert set(FrameOpenCV.BLOCKS) == {"poses", "points", "intrinsics", "distortion"}
    assert FramePhotogrammetric.BLOCKS["distortion"] == "distortion_mm"
    assert PushbroomLines.BLOCKS == BLOCK_NAMES
    assert set(JointCentroids.BLOCKS) == {
        "poses",
        "gap",
        "df",
        "pp",
        "distortion",
        "rotation",
        "offset",
        "drift",
    }
    assert TargetCentroids.BLOCKS["interior"] == "interior"
    assert LineObservations.BLOCKS["xy"] == "xy_m"
    assert BoresightGCP.BLOCKS == {"boresight": "boresight"}
    rng = np.random.default_rng(0)
    view = np.zeros(4, int)
    X = rng.normal(size=(4, 3)) + [0, 0, 5]
    blk = FrameOpenCV(view, rng.normal(size=(4, 2)), 1.0, X=X, blocks={"intrinsics": "K_band2"})
    vals = {
        "poses": np.zeros((1, 6)),
        "K_band2": np.array([500.0, 500.0, 10.0, 10.0]),
        "distortion": np.zeros(5),
    }
    r, jac = blk.evaluate(vals, True)
    assert set(jac) == {"K_band2", "distortion", "poses"} and r.shape == (8,)


def _square_pixel_problem(seed=3, n=30, n_views=4):
    from hsgeo.sensors.frame import project_opencv

    rng = np.random.default_rng(seed)
    X, poses, view, Xall = frame_scene(rng, n, n_views)
    intr = np.array([800.0, 800.0, 320.0, 240.0])
    dist = np.array([-0.2, 0.1, 0.0, 0.0, 0.0])
    uv = project_opencv(poses, view, Xall, intr, dist) + 0.3 * rng.standard_normal((view.size, 2))
    p = Parameters()
    p.add("intrinsics", intr + [5.0, 5.0, 0.0, 0.0])
    p.add("distortion", np.zeros(5))
    p.add("poses", poses + 1e-3)
    p.fix("poses", index=0)
    p.fix("distortion", index=[2, 3, 4])
    return p, view, uv, Xall


def _square_pixel_block(view, uv, sigma, X):
    """Reference: the square-pixel model written out, fx used for both axes (fy unused)."""
    from hsgeo.sensors.frame import FrameOpenCV

    class SquarePixels(FrameOpenCV):
        def evaluate(self, values, jacobian):
            vals = dict(values)
            intr = np.array(vals["intrinsics"], dtype=float)
            intr[1] = intr[0]
            vals["intrinsics"] = intr
            r, jac = super().evaluate(vals, jacobian)
            if jacobian:  # d/dfx gets the y rows' fy derivative; fy itself has none
                J = jac["intrinsics"].copy()
                J[:, 0] += J[:, 1]
                J[:, 1] = 0.0
                jac = {**jac, "intrinsics": J}
            return r, jac

    return SquarePixels(view, uv, sigma, X=X)


def test_tie_equals_square_pixel_model():
    """fy tied to fx (one column) gives the fit of the model that uses fx for both axes, and
    reports fy = fx with fx's σ̂ (no patching of the result)."""
    from hsgeo.sensors.frame import FrameOpenCV

    p, view, uv, X = _square_pixel_problem()
    old = p.copy()
    old.fix("intrinsics", index=1)
    r_old = adjust(old, _square_pixel_block(view, uv, 0.3, X))
    p.tie("intrinsics", index=1, to=("intrinsics", 0))
    r_tie = adjust(p, FrameOpenCV(view, uv, 0.3, X=X))
    fx, fy = r_tie.value("intrinsics")[:2]
    assert fx == fy
    np.testing.assert_allclose(
        r_tie.value("intrinsics")[[0, 2, 3]], r_old.value("intrinsics")[[0, 2, 3]], rtol=1e-9
    )
    for name in ("distortion", "poses"):
        np.testing.assert_allclose(r_tie.value(name), r_old.value(name), rtol=1e-9, atol=1e-12)
    s_tie, s_old = r_tie.sigma("intrinsics"), r_old.sigma("intrinsics")
    assert np.isnan(s_old[1]) and s_tie[1] == s_tie[0]
    np.testing.assert_allclose(s_tie[[0, 2, 3]], s_old[[0, 2, 3]], rtol=1e-9)
    np.testing.assert_allclose(
        r_tie.covariance, r_old.covariance, rtol=1e-9, atol=1e-12 * np.abs(r_old.covariance).max()
    )
    assert r_tie.n_unknowns == r_old.n_unknowns and r_tie.sigma0 == pytest.approx(
        r_old.sigma0, rel=1e-12
    )
    assert r_tie.labels == r_old.labels and "intrinsics[1]" not in r_tie.labels
    # the input is untouched apart from the tie itself
    assert p.ties == {("intrinsics", 1): ("intrinsics", 0)}


def test_tie_checks():
    p = Parameters()
    p.add("a", [1.0, 2.0, 3.0])
    p.add("pts", np.zeros((2, 2)), points=True)
    with pytest.raises(InputError, match="points block"):
        p.tie("pts", index=(0, 1), to=("pts", (0, 0)))
    with pytest.raises(InputError, match="selects 2 entries"):
        p.tie("a", index=slice(0, 2), to=("a", 2))
    with pytest.raises(InputError, match="itself"):
        p.tie("a", index=1, to=("a", 1))
    p.fix("a", index=2)
    with pytest.raises(InputError, match="is fixed"):
        p.tie("a", index=1, to=("a", 2))
    p.tie("a", index=1, to=("a", 0))
    assert p.value("a")[1] == 1.0 and p.n_free == 3 + 4 - 1 - 1  # a[2] fixed, a[1] tied
    with pytest.raises(InputError, match="itself tied"):
        p.tie("a", index=2, to=("a", 1))
    with pytest.raises(InputError, match="cannot be tied in turn"):
        p.tie("a", index=0, to=("a", 2))


def test_adjust_modules_import_without_cycles():
    """The engine's modules form a layered graph (imports inside functions included), and the
    result depends on no solver internals."""
    import ast
    from pathlib import Path

    import hsgeo.adjust

    pkg = Path(hsgeo.adjust.__file__).parent
    graph = {}
    for f in pkg.glob("*.py"):
        deps = set()
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module:
                mods = [node.module]
            elif isinstance(node, ast.Import):
                mods = [a.name for a in node.names]
            else:
                continue
            deps |= {
                m.split(".")[2] for m in mods if m.startswith("hsgeo.adjust.") and m.count(".") >= 2
            }
        graph[f.stem] = deps - {f.stem}
    assert graph["result"] <= {"parameters", "threads"}, graph["result"]  # threads: a leaf
    assert "engine" not in graph
    state = {}

    def visit(m, path):
        if state.get(m) == "done":
            return
        assert state.get(m) != "open", f"import cycle: {' -> '.join(path + [m])}"
        state[m] = "open"
        for d in graph.get(m, ()):
            visit(d, path + [m])
        state[m] = "done"

    for m in graph:
        visit(m, [])


def test_parameters_docstring_examples():
    import doctest

    import hsgeo.adjust.parameters as mod

    assert doctest.testmod(mod).failed == 0


def test_points_held_to_save_a_refused_step(monkeypatch):
    """One point started next to a station, where its bearing changes fast: Gauss–Newton
    steps throw it off and are refused because of it alone. With ``hold_points`` such a step
    is retried with that point held, and accepted; the minimum is the same as without. (Here
    the stations are fixed, so the points are independent and the damping that the refusals
    raise slows nothing else down: the hold saves no iterations. Its use is on blocks where
    one point's refusals damp every other unknown, see bench/results/pushbroom_scaling.json.)
    """
    from hsgeo.adjust import solver as SV

    S, P, st, pt, th = bearing_scene(0, n_stations=6, n_points=40, coverage=4)
    P0 = P + np.random.default_rng(1).normal(0, 0.5, P.shape)
    P0[7] = S[st[pt == 7][0], :2] + np.array([-3.0, -1.0])
    held = []
    orig = SV._Solve._hold_points

    counts = []

    def spy(self, *a, **kw):
        out = orig(self, *a, **kw)
        held.append(out is not None)
        counts.append(max(self.hold_count.values(), default=0))
        return out

    monkeypatch.setattr(SV._Solve, "_hold_points", spy)
    res = {}
    for hold in (True, False):
        p = Parameters()
        p.add("stations", S.copy())
        p.add("points", P0.copy(), points=True)
        p.fix("stations")
        res[hold] = adjust(p, Bearings(st, pt, th, 1e-3), hold_points=hold)
    assert any(held)  # (only called with hold_points=True)
    assert max(counts) <= SolverOptions().hold_max == 3
    # with the cap at one hold per point the same minimum is reached too
    counts.clear()
    p = Parameters()
    p.add("stations", S.copy())
    p.add("points", P0.copy(), points=True)
    p.fix("stations")
    capped = adjust(p, Bearings(st, pt, th, 1e-3), hold_max=1)
    assert counts and max(counts) == 1
    np.testing.assert_allclose(capped.cost_history[-1], res[False].cost_history[-1], rtol=1e-9)
    np.testing.assert_allclose(res[True].cost_history[-1], res[False].cost_history[-1], rtol=1e-9)
    # (to the convergence tolerance: 5e-6 m, against a point σ of about 0.1 m)
    np.testing.assert_allclose(res[True].value("points"), res[False].value("points"), atol=1e-4)
