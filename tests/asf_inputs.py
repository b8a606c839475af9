"""Valid inputs of ``hsgeo asf`` (tests/test_cli_asf.py, tests/test_bad_input.py): a small
simulated runway flight (a 200-pixel scanner, so that it is quick), georegistered and written
as the command reads them."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np


def small_scene():
    from hsgeo.sensors.panoramic import PanoramicScanner
    from hsgeo.simulate.asf_runway import RunwayScene

    return replace(RunwayScene(), sensor=PanoramicScanner(n_px=200), runway_length_m=400.0)


def write_asf_inputs(d: Path, seed: int = 4) -> dict:
    """CROSS.nc, ALONG.nc and runway.csv under ``d``; returns the truth for checks."""
    import pandas as pd

    from hsgeo.io.scans import write_geoscan
    from hsgeo.simulate.asf_runway import simulate_runway
    from hsgeo.workflows.asf import georegister

    obs, truth = simulate_runway(small_scene(), seed, reverse=False)
    for name, s in (("cross", obs.cross), ("along", obs.along)):
        g = georegister(s.values, s.zeta_px, s.t0_s, s.line_rate_hz, s.sensor, s.trajectory)
        write_geoscan(d / f"{name}.nc", g.values, g.scan_angle_rad, g.E_m, g.N_m)
    P = obs.runway_polygon_m
    pd.DataFrame({"E_m": P[:, 0], "N_m": P[:, 1]}).to_csv(d / "runway.csv", index=False)
    return {"truth": truth, "zeta": obs.cross.zeta_px}


def true_asf_normalised(truth, halfwidth_deg=1.0):
    th = truth.scan_angle_rad
    a = truth.asf * truth.brdf_cross[None]
    near = np.abs(th) <= np.deg2rad(halfwidth_deg)
    return a / a[:, near].mean(axis=1, keepdims=True)
