"""RANSAC on the LP fundamental matrix against OpenCV's frame-F RANSAC (issue 25).

Correspondences: exact LP matches between 200-line scenes of two crossing strips in 002's
geometry (1875 / 2500 m above ground, 67 m/s, 200 lines/s, the 002 camera, 15 m of relief),
0.3 px of noise on every coordinate and 30 % gross outliers (a random pixel of image 2).
Times ``hsgeo.measure.lp_ransac.ransac_lp_fundamental`` (threshold 1 px, confidence 0.999)
and ``ransac_frame_fundamental`` (``cv2.findFundamentalMat``, FM_RANSAC) at 50, 200 and 1000
correspondences: seconds per call (best and median of ``--repeat`` calls with different seeds)
and calls per second, with the share of true matches kept and of outliers rejected. Writes
``bench/results/lp_ransac.json``.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

from hsgeo.measure.lp_ransac import ransac_frame_fundamental, ransac_lp_fundamental
from hsgeo.sensors.mount import line_time
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.trajectory import Trajectory

RATE_HZ, SPEED_M_S = 200.0, 67.0  # 002 §4
CAMERA = PushbroomCamera(c_mm=(40.3,), pixel_mm=0.0065, boresight_rad=(0.004, -0.006, 0.003))


def _strip(heading_rad, agl_m):
    d = np.array([np.sin(heading_rad), np.cos(heading_rad), 0.0])
    t = np.array([0.0, 20.0])
    xyz = np.array([0.0, 0.0, agl_m]) + np.outer(t - 10.0, d * SPEED_M_S)
    return Trajectory(t, xyz, np.array([[0.0, 0.0, heading_rad]] * 2))


def _observe(tr, xyz_m, t0_s):
    t = line_time(lambda X, t: CAMERA.project(X, t, tr)[:, 1], xyz_m, tr, 10.0)
    xy = CAMERA.project(xyz_m, t, tr)
    return np.column_stack([(t - t0_s) * RATE_HZ, xy[:, 0] + 899.5])


def correspondences(n, rng):
    """``n`` noisy LP matches of crossing 200-line scenes, 30 % outliers (and their labels)."""
    half = SPEED_M_S * 200 / RATE_HZ / 2
    xyz = np.column_stack([rng.uniform(-half, half, (n, 2)), rng.uniform(0, 15, n)])
    a = _observe(_strip(0.0, 1875.0), xyz, 9.5) + rng.normal(0, 0.3, (n, 2))
    b = _observe(_strip(np.pi / 2, 2500.0), xyz, 9.5)
    out = np.zeros(n, bool)
    out[rng.choice(n, int(0.3 * n), replace=False)] = True
    b[out] = rng.uniform(b.min(axis=0), b.max(axis=0), (out.sum(), 2))
    b[~out] += rng.normal(0, 0.3, (int((~out).sum()), 2))
    return a, b, out


def _time(fn, cases):
    times, keep, reject = [], [], []
    for a, b, out, seed in cases:
        t = time.perf_counter()
        inl = fn(a, b, seed)
        times.append(time.perf_counter() - t)
        keep.append(inl[~out].mean())
        reject.append(1 - inl[out].mean())
    return {
        "s_per_call_best": min(times),
        "s_per_call_median": float(np.median(times)),
        "calls_per_s": 1.0 / float(np.median(times)),
        "true_kept_mean": float(np.mean(keep)),
        "outliers_rejected_mean": float(np.mean(reject)),
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=10, help="calls (seeds) per size")
    args = p.parse_args(argv)
    rows = []
    for n in (50, 200, 1000):
        cases = [(*correspondences(n, np.random.default_rng(s)), s) for s in range(args.repeat)]
        lp_iters = [ransac_lp_fundamental(a, b, rng=s).n_iterations for a, b, _, s in cases]
        rows.append(
            {
                "n_correspondences": n,
                "outlier_share": 0.3,
                "lp": _time(lambda a, b, s: ransac_lp_fundamental(a, b, rng=s).inliers, cases),
                "lp_iterations_median": float(np.median(lp_iters)),
                "frame_cv2": _time(lambda a, b, s: ransac_frame_fundamental(a, b), cases),
            }
        )
        print(json.dumps(rows[-1]), flush=True)
    out = {
        "benchmark": "lp_ransac",
        "threshold_px": 1.0,
        "confidence": 0.999,
        "rows": rows,
        "machine": {"python": platform.python_version(), "numpy": np.__version__,
                    "processor": platform.processor() or platform.machine()},
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }  # fmt: skip
    path = Path(__file__).parent / "results" / "lp_ransac.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
