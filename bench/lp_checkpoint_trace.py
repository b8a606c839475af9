"""One LP campaign's no-GCP check points traced point by point (issue 37): why one lies far.

    python bench/lp_checkpoint_trace.py --seed 1 [--scale 0.05]

The campaign of ``bench/bench_lp_checkpoints.py`` (``hsgeo reproduce lp-observations``'s
``--scale``) is retrieved and adjusted with and without GCPs
(:func:`hsgeo.reproduce.lp_runs.evaluate`). Per check point of the adjustment without GCPs: its
height error, the strips and flying heights (from the plan, above the squares) of the lines that
observe it, and where on the ground (true camera and trajectory) its observations look, as the
offset of their median from the square's centre. Then the fit H ≈ k·AGL (the no-GCP
principal-distance error moves a point along its rays by −AGL·Δc/c) and the heights' STD and
farthest point before and after it. Writes ``bench/results/lp_checkpoint_trace_seed{S}.json``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from hsgeo.reproduce.lp_observations import sim_scale
from hsgeo.reproduce.lp_runs import evaluate
from hsgeo.simulate.lp_campaign import simulate
from hsgeo.stats import nmad


def trace(seed: int, scale: float) -> dict:
    t0 = time.perf_counter()
    obs, truth = simulate(sim_scale(scale), rng=seed)
    ev = evaluate(obs, truth, seed, both=False)
    tab = ev["retrieval"].table
    pid = tab["point_id"].astype(str).to_numpy()
    g = truth.ground_points(
        tab["t_s"].to_numpy(float), tab["x_px"].to_numpy(float), tab["band"].to_numpy()
    )
    agl_of = {
        str(s.strip_id): float(truth.plan[i][3])
        for s, i in zip(obs.strips, truth.strip_index, strict=True)
    }
    ids = list(map(str, obs.square_ids))
    E0 = np.asarray(ev["cp_errors_nogcp_m"], float)
    pts = []
    for c, e in zip(ev["cp_ids_nogcp"], E0, strict=True):
        m = pid == str(c)
        ctr = truth.square_xyz_m[ids.index(str(c))]
        strips = sorted(set(tab["strip"].astype(str)[m]))
        off = np.median(g[m, :2] - ctr[:2], axis=0)
        pts.append(
            {
                "id": str(c),
                "h_error_m": float(e[2]),
                "en_error_m": [float(e[0]), float(e[1])],
                "n_observations": int(m.sum()),
                "strips": strips,
                "agl_m": float(np.mean([agl_of[s] for s in tab["strip"].astype(str)[m]])),
                "ground_offset_from_centre_m": off.tolist(),
                "rms_spread_of_ground_points_m": float(
                    np.sqrt(np.mean(np.sum((g[m, :2] - ctr[:2] - off) ** 2, axis=1)))
                ),
            }
        )
    h = np.array([p["h_error_m"] for p in pts])
    a = np.array([p["agl_m"] for p in pts])
    k = float(np.sum(a * h) / np.sum(a * a))
    r = h - k * a

    def far(x):
        return float(np.max(np.abs(x - np.median(x))) / nmad(x))

    return {
        "seed": seed,
        "scale": scale,
        "check_points": pts,
        "fit_k_h_per_agl": k,
        "std_h_m": float(np.std(h, ddof=1)),
        "std_h_after_agl_m": float(np.std(r, ddof=1)),
        "farthest_over_nmad": far(h),
        "farthest_after_agl_over_nmad": far(r),
        "predicted_h_m": (k * a).tolist(),
        "seconds": time.perf_counter() - t0,
    }


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scale", type=float, default=0.05)
    a = ap.parse_args(argv)
    doc = trace(a.seed, a.scale)
    out = Path(__file__).parent / "results" / f"lp_checkpoint_trace_seed{a.seed}.json"
    out.write_text(json.dumps(doc, indent=1))
    print(json.dumps({k: v for k, v in doc.items() if k != "check_points"}, indent=1))
    return doc


if __name__ == "__main__":
    main()
