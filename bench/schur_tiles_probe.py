"""Why the reduced-matrix kernel grows per observation from 1× to 10× the paper's block (issue 41).

    python bench/schur_tiles_probe.py [--scales 1,10] [--rounds 3] [--calls 2] [--out FILE]

The pushbroom solve at each scale is run until its first reduced-matrix formation, whose inputs
are kept (as ``schur_kernel_vs.py`` does); then the kernel alone, one numba thread, CPU seconds
per call, on these variants of the same inputs, in turn (``rounds`` times, each in a fresh
process):

* ``as_is``: the inputs as the solve gives them;
* ``tiles_in_l1``: the same arithmetic with every item pair's tile folded onto 64 slots (18 KB,
  which stay in the L1 cache): wrong sums, the same loads, multiplies and adds; the difference
  to ``as_is`` is what the tiles' memory traffic costs;
* ``points_by_item``: the points visited in the order of their first and last items (spline
  nodes), so that consecutive points write nearby tiles (fewer distinct tiles per 2,000 points);
* ``rows_contiguous``: each point's rows gathered next to each other (no gather from the
  observation order);
* ``rows_and_points_by_item``: both, the points in the order of ``points_by_item`` and their
  rows gathered in that order (what the kernel would see were the rows written by point, the
  points numbered along the items; the gather itself is not timed).

It also counts, at the smallest scale, how many of the group × group expansions of a formation
are of distinct pairs of groups (a group is one observation's spline items and weights): were
most of them repeated, their blocks could be summed before they are expanded into tiles.
Writes ``bench/results/schur_tiles_probe.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
VARIANTS = (
    "as_is",
    "tiles_in_l1",
    "points_by_item",
    "rows_contiguous",
    "rows_and_points_by_item",
)


def _variant(args: list, name: str) -> list:
    import numpy as np

    a = list(args)
    cols, vals, fcol, fw, fd, jp, order, ptr = a[:8]
    if name == "rows_and_points_by_item":
        a = _variant(a, "points_by_item")
        po = a[8]
        counts = np.diff(ptr)[po]
        rows = order[np.repeat(ptr[po] - np.r_[0, np.cumsum(counts)[:-1]], counts)
                     + np.arange(counts.sum())]  # fmt: skip
        for k in range(6):
            a[k] = np.ascontiguousarray(a[k][rows])
        a[6] = np.arange(rows.size, dtype=np.int64)
        a[7] = np.r_[0, np.cumsum(counts)].astype(np.int64)
        a[8] = np.arange(po.size, dtype=np.int64)
        a[9] = np.ascontiguousarray(a[9][po])  # V⁻¹ of each point
        return a
    if name == "tiles_in_l1":
        slot_of = a[14]
        a[14] = np.where(slot_of >= 0, slot_of % 64, -1)
        a[15] = 64 + fcol.shape[1]  # room for a run of Q tiles from the last slot
    elif name == "points_by_item":
        tile_of = a[13]
        f = fcol[order, 0].astype(np.int64)
        t = np.where(f >= 0, tile_of[np.maximum(f, 0)], 1 << 40)
        first = np.minimum.reduceat(t, ptr[:-1])
        last = np.maximum.reduceat(np.where(f >= 0, t, -1), ptr[:-1])
        a[8] = np.lexsort((last, first)).astype(np.int64)
    elif name == "rows_contiguous":
        for k in range(6):
            a[k] = np.ascontiguousarray(a[k][order])
        a[6] = np.arange(order.size, dtype=np.int64)
    return a


def _child(path: Path, name: str, calls: int) -> dict:
    import hsgeo.adjust._fast as F

    sys.path.insert(0, str(HERE))
    from schur_kernel_vs import kernel_cpu_seconds

    with open(path, "rb") as f:
        args = _variant(pickle.load(f), name)
    F._reduced_kernel(*args)  # compiled kernels loaded, pages touched
    return {"cpu_seconds": kernel_cpu_seconds(F._reduced_kernel, args, calls),
            "rows": int(args[6].size)}  # fmt: skip


def _distinct_pairs(path: Path) -> dict:
    import numpy as np

    with open(path, "rb") as f:
        a = pickle.load(f)
    fcol, fw, order, ptr = a[2], a[3], a[6], a[7]
    key = np.ascontiguousarray(np.concatenate([fcol.astype(np.float64), fw], axis=1))
    gid = np.unique(key.view(np.dtype((np.void, key.itemsize * key.shape[1]))).ravel(),
                    return_inverse=True)[1].ravel()  # fmt: skip
    gid[~(fcol >= 0).any(axis=1)] = -1
    g = gid[order]
    n = 0
    pairs = set()
    for i in range(ptr.size - 1):
        seq = [x for j, x in enumerate(g[ptr[i] : ptr[i + 1]]) if x >= 0]
        gs = [x for j, x in enumerate(seq) if j == 0 or x != seq[j - 1]]
        for p in range(len(gs)):
            for q in range(p, len(gs)):
                n += 1
                pairs.add((int(gs[p]), int(gs[q])))
    return {"rows": int(order.size), "groups": int(np.unique(gid[gid >= 0]).size),
            "group_pair_expansions": n, "distinct_group_pairs": len(pairs),
            "share_distinct": len(pairs) / n}  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scales", default="1,10")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "schur_tiles_probe.json")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(
            "RESULT " + json.dumps(_child(Path(args.child[0]), args.child[1], int(args.child[2])))
        )
        return 0
    sys.path.insert(0, str(HERE))
    import schur_kernel_vs as K

    scales = [float(s) for s in args.scales.split(",")]
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    import pushbroom_vs_main as V

    out = {"what": __doc__.split("\n\n")[0], "variants": {}, "runs": [], "cpu": V._cpu(),
           "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="hsgeo-tiles-") as tmp:
        for sc in scales:
            path = Path(tmp) / f"in{sc:g}.pkl"
            K._capture(sc, args.seed, path)
            if sc == min(scales):
                out["group_pairs_at_smallest_scale"] = _distinct_pairs(path)
            for rnd in range(args.rounds):
                for name in VARIANTS:
                    cmd = [sys.executable, __file__, "--child", str(path), name, str(args.calls)]
                    load = os.getloadavg()[0]
                    cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
                    r = next(
                        json.loads(x[7:]) for x in cp.stdout.splitlines() if x.startswith("RESULT ")
                    )
                    r.update(scale=sc, round=rnd, variant=name, loadavg_1min_before=load)
                    out["runs"].append(r)
                    print(f"{sc:g}x {name:16s} {min(r['cpu_seconds']):7.2f} CPU-s", flush=True)
    for sc in scales:
        for name in VARIANTS:
            rs = [r for r in out["runs"] if r["scale"] == sc and r["variant"] == name]
            med = statistics.median(min(r["cpu_seconds"]) for r in rs)
            out["variants"].setdefault(f"{sc:g}x", {})[name] = {
                "median_cpu_seconds": med,
                "cpu_ns_per_row": med / rs[0]["rows"] * 1e9,
            }
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out["variants"], indent=1))
    print(json.dumps(out.get("group_pairs_at_smallest_scale"), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
