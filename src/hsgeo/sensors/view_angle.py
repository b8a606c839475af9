"""A line scanner given by per-pixel view angles: the form manufacturers calibrate in.

A geometric calibration of a hyperspectral line scanner is delivered as a table: for each pixel
of the line (and, for a sensor with smile / keystone, for each band) the **across-track** view
angle α (positive to the right, about the sensor's x axis) and the **along-track** view angle β
(positive forward, about its y axis). In the sensor frame of :mod:`hsgeo.sensors.line` (x
forward, y right, z down, looking along +z) pixel ζ of band b sees the direction::

    d(ζ, b) = (tan β_b(ζ), tan α_b(ζ), 1)

The table is given at whole pixels ζ = 0 … n−1 (0-based columns of the cube, pixel-centre
origin) and interpolated between them with a monotone C¹ cubic (PCHIP,
:class:`scipy.interpolate.PchipInterpolator`) of tan α and tan β, so that a fractional pixel has
a ray and the projection is smooth. ``project`` inverts tan α (strictly monotone along the
line, checked) by Newton's method; its second coordinate is the point's along-track offset from
the pixel's ray, ``(x/z − tan β(ζ)) / ifov``, in pixels of the mean across-track step ``ifov``
(zero on the line, as the other scanning sensors of :mod:`hsgeo.sensors.mount`).

With β ≡ 0 and tan α linear in ζ this is :class:`hsgeo.sensors.line.LinearIFOV`'s geometry.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.sensors.mount import Mount, line_time

__all__ = ["ViewAngleScanner"]


@dataclass(frozen=True, eq=False)
class ViewAngleScanner:
    """A line scanner whose pixels' view angles are tabulated (module docstring).

    Parameters
    ----------
    across_rad : (n_px,) or (n_bands, n_px) array_like, rad
        Across-track view angle α of each pixel (positive to the right); one row per band or
        one for all bands. Strictly monotone along the line.
    along_rad : same shape as ``across_rad``, rad
        Along-track view angle β of each pixel (positive forward).
    mount : Mount
        Lever arm and boresight on the body.

    Raises
    ------
    InputError
        Shapes that differ, fewer than 2 pixels, angles not finite or beyond ±89°, across
        angles not strictly monotone along the line.
    """

    across_rad: np.ndarray
    along_rad: np.ndarray
    mount: Mount = field(default_factory=Mount)

    def __post_init__(self):
        a = np.atleast_2d(np.asarray(self.across_rad, dtype=float))
        b = np.atleast_2d(np.asarray(self.along_rad, dtype=float))
        if a.shape != b.shape or a.ndim != 2 or a.shape[1] < 2:
            raise InputError(
                f"view angles: across {a.shape} and along {b.shape} must be the same "
                "(n_px,) or (n_bands, n_px) with at least 2 pixels"
            )
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise InputError("view angles: NaN or infinite angles; give every pixel's angles")
        if np.max(np.abs(a)) >= np.deg2rad(89.0) or np.max(np.abs(b)) >= np.deg2rad(89.0):
            raise InputError("view angles: an angle reaches ±89°; a line scanner looks down")
        for k, row in enumerate(a):
            d = np.diff(row)
            if not (np.all(d > 0) or np.all(d < 0)):
                i = int(np.flatnonzero(np.sign(d) != np.sign(d[0]))[0]) if d[0] else 0
                raise InputError(
                    f"view angles (band {k}): across-track angles must change strictly "
                    f"monotonically along the line; pixels {i} and {i + 1} break it"
                )
        from scipy.interpolate import PchipInterpolator

        px = np.arange(a.shape[1], dtype=float)
        object.__setattr__(self, "across_rad", a)
        object.__setattr__(self, "along_rad", b)
        object.__setattr__(self, "_ta", [PchipInterpolator(px, np.tan(r)) for r in a])
        object.__setattr__(self, "_tb", [PchipInterpolator(px, np.tan(r)) for r in b])
        ta = np.tan(a)
        object.__setattr__(
            self, "ifov", float(np.mean(np.abs(ta[:, -1] - ta[:, 0]))) / (a.shape[1] - 1)
        )

    @property
    def n_px(self) -> int:
        """Pixels per line."""
        return int(self.across_rad.shape[1])

    @property
    def n_bands(self) -> int:
        """Tables: 1 (one for all bands) or one per band."""
        return int(self.across_rad.shape[0])

    def check_samples(self, n_samples: int, what: str = "the lines") -> None:
        """Refuse lines whose sample count differs from the table's pixels.

        Raises
        ------
        InputError
            Naming ``what`` and both counts.
        """
        if int(n_samples) != self.n_px:
            raise InputError(
                f"{what} have {int(n_samples)} samples per line, the view-angle table "
                f"{self.n_px} pixels; give the calibration of this sensor (or its binning)"
            )

    def _bands(self, band, n):
        if self.n_bands == 1:
            return np.zeros(n, dtype=int)
        if band is None:
            raise InputError(
                f"this view-angle sensor has one table per band ({self.n_bands}); give band="
            )
        b = np.broadcast_to(np.asarray(band), (n,)).astype(int)
        if np.any((b < 0) | (b >= self.n_bands)):
            raise InputError(f"band must be in 0..{self.n_bands - 1}, got {sorted(set(b))}")
        return b

    def _tan(self, zeta, bands):
        ta, tb = np.empty(zeta.size), np.empty(zeta.size)
        for k in np.unique(bands):
            m = bands == k
            ta[m], tb[m] = self._ta[k](zeta[m]), self._tb[k](zeta[m])
        return ta, tb

    def rays(self, zeta_px, t_s, trajectory, band=None) -> tuple[np.ndarray, np.ndarray]:
        """Origins (m) and unit directions of the rays of pixels ζ at times ``t_s``, map frame.

        Parameters
        ----------
        zeta_px : (n,) array_like, px
            0-based pixel along the line (fractional allowed).
        t_s : (n,) array_like, s
        trajectory : hsgeo.trajectory.Trajectory
        band : int or (n,) array_like of int, optional
            0-based band; required when there is one table per band.
        """
        z = np.asarray(zeta_px, dtype=float).ravel()
        ta, tb = self._tan(z, self._bands(band, z.size))
        d_s = np.column_stack([tb, ta, np.ones_like(ta)])
        return self.mount.rays_along(d_s, t_s, trajectory)

    def _zeta(self, u, bands):
        """Pixel ζ with tan α(ζ) = u (Newton on the PCHIP, from linear interpolation)."""
        z = np.empty(u.size)
        px = np.arange(self.n_px, dtype=float)
        for k in np.unique(bands):
            m = bands == k
            f, fp = self._ta[k], self._ta[k].derivative()
            tab = np.tan(self.across_rad[k])
            order = np.argsort(tab)
            zk = np.interp(u[m], tab[order], px[order])
            for _ in range(50):
                step = (f(zk) - u[m]) / fp(zk)
                zk = zk - step
                if np.all(np.abs(step) < 1e-13 * max(self.n_px, 1)):
                    break
            z[m] = zk
        return z

    def _sensor_xyz(self, xyz_map_m, t_s, trajectory):
        return self.mount.sensor_points_along(xyz_map_m, t_s, trajectory, "view-angle scanner")

    def _along_px(self, p, zeta, bands):
        _, tb = self._tan(zeta, bands)
        return (p[:, 0] / p[:, 2] - tb) / self.ifov

    def project(self, xyz_map_m, t_s, trajectory, band=None) -> np.ndarray:
        """``(ζ, along_px)`` of map points seen at times ``t_s``, ``(n, 2)`` px (module
        docstring: ``along_px`` is zero on the pixel's ray).
        """
        p = self._sensor_xyz(xyz_map_m, t_s, trajectory)
        bands = self._bands(band, p.shape[0])
        zeta = self._zeta(p[:, 1] / p[:, 2], bands)
        if not np.all(np.isfinite(zeta)):
            raise ObservationError("view-angle scanner: a point's across angle has no pixel")
        return np.column_stack([zeta, self._along_px(p, zeta, bands)])

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
        """Time at which each map point lies on the scan line (``along_px = 0``), s.

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
            0-based band; required when there is one table per band.
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

        def along(X, t):
            p = self._sensor_xyz(X, t, trajectory)
            bands = self._bands(band, p.shape[0])
            return self._along_px(p, self._zeta(p[:, 1] / p[:, 2], bands), bands)

        return line_time(along, xyz_map_m, trajectory, t_start_s, tol_s, max_iter)
