"""The compiled nearest-cell search (hsgeo._nearest) against a kd-tree (pykdtree)."""

import numpy as np
import pytest
from pykdtree.kdtree import KDTree

from hsgeo._nearest import nearest_cells


@pytest.mark.parametrize("radius_m", [0.2, 0.38, 1.1])
def test_nearest_cells_is_the_kd_trees_answer(radius_m):
    rng = np.random.default_rng(7)
    res = 0.3
    x = 500000.0 + res * (np.arange(57) + 0.5)
    y = 6600000.0 - res * (np.arange(43) + 0.5)
    n = 4000  # scattered pixels, some beyond the grid's edge
    px = rng.uniform(x[0] - 2.0, x[-1] + 2.0, n)
    py = rng.uniform(y[-1] - 2.0, y[0] + 2.0, n)
    got = nearest_cells(x, y, px, py, radius_m)
    X, Y = np.meshgrid(x, y)
    dist, idx = KDTree(np.column_stack([px, py])).query(
        np.column_stack([X.ravel(), Y.ravel()]), k=1, distance_upper_bound=radius_m
    )
    want = np.where(np.isfinite(dist) & (dist <= radius_m), idx.astype(np.int64), -1)
    assert (want >= 0).any()
    np.testing.assert_array_equal(got, want)


def test_nearest_cells_empty_and_tie():
    x, y = np.array([0.5, 1.5]), np.array([1.5, 0.5])
    assert (nearest_cells(x, y, np.array([]), np.array([]), 1.0) == -1).all()
    # two pixels at the same place: the first given wins, as documented
    got = nearest_cells(x, y, np.array([0.5, 0.5]), np.array([1.5, 1.5]), 0.1)
    np.testing.assert_array_equal(got, [0, -1, -1, -1])
