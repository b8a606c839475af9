"""What each stage of the reduced-matrix kernel costs, by taking it out (issue 41).

    python bench/schur_stage_probe.py [--scale 1] [--rounds 3] [--calls 3] [--out FILE]

The pushbroom solve at ``scale`` is run until its first reduced-matrix formation, whose inputs
are kept (as ``schur_kernel_vs.py`` does). Then copies of ``hsgeo/adjust/_fast.py`` are
written to a temporary directory, each with one stage of the per-point work of
``_reduced_chunk`` taken out, and each copy's ``_reduced_kernel`` is timed on those inputs in a
fresh process (one numba thread, CPU seconds per call, ``rounds`` rounds in turn):

* ``as_is``: the kernel unchanged (a copy too, compiled like the others);
* ``without_tiles``: no group × group block is expanded into the items' tiles;
* ``without_slot_blocks``: no group × slot-column block is expanded into A;
* ``without_group_schur_rows``: the groups' rows of ``C − Z V⁻¹ Zᵀ`` are not formed;
* ``without_normals``: the point's local ``C = Yᵀ Y`` and ``Z = Yᵀ J_p`` are not formed;
* ``without_expansion``: none of the three expansions (tiles, slot blocks, slot × slot).

A stage's cost is ``as_is`` minus the copy without it (the sums are wrong, the rest of the
work is the same). Copies whose patch no longer matches the kernel's source stop the probe
with the stage named: the probe is then out of date, not the kernel.
Writes ``bench/results/schur_stage_probe.json``.
"""

from __future__ import annotations

import argparse
import importlib
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
SOURCE = ROOT / "src" / "hsgeo" / "adjust" / "_fast.py"

_TILES = (
    "                n_miss += _group_tiles("
    "C, fcol, fw, grow, g, h, kf, tile_of, slot_of, tiles, R)\n"
)
_SLOT_BLOCKS = "            _slot_blocks(C, fcol, fw, grow, g, ng, kf, nl, sl, A)\n"
_GROUP_ROWS = "            _schur_row(C, Z, T, a, (a // kf) * kf, L)\n"
_NORMALS = (
    "        _point_normals_local(\n"
    "            cols, vals, fcol, fd, jp, order, a0, a1, grow, ng, pos, L, C, Z, li, lv\n"
    "        )\n"
)
_SLOT_SLOT = (
    "        nr = _runs(sl, nl, run_e, run_s, run_n)\n"
    "        _slot_slot(C, Z, T, ng, kf, gl, nl, sl, run_e, run_n, nr, A)\n"
)
_PASS_TILES = "                pass\n"
_PASS = "            pass\n"

#: variant → the (text, replacement) patches of the kernel's source
VARIANTS = {
    "as_is": [],
    "without_tiles": [(_TILES, _PASS_TILES)],
    "without_slot_blocks": [(_SLOT_BLOCKS, _PASS)],
    "without_group_schur_rows": [(_GROUP_ROWS, _PASS)],
    "without_normals": [(_NORMALS, "        pass\n")],
    "without_expansion": [(_TILES, _PASS_TILES), (_SLOT_BLOCKS, _PASS), (_SLOT_SLOT, "")],
}
#: stage → the variant without it
STAGES = {
    "tiles (group × group blocks into the items' tiles)": "without_tiles",
    "slot blocks (group × slot-column blocks into A)": "without_slot_blocks",
    "groups' rows of C − Z V⁻¹ Zᵀ": "without_group_schur_rows",
    "local normals C = YᵀY, Z = YᵀJ_p": "without_normals",
    "all three expansions": "without_expansion",
}


def _write_variants(tmp: Path) -> None:
    src = SOURCE.read_text(encoding="utf-8")  # (numba caches each copy beside it)
    for name, patches in VARIANTS.items():
        text = src
        for old, new in patches:
            if text.count(old) != 1:
                raise SystemExit(
                    f"schur_stage_probe: the patch of {name!r} does not match "
                    f"{SOURCE.relative_to(ROOT)} once; update the probe's patches"
                )
            text = text.replace(old, new)
        (tmp / f"_fast_{name}.py").write_text(text, encoding="utf-8")


def _child(tmp: Path, path: Path, name: str, calls: int) -> dict:
    sys.path[:0] = [str(tmp), str(HERE)]
    from schur_kernel_vs import kernel_cpu_seconds

    F = importlib.import_module(f"_fast_{name}")
    with open(path, "rb") as f:
        args = pickle.load(f)
    F._reduced_kernel(*args)  # compiled, pages touched
    cpu = kernel_cpu_seconds(F._reduced_kernel, args, calls)
    return {"cpu_seconds": cpu, "points": int(args[7].size - 1), "rows": int(args[6].size)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--calls", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "schur_stage_probe.json")
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        tmp, path, name, calls = args.child
        print("RESULT " + json.dumps(_child(Path(tmp), Path(path), name, int(calls))))
        return 0
    sys.path.insert(0, str(HERE))
    import pushbroom_vs_main as V
    import schur_kernel_vs as K

    env = dict(os.environ, NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    out = {
        "what": __doc__.split("\n\n")[0],
        "scale": args.scale,
        "cpu": V._cpu(),
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "runs": [],
    }
    with tempfile.TemporaryDirectory(prefix="hsgeo-stages-") as tmp:
        _write_variants(Path(tmp))
        path = Path(tmp) / "in.pkl"
        K._capture(args.scale, args.seed, path)
        for rnd in range(args.rounds):
            for name in VARIANTS:
                cmd = [sys.executable, __file__, "--child", tmp, str(path), name, str(args.calls)]
                load = os.getloadavg()[0]
                cp = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
                r = next(json.loads(x[7:]) for x in cp.stdout.splitlines() if x[:7] == "RESULT ")
                r.update(round=rnd, variant=name, loadavg_1min_before=load)
                out["runs"].append(r)
                print(f"{name:26s} {statistics.median(r['cpu_seconds']):6.3f} CPU-s", flush=True)
    med = {
        name: statistics.median(
            statistics.median(r["cpu_seconds"]) for r in out["runs"] if r["variant"] == name
        )
        for name in VARIANTS
    }
    out["median_cpu_seconds"] = med
    out["stage_cpu_seconds"] = {st: med["as_is"] - med[v] for st, v in STAGES.items()}
    out["stage_share_of_kernel"] = {
        st: (med["as_is"] - med[v]) / med["as_is"] for st, v in STAGES.items()
    }
    args.out.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(json.dumps({k: out[k] for k in ("median_cpu_seconds", "stage_cpu_seconds")}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
