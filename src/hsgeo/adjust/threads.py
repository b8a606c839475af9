"""How many threads the engine's compiled kernels and BLAS use, chosen by the work.

A parallel region of the compiled kernels (numba's OpenMP layer) costs a few microseconds on an
idle machine, but when another process holds a core the second thread has to wait for it to
be scheduled, and GNU OpenMP's threads spin while they wait: a line-calibration run of 252
small adjustments took 142 s of wall time (81 s of CPU) with numba's two threads against 8 s
with one, for identical output (2026-11-24, one core busy). Multi-threaded OpenBLAS does the
same on the small dense factorisations of the reduced normal matrix (GUIDE §9).

So the engine decides, per solve, from the size of the problem:

* ``threads="auto"`` (:class:`~hsgeo.adjust.SolverOptions`' default): the compiled kernels run
  on one thread below :data:`PARALLEL_MIN_ROWS` residual rows and on numba's pool
  (``NUMBA_NUM_THREADS``, the number of cores) from there on; ``threads=n``: on n threads (at
  most the pool).
* BLAS runs on ``SolverOptions.blas_threads`` threads, one by default, whatever the shell's
  ``OPENBLAS_NUM_THREADS``: the reduced systems of these problems have at most a few thousand
  unknowns, where one thread was the fastest, and with a fixed count the numbers do not depend
  on the machine's cores.

The threshold is measured, not guessed: ``bench/bench_busy_machine.py`` times whole adjustments
of growing size on one and two threads, idle and with one core busy
(``bench/results/busy_machine.json``); below the threshold two threads never paid.

The number of the kernels' threads changes only the speed, never the numbers: every kernel that
sums over rows or points does so in chunks whose number depends on the size of the problem alone
(:data:`MAX_CHUNKS`), added up in a fixed order (tested bit for bit). BLAS threads change the
summation order of the dense factorisations, so results differ in the last digits; the
decisions taken from them (rank, datum, covariance) use thresholds with a wide margin over
rounding (tested on 1 and 2 BLAS threads).
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Iterator

import numba

from hsgeo._chunks import over_chunks, over_items

__all__ = [
    "PARALLEL_MIN_ROWS",
    "MAX_CHUNKS",
    "resolve",
    "engine_threads",
    "blas_threads",
    "pool_size",
    "chunks",
    "over_chunks",
    "over_items",
]

#: Residual rows (observation components, priors included) from which ``threads="auto"`` runs
#: the compiled kernels in parallel. Measured with bench/bench_busy_machine.py (2026-11-24,
#: 2 cores, bench/results/busy_machine.json): on frame-camera blocks of 16,000–480,000 rows two
#: threads were 1.1–1.2× faster than one on the quiet machine, but 3.2× (16,000 rows) to 1.65×
#: (240,000) slower with one core busy and 1.19× slower at 480,000; the paper-size pushbroom
#: solve (884,000 rows) was faster on two threads busy or not (6.7 s against 11.5 s busy). So
#: below 400,000 rows one thread: never more than 1.5× slower than the best, busy or not.
PARALLEL_MIN_ROWS = 400_000

#: The most chunks a kernel splits its rows or points into (the sum of the chunks, in a fixed
#: order, is the same whatever the number of threads that compute them).
MAX_CHUNKS = 4


def pool_size() -> int:
    """The size of numba's thread pool (``NUMBA_NUM_THREADS``, by default the cores)."""
    return int(numba.config.NUMBA_NUM_THREADS)


def resolve(threads: int | str, rows: int) -> int:
    """The kernels' threads for a solve with ``rows`` residual rows (at most numba's pool).

    ``"auto"``: one thread below :data:`PARALLEL_MIN_ROWS`, numba's pool from there on.
    """
    if threads == "auto":
        return 1 if rows < PARALLEL_MIN_ROWS else pool_size()
    return max(1, min(int(threads), pool_size()))


def chunks(n: int, per_chunk: int) -> int:
    """Chunks for ``n`` items, at least ``per_chunk`` each, at most :data:`MAX_CHUNKS`."""
    return max(1, min(MAX_CHUNKS, n // per_chunk + 1))


@functools.cache
def _controller():
    # threadpoolctl finds the BLAS libraries loaded in the process (numpy's and scipy's
    # OpenBLAS); created once, after scipy.linalg is imported by the engine
    import scipy.linalg  # noqa: F401  (load scipy's BLAS so that the controller sees it)
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


@contextlib.contextmanager
def blas_threads(n: int) -> Iterator[None]:
    """The BLAS libraries (numpy's and scipy's OpenBLAS) limited to ``n`` threads inside the
    block (numba's own OpenMP pool is set by :func:`engine_threads`).
    """
    with _controller().limit(limits=n, user_api="blas"):
        yield


@contextlib.contextmanager
def engine_threads(threads: int | str, rows: int, blas: int = 1) -> Iterator[int]:
    """The compiled kernels on :func:`resolve`'s thread count and BLAS on ``blas`` threads
    inside the block; yields the kernels' count. numba's setting is per calling thread and
    restored on exit, as are the BLAS libraries'.
    """
    n = resolve(threads, rows)
    old = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        with blas_threads(blas):
            yield n
    finally:
        numba.set_num_threads(old)
