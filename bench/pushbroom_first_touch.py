"""What the first touch of the solve's memory costs, and how much of it is numpy's huge pages
(issue 41).

    python bench/pushbroom_first_touch.py [--scales 1,10] [--rounds 3,1] [--out FILE]

Each run is one fresh process (one numba thread, one BLAS thread, the Makefile's
``GLIBC_TUNABLES``, so that memory freed by the first solve is kept for the second): the
scaling benchmark's problem (``bench_pushbroom_ba._problem``) is adjusted twice in a row, and
each solve's user and system seconds and minor page faults are recorded. The second solve
reuses the pages the first one faulted in, so the difference between the two is the first
touch of the solve's memory. Each run is made in three ways, in turn:

* ``as_is``: the engine as it is (the Jacobian's kept arrays advised small pages,
  ``hsgeo.adjust.system._small_pages_empty``; numpy advises huge pages for its other large
  arrays);
* ``buffers_numpy_default``: the Jacobian's arrays left to numpy's advice (huge pages), as
  before the engine advised them;
* ``all_small_pages``: ``NUMPY_MADVISE_HUGEPAGE=0`` (numpy's documented switch): no array of
  the process advised huge pages.

Writes ``bench/results/pushbroom_first_touch.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TUNABLES = "glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967296"
MODES = {"as_is": None, "buffers_numpy_default": None, "all_small_pages": "0"}


def _child(scale: float, seed: int, mode: str) -> dict:
    import gc
    import resource

    import numpy as np

    import hsgeo.adjust.system as S

    if mode == "buffers_numpy_default":
        S._small_pages_empty = lambda shape, dtype=np.float64: np.empty(shape, dtype=dtype)

    sys.path.insert(0, str(HERE))
    import bench_pushbroom_ba as B

    from hsgeo.workflows.pushbroom_ba import solve

    _, p, blocks = B._problem(scale, seed)
    gc.collect()
    B._load_compiled_kernels(seed)
    solves = []
    for _ in range(2):
        gc.collect()
        r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        res = solve(p, blocks)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        solves.append(
            {
                "wall_seconds": wall,
                "user_seconds": r1.ru_utime - r0.ru_utime,
                "system_seconds": r1.ru_stime - r0.ru_stime,
                "minor_faults": r1.ru_minflt - r0.ru_minflt,
                "final_cost": float(res.cost_history[-1]),
            }
        )
    return {
        "solves": solves,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def _thp() -> dict:
    out = {}
    for k in ("enabled", "defrag"):
        f = Path("/sys/kernel/mm/transparent_hugepage") / k
        out[k] = f.read_text().strip() if f.exists() else None
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scales", default="1,10")
    ap.add_argument("--rounds", default="3,1", help="rounds per scale, in the order of --scales")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "pushbroom_first_touch.json")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        sc, seed, mode = args.child
        print("RESULT " + json.dumps(_child(float(sc), int(seed), mode)))
        return 0
    sys.path.insert(0, str(HERE))
    import pushbroom_vs_main as V

    scales = [float(s) for s in args.scales.split(",")]
    rounds = [int(r) for r in args.rounds.split(",")]
    out = {
        "what": __doc__.split("\n\n")[0].replace("\n", " "),
        "cpu": V._cpu(),
        "transparent_hugepage": _thp(),
        "glibc_tunables": TUNABLES,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "runs": [],
        "summary": {},
    }
    for sc, nr in zip(scales, rounds + [rounds[-1]] * len(scales), strict=False):
        for rnd in range(nr):
            for mode, value in MODES.items():
                env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
                env["GLIBC_TUNABLES"] = TUNABLES
                env["PYTHONPATH"] = str(ROOT / "src")
                env.pop("NUMPY_MADVISE_HUGEPAGE", None)
                if value is not None:
                    env["NUMPY_MADVISE_HUGEPAGE"] = value
                cmd = [sys.executable, __file__, "--child", str(sc), str(args.seed), mode]
                load = os.getloadavg()
                cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
                r = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x[:7] == "RESULT ")
                r.update(scale=sc, round=rnd, mode=mode, load_average_1_5_15_before=load)
                out["runs"].append(r)
                a, b = r["solves"]
                print(
                    f"{sc:g}x {mode:26s} first {a['user_seconds']:.2f}+{a['system_seconds']:.2f}"
                    f" second {b['user_seconds']:.2f}+{b['system_seconds']:.2f} CPU-s",
                    flush=True,
                )
        for mode in MODES:
            rs = [r for r in out["runs"] if r["scale"] == sc and r["mode"] == mode]

            def med(i, k, rs=rs):
                return statistics.median(r["solves"][i][k] for r in rs)

            first = med(0, "user_seconds") + med(0, "system_seconds")
            second = med(1, "user_seconds") + med(1, "system_seconds")
            out["summary"].setdefault(f"{sc:g}x", {})[mode] = {
                "runs": len(rs),
                "first_solve_cpu_s": first,
                "first_solve_system_s": med(0, "system_seconds"),
                "second_solve_cpu_s": second,
                "second_solve_system_s": med(1, "system_seconds"),
                "first_touch_cpu_s": first - second,
                "first_solve_minor_faults": med(0, "minor_faults"),
            }
    args.out.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    print(json.dumps(out["summary"], indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
