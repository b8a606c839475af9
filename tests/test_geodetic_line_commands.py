"""A navigation as delivered (geodetic CSV, Applanix SBET) feeding ``adjust-pushbroom`` and
``lp-observations`` (issue 38): ``--nav-crs`` names its CRS, ``--site`` the origin of the local
frame in which the GCPs or squares are given.

The pushbroom campaign of ``tests/test_bad_input.py`` (its ``_pushbroom`` inputs: observations,
local-ENU navigation about the 002 site, GCPs) is adjusted once with its local-ENU navigation
and once with the same navigation written as ETRS89 latitude, longitude, ellipsoidal height and
attitude against each record's NED (the 002 flight test's own writer, an exact geodetic
inverse), as a CSV and as an SBET: the same adjustment. Bad input: a geodetic navigation with
GCPs but no ``--site``, ``--nav-crs`` with a local-ENU file, a truncated SBET, an SBET without
``--nav-crs`` — one line, exit 2.
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest
from test_bad_input import _pushbroom
from test_geodetic_002_flight import _geodetic_csv

from hsgeo.cli import main

SITE = "59.665,10.775,0"


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    """The pushbroom inputs, the navigation also as a geodetic CSV and an SBET (ETRS89)."""
    from hsgeo.crs import SITE_AAS
    from hsgeo.io.navigation import read_trajectory

    d = tmp_path_factory.mktemp("pb") / "in"
    _pushbroom(d)
    traj = read_trajectory(d / "nav.csv")
    _geodetic_csv(d / "geo.csv", traj, SITE_AAS)
    rows = np.loadtxt(d / "geo.csv", delimiter=",", skiprows=2)  # week, sow, lat, lon, h, rph
    with open(d / "nav.out", "wb") as f:
        for _w, t, lat, lon, h, r, p, y in rows:
            rad = np.radians([lat, lon])
            att = np.radians([r, p, y])
            f.write(struct.pack("<17d", t, *rad, h, 0, 0, 0, *att, 0.0, *([0.0] * 6)))
    return d


def _argv(d, nav, *extra):
    return [
        "adjust-pushbroom",
        str(d / "obs.csv"),
        "--trajectory",
        str(d / nav),
        "--camera",
        str(d / "cam.toml"),
        "--gcp",
        str(d / "gcp.csv"),
        "--json",
        "--accept-poor-fit",
        *extra,
    ]


def _shift_obs_times(d, dt_s):
    """The observation table on GPS seconds of week (the geodetic files' time scale)."""
    import pandas as pd

    obs = pd.read_csv(d / "obs.csv")
    obs["t_s"] = obs["t_s"] + dt_s
    p = d / "obs_sow.csv"
    obs.to_csv(p, index=False, float_format="%.17g")
    return p


@pytest.mark.slow
def test_geodetic_navigation_gives_the_local_adjustment(flight, capsys):
    """The adjustment through a geodetic CSV and an SBET (with --site, the GCPs' frame) is the
    local-ENU one: σ̂0 and every camera parameter within 1e-6 relative (measured below)."""
    d = flight
    assert main(_argv(d, "nav.csv")) == 0
    want = json.loads(capsys.readouterr().out)
    _shift_obs_times(d, 302400.0)
    got = {}
    for nav, extra in (("geo.csv", ()), ("nav.out", ("--nav-crs", "EPSG:4937"))):
        argv = _argv(d, nav, "--site", SITE, *extra)
        argv[1] = str(d / "obs_sow.csv")
        assert main(argv) == 0, capsys.readouterr().err
        got[nav] = json.loads(capsys.readouterr().out)
    for nav, res in got.items():
        rel = abs(res["sigma0"] - want["sigma0"]) / want["sigma0"]
        print(f"{nav}: sigma0 {res['sigma0']!r} vs {want['sigma0']!r} (relative {rel:.2e})")
        assert rel < 1e-6, (nav, rel)
        for k, v in want["parameters"].items():
            a, b = (np.asarray(x["value"], float) for x in (v, res["parameters"][k]))
            np.testing.assert_allclose(b, a, rtol=1e-6, atol=1e-9, err_msg=f"{nav} {k}")


def _truncated(d):
    p = d / "cut.out"
    p.write_bytes((d / "nav.out").read_bytes()[:-20])
    return p


@pytest.mark.parametrize(
    "nav, extra, expect",
    [
        ("geo.csv", (), "--site"),  # GCPs in a local frame, its origin not given
        ("nav.csv", ("--nav-crs", "EPSG:4979"), "drop --nav-crs"),
        ("nav.csv", ("--site", SITE), "drop --site"),
        ("nav.out", ("--site", SITE), "--nav-crs"),  # an SBET names no datum
        (_truncated, ("--nav-crs", "EPSG:4937", "--site", SITE), "truncated"),
    ],
    ids=[
        "geodetic-gcp-without-site",
        "nav-crs-with-local",
        "site-with-local",
        "sbet-no-crs",
        "sbet-truncated",
    ],  # fmt: skip
)
def test_bad_navigation_one_line_exit_2(flight, capsys, nav, extra, expect):
    d = flight
    nav = nav(d).name if callable(nav) else nav
    argv = [a for a in _argv(d, nav, *extra) if a not in ("--json", "--accept-poor-fit")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert expect in err and "\n" not in err and "Traceback" not in err, err


@pytest.mark.parametrize("cmd", ["lp-observations", "adjust-pushbroom"])
def test_both_commands_offer_the_options(cmd, capsys):
    with pytest.raises(SystemExit):
        main([cmd, "--help"])
    out = capsys.readouterr().out
    assert "--nav-crs" in out and "--site" in out
