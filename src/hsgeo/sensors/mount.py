"""The one sensor interface: a :class:`Mount` on a body, and what every geometry offers.

Every sensor geometry in :mod:`hsgeo.sensors` has the same face (after COLMAP's ``Rig`` and
the Ames Stereo Pipeline's camera models):

* ``rays(pixels, …) → (origins_m, directions)``: for each pixel the projection centre and the
  unit direction of its ray, both in the **map** frame (east-north-up, metres);
* ``project(xyz_map_m, …) → pixels``: the pixel that sees a map point.

What ``…`` is depends on how the sensor moves. A frame camera takes its exposure poses; a
scanning sensor (the 000 line scanner, the 002 pushbroom camera, a panoramic whiskbroom) takes
a time per pixel and one :class:`hsgeo.trajectory.Trajectory` (timed poses of the **body**,
x forward, y right, z down), so that a whiskbroom, whose samples along one scan are taken at
different times, fits the same call. ``project`` of a scanning sensor is the pinhole
projection at the given times (``(along, across)`` pixels; ``across`` is zero on the line);
finding the time at which a point is on the line is the sensor's ``line_time``.

The sensor sits on the body with one :class:`Mount`: the lever arm (projection centre in the
body frame, m) and the boresight ``R_body_from_sensor``::

    origin    = xyz_body(t) + R_map_from_body(t) · lever_arm_m
    direction = R_map_from_body(t) · R_body_from_sensor · d_sensor

:class:`Sensor` is that contract as a :class:`typing.Protocol` (documentation and static
checks; nothing inherits from it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from hsgeo.errors import ConvergenceError, InputError, ObservationError
from hsgeo.rotations import R_from_rpy

__all__ = ["Mount", "OnTrajectory", "Sensor", "line_time", "unit"]


def _matrix3(a, name: str) -> np.ndarray:
    m = np.array(a, dtype=np.float64)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise InputError(f"{name} must be a finite 3×3 rotation matrix, got shape {m.shape}")
    if not np.allclose(m @ m.T, np.eye(3), atol=1e-9) or np.linalg.det(m) < 0:
        raise InputError(f"{name} is not a rotation (orthonormal, determinant +1)")
    m.setflags(write=False)
    return m


@dataclass(frozen=True)
class Mount:
    """Where a sensor sits on the body: lever arm and boresight.

    Parameters
    ----------
    lever_arm_m : (3,) array_like, m
        Projection centre of the sensor in the body frame (x forward, y right, z down),
        relative to the navigation reference point.
    R_body_from_sensor : (3, 3) array_like
        Boresight: takes sensor-frame vectors to the body frame.
    """

    lever_arm_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    R_body_from_sensor: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self):
        lever = np.array(self.lever_arm_m, dtype=np.float64)
        if lever.shape != (3,) or not np.all(np.isfinite(lever)):
            raise InputError(f"lever_arm_m must be 3 finite numbers, got {self.lever_arm_m!r}")
        lever.setflags(write=False)
        object.__setattr__(self, "lever_arm_m", lever)
        object.__setattr__(
            self, "R_body_from_sensor", _matrix3(self.R_body_from_sensor, "R_body_from_sensor")
        )

    @classmethod
    def from_rpy(cls, boresight_rad=(0.0, 0.0, 0.0), lever_arm_m=(0.0, 0.0, 0.0)) -> Mount:
        """A mount whose boresight is ``R_body_from_sensor = R_from_rpy(roll, pitch, heading)``
        (the convention of the 000 sensor file's ``boresight_deg``).
        """
        return cls(np.asarray(lever_arm_m, float), R_from_rpy(*np.asarray(boresight_rad, float)))

    def origins(self, xyz_body_m, R_map_from_body) -> np.ndarray:
        """Projection centres in the map frame, ``(n, 3)``: ``xyz + R_map_from_body · lever``."""
        xyz = np.atleast_2d(np.asarray(xyz_body_m, dtype=np.float64))
        if not self.lever_arm_m.any():
            return xyz.copy()
        return xyz + np.asarray(R_map_from_body) @ self.lever_arm_m

    def R_map_from_sensor(self, R_map_from_body) -> np.ndarray:
        """The sensor-to-map rotations ``R_map_from_body · R_body_from_sensor``, ``(n, 3, 3)``:
        :meth:`directions`' rotation formed once per pose (for many directions at one pose).
        """
        return np.ascontiguousarray(np.asarray(R_map_from_body) @ self.R_body_from_sensor)

    def directions(self, R_map_from_body, d_sensor) -> np.ndarray:
        """Sensor-frame directions ``(n, 3)`` in the map frame (not normalised)."""
        d_body = np.asarray(d_sensor, dtype=np.float64) @ self.R_body_from_sensor.T
        return np.einsum("nij,nj->ni", np.asarray(R_map_from_body), d_body)

    def to_sensor(self, xyz_map_m, xyz_body_m, R_map_from_body) -> np.ndarray:
        """Map points in the sensor frame (centred on the projection centre), ``(n, 3)``."""
        R = np.asarray(R_map_from_body)
        d = np.atleast_2d(np.asarray(xyz_map_m, float)) - self.origins(xyz_body_m, R)
        d_body = np.einsum("nji,nj->ni", R, d)  # R_map_from_bodyᵀ d
        return d_body @ self.R_body_from_sensor  # R_body_from_sensorᵀ d_body

    # ---- a sensor carried along a trajectory (line, panoramic) ---------------------------------
    def rays_along(self, d_sensor, t_s, trajectory) -> tuple[np.ndarray, np.ndarray]:
        """Origins (m) and unit map-frame directions of sensor-frame directions ``d_sensor``
        ``(n, 3)`` taken at times ``t_s`` on ``trajectory`` (:class:`hsgeo.trajectory.Trajectory`).
        """
        pos, _ = trajectory.pose(t_s)
        R = trajectory.R_map_from_body(t_s)
        return self.origins(pos, R), unit(self.directions(R, d_sensor))

    def sensor_points_along(self, xyz_map_m, t_s, trajectory, sensor: str = "sensor"):
        """Map points in the sensor frame at times ``t_s`` on ``trajectory``, ``(n, 3)``; an
        :class:`~hsgeo.errors.ObservationError` naming ``sensor`` for points behind it (z ≤ 0).
        """
        pos, _ = trajectory.pose(t_s)
        p = self.to_sensor(xyz_map_m, pos, trajectory.R_map_from_body(t_s))
        if np.any(p[:, 2] <= 0):
            raise ObservationError(f"points behind the {sensor} (sensor z ≤ 0)")
        return p


@dataclass(frozen=True)
class OnTrajectory:
    """A frame camera carried along a body trajectory, with the scanning sensors' face
    ``rays(pixels, t_s, trajectory, **kw)``: every pixel exposed at its time ``t_s`` (a frame's
    exposure time), through the camera's ``rays_along`` (the body's pose at that time composed
    with the camera's :class:`Mount`). What ``hsgeo orthorectify`` geolocates frames with.
    """

    camera: object

    @property
    def mount(self) -> Mount:
        return self.camera.mount

    def rays(self, pixels, t_s, trajectory, **kw) -> tuple[np.ndarray, np.ndarray]:
        """Origins (m) and unit map-frame directions of pixels ``(n, 2)`` at times ``t_s``."""
        return self.camera.rays_along(pixels, t_s, trajectory, **kw)


def unit(d) -> np.ndarray:
    """Rows of ``d`` scaled to unit length."""
    d = np.asarray(d, dtype=np.float64)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


@runtime_checkable
class Sensor(Protocol):
    """The face every sensor geometry offers (see the module docstring)."""

    def rays(self, pixels, *args, **kwargs) -> tuple[np.ndarray, np.ndarray]:
        """``(origins_m (n, 3), unit directions (n, 3))`` in the map frame."""
        ...

    def project(self, xyz_map_m, *args, **kwargs) -> np.ndarray:
        """Pixels that see the map points ``(n, 3)``."""
        ...


def line_time(across_px, xyz_map_m, trajectory, t_start_s, tol_s=1e-10, max_iter=30) -> np.ndarray:
    """Secant iteration on ``across_px(X, t) = 0``: when a scanning sensor sees each point, s.

    Shared by the scanning sensors (line, pushbroom, panoramic, view angle): ``across_px`` is the
    point's offset from the scan line at time ``t``. Each offers it with one signature,
    ``sensor.line_time(xyz_map_m, trajectory, t_start_s, *, band=None, tol_s=1e-10,
    max_iter=30)`` (``band`` chooses the line of a sensor whose bands differ).
    """
    X = np.atleast_2d(np.asarray(xyz_map_m, dtype=float))
    lo, hi = trajectory.t_s[0], trajectory.t_s[-1]
    t0 = np.clip(np.broadcast_to(np.asarray(t_start_s, float), (X.shape[0],)).copy(), lo, hi)
    step = 1e-3
    t1 = np.clip(t0 + step, lo, hi)
    t1 = np.where(t1 == t0, t0 - step, t1)
    f0 = across_px(X, t0)
    for _ in range(max_iter):
        f1 = across_px(X, t1)
        den = f1 - f0
        safe = np.where(den == 0, 1.0, den)
        t2 = np.clip(np.where(den == 0, t1, t1 - f1 * (t1 - t0) / safe), lo, hi)
        if np.all(np.abs(t2 - t1) < tol_s):
            return t2
        t0, f0, t1 = t1, f1, t2
    raise ConvergenceError("the line time of a point did not converge (is it under the flight?)")
