"""Does the pushbroom adjustment depend on the order of the observation table's rows?

    python bench/pushbroom_row_order.py [--scale 1] [--seed 0] [--vs CHECKOUT]

Simulates the chapter's campaign (002, seed ``--seed``), builds the problem from its
observation rows as simulated and again from the same rows in a random order (one fixed
permutation), and adjusts both with the chapter's settings (``solve``: 002's rejection in
each iteration). Writes ``bench/results/pushbroom_row_order.json``: per order the final cost,
the iterations, the residual components used (rejected ones excluded), σ0 and the RMSE of the
check points against the simulation's truth; whether the initial points are equal bit for bit;
the largest difference of the adjusted points. With ``--vs`` the same for another checkout's
``src`` (e.g. one before the initial points were chosen by their rays' directions), in a
fresh process.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _child(scale: float, seed: int) -> dict:
    import numpy as np

    from hsgeo.reproduce.pushbroom_runs import camera_prior
    from hsgeo.simulate.pushbroom_campaign import simulate
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
    from hsgeo.workflows.pushbroom_ba import Y_AS_TIME, build_problem, solve

    cfg = CampaignConfig()
    obs, truth = simulate(scale, rng=seed, cfg=cfg)
    cp = truth.cp_index
    cp_xyz = truth.values["points_m"][cp]
    del truth
    lines = obs.lines
    shuffled = lines.take(np.random.default_rng(1).permutation(lines.n))
    out, P0, P = {}, {}, {}
    for name, rows in (("as_simulated", lines), ("random_order", shuffled)):
        p, blocks, _ = build_problem(
            rows,
            obs.n_points,
            camera_prior(cfg, obs),
            t_span_s=obs.t_span_s,
            gcp_index=obs.gcp_index,
            gcp_xyz_m=obs.gcp_xyz_m,
            y_as_time=Y_AS_TIME,
        )
        P0[name] = p.values()["points_m"].copy()
        res = solve(p, blocks)
        P[name] = res.params.values()["points_m"]
        out[name] = {
            "final_cost": float(res.cost_history[-1]),
            "iterations": int(res.iterations),
            "residual_components_used": int(res.n_observations),
            "sigma0": float(res.sigma0),
            "check_point_rmse_m": float(np.sqrt(np.mean((P[name][cp] - cp_xyz) ** 2))),
        }
    a, b = "as_simulated", "random_order"
    out["initial_points_equal_bit_for_bit"] = bool(np.array_equal(P0[a], P0[b]))
    out["initial_points_max_difference_m"] = float(np.max(np.abs(P0[a] - P0[b])))
    out["adjusted_points_max_difference_m"] = float(np.max(np.abs(P[a] - P[b])))
    out["residual_rows"] = int(2 * lines.n)
    return out


def _run(src: Path, scale: float, seed: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1")
    cp = subprocess.run(
        [sys.executable, __file__, "--child", "--scale", str(scale), "--seed", str(seed)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(cp.stdout.strip().splitlines()[-1])


def _commit(root: Path) -> str:
    cp = subprocess.run(
        ["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    )
    return cp.stdout.strip() or "unknown"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--vs", type=Path, help="another checkout, run the same way")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "pushbroom_row_order.json")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(_child(a.scale, a.seed)))
        return
    root = HERE.parent
    res = {
        "what": __doc__.split("\n\n")[0].strip(),
        "scale": a.scale,
        "seed": a.seed,
        "this": {"commit": _commit(root), **_run(root / "src", a.scale, a.seed)},
    }
    if a.vs is not None:
        res["vs"] = {"commit": _commit(a.vs), **_run(a.vs / "src", a.scale, a.seed)}
    res["date_utc"] = time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime())
    a.out.write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
