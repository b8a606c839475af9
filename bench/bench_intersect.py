"""The ray–terrain intersection's cost, now and at a former revision (issue 36).

CPU seconds (``time.process_time``: every thread of the process, the best of 3) of:

* ``lp_render`` — :func:`hsgeo.simulate._lp_render.render_lines` on every strip of the LP
  campaign at ``--scale`` (its ground and rays captured from one :func:`simulate`), per million
  pixel-bands;
* ``dem_8.3deg`` / ``dem_30deg`` — :func:`hsgeo.geocode.intersect` of 200,000 rays within
  ±8.3° (the LP camera) and ±30° off nadir on a :class:`~hsgeo.geocode.DemTerrain` of a town
  (0.5 m cells, 200 flat-roofed buildings 3–8 m on a slope), with the count of rays whose
  crossings differ by more than 1 mm between the two revisions;
* ``map_dsm`` — the same on the orthomosaic test's :class:`~hsgeo.mapgrid.MapTerrain` (one LP
  strip over the hill of ``tests/ortho_inputs.py``).

The former revision's ``geocode.py`` and ``simulate/_lp_render.py`` are read with ``git show``
and imported beside the current ones.

``python bench/bench_intersect.py [--before REV] [--scale S]`` → ``bench/results/intersect.json``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "tests"))


def _module_at(rev: str, path: str, name: str, tmp: Path):
    src = subprocess.run(
        ["git", "show", f"{rev}:{path}"], capture_output=True, text=True, check=True, cwd=HERE
    ).stdout
    f = tmp / f"{name}.py"
    f.write_text(src)
    spec = importlib.util.spec_from_file_location(name, f)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def _cpu(f, *a, **k):
    best, out = np.inf, None
    for _ in range(3):
        t0 = time.process_time()
        out = f(*a, **k)
        best = min(best, time.process_time() - t0)
    return out, best


def _town(rng):
    import xarray as xr

    from hsgeo.geocode import DemTerrain

    E = np.arange(0, 400.5, 0.5)
    z = 0.01 * E[None, :] + 0.005 * E[:, None]
    for _ in range(200):
        e, n = rng.uniform(20, 380, 2)
        w, h = rng.uniform(5, 15, 2)
        m = (np.abs(E[None] - e) <= w / 2) & (np.abs(E[:, None] - n) <= h / 2)
        z = np.where(m, rng.uniform(3, 8) + 0.01 * e, z)
    return DemTerrain(xr.DataArray(z, dims=("N", "E"), coords={"N": E, "E": E}))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--before", default="e9a6a10", help="the former revision (default e9a6a10)")
    p.add_argument("--scale", type=float, default=0.1)
    p.add_argument("--out", default=str(HERE / "results" / "intersect.json"))
    a = p.parse_args(argv)
    from hsgeo import geocode as new_geo
    from hsgeo.simulate import _lp_render as new_lp
    from hsgeo.simulate import lp_campaign as lc

    tmp = Path(tempfile.mkdtemp())
    old_geo = _module_at(a.before, "src/hsgeo/geocode.py", "geocode_before", tmp)
    old_lp = _module_at(a.before, "src/hsgeo/simulate/_lp_render.py", "lp_render_before", tmp)
    res = {"before": a.before, "python": platform.python_version(), "rows": {}}

    calls = []
    orig = lc.render_lines
    lc.render_lines = lambda *x: calls.append(x) or orig(*x)
    lc.simulate(scale=a.scale, rng=0)
    lc.render_lines = orig
    n_pb = sum(R.shape[0] * d.shape[0] * d.shape[1] for R, _, d, _ in calls)
    outs = {}
    for key, mod in (("before", old_lp), ("now", new_lp)):
        mod.render_lines(*calls[0][:3], calls[0][3])  # compiled
        outs[key], cpu = _cpu(lambda m=mod: [m.render_lines(*c) for c in calls])
        res["rows"].setdefault("lp_render", {})[f"cpu_s_per_million_{key}"] = cpu / n_pb * 1e6
    diff = max(float(np.nanmax(np.abs(x - y))) for x, y in zip(*outs.values(), strict=True))
    res["rows"]["lp_render"].update(pixel_bands=n_pb, max_abs_reflectance_change=diff)

    rng = np.random.default_rng(0)
    dem = _town(rng)
    for ang in (8.3, 30.0):
        n = 200_000
        t = np.tan(np.radians(rng.uniform(-ang, ang, n)))
        d = np.column_stack([t, 0.05 * rng.standard_normal(n), -np.ones(n)])
        O = np.column_stack([rng.uniform(60, 340, (n, 2)), np.zeros(n)]) - 1000 * d
        new_geo.intersect(O[:4], d[:4], dem)
        Xb, tb = _cpu(old_geo.intersect, O, d, dem)
        Xn, tn = _cpu(new_geo.intersect, O, d, dem)
        res["rows"][f"dem_{ang:g}deg"] = {
            "rays": n,
            "cpu_s_before": tb,
            "cpu_s_now": tn,
            "rays_moved_over_1mm": int(np.sum(np.linalg.norm(Xb - Xn, axis=1) > 1e-3)),
        }

    from ortho_inputs import FRAME, dsm, flight_trajectory, lp_camera, lp_pixels

    from hsgeo.mapgrid import MapTerrain

    terr = MapTerrain(*dsm(), FRAME)
    nav, times = flight_trajectory()
    tt, px = times[0][::4], lp_pixels()
    o, d = lp_camera().rays(np.tile(px, (tt.size, 1)), np.repeat(tt, len(px)), nav, band=0)
    new_geo.intersect(o[:4], d[:4], terr)
    Xb, tb = _cpu(old_geo.intersect, o, d, terr)
    Xn, tn = _cpu(new_geo.intersect, o, d, terr)
    res["rows"]["map_dsm"] = {
        "rays": len(o),
        "cpu_s_before": tb,
        "cpu_s_now": tn,
        "max_change_m": float(np.abs(Xb - Xn).max()),
    }
    Path(a.out).write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
