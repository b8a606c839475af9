"""Full-size statistical check of the pushbroom bundle adjustment (002): truth within 3σ̂.

The issue's done criterion, too slow for the test suite (≈ 1 min per full-size adjustment):
for each (scale, seed) the campaign is simulated and adjusted as in the chapter (with GCPs,
outlier rejection), and the script prints and writes to
``bench/results/coverage_pushbroom.json``:

* the share of the non-point parameters (nodes and camera) whose truth is within 3σ̂;
* mean and std of z = (estimate − truth)/σ̂ per node component (E, N, H, roll, pitch, yaw);
* max |z| of the 17 camera parameters;
* the tie-point reprojection NMAD (x, y) and the check-point NMAD (E, N, H).

Usage: ``python bench/coverage_pushbroom.py [--cases 0.1:0,0.1:1,0.1:2,0.1:3,1.0:0,1.0:1]``
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from hsgeo.reproduce.pushbroom_runs import adjust_campaign, cp_errors
from hsgeo.simulate.pushbroom_campaign import simulate
from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
from hsgeo.stats import nmad

CAMERA = ("boresight_rad", "lever_arm_m", "distortion", "c_mm")


def one(scale: float, seed: int) -> dict:
    t0 = time.perf_counter()
    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    res, _, _, _ = adjust_campaign(obs, cfg)
    zn = (res.value("nodes") - truth.values["nodes"]) / res.sigma("nodes")
    zc = np.concatenate(
        [(res.value(k) - truth.values[k]).ravel() / res.sigma(k).ravel() for k in CAMERA]
    )
    z = np.r_[zn.ravel(), zc]
    r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
    E = cp_errors(res, truth)
    gsd = cfg.agl_low_m * cfg.pixel_mm / cfg.c_mean_mm
    return {
        "scale": scale,
        "seed": seed,
        "n_observations_2d": obs.lines.n,
        "sigma0": res.sigma0,
        "iterations": res.iterations,
        "share_within_3sigma": float(np.mean(np.abs(z) < 3)),
        "node_z_mean": np.mean(zn, axis=0).round(3).tolist(),
        "node_z_std": np.std(zn, axis=0).round(3).tolist(),
        "camera_max_abs_z": float(np.max(np.abs(zc))),
        "nmad_xy_px": nmad(r, axis=0).round(4).tolist(),
        "cp_nmad_enh_m": nmad(E, axis=0).round(4).tolist(),
        "half_gsd_m": gsd / 2,
        "seconds": time.perf_counter() - t0,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="0.1:0,0.1:1,0.1:2,0.1:3,1.0:0,1.0:1")
    ap.add_argument(
        "--out", default=str(Path(__file__).parent / "results" / "coverage_pushbroom.json")
    )
    args = ap.parse_args(argv)
    out = []
    for case in args.cases.split(","):
        s, seed = case.split(":")
        row = one(float(s), int(seed))
        print(json.dumps(row), flush=True)
        out.append(row)
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
