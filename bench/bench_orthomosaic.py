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
  per strip, no mosaic rule and no CRS.

``python bench/bench_orthomosaic.py [--lines N]`` → ``bench/results/orthomosaic.json``.
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
PATHS = ("in_memory", "chunked_1", "chunked_threads_2", "distributed_2", "ckdtree_handwritten")
CORES = {
    "in_memory": 1,
    "chunked_1": 1,
    "chunked_threads_2": 2,
    "distributed_2": 2,
    "ckdtree_handwritten": 1,
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


def one(path: str, n_lines: int) -> dict:
    strips, terrain, frame = scene(n_lines)
    rss = PeakRSS().__enter__()
    w0, c0 = time.perf_counter(), time.process_time()
    wall_cluster = None
    if path == "in_memory":
        cells = _in_memory(strips, terrain, frame)
    elif path == "ckdtree_handwritten":
        cells = _ckdtree(strips, terrain)
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
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=2000, help="lines per strip (default 2000)")
    ap.add_argument("--one", choices=PATHS, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(one(args.one, args.lines)))
        return 0
    rows = []
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    for p in PATHS:
        r = subprocess.run(
            [sys.executable, __file__, "--one", p, "--lines", str(args.lines)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
        print(json.dumps(rows[-1]), flush=True)
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
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "orthomosaic.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: v for k, v in out.items() if k != "rows"}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
