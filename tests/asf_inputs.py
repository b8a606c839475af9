"""Valid inputs of ``hsgeo asf`` (tests/test_cli_asf.py, tests/test_bad_input.py): a small
simulated runway campaign (a 200-pixel scanner, so that it is quick), written as the command
reads it: the raw scans (``*_raw.nc``), the sensor file, the navigation and the runway; and the
same crossing and along scan georegistered (``cross.nc``, ``along.nc``)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np


def small_scene():
    from hsgeo.sensors.panoramic import PanoramicScanner
    from hsgeo.simulate.asf_runway import RunwayScene

    return replace(RunwayScene(), sensor=PanoramicScanner(n_px=200), runway_length_m=400.0)


def write_asf_inputs(d: Path, seed: int = 4, *, reverse: bool = True) -> dict:
    """Under ``d``: cross.nc, along.nc (georegistered), cross_raw.nc, along_raw.nc,
    reverse_raw.nc (raw), sensor.toml, nav.csv, runway.csv; returns the truth for checks."""
    import pandas as pd

    from hsgeo.io.lines import write_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.io.scans import write_geoscan, write_panoramic_sensor
    from hsgeo.simulate.asf_runway import navigation, simulate_runway
    from hsgeo.workflows.asf import georegister

    obs, truth = simulate_runway(small_scene(), seed, reverse=reverse)
    for name, s in (("cross", obs.cross), ("along", obs.along)):
        g = georegister(s.values, s.zeta_px, s.t0_s, s.line_rate_hz, s.sensor, s.trajectory)
        write_geoscan(d / f"{name}.nc", g.values, g.scan_angle_rad, g.E_m, g.N_m)
    for name in ("cross", "along", "reverse"):
        s = getattr(obs, name)
        if s is not None:
            write_lines(
                d / f"{name}_raw.nc", s.values, s.zeta_px, t0_s=s.t0_s, line_rate_hz=s.line_rate_hz
            )
    write_panoramic_sensor(d / "sensor.toml", obs.cross.sensor)
    write_trajectory(d / "nav.csv", navigation(obs))
    P = obs.runway_polygon_m
    pd.DataFrame({"E_m": P[:, 0], "N_m": P[:, 1]}).to_csv(d / "runway.csv", index=False)
    return {"truth": truth, "zeta": obs.cross.zeta_px}


def raw_argv(d: Path, *extra) -> list[str]:
    """``hsgeo asf`` on the raw scans of :func:`write_asf_inputs`."""
    return [
        "asf", str(d / "cross_raw.nc"), str(d / "along_raw.nc"), "--runway", str(d / "runway.csv"),
        "--sensor", str(d / "sensor.toml"), "--trajectory", str(d / "nav.csv"), *extra,
    ]  # fmt: skip


def true_asf_normalised(truth, halfwidth_deg=1.0, brdf=None):
    th = truth.scan_angle_rad
    a = truth.asf * (truth.brdf_cross if brdf is None else brdf)[None]
    near = np.abs(th) <= np.deg2rad(halfwidth_deg)
    return a / a[:, near].mean(axis=1, keepdims=True)
