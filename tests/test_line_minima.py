import numpy as np
import pytest

from hsgeo import InputError, ObservationError
from hsgeo.measure.line_minima import associate_by_order, find_minima


def profile(centres, sigma=1.0, n=300, depth=0.6):
    x = np.arange(n)
    p = np.ones(n)
    for c in centres:
        p -= depth * np.exp(-0.5 * ((x - c) / sigma) ** 2)
    return 1000 * p


@pytest.mark.parametrize("method,tol", [("parabola", 0.05), ("centroid", 0.02), ("pixel", 0.5)])
def test_subpixel_positions(method, tol):
    c = 20.0 + 23.7 * np.arange(10) + np.linspace(0, 0.9, 10)
    z, contrast = find_minima(profile(c), method=method)
    np.testing.assert_allclose(z, c, atol=tol)
    assert np.all(contrast > 0.5)


def test_wide_dark_region_and_noise_ignored():
    p = profile([50.0, 80.0])
    p[150:] = 60.0 + np.random.default_rng(0).normal(0, 5, 150)  # background beyond the board
    z, _ = find_minima(p)
    assert z.size == 2


def test_errors():
    with pytest.raises(InputError, match="NaN"):
        find_minima(np.r_[np.ones(20), np.nan])
    with pytest.raises(InputError, match="method"):
        find_minima(np.ones(50), method="gauss")
    with pytest.raises(ObservationError, match="found 2 dark features but the pattern has 3"):
        associate_by_order([3.0, 1.0], [0, 1, 2])
    ids, z = associate_by_order([3.0, 1.0], [7, 8])
    assert ids.tolist() == [7, 8] and z.tolist() == [1.0, 3.0]
