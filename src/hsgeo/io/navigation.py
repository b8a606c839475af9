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


def _read_table(path: Path):
    import pandas as pd

    if not path.is_file():
        raise InputError(f"navigation file {str(path)!r} does not exist")
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(path, comment="#")
    except Exception as exc:  # noqa: BLE001 - any parser error becomes an InputError
        raise InputError(
            f"navigation file {str(path)!r} is not a readable CSV or Parquet table: {exc}"
        ) from exc
    df.columns = [str(c).strip() for c in df.columns]
    return df


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
        format gets the conversion to the new columns), has empty, NaN or non-numeric values,
        or its times do not increase strictly.
    """
    path = Path(path)
    df = _read_table(path)
    missing = [c for c in NAV_COLUMNS if c not in df.columns]
    if missing:
        if all(c in df.columns for c in _OLD_PUSHBROOM_COLUMNS):
            raise InputError(
                f"navigation file {str(path)!r} is in the former adjust-pushbroom format "
                "(t_s, E_m, N_m, H_m, roll_rad, pitch_rad, yaw_rad: ENU platform angles). The "
                f"navigation format of every command is now: {_FORMAT} (degrees; the GNSS/INS "
                "attitude of the body x forward, y right, z down in north-east-down). Convert: "
                "U_m = H_m, roll_deg = degrees(roll_rad), pitch_deg = -degrees(pitch_rad), "
                "heading_deg = 90 - degrees(yaw_rad) (hsgeo.trajectory.rph_from_platform_rpy)"
            )
        raise InputError(
            f"navigation file {str(path)!r} lacks the column(s) {missing}; it has "
            f"{list(df.columns)} and needs {_FORMAT} (positions east-north-up in m, attitude "
            "roll, pitch, heading of the body in north-east-down in degrees)"
        )
    sub = df[list(NAV_COLUMNS)]
    try:
        table = sub.to_numpy(dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"navigation file {str(path)!r} has non-numeric values in {_FORMAT}: {exc}"
        ) from None
    bad = ~np.all(np.isfinite(table), axis=1)
    if bad.any():
        rows = (np.flatnonzero(bad)[:5] + 2).tolist()
        raise InputError(
            f"navigation file {str(path)!r}: empty, NaN or infinite values in line(s) {rows} "
            "(line 1 = the header)"
        )
    try:
        return Trajectory(table[:, 0], table[:, 1:4], np.deg2rad(table[:, 4:7]))
    except InputError as exc:
        raise InputError(f"navigation file {str(path)!r}: {exc}") from None


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
