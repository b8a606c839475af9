"""Where a chapter's time goes at the smallest scale: ``bench/results/smallest_scale.json``.

    python bench/profile_smallest_scale.py rikola asf [--scale 0.05]

Each chapter is run once to warm (imports, numba caches), then once more under cProfile at
seed 1; the CPU seconds of the warm run and the share of the profiled time spent in the
chapter's largest parts (cumulative time of the functions below ``run``, the 12 largest) are
written, with what the chapter's ``scale`` reaches (:data:`KNOBS`, read from the code). The
seed sweep (bench/bench_seed_sweep.py) runs every chapter at 0.05: below it no chapter gets
smaller.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import resource
from pathlib import Path

HERE = Path(__file__).parent

#: what ``--scale`` reaches in each chapter below 1 (the floor at 0.05 and below), from the code
KNOBS = {
    "rikola": "n_cubes = max(8, round(20·scale)) and 10 bands for every scale < 1 "
    "(reproduce/rikola.py setup); the campaign is rendered twice (with and without the EOP "
    "drift, the unmodelled-effect table): 2 × 8 × 10 = 160 full frames at any scale < 0.4",
    "asf": "n_runs = max(4, round(12·scale)) noise realisations (reproduce/asf.py run); the "
    "three simulated flights (BRDF, path radiance), the registrations and the shifted cases "
    "do not depend on scale",
    "lp-observations": "the rendered block's side: sim_scale = max(MIN_SCALE = 0.05, "
    "0.35·scale) (reproduce/lp_observations.py, simulate/lp_campaign.py)",
    "pushbroom-ba": "the tie-point share of the main campaign (no floor); the studies run "
    "8 seeds at min(scale, 0.01) (reproduce/pushbroom_runs.py study_plan)",
    "line-calibration": "Monte Carlo size max(20, round(200·scale))",
    "geocoding": "Monte Carlo size max(20, round(200·scale))",
    "mtf": "noise realisations max(8, round(24·scale))",
    "cube": "along-track length max(0.12, 0.6·scale) m",
    "frame-reference": "none (OpenCV's tutorial images)",
}


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def profile(chapter: str, scale: float) -> dict:
    from hsgeo.reproduce import run

    run(chapter, seed=0, scale=scale)  # warm
    prof = cProfile.Profile()
    c0 = _cpu()
    prof.runcall(run, chapter, seed=1, scale=scale)
    cpu = _cpu() - c0
    st = pstats.Stats(prof)
    total = max(v[3] for v in st.stats.values())
    parts = sorted(
        (
            (v[3], f"{Path(k[0]).name}:{k[1]}({k[2]})")
            for k, v in st.stats.items()
            if "hsgeo" in k[0] and "reproduce/__init__" not in k[0]
        ),
        reverse=True,
    )[1:13]
    return {
        "scale": scale,
        "cpu_s_profiled_run": round(cpu, 1),
        "largest_parts_share_of_run": {name: round(t / total, 3) for t, name in parts},
        "knob": KNOBS.get(chapter),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("chapters", nargs="+")
    ap.add_argument("--scale", type=float, default=0.05)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "smallest_scale.json")
    a = ap.parse_args()
    doc = json.loads(a.out.read_text()) if a.out.exists() else {"chapters": {}}
    doc["knobs"] = KNOBS
    for c in a.chapters:
        doc["chapters"][c] = profile(c, a.scale)
        a.out.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
        print(c, doc["chapters"][c]["cpu_s_profiled_run"])


if __name__ == "__main__":
    main()
