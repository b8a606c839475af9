"""The 002 chapter's rows through the geodetic path (issue 38): ``bench/results/geodetic_002.json``.

    python bench/bench_geodetic_002.py [--seed 0] [--scale 0.05]

Runs ``hsgeo reproduce lp-observations`` (``hsgeo.reproduce.run``) twice in one process: as
it is, and with every rendered campaign's navigation (the chapter's, its blur-off rerun's and
the point-target judges') written as a GNSS/INS delivers it — ETRS89 latitude, longitude,
ellipsoidal height, attitude against the NED at each record, GPS seconds of week — by the
002 flight test's own writer (tests/test_geodetic_002_flight.py: an exact geodetic inverse in
extended precision, ``%.17g``) and read back by :func:`hsgeo.io.read_navigation` into the
002 site's frame. Both runs' rows are stored as ``hsgeo reproduce --json`` writes them, with
the navigation's own change (positions, angles); ``bench/issue38_audit.py`` compares them.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scale", type=float, default=0.05)
    ap.add_argument("--out", type=Path, default=RESULTS / "geodetic_002.json")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT / "tests"))
    import tempfile

    from test_geodetic_002_flight import _geodetic_csv

    import hsgeo.reproduce.lp_observations as chapter
    import hsgeo.simulate.lp_campaign as campaign
    from hsgeo.crs import SITE_AAS
    from hsgeo.io import read_navigation
    from hsgeo.reproduce import run
    from hsgeo.trajectory import Trajectory

    t0 = time.perf_counter()
    plain = json.loads(run("lp-observations", seed=args.seed, scale=args.scale).to_json())
    t_plain = time.perf_counter() - t0
    real = campaign.simulate
    nav_change = []
    tmp = Path(tempfile.mkdtemp(prefix="geodetic_002_"))

    def through_geodetic(*a, **kw):
        obs, truth = real(*a, **kw)
        p = _geodetic_csv(tmp / f"nav{len(nav_change)}.csv", obs.navigation, SITE_AAS)
        tr = read_navigation(p, frame=SITE_AAS).trajectory
        nav = Trajectory(tr.t_s - 302400.0, tr.xyz_m, tr.roll_pitch_heading_rad)
        a0 = obs.navigation
        nav_change.append(
            {
                "max_abs_position_m": float(np.max(np.abs(nav.xyz_m - a0.xyz_m))),
                "max_abs_position_coordinate_m": float(np.max(np.abs(a0.xyz_m))),
                "max_abs_angle_rad": float(
                    np.max(np.abs(nav.roll_pitch_heading_rad - a0.roll_pitch_heading_rad))
                ),
                "max_abs_time_s": float(np.max(np.abs(nav.t_s - a0.t_s))),
            }
        )
        return replace(obs, navigation=nav), truth

    chapter.simulate = campaign.simulate = through_geodetic  # the chapter's and the judges'
    try:
        t0 = time.perf_counter()
        geo = json.loads(run("lp-observations", seed=args.seed, scale=args.scale).to_json())
        t_geo = time.perf_counter() - t0
    finally:
        chapter.simulate = campaign.simulate = real
    out = {
        "what": "hsgeo reproduce lp-observations rows, plain and with every campaign's "
        "navigation through the geodetic path (ETRS89 lat/lon/h, per-record NED attitude)",
        "command": f"python bench/bench_geodetic_002.py --seed {args.seed} --scale {args.scale}",
        "seed": args.seed,
        "scale": args.scale,
        "navigation_change": nav_change,
        "seconds": {"plain": t_plain, "geodetic": t_geo},
        "plain": plain,
        "geodetic": geo,
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    args.out.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
    print(f"{len(plain['rows'])} rows; navigations {nav_change}; {t_plain:.0f} s + {t_geo:.0f} s")


if __name__ == "__main__":
    main()
