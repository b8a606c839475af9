"""Issue 38's done-means lines measured on this tree: ``bench/results/issue38_audit.json``.

    python bench/issue38_audit.py [--no-pytest]

One entry per done-means line (the issue's four bullets, split at their clauses): the line,
``status`` (met / short) and the evidence — the test node ids that check it, with their outcome
in this run (pytest in a subprocess, ``--junitxml``; ``--no-pytest`` skips it and says so), and
the numbers, computed here: the six sites' targets, the DSM variants, the SBET against its CSV,
the NetCDF opened and reprojected by rioxarray and the wavelengths GDAL reports are measured by
this script with the tests' own helpers (tests/test_geodetic_geolocation.py,
tests/test_io_navigation.py) and hsgeo's one raster writer; the 002 chapter's rows through the
geodetic path are read from ``bench/results/geodetic_002.json`` (bench/bench_geodetic_002.py),
compared row by row here, with the floating-point floor of a latitude in a file computed
(``np.spacing``).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
sys.path.insert(0, str(ROOT / "tests"))

T_GEO = "tests/test_geodetic_geolocation.py"
T_REQ = "tests/test_geodetic_requested_crs.py"
T_NAV = "tests/test_io_navigation.py"
T_TER = "tests/test_io_terrain.py"
T_CLI_GEO = "tests/test_cli_orthorectify_geodetic.py"
T_CLI = "tests/test_cli_orthorectify.py"
T_ENVI = "tests/test_cli_orthorectify_envi.py"
T_LPE = "tests/test_cli_lp_observations_envi.py"
T_BAD = "tests/test_bad_input.py"
T_BADG = "tests/test_bad_input_geodesy.py"
T_002 = "tests/test_geodetic_002_flight.py"
LPE_BAD = f"{T_LPE}::test_envi_scenes_bad_input_one_line_exit_2"

#: The tests run by this audit (each fast; the slow ones are named in the entries, not run).
NODES = [
    f"{T_GEO}::test_targets_in_the_output_crs_against_pyproj_alone",
    f"{T_GEO}::test_the_boundary_line_crosses_utm_32_33",
    f"{T_GEO}::test_ignoring_each_records_ned_rotation_fails_the_check",
    f"{T_GEO}::test_the_same_flight_on_a_dsm_in_any_crs",
    T_REQ,
    f"{T_NAV}::test_sbet_gives_the_trajectory_of_the_equivalent_csv",
    f"{T_NAV}::test_each_records_ned_is_carried_into_the_frame",
    T_TER,
    T_CLI_GEO,
    f"{T_CLI}::test_gdal_reads_the_wavelengths_from_its_standard_keys",
    f"{T_CLI}::test_the_netcdf_is_cf_and_rioxarray_reprojects_it",
    "tests/test_raster_formats.py",
    "tests/test_data_flight.py::test_targets_land_where_pyproj_puts_them[aas]",
    "tests/test_data_flight.py::test_targets_land_where_pyproj_puts_them[sydney]",
    f"{T_002}::test_the_trajectory_is_the_local_one",
    f"{T_002}::test_ground_points_and_mosaic_are_the_local_ones",
    T_BADG,
    "tests/test_geodetic_line_commands.py::test_bad_navigation_one_line_exit_2",
    T_ENVI,
    T_LPE,
    "tests/test_io_envi_lines.py",
    "tests/test_view_angle.py",
]
#: test_bad_input.py's cases of the new formats (selected with -k).
BAD_INPUT_K = "orthorectify-envi"


def run_pytest(nodes, k=None) -> dict:
    """``{node id: outcome}`` of one pytest run (passed / failed / skipped / error), with the
    printed output of each test."""
    with tempfile.TemporaryDirectory() as tmp:
        xml = Path(tmp) / "junit.xml"
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-s"]
        cmd += ["-m", "not slow"]  # the slow tests are named in the entries, not run
        cmd += ["-o", "junit_logging=system-out", f"--junitxml={xml}", *nodes]
        if k:
            cmd += ["-k", k]
        subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False)
        out = {}
        for tc in ET.parse(xml).getroot().iter("testcase"):
            file = tc.get("classname").replace(".", "/") + ".py"
            node = f"{file}::{tc.get('name')}"
            kind = "passed"
            for tag in ("failure", "error", "skipped"):
                if tc.find(tag) is not None:
                    kind = {"failure": "failed"}.get(tag, tag)
            so = tc.find("system-out")
            out[node] = {"outcome": kind, "printed": (so.text or "").strip()[-600:] if so else ""}
    return out


#: Measured numbers by name (``--numbers FILE`` keeps them between runs: the tests' outcomes
#: and the numbers can then be gathered in two runs side by side).
CACHE: dict = {}


def _cached(name: str, measure):
    if name not in CACHE:
        CACHE[name] = json.loads(json.dumps(measure()))
    return CACHE[name]


def _outcomes(ran: dict | None, prefix: str) -> dict:
    if ran is None:
        return {"not run": "--no-pytest"}
    sel = {n: r["outcome"] for n, r in ran.items() if n.startswith(prefix)}
    return sel or {prefix: "not collected"}


def _passed(ran: dict | None, prefixes) -> bool:
    if ran is None:
        return True  # judged on the numbers alone (said in the entry)
    sel = [r["outcome"] for n, r in ran.items() if any(n.startswith(p) for p in prefixes)]
    return bool(sel) and all(o in ("passed", "skipped") for o in sel)


# ----------------------------------------------------------------------------------------------
def sites(ran) -> list[dict]:
    """The six sites: targets against pyproj alone, default and requested CRS; and without the
    per-record NED rotation."""
    import test_geodetic_geolocation as g
    from test_geodetic_requested_crs import REQUESTED

    from hsgeo.crs import LocalFrame
    from hsgeo.rotations import R_ENU_FROM_NED

    def measure():
        per, req, without = {}, {}, {}
        with tempfile.TemporaryDirectory() as tmp:
            for j, site in enumerate(g.SITES):
                d = Path(tmp) / f"s{j}"
                d.mkdir()
                xy, truth, _ = g._orthorectified(site, d)
                rms, mx = g._rms_and_max(xy, truth)
                lat0, lon0 = g.SITES[site]
                fl = g._flight(lat0, lon0)
                from hsgeo.crs import default_output_crs

                per[site] = {
                    "lat_lon_deg": [lat0, lon0],
                    "line_lon_deg": [float(fl[2].min()), float(fl[2].max())],
                    "line_crosses_the_antimeridian": bool(
                        fl[2].max() > 179.9 and fl[2].min() < -179.9
                    ),
                    "output_crs": f"EPSG:{default_output_crs(lon0, lat0, 4979).to_epsg()}",
                    "n_targets": int(len(xy)),
                    "rms_m": rms,
                    "rms_gsd": rms / g.GSD_M,
                    "max_m": mx,
                }
            for j, (site, crs) in enumerate(REQUESTED):
                d = Path(tmp) / f"r{j}"
                d.mkdir()
                xy, truth, _ = g._orthorectified(site, d, crs=crs)
                rms, mx = g._rms_and_max(xy, truth)
                req[f"{site} in {crs}"] = {"rms_m": rms, "max_m": mx}
            real = LocalFrame.R_enu_from_ned_at

            def no_rotation(self, lon_deg, lat_deg):
                shape = np.broadcast(np.asarray(lon_deg), np.asarray(lat_deg)).shape
                return np.broadcast_to(R_ENU_FROM_NED, (*shape, 3, 3)).copy()

            LocalFrame.R_enu_from_ned_at = no_rotation
            try:
                for j, site in enumerate(g.SITES):
                    d = Path(tmp) / f"n{j}"
                    d.mkdir()
                    xy, truth, _ = g._orthorectified(site, d)
                    rms, mx = g._rms_and_max(xy, truth)
                    without[site] = {"rms_m": rms, "rms_gsd": rms / g.GSD_M, "max_m": mx}
            finally:
                LocalFrame.R_enu_from_ned_at = real
        return per, req, without

    per, req, without = _cached("sites", measure)
    bar = 0.25 * g.GSD_M
    ok = all(v["rms_m"] < bar for v in (*per.values(), *req.values()))
    crosses = per["UTM 32/33 at 12 E"]["line_lon_deg"]
    ok = ok and crosses[0] < 12.0 < crosses[1]
    ok = ok and _passed(ran, [f"{T_GEO}::test_targets", f"{T_GEO}::test_the_boundary", T_REQ])
    fails = all(v["rms_m"] >= bar for v in without.values())
    fails = fails and _passed(ran, [f"{T_GEO}::test_ignoring"])
    both = {s: {"rms_with_m": per[s]["rms_m"], "rms_without_m": without[s]["rms_m"]} for s in per}
    return [
        {
            "line": "At each of Ås, Sydney (33.9 S, 151.2 E), Boulder (40.0 N, 105.3 W), "
            "Svalbard (78.2 N, 15.6 E), the antimeridian (16.5 S, 179.95 E) and a line across "
            "the UTM 32/33 boundary at 12° E, a 30 km line at 2 km above ground: the "
            "orthorectified targets lie within 0.25 GSD (RMS) of their true positions in the "
            "requested CRS, checked against positions computed with pyproj alone (test).",
            "status": "met" if ok else "short",
            "evidence": {
                "how": "an SBET by the test's own struct writer (301 records, 31 km east-west, "
                "2150 m ellipsoidal over terrain at 125–175 m, attitude ±2° against each "
                "record's NED), a DSM GeoTIFF, 30 targets 0–1 km either side seen in the body "
                "frame (PROJ's topocentric frame at the aircraft) → hsgeo.io.read_navigation, "
                "read_terrain, geocode.intersect, the frame → output CRS; truth by pyproj "
                "alone (Geod + Transformer 4979 → CRS)",
                "bar_rms_m": bar,
                "default_crs_per_site": per,
                "requested_crs": req,
                "tests": {
                    **_outcomes(ran, f"{T_GEO}::test_targets"),
                    **_outcomes(ran, f"{T_GEO}::test_the_boundary"),
                    **_outcomes(ran, T_REQ),
                    **_outcomes(ran, "tests/test_data_flight.py"),
                },
                "tests_end_to_end_cli_slow": "tests/test_data_flight.py::test_targets_land_"
                "where_pyproj_puts_them[boulder|svalbard|antimeridian|utm-32-33] (slow: hsgeo "
                "data flight → hsgeo orthorectify ENVI lines + view-angle sensor → COG, targets "
                "fitted in the image within 0.25 output GSD; aas and sydney run here)",
                "files": "tests/test_geodetic_geolocation.py, tests/test_geodetic_requested_crs"
                ".py, src/hsgeo/io/navigation.py, src/hsgeo/io/sbet.py, src/hsgeo/io/terrain.py,"
                " src/hsgeo/crs.py",
            },
        },
        {
            "line": "Ignoring the per-record NED rotation makes that test fail (shown in the "
            "note).",
            "status": "met" if fails else "short",
            "evidence": {
                "how": "the same check with LocalFrame.R_enu_from_ned_at replaced by the frame "
                "origin's R_ENU_FROM_NED (no meridian convergence, no tilt of the normal)",
                "rms_with_and_without_m": both,
                "without_per_site": without,
                "bar_rms_m": bar,
                "tests": {
                    **_outcomes(ran, f"{T_GEO}::test_ignoring"),
                    **_outcomes(ran, f"{T_NAV}::test_each_records_ned"),
                },
                "files": "tests/test_geodetic_geolocation.py, src/hsgeo/crs.py "
                "(LocalFrame.R_enu_from_ned_at)",
            },
        },
    ]


# ----------------------------------------------------------------------------------------------
def dsm_variants(ran) -> dict:
    import test_geodetic_geolocation as g
    from pyproj import Transformer

    from hsgeo.crs import use_system_proj_grids
    from hsgeo.errors import HsgeoError

    has_egm96 = use_system_proj_grids() and Path("/usr/share/proj/egm96_15.gtx").exists()
    site = "Ås"
    lat0, lon0 = g.SITES[site]
    xc, yc = Transformer.from_crs(4979, 3035, always_xy=True).transform(lon0, lat0)
    away = [
        (xc - 17000, yc + 1350, xc + 17000, yc + 1500),
        (xc - 17000, yc - 4000, xc - 15000, yc - 3000),
    ]
    variants = {
        "EPSG:4326": (dict(crs="EPSG:4326"), "ellipsoidal"),
        "EPSG:3035": (dict(crs="EPSG:3035"), "ellipsoidal"),
        "EPSG:3035 with voids away from the line": (
            dict(crs="EPSG:3035", nodata=-9999.0, voids=away),
            "ellipsoidal",
        ),
    }
    if has_egm96:
        variants["EPSG:4326+5773 (EGM96 heights)"] = (
            dict(crs="EPSG:4326+5773", heights=g._egm96_of(lat0, lon0)),
            None,
        )

    def measure():
        out, refusals = {}, {}
        with tempfile.TemporaryDirectory() as tmp:
            ref_dir = Path(tmp) / "utm"
            ref_dir.mkdir()
            ref, truth, _ = g._orthorectified(site, ref_dir)
            for j, (name, (kw, vertical)) in enumerate(variants.items()):
                d = Path(tmp) / f"v{j}"
                d.mkdir()
                xy, _, terrain = g._orthorectified(
                    site, d, dsm=lambda p, kw=kw: g._dsm(p, lat0, lon0, **kw), vertical=vertical
                )
                out[name] = {
                    "max_difference_to_utm_dsm_m": float(np.hypot(*(xy - ref).T).max()),
                    "void_cells_in_window": int(terrain.void.sum()),
                    "source": terrain.source[:160],
                }
            x2, y2 = ref[2]
            hole = [(x2 - 40.0, y2 - 40.0, x2 + 40.0, y2 + 40.0)]
            cases = {
                "void under a target": (
                    lambda p: g._dsm(p, lat0, lon0, nodata=-9999.0, voids=hole),
                    "ellipsoidal",
                ),
                "DSM in EPSG:3035 without a vertical datum, none stated": (
                    lambda p: g._dsm(p, lat0, lon0, crs="EPSG:3035"),
                    None,
                ),
            }
            for j, (name, (make, vertical)) in enumerate(cases.items()):
                d = Path(tmp) / f"x{j}"
                d.mkdir()
                try:
                    g._orthorectified(site, d, dsm=make, vertical=vertical)
                    refusals[name] = {"refused": False}
                except HsgeoError as exc:
                    refusals[name] = {
                        "refused": True,
                        "error": type(exc).__name__,
                        "message": str(exc),
                    }
        return out, refusals

    out, refusals = _cached("dsm", measure)
    ok = all(v["max_difference_to_utm_dsm_m"] <= 0.05 for v in out.values())
    ok = ok and has_egm96 and all(r["refused"] for r in refusals.values())
    ok = ok and _passed(ran, [f"{T_GEO}::test_the_same_flight", T_TER, T_CLI_GEO])
    return {
        "line": "The same flight with the DSM in EPSG:4326, in EPSG:3035, with voids away from "
        "the lines, and in a compound CRS with EGM96 heights gives the same targets within "
        "0.05 m; a void under a line and an unknown vertical datum are refused by name.",
        "status": "met" if ok else "short",
        "evidence": {
            "site": site,
            "egm96_grid_found": has_egm96,
            "variants": out,
            "refused_in_the_library": refusals,
            "refused_by_the_command_exit_2": {
                **_outcomes(ran, f"{T_CLI_GEO}::test_bad_new_formats_one_line_exit_2"),
                **_outcomes(ran, f"{T_CLI_GEO}::test_bad_input_one_line_exit_2"),
            },
            "tests": {
                **_outcomes(ran, f"{T_GEO}::test_the_same_flight"),
                **_outcomes(ran, T_TER),
            },
            "files": "src/hsgeo/io/terrain.py, src/hsgeo/crs.py, tests/test_geodetic_"
            "geolocation.py, tests/test_io_terrain.py, tests/test_cli_orthorectify_geodetic.py",
        },
    }


# ----------------------------------------------------------------------------------------------
def sbet(ran) -> dict:
    import test_io_navigation as t

    from hsgeo.io.navigation import read_navigation

    with tempfile.TemporaryDirectory() as tmp:
        fl = t._flight()
        a = read_navigation(t._write_geodetic_csv(Path(tmp) / "nav.csv", fl))
        b = read_navigation(
            t._write_sbet(Path(tmp) / "sbet_01.out", fl), crs="EPSG:4979", gps_week=2400
        )
    dpos = float(np.max(np.abs(b.trajectory.xyz_m - a.trajectory.xyz_m)))
    dang = float(
        np.max(
            np.abs(
                np.degrees(
                    b.trajectory.roll_pitch_heading_rad - a.trajectory.roll_pitch_heading_rad
                )
            )
        )
    )
    dt = float(np.max(np.abs(b.trajectory.t_s - a.trajectory.t_s)))
    ok = dpos <= 1e-3 and dang <= 1e-6 and a.frame == b.frame
    ok = ok and _passed(ran, [f"{T_NAV}::test_sbet"])
    return {
        "line": "An SBET written by an independent writer (a test's own struct code, the "
        "documented layout) gives the same trajectory as the equivalent CSV to 1 mm and 1e-6°.",
        "status": "met" if ok else "short",
        "evidence": {
            "writer": "tests/test_io_navigation.py::_write_sbet: struct.pack('<17d', time, "
            "lat rad, lon rad, h, vx, vy, vz, roll, pitch, platform heading = true heading + "
            "wander, wander, accelerations, angular rates) per record",
            "n_records": int(a.trajectory.t_s.size),
            "max_abs_position_difference_m": dpos,
            "max_abs_angle_difference_deg": dang,
            "max_abs_time_difference_s": dt,
            "same_frame": a.frame == b.frame,
            "tests": {
                **_outcomes(ran, f"{T_NAV}::test_sbet"),
                **_outcomes(ran, "tests/test_geodetic_line_commands.py"),
            },
            "files": "src/hsgeo/io/sbet.py, src/hsgeo/io/navigation.py",
        },
    }


# ----------------------------------------------------------------------------------------------
KEYS = ("paper", "paper_sigma", "reproduced", "sigma", "truth")


def _largest_change(rows_a, rows_b) -> dict:
    """The largest relative change of any value between two row lists (as
    bench/compare_reproductions.py) and the count of values beyond 1e-9 relative."""
    worst, n_over = {"relative": 0.0}, 0
    for a, b in zip(rows_a, rows_b, strict=True):
        for k in KEYS:
            x, y = a[k], b[k]
            if x is None or y is None or not (math.isfinite(x) and math.isfinite(y)):
                n_over += (x is None) != (y is None)
                continue
            rel = abs(x - y) / max(abs(x), abs(y)) if x != y else 0.0
            n_over += rel > 1e-9
            if rel > worst["relative"]:
                worst = {
                    "relative": rel,
                    "row": f"{a['table']}: {a['quantity']} {k}",
                    "values": [x, y],
                }
    return {"largest": worst, "n_values_beyond_1e-9": n_over, "n_rows": len(rows_a)}


def chapter_rows(ran, baseline=None) -> dict:
    """The 002 chapter through the geodetic path against itself plain (same code, same run);
    the plain run against main's baseline (``--baseline DIR``) when given."""
    path = RESULTS / "geodetic_002.json"
    line = (
        "The 002 chapter's rows unchanged to 1e-9 relative when its flight goes through the "
        "geodetic path."
    )
    if not path.is_file():
        return {
            "line": line,
            "status": "short",
            "evidence": {"not measured": f"{path.relative_to(ROOT)} not written yet"},
        }
    d = json.loads(path.read_text(encoding="utf-8"))
    per_row, n_vals, n_within, n_changed = [], 0, 0, 0
    for a, b in zip(d["plain"]["rows"], d["geodetic"]["rows"], strict=True):
        assert (a["table"], a["quantity"], a["unit"]) == (b["table"], b["quantity"], b["unit"])
        for k in KEYS:
            x, y = a[k], b[k]
            if x is None or y is None or not (math.isfinite(x) and math.isfinite(y)):
                continue
            n_vals += 1
            diff = abs(x - y)
            rel = diff / max(abs(x), abs(y)) if diff else 0.0
            n_within += rel <= 1e-9
            if diff:
                n_changed += 1
                per_row.append(
                    {
                        "table": a["table"],
                        "quantity": a["quantity"],
                        "unit": a["unit"],
                        "field": k,
                        "plain": x,
                        "geodetic": y,
                        "abs_difference": diff,
                        "relative_difference": rel,
                    }
                )
    per_row.sort(key=lambda r: -r["relative_difference"])
    against_main = None
    if baseline is not None and (baseline / "lp-observations.json").is_file():
        base = json.loads((baseline / "lp-observations.json").read_text(encoding="utf-8"))
        if base.get("seed") == d["seed"] and len(base["rows"]) == len(d["plain"]["rows"]):
            against_main = {
                "baseline": str(baseline / "lp-observations.json"),
                **_largest_change(base["rows"], d["plain"]["rows"]),
            }
        else:
            against_main = {"baseline": str(baseline), "comparable": False}
    n_rows = len(d["plain"]["rows"])
    rows_within = n_rows - len(
        {(r["table"], r["quantity"]) for r in per_row if r["relative_difference"] > 1e-9}
    )
    # the file's floor: a float64 latitude/longitude in degrees at the 002 site, in metres
    lat, lon, h = 59.665, 10.775, 130.0
    a_m, f = 6378137.0, 1 / 298.257222101
    e2 = f * (2 - f)
    s2 = math.sin(math.radians(lat)) ** 2
    M = a_m * (1 - e2) / (1 - e2 * s2) ** 1.5  # meridian radius of curvature
    N = a_m / math.sqrt(1 - e2 * s2)
    floor = {
        "latitude_step_deg": float(np.spacing(lat)),
        "latitude_step_m": float(np.spacing(lat)) * math.pi / 180 * M,
        "longitude_step_m": float(np.spacing(lon))
        * math.pi
        / 180
        * N
        * math.cos(math.radians(lat)),
        "height_step_m": float(np.spacing(h)),
        # the file's time: GPS seconds of week (the campaign's clock + 302400 s)
        "gps_seconds_of_week_step_s": float(np.spacing(302400.0 + 1000.0)),
        "what_1e-9_relative_asks_of_the_smallest_changed_metre_row_m": None,
    }
    metre = [r for r in per_row if r["unit"] == "m"]
    if metre:
        smallest = min(metre, key=lambda r: abs(r["plain"]))
        floor["what_1e-9_relative_asks_of_the_smallest_changed_metre_row_m"] = 1e-9 * abs(
            smallest["plain"]
        )
        floor["that_row"] = f"{smallest['table']}: {smallest['quantity']} ({smallest['plain']} m)"
    worst = per_row[0] if per_row else None
    metre_abs = max((r["abs_difference"] for r in metre), default=0.0)
    n_metre = sum(
        1
        for a in d["plain"]["rows"]
        if a["unit"] == "m"
        for k in KEYS
        if a[k] is not None and math.isfinite(a[k])
    )
    beyond = sorted({r["table"] for r in metre if r["abs_difference"] > floor["latitude_step_m"]})
    floor["tables_of_metre_values_beyond_one_latitude_step"] = beyond
    floor["metre_values_changed_by_at_most_one_latitude_step"] = (
        f"{n_metre - sum(r['abs_difference'] > floor['latitude_step_m'] for r in metre)} of "
        f"{n_metre}"
    )
    all_within = not per_row or worst["relative_difference"] <= 1e-9
    return {
        "line": "The 002 chapter's rows unchanged to 1e-9 relative when its flight goes through "
        "the geodetic path.",
        "status": "met" if all_within else "short",
        "evidence": {
            "file": str(path.relative_to(ROOT)) + f" ({d['command']}, {d['date_utc']})",
            "navigation_change": d["navigation_change"],
            "plain_run_against_main_baseline": against_main,
            "n_rows": n_rows,
            "n_values_compared": n_vals,
            "n_values_changed": n_changed,
            "fraction_of_values_within_1e-9_relative": n_within / n_vals if n_vals else None,
            "fraction_of_rows_within_1e-9_relative": rows_within / n_rows,
            "largest_relative_change": worst,
            "largest_absolute_change_of_a_metre_value_m": metre_abs,
            "floating_point_floor": floor,
            "changed_values": per_row,
            "why_short": (
                None
                if all_within
                else "1e-9 relative cannot be met on a row near zero through any file: a "
                "float64 latitude in degrees at 59.7° N steps by "
                f"{floor['latitude_step_m']:.2e} m, while 1e-9 of the smallest changed metre "
                "row asks "
                f"{floor['what_1e-9_relative_asks_of_the_smallest_changed_metre_row_m']:.1e} m "
                "(and a GPS second of week steps by "
                f"{floor['gps_seconds_of_week_step_s']:.1e} s); the metre values moved by at "
                f"most {metre_abs:.2e} m, "
                f"{floor['metre_values_changed_by_at_most_one_latitude_step']} by at most one "
                "latitude step; the others, of the adjusted tables ("
                + "; ".join(beyond)
                + "), move through the adjustments the navigation enters"
            ),
            "tests": {
                **_outcomes(ran, T_002),
                f"{T_002}::test_the_lp_chapter_rows_through_the_geodetic_path": "slow, not run "
                "here (the bench above runs the whole chapter, with the judges and the blur-off "
                "rerun)",
            },
        },
    }


# ----------------------------------------------------------------------------------------------
def _raster():
    import rioxarray  # noqa: F401
    import xarray as xr
    from affine import Affine

    rng = np.random.default_rng(38)
    v = rng.normal(100.0, 10.0, (3, 20, 30)).astype(np.float32)
    da = xr.DataArray(
        v,
        dims=("band", "y", "x"),
        coords={
            "band": ["b1", "b2", "b3"],
            "y": 6_000_000.0 - 5.0 - 10.0 * np.arange(20),
            "x": 500_000.0 + 5.0 + 10.0 * np.arange(30),
            "wavelength_nm": ("band", [460.0, 550.0, 640.0]),
            "fwhm_nm": ("band", [9.0, 10.0, 11.0]),
        },
        name="radiance",
    )
    da = da.rio.write_crs("EPSG:32633")
    return da.rio.write_transform(Affine(10.0, 0.0, 500_000.0, 0.0, -10.0, 6_000_000.0))


def outputs(ran) -> list[dict]:
    import rasterio
    import rioxarray
    import xarray as xr

    from hsgeo.io.raster import envi_data_path, write_raster

    da = _raster()
    rio_ev, gdal_ev = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        paths = {s: Path(tmp) / f"out{s}" for s in (".tif", ".nc", ".hdr")}
        for p in paths.values():
            write_raster(da, p)
        nc = paths[".nc"]
        ds = xr.open_dataset(nc, decode_coords="all")
        v = ds["radiance"]
        w = v.rio.reproject("EPSG:4326")
        r = rioxarray.open_rasterio(nc)
        r = r if not isinstance(r, list) else r[0]
        rio_ev = {
            "xarray_decode_coords_all": {
                "dims": list(v.dims),
                "dtype": str(v.dtype),
                "crs_found": str(v.rio.crs),
                "x_y_found": [v.rio.x_dim, v.rio.y_dim],
                "reprojected_to": str(w.rio.crs),
                "reprojected_shape": list(w.shape),
                "reprojected_finite_share": float(np.isfinite(w.values).mean()),
            },
            "rioxarray_open_rasterio": {
                "crs_found": str(r.rio.crs) if hasattr(r, "rio") else None,
            },
            "conventions": ds.attrs.get("Conventions"),
        }
        ds.close()
        for s, p in paths.items():
            gp = envi_data_path(p) if s == ".hdr" else (f"NETCDF:{p}:radiance" if s == ".nc" else p)
            with rasterio.open(gp) as src:
                bands = []
                for b in range(1, src.count + 1):
                    img, items = src.tags(b, ns="IMAGERY"), src.tags(b)
                    bands.append(
                        {
                            k: v
                            for k, v in {**img, **items}.items()
                            if k
                            in (
                                "CENTRAL_WAVELENGTH_UM",
                                "FWHM_UM",
                                "wavelength",
                                "wavelength_units",
                                "fwhm",
                                "NETCDF_DIM_band",
                            )
                        }
                    )
                ds_tags = {k: v for k, v in src.tags().items() if k.startswith("band#")}
                gdal_ev[s] = {
                    "driver": src.driver,
                    "gdal": rasterio.__gdal_version__,
                    "band_keys": bands,
                    "dataset_band_keys": ds_tags,
                }
    want_um = [0.46, 0.55, 0.64]
    ok_rio = (
        rio_ev["xarray_decode_coords_all"]["crs_found"] == "EPSG:32633"
        and rio_ev["xarray_decode_coords_all"]["reprojected_to"] == "EPSG:4326"
        and rio_ev["xarray_decode_coords_all"]["reprojected_finite_share"] > 0.5
    )
    ok_rio = ok_rio and _passed(ran, [f"{T_CLI}::test_the_netcdf"])

    def imagery(s):
        return [float(b.get("CENTRAL_WAVELENGTH_UM", "nan")) for b in gdal_ev[s]["band_keys"]]

    nc_um = [float(b.get("NETCDF_DIM_band", "nan")) / 1e3 for b in gdal_ev[".nc"]["band_keys"]]
    nc_units = gdal_ev[".nc"]["dataset_band_keys"].get("band#units")
    ok_gdal = np.allclose(imagery(".tif"), want_um) and np.allclose(imagery(".hdr"), want_um)
    ok_gdal = ok_gdal and np.allclose(nc_um, want_um) and nc_units == "nm"
    ok_gdal = ok_gdal and _passed(ran, [f"{T_CLI}::test_gdal_reads", "tests/test_raster_formats"])
    return [
        {
            "line": "rioxarray opens the NetCDF and reprojects it without help.",
            "status": "met" if ok_rio else "short",
            "evidence": {
                "measured": rio_ev,
                "tests": _outcomes(ran, f"{T_CLI}::test_the_netcdf"),
                "files": "src/hsgeo/io/raster.py (the one writer by suffix)",
            },
        },
        {
            "line": "GDAL reports the wavelengths of the COG, the NetCDF and the ENVI output in "
            "its standard keys.",
            "status": "met" if ok_gdal else "short",
            "evidence": {
                "measured": gdal_ev,
                "cog_and_envi_imagery_central_wavelength_um": {
                    ".tif": imagery(".tif"),
                    ".hdr": imagery(".hdr"),
                },
                "netcdf": "GDAL's netCDF driver has no IMAGERY domain: it reports a band's "
                "coordinate as NETCDF_DIM_band with band#units and band#standard_name "
                f"(here {nc_units!r}, "
                f"{gdal_ev['.nc']['dataset_band_keys'].get('band#standard_name')!r}), which is "
                "what is checked for the NetCDF",
                "tests": {
                    **_outcomes(ran, f"{T_CLI}::test_gdal_reads"),
                    **_outcomes(ran, "tests/test_raster_formats.py"),
                },
                "files": "src/hsgeo/io/raster.py, src/hsgeo/io/geotiff.py, src/hsgeo/io/envi.py",
            },
        },
    ]


# ----------------------------------------------------------------------------------------------
#: Every new format's bad input: (format, what is broken, the test that checks it).
BAD = [
    ("SBET", "truncated", f"{T_BADG}::test_truncated_sbet"),
    ("SBET", "truncated, through orthorectify (exit 2)",
     f"{T_CLI_GEO}::test_bad_new_formats_one_line_exit_2[truncated-sbet]"),
    ("SBET", "truncated, through adjust-pushbroom (exit 2)",
     "tests/test_geodetic_line_commands.py::test_bad_navigation_one_line_exit_2[sbet-truncated]"),
    ("SBET", "in degrees or big-endian", f"{T_BADG}::test_sbet_in_degrees_or_big_endian"),
    ("SBET", "no datum named", f"{T_BADG}::test_sbet_needs_its_datum_named"),
    ("SBET", "no datum named (exit 2)",
     "tests/test_geodetic_line_commands.py::test_bad_navigation_one_line_exit_2[sbet-no-crs]"),
    ("geodetic CSV", "a row cut short (exit 2)",
     f"{T_CLI_GEO}::test_bad_new_formats_one_line_exit_2[geodetic-csv-short-row]"),
    ("geodetic CSV", "unknown EPSG, a projected CRS",
     f"{T_BADG}::test_unknown_epsg_and_a_projected_crs"),
    ("geodetic CSV", "heading in radians under heading_deg",
     f"{T_BADG}::test_heading_in_radians_under_deg"),
    ("geodetic CSV", "no time scale, a latitude out of range",
     f"{T_BADG}::test_no_time_scale_or_a_latitude_out_of_range"),
    ("geodetic CSV", "times going back", f"{T_BADG}::test_times_that_go_back"),
    ("geodetic CSV", "a datum without a 3D EPSG code",
     f"{T_BADG}::test_a_datum_without_a_3d_epsg_code_names_the_realisations"),
    ("DSM GeoTIFF", "a void under a ray", f"{T_TER}::test_a_void_under_a_ray_is_refused_by_place"),
    ("DSM GeoTIFF", "a void under the line (exit 2)",
     f"{T_CLI_GEO}::test_bad_new_formats_one_line_exit_2[dsm-void-under-the-line]"),
    ("DSM GeoTIFF", "unknown vertical datum",
     f"{T_TER}::test_an_unknown_vertical_datum_is_refused_with_the_choice"),
    ("DSM GeoTIFF", "a geoid grid missing",
     f"{T_TER}::test_a_vertical_datum_whose_geoid_grid_is_missing_is_refused"),
    ("DSM GeoTIFF", "a grid too large",
     f"{T_BADG}::test_a_terrain_grid_too_large_names_the_spacing"),
    ("ENVI lines", "a times file shorter than the lines",
     f"{T_BAD}::test_bad_input[orthorectify-envi:mismatch:times-shorter-than-lines]"),
    ("ENVI lines", "a times file shorter than the lines (lp-observations)",
     f"{LPE_BAD}[times-shorter-than-lines]"),
    ("ENVI lines", "times files unlike the cubes (lp-observations)",
     f"{LPE_BAD}[times-count-unlike-cubes]"),
    ("ENVI lines", "times for NetCDF lines (lp-observations)",
     f"{LPE_BAD}[times-for-netcdf-lines]"),
    ("ENVI lines", "a cube without wavelengths (lp-observations)",
     f"{LPE_BAD}[cube-without-wavelengths]"),
    ("ENVI lines", "a cube cut short (lp-observations)",
     f"{LPE_BAD}[cube-cut-short]"),
    ("ENVI lines", "x start not a column (lp-observations)", f"{LPE_BAD}[x-start-not-a-column]"),
    ("ENVI lines", "every orthorectify-envi case of the bad-input suite",
     f"{T_BAD}::test_bad_input[orthorectify-envi:*]"),
    ("ENVI lines", "NetCDF/ENVI mix, times count, times for NetCDF",
     f"{T_ENVI}::test_envi_lines_refused_by_name"),
    ("view-angle table", "the wrong pixel count",
     f"{T_ENVI}::test_a_view_angle_table_with_the_wrong_pixel_count_is_refused"),
    ("view-angle table", "the wrong pixel count (library)",
     "tests/test_view_angle.py::test_pixel_count_must_match_the_lines"),
    ("view-angle table", "one pixel short, radians, a row or pixel twice, not monotone",
     f"{T_BAD}::test_bad_input[orthorectify-envi:*:angles-*]"),
    ("view-angle table", "bad tables (library)", "tests/test_view_angle.py::test_bad_tables"),
]  # fmt: skip


def bad_input(ran) -> dict:
    listed = []
    for fmt, what, node in BAD:
        if ran is None:
            outcome = "not run"
        elif node.endswith("*]"):
            head = node[: node.index("[") + 1]
            parts = node[node.index("[") + 1 : -1].split("*")
            sel = [
                r["outcome"]
                for n, r in ran.items()
                if n.startswith(head) and all(p.strip(":") in n for p in parts if p.strip(":"))
            ]
            outcome = f"{sum(o == 'passed' for o in sel)} of {len(sel)} passed" if sel else "none"
        else:
            hits = [r["outcome"] for n, r in ran.items() if n == node or n.startswith(node + "[")]
            outcome = (
                "passed"
                if hits and all(o == "passed" for o in hits)
                else (",".join(hits) or "not collected")
            )
        listed.append({"format": fmt, "case": what, "test": node, "outcome": outcome})
    ok = ran is not None and all(
        e["outcome"] == "passed" or re.fullmatch(r"([1-9]\d*) of \1 passed", e["outcome"])
        for e in listed
    )
    return {
        "line": "the bad-input suite covers every new format (a truncated SBET, a times file "
        "shorter than the lines, a view-angle table with the wrong pixel count …).",
        "status": "met" if ok else "short",
        "evidence": {"cases": listed, "formats": sorted({f for f, _, _ in BAD})},
    }


# ----------------------------------------------------------------------------------------------
def lp_envi(ran) -> dict:
    ok = _passed(ran, [T_LPE])
    printed = ""
    if ran:
        printed = next((r["printed"] for n, r in ran.items() if "test_envi_cubes_give" in n), "")
    return {
        "line": "(what to build) ENVI cubes … for orthorectify and lp-observations",
        "status": "met" if ok and _passed(ran, [T_ENVI]) else "short",
        "evidence": {
            "lp_observations": "hsgeo lp-observations SCENES… --line-times TIMES… (ENVI BIL/"
            "BIP/BSQ, either byte order, header offset, name.hdr / name.raw.hdr, times file "
            "or header start time + line period): the very observation table of the same "
            "strips as NetCDF",
            "printed": printed,
            "tests": {**_outcomes(ran, T_LPE), **_outcomes(ran, T_ENVI)},
            "slow_test_not_run_here": f"{T_LPE}::test_envi_cubes_give_the_netcdf_observation_"
            "table (20 strips of the scale-0.05 campaign as ENVI cubes in BIL/BIP/BSQ → the "
            "NetCDF lines' observation table, pandas assert_frame_equal exact)",
            "files": "src/hsgeo/io/line_cube.py (read_line_strips), src/hsgeo/workflows/"
            "lp_observations.py (lp_observation_files), src/hsgeo/cli_parsers.py",
        },
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-pytest", action="store_true", help="numbers only, no test run")
    ap.add_argument(
        "--pytest-out", type=Path, help="run the tests only, their outcomes into this file"
    )
    ap.add_argument("--pytest-in", type=Path, help="the tests' outcomes from --pytest-out")
    ap.add_argument(
        "--numbers", type=Path, help="keep the measured numbers in this file (read when it exists)"
    )
    ap.add_argument(
        "--baseline", type=Path, help="main's reproduce JSONs (seed of the bench) for the plain run"
    )
    ap.add_argument("--out", type=Path, default=RESULTS / "issue38_audit.json")
    args = ap.parse_args()
    if args.numbers and args.numbers.is_file():
        CACHE.update(json.loads(args.numbers.read_text(encoding="utf-8")))
    ran, when = None, None
    if args.pytest_in:
        saved = json.loads(args.pytest_in.read_text(encoding="utf-8"))
        ran, when = saved["outcomes"], saved["date_utc"]
    elif not args.no_pytest:
        when = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        ran = run_pytest(NODES)
        ran.update(run_pytest([T_BAD], k=BAD_INPUT_K))
        if args.pytest_out:
            args.pytest_out.write_text(
                json.dumps({"date_utc": when, "outcomes": ran}, indent=1) + "\n", encoding="utf-8"
            )
            print(f"{len(ran)} tests -> {args.pytest_out}")
            return
    entries = [
        *sites(ran),
        dsm_variants(ran),
        sbet(ran),
        chapter_rows(ran, args.baseline),
        *outputs(ran),
        bad_input(ran),
        lp_envi(ran),
    ]
    if args.numbers:
        args.numbers.write_text(json.dumps(CACHE, indent=1) + "\n", encoding="utf-8")
    out = {
        "what": "issue 38's done-means lines measured on branch geo38 (main 063ff2f + mends)",
        "command": "python bench/issue38_audit.py"
        + (" --no-pytest" if args.no_pytest else "")
        + (f" --pytest-in {args.pytest_in}" if args.pytest_in else ""),
        "tests_run_at_utc": when,
        "summary": {s: sum(e["status"] == s for e in entries) for s in ("met", "short")},
        "tests_run": None
        if ran is None
        else {
            "n": len(ran),
            "by_outcome": {
                o: sum(r["outcome"] == o for r in ran.values())
                for o in sorted({r["outcome"] for r in ran.values()})
            },
            "not_passed": [n for n, r in ran.items() if r["outcome"] not in ("passed", "skipped")],
        },
        "entries": entries,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    args.out.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps(out["summary"]), out["tests_run"] and out["tests_run"]["by_outcome"])
    for e in entries:
        print(e["status"], "|", e["line"][:90])


if __name__ == "__main__":
    main()
