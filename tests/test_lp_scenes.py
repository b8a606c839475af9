"""Rotation-compensated LP scenes (hsgeo.measure.lp_scenes, 002 eq. (1)) against independent
truths: straight edges come out straight, δx agrees with re-projection, exact round trips."""

import numpy as np
import pytest
from scipy.special import erf

from hsgeo.errors import InputError
from hsgeo.io.lp_lines import LpStrip
from hsgeo.measure.lp_scenes import (
    dx_statistics,
    line_to_scene,
    make_scenes,
    rotation_compensation_px,
    scene_to_line,
)
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.trajectory import Trajectory

RATE = 200.0
CAM = PushbroomCamera(c_mm=(40.0, 40.01), pixel_mm=0.0065, boresight_rad=(0.004, -0.006, 0.003))


def _trajectory(roll_amp=8e-4, pitch_amp=0.0, yaw_amp=0.0, speed=67.0, seconds=2.0):
    t = np.arange(0, seconds + 1e-9, 1 / RATE)
    w = 2 * np.pi * 1.3
    rph = np.column_stack(
        [
            roll_amp * np.sin(w * t + 0.3),
            pitch_amp * np.sin(0.7 * w * t),
            yaw_amp * np.sin(0.5 * w * t + 1.0),
        ]
    )
    xyz = np.column_stack([np.zeros_like(t), speed * t, np.full_like(t, 1875.0)])
    return Trajectory(t, xyz, rph)


def _edge_strip(traj, e_edge_m=100.0, col0=400, n_cols=1000):
    """Lines seeing a straight north–south edge (E = e_edge_m) on flat ground, each line
    rendered analytically from the edge's projection in that line (camera.project)."""
    t = traj.t_s
    pos, _ = traj.pose(t)
    n = pos[:, 1].copy()
    for _ in range(3):  # the edge's point in the line's view plane (y = 0), by secant steps
        y0 = CAM.project(np.column_stack([np.full(t.size, e_edge_m), n, np.zeros(t.size)]), t, traj)
        y1 = CAM.project(
            np.column_stack([np.full(t.size, e_edge_m), n + 1, np.zeros(t.size)]), t, traj
        )
        n = n - y0[:, 1] / (y1[:, 1] - y0[:, 1])
    xy = CAM.project(np.column_stack([np.full(t.size, e_edge_m), n, np.zeros(t.size)]), t, traj)
    assert np.max(np.abs(xy[:, 1])) < 1e-6
    x = col0 + np.arange(n_cols) - 899.5
    vals = 1000 + 2000 * 0.5 * (1 + erf((x[None, :] - xy[:, :1]) / (0.7 * np.sqrt(2))))
    lines = np.repeat(vals[:, :, None], 2, axis=2).astype(np.float32)
    return LpStrip(lines, t, col0, np.array([450.0, 527.0]), "edge"), xy[:, 0]


def _edge_positions(img, x_cols):
    """Sub-pixel x of the edge in each row: for a step blurred by a symmetric kernel sampled
    every pixel, Σ_j f_j = x_last + ½ − e (f the normalised step, 0 … 1; exact up to the
    aliasing term exp(−2π²σ²) ≈ 1e-4 px at σ = 0.7 px)."""
    f = (np.asarray(img, dtype=np.float64) - 1000.0) / 2000.0
    return x_cols[-1] + 0.5 - f.sum(axis=1)


def _curvature_px(xs):
    u = np.arange(xs.size)
    return float(np.std(xs - np.polyval(np.polyfit(u, xs, 1), u)))


def test_compensation_straightens_an_edge_under_roll_wobble():
    traj = _trajectory()
    strip, x_true = _edge_strip(traj)
    x_cols = strip.x_px(1800)
    scenes = make_scenes(strip, traj, CAM, 200, 1800)
    for sc in scenes:
        raw = _edge_positions(strip.lines[sc.line0 : sc.line0 + sc.n_lines, :, 0], x_cols)
        comp = _edge_positions(sc.image[:, :, 0], x_cols)
        # the raw lines see the edge where camera.project says (the edge finder is exact)
        assert np.allclose(raw, x_true[sc.line0 : sc.line0 + sc.n_lines], atol=1e-3)
        assert _curvature_px(raw) > 1.0  # the wobble bends the edge by pixels
        # compensated: straight to 0.02 px, and where the reference line saw it
        assert _curvature_px(comp) < 0.02
        assert abs(np.mean(comp) - raw[0]) < 0.02


def test_dx_agrees_with_reprojection_at_the_reference_attitude():
    """δx of eq. (1) against the exact image motion of a far point seen from a hovering camera
    whose attitude alone changes: they differ by the first-order term x²Δφ/c (≤ 3 %)."""
    traj = _trajectory(roll_amp=2e-3, pitch_amp=1e-3, yaw_amp=1e-3, speed=0.0)
    x = np.linspace(-890, 890, 9)
    t = traj.t_s[::10]
    dx = rotation_compensation_px(x, t, t[0], traj, CAM, band=1)
    o, d = CAM.rays(
        np.column_stack([np.tile(x, t.size), np.zeros(x.size * t.size)]),
        np.repeat(t, x.size),
        traj,
        band=1,
    )
    far = o + 1.0e5 * d
    x_ref = CAM.project(far, np.full(far.shape[0], t[0]), traj, band=1)[:, 0].reshape(t.size, -1)
    moved = x_ref - x[None, :]
    assert np.max(np.abs(moved)) > 5  # a real test: shifts of several pixels
    assert np.all(np.abs(dx - moved) <= 0.03 * np.abs(moved) + 1e-3)
    assert np.allclose(dx[0], 0.0, atol=1e-9)


def test_round_trips_are_exact():
    traj = _trajectory(roll_amp=1e-3, yaw_amp=5e-4)
    strip, _ = _edge_strip(traj)
    sc = make_scenes(strip, traj, CAM, 150, 1800)[1]
    rng = np.random.default_rng(1)
    li = sc.line0 + rng.integers(0, sc.n_lines, 500)
    x = rng.uniform(sc.x_px[0], sc.x_px[-1], 500)
    uv = line_to_scene(sc, li, x)
    back_li, back_x = scene_to_line(sc, uv)
    assert np.array_equal(back_li, li)
    assert np.max(np.abs(back_x - x)) < 1e-6
    uv2 = np.column_stack([rng.integers(0, sc.n_lines, 500), rng.uniform(5, 995, 500)])
    li2, x2 = scene_to_line(sc, uv2)
    assert np.max(np.abs(line_to_scene(sc, li2, x2) - uv2)) < 1e-6
    # nearest line: a fractional row goes to the nearest original line
    assert scene_to_line(sc, [[2.4, 10.0]])[0][0] == sc.line0 + 2


def test_scenes_cover_the_strip_and_statistics():
    traj = _trajectory()
    strip, _ = _edge_strip(traj)
    scenes = make_scenes(strip, traj, CAM, 150, 1800)
    assert [s.line0 for s in scenes] == [0, 150, 300]
    assert sum(s.n_lines for s in scenes) == strip.n_lines  # 401 = 150 + 150 + 101
    st = dx_statistics(scenes)
    all_dx = np.concatenate([s.dx_px.ravel() for s in scenes])
    assert st["rms_px"] == pytest.approx(np.sqrt(np.mean(all_dx**2)))
    assert st["max_px"] == pytest.approx(np.max(np.abs(all_dx)))
    assert st["n_scenes"] == 3


def test_bad_input():
    traj = _trajectory()
    strip, _ = _edge_strip(traj)
    with pytest.raises(InputError, match="n_lines"):
        make_scenes(strip, traj, CAM, 1, 1800)
    with pytest.raises(InputError, match="n_px_full"):
        make_scenes(strip, traj, CAM, 100, 1000)
    with pytest.raises(InputError, match="LpStrip"):
        make_scenes(strip.lines, traj, CAM, 100, 1800)
    with pytest.raises(InputError, match="no scenes"):
        dx_statistics([])
    short = Trajectory(traj.t_s[:100], traj.xyz_m[:100], traj.roll_pitch_heading_rad[:100])
    with pytest.raises(InputError, match="does not cover"):
        make_scenes(strip, short, CAM, 200, 1800)
    sc = make_scenes(strip, traj, CAM, 200, 1800)[0]
    with pytest.raises(InputError, match="NaN"):
        scene_to_line(sc, [[np.nan, 1.0]])
    with pytest.raises(InputError, match="outside scene"):
        line_to_scene(sc, [sc.line0 + 500], [0.0])
    with pytest.raises(InputError, match="band"):
        rotation_compensation_px([0.0], [0.0], 0.0, traj, CAM, band=5)


def test_figure_3_smoke():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from hsgeo.plotting import plot_lp_compensation

    traj = _trajectory()
    strip, _ = _edge_strip(traj)
    sc = make_scenes(strip, traj, CAM, 200, 1800)[0]
    fig, axes = plt.subplots(1, 2)
    out = plot_lp_compensation(axes, strip, sc, band=0, columns=slice(0, 200))
    assert list(out) == list(axes)
    assert len(axes[0].images) == 1 and len(axes[1].images) == 1
    plt.close(fig)
