"""Cube assembly throughput: lines per second per core of dark correction + reflectance + write.

The frames of the simulated vineyard survey (binning 2, 512 × 640 px, 001 §3.2) are rendered
once and held in memory, so that only the pipeline is timed: the dark fit (20 dark frames), then
dark subtraction, incident mean, reflectance and 5-row bands for every frame, and the write
(NetCDF-4 and ENVI BSQ), streamed in chunks of 64 lines on one core (Dask's synchronous
scheduler, one BLAS thread). The obvious alternative is timed in the same run: the whole cube
computed in memory in float64 with NumPy, then written in one piece (``write_envi``); its peak
memory grows with the run, the streamed one does not.

``python bench/bench_cube.py [--lines N]`` → ``bench/results/cube.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from hsgeo.io import write_envi
from hsgeo.io.cube import write_cube
from hsgeo.radiometry import bin_rows, incident_mean, reflectance
from hsgeo.reproduce.cube import ArrayFrames
from hsgeo.simulate import cube_survey as CS
from hsgeo.workflows.cube import CubeInputs, CubeOptions, build_cube, dark_model

HERE = Path(__file__).parent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=256, help="frames of the run (default 256)")
    args = ap.parse_args(argv)
    cfg = CS.CubeSurvey(length_m=args.lines * 0.033 / 24 + 1e-6)
    frames, (dark, t_dark), _ = CS.simulate(cfg, 0)
    raw = frames.read(0, frames.n_frames)
    n = raw.shape[0]
    src = ArrayFrames(raw, frames.exposure_s)
    dsrc = ArrayFrames(dark, t_dark)
    lam, fwhm = cfg.row_wavelength_nm(), cfg.row_fwhm_nm()
    opts = CubeOptions(f_alpha=cfg.f_alpha(), f_theta=tuple(cfg.f_theta()))
    out = {"n_lines": n, "frame_shape": list(raw.shape[1:]), "rows_per_band": 5}

    c0 = time.process_time()
    dm = dark_model(dsrc, opts)
    out["dark_fit_cpu_s"] = time.process_time() - c0
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("cube.nc", "cube.hdr"):
            res = build_cube(CubeInputs(src, dsrc, lam, fwhm), opts, dark=dm)
            w0, c0 = time.perf_counter(), time.process_time()
            write_cube(res.cube, Path(tmp) / name)
            cpu = time.process_time() - c0
            rows[name] = {
                "wall_s": time.perf_counter() - w0,
                "cpu_s": cpu,
                "lines_per_cpu_s": n / cpu,
                "bytes": sum(p.stat().st_size for p in Path(tmp).glob(name.split(".")[0] + "*")),
            }
            for p in Path(tmp).glob("cube*"):
                p.unlink()
        # the obvious alternative: everything in memory (float64), one write at the end
        model, hot = dm
        nr = cfg.layout.n_reflected
        w0, c0 = time.perf_counter(), time.process_time()
        corr = raw - (model.a_dn_per_s[None] * src.exposure_s[:, None, None] + model.b_dn[None])
        e_inc = incident_mean(corr[:, :, nr:], hot[:, nr:])
        r = reflectance(corr[:, :, :nr], e_inc, f_alpha=opts.f_alpha, f_theta=cfg.f_theta())
        cube = bin_rows(r, 5, axis=1).astype(np.float32)  # (lines, bands, samples)
        write_envi(Path(tmp) / "whole", cube.transpose(1, 0, 2))
        cpu = time.process_time() - c0
        rows["in memory, float64 (alternative)"] = {
            "wall_s": time.perf_counter() - w0,
            "cpu_s": cpu,
            "lines_per_cpu_s": n / cpu,
            "intermediate_mib": (corr.nbytes + r.nbytes) / 2**20,
        }
    out["rows"] = rows
    out["machine"] = {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpu_count": os.cpu_count(),
        "load_avg": os.getloadavg(),
        "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
    }
    out["note"] = (
        "lines per CPU second of one core: dark subtraction + incident mean + reflectance + "
        "bands + write; frames pre-rendered in memory; dark fit timed separately. Memory of the "
        "streamed write: tests/test_cube.py (a 600 MB cube, resident memory +71-77 MB)"
    )
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "cube.json").write_text(json.dumps(out, indent=1) + "\n")
    for k, v in rows.items():
        print(f"{k:34s} {v['lines_per_cpu_s']:8.1f} lines/CPU-s  wall {v['wall_s']:.2f} s")
    print(f"dark fit (20 frames) {out['dark_fit_cpu_s']:.2f} CPU-s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
