"""Direct georeferencing: any sensor's rays, intersected with the terrain.

This module knows no particular sensor: a sensor of :mod:`hsgeo.sensors` gives the rays of its
pixels (``rays(pixels, t_s, trajectory)``, origins and unit directions in the map frame, see
:mod:`hsgeo.sensors.mount`), and :func:`intersect` meets them with the terrain. The map frame is
a local east-north-up frame in metres (E, N, U); the 000 paper's y is E, x is N.

A ray ``X(s) = O + s·d`` (``O`` the projection centre in the map frame, ``d`` its direction) is
intersected with a plane of constant height in closed form, or with a DEM by fixed-point iteration
on the height (:func:`intersect`).

The 000 line scanner's geometries (``LineGeometry``, ``LinearIFOV``, ``CalibratedLine``,
``ray_directions``) and its GCP boresight calibration (``BoresightGCP``,
``calibrate_boresight``) live in :mod:`hsgeo.sensors.line`; they are re-exported here for
existing callers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import ConvergenceError, InputError, ObservationError
from hsgeo.sensors import as_sensor
from hsgeo.sensors.line import (
    BoresightGCP,
    CalibratedLine,
    LinearIFOV,
    LineGeometry,
    calibrate_boresight,
    ray_directions,
)

__all__ = [
    "LineGeometry",
    "LinearIFOV",
    "CalibratedLine",
    "PlaneTerrain",
    "DemTerrain",
    "intersect",
    "ray_directions",
    "geocode_rays",
    "geocode_observations",
    "BoresightGCP",
    "calibrate_boresight",
]


@dataclass(frozen=True)
class PlaneTerrain:
    """A horizontal plane at ``height_m`` (map U)."""

    height_m: float = 0.0

    @property
    def mean_height_m(self) -> float:
        return self.height_m

    def height(self, E, N):
        return np.full(np.broadcast(E, N).shape, self.height_m)


class DemTerrain:
    """A digital elevation model on a regular grid, bilinearly interpolated.

    Parameters
    ----------
    dem : xarray.DataArray
        Heights in metres with 1-D coordinates ``E`` and ``N`` (metres, ascending or descending).
    """

    def __init__(self, dem):
        if not {"E", "N"} <= set(dem.dims):
            raise InputError(f"the DEM needs dimensions E and N, got {dem.dims}")
        d = dem.transpose("N", "E").sortby("N").sortby("E")
        z = np.asarray(d.values, dtype=float)
        if not np.all(np.isfinite(z)):
            raise InputError("the DEM has NaN cells: fill them before geocoding")
        from scipy.interpolate import RegularGridInterpolator

        self._f = RegularGridInterpolator(
            (d["N"].values, d["E"].values),
            z,
            method="linear",
            bounds_error=False,
            fill_value=np.nan,
        )
        self.mean_height_m = float(z.mean())
        self.extent = (
            float(d["E"].min()),
            float(d["E"].max()),
            float(d["N"].min()),
            float(d["N"].max()),
        )

    def height(self, E, N):
        E, N = np.broadcast_arrays(np.asarray(E, float), np.asarray(N, float))
        h = self._f(np.stack([N.ravel(), E.ravel()], axis=1)).reshape(E.shape)
        if np.any(~np.isfinite(h)):
            raise ObservationError(
                f"{int(np.sum(~np.isfinite(h)))} rays reach the ground outside the DEM "
                f"(E {self.extent[0]:.0f}…{self.extent[1]:.0f}, N {self.extent[2]:.0f}…"
                f"{self.extent[3]:.0f} m): extend the DEM or give a plane height"
            )
        return h


def intersect(origin_m, direction, terrain, *, tol_m: float = 1e-4, max_iter: int = 100):
    """Intersect rays with the terrain.

    Parameters
    ----------
    origin_m : (n, 3) ndarray
        Projection centres (E, N, U).
    direction : (n, 3) ndarray
        Ray directions in the map frame (any length; must point downwards).
    terrain : PlaneTerrain or DemTerrain or object with ``height(E, N)``
    tol_m : float
        Convergence of the height iteration on a DEM.

    Returns
    -------
    (n, 3) ndarray
        Ground points (E, N, U).
    """
    O = np.atleast_2d(np.asarray(origin_m, dtype=float))
    d = np.atleast_2d(np.asarray(direction, dtype=float))
    if O.shape[-1] != 3 or d.shape != O.shape:
        raise InputError(f"origin and direction must both be (n, 3), got {O.shape}, {d.shape}")
    if not (np.all(np.isfinite(O)) and np.all(np.isfinite(d))):
        raise InputError("ray origins or directions contain NaN or inf")
    if np.any(d[:, 2] >= -1e-9 * np.linalg.norm(d, axis=1)):
        raise ObservationError(
            f"{int(np.sum(d[:, 2] >= 0))} rays do not point downwards; the likely causes: "
            "an attitude of another convention (roll or pitch near 180°: the body upside down, "
            "or z up instead of down), angles in radians where degrees are expected, or the "
            "boresight"
        )
    h = np.full(O.shape[0], terrain.mean_height_m)
    lo, hi = h.copy(), h.copy()  # the heights the iteration visited, per ray
    for _ in range(max_iter):
        s = (h - O[:, 2]) / d[:, 2]
        X = O + s[:, None] * d
        if isinstance(terrain, PlaneTerrain):
            return X
        h_new = terrain.height(X[:, 0], X[:, 1])
        lo, hi = np.minimum(lo, h_new), np.maximum(hi, h_new)
        bad = np.abs(h_new - h) >= tol_m
        if not bad.any():
            X[:, 2] = h_new
            return X
        h = h_new
    # At a step of the DSM (a wall steeper than the ray) the fixed-point iteration jumps between
    # the levels: those rays are marched down between the heights it visited and bisected
    X[bad] = _march_bisect(O[bad], d[bad], terrain, hi[bad] + 1.0, lo[bad] - 1.0, tol_m)
    X[~bad, 2] = h_new[~bad]
    return X


def _march_bisect(O, d, terrain, top_m, bottom_m, tol_m, step_m: float = 0.25):
    """The first crossing of each ray (``(n, 3)`` origins, directions) with the terrain between
    the heights ``top_m`` and ``bottom_m`` (``(n,)``): a march down in steps of ``step_m`` in
    height, then bisection to ``tol_m``.
    """

    def above(hr):  # is the ray's point at height hr above the terrain?
        P = O + ((hr - O[:, 2]) / d[:, 2])[:, None] * d
        return hr > terrain.height(P[:, 0], P[:, 1])

    a = top_m.copy()  # above the terrain
    b = np.full_like(a, np.nan)  # the first height below it
    n_steps = int(np.ceil(np.max(top_m - bottom_m) / step_m)) + 1
    for k in range(1, n_steps + 1):
        hk = np.maximum(top_m - k * step_m, bottom_m)
        todo = np.isnan(b)
        if not todo.any():
            break
        up = above(hk)
        hit = todo & ~up
        b[hit] = hk[hit]
        a[todo & up] = hk[todo & up]
    if np.isnan(b).any():
        raise ConvergenceError(
            f"the ray–DEM intersection did not converge for {int(np.isnan(b).sum())} rays "
            "(the ray does not cross the DSM between the heights the iteration visited)"
        )
    while np.max(a - b) > tol_m:
        m = 0.5 * (a + b)
        up = above(m)
        a, b = np.where(up, m, a), np.where(up, b, m)
    return O + ((b - O[:, 2]) / d[:, 2])[:, None] * d


# ----------------------------------------------------------------------------------------------
# Geocoding of any sensor's pixels (the GCP calibration of the boresight: hsgeo.sensors.line)
# ----------------------------------------------------------------------------------------------
def geocode_rays(sensor, pixels, t_s, trajectory, terrain, **pixel_kwargs) -> np.ndarray:
    """Ground coordinates of pixels of any sensor: its rays (``sensor.rays``) meet the terrain.

    Parameters
    ----------
    sensor : a sensor of :mod:`hsgeo.sensors` (the interface of :mod:`hsgeo.sensors.mount`)
        A scanning sensor with ``rays(pixels, t_s, trajectory, **pixel_kwargs)``.
    pixels : (n,) or (n, 2) ndarray
        The sensor's pixel coordinates (ζ of a line scanner, ``(x, y)`` of a pushbroom camera).
    t_s : (n,) ndarray, s
    trajectory : hsgeo.trajectory.Trajectory
    terrain : PlaneTerrain or DemTerrain
    **pixel_kwargs
        What else the sensor's ``rays`` takes per pixel (``band=`` of a pushbroom camera).

    Returns
    -------
    (n, 3) ndarray of (E, N, U)
    """
    o, d = sensor.rays(pixels, t_s, trajectory, **pixel_kwargs)
    return intersect(o, d, terrain)


def geocode_observations(
    nav,
    sensor,
    line,
    zeta_px,
    *,
    t0_s: float,
    line_rate_hz: float,
    terrain,
    boresight_rad=None,
    **pixel_kwargs,
):
    """Ground coordinates of observations (fractional line, pixel) of a scanning sensor.

    Parameters
    ----------
    nav : hsgeo.trajectory.Trajectory
        Recorded navigation of the body.
    sensor : a scanning sensor of :mod:`hsgeo.sensors`, or a LineGeometry
        A bare :class:`~hsgeo.sensors.line.LineGeometry` (the 000 inner geometry) is mounted
        with ``boresight_rad`` (:func:`hsgeo.sensors.as_sensor`).
    line : (n,) ndarray
        Line numbers (time ``t0_s + line / line_rate_hz``; fractional for sub-line centroids).
    zeta_px : (n,) or (n, 2) ndarray
        The sensor's pixel coordinates.
    terrain : PlaneTerrain or DemTerrain
    boresight_rad : (3,) sequence, optional
        Roll, pitch, heading of ``R_body_from_sensor`` of a bare LineGeometry.

    Returns
    -------
    (n, 3) ndarray of (E, N, U)
    """
    line = np.asarray(line, dtype=float)
    t = t0_s + line / line_rate_hz
    return geocode_rays(as_sensor(sensor, boresight_rad), zeta_px, t, nav, terrain, **pixel_kwargs)
