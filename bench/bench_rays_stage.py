"""The rays stage of the chunked orthomosaic before/after the compiled LP rays (issue 41).

Two figures per engine (``PYTHONPATH`` = this tree's ``src`` or ``--vs-src``), run alternately:

* ``rays_alone``: :meth:`PushbroomCamera.rays` of one strip of :mod:`bench_orthomosaic`'s scene
  (2,000 lines x 900 px) in line blocks of 256 as :func:`hsgeo.ortho._ground_off_nadir` asks for
  them (a :class:`hsgeo._perline.PerLine` trajectory), CPU seconds, best of 3;
* the stages of ``bench/profile_orthomosaic_stages.py`` (its ``rays`` stage and the whole
  orthomosaic's CPU seconds and cells per CPU second), in one of two modes: ``proj`` (the
  workflow as it is: PROJ on every pixel) or ``approx`` (the workflow's
  :func:`hsgeo.ortho.orthomosaic` given ``crs_tol_m = hsgeo._approx_transform.APPROX_TOL_M``,
  the verified polynomial in place of PROJ, as the stage profile of the issue was measured).

``python bench/bench_rays_stage.py --vs-src /path/to/main/src [--pairs 2] [--mode proj|approx]``
writes its mode's medians, every run and the load averages into
``bench/results/rays_stage.json`` (the other mode's entry is kept).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
SRC = HERE.parent / "src"


def rays_alone(n_lines: int = 2000, block: int = 256) -> dict:
    """One strip's rays in line blocks, CPU seconds (best of 3) and a checksum."""

    sys.path.insert(0, str(HERE))
    from bench_orthomosaic import scene

    from hsgeo._perline import PerLine

    s = scene(n_lines)[0][0]
    k = s.pixels.shape[0]
    blocks = [slice(a, min(s.n_lines, a + block)) for a in range(0, s.n_lines, block)]
    inputs = [(s.line_pixels(b), b) for b in blocks]

    def run():
        acc = 0.0
        for (tt, pp), b in inputs:
            nav = PerLine(s.trajectory, s.t_s[b], tt, k)
            o, d = s.sensor.rays(pp, tt, nav, **s.pixel_kw)
            acc += float(d[::997].sum() + o[::997].sum())
        return acc

    run()  # numba's cache load
    cpu = []
    for _ in range(3):
        c0 = time.process_time()
        check = run()
        cpu.append(time.process_time() - c0)
    n = s.n_lines * k
    return {
        "rays": n,
        "cpu_s_best_of_3": min(cpu),
        "ns_per_ray": 1e9 * min(cpu) / n,
        "check": check,
    }


def _run(src: str, args: list[str]) -> dict:
    env = {**os.environ, "PYTHONPATH": src, "OPENBLAS_NUM_THREADS": "1"}
    r = subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, check=True)
    return json.loads(r.stdout.strip().splitlines()[-1])


def stages_approx(out: str) -> None:
    """``profile_orthomosaic_stages.py --out out`` with the workflow's orthomosaic given the
    CRS approximation's tolerance.
    """
    import functools

    import hsgeo.workflows.orthorectify as wf
    from hsgeo._approx_transform import APPROX_TOL_M

    wf.orthomosaic = functools.partial(wf.orthomosaic, crs_tol_m=APPROX_TOL_M)
    sys.path.insert(0, str(HERE))
    import profile_orthomosaic_stages

    profile_orthomosaic_stages.main(["--out", out])


def one(src: str, mode: str) -> dict:
    """Both figures of the engine at ``src`` (each in a fresh process)."""
    alone = _run(src, [__file__, "--alone"])
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "stages.json"
        cmd = (
            [str(HERE / "profile_orthomosaic_stages.py"), "--out", str(out)]
            if mode == "proj"
            else [__file__, "--stages-approx", str(out)]
        )
        subprocess.run(
            [sys.executable, *cmd],
            capture_output=True,
            env={**os.environ, "PYTHONPATH": src, "OPENBLAS_NUM_THREADS": "1"},
            check=True,
        )
        st = json.loads(out.read_text())
    return {
        "rays_alone": alone,
        "rays_stage_cpu_s": st["stages_cpu_s"]["rays"],
        "orthomosaic_cpu_s_build_and_compute": st["cpu_s_build_and_compute"],
        "cells_per_cpu_s_build_and_compute": st["cells_per_cpu_s_build_and_compute"],
        "output_cells": st["output_cells"],
        "stages_cpu_s": st["stages_cpu_s"],
        "checksum_nan_cells": st["checksum_nan_cells"],
        "checksum_nansum": st["checksum_nansum"],
        "load_average_1_5_15": list(os.getloadavg()),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vs-src", help="the previous engine's src directory (main's)")
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--mode", choices=("proj", "approx"), default="proj")
    ap.add_argument("--alone", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--stages-approx", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.alone:
        print(json.dumps(rays_alone()))
        return 0
    if args.stages_approx:
        stages_approx(args.stages_approx)
        return 0
    runs = {"previous_main": [], "this_branch": []}
    for _ in range(args.pairs):
        for side, src in (("previous_main", args.vs_src), ("this_branch", str(SRC))):
            runs[side].append(one(src, args.mode))
            print(side, json.dumps(runs[side][-1]), flush=True)

    def med(side, f):
        return statistics.median(f(r) for r in runs[side])

    out = {
        "mode": args.mode,
        "what": "the rays stage of the chunked orthomosaic (bench/profile_orthomosaic_stages.py: "
        "2 LP strips x 2000 lines x 900 px, 3 bands -> cells at 0.3 m, synchronous scheduler) "
        "and one strip's rays alone (2000 x 900 rays in blocks of 256 lines), the previous main "
        "and this tree alternately on a shared 2-core machine at nice 5; medians of CPU "
        "seconds (they inflate with the load average, recorded per run)",
        "goal_cells_per_cpu_s": 1.0e6,
        **{
            side: {
                "runs": len(runs[side]),
                "rays_alone_ns_per_ray_median": med(side, lambda r: r["rays_alone"]["ns_per_ray"]),
                "rays_stage_cpu_s_median": med(side, lambda r: r["rays_stage_cpu_s"]),
                "orthomosaic_cpu_s_median": med(
                    side, lambda r: r["orthomosaic_cpu_s_build_and_compute"]
                ),
                "cells_per_cpu_s_median": med(
                    side, lambda r: r["cells_per_cpu_s_build_and_compute"]
                ),
                "each_run": runs[side],
            }
            for side in runs
        },
    }
    out["cells_identical"] = (
        len({(r["checksum_nan_cells"], r["checksum_nansum"]) for rs in runs.values() for r in rs})
        == 1
    )
    path = HERE / "results" / "rays_stage.json"
    path.parent.mkdir(exist_ok=True)
    every = json.loads(path.read_text()) if path.exists() else {}
    every[args.mode] = out
    path.write_text(json.dumps(every, indent=1) + "\n")
    brief = {s: {k: v for k, v in out[s].items() if k != "each_run"} for s in runs}
    print(json.dumps({**{k: v for k, v in out.items() if k not in runs}, **brief}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
