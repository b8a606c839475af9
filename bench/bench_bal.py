"""``make bench``: a real bundle problem (BAL Ladybug 49-7776) — hsgeo against Ceres and SciPy.

Writes ``bench/results/bal.json``. Agarwal, Snavely, Seitz, Szeliski (2010), "Bundle Adjustment
in the Large", Ladybug problem 49-7776 (49 cameras, 7,776 points, 31,843 observations; the
file and its attribution are in ``src/hsgeo/data/reference/bal-ladybug``).

**One observation set.** 31 observations are of points behind their camera at the initial
values. COLMAP's reprojection cost returns a zero residual for them (pycolmap reports all
63,686 residuals, but its initial cost is that of the other 31,812 observations): hsgeo
(:func:`hsgeo.workflows.bal.prepare`) leaves them out, and the reconstruction handed to
pycolmap is built from the same filtered problem, so the three solvers adjust the identical
31,812 observations. ``same_observations`` checks it: equal counts, and the initial costs of
hsgeo and Ceres agree to 1e-9 relative.

**Solvers**, one thread each (``OPENBLAS_NUM_THREADS=1``, ``NUMBA_NUM_THREADS=1``, Ceres
``num_threads=1``), every case in its own fresh subprocess (its own peak RSS):

* ``ceres``: ``pycolmap`` 4.2.1 (``create_default_bundle_adjuster``; Ceres LM, DENSE_SCHUR
  chosen by COLMAP for ≤ 50 images), ``RADIAL`` cameras ``(f, cx=0, cy=0, k1, k2)`` — COLMAP's
  ``u = f (1 + k1 ρ² + k2 ρ⁴) x/z + cx`` is Snavely's model once the camera frame is turned by
  diag(1, −1, −1) (COLMAP looks down +z with y down, BAL down −z with y up; the observed y is
  negated), gauge ``TWO_CAMS_FROM_WORLD``, ``function_tolerance`` 1e-6, principal point fixed.
  ``ceres_converged_cost``: the same run to ``function_tolerance`` 1e-12 (the minimum's cost).
* ``hsgeo``: :func:`hsgeo.workflows.bal.adjust_bal` (Schur complement on the points, gauge
  fixed by 7 camera entries, :data:`~hsgeo.workflows.bal.BAL_OPTIONS`). numba loads its
  compiled kernels on their first call in a process (``hsgeo_jit_load_seconds``, a fixed cost
  measured on a 5-camera subset first, not in ``hsgeo_seconds``). ``hsgeo_seconds_to_ceres_cost``
  is the time of the first iterate whose cost is at most Ceres' final cost × (1 + 1e-6).
* ``scipy``: ``least_squares(method="trf", jac_sparsity=…, x_scale="jac", ftol=1e-4)`` with a
  finite-difference Jacobian, as in the SciPy cookbook "Large-scale bundle adjustment in scipy"
  (residuals from the same compiled model as hsgeo's).

The machine is shared: Ceres and hsgeo alternate ``--repeats`` times (median wall time; the
CPU times are reported too, less sensitive to the load).

**Goals** (issue 14): ``goal_cost_reached`` — hsgeo's final cost at most Ceres' × (1 + 1e-6);
``goal_time_met`` (wall) and ``goal_time_met_cpu`` — hsgeo's first iterate at Ceres' final cost
no later than Ceres' end; ``converged_no_later_than_ceres`` — hsgeo's own convergence (its
Gauss–Newton test at 1e-6, which ends 6.5e-6 lower than Ceres' function-tolerance stop, within
2e-8 of the minimum ``ceres_converged_cost``) no later than Ceres' end.

**Paired with the previous main** (issue 41): ``--vs DIR`` (a checkout of the previous main)
runs its hsgeo in turn with this one and Ceres, ``--repeats`` times (Ceres, hsgeo, previous
main, Ceres, …); ``vs_main`` holds each pair's CPU seconds to Ceres' cost, their ratio and
medians, and the load average before each run; the CPU model and the BLAS libraries with
the core type they chose (``cpu_model``, ``blas_hsgeo``, ``machine_info``) stand beside the
figures, because the lead over Ceres differed between two machines of the same kind.

Usage: ``python bench/bench_bal.py [--repeats 3] [--no-scipy] [--vs DIR]``; a case alone:
``python bench/bench_bal.py --case hsgeo``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
THREADS = 1
PROBLEM = "BAL Ladybug problem-49-7776-pre (Agarwal et al. 2010)"


def _cpu_model() -> str | None:
    """The processor's model name (``/proc/cpuinfo``; None where there is none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or None


def _blas() -> list[dict]:
    """The BLAS libraries loaded with numpy and scipy, with the core type each chose
    (threadpoolctl's ``internal_api``, ``architecture``, ``version``, ``num_threads``): a
    lead that depends on the machine (e.g. OpenBLAS' kernels for one core type) shows here.
    """
    import numpy  # noqa: F401
    import scipy.linalg  # noqa: F401
    from threadpoolctl import threadpool_info

    keys = ("user_api", "internal_api", "architecture", "version", "num_threads", "prefix")
    return [{k: d.get(k) for k in keys} for d in threadpool_info() if d.get("user_api") == "blas"]


def _machine_info() -> dict:
    """The machine the figures were measured on, recorded beside them (issue 41)."""
    return {
        "cpu_model": _cpu_model(),
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "platform": platform.machine(),
        "blas": _blas(),
        "loadavg_at_end": list(os.getloadavg()),
    }


def _problem():
    from hsgeo.io.bal import ladybug_path, read_bal
    from hsgeo.workflows.bal import prepare

    return prepare(read_bal(ladybug_path()))


def _initial_cost(prob) -> float:
    import numpy as np

    from hsgeo.sensors.bal import SnavelyReprojection

    b = SnavelyReprojection(prob.camera_index, prob.point_index, prob.xy_px)
    r, _ = b.evaluate({"cameras": prob.cameras, "points": prob.points}, False)
    return 0.5 * float(np.dot(r, r))


def reconstruction(prob):
    """A pycolmap Reconstruction of a BAL problem (see the module docstring)."""
    import numpy as np
    import pycolmap

    from hsgeo.rotations import R_from_rotvec

    F = np.diag([1.0, -1.0, -1.0])  # BAL camera frame (x right, y up, looks −z) → COLMAP's
    R = R_from_rotvec(prob.cameras[:, :3])
    rec = pycolmap.Reconstruction()
    for i in range(prob.n_cameras):
        f, k1, k2 = prob.cameras[i, 6:9]
        cam = pycolmap.Camera(
            model="RADIAL", width=2000, height=2000, params=[f, 0.0, 0.0, k1, k2], camera_id=i + 1
        )
        rec.add_camera_with_trivial_rig(cam)
    where = np.empty((prob.n_observations, 2), dtype=np.int64)
    for i in range(prob.n_cameras):
        sel = np.flatnonzero(prob.camera_index == i)
        img = pycolmap.Image(
            name=f"camera{i}",
            keypoints=prob.xy_px[sel] * [1.0, -1.0],
            camera_id=i + 1,
            image_id=i + 1,
        )
        pose = pycolmap.Rigid3d(pycolmap.Rotation3d(F @ R[i]), F @ prob.cameras[i, 3:6])
        rec.add_image_with_trivial_frame(img, pose)
        where[sel, 0] = i + 1
        where[sel, 1] = np.arange(sel.size)
    order = np.argsort(prob.point_index, kind="stable")
    bounds = np.searchsorted(prob.point_index[order], np.arange(prob.n_points + 1))
    for q in range(prob.n_points):
        obs = order[bounds[q] : bounds[q + 1]]
        if obs.size == 0:
            continue  # every observation of the point was left out: not part of the problem
        track = pycolmap.Track([pycolmap.TrackElement(int(a), int(b)) for a, b in where[obs]])
        rec.add_point3D(prob.points[q], track)
    return rec


def case_ceres(function_tolerance: float = 1e-6, max_iterations: int = 100):
    import pycolmap

    prob, n_dropped = _problem()
    rec = reconstruction(prob)
    opts = pycolmap.BundleAdjustmentOptions()
    opts.refine_focal_length = True
    opts.refine_principal_point = False
    opts.refine_extra_params = True
    opts.print_summary = False
    so = opts.ceres.solver_options
    so.num_threads = THREADS
    so.function_tolerance = function_tolerance
    so.max_num_iterations = max_iterations
    cfg = pycolmap.BundleAdjustmentConfig()
    for i in range(prob.n_cameras):
        cfg.add_image(i + 1)
    cfg.fix_gauge(pycolmap.BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD)
    ba = pycolmap.create_default_bundle_adjuster(opts, cfg, rec)
    c0, t0 = time.process_time(), time.perf_counter()
    summary = ba.solve()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    cs = summary.ceres_summary
    return {
        "seconds": wall,
        "cpu_seconds": cpu,
        "iterations": int(cs.num_successful_steps + cs.num_unsuccessful_steps),
        "initial_cost": float(cs.initial_cost),
        "final_cost": float(cs.final_cost),
        "num_residuals": int(cs.num_residuals),
        "n_observations": int(rec.compute_num_observations()),
        "hsgeo_initial_cost": _initial_cost(prob),
        "linear_solver": str(cs.linear_solver_type_used),
        "num_threads": int(cs.num_threads_used),
        "termination": str(cs.termination_type),
        "pycolmap": pycolmap.__version__,
    }


def case_hsgeo(target_cost: float | None = None):
    from hsgeo.io.bal import ladybug_path, read_bal
    from hsgeo.workflows.bal import BAL_OPTIONS, adjust_bal

    problem = read_bal(ladybug_path())
    # numba's compiled kernels load on their first call in a process: a 5-camera subset first
    t0 = time.perf_counter()
    small = problem.select_cameras(range(5))
    adjust_bal(small, BAL_OPTIONS.replace(max_iter=2, raise_on_failure=False))
    jit = time.perf_counter() - t0
    trace = []
    c0 = time.process_time()
    fit = adjust_bal(
        problem,
        progress=lambda info: trace.append(
            (info["iteration"], info["cost"], info["seconds"], time.process_time() - c0)
        ),
    )
    cpu = time.process_time() - c0
    reach = next((t for t in trace if target_cost and t[1] <= target_cost * (1 + 1e-6)), None)
    return {
        "seconds": fit.seconds,
        "cpu_seconds": cpu,
        "iterations": fit.iterations,
        "initial_cost": fit.initial_cost,
        "final_cost": fit.final_cost,
        "n_observations": fit.n_observations,
        "n_dropped": fit.n_dropped,
        "converged": fit.result.converged,
        "message": fit.result.message,
        "seconds_to_target": None if reach is None else reach[2],
        "iterations_to_target": None if reach is None else reach[0],
        "cpu_seconds_to_target": None if reach is None else reach[3],
        "cost_history": [float(c) for c in fit.result.cost_history],
        "jit_load_seconds": jit,
    }


def case_scipy():
    import numpy as np
    import scipy.sparse as sp
    from scipy.optimize import least_squares

    from hsgeo.sensors.bal import SnavelyReprojection

    prob, _ = _problem()
    nc, npt = prob.n_cameras, prob.n_points
    block = SnavelyReprojection(prob.camera_index, prob.point_index, prob.xy_px)
    block.evaluate({"cameras": prob.cameras, "points": prob.points}, False)  # compile first

    def fun(x):
        r, _ = block.evaluate(
            {"cameras": x[: 9 * nc].reshape(nc, 9), "points": x[9 * nc :].reshape(npt, 3)}, False
        )
        return r

    # the cookbook's sparsity pattern: each observation's 2 rows touch its camera's 9 and its
    # point's 3 columns
    m = 2 * prob.n_observations
    A = sp.lil_matrix((m, 9 * nc + 3 * npt), dtype=int)
    i = np.arange(prob.n_observations)
    for s in range(9):
        A[2 * i, prob.camera_index * 9 + s] = 1
        A[2 * i + 1, prob.camera_index * 9 + s] = 1
    for s in range(3):
        A[2 * i, 9 * nc + prob.point_index * 3 + s] = 1
        A[2 * i + 1, 9 * nc + prob.point_index * 3 + s] = 1
    x0 = np.concatenate([prob.cameras.ravel(), prob.points.ravel()])
    c0, t0 = time.process_time(), time.perf_counter()
    res = least_squares(fun, x0, jac_sparsity=A, verbose=0, x_scale="jac", ftol=1e-4, method="trf")
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return {
        "seconds": wall,
        "cpu_seconds": cpu,
        "final_cost": float(res.cost),
        "nfev": int(res.nfev),
        "status": int(res.status),
    }


def _run_case(name: str, *args: str, tree: Path | None = None) -> dict:
    """One case in a fresh subprocess (one thread each); ``tree``: run hsgeo from another
    checkout's ``src`` (the previous main of ``--vs``), its numba cache kept apart.
    """
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    if tree is not None:
        env["PYTHONPATH"] = str(tree / "src")
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        env["NUMBA_CACHE_DIR"] = str(Path(os.environ.get("TMPDIR", "/tmp")) / "bench_bal_vs_numba")
    load = list(os.getloadavg())
    out = subprocess.run(
        [sys.executable, __file__, "--case", name, *args],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    res = json.loads(out.stdout.strip().splitlines()[-1])
    res["load_average_1_5_15_before"] = load
    return res


def _vs_main(hs: list, vs: list, ceres: list, tree: Path | None) -> dict | None:
    """The paired runs against the previous main (``--vs``): medians and per-pair ratios."""
    if not vs:
        return None
    med = statistics.median
    this = [x["cpu_seconds_to_target"] for x in hs]
    prev = [x["cpu_seconds_to_target"] for x in vs]
    return {
        "tree": str(tree),
        "commit": _commit(tree),
        "pairs": len(vs),
        "order": "ceres, hsgeo (this), hsgeo (previous main), repeated",
        "this_cpu_seconds_to_ceres_cost_runs": this,
        "previous_main_cpu_seconds_to_ceres_cost_runs": prev,
        "this_median_cpu_seconds_to_ceres_cost": med(this),
        "previous_main_median_cpu_seconds_to_ceres_cost": med(prev),
        "ratio_previous_over_this_each_pair": [p / t for p, t in zip(prev, this, strict=True)],
        "ratio_previous_over_this_median": med(p / t for p, t in zip(prev, this, strict=True)),
        "previous_main_iterations_to_ceres_cost": vs[0]["iterations_to_target"],
        "previous_main_final_cost": vs[0]["final_cost"],
        "previous_main_cpu_speedup_over_ceres_median": med(
            c["cpu_seconds"] / v["cpu_seconds_to_target"] for c, v in zip(ceres, vs, strict=True)
        ),
        "load_average_1_5_15_each_run": [x["load_average_1_5_15_before"] for x in vs],
    }


def _commit(tree: Path | None) -> str | None:
    try:
        out = subprocess.run(
            ["git", "-C", str(tree or HERE), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        )
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-scipy", action="store_true")
    ap.add_argument("--case", choices=["ceres", "ceres_converged", "hsgeo", "scipy"])
    ap.add_argument("--target", type=float, default=None)
    ap.add_argument(
        "--vs",
        type=Path,
        default=None,
        help="a checkout of the previous main: its hsgeo runs in turn with this one and Ceres "
        "(paired, alternating), and the ratios go to bal.json's vs_main",
    )
    args = ap.parse_args(argv)
    if args.case:
        fn = {
            "ceres": case_ceres,
            "ceres_converged": lambda: case_ceres(1e-12, 500),
            "hsgeo": lambda: case_hsgeo(args.target),
            "scipy": case_scipy,
        }[args.case]
        out = fn()
        out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
        out["blas"] = _blas()  # the core type this case's BLAS chose, in its own process
        print(json.dumps(out))
        return
    import importlib.util

    if importlib.util.find_spec("pycolmap") is None:
        sys.exit(
            "bench_bal: pycolmap (Ceres) is not installed: pip install -r requirements-bench.lock "
            "(make bench does it)"
        )
    ceres, hs, vs = [], [], []
    for k in range(args.repeats):
        # in turn: Ceres, hsgeo, the previous main's hsgeo (with --vs), on the same machine
        ceres.append(_run_case("ceres"))
        print(f"  ceres run {k + 1}: {ceres[-1]['cpu_seconds']:.2f} CPU-s", flush=True)
        hs.append(_run_case("hsgeo", "--target", repr(ceres[0]["final_cost"])))
        print(f"  hsgeo run {k + 1}: {hs[-1]['cpu_seconds_to_target']:.2f} CPU-s", flush=True)
        if args.vs is not None:
            vs.append(_run_case("hsgeo", "--target", repr(ceres[0]["final_cost"]), tree=args.vs))
            print(f"  vs    run {k + 1}: {vs[-1]['cpu_seconds_to_target']:.2f} CPU-s", flush=True)
    conv = _run_case("ceres_converged")
    sc = None if args.no_scipy else _run_case("scipy")
    c, h = ceres[0], hs[0]
    med = statistics.median
    same = (
        c["n_observations"] == h["n_observations"]
        and c["num_residuals"] == 2 * h["n_observations"]
        and abs(c["initial_cost"] - h["initial_cost"]) <= 1e-9 * c["initial_cost"]
    )
    rel = (h["final_cost"] - c["final_cost"]) / c["final_cost"]
    hs_s, ce_s = med(x["seconds"] for x in hs), med(x["seconds"] for x in ceres)
    ce_cpu = med(x["cpu_seconds"] for x in ceres)
    reached = all(x["seconds_to_target"] is not None for x in hs)
    out_to = med(x["seconds_to_target"] for x in hs) if reached else None
    cpu_to = med(x["cpu_seconds_to_target"] for x in hs) if reached else None
    out = {
        "problem": PROBLEM,
        "n_observations": h["n_observations"],
        "n_dropped_behind_camera": h["n_dropped"],
        "same_observations": bool(same),
        "initial_cost": h["initial_cost"],
        "ceres_initial_cost": c["initial_cost"],
        "initial_cost_relative_difference": (c["initial_cost"] - h["initial_cost"])
        / h["initial_cost"],
        "threads": THREADS,
        "repeats": args.repeats,
        "hsgeo_seconds": hs_s,
        "hsgeo_cpu_seconds": med(x["cpu_seconds"] for x in hs),
        "hsgeo_iterations": h["iterations"],
        "hsgeo_seconds_per_iteration": hs_s / max(h["iterations"], 1),
        "hsgeo_final_cost": h["final_cost"],
        "hsgeo_converged": h["converged"],
        "hsgeo_seconds_to_ceres_cost": out_to,
        "hsgeo_cpu_seconds_to_ceres_cost": cpu_to,
        "hsgeo_iterations_to_ceres_cost": h["iterations_to_target"],
        "hsgeo_jit_load_seconds": med(x["jit_load_seconds"] for x in hs),
        "hsgeo_cost_history": h["cost_history"],
        "ceres_seconds": ce_s,
        "ceres_cpu_seconds": ce_cpu,
        "ceres_iterations": c["iterations"],
        "ceres_seconds_per_iteration": ce_s / max(c["iterations"], 1),
        "ceres_final_cost": c["final_cost"],
        "ceres_converged_cost": conv["final_cost"],
        "ceres_converged_iterations": conv["iterations"],
        "ceres_linear_solver": c["linear_solver"],
        "ceres_num_threads": c["num_threads"],
        "final_cost_relative_difference": rel,
        "goal_cost_reached": bool(h["final_cost"] <= c["final_cost"] * (1 + 1e-6)),
        # the issue's goal read literally: hsgeo's first iterate at Ceres' final cost, no later
        # than Ceres' end (wall, and CPU: less sensitive to the shared machine's load) ...
        "goal_time_met": out_to is not None and bool(out_to <= ce_s),
        "goal_time_met_cpu": cpu_to is not None and bool(cpu_to <= ce_cpu),
        # ... and hsgeo's own convergence (a tighter test than Ceres' function tolerance)
        "converged_no_later_than_ceres": bool(hs_s <= ce_s),
        "hsgeo_seconds_runs": [x["seconds"] for x in hs],
        "ceres_seconds_runs": [x["seconds"] for x in ceres],
        "scipy_seconds": None if sc is None else sc["seconds"],
        "scipy_cpu_seconds": None if sc is None else sc["cpu_seconds"],
        "scipy_final_cost": None if sc is None else sc["final_cost"],
        "scipy_nfev": None if sc is None else sc["nfev"],
        "peak_rss_mb": max(x["peak_rss_mb"] for x in hs),
        "ceres_peak_rss_mb": max(x["peak_rss_mb"] for x in ceres),
        "scipy_peak_rss_mb": None if sc is None else sc["peak_rss_mb"],
        "pycolmap": c["pycolmap"],
        "commit": _commit(None),
        # make bench's malloc setting (the Makefile's GLIBC_TUNABLES: freed memory kept, so the
        # arrays of each iteration reuse pages instead of fresh zeroed ones); "" if unset
        "glibc_tunables": os.environ.get("GLIBC_TUNABLES", ""),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, {platform.python_version()}",
        "load_average": os.getloadavg()[0],
        # the CPU model and the BLAS core type beside the figures: the lead over Ceres was
        # 1.29x on one machine and 0.92x on another of the same kind (issue 41)
        "cpu_model": _cpu_model(),
        "blas_hsgeo": h.get("blas"),
        "blas_ceres_process": c.get("blas"),
        "machine_info": _machine_info(),
        "cpu_speedup_to_ceres_cost": None if cpu_to is None else ce_cpu / cpu_to,
        # each run's ratio against the Ceres run just before it (the pairs see the same load)
        "cpu_speedup_to_ceres_cost_each_run": [
            c["cpu_seconds"] / h["cpu_seconds_to_target"] if h["cpu_seconds_to_target"] else None
            for c, h in zip(ceres, hs, strict=True)
        ],
        "hsgeo_cpu_seconds_to_ceres_cost_runs": [x["cpu_seconds_to_target"] for x in hs],
        "ceres_cpu_seconds_runs": [x["cpu_seconds"] for x in ceres],
        "load_average_1_5_15_each_run": {
            "ceres": [x["load_average_1_5_15_before"] for x in ceres],
            "hsgeo": [x["load_average_1_5_15_before"] for x in hs],
        },
        "goal_cpu_speedup_min": 1.5,
        "vs_main": _vs_main(hs, vs, ceres, args.vs),
    }
    (HERE / "results").mkdir(exist_ok=True)
    path = HERE / "results" / "bal.json"
    path.write_text(json.dumps(out, indent=2) + "\n")
    keys = [k for k in out if not k.endswith(("history", "_runs"))]
    for k in keys:
        print(f"  {k}: {out[k]}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
