"""hsgeo.workflows._lp_height: where the tie points' rays meet, and a terrain height refused.

A stand-in camera whose ray of an observation goes from its strip's aircraft position (the
strip is encoded in ``t_s``) through a known ground point: the intersection must return that
point's height exactly, and the check must refuse a plane beyond 10 % of the height above
ground (plus half the spread of the points' heights) and accept one inside it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hsgeo.errors import InputError
from hsgeo.workflows._lp_height import (
    MAX_HEIGHT_ERROR_OF_AGL,
    check_terrain_height,
    tie_point_heights,
)

AIRCRAFT = {0: (-400.0, 0.0, 2000.0), 1: (400.0, 0.0, 2100.0), 2: (0.0, 300.0, 1900.0)}


class _Camera:
    """Rays from the aircraft of strip ``int(t_s)`` through ground point ``x_px`` of GROUND."""

    def __init__(self, ground):
        self.ground = ground

    def rays(self, xy, t_s, trajectory, band=0):
        o = np.array([AIRCRAFT[int(t)] for t in t_s])
        g = self.ground[np.asarray(xy[:, 0], int)]
        return o, g - o


def _table(n_points, strips=(0, 1, 2)):
    rows = [
        {"point_id": f"p{i}", "band": 0, "t_s": float(s), "x_px": float(i), "y_px": 0.0,
         "strip": f"s{s}"}
        for i in range(n_points)
        for s in strips
    ]  # fmt: skip
    return pd.DataFrame(rows)


def _ground(n, rng):
    return np.column_stack(
        [rng.uniform(-300, 300, n), rng.uniform(-300, 300, n), rng.uniform(95.0, 105.0, n)]
    )


def test_rays_meet_at_the_points_height():
    g = _ground(20, np.random.default_rng(1))
    h, agl = tie_point_heights(_table(20), _Camera(g), None)
    order = np.argsort([f"p{i}" for i in range(20)])  # np.unique sorts the ids as text
    assert np.allclose(h, g[order, 2], atol=1e-6)
    assert np.allclose(agl, 2000.0 - g[order, 2], atol=1e-6)


def test_a_point_of_one_strip_is_left_out():
    g = _ground(5, np.random.default_rng(2))
    h, _ = tie_point_heights(_table(5, strips=(1,)), _Camera(g), None)
    assert h.size == 0


def test_height_far_off_is_refused_near_is_accepted():
    g = _ground(30, np.random.default_rng(3))
    cam, tab = _Camera(g), _table(30)
    tol = MAX_HEIGHT_ERROR_OF_AGL * 1900.0  # about 10 % of the 1,900 m above the points
    check_terrain_height(tab, cam, None, 100.0, "--height", "give {h:.0f}")
    check_terrain_height(tab, cam, None, 100.0 + 0.8 * tol, "--height", "give {h:.0f}")
    with pytest.raises(InputError, match=r"--height 1000 m .* meet at 10\d\.\d m.*give 10\d"):
        check_terrain_height(tab, cam, None, 1000.0, "--height", "give {h:.0f}")
    with pytest.raises(InputError, match="--height -200"):
        check_terrain_height(tab, cam, None, -200.0, "--height", "give {h:.0f}")


def test_too_few_points_say_nothing():
    g = _ground(2, np.random.default_rng(4))
    check_terrain_height(_table(2), _Camera(g), None, 5000.0, "--height", "{h}")
