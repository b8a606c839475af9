r"""RANSAC on the linear-pushbroom (LP) fundamental matrix of Gupta & Hartley (1997).

002 §3.1 filters the key-point matches between two rotation-compensated LP image scenes with
RANSAC on the LP epipolar geometry of Gupta & Hartley (1997), "at least 11 key-point
correspondences" per model. This module derives that geometry, estimates it linearly
(normalised, as Hartley's eight-point algorithm) and runs RANSAC on it; the frame-camera
fundamental matrix of OpenCV is the comparator.

The LP camera
-------------
A scene pixel is ``(u, v)``: ``u`` the row (line index, i.e. the exposure time times the line
rate: the along-track direction) and ``v`` the column (along the line). Within a scene the
camera moves at constant velocity ``V`` with constant attitude ``R`` (002 §3.1: "platform
velocity and orientation are close to constant in the rotation-compensated LP image scenes").
A line exposed at time ``t`` sees the points of its view plane through ``C(t) = C₀ + t V``.
With camera coordinates ``p(t) = R (X − C₀ − t V)`` of a map point ``X``, the point is imaged
when it crosses the view plane, ``p_y(t) = 0``: ``t = r₂·(X − C₀) / r₂·V`` is an *affine*
function of ``X`` and so is ``u = t · rate + u₀``. At that time ``p_x`` and ``p_z`` are affine
in ``X`` too (``t`` is), and the column is the perspective ratio ``v = c p_x / p_z + v₀``.
With ``X̃ = (X, 1)`` (Gupta & Hartley 1997, eq. 1)::

    u = m₁·X̃,        v = m₂·X̃ / m₃·X̃                                     (LP camera)

``M = (m₁; m₂; m₃)`` is 3×4: orthographic (affine) along the flight, perspective across it.

The LP fundamental matrix
-------------------------
A pixel ``(u, v)`` back-projects to the line of points on the two planes
``(m₁ − u e₄)·X̃ = 0`` and ``(m₂ − v m₃)·X̃ = 0`` (``e₄ = (0, 0, 0, 1)``). Two pixels
``(u, v)`` and ``(u', v')`` of two LP cameras ``M``, ``M'`` see one point iff the four planes
meet in a point, i.e.::

    det [m₁ − u e₄;  m₂ − v m₃;  m₁' − u' e₄;  m₂' − v' m₃'] = 0.

The determinant is linear in each row, each row affine in one of ``u, v, u', v'``, so it is
a polynomial in the monomials ``{1, u} × {1, v} × {1, u'} × {1, v'}``: a bilinear form in the
*lifted* coordinates ``L = (u, u v, v, 1)`` and ``L' = (u', u' v', v', 1)``::

    L'ᵀ F L = 0,   F[r(k, l), s(i, j)] = det [a_i; b_j; c_k; d_l]              (LP epipolar)

with ``a₀ = m₁, a₁ = −e₄``, ``b₀ = m₂, b₁ = −m₃``, ``c₀ = m₁', c₁ = −e₄``,
``d₀ = m₂', d₁ = −m₃'`` and ``i, j, k, l`` the powers of ``u, v, u', v'`` in the monomial.
Every term with ``u u'`` has the row ``−e₄`` twice and vanishes: the entries of ``F`` at
``(u', u'v') × (u, uv)`` — its upper-left 2×2 block — are zero::

        (u    uv    v    1)
    F = [0    0     f₁₃  f₁₄]   u'
        [0    0     f₂₃  f₂₄]   u'v'
        [f₃₁  f₃₂   f₃₃  f₃₄]   v'
        [f₄₁  f₄₂   f₄₃  f₄₄]   1

Twelve non-zero entries up to scale: eleven unknowns, one linear equation per correspondence,
hence 11 correspondences for a linear solution (Gupta & Hartley 1997; 002 §3.1). The twelve
entries are not independent: two LP cameras have 2 × 11 parameters and an affine map of space
(12) leaves every LP image unchanged, so F has 10 degrees of freedom — one non-linear
constraint, which we confirmed numerically (the Jacobian of the normalised F with respect to
two random cameras has rank 10) and found to be of degree > 4 (no polynomial of degree ≤ 4
vanishes on 3000 random camera pairs). The linear estimate ignores it, as the eight-point
algorithm ignores ``det F = 0``; the extra freedom is what lets an 11-point F bend through
outliers in near-planar scenes (see :func:`ransac_lp_fundamental`). The epipolar
curves ``v' ↦ u'`` of a fixed ``(u, v)`` are hyperbolas (002 §3.1), not lines.

Estimation. ``u`` and ``v`` of each image are conditioned separately (``û = (u − ū)/s_u``,
``v̂ = (v − v̄)/s_v``, RMS one; Hartley 1997). An affine change of ``u`` and of ``v`` maps the
lifted vector linearly, ``L = T L̂``, with ``T`` keeping ``span(e₁, e₂)`` (the ``u`` and ``uv``
entries), so the conditioned ``F̂ = T'ᵀ F T`` has the same zero block; the 12 entries are the
right singular vector of the smallest singular value of the ``n × 12`` design (rows
``L̂' ⊗ L̂`` on the non-zero positions), and ``F = T'⁻ᵀ F̂ T⁻¹``.

Distance. The first-order geometric (Sampson) distance of a correspondence from the
three-dimensional manifold ``ε(u, v, u', v') = L'ᵀ F L = 0`` in the joint four-dimensional
pixel space, symmetric in the two images::

    d = |ε| / ‖∇ε‖,   ∂ε/∂u  = g₁ + v g₂,    ∂ε/∂v  = u g₂ + g₃,    g = Fᵀ L',
                      ∂ε/∂u' = h₁ + v' h₂,   ∂ε/∂v' = u' h₂ + h₃,   h = F L

(components numbered 1…4 as in ``L``: ``∂L/∂u = (1, v, 0, 0)``, ``∂L/∂v = (0, u, 1, 0)``).
It is the length of the smallest pixel correction of all four coordinates that satisfies the
linearised relation; for a correct model and independent noise σ px in each coordinate it is
``σ |z|`` with ``z`` standard normal. OpenCV's
frame-camera RANSAC scores ``max`` of the two point-to-epipolar-line distances instead, which
is ≥ the Sampson distance (by ≈ √2 when both images are alike): at one threshold the frame
RANSAC is the stricter one even for a correct model.

References
----------
Gupta R, Hartley RI (1997) Linear pushbroom cameras. IEEE Trans Pattern Anal Mach Intell
19(9):963–975.
Torr PHS, Zisserman A (2000) MLESAC: a new robust estimator with application to estimating
image geometry. Comput Vis Image Underst 78(1):138–156.
Hartley RI (1997) In defense of the eight-point algorithm. IEEE Trans Pattern Anal Mach
Intell 19(6):580–593.
Jonassen et al. (2024), 002 §3.1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError, ObservationError

__all__ = [
    "LpRansacResult",
    "MIN_CORRESPONDENCES",
    "fit_lp_fundamental",
    "lp_epipolar_distance",
    "lp_fundamental_from_cameras",
    "ransac_frame_fundamental",
    "ransac_lp_fundamental",
]

#: Correspondences of one linear LP fundamental matrix (11 unknowns; 002 §3.1).
MIN_CORRESPONDENCES = 11
#: Non-zero entries of F (row-major indices into the flattened 4×4): all but the 2×2 block.
_NONZERO = np.array([r * 4 + s for r in range(4) for s in range(4) if not (r < 2 and s < 2)])
_NONZERO.setflags(write=False)
#: A sample whose design has σ₁₁/σ₁ below this is degenerate (rank < 11).
_RANK_TOL = 1e-9


@dataclass(frozen=True)
class LpRansacResult:
    """Outcome of :func:`ransac_lp_fundamental`.

    Attributes
    ----------
    F : (4, 4) ndarray
        LP fundamental matrix refitted on all inliers (Frobenius norm 1), in pixels:
        ``(u', u'v', v', 1) F (u, uv, v, 1)ᵀ = 0``. NaN when no model was found.
    inliers : (n,) bool ndarray
        Correspondences whose Sampson distance to ``F`` is at most the threshold.
    n_iterations : int
        RANSAC samples drawn.
    """

    F: np.ndarray
    inliers: np.ndarray
    n_iterations: int


# ----------------------------------------------------------------------------------------------
# Input checks and the lifted coordinates
# ----------------------------------------------------------------------------------------------
def _check_pairs(uv1, uv2) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(uv1, dtype=np.float64)
    b = np.asarray(uv2, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 2 or b.shape != a.shape:
        raise InputError(
            f"correspondences must be two (n, 2) arrays of (u, v) px of the same n, got "
            f"{np.shape(uv1)} and {np.shape(uv2)}"
        )
    bad = ~(np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1))
    if bad.any():
        rows = np.flatnonzero(bad)
        raise InputError(
            f"{rows.size} correspondences have NaN or inf coordinates (rows "
            f"{', '.join(map(str, rows[:5]))}{', …' if rows.size > 5 else ''}): drop them first"
        )
    return a, b


def _conditioning(uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and scale of u and v (RMS deviation one after conditioning)."""
    mean = uv.mean(axis=0)
    scale = np.sqrt(((uv - mean) ** 2).mean(axis=0))
    return mean, np.where(scale > 0, scale, 1.0)


def _lift(uv: np.ndarray) -> np.ndarray:
    """``(n, 4)`` lifted coordinates ``(u, u v, v, 1)``."""
    u, v = uv[..., 0], uv[..., 1]
    return np.stack([u, u * v, v, np.ones_like(u)], axis=-1)


def _lift_matrix(mean: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """``T`` with ``L(u, v) = T L(û, v̂)`` for ``u = s_u û + ū``, ``v = s_v v̂ + v̄``."""
    (b, d), (a, c) = mean, scale
    return np.array(
        [[a, 0, 0, b], [a * d, a * c, b * c, b * d], [0, 0, c, d], [0, 0, 0, 1.0]],
    )


def _design(L1: np.ndarray, L2: np.ndarray) -> np.ndarray:
    """``(..., n, 12)`` rows ``L' ⊗ L`` on the non-zero entries of F."""
    outer = L2[..., :, None] * L1[..., None, :]  # (..., n, 4 rows of F, 4 columns of F)
    return outer.reshape(*outer.shape[:-2], 16)[..., _NONZERO]


def _denormalise(f12: np.ndarray, T1: np.ndarray, T2: np.ndarray) -> np.ndarray:
    """``(..., 4, 4)`` F in pixels from conditioned entries: ``F = T'⁻ᵀ F̂ T⁻¹``, ‖F‖ = 1."""
    Fh = np.zeros((*f12.shape[:-1], 16))
    Fh[..., _NONZERO] = f12
    Fh = Fh.reshape(*f12.shape[:-1], 4, 4)
    F = np.linalg.inv(T2).T @ Fh @ np.linalg.inv(T1)
    F[..., :2, :2] = 0.0  # exactly zero (T keeps span(e1, e2); rounding only)
    return F / np.linalg.norm(F, axis=(-2, -1), keepdims=True)


# ----------------------------------------------------------------------------------------------
# Linear estimation and distance
# ----------------------------------------------------------------------------------------------
def fit_lp_fundamental(uv1, uv2) -> np.ndarray:
    """Linear (conditioned) estimate of the LP fundamental matrix (Gupta & Hartley 1997).

    Parameters
    ----------
    uv1, uv2 : (n, 2) array_like, px
        Corresponding scene pixels ``(u, v)`` (row, column) in image 1 and image 2, n ≥ 11.

    Returns
    -------
    F : (4, 4) ndarray
        ``(u', u'v', v', 1) F (u, uv, v, 1)ᵀ = 0`` with ``F[:2, :2] = 0`` and ‖F‖_F = 1; the
        algebraic least-squares solution for n > 11.

    Raises
    ------
    InputError
        Arrays of different or wrong shapes, or NaN / inf coordinates.
    ObservationError
        Fewer than 11 correspondences, or a degenerate configuration (the design matrix has
        rank < 11, e.g. repeated points or too few distinct rows or columns).
    """
    a, b = _check_pairs(uv1, uv2)
    if a.shape[0] < MIN_CORRESPONDENCES:
        raise ObservationError(
            f"the LP fundamental matrix needs at least {MIN_CORRESPONDENCES} correspondences "
            f"(11 unknowns, 002 §3.1), got {a.shape[0]}: match more key points or skip this "
            "scene pair"
        )
    m1, s1 = _conditioning(a)
    m2, s2 = _conditioning(b)
    A = _design(_lift((a - m1) / s1), _lift((b - m2) / s2))
    if A.shape[0] == MIN_CORRESPONDENCES:  # a zero row: Vt then holds the null vector too
        A = np.vstack([A, np.zeros((1, 12))])
    _, sv, Vt = np.linalg.svd(A, full_matrices=False)
    if sv[10] <= _RANK_TOL * sv[0]:
        raise ObservationError(
            f"the {a.shape[0]} correspondences do not determine the LP fundamental matrix "
            f"(design rank < 11: σ₁₁/σ₁ = {sv[10] / sv[0]:.1e}): they are degenerate, e.g. "
            "repeated points or too few distinct rows and columns"
        )
    T1, T2 = _lift_matrix(m1, s1), _lift_matrix(m2, s2)
    return _denormalise(Vt[-1], T1, T2)


def _sampson(F: np.ndarray, L1: np.ndarray, L2: np.ndarray, uv1, uv2, gradient=False):
    """Sampson distances ``(..., n)`` of lifted points for one or a stack of ``F`` (and ‖∇ε‖)."""
    FL = L1 @ np.swapaxes(F, -1, -2)  # F L,   (..., n, 4)
    GL = L2 @ F  # Fᵀ L', (..., n, 4)
    eps = (FL * L2).sum(axis=-1)
    u, v = uv1[:, 0], uv1[:, 1]
    u2, v2 = uv2[:, 0], uv2[:, 1]
    du = GL[..., 0] + v * GL[..., 1]
    dv = u * GL[..., 1] + GL[..., 2]
    du2 = FL[..., 0] + v2 * FL[..., 1]
    dv2 = u2 * FL[..., 1] + FL[..., 2]
    g2 = du * du + dv * dv + du2 * du2 + dv2 * dv2
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.abs(eps) / np.sqrt(g2)
    d = np.where(np.isfinite(d), d, np.inf)
    return (d, np.sqrt(g2)) if gradient else d


def lp_epipolar_distance(F, uv1, uv2) -> np.ndarray:
    """First-order geometric (Sampson) distance of correspondences from the LP epipolar relation.

    Parameters
    ----------
    F : (4, 4) array_like
        LP fundamental matrix (:func:`fit_lp_fundamental`).
    uv1, uv2 : (n, 2) array_like, px
        Corresponding scene pixels ``(u, v)`` in image 1 and image 2.

    Returns
    -------
    d_px : (n,) ndarray, px
        ``|L'ᵀ F L| / ‖∇(L'ᵀ F L)‖`` with the gradient over ``(u, v, u', v')``: the length of
        the smallest correction of the four pixel coordinates that satisfies the linearised
        relation (symmetric in the two images). ``inf`` where the gradient vanishes.
    """
    F = np.asarray(F, dtype=np.float64)
    if F.shape != (4, 4):
        raise InputError(f"an LP fundamental matrix is 4×4, got {F.shape}")
    a, b = _check_pairs(uv1, uv2)
    return _sampson(F, _lift(a), _lift(b), a, b)


def lp_fundamental_from_cameras(M1, M2) -> np.ndarray:
    """The LP fundamental matrix of two LP cameras ``u = m₁·X̃, v = m₂·X̃ / m₃·X̃``.

    Parameters
    ----------
    M1, M2 : (3, 4) array_like
        Rows ``m₁, m₂, m₃`` of each camera (Gupta & Hartley 1997, eq. 1).

    Returns
    -------
    F : (4, 4) ndarray
        ``F[r(k, l), s(i, j)] = det[a_i; b_j; c_k; d_l]`` (module docstring), ‖F‖_F = 1.
    """
    M1 = np.asarray(M1, dtype=np.float64)
    M2 = np.asarray(M2, dtype=np.float64)
    e4 = np.array([0.0, 0, 0, 1])
    a, b = (M1[0], -e4), (M1[1], -M1[2])
    c, d = (M2[0], -e4), (M2[1], -M2[2])
    pos = {(1, 0): 0, (1, 1): 1, (0, 1): 2, (0, 0): 3}  # (power of u, power of v) → index in L
    F = np.zeros((4, 4))
    for (i, j), s in pos.items():
        for (k, l_), r in pos.items():
            F[r, s] = np.linalg.det(np.stack([a[i], b[j], c[k], d[l_]]))
    return F / np.linalg.norm(F)


# ----------------------------------------------------------------------------------------------
# RANSAC
# ----------------------------------------------------------------------------------------------
def _iterations_needed(n_inliers: int, n: int, confidence: float, max_iter: int) -> int:
    w = n_inliers / n
    p_good = w**MIN_CORRESPONDENCES
    if p_good <= 0:
        return max_iter
    if p_good >= 1:
        return 1
    return int(min(max_iter, np.ceil(np.log1p(-confidence) / np.log1p(-p_good))))


def _sample_models(A_all: np.ndarray, idx: np.ndarray):
    """Null vectors ``(B, 12)`` of the sampled designs and whether each is non-degenerate."""
    A = A_all[idx]  # (B, 11, 12)
    _, sv, Vt = np.linalg.svd(A, full_matrices=True)
    ok = sv[:, -1] > _RANK_TOL * sv[:, 0]  # σ₁₁ of 11 rows: rank 11
    return Vt[:, -1, :], ok


def ransac_lp_fundamental(
    uv1, uv2, *, threshold_px=1.0, confidence=0.999, max_iter=5000, rng=0, deleted=True
) -> LpRansacResult:
    """RANSAC on the LP fundamental matrix with minimal samples of 11 (002 §3.1).

    Samples are drawn and scored in batches (vectorised SVDs and Sampson distances); the
    number of samples adapts to the best inlier share ``w`` so far,
    ``N = log(1 − confidence) / log(1 − w¹¹)`` (at most ``max_iter``). The best model is
    refitted on all its inliers by gradient-weighted (Sampson) least squares and the
    correspondences are classified again with the refitted F (repeated while the inlier set
    does not shrink, at most 5 times). Samples are scored by MSAC's truncated quadratic
    ``Σ min(d², threshold²)`` (Torr & Zisserman 2000), which prefers the model that fits its
    inliers tightly over one that bends through a few outliers. Last, each inlier's
    *deleted* residual — its Sampson distance from the F refitted on all other inliers — must
    be within the threshold too (``deleted=True``): an 11-unknown F fitted to a few tens of
    matches, or to a near-planar scene, can bend through an outlier, whose own residual is
    then small but whose deleted residual is not (50 matches with 30 % outliers in 002's
    geometry: ≈ 75 % of the outliers rejected without the check, ≈ 100 % with it).

    Parameters
    ----------
    uv1, uv2 : (n, 2) array_like, px
        Corresponding scene pixels ``(u, v)`` (row, column).
    threshold_px : float, px
        Largest Sampson distance (:func:`lp_epipolar_distance`) of an inlier.
    confidence : float
        Probability that at least one sample is outlier-free, in (0, 1).
    max_iter : int
        Largest number of samples.
    rng : int or numpy.random.Generator
        Seed or generator of the samples (same seed, same result).
    deleted : bool
        Drop inliers whose deleted residual exceeds the threshold (one pass, then refit).

    Returns
    -------
    LpRansacResult
        ``F`` (4, 4), ``inliers`` (n,) bool, ``n_iterations``. With no non-degenerate sample
        ``F`` is NaN and no correspondence is an inlier.

    Raises
    ------
    InputError
        Wrong shapes, NaN or inf, or a non-positive threshold.
    ObservationError
        Fewer than 11 correspondences.
    """
    a, b = _check_pairs(uv1, uv2)
    n = a.shape[0]
    if not threshold_px > 0 or not 0 < confidence < 1 or max_iter < 1:
        raise InputError(
            f"RANSAC needs threshold_px > 0, 0 < confidence < 1 and max_iter ≥ 1, got "
            f"{threshold_px!r}, {confidence!r}, {max_iter!r}"
        )
    if n < MIN_CORRESPONDENCES:
        raise ObservationError(
            f"RANSAC on the LP fundamental matrix needs at least {MIN_CORRESPONDENCES} "
            f"correspondences (002 §3.1), got {n}: match more key points or skip this scene pair"
        )
    gen = np.random.default_rng(rng)
    m1, s1 = _conditioning(a)
    m2, s2 = _conditioning(b)
    A_all = _design(_lift((a - m1) / s1), _lift((b - m2) / s2))
    T1, T2 = _lift_matrix(m1, s1), _lift_matrix(m2, s2)
    L1, L2 = _lift(a), _lift(b)
    best_cost, best_F, needed, done = np.inf, None, max_iter, 0
    t2 = float(threshold_px) ** 2
    batch = 32
    while done < min(needed, max_iter):
        B = min(batch, max_iter - done, needed - done)
        # B samples of 11 distinct indices: argpartition of uniform keys (one call, no loop)
        idx = np.argpartition(gen.random((B, n)), MIN_CORRESPONDENCES - 1, axis=1)
        idx = idx[:, :MIN_CORRESPONDENCES]
        done += B
        f12, ok = _sample_models(A_all, idx)
        if not ok.any():
            continue
        F = _denormalise(f12[ok], T1, T2)
        d2 = np.minimum(_sampson(F, L1, L2, a, b) ** 2, t2)
        cost = d2.sum(axis=1)  # MSAC: truncated quadratic (Torr & Zisserman 2000)
        k = int(np.argmin(cost))
        if cost[k] < best_cost:
            best_cost, best_F = float(cost[k]), F[k]
            count = int((d2[k] < t2).sum())
            needed = _iterations_needed(count, n, confidence, max_iter)
    if best_F is None:
        return LpRansacResult(np.full((4, 4), np.nan), np.zeros(n, bool), done)
    F, inliers = _refine(best_F, A_all, (L1, L2), (a, b), (T1, T2), threshold_px, deleted)
    return LpRansacResult(F, inliers, done)


def _refine(F0, A_all, lifted, uv, T, threshold_px, deleted):
    """Refit on the inliers (gradient-weighted), classify again; then the deleted residuals."""
    (L1, L2), (a, b), (T1, T2) = lifted, uv, T
    F = F0
    d, grad = _sampson(F, L1, L2, a, b, gradient=True)
    inliers = d <= threshold_px
    for _ in range(5):  # refit on all inliers, classify again
        if inliers.sum() < MIN_CORRESPONDENCES:
            break
        # gradient-weighted (Sampson) least squares: rows scaled by 1/‖∇ε‖ of the current F,
        # so the fit minimises Σ d² instead of the algebraic Σ ε² (which near-degenerate,
        # near-planar scenes make noise-sensitive). The algebraic error of the conditioned
        # design equals L'ᵀ F L up to one global scale, so the weights carry over.
        Aw = A_all[inliers] / grad[inliers, None]
        _, sv, Vt = np.linalg.svd(Aw, full_matrices=False)
        if Vt.shape[0] < 12 or sv[10] <= _RANK_TOL * sv[0]:
            break
        F_new = _denormalise(Vt[-1], T1, T2)
        d_new, grad_new = _sampson(F_new, L1, L2, a, b, gradient=True)
        new = d_new <= threshold_px
        if new.sum() < inliers.sum():
            break
        stable = np.array_equal(new, inliers)
        F, inliers, grad = F_new, new, grad_new
        if stable:
            break
    for _ in range(1 if deleted else 0):  # drop inliers whose deleted residual is large
        if inliers.sum() <= MIN_CORRESPONDENCES + 1:
            break
        keep = _deleted_residual_px(A_all, grad, inliers, T1, T2, a, b) <= threshold_px
        if keep.sum() < MIN_CORRESPONDENCES or keep.all():
            break
        inliers = inliers.copy()
        inliers[np.flatnonzero(inliers)[~keep]] = False
        Aw = A_all[inliers] / grad[inliers, None]
        F = _denormalise(np.linalg.svd(Aw, full_matrices=False)[2][-1], T1, T2)
        grad = _sampson(F, L1, L2, a, b, gradient=True)[1]
    return F, inliers


def _deleted_residual_px(A_all, grad, inliers, T1, T2, a, b) -> np.ndarray:
    """Sampson distance of each inlier from the F fitted to all *other* inliers, px.

    An 11-unknown F fitted to a few tens of matches, or to a near-planar scene, can bend
    through an outlier; the outlier's residual is then small but its deleted residual is not.
    The refits come from the weighted normal matrix ``N − w_i² a_i a_iᵀ`` (one batched
    12 × 12 eigen-decomposition per inlier).
    """
    idx = np.flatnonzero(inliers)
    Aw = A_all[idx] / grad[idx, None]
    N = Aw.T @ Aw
    Ni = N[None] - Aw[:, :, None] * Aw[:, None, :]
    _, vec = np.linalg.eigh(Ni)
    F = _denormalise(vec[:, :, 0], T1, T2)  # (m, 4, 4): each without its own match
    L1, L2 = _lift(a[idx]), _lift(b[idx])
    FL = np.einsum("mrs,ms->mr", F, L1)
    GL = np.einsum("mrs,mr->ms", F, L2)
    eps = np.sum(L2 * FL, axis=1)
    u, v, u2, v2 = a[idx, 0], a[idx, 1], b[idx, 0], b[idx, 1]
    g2 = (
        (GL[:, 0] + v * GL[:, 1]) ** 2
        + (u * GL[:, 1] + GL[:, 2]) ** 2
        + (FL[:, 0] + v2 * FL[:, 1]) ** 2
        + (u2 * FL[:, 1] + FL[:, 2]) ** 2
    )
    return np.abs(eps) / np.sqrt(g2)


def ransac_frame_fundamental(uv1, uv2, *, threshold_px=1.0, confidence=0.999) -> np.ndarray:
    """Inliers of OpenCV's frame-camera fundamental-matrix RANSAC (the comparator).

    ``cv2.findFundamentalMat(..., cv2.FM_RANSAC, threshold_px, confidence, 5000)`` on the same
    pixels ``(u, v)`` (as image ``(x, y)``); OpenCV scores ``max`` of the two squared
    point-to-epipolar-line distances against ``threshold_px²``. The OpenCV RNG is seeded
    (``cv2.setRNGSeed(0)``) for a deterministic result.

    Parameters
    ----------
    uv1, uv2 : (n, 2) array_like, px
    threshold_px : float, px
    confidence : float

    Returns
    -------
    inliers : (n,) bool ndarray
        All False with fewer than 8 correspondences or when OpenCV finds no model.
    """
    import cv2  # noqa: PLC0415 (the comparator only; keeps import of this module light)

    a, b = _check_pairs(uv1, uv2)
    n = a.shape[0]
    if n < 8:
        return np.zeros(n, bool)
    cv2.setRNGSeed(0)
    F, mask = cv2.findFundamentalMat(
        a, b, cv2.FM_RANSAC, float(threshold_px), float(confidence), 5000
    )
    if F is None or mask is None:
        return np.zeros(n, bool)
    return mask.ravel().astype(bool)
