"""Tests of hsgeo.measure.lp_ransac: the LP fundamental matrix of Gupta & Hartley (1997).

Independent truths: exact LP correspondences from two LP cameras (Gupta & Hartley's matrix
form, and hsgeo's own :class:`~hsgeo.sensors.pushbroom.PushbroomCamera` flown along straight
constant-attitude trajectories, each point's line found by :func:`~hsgeo.sensors.mount.line_time`),
the F of two known cameras computed from its determinant definition, simulated noise and gross
outliers with known labels, and OpenCV's frame-camera RANSAC as the comparator.
"""

import numpy as np
import pytest

from hsgeo.errors import InputError, ObservationError
from hsgeo.measure.lp_ransac import (
    LpRansacResult,
    fit_lp_fundamental,
    lp_epipolar_distance,
    lp_fundamental_from_cameras,
    ransac_frame_fundamental,
    ransac_lp_fundamental,
)
from hsgeo.sensors.mount import line_time
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.trajectory import Trajectory

RATE_HZ = 200.0  # 002 §4: line rate
#: The 002 camera (c ≈ 40.3 mm, 6.5 µm pixels, 1800 px; 002 §4, Fig. 8) with a boresight of a
#: few tenths of a degree and a lever arm, no distortion (an exact LP camera).
CAMERA = PushbroomCamera(
    c_mm=(40.3,),
    pixel_mm=0.0065,
    boresight_rad=(0.004, -0.006, 0.003),
    lever_arm_m=(0.12, -0.05, -0.30),
)
#: Exact data: the residual of a fitted F is at numerical precision. The points' own line
#: times are solved to |y| < 1e-11 px and the conditioned 11-point system (condition ≈ 1e4 in
#: these geometries, coordinates ≈ 1e3 px) amplifies double rounding (1e-16) to ≈ 1e-11 px;
#: 1e-8 px leaves three orders of margin and is eight below any pixel error of interest.
EXACT_TOL_PX = 1e-8


def _strip(heading_rad, east_m, agl_m, speed_m_s, t_mid_s=10.0, half_s=10.0):
    """A straight flight at constant velocity and attitude through (east_m, 0, agl_m)."""
    d = np.array([np.sin(heading_rad), np.cos(heading_rad), 0.0])
    t = np.array([t_mid_s - half_s, t_mid_s + half_s])
    xyz = np.array([east_m, 0.0, agl_m]) + np.outer(t - t_mid_s, d * speed_m_s)
    return Trajectory(t, xyz, np.array([[0.0, 0.0, heading_rad]] * 2))


def _observe(trajectory, xyz_m, t0_s):
    """Scene pixels ``(u, v)``: u = (line time − t0) × line rate, v = column of the line."""

    def across_px(X, t):
        return CAMERA.project(X, t, trajectory)[:, 1]

    t = line_time(across_px, xyz_m, trajectory, trajectory.t_s.mean(), tol_s=1e-13)
    xy = CAMERA.project(xyz_m, t, trajectory)
    assert np.abs(xy[:, 1]).max() < 1e-9  # each point is on its line
    return np.column_stack([(t - t0_s) * RATE_HZ, xy[:, 0] + 899.5])


#: Geometries: (second strip's heading, east offset m, AGL m of both strips, speed m/s,
#: terrain relief m, scene lines). "paper" is 002 §4 (1875 / 2500 m AGL, 67 m/s, 200-line
#: scenes) with 15 m of relief; "uav" a low, slow flight over relief of 30 % of the height.
GEOMETRIES = {
    "paper-opposite": (np.pi, 80.0, (1875.0, 2500.0), 67.0, 15.0, 200),
    "paper-crossing": (np.pi / 2, 0.0, (1875.0, 2500.0), 67.0, 15.0, 200),
    "uav-crossing": (np.pi / 2, 0.0, (100.0, 130.0), 5.0, 30.0, 300),
}


def lp_pairs(name, n, rng):
    """Exact correspondences of ``n`` random points seen in a scene of each of two strips."""
    heading2, east2, (agl1, agl2), speed, relief, n_lines = GEOMETRIES[name]
    tr1 = _strip(0.0, 0.0, agl1, speed)
    tr2 = _strip(heading2, east2, agl2, speed)
    half = speed * n_lines / RATE_HZ / 2  # half the scene's length on the ground, m
    if heading2 == np.pi:  # opposite: the overlap is long across the track
        east = rng.uniform(-0.12 * agl1 + east2, 0.12 * agl1, n)
    else:  # crossing: a square of one scene length
        east = rng.uniform(-half, half, n)
    xyz = np.column_stack([east, rng.uniform(-half, half, n), rng.uniform(0.0, relief, n)])
    t0 = 10.0 - n_lines / RATE_HZ / 2
    return _observe(tr1, xyz, t0), _observe(tr2, xyz, t0)


def gh_pairs(n, rng):
    """Two LP cameras in Gupta & Hartley's form: a camera moving at constant velocity V with
    constant attitude R; u = time of crossing its view plane, v = perspective coordinate."""
    X = np.column_stack([rng.uniform(-50, 50, (n, 2)), rng.uniform(0, 20, n)])
    uvs, cams = [], []
    for C0, V, angles in [
        (np.array([0.0, -200, 300]), np.array([0.0, 10, 0]), (0.02, -0.03, 0.01)),
        (np.array([60.0, 200, 350]), np.array([-3.0, -12, 0.5]), (-0.04, 0.02, 3.1)),
    ]:
        cx, sx = np.cos(angles[0]), np.sin(angles[0])
        cz, sz = np.cos(angles[2]), np.sin(angles[2])
        R = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array(
            [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
        )
        R = R @ np.diag([1.0, 1.0, -1.0])  # camera z looks down
        R = R.T  # camera from map
        p0 = (X - C0) @ R.T
        Vc = R @ V
        t = p0[:, 1] / Vc[1]  # p_y(t) = (R (X − C0 − t V))_y = 0: crossing time
        p = p0 - np.outer(t, Vc)
        c_px, v0_px = 1200.0, 900.0
        uvs.append(np.column_stack([t * RATE_HZ, c_px * p[:, 0] / p[:, 2] + v0_px]))
        # the same camera as a 3×4 matrix (Gupta & Hartley 1997, eq. 1)
        m_t = np.append(R[1], -R[1] @ C0) / Vc[1]  # t = m_t·X̃
        rows = [np.append(R[k], -R[k] @ C0) - Vc[k] * m_t for k in (0, 2)]  # p_x, p_z
        cams.append(np.stack([RATE_HZ * m_t, c_px * rows[0] + v0_px * rows[1], rows[1]]))
    return uvs[0], uvs[1], cams, X


def _with_outliers(uv1, uv2, share, sigma_px, rng):
    """Noise on every coordinate and a share of gross outliers (a random pixel of image 2)."""
    n = uv1.shape[0]
    out = np.zeros(n, bool)
    out[rng.choice(n, int(round(share * n)), replace=False)] = True
    a = uv1 + rng.normal(0, sigma_px, uv1.shape)
    b = uv2 + rng.normal(0, sigma_px, uv2.shape)
    lo, hi = uv2.min(axis=0), uv2.max(axis=0)
    b[out] = rng.uniform(lo, hi, (out.sum(), 2))
    return a, b, out


# ----------------------------------------------------------------------------------------------
# 1. exact data
# ----------------------------------------------------------------------------------------------
def test_gupta_hartley_cameras_exact():
    rng = np.random.default_rng(3)
    uv1, uv2, (M1, M2), X = gh_pairs(60, rng)
    # the matrix form reproduces the camera's pixels (u affine, v a ratio of affine forms)
    Xh = np.column_stack([X, np.ones(len(X))])
    for M, uv in ((M1, uv1), (M2, uv2)):
        np.testing.assert_allclose(Xh @ M[0], uv[:, 0], atol=1e-9)
        np.testing.assert_allclose((Xh @ M[1]) / (Xh @ M[2]), uv[:, 1], atol=1e-9)
    F_cams = lp_fundamental_from_cameras(M1, M2)
    assert np.abs(lp_epipolar_distance(F_cams, uv1, uv2)).max() < EXACT_TOL_PX
    assert np.all(F_cams[:2, :2] == 0)
    F = fit_lp_fundamental(uv1[:11], uv2[:11])
    assert np.all(F[:2, :2] == 0)
    assert lp_epipolar_distance(F, uv1[11:], uv2[11:]).max() < EXACT_TOL_PX
    # the same matrix as the determinant of the two cameras, up to sign
    assert np.abs(F - np.sign(np.sum(F * F_cams)) * F_cams).max() < 1e-9


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
def test_hsgeo_pushbroom_exact(name):
    rng = np.random.default_rng(7)
    uv1, uv2 = lp_pairs(name, 80, rng)
    for n_fit in (11, 40):
        F = fit_lp_fundamental(uv1[:n_fit], uv2[:n_fit])
        d = lp_epipolar_distance(F, uv1[40:], uv2[40:])  # points not used in the fit
        assert d.max() < EXACT_TOL_PX
    # a wrong match is far from the relation (the test can fail)
    d_wrong = lp_epipolar_distance(F, uv1[40:], uv2[40:][::-1])
    assert np.median(d_wrong) > 1.0


def test_sampson_distance_is_first_order_geometric():
    """The Sampson distance equals the distance to the relation's surface to first order:
    moving a correct match by δ along the gradient gives |δ| back (finite differences)."""
    rng = np.random.default_rng(5)
    uv1, uv2, (M1, M2), _ = gh_pairs(30, rng)
    F = lp_fundamental_from_cameras(M1, M2)
    eps = 1e-4
    direction = rng.normal(size=(30, 4))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    d = lp_epipolar_distance(F, uv1 + eps * direction[:, :2], uv2 + eps * direction[:, 2:])
    # numerical gradient of the algebraic error at the correct matches
    L = lambda uv: np.column_stack([uv[:, 0], uv[:, 0] * uv[:, 1], uv[:, 1], np.ones(len(uv))])  # noqa: E731
    alg = lambda a, b: np.einsum("nr,rs,ns->n", L(b), F, L(a))  # noqa: E731
    g = np.zeros((30, 4))
    h = 1e-3
    for k in range(4):
        e = np.zeros((30, 4))
        e[:, k] = h
        g[:, k] = (alg(uv1 + e[:, :2], uv2 + e[:, 2:]) - alg(uv1 - e[:, :2], uv2 - e[:, 2:])) / (
            2 * h
        )
    expected = eps * np.abs(np.sum(g * direction, axis=1)) / np.linalg.norm(g, axis=1)
    np.testing.assert_allclose(d, expected, rtol=1e-3, atol=1e-9)  # second order: ε² × curvature


# ----------------------------------------------------------------------------------------------
# 2. noise and gross outliers
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("name", "keep_min"),
    [("uav-crossing", 0.95), ("gupta-hartley", 0.85)],
)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ransac_noise_and_outliers(name, keep_min, seed):
    """0.3 px noise, 30 % gross outliers: ≥ 95 % of the outliers rejected; ≥ 95 % of the true
    matches kept in the low-flight geometry (observed 99.5–100 %, seeds 0–7). In the
    Gupta–Hartley geometry (scenes 2000 lines long, ≈ 400 px wide) the linear F is
    noise-sensitive: even its least-squares fit to the true matches alone misses clean
    positions by up to 1.6 px; seeds 0–7 keep 89.5–100 % (the exact F 100 %), hence ≥ 85 %."""
    rng = np.random.default_rng(seed)
    if name == "gupta-hartley":
        uv1, uv2, _, _ = gh_pairs(300, rng)
    else:
        uv1, uv2 = lp_pairs(name, 300, rng)
    a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    r = ransac_lp_fundamental(a, b, threshold_px=1.0, rng=seed)
    assert isinstance(r, LpRansacResult)
    assert r.inliers[~out].mean() >= keep_min
    assert 1 - r.inliers[out].mean() >= 0.95
    assert 11 <= r.n_iterations <= 5000
    # the refitted F is close to the truth: true matches within 3σ-ish of it
    d = lp_epipolar_distance(r.F, uv1, uv2)  # noise-free positions
    assert np.median(d) < 0.3


@pytest.mark.parametrize("name", ["paper-opposite", "paper-crossing"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ransac_paper_geometry(name, seed):
    """002's geometry (15 m of relief under 1875–2500 m: a near-planar scene). True matches
    are kept (≥ 95 %), but the 11-point F has near-null directions there that let RANSAC's best
    model bend through a few outliers (3–90 px off the true relation, while the true matches
    stay within 0.5 px of the bent F): ≥ 85 % of them are rejected (observed 91–100 % over
    seeds 0–7, mean 98 %; the exact F rejects 98–100 %), not ≥ 95 % in every case."""
    rng = np.random.default_rng(seed)
    uv1, uv2 = lp_pairs(name, 300, rng)
    a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    r = ransac_lp_fundamental(a, b, threshold_px=1.0, rng=seed)
    assert r.inliers[~out].mean() >= 0.95
    assert 1 - r.inliers[out].mean() >= 0.85


@pytest.mark.parametrize("name", ["paper-crossing", "uav-crossing"])
def test_deleted_residuals_reject_outliers_in_small_sets(name):
    """50 matches (35 true): an 11-unknown F bends through outliers (the plain RANSAC rejects
    70–96 % on average over seeds); the deleted-residual check (each inlier against the F of
    all others) rejects ≥ 95 % on average, keeping ≥ 90 % of the true matches."""
    plain, deleted = [], []
    for seed in range(4):
        rng = np.random.default_rng(seed)
        uv1, uv2 = lp_pairs(name, 50, rng)
        a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
        r0 = ransac_lp_fundamental(a, b, rng=seed, deleted=False)
        r1 = ransac_lp_fundamental(a, b, rng=seed)
        plain.append((r0.inliers[~out].mean(), 1 - r0.inliers[out].mean()))
        deleted.append((r1.inliers[~out].mean(), 1 - r1.inliers[out].mean()))
    plain, deleted = np.array(plain), np.array(deleted)
    assert deleted[:, 1].mean() >= 0.95
    assert deleted[:, 1].mean() > plain[:, 1].mean()
    assert deleted[:, 0].mean() >= 0.90


# ----------------------------------------------------------------------------------------------
# 3. LP against frame fundamental matrix
# ----------------------------------------------------------------------------------------------
def _frame_residual_px(uv1, uv2):
    """OpenCV's frame error (max of the two point-to-epipolar-line distances) of the
    least-squares (8-point) frame F fitted to all correspondences."""
    import cv2

    F, _ = cv2.findFundamentalMat(uv1, uv2, cv2.FM_8POINT)
    h1 = np.column_stack([uv1, np.ones(len(uv1))])
    h2 = np.column_stack([uv2, np.ones(len(uv2))])
    l2, l1 = h1 @ F.T, h2 @ F
    d2 = np.abs(np.sum(h2 * l2, axis=1)) / np.hypot(l2[:, 0], l2[:, 1])
    d1 = np.abs(np.sum(h1 * l1, axis=1)) / np.hypot(l1[:, 0], l1[:, 1])
    return np.maximum(d1, d2)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lp_beats_frame_where_frame_model_is_wrong(seed):
    """Low flight over relief of 30 % of the height, crossing strips: no frame F fits the LP
    correspondences (median residual of the least-squares frame F on *exact* data > 2 px, far
    above the 1 px threshold), so the frame RANSAC can keep at most the minority of matches one
    F happens to fit: ≤ 50 % (observed 23–24 %), against ≥ 95 % for the LP F."""
    rng = np.random.default_rng(seed)
    uv1, uv2 = lp_pairs("uav-crossing", 300, rng)
    assert np.median(_frame_residual_px(uv1, uv2)) > 2.0
    a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    lp = ransac_lp_fundamental(a, b, threshold_px=1.0, rng=seed).inliers
    frame = ransac_frame_fundamental(a, b, threshold_px=1.0)
    assert lp[~out].mean() >= 0.95
    assert frame[~out].mean() <= 0.50


def _mount_motion_rad(t_s, amp_rad, phase_s):
    """Residual attitude of a stabilised mount: the pushbroom campaign's form (roll, pitch,
    yaw sums of 0.3–2.3 Hz sines, hsgeo.simulate.pushbroom_campaign), copied here because
    measure tests do not import the simulator."""
    t = np.asarray(t_s) + phase_s
    w = 2 * np.pi
    roll = 0.6 * np.sin(w * 0.7 * t) + 0.4 * np.sin(w * 1.9 * t + 1.0)
    pitch = 0.5 * np.sin(w * 0.5 * t + 2.0) + 0.3 * np.sin(w * 2.3 * t)
    yaw = 0.5 * np.sin(w * 0.3 * t + 0.5)
    return amp_rad * np.column_stack([roll, pitch, yaw])


def _wobbly_strip(heading_rad, east_m, agl_m, amp_rad, phase_s):
    """Straight constant-velocity flight with the mount's attitude motion, sampled at 1 kHz
    (the trajectory's linear interpolation then errs by < 1e-8 rad)."""
    t = np.arange(0.0, 20.0005, 0.001)
    d = np.array([np.sin(heading_rad), np.cos(heading_rad), 0.0])
    xyz = np.array([east_m, 0.0, agl_m]) + np.outer(t - 10.0, d * 67.0)
    rph = _mount_motion_rad(t, amp_rad, phase_s)
    rph[:, 2] += heading_rad
    return Trajectory(t, xyz, rph)


def _observe_compensated(trajectory, xyz_m, t0_s):
    """Scene pixels after 002 eq. (1): x moved by δx of the rotation from the line's camera
    attitude to the scene's first line's; u is the line (its δy is not compensated, 002 §3.1)."""
    from hsgeo.trajectory import R_BODY_FROM_PLATFORM

    def across_px(X, t):
        return CAMERA.project(X, t, trajectory)[:, 1]

    t = line_time(across_px, xyz_m, trajectory, 10.0, tol_s=1e-12)
    x_px = CAMERA.project(xyz_m, t, trajectory)[:, 0]
    c_px = CAMERA.c_mm[0] / CAMERA.pixel_mm

    def R_map_from_cam(tt):
        return trajectory.R_map_from_body(tt) @ R_BODY_FROM_PLATFORM @ CAMERA.beta.T

    p = np.column_stack([x_px, np.zeros_like(x_px), np.full_like(x_px, c_px)])
    q = np.einsum("ij,njk,nk->ni", R_map_from_cam(t0_s)[0].T, R_map_from_cam(t), p)  # eq. (1)
    dx_px = q[:, 0] - p[:, 0]
    return np.column_stack([(t - t0_s) * RATE_HZ, x_px + dx_px + 899.5]), dx_px


@pytest.mark.parametrize("name", ["paper-opposite", "paper-crossing"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lp_beats_frame_with_mount_motion(name, seed):
    """002's geometry with the campaign's residual mount motion (0.02°; δx RMS 1.4–2.6 px,
    max 2.2–3.9 px in these 200-line scenes, paper 0.91 / 4.43 px), scenes compensated by
    eq. (1). Neither model is exact now (δy stays: the LP F fitted to the exact positions
    leaves 0.2–0.5 px at the 90th percentile), but the LP F is the better one (the frame F's
    90th percentile is 0.6–1.3 px). At 1 px the LP RANSAC keeps ≥ 95 % of the true matches
    (observed 97–100 %, seeds 0–5), the frame RANSAC 74–92 %: ≥ 4 points less in every case
    (observed ≥ 8). Without mount motion the gap is 2–7 points, from the frame's stricter
    error (the larger of two line distances) and its 0.2–0.4 px model error."""
    heading2, east2, (agl1, agl2), speed, relief, n_lines = GEOMETRIES[name]
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 10.0, 2)
    amp = 0.02 * np.pi / 180  # pushbroom campaign: CampaignConfig.mount_motion_rad
    tr1 = _wobbly_strip(0.0, 0.0, agl1, amp, phase[0])
    tr2 = _wobbly_strip(heading2, east2, agl2, amp, phase[1])
    half = speed * n_lines / RATE_HZ / 2
    n = 300
    if heading2 == np.pi:
        east = rng.uniform(-0.12 * agl1 + east2, 0.12 * agl1, n)
    else:
        east = rng.uniform(-half, half, n)
    xyz = np.column_stack([east, rng.uniform(-half, half, n), rng.uniform(0.0, relief, n)])
    uv1, dx1 = _observe_compensated(tr1, xyz, 9.5)
    uv2, _ = _observe_compensated(tr2, xyz, 9.5)
    assert 1.0 < np.sqrt(np.mean(dx1**2)) < 4.0  # the motion is of the paper's size
    a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    lp = ransac_lp_fundamental(a, b, threshold_px=1.0, rng=seed).inliers
    frame = ransac_frame_fundamental(a, b, threshold_px=1.0)
    assert lp[~out].mean() >= 0.95
    assert lp[~out].mean() - frame[~out].mean() >= 0.04
    assert 1 - lp[out].mean() >= 0.90


@pytest.mark.parametrize("name", ["paper-opposite", "paper-crossing"])
def test_frame_model_is_close_enough_in_paper_geometry(name):
    """In 002's geometry the frame F is the wrong model but a close one: on exact LP data its
    least-squares residual is above numerical precision (> 1e-3 px) and below the 1 px
    threshold (observed max 0.2–0.4 px): relief / height ≈ 0.8 % and an 8° half field make the
    scene nearly affine. The frame RANSAC then keeps ≥ 90 % of the true matches (observed
    93–97 %; it loses some to its stricter error, max of two line distances, not the model),
    the LP F ≥ 95 %: with constant attitude the choice of model matters little at 1 px here;
    with the mount's attitude motion it does (:func:`test_lp_beats_frame_with_mount_motion`)."""
    rng = np.random.default_rng(11)
    uv1, uv2 = lp_pairs(name, 300, rng)
    res = _frame_residual_px(uv1, uv2)
    assert 1e-3 < res.max() < 1.0
    a, b, out = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    lp = ransac_lp_fundamental(a, b, threshold_px=1.0, rng=0).inliers
    frame = ransac_frame_fundamental(a, b, threshold_px=1.0)
    assert lp[~out].mean() >= 0.95
    assert frame[~out].mean() >= 0.90


# ----------------------------------------------------------------------------------------------
# 4. error paths and determinism
# ----------------------------------------------------------------------------------------------
def test_error_paths():
    rng = np.random.default_rng(0)
    uv1, uv2, _, _ = gh_pairs(30, rng)
    with pytest.raises(ObservationError, match="at least 11"):
        fit_lp_fundamental(uv1[:10], uv2[:10])
    with pytest.raises(ObservationError, match="at least 11"):
        ransac_lp_fundamental(uv1[:10], uv2[:10])
    bad = uv1.copy()
    bad[3, 1] = np.nan
    with pytest.raises(InputError, match="NaN"):
        fit_lp_fundamental(bad, uv2)
    with pytest.raises(InputError, match="NaN"):
        ransac_lp_fundamental(bad, uv2)
    with pytest.raises(InputError, match="same n"):
        fit_lp_fundamental(uv1, uv2[:-1])
    with pytest.raises(InputError, match="same n"):
        lp_epipolar_distance(np.eye(4), uv1, uv2[:, :1])
    with pytest.raises(InputError, match="threshold"):
        ransac_lp_fundamental(uv1, uv2, threshold_px=0.0)
    # degenerate: every point on one line (one u) leaves u and uv proportional to 1 and v
    flat1 = np.column_stack([np.full(20, 5.0), rng.uniform(0, 1000, 20)])
    flat2 = np.column_stack([rng.uniform(0, 200, 20), rng.uniform(0, 1000, 20)])
    with pytest.raises(ObservationError, match="degenerate"):
        fit_lp_fundamental(flat1, flat2)
    # the frame comparator: fewer than 8 → no inliers
    assert not ransac_frame_fundamental(uv1[:7], uv2[:7]).any()
    assert ransac_frame_fundamental(uv1[:7], uv2[:7]).shape == (7,)


def test_determinism():
    rng = np.random.default_rng(4)
    uv1, uv2 = lp_pairs("uav-crossing", 200, rng)
    a, b, _ = _with_outliers(uv1, uv2, 0.3, 0.3, rng)
    r1 = ransac_lp_fundamental(a, b, rng=17)
    r2 = ransac_lp_fundamental(a, b, rng=np.random.default_rng(17))
    np.testing.assert_array_equal(r1.inliers, r2.inliers)
    np.testing.assert_array_equal(r1.F, r2.F)
    assert r1.n_iterations == r2.n_iterations
    # exact data, the minimum number: every match is an inlier of the one model
    e1, e2 = lp_pairs("uav-crossing", 11, np.random.default_rng(9))
    r = ransac_lp_fundamental(e1, e2, rng=0)
    assert r.inliers.all() and r.inliers.shape == (11,)
    assert lp_epipolar_distance(r.F, e1, e2).max() < EXACT_TOL_PX
    f1 = ransac_frame_fundamental(a, b)
    f2 = ransac_frame_fundamental(a, b)
    np.testing.assert_array_equal(f1, f2)
