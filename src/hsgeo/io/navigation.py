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

Navigation as a GNSS/INS delivers it (:func:`read_navigation`)
--------------------------------------------------------------
A geodetic CSV or Parquet (``lat_deg, lon_deg, h_m`` ellipsoidal height on a named geographic
CRS, or ``X_m, Y_m, Z_m`` on a geocentric one; the CRS as ``# crs: EPSG:4979`` before the header
or passed), with the attitude ``roll_deg, pitch_deg, heading_deg`` against the north-east-down
*at each record* and the time scale in the time column's name (``gps_sow_s`` with an optional
``gps_week``, or ``sod_s``), for example::

    # crs: EPSG:4979
    gps_week,gps_sow_s,lat_deg,lon_deg,h_m,roll_deg,pitch_deg,heading_deg
    2400,345350,60.0,9.73,2000.0,0.1,-0.3,92.5

or the Applanix SBET (:mod:`hsgeo.io.sbet`; its datum passed). Both are read into a local frame
chosen from the data (:meth:`hsgeo.crs.LocalFrame.about`, unless one is given): positions through
PROJ, and each record's attitude carried exactly from its own NED into the frame's
(:meth:`hsgeo.crs.LocalFrame.R_enu_from_ned_at`: meridian convergence, tilt of the normal), so
the :class:`Trajectory` returned is in the form above. The local-ENU file stays readable.

The former ``hsgeo adjust-pushbroom`` format (``t_s, E_m, N_m, H_m, roll_rad, pitch_rad,
yaw_rad`` with ENU platform angles) is recognised and rejected with the conversion
(:func:`hsgeo.trajectory.rph_from_platform_rpy`): ``U_m = H_m``, ``roll_deg = roll``,
``pitch_deg = −pitch``, ``heading_deg = 90° − yaw``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path
from hsgeo.io.tables import _check_separator
from hsgeo.trajectory import Trajectory

__all__ = [
    "NAV_COLUMNS",
    "Navigation",
    "read_navigation",
    "read_trajectory",
    "write_trajectory",
    "NAV_LIMITS",
    "MAX_RATE_DEG_S",
    "MAX_SPEED_M_S",
    "SECONDS_PER_WEEK",
    "SECONDS_PER_DAY",
    "TIME_COLUMNS",
    "GEODETIC_COLUMNS",
    "GEOCENTRIC_COLUMNS",
    "ATTITUDE_COLUMNS",
    "MAX_HEADING_COURSE_DEG",
    "COURSE_MIN_SPEED_M_S",
    "check_heading_follows_course",
    "read_line_navigation",
]

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
    _check_records(name, lines, t, table[:, 1:4], table[:, 4:7], "E_m, N_m, U_m")
    return Trajectory(t, table[:, 1:4], np.deg2rad(table[:, 4:7]))


def _check_records(name, lines, t, xyz_m, angles_deg, position_columns, time_column="t_s"):
    """Times increase strictly; no position jump or angle turn faster than a platform can."""
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.flatnonzero(dt <= 0)[0])
        raise InputError(
            f"{name}, {lines[i + 1]}, column {time_column}: {t[i + 1]:.17g} s does not come "
            f"after {t[i]:.17g} s of {lines[i]}; times must increase strictly (sort the records, "
            "drop duplicates)"
        )
    speed = np.linalg.norm(np.diff(xyz_m, axis=0), axis=1) / dt
    if np.any(speed > MAX_SPEED_M_S):
        i = int(np.flatnonzero(speed > MAX_SPEED_M_S)[0])
        raise InputError(
            f"{name}: the position jumps by {speed[i] * dt[i]:.6g} m in {dt[i]:.6g} s between "
            f"{lines[i]} and {lines[i + 1]} ({speed[i]:.3g} m/s, more than {MAX_SPEED_M_S:g}); "
            f"correct the record (positions {position_columns} in metres, {time_column} in "
            "seconds)"
        )
    for j, c in enumerate(("roll_deg", "pitch_deg", "heading_deg")):
        d = (np.diff(angles_deg[:, j]) + 180.0) % 360.0 - 180.0
        rate = np.abs(d) / dt
        if np.any(rate > MAX_RATE_DEG_S):
            i = int(np.flatnonzero(rate > MAX_RATE_DEG_S)[0])
            raise InputError(
                f"{name}, column {c}: the angle turns by {d[i]:.6g}° in {dt[i]:.6g} s between "
                f"{lines[i]} and {lines[i + 1]} ({rate[i]:.3g}°/s, more than "
                f"{MAX_RATE_DEG_S:g}°/s); correct the record (angles in degrees, {time_column} in "
                "seconds)"
            )


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


# ----------------------------------------------------------------------------------------------
# Navigation as a GNSS/INS delivers it: geodetic (or geocentric) positions on a named datum,
# attitude against the north-east-down at the aircraft, a stated time scale; the Applanix SBET
# ----------------------------------------------------------------------------------------------
#: Seconds of a GPS week and of a day (the two time scales a geodetic navigation may state).
SECONDS_PER_WEEK = 604800.0
SECONDS_PER_DAY = 86400.0

#: Time columns of a geodetic navigation file and the time scale each states.
TIME_COLUMNS = {"gps_sow_s": "GPS seconds of week", "sod_s": "seconds of day"}

#: Position columns: geodetic (on a geographic CRS) or geocentric (on a geocentric CRS).
GEODETIC_COLUMNS = ("lat_deg", "lon_deg", "h_m")
GEOCENTRIC_COLUMNS = ("X_m", "Y_m", "Z_m")
ATTITUDE_COLUMNS = ("roll_deg", "pitch_deg", "heading_deg")

#: Beyond this median difference between the heading and the course over ground (degrees, at
#: ground speeds above :data:`COURSE_MIN_SPEED_M_S`) the heading is not a heading in degrees
#: (radians, a wander-frame heading, a yaw from east): no aircraft crabs by 60°.
MAX_HEADING_COURSE_DEG = 60.0
COURSE_MIN_SPEED_M_S = 10.0

_NAV_CRS_HINT = (
    "EPSG:4979 (WGS 84), EPSG:4937 (ETRS89), EPSG:6319 (NAD83(2011)) or the geocentric EPSG:4978"
)


@dataclass(frozen=True)
class Navigation:
    """A navigation read into the local frame of the computation.

    Attributes
    ----------
    trajectory : Trajectory
        Positions (E, N, U) in the frame's east-north-up (m) and the attitude against the
        frame's north-east-down (rad), each record's own NED carried into it exactly
        (:meth:`hsgeo.crs.LocalFrame.R_enu_from_ned_at`).
    frame : hsgeo.crs.LocalFrame or None
        The frame (chosen from the data unless given); ``None`` for a local-ENU navigation read
        without one.
    time_scale : str
        ``"GPS seconds of week"`` (``t_s`` counted from the start of ``gps_week``),
        ``"seconds of day"``, or ``"as in the file (t_s)"``.
    gps_week : int or None
        The GPS week ``t_s`` counts from, when known.
    source_crs : str
        The navigation's CRS by name and code, or ``"local ENU"``.
    """

    trajectory: Trajectory
    frame: object
    time_scale: str
    gps_week: int | None
    source_crs: str


def read_navigation(
    path, *, crs=None, frame=None, gps_week: int | None = None, map_crs=None
) -> Navigation:
    """Read a navigation as delivered into the local frame of the computation.

    Three formats, told apart by content:

    * the **Applanix SBET** (:mod:`hsgeo.io.sbet`; suffix ``.out`` or ``.sbet``, or any file
      that is not text): GPS seconds of week, latitude, longitude (rad), ellipsoidal height,
      roll, pitch, true heading = platform heading − wander angle. The datum is not in the
      file: ``crs`` is required.
    * a **geodetic CSV or Parquet**: one time column, ``gps_sow_s`` (GPS seconds of week, with
      an optional integer ``gps_week`` column) or ``sod_s`` (seconds of day); positions
      ``lat_deg, lon_deg, h_m`` (ellipsoidal height) on a geographic CRS or ``X_m, Y_m, Z_m`` on
      a geocentric CRS; attitude ``roll_deg, pitch_deg, heading_deg`` of the body (x forward,
      y right, z down) against the north-east-down at the record (true north). The CRS is
      ``crs`` or a comment line ``# crs: EPSG:4979`` before the header.
    * the **local-ENU navigation file** of :func:`read_trajectory` (``t_s, E_m, N_m, U_m, …``),
      already in a local frame: returned as read, with ``frame`` as given.

    Parameters
    ----------
    path : str or path-like
    crs : str or int or pyproj.CRS, optional
        The navigation's geographic 3D or geocentric CRS (overrides the file's ``# crs:``).
    frame : hsgeo.crs.LocalFrame, optional
        The frame to read into (e.g. one shared by several strips); default
        :meth:`hsgeo.crs.LocalFrame.about` the navigation's centre on its datum.
    gps_week : int, optional
        The GPS week of an SBET's or a ``gps_sow_s`` file's times (stored, not applied).
    map_crs : str or int, optional
        The output CRS of a frame chosen here (default: the UTM zone of the centre).

    Returns
    -------
    Navigation

    Raises
    ------
    InputError
        The file is missing or unreadable, a truncated SBET, lacks a column or a time scale,
        names no CRS or one that is not geographic or geocentric, holds out-of-range values,
        times that do not increase, jumps, or headings that do not follow the course over ground
        (radians under ``_deg``): the message names the file, the line and the column.
    """
    path = Path(path)
    if path.suffix.lower() in (".out", ".sbet") or _is_binary(path):
        return _read_sbet_navigation(path, crs, frame, gps_week, map_crs)
    cols = _columns_of(path)
    _check_separator(
        f"navigation file {str(path)!r}",
        cols,
        ("t_s", "E_m", "N_m", "U_m", *GEODETIC_COLUMNS, *GEOCENTRIC_COLUMNS, *TIME_COLUMNS),
    )
    geodetic = {"lat_deg", "lon_deg", "X_m", "Y_m", "Z_m", "gps_sow_s", "sod_s"}
    if not geodetic & set(cols) and ({"t_s", "E_m", "N_m", "U_m"} & set(cols)):
        # a local-ENU file (even one that lacks a column: read_trajectory names it)
        return Navigation(read_trajectory(path), frame, "as in the file (t_s)", None, "local ENU")
    return _read_geodetic_table(path, cols, crs, frame, gps_week, map_crs)


def _is_binary(path: Path) -> bool:
    if not path.is_file():
        raise InputError(f"navigation file {str(path)!r} does not exist or is not a file")
    with open(path, "rb") as f:
        head = f.read(4096)
    if path.suffix.lower() in (".parquet", ".pq"):
        return False
    return b"\x00" in head


def _columns_of(path: Path) -> list[str]:
    import pandas as pd

    from hsgeo.io.tables import _PARQUET

    try:
        if path.suffix.lower() in _PARQUET:
            import pyarrow.parquet as pq

            return [str(c).strip() for c in pq.read_schema(path).names]
        return [str(c).strip() for c in pd.read_csv(path, nrows=0, comment="#").columns]
    except Exception as exc:  # noqa: BLE001 - any parse failure is the user's file
        raise InputError(
            f"navigation file {str(path)!r} cannot be read as a table ({exc})"
        ) from exc


def _crs_comment(path: Path) -> str | None:
    """The ``# crs: …`` comment of a CSV, before its header."""
    import re

    from hsgeo.io.tables import _PARQUET

    if path.suffix.lower() in _PARQUET:
        return None
    with open(path, encoding="utf-8-sig", errors="replace") as f:
        for line in f:
            s = line.strip()
            if s and not s.startswith("#"):
                return None
            m = re.match(r"#\s*crs\s*[:=]\s*(\S.*)$", s, re.IGNORECASE)
            if m:
                return m.group(1).strip()
    return None


def _nav_crs(name: str, crs, path: Path | None, geocentric: bool):
    """The navigation's CRS, checked: geographic 3D for lat/lon/h, geocentric for X/Y/Z."""
    from hsgeo.crs import geographic_3d_crs, parse_crs

    given, what = crs, "--nav-crs"
    if given is None and path is not None:
        given, what = _crs_comment(path), f"{name}, line '# crs:'"
    if given is None:
        where = "a first line '# crs: EPSG:4979' in the file or " if path is not None else ""
        raise InputError(
            f"{name} does not name its CRS: give {where}the option --nav-crs (the datum the "
            f"positions were processed on: {_NAV_CRS_HINT})"
        )
    c = parse_crs(given, what)
    if (c.is_geocentric if geocentric else c.is_geographic) is False:
        want = "a geocentric CRS (EPSG:4978, WGS 84)" if geocentric else "a geographic CRS"
        cols = ", ".join(GEOCENTRIC_COLUMNS if geocentric else GEODETIC_COLUMNS)
        raise InputError(
            f"{name}: positions {cols} need {want}, but the CRS is {c.name!r}; name {_NAV_CRS_HINT}"
        )
    return c, geographic_3d_crs(c)


def _read_geodetic_table(path, cols, crs, frame, gps_week, map_crs) -> Navigation:
    from hsgeo.io.tables import read_table

    name = f"navigation file {str(path)!r}"
    times = [c for c in TIME_COLUMNS if c in cols]
    if len(times) != 1:
        raise InputError(
            f"{name} must state its time scale in one column: gps_sow_s (GPS seconds of week, "
            "with an optional gps_week column) or sod_s (seconds of day); "
            f"found {times or 'neither'} among {cols}"
        )
    tcol = times[0]
    geocentric = all(c in cols for c in GEOCENTRIC_COLUMNS) and "lat_deg" not in cols
    pos_cols = GEOCENTRIC_COLUMNS if geocentric else GEODETIC_COLUMNS
    required = (tcol, *pos_cols, *ATTITUDE_COLUMNS) + (("gps_week",) if "gps_week" in cols else ())
    limits = dict(NAV_LIMITS)
    limits.update({"lat_deg": (-90.0, 90.0), "lon_deg": (-180.0, 360.0), "h_m": (-1e4, 1e5)})
    limits["gps_sow_s"] = (0.0, SECONDS_PER_WEEK)
    limits["sod_s"] = (0.0, SECONDS_PER_DAY)
    df = read_table(
        path,
        required,
        "navigation",
        limits=limits,
        unique_rows=False,
        integer_columns=("gps_week",) if "gps_week" in cols else (),
    )
    lines = _data_lines_of(path, len(df))
    src, crs3d = _nav_crs(name, crs, path, geocentric)
    pos = df[list(pos_cols)].to_numpy(dtype=np.float64)
    if geocentric:
        from pyproj import Transformer

        lon, lat, h = Transformer.from_crs(src, crs3d, always_xy=True).transform(*pos.T)
    else:
        lat, lon, h = pos.T
    t = df[tcol].to_numpy(dtype=np.float64)
    week0 = gps_week
    if "gps_week" in df:
        weeks = df["gps_week"].to_numpy(dtype=np.int64)
        week0 = int(weeks[0])
        t = t + (weeks - weeks[0]) * SECONDS_PER_WEEK
    else:
        t = _unroll(t, SECONDS_PER_WEEK if tcol == "gps_sow_s" else SECONDS_PER_DAY)
    ang = df[list(ATTITUDE_COLUMNS)].to_numpy(dtype=np.float64)
    return _to_frame(
        name,
        lines,
        tcol,
        t,
        np.asarray(lon),
        np.asarray(lat),
        np.asarray(h),
        ang,
        src,
        crs3d,
        frame,
        map_crs,
        TIME_COLUMNS[tcol],
        week0 if tcol == "gps_sow_s" else None,
    )


def _unroll(t: np.ndarray, period_s: float) -> np.ndarray:
    """Times of week (day) that pass the end of the week (midnight) continue past it."""
    back = np.diff(t) < -period_s / 2
    return t + period_s * np.concatenate([[0], np.cumsum(back)])


def _read_sbet_navigation(path, crs, frame, gps_week, map_crs) -> Navigation:
    from hsgeo.io.sbet import read_sbet

    name = f"SBET file {str(path)!r}"
    rec = read_sbet(path)
    src, crs3d = _nav_crs(name, crs, None, geocentric=False)
    t = _unroll(rec["time_s"], SECONDS_PER_WEEK)
    ang = np.rad2deg(np.column_stack([rec["roll_rad"], rec["pitch_rad"], rec["heading_rad"]]))
    lines = [f"record {i + 1}" for i in range(t.size)]
    return _to_frame(
        name,
        lines,
        "time",
        t,
        np.rad2deg(rec["lon_rad"]),
        np.rad2deg(rec["lat_rad"]),
        rec["h_m"],
        ang,
        src,
        crs3d,
        frame,
        map_crs,
        TIME_COLUMNS["gps_sow_s"],
        gps_week,
    )


def _to_frame(
    name, lines, tcol, t, lon, lat, h, ang_deg, src, crs3d, frame, map_crs, scale, week
) -> Navigation:
    """Positions and each record's attitude carried into the local frame (exactly)."""
    from pyproj import Transformer

    from hsgeo.crs import LocalFrame, parse_crs
    from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy, rpy_from_R

    if t.size < 2:
        raise InputError(f"{name} has {t.size} record; a navigation needs at least 2")
    lon = (np.asarray(lon, float) + 180.0) % 360.0 - 180.0
    epsg = crs3d.to_epsg()
    if frame is None:
        if epsg is None:
            raise InputError(
                f"{name}: the CRS {src.name!r} ({src.to_string()}) has no geographic 3D form with "
                "an EPSG code (longitude, latitude, ellipsoidal height); name the realisation the "
                "positions are on, e.g. EPSG:6319 (NAD83(2011)), EPSG:4979 (WGS 84), EPSG:4937 "
                "(ETRS89)"
            )
        m = None if map_crs is None else parse_crs(map_crs).to_epsg()
        frame = LocalFrame.about(lon, lat, epsg, map_epsg=m)
    if epsg != int(frame.datum_epsg):
        tr = Transformer.from_crs(crs3d, frame.datum_crs, always_xy=True)
        lon, lat, h = (np.asarray(v) for v in tr.transform(lon, lat, h))
    enu = np.column_stack(frame.lonlat_to_enu_precise(lon, lat, h))
    _check_records(name, lines, t, enu, ang_deg, "latitude, longitude, height", tcol)
    _check_heading(name, enu, t, ang_deg[:, 2])
    a = np.deg2rad(ang_deg)
    R_frame_enu_from_body = frame.R_enu_from_ned_at(lon, lat) @ R_from_rpy(
        a[:, 0], a[:, 1], a[:, 2]
    )
    rph = rpy_from_R(R_ENU_FROM_NED @ R_frame_enu_from_body)
    src_name = f"{src.name} ({src.to_string()})"
    return Navigation(Trajectory(t, enu, rph), frame, scale, week, src_name)


def check_heading_follows_course(traj: Trajectory, name: str) -> None:
    """Refuse a local-ENU navigation whose heading does not follow its course over ground.

    For the line scanners' commands (``lp-observations``, ``adjust-pushbroom``): their
    platform flies forward, so where it moves faster than :data:`COURSE_MIN_SPEED_M_S` the
    heading is the course within a crab angle (:data:`MAX_HEADING_COURSE_DEG`). Refused here: a
    heading opposite to the course (more than 180° − that angle off: exit 0 with
    mirrored ground points before). A heading otherwise off (radians, from east) is left to the
    adjustment, whose poor fit names the angle unit (``adjust-pushbroom``). Not applied by
    :func:`read_trajectory` itself: a multirotor carrying a frame camera may fly sideways.

    Parameters
    ----------
    traj : Trajectory
    name : str
        The file in the user's words, e.g. ``"navigation file 'nav.csv'"``.

    Raises
    ------
    InputError
        Naming the file, the column heading_deg and the remedy.
    """
    _check_heading(
        name, traj.xyz_m, traj.t_s, np.rad2deg(traj.roll_pitch_heading_rad[:, 2]), opposite=True
    )


def _follows_in_radians(heading, course_deg) -> bool:
    """The heading column read as radians follows the course (a heading of 3.14 on a line
    flown south is π, not 3.14°; unwrapped values such as −3π too): converted, within the crab
    angle. Asked only of a heading that is opposite to the course read as degrees, which a
    heading in degrees that also follows the course as radians is not.
    """
    d = np.abs((np.degrees(heading) - course_deg + 180.0) % 360.0 - 180.0)
    return bool(np.median(d) <= MAX_HEADING_COURSE_DEG)


def _check_heading(name, enu, t, heading_deg, opposite: bool = False) -> None:
    """The heading follows the course over ground (within a crab angle) where the platform
    moves: else the heading column is not a true heading in degrees.
    """
    v = np.diff(enu[:, :2], axis=0) / np.diff(t)[:, None]
    speed = np.hypot(v[:, 0], v[:, 1])
    moving = speed > COURSE_MIN_SPEED_M_S
    if np.count_nonzero(moving) < 2:
        return
    course = np.degrees(np.arctan2(v[:, 0], v[:, 1]))
    hmid = 0.5 * (heading_deg[1:] + heading_deg[:-1])
    d = np.abs((hmid - course + 180.0) % 360.0 - 180.0)[moving]
    med = float(np.median(d))
    if opposite and _follows_in_radians(hmid[moving], course[moving]):
        return  # radians under a _deg column: the adjustment's poor fit names the unit
    if med > 180.0 - MAX_HEADING_COURSE_DEG:  # a heading 180° off
        raise InputError(
            f"{name}, column heading_deg: the heading is opposite to the course over ground "
            f"({med:.1f}° off, median over {d.size} moving records): the sensor would look "
            "backwards and every ground point lands mirrored. Give the true heading of the body's "
            "x axis (forward), in degrees clockwise from north: add 180° if it is the reverse"
        )
    if med > MAX_HEADING_COURSE_DEG and not opposite:
        raise InputError(
            f"{name}, column heading_deg: the heading differs from the course over ground by "
            f"{med:.1f}° (median over {d.size} moving records; an aircraft crabs by less than "
            f"{MAX_HEADING_COURSE_DEG:g}°). Give the true heading in degrees, clockwise from "
            "north (not radians, not a yaw from east, not a wander-frame heading)"
        )


def read_line_navigation(path, *, crs=None, site=None, frame_needed_by: str | None = None):
    """The navigation of the line scanners' commands (``lp-observations``, ``adjust-pushbroom``)
    in a local frame: a local-ENU file as read, or a navigation as delivered (a geodetic CSV
    or Parquet, an Applanix SBET; :func:`read_navigation`) carried into a local frame.

    Parameters
    ----------
    path : str or path-like
    crs : str or int, optional
        ``--nav-crs``: the geodetic navigation's CRS (an SBET's is required; a CSV's may be its
        ``# crs:`` line).
    site : (lat_deg, lon_deg[, h_m]), optional
        ``--site``: the origin of the local frame, on the navigation's datum, in which the
        commands' other tables (GCPs, squares: ``E_m, N_m, H_m``) are given. Without it the
        frame is about the navigation's centre.
    frame_needed_by : str, optional
        The option whose table is in the local frame (``"--gcp"``, ``"--squares"``): a geodetic
        navigation then needs ``site``, else those coordinates would be taken in a frame the
        user never saw.

    Returns
    -------
    traj : Trajectory
        Times as in the file (GPS seconds of week or of day: the lines' and the observations'
        time scale must be the same), positions E, N, U in the frame, attitude against its NED.
    frame : hsgeo.crs.LocalFrame or None
        None for a local-ENU file.

    Raises
    ------
    InputError
        As :func:`read_navigation`; ``--nav-crs``/``--site`` given with a local-ENU file; a
        geodetic navigation with local-frame GCPs or squares but no ``--site``; a heading that
        does not follow the course (:func:`check_heading_follows_course`).
    """
    from hsgeo.crs import LocalFrame

    path = Path(path)
    name = f"navigation file {str(path)!r}"
    nav = read_navigation(path, crs=crs)
    if nav.source_crs == "local ENU":
        if crs is not None or site is not None:
            opt = "--nav-crs" if crs is not None else "--site"
            raise InputError(
                f"{opt} is for a navigation as delivered (latitude, longitude, height or an "
                f"SBET), but {name} is already in a local east-north-up frame (t_s, E_m, N_m, "
                f"U_m): drop {opt}"
            )
        check_heading_follows_course(nav.trajectory, name)
        return nav.trajectory, None
    if site is None and frame_needed_by is not None:
        raise InputError(
            f"{name} is geodetic ({nav.source_crs}), but the table of {frame_needed_by} has "
            "E_m, N_m, H_m in a local east-north-up frame: give its origin as --site LAT,LON[,H] "
            f"(degrees and ellipsoidal metres on the navigation's datum, EPSG:"
            f"{int(nav.frame.datum_epsg)})"
        )
    if site is not None:
        lat, lon, *h = (float(v) for v in site)
        frame = LocalFrame(lat, lon, h[0] if h else 0.0, None, int(nav.frame.datum_epsg))
        nav = read_navigation(path, crs=crs, frame=frame)
    return nav.trajectory, nav.frame
