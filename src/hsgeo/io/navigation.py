"""The navigation file: a GNSS/INS solution as a table, one format for every command.

Format (CSV or Parquet, one row per record, strictly increasing time; extra columns ignored)::

    t_s,E_m,N_m,U_m,roll_deg,pitch_deg,heading_deg

* ``t_s``: time in seconds, on the time scale of the lines (``hsgeo geocode``) or of the
  observations (``hsgeo adjust-pushbroom``);
* ``E_m, N_m, U_m``: position of the projection centre (geocoding) or of the platform reference
  point (pushbroom) in a local east-north-up map frame, metres;
* ``roll_deg, pitch_deg, heading_deg``: the attitude as a GNSS/INS gives it, of the body
  (x forward, y right, z down) relative to north-east-down,
  ``R_ned_from_body = R_from_rpy(roll, pitch, heading)`` (:mod:`hsgeo.rotations`), degrees.

Degrees at the file edge, radians inside (:class:`hsgeo.trajectory.Trajectory`). The writer uses
``%.17g``, so a round trip is lossless, and writes atomically (a temporary file in the target's
directory, then :func:`os.replace`).

The former ``hsgeo adjust-pushbroom`` format (``t_s, E_m, N_m, H_m, roll_rad, pitch_rad,
yaw_rad`` with ENU platform angles) is recognised and rejected with the conversion
(:func:`hsgeo.trajectory.rph_from_platform_rpy`): ``U_m = H_m``, ``roll_deg = roll``,
``pitch_deg = −pitch``, ``heading_deg = 90° − yaw``.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path
from hsgeo.trajectory import Trajectory

__all__ = ["NAV_COLUMNS", "read_trajectory", "write_trajectory"]

#: Columns of the navigation file, in the order the writer uses.
NAV_COLUMNS = ("t_s", "E_m", "N_m", "U_m", "roll_deg", "pitch_deg", "heading_deg")

#: Columns of the former ``hsgeo adjust-pushbroom`` trajectory format (ENU platform angles).
_OLD_PUSHBROOM_COLUMNS = ("H_m", "roll_rad", "pitch_rad", "yaw_rad")

_FORMAT = ", ".join(NAV_COLUMNS)


#: Allowed ranges of the navigation's angles (degrees): roll one turn either way, pitch within
#: ±90, heading 100 turns either way (an unwrapped heading passes 360 after each turn).
NAV_LIMITS = {
    "roll_deg": (-360.0, 360.0),
    "pitch_deg": (-90.0, 90.0),
    "heading_deg": (-36000.0, 36000.0),
}

#: The fastest plausible rotation (degrees per second) between two records, of each angle
#: (differences taken modulo 360): beyond it a record is off or the angles are not in degrees.
MAX_RATE_DEG_S = 360.0

#: The fastest plausible platform (m/s) between two records: beyond it a record is off (a
#: position jump, a wrong unit or time scale). Airborne platforms fly below 300 m/s.
MAX_SPEED_M_S = 1000.0


def read_trajectory(path) -> Trajectory:
    """Read a navigation file (see the module docstring) into a :class:`Trajectory`.

    Parameters
    ----------
    path : str or path-like
        CSV, or Parquet (suffix ``.parquet`` or ``.pq``), with the columns
        ``t_s, E_m, N_m, U_m, roll_deg, pitch_deg, heading_deg``.

    Returns
    -------
    Trajectory
        Positions ``xyz_m`` (E, N, U) in m and ``roll_pitch_heading_rad`` in rad.

    Raises
    ------
    InputError
        If the file is missing or unreadable, lacks a column (the former adjust-pushbroom
        format gets the conversion to the new columns), has empty, NaN, non-numeric or
        out-of-range values (:data:`NAV_LIMITS`), has fewer than 2 records, times that do not
        increase strictly, or a jump between records faster than :data:`MAX_SPEED_M_S`; the
        message names the line and the column.
    """
    from hsgeo.io.tables import read_table

    path = Path(path)
    name = f"navigation file {str(path)!r}"
    try:
        df = read_table(path, NAV_COLUMNS, "navigation", limits=NAV_LIMITS, unique_rows=False)
    except InputError as exc:
        if "missing column" in str(exc):
            _check_old_format(path)
        raise
    lines = _data_lines_of(path, len(df))
    table = df[list(NAV_COLUMNS)].to_numpy(dtype=np.float64)
    t = table[:, 0]
    if t.size < 2:
        raise InputError(f"{name} has {t.size} record; a navigation needs at least 2")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.flatnonzero(dt <= 0)[0])
        raise InputError(
            f"{name}, {lines[i + 1]}, column t_s: {t[i + 1]:.17g} s does not come after "
            f"{t[i]:.17g} s of {lines[i]}; times must increase strictly (sort the records, drop "
            "duplicates)"
        )
    speed = np.linalg.norm(np.diff(table[:, 1:4], axis=0), axis=1) / dt
    if np.any(speed > MAX_SPEED_M_S):
        i = int(np.flatnonzero(speed > MAX_SPEED_M_S)[0])
        raise InputError(
            f"{name}: the position jumps by {speed[i] * dt[i]:.6g} m in {dt[i]:.6g} s between "
            f"{lines[i]} and {lines[i + 1]} ({speed[i]:.3g} m/s, more than {MAX_SPEED_M_S:g}); "
            "correct the record (positions E_m, N_m, U_m in metres, t_s in seconds)"
        )
    for j, c in enumerate(("roll_deg", "pitch_deg", "heading_deg")):
        d = (np.diff(table[:, 4 + j]) + 180.0) % 360.0 - 180.0
        rate = np.abs(d) / dt
        if np.any(rate > MAX_RATE_DEG_S):
            i = int(np.flatnonzero(rate > MAX_RATE_DEG_S)[0])
            raise InputError(
                f"{name}, column {c}: the angle turns by {d[i]:.6g}° in {dt[i]:.6g} s between "
                f"{lines[i]} and {lines[i + 1]} ({rate[i]:.3g}°/s, more than "
                f"{MAX_RATE_DEG_S:g}°/s); correct the record (angles in degrees, t_s in seconds)"
            )
    return Trajectory(t, table[:, 1:4], np.deg2rad(table[:, 4:7]))


def _data_lines_of(path: Path, n: int) -> list[str]:
    """``"line k"`` of each record of a CSV (``"row k"`` for Parquet)."""
    from hsgeo.io._files import read_text
    from hsgeo.io.tables import _PARQUET, _data_lines

    if path.suffix.lower() in _PARQUET:
        return [f"row {i + 1}" for i in range(n)]
    return [f"line {k}" for k in _data_lines(read_text(path, "navigation file", "CSV table"))]


def _check_old_format(path: Path) -> None:
    """The former adjust-pushbroom format gets the conversion to the new columns."""
    import pandas as pd

    try:
        cols = [str(c).strip() for c in pd.read_csv(path, nrows=0, comment="#").columns]
    except Exception:  # noqa: BLE001 - the reader's own message stands
        return
    if all(c in cols for c in _OLD_PUSHBROOM_COLUMNS):
        raise InputError(
            f"navigation file {str(path)!r} is in the former adjust-pushbroom format "
            "(t_s, E_m, N_m, H_m, roll_rad, pitch_rad, yaw_rad: ENU platform angles). The "
            f"navigation format of every command is now: {_FORMAT} (degrees; the GNSS/INS "
            "attitude of the body x forward, y right, z down in north-east-down). Convert: "
            "U_m = H_m, roll_deg = degrees(roll_rad), pitch_deg = -degrees(pitch_rad), "
            "heading_deg = 90 - degrees(yaw_rad) (hsgeo.trajectory.rph_from_platform_rpy)"
        )


def write_trajectory(path, traj: Trajectory, *, inputs: Iterable = ()) -> Path:
    """Write a :class:`Trajectory` as a navigation file (CSV, ``%.17g``: a lossless round trip).

    Parameters
    ----------
    path : str or path-like
        Target CSV file; written atomically (a temporary file next to it, then
        :func:`os.replace`), so a reader never sees half a file.
    traj : Trajectory
    inputs : iterable of path-like, optional
        The files the caller read; ``path`` must not be one of them.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        If ``path`` is one of ``inputs``.
    """
    path = Path(path)
    table = np.column_stack([traj.t_s, traj.xyz_m, np.rad2deg(traj.roll_pitch_heading_rad)])
    with atomic_path(path, inputs) as tmp:
        np.savetxt(
            tmp, table, delimiter=",", fmt="%.17g", header=",".join(NAV_COLUMNS), comments=""
        )
    return path
