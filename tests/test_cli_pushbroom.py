import json

import numpy as np
import pandas as pd
from priors import priors_toml

from hsgeo.cli import main
from hsgeo.io.navigation import write_trajectory
from hsgeo.simulate.pushbroom_campaign import simulate
from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
from hsgeo.trajectory import Trajectory, rph_from_platform_rpy


def _write(tmp_path, obs):
    o = obs.lines
    pd.DataFrame(
        {
            "point_id": o.point + 1000,
            "band": o.band,
            "t_s": o.t_s,
            "x_px": o.xy_px[:, 0],
            "y_px": o.xy_px[:, 1],
        }
    ).to_parquet(tmp_path / "obs.parquet")
    # navigation at the line times (the simulator's solution), sorted and unique; the
    # simulator's platform angles become the GNSS/INS roll, pitch, heading of the file
    t, i = np.unique(o.t_s, return_index=True)
    write_trajectory(
        tmp_path / "nav.csv", Trajectory(t, o.xyz_nav_m[i], rph_from_platform_rpy(o.rpy_nav_rad[i]))
    )
    g = obs.gcp_xyz_m
    pd.DataFrame(
        {"point_id": obs.gcp_index + 1000, "E_m": g[:, 0], "N_m": g[:, 1], "H_m": g[:, 2]}
    ).to_csv(tmp_path / "gcp.csv", index=False)
    la = ", ".join(f"{v:.6f}" for v in obs.lever_arm_m)
    (tmp_path / "cam.toml").write_text(
        f"[camera]\nn_bands = 7\npixel_mm = 0.0065\nc_mm = 40.0\nx0_mm = {CampaignConfig().x0_mm}\n"
        f"lever_arm_m = [{la}]\n" + priors_toml()
    )


def test_adjust_pushbroom_cli(tmp_path, capsys):
    obs, truth = simulate(0.002, rng=4)
    _write(tmp_path, obs)
    rc = main(
        [
            "adjust-pushbroom",
            str(tmp_path / "obs.parquet"),
            "--trajectory",
            str(tmp_path / "nav.csv"),
            "--camera",
            str(tmp_path / "cam.toml"),
            "--gcp",
            str(tmp_path / "gcp.csv"),
            "--json",
        ]
    )
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["converged"]
    c = np.array(out["parameters"]["c_mm"]["value"])
    s = np.array(out["parameters"]["c_mm"]["sigma"])
    assert np.all(np.abs(c - truth.values["c_mm"]) < 4 * s)


def test_adjust_pushbroom_cli_bad_input(tmp_path, capsys):
    obs, _ = simulate(0.001, rng=4)
    _write(tmp_path, obs)
    pd.read_csv(tmp_path / "nav.csv").drop(columns="heading_deg").to_csv(tmp_path / "bad.csv")
    rc = main(
        [
            "adjust-pushbroom",
            str(tmp_path / "obs.parquet"),
            "--trajectory",
            str(tmp_path / "bad.csv"),
            "--camera",
            str(tmp_path / "cam.toml"),
        ]
    )
    assert rc == 2
    assert "heading_deg" in capsys.readouterr().err
    # the former adjust-pushbroom format: the message says how to convert
    o = obs.lines
    pd.DataFrame(
        np.column_stack([o.t_s, o.xyz_nav_m, o.rpy_nav_rad]),
        columns=["t_s", "E_m", "N_m", "H_m", "roll_rad", "pitch_rad", "yaw_rad"],
    ).to_csv(tmp_path / "old.csv", index=False)
    rc = main(
        [
            "adjust-pushbroom",
            str(tmp_path / "obs.parquet"),
            "--trajectory",
            str(tmp_path / "old.csv"),
            "--camera",
            str(tmp_path / "cam.toml"),
        ]
    )
    assert rc == 2
    assert "heading_deg = 90 - degrees(yaw_rad)" in capsys.readouterr().err
    rc = main(
        [
            "adjust-pushbroom",
            str(tmp_path / "nope.csv"),
            "--trajectory",
            str(tmp_path / "nav.csv"),
            "--camera",
            str(tmp_path / "cam.toml"),
        ]
    )
    assert rc == 2


def test_adjust_pushbroom_cli_refuses_an_implausible_fit(tmp_path, capsys):
    """Navigation angles in radians under the *_deg columns (a units mistake): the fit is
    reported, the error names σ0 and the likely cause, and the exit status is 2 unless
    --accept-poor-fit."""
    obs, _ = simulate(0.002, rng=4)
    _write(tmp_path, obs)
    nav = pd.read_csv(tmp_path / "nav.csv")
    for c in ("roll_deg", "pitch_deg", "heading_deg"):
        nav[c] = np.deg2rad(nav[c])
    nav.to_csv(tmp_path / "nav_rad.csv", index=False)
    args = [
        "adjust-pushbroom",
        str(tmp_path / "obs.parquet"),
        "--trajectory",
        str(tmp_path / "nav_rad.csv"),
        "--camera",
        str(tmp_path / "cam.toml"),
        "--json",
    ]
    assert main(args) == 2
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["fit"]["verdict"] == "poor" and out["fit"]["sigma0"] > 3
    err = [line for line in cap.err.splitlines() if "error:" in line]
    assert len(err) == 1 and "σ0 = " in err[0] and "roll_deg" in err[0]
    assert main([*args, "--accept-poor-fit"]) == 0
    assert json.loads(capsys.readouterr().out)["fit"]["verdict"] == "poor"
