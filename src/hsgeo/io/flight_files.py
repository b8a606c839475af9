"""The files of a simulated flight, in the formats a real flight delivers them.

What ``hsgeo data flight`` writes (:mod:`hsgeo.simulate.geo_flight`):

==================  =======================================================================
``lines.raw``       the line scanner's ENVI cube, BIL, float32, header ``lines.raw.hdr``
                    with ``wavelength`` and ``fwhm`` in nm
``line_times.csv``  one time per line (``t_s``: GPS seconds of week)
``nav.csv``         geodetic navigation: ``# crs: EPSG:4979`` (WGS 84), ``gps_sow_s, lat_deg,
                    lon_deg, h_m, roll_deg, pitch_deg, heading_deg`` (attitude against the
                    north-east-down at each record)
``sensor.toml``     the ``view-angle`` sensor file (boresight, lever arm) and its table
``view_angles.csv`` (``pixel, across_deg, along_deg``)
``dsm.tif``         the ground's ellipsoidal heights, GeoTIFF in the output CRS (a 2D CRS:
                    ``--vertical ellipsoidal``)
``targets.csv``     ``# crs: EPSG:n`` (the output CRS), ``target_id, x_m, y_m, lat_deg,
                    lon_deg, h_m``: the targets' true positions
``command.txt``     the ``hsgeo orthorectify`` command line that maps it
==================  =======================================================================
"""

from __future__ import annotations

import os
import shlex
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["FLIGHT_FILES", "write_flight", "orthorectify_command", "check_flight_outputs"]

FLIGHT_FILES = (
    "lines.raw",
    "lines.raw.hdr",
    "line_times.csv",
    "nav.csv",
    "sensor.toml",
    "view_angles.csv",
    "dsm.tif",
    "targets.csv",
    "command.txt",
)


def _csv(header: str, cols, comment: str = "") -> str:
    rows = [comment, header] if comment else [header]
    for r in zip(*cols, strict=True):
        rows.append(
            ",".join(str(int(v)) if isinstance(v, np.integer) else repr(float(v)) for v in r)
        )
    return "\n".join(rows) + "\n"


def orthorectify_command(out: Path, epsg: int) -> list[str]:
    """The command line that orthorectifies the flight written in ``out`` onto ``EPSG:epsg``
    (the targets' CRS).
    """
    o = Path(out)
    return [
        "hsgeo",
        "orthorectify",
        str(o / "lines.raw"),
        "--line-times",
        str(o / "line_times.csv"),
        "--trajectory",
        str(o / "nav.csv"),
        "--sensor",
        str(o / "sensor.toml"),
        "--dsm",
        str(o / "dsm.tif"),
        "--vertical",
        "ellipsoidal",
        "--crs",
        f"EPSG:{int(epsg)}",
        "-o",
        str(o / "ortho.tif"),
    ]


def check_flight_outputs(out, *, overwrite: bool = False) -> list[Path]:
    """Check, before any work, that the flight's files can be written into the folder ``out``
    (it may not exist yet, but its parent must; none of its files may exist, unless
    ``overwrite``).

    Returns
    -------
    list of Path
        The files (module docstring).

    Raises
    ------
    InputError
        Naming ``--out`` and the remedy.
    """
    from hsgeo.io._files import check_outputs

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {str(out)!r} is a file; give a folder for the flight's files")
    if not out.exists():
        if not out.parent.is_dir():
            raise InputError(
                f"--out {str(out)!r}: the folder {str(out.parent)!r} does not exist; create it "
                "first"
            )
        if not os.access(out.parent, os.W_OK | os.X_OK):
            raise InputError(f"--out {str(out)!r}: {str(out.parent)!r} is not writable")
        return [out / n for n in FLIGHT_FILES]
    paths = [out / n for n in FLIGHT_FILES]
    check_outputs([(p, "--out") for p in paths], overwrite=overwrite)
    return paths


def write_flight(out, flight, *, overwrite: bool = False) -> list[Path]:
    """Write a :class:`~hsgeo.simulate.geo_flight.FlightData` into the folder ``out`` (made
    when missing; its files refused if they exist, unless ``overwrite``).

    Returns
    -------
    list of Path
        The files written (module docstring).
    """
    from hsgeo.io._files import make_folder, output_group

    out = Path(out)
    paths = check_flight_outputs(out, overwrite=overwrite)
    make_folder(out)
    if overwrite:  # write_envi and write_geotiff refuse an existing file
        for p in paths:
            p.unlink(missing_ok=True)
    with output_group():  # the flight's files all, or none of them (a write refused)
        _write_files(out, flight)
    return paths


def _write_files(out: Path, flight) -> None:
    from rasterio.transform import from_origin

    from hsgeo.io._files import atomic_path, write_text
    from hsgeo.io.envi import write_envi
    from hsgeo.io.geotiff import write_geotiff

    c = flight.config
    write_envi(
        out / "lines.raw",
        np.ascontiguousarray(flight.lines_lsb.transpose(2, 0, 1)),
        wavelength_nm=list(c.wavelength_nm),
        fwhm_nm=list(c.fwhm_nm),
        interleave="bil",
        description=f"hsgeo data flight: a simulated line scanner over {c.lat_deg:g}, "
        f"{c.lon_deg:g}",
    )
    write_text(out / "line_times.csv", _csv("t_s", [flight.line_t_s]), atomic=True)
    n = flight.nav
    keys = ("gps_sow_s", "lat_deg", "lon_deg", "h_m", "roll_deg", "pitch_deg", "heading_deg")
    write_text(
        out / "nav.csv", _csv(",".join(keys), [n[k] for k in keys], "# crs: EPSG:4979"), atomic=True
    )
    px = np.arange(flight.across_deg.size)
    write_text(
        out / "view_angles.csv",
        _csv("pixel,across_deg,along_deg", [px, flight.across_deg, flight.along_deg]),
        atomic=True,
    )
    write_text(
        out / "sensor.toml",
        "# a line scanner given by its per-pixel view angles (hsgeo data flight)\n[sensor]\n"
        "model = 'view-angle'\nangles_csv = 'view_angles.csv'\n"
        f"boresight_deg = [{', '.join(repr(float(v)) for v in c.boresight_deg)}]\n"
        f"lever_arm_m = [{', '.join(repr(float(v)) for v in c.lever_arm_m)}]\n",
        atomic=True,
    )
    d = flight.dsm
    write_geotiff(
        out / "dsm.tif",
        d["values"],
        from_origin(*d["origin_xy_m"], d["res_m"], d["res_m"]),
        int(d["epsg"]),
    )
    t = flight.targets
    tk = ("target_id", "x_m", "y_m", "lat_deg", "lon_deg", "h_m")
    write_text(
        out / "targets.csv",
        _csv(",".join(tk), [t[k] for k in tk], f"# crs: EPSG:{flight.output_epsg}"),
        atomic=True,
    )
    with atomic_path(out / "command.txt") as tmp:
        Path(tmp).write_text(
            shlex.join(orthorectify_command(out, flight.output_epsg)) + "\n", encoding="utf-8"
        )
