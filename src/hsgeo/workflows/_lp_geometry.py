"""Geometry helpers of :mod:`hsgeo.workflows.lp_observations`: footprints on a plane, convex
overlap, the line that sees a ground point.

Kept apart so the workflow module stays one pipeline; nothing here is specific to a user's
files.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import ObservationError
from hsgeo.geocode import PlaneTerrain, intersect

__all__ = [
    "ground_points",
    "footprint",
    "convex_overlap",
    "convex_edges",
    "inside_convex",
    "crossing_lines",
]


def ground_points(camera, x_px, t_s, trajectory, band, height_m: float) -> np.ndarray:
    """Ground points ``(n, 3)`` of pixels ``x_px`` (on the line, y = 0) at times ``t_s`` on the
    plane at ``height_m`` (the a-priori camera and the navigation).
    """
    xy = np.column_stack([np.asarray(x_px, float), np.zeros(np.size(x_px))])
    o, d = camera.rays(xy, np.asarray(t_s, float), trajectory, band=band)
    return intersect(o, d, PlaneTerrain(float(height_m)))


def footprint(camera, x_first_last_px, t_first_last_s, trajectory, height_m) -> np.ndarray:
    """The quadrilateral ``(4, 2)`` (E, N) a scene covers, counter-clockwise: the rays of its
    first and last column at its first and last line on the plane.
    """
    x0, x1 = x_first_last_px
    t0, t1 = t_first_last_s
    g = ground_points(camera, [x0, x1, x1, x0], [t0, t0, t1, t1], trajectory, 0, height_m)
    P = g[:, :2]
    return _ccw(P)


def _ccw(P: np.ndarray) -> np.ndarray:
    x, y = P[:, 0], P[:, 1]
    area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    return P if area >= 0 else P[::-1].copy()


def _edges(P):
    """Outward unit normals and offsets of a convex polygon's edges (either orientation)."""
    P = _ccw(np.asarray(P, float))
    e = np.roll(P, -1, axis=0) - P
    n = np.column_stack([e[:, 1], -e[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return n, np.einsum("ij,ij->i", n, P)


def convex_overlap(P, Q, margin_m: float = 0.0) -> bool:
    """Whether two convex polygons (``(k, 2)``, either orientation) overlap, or come within
    ``margin_m`` (the separating-axis theorem over both polygons' edge normals).
    """
    for A, B in ((P, Q), (Q, P)):
        n, c = _edges(A)
        # B lies entirely outside an edge of A (beyond the margin): separated
        if np.any(np.min(B @ n.T, axis=0) - c > margin_m):
            return False
    return True


def convex_edges(P) -> tuple[np.ndarray, np.ndarray]:
    """A convex polygon's edges as :func:`inside_convex` uses them (``edges=``): computed once
    for a polygon tested against many point sets.
    """
    return _edges(P)


def inside_convex(points, P, margin_m: float = 0.0, *, edges=None) -> np.ndarray:
    """Points ``(n, 2)`` inside a convex polygon (either orientation), or within ``margin_m``;
    ``edges``: the polygon's :func:`convex_edges`, when already computed (``P`` is then unused).
    """
    n, c = _edges(P) if edges is None else edges
    return np.all(np.asarray(points, float) @ n.T - c <= margin_m, axis=1)


def crossing_lines(camera, xyz_m, t_lines_s, trajectory, band: int = 0):
    """The line of a strip that sees each ground point, and where along it.

    The image y of every point at every line time (:meth:`PushbroomCamera.project`) changes
    sign where the line sweeps over it; linear interpolation between the two lines gives the
    fractional line.

    Parameters
    ----------
    xyz_m : (k, 3) ndarray
    t_lines_s : (n,) ndarray
        The strip's line times.

    Returns
    -------
    line : (k,) ndarray
        Fractional line index (NaN where the strip does not sweep over the point).
    x_px : (k,) ndarray
        x at that line (NaN likewise).
    """
    xyz = np.atleast_2d(np.asarray(xyz_m, float))
    t = np.asarray(t_lines_s, float)
    k, n = xyz.shape[0], t.size
    P = np.repeat(xyz, n, axis=0)
    T = np.tile(t, k)
    try:
        xy = camera.project(P, T, trajectory, band=band).reshape(k, n, 2)
    except ObservationError:  # a point behind the camera: the strip does not see it
        return np.full(k, np.nan), np.full(k, np.nan)
    y = xy[..., 1]
    line = np.full(k, np.nan)
    x = np.full(k, np.nan)
    s = np.sign(y)
    for i in range(k):
        j = np.flatnonzero(s[i, :-1] * s[i, 1:] <= 0)
        if j.size == 0:
            continue
        j = j[np.argmin(np.abs(y[i, j]))]
        f = y[i, j] / (y[i, j] - y[i, j + 1]) if y[i, j] != y[i, j + 1] else 0.0
        line[i] = j + f
        x[i] = xy[i, j, 0] + f * (xy[i, j + 1, 0] - xy[i, j, 0])
    return line, x
