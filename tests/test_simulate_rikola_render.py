"""The Rikola renderer's compiled per-pixel geometry equals the numpy float32 form it replaced
bit for bit (issue 41), and the ideal-coordinate grids are shared between Renderers of the same
camera only.
"""

import numpy as np
import pytest

from hsgeo.rotations import R_from_opk
from hsgeo.simulate._rikola_render import plate_texel_maps
from hsgeo.simulate.rikola import Renderer, make_truth
from hsgeo.simulate.scenarios import load_scenario


@pytest.fixture(scope="module")
def cfg():
    return load_scenario("rikola_bench")


@pytest.fixture(scope="module")
def truth(cfg):
    return make_truth(cfg, np.random.default_rng([3, 0]), n_cubes=4)  # with the EOP drift


def _numpy_maps(ideal, R, f, pose, x_min, y_max, texel):
    """The renderer's numpy form before the kernel (main dcc5cc5), kept as the reference."""
    ix, iy = ideal[..., 0], ideal[..., 1]
    d = [R[i, 0] * ix + R[i, 1] * iy - R[i, 2] * f for i in range(3)]
    with np.errstate(divide="ignore", invalid="ignore"):
        tt = np.float32(-pose[5]) / d[2]
        X = np.float32(pose[3]) + tt * d[0]
        Y = np.float32(pose[4]) + tt * d[1]
    col = (X - np.float32(x_min)) / np.float32(texel) - np.float32(0.5)
    row = (np.float32(y_max) - Y) / np.float32(texel) - np.float32(0.5)
    bad = ~(tt > 0)
    col[bad] = -1e6
    row[bad] = -1e6
    return col, row


@pytest.mark.parametrize("cube, band", [(0, 5), (1, 20), (2, 12), (3, 1), (3, 25)])
def test_texel_maps_bit_identical_to_the_numpy_form(cfg, truth, cube, band):
    r = Renderer(cfg, truth)
    ideal = r._grid(truth.sensor(band))
    pose = truth.band_pose(cube, band)
    R = R_from_opk(*pose[:3]).astype(np.float32)
    f = np.float32(truth.f_mm[truth.band_row(band)])
    x_min, _, _, y_max = cfg.plate.extent_mm
    got = plate_texel_maps(ideal, R, f, pose, x_min, y_max, cfg.plate.texel_mm)
    want = _numpy_maps(ideal, R, f, pose, x_min, y_max, cfg.plate.texel_mm)
    for g, w in zip(got, want, strict=True):
        assert g.dtype == np.float32 and g.shape == w.shape
        assert np.array_equal(g, w)


def test_texel_maps_rays_missing_the_plate():
    """Rays parallel to the plate or pointing away from it get the out-of-texture marker."""
    ideal = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]], np.float32)
    R = np.eye(3, dtype=np.float32)
    pose = np.array([0.0, 0.0, 0.0, 5.0, 6.0, -100.0])  # camera below the plate, looking down
    got = plate_texel_maps(ideal, R, np.float32(10.0), pose, 0.0, 50.0, 0.25)
    want = _numpy_maps(ideal, R, np.float32(10.0), pose, 0.0, 50.0, 0.25)
    assert np.all(got[0] == -1e6) and np.array_equal(got[0], want[0])
    flat = np.array([[[0.0, 0.0], [1.0, 1.0]]], np.float32)
    for z0 in (-100.0, 100.0):  # d_z = 0: t = ±inf, as the numpy form (NaN or the marker)
        p = np.r_[pose[:5], z0]
        got = plate_texel_maps(flat, R, np.float32(0.0), p, 0.0, 50.0, 0.25)
        want = _numpy_maps(flat, R, np.float32(0.0), p, 0.0, 50.0, 0.25)
        for g, w in zip(got, want, strict=True):
            assert np.array_equal(g, w, equal_nan=True)


def test_grids_shared_only_between_the_same_camera(cfg, truth):
    off = make_truth(cfg, np.random.default_rng([3, 0]), n_cubes=4, eop_drift=False)
    shared: dict = {}
    a, b = Renderer(cfg, truth, shared), Renderer(cfg, off, shared)
    assert b._grid(2) is a._grid(2)  # same principal point and distortion: computed once
    assert len(shared) == 1
    other = make_truth(cfg, np.random.default_rng([3, 0]), n_cubes=4)
    other.KP = other.KP * 1.01
    c = Renderer(cfg, other, shared)
    assert c._grid(2) is not a._grid(2) and len(shared) == 2
    np.testing.assert_array_equal(b.render(1, 16, 5), Renderer(cfg, off).render(1, 16, 5))
