"""The Rikola joint model with the EOP drift across the bands (issue 37.7): recovery over seeds.

The simulator rotates each band's camera frame by φ = dφ·(band − 13) (003 §3.4, Fig. 5;
``rikola_bench.toml [eop_drift]``); the joint model
(:func:`hsgeo.workflows.rikola_joint.calibrate_joint`)
now estimates a rotation rate (dω, dφ, dκ) per band. For each seed this script renders and
measures a small bench (8 cubes, the chapter's ten small-scale bands), calibrates the bands, and
adjusts the joint model with the drift estimated and held at zero; it reports z = (estimate −
truth)/σ̂ of the gap model, the principal points, the distortion, sensor II's rotation and the
drift rate, and the rank of the joint model's Jacobian at the truth (identifiability).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python bench/bench_rikola_drift.py --seeds 8 \
        --out bench/results/rikola_drift.json

(or parts, ``--first 4 --seeds 4 --out B.json``, combined with ``--merge A.json B.json --out``).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from hsgeo.adjust import identifiability
from hsgeo.reproduce.rikola import SMALL_BANDS, observe
from hsgeo.simulate.rikola import make_truth
from hsgeo.simulate.scenarios import load_scenario
from hsgeo.workflows.rikola_bands import calibrate_band
from hsgeo.workflows.rikola_joint import DRIFT_REF_BAND, calibrate_joint


def truth_values(truth, j) -> dict:
    """The joint model's parameters at the truth (poses of band 13's frame = sensor I's rigid
    pose, since the drift is zero at the reference band)."""
    from hsgeo.sensors.rikola import focal_from_gap_mm
    from hsgeo.workflows.rikola_bands import BANDS

    s = BANDS["sensor"] - 1
    line = focal_from_gap_mm(BANDS["gap_nm"], truth.gap_model[s, 0], truth.gap_model[s, 1])
    rate = truth.drift_rad[1] - truth.drift_rad[0]
    return {
        "poses": truth.poses[j.cubes],
        "gap_model": truth.gap_model,
        "df_mm": truth.f_mm - line,
        "pp_mm": truth.pp_mm,
        "distortion_mm": truth.KP,
        "sensor2_rotation": truth.rotation_rad,
        "sensor2_offset_mm": truth.offset_mm,
        "eop_drift_rad_per_band": rate,
    }


def rank_at_truth(j, values) -> dict:
    """Rank of the joint model's design at the truth (:func:`hsgeo.adjust.identifiability`):
    the adjustment's parameters set to ``values``, free and fixed as it had them."""
    p = j.result.params.copy()
    for name, v in values.items():
        p.set(name, v)
    ident = identifiability(p, j.block)
    sv = np.asarray(ident.singular_values)
    return {
        "n_unknowns": int(ident.n_unknowns),
        "rank": int(ident.rank),
        "smallest_eigenvalue_ratio": float(sv[0] / sv[-1]),
        "null_space": ident.null_space,
    }


def one_seed(cfg, seed: int) -> dict:
    truth = make_truth(cfg, np.random.default_rng([seed, 0]), n_cubes=8)
    assert truth.drift_rad is not None
    bands = list(SMALL_BANDS)
    obs, *_ = observe(cfg, truth, seed, range(8), bands)
    cals = {b: calibrate_band(obs, b) for b in bands}
    out = {"seed": seed}
    for drift in (True, False):
        j = calibrate_joint(
            obs, init=cals, scatter_mm=tuple(truth.scatter_mm), sigma_px=0.02, model_drift=drift
        )
        tv = truth_values(truth, j)
        z = {}
        for name in ("gap_model", "pp_mm", "distortion_mm", "sensor2_rotation"):
            z[name] = ((j.value(name) - tv[name]) / j.sigma(name)).ravel().tolist()
        if drift:
            name = "eop_drift_rad_per_band"
            z[name] = ((j.value(name) - tv[name]) / j.sigma(name)).tolist()
            out["rank"] = rank_at_truth(j, tv)
            out["drift_estimate_rad_per_band"] = j.value(name).tolist()
            out["drift_truth_rad_per_band"] = tv[name].tolist()
        allz = np.concatenate([np.ravel(v) for v in z.values()])
        out["with_drift" if drift else "rigid"] = {
            "z": z,
            "max_abs_z": float(np.max(np.abs(allz))),
            "x0_z": [z["pp_mm"][0], z["pp_mm"][2]],
            "sigma0": float(j.result.sigma0),
        }
    return out


def summarize(runs: list[dict], seconds: float) -> dict:
    """The seeds' recoveries in numbers: how many seeds have every |z| ≤ 3 with the drift
    estimated, the RMS z, the largest |z| of x0 with and without the drift, the ranks."""
    w = np.array([r["with_drift"]["max_abs_z"] for r in runs])
    allz = np.concatenate([np.ravel(v) for r in runs for v in r["with_drift"]["z"].values()])
    return {
        "reference_band": DRIFT_REF_BAND,
        "n_seeds": len(runs),
        "seeds": [r["seed"] for r in runs],
        "seeds_all_within_3": int(np.sum(w <= 3)),
        "n_z_with_drift": int(allz.size),
        "share_within_3_with_drift": float(np.mean(np.abs(allz) <= 3)),
        "rms_z_with_drift": float(np.sqrt(np.mean(allz**2))),
        "max_abs_z_with_drift": float(w.max()),
        "max_abs_z_rigid": float(max(r["rigid"]["max_abs_z"] for r in runs)),
        "max_abs_x0_z_rigid": float(np.max(np.abs([r["rigid"]["x0_z"] for r in runs]))),
        "max_abs_x0_z_with_drift": float(np.max(np.abs([r["with_drift"]["x0_z"] for r in runs]))),
        "full_rank_at_truth": int(sum(r["rank"]["rank"] == r["rank"]["n_unknowns"] for r in runs)),
        "seconds": seconds,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--merge", type=Path, nargs="+", help="combine outputs of earlier runs")
    args = ap.parse_args()
    if args.merge:
        parts = [json.loads(p.read_text(encoding="utf-8")) for p in args.merge]
        runs = sorted((r for p in parts for r in p["runs"]), key=lambda r: r["seed"])
        out = {"summary": summarize(runs, sum(p["summary"]["seconds"] for p in parts))}
        out["runs"] = runs
    else:
        cfg = load_scenario("rikola_bench")
        t0 = time.time()
        runs = []
        for s in range(args.first, args.first + args.seeds):
            r = one_seed(cfg, s)
            print(
                f"seed {s}: with drift max|z| {r['with_drift']['max_abs_z']:.2f}; rigid max|z| "
                f"{r['rigid']['max_abs_z']:.1f}; rank {r['rank']['rank']} of "
                f"{r['rank']['n_unknowns']}",
                flush=True,
            )
            runs.append(r)
        out = {"summary": summarize(runs, time.time() - t0), "runs": runs}
    print(json.dumps(out["summary"], indent=1))
    if args.out:
        from hsgeo.io._files import write_text

        write_text(args.out, json.dumps(out, indent=1), atomic=True)


if __name__ == "__main__":
    main()
