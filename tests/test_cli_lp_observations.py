"""``hsgeo lp-observations``: LP line files → the observation table that ``hsgeo
adjust-pushbroom`` adjusts unchanged; bad input is one line and status 2, nothing overwritten."""

import hashlib
import json

import pandas as pd
import pytest
from priors import priors_toml

from hsgeo.cli import main


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Eight strips of the rendered campaign (scale 0.1) as LP line files, the navigation, the
    a-priori camera file and the squares (with the 4 GCPs among them)."""
    from hsgeo.io.lp_lines import write_lp_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.simulate.lp_campaign import simulate

    d = tmp_path_factory.mktemp("lp")
    obs, _ = simulate(scale=0.1, rng=2)
    strips = []
    for s in obs.strips[:10:2] + obs.strips[12:15]:
        write_lp_lines(d / f"{s.strip_id}.nc", s)
        strips.append(str(d / f"{s.strip_id}.nc"))
    write_trajectory(d / "nav.csv", obs.navigation)
    cam = obs.camera
    la = ", ".join(f"{v:.6f}" for v in cam.lever_arm_m)
    (d / "cam.toml").write_text(
        f"[camera]\nn_bands = {len(cam.c_mm)}\npixel_mm = {cam.pixel_mm}\nc_mm = {cam.c_mm[0]}\n"
        f"x0_mm = {cam.x0_mm}\nlever_arm_m = [{la}]\n" + priors_toml()
    )
    xyz = obs.square_xyz_m
    sq = pd.DataFrame(
        {"point_id": list(obs.square_ids), "E_m": xyz[:, 0], "N_m": xyz[:, 1], "H_m": xyz[:, 2]}
    )
    sq.to_csv(d / "squares.csv", index=False, float_format="%.17g")
    sq[sq["point_id"].isin(obs.gcp_ids)].to_csv(d / "gcp.csv", index=False, float_format="%.17g")
    return d, strips


def _sha(d):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(d.iterdir())}


def _argv(d, strips, out):
    return [
        "lp-observations",
        *strips,
        "--trajectory",
        str(d / "nav.csv"),
        "--camera",
        str(d / "cam.toml"),
        "--squares",
        str(d / "squares.csv"),
        "-o",
        str(out),
    ]


def test_lp_observations_feeds_adjust_pushbroom(files, capsys):
    d, strips = files
    out = d / "obs.parquet"
    rc = main([*_argv(d, strips, out), "--json"])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    summary = json.loads(cap.out)
    tab = pd.read_parquet(out)
    assert summary["n_observations"] == len(tab) > 500
    assert summary["n_squares"] >= 4 and summary["options"]["ransac"] == "lp"
    assert {"point_id", "band", "t_s", "x_px", "y_px", "strip", "line"} <= set(tab.columns)
    # the GCPs measured in these strips (a square seen in fewer than two lines is not in the table)
    gcp = pd.read_csv(d / "gcp.csv")
    gcp = gcp[gcp["point_id"].isin(tab["point_id"])]
    assert len(gcp) >= 2
    gcp.to_csv(d / "gcp_seen.csv", index=False, float_format="%.17g")
    rc = main(
        [
            "adjust-pushbroom",
            str(out),
            "--trajectory",
            str(d / "nav.csv"),
            "--camera",
            str(d / "cam.toml"),
            "--gcp",
            str(d / "gcp_seen.csv"),
            "--json",
        ]
    )
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    res = json.loads(cap.out)
    assert res["converged"] and res["n_observations_2d"] == len(tab)
    # the frame model as the RANSAC and the text summary
    out2 = d / "obs_frame.csv"
    assert main([*_argv(d, strips, out2), "--ransac", "frame", "--scene-lines", "150"]) == 0
    line = capsys.readouterr().out
    assert "observations of" in line and "frame-F RANSAC inliers" in line
    assert len(pd.read_csv(out2)) > 0
    # --all-bands: every band's tie points, a superset of the default's rows
    out3 = d / "obs_all.parquet"
    assert main([*_argv(d, strips, out3), "--all-bands", "--json"]) == 0
    s3 = json.loads(capsys.readouterr().out)
    every = pd.read_parquet(out3)
    assert s3["n_observations"] == len(every) == s3["n_observations_all_bands"] > len(tab)
    assert summary["n_observations_all_bands"] == len(every)
    cols = ["point_id", "band", "strip", "line"]
    assert len(tab[cols].merge(every[cols])) == len(tab)


@pytest.mark.parametrize(
    "mutate, expect",
    [
        (lambda a, d, s: a, "--overwrite"),  # the output exists (written first)
        (lambda a, d, s: [*a, "--bands", "0,9"], "band(s) [9]"),
        (lambda a, d, s: [*a, "--bands", "x"], "--bands"),
        (lambda a, d, s: [*a, "--ransac", "homography"], "--ransac"),
        (lambda a, d, s: [*a, "--scene-lines", "2"], "--scene-lines"),
        (lambda a, d, s: [a[0], s[0], s[1], *a[1 + len(s) :]], "strip(s) given"),
        (lambda a, d, s: [a[0], s[0], *a[1:]], "given twice"),
        (lambda a, d, s: [x.replace("nav.csv", "nav_short.csv") for x in a], "covers t_s"),
        (lambda a, d, s: [x.replace("squares.csv", "missing.csv") for x in a], "missing.csv"),
        (lambda a, d, s: [x.replace("obs_bad.parquet", "cam.toml") for x in a], "input"),
        (lambda a, d, s: [x.replace("obs_bad.parquet", "obs_bad.txt") for x in a], ".txt"),
        (lambda a, d, s: [x.replace(s[0], str(d / "cam.toml")) for x in a], "cam.toml"),
    ],
)
def test_lp_observations_bad_input(files, capsys, mutate, expect):
    d, strips = files
    nav = pd.read_csv(d / "nav.csv")
    nav.iloc[: len(nav) // 2].to_csv(d / "nav_short.csv", index=False, float_format="%.17g")
    out = d / "obs_bad.parquet"
    out.write_bytes(b"not yet")  # an existing output: refused without --overwrite
    argv = mutate(_argv(d, strips, out), d, strips)
    if expect != "--overwrite":
        argv.append("--overwrite")
    before = _sha(d)
    try:
        rc = main(argv)
    except SystemExit as exc:  # argparse's own errors (one line, status 2)
        rc = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2
    assert len(err) == 1 and expect in err[0], err
    assert _sha(d) == before  # nothing written, nothing overwritten
