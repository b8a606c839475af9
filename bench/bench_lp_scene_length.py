"""002 §4's scene-length trade-off over 8 campaigns: observations from scenes of 100, 200 and 300
lines (002: 352,431 / 441,587 / 385,166, 200 best).

For every seed one block of the 002 campaign is rendered at the renderer's ``--sim-scale``
(default 0.34: every strip holds ~610 lines, 6, 3 and 2 full scenes, so the scenes' ends fall at
the same places for the three lengths) and retrieved without squares
(:func:`hsgeo.reproduce.lp_runs.scene_length_counts`). Recorded per seed: the observations per
length, the ratios to 200 lines and the best length; over the seeds: the ratios' mean and
standard deviation (and the standard error of the mean) beside 002's, and how often each length
is best. Writes ``bench/results/lp_scene_length_seeds.json``.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

from hsgeo.papers import P002
from hsgeo.reproduce.lp_runs import scene_length_counts
from hsgeo.simulate.lp_campaign import simulate

LENGTHS = (100, 200, 300)


def one_seed(seed: int, sim_scale: float) -> dict:
    """Observations per scene length for one rendered campaign."""
    t0 = time.perf_counter()
    obs, _ = simulate(sim_scale, rng=seed)
    res = scene_length_counts(obs, LENGTHS, seed)
    n = {str(k): int(res[k].counts["all"]["observations"]) for k in LENGTHS}
    return {
        "seed": seed,
        "observations": n,
        "lines_per_strip": [int(s.n_lines) for s in obs.strips],
        "ratio_100_200": n["100"] / n["200"],
        "ratio_300_200": n["300"] / n["200"],
        "best": int(LENGTHS[int(np.argmax([n[str(k)] for k in LENGTHS]))]),
        "seconds": time.perf_counter() - t0,
    }


def _stats(x) -> dict:
    x = np.asarray(x, float)
    sd = float(np.std(x, ddof=1)) if x.size > 1 else float("nan")
    return {"mean": float(np.mean(x)), "sd": sd, "sem": sd / np.sqrt(x.size)}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim-scale", type=float, default=0.34)
    ap.add_argument("--seeds", type=int, nargs="+", default=list(range(8)))
    ap.add_argument(
        "--out", default=str(Path(__file__).parent / "results" / "lp_scene_length_seeds.json")
    )
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    runs = []
    for seed in a.seeds:
        runs.append(one_seed(seed, a.sim_scale))
        print(f"seed {seed}: {runs[-1]['seconds']:.0f} s", flush=True)
    paper = P002["observations_by_scene_lines"]
    doc = {
        "bench": "lp_scene_length_seeds",
        "sim_scale": a.sim_scale,
        "seeds": a.seeds,
        "ratio_100_200": _stats([r["ratio_100_200"] for r in runs]),
        "ratio_300_200": _stats([r["ratio_300_200"] for r in runs]),
        "paper_ratio_100_200": paper[100] / paper[200],
        "paper_ratio_300_200": paper[300] / paper[200],
        "best_counts": {str(k): sum(r["best"] == k for r in runs) for k in LENGTHS},
        "runs": runs,
        "wall_s": time.perf_counter() - t0,
        "date": time.strftime("%Y-%m-%d"),
        "machine": platform.platform(),
    }
    Path(a.out).write_text(json.dumps(doc, indent=1))
    return doc


if __name__ == "__main__":
    main()
