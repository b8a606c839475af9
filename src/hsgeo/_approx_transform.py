"""PROJ at a few nodes, a polynomial between them, its error checked against PROJ: fast CRS maps.

Orthorectification takes every pixel through the frame's PROJ pipelines several times (the
chord ends of the DSM intersection into the map CRS, the crossing back, the ground point into
the output CRS): at 0.2–0.4 µs a point that was most of the mosaic's CPU time
(``bench/results/orthomosaic_stages.json``). Over the few hundred metres of a block of lines
these maps are smooth to the scale of the Earth's radius R: the cubic (all monomials of total
degree ≤ 3 in the three scaled inputs, 20 terms) fitted by least squares to PROJ at the 4 × 4 × 4
Chebyshev–Lobatto nodes of the points' bounding box departs from PROJ by about (h/R)³·h (h the
half-width of the box: 1e-12 m for h = 150 m, 1e-7 m for 2.5 km), far inside
:data:`APPROX_TOL_M`; what remains is PROJ's own rounding (≈ 1e-8 m on coordinates of 6e6 m).

That is the expectation; what is used is verified per call: PROJ is also run at a check set —
the box's corners, edge midpoints and the half-way points between the nodes (where a fit's error
peaks), 7 × 7 × 7 points, plus every k-th point of the input (about 256) — and the polynomial
is used only if its largest difference there is within :data:`CHECK_MARGIN` × the tolerance.
Otherwise (a box too large for a cubic, a longitude that wraps at the antimeridian in a
geographic CRS, a point PROJ cannot transform, a NaN) the whole call falls back to PROJ on
every point. An input axis of one value (the chord ends of the DSM intersection lie on one
height) is constant for the fit.

Why hand-written: pyproj has no approximate array transformer (PROJ's ``+approx`` selects
another series for the transverse Mercator, still per point, and says nothing of the error);
GDAL's approximate transformer (``GDALCreateApproxTransformer``: linear interpolation along
scanlines of an image, within an error threshold) is not exposed by rasterio or pyproj and
interpolates along image rows, not over scattered points. The polynomial here is evaluated by
a compiled kernel (numba) at ≈ 5 ns a point and output, where PROJ takes 300–400 ns a point.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numba import njit

__all__ = [
    "APPROX_TOL_M",
    "CHECK_MARGIN",
    "MIN_POINTS",
    "DEGREE",
    "approx_transform",
    "tolerance_in_units",
    "enu_to_map",
    "map_to_enu",
]

#: The largest difference (m) allowed between the approximate and the exact (PROJ) coordinates:
#: a thousandth of the 0.3 m cells of the 002 mosaic, a hundredth of the DSMs' height accuracy;
#: it can move a cell's nearest pixel only where two pixels are within 1 mm of a tie.
APPROX_TOL_M = 1e-3
#: The check set's largest difference must be within this share of the tolerance: between the
#: check points (half-way between the nodes, where a Chebyshev interpolant's error peaks) the
#: error of a smooth map stays within a small factor of that at the check points.
CHECK_MARGIN = 0.25
#: Fewer points are transformed exactly: the fit's ≈ 300 PROJ points would not pay.
MIN_POINTS = 4096
#: Nodes of the fit along each input axis, less one: the cubic is determined on each axis.
DEGREE = (3, 3, 3)
#: Points of the input taken into the check set (every k-th, k = n // CHECK_POINTS).
CHECK_POINTS = 256
#: An input axis spanning less than this (in its units) is constant for the fit (degree 0).
_FLAT_SPAN = 1e-9


def _lobatto(lo: float, hi: float, deg: int) -> np.ndarray:
    """Chebyshev–Lobatto nodes (the box's edges among them) of [lo, hi]."""
    if deg == 0:
        return np.array([0.5 * (lo + hi)])
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(np.pi * np.arange(deg, -1, -1) / deg)


def approx_transform(exact, inputs, tol, *, min_points: int = MIN_POINTS):
    """``exact(*inputs)`` by a verified polynomial (module docstring), or exactly.

    Parameters
    ----------
    exact : callable
        ``exact(a, b, c) -> tuple of arrays``: the PROJ transform of three coordinate arrays.
    inputs : sequence of 3 array_like
        The coordinates (broadcast together).
    tol : sequence of float
        The tolerance of each output, in its units (:data:`APPROX_TOL_M` in metres, or its
        equivalent in degrees, :func:`tolerance_in_units`).
    min_points : int
        Fewer points go through ``exact`` directly.

    Returns
    -------
    outputs : tuple of ndarray
        As ``exact``'s, in the inputs' shape.
    info : dict
        ``approx`` (whether the polynomial was used), ``max_check_error`` (per output, in its
        units; None when not fitted) and ``n_check``.
    """
    a, b, c = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in inputs))
    shape = a.shape
    cols = [np.ascontiguousarray(v).ravel() for v in (a, b, c)]
    n = cols[0].size
    tol = np.asarray(tol, float)
    info = {"approx": False, "max_check_error": None, "n_check": 0}
    if n < min_points:
        return _exact(exact, cols, shape), info
    lo, hi = _bounds(cols[0], cols[1], cols[2])
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):  # a NaN among the points
        return _exact(exact, cols, shape), info
    centre = 0.5 * (lo + hi)
    half = np.where(hi - lo > _FLAT_SPAN, 0.5 * (hi - lo), 1.0)
    deg = [d if hi[i] - lo[i] > _FLAT_SPAN else 0 for i, d in enumerate(DEGREE)]
    nodes = _lattice(lo, hi, deg)
    step = max(1, n // CHECK_POINTS)
    check = np.concatenate(
        [_lattice(lo, hi, [2 * d for d in deg]), np.column_stack([v[::step] for v in cols])]
    )
    with np.errstate(all="ignore"):
        ref = np.column_stack(
            [np.asarray(v, float) for v in exact(*np.concatenate([nodes, check]).T)]
        )
    if not np.all(np.isfinite(ref)):
        return _exact(exact, cols, shape), info
    V = _monomials((nodes - centre) / half)
    coef = np.linalg.lstsq(V, ref[: nodes.shape[0]], rcond=None)[0]  # (20 terms, n_out)
    coef = np.ascontiguousarray(coef.T)
    got = np.empty((coef.shape[0], check.shape[0]))  # the very kernel that is used below
    _poly3(*(np.ascontiguousarray(v) for v in check.T), centre, 1.0 / half, coef, got)
    got = got.T
    err = np.abs(got - ref[nodes.shape[0] :]).max(axis=0)
    info.update(max_check_error=err.tolist(), n_check=int(check.shape[0]))
    if not np.all(err <= CHECK_MARGIN * tol):
        return _exact(exact, cols, shape), info
    info["approx"] = True
    out = np.empty((coef.shape[0], n))
    _poly3(cols[0], cols[1], cols[2], centre, 1.0 / half, coef, out)
    return tuple(out[k].reshape(shape) for k in range(out.shape[0])), info


def _lattice(lo, hi, deg):
    """The tensor lattice of the axes' Chebyshev–Lobatto nodes, ``(m, 3)``."""
    axes = np.meshgrid(*(_lobatto(lo[i], hi[i], deg[i]) for i in range(3)), indexing="ij")
    return np.stack([g.ravel() for g in axes], axis=1)


def _monomials(S):
    """The 20 monomials of total degree ≤ 3 of scaled points ``S`` (m, 3), in
    :func:`_poly3`'s order.
    """
    e, n, u = S.T
    one = np.ones_like(e)
    return np.column_stack(
        [one, e, n, u, e * e, e * n, e * u, n * n, n * u, u * u]
        + [e * e * e, e * e * n, e * e * u, e * n * n, e * n * u, e * u * u]
        + [n * n * n, n * n * u, n * u * u, u * u * u]
    )


@lru_cache(maxsize=64)
def tolerance_in_units(crs: str, tol_m: float = APPROX_TOL_M) -> tuple[float, float]:
    """``tol_m`` in the units of the first two axes of ``crs`` (anything pyproj reads).

    A linear unit: ``tol_m`` over its metres (a US foot's 0.3048). An angular unit (a
    geographic CRS): ``tol_m`` over the metres of one unit along a meridian or parallel at
    most (6,400 km a radian: the meridian's radius of curvature at the poles, 6,399.6 km, is
    the largest), so that the bound holds in metres everywhere.
    """
    from pyproj import CRS

    c = CRS.from_user_input(crs)
    out = []
    for ax in c.axis_info[:2]:
        f = float(ax.unit_conversion_factor)
        out.append(tol_m / (f * 6.4e6) if c.is_geographic else tol_m / f)
    return out[0], out[1]


def enu_to_map(frame, E_m, N_m, U_m, tol_m: float = APPROX_TOL_M):
    """:meth:`hsgeo.crs.LocalFrame.enu_to_map` within ``tol_m`` (verified, else exact)."""
    tol = (*tolerance_in_units(f"EPSG:{int(frame.map_epsg)}", tol_m), tol_m)
    return approx_transform(frame.enu_to_map, (E_m, N_m, U_m), tol)[0]


def map_to_enu(frame, x_m, y_m, z_m, tol_m: float = APPROX_TOL_M):
    """:meth:`hsgeo.crs.LocalFrame.map_to_enu` within ``tol_m`` (verified, else exact)."""
    return approx_transform(frame.map_to_enu, (x_m, y_m, z_m), (tol_m,) * 3)[0]


def _exact(exact, cols, shape):
    return tuple(np.asarray(v, float).reshape(shape) for v in exact(*cols))


@njit(cache=True)
def _poly3(a, b, c, centre, inv_half, coef, out):  # pragma: no cover - compiled
    """The cubic of :func:`_monomials` (coefficients ``coef`` (n_out, 20)) at the points, in
    Horner's form; one output at a time over all points (a loop the compiler vectorises:
    ≈ 5 ns a point and output, 17 ns with the outputs inside the loop over points).
    """
    c0, c1, c2 = centre[0], centre[1], centre[2]
    h0, h1, h2 = inv_half[0], inv_half[1], inv_half[2]
    for o in range(coef.shape[0]):
        k = coef[o]
        k0, k1, k2, k3, k4, k5, k6, k7, k8, k9 = (
            k[0],
            k[1],
            k[2],
            k[3],
            k[4],
            k[5],
            k[6],
            k[7],
            k[8],
            k[9],
        )
        k10, k11, k12, k13, k14, k15 = k[10], k[11], k[12], k[13], k[14], k[15]
        k16, k17, k18, k19 = k[16], k[17], k[18], k[19]
        for p in range(a.size):
            e = (a[p] - c0) * h0
            n = (b[p] - c1) * h1
            u = (c[p] - c2) * h2
            out[o, p] = (
                k0
                + e * (k1 + e * (k4 + e * k10 + n * k11 + u * k12) + n * (k5 + n * k13 + u * k14)
                       + u * (k6 + u * k15))
                + n * (k2 + n * (k7 + n * k16 + u * k17) + u * (k8 + u * k18))
                + u * (k3 + u * (k9 + u * k19))
            )  # fmt: skip


@njit(cache=True)
def _bounds(a, b, c):  # pragma: no cover - compiled
    """(lo, hi) of three columns in one pass; NaN anywhere makes both NaN."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    bad = False
    for p in range(a.size):
        for j in range(3):
            v = a[p] if j == 0 else (b[p] if j == 1 else c[p])
            if v != v:
                bad = True
            if v < lo[j]:
                lo[j] = v
            if v > hi[j]:
                hi[j] = v
    if bad:
        lo[:] = np.nan
        hi[:] = np.nan
    return lo, hi
