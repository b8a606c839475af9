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
engine: this tree's or another's, for a before/after).
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=2000)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
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
    print(json.dumps(out, indent=1))
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
