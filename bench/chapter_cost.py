"""CPU seconds of one chapter's run at one seed and scale, in one warm process (issue 41/42).

    PYTHONPATH=TREE/src nice -n 5 python bench/chapter_cost.py CHAPTER --seed S --scale 0.05 \
        --label before|after [--rows DIR] [--profile FILE] [--out bench/results/chapter_costs.json]

"Warm": the imports are done and numba's on-disk caches of the kernels exist (a run before this
one compiled them), so the figure is the chapter's own work — what each seed of the seed sweep
(``bench/bench_seed_sweep.py``) costs. Measured with ``time.process_time`` around
:func:`hsgeo.reproduce.run` (this process's user + system CPU, all threads), beside the wall time
and the load average before and after. ``--rows DIR`` writes the chapter's JSON as
``hsgeo reproduce --json`` does (for ``bench/compare_reproductions.py``); ``--profile FILE``
runs under cProfile (the CPU figure then includes its overhead) and records the top items by
cumulative and own time. ``--out`` merges the measurement into that file under
``chapters.<chapter>.<label>``.
"""

import argparse
import io
import json
import os
import pstats
import subprocess
import sys
import time
from pathlib import Path


def _top(prof_path: str, key: str, n: int = 12) -> list[dict]:
    s = io.StringIO()
    st = pstats.Stats(prof_path, stream=s)
    st.sort_stats(key)
    out = []
    for func in st.fcn_list[:n]:
        cc, nc, tt, ct, _ = st.stats[func]
        out.append(
            {
                "function": f"{Path(func[0]).name}:{func[1]}({func[2]})",
                "calls": int(nc),
                "own_s": round(tt, 2),
                "cumulative_s": round(ct, 2),
            }
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("chapter")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scale", type=float, default=0.05)
    ap.add_argument("--label", required=True)
    ap.add_argument("--rows", default=None, help="folder for CHAPTER.json")
    ap.add_argument("--profile", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--commit", default=None, help="the source's commit, if not a git tree")
    a = ap.parse_args()

    import hsgeo
    from hsgeo.reproduce import run

    load0 = os.getloadavg()
    w0, c0 = time.perf_counter(), time.process_time()
    if a.profile:
        import cProfile

        prof = cProfile.Profile()
        rep = prof.runcall(run, a.chapter, a.seed, a.scale)
        prof.dump_stats(a.profile)
    else:
        rep = run(a.chapter, a.seed, a.scale)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    load1 = os.getloadavg()
    if a.rows:
        Path(a.rows).mkdir(parents=True, exist_ok=True)
        (Path(a.rows) / f"{a.chapter}.json").write_text(rep.to_json())
    src = Path(hsgeo.__file__).resolve().parents[2]
    try:
        commit = subprocess.run(
            ["git", "-C", str(src), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = bool(
            subprocess.run(
                ["git", "-C", str(src), "status", "--porcelain", "src"],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.strip()
        )
    except (subprocess.CalledProcessError, FileNotFoundError):
        commit, dirty = "unknown (not a git tree)", False
    if a.commit:
        commit, dirty = a.commit, False
    m = {
        "seed": a.seed,
        "scale": a.scale,
        "cpu_s": round(cpu, 1),
        "wall_s": round(wall, 1),
        "load_average_1min_before_after": [round(load0[0], 2), round(load1[0], 2)],
        "source": str(src),
        "commit": commit + (" + uncommitted changes" if dirty else ""),
        "profiled": bool(a.profile),
        "python": sys.version.split()[0],
    }
    if a.profile:
        m["profile_top_cumulative"] = _top(a.profile, "cumulative")
        m["profile_top_own"] = _top(a.profile, "tottime")
    print(json.dumps(m, indent=1))
    if a.out:
        p = Path(a.out)
        doc = json.loads(p.read_text()) if p.exists() else {}
        doc.setdefault("description", __doc__.split("\n\n")[0].strip())
        doc.setdefault("chapters", {}).setdefault(a.chapter, {})[a.label] = m
        p.write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
