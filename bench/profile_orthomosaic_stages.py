"""Where the chunked orthomosaic's CPU time goes, stage by stage (issue 41).

The scene of :mod:`bench_orthomosaic` (2 LP strips x N lines x 900 px, 3 bands, 0.3 m, EPSG:25832)
is mosaicked by :func:`hsgeo.workflows.orthorectify.orthorectify` on Dask's synchronous
scheduler (one core), with the engine's stage functions wrapped by CPU-time counters
(``time.process_time``; a stage's time excludes the stages it calls that are counted too):

* ``footprint`` — :func:`hsgeo.ortho.strip_footprints` (the graph's block bounding boxes);
* ``rays`` — the sensor's ``rays`` (the trajectory's poses, the pixels' directions);
* ``intersection`` — :func:`hsgeo.geocode.intersect` (first crossing with the DSM);
* ``to_map`` — every CRS transform: the ground points into the grid's CRS and the DSM
  intersection's chords (``LocalFrame.enu_to_lonlat``, ``enu_to_map``,
  :func:`hsgeo.crs.lonlat_to_crs`, and :func:`hsgeo._approx_transform.approx_transform`,
  the verified polynomial that replaces them on most pixels; ``map_to_enu`` by PROJ is inside
  ``intersection``);
* ``neighbour_search`` — the nearest pixel of each cell (whatever the engine calls for it);
* ``mosaic_rule_and_rest`` — the tile's task minus the stages above (the rule, the values'
  gather, the concatenations);
* ``dask_graph_and_scheduler`` — the whole compute minus the tasks;
* ``write`` — :func:`hsgeo.io.raster.write_raster` of the computed mosaic to a GeoTIFF.

``python bench/profile_orthomosaic_stages.py [--lines N] [--out FILE]`` (PYTHONPATH selects the
engine: this tree's or another's, for a before/after); ``--summarise-main F … --summarise-this
F …`` writes the medians of such runs to ``bench/results/orthomosaic_stages.json``.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))


class Stages:
    """CPU seconds per stage, exclusive of nested counted stages."""

    def __init__(self):
        self.cpu, self.calls, self._stack = {}, {}, []

    def wrap(self, name, fn):
        @functools.wraps(fn)
        def inner(*a, **k):
            t0 = time.process_time()
            self._stack.append(0.0)
            try:
                return fn(*a, **k)
            finally:
                nested = self._stack.pop()
                dt = time.process_time() - t0
                self.cpu[name] = self.cpu.get(name, 0.0) + dt - nested
                self.calls[name] = self.calls.get(name, 0) + 1
                if self._stack:
                    self._stack[-1] += dt

        return inner


def patch(stages, strips, frame):
    import hsgeo.crs as hcrs
    import hsgeo.ortho as ortho

    cls = type(strips[0].sensor)
    cls.rays = stages.wrap("rays", cls.rays)
    ortho.intersect = stages.wrap("intersection", ortho.intersect)
    ortho.strip_footprints = stages.wrap("footprint", ortho.strip_footprints)
    fcls = type(frame)
    for m in ("enu_to_lonlat", "enu_to_map"):
        setattr(fcls, m, stages.wrap("to_map", getattr(fcls, m)))
    hcrs.lonlat_to_crs = stages.wrap("to_map", hcrs.lonlat_to_crs)
    try:  # the verified polynomial in place of PROJ on every pixel (issue 41)
        import hsgeo._approx_transform as hax

        hax.approx_transform = stages.wrap("to_map", hax.approx_transform)
    except ImportError:
        pass
    if hasattr(ortho, "resample_swath"):  # the kd-tree of the tiles before issue 41
        ortho.resample_swath = stages.wrap("neighbour_search", ortho.resample_swath)
    try:  # the compiled bucket search (imported by the tile's task when it runs)
        import hsgeo._nearest as near

        near.nearest_cells = stages.wrap("neighbour_search", near.nearest_cells)
    except ImportError:
        pass
    for name in ("mosaic_tile", "_tile_task"):
        setattr(ortho, name, stages.wrap("mosaic_rule_and_rest", getattr(ortho, name)))
    if hasattr(ortho, "block_ground"):
        ortho.block_ground = stages.wrap("geolocation_rest", ortho.block_ground)


def summarise(main_files, this_files, out_path) -> dict:
    """The median of each stage over paired runs of the previous main and this tree (files of
    ``--out``), into ``out_path`` (``bench/results/orthomosaic_stages.json``).
    """
    import statistics

    def side(files):
        runs = [json.loads(Path(f).read_text()) for f in files]
        names = sorted({k for r in runs for k in r["stages_cpu_s"]})
        med = {k: statistics.median(r["stages_cpu_s"].get(k, 0.0) for r in runs) for k in names}
        cells = runs[0]["output_cells"]
        cpu = statistics.median(r["cpu_s_build_and_compute"] for r in runs)
        return {
            "runs": len(runs),
            "engine": runs[0]["engine"],
            "output_cells": cells,
            "cpu_s_build_and_compute_median": cpu,
            "cells_per_cpu_s_build_and_compute_median": cells / cpu,
            "stages_cpu_s_median": med,
            "stages_ns_per_cell_median": {k: 1e9 * t / cells for k, t in med.items()},
            "cells_per_cpu_s_of_each_stage_median": {
                k: (cells / t if t > 0 else None) for k, t in med.items()
            },
            "checksum_nan_cells": sorted({r["checksum_nan_cells"] for r in runs}),
            "checksum_nansum": sorted(
                {r["checksum_nansum"] for r in runs if "checksum_nansum" in r}
            ),
            "load_average_1_5_15_each_run": [r["load_average_1_5_15"] for r in runs],
            "each_run": runs,
        }

    a, b = side(main_files), side(this_files)
    diff = [
        r["approx_largest_difference_m_first_block"]
        for r in b["each_run"]
        if "approx_largest_difference_m_first_block" in r
    ]
    out = {
        "what": "CPU seconds per stage of the chunked orthomosaic (bench/profile_orthomosaic_"
        "stages.py --summarise): 2 LP strips x 2000 lines x 900 px, 3 bands -> 3,165,204 cells "
        "at 0.3 m in EPSG:25832, Dask synchronous scheduler, one process, OPENBLAS_NUM_THREADS=1;"
        " the previous main and this tree run alternately (A B A B) on a shared 2-core machine "
        "under load (each run's load average recorded: CPU seconds inflate with it); medians",
        "goal_cells_per_cpu_s": 1.0e6,
        "previous_main": a,
        "this_branch": b,
        "cells_identical": a["checksum_nan_cells"] == b["checksum_nan_cells"]
        and (not a["checksum_nansum"] or a["checksum_nansum"] == b["checksum_nansum"]),
        "approximation": {
            "what": "each line block's PROJ transforms (the DSM chords to the map CRS and back, "
            "the ground to the grid's CRS) by a cubic fitted to PROJ at 64 nodes of the block's "
            "box, used only where the check set (343 lattice points + ~256 of the block's) is "
            "within a quarter of 1 mm (hsgeo._approx_transform)",
            "tolerance_m": 1e-3,
            "largest_difference_m_first_block": max(diff) if diff else None,
        },
        "what_remains": "the rays (the sensor's per-pixel rotations: hsgeo.sensors.pushbroom, "
        "numpy), the intersection's compiled cast and the PROJ checks of the approximation, "
        "the tiles' bucket search and mosaic rule, Dask's graph; the write (a COG with "
        "overviews, Zstandard) is outside the figure as in the bench",
    }
    Path(out_path).write_text(json.dumps(out, indent=1) + "\n")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=2000)
    ap.add_argument("--out", default=None)
    ap.add_argument("--summarise-main", nargs="*", help="--out files of the previous main")
    ap.add_argument("--summarise-this", nargs="*", help="--out files of this tree")
    args = ap.parse_args(argv)
    if args.summarise_main:
        out = summarise(
            args.summarise_main,
            args.summarise_this,
            args.out or HERE / "results" / "orthomosaic_stages.json",
        )
        print(
            json.dumps({k: v for k, v in out.items() if k not in ("previous_main", "this_branch")})
        )
        return 0
    import numpy as np
    from bench_orthomosaic import scene

    from hsgeo.io.raster import write_raster
    from hsgeo.workflows.orthorectify import OrthoInputs, OrthoOptions, orthorectify

    strips, terrain, frame = scene(args.lines)
    # warm the compiled kernels outside the timing (numba's cache load)
    orthorectify(
        OrthoInputs(tuple(s for s in strips), terrain),
        OrthoOptions(resolution_m=0.3, tile_px=512, frame=frame),
    )[:, :8, :8].compute(scheduler="synchronous")
    st = Stages()
    patch(st, strips, frame)
    c0 = time.process_time()
    m = orthorectify(
        OrthoInputs(tuple(strips), terrain),
        OrthoOptions(resolution_m=0.3, tile_px=512, frame=frame),
    )
    c1 = time.process_time()
    v = m.compute(scheduler="synchronous")
    c2 = time.process_time()
    with tempfile.TemporaryDirectory() as d:
        write_raster(v, Path(d) / "o.tif")
    c3 = time.process_time()
    cells = int(m.shape[1] * m.shape[2])
    tasks = sum(t for k, t in st.cpu.items() if k != "footprint")
    stages = {
        "graph_build_excl_footprint": c1 - c0 - st.cpu.get("footprint", 0.0),
        **st.cpu,
        "dask_graph_and_scheduler": (c2 - c1) - tasks,
        "write": c3 - c2,
    }
    out = {
        "lines_per_strip": args.lines,
        "output_cells": cells,
        "cpu_s_build_and_compute": c2 - c0,
        "cells_per_cpu_s_build_and_compute": cells / (c2 - c0),
        "stages_cpu_s": stages,
        "stage_calls": st.calls,
        "stages_ns_per_cell": {k: 1e9 * t / cells for k, t in stages.items()},
        "input_pixels": int(sum(s.n_lines * s.pixels.shape[0] for s in strips)),
        "checksum_nan_cells": int(np.isnan(v.values[0]).sum()),
        "load_average_1_5_15": list(os.getloadavg()),
        "engine": str(Path(sys.modules["hsgeo"].__file__).parent),
    }
    out["checksum_nansum"] = float(np.nansum(v.values.astype(np.float64)))
    try:  # the approximation's largest difference from PROJ on the first block (issue 41)
        from hsgeo._approx_transform import APPROX_TOL_M
        from hsgeo.ortho import block_ground

        g = [
            block_ground(strips[0].geometry(), terrain, frame, (0, 256), "EPSG:25832", tol)
            for tol in (APPROX_TOL_M, None)
        ]
        out["approx_largest_difference_m_first_block"] = float(np.abs(g[0][:2] - g[1][:2]).max())
    except ImportError:
        pass
    print(json.dumps(out, indent=1))
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
