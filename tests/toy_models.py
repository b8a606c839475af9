"""Small residual blocks used to test the engine (independent of any sensor model)."""

import numpy as np

from hsgeo.adjust import Indexed, ResidualBlock


class Line(ResidualBlock):
    """y = a + b t: a linear model, solvable in closed form with numpy.linalg.lstsq."""

    name = "line"
    BLOCKS = {"ab": "ab"}

    def __init__(self, t, y, sigma, blocks=None):
        super().__init__(np.broadcast_to(sigma, np.shape(y)), blocks=blocks)
        self.t, self.y = np.asarray(t, float), np.asarray(y, float)

    def evaluate(self, values, jacobian):
        a, b = values[self.blocks["ab"]]
        r = a + b * self.t - self.y
        if not jacobian:
            return r, None
        return r, {self.blocks["ab"]: np.column_stack([np.ones_like(self.t), self.t])}


class Exponential(ResidualBlock):
    """y = A exp(-k t): non-linear, for comparison with scipy.optimize.least_squares."""

    name = "exponential"
    BLOCKS = {"Ak": "Ak"}

    def __init__(self, t, y, sigma, blocks=None):
        super().__init__(np.broadcast_to(sigma, np.shape(y)), blocks=blocks)
        self.t, self.y = np.asarray(t, float), np.asarray(y, float)

    def evaluate(self, values, jacobian):
        A, k = values[self.blocks["Ak"]]
        e = np.exp(-k * self.t)
        r = A * e - self.y
        if not jacobian:
            return r, None
        return r, {self.blocks["Ak"]: np.column_stack([e, -A * self.t * e])}


class Bearings(ResidualBlock):
    """Planar bearings from stations (x, y, heading) to points (x, y): a tiny bundle block.

    θ = atan2(Py − Sy, Px − Sx) − heading. Stations are an ordinary Indexed block, points the
    Schur-eliminated points block (or an ordinary block, to compare the two solutions).
    """

    name = "bearings"
    BLOCKS = {"stations": "stations", "points": "points"}

    def __init__(self, station, point, theta_rad, sigma_rad, blocks=None):
        super().__init__(np.full(len(theta_rad), sigma_rad), blocks=blocks)
        self.station, self.point = np.asarray(station), np.asarray(point)
        self.theta = np.asarray(theta_rad, float)

    @staticmethod
    def model(S, P, station, point):
        d = P[point] - S[station, :2]
        return np.arctan2(d[:, 1], d[:, 0]) - S[station, 2], d

    def evaluate(self, values, jacobian):
        S, P = values[self.blocks["stations"]], values[self.blocks["points"]]
        th, d = self.model(S, P, self.station, self.point)
        r = np.angle(np.exp(1j * (th - self.theta)))
        if not jacobian:
            return r, None
        q = (d**2).sum(axis=1)
        dth_dP = np.column_stack([-d[:, 1] / q, d[:, 0] / q])
        dth_dS = np.column_stack([-dth_dP, -np.ones(len(q))])
        nm = self.blocks
        return r, {
            nm["stations"]: Indexed(self.station, dth_dS),
            nm["points"]: Indexed(self.point, dth_dP),
        }


def bearing_scene(rng, n_stations=6, n_points=40, sigma_rad=1e-3, coverage=4):
    """Stations on a circle looking inward, points inside; returns truth and observations."""
    rng = np.random.default_rng(rng)
    ang = np.linspace(0, 2 * np.pi, n_stations, endpoint=False)
    heading = ang + np.pi + 0.1 * rng.standard_normal(n_stations)
    S = np.column_stack([100 * np.cos(ang), 100 * np.sin(ang), heading])
    P = rng.uniform(-40, 40, (n_points, 2))
    st, pt = [], []
    for j in range(n_points):
        for s in rng.choice(n_stations, size=coverage, replace=False):
            st.append(s)
            pt.append(j)
    st, pt = np.array(st), np.array(pt)
    th, _ = Bearings.model(S, P, st, pt)
    th = th + sigma_rad * rng.standard_normal(th.size)
    return S, P, st, pt, th


def frame_scene(rng, n=30, n_views=3):
    """Object points and camera poses of a small frame-camera bench, drawn from ``rng``.

    Returns ``X (n, 3)``, ``poses (n_views, 6)`` (ω, φ, κ, X0, Y0, Z0), ``view`` and ``Xall``
    (one row per observation).
    """
    X = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-0.2, 0.2, n)])
    poses = np.column_stack(
        [
            rng.normal(0, 0.1, (n_views, 3)),
            rng.normal(0, 0.3, (n_views, 2)),
            rng.uniform(-5, -3, n_views),
        ]
    )
    view = np.repeat(np.arange(n_views), n)
    Xall = np.tile(X, (n_views, 1))
    return X, poses, view, Xall
