"""Orthomosaic throughput: output pixels per second per core, and peak memory, by path.

Two opposite LP strips (900 px of 6.5 µm, c = 40 mm, 1875 m above a DSM in EPSG:25832: 0.30 m
GSD, 275 m swath, 150 m apart) of 2,000 lines each with 3 bands, rendered once and held in
memory (only the mosaic is timed), onto a 0.3 m grid in EPSG:25832. Each path runs in a fresh
process; its peak RSS is sampled while it runs (``peak_rss_over_start_mib``: over the process
with the inputs in memory):

* ``in_memory`` — :func:`hsgeo.ortho.resample_swath` per strip (the kd-tree on the whole grid
  at once, no Dask), then the nearest-to-nadir rule;
* ``chunked_1`` — :func:`hsgeo.workflows.orthorectify.orthorectify` (what ``hsgeo
  orthorectify`` runs: Dask tiles of 512 cells, the geolocation per line block inside each
  tile's task), synchronous scheduler (one core);
* ``chunked_threads_2`` — the same graph on Dask's threaded scheduler with 2 threads;
* ``distributed_2`` — the same graph on a ``dask.distributed`` LocalCluster of 2 worker
  processes (1 thread each; their memory is not in the client's RSS, and the wall time excludes
  starting the cluster);
* ``ckdtree_handwritten`` — the path ``hsgeo geocode`` used before issue 26 (its
  ``geocode.orthorectify`` is gone; the same steps are written out here):
  :func:`hsgeo.ortho.ground_points`, then scipy's cKDTree on the local-frame plane, in memory,
  per strip, no mosaic rule and no CRS;
* ``gdal_warp_geoloc`` — the peer: GDAL's warper (``rasterio.warp.reproject`` with
  ``src_geoloc_array``, GDAL's geolocation-array transformer), nearest neighbour, onto the
  same grid, given the very per-pixel ground coordinates of ours (:func:`hsgeo.ortho.
  block_ground`, timed with it: ``geolocation_cpu_s`` of the row; as the pixels' top-left
  corners, GDAL's convention, :func:`_corners`) and the off-nadir angle as a
  fourth band for the same nearest-to-nadir rule; ``warp_cpu_s`` is GDAL's part alone
  (``output_px_per_warp_cpu_s``: GDAL's warper given the coordinates for free), and
  ``share_cells_equal_to_ours`` compares its mosaic with ours (computed after the timing). The
  coordinates are those of the engine's orthomosaic: since issue 41 within 1 mm of PROJ
  (``hsgeo._approx_transform.APPROX_TOL_M``), before it PROJ on every pixel.

Before its timing each path runs once on the strips' first 64 lines (:func:`_warm`): imports
and numba's kernel cache, about 1 CPU-s a process, are not charged to the cells.

``--pairs N --vs-src DIR`` also runs ``chunked_1`` N times alternating with the engine at
``DIR`` (another tree's ``src``, e.g. main's; each run a fresh process, ``PYTHONPATH=DIR``) and
writes the medians, the load average of every run and the goal beside them (``vs_main``).

``python bench/bench_orthomosaic.py [--lines N] [--pairs N --vs-src DIR]`` →
``bench/results/orthomosaic.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
PATHS = (
    "in_memory",
    "chunked_1",
    "chunked_threads_2",
    "distributed_2",
    "ckdtree_handwritten",
    "gdal_warp_geoloc",
)
#: issue 41's goal for the chunked path, output cells per CPU second
GOAL_CELLS_PER_CPU_S = 1.0e6
CORES = {
    "in_memory": 1,
    "chunked_1": 1,
    "chunked_threads_2": 2,
    "distributed_2": 2,
    "ckdtree_handwritten": 1,
    "gdal_warp_geoloc": 1,
}


def scene(n_lines: int, n_px: int = 900):
    """Two rendered strips (numpy values), the terrain, the frame."""
    from hsgeo.crs import SITE_AAS as F
    from hsgeo.mapgrid import MapGrid, MapTerrain
    from hsgeo.ortho import Strip
    from hsgeo.sensors.pushbroom import PushbroomCamera
    from hsgeo.simulate.ortho_scene import SquaresScene, render_lines, straight_flight

    x0, y0 = (float(v) for v in F.enu_to_map(0.0, 0.0, 0.0)[:2])
    gsd, v = 1875.0 * 0.0065 / 40.0, 67.0
    length = n_lines * gsd
    g = MapGrid.covering(
        (x0 - 400, x0 + 400),
        (y0 - length / 2 - 200, y0 + length / 2 + 200),
        2.0,
        f"EPSG:{F.map_epsg}",
    )
    X, Y = np.meshgrid(g.x_m - x0, g.y_m - y0)
    terrain = MapTerrain(100.0 + 4.0 * np.exp(-(X**2 + Y**2) / 2 / 80.0**2), g, F)
    cam = PushbroomCamera(c_mm=(40.0,), pixel_mm=0.0065)
    px = np.column_stack([np.arange(n_px) - (n_px - 1) / 2, np.zeros(n_px)])
    sq = SquaresScene(np.array([[x0, y0]]), band_gain=(1.0, 0.8, 0.6))
    strips = []
    for i, (dx, hd) in enumerate(((-75.0, 0.0), (75.0, 180.0))):
        sy = y0 - length / 2 - v if hd == 0 else y0 + length / 2 + v
        nav = straight_flight(
            F,
            start_xy_m=(x0 + dx, sy),
            heading_deg=hd,
            speed_m_s=v,
            height_m=1975.0,
            duration_s=length / v + 3.0,
            roll_amp_deg=0.05,
        )
        t = 1.0 + np.arange(n_lines) * gsd / v
        shell = Strip(cam, nav, t, px, None, {"band": 0})
        vals = np.concatenate(
            [render_lines(shell, sq, terrain, F, slice(a, a + 256)) for a in range(0, n_lines, 256)]
        )
        strips.append(Strip(cam, nav, t, px, vals, {"band": 0}, f"s{i + 1}"))
    return strips, terrain, F


def _ground(s, terrain):
    """Every pixel's ground point of one strip (hsgeo.ortho.ground_points, band 0)."""
    from hsgeo.ortho import ground_points

    return ground_points(s.sensor, s.trajectory, s.t_s, s.pixels, terrain, band=0)


def _in_memory(strips, terrain, frame):
    from hsgeo.mapgrid import MapGrid
    from hsgeo.ortho import resample_swath, strip_footprints

    allb = np.concatenate(
        [strip_footprints(s, terrain, frame, 256, "EPSG:25832")[1] for s in strips]
    )
    grid = MapGrid.covering(allb[:, [0, 2]].ravel(), allb[:, [1, 3]].ravel(), 0.3, "EPSG:25832")
    best = np.full((3, grid.height, grid.width), np.nan, np.float32)
    rank = np.full((grid.height, grid.width), np.inf)
    for s in strips:
        g = _ground(s, terrain)
        lon, lat, _ = frame.enu_to_lonlat(g[..., 0], g[..., 1], g[..., 2])
        o, d = s.sensor.rays(
            np.tile(s.pixels, (s.n_lines, 1)),
            np.repeat(s.t_s, s.pixels.shape[0]),
            s.trajectory,
            band=0,
        )
        off = np.degrees(np.arccos(-d[:, 2]))
        v, r = resample_swath(
            np.column_stack([lon.ravel(), lat.ravel()]),
            np.asarray(s.values).reshape(-1, 3),
            off,
            grid,
            0.55 * np.hypot(0.31, 0.31) + 0.15,
            frame.datum_epsg,
        )
        win = r < rank
        best[:, win], rank[win] = v[:, win], r[win]
    return best.shape[1] * best.shape[2]


def _chunked(strips, terrain, frame, scheduler):
    from hsgeo.workflows.orthorectify import OrthoInputs, OrthoOptions, orthorectify

    m = orthorectify(
        OrthoInputs(tuple(strips), terrain),
        OrthoOptions(resolution_m=0.3, tile_px=512, frame=frame),
    )
    if scheduler == "distributed":
        from distributed import Client, LocalCluster

        with (
            LocalCluster(
                n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
            ) as c,
            Client(c) as cl,
        ):
            t0 = time.perf_counter()
            cl.compute(m.data).result()
            return m.shape[1] * m.shape[2], time.perf_counter() - t0
    kw = (
        {"scheduler": "synchronous"}
        if scheduler == "sync"
        else {"scheduler": "threads", "num_workers": 2}
    )
    m.compute(**kw)
    return m.shape[1] * m.shape[2], None


def _ckdtree(strips, terrain):
    """Nearest neighbour by scipy's cKDTree on the local-frame plane, per strip (no CRS)."""
    from scipy.spatial import cKDTree

    cells = 0
    for s in strips:
        g = _ground(s, terrain)
        EN = g[..., :2].reshape(-1, 2)
        E = np.arange(np.floor(EN[:, 0].min() / 0.3) * 0.3 + 0.15, EN[:, 0].max(), 0.3)
        N = np.arange(np.ceil(EN[:, 1].max() / 0.3) * 0.3 - 0.15, EN[:, 1].min(), -0.3)
        gE, gN = np.meshgrid(E, N)
        dist, idx = cKDTree(EN).query(
            np.column_stack([gE.ravel(), gN.ravel()]), distance_upper_bound=0.59
        )
        ok = np.isfinite(dist)
        flat = np.asarray(s.values).reshape(-1, 3)
        out = np.full((gE.size, 3), np.nan)
        out[ok] = flat[idx[ok]]
        cells += gE.size
    return cells


def _our_grid(strips, terrain, frame):
    """Our lazy mosaic (the footprints and the grid; nothing computed) and its MapGrid."""
    from hsgeo.mapgrid import MapGrid
    from hsgeo.workflows.orthorectify import OrthoInputs, OrthoOptions, orthorectify

    m = orthorectify(
        OrthoInputs(tuple(strips), terrain),
        OrthoOptions(resolution_m=0.3, tile_px=512, frame=frame),
    )
    x, y, r = m["x"].values, m["y"].values, float(m.attrs["resolution_m"])
    grid = MapGrid(float(x[0]) - r / 2, float(y[0]) + r / 2, r, x.size, y.size, "EPSG:25832")
    return m, grid


def _corners(a):
    """Each pixel's top-left corner from the pixels' centres (the mean of the four centres
    about it; the first row and column extrapolated): GDAL reads geolocation arrays as the
    top-left corners (its default GEOREFERENCING_CONVENTION, which rasterio does not pass on);
    given the centres, its nearest pixel was ours in 25 % of the cells, given the corners in
    99.7 % (300 lines).
    """
    a = np.concatenate([2 * a[:1] - a[1:2], a], axis=0)
    a = np.concatenate([2 * a[:, :1] - a[:, 1:2], a], axis=1)
    return 0.25 * (a[:-1, :-1] + a[1:, :-1] + a[:-1, 1:] + a[1:, 1:])


def _gdal_warp(strips, terrain, frame, grid, extra):
    """The peer: GDAL's warper with geolocation arrays (module docstring), nearest to nadir."""
    from rasterio.crs import CRS
    from rasterio.warp import Resampling, reproject

    from hsgeo.ortho import block_ground

    try:  # ours' coordinates: within 1 mm of PROJ, as the orthomosaic's own (issue 41)
        from hsgeo._approx_transform import APPROX_TOL_M as tol
    except ImportError:  # an engine before issue 41: PROJ on every pixel
        tol = None
    if tol is None:
        block_ground = _exact_block_ground(block_ground)
    best = np.full((3, grid.height, grid.width), np.nan, np.float32)
    rank = np.full((grid.height, grid.width), np.inf)
    warp = geo = 0.0
    for s in strips:
        c0 = time.process_time()
        g = np.concatenate(
            [
                block_ground(
                    s.geometry(), terrain, frame, (a, min(s.n_lines, a + 256)), grid.crs, tol
                )
                for a in range(0, s.n_lines, 256)
            ],
            axis=1,
        ).reshape(3, s.n_lines, -1)
        c1 = time.process_time()
        src = np.concatenate([np.moveaxis(np.asarray(s.values, np.float64), 2, 0), g[2:3]])
        dst = np.full((4, grid.height, grid.width), np.nan)
        reproject(
            src,
            dst,
            src_crs=CRS.from_string(grid.crs),
            src_geoloc_array=np.stack([_corners(g[0]), _corners(g[1])]),
            dst_transform=grid.transform,
            dst_crs=CRS.from_string(grid.crs),
            src_nodata=np.nan,
            dst_nodata=np.nan,
            resampling=Resampling.nearest,
            num_threads=1,
        )
        warp += time.process_time() - c1
        geo += c1 - c0
        r = np.where(np.isfinite(dst[3]), dst[3], np.inf)
        win = r < rank
        best[:, win], rank[win] = dst[:3, win].astype(np.float32), r[win]
    extra.update(geolocation_cpu_s=geo, warp_cpu_s=warp)
    return best


def _exact_block_ground(block_ground):
    """An engine's block_ground without the tolerance argument (before issue 41)."""

    def exact(strip, terrain, frame, lines, crs, tol):
        return block_ground(strip, terrain, frame, lines, crs)

    return exact


class PeakRSS:
    """The largest resident size of this process while the block runs (psutil, every 10 ms)."""

    def __enter__(self):
        import threading

        import psutil

        self._p, self._stop = psutil.Process(), threading.Event()
        self.start = self.peak = self._p.memory_info().rss

        def sample():
            while not self._stop.wait(0.01):
                self.peak = max(self.peak, self._p.memory_info().rss)

        self._t = threading.Thread(target=sample, daemon=True)
        self._t.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._t.join()
        self.peak = max(self.peak, self._p.memory_info().rss)


#: Lines per strip of the warm-up run before the timing (module docstring).
WARM_LINES = 64


def _warm(path: str, strips, terrain, frame) -> None:
    """The path once on the strips' first :data:`WARM_LINES` lines, untimed: the libraries'
    imports and numba's cached kernels are loaded once per process (about 1 CPU-s, not per
    cell), as they already were for the GDAL row (whose grid, ours, is built before its timing).
    """
    from hsgeo.ortho import Strip

    sub = [
        Strip(s.sensor, s.trajectory, s.t_s[:WARM_LINES], s.pixels, np.asarray(s.values)[
            :WARM_LINES], s.pixel_kw, s.name)
        for s in strips
    ]  # fmt: skip
    if path == "in_memory":
        _in_memory(sub, terrain, frame)
    elif path == "ckdtree_handwritten":
        _ckdtree(sub, terrain)
    elif path == "gdal_warp_geoloc":
        _gdal_warp(sub, terrain, frame, _our_grid(sub, terrain, frame)[1], {})
    else:  # a cluster's workers are processes of their own: the client warms alone
        _chunked(sub, terrain, frame, "sync")


def one(path: str, n_lines: int) -> dict:
    strips, terrain, frame = scene(n_lines)
    _warm(path, strips, terrain, frame)
    rss = PeakRSS().__enter__()
    w0, c0 = time.perf_counter(), time.process_time()
    wall_cluster, extra = None, {}
    if path == "in_memory":
        cells = _in_memory(strips, terrain, frame)
    elif path == "ckdtree_handwritten":
        cells = _ckdtree(strips, terrain)
    elif path == "gdal_warp_geoloc":
        ours, grid = _our_grid(strips, terrain, frame)
        w0, c0 = time.perf_counter(), time.process_time()  # the grid is given, as to GDAL
        gdal = _gdal_warp(strips, terrain, frame, grid, extra)
        cells = gdal.shape[1] * gdal.shape[2]
    else:
        sched = {
            "chunked_1": "sync",
            "chunked_threads_2": "threads",
            "distributed_2": "distributed",
        }
        cells, wall_cluster = _chunked(strips, terrain, frame, sched[path])
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    rss.__exit__(None, None, None)
    w = wall_cluster or wall
    if path == "gdal_warp_geoloc":
        ref = ours.compute(scheduler="synchronous").values
        same = (gdal == ref) | (np.isnan(gdal) & np.isnan(ref))
        extra["share_cells_equal_to_ours"] = float(same.all(axis=0).mean())
        extra["output_px_per_warp_cpu_s"] = cells / extra["warp_cpu_s"]
        extra["share_cells_filled_ours_gdal"] = [
            float(np.isfinite(ref[0]).mean()),
            float(np.isfinite(gdal[0]).mean()),
        ]
    return {
        "path": path,
        "cores": CORES[path],
        "output_pixels": int(cells),
        "wall_s": w,
        "client_cpu_s": cpu,
        "output_px_per_s_per_core": cells / w / CORES[path],
        # the work this process did, per CPU second (a distributed run's is on its workers)
        "output_px_per_cpu_s": None if path == "distributed_2" else cells / cpu,
        "peak_rss_mib": rss.peak / 2**20,
        "peak_rss_over_start_mib": (rss.peak - rss.start) / 2**20,
        "input_mib": sum(np.asarray(s.values).nbytes for s in strips) / 2**20,
        "load_average_1_5_15": list(os.getloadavg()),
        "engine": str(Path(sys.modules["hsgeo"].__file__).parent),
        **extra,
    }


def _pairs(args, env) -> dict:
    """``chunked_1`` of this engine and of ``--vs-src``'s in turn (A B A B …), each a fresh
    process: the medians, the ratio pair by pair and each run's load average.
    """
    import statistics

    runs = {"this": [], "vs": []}
    for _ in range(args.pairs):
        for who in ("this", "vs"):
            e = dict(env)
            if who == "vs":
                e["PYTHONPATH"] = str(Path(args.vs_src).resolve())
            r = subprocess.run(
                [sys.executable, __file__, "--one", "chunked_1", "--lines", str(args.lines)],
                capture_output=True,
                text=True,
                env=e,
                check=True,
            )
            runs[who].append(json.loads(r.stdout.strip().splitlines()[-1]))
            print(who, json.dumps(runs[who][-1]), flush=True)

    def med(who, key):
        return statistics.median(r[key] for r in runs[who])

    ratio = [
        a["output_px_per_cpu_s"] / b["output_px_per_cpu_s"]
        for a, b in zip(runs["this"], runs["vs"], strict=True)
    ]
    return {
        "path": "chunked_1",
        "pairs": args.pairs,
        "vs_src": str(args.vs_src),
        "goal_output_px_per_cpu_s": GOAL_CELLS_PER_CPU_S,
        "this_median_output_px_per_cpu_s": med("this", "output_px_per_cpu_s"),
        "vs_median_output_px_per_cpu_s": med("vs", "output_px_per_cpu_s"),
        "ratio_this_over_vs_px_per_cpu_s_median": statistics.median(ratio),
        "ratio_this_over_vs_px_per_cpu_s_each": ratio,
        "this_median_peak_rss_over_start_mib": med("this", "peak_rss_over_start_mib"),
        "vs_median_peak_rss_over_start_mib": med("vs", "peak_rss_over_start_mib"),
        "load_average_1_5_15_each_run": {
            k: [r["load_average_1_5_15"] for r in v] for k, v in runs.items()
        },
        "runs": runs,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=2000, help="lines per strip (default 2000)")
    ap.add_argument("--one", choices=PATHS, help=argparse.SUPPRESS)
    ap.add_argument("--pairs", type=int, default=0, help="alternating chunked_1 runs vs --vs-src")
    ap.add_argument("--vs-src", default=None, help="the other engine's src directory (main's)")
    ap.add_argument("--pairs-only", action="store_true", help="only the pairs (no path rows)")
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(one(args.one, args.lines)))
        return 0
    rows = []
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    vs = _pairs(args, env) if args.pairs else None
    for p in PATHS if not args.pairs_only else ():
        r = subprocess.run(
            [sys.executable, __file__, "--one", p, "--lines", str(args.lines)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
        print(json.dumps(rows[-1]), flush=True)
    if args.pairs_only:
        out = {"n_lines_per_strip": args.lines, "vs_main": vs}
        (HERE / "results").mkdir(exist_ok=True)
        (HERE / "results" / "orthomosaic_vs_main.json").write_text(json.dumps(out, indent=1) + "\n")
        print(json.dumps(out, indent=1))
        return 0
    by = {r["path"]: r for r in rows}
    out = {
        "n_lines_per_strip": args.lines,
        "n_strips": 2,
        "n_px": 900,
        "n_bands": 3,
        "resolution_m": 0.3,
        "crs": "EPSG:25832",
        "rows": rows,
        "speedup_chunked_threads_2_over_chunked_1": by["chunked_1"]["wall_s"]
        / by["chunked_threads_2"]["wall_s"],
        "speedup_distributed_2_over_chunked_1": by["chunked_1"]["wall_s"]
        / by["distributed_2"]["wall_s"],
        "pyresample_in_memory_over_ckdtree_px_per_s": by["in_memory"]["output_px_per_s_per_core"]
        / by["ckdtree_handwritten"]["output_px_per_s_per_core"],
        "pyresample_in_memory_over_ckdtree_px_per_cpu_s": by["in_memory"]["output_px_per_cpu_s"]
        / by["ckdtree_handwritten"]["output_px_per_cpu_s"],
        "chunked_1_over_in_memory_px_per_cpu_s": by["chunked_1"]["output_px_per_cpu_s"]
        / by["in_memory"]["output_px_per_cpu_s"],
        "chunked_1_over_gdal_warp_geoloc_px_per_cpu_s": by["chunked_1"]["output_px_per_cpu_s"]
        / by["gdal_warp_geoloc"]["output_px_per_cpu_s"],
        "chunked_1_over_gdal_warp_alone_px_per_cpu_s": by["chunked_1"]["output_px_per_cpu_s"]
        / by["gdal_warp_geoloc"]["output_px_per_warp_cpu_s"],
        "goal_chunked_output_px_per_cpu_s": GOAL_CELLS_PER_CPU_S,
        "machine": {
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "load_average_1_5_15": list(os.getloadavg()),
            "note": "a shared 2-core machine: wall times (px/s/core) move with the other jobs, "
            "CPU seconds much less",
        },
        "note": "ckdtree_handwritten grids each strip alone in the local frame (no mosaic, no "
        "CRS): its output pixels are the sum of the two strips' grids",
    }
    if vs is not None:
        out["vs_main"] = vs
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "orthomosaic.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: v for k, v in out.items() if k != "rows"}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
