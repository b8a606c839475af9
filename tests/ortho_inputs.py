"""A small 002-like orthomosaic scene at Ås (tests/test_ortho*.py, bench/bench_orthomosaic.py).

Two opposite strips of an LP camera (300 px of 6.5 µm, c = 40 mm, 1875 m above a DSM of a
gentle hill in EPSG:25832: GSD ≈ 0.30 m, swath ≈ 92 m, 60 m between the flight lines) over
reference squares of 1.2 m; the lines are rendered from the same geometry (the pixel centre's
ground point) at 67 m/s and 0.3 m line spacing. Also the 000 line scanner on the same flight.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.crs import SITE_AAS
from hsgeo.mapgrid import MapGrid, MapTerrain
from hsgeo.ortho import Strip
from hsgeo.sensors.line import LinearIFOV, LineScanner
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.simulate.ortho_scene import SquaresScene, lazy_cube, render_lines, straight_flight

FRAME = SITE_AAS
#: ``hsgeo orthorectify``'s options for FRAME (a local-ENU navigation names its origin, --site, on
#: its datum, --nav-crs): the paper's site is the test's input, never the command's default.
SITE_ARGS = [
    "--site",
    f"{FRAME.lat_deg!r},{FRAME.lon_deg!r},{FRAME.h_m!r}",
    "--nav-crs",
    f"EPSG:{FRAME.datum_epsg}",
]
HEIGHT_M = 1875.0
SPEED_M_S = 67.0
GSD_M = HEIGHT_M * 0.0065 / 40.0


def origin_xy():
    x, y, _ = FRAME.enu_to_map(0.0, 0.0, 0.0)
    return float(x), float(y)


def dsm(pad_m: float = 250.0, cell_m: float = 2.0, shift_xy=(0.0, 0.0)):
    """Heights (m above GRS80) of a gentle hill and its grid (EPSG:25832)."""
    x0, y0 = origin_xy()
    grid = MapGrid.covering(
        (x0 - pad_m + shift_xy[0], x0 + pad_m + shift_xy[0]),
        (y0 - pad_m + shift_xy[1], y0 + pad_m + shift_xy[1]),
        cell_m,
        f"EPSG:{FRAME.map_epsg}",
    )
    X, Y = np.meshgrid(grid.x_m - x0, grid.y_m - y0)
    z = 100.0 + 4.0 * np.exp(-(X**2 + Y**2) / (2 * 60.0**2)) + 0.01 * X
    return z, grid


def squares_xy():
    x0, y0 = origin_xy()
    off = np.array(
        [[-30.3, -40.1], [-12.0, 10.4], [0.2, 30.7], [15.6, -20.2], [31.1, 45.3], [-2.7, -60.9]]
    )
    return off + [x0, y0]


def scene():
    return SquaresScene(squares_xy(), side_m=1.2, band_gain=(1.0, 0.8, 0.6, 0.4))


WAVELENGTH_NM = (640.0, 550.0, 460.0, 800.0)


@dataclass(frozen=True)
class Flight:
    strips: tuple  # Strip with rendered values
    terrain: MapTerrain
    trajectories: tuple


def flight_trajectory(length_m: float = 240.0, lateral_m: float = 60.0, roll_amp_deg=0.05):
    """One navigation: strip 1 northwards, a turn of 20 s, strip 2 southwards, 60 m apart.

    Returns the :class:`Trajectory` and the two strips' line times (s).
    """
    from hsgeo.trajectory import Trajectory

    x0, y0 = origin_xy()
    dur = length_m / SPEED_M_S + 2.0
    half = length_m / 2 + SPEED_M_S
    kw = dict(
        speed_m_s=SPEED_M_S, height_m=HEIGHT_M + 100.0, duration_s=dur, roll_amp_deg=roll_amp_deg
    )
    t1 = straight_flight(FRAME, start_xy_m=(x0 - lateral_m / 2, y0 - half), heading_deg=0.0, **kw)
    t2 = straight_flight(FRAME, start_xy_m=(x0 + lateral_m / 2, y0 + half), heading_deg=180.0, **kw)
    off = t1.t_s[-1] + 20.0
    nav = Trajectory(
        np.concatenate([t1.t_s, t2.t_s + off]),
        np.concatenate([t1.xyz_m, t2.xyz_m]),
        np.concatenate([t1.roll_pitch_heading_rad, t2.roll_pitch_heading_rad]),
    )
    lt = line_times(length_m)
    return nav, (lt, lt + off)


def line_times(length_m: float = 240.0):
    return np.arange(1.0, 1.0 + length_m / SPEED_M_S, GSD_M / SPEED_M_S)


def lp_camera(n_bands: int = 4):
    return PushbroomCamera(c_mm=(40.0,) * n_bands, pixel_mm=0.0065)


def lp_pixels(n_px: int = 300):
    x = np.arange(n_px) - (n_px - 1) / 2
    return np.column_stack([x, np.zeros(n_px)])


def line_scanner(n_px: int = 300):
    return LineScanner(LinearIFOV(zeta0_px=(n_px - 1) / 2, c_px=40.0 / 0.0065))


def flight(sensor="lp", lazy=False, length_m=240.0, render_nav=None, nav=None, camera=None):
    """Two rendered strips of the LP camera ("lp") or the 000 line scanner ("line"), rendered
    along ``render_nav`` (default the navigation) and mosaicked along ``nav``; ``camera``:
    ``(PushbroomCamera, pixel_kw)`` that renders the LP strips (default :func:`lp_camera`)."""
    z, g = dsm()
    terrain = MapTerrain(z, g, FRAME)
    nav0, times = flight_trajectory(length_m)
    nav = nav or nav0
    rnav = render_nav or nav0
    sc = scene()
    if sensor == "lp":
        sen, px, kw = (
            (lp_camera(), lp_pixels(), {"band": 0})
            if camera is None
            else (
                camera[0],
                lp_pixels(),
                camera[1],
            )
        )
    else:
        n = 300
        sen, px, kw = line_scanner(n), np.arange(n, dtype=float), {}
    strips = []
    for i, t in enumerate(times):
        shell = Strip(sen, rnav, t, px, np.zeros((t.size, px.shape[0], 4), np.float32), kw)
        vals = (
            lazy_cube(shell, sc, terrain, FRAME, 64)
            if lazy
            else render_lines(shell, sc, terrain, FRAME)
        )
        strips.append(Strip(sen, nav, t, px, vals, kw, f"s{i + 1}"))
    return Flight(tuple(strips), terrain, (nav, nav))


def node_corrections(nav):
    """A known adjustment: node corrections of 1.2 m east, -0.9 m north, 0.3 m up and a few
    hundredths of a degree (the recorded navigation lacks them)."""
    from hsgeo.trajectory import SplineNodes

    nodes = SplineNodes(float(nav.t_s[0]), float(nav.t_s[-1]), 10.0)
    k = np.arange(nodes.n_nodes)[:, None]
    v = np.hstack(
        [
            np.full((nodes.n_nodes, 1), 1.2),
            np.full((nodes.n_nodes, 1), -0.9),
            np.full((nodes.n_nodes, 1), 0.3),
            np.radians(0.02) * np.cos(k + [0, 1, 2]),
        ]
    )
    return nodes, v


def adjustment_json(nodes, v) -> str:
    import json

    from hsgeo.trajectory import CORRECTION_COLUMNS

    par = {
        "boresight_deg": [0.0, 0.0, 0.0],
        "lever_arm_m": [0.0, 0.0, 0.0],
        "distortion": [0.0, 0.0, 0.0, 0.0],
        "c_mm": [40.0],
    }
    return json.dumps(
        {
            "converged": True,
            "parameters": {k: {"value": x, "sigma": [0.0] * len(x)} for k, x in par.items()},
            "nodes": {
                "t_s": nodes.t_nodes_s.tolist(),
                "value": v.tolist(),
                "sigma": np.zeros_like(v).tolist(),
                "columns": list(CORRECTION_COLUMNS),
            },
        }
    )


#: The camera file of issue 36: a principal distance per band, distortion and a boresight of
#: 0.3° (≈ 9.8 m on the ground at 1875 m), which a reader that drops them misplaces.
FULL_CAMERA_TOML = (
    "[camera]\nn_bands = 4\npixel_mm = 0.0065\nc_mm = 40.0\n"
    "c_band_mm = [40.0, 40.1, 40.2, 40.3]\ndistortion = [1e-4, 0.0, 0.0, 0.0]\n"
    "boresight_deg = [0.3, -0.2, 0.1]\n"
)


def full_camera():
    """The camera of :data:`FULL_CAMERA_TOML`, built here (not by the reader under test)."""
    return PushbroomCamera(
        c_mm=(40.0, 40.1, 40.2, 40.3),
        pixel_mm=0.0065,
        distortion=(1e-4, 0.0, 0.0, 0.0),
        boresight_rad=tuple(np.radians([0.3, -0.2, 0.1])),
    )


def write_ortho_inputs(
    d, *, adjusted: bool = False, lazy: bool = False, full_camera_file: bool = False
) -> dict:
    """LP line files, NAV, camera TOML, DSM GeoTIFF (and RESULT.json) under ``d``.

    With ``adjusted``, the lines are rendered along the true trajectory and the navigation file
    lacks the corrections of :func:`node_corrections`, which RESULT.json carries. With
    ``full_camera_file``, the lines are rendered with :func:`full_camera` (band 1's geometry,
    the middle one of 640, 550, 460 nm) and the camera file is :data:`FULL_CAMERA_TOML`.
    """
    from pathlib import Path

    from hsgeo.io.geotiff import write_geotiff
    from hsgeo.io.lp_lines import LpStrip, write_lp_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.trajectory import corrected_trajectory

    d = Path(d)
    true_nav, _ = flight_trajectory()
    files = {}
    if adjusted:
        nodes, v = node_corrections(true_nav)
        nav = corrected_trajectory(true_nav, nodes, -v)
        files["adjustment"] = d / "result.json"
        files["adjustment"].write_text(adjustment_json(nodes, v))
    else:
        nav = true_nav
    cam = (full_camera(), {"band": 1}) if full_camera_file else None
    fl = flight("lp", lazy=lazy, render_nav=true_nav, nav=nav, camera=cam)
    files["lines"] = []
    for s in fl.strips:
        p = d / f"{s.name}.nc"
        n = s.pixels.shape[0]  # a full line: x_px = j - (n - 1)/2
        write_lp_lines(p, LpStrip(s.values, s.t_s, 0, WAVELENGTH_NM, s.name, n_px_full=n))
        files["lines"].append(p)
    files["nav"] = write_trajectory(d / "nav.csv", nav)
    files["camera"] = d / "camera.toml"
    files["camera"].write_text(
        FULL_CAMERA_TOML
        if full_camera_file
        else "[camera]\nn_bands = 4\npixel_mm = 0.0065\nc_mm = 40.0\n"
    )
    z, g = dsm()
    files["dsm"] = write_geotiff(d / "dsm.tif", z, g.transform, 25832)
    return files
