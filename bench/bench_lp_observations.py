"""LP observations from pixels, stage by stage (issue 25): rendering, rotation compensation,
detection + matching, RANSAC per strip.

One rendered block of the 002 campaign (:func:`hsgeo.simulate.lp_campaign.simulate` at
``--scale``, default 0.175: the chapter's, 3 % of the campaign) is retrieved by
:func:`hsgeo.workflows.lp_observations.retrieve` with 002's 200-line scenes. Every stage is
timed in wall-clock and CPU seconds on one core (``OPENBLAS_NUM_THREADS=1``, the retrieval is
single-threaded; "seconds per core" = CPU seconds), per strip and per million pixel-bands, with
observations per second of the whole retrieval. The obvious alternative in the same run: on the
same scene pairs, RANSAC on the LP fundamental matrix (``hsgeo.measure.lp_ransac``) against
OpenCV's frame-F RANSAC (``cv2.findFundamentalMat``), seconds per pair. Peak memory (max RSS).
Writes ``bench/results/lp_observations.json``.
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import time
from pathlib import Path

import numpy as np

from hsgeo.measure.lp_ransac import ransac_frame_fundamental, ransac_lp_fundamental
from hsgeo.measure.lp_scenes import make_scenes
from hsgeo.simulate.lp_campaign import simulate
from hsgeo.workflows.lp_observations import LpInputs, LpOptions, retrieve


def _clock():
    return time.perf_counter(), time.process_time()


def _since(c):
    return {"wall_s": time.perf_counter() - c[0], "cpu_s": time.process_time() - c[1]}


def _ransac_pairs(matches, pairs, n_pairs, seed):
    """LP-F and frame-F RANSAC on the same scene pairs (≥ 11 matches): seconds per pair."""
    big = pairs[pairs["n_matches"] >= 11]["pair"].to_numpy()
    pick = np.random.default_rng(seed).choice(big, min(n_pairs, big.size), replace=False)
    out = {"lp": [], "frame": [], "n_matches": []}
    for p in pick:
        m = matches[matches["pair"] == p]
        a = m[["u_a", "v_a"]].to_numpy(float)
        b = m[["u_b", "v_b"]].to_numpy(float)
        t = time.perf_counter()
        ransac_lp_fundamental(a, b, rng=int(p))
        out["lp"].append(time.perf_counter() - t)
        t = time.perf_counter()
        ransac_frame_fundamental(a, b)
        out["frame"].append(time.perf_counter() - t)
        out["n_matches"].append(len(m))
    return {
        "n_pairs": int(pick.size),
        "matches_per_pair_median": float(np.median(out["n_matches"])),
        "lp_s_per_pair_median": float(np.median(out["lp"])),
        "frame_cv2_s_per_pair_median": float(np.median(out["frame"])),
        "lp_over_frame": float(np.sum(out["lp"]) / np.sum(out["frame"])),
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scale", type=float, default=0.175, help="renderer scale (block side / 600 m)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--pairs", type=int, default=100, help="scene pairs for LP-F vs frame-F")
    args = p.parse_args(argv)
    c = _clock()
    obs, _ = simulate(args.scale, rng=args.seed)
    render = _since(c)
    n_strips = len(obs.strips)
    mpix = sum(s.lines.size for s in obs.strips) / 1e6
    # rotation compensation alone, strip by strip (the retrieval does it again inside)
    comp = []
    for s in obs.strips:
        c = _clock()
        make_scenes(s, obs.navigation, obs.camera, 200, obs.n_px_full)
        comp.append(_since(c))
    inp = LpInputs(
        tuple(obs.strips), obs.navigation, obs.camera, obs.square_ids, obs.square_xyz_m, None,
        obs.n_px_full,
    )  # fmt: skip
    c = _clock()
    res = retrieve(inp, LpOptions(rng=args.seed))
    total = _since(c)
    T = res.timings_s
    n_obs = int(res.counts["all"]["observations"])
    per_strip = {
        "rendering_s": render["wall_s"] / n_strips,
        "compensation_s": float(np.mean([x["wall_s"] for x in comp])),
        "detection_and_matching_s": (T["detection"] + T["matching"]) / n_strips,
        "ransac_s": float(np.mean(T["ransac_per_strip"])),
        "ransac_s_max": float(np.max(T["ransac_per_strip"])),
        "squares_s": T["squares"] / n_strips,
    }
    out = {
        "benchmark": "lp_observations",
        "scale": args.scale,
        "campaign_fraction": args.scale**2,
        "seed": args.seed,
        "n_strips": n_strips,
        "million_pixel_bands": mpix,
        "rendering": {**render, "s_per_million_pixel_bands": render["wall_s"] / mpix},
        "compensation": {
            "wall_s": float(sum(x["wall_s"] for x in comp)),
            "cpu_s": float(sum(x["cpu_s"] for x in comp)),
            "s_per_million_pixel_bands": float(sum(x["wall_s"] for x in comp)) / mpix,
        },
        "retrieval": {
            **total,
            "stages_wall_s": {k: float(v) for k, v in T.items() if not isinstance(v, list)},
            "ransac_per_strip_s": [float(x) for x in T["ransac_per_strip"]],
            "observations": n_obs,
            "observations_per_s": n_obs / total["wall_s"],
            "observations_per_cpu_s": n_obs / total["cpu_s"],
            "keypoints": int(res.counts["all"]["keypoints"]),
            "matches": int(res.counts["all"]["matches"]),
        },
        "per_strip": per_strip,
        "ransac_lp_vs_frame": _ransac_pairs(res.matches, res.pairs, args.pairs, args.seed),
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "machine": {"python": platform.python_version(), "numpy": np.__version__,
                    "processor": platform.processor() or platform.machine(),
                    "note": "shared 2-core machine; other sessions' load inflates wall times"},
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }  # fmt: skip
    print(json.dumps(out, indent=1), flush=True)
    path = Path(__file__).parent / "results" / "lp_observations.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
