"""The simulated calibration flight of 004: a DAEDALUS crossing and flying along a runway.

The scene (004 § Application): a runway of asphalt about 50 pixels wide whose reflectance varies
by up to 20 % (a sum of cosines of 15–200 m wavelength, shared by the channels, plus a weaker
pattern that differs between channels), with structure finer than a pixel — sealed transverse
joints every 5 m and the centre line's painted dashes (ICAO: 30 m long, 0.9 m wide, 20 m apart),
integrated exactly over each pixel's footprint (:meth:`_Field.subpixel`) — grass beside it,
small bright landmarks at its sides;
the sun 40° from the zenith, at an azimuth such that the cross-runway scan makes 68.5° (to the
left) and 111.5° (to the right) with it. Reflectance images (the atmosphere already removed,
as in 004). The runway runs east–west, centred on N = 0.

Flights (:class:`RunwayScene`): one crossing at right angles (heading north, the runway spans the
whole scan line), one along the runway (heading east over its centre), and — beyond 004 — a
second crossing with the opposite heading. The scanner is
:class:`hsgeo.sensors.panoramic.PanoramicScanner` on a true trajectory; each pixel is the mean of
``subsamples²`` rays jittered over its footprint (its angle and its time; one in each cell),
times the channel's true ASF at the pixel's scan angle and a mild BRDF factor (switchable)::

    f(θv, φ) = 1 + k_even·sin²θv + k_odd·sin θv·cos φ

(θv the view zenith, φ the azimuth between the view and the sun): across the principal plane the
first term is even in the scan angle and the second odd. A residual of the atmospheric
correction (switchable, off by default) adds path radiance growing as 1/cos θv − 1. Multiplicative
sensor noise is added.
The recorded navigation differs from the true one by a constant position error per flight, so
that the along-runway image must be registered onto the cross scan.

The flights follow each other in time, so that one navigation record covers them all
(:func:`navigation`), as a GNSS/INS delivers it.

Chosen (not in 004, stated in the chapter): the true ASF curves (:func:`true_asf`, shaped as
the paper describes them — largest variation 15 % in channel 1, 4–12 % in the others), the
reflectances, the texture, the joints (5.5 mm, half as bright as the pavement) and the dashes,
the landmarks, the BRDF and path-radiance coefficients, the noise (0.5 % per sample),
the speed and line rate (0.63 m per line), the navigation errors.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.geocode import PlaneTerrain, intersect
from hsgeo.papers import ASF_004_FLIGHT
from hsgeo.sensors.panoramic import PanoramicScanner
from hsgeo.simulate import as_rng
from hsgeo.simulate.scenarios import ScenarioInfo
from hsgeo.trajectory import Trajectory

__all__ = [
    "RunwayScene",
    "AsfRunwayScenario",
    "Scan",
    "RunwayObservations",
    "RunwayTruth",
    "true_asf",
    "simulate_runway",
    "add_noise",
    "navigation",
    "ASF_PEAK_TO_PEAK_PERCENT",
]

#: Chosen peak-to-peak variation of the true ASF per channel, % (004: "variations up to 15 %
#: (depending on channel)"; the largest is the paper's 15 %, in channel 1 as in the 1994 lab).
ASF_PEAK_TO_PEAK_PERCENT = (15.0, 6.0, 4.0, 5.0, 4.0, 5.0, 7.0, 12.0, 8.0, 10.0, 6.0)
#: Chosen shape of each channel's curve: coefficients of x, x², x³, sin(3πx/2), x = θ/θ_max.
_SHAPES = (
    (0.3, -1.0, 0.2, 0.0),
    (0.5, -0.6, -0.2, 0.1),
    (-0.2, -1.0, 0.0, 0.05),
    (0.6, -0.4, 0.3, 0.0),
    (0.1, -1.0, -0.3, 0.1),
    (-0.4, -0.8, 0.2, 0.0),
    (0.5, -1.0, 0.0, -0.1),
    (0.8, -0.5, -0.4, 0.1),
    (-0.3, -1.0, 0.3, 0.0),
    (0.4, -0.9, 0.1, 0.15),
    (0.2, -0.7, -0.2, -0.05),
)
#: Reflectance of asphalt, grass and the landmarks' paint per channel (chosen).
_ASPHALT = (0.07, 0.08, 0.09, 0.10, 0.10, 0.11, 0.12, 0.13, 0.16, 0.15, 0.14)
_GRASS = (0.04, 0.05, 0.09, 0.07, 0.05, 0.20, 0.42, 0.45, 0.25, 0.12, 0.10)
_PAINT = (0.55, 0.60, 0.62, 0.62, 0.62, 0.62, 0.60, 0.58, 0.50, 0.45, 0.40)


@dataclass(frozen=True)
class RunwayScene:
    """The experiment's chosen parameters; defaults from 004 where it gives them."""

    height_m: float = ASF_004_FLIGHT["height_m"]  # 004
    runway_width_m: float = 32.0  # 004: "about 50 pixels" (0.63 m at nadir)
    runway_length_m: float = 1400.0
    reflectance_variation: float = ASF_004_FLIGHT["reflectance_variation"]  # 004
    n_cosines: int = 12
    texture_min_wavelength_m: float = 15.0
    landmark_spacing_m: float = 15.0
    landmark_size_m: float = 1.5
    landmark_offset_m: float = 3.0  # outside the runway edge
    sun_zenith_deg: float = ASF_004_FLIGHT["sun_zenith_deg"]  # 004
    sun_azimuth_deg: float = 201.5  # 004: scan-to-sun 68.5° (left) and 111.5° (right)
    brdf: bool = False
    brdf_even: float = 0.04
    brdf_odd: float = 0.05
    noise_relative: float = 0.005
    speed_m_s: float = 63.0
    line_rate_hz: float = 100.0
    subsamples: int = 2
    cross_margin_m: float = 14.0
    along_halfwidth_px: int = 50
    cross_nav_error_m: tuple[float, ...] = (0.6, -0.4, 0.0)
    along_nav_error_m: tuple[float, ...] = (-0.9, 0.7, 0.0)
    reverse_nav_error_m: tuple[float, ...] = (0.3, 0.5, 0.0)
    along_offset_m: float = 1.5  # the along track's distance north of the runway's centre line
    # sub-metre structure of the runway (chosen; 37.6: a runway with none lets any
    # registration pass): sealed transverse joints between the pavement's slabs and the
    # centre-line markings (ICAO Annex 14: dashes 30 m long, 20 m gaps, 0.9 m wide)
    joint_spacing_m: float = 5.0
    joint_width_m: float = 0.0055
    joint_factor: float = 0.5  # the sealant's reflectance / the pavement's
    centreline_dash_m: float = 30.0
    centreline_gap_m: float = 20.0
    centreline_width_m: float = 0.9
    # residual of the atmospheric correction (unmodelled; off by default): an additive term
    # growing with the view angle as 1/cos θv − 1, this share of the runway's mean
    # reflectance at θv = 43°
    path_radiance: bool = False
    path_radiance_percent: float = 3.0
    # the flights follow each other (one navigation file for all): start times, s
    flight_start_s: tuple[float, ...] = (0.0, 100.0, 200.0)
    sensor: PanoramicScanner = field(default_factory=PanoramicScanner)

    @property
    def n_channels(self) -> int:
        return len(ASF_PEAK_TO_PEAK_PERCENT)

    @property
    def runway_polygon_m(self) -> np.ndarray:
        """Corners (E, N) of the runway, m, counter-clockwise."""
        h, w = self.runway_length_m / 2, self.runway_width_m / 2
        return np.array([[-h, -w], [h, -w], [h, w], [-h, w]])


@dataclass(frozen=True)
class AsfRunwayScenario:
    """``data_synthetic/asf_runway.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`): the
    004 runway flights of the asf chapter, ``[scene]`` a :class:`RunwayScene`.
    """

    scenario: ScenarioInfo
    scene: RunwayScene = RunwayScene()


@dataclass(frozen=True)
class Scan:
    """One recorded flight line: reflectance, the pixels, timing and the recorded navigation."""

    values: np.ndarray  # (bands, lines, pixels)
    zeta_px: np.ndarray  # (pixels,)
    t0_s: float
    line_rate_hz: float
    trajectory: Trajectory  # recorded (with the navigation error)
    sensor: PanoramicScanner


@dataclass(frozen=True)
class RunwayObservations:
    """The scans a user has: the crossing, the along-runway flight, the reverse crossing (or
    None), and the runway's corners (E, N), m.
    """

    cross: Scan
    along: Scan
    reverse: Scan | None
    runway_polygon_m: np.ndarray


@dataclass(frozen=True)
class RunwayTruth:
    """What only reproduce/ may see."""

    scene: RunwayScene
    scan_angle_rad: np.ndarray  # (716,)
    asf: np.ndarray  # (bands, 716), 1 at nadir
    brdf_cross: np.ndarray  # (716,) mean BRDF factor over the runway of each cross column
    brdf_reverse: np.ndarray | None
    shift_m: np.ndarray  # the along image's offset from the cross scan, (E, N): e_along − e_cross
    shift_reverse_m: np.ndarray
    clean: dict  # noise-free images, by flight


def true_asf(scan_angle_rad, scene: RunwayScene | None = None) -> np.ndarray:
    """The chosen true ASF per channel, ``(11, n)``, 1 at nadir (θ = 0)."""
    scene = scene or RunwayScene()
    th_max = np.deg2rad(43.0)
    x = np.asarray(scan_angle_rad, dtype=float) / th_max
    grid = np.linspace(-1, 1, 2001)
    out = []
    for pp, (a, b, c, d) in zip(ASF_PEAK_TO_PEAK_PERCENT, _SHAPES, strict=True):

        def shape(u, a=a, b=b, c=c, d=d):
            return a * u + b * u**2 + c * u**3 + d * np.sin(1.5 * np.pi * u)

        g = shape(grid)
        k = (pp / 100.0) / (g.max() - g.min())
        out.append(1.0 + k * shape(x))
    return np.array(out)


def _cosines(rng, n, lam_min, lam_max, total):
    lam = np.exp(rng.uniform(np.log(lam_min), np.log(lam_max), n))
    ang = rng.uniform(0, np.pi, n)
    k = 2 * np.pi / lam
    kx, ky = k * np.cos(ang), k * np.sin(ang)
    amp = rng.uniform(0.5, 1.0, n)
    amp *= total / amp.sum()
    return kx, ky, rng.uniform(0, 2 * np.pi, n), amp


def _pattern(p, E, N):
    kx, ky, ph, amp = p
    out = np.zeros_like(E)
    for i in range(kx.size):
        out += amp[i] * np.cos(kx[i] * E + ky[i] * N + ph[i])
    return out


@dataclass(frozen=True)
class _Field:
    """The ground reflectance, ``(bands, n)`` at any (E, N)."""

    scene: RunwayScene
    runway: tuple
    runway2: tuple
    weights2: np.ndarray
    grass: tuple
    landmarks_en: np.ndarray
    feature_offsets_m: tuple  # where the joints and the centre-line dashes start (E, m)

    def __call__(self, E, N):
        s = self.scene
        on = np.abs(N) <= s.runway_width_m / 2
        rho = np.empty((s.n_channels, E.size))
        Er, Nr = E[on], N[on]
        v1 = _pattern(self.runway, Er, Nr)
        v2 = _pattern(self.runway2, Er, Nr)
        rho[:, on] = np.asarray(_ASPHALT)[:, None] * (1 + v1 + self.weights2[:, None] * v2)
        g = _pattern(self.grass, E[~on], N[~on])
        rho[:, ~on] = np.asarray(_GRASS)[:, None] * (1 + g)
        half = s.landmark_size_m / 2
        # landmarks: squares of paint; a grid lookup (they lie on two rows, N = ±row)
        lm = self.landmarks_en
        j = np.searchsorted(lm[:, 0], E)
        hit = np.zeros(E.shape, bool)
        for jj in (j - 1, j):
            jj = np.clip(jj, 0, lm.shape[0] - 1)
            hit |= (np.abs(E - lm[jj, 0]) <= half) & (np.abs(np.abs(N) - lm[jj, 1]) <= half)
        return np.where(hit, np.asarray(_PAINT)[:, None], rho)

    def subpixel(self, E, N, wE, wN):
        """Shares of each pixel's footprint (a box ``wE × wN`` m centred on (E, N)) covered by
        the centre-line paint and by the joints' sealant: these features are narrower than a
        pixel, so they are integrated over the footprint exactly instead of being hit by the
        jittered rays (a 2 cm joint hit by one ray in four would add its full contrast to a
        pixel by chance).
        """
        s = self.scene
        w = s.runway_width_m / 2
        e0, e1 = E - wE / 2, E + wE / 2
        n0, n1 = N - wN / 2, N + wN / 2
        jo, do = self.feature_offsets_m
        joints = _periodic_overlap(e0, e1, jo, s.joint_spacing_m, s.joint_width_m)
        joints *= _overlap(n0, n1, -w, w)
        cw = s.centreline_width_m / 2
        period = s.centreline_dash_m + s.centreline_gap_m
        paint = _periodic_overlap(e0, e1, do, period, s.centreline_dash_m)
        paint *= _overlap(n0, n1, -cw, cw)
        area = wE * wN
        return paint / area, joints / area


def _overlap(a0, a1, b0, b1):
    """Length of [a0, a1] ∩ [b0, b1]."""
    return np.clip(np.minimum(a1, b1) - np.maximum(a0, b0), 0.0, None)


def _periodic_overlap(a0, a1, x0, period, length):
    """Length of [a0, a1] ∩ (the union of [x0 + k·period, x0 + k·period + length], all k)."""

    def cum(x):
        u = x - x0
        return np.floor(u / period) * length + np.clip(np.mod(u, period), 0.0, length)

    return cum(a1) - cum(a0)


def _field(scene: RunwayScene, rng) -> _Field:
    lam = (scene.texture_min_wavelength_m, 200.0)
    runway = _cosines(rng, scene.n_cosines, *lam, 0.8 * scene.reflectance_variation)
    runway2 = _cosines(rng, 6, *lam, 0.2 * scene.reflectance_variation)
    weights2 = rng.uniform(-1, 1, scene.n_channels)
    grass = _cosines(rng, 8, 5.0, 40.0, 0.15)
    half = scene.runway_length_m / 2
    E = np.arange(-half, half, scene.landmark_spacing_m)
    E = E + rng.uniform(-0.3, 0.3, E.size) * scene.landmark_spacing_m
    row = scene.runway_width_m / 2 + scene.landmark_offset_m
    # one landmark on each side at each E (the field looks them up at |N| = row)
    lm = np.column_stack([np.sort(E), np.full(E.size, row)])
    offsets = (
        rng.uniform(0, scene.joint_spacing_m),
        rng.uniform(0, scene.centreline_dash_m + scene.centreline_gap_m),
    )
    return _Field(scene, runway, runway2, weights2, grass, lm, offsets)


def _path_radiance(scene: RunwayScene, directions) -> np.ndarray:
    """The atmospheric correction's residual, ``(bands, n)`` in reflectance units (0 if off)."""
    nb = scene.n_channels
    if not scene.path_radiance:
        return np.zeros((nb, directions.shape[0]))
    grow = 1.0 / np.abs(directions[:, 2]) - 1.0
    edge = 1.0 / np.cos(np.deg2rad(43.0)) - 1.0
    level = scene.path_radiance_percent / 100.0 * np.asarray(_ASPHALT)[:, None]
    return level * (grow / edge)[None]


def _brdf(scene: RunwayScene, origins, directions) -> np.ndarray:
    """BRDF factor of the view (direction from the ground to the sensor) of each ray."""
    if not scene.brdf:
        return np.ones(directions.shape[0])
    v = -directions
    sin_v = np.hypot(v[:, 0], v[:, 1])
    az_v = np.arctan2(v[:, 0], v[:, 1])
    phi = az_v - np.deg2rad(scene.sun_azimuth_deg)
    return 1.0 + scene.brdf_even * sin_v**2 + scene.brdf_odd * sin_v * np.cos(phi)


def _render(scene, field_, traj, lines, zeta, t0_s, asf, rng):
    """Noise-free image (bands, lines, pixels) and the BRDF factor of each pixel centre.

    Each pixel is the mean of ``subsamples²`` rays, one drawn uniformly in each cell of a
    ``subsamples × subsamples`` split of its footprint (stratified jitter): the expected value is
    the footprint's exact box average. Rays on a fixed grid would quantise where a sharp edge
    (the runway's, a landmark's) appears to ``1/subsamples`` of a pixel — the same error at every
    window along a straight edge, which biased the registration across the runway by 0.06 px.
    """
    s = scene.sensor
    m = scene.subsamples
    u = np.arange(m) / m - 0.5  # the cells' lower corners, px
    nb, nl, nz = scene.n_channels, lines.size, zeta.size
    out = np.zeros((nb, nl, nz))
    brdf = np.zeros((nl, nz))
    terrain = PlaneTerrain(0.0)
    for a in range(0, nl, 64):
        ll = lines[a : a + 64]
        L, Z = np.meshgrid(ll.astype(float), zeta, indexing="ij")
        acc = np.zeros((nb, L.size))
        for cu in u:
            for cz in u:
                du, dz = np.array([[cu], [cz]]) + rng.uniform(0.0, 1.0 / m, (2, L.size))
                t = s.times(L.ravel() + du, Z.ravel() + dz, t0_s, scene.line_rate_hz)
                o, d = s.rays(Z.ravel() + dz, t, traj)
                g = intersect(o, d, terrain)
                acc += field_(g[:, 0], g[:, 1])
        base = acc / m**2
        t = s.times(L.ravel(), Z.ravel(), t0_s, scene.line_rate_hz)
        o, d = s.rays(Z.ravel(), t, traj)
        g0 = intersect(o, d, terrain)
        # the footprint's extent in E and N from the neighbouring pixel and line
        ext = np.zeros((2, L.size))
        for dl, dz in ((0.0, 1.0), (1.0, 0.0)):
            t1 = s.times(L.ravel() + dl, Z.ravel() + dz, t0_s, scene.line_rate_hz)
            g1 = intersect(*s.rays(Z.ravel() + dz, t1, traj), terrain)
            ext += np.abs(g1[:, :2] - g0[:, :2]).T
        if hasattr(field_, "subpixel"):  # a bare function of (E, N) has no sub-pixel parts
            paint, joint = field_.subpixel(g0[:, 0], g0[:, 1], ext[0], ext[1])
            base = base * (1.0 - paint - (1.0 - scene.joint_factor) * joint)
            base += paint[None] * np.asarray(_PAINT)[:, None]
        b = _brdf(scene, o, d)
        val = base * b[None] + _path_radiance(scene, d)
        out[:, a : a + ll.size] = val.reshape(nb, ll.size, nz)
        brdf[a : a + ll.size] = b.reshape(ll.size, nz)
    return out * asf[:, None, :], brdf


def _flight(scene, heading_rad, start_en, n_lines, nav_error_m, t_start_s=0.0):
    """True and recorded trajectories of a straight level flight, and t0 of line 0."""
    T = n_lines / scene.line_rate_hz + 2.0
    v = scene.speed_m_s * np.array([np.sin(heading_rad), np.cos(heading_rad), 0.0])
    p0 = np.array([start_en[0], start_en[1], scene.height_m]) - v * 1.0
    t = t_start_s + np.array([0.0, T])
    xyz = np.stack([p0, p0 + v * T])
    att = np.tile(np.deg2rad([0.3, -0.2, 0.0]) + [0, 0, heading_rad], (2, 1))
    true = Trajectory(t, xyz, att)
    rec = Trajectory(t, xyz + np.asarray(nav_error_m, float), att)
    return true, rec, t_start_s + 1.0


def simulate_runway(scene: RunwayScene | None = None, rng=0, *, reverse: bool = True):
    """Render the crossing, the along-runway flight (and the reverse crossing) with noise.

    Returns
    -------
    (RunwayObservations, RunwayTruth)
    """
    scene = scene or RunwayScene()
    rng = as_rng(rng)
    field_ = _field(scene, rng)
    s = scene.sensor
    zeta_all = np.arange(s.n_px, dtype=float)
    th_all = s.scan_angle_rad(zeta_all)
    asf = true_asf(th_all, scene)
    dl = scene.speed_m_s / scene.line_rate_hz
    half_w = scene.runway_width_m / 2 + scene.cross_margin_m
    n_cross = int(np.ceil(2 * half_w / dl))
    swath = scene.height_m * np.tan(np.deg2rad(43.5)) + 20.0
    n_along = int(np.ceil(2 * swath / dl))
    flights = {
        "cross": (0.0, (0.0, -half_w), n_cross, scene.cross_nav_error_m, zeta_all),
        "along": (
            np.pi / 2,
            (-swath, scene.along_offset_m),
            n_along,
            scene.along_nav_error_m,
            np.arange(
                s.zeta0_px - scene.along_halfwidth_px + 0.5, s.zeta0_px + scene.along_halfwidth_px
            ),
        ),
    }
    if reverse:
        flights["reverse"] = (np.pi, (0.0, half_w), n_cross, scene.reverse_nav_error_m, zeta_all)
    scans, clean, brdfs = {}, {}, {}
    starts = dict(zip(("cross", "along", "reverse"), scene.flight_start_s, strict=True))
    for name, (heading, start, n, err, zeta) in flights.items():
        true, rec, t0 = _flight(scene, heading, start, n, err, starts[name])
        a = asf[:, np.rint(zeta).astype(int)]
        img, brdf = _render(scene, field_, true, np.arange(n), zeta, t0, a, rng)
        clean[name] = img
        brdfs[name] = brdf
        scans[name] = Scan(
            add_noise(img, scene, rng), zeta, t0, scene.line_rate_hz, rec, scene.sensor
        )
    on = scene.runway_width_m / 2

    def column_brdf(name):
        b = brdfs[name]
        # lines whose nadir lies on the runway: the lines over the runway (heading ±north)
        n = b.shape[0]
        y = -half_w + (np.arange(n) + 0.5) * dl
        return b[np.abs(y) <= on].mean(axis=0)

    err = {k: np.asarray(v[3], float)[:2] for k, v in flights.items()}
    obs = RunwayObservations(
        scans["cross"], scans["along"], scans.get("reverse"), scene.runway_polygon_m
    )
    truth = RunwayTruth(
        scene,
        th_all,
        asf,
        column_brdf("cross"),
        column_brdf("reverse") if reverse else None,
        err["along"] - err["cross"],
        err["along"] - err["reverse"] if reverse else np.zeros(2),
        clean,
    )
    return obs, truth


def add_noise(clean, scene: RunwayScene, rng) -> np.ndarray:
    """Multiplicative sensor noise: ``x·(1 + σ·n)``, n standard normal (chosen σ = 0.5 %)."""
    rng = as_rng(rng)
    x = np.asarray(clean, dtype=float)
    return x * (1.0 + scene.noise_relative * rng.standard_normal(x.shape))


def navigation(obs: RunwayObservations) -> Trajectory:
    """The recorded navigation of all flights as one record (what a GNSS/INS delivers for the
    whole campaign): the flights' records in time order.
    """
    trs = [s.trajectory for s in (obs.cross, obs.along, obs.reverse) if s is not None]
    trs.sort(key=lambda tr: tr.t_s[0])
    return Trajectory(
        np.concatenate([tr.t_s for tr in trs]),
        np.concatenate([tr.xyz_m for tr in trs]),
        np.concatenate([tr.roll_pitch_heading_rad for tr in trs]),
    )
