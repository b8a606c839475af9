"""Every bad input gets one clear error, and nothing is ever lost (issue 12).

The valid inputs of ``tests/test_cli*.py`` (a line-scanner calibration, a pushbroom campaign,
a flight line to orthorectify, OpenCV's ChArUco photographs, two LP strips to mosaic) are built
once; each case copies the command's inputs, spoils one thing (a table of mutations: missing,
empty, garbage, binary and mistyped files; NaN, inf, 1e300; wrong units and types; degenerate
geometry; duplicates; bad options; output paths) and runs ``hsgeo.cli.main`` in-process.
Each case must end with exit status 2, exactly one line on stderr (no traceback) naming the
file / column / option / id in question (a per-case substring), and nothing on stdout. Benign
variants (reordered and extra columns, CRLF, a UTF-8 BOM, 16-bit images, Parquet) must still
work. The SHA-256 of every input file is the same before and after every command, failing or
succeeding.

``python tests/test_bad_input.py`` prints the count of cases by command and class.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import shutil
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from priors import priors_toml

ROOT = Path(__file__).resolve().parents[1]
CHARUCO = ROOT / "src/hsgeo/data/reference/opencv-charuco"

# ---------------------------------------------------------------------------------------------
# the valid inputs (as tests/test_cli*.py build them)


def _line(d: Path) -> None:
    from hsgeo.reproduce.line_calibration import generate
    from hsgeo.simulate.line_lab import LineLabScenario
    from hsgeo.simulate.scenarios import ScenarioInfo

    d.mkdir()
    generate(LineLabScenario(ScenarioInfo("line_lab", 4)), d)
    (d / "line_lab_observations.csv").rename(d / "obs.csv")
    (d / "line_lab_control.csv").rename(d / "control.csv")
    (d / "line_lab_truth.csv").unlink()


def _pushbroom(d: Path) -> None:
    import pandas as pd

    from hsgeo.io.navigation import write_trajectory
    from hsgeo.simulate.pushbroom_campaign import simulate
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
    from hsgeo.trajectory import Trajectory, rph_from_platform_rpy

    d.mkdir()
    obs, _ = simulate(0.001, rng=4)
    o = obs.lines
    pd.DataFrame(
        {
            "point_id": o.point + 1000,
            "band": o.band,
            "t_s": o.t_s,
            "x_px": o.xy_px[:, 0],
            "y_px": o.xy_px[:, 1],
        }
    ).to_csv(d / "obs.csv", index=False, float_format="%.17g")
    t, i = np.unique(o.t_s, return_index=True)
    write_trajectory(
        d / "nav.csv", Trajectory(t, o.xyz_nav_m[i], rph_from_platform_rpy(o.rpy_nav_rad[i]))
    )
    g = obs.gcp_xyz_m
    pd.DataFrame(
        {"point_id": obs.gcp_index + 1000, "E_m": g[:, 0], "N_m": g[:, 1], "H_m": g[:, 2]}
    ).to_csv(d / "gcp.csv", index=False, float_format="%.17g")
    la = ", ".join(f"{v:.6f}" for v in obs.lever_arm_m)
    (d / "cam.toml").write_text(
        f"[camera]\nn_bands = 7\npixel_mm = 0.0065\nc_mm = 40.0\nx0_mm = {CampaignConfig().x0_mm}\n"
        f"lever_arm_m = [{la}]\n" + priors_toml()
    )


def _geocode(d: Path) -> None:
    import xarray as xr

    from hsgeo.geocode import PlaneTerrain
    from hsgeo.io import write_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.ortho import ground_points
    from hsgeo.sensors import as_sensor
    from hsgeo.sensors.line import CalibratedLine
    from hsgeo.trajectory import Trajectory

    d.mkdir()
    t = np.linspace(0, 10.0, 201)
    EN = np.outer(20.0 * t, [0.0, 1.0])
    rpy = np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.zeros(t.size)])
    nav = Trajectory(t, np.column_stack([EN, np.full(t.size, 500.0)]), rpy)
    write_trajectory(d / "nav.csv", nav)
    cal = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1
    zeta = np.arange(200.0, 800.0, 4.0)
    g = ground_points(as_sensor(cal), nav, 0.5 + np.arange(40) / 8.0, zeta, PlaneTerrain(3.0))
    write_lines(d / "lines.nc", g[..., 0], zeta, t0_s=0.5, line_rate_hz=8.0)
    (d / "sensor.toml").write_text(
        "[sensor]\nmodel = 'calibrated'\nzeta0_px = 486.8\nc_px = 3539.0\n"
        "K = [1.459, -0.1636, 0.00526]\nboresight_deg = [0.0, 0.0, 0.0]\n"
    )
    E = np.arange(-300.0, 301.0, 10.0)
    N = np.arange(-300.0, 501.0, 10.0)
    xr.Dataset(
        {"height": (("N", "E"), np.full((N.size, E.size), 3.0))}, {"N": N, "E": E}
    ).to_netcdf(d / "dem.nc", engine="scipy")


def _lp(d: Path) -> None:
    """Four strips of the rendered LP campaign (scale 0.1) as LP line files, the navigation,
    the a-priori camera and the reference squares."""
    import pandas as pd

    from hsgeo.io.lp_lines import write_lp_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.simulate.lp_campaign import simulate
    from hsgeo.trajectory import Trajectory

    d.mkdir()
    obs, _ = simulate(scale=0.1, rng=2)
    strips = [obs.strips[k] for k in (0, 2, 4, 12)]
    for i, s in enumerate(strips):
        write_lp_lines(d / f"s{i}.nc", s)
    # the navigation of the four strips' flight lines only (their records from 10 s before the
    # strip to 10 s after it) and of the line flown before the first strip (60 s before it, the
    # turn between them: east in mm then jumps faster than a platform flies): the whole
    # flight's 68,784 records made every case of the command read, hash and copy 9.7 MB (0.8 s
    # a case, 161 cases; issue 41)
    nav = obs.navigation
    t = nav.t_s
    keep = np.zeros(t.size, dtype=bool)
    for k, s in enumerate(strips):
        keep |= (t >= s.t_s[0] - (80.0 if k == 0 else 10.0)) & (t <= s.t_s[-1] + 10.0)
    write_trajectory(
        d / "nav.csv", Trajectory(t[keep], nav.xyz_m[keep], nav.roll_pitch_heading_rad[keep])
    )
    cam = obs.camera
    la = ", ".join(f"{v:.6f}" for v in cam.lever_arm_m)
    (d / "cam.toml").write_text(
        f"[camera]\nn_bands = {len(cam.c_mm)}\npixel_mm = {cam.pixel_mm}\nc_mm = {cam.c_mm[0]}\n"
        f"x0_mm = {cam.x0_mm}\nlever_arm_m = [{la}]\n" + priors_toml()
    )
    xyz = obs.square_xyz_m
    pd.DataFrame(
        {"point_id": list(obs.square_ids), "E_m": xyz[:, 0], "N_m": xyz[:, 1], "H_m": xyz[:, 2]}
    ).to_csv(d / "squares.csv", index=False, float_format="%.17g")


def _envi_lines(d: Path) -> None:
    """One line of a view-angle line scanner as it writes it (issue 38): an ENVI BIL cube
    (cube.raw + cube.hdr, 2 bands, wavelengths in the header), its times file (one time per
    line), the view-angle sensor file (va.toml + angles.csv) and the navigation."""
    from hsgeo.geocode import PlaneTerrain
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.ortho import ground_points
    from hsgeo.sensors.view_angle import ViewAngleScanner
    from hsgeo.trajectory import Trajectory

    d.mkdir()
    t = np.linspace(0, 10.0, 201)
    EN = np.outer(20.0 * t, [0.0, 1.0])
    rpy = np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.zeros(t.size)])
    nav = Trajectory(t, np.column_stack([EN, np.full(t.size, 500.0)]), rpy)
    write_trajectory(d / "nav.csv", nav)
    across = np.linspace(-0.2, 0.2, 150)
    along = 0.01 * across**2
    rows = ["pixel,across_deg,along_deg"]
    rows += [
        f"{i},{float(np.rad2deg(a))!r},{float(np.rad2deg(b))!r}"
        for i, (a, b) in enumerate(zip(across, along, strict=True))
    ]
    (d / "angles.csv").write_text("\n".join(rows) + "\n")
    (d / "va.toml").write_text("[sensor]\nmodel = 'view-angle'\nangles_csv = 'angles.csv'\n")
    t_l = 0.5 + np.arange(40) / 8.0
    g = ground_points(
        ViewAngleScanner(across, along), nav, t_l, np.arange(150.0), PlaneTerrain(3.0)
    )
    np.ascontiguousarray(g[..., :2].astype("<f4").transpose(0, 2, 1)).tofile(d / "cube.raw")
    (d / "cube.hdr").write_text(
        "ENVI\nsamples = 150\nlines = 40\nbands = 2\nheader offset = 0\ndata type = 4\n"
        "interleave = bil\nbyte order = 0\nwavelength units = Nanometers\n"
        "wavelength = {500.0, 600.0}\nfwhm = {5.0, 5.0}\n"
    )
    (d / "times.txt").write_text("".join(f"{float(v)!r}\n" for v in t_l))


def _frames(d: Path) -> None:
    """Two frames of the Rikola (2 bands, 40 x 30 px, ENVI BSQ f0.raw, f1.raw), their exposure
    table (one row per frame and band), the Rikola's sensor file (turned over to look down),
    an OpenCV frame camera's sensor file and the navigation, 500 m above a plane at 3 m."""
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.trajectory import Trajectory

    d.mkdir()
    t = np.linspace(0, 10.0, 201)
    nav = Trajectory(
        t,
        np.column_stack([np.zeros(t.size), 20.0 * t, np.full(t.size, 500.0)]),
        np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.zeros(t.size)]),
    )
    write_trajectory(d / "nav.csv", nav)
    rng = np.random.default_rng(3)
    for i in range(2):
        rng.random((2, 30, 40)).astype("<f4").tofile(d / f"f{i}.raw")
        (d / f"f{i}.hdr").write_text(
            "ENVI\nsamples = 40\nlines = 30\nbands = 2\nheader offset = 0\ndata type = 4\n"
            "interleave = bsq\nbyte order = 0\n"
        )
    (d / "frames.csv").write_text(
        "file,time_s,band\nf0.raw,4.0,1\nf0.raw,4.05,2\nf1.raw,5.0,1\nf1.raw,5.05,2\n"
    )
    (d / "rikola.toml").write_text(
        "[sensor]\nmodel = 'rikola'\nf_band_mm = [8.7, 8.8]\nband_sensor = [1, 2]\n"
        "bands = [1, 2]\npp_I_mm = [0.0, 0.0]\npp_II_mm = [0.0, 0.0]\n"
        "image_size_px = [40, 30]\nboresight_deg = [180.0, 0.0, 0.0]\n"
    )
    (d / "cv.toml").write_text(
        "[sensor]\nmodel = 'frame-opencv'\nfx_px = 400.0\nfy_px = 400.0\ncx_px = 19.5\n"
        "cy_px = 14.5\nimage_size_px = [40, 30]\n"
    )


def _frame(d: Path) -> None:
    d.mkdir()
    for p in sorted((CHARUCO / "images").glob("*.jpg"))[:3]:
        shutil.copy(p, d / p.name)
    shutil.copy(CHARUCO / "board.toml", d / "board.toml")


def _bal(d: Path) -> None:
    """A small BAL problem: the shipped Ladybug file's first 40 observations, renumbered."""
    from hsgeo.io.bal import ladybug_path, read_bal

    d.mkdir()
    prob = read_bal(ladybug_path())
    keep = np.flatnonzero(prob.camera_index < 2)[:40]
    cams, pts = np.unique(prob.camera_index[keep]), np.unique(prob.point_index[keep])
    ci = np.searchsorted(cams, prob.camera_index[keep])
    pi = np.searchsorted(pts, prob.point_index[keep])
    lines = [f"{len(cams)} {len(pts)} {len(keep)}"]
    lines += [
        f"{c} {p} {float(x)!r} {float(y)!r}"
        for c, p, (x, y) in zip(ci, pi, prob.xy_px[keep], strict=True)
    ]
    lines += [repr(float(v)) for v in prob.cameras[cams].ravel()]
    lines += [repr(float(v)) for v in prob.points[pts].ravel()]
    (d / "problem.txt").write_text("\n".join(lines) + "\n")


def _mtf(d: Path) -> None:
    from mtf_inputs import write_bar_inputs

    d.mkdir()
    write_bar_inputs(d)


def _mtf_edge(d: Path) -> None:
    from mtf_inputs import write_edge_image

    d.mkdir()
    write_edge_image(d / "edge.png")


def _cube(d: Path) -> None:
    """A short simulated ImSpector run (binning 2): raw/ and dark/ frame folders (.npy)."""
    from hsgeo.io.frames import write_frame_folder
    from hsgeo.simulate import cube_survey as CS

    cfg = CS.CubeSurvey(length_m=0.02)
    frames, (dark, t), _ = CS.simulate(cfg, 4)
    raw = frames.read(0, frames.n_frames)
    write_frame_folder(
        d / "raw",
        raw,
        frames.exposure_s,
        wavelength_nm=cfg.row_wavelength_nm(),
        fwhm_nm=cfg.row_fwhm_nm(),
    )
    write_frame_folder(d / "dark", dark, t)


def _asf(d: Path) -> None:
    from asf_inputs import write_asf_inputs

    d.mkdir()
    write_asf_inputs(d)


def _ortho(d: Path) -> None:
    """Two LP strips over the Ås hill (tests/ortho_inputs.py), their navigation lacking known
    node corrections, the adjust-pushbroom result that carries them, the camera and the DSM."""
    from ortho_inputs import write_ortho_inputs

    d.mkdir()
    write_ortho_inputs(d, adjusted=True)


#: each command's valid inputs: its folder under ``valid`` and the function that writes it
VALID_BUILDERS: dict[str, Callable[[Path], None]] = {
    "asf": _asf,
    "mtf": _mtf,
    "mtf-edge": _mtf_edge,
    "adjust-bal": _bal,
    "cube": _cube,
    "calibrate-line": _line,
    "adjust-pushbroom": _pushbroom,
    "orthorectify-line": _geocode,
    "calibrate-frame": _frame,
    "lp-observations": _lp,
    "orthorectify-strips": _ortho,
    "orthorectify-envi": _envi_lines,
    "orthorectify-frames": _frames,
}


def build_valid(root: Path) -> Path:
    """Write the valid inputs of every command under ``root`` (one folder per command)."""
    for cmd in VALID_BUILDERS:
        valid_inputs(root, cmd)
    return root


def valid_inputs(root: Path, cmd: str) -> Path | None:
    """``root / cmd``, the valid inputs of ``cmd``, written by the first process that asks.

    The folder of :func:`valid` is shared by the pytest-xdist workers and by the three files
    that use it (tests/test_bad_input*.py): each command's inputs are written once per session
    (≈ 30 CPU-s for all thirteen; before issue 41 once per file that used them), a lock file per
    command making a second process wait for the first one's folder. The cases only copy it.
    ``None`` for a command without inputs of its own (``hsgeo data``, ``reproduce``).
    """
    import fcntl

    if cmd not in VALID_BUILDERS:
        return None
    d = root / cmd
    root.mkdir(parents=True, exist_ok=True)
    with open(root / f"{cmd}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # a second process waits here for the first's folder
        if not d.is_dir():  # written beside, renamed when complete: never seen half-written
            stage = root / f".{cmd}.{os.getpid()}"
            shutil.rmtree(stage, ignore_errors=True)
            stage.mkdir()
            VALID_BUILDERS[cmd](stage / cmd)
            (stage / cmd).rename(d)
            stage.rmdir()
    return d


def base_argv(cmd: str, d: Path) -> list[str]:
    """The command line that succeeds on the valid inputs in ``d``."""
    s = str
    if cmd == "calibrate-line":
        return [cmd, s(d / "obs.csv"), "--control", s(d / "control.csv")]
    if cmd == "adjust-pushbroom":
        return [
            cmd,
            s(d / "obs.csv"),
            "--trajectory",
            s(d / "nav.csv"),
            "--camera",
            s(d / "cam.toml"),
            "--gcp",
            s(d / "gcp.csv"),
        ]
    if cmd == "orthorectify-line":  # one recorded line of the 000 line scanner
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [
            "orthorectify",
            s(d / "lines.nc"),
            "--trajectory",
            s(d / "nav.csv"),
            "--site",  # the 002 site on ETRS89: the frame of the simulated navigation
            "59.665,10.775,0",
            "--nav-crs",
            "EPSG:4937",
            "--sensor",
            s(d / "sensor.toml"),
            "--height",
            "3",
            "--resolution",
            "0.5",
            "-o",
            s(out / "ortho.nc"),
            "--quiet",
        ]
    if cmd == "orthorectify-envi":  # an ENVI cube of a view-angle line scanner (issue 38)
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [
            "orthorectify",
            s(d / "cube.raw"),
            "--line-times",
            s(d / "times.txt"),
            "--trajectory",
            s(d / "nav.csv"),
            "--sensor",
            s(d / "va.toml"),
            "--height",
            "3",
            "--site",
            "59.665,10.775",
            "--resolution",
            "0.5",
            "-o",
            s(out / "ortho.nc"),
            "--quiet",
        ]
    if cmd == "orthorectify-frames":  # two frames of the Rikola (issue 36)
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [
            "orthorectify",
            s(d / "f0.raw"),
            s(d / "f1.raw"),
            "--frame-times",
            s(d / "frames.csv"),
            "--trajectory",
            s(d / "nav.csv"),
            "--sensor",
            s(d / "rikola.toml"),
            "--height",
            "3",
            "--site",
            "59.665,10.775",
            "-o",
            s(out / "ortho.nc"),
            "--quiet",
        ]
    if cmd == "calibrate-frame":
        return [cmd, *(s(d / f"img_0{i}.jpg") for i in range(3)), "--board", s(d / "board.toml")]
    if cmd == "lp-observations":
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [
            cmd,
            *(s(d / f"s{i}.nc") for i in range(4)),
            "--trajectory",
            s(d / "nav.csv"),
            "--camera",
            s(d / "cam.toml"),
            "--squares",
            s(d / "squares.csv"),
            "-o",
            s(out / "obs.parquet"),
        ]
    if cmd == "orthorectify-strips":  # two LP strips of the 002 camera, adjusted
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [
            "orthorectify",
            s(d / "s1.nc"),
            s(d / "s2.nc"),
            "--trajectory",
            s(d / "nav.csv"),
            "--site",
            "59.665,10.775,0",
            "--nav-crs",
            "EPSG:4937",
            "--sensor",
            s(d / "camera.toml"),
            "--adjustment",
            s(d / "result.json"),
            "--dsm",
            s(d / "dsm.tif"),
            "--resolution",
            "1",  # a 244 x 166 mosaic: about 1 s
            "-o",
            s(out / "mosaic.tif"),
            "--quiet",
        ]
    if cmd == "adjust-bal":
        return [cmd, s(d / "problem.txt"), "--json"]
    if cmd == "mtf":
        return [cmd, s(d / "profiles.csv"), "--bars", s(d / "bars.toml")]
    if cmd == "mtf-edge":
        return [cmd, s(d / "edge.png"), "--json"]
    if cmd == "cube":
        out = d.parent / "out"
        out.mkdir(exist_ok=True)
        return [cmd, s(d / "raw"), "--dark", s(d / "dark"), "-o", s(out / "cube.nc"), "--quiet"]
    if cmd == "asf":
        return [cmd, s(d / "cross.nc"), s(d / "along.nc"), "--runway", s(d / "runway.csv")]
    if cmd == "reproduce":
        return [cmd, "frame-reference"]
    if cmd == "data":
        return [cmd]
    return [cmd]


# ---------------------------------------------------------------------------------------------
# mutations of files


def read_csv(p: Path) -> tuple[list[str], list[list[str]]]:
    rows = list(csv.reader(io.StringIO(p.read_text())))
    return rows[0], rows[1:]


def write_csv(p: Path, header, rows) -> None:
    p.write_text("\n".join(",".join(r) for r in [header, *rows]) + "\n")


def set_cell(column: str, value: str, row: int = 3):
    def edit(p: Path):
        h, rows = read_csv(p)
        rows[row][h.index(column)] = value
        write_csv(p, h, rows)

    return edit


def scale_column(column: str, factor: float):
    def edit(p: Path):
        h, rows = read_csv(p)
        j = h.index(column)
        for r in rows:
            r[j] = repr(float(r[j]) * factor)
        write_csv(p, h, rows)

    return edit


def drop_column(column: str):
    def edit(p: Path):
        h, rows = read_csv(p)
        j = h.index(column)
        write_csv(p, h[:j] + h[j + 1 :], [r[:j] + r[j + 1 :] for r in rows])

    return edit


def rename_column(column: str, new: str):
    def edit(p: Path):
        h, rows = read_csv(p)
        h[h.index(column)] = new
        write_csv(p, h, rows)

    return edit


def duplicate_row(row: int = 2):
    def edit(p: Path):
        h, rows = read_csv(p)
        write_csv(p, h, rows[: row + 1] + [rows[row]] + rows[row + 1 :])

    return edit


def keep_rows(n: int):
    def edit(p: Path):
        h, rows = read_csv(p)
        write_csv(p, h, rows[:n])

    return edit


def swap_rows(a: int, b: int):
    def edit(p: Path):
        h, rows = read_csv(p)
        rows[a], rows[b] = rows[b], rows[a]
        write_csv(p, h, rows)

    return edit


def delete_rows(a: int, b: int):
    def edit(p: Path):
        h, rows = read_csv(p)
        write_csv(p, h, rows[:a] + rows[b:])

    return edit


def text_append(extra: str):
    def f(p: Path):
        p.write_text(p.read_text() + extra + "\n")

    return f


def drop_last_lines(n: int):
    def f(p: Path):
        p.write_text("\n".join(p.read_text().splitlines()[:-n]) + "\n")

    return f


def text(content: str | bytes):
    def edit(p: Path):
        if isinstance(content, bytes):
            p.write_bytes(content)
        else:
            p.write_text(content)

    return edit


def chain_edits(*edits):
    def edit(p: Path):
        for e in edits:
            e(p)

    return edit


def remove(p: Path):
    p.unlink()


def make_dir(p: Path):
    p.unlink()
    p.mkdir()


def header_only(p: Path):
    p.write_text(p.read_text().splitlines()[0] + "\n")


def copy_from(other: str):
    def edit(p: Path):
        shutil.copy(p.parent / other, p)

    return edit


def toml_set(table: str, key: str, value: str | None):
    """Set (or with ``None`` delete) ``key`` of ``[table]`` in a TOML file, as raw TOML text."""

    def edit(p: Path):
        out, cur, done = [], None, False
        for ln in p.read_text().splitlines():
            s = ln.strip()
            if s.startswith("["):
                if cur == table and not done and value is not None:
                    out.append(f"{key} = {value}")
                    done = True
                cur = s.strip("[]")
            elif cur == table and s.split("=")[0].strip() == key:
                if value is not None:
                    out.append(f"{key} = {value}")
                done = True
                continue
            out.append(ln)
        if not done and value is not None:
            if cur != table:
                out.append(f"[{table}]")
            out.append(f"{key} = {value}")
        p.write_text("\n".join(out) + "\n")

    return edit


def toml_append(extra: str):
    def edit(p: Path):
        p.write_text(p.read_text() + extra)

    return edit


def toml_rename(old: str, new: str):
    def edit(p: Path):
        p.write_text(
            "\n".join(
                new + ln.strip()[len(old) :] if ln.strip().startswith(old + " ") else ln
                for ln in p.read_text().splitlines()
            )
            + "\n"
        )

    return edit


def nc_edit(fn):
    """Rewrite a NetCDF file through ``fn(Dataset) -> Dataset``."""

    def edit(p: Path):
        import xarray as xr

        with xr.open_dataset(p, engine="scipy") as ds:
            new = fn(ds.load())
        p.unlink()
        new.to_netcdf(p, engine="scipy")

    return edit


# ---------------------------------------------------------------------------------------------
# the cases


@dataclass(frozen=True)
class Case:
    """One bad input: the command, its class, a name, what to do to the valid inputs, the
    substring the error must contain."""

    cmd: str
    kind: str
    name: str
    files: tuple  # ((file name, edit), ...)
    argv: Callable | None  # (argv, d) -> argv
    expect: str

    @property
    def id(self) -> str:
        return f"{self.cmd}:{self.kind}:{self.name}"


CASES: list[Case] = []


def case(cmd, kind, name, expect, files=(), argv=None):
    CASES.append(Case(cmd, kind, name, tuple(files), argv, expect))


def opt(option: str, value: str | None = None):
    """Replace the value of ``option`` (or append it) in the argv."""

    def f(a, d):
        a = list(a)
        if option in a:
            i = a.index(option)
            if value is None:
                del a[i : i + 2]
            else:
                a[i + 1] = value
        elif value is not None:
            a += [option, value]
        else:
            a.append(option)
        return a

    return f


def flag(*extra):
    return lambda a, d: list(a) + list(extra)


def chain(*fs):
    def f(a, d):
        for g in fs:
            a = g(a, d)
        return a

    return f


def replace_arg(old: str, new):
    """Replace the argument ending in ``old`` by ``new(d)`` (a path in the inputs' folder)."""

    def f(a, d):
        return [str(new(d)) if x.endswith(old) else x for x in a]

    return f


BAD_VALUES = [
    ("nan", "nan", "nonfinite"),
    ("inf", "inf", "nonfinite"),
    ("-inf", "-inf", "nonfinite"),
    ("1e300", "1e300", "range"),
    ("text", "abc", "type"),
    ("empty", "", "missing"),
]

BINARY = bytes(range(256)) * 8


def table_file_cases(cmd: str, file: str, what: str, columns: list[str], other: str) -> None:
    """File-level mutations of a CSV table and every bad value in each numeric column."""
    case(cmd, "missing", f"{file}-missing", file, [(file, remove)])
    case(cmd, "missing", f"{file}-directory", file, [(file, make_dir)])
    case(cmd, "empty", f"{file}-empty", file, [(file, text(""))])
    case(cmd, "empty", f"{file}-header-only", file, [(file, header_only)])
    case(cmd, "empty", f"{file}-blank-lines", file, [(file, text("\n\n\n"))])
    case(cmd, "garbage", f"{file}-garbage", file, [(file, text("hello world\x01\nfoo;bar\n"))])
    case(cmd, "binary", f"{file}-binary", file, [(file, text(BINARY))])
    case(cmd, "binary", f"{file}-gzip", file, [(file, text(b"\x1f\x8b\x08\x00" + BINARY))])
    case(cmd, "mistyped", f"{file}-other-table", file, [(file, copy_from(other))])
    case(cmd, "mistyped", f"{file}-toml", file, [(file, text("[camera]\nc_mm = 40.0\n"))])
    for c in columns:
        case(cmd, "mistyped", f"{file}-no-{c}", c, [(file, drop_column(c))])
        case(cmd, "mistyped", f"{file}-{c}-misspelled", c, [(file, rename_column(c, c + "x"))])
    for c in columns:
        if c in ("point", "point_id", "image", "band"):
            continue
        for name, v, kind in BAD_VALUES:
            case(cmd, kind, f"{file}-{c}-{name}", c, [(file, set_cell(c, v))])


# --- calibrate-line ------------------------------------------------------------------------
C = "calibrate-line"
table_file_cases(C, "obs.csv", "observations", ["image", "point", "zeta_px"], "control.csv")
table_file_cases(C, "control.csv", "control", ["point", "x_m", "y_m"], "obs.csv")
case(C, "duplicates", "obs-duplicate-row", "line 4", [("obs.csv", duplicate_row(2))])
case(C, "duplicates", "control-duplicate-id", "line 3", [("control.csv", set_cell("point", "", 1))])
case(C, "duplicates", "control-same-id-twice", "P", [("control.csv", duplicate_row(0))])
case(C, "mistyped", "obs-unknown-point", "999999", [("obs.csv", set_cell("point", "999999"))])
case(C, "degenerate", "obs-three-rows", "at least", [("obs.csv", keep_rows(3))])
case(C, "range", "zeta-negative-huge", "zeta_px", [("obs.csv", set_cell("zeta_px", "-5e7"))])
case(C, "units", "control-in-mm", "control", [("control.csv", scale_column("x_m", 1e6))])
case(C, "degenerate", "control-collinear", "collinear", [("control.csv", scale_column("y_m", 0.0))])
case(
    C,
    "degenerate",
    "image-all-zeta-equal",
    "image img0",
    [("obs.csv", lambda p: _set_image_zeta(p, "img0", "100.0"))],
)
for o, vals in {
    "--sigma-px": ["0", "-1", "nan", "inf", "abc"],
    "--zeta0-px": ["nan", "inf", "abc", "1e300"],
    "--c-px": ["0", "-3600", "nan", "abc"],
    "--reject-k": ["0", "-2", "nan"],
}.items():
    for v in vals:
        case(C, "options", f"{o}={v}", o, argv=opt(o, v))
case(C, "options", "no-control", "--control", argv=opt("--control"))
case(C, "options", "unknown-option", "--sigmapx", argv=flag("--sigmapx", "1"))

# --- adjust-pushbroom ----------------------------------------------------------------------
C = "adjust-pushbroom"
table_file_cases(
    C, "obs.csv", "observation", ["point_id", "band", "t_s", "x_px", "y_px"], "gcp.csv"
)
table_file_cases(C, "gcp.csv", "GCP", ["point_id", "E_m", "N_m", "H_m"], "obs.csv")
NAV = ["t_s", "E_m", "N_m", "U_m", "roll_deg", "pitch_deg", "heading_deg"]
table_file_cases(C, "nav.csv", "navigation", NAV, "obs.csv")
case(C, "duplicates", "obs-duplicate-row", "line 4", [("obs.csv", duplicate_row(2))])
case(C, "duplicates", "gcp-duplicate-id", "1", [("gcp.csv", duplicate_row(1))])
case(C, "duplicates", "nav-duplicate-time", "t_s", [("nav.csv", duplicate_row(5))])
case(C, "degenerate", "nav-times-decreasing", "t_s", [("nav.csv", swap_rows(5, 6))])
case(C, "degenerate", "nav-gap", "--max-nav-gap-s", [("nav.csv", delete_rows(20, 80))])
case(C, "degenerate", "nav-one-row", "navigation", [("nav.csv", keep_rows(1))])
case(C, "degenerate", "nav-not-covering", "t_s", [("nav.csv", keep_rows(20))])
case(C, "mistyped", "gcp-unknown-id", "999999", [("gcp.csv", set_cell("point_id", "999999"))])
case(
    C,
    "degenerate",
    "point-observed-once",
    "999999",
    [("obs.csv", set_cell("point_id", "999999", 0))],
)
case(C, "range", "band-negative", "band", [("obs.csv", set_cell("band", "-1"))])
case(C, "range", "band-too-large", "n_bands", [("obs.csv", set_cell("band", "7"))])
case(C, "type", "band-fraction", "band", [("obs.csv", set_cell("band", "1.5"))])
case(C, "range", "nav-jump-100km", "line 12", [("nav.csv", set_cell("E_m", "100000", 10))])
case(C, "units", "roll-out-of-range", "roll_deg", [("nav.csv", set_cell("roll_deg", "400"))])
case(C, "units", "pitch-out-of-range", "pitch_deg", [("nav.csv", set_cell("pitch_deg", "-95"))])
case(C, "units", "nav-position-mm", "navigation", [("nav.csv", scale_column("E_m", 1e3))])
for key, value, expect in [
    ("n_bands", "0", "n_bands"),
    ("n_bands", "'abc'", "n_bands"),
    ("n_bands", "2.5", "n_bands"),
    ("n_bands", None, "n_bands"),
    ("pixel_mm", "0", "pixel_mm"),
    ("pixel_mm", "'abc'", "pixel_mm"),
    ("pixel_mm", "nan", "pixel_mm"),
    ("pixel_mm", "6.5", "pixel_mm"),
    ("c_mm", "-40.0", "c_mm"),
    ("c_mm", "inf", "c_mm"),
    ("c_mm", "1e300", "c_mm"),
    ("c_mm", None, "c_mm"),
    ("x0_mm", "'abc'", "x0_mm"),
    ("x0_mm", "1e300", "x0_mm"),
    ("lever_arm_m", "[1.0, 2.0]", "lever_arm_m"),
    ("lever_arm_m", "[1.0, 'a', 2.0]", "lever_arm_m"),
    ("lever_arm_m", "[1e300, 0.0, 0.0]", "lever_arm_m"),
    ("sigma_lever_m", "0", "sigma_lever_m"),
]:
    kind = "missing" if value is None else ("range" if "1e300" in value else "type")
    case(C, kind, f"cam-{key}={value}", expect, [("cam.toml", toml_set("camera", key, value))])
for extra, expect in [
    ("[gnss]\nsigma_pos_m = [0.01, 0.01, 0.02]\n", "gnss_ins"),
    ("[observation]\nsigma_px = 0.5\n", "observations"),
    ("[gnss_ins]\nsigma_pos_m = [0.01, 0.01]\n", "sigma_pos_m"),
    ("[gnss_ins]\nsigma_att_deg = [0.0, 0.01, 0.01]\n", "sigma_att_deg"),
    ("[observations]\nsigma_px = 0\n", "sigma_px"),
    ("[gcp]\nsigma_m = -1.0\n", "sigma_m"),
]:
    head, key = extra.split(chr(10))[0], extra.split(chr(10))[1].split(" =")[0]
    table, value = head.strip("[]"), extra.split(chr(10))[1].split(" = ")[1]
    # the camera file states every a-priori σ: a known table's key is set in place
    edit = toml_set(table, key, value) if table in ("gnss_ins", "observations", "gcp") else None
    case(C, "mistyped", f"cam-{head}-{key}", expect, [("cam.toml", edit or toml_append(extra))])
# no a-priori σ is a default (a paper's is not the user's instruments'): each missing one named
for table, key in [
    ("camera", "sigma_lever_m"),
    ("gnss_ins", "sigma_pos_m"),
    ("gnss_ins", "sigma_att_deg"),
    ("observations", "sigma_px"),
    ("gcp", "sigma_m"),
]:
    expect = f"[{table}] {key}"
    case(C, "missing", f"cam-no-{key}", expect, [("cam.toml", toml_set(table, key, None))])
case(
    C,
    "mistyped",
    "cam-level_arm_m",
    "lever_arm_m",
    [("cam.toml", toml_rename("lever_arm_m", "level_arm_m"))],
)
case(C, "missing", "cam-missing", "cam.toml", [("cam.toml", remove)])
case(C, "empty", "cam-empty", "[camera]", [("cam.toml", text(""))])
case(C, "binary", "cam-binary", "cam.toml", [("cam.toml", text(BINARY))])
case(C, "garbage", "cam-malformed", "cam.toml", [("cam.toml", text("[camera\nc_mm = \n"))])
case(C, "mistyped", "cam-is-csv", "cam.toml", [("cam.toml", copy_from("gcp.csv"))])
# the one sensor file (issue 36): a mount in the wrong units, the 002 camera's keys checked
RAD = "[0.005235987755982988, -0.003490658503988659, 0.0017453292519943296]"  # 0.3, -0.2, 0.1°
for name, key, value, expect in [
    ("cam-lever-arm-in-mm", "lever_arm_m", "[150.0, 0.0, -300.0]", "not mm"),
    ("cam-boresight-in-radians", "boresight_deg", RAD, "are radians"),
    ("cam-c_band-count", "c_band_mm", "[40.0, 40.1]", "c_band_mm has 2 values"),
]:
    case(C, "units", name, expect, [("cam.toml", toml_set("camera", key, value))])
for o, vals in {"--node-interval": ["0", "-10", "nan", "inf", "abc"]}.items():
    for v in vals:
        case(C, "options", f"{o}={v}", o, argv=opt(o, v))
case(C, "options", "--max-nav-gap-s=0", "--max-nav-gap-s", argv=opt("--max-nav-gap-s", "0"))
case(C, "options", "no-camera", "--camera", argv=opt("--camera"))
case(C, "options", "no-trajectory", "--trajectory", argv=opt("--trajectory"))

# --- lp-observations -----------------------------------------------------------------------
C = "lp-observations"
SQUARES = ["point_id", "E_m", "N_m", "H_m"]
table_file_cases(C, "nav.csv", "navigation", NAV, "squares.csv")
table_file_cases(C, "squares.csv", "squares", SQUARES, "nav.csv")
case(C, "duplicates", "squares-same-id-twice", "point_id", [("squares.csv", duplicate_row(0))])
case(C, "degenerate", "nav-not-covering", "navigation", [("nav.csv", keep_rows(60))])
case(C, "degenerate", "nav-times-decreasing", "t_s", [("nav.csv", swap_rows(5, 6))])
case(C, "units", "nav-east-in-mm", "jumps", [("nav.csv", scale_column("E_m", 1000.0))])


def _lp_noise(p: Path) -> None:
    """The strip's lines replaced by noise: nothing to match."""
    from dataclasses import replace

    from hsgeo.io.lp_lines import read_lp_lines, write_lp_lines

    s = read_lp_lines(p)
    rng = np.random.default_rng(int(p.stem[1:]))  # each strip its own noise
    write_lp_lines(
        p, replace(s, lines=rng.normal(1000, 30, s.lines.shape).astype(np.float32)), overwrite=True
    )


def _lp_drop(var: str):
    def edit(p: Path) -> None:
        import xarray as xr

        with xr.open_dataset(p, engine="h5netcdf") as ds:
            new = ds.load().drop_vars(var)
        p.unlink()
        new.to_netcdf(p, engine="h5netcdf")

    return edit


for f in ("s0.nc", "s3.nc"):
    case(C, "missing", f"{f}-missing", f, [(f, remove)])
    case(C, "missing", f"{f}-directory", f, [(f, make_dir)])
    case(C, "empty", f"{f}-empty", f, [(f, text(""))])
    case(C, "garbage", f"{f}-text", f, [(f, text("hello world\n"))])
    case(C, "binary", f"{f}-binary", f, [(f, text(BINARY))])
    case(C, "mistyped", f"{f}-a-csv", f, [(f, copy_from("nav.csv"))])
    case(C, "mistyped", f"{f}-no-t_s", "t_s", [(f, _lp_drop("t_s"))])
    case(C, "mistyped", f"{f}-no-lines", "lines", [(f, _lp_drop("lines"))])
case(C, "degenerate", "noise-only", "11 matches", [(f"s{i}.nc", _lp_noise) for i in range(4)])
case(C, "degenerate", "two-strips", "strip(s) given", argv=lambda a, d: [a[0], a[1], a[2], *a[5:]])
case(C, "duplicates", "strip-twice", "twice", argv=lambda a, d: [a[0], a[1], *a[1:]])
case(C, "missing", "cam-missing", "cam.toml", [("cam.toml", remove)])
case(C, "garbage", "cam-garbage", "cam.toml", [("cam.toml", text("[camera\nn_bands = \n"))])
case(C, "mismatch", "cam-3-bands", "n_bands", [("cam.toml", toml_set("camera", "n_bands", "3"))])
case(
    C,
    "range",
    "cam-pixel-negative",
    "pixel_mm",
    [("cam.toml", toml_set("camera", "pixel_mm", "-6.5"))],
)
case(C, "options", "bands-9", "band(s) [9]", argv=flag("--bands", "0,9"))
case(C, "options", "bands-text", "--bands", argv=flag("--bands", "red"))
case(C, "options", "bands-negative", "--bands", argv=flag("--bands", "-1"))
case(C, "options", "scene-lines-2", "--scene-lines", argv=flag("--scene-lines", "2"))
case(C, "options", "scene-lines-text", "--scene-lines", argv=flag("--scene-lines", "many"))
case(C, "options", "ransac-homography", "--ransac", argv=flag("--ransac", "homography"))
case(C, "options", "threshold-0", "--threshold-px", argv=flag("--threshold-px", "0"))
case(C, "options", "height-nan", "--height", argv=flag("--height", "nan"))
case(C, "options", "no-trajectory", "--trajectory", argv=opt("--trajectory"))
case(C, "options", "no-output", "-o", argv=opt("-o"))
case(C, "options", "no-height-no-squares", "--height", argv=opt("--squares"))
case(C, "output", "output-is-nav", "nav.csv", argv=lambda a, d: opt("-o", str(d / "nav.csv"))(a, d))
case(C, "output", "output-is-strip", "s0.nc", argv=lambda a, d: opt("-o", str(d / "s0.nc"))(a, d))
case(C, "output", "output-txt", ".txt", argv=lambda a, d: opt("-o", str(d.parent / "o.txt"))(a, d))
case(
    C,
    "output",
    "output-folder-missing",
    "does not exist",
    argv=lambda a, d: opt("-o", str(d / "no" / "o.parquet"))(a, d),
)
case(
    C,
    "outputs",
    "output-exists",
    "--overwrite",
    argv=lambda a, d: _touch_output(a, d),
)


# --- orthorectify: one line of the 000 line scanner ----------------------------------------
C = "orthorectify-line"
table_file_cases(C, "nav.csv", "navigation", NAV, "sensor.toml")
case(C, "duplicates", "nav-duplicate-time", "t_s", [("nav.csv", duplicate_row(5))])
case(C, "degenerate", "nav-times-decreasing", "t_s", [("nav.csv", swap_rows(5, 6))])
case(C, "degenerate", "nav-gap-6s", "--max-nav-gap-s", [("nav.csv", delete_rows(40, 160))])
case(C, "degenerate", "nav-not-covering", "navigation", [("nav.csv", keep_rows(60))])
case(C, "range", "nav-record-100km-off", "line 12", [("nav.csv", set_cell("E_m", "100000", 10))])
case(
    C,
    "units",
    "nav-heading-out-of-range",
    "heading_deg",
    [("nav.csv", set_cell("heading_deg", "1000"))],
)
case(C, "units", "nav-attitude-in-mrad", "roll_deg", [("nav.csv", scale_column("roll_deg", 1e4))])
case(C, "degenerate", "height-above-aircraft", "--height", argv=opt("--height", "600"))
case(C, "degenerate", "height-at-aircraft", "--height", argv=opt("--height", "500"))
for v in ("nan", "inf", "abc", "1e300"):
    case(C, "options", f"--height={v}", "--height", argv=opt("--height", v))
for v in ("0", "-1", "nan", "inf", "abc"):
    case(C, "options", f"--resolution={v}", "--resolution", argv=opt("--resolution", v))
case(
    C, "degenerate", "resolution-5mm", "--resolution 0.005 m",
    argv=lambda a, d: flag("--max-gib", "1")(opt("--resolution", "0.005")(a, d), d),
)  # fmt: skip
case(C, "degenerate", "resolution-1e-9", "--resolution 1e-09 m", argv=opt("--resolution", "1e-9"))
case(C, "options", "max-gib-0", "--max-gib", argv=opt("--max-gib", "0"))
case(C, "options", "max-nav-gap-nan", "--max-nav-gap-s", argv=opt("--max-nav-gap-s", "nan"))
case(C, "options", "dem-and-height", "--height", argv=flag("--dsm", "x.nc"))
case(C, "options", "no-output", "--output", argv=opt("-o"))
# LINES
case(C, "missing", "lines-missing", "lines.nc", [("lines.nc", remove)])
case(C, "missing", "lines-directory", "lines.nc", [("lines.nc", make_dir)])
case(C, "empty", "lines-empty", "lines.nc", [("lines.nc", text(""))])
case(C, "mistyped", "lines-is-csv", "lines.nc", [("lines.nc", copy_from("nav.csv"))])
case(C, "binary", "lines-binary", "lines.nc", [("lines.nc", text(BINARY))])
case(
    C,
    "binary",
    "lines-hdf5-garbage",
    "lines.nc",
    [("lines.nc", text(b"\x89HDF\r\n\x1a\n" + BINARY))],
)
case(
    C,
    "binary",
    "lines-truncated",
    "lines.nc",
    [("lines.nc", lambda p: p.write_bytes(p.read_bytes()[:300]))],
)
case(
    C,
    "mistyped",
    "lines-no-pixel",
    "pixel",
    [("lines.nc", nc_edit(lambda ds: ds.drop_vars("pixel")))],
)
case(
    C,
    "mistyped",
    "lines-no-radiance",
    "radiance",
    [("lines.nc", nc_edit(lambda ds: ds.rename(radiance="L")))],
)
case(
    C, "mistyped", "lines-no-t0", "t0_s", [("lines.nc", nc_edit(lambda ds: _drop_attr(ds, "t0_s")))]
)
case(
    C,
    "mistyped",
    "lines-no-rate",
    "line_rate_hz",
    [("lines.nc", nc_edit(lambda ds: _drop_attr(ds, "line_rate_hz")))],
)
for attr, v, kind in [
    ("line_rate_hz", np.nan, "nonfinite"),
    ("line_rate_hz", 0.0, "range"),
    ("line_rate_hz", -8.0, "range"),
    ("line_rate_hz", "abc", "type"),
    ("t0_s", np.nan, "nonfinite"),
    ("t0_s", np.inf, "nonfinite"),
    ("t0_s", "abc", "type"),
]:
    case(
        C,
        kind,
        f"lines-{attr}={v}",
        attr,
        [("lines.nc", nc_edit(lambda ds, a=attr, v=v: _set_attr(ds, a, v)))],
    )
case(
    C, "degenerate", "lines-one-line", "line", [("lines.nc", nc_edit(lambda ds: ds.isel(line=[0])))]
)
case(
    C,
    "degenerate",
    "lines-one-pixel",
    "pixel",
    [("lines.nc", nc_edit(lambda ds: ds.isel(pixel=[0])))],
)
case(
    C,
    "nonfinite",
    "lines-pixel-nan",
    "pixel",
    [("lines.nc", nc_edit(lambda ds: ds.assign_coords(pixel=ds["pixel"].values * np.nan)))],
)
case(
    C,
    "duplicates",
    "lines-pixel-duplicated",
    "pixel",
    [
        (
            "lines.nc",
            nc_edit(
                lambda ds: ds.assign_coords(
                    pixel=np.r_[ds["pixel"].values[:1], ds["pixel"].values[:-1]]
                )
            ),
        )
    ],
)
case(
    C,
    "range",
    "lines-pixel-1e300",
    "pixel",
    [("lines.nc", nc_edit(lambda ds: ds.assign_coords(pixel=ds["pixel"].values + 1e300)))],
)
case(
    C,
    "mistyped",
    "lines-wrong-dims",
    "radiance",
    [("lines.nc", nc_edit(lambda ds: ds.rename(line="row")))],
)
case(
    C,
    "degenerate",
    "lines-after-navigation",
    "navigation",
    [("lines.nc", nc_edit(lambda ds: _set_attr(ds, "t0_s", 100.0)))],
)
case(
    C,
    "degenerate",
    "lines-rate-too-low",
    "navigation",
    [("lines.nc", nc_edit(lambda ds: _set_attr(ds, "line_rate_hz", 1.0)))],
)
# SENSOR
for key, value, kind in [
    ("zeta0_px", "'abc'", "type"),
    ("zeta0_px", "nan", "nonfinite"),
    ("zeta0_px", "inf", "nonfinite"),
    ("zeta0_px", "1e300", "range"),
    ("zeta0_px", None, "missing"),
    ("c_px", "0", "range"),
    ("c_px", "-3539.0", "range"),
    ("c_px", "'3539'", "type"),
    ("c_px", "1e300", "range"),
    ("K", "[1.0, 2.0]", "type"),
    ("K", "1.0", "type"),
    ("K", "[nan, 0.0, 0.0]", "nonfinite"),
    ("boresight_deg", "[0.0, 0.0]", "type"),
    ("boresight_deg", "[400.0, 0.0, 0.0]", "units"),
    ("boresight_deg", "[1e300, 0.0, 0.0]", "range"),
    ("model", "'pinhole'", "type"),
    ("model", "3", "type"),
]:
    case(C, kind, f"sensor-{key}={value}", key, [("sensor.toml", toml_set("sensor", key, value))])
case(
    C,
    "mistyped",
    "sensor-borsight",
    "boresight_deg",
    [("sensor.toml", toml_rename("boresight_deg", "borsight_deg"))],
)
# the one sensor file (issue 36): unknown model, a key the model cannot use, wrong units
for name, key, value, kind, expect in [
    ("sensor-unknown-model", "model", "'pushbrom'", "mistyped", "did you mean 'pushbroom'"),
    ("sensor-key-of-pushbroom", "c_band_mm", "[40.0]", "mistyped", "cannot use this key"),
    ("sensor-lever-arm-in-mm", "lever_arm_m", "[300.0, 0.0, -150.0]", "units", "not mm"),
    ("sensor-boresight-in-radians", "boresight_deg", RAD, "units", "are radians"),
]:
    case(C, kind, name, expect, [("sensor.toml", toml_set("sensor", key, value))])
case(
    C,
    "mistyped",
    "sensor-unknown-table",
    "[sensr]",
    [("sensor.toml", toml_append("[sensr]\nc = 1\n"))],
)
case(
    C,
    "mistyped",
    "sensor-ifov-with-K",
    "cannot use this key",
    [("sensor.toml", toml_set("sensor", "model", "'linear-ifov'"))],
)
case(C, "missing", "sensor-missing", "sensor.toml", [("sensor.toml", remove)])
case(C, "empty", "sensor-empty", "[sensor]", [("sensor.toml", text(""))])
case(C, "binary", "sensor-binary", "sensor.toml", [("sensor.toml", text(BINARY))])
case(
    C,
    "binary",
    "sensor-latin1",
    "sensor.toml",
    [("sensor.toml", text("[sensor]\n# \xe9t\xe9\n".encode("latin-1")))],
)
case(C, "garbage", "sensor-malformed", "sensor.toml", [("sensor.toml", text("[sensor\n"))])
case(C, "mistyped", "sensor-is-csv", "sensor.toml", [("sensor.toml", copy_from("nav.csv"))])
case(
    C,
    "degenerate",
    "sensor-zeta0-outside",
    "zeta0_px",
    [("sensor.toml", toml_set("sensor", "zeta0_px", "5000.0"))],
)
# DEM


def _dem(a, d):
    a = [x for x in a]
    i = a.index("--height")
    a[i : i + 2] = ["--dsm", str(d / "dem.nc")]
    return a


case(C, "missing", "dem-missing", "dem.nc", [("dem.nc", remove)], argv=_dem)
case(C, "empty", "dem-empty", "dem.nc", [("dem.nc", text(""))], argv=_dem)
case(C, "mistyped", "dem-is-lines", "height", [("dem.nc", copy_from("lines.nc"))], argv=_dem)
case(C, "nonfinite", "dem-nan", "DEM", [("dem.nc", nc_edit(lambda ds: ds * np.nan))], argv=_dem)
case(
    C,
    "mistyped",
    "dem-x-y-dimensions",
    "dimensions N, E",
    [("dem.nc", nc_edit(lambda ds: ds.rename(N="y", E="x")))],
    argv=_dem,
)
case(
    C,
    "degenerate",
    "dem-one-cell",
    "2 x 2 cells",
    [("dem.nc", nc_edit(lambda ds: ds.isel(N=[0], E=[0])))],
    argv=_dem,
)
case(
    C,
    "degenerate",
    "dem-above-aircraft",
    "DEM",
    [("dem.nc", nc_edit(lambda ds: ds + 700.0))],
    argv=_dem,
)
case(
    C,
    "degenerate",
    "dem-not-covering",
    "DEM",
    [("dem.nc", nc_edit(lambda ds: ds.isel(N=slice(0, 5))))],
    argv=_dem,
)
# outputs
case(
    C,
    "output",
    "output-is-lines",
    "lines.nc",
    argv=lambda a, d: opt("-o", str(d / "lines.nc"))(a, d),
)
case(C, "output", "output-is-nav", "nav.csv", argv=lambda a, d: opt("-o", str(d / "nav.csv"))(a, d))
case(
    C,
    "output",
    "output-is-sensor",
    "sensor.toml",
    argv=lambda a, d: opt("-o", str(d / "sensor.toml"))(a, d),
)
case(
    C, "output", "envi-data-is-lines", "lines.nc",
    argv=lambda a, d: opt("-o", str(d / "lines.nc.hdr"))(a, d),
)  # fmt: skip
case(
    C,
    "output",
    "envi-hdr-is-input",
    "s.hdr",
    files=[("sensor.toml", lambda p: shutil.copy(p, p.parent / "s.hdr"))],
    argv=lambda a, d: chain(opt("--sensor", str(d / "s.hdr")), opt("-o", str(d / "s.hdr")))(a, d),
)
case(
    C,
    "output",
    "output-dir-missing",
    "does-not-exist",
    argv=lambda a, d: opt("-o", str(d / "does-not-exist" / "o.nc"))(a, d),
)
case(
    C,
    "output",
    "envi-dir-missing",
    "does-not-exist",
    argv=lambda a, d: opt("-o", str(d / "does-not-exist" / "o.hdr"))(a, d),
)
case(C, "output", "output-is-directory", "directory", argv=lambda a, d: opt("-o", str(d))(a, d))
case(C, "output", "output-exists", "--overwrite", argv=lambda a, d: _touch_output(a, d))
case(C, "output", "envi-data-exists", "--overwrite", argv=lambda a, d: _touch_envi(a, d))
case(C, "output", "output-dir-readonly", "writ", argv=lambda a, d: _readonly_output(a, d))


def _set_image_zeta(p, image, value):
    h, rows = read_csv(p)
    write_csv(p, h, [[r[0], r[1], value] if r[0] == image else r for r in rows])


def _drop_attr(ds, a):
    ds.attrs.pop(a, None)
    ds["radiance"].attrs.pop(a, None)
    return ds


def _set_attr(ds, a, v):
    ds.attrs[a] = v
    return ds


def _touch_output(a, d):
    out = Path(a[a.index("-o") + 1])
    out.write_text("precious")
    return a


def _touch_envi(a, d):
    envi = d.parent / "out" / "ortho_envi"
    envi.write_text("precious")  # the ENVI data file of -o ortho_envi.hdr
    return opt("-o", str(envi) + ".hdr")(a, d)


def _readonly_output(a, d):
    ro = d.parent / "readonly"
    ro.mkdir()
    ro.chmod(0o555)
    return opt("-o", str(ro / "o.nc"))(a, d)


# --- calibrate-frame -----------------------------------------------------------------------
C = "calibrate-frame"


def add_image(path):
    """Add the image ``path(d)`` to the command's images (before --board)."""
    return lambda a, d: [a[0], str(path(d)), *a[1:]]


def _first_image(d):
    return sorted(d.glob("*.jpg"))[0]


case(C, "duplicates", "same-image-twice", "given twice", argv=add_image(_first_image))
case(
    C,
    "duplicates",
    "same-image-two-names",
    "same image",
    files=[("img_00.jpg", lambda p: shutil.copy(p, p.parent / "copy.jpg"))],
    argv=add_image(lambda d: d / "copy.jpg"),
)
case(
    C,
    "duplicates",
    "same-image-relative",
    "given twice",
    argv=add_image(lambda d: d / ".." / d.name / "img_00.jpg"),
)
case(C, "missing", "image-missing", "img_01.jpg", [("img_01.jpg", remove)])
case(C, "missing", "image-directory", "img_01.jpg", [("img_01.jpg", make_dir)])
case(C, "empty", "image-empty", "img_01.jpg", [("img_01.jpg", text(b""))])
case(C, "binary", "image-garbage", "img_01.jpg", [("img_01.jpg", text(BINARY))])
case(C, "mistyped", "image-is-toml", "board.toml", argv=add_image(lambda d: d / "board.toml"))
case(C, "degenerate", "image-other-size", "img_01.jpg", [("img_01.jpg", lambda p: _resize(p, 0.5))])
case(C, "degenerate", "image-blank", "img_01.jpg", [("img_01.jpg", lambda p: _blank(p))])
case(C, "degenerate", "one-image", "image", argv=lambda a, d: [a[0], a[1], *a[-2:]])
case(
    C,
    "mismatch",
    "board-other-dictionary",
    "dictionary",
    [("board.toml", toml_set("board", "dictionary", "'DICT_4X4_50'"))],
)
case(
    C,
    "mismatch",
    "board-other-size",
    "board",
    [("board.toml", toml_set("board", "squares_x", "9"))],
)
case(
    C,
    "mismatch",
    "board-aruco-grid",
    "board",
    [
        (
            "board.toml",
            text(
                "[board]\ntype = 'aruco_grid'\ndictionary = 'DICT_4X4_50'\nmarkers_x = 4\n"
                "markers_y = 4\nmarker_mm = 20.0\nseparation_mm = 5.0\n"
            ),
        )
    ],
)
for key, value, kind, expect in [
    ("marker_mm", "50.0", "degenerate", "marker_mm"),
    ("marker_mm", "40.0", "degenerate", "marker_mm"),
    ("square_mm", "0", "range", "square_mm"),
    ("square_mm", "'abc'", "type", "square_mm"),
    ("square_mm", "nan", "nonfinite", "square_mm"),
    ("square_mm", "1e300", "range", "square_mm"),
    ("squares_x", "1", "degenerate", "squares"),
    ("squares_x", "2.5", "type", "squares_x"),
    ("squares_y", None, "missing", "squares_y"),
    ("type", "'hexagons'", "type", "type"),
    ("dictionary", "'DICT_NOPE'", "type", "dictionary"),
    ("markers_x", "4", "mistyped", "markers_x"),
    ("dictonary", "'DICT_6X6_250'", "mistyped", "dictionary"),
]:
    case(C, kind, f"board-{key}={value}", expect, [("board.toml", toml_set("board", key, value))])
case(
    C,
    "type",
    "board-pixel_mm-0",
    "pixel_mm",
    [("board.toml", toml_append("[camera]\npixel_mm = 0\n"))],
)
case(
    C,
    "mistyped",
    "board-pixl_mm",
    "pixel_mm",
    [("board.toml", toml_append("[camera]\npixl_mm = 0.0055\n"))],
)
case(C, "missing", "board-missing", "board.toml", [("board.toml", remove)])
case(C, "empty", "board-empty", "[board]", [("board.toml", text(""))])
case(C, "binary", "board-binary", "board.toml", [("board.toml", text(BINARY))])
case(
    C,
    "mistyped",
    "board-is-image",
    "board",
    argv=lambda a, d: opt("--board", str(_first_image(d)))(a, d),
)
for v in ("0", "-1", "nan", "abc"):
    case(C, "options", f"--sigma-px={v}", "--sigma-px", argv=opt("--sigma-px", v))
case(C, "options", "band-regex-no-group", "--band-regex", argv=opt("--band-regex", "img"))
case(C, "options", "band-regex-invalid", "--band-regex", argv=opt("--band-regex", "img(("))
case(C, "options", "band-regex-no-match", "--band-regex", argv=opt("--band-regex", r"band(\d+)"))
case(C, "options", "joint-without-regex", "--band-regex", argv=flag("--joint"))
case(C, "options", "no-board", "--board", argv=opt("--board"))


def _resize(p, f):
    import cv2

    img = cv2.imread(str(p))
    cv2.imwrite(str(p), cv2.resize(img, None, fx=f, fy=f))


def _blank(p):
    import cv2

    img = cv2.imread(str(p))
    cv2.imwrite(str(p), np.full_like(img, 128))


# --- cube ----------------------------------------------------------------------------------
C = "cube"


def _npy(edit):
    """Rewrite a .npy frame through ``edit(array) -> array``."""

    def f(p: Path):
        a = np.load(p)
        np.save(p, edit(a))

    return f


def _saturate_incident(a):
    a = a.copy()
    a[100:140, 585:] = 4095
    return a


case(
    C,
    "degenerate",
    "mixed-frame-sizes",
    "mixed sizes",
    [("raw/frame_000003.npy", _npy(lambda a: a[:, :600]))],
)
case(
    C,
    "degenerate",
    "dark-mixed-sizes",
    "mixed sizes",
    [("dark/frame_000002.npy", _npy(lambda a: a[:500]))],
)
case(
    C,
    "degenerate",
    "dark-one-exposure-time",
    "one exposure time",
    [
        ("dark/exposures.csv", scale_column("exposure_s", 0.0)),
        ("dark/exposures.csv", lambda p: p.write_text(p.read_text().replace(",0.0", ",0.2"))),
    ],
)
case(
    C,
    "range",
    "saturated-incident",
    "saturated",
    [("raw/frame_000002.npy", _npy(_saturate_incident))],
)
case(C, "missing", "wavelengths-missing", "wavelengths.csv", [("raw/wavelengths.csv", remove)])
case(
    C,
    "missing",
    "wavelengths-rows-missing",
    "missing wavelengths",
    [("raw/wavelengths.csv", keep_rows(300))],
)
case(
    C,
    "mistyped",
    "wavelengths-no-fwhm",
    "fwhm_nm",
    [("raw/wavelengths.csv", drop_column("fwhm_nm"))],
)
case(
    C,
    "nonfinite",
    "wavelength-nan",
    "wavelength_nm",
    [("raw/wavelengths.csv", set_cell("wavelength_nm", "nan"))],
)
case(C, "missing", "exposures-missing", "exposures.csv", [("raw/exposures.csv", remove)])
case(
    C,
    "missing",
    "exposure-of-a-frame-missing",
    "frame_000005.npy",
    [("raw/exposures.csv", delete_rows(5, 6))],
)
case(
    C,
    "range",
    "exposure-in-ms",
    "exposure_s",
    [("raw/exposures.csv", scale_column("exposure_s", 1e4))],
)
case(C, "garbage", "frame-not-npy", "frame_000001.npy", [("raw/frame_000001.npy", text("hello\n"))])
# issue 42: answers on wrong frames (exit 0) before
case(
    C,
    "units",
    "raw-exposure-in-ms-dark-in-s",
    "not ms",
    [("raw/exposures.csv", scale_column("exposure_s", 1e3))],
)
case(
    C,
    "missing",
    "frame-numbering-gap",
    "frame_000004.npy to frame_000006.npy",
    [("raw/frame_000005.npy", remove), ("raw/exposures.csv", delete_rows(5, 6))],
)
case(
    C,
    "units",
    "frames-8-bit",
    "uint8",
    [("raw/frame_000002.npy", _npy(lambda a: (a >> 4).astype(np.uint8)))],
)
case(
    C,
    "duplicates",
    "extra-frame-file",
    "notes_1.npy",
    [
        ("raw/notes_1.npy", lambda p: shutil.copy(p.parent / "frame_000001.npy", p)),
        ("raw/exposures.csv", text_append("notes_1.npy,0.042")),
    ],
)
case(
    C,
    "missing",
    "exposure-row-of-an-absent-frame",
    "frame_000099.npy",
    [("raw/exposures.csv", text_append("frame_000099.npy,0.042"))],
)
case(C, "mistyped", "envi-frames-beside", "frames.hdr", [("raw/frames.hdr", text("ENVI\n"))])
case(C, "missing", "raw-dir-missing", "RAW_DIR", argv=replace_arg("raw", lambda d: d / "nope"))
case(C, "options", "binning-1", "--binning", argv=flag("--binning", "1"))
for o, vals in {
    "--binning": ["3", "0", "abc"],
    "--rows-per-band": ["0", "2.5"],
    "--f-alpha": ["0", "nan"],
}.items():
    for v in vals:
        case(C, "options", f"{o}={v}", o, argv=opt(o, v))
case(C, "options", "no-dark", "--dark", argv=opt("--dark"))
case(
    C,
    "outputs",
    "output-txt",
    "unknown cube format",
    argv=lambda a, d: [x.replace("cube.nc", "cube.txt") for x in a],
)


def _envi_data_exists(a, d):
    """-o cube.hdr while the ENVI data file 'cube' exists (not only the header is checked)."""
    (d.parent / "out").mkdir(exist_ok=True)
    (d.parent / "out" / "cube").write_text("an earlier result\n")
    return [x.replace("cube.nc", "cube.hdr") for x in a]


case(C, "outputs", "envi-data-file-exists", "exists", argv=_envi_data_exists)
case(
    C,
    "outputs",
    "output-is-an-input",
    "input",
    argv=lambda a, d: (
        [str(d / "raw" / "wavelengths.csv") if x.endswith("cube.nc") else x for x in a][:-1]
        + ["--overwrite"]
    ),
)


# --- reproduce, data, versions, the top level ----------------------------------------------
C = "adjust-bal"
F = "problem.txt"


def bal_line(lineno: int, new: str):
    """Replace line ``lineno`` (1-based) of the BAL file."""

    def f(p: Path):
        lines = p.read_text().splitlines()
        lines[lineno - 1] = new
        p.write_text("\n".join(lines) + "\n")

    return f


case(C, "missing", "no-such-file", "problem.txt", files=[(F, remove)])
case(C, "missing", "a-folder", "problem.txt", files=[(F, make_dir)])
case(C, "empty", "empty-file", "empty file", files=[(F, text(""))])
case(C, "binary", "binary-file", "problem.txt", files=[(F, text(bytes(range(256)) * 8))])
case(C, "garbage", "header-words", "line 1", files=[(F, bal_line(1, "cameras points obs"))])
case(C, "garbage", "header-two-numbers", "line 1", files=[(F, bal_line(1, "2 5"))])
case(C, "range", "header-zero-cameras", "positive", files=[(F, bal_line(1, "0 5 40"))])
case(C, "range", "header-negative", "positive", files=[(F, bal_line(1, "2 -5 40"))])
case(
    C,
    "degenerate",
    "truncated-observations",
    "observation lines",
    files=[(F, bal_line(1, "2 500 40000"))],
)
case(C, "garbage", "observation-three-fields", "line 2", files=[(F, bal_line(2, "0 0 1.0"))])
case(C, "type", "observation-text", "line 3", files=[(F, bal_line(3, "0 a 1.0 2.0"))])
case(
    C, "range", "camera-index-out-of-range", "out of range", files=[(F, bal_line(4, "7 0 1.0 2.0"))]
)
case(C, "range", "point-index-negative", "out of range", files=[(F, bal_line(4, "0 -1 1.0 2.0"))])
case(C, "nonfinite", "observation-nan", "NaN", files=[(F, bal_line(5, "0 0 nan 2.0"))])
case(C, "nonfinite", "observation-inf", "NaN", files=[(F, bal_line(5, "0 0 1.0 inf"))])
case(C, "nonfinite", "camera-value-nan", "NaN", files=[(F, bal_line(45, "nan"))])
case(C, "type", "camera-value-text", "numbers", files=[(F, bal_line(45, "focal"))])
case(C, "garbage", "extra-values", "more values", files=[(F, text_append("1.0 2.0 3.0"))])
case(C, "degenerate", "missing-values", "camera and point values", files=[(F, drop_last_lines(3))])
case(C, "options", "unknown-option", "--threads", argv=flag("--threads", "2"))

# --- mtf, mtf-edge ---------------------------------------------------------------------------
C = "mtf"
table_file_cases(C, "profiles.csv", "profile", ["x_px", "intensity_dn"], "bars.toml")
case(C, "degenerate", "too-few-bars", "row 100", [("profiles.csv", keep_rows(200))])
case(
    C, "range", "saturated", "saturated", [("profiles.csv", set_cell("intensity_dn", "4095", 300))]
)
case(C, "duplicates", "same-x-twice", "line", [("profiles.csv", duplicate_row(5))])
case(C, "missing", "bars-missing", "bars.toml", [("bars.toml", remove)])
case(C, "empty", "bars-empty", "bars.toml", [("bars.toml", text(""))])
case(C, "garbage", "bars-garbage", "bars.toml", [("bars.toml", text("[target\npair_mm = \n"))])
case(C, "binary", "bars-binary", "bars.toml", [("bars.toml", text(BINARY))])
case(C, "range", "gsd-negative", "gsd_mm", [("bars.toml", toml_set("profile", "gsd_mm", "-0.5"))])
case(C, "nonfinite", "gsd-nan", "gsd_mm", [("bars.toml", toml_set("profile", "gsd_mm", "nan"))])
case(C, "mistyped", "gsd-misspelled", "gsd_mm", [("bars.toml", toml_rename("gsd_mm", "gsd_m"))])
case(C, "missing", "no-start", "start_px", [("bars.toml", toml_set("profile", "start_px", None))])
case(
    C, "degenerate", "start-far-off", "start_px",
    [("bars.toml", toml_set("profile", "start_px", "600.0"))],
)  # fmt: skip
case(
    C, "mistyped", "pairs-counts-differ", "n_pairs",
    [("bars.toml", toml_set("target", "pair_mm", "[20.88, 18.6]"))],
)  # fmt: skip
case(
    C, "range", "black-above-white", "black",
    [("bars.toml", toml_set("target", "black_reflectance", "0.95"))],
)  # fmt: skip


def _mirror_profile(p: Path) -> None:
    h, rows = read_csv(p)
    j = h.index("intensity_dn")
    vals = [r[j] for r in rows][::-1]
    for r, v in zip(rows, vals, strict=True):
        r[j] = v
    write_csv(p, h, rows)


# issue 42: answers on wrong profiles (exit 0) before
case(C, "degenerate", "profile-mirrored", "mirrored", [("profiles.csv", _mirror_profile)])
case(
    C, "degenerate", "profile-shifted-half-pair", "shifted by half a pair",
    [("bars.toml", toml_set("profile", "start_px", "104.5"))],
)  # fmt: skip
case(
    C, "range", "dark-above-bright", "dark_dn = 5000",
    [("bars.toml", toml_set("profile", "dark_dn", "5000.0"))],
)  # fmt: skip
case(C, "options", "no-bars", "--bars", argv=opt("--bars"))
case(C, "options", "unknown-option", "--roi", argv=flag("--roi", "1,2,3,4"))
C = "mtf-edge"
case(C, "missing", "no-image", "edge.png", [("edge.png", remove)])
case(C, "missing", "image-directory", "edge.png", [("edge.png", make_dir)])
case(C, "empty", "image-empty", "edge.png", [("edge.png", text(""))])
case(C, "garbage", "image-text", "edge.png", [("edge.png", text("not an image\n"))])
case(C, "binary", "image-binary", "edge.png", [("edge.png", text(BINARY))])
for v in ("abc", "1,2,3", "10,10,5,5", "-1,0,10,10"):
    case(C, "options", f"--roi={v}", "--roi", argv=opt("--roi", v))
case(C, "range", "roi-outside", "--roi", argv=opt("--roi", "0,0,5000,5000"))
case(C, "degenerate", "roi-without-edge", "no edge", argv=opt("--roi", "0,0,30,30"))
case(C, "degenerate", "flat-image", "--roi", [("edge.png", lambda p: _blank(p))])
case(C, "degenerate", "edge-not-slanted", "slanted", [("edge.png", lambda p: _straight_edge(p))])


def _straight_edge(p):
    import cv2

    img = np.full((200, 160), 300, np.uint16)
    img[:, 80:] = 3000
    img += np.random.default_rng(0).integers(0, 20, img.shape).astype(np.uint16)
    cv2.imwrite(str(p), img)


# --- asf ---------------------------------------------------------------------------------------
C = "asf"
table_file_cases(C, "runway.csv", "runway", ["E_m", "N_m"], "cross.nc")
case(C, "degenerate", "runway-two-corners", "3 corners", [("runway.csv", keep_rows(2))])
case(C, "duplicates", "runway-flattened", "line 4", [("runway.csv", scale_column("N_m", 0.0))])
case(
    C,
    "degenerate",
    "runway-collinear",
    "no area",
    [("runway.csv", lambda p: p.write_text("E_m,N_m\n0,0\n10,1\n20,2\n"))],
)
case(
    C,
    "degenerate",
    "runway-outside-the-image",
    "outside the cross scan",
    [("runway.csv", lambda p: p.write_text("E_m,N_m\n5000,-16\n5400,-16\n5400,16\n5000,16\n"))],
)
for f in ("cross.nc", "along.nc"):
    case(C, "missing", f"{f}-missing", f, [(f, remove)])
    case(C, "missing", f"{f}-directory", f, [(f, make_dir)])
    case(C, "empty", f"{f}-empty", f, [(f, text(""))])
    case(C, "garbage", f"{f}-text", f, [(f, text("hello world\n"))])
    case(C, "binary", f"{f}-binary", f, [(f, text(BINARY))])
    case(C, "mistyped", f"{f}-csv", f, [(f, copy_from("runway.csv"))])
    case(
        C, "mistyped", f"{f}-no-reflectance", "reflectance",
        [(f, nc_edit(lambda ds: ds.rename({"reflectance": "radiance"})))],
    )  # fmt: skip
    case(C, "mistyped", f"{f}-no-E_m", "E_m", [(f, nc_edit(lambda ds: ds.drop_vars("E_m")))])
    case(
        C, "mistyped", f"{f}-no-scan-angle", "scan_angle_deg",
        [(f, nc_edit(lambda ds: ds.drop_vars("scan_angle_deg")))],
    )  # fmt: skip
    case(
        C, "nonfinite", f"{f}-N_m-nan", "N_m",
        [(f, nc_edit(lambda ds: ds.assign(N_m=ds["N_m"].where(ds["N_m"] > 1e9))))],
    )  # fmt: skip
    case(
        C, "units", f"{f}-scan-angle-in-px", "scan_angle_deg",
        [(f, nc_edit(lambda ds: ds.assign(scan_angle_deg=ds["scan_angle_deg"] * 100)))],
    )  # fmt: skip
    case(
        C, "degenerate", f"{f}-scan-angle-constant", "scan_angle_deg",
        [(f, nc_edit(lambda ds: ds.assign(scan_angle_deg=ds["scan_angle_deg"] * 0)))],
    )  # fmt: skip
case(
    C,
    "degenerate",
    "scans-do-not-cross",
    "do the scans cross",
    [("along.nc", nc_edit(lambda ds: ds.assign(N_m=ds["N_m"] + 5000.0)))],
)
case(
    C,
    "degenerate",
    "scans-do-not-cross-unregistered",
    "do the two scans cross",
    [("along.nc", nc_edit(lambda ds: ds.assign(N_m=ds["N_m"] + 5000.0)))],
    argv=flag("--no-register"),
)
case(
    C,
    "mistyped",
    "bands-differ",
    "bands",
    [("along.nc", nc_edit(lambda ds: ds.isel(band=slice(0, 3))))],
)
for v in ("nan", "-1", "abc"):
    case(C, "options", f"--margin={v}", "--margin", argv=opt("--margin", v))
case(C, "options", "no-runway", "--runway", argv=opt("--runway"))


C = "reproduce"
case(
    C,
    "options",
    "unknown-chapter",
    "no-such-chapter",
    argv=lambda a, d, C=C: [C, "no-such-chapter"],
)
case(
    C, "options", "chapter-typo", "line-calibration", argv=lambda a, d, C=C: [C, "line-calibratio"]
)
for v in ("-1", "abc", "1.5", "1e300"):
    case(C, "options", f"--seed={v}", "--seed", argv=opt("--seed", v))
for v in ("0", "-1", "2", "nan", "inf", "abc"):
    case(C, "options", f"--scale={v}", "--scale", argv=opt("--scale", v))
C = "data"
case(
    C,
    "output",
    "out-missing-dir",
    "--out",
    argv=lambda a, d, C=C: [C, "--out", str(d / "no" / "such")],
)
case(C, "output", "out-is-file", "--out", argv=lambda a, d, C=C: [C, "--out", str(_a_file(d))])
case(
    C,
    "output",
    "out-exists",
    "--overwrite",
    argv=lambda a, d, C=C: [C, "--out", str(_filled_dir(d))],
)
case(
    C, "output", "out-readonly", "writ", argv=lambda a, d, C=C: [C, "--out", str(_readonly_dir(d))]
)
case(C, "options", "verify-and-update", "--verify", argv=flag("--verify", "--update-manifest"))


def _flight_argv(*extra, out="f"):
    return lambda a, d: ["data", "flight", "--out", str(d / out), "--length-km", "0.5", *extra]


def _flight_file_exists(a, d):
    (d / "f").mkdir()
    (d / "f" / "lines.raw").write_bytes(b"")
    return _flight_argv("--site=59.7,10.8")(a, d)


case(C, "options", "flight-no-site", "--site", argv=_flight_argv())
case(C, "options", "flight-site-lat-95", "--site", argv=_flight_argv("--site=95,10"))
case(C, "options", "flight-site-garbage", "--site", argv=_flight_argv("--site=abc"))
case(C, "options", "site-without-flight", "data flight",
     argv=lambda a, d: ["data", "--site=59.7,10.8", "--out", str(d / "f")])  # fmt: skip
case(C, "options", "flight-length-0", "--length-km", argv=_flight_argv("--length-km", "0"))
case(C, "output", "flight-out-missing-dir", "does not exist",
     argv=_flight_argv("--site=59.7,10.8", out="no/such"))  # fmt: skip
case(C, "output", "flight-out-is-file", "is a file",
     argv=lambda a, d: _flight_argv("--site=59.7,10.8", out=_a_file(d).name)(a, d))  # fmt: skip
case(C, "output", "flight-file-exists", "--overwrite", argv=_flight_file_exists)
case(C, "options", "unknown-option", "--outt", argv=flag("--outt", "x"))
C = "versions"
case(C, "options", "extra-argument", "unrecognized", argv=flag("now"))
C = "hsgeo"
case(C, "options", "no-command", "command", argv=lambda a, d: [])
case(C, "options", "unknown-command", "geocod", argv=lambda a, d: ["geocod"])


def _a_file(d):
    (d / "f.txt").write_text("x")
    return d / "f.txt"


def _filled_dir(d):
    (d / "gen").mkdir()
    (d / "gen" / "line_lab_control.csv").write_text("precious")
    return d / "gen"


def _readonly_dir(d):
    (d / "ro").mkdir()
    (d / "ro").chmod(0o555)
    return d / "ro"


# --- issue 24: what the operating system refuses, sizes, silent wrong answers -----------------
# (a case per kind; the same checks serve every command through hsgeo.io / hsgeo.validate)
LONG = "a" * 300


def column_twice(column: str):
    """The header names ``column`` twice (the second copy holding other numbers)."""

    def edit(p: Path):
        h, rows = read_csv(p)
        j = h.index(column)
        write_csv(p, [*h, column], [[*r, r[j] + "1"] for r in rows])

    return edit


def _dem_e_repeats(ds):
    E = ds["E"].values.copy()
    E[5] = E[4]
    return ds.assign_coords(E=E)


def _out(name):
    """-o NAME, NAME under the output folder (or an absolute path as it is)."""
    return lambda a, d: opt("-o", name if name.startswith("/") else f"{d.parent / 'out'}/{name}")(
        a, d
    )


# OS refusals: a name too long (input and output), no file can be created there (/proc, /sys
# as root), a folder where a file is meant, a DEM the interpolator refuses
case(
    "calibrate-line", "os", "input-name-too-long", "too long",
    argv=replace_arg("obs.csv", lambda d: d / (LONG + ".csv")),
)  # fmt: skip
case("orthorectify-line", "os", "output-name-too-long", "too long", argv=_out(LONG + ".nc"))
case("cube", "os", "output-name-too-long", "too long", argv=_out(LONG + ".nc"))
case("orthorectify-line", "os", "output-in-proc", "no file can be created", argv=_out("/proc/o.nc"))
case("orthorectify-line", "os", "output-in-sys", "no file can be created", argv=_out("/sys/o.nc"))
case("cube", "os", "output-in-proc", "no file can be created", argv=_out("/proc/c.nc"))
case("orthorectify-line", "os", "output-names-a-folder", "names a folder", argv=_out("newdir/"))
case("orthorectify-line", "os", "output-existing-folder/", "names a folder", argv=_out("./"))
case(
    "orthorectify-line", "degenerate", "dem-E-repeats", "strictly increasing",
    [("dem.nc", nc_edit(_dem_e_repeats))], argv=_dem,
)  # fmt: skip
# output formats by extension: refuse what is not written
case("orthorectify-line", "output", "output-png", "name the file o.tif", argv=_out("o.png"))
case("orthorectify-line", "output", "output-no-extension", "name the file o.tif", argv=_out("o"))
# sizes a file declares, checked against the file; requests that cannot fit in memory
case(
    "adjust-bal", "size", "header-1e9-cameras", "header on line 1 declares",
    files=[(F, bal_line(1, "1000000000 5 40"))],
)  # fmt: skip
case(
    "adjust-bal", "size", "header-1e9-observations", "observation lines",
    files=[(F, bal_line(1, "2 5 1000000000"))],
)  # fmt: skip
case(
    "adjust-pushbroom", "size", "node-interval-1ms", "GiB of memory",
    argv=opt("--node-interval", "0.001"),
)  # fmt: skip
# silent wrong answers: a column named twice in every CSV, impossible sensor values, 1e300
for cmd, file, column in [
    ("calibrate-line", "obs.csv", "zeta_px"),
    ("calibrate-line", "control.csv", "x_m"),
    ("adjust-pushbroom", "obs.csv", "x_px"),
    ("adjust-pushbroom", "nav.csv", "roll_deg"),
    ("adjust-pushbroom", "gcp.csv", "H_m"),
    ("orthorectify-line", "nav.csv", "E_m"),
    ("mtf", "profiles.csv", "intensity_dn"),
]:
    case(cmd, "duplicates", f"{file}-column-{column}-twice", f"{column} 2 times",
         [(file, column_twice(column))])  # fmt: skip
for key, value in [
    ("zeta0_px", "900.0"),  # off the LINES file's pixels (200 ... 796), views still < 80 deg
    ("zeta0_px", "-50.0"),
]:
    case("orthorectify-line", "units", f"sensor-{key}={value}-off-the-line", "principal point",
         [("sensor.toml", toml_set("sensor", key, value))])  # fmt: skip
for key, value in [
    ("lever_arm_m", "[100.0, 0.0, -200.0]"),  # in mm
    ("c_mm", "40000.0"),  # in um
    ("x0_mm", "500.0"),
    ("sigma_lever_m", "20.0"),
]:
    case("adjust-pushbroom", "units", f"cam-{key}={value}", f"{key}",
         [("cam.toml", toml_set("camera", key, value))])  # fmt: skip
case(
    "adjust-bal", "range", "observation-1e300", "beyond",
    files=[(F, bal_line(5, "0 0 1e300 2.0"))],
)  # fmt: skip
# messages that named the wrong cause
case(
    "adjust-bal", "degenerate", "all-points-behind", "behind",
    files=[(F, lambda p: _bal_points_behind(p))],
)  # fmt: skip

case(
    "adjust-pushbroom", "units", "nav-and-obs-times-in-ms", "milliseconds",
    [("nav.csv", scale_column("t_s", 1e3)), ("obs.csv", scale_column("t_s", 1e3))],
)  # fmt: skip
case(
    "adjust-pushbroom", "units", "nav-times-in-ms", "milliseconds",
    [("nav.csv", scale_column("t_s", 1e3))],
)  # fmt: skip
case(
    "orthorectify-line", "units", "nav-upside-down", "navigation's attitude",
    [("nav.csv", lambda p: _add_to_column(p, "roll_deg", 180.0))],
)  # fmt: skip
case(
    "calibrate-frame", "mismatch", "board-aruco-grid-same-dictionary", "board type other",
    [("board.toml", text(
        "[board]\ntype = 'aruco_grid'\ndictionary = 'DICT_6X6_250'\nmarkers_x = 5\n"
        "markers_y = 7\nmarker_mm = 20.0\nseparation_mm = 5.0\n"))],
)  # fmt: skip
case(
    "orthorectify-line", "empty", "lines-zero-lines", "length 0",
    [("lines.nc", nc_edit(lambda ds: ds.isel(line=slice(0, 0))))],
)  # fmt: skip


# --- orthorectify: an ENVI cube of a view-angle line scanner (issue 38) ----------------------
C = "orthorectify-envi"


def _cut(n_bytes: int):
    def edit(p: Path):
        p.write_bytes(p.read_bytes()[:-n_bytes])

    return edit


def _hdr_set(key: str, value: str):
    def edit(p: Path):
        lines = [ln for ln in p.read_text().splitlines() if not ln.startswith(key + " =")]
        p.write_text("\n".join([*lines, f"{key} = {value}"]) + "\n")

    return edit


case(C, "size", "envi-truncated", "cut short", [("cube.raw", _cut(1000))])
case(C, "size", "envi-one-byte-more", "larger than its header",
     [("cube.raw", lambda p: p.write_bytes(p.read_bytes() + b"\0"))])  # fmt: skip
case(C, "size", "hdr-samples-disagree", "header says", [("cube.hdr", _hdr_set("samples", "149"))])
case(C, "size", "hdr-lines-disagree", "header says", [("cube.hdr", _hdr_set("lines", "41"))])
case(C, "size", "hdr-bands-disagree", "header says", [("cube.hdr", _hdr_set("bands", "3"))])
case(
    C, "size", "hdr-data-type-disagrees", "header says", [("cube.hdr", _hdr_set("data type", "5"))]
)
case(C, "units", "hdr-byte-order-2", "byte order", [("cube.hdr", _hdr_set("byte order", "2"))])
case(C, "units", "hdr-interleave-xyz", "interleave", [("cube.hdr", _hdr_set("interleave", "xyz"))])
case(C, "missing", "hdr-missing", "no header beside it", [("cube.hdr", remove)])
case(C, "empty", "envi-empty", "cut short", [("cube.raw", text(""))])
case(C, "mismatch", "times-shorter-than-lines", "times.txt", [("times.txt", drop_last_lines(1))])
case(C, "mismatch", "times-longer-than-lines", "41 times", [("times.txt", text_append("99.0"))])
case(C, "degenerate", "times-not-increasing", "does not increase",
     [("times.txt", lambda p: p.write_text(p.read_text().replace("0.625", "0.5")))])  # fmt: skip


def _garbage_line_3(p: Path):
    rows = p.read_text().splitlines()
    rows[2] = "abc"
    p.write_text("\n".join(rows) + "\n")


case(C, "garbage", "times-garbage", "line 3", [("times.txt", _garbage_line_3)])
case(C, "missing", "times-missing", "times file", [("times.txt", remove)])
case(C, "missing", "no-times-anywhere", "no line times", argv=opt("--line-times"))
case(C, "options", "line-times-twice", "one times file per cube",
     argv=flag("--line-times", "x.txt"))  # fmt: skip
case(C, "mismatch", "angles-one-pixel-short", "150 samples", [("angles.csv", keep_rows(149))])
case(C, "units", "angles-in-radians", "radians",
     [("angles.csv", chain_edits(scale_column("across_deg", np.pi / 180),
                                 scale_column("along_deg", np.pi / 180)))])  # fmt: skip
case(C, "duplicates", "angles-row-twice", "repeats line", [("angles.csv", duplicate_row(5))])
case(
    C,
    "duplicates",
    "angles-pixel-twice",
    "appears twice",
    [("angles.csv", set_cell("pixel", "6", 5))],
)
case(C, "degenerate", "angles-not-monotone", "monotonically",
     [("angles.csv", set_cell("across_deg", "30.0", 5))])  # fmt: skip
case(C, "mismatch", "lines-mix-envi-and-netcdf", "mixes ENVI",
     argv=lambda a, d: [a[0], a[1], str(d / "nav.csv.nc"), *a[2:]])  # fmt: skip


def _add_to_column(p: Path, column: str, value: float):
    h, rows = read_csv(p)
    j = h.index(column)
    for r in rows:
        r[j] = repr(float(r[j]) + value)
    write_csv(p, h, rows)


def _bal_points_behind(p: Path):
    """Every point mirrored through its cameras (all of them behind every camera)."""
    from hsgeo.io.bal import read_bal

    prob = read_bal(p)
    lines = p.read_text().splitlines()
    n = 1 + prob.n_observations + 9 * prob.n_cameras
    C = prob.cameras
    from hsgeo.rotations import R_from_rotvec

    R = R_from_rotvec(C[:, :3])
    centre = -np.einsum("nji,nj->ni", R, C[:, 3:6]).mean(axis=0)
    pts = 2 * centre - prob.points
    p.write_text("\n".join(lines[:n] + [repr(float(v)) for v in pts.ravel()]) + "\n")


# --- orthorectify: frames of the Rikola and of an OpenCV camera (issue 36) -------------------
C = "orthorectify-frames"


def _frames_csv(edit):
    def f(p: Path):
        p.write_text(edit(p.read_text()))

    return f


case(C, "missing", "frame-without-exposure-time", "has no exposure time in --frame-times",
     [("frames.csv", _frames_csv(lambda t: t.replace("f1.raw,5.0,1\n", "")))])  # fmt: skip
case(C, "mismatch", "frame-time-outside-the-navigation", "column time_s",
     [("frames.csv", _frames_csv(lambda t: t.replace("5.0,1", "50.0,1")))])  # fmt: skip
case(C, "mismatch", "frame-size-not-the-sensors", "image_size_px = [40, 31]",
     [("rikola.toml", _frames_csv(lambda t: t.replace("[40, 30]", "[40, 31]")))])  # fmt: skip
case(C, "mismatch", "rikola-band-not-in-the-sensor-file", "names band 7",
     [("frames.csv", _frames_csv(lambda t: t.replace("4.05,2", "4.05,7")))])  # fmt: skip
case(C, "mismatch", "rikola-frame-with-a-band-too-many", "a layer of the frame must be a band",
     [("rikola.toml", _frames_csv(lambda t: t.replace("f_band_mm = [8.7, 8.8]\nband_sensor = "
                                                     "[1, 2]\nbands = [1, 2]",
                                                     "f_band_mm = [8.7]\nband_sensor = [1]\n"
                                                     "bands = [1]"))),
      ("frames.csv", _frames_csv(lambda t: t.replace("f0.raw,4.05,2\n", "")
                                           .replace("f1.raw,5.05,2\n", "")))])  # fmt: skip
case(C, "options", "frame-sensor-given-line-times", "--line-times",
     argv=flag("--line-times", "x.txt"))  # fmt: skip
case(C, "missing", "frame-sensor-without-frame-times", "give the frames' exposure times",
     argv=opt("--frame-times"))  # fmt: skip
case(C, "missing", "frame-times-without-time_s", "time_s",
     [("frames.csv", _frames_csv(lambda t: t.replace("time_s", "t")))])  # fmt: skip


def _sensor(name: str):
    return lambda a, d: opt("--sensor", str(d / name))(a, d)


case(C, "options", "scanning-sensor-given-frame-times", "--frame-times is for the frames",
     [("pano.toml", text("[sensor]\nmodel = 'panoramic'\nn_px = 40\n"))],
     argv=_sensor("pano.toml"))  # fmt: skip
case(C, "mismatch", "opencv-band-column", "column band is for the Rikola",
     argv=_sensor("cv.toml"))  # fmt: skip


# --- orthorectify: LP strips -----------------------------------------------------------------
C = "orthorectify-strips"


def _h5_edit(fn):
    """Rewrite an LP line file (NetCDF-4) through ``fn(Dataset) -> Dataset``."""

    def edit(p: Path) -> None:
        import xarray as xr

        with xr.open_dataset(p, engine="h5netcdf") as ds:
            new = fn(ds.load())
        p.unlink()
        new.to_netcdf(p, engine="h5netcdf")

    return edit


def _tif_edit(fn):
    """Rewrite the DSM GeoTIFF through ``fn(z, transform, crs) -> (z, transform, crs)``."""

    def edit(p: Path) -> None:
        import rasterio

        with rasterio.open(p) as src:
            z, t, crs = fn(src.read(1), src.transform, src.crs)
        p.unlink()
        with rasterio.open(
            p, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1,
            dtype=z.dtype, crs=crs, transform=t,
        ) as dst:  # fmt: skip
            dst.write(z, 1)

    return edit


def _json_edit(fn):
    """Rewrite the adjust-pushbroom result through ``fn(dict)`` (in place)."""

    def edit(p: Path) -> None:
        d = json.loads(p.read_text())
        fn(d)
        p.write_text(json.dumps(d))

    return edit


def _set(path: str, value):
    """``d[a][b]... = value`` for ``path`` 'a.b...' (a list index as a number)."""

    def f(d):
        *head, last = path.split(".")
        for k in head:
            d = d[int(k)] if isinstance(d, list) else d[k]
        d[int(last) if isinstance(d, list) else last] = value

    return f


def _uneven_nodes(d):
    d["nodes"]["t_s"][3] += 2.5


NAV_S = ["t_s", "E_m", "N_m", "U_m", "roll_deg", "pitch_deg", "heading_deg"]
table_file_cases(C, "nav.csv", "navigation", NAV_S, "camera.toml")
case(C, "duplicates", "nav-duplicate-time", "t_s", [("nav.csv", duplicate_row(5))])
case(C, "degenerate", "nav-times-decreasing", "t_s", [("nav.csv", swap_rows(5, 6))])
case(C, "degenerate", "nav-not-covering", "navigation", [("nav.csv", keep_rows(100))])
case(C, "degenerate", "nav-gap", "--max-nav-gap-s", [("nav.csv", delete_rows(100, 200))])
case(C, "units", "nav-east-in-mm", "jumps", [("nav.csv", scale_column("E_m", 1000.0))])
case(C, "units", "nav-times-in-ms", "t_s", [("nav.csv", scale_column("t_s", 1000.0))])
# LINES
for f in ("s1.nc", "s2.nc"):
    case(C, "missing", f"{f}-missing", f, [(f, remove)])
    case(C, "binary", f"{f}-binary", f, [(f, text(BINARY))])
f = "s1.nc"
case(C, "missing", f"{f}-directory", f, [(f, make_dir)])
case(C, "empty", f"{f}-empty", f, [(f, text(""))])
case(C, "garbage", f"{f}-text", f, [(f, text("hello world\n"))])
case(C, "binary", f"{f}-hdf5-garbage", f, [(f, text(b"\x89HDF\r\n\x1a\n" + BINARY))])
case(C, "binary", f"{f}-truncated", f, [(f, lambda p: p.write_bytes(p.read_bytes()[:4000]))])
case(C, "mistyped", f"{f}-a-csv", f, [(f, copy_from("nav.csv"))])
case(C, "mistyped", f"{f}-the-dsm", f, [(f, copy_from("dsm.tif"))])
for var in ("lines", "t_s", "wavelength_nm"):
    case(C, "mistyped", f"{f}-no-{var}", var, [(f, _h5_edit(lambda ds, v=var: ds.drop_vars(v)))])
case(
    C, "mistyped", f"{f}-no-col0", "col0",
    [(f, _h5_edit(lambda ds: _drop_attr_lp(ds, "col0")))],
)  # fmt: skip
case(
    C, "nonfinite", f"{f}-t_s-nan", "t_s",
    [(f, _h5_edit(lambda ds: ds.assign(t_s=ds["t_s"].where(ds["line"] != 3))))],
)  # fmt: skip
case(
    C, "degenerate", f"{f}-t_s-out-of-order", "line times must increase",
    [(f, _h5_edit(lambda ds: ds.assign(t_s=("line", _swap_two(ds["t_s"].values)))))],
)  # fmt: skip
case(
    C, "degenerate", f"{f}-zero-lines", f,
    [(f, _h5_edit(lambda ds: ds.isel(line=slice(0, 0))))],
)  # fmt: skip
case(
    C, "mismatch", "strips-other-bands", "bands differ",
    [("s2.nc", _h5_edit(lambda ds: ds.assign(wavelength_nm=ds["wavelength_nm"] + 30.0)))],
)  # fmt: skip
case(
    C, "mismatch", "strips-other-n_px_full", "n_px_full",
    [("s2.nc", _h5_edit(lambda ds: _set_attr(ds, "n_px_full", 600)))],
)  # fmt: skip
case(
    C, "range", f"{f}-col0-beyond-the-line", "n_px_full",
    [(f, _h5_edit(lambda ds: _set_attr(ds, "col0", 100)))],
)  # fmt: skip
case(C, "duplicates", "strip-twice", "twice", argv=lambda a, d: [a[0], a[1], *a[1:]])
case(
    C, "degenerate", "lines-after-navigation", "navigation",
    [(f, _h5_edit(lambda ds: ds.assign(t_s=ds["t_s"] + 1000.0)))],
)  # fmt: skip
# CAMERA
case(C, "missing", "cam-missing", "camera.toml", [("camera.toml", remove)])
case(C, "empty", "cam-empty", "model", [("camera.toml", text(""))])
case(C, "garbage", "cam-garbage", "camera.toml", [("camera.toml", text("[camera\nn_bands = \n"))])
case(C, "binary", "cam-binary", "camera.toml", [("camera.toml", text(BINARY))])
case(C, "mistyped", "cam-is-csv", "camera.toml", [("camera.toml", copy_from("nav.csv"))])
for key, value, kind in [
    ("n_bands", "0", "range"),
    ("n_bands", "3", "mismatch"),
    ("pixel_mm", "-0.0065", "range"),
    ("pixel_mm", "6.5", "units"),
    ("c_mm", "nan", "nonfinite"),
    ("c_mm", None, "missing"),
]:
    case(C, kind, f"cam-{key}={value}", key, [("camera.toml", toml_set("camera", key, value))])
case(
    C, "mistyped", "cam-pixel-mm-misspelled", "pixel_mm",
    [("camera.toml", toml_rename("pixel_mm", "pixel_size_mm"))],
)  # fmt: skip
# RESULT.json of adjust-pushbroom
R = "result.json"
case(C, "missing", "adjustment-missing", R, [(R, remove)])
case(C, "empty", "adjustment-empty", R, [(R, text(""))])
case(C, "garbage", "adjustment-garbage", R, [(R, text("{'converged': true,"))])
case(C, "binary", "adjustment-binary", R, [(R, text(BINARY))])
case(C, "mistyped", "adjustment-a-list", R, [(R, text("[1, 2, 3]\n"))])
case(C, "mistyped", "adjustment-is-toml", R, [(R, copy_from("camera.toml"))])
case(C, "mistyped", "adjustment-no-nodes", "nodes", [(R, _json_edit(lambda d: d.pop("nodes")))])
case(
    C, "degenerate", "adjustment-not-converged", "did not converge",
    [(R, _json_edit(lambda d: d.update(converged=False)))],
)  # fmt: skip
for path, value, kind, expect in [
    ("parameters.boresight_deg.value", [0.0, 0.0], "type", "boresight"),
    ("parameters.boresight_deg.value", [0.0, "a", 0.0], "type", "boresight"),
    ("parameters.boresight_deg.value", [1e300, 0.0, 0.0], "range", "boresight"),
    ("parameters.lever_arm_m.value", [float("nan"), 0.0, 0.0], "nonfinite", "lever_arm_m"),
    ("parameters.c_mm.value", [40.0, 40.0], "mismatch", "c_mm"),
    ("parameters.c_mm.value", [-40.0], "range", "c_mm"),
    ("parameters.distortion.value", [0.0], "type", "distortion"),
    ("nodes.columns", ["E", "N", "U", "r", "p", "h"], "mistyped", "columns"),
    ("nodes.value.2.0", float("nan"), "nonfinite", "nodes"),
    ("nodes.value.2.0", 1e300, "range", "nodes"),
    ("nodes.t_s.0", float("nan"), "nonfinite", "t_s"),
]:
    case(C, kind, f"adjustment-{path}={value}", expect, [(R, _json_edit(_set(path, value)))])
case(C, "degenerate", "adjustment-nodes-uneven", "evenly", [(R, _json_edit(_uneven_nodes))])
case(
    C, "mismatch", "adjustment-nodes-not-covering", "node times of --adjustment",
    [(R, _json_edit(lambda d: d["nodes"].update(t_s=[t + 500.0 for t in d["nodes"]["t_s"]])))],
)  # fmt: skip
case(
    C, "degenerate", "adjustment-three-nodes", "nodes",
    [(R, _json_edit(lambda d: d["nodes"].update(t_s=d["nodes"]["t_s"][:3],
                                                 value=d["nodes"]["value"][:3])))],
)  # fmt: skip
# DSM
case(C, "missing", "dsm-missing", "dsm.tif", [("dsm.tif", remove)])
case(C, "missing", "dsm-directory", "dsm.tif", [("dsm.tif", make_dir)])
case(C, "empty", "dsm-empty", "dsm.tif", [("dsm.tif", text(""))])
case(C, "garbage", "dsm-text", "dsm.tif", [("dsm.tif", text("hello world\n"))])
case(C, "binary", "dsm-binary", "dsm.tif", [("dsm.tif", text(BINARY))])
case(C, "mistyped", "dsm-is-lines", "dsm.tif", [("dsm.tif", copy_from("s1.nc"))])
case(C, "mistyped", "dsm-no-crs", "CRS", [("dsm.tif", _tif_edit(lambda z, t, c: (z, t, None)))])
case(
    C, "mismatch", "dsm-wgs84-utm", "EPSG:32632",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z, t, "EPSG:32632")))],
)  # fmt: skip
case(
    C, "mismatch", "dsm-geographic", "EPSG:4326",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z, t, "EPSG:4326")))],
)  # fmt: skip
case(
    C, "degenerate", "dsm-not-covering", "outside --dsm",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z[:40, :40], t, c)))],
)  # fmt: skip
case(
    C, "nonfinite", "dsm-all-nan", "dsm",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z * np.nan, t, c)))],
)  # fmt: skip
case(
    C, "nonfinite", "dsm-nan-under-the-strips", "dsm",
    [("dsm.tif", _tif_edit(lambda z, t, c: (_nan_middle(z), t, c)))],
)  # fmt: skip
case(
    C, "units", "dsm-heights-in-mm", "dsm",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z * 1000.0, t, c)))],
)  # fmt: skip
case(
    C, "degenerate", "dsm-rotated", "north-up",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z, t * t.rotation(10.0), c)))],
)  # fmt: skip
case(
    C, "degenerate", "dsm-south-up", "north-up",
    [("dsm.tif", _tif_edit(lambda z, t, c: (z, t * t.scale(1.0, -1.0), c)))],
)  # fmt: skip
# options
for o, vals in {
    "--resolution": ["0", "-1", "nan", "inf", "abc"],
    "--line-pixels": ["0", "1.5", "abc"],
    "--max-nav-gap-s": ["0", "-1", "nan"],
    "--bands": ["red", "-640", "", "640,,460"],
}.items():
    for v in vals:
        case(C, "options", f"{o}={v}", o, argv=opt(o, v))
case(C, "options", "bands-1200", "--bands 1200", argv=opt("--bands", "640,1200"))
case(C, "options", "bands-in-um", "--bands", argv=opt("--bands", "0.64,0.55,0.46"))
case(C, "options", "line-pixels-299", "--line-pixels", argv=opt("--line-pixels", "299"))
case(C, "degenerate", "resolution-1mm", "--resolution", argv=opt("--resolution", "0.001"))
case(C, "degenerate", "resolution-1e-9", "--resolution", argv=opt("--resolution", "1e-9"))
case(C, "degenerate", "resolution-10km", "--resolution", argv=opt("--resolution", "10000"))
case(C, "options", "scheduler-not-an-address", "--scheduler", argv=opt("--scheduler", "nowhere"))
case(C, "options", "scheduler-bad-port", "--scheduler", argv=opt("--scheduler", "tcp://x:port"))
for o in ("--trajectory", "--sensor", "-o"):
    case(C, "options", f"no-{o}", o, argv=opt(o))
case(C, "options", "no--dsm", "--dsm --height", argv=opt("--dsm"))
case(C, "options", "no-lines", "LINES", argv=lambda a, d: [a[0], *a[3:]])
case(C, "options", "unknown-option", "--dem", argv=flag("--dem", "x.tif"))
case(C, "options", "unknown-mosaic-rule", "--mosaic", argv=flag("--mosaic", "median"))
case(
    C,
    "options",
    "camera-is-now-sensor",
    "--sensor",
    argv=replace_arg("--sensor", lambda d: "--camera"),
)
# outputs
for name in ("s1.nc", "nav.csv", "camera.toml", "dsm.tif", "result.json"):
    case(
        C,
        "output",
        f"output-is-{name}",
        name,
        argv=lambda a, d, n=name: opt("-o", str(d / n))(a, d),
    )
case(
    C, "output", "output-is-dsm-overwrite", "dsm.tif",
    argv=lambda a, d: flag("--overwrite")(opt("-o", str(d / "dsm.tif"))(a, d), d),
)  # fmt: skip
case(C, "output", "output-exists", "--overwrite", argv=lambda a, d: _touch_output(a, d))
case(C, "output", "output-png", "mosaic.tif", argv=_out("mosaic.png"))
case(C, "output", "output-no-extension", "mosaic.tif", argv=_out("mosaic"))
case(C, "output", "output-dir-missing", "does-not-exist", argv=_out("does-not-exist/m.tif"))
case(C, "output", "output-is-directory", "folder", argv=_out("./"))
case(C, "output", "output-dir-readonly", "writ", argv=lambda a, d: _readonly_tif(a, d))


def _swap_two(t):
    """Two line times exchanged: neither increasing nor decreasing (lines stored last first
    are read in time order, issue 42)."""
    t = t.copy()
    t[[3, 4]] = t[[4, 3]]
    return t


def _drop_attr_lp(ds, a):
    ds.attrs.pop(a, None)
    return ds


def _readonly_tif(a, d):
    ro = d.parent / "readonly"
    ro.mkdir()
    ro.chmod(0o555)
    return opt("-o", str(ro / "m.tif"))(a, d)


def _nan_middle(z):
    z = z.copy()
    n, m = z.shape
    z[n // 2 - 20 : n // 2 + 20, :] = np.nan
    return z


# --- issue 42's classes not covered above (tests/test_bad_input_classes.py lists them all) -----
def _semicolons(p: Path) -> None:
    """The table as a spreadsheet in a comma-decimal locale saves it: ';' between the columns."""
    p.write_text(p.read_text().replace(",", ";"))


def _as_parquet_text(column: str):
    """The CSV table as Parquet (same name, .parquet beside it) with ``column`` stored as text."""

    def edit(p: Path) -> None:
        import pandas as pd

        df = pd.read_csv(p)
        df[column] = df[column].astype(str)
        df.to_parquet(p.with_suffix(".parquet"))

    return edit


def _as_parquet_datetime(column: str):
    def edit(p: Path) -> None:
        import pandas as pd

        df = pd.read_csv(p)
        df[column] = pd.to_datetime(df[column], unit="s")
        df.to_parquet(p.with_suffix(".parquet"))

    return edit


def _csv_frame(fn):
    """Rewrite a CSV table through ``fn(DataFrame) -> DataFrame`` (17 digits)."""

    def edit(p: Path) -> None:
        import pandas as pd

        fn(pd.read_csv(p)).to_csv(p, index=False, float_format="%.17g")

    return edit


def _to_parquet_argv(name: str):
    return lambda a, d: [x.replace(name, Path(name).stem + ".parquet") for x in a]


_BORESIGHT_RAD = "[0.005235987755982988, -0.003490658503988659, 0.0017453292519943296]"

# separators other than the comma: the cause, not "rename 'a;b' to 'b'" (a wrong cause before)
for cmd, file in [
    ("calibrate-line", "obs.csv"),
    ("adjust-pushbroom", "obs.csv"),
    ("adjust-pushbroom", "nav.csv"),
    ("adjust-pushbroom", "gcp.csv"),
    ("lp-observations", "squares.csv"),
    ("lp-observations", "nav.csv"),
    ("orthorectify-strips", "nav.csv"),
    ("mtf", "profiles.csv"),
    ("asf", "runway.csv"),
]:
    case(cmd, "mistyped", f"{file}-semicolons", "separated by semicolons", [(file, _semicolons)])
case("mtf", "mistyped", "profiles-tabs", "separated by tabs",
     [("profiles.csv", lambda p: p.write_text(p.read_text().replace(",", "\t")))])  # fmt: skip
# a file of another format under a table's name: the format named ("binary or not UTF-8")


def _parquet_named_csv(p: Path) -> None:
    import pandas as pd

    df = pd.read_csv(p)
    p.unlink()
    df.to_parquet(p)


case("mtf", "mistyped", "profiles-parquet-named-csv", "a Parquet table",
     [("profiles.csv", _parquet_named_csv)])  # fmt: skip
case("mtf", "mistyped", "profiles-utf-16", "UTF-16",
     [("profiles.csv", lambda p: p.write_bytes(p.read_text().encode("utf-16")))])  # fmt: skip
case("mtf", "mistyped", "profiles-a-zip", "ZIP archive",
     [("profiles.csv", text(b"PK\x03\x04" + BINARY))])  # fmt: skip
case("mtf", "mistyped", "profiles-csv-named-parquet", "is text",
     [("profiles.csv", lambda p: shutil.copy(p, p.with_suffix(".parquet")))],
     argv=_to_parquet_argv("profiles.csv"))  # fmt: skip
# a Parquet column's stored type: text or dates where numbers are meant (exit 0 before)
case(
    "adjust-pushbroom", "type", "obs-parquet-t_s-as-text", "stored as",
    [("obs.csv", _as_parquet_text("t_s"))], argv=_to_parquet_argv("obs.csv"),
)  # fmt: skip
case(
    "adjust-pushbroom", "type", "obs-parquet-t_s-as-dates", "dates or durations",
    [("obs.csv", _as_parquet_datetime("t_s"))], argv=_to_parquet_argv("obs.csv"),
)  # fmt: skip
case(
    "mtf", "type", "profiles-parquet-intensity-as-text", "stored as",
    [("profiles.csv", _as_parquet_text("intensity_dn"))], argv=_to_parquet_argv("profiles.csv"),
)  # fmt: skip
# mtf: 8-bit profiles against a 12-bit bar file (exit 0, or a dark-level cause, before)
case(
    "mtf", "units", "profiles-8-bit", "8-bit",
    [("profiles.csv", _csv_frame(
        lambda df: df.assign(intensity_dn=np.minimum(np.round(df["intensity_dn"] / 16), 255))))],
)  # fmt: skip


def _bars_reversed(p: Path) -> None:
    """The bar file's groups listed fine first (the profile's order is coarse first)."""
    import re

    def rev(m):
        return m.group(1) + "[" + ", ".join(v.strip() for v in m.group(2).split(",")[::-1]) + "]"

    text = re.sub(r"(pair_mm = )\[([^\]]*)\]", rev, p.read_text())
    p.write_text(re.sub(r"(n_pairs = )\[([^\]]*)\]", rev, text))


case("mtf", "degenerate", "bars-in-reverse-order", "reverse order", [("bars.toml", _bars_reversed)])
# lp-observations: answers on wrong input (exit 0 before)
C = "lp-observations"
case(
    C, "mismatch", "strips-other-wavelengths", "bands differ",
    [("s1.nc", _h5_edit(lambda ds: ds.assign(wavelength_nm=ds["wavelength_nm"] + 30.0)))],
)  # fmt: skip
case(
    C, "degenerate", "nav-gap-under-a-strip", "--max-nav-gap-s",
    [("nav.csv", _csv_frame(lambda df: df[(df["t_s"] < 304.0) | (df["t_s"] > 305.3)]))],
)  # fmt: skip
case(
    C, "degenerate", "nav-shifted-2-s", "not shifted",
    [("nav.csv", _csv_frame(lambda df: df.assign(t_s=df["t_s"] + 2.0)))],
)  # fmt: skip
case(
    C, "units", "cam-boresight-in-radians", "are radians",
    [("cam.toml", toml_set("camera", "boresight_deg", _BORESIGHT_RAD))],
)  # fmt: skip
case(
    C, "degenerate", "squares-far-off", "none of the 17 squares",
    [("squares.csv", _csv_frame(lambda df: df.assign(E_m=df["E_m"] + 5000.0)))],
)  # fmt: skip
case(
    C, "units", "squares-in-lon-lat", "longitude/latitude",
    [("squares.csv", _csv_frame(
        lambda df: df.assign(E_m=10.775 + df["E_m"] / 56e3, N_m=59.665 + df["N_m"] / 111e3)))],
)  # fmt: skip
case(
    C, "units", "squares-heights-in-mm", "in mm",
    [("squares.csv", _csv_frame(lambda df: df.assign(H_m=df["H_m"] * 1000.0)))],
)  # fmt: skip
# a camera unit off by 10: the field of view named (only "too short, poor texture, too far off")
case(
    C, "units", "cam-c-in-cm", "field of view",
    [("cam.toml", toml_set("camera", "c_mm", "4.0"))],
)  # fmt: skip
case(
    C, "units", "cam-pixel-in-10-um", "field of view",
    [("cam.toml", toml_set("camera", "pixel_mm", "0.065"))],
)  # fmt: skip
# --height far from the ground the strips see (without --squares: 39 instead of 689
# observations at 1000 m, exit 0 before): the tie points' rays meet near 11 m. Where the
# footprints on that plane are too far off for any scene pair to match (1000 m on the textured
# ground of 5f8a3ec), the refusal comes before the tie points: either message names --height
for h in ("1000", "-600", "400"):
    case(
        C, "degenerate", f"height-{h}-m-over-ground-at-0-m", "--height",
        argv=chain(opt("--squares"), opt("--height", h)),
    )  # fmt: skip
# the squares' heights 500 m off (another vertical datum?): the mean H_m named
case(
    C, "degenerate", "squares-heights-500-m-off", "mean H_m of the squares",
    [("squares.csv", _csv_frame(lambda df: df.assign(H_m=df["H_m"] + 500.0)))],
)  # fmt: skip
# orthorectify: a DSM of three bands (band 1 read as heights, exit 0 before)
C = "orthorectify-strips"


def _three_bands(z, t, c):
    return np.stack([z, z, z]), t, c


def _tif_bands_edit(fn):
    """Rewrite the DSM GeoTIFF through ``fn(z, transform, crs)``, any number of bands."""

    def edit(p: Path) -> None:
        import rasterio

        with rasterio.open(p) as src:
            z, t, crs = fn(src.read(1), src.transform, src.crs)
        z = np.atleast_3d(z) if z.ndim == 3 else z[None]
        p.unlink()
        with rasterio.open(
            p, "w", driver="GTiff", width=z.shape[2], height=z.shape[1], count=z.shape[0],
            dtype=z.dtype, crs=crs, transform=t,
        ) as dst:  # fmt: skip
            dst.write(z)

    return edit


case(C, "mistyped", "dsm-three-bands", "3 bands", [("dsm.tif", _tif_bands_edit(_three_bands))])


def _scheduler_http(a, d):
    """--scheduler at a port that answers, but HTTP (a traceback after 20 s before)."""
    import http.server
    import threading

    srv = http.server.HTTPServer(("127.0.0.1", 0), http.server.BaseHTTPRequestHandler)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    return opt("--scheduler", f"tcp://127.0.0.1:{srv.server_address[1]}")(a, d)


case(C, "options", "scheduler-an-http-port", "--scheduler", argv=_scheduler_http)


# ---------------------------------------------------------------------------------------------
# running


@pytest.fixture(scope="session")
def valid(tmp_path_factory) -> Path:
    """The folder of every command's valid inputs, one per session: the pytest-xdist workers
    share it (the parent of a worker's base temporary directory is the session's); each
    command's folder is written on first use (:func:`valid_inputs`)."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    return base / "valid"


def _sha(root: Path) -> dict:
    return {
        p.relative_to(root): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and "__pycache__" not in p.parts
    }


def _tree(root: Path) -> dict:
    """Every file (its SHA-256) and folder under ``root``, readable or not."""
    out = {}
    for p in sorted(root.rglob("*")):
        if "__pycache__" in p.parts:
            continue
        try:
            out[str(p.relative_to(root))] = (
                "dir" if p.is_dir() else hashlib.sha256(p.read_bytes()).hexdigest()
            )
        except OSError:  # a file the case made unreadable
            out[str(p.relative_to(root))] = "unreadable"
    return out


@dataclass
class Inputs:
    dir: Path
    before: dict


@pytest.fixture
def inputs(tmp_path, valid, request, monkeypatch):
    """A copy of the command's valid inputs; their SHA-256 must be unchanged afterwards.

    The working directory is a fresh folder (``hsgeo data`` writes under it).
    """
    cmd = request.node.callspec.params.get("cmd") if hasattr(request.node, "callspec") else None
    c = request.node.callspec.params.get("case") if hasattr(request.node, "callspec") else None
    cmd = c.cmd if c is not None else cmd
    d = tmp_path / "in"
    src = valid_inputs(valid, cmd) if cmd is not None else None
    if src is not None:
        shutil.copytree(src, d)
    else:
        d.mkdir()
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    holder = Inputs(d, {})
    yield holder
    for p in tmp_path.rglob("*"):  # readonly folders made by the cases
        if p.is_dir():
            p.chmod(0o755)
    after = _sha(d)
    changed = [str(p) for p, h in holder.before.items() if after.get(p) != h]
    assert not changed, f"input files changed or removed: {changed}"
    parts = [str(p) for p in tmp_path.rglob("*.part")]
    assert not parts, f"partial files left: {parts}"


def run_cli(argv, capsys) -> tuple[int, str, str]:
    from hsgeo.cli import main

    try:
        rc = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def _outputs(argv) -> list[str]:
    """The files a command line asks to write (-o, --output, --envi and its .hdr)."""
    out = []
    for i, a in enumerate(argv[:-1]):
        if a in ("-o", "--output", "--envi"):
            out.append(str(argv[i + 1]))
            if a == "--envi":
                out.append(str(argv[i + 1]) + ".hdr")
    return out


# issue 42: a heading 180° off (mirrored ground points and exit 0 before) — geo38
for _cmd in ("lp-observations", "adjust-pushbroom"):
    case(
        _cmd, "units", "nav-heading-180-off", "opposite to the course",
        [("nav.csv", lambda p: _add_to_column(p, "heading_deg", 180.0))],
    )  # fmt: skip


# issue 38's formats (geo38): a per-band view-angle file of the wrong band count (was refused
# as 'line 152 repeats line 2': the band column was not part of a row), a header line period of 0
def _angles_per_band(n_bands: int):
    def edit(p: Path):
        import pandas as pd

        t = pd.read_csv(p)
        pd.concat([t.assign(band=b) for b in range(n_bands)]).to_csv(p, index=False)

    return edit


def _without_line_times(a, d):
    i = a.index("--line-times")
    return a[:i] + a[i + 2 :]


case(
    "orthorectify-envi", "mismatch", "angles-per-band-3-for-2-bands", "3 view-angle tables",
    [("angles.csv", _angles_per_band(3))],
)  # fmt: skip
case(
    "orthorectify-envi", "range", "hdr-line-period-0", "must be a positive number",
    [("cube.hdr", chain_edits(_hdr_set("start time_s", "0.0"), _hdr_set("line period_s", "0")))],
    argv=_without_line_times,
)  # fmt: skip


def _record(case: Case, rc, err: str, lines, tree: dict, left, changed) -> None:
    """With ``HSGEO_BAD_INPUT_RECORD=FILE``, append what the case did as one JSON line (every
    property, whichever assertion fails first): bench/issue42_audit.py counts them. ``tree``:
    the case's folder before the command (``in/`` its inputs), ``changed``: what differs after.
    """
    path = os.environ.get("HSGEO_BAD_INPUT_RECORD")
    if not path:
        return
    rec = {
        "id": case.id,
        "exit": rc,
        "traceback": "Traceback" in err or rc == 1,
        "answer": rc == 0,
        "inputs_modified": [k for k in changed if k.startswith("in") and tree.get(k) not in
                            (None, "dir")],
        "partial_outputs": sorted({str(a) for a in left} | {k for k in changed if
                                                            k.endswith(".part")}),
        "folder_changed": len(changed),
        "one_line": len(lines) == 1,
        "cause_named": bool(lines) and case.expect.lower() in lines[0].lower(),
    }  # fmt: skip
    with open(path, "a", encoding="utf-8") as f:
        f.write(json.dumps(rec) + "\n")


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case: Case, inputs: Inputs, capsys):
    if "readonly" in case.name and os.geteuid() == 0:
        pytest.skip("root writes into read-only folders")
    d = inputs.dir
    for name, edit in case.files:
        edit(d / name)
    argv = base_argv(case.cmd, d) if case.cmd != "hsgeo" else []
    if case.argv is not None:
        argv = case.argv(argv, d)
    inputs.before = _sha(d)
    fresh = [a for a in _outputs(argv) if not os.path.lexists(a)]
    root = d.parent  # the case's folder: inputs, outputs, working directory
    tree = _tree(root)
    rc, out, err = run_cli(argv, capsys)
    lines = err.splitlines()
    left = [a for a in fresh if os.path.lexists(a)]
    # issue 42: nothing written, changed or removed anywhere in the case's folder
    after = _tree(root)
    changed = sorted(k for k in set(tree) | set(after) if tree.get(k) != after.get(k))
    _record(case, rc, err, lines, tree, left, changed)
    assert not left, f"output left behind by a failing command: {left}"
    assert not changed, f"the case's folder changed: {changed[:10]}"
    assert rc == 2, f"exit {rc}; stderr: {err[-2000:]}"
    assert len(lines) == 1, f"{len(lines)} lines on stderr:\n{err[-3000:]}"
    assert "Traceback" not in err
    assert case.expect.lower() in lines[0].lower(), lines[0]
    # not a case that fails for a reason of the harness's making
    assert "unrecognized arguments" not in err or case.kind == "options", err
    if "--json" in argv:  # --json: one JSON object naming the error (issue 42), nothing else
        assert json.loads(out)["ok"] is False, f"stdout: {out[:500]}"
    else:
        assert out == "", f"stdout: {out[:500]}"


# --- benign variants still work --------------------------------------------------------------


def _crlf(p: Path):
    p.write_bytes(p.read_bytes().replace(b"\n", b"\r\n"))


def _bom(p: Path):
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())


def _reorder(p: Path):
    h, rows = read_csv(p)
    order = list(reversed(range(len(h))))
    write_csv(p, [h[i] for i in order], [[r[i] for i in order] for r in rows])


def _extra_column(p: Path):
    h, rows = read_csv(p)
    write_csv(p, [*h, "comment"], [[*r, "ok"] for r in rows])


def _parquet(p: Path):
    import pandas as pd

    pd.read_csv(p).to_parquet(p.with_suffix(".parquet"))


def _gray16(p: Path):
    import cv2

    img = cv2.imread(str(p), cv2.IMREAD_GRAYSCALE).astype(np.uint16) * 257
    p.unlink()
    cv2.imwrite(str(p.with_suffix(".png")), img)


def _npy_to_tiff(p: Path):
    """Every .npy frame of the folder of ``p`` as a 16-bit TIFF (exposures.csv renamed)."""
    from PIL import Image

    for f in sorted(p.parent.glob("*.npy")):
        Image.fromarray(np.load(f)).save(f.with_suffix(".tif"), format="TIFF")
        f.unlink()
    p.write_text(p.read_text().replace(".npy", ".tif"))


BENIGN = [
    ("calibrate-line", "crlf", [("obs.csv", _crlf), ("control.csv", _crlf)], None),
    ("calibrate-line", "bom", [("obs.csv", _bom), ("control.csv", _bom)], None),
    ("calibrate-line", "reordered", [("obs.csv", _reorder), ("control.csv", _reorder)], None),
    ("calibrate-line", "extra-column", [("obs.csv", _extra_column)], None),
    ("calibrate-line", "options", [], flag("--sigma-px", "0.2", "--reject-k", "5", "--json")),
    ("orthorectify-line", "crlf-nav", [("nav.csv", _crlf), ("sensor.toml", _crlf)], None),
    ("orthorectify-line", "bom-nav", [("nav.csv", _bom), ("sensor.toml", _bom)], None),
    ("orthorectify-line", "reordered-nav", [("nav.csv", _reorder)], None),
    ("orthorectify-line", "extra-column-nav", [("nav.csv", _extra_column)], None),
    ("orthorectify-line", "dem", [], _dem),
    (
        "orthorectify-strips",
        "crlf-bom-nav-json",
        [("nav.csv", _crlf), ("camera.toml", _bom)],
        flag("--json"),
    ),
    (
        "orthorectify-strips",
        "overwrite-existing",
        [],
        lambda a, d: flag("--overwrite")(_touch_output(a, d), d),
    ),
    (
        "orthorectify-line",
        "envi-and-overwrite",
        [],
        lambda a, d: flag("--overwrite")(_touch_envi(a, d), d),
    ),
    ("orthorectify-line", "cog", [], _out("o.tif")),
    (
        "orthorectify-line",
        "overwrite-existing",
        [],
        lambda a, d: flag("--overwrite")(_touch_output(a, d), d),
    ),
    (
        "adjust-pushbroom",
        "crlf-bom-reordered",
        [("obs.csv", _reorder), ("nav.csv", _crlf), ("gcp.csv", _bom)],
        flag("--json", "--accept-poor-fit"),
    ),
    (
        "adjust-pushbroom",
        "parquet-extra-columns",
        [("obs.csv", _extra_column), ("obs.csv", _parquet), ("gcp.csv", _extra_column)],
        lambda a, d: replace_arg("obs.csv", lambda d: d / "obs.parquet")(a, d) + ["--json"],
    ),
    ("calibrate-frame", "gray16-png", [(f"img_0{i}.jpg", _gray16) for i in range(3)], None),
    ("mtf", "crlf-bom-reordered", [("profiles.csv", _reorder), ("bars.toml", _crlf)], None),
    ("mtf", "json", [("profiles.csv", _bom)], flag("--json")),
    ("mtf-edge", "roi", [], flag("--roi", "10,10,150,190")),
    (
        "cube",
        "tiff-frames-envi",
        [("raw/exposures.csv", _npy_to_tiff)],
        lambda a, d: [x.replace("cube.nc", "cube.hdr") for x in a],
    ),
    (
        "cube",
        "binning-2-bil-json",
        [],
        lambda a, d: [x.replace("cube.nc", "cube.bil") for x in a] + ["--json"],
    ),
]


def _last_first(ds):
    """Lines stored last first, each with its own time (refused before, issue 42)."""
    return ds.isel(line=slice(None, None, -1))


def _nodata_corner(z, t, c):
    """A DSM with a nodata corner far from the strips (refused before, issue 42)."""
    z = z.astype(np.float32)
    z[:5, :5] = np.nan
    return z, t, c


# issue 42's benign inputs that were refused
BENIGN += [
    ("lp-observations", "strips-in-another-order", [],
     lambda a, d: [a[0], a[3], a[1], a[4], a[2], *a[5:]]),
    ("lp-observations", "strip-stored-last-first", [("s1.nc", _h5_edit(_last_first))], None),
    ("orthorectify-strips", "strip-stored-last-first", [("s1.nc", _h5_edit(_last_first))], None),
    ("orthorectify-strips", "dsm-nodata-corner", [("dsm.tif", _tif_edit(_nodata_corner))], None),
    # --height instead of the squares: the ground's (about 0 m; the tie points meet at 11 m)
    # and 150 m off it (8 % of the 1,860 m above ground: the same observations)
    ("lp-observations", "height-0-without-squares", [],
     chain(opt("--squares"), opt("--height", "0"))),
    ("lp-observations", "height-150-m-off", [], chain(opt("--squares"), opt("--height", "150"))),
]  # fmt: skip


@pytest.mark.parametrize("cmd,name,files,argv", BENIGN, ids=[f"{b[0]}:{b[1]}" for b in BENIGN])
def test_benign_variant(cmd, name, files, argv, inputs: Inputs, capsys):
    d = inputs.dir
    for f, edit in files:
        edit(d / f)
    a = base_argv(cmd, d)
    if cmd == "calibrate-frame":
        a = [cmd, *map(str, sorted(d.glob("img_*"))), "--board", str(d / "board.toml")]
    if argv is not None:
        a = argv(a, d)
    inputs.before = _sha(d)
    rc, out, err = run_cli(a, capsys)
    assert rc == 0, err[-3000:]
    assert "Traceback" not in err


@pytest.mark.parametrize("cmd", ["data"])
def test_data_writes_under_the_working_directory(cmd, inputs: Inputs, capsys):
    """``hsgeo data`` run outside the repository: the files go to --out, or without it to
    ./data_synthetic/generated under the working directory; never into the package or the
    repository (their files keep their SHA-256, no file is added)."""
    import hsgeo
    from hsgeo.simulate.scenarios import data_dir

    watched = [Path(hsgeo.__file__).resolve().parent, data_dir()]
    before = {w: _sha(w) for w in watched}
    out = inputs.dir / "gen"
    rc, _, err = run_cli(["data", "--out", str(out)], capsys)
    assert rc == 0, err
    assert (out / "line_lab_observations.csv").is_file()
    rc, _, err = run_cli(["data"], capsys)  # the working directory is a fresh folder
    assert rc == 0, err
    assert (Path.cwd() / "data_synthetic/generated/line_lab_observations.csv").is_file()
    for w in watched:
        assert _sha(w) == before[w], w


def counts() -> str:
    """The table of cases by command and class."""
    by = Counter((c.cmd, c.kind) for c in CASES)
    cmds = sorted({c for c, _ in by})
    kinds = sorted({k for _, k in by})
    w = max(map(len, kinds)) + 2
    lines = ["command".ljust(18) + "".join(k[: w - 1].rjust(w) for k in kinds) + "   total"]
    for c in cmds:
        row = [by[(c, k)] for k in kinds]
        lines.append(c.ljust(18) + "".join(str(n or "").rjust(w) for n in row) + f"{sum(row):8d}")
    lines.append(
        "total".ljust(18)
        + "".join(str(sum(by[(c, k)] for c in cmds)).rjust(w) for k in kinds)
        + f"{len(CASES):8d}"
    )
    return "\n".join(lines)


if __name__ == "__main__":
    print(counts())


@pytest.mark.parametrize("cmd", ["orthorectify-line"])
def test_a_failing_envi_leaves_no_file(cmd, inputs: Inputs, monkeypatch, capsys):
    """-o y.hdr: if writing the ENVI pair fails, neither its header nor its data file is left
    behind (both or none), and no temporary file remains (the fixture checks *.part)."""
    from hsgeo.errors import InputError
    from hsgeo.io import raster

    def fail(*args, **kwargs):
        raise InputError("the ENVI writer failed")

    monkeypatch.setattr(raster, "_rows", fail)
    d = inputs.dir
    out = d.parent / "out"
    a = opt("-o", str(out / "o_envi.hdr"))(base_argv("orthorectify-line", d), d)
    inputs.before = _sha(d)
    rc, _, err = run_cli(a, capsys)
    assert rc == 2 and "ENVI writer failed" in err
    assert sorted(p.name for p in out.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        ["--help"],
        *(
            [c, "--help"]
            for c in sorted(
                {"orthorectify" if "orthorectify" in c.cmd else c.cmd for c in CASES} - {"hsgeo"}
            )
        ),
    ],
)
def test_help_still_works(argv, capsys):
    from hsgeo.cli import main

    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith("usage: hsgeo")


@pytest.mark.parametrize(
    "cmd,edit,expect",
    [
        ("calibrate-line", lambda a, d: opt("--zeta0-px", "nan")(a, d), "--zeta0-px"),
        ("calibrate-line", lambda a, d: opt("--c-px", "0")(a, d), "--c-px"),
        ("orthorectify-line", lambda a, d: opt("--resolution", "1e-9")(a, d), "--resolution"),
    ],
    ids=["zeta0-nan", "c-px-0", "resolution-1nm"],
)
def test_end_to_end_in_a_subprocess(cmd, edit, expect, inputs: Inputs):
    """The console command as a user runs it: file descriptors 1 and 2 as they are (a LAPACK
    or C-library message would show here, where capsys cannot see it)."""
    import subprocess
    import sys

    d = inputs.dir
    argv = edit(base_argv(cmd, d), d)
    inputs.before = _sha(d)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1"}
    p = subprocess.run(
        [sys.executable, "-m", "hsgeo.cli", *argv], capture_output=True, text=True, env=env
    )
    assert p.returncode == 2
    assert p.stdout == ""
    assert len(p.stderr.splitlines()) == 1 and expect in p.stderr, p.stderr


# --- issue 24: locales, Ctrl-C, pipes, progress, the same words in and out of the repository --


def _run_sub(argv, env_extra=None, **kwargs):
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1"}
    env.update(env_extra or {})
    return subprocess.run(
        [sys.executable, "-m", "hsgeo.cli", *map(str, argv)],
        capture_output=True,
        env=env,
        **kwargs,
    )


#: the line count of each command's report on a UTF-8 terminal
_UTF8_LINES: dict[str, int] = {}


@pytest.mark.parametrize(
    "cmd,env",
    [
        ("calibrate-line", {"PYTHONIOENCODING": "ascii"}),
        ("calibrate-line", {"PYTHONIOENCODING": "latin-1"}),
        ("mtf", {"PYTHONIOENCODING": "ascii"}),
        ("adjust-pushbroom", {"PYTHONIOENCODING": "ascii"}),
        ("orthorectify-line", {"PYTHONIOENCODING": "ascii", "LANG": "C", "LC_ALL": "C"}),
        ("reproduce", {"PYTHONIOENCODING": "ascii"}),
    ],
    ids=[
        "calibrate-line-ascii",
        "calibrate-line-latin1",
        "mtf-ascii",
        "pushbroom-ascii",
        "C",
        "reproduce-ascii",
    ],
)
def test_reports_print_in_any_locale(cmd, env, inputs: Inputs):
    """The text report and the error line survive a terminal that cannot show Σ, σ, …, →:
    the characters are spelled in ASCII instead of ending in UnicodeEncodeError."""
    d = inputs.dir
    argv = base_argv(cmd, d)
    if cmd == "adjust-pushbroom":
        argv += ["--accept-poor-fit"]
    inputs.before = _sha(d)
    p = _run_sub(argv, env)
    assert p.returncode == 0, p.stderr.decode("ascii", "replace")[-2000:]
    assert b"UnicodeEncodeError" not in p.stderr
    p.stdout.decode("ascii" if env["PYTHONIOENCODING"] == "ascii" else "latin-1")  # encodable
    # the whole report, every line of it, as on a UTF-8 terminal (spelled, not cut short); the
    # UTF-8 run once per command (its line count does not depend on the folder's name)
    if cmd not in _UTF8_LINES:
        ref = _run_sub(
            [*argv, "--overwrite"] if cmd == "orthorectify-line" else argv,
            {"PYTHONIOENCODING": "utf-8"},
        )
        assert ref.returncode == 0, ref.stderr[-500:]
        _UTF8_LINES[cmd] = ref.stdout.count(b"\n")
    assert p.stdout.count(b"\n") == _UTF8_LINES[cmd], p.stdout[-300:]
    if cmd == "orthorectify-line":  # an error line with non-ASCII characters ('…' of a pixel range)
        bad = d / "bad.toml"
        bad.write_text((d / "sensor.toml").read_text().replace("486.8", "900.0"))
        e = _run_sub(
            [x if not x.endswith("sensor.toml") else bad for x in argv] + ["--overwrite"], env
        )
        assert e.returncode == 2 and len(e.stderr.splitlines()) == 1, e.stderr
        assert b"200...796 px" in e.stderr, e.stderr


def test_ascii_spellings_of_the_report():
    """The spelling of the report's symbols where the terminal cannot show them."""
    import io as _io

    from hsgeo.terminal import setup_streams  # registers the error handler

    setup_streams()
    buf = _io.TextIOWrapper(_io.BytesIO(), encoding="ascii", errors="hsgeo-ascii")
    buf.write("cost ½Σr² 2.5 → 1.7 px², σ0 1.03, σ̂ 0.1, λ 1e-5, 3 µm, mm⁻⁴, é, ☃")
    buf.flush()
    assert buf.buffer.getvalue().decode() == (
        "cost 1/2Sumr^2 2.5 -> 1.7 px^2, sigma0 1.03, sigma_hat 0.1, lambda 1e-5, 3 um, mm^-4, e, ?"
    )


#: The child of the Ctrl-C test: ``hsgeo`` as it is, but SIGINT sent to itself ``delay`` seconds
#: after the solver reports iteration ``k``: the signal lands while the next iteration runs,
#: mostly inside the numba kernels (where Ctrl-C surfaces as SystemError), at a time that does
#: not depend on how busy the machine is.
_SIGINT_CHILD = """
import os, signal, sys, threading
# Ctrl-C as in a terminal: a shell starts background jobs with SIGINT ignored, which Python
# keeps, so a suite run with `make test &` would see no interrupt at all
signal.signal(signal.SIGINT, signal.default_int_handler)
from hsgeo import cli, terminal
k, delay = int(sys.argv[1]), float(sys.argv[2])
def printer(stream=None):
    def show(info):
        if info["iteration"] == k:
            threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT)).start()
    return show
terminal.progress_printer = printer
sys.exit(cli.main(sys.argv[3:]))
"""


@pytest.mark.parametrize("cmd", ["adjust-bal"])
def test_ctrl_c_inside_a_compiled_kernel(cmd, inputs: Inputs):
    """SIGINT while adjust-bal iterates on BAL Ladybug-49 (numba kernels, where Ctrl-C
    surfaced as ``SystemError: CPUDispatcher(_reduced_kernel)`` about half the time): one line
    'interrupted' and exit status 130 on every try, nothing on stdout, nothing written."""
    import subprocess
    import sys

    ladybug = ROOT / "src/hsgeo/data/reference/bal-ladybug/problem-49-7776-pre.txt.bz2"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1"}
    before = sorted(inputs.dir.rglob("*"))
    # on main before issue 24 these four ended in SystemError, status 1 (9 of 10 such tries)
    for k, delay_s in ((1, 0.04), (2, 0.06), (3, 0.045), (6, 0.035)):
        p = subprocess.run(
            [sys.executable, "-c", _SIGINT_CHILD, str(k), str(delay_s), cmd, str(ladybug)],
            capture_output=True,
            env=env,
            cwd=inputs.dir,
            timeout=300,
        )
        err = p.stderr.decode()
        assert p.returncode == 130, (k, delay_s, err[-2000:])
        assert err.splitlines() == [f"hsgeo {cmd}: interrupted"], err[-2000:]
        assert p.stdout == b""
    assert sorted(inputs.dir.rglob("*")) == before


#: The child of the Ctrl-C-while-writing test: SIGINT at a set point of the writing, not after a
#: time (a time depends on how busy the machine is): right after atomic_path made its .part
#: ("part"), or at the k-th task the NetCDF writer completes ("task", k).
_SIGINT_WRITING_CHILD = """
import os, signal, sys, tempfile
# Ctrl-C as in a terminal: a shell starts background jobs with SIGINT ignored, which Python
# keeps, so a suite run with `make test &` would see no interrupt at all
signal.signal(signal.SIGINT, signal.default_int_handler)
from hsgeo import cli
import hsgeo.io.cube as cube
where, k = sys.argv[1], int(sys.argv[2])
def interrupt():
    os.kill(os.getpid(), signal.SIGINT)
if where == "part":
    mkstemp = tempfile.mkstemp
    def mk(*a, **kw):
        r = mkstemp(*a, **kw)
        if kw.get("suffix") == ".part" and mk.calls == k:
            interrupt()
        mk.calls += 1
        return r
    mk.calls = 0
    tempfile.mkstemp = mk
else:
    write = cube._compute_with_progress
    def compute(delayed, progress, n_lines):
        calls = []
        def tick(done, total):
            calls.append(done)
            if len(calls) == k:
                interrupt()
        return write(delayed, tick, n_lines)
    cube._compute_with_progress = compute
sys.exit(cli.main(sys.argv[3:]))
"""


@pytest.mark.parametrize("cmd", ["cube"])
def test_cube_bytes_do_not_depend_on_the_hash_seed(cmd, inputs: Inputs):
    """The same inputs give the same bytes in any process: the order in which the delayed
    NetCDF store computed two Dask-backed variables followed PYTHONHASHSEED (issue 42: 1 run
    in 6 gave other bytes; seeds 1 and 3 differed)."""
    import subprocess
    import sys

    d = inputs.dir
    inputs.before = _sha(d)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1"}
    out = []
    for seed in ("1", "3"):
        argv = [x.replace("cube.nc", f"cube{seed}.nc") for x in base_argv(cmd, d)]
        p = subprocess.run(
            [sys.executable, "-m", "hsgeo.cli", *argv],
            capture_output=True,
            env={**env, "PYTHONHASHSEED": seed},
            timeout=300,
        )
        assert p.returncode == 0, p.stderr.decode()[-2000:]
        out.append((d.parent / "out" / f"cube{seed}.nc").read_bytes())
    assert out[0] == out[1]


@pytest.mark.parametrize("cmd", ["cube"])
def test_ctrl_c_while_writing_leaves_nothing(cmd, inputs: Inputs):
    """SIGINT while the cube is written chunk by chunk: one line, 130, and no output and no
    temporary file left (atomic_path removes its .part; SIGINT is held back between making
    the temporary file and owning it)."""
    import subprocess
    import sys

    d = inputs.dir
    inputs.before = _sha(d)
    argv = base_argv(cmd, d) + ["--lines-per-chunk", "2"]
    out = d.parent / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1"}
    # check_outputs' probe is .part number 0, atomic_path's number 1
    for where, k in (("part", 0), ("part", 1), ("task", 1), ("task", 5)):
        p = subprocess.run(
            [sys.executable, "-c", _SIGINT_WRITING_CHILD, where, str(k), *argv],
            capture_output=True,
            env=env,
            timeout=300,
        )
        err = p.stderr.decode()
        assert p.returncode == 130, (where, k, err[-2000:])
        assert err.splitlines() == [f"hsgeo {cmd}: interrupted"], err[-2000:]
        assert sorted(x.name for x in out.iterdir()) == [], (where, k)


@pytest.mark.parametrize("cmd", ["calibrate-line"])
def test_input_from_a_pipe(cmd, inputs: Inputs):
    """`cat obs.csv | hsgeo calibrate-line /dev/stdin ...` and a process substitution
    (`<(cat obs.csv)`: a pipe at /dev/fd/N) read as the file itself."""

    def report(out: bytes) -> list[bytes]:  # without the line that gives the seconds taken
        return [ln for ln in out.splitlines() if b" s\n" not in ln + b"\n"]

    d = inputs.dir
    inputs.before = _sha(d)
    want = _run_sub(base_argv(cmd, d))
    assert want.returncode == 0, want.stderr
    argv = base_argv(cmd, d)
    argv[1] = "/dev/stdin"
    with open(d / "obs.csv", "rb") as fh:
        got = _run_sub(argv, stdin=fh)
    assert got.returncode == 0, got.stderr
    assert report(got.stdout) == report(want.stdout)
    r, w = os.pipe()
    os.write(w, (d / "obs.csv").read_bytes())  # a few kB: fits in the pipe's buffer
    os.close(w)
    argv[1] = f"/dev/fd/{r}"
    try:
        got = _run_sub(argv, pass_fds=(r,))
    finally:
        os.close(r)
    assert got.returncode == 0, got.stderr
    assert report(got.stdout) == report(want.stdout)


@pytest.mark.parametrize("cmd", ["adjust-bal"])
def test_bal_blank_lines_are_whitespace(cmd, inputs: Inputs, capsys):
    """A blank line after the BAL header (or anywhere) changes nothing: the format is
    whitespace-separated numbers. The same problem is read, and the command ends alike."""
    from hsgeo.io.bal import read_bal

    d = inputs.dir
    p = d / "problem.txt"
    want = read_bal(p)
    rc, out, err = run_cli(base_argv(cmd, d), capsys)
    lines = p.read_text().splitlines()
    p.write_text("\n".join([lines[0], "", *lines[1:5], "   ", *lines[5:]]) + "\n\n")
    got = read_bal(p)
    for f in ("cameras", "points", "camera_index", "point_index", "xy_px"):
        np.testing.assert_array_equal(getattr(got, f), getattr(want, f))
    inputs.before = _sha(d)
    rc2, out2, err2 = run_cli(base_argv(cmd, d), capsys)
    assert rc2 == rc and err2 == err and "line" not in err2, err2  # the same outcome either way
    if rc == 0:
        assert json.loads(out2)["final_cost"] == json.loads(out)["final_cost"]


@pytest.mark.parametrize("cmd", ["adjust-pushbroom"])
def test_progress_only_on_a_terminal(cmd, inputs: Inputs):
    """With stderr redirected (not a terminal) no iteration progress: a failing fit's one
    error line is the only line on stderr; on a terminal the progress line clears itself."""
    import io as _io

    from hsgeo import terminal

    d = inputs.dir
    inputs.before = _sha(d)
    p = _run_sub(base_argv(cmd, d))
    err = p.stderr.decode()
    assert "iter" not in err
    assert len(err.splitlines()) == (1 if p.returncode == 2 else 0), err
    assert terminal.progress_printer(_io.StringIO()) is None  # not a tty

    class Tty(_io.StringIO):
        def isatty(self):
            return True

    tty = Tty()
    show = terminal.progress_printer(tty)
    show({"iteration": 1, "cost": 2.0, "lambda": 1e-3, "seconds": 0.1})
    show({"iteration": 2, "cost": 1.0, "lambda": 1e-4, "seconds": 0.2})
    terminal.clear_progress(tty)
    text = tty.getvalue()
    assert "\n" not in text and text.endswith("\r\033[K") and "iter   2" in text


@pytest.mark.parametrize("cmd", ["data"])
def test_data_verify_out_uses_the_repository_words(cmd, inputs: Inputs, capsys):
    """`hsgeo data --verify --out DIR` and the check in the repository: the same tolerance
    and words (files that differ only in the last bits are not 'differ from MANIFEST')."""
    rc, _, err = run_cli(["data", "--verify", "--out", str(inputs.dir / "gen")], capsys)
    assert rc == 0, err
    assert "differ from MANIFEST" not in err
    assert "files match MANIFEST.sha256" in err.splitlines()[-1]


def test_json_is_strict():
    """NaN and inf are written as null: JSON has no Infinity (a BAL cost of 1e300² was)."""
    import json

    from hsgeo.terminal import json_text

    d = {"cost": float("inf"), "x": [1.0, float("nan")], "a": np.array([np.inf, 2.0])}
    assert json.loads(json_text(d)) == {"cost": None, "x": [1.0, None], "a": [None, 2.0]}


def test_interrupt_and_os_errors_are_recognised():
    import errno

    from hsgeo.terminal import error_line, interrupted

    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as ki:
            raise SystemError("CPUDispatcher(_reduced_kernel) returned a result") from ki
    except SystemError as exc:
        assert interrupted(exc)
    assert not interrupted(SystemError("a bug"))
    e = OSError(errno.ENAMETOOLONG, "File name too long", "x" * 300)
    assert "too long" in error_line(e) and "300 characters" in error_line(e)
    assert "memory" in error_line(MemoryError("Unable to allocate 67 GiB"))
    assert error_line(ValueError("a bug")) is None


def chain_edits(*fs):
    def edit(p: Path):
        for f in fs:
            f(p)

    return edit


@pytest.mark.parametrize(
    "cmd,file,edit,must,must_not",
    [
        ("adjust-pushbroom", "nav.csv", drop_column("N_m"), "N_m", "rename"),
        ("orthorectify-line", "nav.csv", drop_column("U_m"), "U_m", "rename"),
        # image coordinates in mm: the fit is poor, and the message says which units to check
        (
            "adjust-pushbroom",
            "obs.csv",
            chain_edits(scale_column("x_px", 0.0065), scale_column("y_px", 0.0065)),
            "x_px, y_px not in pixels",
            "GCP",
        ),
    ],
    ids=["pushbroom-nav-no-N_m", "geocode-nav-no-U_m", "pushbroom-obs-in-mm"],
)
def test_names_the_right_cause(cmd, file, edit, must, must_not, inputs: Inputs, capsys):
    """A missing column is not 'renamed' from another required column that is present."""
    d = inputs.dir
    edit(d / file)
    inputs.before = _sha(d)
    rc, _, err = run_cli(base_argv(cmd, d), capsys)
    assert rc == 2 and must in err and must_not not in err, err


@pytest.mark.parametrize("cmd", ["data"])
def test_data_twice_outside_the_repository(cmd, inputs: Inputs, capsys):
    """A second `hsgeo data` outside the repository names the folder the user never gave as
    the default one, not as an option they did not type."""
    rc, _, err = run_cli(["data"], capsys)
    assert rc == 0, err
    rc, _, err = run_cli(["data"], capsys)
    assert rc == 2 and "where hsgeo data writes without --out" in err, err
    assert "--out " + str(Path.cwd()) not in err


@pytest.mark.parametrize("cmd", ["orthorectify-line"])
def test_toml_and_netcdf_from_a_pipe(cmd, inputs: Inputs):
    """A TOML read twice (its kind, then its content) from a pipe: `--sensor /dev/stdin`; a
    NetCDF LINES file from a pipe."""
    d = inputs.dir
    argv = [x if not x.endswith("sensor.toml") else "/dev/stdin" for x in base_argv(cmd, d)]
    inputs.before = _sha(d)
    with open(d / "sensor.toml", "rb") as fh:
        p = _run_sub(argv, stdin=fh)
    assert p.returncode == 0, p.stderr
    assert (d.parent / "out" / "ortho.nc").is_file()
    # a NetCDF from a pipe (the LINES file): read once, opened from memory
    argv = [x if not x.endswith("lines.nc") else "/dev/stdin" for x in base_argv(cmd, d)]
    with open(d / "lines.nc", "rb") as fh:
        p = _run_sub([*argv, "--overwrite"], stdin=fh)
    assert p.returncode == 0, p.stderr
