"""The navigation file (hsgeo.io.navigation): format, round trip, old-format and error messages."""

import numpy as np
import pandas as pd
import pytest

from hsgeo import InputError
from hsgeo.io.navigation import NAV_COLUMNS, read_trajectory, write_trajectory
from hsgeo.trajectory import Trajectory


def _traj(n=11):
    t = np.linspace(0, 10, n)
    rng = np.random.default_rng(0)
    return Trajectory(
        t,
        np.column_stack([t, 2 * t, np.full(n, 100.0)]) + rng.normal(0, 1, (n, 3)),
        np.column_stack([0.01 * t, -0.02 * t, np.full(n, 3.1)]) + rng.normal(0, 0.1, (n, 3)),
    )


def test_round_trip_is_lossless_and_the_header_is_the_format(tmp_path):
    tr = _traj()
    p = write_trajectory(tmp_path / "nav.csv", tr)
    assert p.read_text().splitlines()[0] == ",".join(NAV_COLUMNS)
    back = read_trajectory(p)
    np.testing.assert_array_equal(back.t_s, tr.t_s)
    np.testing.assert_array_equal(back.xyz_m, tr.xyz_m)
    # degrees at the edge: deg2rad(rad2deg(x)) is x to the last bit or one ulp
    np.testing.assert_allclose(
        back.roll_pitch_heading_rad, tr.roll_pitch_heading_rad, rtol=2e-16, atol=0
    )
    # degrees in the file, to the last bit (%.17g)
    table = np.loadtxt(p, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 4:], np.rad2deg(tr.roll_pitch_heading_rad))
    assert not list(tmp_path.glob(".*tmp"))  # no temporary file left


def test_parquet_and_extra_columns(tmp_path):
    tr = _traj()
    df = pd.DataFrame(
        np.column_stack([tr.t_s, tr.xyz_m, np.rad2deg(tr.roll_pitch_heading_rad)]),
        columns=list(NAV_COLUMNS),
    )
    df["quality"] = 1
    df.to_parquet(tmp_path / "nav.parquet")
    back = read_trajectory(tmp_path / "nav.parquet")
    np.testing.assert_array_equal(back.xyz_m, tr.xyz_m)
    pos, _ = back.pose([2.5])
    np.testing.assert_allclose(pos, tr.pose([2.5])[0])


def test_never_overwrites_an_input(tmp_path):
    tr = _traj()
    src = write_trajectory(tmp_path / "in.csv", tr)
    before = src.read_bytes()
    with pytest.raises(InputError, match="is an input of the command and would be overwritten"):
        write_trajectory(tmp_path / "in.csv", tr, inputs=[src])
    assert src.read_bytes() == before


def test_old_pushbroom_format_gets_the_conversion(tmp_path):
    pd.DataFrame(
        np.zeros((3, 7)) + np.arange(3)[:, None],
        columns=["t_s", "E_m", "N_m", "H_m", "roll_rad", "pitch_rad", "yaw_rad"],
    ).to_csv(tmp_path / "old.csv", index=False)
    with pytest.raises(InputError) as e:
        read_trajectory(tmp_path / "old.csv")
    msg = str(e.value)
    for col in NAV_COLUMNS:
        assert col in msg
    assert "heading_deg = 90 - degrees(yaw_rad)" in msg
    assert "pitch_deg = -degrees(pitch_rad)" in msg


def test_errors_name_the_file_and_the_remedy(tmp_path):
    tr = _traj()
    p = write_trajectory(tmp_path / "nav.csv", tr)
    df = pd.read_csv(p)
    df.drop(columns="heading_deg").to_csv(tmp_path / "a.csv", index=False)
    with pytest.raises(InputError, match="heading_deg"):
        read_trajectory(tmp_path / "a.csv")
    d = df.copy()
    d.loc[3, "E_m"] = np.nan
    d.to_csv(tmp_path / "b.csv", index=False)
    with pytest.raises(InputError, match=r"line 5, column E_m"):
        read_trajectory(tmp_path / "b.csv")
    df.iloc[::-1].to_csv(tmp_path / "c.csv", index=False)
    with pytest.raises(InputError, match="c.csv.*increase strictly"):
        read_trajectory(tmp_path / "c.csv")
    d = df.astype({"U_m": object})
    d.loc[2, "U_m"] = "high"
    d.to_csv(tmp_path / "d.csv", index=False)
    with pytest.raises(InputError, match="column U_m: 'high' is not a number"):
        read_trajectory(tmp_path / "d.csv")
    with pytest.raises(InputError, match="missing.csv' not found"):
        read_trajectory(tmp_path / "missing.csv")
    (tmp_path / "e.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="not a readable"):
        read_trajectory(tmp_path / "e.parquet")
