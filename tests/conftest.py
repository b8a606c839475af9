import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from repro_cache import cached_run  # noqa: E402


@pytest.fixture(scope="session")
def repro_cache_dir(tmp_path_factory) -> Path:
    """The session's cache of chapter results (tests/repro_cache.py), shared by the
    pytest-xdist workers (the parent of a worker's base temporary directory is the session's)
    and the chapters' kernels (``$HSGEO_TEST_REPRO_CACHE``, set by tests/test_chapters.py)."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    return base / "reproductions"


@pytest.fixture(scope="session")
def reproduction(repro_cache_dir):
    """``reproduction(chapter, seed, scale)``: ``hsgeo.reproduce.run``'s result, computed once per
    session for every test and chapter that asks for it (each gets its own copy)."""

    def get(chapter: str, seed: int = 0, scale: float = 1.0):
        return cached_run(repro_cache_dir, chapter, seed=seed, scale=scale)

    return get


def _compile_pushbroom_kernels() -> None:
    """One tiny pushbroom adjustment: numba compiles the engine's kernels into its cache.

    The kernels (``cache=True``) are cached beside the sources and shared by every process, but
    on a fresh clone each process that calls one before it is cached compiles it itself. Two
    pytest-xdist workers reaching the pushbroom engine at the same time both compiled its 24
    kernels: 137 CPU-s each (issue 41, measured on a cold cache: tests/test_kernels.py and
    tests/test_pushbroom.py 163 CPU-s cold, 26 warm). Compiled once here, before the workers
    start, every worker loads them from the cache: 19 of the 24 kernels, 123.7 CPU-s with an
    empty cache, 6.9 CPU-s with a warm one (bench/results/test_suite_cost.json).
    """
    from priors import campaign_prior

    from hsgeo.adjust import adjust
    from hsgeo.simulate.pushbroom_campaign import simulate
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
    from hsgeo.workflows.pushbroom_ba import build_problem

    obs, _ = simulate(0.001, rng=3)
    cfg = CampaignConfig()
    cam = campaign_prior(x0_mm=cfg.x0_mm, lever_arm_m=tuple(obs.lever_arm_m))
    params, blocks, _ = build_problem(
        obs.lines,
        obs.n_points,
        cam,
        node_interval_s=10.0,
        t_span_s=obs.t_span_s,
        node_prior_mean=obs.node_prior_mean,
        gcp_index=obs.gcp_index,
        gcp_xyz_m=obs.gcp_xyz_m,
    )
    # with rejection (robust leverages) and the points' covariance: their kernels too
    res = adjust(params, blocks, reject_k=5.0, reject_every_iteration=True, keep_jacobian=True)
    res.point_covariance()


def pytest_configure(config):
    # Only in pytest-xdist's controller (`make test` runs two workers): a worker has
    # `workerinput`, a single-process run has no `numprocesses`.
    workers = getattr(config.option, "numprocesses", None)
    if workers and not hasattr(config, "workerinput") and not os.environ.get("HSGEO_NO_WARMUP"):
        _compile_pushbroom_kernels()
