import os
import sys
from pathlib import Path

import pytest

# The compiled kernels' threads (numba's OpenMP layer, libgomp) wait for work by spinning on
# their core unless told otherwise: with two pytest-xdist workers on two cores, each with its
# threads, a spinning thread takes the core from the other worker after every parallel loop.
# Passive waiting changes no result (the same threads split the same loops) and only the CPU
# spent waiting (issue 41: bench/results/test_suite_cost.json). Set before any process of the
# session loads libgomp (it reads the variable once); the workers, the chapters' kernels and the
# CLI's subprocesses inherit it.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
# BLAS on one thread in every process of the session, as `make test` sets it (Makefile) and as
# the command line runs: BLAS threads change a result's last digits (README, "threads"), so a
# plain `pytest` in a shell without these variables compared a chapter's kernel (one thread,
# tests/test_chapters.py) with a worker (all cores) and found σ̂ of lp-observations 4e-13
# apart (test_same_seed_same_rows, session 22). The variables reach the workers, the chapters'
# kernels and the CLI's subprocesses; threadpoolctl limits a BLAS this process already loaded.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
if os.environ["OPENBLAS_NUM_THREADS"] == "1":
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")

sys.path.insert(0, str(Path(__file__).parent))

import compile_lock  # noqa: E402
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


@pytest.fixture(scope="session", autouse=True)
def _compile_once(tmp_path_factory) -> None:
    """Each compiled kernel compiled by one process of the session (tests/compile_lock.py): the
    workers, the chapters' kernels and the CLI's subprocesses share a folder of lock files."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    os.environ[compile_lock.ENV] = str(base / "compile-locks")
    compile_lock.install()


#: The test files by CPU seconds, the costliest first (a fresh clone of main 3072200, `make test`
#: with bench/pytest_cpu_cost.py; bench/results/test_suite_cost.json). pytest-xdist hands a
#: worker its next file when it is done with one: begun first, the long files end together
#: instead of one worker running the chapters alone at the end (xdist's default order is by
#: number of tests, which put tests/test_chapters.py, 314 CPU-s in 19 tests, last). Files not
#: named here follow in the order collected. CPU-s of each file in that run in the comments.
COSTLIEST_FIRST = (
    "test_bad_input.py",  # 353
    "test_chapters.py",  # 314
    # after test_cube.py: a worker takes the next file when its own is nearly done, and 3rd
    # this file began in the other worker while the lp-observations chapter computed the run
    # both need (seed 0, 0.3) and waited 78 s for it (tests/repro_cache.py's lock); 4th it
    # begins after the chapters or after test_cube.py (139 s more) and finds the run cached
    "test_cube.py",  # 156
    "test_reproduce_lp_observations.py",  # 168
    "test_bad_input_every_command.py",  # 66
    "test_asf.py",  # 60
    "test_reproduce_lp_mosaic.py",  # 55
    "test_geodetic_002_flight.py",  # 48
    "test_reproduce_asf.py",  # 36
    "test_lp_campaign.py",  # 35
    "test_rikola.py",  # 35
    "test_reproduce_geocoding.py",  # 28
    "test_cli_lp_observations.py",  # 25
    "test_cli_lp_observations_envi.py",  # 24
    "test_ortho_scale.py",  # 22
    "test_orthorectify_registry.py",  # 19
    "test_geodetic_geolocation.py",  # 18
    "test_engine_threads.py",  # 17
    "test_approx_transform.py",  # 17
    "test_raycast_rows.py",  # 15
    "test_lp_observations.py",  # 14
    "test_bad_input_classes.py",  # 14
    "test_reproduce_lp_targets.py",  # 13
    "test_cli_orthorectify.py",  # 12
    "test_reproduce_line_calibration.py",  # 12
    "test_cli_orthorectify_envi.py",  # 11
    "test_cli_asf.py",  # 11
    "test_ortho.py",  # 11
    "test_bal.py",  # 11
    "test_measure_mtf.py",  # 10
)


def pytest_collection_modifyitems(session, config, items):
    """Under pytest-xdist: the files in :data:`COSTLIEST_FIRST` order (each file's tests in
    their own order). Both workers collect the same order, as xdist requires."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    rank = {name: i for i, name in enumerate(COSTLIEST_FIRST)}
    files = list(dict.fromkeys(item.nodeid.split("::")[0] for item in items))
    order = {f: (rank.get(Path(f).name, len(rank)), i) for i, f in enumerate(files)}
    items.sort(key=lambda item: order[item.nodeid.split("::")[0]])


def pytest_configure(config):
    # pytest-xdist's controller schedules the files in the order the workers collected them
    # (pytest_collection_modifyitems), not by their number of tests
    if hasattr(config.option, "loadscopereorder") and not hasattr(config, "workerinput"):
        config.option.loadscopereorder = False
