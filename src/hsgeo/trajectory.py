"""Timed platform poses and local cubic B-spline corrections at nodes (002 §3.3).

A GNSS/INS solution gives the platform pose at any time: position ``xyz_m`` in the map frame
(east, north, up) and attitude ``rpy_rad`` (roll, pitch, yaw) with
``R_map_from_platform = R_from_rpy(roll, pitch, yaw)`` (see :mod:`hsgeo.rotations`). Its
high-frequency motion is right; what remains wrong is smooth and low-frequency. The bundle
adjustment therefore estimates *corrections* ``δ(t) = (δE, δN, δH, δroll, δpitch, δyaw)`` at
nodes every ``Δt`` seconds and interpolates them to each line's exposure time (002 Fig. 4).

Which spline, and why
---------------------
We use the **uniform cubic B-spline** (local support): the correction at time ``t`` in the
interval ``[τ_k, τ_k + Δt)`` depends on the four node values ``c_{k-1} … c_{k+2}`` only,

``δ(t) = Σ_{a=0}^{3} B_a(u) c_{k-1+a}``,  ``u = (t - τ_k) / Δt``, with
``B_0 = (1-u)³/6``, ``B_1 = (3u³ - 6u² + 4)/6``, ``B_2 = (-3u³ + 3u² + 3u + 1)/6``, ``B_3 = u³/6``.

It is C² continuous like the interpolating ("natural") cubic spline, but an interpolating
spline is *global*: moving one node changes the curve everywhere, so every observation would
depend on every node and the Jacobian of the ~441,000 observations would be dense in the ~1,100
trajectory unknowns. With local support each line touches 4 nodes × 6 corrections = 24 columns.
The price: the node values are control values, not the correction at the node times (the curve
passes near, not through them; for a constant correction they coincide).

Node times: ``τ_j = t_start + (j - 1) Δt`` for ``j = 0 … n_nodes - 1`` with
``n_nodes = ceil((t_end - t_start) / Δt) + 3``, so that every ``t`` in ``[t_start, t_end]`` has
its four nodes.

References
----------
Jonassen et al. (2024), 002 §3.3, Fig. 4; Glira et al. (2016) for spline trajectory corrections.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo._kernels import bspline_weights_rows
from hsgeo.errors import InputError
from hsgeo.rotations import R_from_rpy

__all__ = ["Trajectory", "SplineNodes", "bspline_basis", "bspline_basis_derivative"]

#: Names of the six corrections per node, in order.
CORRECTION_COLUMNS = ("dE_m", "dN_m", "dH_m", "droll_rad", "dpitch_rad", "dyaw_rad")


def bspline_basis(u):
    """Uniform cubic B-spline weights at local coordinate ``u`` in [0, 1).

    The compiled core :func:`hsgeo._kernels.bspline_weights` (002 §3.3), which the pushbroom
    kernel evaluates too.

    Returns
    -------
    B : (..., 4) ndarray
        Weights of the nodes ``k-1, k, k+1, k+2``; they sum to one.
    """
    u = np.asarray(u, dtype=np.float64)
    w, _ = bspline_weights_rows(np.ascontiguousarray(u.ravel()), 1.0)
    return w.reshape(u.shape + (4,))


def bspline_basis_derivative(u):
    """Derivatives ``dB_a/du`` of :func:`bspline_basis` (divide by Δt for a rate per second)."""
    u = np.asarray(u, dtype=np.float64)
    _, dw = bspline_weights_rows(np.ascontiguousarray(u.ravel()), 1.0)
    return dw.reshape(u.shape + (4,))


@dataclass(frozen=True)
class SplineNodes:
    """Node layout of a local cubic B-spline correction (see the module docstring).

    Parameters
    ----------
    t_start_s, t_end_s : float
        Time span to cover (the exposure times of the observations).
    interval_s : float
        Node spacing Δt (002 §4: 10 s).
    """

    t_start_s: float
    t_end_s: float
    interval_s: float

    def __post_init__(self):
        if not (np.isfinite(self.interval_s) and self.interval_s > 0):
            raise InputError(f"node interval must be positive, got {self.interval_s!r} s")
        if not (np.isfinite(self.t_start_s) and np.isfinite(self.t_end_s)) or (
            self.t_end_s < self.t_start_s
        ):
            raise InputError(
                f"node span [{self.t_start_s}, {self.t_end_s}] s is not a finite interval"
            )

    @property
    def n_nodes(self) -> int:
        return int(np.ceil((self.t_end_s - self.t_start_s) / self.interval_s)) + 3

    @property
    def t_nodes_s(self) -> np.ndarray:
        return self.t_start_s + (np.arange(self.n_nodes) - 1) * self.interval_s

    def basis(self, t_s):
        """Node indices and weights at times ``t_s``.

        Returns
        -------
        index : (m, 4) int ndarray
            The four nodes each time depends on.
        weight : (m, 4) ndarray
            Their B-spline weights (the Jacobian of the correction w.r.t. the node values).
        """
        index, u = self.piece(t_s)
        return index, bspline_basis(u)

    def piece(self, t_s):
        """The four nodes of each time's cubic piece and the local coordinate ``u`` in it.

        Returns
        -------
        index : (m, 4) int ndarray
        u : (m,) ndarray
            In [0, 1] (at ``t_end_s``, 1 on the last piece).
        """
        t = np.asarray(t_s, dtype=np.float64).ravel()
        eps = 1e-9 * self.interval_s
        if np.any(t < self.t_start_s - eps) or np.any(t > self.t_end_s + eps):
            raise InputError(
                f"times outside the spline span [{self.t_start_s}, {self.t_end_s}] s: build "
                "SplineNodes over the observations' time range"
            )
        x = (t - self.t_start_s) / self.interval_s
        k = np.clip(np.floor(x).astype(np.int64), 0, self.n_nodes - 4)
        index = k[:, None] + np.arange(4)  # nodes k-1..k+2 in 0-based j = k .. k+3
        return index, x - k

    def evaluate_rate(self, nodes, t_s) -> np.ndarray:
        """Time derivative of the correction at ``t_s`` (per second), ``(m, k)``."""
        nodes = np.asarray(nodes, dtype=np.float64)
        if nodes.ndim != 2 or nodes.shape[0] != self.n_nodes:
            raise InputError(f"node values must be ({self.n_nodes}, k), got {nodes.shape}")
        idx, u = self.piece(t_s)
        dw = bspline_basis_derivative(u) / self.interval_s
        return np.einsum("ma,mak->mk", dw, nodes[idx])

    def evaluate(self, nodes, t_s) -> np.ndarray:
        """Correction at ``t_s`` from node values ``nodes`` ``(n_nodes, k)`` -> ``(m, k)``."""
        nodes = np.asarray(nodes, dtype=np.float64)
        if nodes.ndim != 2 or nodes.shape[0] != self.n_nodes:
            raise InputError(
                f"node values must be ({self.n_nodes}, k), got {nodes.shape}"
            )
        idx, w = self.basis(t_s)
        return np.einsum("ma,mak->mk", w, nodes[idx])


@dataclass
class Trajectory:
    """Timed platform poses (a GNSS/INS solution), linearly interpolated in time.

    Parameters
    ----------
    t_s : (n,) ndarray
        Strictly increasing times.
    xyz_m : (n, 3) ndarray
        Platform position (E, N, U) in the map frame.
    rpy_rad : (n, 3) ndarray
        Roll, pitch, yaw with ``R_map_from_platform = R_from_rpy(roll, pitch, yaw)``. Yaw is
        unwrapped before interpolation.
    """

    t_s: np.ndarray
    xyz_m: np.ndarray
    rpy_rad: np.ndarray

    def __post_init__(self):
        self.t_s = np.asarray(self.t_s, dtype=np.float64).ravel()
        self.xyz_m = np.asarray(self.xyz_m, dtype=np.float64)
        self.rpy_rad = np.asarray(self.rpy_rad, dtype=np.float64)
        n = self.t_s.size
        if n < 2:
            raise InputError("a trajectory needs at least two epochs")
        if self.xyz_m.shape != (n, 3) or self.rpy_rad.shape != (n, 3):
            raise InputError(
                f"trajectory: {n} times but positions {self.xyz_m.shape} and attitudes "
                f"{self.rpy_rad.shape}; expected ({n}, 3) each"
            )
        if not (np.all(np.isfinite(self.xyz_m)) and np.all(np.isfinite(self.rpy_rad))
                and np.all(np.isfinite(self.t_s))):
            raise InputError("trajectory contains NaN or inf")
        if np.any(np.diff(self.t_s) <= 0):
            raise InputError("trajectory times must be strictly increasing (sort the file)")
        self.rpy_rad = self.rpy_rad.copy()
        self.rpy_rad[:, 2] = np.unwrap(self.rpy_rad[:, 2])

    def pose(self, t_s):
        """Position ``(m, 3)`` and attitude angles ``(m, 3)`` at ``t_s`` (linear interpolation)."""
        t = np.asarray(t_s, dtype=np.float64).ravel()
        if np.any(t < self.t_s[0]) or np.any(t > self.t_s[-1]):
            raise InputError(
                f"times outside the trajectory [{self.t_s[0]}, {self.t_s[-1]}] s: the navigation "
                "file does not cover the observations"
            )
        xyz = np.column_stack([np.interp(t, self.t_s, self.xyz_m[:, i]) for i in range(3)])
        rpy = np.column_stack([np.interp(t, self.t_s, self.rpy_rad[:, i]) for i in range(3)])
        return xyz, rpy

    def rates(self, t_s, step_s: float = 1e-3):
        """Velocity ``(m, 3)`` m/s and attitude-angle rates ``(m, 3)`` rad/s at ``t_s``.

        Central differences of :meth:`pose` over ``± step_s`` (one-sided at the ends of the
        trajectory): the slope of the linear interpolation, averaged at the epochs.
        """
        t = np.asarray(t_s, dtype=np.float64).ravel()
        self.pose(t)  # span check
        ta = np.maximum(t - step_s, self.t_s[0])
        tb = np.minimum(t + step_s, self.t_s[-1])
        xa, ra = self.pose(ta)
        xb, rb = self.pose(tb)
        dt = (tb - ta)[:, None]
        return (xb - xa) / dt, (rb - ra) / dt

    def R_map_from_platform(self, t_s) -> np.ndarray:
        _, rpy = self.pose(t_s)
        return R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
