"""A panoramic (whiskbroom) scanner: a rotating mirror sweeps one detector across the track (004).

The DAEDALUS AADS 1268 of paper 004: 716 pixels per scan line, scan angles ±43° (0.12° per
pixel), "the scan starts at the right (when looking into direction of flight heading), so pixel
number 0 corresponds to a scanning direction to the right" (004 § Description of the detector).

Frames as in :mod:`hsgeo.sensors.mount`: **sensor** like body (x forward, y right, z down). The
mirror turns about the sensor x axis, so pixel ζ looks along

    d_sensor(ζ) = (0, sin θ, cos θ),   θ(ζ) = (ζ0 − ζ)·δ

with θ the scan angle (positive to the right), δ the angular pixel size (rad) and ζ0 the pixel
that looks at nadir (357.5 for 716 pixels, pixel-centre origin). Unlike a line camera the scan
angle is linear in the pixel number — equal angles, not equal distances on a plane: the ground
sampling grows as 1/cos²θ across the track (the *panoramic distortion* of 004 step 1). Each
sample of a scan line is taken at its own time (:meth:`PanoramicScanner.times`).

``project`` returns ``(ζ, across_px)``: ``across_px = asin(x_s/|p|)/δ`` is the point's angle out
of the scan plane in pixels (zero on the line), so ``project(rays(ζ))`` gives back ``(ζ, 0)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.errors import InputError
from hsgeo.sensors.mount import Mount, line_time

__all__ = ["PanoramicScanner", "DAEDALUS_N_PX", "DAEDALUS_IFOV_DEG"]

#: 004 § Description of the detector: "716 pixels for each of the 11 spectral channels".
DAEDALUS_N_PX = 716
#: 004: "Each pixel covers an angular range of 2·43°/716 = 0.12°" (the paper's value is
#: ``hsgeo.papers.ASF_004["angular pixel size"]``; a test checks both agree). Typed here, not
#: imported, so that the sensors a workflow reads carry no paper table (the import contract
#: "workflows are truth-free" holds through hsgeo.io.read_sensor).
DAEDALUS_IFOV_DEG = 0.12


@dataclass(frozen=True)
class PanoramicScanner:
    """A rotating-mirror scanner on a moving body: the interface of :mod:`hsgeo.sensors.mount`.

    Parameters
    ----------
    n_px : int
        Pixels per scan line (004: 716).
    ifov_deg : float
        Angular pixel size δ, deg (004: 0.12°; the exact 2·43°/716 = 0.1201° is within the
        paper's rounding).
    mount : Mount
        Lever arm and boresight on the body of the trajectory.
    active_fraction : float
        Share of the line period during which the mirror sweeps the pixels (a one-faced mirror
        turning once per line: 2·43°/360°); sets :meth:`times`.

    References
    ----------
    .. [1] Meister, G., Jupp, D., Rothkirch, A. and Spitzer, H. (1999). Determination of the angular
           sensitivity of a multispectral line scanner from image data. IGARSS 1999, vol. 1, 458
           (paper 004).
    """

    n_px: int = DAEDALUS_N_PX
    ifov_deg: float = DAEDALUS_IFOV_DEG
    mount: Mount = field(default_factory=Mount)
    active_fraction: float = 2 * 43.0 / 360.0

    def __post_init__(self):
        if not (isinstance(self.n_px, (int, np.integer)) and self.n_px >= 2):
            raise InputError(f"n_px must be an integer ≥ 2, got {self.n_px!r}")
        if not (0 < self.ifov_deg and self.n_px * self.ifov_deg < 180.0):
            raise InputError(
                f"ifov_deg = {self.ifov_deg!r}: the scan (n_px·ifov) must lie within (0°, 180°)"
            )
        if not 0 <= self.active_fraction <= 1:
            raise InputError(f"active_fraction must be in [0, 1], got {self.active_fraction!r}")

    # ---- the inner geometry: pixel ↔ scan angle -----------------------------------------------
    @property
    def ifov_rad(self) -> float:
        return float(np.deg2rad(self.ifov_deg))

    @property
    def zeta0_px(self) -> float:
        """The pixel that looks at nadir (between the two middle pixels for an even count)."""
        return (self.n_px - 1) / 2.0

    def scan_angle_rad(self, zeta_px) -> np.ndarray:
        """Scan angle θ of pixel ζ, rad, positive to the right of the heading (004: pixel 0
        looks right).
        """
        return (self.zeta0_px - np.asarray(zeta_px, dtype=float)) * self.ifov_rad

    def zeta(self, scan_angle_rad) -> np.ndarray:
        """The pixel that looks at scan angle θ (inverse of :meth:`scan_angle_rad`)."""
        return self.zeta0_px - np.asarray(scan_angle_rad, dtype=float) / self.ifov_rad

    def times(self, line, zeta_px, t0_s: float, line_rate_hz: float) -> np.ndarray:
        """When the sample ``(line, ζ)`` is taken, s: ``t0 + (line + f·ζ/n_px)/rate``, ``f`` the
        active fraction (the mirror sweeps pixel 0 first).
        """
        line = np.asarray(line, dtype=float)
        z = np.asarray(zeta_px, dtype=float)
        return t0_s + (line + self.active_fraction * z / self.n_px) / line_rate_hz

    # ---- the sensor interface ---------------------------------------------------------------
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
        th = np.atleast_1d(self.scan_angle_rad(zeta_px)).ravel()
        d_s = np.stack([np.zeros_like(th), np.sin(th), np.cos(th)], axis=1)
        return self.mount.rays_along(d_s, t_s, trajectory)

    def _sensor_xyz(self, xyz_map_m, t_s, trajectory) -> np.ndarray:
        return self.mount.sensor_points_along(xyz_map_m, t_s, trajectory, "panoramic scanner")

    def project(self, xyz_map_m, t_s, trajectory) -> np.ndarray:
        """``(ζ, across_px)`` of map points seen at times ``t_s``, ``(n, 2)`` px."""
        p = self._sensor_xyz(xyz_map_m, t_s, trajectory)
        zeta = self.zeta(np.arctan2(p[:, 1], p[:, 2]))
        across = np.arctan2(p[:, 0], np.hypot(p[:, 1], p[:, 2])) / self.ifov_rad
        return np.column_stack([zeta, across])

    def project_jacobian(self, xyz_map_m, t_s, trajectory) -> np.ndarray:
        """``∂(ζ, across_px)/∂(E, N, U)`` of :meth:`project` at fixed times, ``(n, 2, 3)`` px/m."""
        p = self._sensor_xyz(xyz_map_m, t_s, trajectory)
        R = trajectory.R_map_from_body(t_s)
        # p = R_bsᵀ R_mbᵀ (X − O): ∂p/∂X = R_bsᵀ R_mbᵀ
        M = np.einsum("ji,njk->nik", self.mount.R_body_from_sensor, np.transpose(R, (0, 2, 1)))
        x, y, z = p.T
        rho2 = y * y + z * z
        rho = np.sqrt(rho2)
        r2 = rho2 + x * x
        d = 1.0 / self.ifov_rad
        dzeta = -d * np.stack([np.zeros_like(x), z / rho2, -y / rho2], axis=1)
        dacross = d * np.stack([rho / r2, -x * y / (rho * r2), -x * z / (rho * r2)], axis=1)
        return np.einsum("nai,nij->naj", np.stack([dzeta, dacross], axis=1), M)

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
        """Time at which each map point lies in the scan plane (``across_px = 0``), s.

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
            Accepted for the shared signature; every channel has this one geometry.
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
            return self.project(X, t, trajectory)[:, 1]

        return line_time(across_px, xyz_map_m, trajectory, t_start_s, tol_s, max_iter)
