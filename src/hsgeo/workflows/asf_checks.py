"""What must hold of the two scans of ``hsgeo asf`` before their ratio means anything: two
different flights, the cross scan across the runway and the along scan along it, scan angles
that fit the ground points (degrees, not radians or pixels), a scan wide enough for an ASF.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = ["check_pair"]


def check_pair(inputs) -> None:
    """What must hold of the two scans before their ratio means anything.

    Raises
    ------
    InputError
        The same scan given twice; the cross scan not crossing the runway or the along scan not
        flown along it (the two swapped); a scan whose angles do not fit its ground points
        (radians or pixels under ``scan_angle_deg``); a cross scan too narrow for an ASF.
    """
    c, a = inputs.cross, inputs.along
    nc, na = inputs.names
    if c.values.shape == a.values.shape and np.array_equal(c.values, a.values):
        raise InputError(
            f"{nc} and {na} hold the same samples: give the scan crossing the runway and the "
            "scan flown along it (two different flights)"
        )
    axis = _runway_axis(inputs.runway_polygon_m)
    ang = {k: _angle_to_axis_deg(g, axis) for k, g in (("c", c), ("a", a))}
    if ang["c"] < 45 and ang["a"] >= 45:
        raise InputError(
            f"{nc} is flown along the runway ({ang['c']:.0f}° from its long axis) and {na} "
            f"across it ({ang['a']:.0f}°): the two scans are swapped; give the cross-runway "
            "scan first (CROSS), then the along-runway scan (ALONG)"
        )
    if ang["c"] < 45:
        raise InputError(
            f"{nc} is flown {ang['c']:.0f}° from the runway's long axis: the cross scan must "
            "cross the runway (its scan lines along the runway); check the runway file's "
            "corners and the scan"
        )
    if ang["a"] >= 45:
        raise InputError(
            f"{na} is flown {ang['a']:.0f}° from the runway's long axis: the along scan must be "
            "flown along the runway; check the runway file's corners and the scan"
        )
    half = float(np.rad2deg(np.abs(c.scan_angle_rad).max()))
    if half < 10.0:
        raise InputError(
            f"{nc} spans only ±{half:.2f}° of scan angle: an ASF from crossings needs a scan "
            "over a wide angle; are its angles (scan_angle_deg, or the sensor file's ifov_deg) "
            "in radians instead of degrees?"
        )
    for g, name in ((c, nc), (a, na)):
        _check_angles_fit_ground(g, name)


def _runway_axis(polygon_m) -> np.ndarray:
    P = np.asarray(polygon_m, float)
    d = np.roll(P, -1, axis=0) - P
    k = int(np.argmax(np.hypot(d[:, 0], d[:, 1])))
    return d[k] / np.hypot(*d[k])


def _angle_to_axis_deg(g, axis) -> float:
    """Angle between the flight direction of a scan and the runway's axis, 0–90°."""
    j = g.E_m.shape[1] // 2
    v = np.array([g.E_m[-1, j] - g.E_m[0, j], g.N_m[-1, j] - g.N_m[0, j]])
    c = abs(float(v @ axis)) / max(float(np.hypot(*v)), 1e-12)
    return float(np.rad2deg(np.arccos(min(c, 1.0))))


def _check_angles_fit_ground(g, name: str) -> None:
    """On flat ground the spacing of the columns grows as 1/cos²θ of their scan angle, whatever
    the sensor: the height ``spacing·cos²θ/Δθ`` must be the same across the scan. Angles in
    radians (or pixels) under ``scan_angle_deg`` break that by the factor 1/cos²θ itself.
    """
    th = np.asarray(g.scan_angle_rad, float)
    if th.size < 8 or np.abs(th).max() < np.deg2rad(10):
        return
    dE = np.diff(g.E_m, axis=1)
    dN = np.diff(g.N_m, axis=1)
    spacing = np.median(np.hypot(dE, dN), axis=0)
    mid = 0.5 * (th[1:] + th[:-1])
    h = spacing * np.cos(mid) ** 2 / np.abs(np.diff(th))
    near = np.abs(mid) <= np.quantile(np.abs(mid), 0.1)
    far = np.abs(mid) >= np.quantile(np.abs(mid), 0.9)
    ratio = float(np.median(h[far]) / np.median(h[near]))
    if not 0.8 < ratio < 1.25:
        edge = float(np.rad2deg(np.abs(th).max()))
        raise InputError(
            f"{name}: its scan angles do not fit its ground points: on flat ground the columns' "
            f"spacing grows as 1/cos²θ (×{1 / np.cos(np.deg2rad(edge)) ** 2:.2f} at the "
            f"scan's ±{edge:.1f}°), but it grows {ratio / np.cos(np.deg2rad(edge)) ** 2:.2f}× "
            "as much: are the scan angles (scan_angle_deg) in radians or pixels instead of "
            "degrees?"
        )
