"""Normal equations and the Schur-reduced Levenberg–Marquardt step.

With ``N = [[N_cc, W], [Wᵀ, V]]`` and ``V`` block diagonal (one ``p × p`` block per point), the
reduced system ``S Δc = −(g_c − W V⁻¹ g_p)`` with ``S = N_cc − W V⁻¹ Wᵀ`` is solved densely
(Cholesky) and the points follow as ``Δp = −V⁻¹ (g_p + Wᵀ Δc)``. Damping is Marquardt's
``N + λ diag(N)``; the point blocks are damped only above ``lambda_points_min``
(:class:`~hsgeo.adjust.options.SolverOptions`), so one reduced matrix per linearisation point
serves the datum check, the damped retries and the covariance.

Two paths form the same equations: the compiled row-compressed kernels
(:mod:`hsgeo.adjust._fast`, ``SolverOptions.compiled``) and a generic scipy.sparse path;
``tests/test_engine.py`` compares them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.linalg import lapack

from hsgeo.adjust.options import SolverOptions
from hsgeo.adjust.system import _Clock, _Layout, _System

__all__: list[str] = ["NULL_SHARE"]


@dataclass
class _Normal:
    _Ncc: np.ndarray | None  # (n_c, n_c) dense (on the compiled path: built on request)
    gc: np.ndarray  # (n_c,)
    V: np.ndarray | None  # (n_pts, p, p)
    gp: np.ndarray | None  # (n_pts, p)
    _W: sp.csr_matrix | None = None  # (n_c, n_pts * p), generic path (built on request)
    sy: _System | None = None  # the rows, for the compiled path
    order: np.ndarray | None = None  # rows sorted by point
    ptr: np.ndarray | None = None  # rows of point i: order[ptr[i]:ptr[i + 1]]
    n_pts: int = 0
    pt_order: np.ndarray | None = None  # order in which the kernel visits the points
    Ncc_free: np.ndarray | None = None  # J_cᵀ J_c of the rows without a point (compiled path)
    diag_cc: np.ndarray | None = None  # diag(N_cc)
    reduced0: tuple | None = None  # (S, rhs, V⁻¹) with undamped point blocks, see _reduced
    S_chord: np.ndarray | None = None  # a reduced matrix formed at an earlier point, see adjust
    D_c: np.ndarray | None = None  # damping diagonal of the non-point unknowns (None: diag N_cc)
    options: SolverOptions = SolverOptions()  # compiled path, lambda_points_min
    orders: _OrderCache | None = None  # keeps the Schur kernel's pattern between formations
    clock: _Clock | None = None  # seconds of the formation and the solve (see _step)

    @property
    def compiled_schur(self) -> bool:
        """The reduced matrix is formed point by point by the compiled kernel."""
        return self.V is not None and self.sy is not None and self._W is None and self._Ncc is None

    def exact(self) -> None:
        """Drop a chord matrix: the next reduced system is formed at this point."""
        if self.S_chord is not None:
            self.S_chord = None
            self.reduced0 = None

    def damping_diagonal(self) -> np.ndarray:
        """The diagonal λ scales for the non-point unknowns: ``D_c``, else ``diag(N_cc)``."""
        if self.D_c is not None:
            return self.D_c
        return self.diag_cc if self.diag_cc is not None else np.diag(self.Ncc)

    @property
    def Ncc(self) -> np.ndarray:
        """``J_cᵀ J_c`` (dense)."""
        if self._Ncc is None:
            from hsgeo.adjust._fast import normal_cc

            self._Ncc = normal_cc(self.sy.Jrc.arrays, self.sy.Jrc.n_cols)
        return self._Ncc

    @property
    def W(self) -> sp.csr_matrix | None:
        """``J_cᵀ J_p`` as scipy.sparse (built on first use on the compiled path)."""
        if self._W is None and self.V is not None:
            self._W = _W_sparse(self.sy, self.n_pts)
        return self._W

    def Wt_dot(self, dc: np.ndarray) -> np.ndarray:
        """``Wᵀ dc`` as ``(n_pts, p)``."""
        if self._W is not None or self.sy is None:
            return (self.W.T @ dc).reshape(self.n_pts, -1)
        from hsgeo.adjust._fast import scatter_points

        return scatter_points(self.sy.Jp, self.sy.pidx, self.sy.Jrc.matvec(dc), self.n_pts)

    def W_dot(self, y: np.ndarray) -> np.ndarray:
        """``W y`` for ``y`` of shape ``(n_pts, p)``."""
        if self._W is not None or self.sy is None:
            return self.W @ y.ravel()
        from hsgeo.adjust._fast import point_rows_dot

        return self.sy.Jrc.rmatvec(
            point_rows_dot(self.sy.Jp, self.sy.pidx, np.ascontiguousarray(y))
        )


def _W_sparse(sy: _System, n_pts: int) -> sp.csr_matrix:
    p = sy.Jp.shape[1]
    rows = np.flatnonzero(sy.pidx >= 0)
    pi = sy.pidx[rows]
    jp = sy.Jp[rows]
    Jp_sp = sp.csr_matrix(
        (jp.ravel(), (np.repeat(rows, p), (pi[:, None] * p + np.arange(p)).ravel())),
        shape=(sy.r.size, n_pts * p),
    )
    return (sy.Jc.T @ Jp_sp).tocsr()


class _OrderCache:
    """The processing orders of the last sparsity structure seen by :func:`_normal`.

    One per solve (or per :func:`~hsgeo.adjust.identifiability` call): the rows and points of
    consecutive iterations are the same, so their orders are computed once.
    """

    def __init__(self) -> None:
        self.key: tuple | None = None
        self.value: tuple | None = None
        self.pattern: tuple | None = None  # _fast.schur_pattern (on first use, see get)
        #: the reduced-matrix kernel's output arrays, reused by each formation (_fast._zeros)
        self.kernel_out: dict = {}

    def get(self, layout: _Layout, sy: _System):
        """``(order, ptr, row_order, pt_order)`` for ``sy``, computed on a change of structure."""
        from hsgeo.adjust._fast import locality_orders, rows_by_point

        key = self.key
        if (
            key is not None
            and key[0] == layout.n_c
            and key[1] == layout.n_pts
            and key[3] == sy.Jrc.cols.shape
            and np.array_equal(key[2], sy.pidx)
        ):
            # same rows and points as the previous iteration: reuse the processing orders
            # (order and ptr depend only on pidx; row_order is a permutation of the rows that
            # only affects speed, so a changed column pattern cannot make it wrong)
            return self.value
        order = ptr = None
        if layout.pblock is not None:
            order, ptr = rows_by_point(np.asarray(sy.pidx, dtype=np.int64), layout.n_pts)
        # the rows without a point (priors) form N_cc directly; the others go through the
        # Schur kernel point by point
        rows_np = np.flatnonzero(sy.pidx < 0) if layout.pblock is not None else None
        row_order, pt_order = locality_orders(sy.Jrc, layout.n_c, order, ptr, rows_np)
        self.key = (layout.n_c, layout.n_pts, sy.pidx.copy(), sy.Jrc.cols.shape)
        self.value = (order, ptr, row_order, pt_order)
        # the Schur pattern is kept: it is in columns, not rows, and the rows left after an
        # outlier rejection couple a subset of what they coupled before (the kernel notices
        # anything outside it, and the pattern is then computed again)
        return self.value


def _normal(
    layout: _Layout,
    sy: _System,
    options: SolverOptions,
    orders: _OrderCache | None = None,
    clock: _Clock | None = None,
) -> _Normal:
    """The normal equations at ``sy`` (compiled or generic path, see ``options.compiled``).

    ``orders`` carries the processing orders from one call to the next (a new cache if None);
    ``clock`` takes the seconds (``formation``) and goes with the result to :func:`_step`.
    """
    clock = clock or _Clock()
    t0 = time.perf_counter()
    ne = _normal_equations(layout, sy, options, orders)
    ne.clock = clock
    clock.add("formation", t0)
    return ne


def _normal_equations(layout, sy, options, orders) -> _Normal:
    """:func:`_normal` without the clock."""
    order = ptr = pt_order = None
    compiled = options.compiled
    if compiled:
        from hsgeo.adjust._fast import normal_cc

        orders = orders or _OrderCache()
        order, ptr, row_order, pt_order = orders.get(layout, sy)
        Jrc = sy.Jrc
        gc, diag_cc = sy.gradient_diag()  # (accumulated by the fused blocks' pass)
        if layout.pblock is None:
            Ncc = normal_cc(Jrc.arrays, layout.n_c, row_order)
            return _Normal(Ncc, gc, None, None, diag_cc=diag_cc, options=options)
        Ncc_free = normal_cc(Jrc.arrays, layout.n_c, row_order)
        Ncc = None
    else:
        Jc = sy.Jc
        Ncc = (Jc.T @ Jc).toarray() if layout.n_c else np.zeros((0, 0))
        gc = Jc.T @ sy.r
    if layout.pblock is None:
        return _Normal(Ncc, gc, None, None, options=options)
    n_pts, p = layout.n_pts, layout.p
    if compiled:
        from hsgeo.adjust._fast import point_normals

        V, gp = point_normals(order, ptr, sy.Jp, sy.r)
    else:
        rows = np.flatnonzero(sy.pidx >= 0)
        pi = sy.pidx[rows]
        jp = sy.Jp[rows]
        # V_i = Σ_rows jpᵀ jp, g_p,i = Σ jpᵀ r  (sparse aggregation instead of a Python loop)
        agg = sp.csr_matrix(
            (np.ones(rows.size), (pi, np.arange(rows.size))), shape=(n_pts, rows.size)
        )
        V = (agg @ (jp[:, :, None] * jp[:, None, :]).reshape(rows.size, p * p)).reshape(n_pts, p, p)
        gp = agg @ (jp * sy.r[rows, None])
    # fixed point entries: unit diagonal, zero gradient -> zero update
    # (their Jacobian columns were zeroed in _evaluate, so V has zero rows/columns there)
    fixed = ~layout.pfree
    ii = np.nonzero(fixed)
    V[ii[0], ii[1], ii[1]] = 1.0
    gp[fixed] = 0.0
    if not compiled:
        return _Normal(Ncc, gc, V, gp, _W_sparse(sy, n_pts), n_pts=n_pts, options=options)
    return _Normal(
        Ncc,
        gc,
        V,
        gp,
        None,
        sy,
        order,
        ptr,
        n_pts,
        pt_order,
        Ncc_free,
        diag_cc,
        options=options,
        orders=orders,
    )


def _damped(A: np.ndarray, lam: float, D: np.ndarray | None = None) -> np.ndarray:
    """A + λ·diag(A) on the last two axes (Marquardt), with a floor on zero diagonals;
    with ``D``, A + λ·D instead (see ``SolverOptions.damping_diagonal``).
    """
    if lam == 0.0:
        return A
    A = A.copy()
    d = np.diagonal(A, axis1=-2, axis2=-1) if D is None else D
    floor = 1e-12 * max(float(np.max(d)) if d.size else 1.0, 1e-300)
    idx = np.arange(A.shape[-1])
    A[..., idx, idx] += lam * np.maximum(d, floor)
    return A


def _inv_blocks(Vd: np.ndarray, compiled: bool = True, rtol: float = 1e-11) -> np.ndarray:
    """The inverses of the blocks ``Vd[i]``; a pseudo-inverse for the singular ones.

    A block is singular when the smallest eigenvalue of its unit-diagonal scaling is below
    ``rtol`` times the largest (the datum check's rule, ``SolverOptions.rank_rtol``): a point
    whose rays have become parallel, or whose observations were all rejected. Its
    pseudo-inverse ``D⁻¹ (D⁻¹ V D⁻¹)⁺ D⁻¹`` drops the direction its observations cannot see,
    which no other unknown sees either (``W u = J_cᵀ J_p u = 0``), so the reduced matrix stays
    positive semi-definite instead of taking the rounding noise of an inverse of a singular
    block (an indefinite reduced matrix at the solution of a 4-camera BAL subset).
    """
    if compiled and Vd.ndim == 3 and Vd.shape[1:] == (3, 3):
        from hsgeo.adjust._fast import inv3

        out, ok = inv3(np.ascontiguousarray(Vd), rtol)
    else:
        dv = np.diagonal(Vd, axis1=-2, axis2=-1)
        pos = np.all(dv > 0, axis=-1)
        sq = np.sqrt(np.where(dv > 0, dv, 1.0))
        p = Vd.shape[-1]
        # unit diagonal: det ≥ rtol·p^p proves λ_min ≥ rtol·λ_max (as the datum check)
        ok = pos & (np.linalg.det(Vd / sq[..., :, None] / sq[..., None, :]) >= rtol * p**p)
        out = np.empty_like(Vd)
        out[ok] = np.linalg.inv(Vd[ok])
    if not ok.all():
        out[~ok] = _scaled_pinv(Vd[~ok], rtol)
    return out


def _scaled_pinv(V: np.ndarray, rtol: float) -> np.ndarray:
    """``D⁻¹ (D⁻¹ V D⁻¹)⁺ D⁻¹`` of symmetric blocks, eigenvalues below ``rtol·λ_max`` dropped."""
    dv = np.diagonal(V, axis1=-2, axis2=-1)
    sq = np.sqrt(np.where(dv > 0, dv, 1.0))
    Vs = V / sq[..., :, None] / sq[..., None, :]
    Vs = np.where((dv > 0)[..., :, None] & (dv > 0)[..., None, :], Vs, 0.0)
    ev, U = np.linalg.eigh(Vs)
    keep = ev > rtol * np.maximum(ev[..., -1:], 1e-300)
    inv_ev = np.where(keep, 1.0 / np.where(keep, ev, 1.0), 0.0)
    P = np.einsum("...ik,...k,...jk->...ij", U, inv_ev, U)
    return P / sq[..., :, None] / sq[..., None, :]


def _block_diag(Vinv: np.ndarray) -> sp.csr_matrix:
    n, p, _ = Vinv.shape
    rows = np.repeat(np.arange(n * p), p)
    cols = (np.arange(n)[:, None, None] * p + np.zeros((1, p, 1), dtype=int) + np.arange(p)).ravel()
    return sp.csr_matrix((Vinv.ravel(), (rows, cols)), shape=(n * p, n * p))


def _lambda_points(lam: float, lambda_points_min: float) -> float:
    """The damping of the point blocks: none below ``lambda_points_min`` (see _reduced)."""
    return lam if lam > lambda_points_min else 0.0


def _reduced(layout: _Layout, ne: _Normal, lam: float):
    """S, rhs and the pieces for back-substitution, at damping λ.

    Marquardt damping ``λ diag(N)`` is added to the reduced system; the points' blocks ``V``
    are damped too only when ``λ > lambda_points_min`` (at smaller λ, damping a 3 × 3 point
    block by a factor ``1 + λ`` changes nothing but the cost of re-forming ``S``).
    """
    rhs = ne.gc.copy()
    lam_p = _lambda_points(lam, ne.options.lambda_points_min)
    if ne.compiled_schur:
        # compiled path: S = N_cc − Σ W_i V_i⁻¹ W_iᵀ accumulated point by point from the rows
        # grouped by point; neither W nor the full N_cc is formed
        from hsgeo.adjust._fast import reduced_points

        cached = ne.reduced0 if lam_p == 0.0 else None
        if cached is None:
            Vinv = _inv_blocks(_damped(ne.V, lam_p), ne.options.compiled, ne.options.rank_rtol)
            sy = ne.sy
            if ne.S_chord is not None and lam_p == 0.0:
                S0 = ne.S_chord  # a chord step: the matrix of an earlier point (see adjust)
            else:
                S0 = ne.Ncc_free + reduced_points(
                    sy.Jrc.arrays,
                    sy.Jp,
                    ne.order,
                    ne.ptr,
                    Vinv,
                    layout.n_c,
                    ne.pt_order,
                    ne.orders,
                )
            r0 = rhs - ne.W_dot(np.einsum("nij,nj->ni", Vinv, ne.gp)) if layout.n_c else rhs
            if lam_p == 0.0:  # keep the undamped one (datum check, steps, covariance)
                ne.reduced0 = (S0, r0, Vinv)
        else:
            S0, r0, Vinv = cached
        S = S0.copy()
        rhs = r0.copy()
        if lam != 0.0 and layout.n_c:
            d = ne.diag_cc if ne.D_c is None else ne.D_c
            floor = 1e-12 * max(float(np.max(d)), 1e-300)
            S[np.diag_indices_from(S)] += lam * np.maximum(d, floor)
        return S, rhs, Vinv, None
    S = _damped(ne.Ncc, lam, ne.D_c)
    if ne.V is None:
        return S, rhs, None, None
    Vinv = _inv_blocks(_damped(ne.V, lam_p), ne.options.compiled, ne.options.rank_rtol)
    WVinv = (ne.W @ _block_diag(Vinv)).tocsr()
    if layout.n_c:
        S = S - (WVinv @ ne.W.T).toarray()
        rhs = rhs - WVinv @ ne.gp.ravel()
    return S, rhs, Vinv, WVinv


def _coupled(S: np.ndarray) -> np.ndarray | None:
    """The columns of the symmetric ``S`` with a non-zero entry off the diagonal; None when
    every column has one.

    A column with nothing but its diagonal is a 1 × 1 block of its own: solving with,
    factorising or inverting ``S`` is doing so for the coupled columns and dividing by the
    diagonal for the rest, exactly. In a pushbroom block these are the spline nodes of the turns
    between strips, held by their prior alone: 354 of the 1,073 unknowns of the pushbroom
    chapter's campaign (10 s nodes over a 1,724-s flight of 24 strips of 14 s), where the dense
    factorisation costs ``n³/3`` (issue 41).
    """
    off = np.count_nonzero(S, axis=1) - (np.diagonal(S) != 0)
    if np.all(off):
        return None
    return np.flatnonzero(off)


def _spd_solve(S: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``S⁻¹ rhs`` of a symmetric positive definite ``S`` by Cholesky, on its coupled columns
    only (:func:`_coupled`); LinAlgError where ``S`` is not positive definite.
    """
    keep = _coupled(S)
    if keep is None:
        return sla.cho_solve(sla.cho_factor(S, check_finite=False), rhs, check_finite=False)
    d = np.diagonal(S)
    if not np.all(d > 0):
        raise np.linalg.LinAlgError("the matrix has a zero or negative diagonal entry")
    x = rhs / d
    if keep.size:
        Sk = S[np.ix_(keep, keep)]
        c = sla.cho_factor(Sk, check_finite=False)
        x[keep] = sla.cho_solve(c, rhs[keep], check_finite=False)
    return x


def _step(layout: _Layout, ne: _Normal, lam: float):
    """The damped step ``(dc, dp)`` at λ (the reduced matrix formed or taken from the cache,
    factorised, and the points back-substituted); its seconds go to ``ne.clock``.
    """
    clock = ne.clock or _Clock()
    t = time.perf_counter()
    S, rhs, Vinv, _ = _reduced(layout, ne, lam)
    t = clock.add("formation", t)
    if layout.n_c:
        try:
            dc = -_spd_solve(S, rhs)
        except (np.linalg.LinAlgError, sla.LinAlgError):
            dc = -np.linalg.lstsq(S, rhs, rcond=None)[0]
    else:
        dc = np.zeros(0)
    dp = None
    if Vinv is not None:
        b = ne.gp + ne.Wt_dot(dc)
        dp = -np.einsum("nij,nj->ni", Vinv, b)
    clock.add("solve", t)
    return dc, dp


def _predicted_decrease(layout, ne: _Normal, lam, dc, dp) -> float:
    """L(0) - L(h) = ½ hᵀ(λ D h - g) for the damped Gauss–Newton step h (Madsen et al. eq. 3.14)."""
    if not layout.n_c:
        Dc = np.zeros(0)
    else:
        Dc = np.maximum(ne.damping_diagonal(), 0.0)
    pred = 0.5 * float(dc @ (lam * Dc * dc - ne.gc))
    if dp is not None:
        Dp = np.maximum(np.diagonal(ne.V, axis1=1, axis2=2), 0.0)
        lam_p = _lambda_points(lam, ne.options.lambda_points_min)
        pred += 0.5 * float(np.sum(dp * (lam_p * Dp * dp - ne.gp)))
    return pred


# ----------------------------------------------------------------------------------------------
# Covariances at the solution
# ----------------------------------------------------------------------------------------------
def _spd_inverse(S: np.ndarray, rtol: float) -> np.ndarray:
    """The inverse of a symmetric positive definite matrix, scaled to unit diagonal first.

    LAPACK potrf + potri on ``D^-½ S D^-½`` (a third of the work of solving for the identity).
    The scaling makes the factorisation's success depend on the matrix's conditioning, not on
    the units of its columns; if it still fails, the eigenvalues decide with the datum check's
    rule (smallest ≥ ``rtol`` × largest), so that whether a matrix counts as singular does not
    depend on the summation order of the BLAS threads.
    """
    d = np.diag(S).copy()
    if not np.all(d > 0):
        raise np.linalg.LinAlgError("the matrix has a zero or negative diagonal entry")
    d = 1.0 / np.sqrt(d)
    Ss = S * d[:, None] * d[None, :]
    keep = _coupled(Ss)
    if keep is None:
        return _unit_spd_inverse(Ss, rtol) * d[:, None] * d[None, :]
    # the uncoupled columns (unit diagonal, 1 × 1 blocks) invert to 1, and are eigenvalues 1
    inv = np.eye(S.shape[0])
    if keep.size:
        inv[np.ix_(keep, keep)] = _unit_spd_inverse(Ss[np.ix_(keep, keep)], rtol, 1.0)
    return inv * d[:, None] * d[None, :]


def _unit_spd_inverse(Ss: np.ndarray, rtol: float, ev_other: float | None = None) -> np.ndarray:
    """:func:`_spd_inverse` of a unit-diagonal block (``ev_other``: an eigenvalue of the rest
    of the matrix, which the singularity rule compares too; None: the block is the matrix).
    """
    c, info = lapack.dpotrf(Ss, lower=True, clean=False)
    if info == 0:
        inv, info = lapack.dpotri(c, lower=True, overwrite_c=True)
        inv = np.tril(inv) + np.tril(inv, -1).T
    if info != 0:
        ev, evec = np.linalg.eigh(Ss)
        lo, hi = float(ev[0]), float(ev[-1])
        if ev_other is not None:
            lo, hi = min(lo, ev_other), max(hi, ev_other)
        if not lo >= rtol * max(hi, 1e-300):
            raise np.linalg.LinAlgError(
                f"the matrix is singular (smallest eigenvalue {lo:.3g} of the unit-diagonal "
                f"scaled matrix, largest {hi:.3g})"
            )
        inv = (evec / ev) @ evec.T
    return inv


def _reduced_inverse(layout: _Layout, ne: _Normal) -> np.ndarray:
    """``S⁻¹`` of the undamped reduced matrix at the point of ``ne`` (a chord matrix dropped).

    Raises ``np.linalg.LinAlgError`` if ``S`` is singular (see :func:`_spd_inverse`).
    """
    ne.exact()  # the covariance needs the reduced matrix of this point
    S, _, _, _ = _reduced(layout, ne, 0.0)
    if not layout.n_c:
        return np.zeros((0, 0))
    return _spd_inverse(S, ne.options.rank_rtol)


#: A parameter is undetermined when its entries of the null space (unit-diagonal scaled, unit
#: null vectors) carry at least this share of a unit vector: the null vectors of a matrix
#: singular to rounding have entries of order √eps elsewhere.
NULL_SHARE = 1e-6


def _estimable_inverse(S: np.ndarray, rtol: float) -> tuple[np.ndarray, np.ndarray, int]:
    """A generalised inverse of a singular ``S`` and the parameters it cannot determine.

    Columns with a zero diagonal (no observation left) are undetermined outright; the rest is
    scaled to unit diagonal and decomposed (``eigh``); eigenvalues below ``rtol`` × the
    largest (the datum check's rule) span the null space, and every parameter with a share of
    at least :data:`NULL_SHARE` in it is undetermined. The pseudo-inverse of the scaled matrix,
    scaled back, is a generalised inverse ``G`` of ``S`` (``S G S = S``), so ``G`` gives the
    unique covariance of every estimable function — a parameter outside the null space
    among them (the caller sets the undetermined parameters' rows and columns to NaN).

    Returns
    -------
    G : (n, n) ndarray
    undetermined : (k,) int ndarray
        Indices of the undetermined parameters (sorted).
    defect : int
        ``n − rank(S)``: the dimension of the null space.
    """
    n = S.shape[0]
    d = np.diag(S).copy()
    live = np.flatnonzero(d > 0)
    G = np.zeros_like(S)
    if live.size:
        w = 1.0 / np.sqrt(d[live])
        Ss = S[np.ix_(live, live)] * w[:, None] * w[None, :]
        ev, evec = np.linalg.eigh(Ss)
        null = ev < rtol * max(float(ev[-1]), 1e-300)
        share = np.sum(evec[:, null] ** 2, axis=1)
        keep = ~null
        Gs = (evec[:, keep] / ev[keep]) @ evec[:, keep].T
        G[np.ix_(live, live)] = Gs * w[:, None] * w[None, :]
        bad = np.union1d(np.setdiff1d(np.arange(n), live), live[share >= NULL_SHARE])
        defect = n - live.size + int(null.sum())
    else:
        bad, defect = np.arange(n), n
    return G, bad.astype(int), defect


def _reduced_estimable_inverse(layout: _Layout, ne: _Normal) -> tuple[np.ndarray, np.ndarray, int]:
    """:func:`_estimable_inverse` of the undamped reduced matrix at the point of ``ne``."""
    ne.exact()
    S, _, _, _ = _reduced(layout, ne, 0.0)
    return _estimable_inverse(S, ne.options.rank_rtol)


def _point_cofactors(
    ne: _Normal, S_inv: np.ndarray, pts: np.ndarray, chunk: int = 20000
) -> np.ndarray:
    """``V⁻¹ + V⁻¹ Wᵀ S⁻¹ W V⁻¹`` of the points ``pts``: ``(len(pts), p, p)``, NaN for a point
    whose ``V`` is singular (e.g. too few rays left after outlier rejection).

    Needs the Jacobian of the solution (``ne.sy`` on the compiled path, ``ne.W`` otherwise).
    """
    n_c = S_inv.shape[0]
    p = ne.V.shape[-1]
    V = ne.V[pts]
    ev = np.linalg.eigvalsh(V)
    ok = ev[:, 0] > 1e-12 * np.maximum(ev[:, -1], 1e-300)
    Vinv = np.full_like(V, np.nan)
    Vinv[ok] = np.linalg.inv(V[ok])
    Vinv_w = np.where(ok[:, None, None], Vinv, 0.0)
    out = Vinv.copy()
    if n_c and ne.sy is not None and ne.order is not None:
        # compiled path: each point's W_i from its rows, on its local columns
        from hsgeo.adjust._fast import point_covariance as _pc

        Vfull = np.zeros_like(ne.V)
        Vfull[pts] = Vinv_w
        sy = ne.sy
        cov = _pc(sy.Jrc.arrays, sy.Jp, ne.order, ne.ptr, pts, Vfull, S_inv)
        out = np.where(ok[:, None, None], cov, np.nan)
    elif n_c:
        Wd = ne.W.tocsc()
        for a0 in range(0, pts.size, chunk):
            sel = pts[a0 : a0 + chunk]
            colidx = (sel[:, None] * p + np.arange(p)).ravel()
            Wi = Wd[:, colidx].toarray().T.reshape(sel.size, p, n_c)  # (k, p, n_c)
            A = np.einsum("kij,kjc->kic", Vinv_w[a0 : a0 + sel.size], Wi)  # V⁻¹ Wᵀ
            out[a0 : a0 + sel.size] += np.einsum("kic,cd,kjd->kij", A, S_inv, A)
    return out


def _selected_W(ne: _Normal, pts: np.ndarray) -> np.ndarray:
    """``W`` restricted to the columns of the (distinct) points ``pts``: dense ``(n_c, k·p)``,
    point by point. On the compiled path only the rows of those points are read.
    """
    p = ne.V.shape[-1]
    k = pts.size
    if ne._W is not None or ne.sy is None:
        cols = (pts[:, None] * p + np.arange(p)).ravel()
        return ne.W[:, cols].toarray()
    sy = ne.sy
    where = np.full(ne.n_pts, -1, dtype=np.int64)
    where[pts] = np.arange(k)
    rows = np.flatnonzero((sy.pidx >= 0) & (where[np.maximum(sy.pidx, 0)] >= 0))
    loc = where[sy.pidx[rows]]
    Jp_sel = sp.csr_matrix(
        (
            sy.Jp[rows].ravel(),
            (np.repeat(np.arange(rows.size), p), (loc[:, None] * p + np.arange(p)).ravel()),
        ),
        shape=(rows.size, k * p),
    )
    return (sy.Jc[rows].T @ Jp_sel).toarray()


def _joint_point_cofactors(ne: _Normal, S_inv: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """The joint cofactor matrix of the points ``pts``: ``(k·p, k·p)``, point by point.

    ``blockdiag(V_i⁻¹) + A S⁻¹ Aᵀ`` with ``A_i = V_i⁻¹ W_iᵀ`` — the Schur complement's
    back-substitution (every point moves with the non-point unknowns through its own ``A_i``);
    its diagonal blocks are :func:`_point_cofactors`. This is the points' block of the inverse
    of the full normal matrix. Rows and columns of a point whose ``V`` is singular are NaN.
    """
    p = ne.V.shape[-1]
    uniq, inv = np.unique(np.asarray(pts, dtype=np.int64), return_inverse=True)
    k = uniq.size
    V = ne.V[uniq]
    ev = np.linalg.eigvalsh(V)
    ok = ev[:, 0] > 1e-12 * np.maximum(ev[:, -1], 1e-300)
    Vinv = np.zeros_like(V)
    Vinv[ok] = np.linalg.inv(V[ok])
    out = np.zeros((k * p, k * p))
    for i in range(k):
        out[i * p : (i + 1) * p, i * p : (i + 1) * p] = Vinv[i]
    if S_inv.shape[0]:
        Wt = _selected_W(ne, uniq).T.reshape(k, p, -1)  # (k, p, n_c)
        A = np.einsum("kij,kjc->kic", Vinv, Wt).reshape(k * p, -1)  # V⁻¹ Wᵀ
        out += A @ S_inv @ A.T
        out = 0.5 * (out + out.T)
    bad = np.repeat(~ok, p)
    out[bad, :] = np.nan
    out[:, bad] = np.nan
    sel = (inv[:, None] * p + np.arange(p)).ravel()
    return out[np.ix_(sel, sel)]


class _Cofactors:
    """The points' cofactors at the solution: ``f(pts, chunk)`` → their blocks
    (:func:`_point_cofactors`), ``f.joint(pts)`` → their joint matrix
    (:func:`_joint_point_cofactors`).

    Holds the Jacobian of the solution; the result keeps it only on request
    (``SolverOptions.keep_jacobian``).
    """

    def __init__(self, ne: _Normal, S_inv: np.ndarray) -> None:
        self.ne, self.S_inv = ne, S_inv

    def __call__(self, pts: np.ndarray, chunk: int = 20000) -> np.ndarray:
        return _point_cofactors(self.ne, self.S_inv, pts, chunk)

    def joint(self, pts: np.ndarray) -> np.ndarray:
        return _joint_point_cofactors(self.ne, self.S_inv, pts)


def _point_cofactor_function(ne: _Normal, S_inv: np.ndarray) -> _Cofactors:
    """The points' cofactors at the solution (see :class:`_Cofactors`)."""
    return _Cofactors(ne, S_inv)
