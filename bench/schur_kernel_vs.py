"""The reduced-matrix (Schur) kernel alone, on one set of inputs, checkouts in turn.

    python bench/schur_kernel_vs.py --scale 10 --vs /path/to/checkout [--vs …] [--rounds 3]
        [--calls 2] [--out FILE]

The pushbroom solve at ``scale`` is run with this checkout until its first reduced-matrix
formation; that call's inputs (the row-compressed Jacobian, point rows, V⁻¹, the Schur pattern)
are pickled. Then each checkout (this one first, then every ``--vs``) in turn, ``rounds``
times, loads them in a fresh process with its own ``src`` first on the path, calls its
``hsgeo.adjust._fast._reduced_kernel`` once (compiled kernels loaded) and ``calls`` more times,
each timed in CPU seconds (one numba thread). The output's hash tells whether the checkouts
form the same bits. Whole-solve profiles mix the kernel with everything around it and vary by
±10 % between runs on these machines; the same inputs, in turn, isolate the kernel.
Writes ``bench/results/schur_kernel_vs.json``.
"""

from __future__ import annotations

import argparse
import hashlib
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


def _capture(scale: float, seed: int, path: Path) -> None:
    sys.path.insert(0, str(HERE))
    import bench_pushbroom_ba as B

    import hsgeo.adjust._fast as F
    from hsgeo.workflows.pushbroom_ba import solve

    kernel = F._reduced_kernel

    class _Got(Exception):
        pass

    def first(*a):
        with open(path, "wb") as f:
            pickle.dump(a, f, protocol=5)
        raise _Got

    F._reduced_kernel = first
    _, p, blocks = B._problem(scale, seed)
    try:
        solve(p, blocks)
    except _Got:
        return
    finally:
        F._reduced_kernel = kernel
    raise SystemExit("the solve formed no reduced matrix")


def _time(root: Path, path: Path, calls: int) -> dict:
    import hsgeo.adjust._fast as F

    if not Path(F.__file__).resolve().is_relative_to(root.resolve()):
        raise SystemExit(f"hsgeo imported from {F.__file__}, not from {root}")
    with open(path, "rb") as f:
        args = pickle.load(f)
    out = F._reduced_kernel(*args)
    digest = hashlib.sha1(out[0].tobytes() + out[1].tobytes()).hexdigest()[:12]
    del out
    return {"hash": digest, "cpu_seconds": kernel_cpu_seconds(F._reduced_kernel, args, calls)}


def kernel_cpu_seconds(kernel, args, calls: int) -> list[float]:
    """The CPU seconds (user + system, this process) of ``calls`` calls of ``kernel(*args)``,
    each on its own; the caller has called it once already (compiled kernels loaded, pages
    touched). Shared by the kernel probes (schur_tiles_probe.py, schur_stage_probe.py)."""
    import resource

    cpu = []
    for _ in range(calls):
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        out = kernel(*args)
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        cpu.append((r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
        del out
    return cpu


def _commit(root: Path) -> str | None:
    cp = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True
    )
    return cp.stdout.strip() or None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vs", type=Path, action="append", default=[], help="another checkout")
    ap.add_argument("--scale", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=2)
    ap.add_argument("--child", choices=("capture", "time"), help=argparse.SUPPRESS)
    ap.add_argument("--root", type=Path, default=ROOT, help=argparse.SUPPRESS)
    ap.add_argument("--inputs", type=Path, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--out", default=str(HERE / "results" / "schur_kernel_vs.json"))
    args = ap.parse_args(argv)
    if args.child == "capture":
        _capture(args.scale, args.seed, args.inputs)
        return 0
    if args.child == "time":
        print("RESULT " + json.dumps(_time(args.root, args.inputs, args.calls)), flush=True)
        return 0
    roots = [ROOT, *args.vs]
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        inputs = Path(tmp) / "inputs.pkl"
        e = dict(env, PYTHONPATH=str(ROOT / "src"))
        cmd = [sys.executable, __file__, "--child", "capture", "--scale", str(args.scale)]
        subprocess.run([*cmd, "--seed", str(args.seed), "--inputs", str(inputs)], env=e, check=True)
        runs = {str(r): [] for r in roots}
        for k in range(args.rounds):
            for r in roots:
                print(f"round {k + 1}/{args.rounds}: {r} ...", flush=True)
                e = dict(env, PYTHONPATH=str(r / "src"))
                cmd = [sys.executable, __file__, "--child", "time", "--root", str(r)]
                cmd += ["--inputs", str(inputs), "--calls", str(args.calls)]
                load = os.getloadavg()
                cp = subprocess.run(cmd, env=e, capture_output=True, text=True, check=True)
                got = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x[:7] == "RESULT ")
                got["load_average_1_5_15_before"] = load
                runs[str(r)].append(got)
    sides = {
        str(r): {
            "commit": _commit(r),
            "hash": sorted({g["hash"] for g in runs[str(r)]}),
            "cpu_seconds_each_call": [c for g in runs[str(r)] for c in g["cpu_seconds"]],
            "median_cpu_seconds": statistics.median(
                c for g in runs[str(r)] for c in g["cpu_seconds"]
            ),
        }
        for r in roots
    }
    this = sides[str(ROOT)]["median_cpu_seconds"]
    out = {
        "what": "the reduced-matrix kernel (_fast._reduced_kernel) alone on the inputs of the "
        "pushbroom solve's first formation, each checkout in turn in a fresh process, one "
        "numba thread, CPU seconds per call",
        "scale": args.scale,
        "rounds": args.rounds,
        "calls_per_round": args.calls,
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "this": str(ROOT),
        "sides": sides,
        "median_ratio_this_over_each": {
            r: this / s["median_cpu_seconds"] for r, s in sides.items() if r != str(ROOT)
        },
        "same_bits_as_this": {
            r: s["hash"] == sides[str(ROOT)]["hash"] for r, s in sides.items() if r != str(ROOT)
        },
        "runs": runs,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({k: out[k] for k in ("median_ratio_this_over_each", "same_bits_as_this")}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
