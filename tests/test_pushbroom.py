import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.adjust import adjust, identifiability
from hsgeo.adjust.checks import analytic_jacobian, check_jacobian
from hsgeo.pushbroom_ba import CameraPrior, build_problem
from hsgeo.sensors.pushbroom import PushbroomLines
from hsgeo.simulate.pushbroom_campaign import simulate
from hsgeo.stats import nmad


def _problem(camp, with_gcp=True, node_interval_s=10.0, y_as_time=False):
    cfg = camp.cfg
    cam = CameraPrior(n_bands=len(cfg.c_offsets_um), x0_mm=cfg.x0_mm,
                      lever_arm_m=tuple(camp.lever_arm_measured_m))
    return build_problem(
        camp.obs, camp.n_points, cam, node_interval_s=node_interval_s,
        t_span_s=(0.0, camp.nodes.t_end_s), node_prior_mean=camp.node_prior_mean,
        gcp_index=camp.gcp_index if with_gcp else None,
        gcp_xyz_m=camp.gcp_xyz_m if with_gcp else None, y_as_time=y_as_time)


@pytest.fixture(scope="module")
def tiny():
    return simulate(0.001, rng=3)


def test_model_is_exact_at_truth_noise_free():
    camp = simulate(0.001, rng=5, noise_free=True)
    _, blocks, _ = _problem(camp)
    r, _ = blocks[0].evaluate(camp.truth, False)
    assert np.max(np.abs(r)) < 1e-9


@pytest.mark.parametrize("name,step", [
    ("points_m", 1e-3), ("boresight_rad", 1e-7), ("lever_arm_m", 1e-4),
    ("distortion", [1e-7, 1e-9, 1e-7, 1e-7]), ("c_mm", 1e-5)])
@pytest.mark.parametrize("y_as_time", [False, True])
def test_jacobians_against_finite_differences(tiny, name, step, y_as_time):
    _, blocks, _ = _problem(tiny, y_as_time=y_as_time)
    vals = dict(tiny.truth)
    vals["nodes"] = vals["nodes"] + 0.01  # away from zero corrections
    assert check_jacobian(blocks[0], vals, name, step) < 1e-6


@pytest.mark.parametrize("y_as_time", [False, True])
def test_node_jacobian_against_finite_differences(tiny, y_as_time):
    """Every correction of the nodes that the first observations touch."""
    _, blocks, _ = _problem(tiny, y_as_time=y_as_time)
    b = blocks[0]
    vals = dict(tiny.truth)
    vals["nodes"] = vals["nodes"] + 0.01
    A = analytic_jacobian(b, vals, "nodes")
    nodes = np.unique(b._basis[0][:3])
    for j in nodes:
        for k, h in enumerate([1e-4] * 3 + [1e-7] * 3):
            vp, vm = dict(vals), dict(vals)
            vp["nodes"], vm["nodes"] = vals["nodes"].copy(), vals["nodes"].copy()
            vp["nodes"][j, k] += h
            vm["nodes"][j, k] -= h
            num = (b.evaluate(vp, False)[0] - b.evaluate(vm, False)[0]) / (2 * h)
            col = A[:, j * 6 + k]
            assert np.max(np.abs(col - num)) <= 1e-6 * max(np.max(np.abs(num)), 1e-12)


def test_noise_free_recovers_truth():
    camp = simulate(0.001, rng=11, noise_free=True)
    p, blocks, _ = _problem(camp, y_as_time=True)
    assert identifiability(p, blocks).full_rank
    res = adjust(p, blocks, ftol=1e-15)
    for k, v in camp.truth.items():
        np.testing.assert_allclose(res.value(k), v, rtol=0, atol=1e-7, err_msg=k)


@pytest.mark.parametrize("seed", [0])
def test_truth_within_3_sigma_small_scale(seed):
    camp = simulate(0.01, rng=seed)
    p, blocks, _ = _problem(camp, y_as_time=True)
    res = adjust(p, blocks, reject_k=5.0, reject_every_iteration=True)
    for k in ["boresight_rad", "lever_arm_m", "distortion", "c_mm"]:
        z = (res.value(k) - camp.truth[k]) / res.sigma(k)
        assert np.max(np.abs(z)) < 3.5, (k, z)  # 17 values: family-wise ≈ 1 % false alarms
    # ~1,000 node corrections: a few |z| > 3 are expected (0.27 %), so assert the coverage and
    # the spread of z rather than max |z| < 3
    z = (res.value("nodes") - camp.truth["nodes"]) / res.sigma("nodes")
    assert np.mean(np.abs(z) < 3) >= 0.99
    assert 0.8 <= np.std(z) <= 1.2, np.std(z, axis=0)
    r = res.residuals(0).reshape(-1, 2)[~res.outliers(0)]
    assert np.all((nmad(r, axis=0) > 0.2) & (nmad(r, axis=0) < 0.5))
    cp = res.value("points_m")[camp.cp_index] - camp.truth["points_m"][camp.cp_index]
    assert np.all(nmad(cp[:, :2], axis=0) < 0.15)  # half the 0.3 m GSD
    # most simulated gross errors are found
    assert np.mean(res.outliers(0)[camp.obs["outlier"]]) > 0.75  # 3 px ones can hide


def test_bad_input(tiny):
    o = tiny.obs
    _, blocks, nodes = _problem(tiny)
    with pytest.raises(InputError, match="shape"):
        PushbroomLines(o["point"], o["band"][:-1], o["t_s"], o["xy_px"], o["xyz_nav_m"],
                       o["rpy_nav_rad"], nodes, 0.0065)
    with pytest.raises(InputError, match="pixel pitch"):
        PushbroomLines(o["point"], o["band"], o["t_s"], o["xy_px"], o["xyz_nav_m"],
                       o["rpy_nav_rad"], nodes, 0.0)
    with pytest.raises(InputError, match="scale"):
        simulate(0.0)
    obs = dict(o)
    obs["point"] = o["point"].copy()
    obs["point"][obs["point"] == 5] = 6  # point 5 unobserved
    with pytest.raises(InputError, match="fewer than two"):
        build_problem(obs, tiny.n_points, CameraPrior(n_bands=7))


def test_same_seed_same_bits():
    a, b = simulate(0.001, rng=7), simulate(0.001, rng=7)
    assert np.array_equal(a.obs["xy_px"], b.obs["xy_px"])
    assert np.array_equal(a.truth["nodes"], b.truth["nodes"])


def test_compiled_schur_equals_generic_on_pushbroom(tiny, monkeypatch):
    from hsgeo.adjust import engine as E

    p, blocks, _ = _problem(tiny)
    lay = E._Layout(p)
    sy = E._evaluate(lay, blocks, [np.ones(b.m, bool) for b in blocks], True)
    got = {}
    for fast in (True, False):
        monkeypatch.setattr(E, "FAST", fast)
        ne = E._normal(lay, sy)
        S, rhs, _, _ = E._reduced(lay, ne, 1e-4)
        got[fast] = (S, rhs)
    for a, b in zip(got[True], got[False], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.max(np.abs(b)))


def test_point_covariance_subset_equals_all(tiny):
    p, blocks, _ = _problem(tiny)
    res = adjust(p, blocks, reject_k=5.0)
    sub = res.point_covariance(index=tiny.cp_index)
    full = res.point_covariance()[tiny.cp_index]
    np.testing.assert_allclose(sub, full, rtol=1e-12)


@pytest.mark.parametrize("y_as_time", [False, True])
def test_compiled_block_equals_numpy_block(tiny, y_as_time):
    _, blocks, _ = _problem(tiny, y_as_time=y_as_time)
    b = blocks[0]
    vals = dict(tiny.truth)
    vals["nodes"] = vals["nodes"] + 0.01
    r1, j1 = b.evaluate(vals, True)
    r2, j2 = b.evaluate_numpy(vals, True)
    np.testing.assert_allclose(r1, r2, rtol=0, atol=1e-9)
    for k in j2:
        a, c = j1[k], j2[k]
        if hasattr(c, "d"):
            a = a.expanded()  # the compiled block returns the node Jacobian factored
            np.testing.assert_array_equal(a.index, c.index)
            a, c = a.d, c.d
        np.testing.assert_allclose(a, c, rtol=1e-9, atol=1e-9 * np.max(np.abs(c)), err_msg=k)


@pytest.mark.parametrize("lam", [0.0, 1e-3])
@pytest.mark.parametrize("fix_node", [False, True])
def test_factored_node_jacobian_compiled_equals_generic(tiny, monkeypatch, lam, fix_node):
    """The compiled path's factored spline Jacobian forms the same normal equations as scipy.

    ``fix_node`` fixes one node entry, which makes the engine expand the factored Jacobian
    into ordinary slots (non-contiguous columns).
    """
    from hsgeo.adjust import engine as E

    p, blocks, _ = _problem(tiny, y_as_time=True)
    if fix_node:
        p.fix("nodes", index=(3, 4))
    lay = E._Layout(p)
    out = {}
    for fast in (True, False):
        monkeypatch.setattr(E, "FAST", fast)
        sy = E._evaluate(lay, blocks, [np.ones(b.m, bool) for b in blocks], True)
        assert (sy.Jrc.fcol.shape[1] == 4) == (fast and not fix_node)
        ne = E._normal(lay, sy)
        S_, rhs, _, _ = E._reduced(lay, ne, lam)
        dc, dp = E._step(lay, ne, lam)
        out[fast] = (S_, rhs, dc, dp, ne.Ncc)
    for a, b in zip(out[True], out[False], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.max(np.abs(b)))
