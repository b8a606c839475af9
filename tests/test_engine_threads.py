"""The engine's threads (issue 20): chosen by the size of the problem, restored afterwards, and
never a cause of different numbers or different decisions (rank, datum, covariance)."""

import numba
import numpy as np
import pytest
from test_engine import _bearing_params
from threadpoolctl import threadpool_info
from toy_models import bearing_scene

from hsgeo import DatumError, InputError
from hsgeo.adjust import Parameters, SolverOptions, adjust
from hsgeo.adjust.threads import (
    MAX_CHUNKS,
    PARALLEL_MIN_ROWS,
    chunks,
    engine_threads,
    over_chunks,
    pool_size,
    resolve,
)
from hsgeo.io.bal import ladybug_path, read_bal
from hsgeo.sensors.frame import FrameOpenCV, project_opencv
from hsgeo.workflows.bal import BAL_OPTIONS, adjust_bal


def _blas_threads():
    return {i["filepath"]: i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


@pytest.mark.parametrize("value", [0, -1, 1.5, True, "all", None])
def test_threads_option_is_checked(value):
    with pytest.raises(InputError, match="threads"):
        SolverOptions(threads=value)


@pytest.mark.parametrize("value", [0, 1.0, "auto"])
def test_blas_threads_option_is_checked(value):
    with pytest.raises(InputError, match="blas_threads"):
        SolverOptions(blas_threads=value)


def test_auto_is_serial_below_the_threshold_and_the_pool_above():
    assert resolve("auto", PARALLEL_MIN_ROWS - 1) == 1
    assert resolve("auto", PARALLEL_MIN_ROWS) == pool_size()
    assert resolve(1, 10**9) == 1
    assert resolve(10**6, 10) == pool_size()  # never more than numba's pool


def test_chunks_depend_on_the_size_alone():
    assert chunks(10, 2000) == 1
    assert chunks(10**9, 2000) == MAX_CHUNKS


def test_settings_are_restored_and_blas_limited_inside():
    before_numba, before_blas = numba.get_num_threads(), _blas_threads()
    with engine_threads("auto", 10, blas=2) as n:
        assert n == 1 and numba.get_num_threads() == 1
        assert set(_blas_threads().values()) == {2}
    assert numba.get_num_threads() == before_numba and _blas_threads() == before_blas


def _frame_block(n_points, seed=0):
    """A frame-camera bundle block with tie points, large enough for several chunks."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(6), np.arange(5))
    C = np.column_stack([gx.ravel() * 60.0, gy.ravel() * 60.0, np.full(gx.size, -300.0)])
    poses = np.column_stack([rng.normal(0, 0.02, (C.shape[0], 3)), C])
    X = np.column_stack(
        [rng.uniform(0, 300, n_points), rng.uniform(0, 240, n_points), rng.normal(0, 5, n_points)]
    )
    intr = np.array([1000.0, 1000.0, 500.0, 400.0])
    dist = np.zeros(5)
    d = np.hypot(C[None, :, 0] - X[:, None, 0], C[None, :, 1] - X[:, None, 1])
    view = np.argsort(d, axis=1)[:, :4].ravel()
    point = np.repeat(np.arange(n_points), 4)
    uv = project_opencv(poses, view, X[point], intr, dist)
    uv += 0.5 * rng.standard_normal(uv.shape)
    p = Parameters()
    p.add("intrinsics", intr * [1.01, 1.01, 1, 1])
    p.add("distortion", dist)
    p.fix("distortion")
    p.add("poses", poses + rng.normal(0, [0.002] * 3 + [0.5] * 3, poses.shape))
    p.add("points", X + rng.normal(0, 0.5, X.shape), points=True)
    for j in range(0, n_points, 50):
        p.set_prior("points", 0.05, index=j, mean=X[j])
    return p, FrameOpenCV(view, uv, 0.5, point=point)


def test_same_bits_on_one_and_two_threads():
    """Several chunks of points (6,000 points: 3 chunks) summed in a fixed order: the kernels on
    one thread and on two give the same estimate, σ0 and covariance, bit for bit."""
    p, blk = _frame_block(6000)
    assert chunks(6000, 2000) > 1
    one = adjust(p, blk, threads=1)
    two = adjust(p, blk, threads=2)
    assert one.iterations == two.iterations
    np.testing.assert_array_equal(one.value("poses"), two.value("poses"))
    np.testing.assert_array_equal(one.value("points"), two.value("points"))
    np.testing.assert_array_equal(one.covariance, two.covariance)
    assert one.sigma0 == two.sigma0


def test_datum_decision_is_the_same_for_any_thread_count():
    S, P, st, pt, th = bearing_scene(1)
    p, blk = _bearing_params(S, P, st, pt, th, n_control=0)  # no datum: rank 4 short
    names = []
    for t in (1, 2):
        with pytest.raises(DatumError, match="rank deficient") as ei:
            adjust(p, blk, threads=t, blas_threads=t)
        names.append(ei.value.parameters)
    assert names[0] == names[1]


@pytest.mark.slow
def test_bal_example_same_minimum_on_one_and_two_blas_threads():
    """The README's `hsgeo adjust-bal` example: with one thread (BLAS and kernels) and with two,
    the solve converges, the covariance exists (the reduced matrix at the solution is not
    called singular) and the minimum is the same to 1e-9."""
    problem = read_bal(ladybug_path())
    fits = [adjust_bal(problem, BAL_OPTIONS.replace(threads=t, blas_threads=t)) for t in (1, 2)]
    for fit in fits:
        assert fit.result.converged
        assert np.all(np.isfinite(np.diag(fit.result.covariance)))
    assert fits[1].final_cost == pytest.approx(fits[0].final_cost, rel=1e-9)


@numba.njit(nogil=True)
def _chunk_sum(ch, step, x, out):  # pragma: no cover - compiled
    s = 0.0
    for i in range(ch * step, min(x.size, (ch + 1) * step)):
        s += x[i] * x[i]
    out[ch] = s
    return ch * 10


@pytest.mark.parametrize("threads", [1, 2])
def test_over_chunks_runs_every_chunk_once_in_order(threads):
    """over_chunks (the reduced-matrix and pushbroom-lines kernels' chunks, issue 41): every
    chunk once, its return values in chunk order, the same outputs on one thread or two."""
    x = np.random.default_rng(0).normal(size=1001)
    out = np.full(7, np.nan)
    with engine_threads(threads, 10**9):
        got = over_chunks(_chunk_sum, 7, 143, x, out)
    assert got == [0, 10, 20, 30, 40, 50, 60]
    want = [float(np.sum(x[c * 143 : (c + 1) * 143] ** 2)) for c in range(7)]
    np.testing.assert_allclose(out, want, rtol=1e-12)


def test_over_chunks_raises_what_a_chunk_raises():
    def chunk(ch):
        if ch == 2:
            raise ValueError("chunk 2")
        return ch

    with engine_threads(2, 10**9), pytest.raises(ValueError, match="chunk 2"):
        over_chunks(chunk, 4)
