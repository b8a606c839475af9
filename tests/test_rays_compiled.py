"""The LP camera's rays grouped by line (hsgeo.sensors._pushbroom_rays) equal the per-pixel
numpy formula of 002 eq. (4) read backwards, to rounding (reassociation only).

The reference below is the per-pixel path the compiled one replaced: every pixel's pose from
the trajectory, ``R_map_from_platform`` per pixel, the undistortion per pixel, ``R βᵀ d_cam``
by einsum and the normalisation last.
"""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo._perline import PerLine
from hsgeo.distortion import undistort_pushbroom_line
from hsgeo.errors import InputError
from hsgeo.rotations import R_from_rpy
from hsgeo.sensors._pushbroom_rays import line_runs
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.trajectory import R_BODY_FROM_PLATFORM, Trajectory

REL = 1e-12


def reference_rays_at(cam, xy_px, band, xyz, R):
    """The per-pixel numpy formula: ``x + R l^p`` and ``unit(R βᵀ (x̄, ȳ, c_b))``."""
    xy_mm = np.asarray(xy_px, float) * cam.pixel_mm - np.array([cam.x0_mm, cam.y0_mm])
    if any(cam.distortion):
        xy_mm = undistort_pushbroom_line(xy_mm, cam.distortion)
    c = np.asarray(cam.c_mm, float)[np.broadcast_to(band, (xy_mm.shape[0],))]
    d_cam = np.column_stack([xy_mm, c])
    origins = xyz + R @ np.asarray(cam.lever_arm_m, float)
    d = np.einsum("nij,nj->ni", R, d_cam @ cam.beta)
    return origins, d / np.linalg.norm(d, axis=-1, keepdims=True)


def reference_rays(cam, xy_px, t_s, traj, band):
    pos, _ = traj.pose(t_s)
    R = traj.R_map_from_body(t_s) @ R_BODY_FROM_PLATFORM
    return reference_rays_at(cam, xy_px, band, pos, R)


def _trajectory(rng, n=40):
    t = np.sort(rng.uniform(0.0, 20.0, n))
    t[0], t[-1] = 0.0, 20.0
    xyz = np.column_stack(
        [67.0 * t + rng.normal(0, 0.3, n), rng.normal(0, 2, n), 1000 + rng.normal(0, 5, n)]
    )
    rph = np.column_stack(
        [rng.normal(0, 0.05, n), rng.normal(0, 0.05, n), 0.3 + rng.normal(0, 0.02, n)]
    )
    return Trajectory(t, xyz, rph)


def _camera(rng, distorted=True):
    return PushbroomCamera(
        c_mm=tuple(rng.uniform(30.0, 50.0, 4)),
        pixel_mm=0.0065,
        distortion=tuple(rng.normal(0, [2e-5, 1e-8, 1e-4, 1e-4])) if distorted else (0, 0, 0, 0),
        x0_mm=float(rng.normal(0, 0.05)),
        y0_mm=float(rng.normal(0, 0.05)),
        boresight_rad=tuple(rng.normal(0, 0.01, 3)),
        lever_arm_m=tuple(rng.normal(0, 0.5, 3)),
    )


def _close(a, b):
    scale = np.max(np.abs(b), axis=-1, keepdims=True)
    assert np.all(np.abs(a - b) <= REL * scale), np.max(np.abs(a - b) / scale)


def _lines(rng, m, k, row_px=None):
    t_line = np.sort(rng.uniform(0.5, 19.5, m))
    x = np.arange(k) - (k - 1) / 2 + rng.normal(0, 0.2)
    xy = np.column_stack([np.tile(x, m), np.zeros(m * k)])
    if row_px is not None:
        xy[:, 1] += np.repeat(row_px, k)
    return np.repeat(t_line, k), xy, t_line


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("distorted", [False, True])
def test_rays_by_line_equal_the_per_pixel_formula_over_blocks(seed, distorted):
    """Line blocks as the orthomosaic asks for them (the trajectory read once per line
    through PerLine): every block's origins and directions equal the per-pixel formula.
    """
    rng = np.random.default_rng(seed)
    cam, traj = _camera(rng, distorted), _trajectory(rng)
    t_px, xy, t_line = _lines(rng, 60, 37)
    for a, b in ((0, 16), (16, 32), (32, 60), (59, 60)):
        sl = slice(a * 37, b * 37)
        band = int(rng.integers(0, 4))
        nav = PerLine(traj, t_line[a:b], t_px[sl], 37)
        o, d = cam.rays(xy[sl], t_px[sl], nav, band=band)
        o_ref, d_ref = reference_rays(cam, xy[sl], t_px[sl], traj, band)
        _close(o, o_ref)
        _close(d, d_ref)
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=0, atol=1e-15)


@pytest.mark.parametrize("seed", range(4))
def test_rays_per_pixel_bands_rows_and_irregular_lines(seed):
    """Pixels that are not the same on every line (rows per line, bands per pixel, lines of
    different lengths, times out of order) take the per-pixel directions, still one pose per
    run of equal times.
    """
    rng = np.random.default_rng(100 + seed)
    cam, traj = _camera(rng), _trajectory(rng)
    t_px, xy, _ = _lines(rng, 25, 11, row_px=rng.normal(0, 0.5, 25))
    band = rng.integers(0, 4, t_px.size)
    for args in (
        (xy, t_px, band),  # rows differ per line
        (xy[:, :], t_px, np.tile(rng.integers(0, 4, 11), 25)),  # bands per column
        (xy[3:200], t_px[3:200], band[3:200]),  # partial lines at both ends
        (xy[::-1], t_px[::-1], band[::-1]),  # descending times
        (xy[:1], t_px[:1], 2),  # one pixel
    ):
        o, d = cam.rays(args[0], args[1], traj, band=args[2])
        o_ref, d_ref = reference_rays(cam, *args[:2], traj, args[2])
        _close(o, o_ref)
        _close(d, d_ref)
    xy_same = np.tile(xy[:11], (25, 1))  # same pixels, bands changing per line
    band_line = np.repeat(rng.integers(0, 4, 25), 11)
    o, d = cam.rays(xy_same, t_px, traj, band=band_line)
    _close(d, reference_rays(cam, xy_same, t_px, traj, band_line)[1])


def test_rays_at_one_pose_per_pixel_and_broadcast_pose():
    rng = np.random.default_rng(7)
    cam = _camera(rng)
    n = 50
    xy = np.column_stack([rng.uniform(-900, 900, n), rng.normal(0, 1, n)])
    band = rng.integers(0, 4, n)
    xyz = rng.normal(0, 100, (n, 3))
    R = R_from_rpy(*rng.normal(0, 0.3, (3, n)))
    o, d = cam.rays_at(xy, band, xyz, R)
    o_ref, d_ref = reference_rays_at(cam, xy, band, xyz, R)
    _close(o, o_ref)
    _close(d, d_ref)
    o1, d1 = cam.rays_at(xy, band, xyz[:1], R[:1])  # one pose for every pixel
    o1_ref, d1_ref = reference_rays_at(
        cam, xy, band, np.repeat(xyz[:1], n, 0), np.repeat(R[:1], n, 0)
    )
    _close(o1, o1_ref)
    _close(d1, d1_ref)


def test_rays_one_time_for_every_pixel_and_mismatched_times():
    rng = np.random.default_rng(8)
    cam, traj = _camera(rng), _trajectory(rng)
    xy = np.column_stack([np.arange(9.0) - 4, np.zeros(9)])
    o, d = cam.rays(xy, 3.25, traj, band=1)
    o_ref, d_ref = reference_rays(cam, xy, np.full(9, 3.25), traj, 1)
    _close(o, o_ref)
    _close(d, d_ref)
    with pytest.raises(InputError, match="t_s must be one time or one per pixel"):
        cam.rays(xy, np.full(8, 3.25), traj)
    with pytest.raises(InputError, match="band must be one index or one per pixel"):
        cam.rays(xy, np.full(9, 3.25), traj, band=np.zeros(8, int))
    with pytest.raises(InputError, match="band indices"):
        cam.rays(xy, np.full(9, 3.25), traj, band=4)


def test_line_runs():
    np.testing.assert_array_equal(line_runs(np.array([1.0, 1.0, 2.0, 2.0, 2.0, 1.0])), [0, 2, 5, 6])
    np.testing.assert_array_equal(line_runs(np.zeros(0)), [0])
    np.testing.assert_array_equal(line_runs(np.array([5.0])), [0, 1])
