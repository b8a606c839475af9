"""The adjustment engine on a frame-camera bundle block with tie points, against scipy.

Problem: n_views cameras on a grid over a plane of tie points, each point seen in ~4 views,
OpenCV-form camera, intrinsics and poses free, a few points with priors for the datum.
The alternative: ``scipy.optimize.least_squares(method="trf", tr_solver="lsmr", x_scale="jac")``
with the same analytic sparse Jacobian, on the same problem, to the same final cost.
Writes ``bench/results/engine_frame_ba.json``.
"""

import json
import resource
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.optimize import least_squares

from hsgeo.adjust import Parameters, adjust
from hsgeo.adjust.system import _evaluate, _Layout
from hsgeo.sensors.frame import FrameOpenCV, project_opencv


def make_problem(n_points, seed=0):
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(10), np.arange(8))
    C = np.column_stack([gx.ravel() * 60.0, gy.ravel() * 60.0, np.full(gx.size, -300.0)])
    poses = np.column_stack([rng.normal(0, 0.02, (C.shape[0], 3)), C])
    X = np.column_stack(
        [rng.uniform(0, 540, n_points), rng.uniform(0, 420, n_points), rng.normal(0, 5, n_points)]
    )
    intr = np.array([1000.0, 1000.0, 500.0, 400.0])
    dist = np.array([-0.1, 0.05, 0.0, 0.0, 0.0])
    view, point = [], []
    for j in range(n_points):
        d = np.hypot(C[:, 0] - X[j, 0], C[:, 1] - X[j, 1])
        for v in np.argsort(d)[:4]:
            view.append(v)
            point.append(j)
    view, point = np.array(view), np.array(point)
    uv = project_opencv(poses, view, X[point], intr, dist) + 0.5 * rng.standard_normal(
        (view.size, 2)
    )
    p = Parameters()
    p.add("intrinsics", intr * [1.01, 1.01, 1, 1], columns=("fx", "fy", "cx", "cy"))
    p.add("distortion", np.zeros(5))
    p.fix("distortion", index=[2, 3, 4])
    p.add("poses", poses + rng.normal(0, [0.002] * 3 + [0.5] * 3, poses.shape))
    p.add("points", X + rng.normal(0, 0.5, X.shape), points=True)
    for j in range(0, n_points, max(1, n_points // 20)):
        p.set_prior("points", 0.05, index=j, mean=X[j])
    return p, FrameOpenCV(view, uv, 0.5, point=point)


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run_scipy(p, blk):
    lay = _Layout(p)
    masks = [np.ones(blk.m, bool)]
    cols = lay.n_c
    pfree = lay.pfree.ravel()

    def unpack(x):
        lay.apply(x[:cols] - unpack.cur[:cols], None)
        pts = lay.pblock.value.ravel().copy()
        pts[pfree] = x[cols:]
        lay.pblock.value = pts.reshape(lay.pblock.shape)
        unpack.cur = x.copy()

    x0 = np.concatenate([np.zeros(cols), lay.pblock.value.ravel()[pfree]])
    unpack.cur = np.zeros_like(x0)
    unpack.cur[cols:] = x0[cols:]

    def fun(x):
        unpack(x)
        return _evaluate(lay, [blk], masks, False).r

    def jac(x):
        unpack(x)
        s = _evaluate(lay, [blk], masks, True)
        rows = np.repeat(np.arange(s.r.size), lay.p)
        c = (np.maximum(s.pidx, 0)[:, None] * lay.p + np.arange(lay.p)).ravel()
        Jp = sp.csr_matrix((s.Jp.ravel(), (rows, c)), shape=(s.r.size, lay.n_pts * lay.p))
        return sp.hstack([s.Jc, Jp[:, np.flatnonzero(pfree)]]).tocsr()

    t = time.perf_counter()
    res = least_squares(
        fun,
        x0,
        jac=jac,
        method="trf",
        tr_solver="lsmr",
        x_scale="jac",
        ftol=1e-10,
        xtol=1e-12,
        gtol=1e-12,
        max_nfev=200,
    )
    return time.perf_counter() - t, 0.5 * float(res.fun @ res.fun)


if __name__ == "__main__":
    out = {}
    p, blk = make_problem(40000)
    t = time.perf_counter()
    res = adjust(p, blk)
    out.update(
        n_observations=int(blk.m),
        n_unknowns=int(res.n_unknowns),
        seconds=time.perf_counter() - t,
        iterations=res.iterations,
        sigma0=res.sigma0,
        peak_rss_mb=peak_rss_mb(),
    )
    print(
        f"hsgeo: {blk.m} observations, {res.n_unknowns} unknowns, {out['seconds']:.2f} s, "
        f"{res.iterations} iterations"
    )
    pb, bb = make_problem(5000)
    t = time.perf_counter()
    rb = adjust(pb, bb)
    ours_small = time.perf_counter() - t
    base_s, base_cost = run_scipy(pb, bb)
    ours_cost = 0.5 * (rb.sigma0**2) * rb.dof
    out.update(
        baseline="scipy.optimize.least_squares trf/lsmr x_scale=jac, same Jacobian",
        baseline_n_observations=int(bb.m),
        baseline_seconds=base_s,
        ours_seconds_at_baseline_size=ours_small,
        final_cost_ratio=base_cost / ours_cost,
        speedup=base_s / ours_small,
    )
    print(
        f"at {bb.m} observations: hsgeo {ours_small:.2f} s, scipy {base_s:.2f} s, "
        f"cost ratio scipy/hsgeo {base_cost / ours_cost:.6f}"
    )
    path = Path(__file__).parent / "results" / "engine_frame_ba.json"
    path.write_text(json.dumps(out, indent=1))
    print(f"wrote {path}")
