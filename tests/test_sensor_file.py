"""The one sensor file (hsgeo.io.read_sensor): the same file gives the same sensor in every
command's reading path (issue 36), the former formats are read or refused with the conversion,
keys a model cannot use and mounts in the wrong units are errors, and ``adjusted`` applies an
adjustment to any sensor."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from priors import priors_toml

from hsgeo import InputError
from hsgeo.io import read_pushbroom_camera, read_scanning_sensor, read_sensor
from hsgeo.io.sensor_file import MODELS, sensor_toml
from hsgeo.sensors import adjusted
from hsgeo.sensors.pushbroom import PushbroomCamera

#: The camera of issue 36: every command must see all three of c_band_mm, distortion and
#: boresight_deg.
ISSUE_36 = (
    "n_bands = 3\npixel_mm = 0.0065\nc_mm = 40.0\nc_band_mm = [40.0, 40.1, 40.2]\n"
    "distortion = [1e-4, 0, 0, 0]\nboresight_deg = [0.3, -0.2, 0.1]\nlever_arm_m = [0.1, 0, -0.2]\n"
)
EXPECTED = PushbroomCamera(
    (40.0, 40.1, 40.2),
    0.0065,
    (1e-4, 0.0, 0.0, 0.0),
    boresight_rad=tuple(np.deg2rad([0.3, -0.2, 0.1])),
    lever_arm_m=(0.1, 0.0, -0.2),
)


def same(a, b) -> bool:
    """Two sensors are the same: same class, every field equal (arrays element-wise)."""
    if type(a) is not type(b):
        return False
    if not dataclasses.is_dataclass(a):
        return a == b
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if dataclasses.is_dataclass(x):
            if not same(x, y):
                return False
        elif not np.array_equal(np.asarray(x, dtype=float), np.asarray(y, dtype=float)):
            return False
    return True


def _paths():
    """Every command's way from a camera file to the camera object."""
    from hsgeo.workflows.pushbroom_ba import read_camera

    return {
        "read_sensor": read_sensor,
        "geocode, lp-observations (read_pushbroom_camera)": read_pushbroom_camera,
        "geocode (read_scanning_sensor)": read_scanning_sensor,
        "adjust-pushbroom (read_camera)": lambda p: read_camera(p).camera(),
    }


@pytest.mark.parametrize("form", ["[camera]", "[sensor]"])
@pytest.mark.parametrize("path_name", list(_paths()))
def test_the_issue_36_camera_is_one_camera_in_every_command(tmp_path, form, path_name):
    p = tmp_path / "cam.toml"
    head = "[camera]\n" if form == "[camera]" else '[sensor]\nmodel = "pushbroom"\n'
    p.write_text(head + ISSUE_36 + priors_toml())
    got = _paths()[path_name](p)
    assert same(got, EXPECTED), got
    assert same(got, read_sensor(p))


def test_orthorectify_reads_the_same_camera(tmp_path):
    """``hsgeo orthorectify`` (which replaced ``orthomosaic``, whose camera_from_files dropped
    c_band_mm, distortion and boresight) reads its --sensor with read_sensor and applies
    --adjustment with adjusted: the module has no camera reader of its own."""
    import inspect

    from hsgeo.workflows import _ortho_strips, orthorectify

    src = inspect.getsource(orthorectify) + inspect.getsource(_ortho_strips)
    assert "read_sensor(sensor)" in src and "adjusted(" in src
    assert "read_camera" not in src and "read_scanning_sensor" not in src


def test_adjust_pushbroom_starts_from_the_files_camera(tmp_path):
    """The adjustment's initial boresight, distortion and per-band c are the file's (they
    started from zero and c_mm for every band before)."""
    from hsgeo.simulate.pushbroom_campaign import simulate
    from hsgeo.workflows.pushbroom_ba import build_problem, read_camera

    obs, _ = simulate(0.001, rng=3)
    p = tmp_path / "cam.toml"
    text = ISSUE_36.replace("n_bands = 3", "n_bands = 7").replace(
        "[40.0, 40.1, 40.2]", "[40.0, 40.1, 40.2, 40.3, 40.4, 40.5, 40.6]"
    )
    p.write_text('[sensor]\nmodel = "pushbroom"\n' + text + priors_toml())
    cam = read_camera(p)
    params, _, _ = build_problem(obs.lines, obs.n_points, cam, t_span_s=obs.t_span_s)
    np.testing.assert_array_equal(params.value("boresight_rad"), np.deg2rad([0.3, -0.2, 0.1]))
    np.testing.assert_array_equal(params.value("distortion"), [1e-4, 0, 0, 0])
    np.testing.assert_array_equal(params.value("c_mm"), [40.0, 40.1, 40.2, 40.3, 40.4, 40.5, 40.6])
    np.testing.assert_array_equal(params.value("lever_arm_m"), [0.1, 0.0, -0.2])


def test_the_former_000_sensor_file_is_read(tmp_path):
    from hsgeo.io import read_sensor_toml
    from hsgeo.sensors.line import LineScanner
    from hsgeo.sensors.mount import Mount

    p = tmp_path / "s.toml"
    p.write_text(
        "[sensor]\nmodel = 'calibrated'\nzeta0_px = 486.8\nc_px = 3539\n"
        "K = [1.459, -0.1636, 0.00526]\nboresight_deg = [1.0, -2.0, 90]\n"
    )
    geom, b = read_sensor_toml(p)
    assert same(read_sensor(p), LineScanner(geom, Mount.from_rpy(b)))
    assert same(read_scanning_sensor(p), read_sensor(p))


@pytest.mark.parametrize(
    "text, needles",
    [
        (
            "[sensor]\nzeta0_px = 1\nc_px = 2\n",
            ["[sensor] model: missing", 'add model = "line-scanner"'],
        ),
        (
            '[sensor]\nmodel = "pushbrom"\n',
            ["unknown model 'pushbrom'", "did you mean 'pushbroom'?"],
        ),
        (
            '[sensor]\nmodel = "line-scanner"\nzeta0_px = 486.8\nc_px = 3539\nc_band_mm = [40.0]\n',
            ["[sensor] c_band_mm", "model 'line-scanner' cannot use this key", "'pushbroom'"],
        ),
        (
            '[sensor]\nmodel = "linear-ifov"\nzeta0_px = 485\nc_px = 3600\nK = [1, 0, 0]\n',
            ["[sensor] K", "model 'line-scanner-linear-ifov' cannot use this key"],
        ),
        (
            '[sensor]\nmodel = "panoramic"\nifov_dg = 0.12\n',
            ["[sensor] ifov_dg", "did you mean 'ifov_deg'?", "model 'panoramic'"],
        ),
        (
            '[sensor]\nmodel = "panoramic"\n[gnss_ins]\nsigma_pos_m = [1, 1, 1]\n',
            ["[gnss_ins]", "model 'panoramic' cannot use"],
        ),
        (
            '[sensor]\nmodel = "panoramic"\nlever_arm_m = [300.0, 0, -150.0]\n',
            ["[sensor] lever_arm_m[0]", "not mm"],
        ),
        (
            '[sensor]\nmodel = "pushbroom"\nn_bands = 1\npixel_mm = 0.0065\nc_mm = 40\n'
            "boresight_deg = [0.005235987755982988, -0.003490658503988659, 0.0]\n",
            ["boresight_deg", "are radians", "boresight_deg = [0.3, -0.2, 0]"],
        ),
        (
            '[sensor]\nmodel = "pushbroom"\nn_bands = 2\npixel_mm = 0.0065\nc_mm = 40\n'
            "c_band_mm = [40.0]\n",
            ["c_band_mm has 1 values for n_bands = 2"],
        ),
    ],
)
def test_sensor_file_errors(tmp_path, text, needles):
    p = tmp_path / "s.toml"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_sensor(p)
    msg = str(e.value)
    assert "s.toml" in msg
    for n in needles:
        assert n in msg, (n, msg)


def test_a_boresight_in_degrees_is_not_taken_for_radians(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(
        '[sensor]\nmodel = "line-scanner"\nzeta0_px = 486.8\nc_px = 3539\n'
        "boresight_deg = [0.3, -0.2, 0.1]\n"
    )
    np.testing.assert_allclose(
        read_sensor(p).mount.R_body_from_sensor,
        __import__("hsgeo.rotations", fromlist=["R_from_rpy"]).R_from_rpy(
            *np.deg2rad([0.3, -0.2, 0.1])
        ),
    )


@pytest.mark.parametrize("name", ["rikola_fpi2015.toml", "imspector_v9_pixelfly.toml"])
def test_instrument_files_are_refused_with_the_conversion(name):
    from pathlib import Path

    import hsgeo

    p = Path(hsgeo.__file__).parent / "data" / "instruments" / name
    with pytest.raises(InputError) as e:
        read_sensor(p)
    msg = str(e.value)
    assert "instrument file" in msg and "[sensor] model =" in msg
    assert ('"rikola"' in msg) == name.startswith("rikola")


def test_a_command_refuses_a_sensor_it_cannot_use(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(sensor_toml("frame-opencv", MODELS["frame-opencv"].example))
    with pytest.raises(InputError, match="model 'frame-opencv' is not a scanning sensor"):
        read_scanning_sensor(p)
    with pytest.raises(InputError, match="'frame-opencv' is not the 002 pushbroom camera"):
        read_pushbroom_camera(p)


# ---- adjusted ------------------------------------------------------------------------------
def _nav():
    from hsgeo.trajectory import Trajectory

    t = np.linspace(0, 40, 401)
    xyz = np.column_stack([np.zeros_like(t), 60 * t, np.full_like(t, 1500.0)])
    return Trajectory(t, xyz, np.zeros((t.size, 3)))


def _adjustment():
    from hsgeo.trajectory import CORRECTION_COLUMNS

    t = np.arange(-10.0, 60.0, 10.0)
    nodes = np.zeros((t.size, 6))
    nodes[:, 0] = 1.5  # 1.5 m east everywhere
    nodes[:, 3] = 1e-3
    return {
        "boresight_rad": np.array([1e-3, -2e-3, 3e-3]),
        "lever_arm_m": np.array([0.1, 0.2, 0.3]),
        "distortion": np.array([1e-5, 0, 0, 0]),
        "c_mm": np.array([40.05]),
        "t_nodes_s": t,
        "nodes": nodes,
        "node_columns": CORRECTION_COLUMNS,
    }


def test_adjusted_pushbroom_camera_and_trajectory():
    nav = _nav()
    cam, traj = adjusted(EXPECTED, nav, _adjustment())
    assert cam.c_mm == (40.05,) * 3 and cam.distortion == (1e-5, 0.0, 0.0, 0.0)
    assert cam.boresight_rad == (1e-3, -2e-3, 3e-3) and cam.lever_arm_m == (0.1, 0.2, 0.3)
    np.testing.assert_allclose(traj.xyz_m[:, 0], nav.xyz_m[:, 0] + 1.5, atol=1e-12)
    assert not np.allclose(traj.roll_pitch_heading_rad, nav.roll_pitch_heading_rad)
    assert adjusted(EXPECTED, nav, None) == (EXPECTED, nav)


def test_adjusted_line_scanner_mount_and_refusals(tmp_path):
    from hsgeo.rotations import R_from_rpy

    p = tmp_path / "s.toml"
    p.write_text(sensor_toml("line-scanner", MODELS["line-scanner"].example))
    s = read_sensor(p)
    nav = _nav()
    b = np.array([0.01, -0.02, 0.03])
    s2, nav2 = adjusted(s, nav, {"boresight_rad": b, "sensor_model": "line-scanner"})
    np.testing.assert_array_equal(s2.mount.R_body_from_sensor, R_from_rpy(*b))
    assert nav2 is nav and s2.geometry == s.geometry
    with pytest.raises(InputError, match="it adjusts a 'pushbroom' sensor"):
        adjusted(s, nav, {**_adjustment(), "sensor_model": "pushbroom"})
    with pytest.raises(InputError, match="c_mm, distortion are parameters of the 002"):
        adjusted(s, nav, _adjustment())
    with pytest.raises(InputError, match="did you mean 'boresight_rad'"):
        adjusted(s, nav, {"boresight_deg": b})
    # the trajectory corrections alone apply to any sensor on the trajectory
    adj = {k: v for k, v in _adjustment().items() if k not in ("c_mm", "distortion")}
    s3, nav3 = adjusted(s, nav, adj)
    np.testing.assert_allclose(nav3.xyz_m[:, 0], 1.5, atol=1e-12)
    np.testing.assert_array_equal(s3.mount.lever_arm_m, [0.1, 0.2, 0.3])
