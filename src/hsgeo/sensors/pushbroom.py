"""Linear pushbroom (LP) lines as pinhole exposures with spline trajectory corrections (002 eq. 2–4).

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

The nominal mount ``β₀`` maps the platform frame (x forward, y left, z up) to the camera frame
(x along the line to the right, y backward, z down the viewing direction).

References
----------
Jonassen et al. (2024), 002 eq. (2)–(4), §3.3–3.5.
"""

from __future__ import annotations

import numpy as np

from hsgeo.adjust import Indexed, ResidualBlock
from hsgeo.errors import InputError
from hsgeo.rotations import R_from_opk, R_from_rpy, dR_dopk, dR_drpy
from hsgeo.trajectory import SplineNodes

__all__ = ["PushbroomLines", "BETA0_CAM_FROM_PLATFORM", "BLOCK_NAMES", "project"]

#: Nominal camera-from-platform rotation (platform x forward, y left, z up → camera x right,
#: y backward, z down).
BETA0_CAM_FROM_PLATFORM = np.array([[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])

#: Default parameter block names used by :class:`PushbroomLines`.
BLOCK_NAMES = {
    "points": "points_m",
    "nodes": "nodes",
    "boresight": "boresight_rad",
    "lever_arm": "lever_arm_m",
    "distortion": "distortion",
    "c": "c_mm",
}


def _camera_geometry(values, names, nodes: SplineNodes, t_s, xyz_nav, rpy_nav, pidx, band,
                     beta0, jacobian):
    """p^c and intermediate quantities for every observation (002 eq. 4)."""
    P = values[names["points"]][pidx]
    idx, w = nodes.basis(t_s)
    node_vals = values[names["nodes"]]
    delta = np.einsum("ma,mak->mk", w, node_vals[idx])
    x = xyz_nav + delta[:, :3]
    rpy = rpy_nav + delta[:, 3:]
    R = R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    bore = values[names["boresight"]]
    beta = R_from_opk(bore[0], bore[1], bore[2]) @ beta0
    lever = values[names["lever_arm"]]
    d = P - x
    q = np.einsum("mji,mj->mi", R, d) - lever  # Rᵀ d − l
    p = q @ beta.T
    out = {"p": p, "q": q, "d": d, "R": R, "beta": beta, "idx": idx, "w": w, "rpy": rpy}
    return out


def project(values, names, nodes, t_s, xyz_nav, rpy_nav, pidx, band, beta0, x0_mm, y0_mm):
    """Image coordinates (mm) of every observation (002 eq. 2–4), without derivatives."""
    g = _camera_geometry(values, names, nodes, t_s, xyz_nav, rpy_nav, pidx, band, beta0, False)
    p = g["p"]
    c = values[names["c"]][band]
    K1, K2, P1, P2 = values[names["distortion"]]
    xb = c * p[:, 0] / p[:, 2]
    yb = c * p[:, 1] / p[:, 2]
    x = xb + K1 * xb**3 + K2 * xb**5 + 3 * P1 * xb**2 + x0_mm  # 002 eq. (3)
    y = yb + P2 * xb**2 + y0_mm
    return np.column_stack([x, y]), p


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
    names : dict, optional
        Parameter block names (defaults :data:`BLOCK_NAMES`).
    """

    name = "image points"
    group_size = 2

    def __init__(self, point, band, t_s, xy_px, xyz_nav_m, rpy_nav_rad, nodes: SplineNodes,
                 pixel_mm: float, sigma_px: float = 0.5, x0_mm: float = 0.0,
                 y0_mm: float = 0.0, names: dict | None = None,
                 beta0=BETA0_CAM_FROM_PLATFORM):
        point = np.asarray(point)
        m = point.size
        xy = np.asarray(xy_px, dtype=np.float64)
        for nm, arr, shape in [("band", band, (m,)), ("t_s", t_s, (m,)), ("xy_px", xy, (m, 2)),
                               ("xyz_nav_m", xyz_nav_m, (m, 3)),
                               ("rpy_nav_rad", rpy_nav_rad, (m, 3))]:
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
        super().__init__(np.full(2 * m, float(sigma_px)))
        self.point = point.astype(np.int64)
        self.band = np.asarray(band, dtype=np.int64)
        self.t_s = np.asarray(t_s, dtype=np.float64)
        self.xy_px = xy
        self.xyz_nav = np.asarray(xyz_nav_m, dtype=np.float64)
        self.rpy_nav = np.asarray(rpy_nav_rad, dtype=np.float64)
        self.nodes = nodes
        self.pixel_mm = float(pixel_mm)
        self.x0_mm, self.y0_mm = float(x0_mm), float(y0_mm)
        self.names = dict(BLOCK_NAMES if names is None else names)
        self.beta0 = np.asarray(beta0, dtype=np.float64)
        self._basis = nodes.basis(self.t_s)

    def image_mm(self, values):
        """Modelled image coordinates in mm, ``(m, 2)``."""
        xy, _ = project(values, self.names, self.nodes, self.t_s, self.xyz_nav, self.rpy_nav,
                        self.point, self.band, self.beta0, self.x0_mm, self.y0_mm)
        return xy

    def evaluate(self, values, jacobian):
        nm = self.names
        g = _camera_geometry(values, nm, self.nodes, self.t_s, self.xyz_nav, self.rpy_nav,
                             self.point, self.band, self.beta0, jacobian)
        p, q, d, R, beta = g["p"], g["q"], g["d"], g["R"], g["beta"]
        c = values[nm["c"]][self.band]
        K1, K2, P1, P2 = values[nm["distortion"]]
        iz = 1.0 / p[:, 2]
        xb = c * p[:, 0] * iz
        yb = c * p[:, 1] * iz
        x = xb + K1 * xb**3 + K2 * xb**5 + 3 * P1 * xb**2 + self.x0_mm  # 002 eq. (3)
        y = yb + P2 * xb**2 + self.y0_mm
        k = 1.0 / self.pixel_mm
        m = self.point.size
        r = np.empty(2 * m)
        r[0::2] = x * k - self.xy_px[:, 0]
        r[1::2] = y * k - self.xy_px[:, 1]
        if not jacobian:
            return r, None
        # d(x, y)/d p^c  (2 × 3 per observation), in px
        gx = 1.0 + 3 * K1 * xb**2 + 5 * K2 * xb**4 + 6 * P1 * xb  # dx/dx̄
        gy = 2 * P2 * xb  # dy/dx̄
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
        dDist = np.zeros((m, 2, 4))
        dDist[:, 0, 0] = xb**3 * k
        dDist[:, 0, 1] = xb**5 * k
        dDist[:, 0, 2] = 3 * xb**2 * k
        dDist[:, 1, 3] = xb**2 * k
        rep = np.repeat
        jac = {
            nm["points"]: Indexed(rep(self.point, 2), dP.reshape(2 * m, 3)),
            nm["nodes"]: Indexed(rep(idx, 2, axis=0), dnodes.reshape(2 * m, 4, 6)),
            nm["boresight"]: dBore.reshape(2 * m, 3),
            nm["lever_arm"]: dLever.reshape(2 * m, 3),
            nm["distortion"]: dDist.reshape(2 * m, 4),
            nm["c"]: Indexed(rep(self.band, 2), dC.reshape(2 * m, 1)),
        }
        return r, jac
