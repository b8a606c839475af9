"""Linear pushbroom (LP) lines as pinhole exposures with spline trajectory corrections.

Kept as one file: the one 002 LP camera model in its three faces (the sensor
:class:`PushbroomCamera`, the numpy reference :func:`project`, the residual block
:class:`PushbroomLines`) sharing its geometry; the compiled kernel is in
:mod:`hsgeo.sensors._pushbroom_kernel`, the compiled rays of lines of pixels (one pose per line,
one camera direction per column) in :mod:`hsgeo.sensors._pushbroom_rays`.

002 eq. 2–4.

Every LP image line is a pinhole exposure at its time ``t_e``. An observation is a tie point
``k`` seen in one line of one spectral band at image coordinates ``(x, y)`` in pixels from the
line's centre (``x`` along the line, ``y`` across it: ``y = 0`` is the line itself).

Model, for an observation at time ``t`` (002 eq. 4)::

    δ(t)     = Σ_a B_a(t) c_{j_a}                      local cubic B-spline of node corrections
    x(t)     = x_nav(t) + δ_xyz(t)                     platform position, map frame (E, N, U)
    R(t)     = R_from_rpy(rpy_nav(t) + δ_rpy(t))       R_map_from_platform
    p^c      = β (R(t)ᵀ (p^m − x(t)) − l^p)            = β R⁻¹ (p^m − x − R l)   (002 eq. 4)
    β        = R_from_opk(ω_b, φ_b, κ_b) β₀            boresight: small angles on the nominal mount

and the image coordinates in mm (002 eq. 2–3)::

    x̄ = c_b p^c_x / p^c_z,   ȳ = c_b p^c_y / p^c_z     one principal distance c_b per band
    x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄² + x0
    y = ȳ + P2 x̄² + y0

Eq. (3) is printed with powers of ``p^c_x``; we evaluate the distortion at the ideal image
coordinate ``x̄`` (mm), which is what a distortion polynomial of an image line means (units:
K1 mm⁻², K2 mm⁻⁴, P1 and P2 mm⁻¹). The principal point ``(x0, y0)`` is fixed at its calibrated
value (002 §3.4: it correlates with the tangential terms and is not estimated).

**The residual across the line is a time.** What an LP observation records across the line is
*which line* saw the point, i.e. a time ``t_e``; its error is the time between the crossing of
the point (``y = 0``) and the line's exposure (line quantisation and the key-point
localisation). The residual of 002 eq. (2), ``y(θ, t_e) − 0``, is that time error multiplied by
the image rate ``ẏ = ∂y/∂t`` — which depends on the parameters θ (``c``, depth, the pitch rate
of the trajectory corrections, ...). The derivatives of the residual then contain the error
itself, and least squares is biased by a fixed amount (∝ σ_t² Σ ẏ ∂ẏ/∂θ) that becomes visible as
σ̂ shrinks with the number of observations. With the navigation rates given, the residual
across the line is instead a time: the model's crossing time ``t*`` of the line,
``y(θ, t*) = y_obs``, minus the line time, in pixels at a reference image rate ``ẏ_ref``::

    r_y = ẏ_ref (t_e − t*),   r_x = x(θ, t*) − x_obs,   ∂t*/∂θ = −(∂y/∂θ) / ẏ

``t*`` is found by Newton's method (to ``NEWTON_TOL_S`` = 1e-8 s), with the navigation pose
moved by its velocity and angular rate and the spline piece of ``t_e`` continued. It starts
from the crossing time of the block's previous evaluation (``t_e`` at the first): near the
solution an iteration moves most crossings by less than 1e-8 s, and one evaluation of the pose
per observation suffices instead of two. A trial step given the step's linear prediction
(:meth:`PushbroomLines.start_trial`) starts from the linearisation's time moved by it.
A time held at the bound ``±T_MAX`` ends its Newton
(a further pass would evaluate the same time). The residuals carry the last Newton correction
to first order (``ẏ_ref (t_e − t_k + e)`` and ``x − ẋ e``), so stopping at ``|e| < 1e-8 s``
leaves an error of ``½ ÿ e²`` (below 1e-13 px with the mount's ÿ of a few hundred px/s²); the
solver's trial steps (:meth:`PushbroomLines.trial_residuals`) stop at ``|e| < 1e-4 s``
(``TRIAL_TOL_S``: 2.5e-6 px at that ÿ; the chapter's ÿ is below 0.4 px/s² for 99 % of the
observations), one pass for most observations from the third trial on, and the solver
checks each accepted trial's cost against the exact cost of the linearisation at its point
(:class:`hsgeo.adjust.ResidualBlock`); the
derivatives, taken at ``t_k``, depend on where Newton started only to ~1e-9 relative. ``ẏ``
and ``ẋ`` are the image rates along the corrected trajectory. The derivatives
are evaluated at ``t*``, so they do not contain the time error, and the node derivatives keep
the factored form ``B_a(t*) ∂r/∂δ``. Evaluating x at ``t*`` rather than ``t_e`` adds
``ẋ (t* − t_e)`` (≈ 0.1 px at the mount's angular rates) to the x residual, zero-mean.

002 eq. (3)–(4) and the spline weights are the scalar cores of :mod:`hsgeo._kernels`
(:func:`~hsgeo._kernels.pushbroom_camera_point`, :func:`~hsgeo._kernels.pushbroom_image_mm`,
:func:`~hsgeo._kernels.bspline_weights`): the compiled kernel calls them per observation, the
numpy reference path (:func:`project`, :meth:`PushbroomLines.evaluate_numpy`) through
:func:`~hsgeo._kernels.pushbroom_image_rows`.

The nominal mount ``β₀`` maps the platform frame (x forward, y left, z up) to the camera frame
(x along the line to the right, y backward, z down the viewing direction).

The attitude angles ``rpy_nav`` and their corrections are the model's own: roll, pitch, yaw of
the platform frame relative to east-north-up, ``R_map_from_platform = R_from_rpy(roll, pitch,
yaw)``. A GNSS/INS attitude (:class:`hsgeo.trajectory.Trajectory`: roll, pitch, heading of the
body x forward, y right, z down in north-east-down) converts exactly by
:func:`hsgeo.trajectory.platform_rpy_from_rph`, ``(roll, −pitch, π/2 − heading)``.

References
----------
Jonassen et al. (2024), 002 eq. (2)–(4), §3.3–3.5.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from types import MappingProxyType

import numpy as np

from hsgeo._kernels import pushbroom_image_rows
from hsgeo.adjust import Indexed, ResidualBlock
from hsgeo.distortion import (
    distort_pushbroom_line_jacobian,
    undistort_pushbroom_line,
)
from hsgeo.errors import InputError, ObservationError
from hsgeo.rotations import R_from_opk, R_from_rpy, dR_dopk, dR_drpy
from hsgeo.sensors._pushbroom_kernel import (
    NEWTON_TOL_S,
    T_MAX,
    TRIAL_PREDICTION_MAX_S,
    TRIAL_TOL_S,
    _lines_kernel,
)
from hsgeo.sensors._pushbroom_rays import line_runs, rays_by_line
from hsgeo.sensors.mount import Mount, line_time, unit
from hsgeo.trajectory import R_BODY_FROM_PLATFORM, SplineNodes, bspline_basis

__all__ = [
    "PushbroomCamera",
    "PushbroomLines",
    "PushbroomObservations",
    "BETA0_CAM_FROM_PLATFORM",
    "BLOCK_NAMES",
    "project",
]

#: Nominal camera-from-platform rotation (platform x forward, y left, z up → camera x right,
#: y backward, z down).
BETA0_CAM_FROM_PLATFORM = np.array([[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
BETA0_CAM_FROM_PLATFORM.setflags(write=False)

#: Default parameter-block names of :class:`PushbroomLines` by role (its ``BLOCKS``).
BLOCK_NAMES = MappingProxyType(
    {
        "points": "points_m",
        "nodes": "nodes",
        "boresight": "boresight_rad",
        "lever_arm": "lever_arm_m",
        "distortion": "distortion",
        "c": "c_mm",
    }
)


def _camera_geometry(
    values, names, nodes: SplineNodes, t_s, xyz_nav, rpy_nav, pidx, band, beta0, x0_mm, y0_mm
):
    """Image coordinates, p^c and intermediate quantities for every observation (002 eq. 3–4).

    The numpy path: the pose is corrected here, 002 eq. (3)–(4) are the compiled cores of
    :mod:`hsgeo._kernels` that :func:`_lines_kernel` calls too.
    """
    P = values[names["points"]][pidx]
    idx, w = nodes.basis(t_s)
    node_vals = values[names["nodes"]]
    delta = np.einsum("ma,mak->mk", w, node_vals[idx])
    x = xyz_nav + delta[:, :3]
    rpy = rpy_nav + delta[:, 3:]
    R = R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    bore = values[names["boresight"]]
    beta = R_from_opk(bore[0], bore[1], bore[2]) @ beta0
    lever = np.asarray(values[names["lever_arm"]], dtype=np.float64)
    d = np.ascontiguousarray(P - x, dtype=np.float64)
    c = np.ascontiguousarray(values[names["c"]][band], dtype=np.float64)
    dist = np.asarray(values[names["distortion"]], dtype=np.float64)
    q, p, xy, xb, yb, iz, gx, gy = pushbroom_image_rows(  # 002 eq. (3)–(4)
        np.ascontiguousarray(R),
        d,
        lever,
        np.ascontiguousarray(beta),
        c,
        dist,
        float(x0_mm),
        float(y0_mm),
    )
    return {
        "xy": xy,
        "p": p,
        "q": q,
        "d": d,
        "R": R,
        "beta": beta,
        "idx": idx,
        "w": w,
        "rpy": rpy,
        "c": c,
        "xb": xb,
        "yb": yb,
        "iz": iz,
        "gx": gx,
        "gy": gy,
    }


def project(values, names, nodes, t_s, xyz_nav, rpy_nav, pidx, band, beta0, x0_mm, y0_mm):
    """Image coordinates (mm) of every observation (002 eq. 2–4), without derivatives.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    g = _camera_geometry(
        values, names, nodes, t_s, xyz_nav, rpy_nav, pidx, band, beta0, x0_mm, y0_mm
    )
    return g["xy"], g["p"]


@dataclass(frozen=True)
class PushbroomObservations:
    """Tie-point observations in LP lines and the GNSS/INS pose at their line times.

    What a user's files give once the navigation is read at the line times (``hsgeo
    adjust-pushbroom``), and what a simulator hands to the adjustment: nothing here is truth.
    Arrays are converted (integers to int64, the rest to float64) and their shapes checked.

    Parameters
    ----------
    point : (m,) int ndarray
        Tie point of each observation (0-based row of the points block).
    band : (m,) int ndarray
        Spectral band (0-based).
    t_s : (m,) ndarray
        Exposure time of the line, s (the navigation's time scale).
    xy_px : (m, 2) ndarray
        Image coordinates, px from the line centre (x along the line, y across it).
    xyz_nav_m, rpy_nav_rad : (m, 3) ndarray
        GNSS/INS position (map frame E, N, U, m) and attitude (roll, pitch, yaw, rad) at ``t_s``.
    xyz_rate_nav_m_s, rpy_rate_nav_rad_s : (m, 3) ndarray, optional
        GNSS/INS velocity (m/s) and attitude rates (rad/s) at ``t_s``: both or neither (the
        residual across the line as a time needs them).
    """

    point: np.ndarray
    band: np.ndarray
    t_s: np.ndarray
    xy_px: np.ndarray
    xyz_nav_m: np.ndarray
    rpy_nav_rad: np.ndarray
    xyz_rate_nav_m_s: np.ndarray | None = None
    rpy_rate_nav_rad_s: np.ndarray | None = None

    def __post_init__(self):
        if (self.xyz_rate_nav_m_s is None) != (self.rpy_rate_nav_rad_s is None):
            raise InputError(
                "give both GNSS/INS rates (xyz_rate_nav_m_s and rpy_rate_nav_rad_s) or neither"
            )
        point = np.asarray(self.point)
        band = np.asarray(self.band)
        for nm, arr in (("point", point), ("band", band)):
            if arr.size and (not np.issubdtype(arr.dtype, np.integer) or np.any(arr < 0)):
                raise InputError(f"{nm} indices must be non-negative integers")
        m = point.size
        shapes = {
            "point": (m,),
            "band": (m,),
            "t_s": (m,),
            "xy_px": (m, 2),
            "xyz_nav_m": (m, 3),
            "rpy_nav_rad": (m, 3),
            "xyz_rate_nav_m_s": (m, 3),
            "rpy_rate_nav_rad_s": (m, 3),
        }
        for nm, shape in shapes.items():
            v = getattr(self, nm)
            if v is None:
                continue
            v = np.asarray(v, dtype=np.int64 if nm in ("point", "band") else np.float64)
            if v.shape != shape:
                raise InputError(
                    f"observations: {nm} has shape {v.shape}, expected {shape} for {m} observations"
                )
            object.__setattr__(self, nm, v)

    @property
    def n(self) -> int:
        """Number of observations (each an x and a y)."""
        return int(self.point.size)

    @property
    def has_rates(self) -> bool:
        """Whether the GNSS/INS rates are given."""
        return self.xyz_rate_nav_m_s is not None

    def take(self, rows) -> PushbroomObservations:
        """The observations at ``rows``: indices (in their order: the table sorted or shuffled)
        or a boolean mask of :attr:`n` (a subset), every column alike.
        """
        rows = np.asarray(rows)
        if rows.dtype == bool and rows.shape != (self.n,):
            raise InputError(f"observations: a mask of {rows.shape} for {self.n} observations")
        return replace(
            self,
            **{
                f.name: getattr(self, f.name)[rows]
                for f in fields(self)
                if getattr(self, f.name) is not None
            },
        )


def _no_cols():
    """``cols`` of PushbroomLines._kernel when no gradient is accumulated (fresh, writable
    arrays: the compiled kernel's signature is that of writable ones).
    """
    return (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), 0)


class PushbroomLines(ResidualBlock):
    """Image observations of tie points in LP lines (002 eq. 2–4) as a residual block.

    Residuals are model − observation in pixels, interleaved ``(x0, y0, x1, y1, ...)``; one
    observation (x and y) is the unit of outlier rejection.

    Parameters
    ----------
    point : (m,) int ndarray
        Row of the points block each observation sees.
    band : (m,) int ndarray
        Spectral band (index into the per-band principal distance ``c_mm``).
    t_s : (m,) ndarray
        Exposure time of the line.
    xy_px : (m, 2) ndarray
        Observed image coordinates in pixels from the line centre.
    xyz_nav_m, rpy_nav_rad : (m, 3) ndarray
        The GNSS/INS pose at ``t_s`` (uncorrected).
    nodes : SplineNodes
        The spline node layout of the trajectory corrections.
    pixel_mm : float
        Pixel pitch (002 §4: 6.5 µm).
    sigma_px : float
        A-priori σ of an image coordinate (002 §4: 1/2 px).
    x0_mm, y0_mm : float
        Principal point (fixed).
    blocks : mapping, optional
        Parameter-block names by role (defaults :data:`BLOCK_NAMES`), see
        :class:`~hsgeo.adjust.ResidualBlock`.
    xyz_rate_m_s, rpy_rate_rad_s : (m, 3) ndarray, optional
        GNSS/INS velocity and attitude-angle rates at ``t_s``. Given, the residual across the
        line is a time (see the module docstring), in pixels at ``y_rate_ref_px_s``; omitted,
        it is the image y of 002 eq. (2).
    y_rate_ref_px_s : float, optional
        Reference image rate across the line (px/s) that converts the time residual to pixels
        (required with the rates; e.g. ``c V / (Z pixel)``).
    newton_iterations : int
        Most Newton iterations for the crossing time per evaluation (they stop when the
        correction falls below ``NEWTON_TOL_S``; started from the previous evaluation's
        crossing time, usually after the first).

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    name = "image points"
    group_size = 2
    BLOCKS = BLOCK_NAMES

    def __init__(
        self,
        point,
        band,
        t_s,
        xy_px,
        xyz_nav_m,
        rpy_nav_rad,
        nodes: SplineNodes,
        pixel_mm: float,
        sigma_px: float = 0.5,
        x0_mm: float = 0.0,
        y0_mm: float = 0.0,
        blocks: Mapping[str, str] | None = None,
        beta0=BETA0_CAM_FROM_PLATFORM,
        xyz_rate_m_s=None,
        rpy_rate_rad_s=None,
        y_rate_ref_px_s: float | None = None,
        newton_iterations: int = 8,
    ):
        point = np.asarray(point)
        m = point.size
        xy = np.asarray(xy_px, dtype=np.float64)
        checks = [
            ("band", band, (m,)),
            ("t_s", t_s, (m,)),
            ("xy_px", xy, (m, 2)),
            ("xyz_nav_m", xyz_nav_m, (m, 3)),
            ("rpy_nav_rad", rpy_nav_rad, (m, 3)),
        ]
        if (xyz_rate_m_s is None) != (rpy_rate_rad_s is None):
            raise InputError("PushbroomLines: give both xyz_rate_m_s and rpy_rate_rad_s, or none")
        timed = xyz_rate_m_s is not None
        if timed:
            checks += [
                ("xyz_rate_m_s", xyz_rate_m_s, (m, 3)),
                ("rpy_rate_rad_s", rpy_rate_rad_s, (m, 3)),
            ]
        for nm, arr, shape in checks:
            if np.shape(arr) != shape:
                raise InputError(
                    f"PushbroomLines: {nm} has shape {np.shape(arr)}, expected {shape} "
                    f"for {m} observations"
                )
        if not np.issubdtype(point.dtype, np.integer) or np.any(point < 0):
            raise InputError("PushbroomLines: point indices must be non-negative integers")
        if not np.issubdtype(np.asarray(band).dtype, np.integer) or np.any(np.asarray(band) < 0):
            raise InputError("PushbroomLines: band indices must be non-negative integers")
        if not (pixel_mm > 0):
            raise InputError(f"pixel pitch must be positive, got {pixel_mm!r} mm")
        super().__init__(np.full(2 * m, float(sigma_px)), blocks=blocks)
        self.point = point.astype(np.int64)
        self.band = np.asarray(band, dtype=np.int64)
        self.t_s = np.asarray(t_s, dtype=np.float64)
        self.xy_px = xy
        self.xyz_nav = np.asarray(xyz_nav_m, dtype=np.float64)
        self.rpy_nav = np.asarray(rpy_nav_rad, dtype=np.float64)
        self.nodes = nodes
        self.pixel_mm = float(pixel_mm)
        self.x0_mm, self.y0_mm = float(x0_mm), float(y0_mm)
        self.beta0 = np.array(beta0, dtype=np.float64)  # a writable copy, as the kernels take
        index, u = nodes.piece(self.t_s)
        self._basis = (index, bspline_basis(u))
        self._u0 = np.ascontiguousarray(u)  # the kernel's Newton moves along this piece
        # t* − t_e of the last evaluation: where the next one's Newton starts (module docstring)
        self._dt_s = np.zeros(m)
        self._dt_lin_s: np.ndarray | None = None  # ... of the last one with derivatives
        self.timed = timed
        zeros = np.zeros((m, 3))
        self.xyz_rate = np.ascontiguousarray(xyz_rate_m_s if timed else zeros, dtype=np.float64)
        self.rpy_rate = np.ascontiguousarray(rpy_rate_rad_s if timed else zeros, dtype=np.float64)
        self.y_rate_ref_px_s = 1.0
        if timed:
            if not (
                y_rate_ref_px_s is not None and np.isfinite(y_rate_ref_px_s) and y_rate_ref_px_s > 0
            ):
                raise InputError(
                    "PushbroomLines: the time residual needs y_rate_ref_px_s > 0 (the image "
                    f"rate across the line in px/s, c V / (Z pixel)), got {y_rate_ref_px_s!r}"
                )
            self.y_rate_ref_px_s = float(y_rate_ref_px_s)
        if not (isinstance(newton_iterations, int | np.integer) and newton_iterations >= 1):
            raise InputError(f"newton_iterations must be an integer ≥ 1, got {newton_iterations!r}")
        self.newton_iterations = int(newton_iterations)
        self._pidx2 = np.repeat(self.point, 2)
        self._idx2 = np.repeat(self._basis[0], 2, axis=0)
        self._band2 = np.repeat(self.band, 2)
        for a in ("xyz_nav", "rpy_nav", "xy_px"):
            setattr(self, a, np.ascontiguousarray(getattr(self, a)))

    def fresh(self) -> PushbroomLines:
        """A copy with its own Newton start (the line times), as this block was built.

        Checks at the truth (:func:`hsgeo.adjust.identifiability`) evaluate such a copy: the
        crossing times it finds never become the start of the adjustment's evaluations.
        """
        other = super().fresh()
        other._dt_s = np.zeros_like(self._dt_s)
        other._dt_lin_s = None
        return other

    def evaluate_numpy(self, values, jacobian):
        """:meth:`evaluate` in plain numpy, for the image y of 002 eq. (2) (tests' reference).

        The time residual is checked against a bisection for the crossing time instead.
        """
        if self.timed:
            raise NotImplementedError("the numpy reference covers the image-y residual only")
        nm = self.blocks
        g = _camera_geometry(
            values,
            nm,
            self.nodes,
            self.t_s,
            self.xyz_nav,
            self.rpy_nav,
            self.point,
            self.band,
            self.beta0,
            self.x0_mm,
            self.y0_mm,
        )
        q, d, R, beta = g["q"], g["d"], g["R"], g["beta"]
        c, xb, yb, iz = g["c"], g["xb"], g["yb"], g["iz"]
        k = 1.0 / self.pixel_mm
        m = self.point.size
        r = np.empty(2 * m)
        r[0::2] = g["xy"][:, 0] * k - self.xy_px[:, 0]
        r[1::2] = g["xy"][:, 1] * k - self.xy_px[:, 1]
        if not jacobian:
            return r, None
        # d(x, y)/d p^c  (2 × 3 per observation), in px
        gx, gy = g["gx"], g["gy"]  # dx/dx̄, dy/dx̄ of 002 eq. (3)
        a = c * iz
        dxb = np.stack([a, np.zeros(m), -xb * iz], axis=1)
        dyb = np.stack([np.zeros(m), a, -yb * iz], axis=1)
        Jp = np.empty((m, 2, 3))
        Jp[:, 0] = gx[:, None] * dxb
        Jp[:, 1] = dyb + gy[:, None] * dxb
        Jp *= k
        JpB = Jp @ beta  # d/d q  (m, 2, 3)
        # points: p = β Rᵀ (P − x) − β l  →  dp/dP = β Rᵀ
        dP = JpB @ np.transpose(R, (0, 2, 1))
        # attitude: dq/drpy_k = (dR_k)ᵀ d
        rpy = g["rpy"]
        dR = dR_drpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])  # (m, 3, 3, 3)
        dq_drpy = np.einsum("mkji,mj->mik", dR, d)  # (m, 3(i), 3(k))
        dAtt = JpB @ dq_drpy
        d6 = np.concatenate([-dP, dAtt], axis=2)  # (m, 2, 6): position, attitude
        idx, w = g["idx"], g["w"]
        dnodes = w[:, None, :, None] * d6[:, :, None, :]  # (m, 2, 4, 6)
        # boresight: dp/dbore_k = dβ_k q
        bore = values[nm["boresight"]]
        dbeta = dR_dopk(bore[0], bore[1], bore[2]) @ self.beta0  # (3, 3, 3)
        dBore = np.einsum("mrj,kji,mi->mrk", Jp, dbeta, q)
        dLever = -JpB
        dC = np.stack([gx * xb / c, yb / c + gy * xb / c], axis=1) * k  # (m, 2)
        # ∂(x, y)/∂(K1, K2, P1, P2) of 002 eq. (3): hsgeo.distortion's (the compiled kernel
        # has the same terms inline)
        dist = np.asarray(values[nm["distortion"]], dtype=np.float64)
        dDist = distort_pushbroom_line_jacobian(np.column_stack([xb, yb]), dist)[1] * k
        jac = {
            nm["points"]: Indexed(self._pidx2, dP.reshape(2 * m, 3)),
            nm["nodes"]: Indexed(np.repeat(idx, 2, axis=0), dnodes.reshape(2 * m, 4, 6)),
            nm["boresight"]: dBore.reshape(2 * m, 3),
            nm["lever_arm"]: dLever.reshape(2 * m, 3),
            nm["distortion"]: dDist.reshape(2 * m, 4),
            nm["c"]: Indexed(self._band2, dC.reshape(2 * m, 1)),
        }
        return r, jac

    def evaluate(self, values, jacobian, tol_s=NEWTON_TOL_S):
        """See :meth:`ResidualBlock.evaluate`; ``tol_s``: the crossing time's Newton
        tolerance (:meth:`trial_residuals` passes ``TRIAL_TOL_S``).
        """
        nm = self.blocks
        m = self.point.size
        r = np.empty(2 * m)
        w_out = np.empty((m if jacobian else 0, 4))  # the spline weights: only for the Jacobian
        shp = (2 * m,) if jacobian else (0,)
        dP = np.empty(shp + (3,))
        dN = np.empty(shp + (6,))  # d r / d δ(t); the node columns are B_a(t) × this
        # the camera's columns as views of one (2m, 11) array and a read-only w_row, as
        # evaluate_into passes them: the kernel is compiled once for both (a second
        # compilation cost 8 s of a first run; issue 41). Two unused rows without the
        # Jacobian: numpy calls any empty view contiguous, and numba would type it so.
        V = np.empty((2 * m if jacobian else 2, 11))
        dB, dL, dD, dC = V[:, 0:3], V[:, 3:6], V[:, 6:10], V[:, 10:11]
        none = np.zeros(0, dtype=np.int64)
        no_w = np.zeros(0)
        no_w.flags.writeable = False
        derivs = (dP, dN, dB, dL, dD, dC)
        self._kernel(values, jacobian, r, w_out, derivs, none, no_w, np.zeros((0, 4)), tol_s=tol_s)
        if not jacobian:
            return r, None
        dB, dL, dD, dC = (np.ascontiguousarray(d) for d in (dB, dL, dD, dC))
        jac = {
            nm["points"]: Indexed(self._pidx2, dP),
            # 002 eq. (4) through the spline: ∂r/∂c_a = B_a(t*) ∂r/∂δ (factored)
            nm["nodes"]: Indexed(self._idx2, dN, weights=np.repeat(w_out, 2, axis=0)),
            nm["boresight"]: dB,
            nm["lever_arm"]: dL,
            nm["distortion"]: dD,
            nm["c"]: Indexed(self._band2, dC),
        }
        return r, jac

    def fused_spec(self) -> dict:
        """The layout :meth:`evaluate_into` writes (the engine's fused path, see
        :class:`hsgeo.adjust.system._FusedPart`): the points block, the factored block
        ``(name, item index (2m, 4), k)``, and the slot columns in order, ``(name, index)``
        with ``index`` (2m,) the item of an indexed block of width 1, None for a dense block.
        """
        nm = self.blocks
        return {
            "points": (nm["points"], self._pidx2),
            "factored": (nm["nodes"], self._idx2, 6),
            "slots": [
                (nm["boresight"], None),
                (nm["lever_arm"], None),
                (nm["distortion"], None),
                (nm["c"], self._band2),
            ],
        }

    def evaluate_into(self, values, dst, w_row, r, jp, vals, fw, fd, gd=None, cols=None):
        """:meth:`evaluate` writing the whitened derivatives straight into the engine's arrays.

        Parameters
        ----------
        values : mapping
            The parameter values.
        dst : (m,) int64 ndarray
            The destination pair of each observation (rows ``2 dst[j], 2 dst[j] + 1`` of the
            destination arrays); -1: not written (a rejected observation).
        w_row : (2m,) ndarray
            Whitening weights of the residual rows (1/σ, 1/px).
        r : (2m,) ndarray
            Out: the residuals of every row (px, not whitened).
        jp : (n, 3) ndarray
            Out: whitened derivatives w.r.t. the observation's point (1/m).
        vals : (n, 11) ndarray
            Out: whitened derivatives w.r.t. the boresight (3), the lever arm (3), the
            distortion (4) and the observation's band's principal distance (1), in the order
            of :meth:`fused_spec`'s slots.
        fw : (n, 4) ndarray
            Out: the spline weights of the observation's four nodes.
        fd : (n, 6) ndarray
            Out: whitened derivatives w.r.t. the trajectory correction at the crossing time;
            the node columns are ``fw × fd``.
        gd : (2, n_chunks, n_c) ndarray, optional
            Out (zeroed by the caller): per chunk of observations, the gradient ``Jᵀ r``
            (``gd[0]``) and the diagonal ``diag(JᵀJ)`` (``gd[1]``) of the engine's non-point
            unknowns over the rows written, accumulated in the same pass.
        cols : tuple, optional
            With ``gd``: ``(cam_cols (10,), c_cols (n_bands,), node_c0)``, the engine's
            columns of the boresight, lever arm and distortion entries, of each band's
            principal distance (-1: fixed) and of the first node entry.
        """
        derivs = (jp, fd, vals[:, 0:3], vals[:, 3:6], vals[:, 6:10], vals[:, 10:11])
        # the spline weights go to fw, whitened rows' factored weights (no w_out)
        self._kernel(values, True, r, np.empty((0, 4)), derivs, dst, w_row, fw, gd, cols)

    def trial_residuals(self, values):
        """The residuals at the solver's trial point of a step (see
        :meth:`~hsgeo.adjust.ResidualBlock.trial_residuals`): the crossing time's Newton stops
        at a correction below ``TRIAL_TOL_S`` (1e-4 s) instead of ``NEWTON_TOL_S``. From the
        third trial of the chapter's adjustment on, 97–100 % of the observations then take one
        pass instead of two (the residuals carry the correction to first order: exact to
        ``½ ÿ e²``, see ``TRIAL_TOL_S``); the linearisation at an accepted step starts from the
        corrected times.
        """
        return self.evaluate(values, False, tol_s=TRIAL_TOL_S)[0]

    def start_trial(self, change):
        """See :meth:`~hsgeo.adjust.ResidualBlock.start_trial`: the crossing times' Newton of
        the next trial starts at the linearisation's times moved by their linear prediction,
        ``Δt* = −Δr_y / ẏ_ref`` (the y row is the time residual, ``y_as_time``), where that
        is at most ``TRIAL_PREDICTION_MAX_S`` and the linearisation's time was not held at
        ``±T_MAX``; elsewhere where the last evaluation ended, as before.

        In the chapter's adjustment the second trial then takes one pass for most observations
        instead of two (0.118 against 0.065 CPU-s at the paper's size; the first trial, whose
        crossings move up to ``T_MAX``, gains nothing and is left as it was by the bound on
        the prediction: bench/results/pushbroom_model_passes.json).
        """
        if not self.timed or self._dt_lin_s is None:
            return
        dt = np.asarray(change[1::2], dtype=np.float64) * (-1.0 / self.y_rate_ref_px_s)
        ok = np.abs(dt) <= TRIAL_PREDICTION_MAX_S  # (False where NaN: a row left out)
        ok &= np.abs(self._dt_lin_s) < T_MAX
        np.add(self._dt_lin_s, dt, out=self._dt_s, where=ok)

    def _kernel(
        self, values, jacobian, r, w_out, derivs, dst, w_row, fw, gd=None, cols=None,
        tol_s=NEWTON_TOL_S,
    ):  # fmt: skip
        """One call of the compiled kernel (see ``_pushbroom_kernel._lines_kernel``)."""
        nm = self.blocks
        idx = self._basis[0]
        bore = values[nm["boresight"]]
        beta = R_from_opk(bore[0], bore[1], bore[2]) @ self.beta0
        dbeta = dR_dopk(bore[0], bore[1], bore[2]) @ self.beta0
        _lines_kernel(
            np.ascontiguousarray(values[nm["points"]], dtype=np.float64),
            self.point,
            idx,
            self._u0,
            1.0 / self.nodes.interval_s,
            np.ascontiguousarray(values[nm["nodes"]], dtype=np.float64),
            self.xyz_nav,
            self.rpy_nav,
            self.xyz_rate,
            self.rpy_rate,
            self.band,
            np.asarray(values[nm["c"]], dtype=np.float64),
            np.asarray(values[nm["distortion"]], dtype=np.float64),
            beta,
            dbeta,
            np.asarray(values[nm["lever_arm"]], dtype=np.float64),
            self.x0_mm,
            self.y0_mm,
            1.0 / self.pixel_mm,
            self.xy_px,
            self.timed,
            self.newton_iterations,
            tol_s,
            self.y_rate_ref_px_s,
            bool(jacobian),
            self._dt_s,
            r,
            w_out,
            *derivs,
            dst,
            w_row,
            fw,
            np.zeros((2, 0, 0)) if gd is None else gd,
            *(_no_cols() if cols is None else cols),
        )
        if jacobian:  # where start_trial's prediction starts from
            if self._dt_lin_s is None or self._dt_lin_s.shape != self._dt_s.shape:
                self._dt_lin_s = np.empty_like(self._dt_s)
            np.copyto(self._dt_lin_s, self._dt_s)


# ----------------------------------------------------------------------------------------------
# The sensor interface (hsgeo.sensors.mount): pixels ↔ rays of the LP camera
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PushbroomCamera:
    """The 002 LP camera as a sensor: pixel → ray and map point → pixel (002 eq. 2–4).

    The same model as :class:`PushbroomLines` without the trajectory corrections (give a
    corrected trajectory for an adjusted one): ``p^c = β (R_map_from_platformᵀ (p^m − x) − l^p)``,
    ``x̄ = c_b p^c_x / p^c_z``, ``ȳ = c_b p^c_y / p^c_z`` and the line distortion of 002
    eq. (3) (:func:`hsgeo.distortion.distort_pushbroom_line`; a ray undistorts with
    :func:`~hsgeo.distortion.undistort_pushbroom_line`).

    Parameters
    ----------
    c_mm : sequence of float, mm
        Principal distance of each band.
    pixel_mm : float, mm
        Pixel pitch.
    distortion : (4,) sequence
        K1 (mm⁻²), K2 (mm⁻⁴), P1, P2 (mm⁻¹) of 002 eq. (3).
    x0_mm, y0_mm : float, mm
        Principal point.
    boresight_rad : (3,) sequence, rad
        ω, φ, κ of ``β = R_from_opk(ω, φ, κ) β₀``.
    lever_arm_m : (3,) sequence, m
        Lever arm ``l^p`` in the platform frame (x forward, y left, z up).
    beta0 : (3, 3) array_like
        Nominal camera-from-platform rotation (:data:`BETA0_CAM_FROM_PLATFORM`).

    Pixels are ``(x, y)`` px from the line centre (x along the line, y across it; ``y = 0`` on
    the line) with a band each, at a time ``t_s`` each. The :attr:`mount` is the same mount in
    the body frame of a :class:`hsgeo.trajectory.Trajectory` (x forward, y right, z down).

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    c_mm: tuple
    pixel_mm: float
    distortion: tuple = (0.0, 0.0, 0.0, 0.0)
    x0_mm: float = 0.0
    y0_mm: float = 0.0
    boresight_rad: tuple = (0.0, 0.0, 0.0)
    lever_arm_m: tuple = (0.0, 0.0, 0.0)
    beta0: np.ndarray = field(default_factory=lambda: BETA0_CAM_FROM_PLATFORM.copy())

    def __post_init__(self):
        c = np.atleast_1d(np.asarray(self.c_mm, dtype=float))
        if c.ndim != 1 or not np.all(np.isfinite(c) & (c > 0)):
            raise InputError(f"c_mm must be positive principal distances per band, got {c}")
        if not self.pixel_mm > 0:
            raise InputError(f"pixel pitch must be positive, got {self.pixel_mm!r} mm")
        if np.shape(self.distortion) != (4,):
            raise InputError("distortion must be (K1, K2, P1, P2) of 002 eq. (3)")

    @property
    def beta(self) -> np.ndarray:
        """``β = R_cam_from_platform = R_from_opk(ω, φ, κ) β₀``."""
        return R_from_opk(*np.asarray(self.boresight_rad, float)) @ np.asarray(self.beta0)

    @property
    def platform_mount(self) -> Mount:
        """The camera's mount on 002's platform frame (x forward, y left, z up): lever arm
        ``l^p`` and ``R_platform_from_camera = βᵀ``.
        """
        return Mount(np.asarray(self.lever_arm_m, float), self.beta.T)

    @property
    def mount(self) -> Mount:
        """The camera's mount on the trajectory's body frame (lever arm and boresight)."""
        D = R_BODY_FROM_PLATFORM
        m = self.platform_mount
        return Mount(D @ m.lever_arm_m, D @ m.R_body_from_sensor)

    def _band_c(self, band, n) -> np.ndarray:
        c = np.atleast_1d(np.asarray(self.c_mm, dtype=float))
        b = np.broadcast_to(np.asarray(band), (n,))
        if not np.issubdtype(b.dtype, np.integer) or np.any((b < 0) | (b >= c.size)):
            raise InputError(f"band indices must be integers in 0…{c.size - 1}")
        return c[b]

    def _unit_camera_directions(self, xy_px, band) -> np.ndarray:
        """Unit camera-frame directions ``(x̄, ȳ, c_b) / |·|`` of pixels ``(n, 2)`` (002 eq. (3)
        inverted: the pixel in mm from the principal point, undistorted, and the band's c).
        """
        xy_mm = xy_px * self.pixel_mm - np.array([self.x0_mm, self.y0_mm])
        if any(self.distortion):
            xy_mm = undistort_pushbroom_line(xy_mm, self.distortion)  # 002 eq. (3) inverted
        return unit(np.column_stack([xy_mm, self._band_c(band, xy_mm.shape[0])]))

    def _rays_by_line(self, xy_px, band, starts, xyz_platform_m, R_map_from_platform):
        """Rays of pixels grouped in lines ``starts`` (:func:`~hsgeo.sensors._pushbroom_rays.
        line_runs`) with one platform pose per line: the one implementation of :meth:`rays`
        and :meth:`rays_at`.

        ``R_map_from_platform βᵀ`` and the origin ``x + R l^p`` are formed once per line; the
        camera directions once per column when every line has the same pixels (and bands),
        else once per pixel; :func:`~hsgeo.sensors._pushbroom_rays.rays_by_line` turns them.
        """
        xy = np.asarray(xy_px, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2:
            raise InputError(f"pixels must be (n, 2) (x, y) px, got shape {xy.shape}")
        n, m = xy.shape[0], starts.size - 1
        b = np.asarray(band)
        if b.ndim and b.shape != (n,):
            raise InputError(f"band must be one index or one per pixel ({n}), got {b.shape}")
        k = int(starts[1] - starts[0]) if m else 0
        per_column = (
            m > 1
            and n == m * k
            and np.array_equal(starts, np.arange(m + 1) * k)
            and bool(np.all(xy.reshape(m, k, 2) == xy[:k]))
            and (b.ndim == 0 or bool(np.all(b.reshape(m, k) == b[:k])))
        )
        if per_column:
            u_cam = self._unit_camera_directions(xy[:k], b if b.ndim == 0 else b[:k])
        else:
            u_cam = self._unit_camera_directions(xy, b)
        R = np.asarray(R_map_from_platform, dtype=np.float64).reshape(m, 3, 3)
        # 002 eq. (4) read backwards, per line: x + R l^p and R βᵀ
        mount = self.platform_mount
        origin = mount.origins(np.reshape(xyz_platform_m, (m, 3)), R)
        R_map_from_cam = mount.R_map_from_sensor(R)
        origins, dirs = np.empty((n, 3)), np.empty((n, 3))
        rays_by_line(
            starts,
            np.ascontiguousarray(origin, dtype=np.float64),
            R_map_from_cam,
            np.ascontiguousarray(u_cam),
            per_column,
            origins,
            dirs,
        )
        return origins, dirs

    def rays_at(self, xy_px, band, xyz_platform_m, R_map_from_platform):
        """Rays of pixels at given platform poses (one pose per pixel; :meth:`rays` groups the
        pixels of a line under one pose).

        Parameters
        ----------
        xy_px : (n, 2) array_like, px
        band : int or (n,) int array_like
        xyz_platform_m : (n, 3) array_like, m
            Position of the platform (navigation reference point), map frame.
        R_map_from_platform : (n, 3, 3) array_like

        Returns
        -------
        origins_m, directions : (n, 3) ndarray
            Projection centres ``x + R l^p`` and unit directions ``R βᵀ (x̄, ȳ, c_b)``.
        """
        n = np.shape(xy_px)[0]
        xyz = np.broadcast_to(np.asarray(xyz_platform_m, dtype=np.float64), (n, 3))
        R = np.broadcast_to(np.asarray(R_map_from_platform, dtype=np.float64), (n, 3, 3))
        return self._rays_by_line(xy_px, band, np.arange(n + 1, dtype=np.int64), xyz, R)

    def rays(self, xy_px, t_s, trajectory, band=0) -> tuple[np.ndarray, np.ndarray]:
        """Origins (m) and unit directions of the rays of pixels seen at times ``t_s``.

        The pose is computed once per run of equal consecutive times (the pixels of one line)
        and the camera direction once per column when the lines share their pixels.

        Parameters
        ----------
        xy_px : (n, 2) array_like, px
        t_s : float or (n,) array_like, s
        trajectory : hsgeo.trajectory.Trajectory
            GNSS/INS poses of the body (corrected ones, for an adjusted trajectory).
        band : int or (n,) int array_like
            Band of each pixel (its principal distance).
        """
        n = np.shape(xy_px)[0]
        t = np.asarray(t_s, dtype=np.float64)
        if t.size == 1:
            t = np.full(n, t.item())
        if t.shape != (n,):
            raise InputError(f"t_s must be one time or one per pixel ({n}), got {t.shape}")
        starts = line_runs(t)
        t_line = t[starts[:-1]]
        pos, _ = trajectory.pose(t_line)
        R = trajectory.R_map_from_body(t_line) @ R_BODY_FROM_PLATFORM
        return self._rays_by_line(xy_px, band, starts, pos, R)

    def project_at(self, xyz_map_m, band, xyz_platform_m, R_map_from_platform) -> np.ndarray:
        """Pixels ``(n, 2)`` of map points at given platform poses (002 eq. (2)–(4))."""
        d = np.atleast_2d(np.asarray(xyz_map_m, float) - np.asarray(xyz_platform_m, float))
        R = np.broadcast_to(np.asarray(R_map_from_platform, dtype=float), (d.shape[0], 3, 3))
        c = self._band_c(band, d.shape[0])
        # 002 eq. (3)–(4): the compiled cores the adjustment's kernel calls (hsgeo._kernels)
        try:
            _, p, xy, *_ = pushbroom_image_rows(
                np.ascontiguousarray(R),
                np.ascontiguousarray(d, dtype=np.float64),
                np.asarray(self.lever_arm_m, dtype=np.float64),
                np.ascontiguousarray(self.beta),
                np.ascontiguousarray(c),
                np.asarray(self.distortion, dtype=np.float64),
                float(self.x0_mm),
                float(self.y0_mm),
            )
        except ZeroDivisionError:  # a point in the camera's plane (p^c_z = 0)
            p = np.zeros((1, 3))
        if np.any(p[:, 2] <= 0):
            raise ObservationError("points behind the pushbroom camera (p^c_z ≤ 0)")
        return xy / self.pixel_mm

    def project(self, xyz_map_m, t_s, trajectory, band=0) -> np.ndarray:
        """Pixels ``(x, y)`` ``(n, 2)`` of map points at times ``t_s`` (y = 0 on the line)."""
        pos, _ = trajectory.pose(t_s)
        R = trajectory.R_map_from_body(t_s) @ R_BODY_FROM_PLATFORM
        return self.project_at(xyz_map_m, band, pos, R)

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
        """Time at which each map point is on the line of ``band`` (image ``y = 0``), s.

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
            0-based band (its principal distance); None: band 0.
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
        band = 0 if band is None else band

        def across_px(X, t):
            return self.project(X, t, trajectory, band=band)[:, 1]

        return line_time(across_px, xyz_map_m, trajectory, t_start_s, tol_s, max_iter)
