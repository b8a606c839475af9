"""hsgeo.io: every reader round-trips a good file and turns a bad one into one InputError that
names the file, the column / key and the remedy."""

import os
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import pytest

from hsgeo import InputError
from hsgeo.io import (
    Key,
    atomic_path,
    read_board,
    read_camera_toml,
    read_dataclass,
    read_dem,
    read_lines,
    read_opencv_storage,
    read_sensor_toml,
    read_table,
    write_lines,
    write_raster,
)
from hsgeo.io.boards import OPENCV_TUTORIAL_CHARUCO, Board
from hsgeo.sensors.line import CalibratedLine, LinearIFOV
from hsgeo.simulate.scenarios import load_scenario


# ---- OpenCV FileStorage
def test_read_opencv_storage_bad_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_opencv_storage(tmp_path / "missing.yml")
    bad = tmp_path / "bad.yml"
    bad.write_text("%YAML:1.0\ncamera_matrix: [1, 2\n  : :\n")
    with pytest.raises(InputError):
        read_opencv_storage(bad)
    ok = tmp_path / "ok.yml"
    ok.write_text("%YAML:1.0\nimage_width: 640\n")
    assert read_opencv_storage(ok)["image_width"] == 640
    with pytest.raises(InputError, match="missing entries"):
        read_opencv_storage(ok, required=("camera_matrix",))


def test_read_opencv_storage_round_trip(tmp_path):
    import cv2

    K = np.array([[800.0, 0, 320.5], [0, 801.0, 240.25], [0, 0, 1]])
    fs = cv2.FileStorage(str(tmp_path / "c.yml"), cv2.FILE_STORAGE_WRITE)
    fs.write("camera_matrix", K)
    fs.write("name", "webcam")
    fs.release()
    d = read_opencv_storage(tmp_path / "c.yml", required=("camera_matrix",))
    np.testing.assert_array_equal(d["camera_matrix"], K)
    assert d["name"] == "webcam"


# ---- tables
COLS = ("image", "point", "zeta_px")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_read_table_round_trip(tmp_path, suffix):
    df = pd.DataFrame(
        {
            "image": ["a", "a", "b"],
            "point": ["01", "2", "3"],
            "zeta_px": [3.5, -1.25, 1e3],
            "extra": [1, 2, 3],
        }
    )
    p = tmp_path / f"obs{suffix}"
    if suffix == ".csv":
        df.to_csv(p, index=False)
    else:
        df.to_parquet(p)
    back = read_table(p, COLS, "observation", text_columns=("image", "point"))
    assert back["point"].tolist() == ["01", "2", "3"]  # ids stay text: "01" is not 1
    np.testing.assert_array_equal(back["zeta_px"].to_numpy(), df["zeta_px"].to_numpy())
    assert back["extra"].tolist() == [1, 2, 3]


def test_read_table_comments_and_line_numbers(tmp_path):
    p = tmp_path / "obs.csv"
    p.write_text("# measured 2026-11\nimage, point, zeta_px\n1,2,3.5\n\n# a comment\n1,3,\n")
    with pytest.raises(InputError) as e:
        read_table(p, COLS, "observation")
    msg = str(e.value)
    assert "obs.csv" in msg and "line 6" in msg and "column zeta_px" in msg
    assert "fill it in or delete the row" in msg


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            "image,point,zeta\n1,2,3.5\n",
            ["missing column(s) zeta_px", "rename 'zeta' to 'zeta_px'"],
        ),
        ("image,point,zeta_px\n1,2,nan\n", ["line 2", "column zeta_px", "NaN"]),
        ("image,point,zeta_px\n1,2,abc\n", ["line 2", "column zeta_px", "'abc' is not a number"]),
        ("image,point,zeta_px\n1,,3\n", ["line 2", "column point", "empty"]),
        ("", ["is empty", "header line"]),
        ("image,point,zeta_px\n", ["no data rows"]),
    ],
)
def test_read_table_bad_files(tmp_path, text, needle):
    p = tmp_path / "obs.csv"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_table(p, COLS, "observation")
    msg = str(e.value)
    assert "observation file" in msg and "obs.csv" in msg
    for n in needle:
        assert n in msg, (n, msg)


def test_read_table_missing_and_unreadable(tmp_path):
    with pytest.raises(InputError, match="not found; check the path"):
        read_table(tmp_path / "none.csv", COLS)
    p = tmp_path / "x.parquet"
    p.write_text("not parquet")
    with pytest.raises(InputError, match="not a readable Parquet"):
        read_table(p, COLS)
    q = tmp_path / "nan.parquet"
    pd.DataFrame({"image": [1], "point": [2], "zeta_px": [np.inf]}).to_parquet(q)
    with pytest.raises(InputError, match="row 1, column zeta_px: empty, NaN or infinite"):
        read_table(q, COLS)


# ---- TOML with a schema: the one loader, as the instrument files use it
@dataclass(frozen=True, kw_only=True)
class _A:
    x_m: float
    n: int = 3
    v: tuple[float, ...] | None = field(default=None, metadata={"key": Key("floats", length=2)})
    kind: str | None = field(default=None, metadata={"key": Key("str", choices=("one", "two"))})


@dataclass(frozen=True, kw_only=True)
class _File:
    a: _A


def test_read_dataclass_round_trip_and_defaults(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text("[a]\nx_m = 2\nv = [1, 2.5]\nkind = 'two'\n")
    cfg = read_dataclass(p, _File)
    assert cfg == _File(a=_A(x_m=2.0, n=3, v=(1.0, 2.5), kind="two"))
    assert isinstance(cfg.a.x_m, float)


@pytest.mark.parametrize(
    "text, needle",
    [
        ("[a]\nx_mm = 1\n", ["[a] x_mm: unknown key; did you mean 'x_m'?", "[a] x_m: missing"]),
        ("[aa]\nx_m = 1\n", ["[aa]: unknown table; did you mean 'a'?", "[a]: missing table"]),
        ("[a]\nx_m = nan\n", ["[a] x_m: must be a finite number"]),
        ("[a]\nx_m = 'one'\n", ["[a] x_m: expected a number"]),
        ("[a]\nx_m = 1\nn = 1.5\n", ["[a] n: expected a whole number"]),
        ("[a]\nx_m = 1\nv = [1]\n", ["[a] v: needs 2 numbers"]),
        ("[a]\nx_m = 1\nkind = 'tow'\n", ["[a] kind must be one of 'one', 'two'", "'two'?"]),
        ("[a\n", ["malformed TOML"]),
        ("", ["[a]: missing table; add a [a] table"]),
    ],
)
def test_read_dataclass_errors(tmp_path, text, needle):
    p = tmp_path / "c.toml"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_dataclass(p, _File, "test file")
    msg = str(e.value)
    assert "c.toml" in msg
    for n in needle:
        assert n in msg, (n, msg)


def test_sensor_toml(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(
        "[sensor]\nmodel = 'calibrated'\nzeta0_px = 486.8\nc_px = 3539\n"
        "K = [1.459, -0.1636, 0.00526]\nboresight_deg = [1.0, -2.0, 90]\n"
    )
    geom, b = read_sensor_toml(p)
    assert geom == CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))
    np.testing.assert_allclose(b, np.deg2rad([1.0, -2.0, 90.0]), rtol=0, atol=0)
    p.write_text("[sensor]\nmodel = 'linear-ifov'\nzeta0_px = 485\nc_px = 3600\n")
    geom, b = read_sensor_toml(p)
    assert geom == LinearIFOV(485.0, 3600.0) and not b.any()


@pytest.mark.parametrize(
    "text, needle",
    [
        ("[sensor]\nmodel = 'pinhole'\nzeta0_px = 1\nc_px = 2\n", "model must be one of"),
        ("[sensor]\nzeta0_px = 1\n", "[sensor] c_px: missing"),
        (
            "[sensor]\nzeta0_px = 1\nc_px = 2\nborsight_deg = [0, 0, 0]\n",
            "[sensor] borsight_deg: unknown key; did you mean 'boresight_deg'?",
        ),
        ("[sensor]\nzeta0_px = 1\nc_px = 2\nboresight_deg = [0, 0]\n", "needs 3 numbers"),
        ("[sensor]\nzeta0_px = nan\nc_px = 2\n", "[sensor] zeta0_px: must be a finite number"),
        ("[sensor\n", "malformed"),
    ],
)
def test_sensor_toml_errors(tmp_path, text, needle):
    p = tmp_path / "s.toml"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_sensor_toml(p)
    assert needle in str(e.value) and "s.toml" in str(e.value)


def test_camera_toml(tmp_path):
    from hsgeo.workflows.pushbroom_ba import read_camera

    p = tmp_path / "cam.toml"
    head = "[camera]\nn_bands = 7\npixel_mm = 0.0065\nc_mm = 40\n"
    p.write_text(head + "[gnss_ins]\nsigma_att_deg = [0.01, 0.01, 0.02]\n[gcp]\nsigma_m = 0.05\n")
    assert read_camera_toml(p)["camera"] == {"n_bands": 7, "pixel_mm": 0.0065, "c_mm": 40.0}
    # no σ is a default (a paper's σ is not the user's instruments'): each missing one by name
    with pytest.raises(InputError) as e:
        read_camera(p)
    msg = str(e.value)
    for key in ("[camera] sigma_lever_m", "[gnss_ins] sigma_pos_m", "[observations] sigma_px"):
        assert key in msg, key
    assert "sigma_att_deg" not in msg and "[gcp] sigma_m" not in msg and "cam.toml" in msg
    priors = (
        "sigma_lever_m = 0.03\n[gnss_ins]\nsigma_pos_m = [0.02, 0.02, 0.04]\n"
        "sigma_att_deg = [0.01, 0.01, 0.02]\n[observations]\nsigma_px = 0.4\n"
    )
    p.write_text(head + priors)
    with pytest.raises(InputError, match=r"\[gcp\] sigma_m"):
        read_camera(p)  # GCPs need theirs
    cam = read_camera(p, need_gcp_sigma=False)
    assert np.isnan(cam.sigma_gcp_m) and cam.sigma_obs_px == 0.4 and cam.sigma_lever_m == 0.03
    p.write_text(head + priors + "[gcp]\nsigma_m = 0.05\n")
    cam = read_camera(p)
    assert cam.sigma_gcp_m == 0.05 and cam.sigma_pos_m == (0.02, 0.02, 0.04)
    np.testing.assert_allclose(cam.sigma_att_rad, np.deg2rad([0.01, 0.01, 0.02]))
    p.write_text("[camera]\nn_bands = 7\npixel_mm = 0.0065\nc_mm = 40\n[gnss]\n")
    with pytest.raises(InputError, match=r"\[gnss\]: unknown table; did you mean 'gnss_ins'"):
        read_camera(p)
    p.write_text("[camera]\nn_bands = 7\nc_mm = -40\n")
    with pytest.raises(InputError) as e:
        read_camera(p)
    assert "[camera] pixel_mm: missing" in str(e.value)
    assert "[camera] c_mm: must be positive" in str(e.value)


# ---- boards
def test_read_board_round_trip(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(
        '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 5\n'
        "squares_y = 7\nsquare_mm = 40\nmarker_mm = 20\n"
    )
    assert read_board(p) == OPENCV_TUTORIAL_CHARUCO
    p.write_text(
        '[board]\ntype = "aruco_grid"\ndictionary = "DICT_4X4_100"\nmarkers_x = 9\n'
        "markers_y = 6\nmarker_mm = 60.0\nseparation_mm = 20.0\n"
        "[camera]\npixel_mm = 0.0055\n"
    )
    assert read_board(p) == Board.aruco_grid(9, 6, 60.0, 20.0, "DICT_4X4_100", 0.0055)


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 5\n',
            "is missing squares_y, square_mm, marker_mm",
        ),
        (
            '[board]\ntype = "hexagons"\ndictionary = "DICT_6X6_250"\n',
            "[board] type must be one of",
        ),
        (
            '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 5\nsquares_y = 7\n'
            "square_mm = 40\nmarker_mm = 20\nseparation_mm = 3\n",
            "belong to the other board type",
        ),
        (
            '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 5\nsquares_y = 7\n'
            "squre_mm = 40\nmarker_mm = 20\n",
            "did you mean 'square_mm'?",
        ),
        (
            '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_999"\nsquares_x = 5\nsquares_y = 7\n'
            "square_mm = 40\nmarker_mm = 20\n",
            "unknown ArUco dictionary",
        ),
        (
            '[board]\ntype = "charuco"\ndictionary = "DICT_6X6_250"\nsquares_x = 1\nsquares_y = 7\n'
            "square_mm = 40\nmarker_mm = 20\n",
            "at least 2 x 2",
        ),
        ("[board\n", "malformed"),
    ],
)
def test_read_board_errors(tmp_path, text, needle):
    p = tmp_path / "b.toml"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_board(p)
    assert needle in str(e.value) and "b.toml" in str(e.value)


def test_board_units_reach_opencv():
    cm = OPENCV_TUTORIAL_CHARUCO.cv_board("mm").getChessboardCorners()
    m = OPENCV_TUTORIAL_CHARUCO.cv_board("m").getChessboardCorners()
    np.testing.assert_allclose(np.asarray(m) * 1000.0, np.asarray(cm), rtol=1e-6)
    assert np.asarray(cm)[1, 0] - np.asarray(cm)[0, 0] == 40.0  # square side in mm
    with pytest.raises(InputError, match="length_unit"):
        OPENCV_TUTORIAL_CHARUCO.cv_board("inch")


# ---- flight lines, maps, DEMs, atomic writes
def test_lines_round_trip_and_errors(tmp_path):
    rng = np.random.default_rng(0)
    r = rng.random((2, 5, 4)).astype(np.float32)
    write_lines(
        tmp_path / "l.nc",
        r,
        [10.0, 11, 12, 13],
        t0_s=1.5,
        line_rate_hz=8.0,
        wavelength_nm=[500.0, 600.0],
    )
    da, t0, rate = read_lines(tmp_path / "l.nc")
    np.testing.assert_array_equal(da.values, r)
    assert (t0, rate) == (1.5, 8.0) and da["pixel"].values.tolist() == [10, 11, 12, 13]
    import xarray as xr

    xr.Dataset({"dn": (("line", "pixel"), r[0])}).to_netcdf(tmp_path / "b.nc", engine="scipy")
    with pytest.raises(InputError, match="no variable 'radiance'"):
        read_lines(tmp_path / "b.nc")
    xr.Dataset({"radiance": (("line", "pixel"), r[0])}).to_netcdf(tmp_path / "c.nc", engine="scipy")
    with pytest.raises(InputError, match="no coordinate 'pixel'"):
        read_lines(tmp_path / "c.nc")
    xr.Dataset(
        {"radiance": (("line", "pixel"), r[0])}, coords={"pixel": [10.0, 11, 12, 13]}
    ).to_netcdf(tmp_path / "c.nc", engine="scipy")
    with pytest.raises(InputError, match="attribute 't0_s' missing"):
        read_lines(tmp_path / "c.nc")
    with pytest.raises(InputError, match="none.nc' not found"):
        read_lines(tmp_path / "none.nc")
    (tmp_path / "t.nc").write_text("text")
    with pytest.raises(InputError, match="t.nc' is not a NetCDF file"):
        read_lines(tmp_path / "t.nc")


def test_map_rasters_refuse_inputs_and_are_atomic(tmp_path):
    import rioxarray  # noqa: F401
    import xarray as xr

    from hsgeo.io import read_envi

    da = xr.DataArray(
        np.arange(6.0, dtype=np.float32).reshape(1, 2, 3),
        dims=("band", "y", "x"),
        coords={"band": ["b0"], "y": [10.0, 9.0], "x": [0.0, 1.0, 2.0]},
        name="radiance",
        attrs={"resolution_m": 1.0},
    ).rio.write_crs("EPSG:25832")
    src = tmp_path / "input.nc"
    src.write_text("the input")
    with pytest.raises(InputError, match="input of the command"):
        write_raster(da, src, inputs=[src])
    with pytest.raises(InputError, match="input of the command"):
        write_raster(da, tmp_path / "input.hdr", inputs=[tmp_path / "input"])
    assert src.read_text() == "the input" and not (tmp_path / "input.hdr").exists()
    out = write_raster(da, tmp_path / "o.nc", inputs=[src])
    np.testing.assert_array_equal(xr.open_dataset(out[0])["radiance"].values, da.values)
    assert write_raster(da, tmp_path / "o_envi.hdr") == [
        tmp_path / "o_envi",
        tmp_path / "o_envi.hdr",
    ]
    data, hdr = read_envi(tmp_path / "o_envi")
    np.testing.assert_array_equal(data, da.values)
    assert hdr["map_info"] == (-0.5, 10.5, 1.0, 1.0)
    assert sorted(os.listdir(tmp_path)) == ["input.nc", "o.nc", "o_envi", "o_envi.hdr"]


def test_atomic_path_gives_a_new_file_s_mode(tmp_path):
    import os

    umask = os.umask(0o022)
    try:
        with atomic_path(tmp_path / "x.txt") as tmp:
            tmp.write_text("x")
        assert (tmp_path / "x.txt").stat().st_mode & 0o777 == 0o644
    finally:
        os.umask(umask)


def test_atomic_path_keeps_the_old_file_on_failure(tmp_path):
    p = tmp_path / "x.txt"
    p.write_text("old")
    with pytest.raises(RuntimeError), atomic_path(p) as tmp:
        tmp.write_text("half")
        raise RuntimeError("disk full")
    assert p.read_text() == "old" and os.listdir(tmp_path) == ["x.txt"]
    with atomic_path(p) as tmp:
        tmp.write_text("new")
    assert p.read_text() == "new" and os.listdir(tmp_path) == ["x.txt"]
    with (
        pytest.raises(InputError, match="does not exist; create it"),
        atomic_path(tmp_path / "no" / "x.txt"),
    ):
        pass


def test_read_dem(tmp_path):
    import xarray as xr

    h = xr.DataArray(np.ones((2, 3)), dims=("N", "E"), coords={"N": [1.0, 0], "E": [0.0, 1, 2]})
    h.to_dataset(name="height").to_netcdf(tmp_path / "d.nc", engine="scipy")
    np.testing.assert_array_equal(read_dem(tmp_path / "d.nc").values, h.values)
    h.to_dataset(name="z").to_netcdf(tmp_path / "z.nc", engine="scipy")
    with pytest.raises(InputError, match="no variable 'height'"):
        read_dem(tmp_path / "z.nc")


def test_load_scenario_errors(tmp_path, monkeypatch):
    with pytest.raises(InputError, match="no scenario"):
        load_scenario("nope")
    d = tmp_path / "data_synthetic"
    d.mkdir()
    (d / "broken.toml").write_text("[scenario\n")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="malformed TOML"):
        load_scenario("broken")


def test_the_rikola_band_split_is_the_papers():
    """The instrument file (hsgeo/data/instruments/rikola_fpi2015.toml) against 003 Table 2."""
    from hsgeo.io import read_band_split
    from hsgeo.papers import RIKOLA_BANDS

    b = read_band_split()
    for k in ("band", "sensor", "gap_nm"):
        np.testing.assert_array_equal(b[k], RIKOLA_BANDS[k])
        assert b[k].dtype == RIKOLA_BANDS[k].dtype


def test_the_imspector_frame_layout_is_the_papers():
    """The instrument file (hsgeo/data/instruments/imspector_v9_pixelfly.toml) against 001
    Table 1 and §2.1 as hsgeo.papers has them."""
    from hsgeo.io import read_frame_layouts
    from hsgeo.papers import P001_CUBE, P001_SENSOR

    d = read_frame_layouts()
    assert d["bits"] == P001_SENSOR["bits"]
    assert sorted(d["layouts"]) == sorted(P001_CUBE["frame_rate_hz"]) == [1, 2]
    for b, lay in d["layouts"].items():
        assert lay["n_rows"] == P001_SENSOR["n_rows"] // b
        assert lay["n_columns"] == P001_SENSOR["n_columns"] // b
        assert lay["n_reflected"] == P001_CUBE["n_reflected_columns"][b]
        assert lay["n_incident"] == P001_CUBE["n_incident_columns"][b]
        assert lay["frame_rate_hz"] == P001_CUBE["frame_rate_hz"][b]
    lay1 = d["layouts"][1]
    assert (lay1["n_reflected"], lay1["n_incident"]) == (
        P001_SENSOR["n_reflected_columns"],
        P001_SENSOR["n_incident_columns"],
    )


def test_a_bad_frame_layout_names_the_problem(tmp_path):
    from hsgeo.io import read_frame_layouts

    f = tmp_path / "i.toml"
    f.write_text(
        "[instrument]\nname = 'x'\nbits = 12\n[frame]\nbinning = [1]\nn_rows = [1024]\n"
        "n_columns = [1280]\nn_reflected_columns = [1170]\nn_incident_columns = [100]\n"
        "frame_rate_hz = [12.5]\n"
    )
    with pytest.raises(InputError, match="n_reflected_columns \\+ n_incident_columns must be"):
        read_frame_layouts(f)
    f.write_text(f.read_text().replace("n_rows", "n_row"))
    with pytest.raises(InputError, match="unknown key; did you mean 'n_rows'"):
        read_frame_layouts(f)


def test_a_bad_band_split_names_the_problem(tmp_path):
    from hsgeo.io import read_band_split

    f = tmp_path / "i.toml"
    f.write_text(
        "[instrument]\nname = 'x'\nn_sensors = 2\n[bands]\nband = [1, 2]\nsensor = [1, 3]\n"
        "gap_nm = [500.0, 600.0]\n"
    )
    with pytest.raises(InputError, match="sensor must be integers 1…2"):
        read_band_split(f)


def test_write_table_round_trip_and_refuses_an_input(tmp_path):
    """io.write_table: Parquet and CSV by suffix, the same numbers read back (CSV at 17
    digits), never over an input of the command."""
    import pandas as pd

    from hsgeo.errors import InputError
    from hsgeo.io.tables import write_table

    df = pd.DataFrame({"point_id": ["a", "b"], "band": [0, 3], "x_px": [0.1 + 0.2, -1 / 3]})
    for name in ("t.parquet", "t.csv"):
        write_table(tmp_path / name, df)
        back = (pd.read_parquet if name.endswith("parquet") else pd.read_csv)(tmp_path / name)
        assert back["x_px"].tolist() == df["x_px"].tolist()
        assert back["point_id"].tolist() == ["a", "b"]
    (tmp_path / "in.csv").write_text("keep\n")
    with pytest.raises(InputError, match="input"):
        write_table(tmp_path / "in.csv", df, inputs=[tmp_path / "in.csv"])
    assert (tmp_path / "in.csv").read_text() == "keep\n"


def test_read_adjustment(tmp_path):
    """hsgeo.io.sensors.read_adjustment: what adjust-pushbroom --json prints, round trip."""
    import json

    from ortho_inputs import adjustment_json, flight_trajectory, node_corrections

    from hsgeo.io.sensors import read_adjustment

    nav, _ = flight_trajectory()
    nodes, v = node_corrections(nav)
    p = tmp_path / "r.json"
    p.write_text(adjustment_json(nodes, v))
    a = read_adjustment(p)
    np.testing.assert_array_equal(a["nodes"], v)
    np.testing.assert_array_equal(a["t_nodes_s"], nodes.t_nodes_s)
    assert a["boresight_rad"].shape == (3,) and a["c_mm"].tolist() == [40.0]
    d = json.loads(p.read_text())
    del d["nodes"]["value"]
    p.write_text(json.dumps(d))
    with pytest.raises(InputError, match="adjust-pushbroom --json"):
        read_adjustment(p)


def test_read_dsm(tmp_path):
    from affine import Affine

    from hsgeo.io.geotiff import read_dsm, write_geotiff

    z = np.arange(12, dtype=float).reshape(3, 4)
    write_geotiff(tmp_path / "d.tif", z, Affine(2.0, 0, 600000.0, 0, -2.0, 6615000.0), 25832)
    h, g = read_dsm(tmp_path / "d.tif")
    np.testing.assert_array_equal(h, z)
    assert (g.x_min_m, g.y_max_m, g.resolution_m, g.width, g.height, g.crs) == (
        600000.0,
        6615000.0,
        2.0,
        4,
        3,
        "EPSG:25832",
    )
    (tmp_path / "x.tif").write_text("not a raster")
    with pytest.raises(InputError, match="not a raster"):
        read_dsm(tmp_path / "x.tif")
    with pytest.raises(InputError, match="not found"):
        read_dsm(tmp_path / "missing.tif")


def test_the_package_loads_its_modules_on_first_use():
    """``hsgeo.io`` loads a reader's module when a name of it is first used (PEP 562), and
    answers as a package that imported them: names, modules, ``dir``, an unknown name."""
    import importlib
    import subprocess
    import sys

    code = (
        "import sys, hsgeo.io as io\n"
        "print('hsgeo.io.terrain' in sys.modules)\n"
        "io.read_terrain\n"
        "print('hsgeo.io.terrain' in sys.modules)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert p.stdout.split() == ["False", "True"]
    io = importlib.import_module("hsgeo.io")
    assert io.tables is importlib.import_module("hsgeo.io.tables")  # a module by attribute
    assert io.read_table is io.tables.read_table
    assert set(io.__all__) <= set(dir(io))
    with pytest.raises(AttributeError, match="no attribute 'read_tabel'"):
        io.read_tabel  # noqa: B018
