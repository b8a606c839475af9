"""``hsgeo asf`` from the raw scans: the flights georegistered with the sensor and the navigation
(004 step 1, the correction of the panoramic distortion), the ASF of each crossing
(:func:`hsgeo.workflows.asf.asf_from_scans`), and two crossings of opposite heading combined
(beyond 004: :func:`hsgeo.radiometry.combine_opposite_crossings`).

The in-memory core :func:`asf_from_flights` (frozen :class:`FlightsInputs` → :class:`FlightsResult`)
is what ``hsgeo reproduce asf`` and ``hsgeo asf --sensor … --trajectory …`` both call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError
from hsgeo.geocode import PlaneTerrain
from hsgeo.radiometry import combine_opposite_crossings
from hsgeo.workflows.asf import (
    AsfInputs,
    AsfOptions,
    AsfResult,
    GeoScan,
    asf_from_scans,
    georegister,
)

__all__ = [
    "RawScan",
    "FlightsInputs",
    "FlightsResult",
    "georegister_raw",
    "asf_from_flights",
    "asf_files",
]


@dataclass(frozen=True)
class RawScan:
    """One recorded flight line of a whiskbroom scanner, as the scanner writes it.

    Attributes
    ----------
    values : (bands, lines, pixels) ndarray
        Radiance (or reflectance) of each sample.
    zeta_px : (pixels,) ndarray
        The detector pixel ζ of each column, px (pixel-centre origin).
    t0_s : float
        Time of line 0 on the navigation's time scale, s.
    line_rate_hz : float
        Scan lines per second.
    name : str
        How messages name the scan (``"CROSS file 'c.nc'"``).
    """

    values: np.ndarray
    zeta_px: np.ndarray
    t0_s: float
    line_rate_hz: float
    name: str = "the scan"


def georegister_raw(scan: RawScan, sensor, trajectory, terrain=None) -> GeoScan:
    """The ground point of every sample of a raw scan (:func:`hsgeo.workflows.asf.georegister`)
    on ``terrain`` (default the plane U = 0 of the navigation's frame).

    Raises
    ------
    InputError
        If the navigation does not cover the scan's time, or its pixels are not the sensor's.
    """
    n = getattr(sensor, "n_px", None)
    z = np.asarray(scan.zeta_px, float)
    if n is not None and (z.min() < -0.5 or z.max() > n - 0.5):
        raise InputError(
            f"{scan.name}: its pixels ζ run from {z.min():g} to {z.max():g}, the sensor has "
            f"{n} (0…{n - 1}): is the sensor file (--sensor) the scanner that recorded it?"
        )
    try:
        return georegister(
            scan.values, z, scan.t0_s, scan.line_rate_hz, sensor, trajectory, terrain
        )
    except InputError as e:
        if "outside the trajectory" not in str(e):
            raise
        t1 = scan.t0_s + scan.values.shape[1] / scan.line_rate_hz
        raise InputError(
            f"{scan.name}: its lines ({scan.t0_s:.3f}…{t1:.3f} s, from t0_s and line_rate_hz) "
            f"are not covered by the navigation (--trajectory, {trajectory.t_s[0]:.3f}…"
            f"{trajectory.t_s[-1]:.3f} s): give the navigation of this flight, on the same "
            "time scale as the scan's t0_s"
        ) from None


@dataclass(frozen=True)
class FlightsInputs:
    """The raw scans, the runway polygon (E, N corners, m), the sensor and the navigation.

    ``reverse``: a second crossing flown with the opposite heading (optional).
    ``terrain_height_m``: the runway's height U in the navigation's frame.
    """

    cross: RawScan
    along: RawScan
    runway_polygon_m: np.ndarray
    sensor: object
    trajectory: object
    reverse: RawScan | None = None
    terrain_height_m: float = 0.0


@dataclass(frozen=True)
class FlightsResult:
    """The ASF of the crossing (and of the reverse crossing), and their combination.

    ``asf`` is the crossing's ASF, or — with a reverse crossing — ``sqrt(r_a·r_b)``, the ASF
    freed of the odd part of a BRDF (``brdf_odd`` = ``sqrt(r_a/r_b)``); ``usable`` the columns
    usable in every crossing. ``geo`` holds the georegistered scans by flight.
    """

    cross: AsfResult
    reverse: AsfResult | None
    asf: np.ndarray
    brdf_odd: np.ndarray | None
    usable: np.ndarray
    geo: dict

    @classmethod
    def of_crossing(cls, res: AsfResult, geo: dict) -> FlightsResult:
        """The result of one crossing without a reverse one: its ASF and usable columns."""
        return cls(res, None, res.asf, None, res.usable, geo)

    @property
    def scan_angle_deg(self) -> np.ndarray:
        return self.cross.scan_angle_deg

    def to_dict(self) -> dict:
        out = self.cross.to_dict()
        if self.reverse is not None:
            r = self.reverse.to_dict()

            def num(a):
                a = np.asarray(a, float)
                return [None if not np.isfinite(x) else round(float(x), 6) for x in a.ravel()]

            out["reverse"] = {k: r[k] for k in ("asf", "usable", "registration")}
            out["combined"] = {
                "asf": [num(a) for a in self.asf],
                "brdf_odd": [num(a) for a in self.brdf_odd],
                "usable": [bool(u) for u in self.usable],
            }
        return out


def asf_from_flights(inputs: FlightsInputs, options: AsfOptions | None = None) -> FlightsResult:
    """Georegister the flights, then the ASF of each crossing against the along image; two
    crossings of opposite heading combined (:func:`hsgeo.radiometry.combine_opposite_crossings`).
    """
    options = options or AsfOptions()
    terrain = PlaneTerrain(float(inputs.terrain_height_m))
    geo = {}
    for k in ("cross", "along", "reverse"):
        s = getattr(inputs, k)
        if s is not None:
            geo[k] = georegister_raw(s, inputs.sensor, inputs.trajectory, terrain)
    P = inputs.runway_polygon_m
    names = (inputs.cross.name, inputs.along.name)
    res = asf_from_scans(AsfInputs(geo["cross"], geo["along"], P, names), options)
    if inputs.reverse is None:
        return FlightsResult.of_crossing(res, geo)
    rc, rr = inputs.cross, inputs.reverse
    if not np.array_equal(np.asarray(rc.zeta_px), np.asarray(rr.zeta_px)):
        raise InputError(
            f"{rr.name} and {rc.name} hold different pixels (ζ): two opposite crossings are "
            "combined pixel by pixel; give both with every pixel of the scan line"
        )
    rev = asf_from_scans(AsfInputs(geo["reverse"], geo["along"], P, (rr.name, names[1])), options)
    heading = [_heading_rad(geo[k]) for k in ("cross", "reverse")]
    if abs(np.cos(heading[0] - heading[1]) + 1) > 0.25:  # not within ~41° of opposite
        raise InputError(
            f"{rr.name} is flown at {np.rad2deg(heading[1]) % 360:.0f}°, {rc.name} at "
            f"{np.rad2deg(heading[0]) % 360:.0f}°: the reverse crossing (--reverse) must be "
            "flown with the opposite heading"
        )
    asf, odd = combine_opposite_crossings(res.asf, rev.asf)
    usable = res.usable & rev.usable
    return FlightsResult(res, rev, asf, odd, usable, geo)


def _heading_rad(g: GeoScan) -> float:
    """Direction of flight (from north, clockwise) of a georegistered scan."""
    j = g.E_m.shape[1] // 2
    return float(np.arctan2(g.E_m[-1, j] - g.E_m[0, j], g.N_m[-1, j] - g.N_m[0, j]))


def asf_files(
    cross_path,
    along_path,
    runway_path,
    options: AsfOptions | None = None,
    *,
    sensor_path=None,
    trajectory_path=None,
    reverse_path=None,
    terrain_height_m: float = 0.0,
) -> FlightsResult:
    """The file front end of ``hsgeo asf`` (formats in :mod:`hsgeo.io.scans`): one
    :class:`FlightsResult` whatever the input.

    With ``sensor_path`` and ``trajectory_path``: raw scans, georegistered here with the sensor
    and the navigation (:func:`hsgeo.workflows.asf_flights.asf_from_flights`; ``reverse_path``
    a second crossing of opposite heading, combined with the first). Without: two scans
    georegistered elsewhere (:func:`hsgeo.workflows.asf.asf_from_scans`), as one crossing
    (:meth:`FlightsResult.of_crossing`; ``geo`` the two scans as read).
    """
    from pathlib import Path

    from hsgeo.io.scans import read_geoscan, read_runway

    options = options or AsfOptions()
    paths = {"CROSS": cross_path, "ALONG": along_path}
    if reverse_path is not None:
        paths["REVERSE"] = reverse_path
    seen = {}
    for role, p in paths.items():
        key = Path(p).resolve()
        if key in seen:
            raise InputError(
                f"{role} and {seen[key]} are the same file {str(p)!r}: each must be a "
                "different flight (CROSS crossing the runway, ALONG flown along it, --reverse "
                "the crossing with the opposite heading)"
            )
        seen[key] = role
    if (sensor_path is None) != (trajectory_path is None):
        missing = "--trajectory NAV.csv" if trajectory_path is None else "--sensor SENSOR.toml"
        raise InputError(
            f"raw scans are georegistered with a sensor file and the navigation: give "
            f"{missing} too (or, for scans georegistered elsewhere, neither)"
        )
    if reverse_path is not None and sensor_path is None:
        raise InputError(
            "--reverse needs raw scans with --sensor and --trajectory (the crossings are "
            "georegistered here)"
        )
    poly = read_runway(runway_path)
    if sensor_path is None:
        cross = GeoScan(*read_geoscan(cross_path, "CROSS"))
        along = GeoScan(*read_geoscan(along_path, "ALONG"))
        names = (f"CROSS file {str(cross_path)!r}", f"ALONG file {str(along_path)!r}")
        res = asf_from_scans(AsfInputs(cross, along, poly, names), options)
        return FlightsResult.of_crossing(res, {"cross": cross, "along": along})
    from hsgeo.io.navigation import read_trajectory
    from hsgeo.io.scans import read_panoramic_sensor, read_raw_scan

    sensor = read_panoramic_sensor(sensor_path)
    trajectory = read_trajectory(trajectory_path)
    raw = {
        role: RawScan(*read_raw_scan(p, role), name=f"{role} file {str(p)!r}")
        for role, p in paths.items()
    }
    inputs = FlightsInputs(
        raw["CROSS"],
        raw["ALONG"],
        poly,
        sensor,
        trajectory,
        raw.get("REVERSE"),
        terrain_height_m,
    )
    return asf_from_flights(inputs, options)
