"""The 000 line scanner's geometry: pixel ζ ↔ across-track view angle, and its rays.

The inner geometry (:class:`LineGeometry`): the uncalibrated linear-IFOV model
(:class:`LinearIFOV`) and the calibrated model of 000 eq. (2) in its ray form
(:class:`CalibratedLine`, the equations in :mod:`hsgeo.sensors.line1d`).

Frames: **body** x forward, y right, z down (a GNSS/INS attitude, NED); **sensor** like body,
looking down with its pixel line along y: pixel ζ sees the direction ``(0, t(ζ), 1)``, ``t`` the
tangent of the across-track view angle, positive to the right. The map frame is east-north-up.

:mod:`hsgeo.sensors.line1d` holds the 000 laboratory calibration model (eq. (2) and its
residual blocks); this module holds what a flying line scanner needs of it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

from hsgeo.adjust import Parameters, ResidualBlock, adjust
from hsgeo.errors import ObservationError
from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy, dR_drpy
from hsgeo.sensors import line1d
from hsgeo.sensors.mount import Mount, line_time

__all__ = [
    "LineGeometry",
    "LinearIFOV",
    "CalibratedLine",
    "LineScanner",
    "ray_directions",
    "BoresightGCP",
    "calibrate_boresight",
    "sensor_directions",
]


class LineGeometry:
    """The inner geometry of a line scanner: pixel ζ ↔ tangent of the across-track view angle."""

    def tan_angle(self, zeta_px) -> np.ndarray:
        """Tangent of the view angle (positive to the right) of pixel ζ."""
        raise NotImplementedError

    def zeta(self, tan_angle) -> np.ndarray:
        """The pixel that sees the given tangent (inverse of :meth:`tan_angle`)."""
        raise NotImplementedError


@dataclass(frozen=True)
class LinearIFOV(LineGeometry):
    """The uncalibrated model of Jakšić (2009): the view angle is linear in the pixel distance.

    ``θ = −(ζ − ζ0)·IFOV`` with ``IFOV = 1/c`` (rad per pixel) and no distortion (000 §
    "Verification": "IFOV ... linear function of the distance from the central pixel ... optical
    distortion was neglected").

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """

    zeta0_px: float = 485.0
    c_px: float = 3600.0

    def tan_angle(self, zeta_px):
        return np.tan(-(np.asarray(zeta_px, dtype=float) - self.zeta0_px) / self.c_px)

    def zeta(self, tan_angle):
        return self.zeta0_px - np.arctan(np.asarray(tan_angle, dtype=float)) * self.c_px


@dataclass(frozen=True)
class CalibratedLine(LineGeometry):
    """The calibrated 1D model of 000 eq. (2) in its ray form (:mod:`hsgeo.sensors.line1d`).

    ``ζ = ζ0 − c·tan θ + δ(ζ − ζ0)``, δ the odd 7th-order polynomial in units of 100 px.

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """

    zeta0_px: float
    c_px: float
    K: tuple[float, ...] = (0.0, 0.0, 0.0)

    def tan_angle(self, zeta_px):
        return line1d.tan_from_zeta(zeta_px, self.zeta0_px, self.c_px, self.K)

    def zeta(self, tan_angle):
        return line1d.zeta_from_tan(tan_angle, self.zeta0_px, self.c_px, self.K)


def sensor_directions(tan_angle) -> np.ndarray:
    """Sensor-frame directions ``(0, t, 1)`` ``(n, 3)`` of pixels whose across-track view angle
    has tangent ``t`` (the one place the line scanner's pixel → camera ray is written; the
    tangent comes from :meth:`LineGeometry.tan_angle`).
    """
    t = np.asarray(tan_angle, dtype=float).ravel()
    return np.stack([np.zeros_like(t), t, np.ones_like(t)], axis=1)


def ray_directions(rpy_rad, tan_angle, R_body_from_sensor=None) -> np.ndarray:
    """Map-frame directions of line-scanner pixels.

    Parameters
    ----------
    rpy_rad : (n, 3) ndarray
        INS roll, pitch, heading of the body (NED).
    tan_angle : (n,) ndarray
        Tangent of each pixel's across-track view angle (:class:`LineGeometry`).
    R_body_from_sensor : (3, 3) ndarray, optional
        Boresight misalignment (identity if omitted).

    Returns
    -------
    (n, 3) ndarray
        Unnormalised directions ``R_enu_from_ned R_ned_from_body R_body_from_sensor (0, t, 1)``.
    """
    rpy = np.atleast_2d(np.asarray(rpy_rad, dtype=float))
    d_s = sensor_directions(tan_angle)
    if R_body_from_sensor is not None:
        d_s = d_s @ np.asarray(R_body_from_sensor).T
    R = R_ENU_FROM_NED @ R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    return np.einsum("nij,nj->ni", R, d_s)


@dataclass(frozen=True)
class LineScanner:
    """A line scanner on a moving body: the sensor interface of :mod:`hsgeo.sensors.mount`.

    Parameters
    ----------
    geometry : LineGeometry
        Pixel ζ ↔ tangent of the across-track view angle.
    mount : Mount
        Lever arm and boresight ``R_body_from_sensor`` on the body of the trajectory.

    Pixels are ζ (px along the line) at a time ``t_s`` each; ``project`` returns
    ``(ζ, across_px)`` with ``across_px = c_px · x_s / z_s`` the along-track offset of the point
    from the line's plane in pixels (zero on the line).
    """

    geometry: LineGeometry
    mount: Mount = field(default_factory=Mount)

    def rays(self, zeta_px, t_s, trajectory) -> tuple[np.ndarray, np.ndarray]:
        """Origins (m) and unit directions of the rays of pixels ζ at times ``t_s``, map frame.

        Parameters
        ----------
        zeta_px : (n,) array_like, px
        t_s : (n,) array_like, s
        trajectory : hsgeo.trajectory.Trajectory

        Returns
        -------
        origins_m : (n, 3) ndarray
        directions : (n, 3) ndarray, unit length
        """
        d_s = sensor_directions(self.geometry.tan_angle(zeta_px))
        return self.mount.rays_along(d_s, t_s, trajectory)

    def _sensor_xyz(self, xyz_map_m, t_s, trajectory) -> np.ndarray:
        return self.mount.sensor_points_along(xyz_map_m, t_s, trajectory, "line scanner")

    def project(self, xyz_map_m, t_s, trajectory) -> np.ndarray:
        """``(ζ, across_px)`` of map points seen at times ``t_s``, ``(n, 2)`` px."""
        p = self._sensor_xyz(xyz_map_m, t_s, trajectory)
        zeta = np.asarray(self.geometry.zeta(p[:, 1] / p[:, 2]), dtype=float)
        return np.column_stack([zeta, self.geometry.c_px * p[:, 0] / p[:, 2]])

    def line_time(
        self,
        xyz_map_m,
        trajectory,
        t_start_s,
        *,
        band=None,
        tol_s: float = 1e-10,
        max_iter: int = 30,
    ) -> np.ndarray:
        """Time at which each map point lies on the scan line (``across_px = 0``), s.

        Secant iteration from ``t_start_s`` (one per point), within the trajectory's span
        (:func:`hsgeo.sensors.mount.line_time`; the signature every scanning sensor shares).

        Parameters
        ----------
        xyz_map_m : (n, 3) array_like, m
            Map points.
        trajectory : hsgeo.trajectory.Trajectory
        t_start_s : float or (n,) array_like, s
            Where the secant iteration starts (clipped to the trajectory's span).
        band : int or (n,) array_like of int, optional
            Accepted for the shared signature; every band has this one geometry.
        tol_s : float
            Convergence threshold on the time step, s.
        max_iter : int

        Returns
        -------
        t_s : (n,) ndarray, s

        Raises
        ------
        hsgeo.errors.ConvergenceError
            A point the line never crosses within ``max_iter`` steps.
        """

        def across_px(X, t):
            p = self._sensor_xyz(X, t, trajectory)
            return self.geometry.c_px * p[:, 0] / p[:, 2]

        return line_time(across_px, xyz_map_m, trajectory, t_start_s, tol_s, max_iter)


# ----------------------------------------------------------------------------------------------
# The GCP calibration of the boresight (PARGE-style, 000 Tables 2–3)
# ----------------------------------------------------------------------------------------------
class BoresightGCP(ResidualBlock):
    """Residuals geocoded − reference (E, N) at GCPs as a function of the boresight angles.

    The rays are the sensor's face (:meth:`LineScanner.rays`, lever arm included) with the
    boresight ``R_body_from_sensor = R_from_rpy(b)`` of the parameter block. Over a plane of
    height h: ``X = O + s·d``, ``s = (h − O_U)/d_U`` and ``∂X/∂b = s·(∂d/∂b − d·(∂d_U/∂b)/d_U)``
    with ``∂d/∂b = R_map_from_body (∂R_bs/∂b) d_sensor`` (the origin ``O`` does not depend on
    the boresight). Parameter block of role ``boresight`` (default name ``boresight``, see
    ``blocks``): (roll, pitch, heading) of ``R_body_from_sensor`` in rad.

    ``sensor`` is a :class:`LineScanner` (its geometry and its mount's lever arm; its
    boresight is the parameter's) or a bare :class:`LineGeometry` (no lever arm).
    """

    name = "GCP deviations"
    group_size = 2
    BLOCKS = MappingProxyType({"boresight": "boresight"})

    def __init__(
        self,
        nav,
        sensor: LineGeometry | LineScanner,
        line,
        zeta_px,
        gcp_enu_m,
        *,
        t0_s: float,
        line_rate_hz: float,
        height_m: float,
        sigma_m: float,
        blocks: Mapping[str, str] | None = None,
    ):
        gcp = np.asarray(gcp_enu_m, dtype=float)
        super().__init__(np.full(2 * gcp.shape[0], sigma_m), blocks=blocks)
        scanner = sensor if isinstance(sensor, LineScanner) else LineScanner(sensor)
        self.scanner, self.nav = scanner, nav
        self.t_s = t0_s + np.asarray(line, float) / line_rate_hz
        self.zeta_px = np.asarray(zeta_px, dtype=float)
        self.R_mb = nav.R_map_from_body(self.t_s)
        self.d_s = sensor_directions(scanner.geometry.tan_angle(zeta_px))
        self.gcp_en = gcp[:, :2]
        self.h = height_m

    def evaluate(self, values, jacobian):
        b = values[self.blocks["boresight"]]
        m = self.scanner.mount
        face = replace(self.scanner, mount=Mount(m.lever_arm_m, R_from_rpy(*b)))
        o, u = face.rays(self.zeta_px, self.t_s, self.nav)  # the sensor's face
        if np.any(u[:, 2] >= 0):
            raise ObservationError("a GCP ray does not point downwards: check the attitude")
        X = o + ((self.h - o[:, 2]) / u[:, 2])[:, None] * u
        r = (X[:, :2] - self.gcp_en).ravel()
        if not jacobian:
            return r, None
        d = face.mount.directions(self.R_mb, self.d_s)  # u unnormalised: the face's mount
        s = (self.h - o[:, 2]) / d[:, 2]
        dR = dR_drpy(*b)  # (3 angles, 3, 3)
        dd = np.einsum("nij,kjl,nl->nki", self.R_mb, dR, self.d_s)  # (n, 3 angles, 3)
        dX = s[:, None, None] * (dd - d[:, None, :] * (dd[:, :, 2:3] / d[:, None, 2:3]))
        return r, {self.blocks["boresight"]: np.transpose(dX[:, :, :2], (0, 2, 1)).reshape(-1, 3)}


def calibrate_boresight(
    nav,
    sensor: LineGeometry,
    line,
    zeta_px,
    gcp_enu_m,
    *,
    t0_s,
    line_rate_hz,
    height_m,
    sigma_m=0.3,
):
    """Estimate the boresight angles from GCPs (as PARGE does with GCP-calibrated data).

    The rank of the design is checked first: with one straight line over a flat field, the three
    angles are determined by the GCPs' along- and across-track spread; a GNSS position offset
    could not be separated from roll and pitch and is therefore absorbed by them.

    Returns
    -------
    hsgeo.adjust.AdjustmentResult
        Block ``boresight`` (roll, pitch, heading in rad) with σ̂.
    """
    p = Parameters()
    p.add("boresight", np.zeros(3), columns=("roll_rad", "pitch_rad", "heading_rad"))
    blk = BoresightGCP(
        nav,
        sensor,
        line,
        zeta_px,
        gcp_enu_m,
        t0_s=t0_s,
        line_rate_hz=line_rate_hz,
        height_m=height_m,
        sigma_m=sigma_m,
    )
    return adjust(p, blk)
