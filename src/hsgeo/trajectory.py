"""Timed poses of a GNSS/INS solution, and local cubic B-spline corrections at nodes (002 §3.3).

The one timed pose
------------------
:class:`Trajectory` holds a GNSS/INS solution as the instrument gives it: at each time ``t_s``
the position ``xyz_m`` = (E, N, U) in a local **east-north-up** map frame (metres), and the
attitude ``roll_pitch_heading_rad`` = (roll, pitch, heading) of the **body** (x forward, y right,
z down) relative to **north-east-down**::

    R_ned_from_body = R_from_rpy(roll, pitch, heading)            (hsgeo.rotations)
    R_map_from_body = R_ENU_FROM_NED @ R_ned_from_body            (Trajectory.R_map_from_body)

Positions and the three (unwrapped) angles are interpolated linearly in time
(:meth:`Trajectory.pose`); the velocity and angle rates are the slopes of that interpolation
(:meth:`Trajectory.rates`). Files: :mod:`hsgeo.io.navigation`.

The pushbroom model's angles (002)
----------------------------------
The pushbroom model of 002 (:mod:`hsgeo.sensors.pushbroom`) parametrises the attitude with its
own angles: roll, pitch, yaw of the **platform** frame (x forward, y left, z up) relative to
east-north-up, ``R_map_from_platform = R_from_rpy(roll, pitch, yaw)``; its node corrections
δroll, δpitch, δyaw are corrections of those angles. With
``R_body_from_platform = diag(1, −1, −1)`` the two are related exactly by::

    R_ENU_FROM_NED @ R_from_rpy(r, p, h) @ diag(1, −1, −1) = R_from_rpy(r, −p, π/2 − h)

so the platform angles are ``(roll, −pitch, π/2 − heading)`` (:func:`platform_rpy_from_rph`),
and back the same map (:func:`rph_from_platform_rpy`; it is its own inverse). The map is linear,
so interpolating either set of angles gives the same poses, and the rates convert as
``(ṙ, −ṗ, −ḣ)`` (:func:`platform_rpy_rate_from_rph_rate`).

Spline corrections
------------------
A GNSS/INS solution's high-frequency motion is right; what remains wrong is smooth and
low-frequency. The bundle adjustment therefore estimates *corrections*
``δ(t) = (δE, δN, δH, δroll, δpitch, δyaw)`` (platform angles) at nodes every ``Δt`` seconds
and interpolates them to each line's exposure time (002 Fig. 4).

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
from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

__all__ = [
    "Trajectory",
    "R_BODY_FROM_PLATFORM",
    "platform_rpy_from_rph",
    "rph_from_platform_rpy",
    "platform_rpy_rate_from_rph_rate",
    "SplineNodes",
    "corrected_trajectory",
    "bspline_basis",
    "bspline_basis_derivative",
    "CORRECTION_COLUMNS",
]

#: Names of the six corrections per node, in order (positions E, N, U; platform angles).
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
            raise InputError(f"node values must be ({self.n_nodes}, k), got {nodes.shape}")
        idx, w = self.basis(t_s)
        return np.einsum("ma,mak->mk", w, nodes[idx])


# ----------------------------------------------------------------------------------------------
# The one timed pose
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Trajectory:
    """Timed poses of a GNSS/INS solution, linearly interpolated in time.

    Parameters
    ----------
    t_s : (n,) array_like, s
        Strictly increasing times, n ≥ 2.
    xyz_m : (n, 3) array_like, m
        Position (E, N, U) in the local east-north-up map frame.
    roll_pitch_heading_rad : (n, 3) array_like, rad
        Roll, pitch, heading of the body (x forward, y right, z down) relative to
        north-east-down: ``R_ned_from_body = R_from_rpy(roll, pitch, heading)``. All three are
        unwrapped along time (``numpy.unwrap``) before they are stored, so that interpolation
        never passes the long way round ±180°.

    Raises
    ------
    InputError
        On wrong shapes, fewer than two records, NaN or inf, or times that do not increase
        strictly.

    Examples
    --------
    >>> import numpy as np
    >>> tr = Trajectory([0.0, 1.0], [[0, 0, 100], [10, 0, 100]], [[0, 0, 0], [0, 0, 0.2]])
    >>> xyz, rph = tr.pose(0.5)
    >>> xyz.tolist(), rph.round(6).tolist()
    ([[5.0, 0.0, 100.0]], [[0.0, 0.0, 0.1]])
    """

    t_s: np.ndarray
    xyz_m: np.ndarray
    roll_pitch_heading_rad: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.t_s, dtype=np.float64)
        p = np.asarray(self.xyz_m, dtype=np.float64)
        a = np.asarray(self.roll_pitch_heading_rad, dtype=np.float64)
        if t.ndim != 1 or p.shape != (t.size, 3) or a.shape != (t.size, 3):
            raise InputError(
                f"trajectory: times (n,), positions (n, 3) and attitudes (n, 3) expected, got "
                f"{t.shape}, {p.shape}, {a.shape}"
            )
        if t.size < 2:
            raise InputError("a trajectory needs at least 2 records")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p)) and np.all(np.isfinite(a))):
            raise InputError("trajectory records contain NaN or inf")
        if np.any(np.diff(t) <= 0):
            i = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise InputError(
                f"trajectory times must increase strictly (records {i}, {i + 1}): sort the "
                "records and drop duplicates"
            )
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "xyz_m", p)
        object.__setattr__(self, "roll_pitch_heading_rad", np.unwrap(a, axis=0))

    def pose(self, t_s) -> tuple[np.ndarray, np.ndarray]:
        """Position and attitude angles at the given times (linear interpolation).

        Parameters
        ----------
        t_s : float or (m,) array_like, s
            Times within the record.

        Returns
        -------
        xyz_m : (m, 3) ndarray, m
            Position (E, N, U).
        roll_pitch_heading_rad : (m, 3) ndarray, rad
            Roll, pitch, heading (NED), interpolated on the unwrapped angles.

        Raises
        ------
        InputError
            If a time falls outside the record.
        """
        t = self._times(t_s)
        pos = np.stack([np.interp(t, self.t_s, self.xyz_m[:, k]) for k in range(3)], axis=1)
        return pos, self._attitude(t)

    def _times(self, t_s) -> np.ndarray:
        """``t_s`` as a flat float array, checked to lie within the record."""
        t = np.atleast_1d(np.asarray(t_s, dtype=np.float64)).ravel()
        if np.any(t < self.t_s[0]) or np.any(t > self.t_s[-1]):
            raise InputError(
                f"times {t.min():.3f}…{t.max():.3f} s fall outside the trajectory "
                f"{self.t_s[0]:.3f}…{self.t_s[-1]:.3f} s: the navigation does not cover them"
            )
        return t

    def _attitude(self, t: np.ndarray) -> np.ndarray:
        """Roll, pitch, heading at checked times ``t`` (:meth:`pose`'s second output)."""
        a = self.roll_pitch_heading_rad
        return np.stack([np.interp(t, self.t_s, a[:, k]) for k in range(3)], axis=1)

    def rates(self, t_s, step_s: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
        """Velocity and attitude-angle rates at the given times.

        Central differences of :meth:`pose` over ``± step_s`` (one-sided at the ends of the
        record): the slope of the linear interpolation, averaged at the records.

        Returns
        -------
        velocity_m_s : (m, 3) ndarray, m/s
            (Ė, Ṅ, U̇).
        roll_pitch_heading_rate_rad_s : (m, 3) ndarray, rad/s
        """
        t = np.atleast_1d(np.asarray(t_s, dtype=np.float64)).ravel()
        self.pose(t)  # span check
        ta = np.maximum(t - step_s, self.t_s[0])
        tb = np.minimum(t + step_s, self.t_s[-1])
        xa, ra = self.pose(ta)
        xb, rb = self.pose(tb)
        dt = (tb - ta)[:, None]
        return (xb - xa) / dt, (rb - ra) / dt

    def R_map_from_body(self, t_s) -> np.ndarray:
        """``R_map_from_body = R_ENU_FROM_NED @ R_from_rpy(roll, pitch, heading)``, ``(m, 3, 3)``.

        Takes body vectors (x forward, y right, z down) to the east-north-up map frame.
        """
        a = self._attitude(self._times(t_s))  # the attitude of pose(), without the positions
        return R_ENU_FROM_NED @ R_from_rpy(a[:, 0], a[:, 1], a[:, 2])


# ----------------------------------------------------------------------------------------------
# The pushbroom model's platform angles (002) <-> the GNSS/INS angles
# ----------------------------------------------------------------------------------------------
#: Body (x forward, y right, z down) from the pushbroom model's platform frame (x forward,
#: y left, z up): ``xyz_body = R_BODY_FROM_PLATFORM @ xyz_platform`` (its own inverse).
R_BODY_FROM_PLATFORM = np.diag([1.0, -1.0, -1.0])
R_BODY_FROM_PLATFORM.setflags(write=False)
R_BODY_FROM_PLATFORM.setflags(write=False)


def _angles3(a, name: str) -> np.ndarray:
    a = np.array(a, dtype=np.float64)
    if a.ndim < 1 or a.shape[-1] != 3:
        raise InputError(f"{name} must have shape (..., 3), got {a.shape}")
    return a


def platform_rpy_from_rph(roll_pitch_heading_rad) -> np.ndarray:
    """The pushbroom model's platform angles from GNSS/INS roll, pitch, heading.

    ``(roll, pitch, yaw) = (roll, −pitch, π/2 − heading)``, exact because
    ``R_ENU_FROM_NED @ R_from_rpy(r, p, h) @ R_BODY_FROM_PLATFORM = R_from_rpy(r, −p, π/2 − h)``
    (see the module docstring).

    Parameters
    ----------
    roll_pitch_heading_rad : (..., 3) array_like, rad
        Attitude of the body (x forward, y right, z down) relative to north-east-down.

    Returns
    -------
    rpy_rad : (..., 3) ndarray, rad
        Attitude of the platform (x forward, y left, z up) relative to east-north-up,
        ``R_map_from_platform = R_from_rpy(roll, pitch, yaw)``.
    """
    a = _angles3(roll_pitch_heading_rad, "roll_pitch_heading_rad")
    return np.stack([a[..., 0], -a[..., 1], np.pi / 2 - a[..., 2]], axis=-1)


def rph_from_platform_rpy(rpy_rad) -> np.ndarray:
    """GNSS/INS roll, pitch, heading from the pushbroom model's platform angles.

    ``(roll, pitch, heading) = (roll, −pitch, π/2 − yaw)``: the inverse of
    :func:`platform_rpy_from_rph` (the map is its own inverse).

    Parameters
    ----------
    rpy_rad : (..., 3) array_like, rad
        ``R_map_from_platform = R_from_rpy(roll, pitch, yaw)`` (platform x forward, y left, z up;
        map east-north-up).

    Returns
    -------
    roll_pitch_heading_rad : (..., 3) ndarray, rad
        ``R_ned_from_body = R_from_rpy(roll, pitch, heading)`` (body x forward, y right, z down).
    """
    a = _angles3(rpy_rad, "rpy_rad")
    return np.stack([a[..., 0], -a[..., 1], np.pi / 2 - a[..., 2]], axis=-1)


def platform_rpy_rate_from_rph_rate(roll_pitch_heading_rate_rad_s) -> np.ndarray:
    """Rates of the platform angles from rates of roll, pitch, heading: ``(ṙ, −ṗ, −ḣ)``.

    The derivative of :func:`platform_rpy_from_rph` (a linear map); also its own inverse.

    Parameters
    ----------
    roll_pitch_heading_rate_rad_s : (..., 3) array_like, rad/s

    Returns
    -------
    rpy_rate_rad_s : (..., 3) ndarray, rad/s
    """
    a = _angles3(roll_pitch_heading_rate_rad_s, "roll_pitch_heading_rate_rad_s")
    return np.stack([a[..., 0], -a[..., 1], -a[..., 2]], axis=-1)


def corrected_trajectory(trajectory: Trajectory, nodes: SplineNodes, values) -> Trajectory:
    """The trajectory with the spline corrections of an adjustment applied (002 eq. 4).

    At every record ``x = x_nav + δ_xyz`` and the platform angles ``rpy_nav + δ_rpy``
    (:func:`platform_rpy_from_rph`), converted back to roll, pitch, heading. Records outside the
    spline's span take the correction at its nearest end (held constant).

    Parameters
    ----------
    trajectory : Trajectory
        The GNSS/INS solution the adjustment started from.
    nodes : SplineNodes
    values : (n_nodes, 6) array_like
        Node corrections in the order of :data:`CORRECTION_COLUMNS` (m, rad).

    Returns
    -------
    Trajectory
        At the same record times (the corrections vary over the node interval, seconds, far
        slower than the records).
    """
    t = np.clip(trajectory.t_s, nodes.t_start_s, nodes.t_end_s)
    v = np.asarray(values, dtype=np.float64)
    if v.shape != (nodes.n_nodes, len(CORRECTION_COLUMNS)):
        raise InputError(
            f"node corrections must be ({nodes.n_nodes}, {len(CORRECTION_COLUMNS)}) "
            f"({', '.join(CORRECTION_COLUMNS)}), got {v.shape}"
        )
    d = nodes.evaluate(v, t)
    rpy = platform_rpy_from_rph(trajectory.roll_pitch_heading_rad) + d[:, 3:]
    return Trajectory(trajectory.t_s, trajectory.xyz_m + d[:, :3], rph_from_platform_rpy(rpy))
