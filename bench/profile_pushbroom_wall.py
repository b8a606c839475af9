"""Where the paper-size pushbroom solve's wall seconds go on the kernels' threads (issue 41).

    python bench/profile_pushbroom_wall.py [--scale 1] [--threads 2] [--out FILE]

The wall goal (≤ 2.0 s, two threads) asks for a split that :mod:`profile_pushbroom` (one
thread, CPU seconds) cannot give: how much of the solve's wall time the main thread spends
waiting for the compiled kernels' chunks on the other threads (``over_chunks``: the waits are
``acquire`` of a lock) and how much it spends alone (Python, numpy and the kernels that run on
one thread). The scaling benchmark's problem (``bench_pushbroom_ba._problem``) is adjusted as
in the chapter, under ``cProfile`` with its default wall clock, after the compiled kernels
were loaded. Writes ``bench/results/pushbroom_wall_profile.json``: the wall and CPU seconds of
the solve, the seconds waited on the threads, and the main thread's own calls that take the
rest (by their own time).
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import json
import os
import pstats
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=None, help="numba threads (default: all)")
    ap.add_argument("--top", type=int, default=15)
    ap.add_argument("--out", default=str(HERE / "results" / "pushbroom_wall_profile.json"))
    ap.add_argument("--pstats", help="also dump cProfile's statistics to this file (callers)")
    args = ap.parse_args()
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import numba

    if args.threads:
        numba.set_num_threads(args.threads)
    sys.path.insert(0, str(HERE))
    import bench_pushbroom_ba as B

    from hsgeo.workflows.pushbroom_ba import solve

    obs, p, blocks = B._problem(args.scale, args.seed)
    del obs
    gc.collect()
    B._load_compiled_kernels(args.seed)
    pr = cProfile.Profile()
    t0, c0 = time.perf_counter(), time.process_time()
    pr.enable()
    res = solve(p, blocks)
    pr.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    if args.pstats:
        pr.dump_stats(args.pstats)
    st = pstats.Stats(pr).stats
    lock = "<method 'acquire' of '_thread.lock' objects>"
    waited = sum(v[2] for k, v in st.items() if k[2] == lock)
    own = sorted(
        ((v[2], f"{Path(k[0]).name}:{k[1]}({k[2]})") for k, v in st.items() if k[2] != lock),
        reverse=True,
    )
    out = {
        "what": __doc__.splitlines()[0],
        "scale": args.scale,
        "numba_threads": numba.get_num_threads(),
        "iterations": res.iterations,
        "wall_seconds": wall,
        "cpu_seconds": cpu,
        "waited_on_the_kernels_threads_s": waited,
        "main_thread_alone_s": wall - waited,
        "main_thread_calls_by_own_seconds": [
            {"seconds": round(s, 4), "call": name} for s, name in own[: args.top]
        ],
        "note": "cProfile's own overhead is in main_thread_alone_s (≈ 50,000 calls)",
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "date_utc": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()),
        "loadavg": os.getloadavg(),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
