"""The Applanix SBET (Smoothed Best Estimate of Trajectory) binary file, read as documented.

An SBET (``sbet_*.out``, written by Applanix POSPac) has no header: records of 17 little-endian
IEEE doubles (136 bytes), in this order (PDAL's ``readers.sbet``, the ``sbet`` crate of
gadomski/sbet-rs, Applanix's POSPac output description):

====  =====================  ====================================================
 k    field                  unit
====  =====================  ====================================================
 0    time                   s, GPS seconds of the week
 1    latitude               rad, geodetic, on the datum of the processing
 2    longitude              rad
 3    altitude               m, ellipsoidal height
 4-6  x, y, z velocity       m/s, wander-azimuth frame
 7    roll                   rad
 8    pitch                  rad
 9    platform heading       rad, in the wander-azimuth frame
 10   wander angle           rad
 11-13 x, y, z acceleration  m/s², body
 14-16 x, y, z angular rate  rad/s, body
====  =====================  ====================================================

The true heading (against the north at the aircraft) is the platform heading minus the wander
angle. The datum is not in the file: it is the one the trajectory was processed on (the base
stations' or the precise orbits' frame), which the user names (:func:`read_sbet` leaves it to
:func:`hsgeo.io.navigation.read_navigation`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["SBET_FIELDS", "SBET_RECORD_BYTES", "read_sbet"]

#: The 17 fields of an SBET record, in file order (units in the module docstring).
SBET_FIELDS = (
    "time_s",
    "lat_rad",
    "lon_rad",
    "h_m",
    "vx_m_s",
    "vy_m_s",
    "vz_m_s",
    "roll_rad",
    "pitch_rad",
    "platform_heading_rad",
    "wander_rad",
    "ax_m_s2",
    "ay_m_s2",
    "az_m_s2",
    "wx_rad_s",
    "wy_rad_s",
    "wz_rad_s",
)
SBET_RECORD_BYTES = 8 * len(SBET_FIELDS)
_DTYPE = np.dtype([(f, "<f8") for f in SBET_FIELDS])


def read_sbet(path) -> dict[str, np.ndarray]:
    """Read an SBET into its fields, checked.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    dict of str to (n,) ndarray
        Every field of :data:`SBET_FIELDS`, plus ``"heading_rad"``: the true heading, platform
        heading minus wander angle.

    Raises
    ------
    InputError
        If the file is missing, empty, not a whole number of 136-byte records (truncated, or not
        an SBET), or a record holds a non-finite value or a latitude, longitude, height or angle
        no SBET can hold (degrees instead of radians, big-endian, another format); the message
        names the record and its byte offset.
    """
    path = Path(path)
    name = f"SBET file {str(path)!r}"
    if not path.is_file():
        raise InputError(f"{name} does not exist or is not a file")
    data = path.read_bytes()
    n, rest = divmod(len(data), SBET_RECORD_BYTES)
    if n == 0 or rest:
        raise InputError(
            f"{name} has {len(data)} bytes: not a whole number of {SBET_RECORD_BYTES}-byte "
            f"records ({n} records and {rest} bytes left over). The file is truncated (copy it "
            "again from POSPac's output) or is not an SBET (17 little-endian doubles a record)"
        )
    rec = np.frombuffer(data, dtype=_DTYPE)
    out = {f: np.array(rec[f], dtype=np.float64) for f in SBET_FIELDS}
    table = np.column_stack([out[f] for f in SBET_FIELDS])
    bad = ~np.isfinite(table)
    if np.any(bad):
        i, k = np.argwhere(bad)[0]
        _refuse(name, i, SBET_FIELDS[k], "is not a finite number")
    checks = (
        ("lat_rad", np.pi / 2, "is not a latitude in radians (|φ| ≤ π/2)"),
        ("lon_rad", 2 * np.pi, "is not a longitude in radians (|λ| ≤ 2π)"),
        ("h_m", 1e5, "is not an ellipsoidal height in metres (|h| ≤ 100 km)"),
        ("roll_rad", 2 * np.pi, "is not an angle in radians"),
        ("pitch_rad", np.pi / 2, "is not a pitch in radians (|θ| ≤ π/2)"),
        ("platform_heading_rad", 4 * np.pi, "is not an angle in radians"),
        ("wander_rad", 4 * np.pi, "is not an angle in radians"),
    )
    for f, lim, what in checks:
        over = np.abs(out[f]) > lim
        if np.any(over):
            i = int(np.flatnonzero(over)[0])
            _refuse(name, i, f, f"= {out[f][i]:.6g} {what}")
    out["heading_rad"] = out["platform_heading_rad"] - out["wander_rad"]
    return out


def _refuse(name: str, i: int, field: str, what: str) -> None:
    raise InputError(
        f"{name}, record {i + 1} (byte {i * SBET_RECORD_BYTES}), field {field} {what}: the "
        "file is not an Applanix SBET (17 little-endian doubles a record: time, latitude and "
        "longitude in radians, height in metres, …) or is damaged"
    )
