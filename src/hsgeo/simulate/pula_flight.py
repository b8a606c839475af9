"""An airborne line-scanner flight over a GCP calibration field (000 § Verification; 001 §2.1).

The ImSpector V9 + PixelFly scanner, coupled to an iMAR iVRU-RSSC IMU (200 Hz) and a
single-frequency GPS, flies one line over a field of ground control points. The truth is a smooth
trajectory with helicopter-like attitude motion; the recorded navigation adds GNSS and IMU errors;
the scanner is mounted with an unknown boresight misalignment. Each GCP is observed where the
true sensor sees it: its line (sub-line centroid, with noise) and its pixel ζ (with noise).

:func:`simulate_flight` returns ``(observations, truth)``: the recorded navigation, the GCP
image observations and what the operator knows (surveyed GCPs, nominal sensor) in
:class:`FlightObservations`; the true navigation, sensor and boresight in :class:`FlightTruth`.
Geocoding the GCPs is a workflow (:func:`hsgeo.workflows.geocoding.gcp_deviations`).

Every function takes ``rng``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.geocode import PlaneTerrain
from hsgeo.io.config import Key
from hsgeo.io.navigation import write_trajectory
from hsgeo.io.tables import write_csv_array
from hsgeo.papers import P000_TABLE1_CALIBRATED, P000_TABLE1_UNCALIBRATED
from hsgeo.sensors.line import CalibratedLine, LinearIFOV, LineGeometry
from hsgeo.sensors.mount import Mount
from hsgeo.simulate import as_rng
from hsgeo.simulate.scenarios import ScenarioInfo
from hsgeo.trajectory import Trajectory

__all__ = [
    "PulaFlightScenario",
    "FlightSensorTruth",
    "FlightSensorNominal",
    "FlightScanner",
    "FlightImu",
    "FlightGnss",
    "FlightPath",
    "GcpField",
    "FlightMeasurement",
    "FlightObservations",
    "FlightTruth",
    "simulate_flight",
    "gcp_field",
    "observe_gcps",
    "gcp_sightings",
    "gcps_in_swath",
    "MAX_FLIGHT_DRAWS",
    "generate",
    "airfield_scene",
    "render_line_image",
    "true_sensor",
    "nominal_sensor",
]


def _floats(n: int | None = None, doc: str = ""):
    return field(metadata={"key": Key("floats", length=n, doc=doc)})


@dataclass(frozen=True)
class FlightSensorTruth:
    """``[sensor_truth]``: the calibrated inner orientation at 870 nm (000 Table 1)."""

    zeta0_px: float = P000_TABLE1_CALIBRATED.zeta0_px
    c_px: float = P000_TABLE1_CALIBRATED.c_px
    K: tuple[float, ...] = (
        P000_TABLE1_CALIBRATED.K1,
        P000_TABLE1_CALIBRATED.K2,
        P000_TABLE1_CALIBRATED.K3,
    )


@dataclass(frozen=True)
class FlightSensorNominal:
    """``[sensor_nominal]``: the uncalibrated model of Jakšić (2009), 000 Table 1."""

    zeta0_px: float = P000_TABLE1_UNCALIBRATED.zeta0_px
    c_px: float = P000_TABLE1_UNCALIBRATED.c_px


@dataclass(frozen=True)
class FlightScanner:
    """``[scanner]``: line rate (Hz) and the pixels used either side of ζ0 (000 Fig. 7)."""

    line_rate_hz: float = field(metadata={"key": Key("float", positive=True)})
    usable_half_width_px: float = field(metadata={"key": Key("float", positive=True)})


@dataclass(frozen=True)
class FlightImu:
    """``[imu]``: rate and errors of the IMU (001 §2.1)."""

    rate_hz: float = field(metadata={"key": Key("float", positive=True)})
    attitude_noise_deg: float
    attitude_bias_deg: float
    heading_drift_deg_per_s: float


@dataclass(frozen=True)
class FlightGnss:
    """``[gnss]``: constant bias, random walk and white noise of the GNSS positions."""

    bias_m: float
    random_walk_m_per_sqrt_s: float
    white_m: float


@dataclass(frozen=True)
class FlightPath:
    """``[flight]``: height, speed, heading and motion of the flight line (chosen)."""

    height_agl_m: float
    speed_m_s: float = field(metadata={"key": Key("float", positive=True)})
    heading_deg: float
    start_EN_m: tuple[float, ...] = _floats(2)
    strip_length_m: float = field(metadata={"key": Key("float", positive=True)})
    attitude_motion_deg: tuple[float, ...] = _floats(3, "roll, pitch, heading amplitudes")
    attitude_period_s: tuple[float, ...] = _floats(3, "roll, pitch, heading periods")
    lateral_wander_m: float
    height_wander_m: float
    boresight_sigma_deg: float


@dataclass(frozen=True)
class GcpField:
    """``[field]``: the GCPs, across track in nominal px and along track in m, on a flat field
    of ``height_m``.
    """

    gcp_id: tuple[int, ...]
    across_px: tuple[float, ...]
    along_m: tuple[float, ...]
    height_m: float


@dataclass(frozen=True)
class FlightMeasurement:
    """``[measurement]``: σ of a GCP's measured ζ (px) and line (lines)."""

    sigma_px: float
    sigma_line: float


@dataclass(frozen=True)
class PulaFlightScenario:
    """``data_synthetic/pula_flight.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`)."""

    scenario: ScenarioInfo
    scanner: FlightScanner
    imu: FlightImu
    gnss: FlightGnss
    flight: FlightPath
    field: GcpField
    measurement: FlightMeasurement
    sensor_truth: FlightSensorTruth = FlightSensorTruth()
    sensor_nominal: FlightSensorNominal = FlightSensorNominal()


@dataclass(frozen=True)
class FlightObservations:
    """What the operator of one simulated flight has: nothing here is truth.

    Attributes
    ----------
    recorded_nav : Trajectory
        The recorded GNSS/IMU navigation (with its errors).
    t0_s : float
        Time of line 0, s.
    line_rate_hz : float
        Scanner line rate, Hz.
    gcp_id : (n,) int ndarray
        GCP labels.
    gcp_enu_m : (n, 3) ndarray
        Surveyed GCP coordinates, E, N, U in m.
    line : (n,) ndarray
        Measured (fractional) line of each GCP.
    zeta_px : (n,) ndarray
        Measured pixel of each GCP, px.
    terrain_height_m : float
        Height of the (flat) field, m.
    sensor_nominal : LinearIFOV
        The uncalibrated sensor model the operator starts from (Jakšić 2009).
    """

    recorded_nav: Trajectory
    t0_s: float
    line_rate_hz: float
    gcp_id: np.ndarray
    gcp_enu_m: np.ndarray
    line: np.ndarray
    zeta_px: np.ndarray
    terrain_height_m: float
    sensor_nominal: LinearIFOV


@dataclass(frozen=True)
class FlightTruth:
    """The truth of one simulated flight (for :mod:`hsgeo.reproduce` and rendering only).

    Attributes
    ----------
    true_nav : Trajectory
        The true trajectory.
    sensor : CalibratedLine
        The true sensor (000 Table 1).
    boresight_rad : (3,) ndarray
        True (roll, pitch, heading) misalignment of the scanner, rad.
    gcp_enu_m : (n, 3) ndarray
        True GCP coordinates, m (the surveyed ones are exact in this scenario).
    terrain_height_m : float
        True height of the field, m.
    t0_s, line_rate_hz : float
        Time of line 0 (s) and line rate (Hz) of the scanner.
    n_draws : int
        How many draws :func:`simulate_flight` took to get a flight that images every GCP
        within the usable swath (1: the first draw was kept).
    """

    true_nav: Trajectory
    sensor: CalibratedLine
    boresight_rad: np.ndarray
    gcp_enu_m: np.ndarray
    terrain_height_m: float
    t0_s: float
    line_rate_hz: float
    n_draws: int = 1


def gcp_field(cfg: PulaFlightScenario) -> tuple[np.ndarray, np.ndarray]:
    """GCP ids and (E, N, U) from the scenario's ``[field]`` table."""
    f, fl = cfg.field, cfg.flight
    ids = np.asarray(f.gcp_id, dtype=int)
    h = np.deg2rad(fl.heading_deg)
    u = np.array([np.sin(h), np.cos(h)])  # along track (E, N)
    w = np.array([np.cos(h), -np.sin(h)])  # across track, to the right
    across_m = np.asarray(f.across_px) * fl.height_agl_m / cfg.sensor_truth.c_px
    EN = np.asarray(fl.start_EN_m) + np.outer(f.along_m, u) + np.outer(across_m, w)
    return ids, np.column_stack([EN, np.full(len(ids), f.height_m)])


def _true_trajectory(cfg: PulaFlightScenario, rng) -> tuple[Trajectory, float, float]:
    fl = cfg.flight
    v, H = fl.speed_m_s, fl.height_agl_m + cfg.field.height_m
    heading = np.deg2rad(fl.heading_deg)
    length = fl.strip_length_m
    T = length / v
    t = np.arange(0.0, T + 1e-9, 1.0 / cfg.imu.rate_hz)
    u = np.array([np.sin(heading), np.cos(heading)])  # flight direction in (E, N)
    start = np.array(fl.start_EN_m)
    # attitude motion: a few sinusoids per axis with random phases (helicopter-like)
    amp = np.deg2rad(np.array(fl.attitude_motion_deg))
    per = np.array(fl.attitude_period_s)
    ph = rng.uniform(0, 2 * np.pi, 3)
    rph = np.stack([amp[k] * np.sin(2 * np.pi * t / per[k] + ph[k]) for k in range(3)], axis=1)
    rph[:, 2] += heading  # roll, pitch, heading (NED)
    s = v * t
    lateral = fl.lateral_wander_m * np.sin(2 * np.pi * t / (2.5 * per[0]) + ph[1])
    EN = start + s[:, None] * u + lateral[:, None] * np.array([u[1], -u[0]])
    U = H + fl.height_wander_m * np.sin(2 * np.pi * t / (3 * per[1]) + ph[2])
    return Trajectory(t, np.column_stack([EN, U]), rph), T, H


def _recorded(nav: Trajectory, cfg: PulaFlightScenario, rng) -> Trajectory:
    """Add GNSS and IMU errors (001 §2.1: iVRU-RSSC attitude resolution < 0.01°)."""
    g, imu = cfg.gnss, cfg.imu
    n = nav.t_s.size
    dt = np.diff(nav.t_s, prepend=nav.t_s[0])
    pos_bias = rng.normal(0, g.bias_m, 3)
    steps = rng.normal(0, 1, (n, 3)) * np.sqrt(dt)[:, None]
    walk = np.cumsum(steps, axis=0) * g.random_walk_m_per_sqrt_s
    pos = nav.xyz_m + pos_bias + walk + rng.normal(0, g.white_m, (n, 3))
    att_bias = rng.normal(0, np.deg2rad(imu.attitude_bias_deg), 3)
    att = (
        nav.roll_pitch_heading_rad
        + att_bias
        + rng.normal(0, np.deg2rad(imu.attitude_noise_deg), (n, 3))
        + np.deg2rad(imu.heading_drift_deg_per_s) * nav.t_s[:, None] * np.array([0, 0, 1])
    )
    return Trajectory(nav.t_s, pos, att)


def gcp_sightings(nav: Trajectory, boresight_rad, gcp_enu_m) -> tuple[np.ndarray, np.ndarray]:
    """When and under which view angle the true sensor sees each GCP (noise-free).

    The time is where the GCP crosses the scan plane (sensor x = 0), found by bisection on the
    true trajectory; the angle is the tangent y/z of the GCP in the sensor frame then. Returns
    ``(t_s (n,), tan_angle (n,))``; ``t_s`` is NaN for a GCP that the scan plane does not cross
    during the flight (it is ahead of the first line or behind the last).
    """
    mount = Mount.from_rpy(boresight_rad)  # the sensors' one mount (no lever arm here)

    def sensor_coords(t, X):
        pos, _ = nav.pose(t)
        return mount.to_sensor(X, pos, nav.R_map_from_body(t))

    lo = np.full(len(gcp_enu_m), nav.t_s[0])
    hi = np.full(len(gcp_enu_m), nav.t_s[-1])
    f_lo = sensor_coords(lo, gcp_enu_m)[:, 0]
    crossed = np.sign(f_lo) != np.sign(sensor_coords(hi, gcp_enu_m)[:, 0])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        f_mid = sensor_coords(mid, gcp_enu_m)[:, 0]
        left = np.sign(f_mid) == np.sign(f_lo)
        lo = np.where(left, mid, lo)
        f_lo = np.where(left, f_mid, f_lo)
        hi = np.where(left, hi, mid)
    t = 0.5 * (lo + hi)
    xs = sensor_coords(t, gcp_enu_m)
    return np.where(crossed, t, np.nan), xs[:, 1] / xs[:, 2]


def observe_gcps(
    nav: Trajectory,
    sensor: LineGeometry,
    boresight_rad,
    t0_s,
    line_rate_hz,
    gcp_enu_m,
    rng,
    sigma_line: float,
    sigma_px: float,
):
    """Where the true sensor sees each GCP: (fractional line, ζ), with measurement noise.

    The line time and view angle are :func:`gcp_sightings`; ζ follows from the true sensor's
    inverse model (which raises :class:`~hsgeo.ConvergenceError` for a GCP outside its
    calibrated field of view; :func:`simulate_flight` never asks for one).
    """
    t, tan = gcp_sightings(nav, boresight_rad, gcp_enu_m)
    return _measured(t, tan, sensor, t0_s, line_rate_hz, rng, sigma_line, sigma_px)


def _measured(t_s, tan, sensor, t0_s, line_rate_hz, rng, sigma_line, sigma_px):
    """The noisy (line, ζ) of GCPs seen at times ``t_s`` under tangents ``tan``."""
    zeta = sensor.zeta(tan)
    line = (t_s - t0_s) * line_rate_hz
    return (line + rng.normal(0, sigma_line, line.size), zeta + rng.normal(0, sigma_px, zeta.size))


def gcps_in_swath(t_s, tan_angle, sensor: LineGeometry, half_width_px: float) -> np.ndarray:
    """Which GCPs the scanner images: crossed during the flight (``t_s`` finite) and seen within
    the usable swath ``|ζ − ζ0| ≤ half_width_px`` (000 Fig. 7 / 001 Fig. 8: the calibrated field
    of view ends at 450 px). The test is on the tangent, against the forward model's tangents of
    the swath's two edges, so a direction outside it is never inverted.
    """
    edges = sensor.tan_angle(sensor.zeta0_px + np.array([half_width_px, -half_width_px]))
    tan = np.asarray(tan_angle, dtype=float)
    return np.isfinite(t_s) & (tan >= edges.min()) & (tan <= edges.max())


def nominal_sensor(cfg: PulaFlightScenario) -> LinearIFOV:
    """The uncalibrated model of Jakšić (2009) from ``[sensor_nominal]``."""
    s = cfg.sensor_nominal
    return LinearIFOV(s.zeta0_px, s.c_px)


def true_sensor(cfg: PulaFlightScenario) -> CalibratedLine:
    """The true sensor from ``[sensor_truth]`` (000 Table 1, calibrated)."""
    s = cfg.sensor_truth
    return CalibratedLine(s.zeta0_px, s.c_px, tuple(s.K))


#: Draws of one flight before :func:`simulate_flight` gives up on a scenario (see there).
MAX_FLIGHT_DRAWS = 100


def simulate_flight(cfg: PulaFlightScenario, rng) -> tuple[FlightObservations, FlightTruth]:
    """One flight over the field (see the module docstring): ``(observations, truth)``.

    **Rejection.** A flight whose random attitude motion and boresight put a GCP outside the
    usable swath (``|ζ − ζ0| > scanner.usable_half_width_px``, beyond the calibrated field of
    view) or outside the strip is *redrawn*: 000 Tables 2–3 list every one of the ten GCPs, so
    the paper's experiment cannot have had such a flight. The redraw continues the same random
    stream (trajectory, navigation errors, boresight, again), so the same seed gives the same
    bytes, and a flight accepted at the first draw is exactly the flight drawn before this rule
    (rare with ``pula_flight.toml``: a boresight roll near 4 σ on top of the roll motion;
    ``truth.n_draws`` says how many draws a flight took, and ``hsgeo reproduce geocoding``
    counts the redrawn flights in ``meta["n_flights_redrawn"]``). The measurement noise is
    drawn once, for the accepted flight.

    Raises
    ------
    InputError
        If none of :data:`MAX_FLIGHT_DRAWS` draws images every GCP: the scenario's field does
        not fit its swath.
    """
    rng = as_rng(rng)
    ids, enu = gcp_field(cfg)
    sensor = true_sensor(cfg)
    nav, rec, bs, t_s, tan, n_draws = _draw_imaging_flight(cfg, rng, sensor, enu)
    rate = cfg.scanner.line_rate_hz
    m = cfg.measurement
    line, zeta = _measured(t_s, tan, sensor, 0.0, rate, rng, m.sigma_line, m.sigma_px)
    h = cfg.field.height_m
    obs = FlightObservations(rec, 0.0, rate, ids, enu.copy(), line, zeta, h, nominal_sensor(cfg))
    return obs, FlightTruth(nav, sensor, bs, enu, h, 0.0, rate, n_draws)


def _draw_imaging_flight(cfg: PulaFlightScenario, rng, sensor, gcp_enu_m):
    """Draw (true trajectory, recorded navigation, boresight) until every GCP is imaged within
    the usable swath: ``(nav, recorded, boresight, t_s, tan, n_draws)`` (see
    :func:`simulate_flight`, **Rejection**).
    """
    half = cfg.scanner.usable_half_width_px
    for n_draws in range(1, MAX_FLIGHT_DRAWS + 1):
        nav, _, _ = _true_trajectory(cfg, rng)
        rec = _recorded(nav, cfg, rng)
        bs = rng.normal(0, np.deg2rad(cfg.flight.boresight_sigma_deg), 3)
        t_s, tan = gcp_sightings(nav, bs, gcp_enu_m)
        if np.all(gcps_in_swath(t_s, tan, sensor, half)):
            return nav, rec, bs, t_s, tan, n_draws
    raise InputError(
        f"pula_flight scenario: in {MAX_FLIGHT_DRAWS} draws no flight imaged every GCP within "
        f"±{half:g} px of the swath; move the GCPs towards the centre ([field] across_px, "
        "along_m) or lower [flight] attitude_motion_deg / boresight_sigma_deg"
    )


def generate(cfg: PulaFlightScenario, outdir: Path) -> list[Path]:
    """``make data``: the recorded navigation and GCP observations of the scenario's seed."""
    fl, _ = simulate_flight(cfg, cfg.scenario.seed)
    nav = write_trajectory(outdir / "pula_flight_navigation.csv", fl.recorded_nav)
    obs = outdir / "pula_flight_gcp_observations.csv"
    write_csv_array(
        obs,
        np.column_stack([fl.gcp_id, fl.line, fl.zeta_px, fl.gcp_enu_m]),
        fmt=["%d"] + ["%.17g"] * 5,
        header="gcp,line,zeta_px,E_m,N_m,U_m",
    )
    return [nav, obs]


def airfield_scene(E_m, N_m, gcp_enu_m=None, target_m: float = 3.0) -> np.ndarray:
    """Radiance of a synthetic airfield: asphalt texture, painted stripes and white GCP targets.

    A smooth deterministic texture (sums of sinusoids) on a mid-grey background, white stripes
    every 30 m in both directions, and a white square of ``target_m`` with a black centre at each
    GCP, so that misregistration shows as shifted edges in a difference image.
    """
    E, N = np.asarray(E_m, float), np.asarray(N_m, float)
    val = 0.3 + 0.05 * (np.sin(E / 7.3) * np.cos(N / 5.1) + np.sin((E + N) / 11.7))
    stripe = (np.abs(((E + 4.0) % 30.0) - 15.0) > 13.5) | (np.abs(((N + 9.0) % 30.0) - 15.0) > 13.5)
    val = np.where(stripe, 0.8, val)
    if gcp_enu_m is not None:
        for e, n, _ in np.asarray(gcp_enu_m):
            inside = (np.abs(E - e) < target_m / 2) & (np.abs(N - n) < target_m / 2)
            centre = (np.abs(E - e) < target_m / 6) & (np.abs(N - n) < target_m / 6)
            val = np.where(inside, 0.95, val)
            val = np.where(centre, 0.05, val)
    return val


def render_line_image(
    truth: FlightTruth, cfg: PulaFlightScenario, rng=None, *, noise: float = 0.005
):
    """What the scanner records along the flight: ``(n_lines, n_px)`` radiance and the ζ of the
    columns (pixel centres ζ0 ± usable half width), rendered with the *true* navigation, boresight
    and sensor, with Gaussian noise.
    """
    fl = truth
    from hsgeo.ortho import ground_points
    from hsgeo.sensors import as_sensor

    rng = as_rng(0 if rng is None else rng)
    half = cfg.scanner.usable_half_width_px
    z0 = round(cfg.sensor_truth.zeta0_px)
    zeta = np.arange(z0 - half, z0 + half + 1, dtype=float)
    n_lines = int((fl.true_nav.t_s[-1] - fl.t0_s) * fl.line_rate_hz)
    ground = ground_points(
        as_sensor(fl.sensor, fl.boresight_rad),
        fl.true_nav,
        fl.t0_s + np.arange(n_lines) / fl.line_rate_hz,
        zeta,
        PlaneTerrain(fl.terrain_height_m),
    )
    img = airfield_scene(ground[..., 0], ground[..., 1], fl.gcp_enu_m)
    return img + noise * rng.standard_normal(img.shape), zeta
