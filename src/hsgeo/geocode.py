"""Direct georeferencing: any sensor's rays, intersected with the terrain.

This module knows no particular sensor: a sensor of :mod:`hsgeo.sensors` gives the rays of its
pixels (``rays(pixels, t_s, trajectory)``, origins and unit directions in the map frame, see
:mod:`hsgeo.sensors.mount`), and :func:`intersect` meets them with the terrain. The map frame is
a local east-north-up frame in metres (E, N, U); the 000 paper's y is E, x is N.

A ray ``X(s) = O + s·d`` (``O`` the projection centre in the map frame, ``d`` its direction) is
intersected with a plane of constant height in closed form, or with a DEM or DSM at its FIRST
crossing (:func:`intersect`): the compiled grid traversal of :mod:`hsgeo._raycast`, the one
intersection of every command and every simulator's renderer.

The 000 line scanner's geometries and its GCP boresight calibration live in
:mod:`hsgeo.sensors.line`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo._raycast import (
    BELOW,
    HIT,
    OUTSIDE,
    GridSurface,
    cast_chords,
    first_crossing_reference,
    first_crossing_rows,
)
from hsgeo.errors import InputError, ObservationError
from hsgeo.sensors import as_sensor

__all__ = [
    "PlaneTerrain",
    "DemTerrain",
    "intersect",
    "geocode_rays",
    "geocode_observations",
    "cast_rays",
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
        Heights in metres with 1-D coordinates ``E`` and ``N`` (metres, ascending or descending;
        evenly spaced for the compiled intersection, else :func:`intersect` marches).
    """

    def __init__(self, dem):
        if not {"E", "N"} <= set(dem.dims):
            raise InputError(f"the DEM needs dimensions E and N, got {dem.dims}")
        d = dem.transpose("N", "E").sortby("N").sortby("E")
        z = np.asarray(d.values, dtype=float)
        if not np.all(np.isfinite(z)):
            raise InputError("the DEM has NaN cells: fill them before geocoding")
        if z.shape[0] < 2 or z.shape[1] < 2:
            raise InputError(f"the DEM needs at least 2 x 2 cells, got {z.shape[::-1]} (E x N)")
        from scipy.interpolate import RegularGridInterpolator

        E, N = np.asarray(d["E"].values, float), np.asarray(d["N"].values, float)
        self._f = RegularGridInterpolator(
            (N, E), z, method="linear", bounds_error=False, fill_value=np.nan
        )
        self.mean_height_m = float(z.mean())
        self.height_range_m = (float(z.min()), float(z.max()))
        self.cell_m = float(min(np.diff(E).min(), np.diff(N).min()))
        self.extent = (float(E[0]), float(E[-1]), float(N[0]), float(N[-1]))
        even = all(
            np.allclose(np.diff(c), (c[-1] - c[0]) / (c.size - 1), rtol=1e-9, atol=0)
            for c in (E, N)
        )
        #: the grid for the compiled intersection (None: the coordinates are not evenly spaced)
        self.surface = (
            GridSurface.from_heights(
                z, E[0], N[0], (E[-1] - E[0]) / (E.size - 1), (N[-1] - N[0]) / (N.size - 1)
            )
            if even
            else None
        )

    def height(self, E, N, *, outside: str = "raise"):
        """Bilinear height at (E, N); outside the DEM an error (``outside="raise"``) or NaN."""
        E, N = np.broadcast_arrays(np.asarray(E, float), np.asarray(N, float))
        h = self._f(np.stack([N.ravel(), E.ravel()], axis=1)).reshape(E.shape)
        if outside == "raise" and np.any(~np.isfinite(h)):
            raise ObservationError(self._outside_message(int(np.sum(~np.isfinite(h)))))
        return h

    def _outside_message(self, n: int) -> str:
        return (
            f"{n} rays reach the ground outside the DEM "
            f"(E {self.extent[0]:.0f}…{self.extent[1]:.0f}, N {self.extent[2]:.0f}…"
            f"{self.extent[3]:.0f} m): extend the DEM or give a plane height"
        )


def intersect(
    origin_m,
    direction,
    terrain,
    *,
    tol_m: float = 1e-7,
    max_iter: int | None = None,
    on_miss: str = "raise",
    crs_tol_m: float | None = None,
):
    """The first crossing of rays with the terrain.

    A ray ``X(s) = O + s·d`` meets a :class:`PlaneTerrain` in closed form; a terrain on a grid
    (:class:`DemTerrain`, :class:`hsgeo.mapgrid.MapTerrain`) at its FIRST crossing with the
    bilinear surface, by the compiled grid traversal of :mod:`hsgeo._raycast` (exact to
    rounding: a roof occludes the ground behind it, a wall steeper than the ray is met on the
    wall). A DEM whose coordinates are not evenly spaced, or another terrain with
    ``height(E, N, outside="nan")``, ``height_range_m`` and ``cell_m``, is marched down each ray
    in steps of a quarter cell and bisected to ``tol_m``
    (:func:`hsgeo._raycast.first_crossing_reference`).

    Parameters
    ----------
    origin_m : (n, 3) ndarray
        Projection centres (E, N, U).
    direction : (n, 3) ndarray
        Ray directions in the map frame (any length; must point downwards).
    terrain : PlaneTerrain, DemTerrain, MapTerrain or a terrain as above
    tol_m : float
        The march's bisection end (the grids' traversal needs none).
    max_iter : None
        Ignored (the former height iteration's limit, kept for callers).
    on_miss : {"raise", "nan"}
        A ray that leaves the terrain's grid before it meets the surface, or starts under it:
        an :class:`~hsgeo.errors.ObservationError` naming the count and the grid's extent
        (``"raise"``), or a row of NaN (``"nan"``).
    crs_tol_m : float, optional
        A DSM in a map CRS (:class:`~hsgeo.mapgrid.MapTerrain`): the frame's PROJ transforms
        of the chords replaced by a polynomial within this bound, verified against PROJ
        (:mod:`hsgeo._approx_transform`, e.g. its ``APPROX_TOL_M``, 1 mm); None: PROJ on
        every point.

    Returns
    -------
    (n, 3) ndarray
        Ground points (E, N, U).
    """
    del max_iter
    O = np.atleast_2d(np.asarray(origin_m, dtype=float))
    d = np.atleast_2d(np.asarray(direction, dtype=float))
    if O.shape[-1] != 3 or d.shape != O.shape:
        raise InputError(f"origin and direction must both be (n, 3), got {O.shape}, {d.shape}")
    if not (np.all(np.isfinite(O)) and np.all(np.isfinite(d))):
        raise InputError("ray origins or directions contain NaN or inf")
    if on_miss not in ("raise", "nan"):
        raise InputError(f'on_miss must be "raise" or "nan", got {on_miss!r}')
    if np.any(d[:, 2] >= -1e-9 * np.linalg.norm(d, axis=1)):
        raise ObservationError(
            f"{int(np.sum(d[:, 2] >= 0))} rays do not point downwards; the likely causes: "
            "an attitude of another convention (roll or pitch near 180°: the body upside down, "
            "or z up instead of down), angles in radians where degrees are expected, or the "
            "boresight"
        )
    if isinstance(terrain, PlaneTerrain):
        s = (terrain.height_m - O[:, 2]) / d[:, 2]
        X = O + s[:, None] * d
        if np.any(s < 0):
            return _missed(X, s < 0, np.zeros(s.size, bool), terrain, on_miss)
        return X
    surface = getattr(terrain, "surface", None)
    if isinstance(surface, GridSurface):
        s, status = cast_rays(O, d, surface)
        X = O + s[:, None] * d
    elif getattr(terrain, "map_surface", None) is not None:
        X, status = _intersect_map(O, d, terrain, crs_tol_m)
    else:
        X, status = _intersect_marching(O, d, terrain, tol_m)
    bad = status != HIT
    if bad.any():
        return _missed(X, status == BELOW, status == OUTSIDE, terrain, on_miss)
    return X


def cast_rays(O, d, surface: GridSurface):
    """The compiled first crossing of rays ``O + s d`` ((n, 3) each) with a grid surface.

    Returns
    -------
    s : (n,) ndarray
        Ray parameters (NaN where the status is not :data:`~hsgeo._raycast.HIT`).
    status : (n,) int8 ndarray
    """
    O = np.ascontiguousarray(O, dtype=np.float64)
    d = np.ascontiguousarray(d, dtype=np.float64)
    s = np.empty(O.shape[0])
    status = np.empty(O.shape[0], np.int8)
    if O.shape[0]:
        first_crossing_rows(O, d, *surface.args(), s, status)
    return s, status


def _missed(X, below, outside, terrain, on_miss):
    """Rays that met nothing: NaN rows, or the error that says why."""
    if on_miss == "nan":
        X[below | outside] = np.nan
        return X
    if outside.any():
        msg = getattr(terrain, "_outside_message", None)
        raise ObservationError(
            msg(int(outside.sum()))
            if msg
            else f"{int(outside.sum())} rays reach the ground outside the terrain's grid: "
            "give a DEM or DSM that covers the lines"
        )
    source = getattr(terrain, "source", None)
    where = f"{source} (the DSM)" if source else "the terrain"
    raise ObservationError(
        f"{int(below.sum())} rays start under {where} (a projection centre below the DSM or DEM, "
        "or a plane above the sensor): check that the navigation's heights and the terrain's "
        "are in the same vertical datum (ellipsoidal or orthometric) and units (metres)"
    )


def _intersect_marching(O, d, terrain, tol_m):
    """The numpy reference for a terrain with only ``height(E, N, outside="nan")``,
    ``height_range_m`` and ``cell_m`` (a quarter cell's step).
    """
    for a in ("height_range_m", "cell_m"):
        if not hasattr(terrain, a):
            raise InputError(
                f"the terrain {type(terrain).__name__} has no {a}: give a PlaneTerrain, a "
                "DemTerrain or a MapTerrain"
            )
    s = first_crossing_reference(
        O,
        d,
        lambda E, N: terrain.height(E, N, outside="nan"),
        terrain.height_range_m,
        0.25 * terrain.cell_m,
        tol_m,
    )
    X = O + s[:, None] * d
    below = np.isnan(s) & (O[:, 2] < terrain.height_range_m[1])
    below &= ~(terrain.height(O[:, 0], O[:, 1], outside="nan") < O[:, 2])
    below &= np.isfinite(terrain.height(O[:, 0], O[:, 1], outside="nan"))
    status = np.where(np.isfinite(s), HIT, np.where(below, BELOW, OUTSIDE))
    return X, status


def _intersect_map(O, d, terrain, crs_tol_m=None):
    """The first crossing with a DSM on a grid of a map CRS (:class:`hsgeo.mapgrid.MapTerrain`).

    The ray between the heights the DSM spans is a straight line in the local frame and very
    nearly one in the map CRS (x, y, ellipsoidal h): its chord between those heights, taken to
    the map CRS by the frame, is cast on the DSM's own grid (compiled, exact), and the crossing
    is taken back. The chord departs from the ray's image by about L²/(8 R) (L its length, R the
    Earth's radius: 2 µm for 11 m of relief, 0.2 mm for 100 m); a chord longer than 10 m is cast
    a second time, 1 m about the first crossing.
    """
    frame, surf = terrain.frame, terrain.map_surface
    u_lo, u_hi = terrain.u_range_m
    X, status = _cast_chord(O, d, u_hi, u_lo, frame, surf, crs_tol_m)
    span = (u_hi - u_lo) * np.linalg.norm(d, axis=1) / -d[:, 2]
    again = (status == HIT) & (span > 10.0)
    if again.any():
        k = np.flatnonzero(again)
        X2, st2 = _cast_chord(O[k], d[k], X[k, 2] + 1.0, X[k, 2] - 1.0, frame, surf, crs_tol_m)
        ok = st2 == HIT
        X[k[ok]] = X2[ok]
    return X, status


def _cast_chord(O, d, u_top, u_bottom, frame, surf, crs_tol_m=None):
    """Cast the chords of rays between local heights ``u_top`` and ``u_bottom`` in the map CRS;
    the crossings in the local frame, projected onto the rays, and the status (``crs_tol_m``:
    :func:`intersect`'s).
    """
    to_map, to_enu = frame.enu_to_map, frame.map_to_enu
    if crs_tol_m is not None:
        from hsgeo import _approx_transform as ax

        def to_map(E, N, U):
            return ax.enu_to_map(frame, E, N, U, crs_tol_m)

        def to_enu(x, y, z):
            return ax.map_to_enu(frame, x, y, z, crs_tol_m)

    return cast_chords(O, d, u_top, u_bottom, to_map, to_enu, surf)


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
