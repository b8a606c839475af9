"""A check point the adjustment cannot determine (its covariance is not finite: a square seen
along one ray only) is left out of the LP chapter's check-point statistics and named, instead
of stopping the chapter (``hsgeo reproduce lp-observations --seed 2 --scale 0.05`` stopped with
"describe: data contain 13 non-finite value(s)" before)."""

from types import SimpleNamespace

import numpy as np

from hsgeo.reproduce.lp_runs import _check_points


class _Result:
    """An adjustment result with four points; point 2's covariance is not finite."""

    def __init__(self):
        self.xyz = np.arange(12.0).reshape(4, 3)
        c = np.diag(np.arange(1.0, 13.0)) * 1e-4
        c[6:9, :] = np.nan
        c[:, 6:9] = np.nan
        self.cov = c

    def value(self, name):
        assert name == "points_m"
        return self.xyz

    def point_covariance(self, index, joint):
        rows = np.concatenate([np.arange(3 * i, 3 * i + 3) for i in index])
        return self.cov[np.ix_(rows, rows)]


def test_undetermined_check_point_left_out_and_named():
    r = SimpleNamespace(result=_Result())
    pin = SimpleNamespace(point_ids=np.array(["a", "b", "c", "d"]))
    obs = SimpleNamespace(square_ids=["a", "b", "c", "d"])
    truth = SimpleNamespace(square_xyz_m=np.zeros((4, 3)))
    E, cov, ids, lost = _check_points(r, pin, obs, truth, ["b", "c", "d"])
    assert lost == ["c"]
    assert list(ids) == ["b", "d"]
    np.testing.assert_array_equal(E, r.result.xyz[[1, 3]])
    assert cov.shape == (6, 6) and np.all(np.isfinite(cov))
    np.testing.assert_array_equal(np.diag(cov), np.r_[4:7, 10:13] * 1e-4)


def test_all_determined_keeps_every_check_point():
    res = _Result()
    res.cov = np.diag(np.arange(1.0, 13.0))
    r = SimpleNamespace(result=res)
    pin = SimpleNamespace(point_ids=np.array(["a", "b", "c", "d"]))
    obs = SimpleNamespace(square_ids=["a", "b", "c", "d"])
    truth = SimpleNamespace(square_xyz_m=np.ones((4, 3)))
    E, cov, ids, lost = _check_points(r, pin, obs, truth, ["a", "c"])
    assert lost == [] and list(ids) == ["a", "c"] and cov.shape == (6, 6)
    np.testing.assert_array_equal(E, res.xyz[[0, 2]] - 1.0)
