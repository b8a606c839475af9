"""A simulated airborne flight about any site on Earth, in the files a real one delivers
(``hsgeo data flight``).

A straight line along a geodesic through the site (WGS 84) at a height above a ground of
constant ellipsoidal height, the aircraft rolling, pitching and crabbing; a line scanner given
by a per-pixel view-angle table (a wide-angle lens with radial distortion and a smile) on a
boresight and a lever arm; Gaussian targets on the ground. Every pixel is rendered with pyproj
and numpy alone, in the Earth-centred frame, independently of :mod:`hsgeo.crs`,
:mod:`hsgeo.trajectory` and the sensors (only :func:`hsgeo.rotations.R_from_rpy`, the project's
one roll–pitch–heading convention, is shared):

* the body's attitude is against the north-east-down **at the aircraft** (what a GNSS/INS
  records): ``R_ecef_from_body = R_ecef_from_enu(φ, λ) · R_ENU_FROM_NED · R_from_rpy(r, p, h)``
  with φ, λ the aircraft's own latitude and longitude;
* the ray of pixel i: origin ``X + R_ecef_from_body · lever_arm``, direction
  ``R_ecef_from_body · R_from_rpy(boresight) · (tan β_i, tan α_i, 1)``;
* it meets the ground (ellipsoidal height ``ground_h_m``) by Newton steps on the height of
  pyproj's geodetic conversion (to 0.1 mm);
* each pixel's value: a background plus each target's ``A · exp(−r² / 2σ²)``, r the distance of
  the pixel's ground point from the target in the output CRS (the UTM zone of the site on
  WGS 84, pyproj's query), one scale per band.

The navigation records are taken at the line times (so that no interpolation stands between
the truth and the file), plus margin records before and after.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

__all__ = [
    "FlightConfig",
    "FlightData",
    "simulate_flight",
    "utm_epsg",
    "NAV_EPSG",
    "ECEF_EPSG",
    "view_angles",
]

#: The navigation's datum: WGS 84 geographic 3D (and its geocentric frame).
NAV_EPSG, ECEF_EPSG = 4979, 4978


@dataclass(frozen=True)
class FlightConfig:
    """The flight (defaults: a 30 km line at 2 km above the ground).

    Attributes
    ----------
    lat_deg, lon_deg : float
        The site: the line's centre (WGS 84).
    length_m, agl_m, speed_m_s, heading_deg : float
        The imaged line's length, height above the ground, ground speed and course.
    ground_h_m : float
        The ground's ellipsoidal height (WGS 84), m.
    n_px, fov_deg : int, float
        Pixels per line and the across-track field of view.
    wavelength_nm, fwhm_nm : tuple
        The bands.
    n_targets : int
    boresight_deg, lever_arm_m : tuple
        The sensor's mount (roll, pitch, heading of R_body_from_sensor; body frame, m).
    """

    lat_deg: float
    lon_deg: float
    length_m: float = 30000.0
    agl_m: float = 2000.0
    speed_m_s: float = 60.0
    heading_deg: float = 75.0
    ground_h_m: float = 120.0
    n_px: int = 256
    fov_deg: float = 40.0
    wavelength_nm: tuple = (460.0, 550.0, 640.0)
    fwhm_nm: tuple = (9.0, 10.0, 11.0)
    n_targets: int = 12
    boresight_deg: tuple = (0.4, -0.3, 0.6)
    lever_arm_m: tuple = (0.3, -0.1, -0.4)


@dataclass(frozen=True)
class FlightData:
    """What :func:`hsgeo.io.flight_files.write_flight` writes (SI units, degrees in names)."""

    config: FlightConfig
    lines_lsb: np.ndarray  # (line, sample, band) float32
    line_t_s: np.ndarray  # GPS seconds of week of each line
    nav: dict  # gps_sow_s, lat_deg, lon_deg, h_m, roll_deg, pitch_deg, heading_deg
    across_deg: np.ndarray  # (n_px,)
    along_deg: np.ndarray
    targets: dict  # target_id, x_m, y_m (output CRS), lat_deg, lon_deg, h_m
    output_epsg: int
    gsd_m: float
    dsm: dict  # values (rows, cols) ellipsoidal heights, transform, epsg


def utm_epsg(lon_deg: float, lat_deg: float) -> int:
    """EPSG code of the UTM zone of a point on WGS 84: the zone ``⌊(λ + 180°) / 6°⌋ + 1``
    (at a boundary such as 12° E the eastern one), if pyproj lists it for the point, else the
    first zone pyproj lists.
    """
    from pyproj.aoi import AreaOfInterest
    from pyproj.database import query_utm_crs_info

    info = query_utm_crs_info(
        datum_name="WGS 84",
        area_of_interest=AreaOfInterest(lon_deg, lat_deg, lon_deg, lat_deg),
    )
    lon = (float(lon_deg) + 180.0) % 360.0 - 180.0
    code = (32600 if lat_deg >= 0 else 32700) + int((lon + 180.0) // 6.0) % 60 + 1
    codes = [int(i.code) for i in info]
    return code if code in codes else codes[0]


def _R_ecef_from_enu(lat_rad, lon_rad):
    """``(n, 3, 3)``: columns east, north, up at geodetic latitude and longitude."""
    sp, cp, sl, cl = np.sin(lat_rad), np.cos(lat_rad), np.sin(lon_rad), np.cos(lon_rad)
    e = np.stack([-sl, cl, np.zeros_like(sl)], -1)
    n = np.stack([-sp * cl, -sp * sl, cp], -1)
    u = np.stack([cp * cl, cp * sl, sp], -1)
    return np.stack([e, n, u], -1)


def view_angles(n_px: int, fov_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Across- and along-track view angles (rad) of a lens with radial distortion and smile."""
    u = np.linspace(-1.0, 1.0, n_px)
    across = np.arctan(np.tan(np.deg2rad(fov_deg) / 2) * u * (1.0 - 0.02 * u**2))
    along = 0.0015 * u**2 - 0.0004  # smile, rad
    return across, along


def _trajectory(cfg: FlightConfig, rng, n_lines: int, dt_s: float, margin: int):
    """Records at the line times (and ``margin`` more each side): geodesic positions, attitude."""
    from pyproj import Geod

    g = Geod(ellps="WGS84")
    n = n_lines + 2 * margin
    k = np.arange(n) - margin
    s = (k - (n_lines - 1) / 2.0) * dt_s * cfg.speed_m_s
    lon, lat, back = (
        np.asarray(v, float)
        for v in g.fwd(
            np.full(n, cfg.lon_deg), np.full(n, cfg.lat_deg), np.full(n, cfg.heading_deg), s
        )
    )
    course = (back + 180.0) % 360.0  # the forward azimuth at each point (s < 0 too)
    t = k * dt_s
    ph = rng.uniform(0, 2 * np.pi, 4)
    roll = 1.2 * np.sin(2 * np.pi * t / 23.0 + ph[0]) + 0.3 * np.sin(2 * np.pi * t / 5.1 + ph[1])
    pitch = 0.8 * np.cos(2 * np.pi * t / 31.0 + ph[2]) + 0.2
    heading = (course + 2.5 + 0.5 * np.sin(2 * np.pi * t / 41.0 + ph[3])) % 360.0
    h = cfg.ground_h_m + cfg.agl_m + 3.0 * np.sin(2 * np.pi * t / 60.0)
    return lat, lon, h, np.column_stack([roll, pitch, heading])


def _ground(cfg, lat, lon, h, rph, d_sensor):
    """ECEF ground points ``(n_lines, n_px, 3)`` and their lon, lat (module docstring)."""
    from pyproj import Transformer

    to_ecef = Transformer.from_crs(NAV_EPSG, ECEF_EPSG, always_xy=True)
    X = np.column_stack(to_ecef.transform(lon, lat, h))
    R = _R_ecef_from_enu(np.radians(lat), np.radians(lon)) @ R_ENU_FROM_NED
    R = R @ R_from_rpy(*np.radians(rph).T)
    B = R_from_rpy(*np.radians(cfg.boresight_deg))
    o = X + np.einsum("nij,j->ni", R, np.asarray(cfg.lever_arm_m, float))
    d = np.einsum("nij,pj->npi", R, d_sensor @ B.T)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    up = _R_ecef_from_enu(np.radians(lat), np.radians(lon))[:, :, 2]
    vu = np.einsum("npi,ni->np", d, up)
    s = (h - cfg.ground_h_m)[:, None] / -vu
    inv = Transformer.from_crs(ECEF_EPSG, NAV_EPSG, always_xy=True)
    for _ in range(12):
        p = o[:, None, :] + s[..., None] * d
        glon, glat, gh = (np.asarray(v) for v in inv.transform(*p.reshape(-1, 3).T))
        dh = gh.reshape(s.shape) - cfg.ground_h_m
        s = s - dh / vu
        if np.max(np.abs(dh)) < 1e-5:
            break
    if np.max(np.abs(dh)) > 1e-4:
        raise RuntimeError(f"ray-ground intersection did not converge ({np.max(np.abs(dh))} m)")
    return glon.reshape(s.shape), glat.reshape(s.shape)


def simulate_flight(cfg: FlightConfig, rng=0) -> FlightData:
    """Simulate the flight (module docstring).

    Parameters
    ----------
    cfg : FlightConfig
    rng : int or numpy.random.Generator

    Returns
    -------
    FlightData
    """
    from pyproj import Geod, Transformer

    rng = np.random.default_rng(rng)
    across, along = view_angles(cfg.n_px, cfg.fov_deg)
    gsd = cfg.agl_m * float(np.mean(np.diff(np.tan(across))))
    dt = gsd / cfg.speed_m_s  # square ground pixels at nadir
    n_lines = int(round(cfg.length_m / (dt * cfg.speed_m_s))) + 1
    margin = 50
    lat, lon, h, rph = _trajectory(cfg, rng, n_lines, dt, margin)
    t0 = float(rng.uniform(2e5, 4e5))
    d_sensor = np.column_stack([np.tan(along), np.tan(across), np.ones(cfg.n_px)])
    sl = slice(margin, margin + n_lines)
    glon, glat = _ground(cfg, lat[sl], lon[sl], h[sl], rph[sl], d_sensor)
    epsg = utm_epsg(cfg.lon_deg, cfg.lat_deg)
    to_map = Transformer.from_crs(NAV_EPSG, epsg, always_xy=True)
    gx, gy = (np.asarray(v) for v in to_map.transform(glon, glat))
    # targets: spread along the line, within 70 % of the half swath across it
    geod = Geod(ellps="WGS84")
    m = cfg.n_targets
    k = np.linspace(0.1, 0.9, m) * (n_lines - 1)
    ki = np.round(k).astype(int) + margin
    half = cfg.agl_m * np.tan(np.deg2rad(cfg.fov_deg) / 2)
    off = rng.uniform(-0.7, 0.7, m) * half
    az = rph[ki, 2] + 90.0
    tlon, tlat, _ = (np.asarray(v) for v in geod.fwd(lon[ki], lat[ki], az, off))
    tx, ty = (np.asarray(v) for v in to_map.transform(tlon, tlat))
    sigma = 1.5 * gsd
    blob = np.zeros(gx.shape)
    for x, y in zip(tx, ty, strict=True):
        r2 = (gx - x) ** 2 + (gy - y) ** 2
        blob += np.exp(-r2 / (2 * sigma**2))
    scale = np.linspace(1.0, 0.6, len(cfg.wavelength_nm))
    lines = (100.0 + 900.0 * blob)[..., None] * scale
    # the DSM: the ground's ellipsoidal height on a 30 m grid of the output CRS
    pad = 3 * half + 500.0
    x0, x1 = float(gx.min() - pad), float(gx.max() + pad)
    y0, y1 = float(gy.min() - pad), float(gy.max() + pad)
    res = 30.0
    cols, rows = int(np.ceil((x1 - x0) / res)), int(np.ceil((y1 - y0) / res))
    dsm = {
        "values": np.full((rows, cols), cfg.ground_h_m, np.float32),
        "origin_xy_m": (x0, y0 + rows * res),
        "res_m": res,
        "epsg": epsg,
    }
    nav = {
        "gps_sow_s": t0 + (np.arange(lat.size) - margin) * dt,
        "lat_deg": lat,
        "lon_deg": lon,
        "h_m": h,
        "roll_deg": rph[:, 0],
        "pitch_deg": rph[:, 1],
        "heading_deg": rph[:, 2],
    }
    targets = {
        "target_id": np.arange(1, m + 1),
        "x_m": tx,
        "y_m": ty,
        "lat_deg": tlat,
        "lon_deg": tlon,
        "h_m": np.full(m, cfg.ground_h_m),
    }
    return FlightData(
        cfg,
        lines.astype(np.float32),
        nav["gps_sow_s"][sl].copy(),
        nav,
        np.rad2deg(across),
        np.rad2deg(along),
        targets,
        epsg,
        gsd,
        dsm,
    )
