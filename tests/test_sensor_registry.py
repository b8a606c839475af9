"""The sensor registry (hsgeo.io.sensor_file.MODELS): every model, read from its sensor file,
passes one template — rays ↔ project round trip both ways, a finite-difference Jacobian of
``project`` (the ray is its null direction; equal to the model's analytic Jacobian where it
has one) and, where the model has a residual block, block residual = face projection −
observation. The template is shown to fail on deliberately broken models (the last tests), so
it is not a tautology: the face and the block are computed by different code.
"""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo.io import read_sensor
from hsgeo.io.sensor_file import MODELS, sensor_toml
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.trajectory import Trajectory

#: Mount used for every model in the template (so the lever arm and boresight are exercised);
#: frame sensors get it scaled to a bench.
MOUNT_KEYS = {"lever_arm_m": [0.3, -0.2, 0.5], "boresight_deg": [0.4, -0.3, 0.8]}


def wavy_nav(H=1500.0, T=30.0, v=60.0):
    """A flight north-east with rolling, pitching and yawing attitude (GNSS/INS angles)."""
    t = np.linspace(0.0, T, 3001)
    h = np.deg2rad(40.0)
    xyz = np.column_stack([v * t * np.sin(h), v * t * np.cos(h), H + 2 * np.sin(0.3 * t)])
    rph = np.column_stack(
        [0.03 * np.sin(0.7 * t), 0.02 * np.cos(0.5 * t), h + 0.01 * np.sin(0.2 * t)]
    )
    return Trajectory(t, xyz, rph)


def sensor_of(name, tmp_path, **extra):
    """The model's example sensor file (with the template's mount), read by read_sensor."""
    values = {**MODELS[name].example, **extra}
    if "lever_arm_m" in MODELS[name].keys:
        values = {**MOUNT_KEYS, **values}
    p = tmp_path / f"{name}.toml"
    p.write_text(sensor_toml(name, values))
    return read_sensor(p)


class Case:
    """How the template calls one model: pixels, their rays, the projection of points."""

    def __init__(self, name, sensor, rng):
        self.name, self.sensor, self.kind = name, sensor, MODELS[name].kind
        n = self.n = 60
        self.band = None
        if self.kind == "scanning":
            self.nav = wavy_nav()
            self.t = rng.uniform(2, 28, n)
            self.args = (self.t, self.nav)
            self.range_m = (500.0, 2000.0)
            if name == "pushbroom":
                self.band = rng.integers(0, len(sensor.c_mm), n)
                self.px = np.column_stack([rng.uniform(-900, 900, n), rng.uniform(-3, 3, n)])
            elif name == "panoramic":
                self.px = rng.uniform(0, sensor.n_px - 1, n)
            else:
                self.px = rng.uniform(50, 920, n)
        else:
            self.poses = np.column_stack(
                [rng.normal(0, 0.05, (3, 3)), rng.normal(0, 1.0, (3, 3)) + [0, 0, 0]]
            )
            self.view = rng.integers(0, 3, n)
            self.args = (self.poses, self.view)
            self.range_m = (3.0, 20.0)
            if name == "rikola":
                nums = sensor.bands or tuple(range(1, len(sensor.f_mm) + 1))
                self.band = np.asarray(nums)[rng.integers(0, len(nums), n)]
                w, h = sensor.image_size
            else:
                w, h = 1280, 960
            self.px = np.column_stack([rng.uniform(0, w - 1, n), rng.uniform(0, h - 1, n)])

    def kw(self):
        return {} if self.band is None else {"band": self.band}

    def rays(self, px=None):
        return self.sensor.rays(self.px if px is None else px, *self.args, **self.kw())

    def project(self, X, idx=None):
        args = self.args if idx is None else tuple(a[idx] for a in self.args[:1]) + self.args[1:]
        kw = self.kw() if idx is None or self.band is None else {"band": self.band[idx]}
        if self.kind == "frame" and idx is not None:
            args = (self.poses, self.view[idx])
        return self.sensor.project(X, *args, **kw)

    def expected_pixels(self):
        """What project gives back for a point on a pixel's ray: the pixel (and 0 across the
        line for the 1-D scanners)."""
        if self.px.ndim == 1:
            return np.column_stack([self.px, np.zeros(self.n)])
        return self.px


@pytest.fixture(params=list(MODELS))
def case(request, tmp_path):
    name = request.param
    return Case(name, sensor_of(name, tmp_path), np.random.default_rng(7))


def test_every_model_is_read_from_its_file(case):
    assert isinstance(case.sensor, MODELS[case.name].cls)
    assert hasattr(case.sensor, "rays") and hasattr(case.sensor, "project")
    if case.kind == "scanning":  # every scanning sensor has line_time
        assert callable(getattr(case.sensor, "line_time", None))


def test_every_scanning_sensor_has_one_line_time():
    """One signature for every scanning sensor's ``line_time`` (so a caller need not know the
    model), and each finds the time at which a point on a pixel's ray was on the line.
    """
    import inspect

    sigs = {
        m.cls.__name__: inspect.signature(m.cls.line_time)
        for m in MODELS.values()
        if hasattr(m.cls, "line_time")
    }
    scanning = {m.cls.__name__ for m in MODELS.values() if m.kind == "scanning"}
    assert set(sigs) == scanning, (sigs, scanning)
    assert len(scanning) == 4  # line scanner, pushbroom, panoramic, view angle
    shapes = {
        name: [(q.name, q.kind, q.default) for q in s.parameters.values()]
        for name, s in sigs.items()
    }
    first = next(iter(shapes.values()))
    for name, shape in shapes.items():
        assert shape == first, (name, shape, first)


def test_line_time_finds_the_time_of_a_point_on_a_pixel_ray(case):
    if case.kind != "scanning":
        pytest.skip("a frame sensor has no line time")
    px = case.px.copy()
    if px.ndim == 2:  # the pushbroom camera: pixels on the line (image y = 0)
        px[:, 1] = 0.0
    o, d = case.rays(px)
    X = o + np.random.default_rng(2).uniform(*case.range_m, case.n)[:, None] * d
    t = case.sensor.line_time(X, case.nav, case.t + 0.2, band=case.band)
    np.testing.assert_allclose(t, case.t, rtol=0, atol=1e-8)


def check_round_trip(case, tol_px=1e-8):
    rng = np.random.default_rng(1)
    o, d = case.rays()
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-14)
    X = o + rng.uniform(*case.range_m, case.n)[:, None] * d
    np.testing.assert_allclose(case.project(X), case.expected_pixels(), rtol=0, atol=tol_px)
    # and back: the ray of the projected pixel passes through the point
    px = case.project(X)
    o2, d2 = case.rays(px if case.px.ndim == 2 else px[:, 0])
    v = X - o2
    along = np.einsum("ni,ni->n", v, d2)
    miss = np.linalg.norm(v - along[:, None] * d2, axis=1)
    assert np.all(along > 0)
    np.testing.assert_array_less(miss, 1e-9 * along)


def test_rays_project_round_trip(case):
    check_round_trip(case)


def fd_jacobian(case, X, h_m):
    """∂project/∂X by central differences, (n, 2, 3)."""
    J = np.empty((case.n, 2, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h_m
        J[:, :, k] = (case.project(X + e) - case.project(X - e)) / (2 * h_m)
    return J


def analytic_point_jacobian(case, X):
    """The model's own ∂project/∂X where it has one (panoramic: project_jacobian; pushbroom:
    the residual block's point derivatives; frame: FrameOpenCV's), else None."""
    s = case.sensor
    if case.name == "panoramic":
        return s.project_jacobian(X, *case.args)
    if case.name == "pushbroom":
        blk, values = pushbroom_block(case, X, np.zeros((case.n, 2)))
        _, jac = blk.evaluate_numpy(values, True)
        return jac["points_m"].d.reshape(case.n, 2, 3)
    if case.name == "frame-opencv":
        blk, values = frame_block(case, X, np.zeros((case.n, 2)))
        _, jac = blk.evaluate(values, True)
        return jac["points"].d.reshape(case.n, 2, 3)
    return None


def check_jacobian(case):
    rng = np.random.default_rng(2)
    o, d = case.rays()
    X = o + rng.uniform(*case.range_m, case.n)[:, None] * d
    J = fd_jacobian(case, X, 1e-4 * case.range_m[0])
    scale = np.linalg.norm(J, axis=(1, 2))
    assert np.all(scale > 0)
    # the ray is the null direction of the projection (a point moved along it keeps its pixel)
    null = np.linalg.norm(np.einsum("nij,nj->ni", J, d), axis=1)
    np.testing.assert_array_less(null, 1e-6 * scale)
    # two independent directions: the pixel moves with the point across the ray
    sv = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_array_less(1e-3 * sv[:, 0], sv[:, 1])
    A = analytic_point_jacobian(case, X)
    if A is not None:
        np.testing.assert_allclose(A, J, rtol=1e-5, atol=1e-7 * scale.max())


def test_project_jacobian_by_finite_differences(case):
    check_jacobian(case)


# ---- residual blocks: block residual = face projection − observation -------------------------
def pushbroom_block(case, X, xy_obs):
    from hsgeo.sensors.pushbroom import BLOCK_NAMES, PushbroomLines
    from hsgeo.trajectory import SplineNodes, platform_rpy_from_rph

    cam, nav, t = case.sensor, case.nav, case.t
    pos, rph = nav.pose(t)
    nodes = SplineNodes(0.0, 30.0, 10.0)
    blk = PushbroomLines(
        np.arange(case.n),
        case.band,
        t,
        xy_obs,
        pos,
        platform_rpy_from_rph(rph),
        nodes,
        cam.pixel_mm,
        0.5,
        cam.x0_mm,
        cam.y0_mm,
    )
    nm = BLOCK_NAMES
    values = {
        nm["points"]: X,
        nm["nodes"]: np.zeros((nodes.n_nodes, 6)),
        nm["boresight"]: np.asarray(cam.boresight_rad),
        nm["lever_arm"]: np.asarray(cam.lever_arm_m),
        nm["distortion"]: np.asarray(cam.distortion),
        nm["c"]: np.asarray(cam.c_mm),
    }
    return blk, values


def camera_poses(sensor, poses):
    """Poses of the camera itself (body pose ∘ mount), rows (ω, φ, κ, X0, Y0, Z0)."""
    R_wb = R_from_opk(poses[:, 0], poses[:, 1], poses[:, 2])
    R_wc = R_wb @ sensor.mount.R_body_from_sensor
    X0 = poses[:, 3:] + R_wb @ sensor.mount.lever_arm_m
    return np.column_stack([np.stack([opk_from_R(R) for R in R_wc]), X0])


def frame_block(case, X, uv_obs):
    from hsgeo.sensors.frame import FrameOpenCV

    s = case.sensor
    blk = FrameOpenCV(case.view, uv_obs, 1.0, point=np.arange(case.n))
    values = {
        "poses": camera_poses(s, case.poses),
        "points": X,
        "intrinsics": np.asarray(s.intrinsics, float),
        "distortion": np.asarray(s.dist, float),
    }
    return blk, values


def block_residual(case, X, obs):
    """The residual block's residuals at the sensor's parameters, (n, 2); None: no block."""
    if case.name == "pushbroom":
        blk, values = pushbroom_block(case, X, obs)
        return blk.evaluate_numpy(values, False)[0].reshape(-1, 2)
    if case.name == "frame-opencv":
        blk, values = frame_block(case, X, obs)
        return blk.evaluate(values, False)[0].reshape(-1, 2)
    if case.name == "rikola":
        return rikola_residual(case, X, obs)
    return None


def rikola_residual(case, X, obs_px):
    """JointCentroids on one tiny target per point (the corners ±1 mm about X): its residual in
    mm, converted to the face's pixels (pixel_to_mm is linear with slope ±pixel_mm)."""
    from hsgeo.sensors.frame import pixel_to_mm
    from hsgeo.sensors.rikola import JointCentroids

    s = case.sensor
    nums = np.asarray(s.bands or range(1, len(s.f_mm) + 1))
    bidx = np.searchsorted(nums, case.band)
    corners = X[:, None, :] + 1e-3 * np.array([[1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0.0]])
    face_mm = np.mean(
        [pixel_to_mm(case.project(corners[:, k]), s.image_size, s.pixel_mm) for k in range(4)],
        axis=0,
    )
    obs_mm = pixel_to_mm(obs_px, s.image_size, s.pixel_mm)
    blk = JointCentroids(
        case.view,
        bidx,
        corners,
        obs_mm,
        1.0,
        np.zeros(nums.size),  # gap 0: f = b + df, the band's f
        np.asarray(s.sensor),
    )
    values = {
        "poses": camera_poses(s, case.poses),
        "gap_model": np.zeros((2, 2)),
        "df_mm": np.asarray(s.f_mm, float),
        "pp_mm": np.asarray(s.pp_mm, float),
        "distortion_mm": np.asarray(s.KP, float),
        "sensor2_rotation": np.asarray(s.rotation_rad, float),
        "sensor2_offset_mm": np.asarray(s.offset_mm, float),
    }
    r_mm = blk.evaluate(values, False)[0].reshape(-1, 2)
    return r_mm, face_mm - obs_mm


BLOCKS = {"pushbroom", "frame-opencv", "rikola", "line-scanner", "line-scanner-linear-ifov"}


def test_models_without_a_residual_block_are_known():
    assert set(MODELS) - BLOCKS == {"panoramic", "view-angle"}


def check_block(case):
    rng = np.random.default_rng(3)
    o, d = case.rays()
    X = o + rng.uniform(*case.range_m, case.n)[:, None] * d
    if case.name.startswith("line-scanner"):
        return check_boresight_gcp(case, X)
    obs = case.project(X) + rng.normal(0, 2.0, (case.n, 2))
    r = block_residual(case, X, obs)
    if case.name == "rikola":
        r_mm, face_minus_obs_mm = r
        np.testing.assert_allclose(r_mm, face_minus_obs_mm, rtol=0, atol=1e-9)
        return
    np.testing.assert_allclose(r, case.project(X) - obs, rtol=0, atol=1e-8)


def check_boresight_gcp(case, X):
    """The line scanner's block (BoresightGCP) geocodes GCPs on a plane: its residual is the
    face's ray meeting the plane, minus the GCP (E, N)."""
    from hsgeo.sensors.line import BoresightGCP

    rng = np.random.default_rng(4)
    s, nav = case.sensor, case.nav
    h = 5.0
    gcp = np.column_stack([rng.uniform(-50, 50, (case.n, 2)), np.full(case.n, h)])
    line_rate_hz = 12.5
    line = case.t * line_rate_hz
    blk = BoresightGCP(
        nav, s, line, case.px, gcp, t0_s=0.0, line_rate_hz=line_rate_hz, height_m=h, sigma_m=1.0
    )
    from hsgeo.rotations import rpy_from_R

    b = rpy_from_R(s.mount.R_body_from_sensor)
    r = blk.evaluate({"boresight": b}, False)[0].reshape(-1, 2)
    o, d = s.rays(case.px, line / line_rate_hz, nav)
    ground = o + ((h - o[:, 2]) / d[:, 2])[:, None] * d
    np.testing.assert_allclose(r, ground[:, :2] - gcp[:, :2], rtol=0, atol=1e-7)
    # and its boresight Jacobian against finite differences
    _, jac = blk.evaluate({"boresight": b}, True)
    J = jac["boresight"]
    eps = 1e-7
    for k in range(3):
        e = np.zeros(3)
        e[k] = eps
        fd = (
            blk.evaluate({"boresight": b + e}, False)[0]
            - blk.evaluate({"boresight": b - e}, False)[0]
        ) / (2 * eps)
        np.testing.assert_allclose(J[:, k], fd, rtol=1e-5, atol=1e-4)


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_block_residual_is_face_projection_minus_observation(name, tmp_path):
    check_block(Case(name, sensor_of(name, tmp_path), np.random.default_rng(7)))


# ---- the template fails on broken models (it is not a tautology) ----------------------------
def test_template_fails_on_a_project_that_ignores_the_lever_arm(tmp_path, monkeypatch):
    """A LineScanner whose project forgets the lever arm fails the round trip."""
    from hsgeo.sensors.line import LineScanner
    from hsgeo.sensors.mount import Mount

    case = Case("line-scanner", sensor_of("line-scanner", tmp_path), np.random.default_rng(7))
    good = LineScanner.project

    def broken(self, X, t_s, trajectory):
        m = self.mount
        return good(
            LineScanner(self.geometry, Mount(np.zeros(3), m.R_body_from_sensor)), X, t_s, trajectory
        )

    monkeypatch.setattr(LineScanner, "project", broken)
    with pytest.raises(AssertionError):
        check_round_trip(case)


def test_template_fails_on_a_wrong_distortion_sign(tmp_path, monkeypatch):
    """A pushbroom camera whose rays undistort with the wrong sign fails the round trip."""
    import hsgeo.sensors.pushbroom as pb

    case = Case("pushbroom", sensor_of("pushbroom", tmp_path), np.random.default_rng(7))
    good = pb.undistort_pushbroom_line
    monkeypatch.setattr(
        pb, "undistort_pushbroom_line", lambda xy, k: good(xy, tuple(-np.asarray(k)))
    )
    with pytest.raises(AssertionError):
        check_round_trip(case)


def test_template_fails_on_a_wrong_panoramic_jacobian(tmp_path, monkeypatch):
    """A panoramic project_jacobian with a swapped sign fails the Jacobian check."""
    from hsgeo.sensors.panoramic import PanoramicScanner

    case = Case("panoramic", sensor_of("panoramic", tmp_path), np.random.default_rng(7))
    good = PanoramicScanner.project_jacobian
    monkeypatch.setattr(
        PanoramicScanner, "project_jacobian", lambda self, *a: good(self, *a) * [[1], [-1]]
    )
    with pytest.raises(AssertionError):
        check_jacobian(case)


def test_template_fails_on_a_block_without_the_lever_arm(tmp_path, monkeypatch):
    """The line scanner's GCP block with its lever arm dropped (as BoresightGCP was before it
    used the face) fails block = face − observation."""
    from hsgeo.sensors.line import BoresightGCP, LineScanner

    case = Case("line-scanner", sensor_of("line-scanner", tmp_path), np.random.default_rng(7))
    good = BoresightGCP.__init__

    def no_lever(self, nav, sensor, *a, **kw):
        good(self, nav, sensor.geometry if isinstance(sensor, LineScanner) else sensor, *a, **kw)

    monkeypatch.setattr(BoresightGCP, "__init__", no_lever)
    with pytest.raises(AssertionError):
        check_block(case)


def test_template_fails_on_a_frame_block_with_another_principal_point(tmp_path, monkeypatch):
    """FrameOpenCV with cx shifted by 0.01 px fails block = face − observation."""
    import hsgeo.sensors.frame as fr

    case = Case("frame-opencv", sensor_of("frame-opencv", tmp_path), np.random.default_rng(7))
    good = fr.FrameOpenCV.evaluate

    def shifted(self, values, jacobian):
        v = dict(values)
        v["intrinsics"] = np.asarray(values["intrinsics"]) + [0, 0, 0.01, 0]
        return good(self, v, jacobian)

    monkeypatch.setattr(fr.FrameOpenCV, "evaluate", shifted)
    with pytest.raises(AssertionError):
        check_block(case)


def test_the_daedalus_constants_are_the_papers():
    from hsgeo.papers import ASF_004
    from hsgeo.sensors.panoramic import DAEDALUS_IFOV_DEG

    assert DAEDALUS_IFOV_DEG == ASF_004["angular pixel size"][0]
