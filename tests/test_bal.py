"""BAL ("Bundle Adjustment in the Large"): reader, Snavely's camera, the adjustment, the CLI.

The whole-problem test compares with Ceres Solver (through pycolmap 4.2.1) on the same
observations, values from ``bench/bench_bal.py`` (see ``CERES_*`` below).
"""

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hsgeo.adjust.checks import analytic_jacobian, check_jacobian, numerical_jacobian
from hsgeo.cli import main
from hsgeo.errors import InputError
from hsgeo.io.bal import BALProblem, ladybug_path, read_bal
from hsgeo.sensors.bal import SnavelyReprojection, in_front
from hsgeo.workflows.bal import BAL_OPTIONS, adjust_bal, gauge_fix, prepare

# Ceres Solver through pycolmap 4.2.1 on the Ladybug problem 49-7776 with the 31 observations
# behind their camera left out (31,812 observations), RADIAL cameras, gauge TWO_CAMS_FROM_WORLD,
# one thread; `python bench/bench_bal.py --case ceres` (function_tolerance 1e-6: 31 iterations)
# and `--case ceres_converged` (function_tolerance 1e-12: 104 iterations), run 2026-11-23.
CERES_INITIAL_COST = 850802.0903411749
CERES_FINAL_COST = 13308.493219888911
CERES_CONVERGED_COST = 13308.405954245813

TINY = """2 3 5
0 0 -3.0 1.5
1 0 -2.5 1.0
0 1 4.0 -2.0
1 1 3.5 -2.5
1 2 0.5 0.25
0.01 -0.02 0.03
0.1 0.2 -5.0
500.0
-1e-7
2e-13
-0.02 0.01 0.005
-0.3 0.1 -4.0
480.0 0.0 0.0
1.0 2.0 3.0
-1.0 0.5 2.0
0.0 0.0 1.0
"""


def _write(tmp_path, text, name="p.txt"):
    f = tmp_path / name
    f.write_text(text)
    return f


def test_read_tiny(tmp_path):
    p = read_bal(_write(tmp_path, TINY))
    assert (p.n_cameras, p.n_points, p.n_observations) == (2, 3, 5)
    np.testing.assert_array_equal(p.camera_index, [0, 1, 0, 1, 1])
    np.testing.assert_array_equal(p.point_index, [0, 0, 1, 1, 2])
    np.testing.assert_array_equal(p.xy_px[4], [0.5, 0.25])
    # values may be spread over lines in any way: 9 per camera, 3 per point
    np.testing.assert_array_equal(
        p.cameras[0], [0.01, -0.02, 0.03, 0.1, 0.2, -5.0, 500, -1e-7, 2e-13]
    )
    np.testing.assert_array_equal(p.cameras[1, 6:], [480.0, 0.0, 0.0])
    np.testing.assert_array_equal(p.points[2], [0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    "edit, where",
    [
        (lambda t: t.replace("2 3 5", "2 3"), "line 1"),
        (lambda t: t.replace("1 1 3.5 -2.5", "1 x 3.5 -2.5"), "line 5"),
        (lambda t: t.replace("1 1 3.5 -2.5", "1 7 3.5 -2.5"), "line 5: camera index 1 or point"),
        (lambda t: t.replace("1 2 0.5 0.25", "1 2 0.5"), "line 6"),
        (lambda t: t.replace("500.0", "nan"), "line 9"),
        (lambda t: t.replace("-1e-7", "abc"), "line 10"),
        (lambda t: t.rsplit("\n", 2)[0] + "\n", "the file ends after"),
        (lambda t: t + "7.0\n", "more values than"),
    ],
)
def test_read_malformed_names_file_and_line(tmp_path, edit, where):
    f = _write(tmp_path, edit(TINY))
    with pytest.raises(InputError, match=where) as e:
        read_bal(f)
    assert str(f) in str(e.value) and "\n" not in str(e.value)


def test_read_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_bal(tmp_path / "absent.txt")


@pytest.fixture(scope="module")
def ladybug():
    return read_bal(ladybug_path())


def test_read_ladybug_counts(ladybug):
    p = ladybug
    assert (p.n_cameras, p.n_points, p.n_observations) == (49, 7776, 31843)
    # first observation and first camera as in the file
    np.testing.assert_array_equal(p.xy_px[0], [-332.65, 262.09])
    assert p.cameras[0, 6] == pytest.approx(399.75152639358436, rel=1e-15)


def test_model_matches_formula_written_out(ladybug):
    """Residuals against BAL's equations written out here with scipy's rotation."""
    p = ladybug
    sel = np.arange(0, p.n_observations, 997)
    b = SnavelyReprojection(p.camera_index[sel], p.point_index[sel], p.xy_px[sel])
    r, _ = b.evaluate({"cameras": p.cameras, "points": p.points}, False)
    c = p.cameras[p.camera_index[sel]]
    P = Rotation.from_rotvec(c[:, :3]).apply(p.points[p.point_index[sel]]) + c[:, 3:6]
    q = -P[:, :2] / P[:, 2:3]
    n2 = (q**2).sum(1)
    pred = c[:, 6:7] * (1 + c[:, 7:8] * n2[:, None] + c[:, 8:9] * n2[:, None] ** 2) * q
    np.testing.assert_allclose(r.reshape(-1, 2), pred - p.xy_px[sel], rtol=1e-12, atol=1e-9)


def test_jacobian_matches_finite_differences(ladybug):
    p = ladybug.select_cameras([0, 1, 2, 3])
    b = SnavelyReprojection(p.camera_index, p.point_index, p.xy_px)
    vals = {"cameras": p.cameras.copy(), "points": p.points.copy()}
    assert check_jacobian(b, vals, "points") < 1e-7
    # k1, k2 are ~1e-7 and ~1e-13: absolute steps for them (the model is linear in them)
    step = np.maximum(np.abs(p.cameras), 1.0) * 1e-6
    a = analytic_jacobian(b, vals, "cameras")
    n = numerical_jacobian(b, vals, "cameras", step.ravel())
    scale = np.abs(n).max(axis=0)
    assert np.all(scale > 0)  # every camera entry acts on the residuals
    assert np.max(np.abs(a - n) / scale) < 1e-6


def test_prepare_drops_points_behind_cameras(ladybug):
    prob, n_dropped = prepare(ladybug)
    assert n_dropped == 31 and prob.n_observations == 31843 - 31
    assert in_front(prob.cameras, prob.points, prob.camera_index, prob.point_index).all()


def test_cost_is_invariant_under_a_similarity(ladybug):
    """The 7-parameter gauge: a similarity of the whole block changes no residual."""
    p = ladybug.select_cameras(range(6))
    b = SnavelyReprojection(p.camera_index, p.point_index, p.xy_px)
    r0, _ = b.evaluate({"cameras": p.cameras, "points": p.points}, False)
    Q = Rotation.from_rotvec([0.3, -0.2, 0.5])
    s, T = 2.5, np.array([1.0, -3.0, 0.5])
    X = s * Q.apply(p.points) + T  # X' = s Q X + T
    cams = p.cameras.copy()
    R = Rotation.from_rotvec(cams[:, :3])
    R2 = R * Q.inv()  # R' = R Qᵀ,  t' = s t − R' T
    cams[:, :3] = R2.as_rotvec()
    cams[:, 3:6] = s * cams[:, 3:6] - R2.apply(T)
    r1, _ = b.evaluate({"cameras": cams, "points": X}, False)
    np.testing.assert_allclose(r1, r0, atol=1e-8)
    fixed = gauge_fix(p.cameras)
    assert len(fixed) == 7 and fixed[:6] == [(0, j) for j in range(6)] and fixed[6][0] == 1


def _gradient(prob, vals, fixed):
    """Jᵀr of the free entries (the cost's gradient), by block."""
    b = SnavelyReprojection(prob.camera_index, prob.point_index, prob.xy_px)
    r, jac = b.evaluate(vals, True)
    g = {}
    for name, J in jac.items():
        k = J.d.shape[-1]
        out = np.zeros(vals[name].size)
        idx = (J.index[:, 0, None] * k + np.arange(k)).ravel()
        np.add.at(out, idx, (J.d[:, 0] * r[:, None]).ravel())
        g[name] = out.reshape(vals[name].shape)
    for i, j in fixed:
        g["cameras"][i, j] = 0.0
    return g


def test_subset_adjusts_to_a_stationary_point(ladybug):
    """5 cameras and the points they share: the cost decreases and the gradient vanishes."""
    prob = ladybug.select_cameras(range(5))
    assert prob.n_cameras == 5 and prob.n_points > 100
    fit = adjust_bal(prob, BAL_OPTIONS.replace(ftol=1e-14))
    assert fit.result.converged
    assert fit.final_cost < 0.5 * fit.initial_cost
    h = fit.result.cost_history
    assert all(b <= a for a, b in zip(h, h[1:], strict=False))
    prob, _ = prepare(prob)  # the observations adjust_bal adjusted
    g0 = _gradient(prob, {"cameras": prob.cameras, "points": prob.points}, fit.fixed)
    vals = {n: fit.result.value(n) for n in ("cameras", "points")}
    g1 = _gradient(prob, vals, fit.fixed)
    # each entry's gradient times its scale (the first-order change of the cost for a
    # relative change of the parameter), against the same at the initial values
    for name in ("cameras", "points"):
        x = np.abs(vals[name]) if name == "cameras" else np.abs(vals[name]).max()
        assert np.max(np.abs(g1[name]) * x) < 1e-6 * np.max(np.abs(g0[name]) * x)


def _bal_text(p: BALProblem) -> str:
    lines = [f"{p.n_cameras} {p.n_points} {p.n_observations}"]
    lines += [
        f"{c} {q} {float(x)!r} {float(y)!r}"
        for c, q, (x, y) in zip(p.camera_index, p.point_index, p.xy_px, strict=True)
    ]
    lines += [repr(float(v)) for v in np.concatenate([p.cameras.ravel(), p.points.ravel()])]
    return "\n".join(lines) + "\n"


def test_cli_adjust_bal(tmp_path, ladybug, capsys):
    f = _write(tmp_path, _bal_text(ladybug.select_cameras(range(4))), "four.txt")
    assert main(["adjust-bal", str(f), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_cameras"] == 4 and out["converged"]
    assert out["final_cost"] < out["initial_cost"]
    assert main(["adjust-bal", str(f)]) == 0
    text = capsys.readouterr().out
    assert "iterations" in text and "cost ½Σr²" in text


def test_cli_adjust_bal_malformed_exits_2(tmp_path, capsys):
    f = _write(tmp_path, TINY.replace("0 1 4.0 -2.0", "0 1 4.0 oops"))
    assert main(["adjust-bal", str(f)]) == 2
    err = capsys.readouterr().err
    assert "line 4" in err and err.count("\n") == 1


@pytest.mark.slow
def test_ladybug_reaches_ceres_cost(ladybug):
    """The whole problem: hsgeo's minimum is Ceres' (pycolmap 4.2.1, values above)."""
    fit = adjust_bal(ladybug)
    assert fit.n_observations == 31812
    assert fit.initial_cost == pytest.approx(CERES_INITIAL_COST, rel=1e-9)
    # at or below Ceres' final cost (Ceres stops at a relative decrease below 1e-6 per
    # iteration), and not below the converged minimum's cost
    assert fit.final_cost <= CERES_FINAL_COST * (1 + 1e-6)
    assert fit.final_cost >= CERES_CONVERGED_COST * (1 - 1e-6)
