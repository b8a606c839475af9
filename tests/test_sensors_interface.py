"""The one sensor interface (hsgeo.sensors.mount): rays ↔ project round trips for every sensor,
and each sensor against an independent computation."""

import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.distortion import distort_pushbroom_line
from hsgeo.rotations import R_from_opk, R_from_rpy
from hsgeo.sensors.line import CalibratedLine, LinearIFOV, LineScanner, ray_directions
from hsgeo.sensors.mount import Mount, Sensor
from hsgeo.sensors.pushbroom import (
    BETA0_CAM_FROM_PLATFORM,
    BLOCK_NAMES,
    PushbroomCamera,
    project,
)
from hsgeo.trajectory import SplineNodes, Trajectory, platform_rpy_from_rph

CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1
MOUNT = Mount.from_rpy(np.deg2rad([0.4, -0.3, 0.8]), lever_arm_m=(0.3, -0.2, 0.5))
# 002-like LP camera (002 §4: 6.5 µm pixels, c ≈ 40 mm), distortion as in the simulator
CAM = PushbroomCamera(
    c_mm=(40.02, 39.98, 40.05),
    pixel_mm=0.0065,
    distortion=(-4.0e-5, 3.0e-7, 2.5e-5, -3.0e-5),
    x0_mm=0.01,
    y0_mm=-0.005,
    boresight_rad=tuple(np.deg2rad([0.2, -0.3, 0.5])),
    lever_arm_m=(0.12, -0.05, -0.30),
)


def wavy_nav(H=1500.0, T=30.0, v=60.0):
    """A flight north-east with rolling, pitching and yawing attitude (GNSS/INS angles)."""
    t = np.linspace(0.0, T, 3001)
    h = np.deg2rad(40.0)
    xyz = np.column_stack([v * t * np.sin(h), v * t * np.cos(h), H + 2 * np.sin(0.3 * t)])
    rph = np.column_stack(
        [0.03 * np.sin(0.7 * t), 0.02 * np.cos(0.5 * t), h + 0.01 * np.sin(0.2 * t)]
    )
    return Trajectory(t, xyz, rph)


#: The one face (hsgeo.sensors.mount): the leading arguments of ``project`` and the arguments
#: after the pixels of ``rays``, by the kind of a registered model.
FACE = {
    "scanning": (("xyz_map_m", "t_s", "trajectory"), ("t_s", "trajectory")),
    "frame": (("xyz_world", "poses", "view"), ("poses", "view")),
}


def face_problems(sensor, kind: str) -> list[str]:
    """What ``sensor`` lacks of the face of its ``kind`` (empty: it has the face)."""
    import inspect

    problems = []
    if not isinstance(sensor, Sensor):
        return [f"{type(sensor).__name__}: no rays() and project()"]
    project_args, ray_args = FACE[kind]
    got = list(inspect.signature(sensor.project).parameters)
    if tuple(got[: len(project_args)]) != project_args:
        problems.append(f"project{tuple(got)}: expected the arguments {project_args} first")
    got = list(inspect.signature(sensor.rays).parameters)
    if tuple(got[1 : 1 + len(ray_args)]) != ray_args:
        problems.append(f"rays{tuple(got)}: expected (pixels, {', '.join(ray_args)}, ...)")
    if not isinstance(getattr(sensor, "mount", None), Mount):
        problems.append("no .mount (lever arm and boresight, hsgeo.sensors.mount.Mount)")
    if kind == "scanning" and not callable(getattr(sensor, "line_time", None)):
        problems.append("a scanning sensor without line_time()")
    return problems


def registered_sensor(name, tmp_path):
    from hsgeo.io import read_sensor
    from hsgeo.io.sensor_file import MODELS, sensor_toml

    p = tmp_path / f"{name}.toml"
    p.write_text(sensor_toml(name, MODELS[name].example))
    return read_sensor(p)


def _model_names():
    from hsgeo.io.sensor_file import MODELS

    return sorted(MODELS)


@pytest.mark.parametrize("name", _model_names())
def test_every_registered_sensor_offers_the_one_face(name, tmp_path):
    """Every model of the registry, read from its example file, has rays/project with the face's
    arguments, a Mount, and (if it scans) line_time; a new model that breaks the face fails."""
    from hsgeo.io.sensor_file import MODELS

    sensor = registered_sensor(name, tmp_path)
    assert not face_problems(sensor, MODELS[name].kind), face_problems(sensor, MODELS[name].kind)


def test_the_face_check_fails_on_sensors_that_break_the_face():
    """The check can fail: each of these breaks the face in one way and is caught."""

    class NoRays:
        mount = Mount()

        def project(self, xyz_map_m, t_s, trajectory):
            return xyz_map_m

    class SwappedProject(NoRays):
        def project(self, t_s, xyz_map_m, trajectory):
            return xyz_map_m

        def rays(self, zeta_px, t_s, trajectory):
            return zeta_px, zeta_px

    class NoMount(SwappedProject):
        mount = None

        def project(self, xyz_map_m, t_s, trajectory):
            return xyz_map_m

    class NoLineTime(NoMount):
        mount = Mount()

    assert face_problems(NoRays(), "scanning") == ["NoRays: no rays() and project()"]
    assert face_problems(SwappedProject(), "scanning")[0].startswith("project(")
    assert face_problems(NoMount(), "scanning")[0].startswith("no .mount")
    assert face_problems(NoLineTime(), "scanning") == ["a scanning sensor without line_time()"]
    assert face_problems(NoLineTime(), "frame")[0].startswith("project(")
    assert face_problems(LineScanner(CAL), "frame")  # a scanner's arguments are not a frame's
    assert face_problems(CAM, "scanning") == []


@pytest.mark.parametrize("geom", [CAL, LinearIFOV(485.0, 3600.0)])
@pytest.mark.parametrize("mount", [Mount(), MOUNT])
def test_line_scanner_round_trip(geom, mount):
    rng = np.random.default_rng(1)
    sensor = LineScanner(geom, mount)
    nav = wavy_nav()
    n = 200
    zeta = rng.uniform(50, 920, n)  # the calibrated domain |ζ − ζ0| ≤ 450 px
    t = rng.uniform(1, 29, n)
    o, d = sensor.rays(zeta, t, nav)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-15)
    X = o + rng.uniform(500, 2000, n)[:, None] * d
    px = sensor.project(X, t, nav)
    np.testing.assert_allclose(px[:, 0], zeta, rtol=0, atol=1e-9)
    np.testing.assert_allclose(px[:, 1], 0.0, rtol=0, atol=1e-9)
    # and the time at which each point is on the line, from a start 0.5 s off
    np.testing.assert_allclose(sensor.line_time(X, nav, t + 0.5), t, rtol=0, atol=1e-8)


def test_line_scanner_rays_against_the_ray_equation_and_a_level_flight():
    """Independent: (a) ray_directions' rotation chain (no lever arm); (b) by hand, a level
    flight due north at 1000 m sees the pixel at view angle θ (to the right = east) at
    E = 1000 tan θ (LinearIFOV: θ = −(ζ − ζ0)/c)."""
    nav = wavy_nav()
    t = np.linspace(2, 28, 50)
    zeta = np.linspace(50, 920, 50)
    bs = np.deg2rad([0.4, -0.3, 0.8])
    o, d = LineScanner(CAL, Mount.from_rpy(bs)).rays(zeta, t, nav)
    ref = ray_directions(nav.pose(t)[1], CAL.tan_angle(zeta), R_from_rpy(*bs))
    np.testing.assert_allclose(d, ref / np.linalg.norm(ref, axis=1, keepdims=True), atol=1e-15)
    np.testing.assert_array_equal(o, nav.pose(t)[0])

    level = Trajectory([0.0, 10.0], [[0, 0, 1000.0], [0, 500, 1000.0]], np.zeros((2, 3)))
    geom = LinearIFOV(485.0, 3600.0)
    z = np.array([0.0, 200.0, 485.0, 900.0])
    o, d = LineScanner(geom).rays(z, np.full(4, 5.0), level)
    theta = -(z - 485.0) / 3600.0
    E = o[:, 0] + (0.0 - o[:, 2]) / d[:, 2] * d[:, 0]
    np.testing.assert_allclose(E, 1000.0 * np.tan(theta), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("distorted", [False, True])
def test_pushbroom_camera_round_trip(distorted):
    rng = np.random.default_rng(2)
    cam = CAM if distorted else PushbroomCamera(CAM.c_mm, CAM.pixel_mm)
    nav = wavy_nav()
    n = 300
    xy = np.column_stack([rng.uniform(-1000, 1000, n), rng.uniform(-3, 3, n)])
    band = rng.integers(0, 3, n)
    t = rng.uniform(1, 29, n)
    o, d = cam.rays(xy, t, nav, band=band)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-15)
    X = o + rng.uniform(800, 2500, n)[:, None] * d
    np.testing.assert_allclose(cam.project(X, t, nav, band=band), xy, rtol=0, atol=1e-9)


def test_pushbroom_camera_projects_as_the_adjustment_model():
    """Independent: the residual block's projection (002 eq. (2)–(4) through the compiled cores
    of hsgeo._kernels, platform angles) at zero trajectory corrections."""
    rng = np.random.default_rng(3)
    nav = wavy_nav()
    n = 100
    t = rng.uniform(1, 29, n)
    pos, rph = nav.pose(t)
    X = pos + np.column_stack([rng.uniform(-150, 150, (n, 2)), np.full(n, -1500.0)])
    band = rng.integers(0, 3, n)
    nodes = SplineNodes(0.0, 30.0, 10.0)
    values = {
        BLOCK_NAMES["points"]: X,
        BLOCK_NAMES["nodes"]: np.zeros((nodes.n_nodes, 6)),
        BLOCK_NAMES["boresight"]: np.asarray(CAM.boresight_rad),
        BLOCK_NAMES["lever_arm"]: np.asarray(CAM.lever_arm_m),
        BLOCK_NAMES["distortion"]: np.asarray(CAM.distortion),
        BLOCK_NAMES["c"]: np.asarray(CAM.c_mm),
    }
    xy_mm, _ = project(
        values,
        BLOCK_NAMES,
        nodes,
        t,
        pos,
        platform_rpy_from_rph(rph),
        np.arange(n),
        band,
        BETA0_CAM_FROM_PLATFORM,
        CAM.x0_mm,
        CAM.y0_mm,
    )
    np.testing.assert_allclose(CAM.project(X, t, nav, band=band), xy_mm / CAM.pixel_mm, atol=1e-9)


def test_pushbroom_rays_by_hand_at_nadir():
    """Level flight north, platform angles (0, 0, π/2): the line's centre pixel (ideal image
    origin) looks straight down; a pixel x mm along the line looks 'to the right' (east) by
    atan(x̄/c), x̄ the undistorted coordinate."""
    level = Trajectory([0.0, 10.0], [[0, 0, 1000.0], [0, 500, 1000.0]], np.zeros((2, 3)))
    cam = PushbroomCamera((40.0,), 0.0065, distortion=(-4.0e-5, 3.0e-7, 2.5e-5, 0.0))
    x_bar = np.array([-3.0, 0.0, 2.0])  # ideal mm
    x_d = distort_pushbroom_line(np.column_stack([x_bar, np.zeros(3)]), cam.distortion)
    o, d = cam.rays(x_d / cam.pixel_mm, np.full(3, 5.0), level)
    np.testing.assert_allclose(d[:, 0] / -d[:, 2], x_bar / 40.0, atol=1e-13)
    np.testing.assert_allclose(d[:, 1], 0.0, atol=1e-15)


def test_mount_maps_back_and_forth():
    rng = np.random.default_rng(4)
    R = np.stack([R_from_opk(*a) for a in rng.normal(0, 0.5, (20, 3))])
    pos = rng.normal(0, 100, (20, 3))
    d_s = rng.normal(size=(20, 3))
    X = MOUNT.origins(pos, R) + 7.0 * MOUNT.directions(R, d_s)
    np.testing.assert_allclose(MOUNT.to_sensor(X, pos, R), 7.0 * d_s, atol=1e-10)


def test_mount_rejects_a_non_rotation():
    with pytest.raises(InputError, match="rotation"):
        Mount(R_body_from_sensor=np.diag([1.0, 1.0, 2.0]))
    with pytest.raises(InputError, match="lever_arm_m"):
        Mount(lever_arm_m=(1.0, 2.0))


def test_geocoding_002_lines_with_the_true_trajectory_hits_the_reference_squares():
    """Geocoding for any sensor: the 002 simulated lines (noise-free observations) geocoded with
    the true trajectory (a Trajectory of the true poses at the line times) and the true camera
    put each of the 17 reference squares within 0.1 GSD of its position. Independent: the
    simulator projects with the adjustment model's compiled cores; the rays undistort 002
    eq. (3) by Newton and go through Trajectory's GNSS/INS angles."""
    from hsgeo.geocode import PlaneTerrain, geocode_rays
    from hsgeo.simulate.pushbroom_campaign import simulate
    from hsgeo.trajectory import rph_from_platform_rpy

    obs, truth = simulate(0.003, rng=4, noise_free=True, trajectory_error="spline")
    lines, v, nm = obs.lines, truth.values, BLOCK_NAMES
    delta = truth.nodes.evaluate(v[nm["nodes"]], lines.t_s)  # true = navigation + δ(t)
    t, first = np.unique(lines.t_s, return_index=True)
    nav = Trajectory(
        t,
        lines.xyz_nav_m[first] + delta[first, :3],
        rph_from_platform_rpy(lines.rpy_nav_rad[first] + delta[first, 3:]),
    )
    cfg = truth.cfg
    cam = PushbroomCamera(
        tuple(v[nm["c"]]),
        cfg.pixel_mm,
        tuple(v[nm["distortion"]]),
        cfg.x0_mm,
        cfg.y0_mm,
        tuple(v[nm["boresight"]]),
        tuple(v[nm["lever_arm"]]),
    )
    P = v[nm["points"]]
    n_seen = 0
    for k in range(17):
        rows = np.flatnonzero(lines.point == k)
        X = geocode_rays(
            cam,
            lines.xy_px[rows],
            lines.t_s[rows],
            nav,
            PlaneTerrain(float(P[k, 2])),
            band=lines.band[rows],
        )
        agl = lines.xyz_nav_m[rows, 2] - P[k, 2]
        gsd_m = cfg.pixel_mm / cam.c_mm[0] * agl
        err = np.linalg.norm(X[:, :2] - P[k, :2], axis=1)
        assert np.all(err < 0.1 * gsd_m), (k, err.max(), gsd_m.min())
        n_seen += rows.size
    assert n_seen >= 3 * 17


def _frame_poses(rng, n=5):
    return np.column_stack([rng.normal(0, 0.2, (n, 3)), rng.normal(0, 2.0, (n, 3))])


@pytest.mark.parametrize("mount", [Mount(), MOUNT])
def test_frame_camera_round_trip(mount):
    from hsgeo.sensors.frame import FrameCamera

    rng = np.random.default_rng(5)
    # OpenCV's calibration of its tutorial camera (hsgeo/data/reference/opencv-chessboard)
    cam = FrameCamera((657.3, 657.3, 319.5, 239.5), (-0.42, 0.50, 0.0, 0.0, -0.57), mount)
    poses = _frame_poses(rng)
    n = 200
    view = rng.integers(0, 5, n)
    uv = np.column_stack([rng.uniform(20, 620, n), rng.uniform(20, 460, n)])
    o, d = cam.rays(uv, poses, view)
    X = o + rng.uniform(2, 50, n)[:, None] * d
    np.testing.assert_allclose(cam.project(X, poses, view), uv, rtol=0, atol=1e-9)


def test_frame_camera_projects_as_the_adjustment_model():
    """Independent: project_opencv (the residual block's projection) and OpenCV's
    cv2.projectPoints (R_cam_from_world = R_from_opk(ω, φ, κ)ᵀ, t = −R X0)."""
    import cv2

    from hsgeo.sensors.frame import FrameCamera, project_opencv

    rng = np.random.default_rng(6)
    K = (657.3, 650.1, 319.5, 239.5)
    dist = (-0.2, 0.1, 1e-3, -2e-3, 0.0)
    cam = FrameCamera(K, dist)
    poses = _frame_poses(rng, 1)
    X = np.column_stack([rng.uniform(-1, 1, (30, 2)), rng.uniform(4, 8, 30)])
    X = (R_from_opk(*poses[0, :3]) @ X.T).T + poses[0, 3:]  # in front of the camera
    view = np.zeros(30, np.int64)
    uv = cam.project(X, poses, view)
    np.testing.assert_allclose(uv, project_opencv(poses, view, X, K, dist), atol=1e-9)
    R_cw = R_from_opk(*poses[0, :3]).T
    rvec, _ = cv2.Rodrigues(R_cw)
    Kmat = np.array([[K[0], 0, K[2]], [0, K[1], K[3]], [0, 0, 1.0]])
    ref, _ = cv2.projectPoints(X, rvec, -R_cw @ poses[0, 3:], Kmat, np.array(dist))
    np.testing.assert_allclose(uv, ref[:, 0, :], atol=1e-6)
