"""One computation per ``hsgeo.reproduce.run(chapter, seed, scale)`` in a test session (issue 41).

The chapters executed by ``tests/test_chapters.py`` (in a Jupyter kernel, a separate process) and
the tests of ``tests/test_reproduce_*.py`` (in a pytest-xdist worker) ran some chapters at the same
seed and scale: the lp-observations chapter at seed 0, scale 0.3 and the mtf chapter at seed 0,
scale 0.1 were each computed twice per ``make test``. The result depends on (chapter, seed, scale)
only (determinism: numpy Generators seeded from ``seed``), so it is computed once per session and
kept as a pickle in a directory every process of the session shares (``$HSGEO_TEST_REPRO_CACHE``,
under pytest's base temporary directory, so never reused by another session or another commit).
A lock file per key makes a second process wait for the first one's result instead of computing
it again. Every caller gets its own unpickled copy: a test that changes its copy changes nobody
else's.
"""

from __future__ import annotations

import fcntl
import os
import pickle
import warnings
from pathlib import Path

import cloudpickle

#: the directory of the session's cached results (set by tests/conftest.py for the kernels)
ENV = "HSGEO_TEST_REPRO_CACHE"

#: (chapter, seed, scale) that a chapter of the book (``HSGEO_SCALE=small``) and a test both run:
#: the kernels share only these (pickling the others would cost without a reader). A test asking
#: :func:`cached_run` for another key computes it once for the session all the same.
SHARED = {
    ("lp-observations", 0, 0.3),  # book/chapters/lp_observations.md, test_reproduce_lp_observations
    ("mtf", 0, 0.1),  # book/chapters/mtf.md, tests/test_reproduce_mtf.py
    ("cube", 0, 0.25),  # book/chapters/cube.md, tests/test_cube.py
}
#: results that could not be pickled, kept for the rest of this process
_UNSHARED: dict = {}


def _key(chapter: str, seed: int, scale: float) -> str:
    return f"{chapter}-seed{int(seed)}-scale{float(scale)!r}"


def cached_run(directory: str | Path, chapter: str, seed: int = 0, scale: float = 1.0):
    """``hsgeo.reproduce.run(chapter, seed, scale)``, computed once per ``directory``.

    The result is the one :func:`hsgeo.reproduce.run` returns (rows marked by the scoreboard's
    ``mark_context``, ``meta["scale"]`` set), extras included; it is recorded under
    ``$HSGEO_RECORD_DIR`` like a computed one (the book build's scoreboard reads those records).
    """
    import hsgeo.reproduce as R

    run = getattr(R.run, "_uncached", R.run)
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    key = _key(chapter, seed, scale)
    if key in _UNSHARED:
        return _UNSHARED[key]
    path = d / f"{key}.pickle"
    with open(d / f"{key}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # a second process waits here for the first's result
        if path.is_file():
            rep = cloudpickle.loads(path.read_bytes())
            _record(R, chapter, rep)
            return rep
        rep = run(chapter, seed=seed, scale=scale)
        try:  # cloudpickle (dask's) also pickles the local functions of a dask graph (cube)
            data = cloudpickle.dumps(rep, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as err:  # an unpicklable extra: not shared, every caller computes it
            warnings.warn(f"{key} not shared between processes: {err}", stacklevel=2)
            _UNSHARED[key] = rep
            return rep
        tmp = path.with_suffix(".part")
        tmp.write_bytes(data)
        tmp.rename(path)
    return rep


def _record(R, chapter: str, rep) -> None:
    """As :func:`hsgeo.reproduce.run` records a computed result (``$HSGEO_RECORD_DIR``)."""
    directory = os.environ.get(R.RECORD_ENV)
    if directory and chapter != "scoreboard":
        from hsgeo.io._files import write_text

        write_text(
            Path(directory) / f"{chapter}.json", rep.to_json(), atomic=True, make_parents=True
        )


def install() -> None:
    """In a chapter's kernel: ``hsgeo.reproduce.run`` becomes :func:`cached_run` on
    ``$HSGEO_TEST_REPRO_CACHE`` for the keys of :data:`SHARED` (a no-op when it is unset)."""
    import hsgeo.reproduce as R

    directory = os.environ.get(ENV)
    if not directory or hasattr(R.run, "_uncached"):
        return
    original = R.run

    def run(chapter: str, seed: int = 0, scale: float = 1.0):
        if (chapter, seed, scale) not in SHARED:
            return original(chapter, seed=seed, scale=scale)
        return cached_run(directory, chapter, seed=seed, scale=scale)

    run.__doc__ = original.__doc__
    run._uncached = original
    R.run = run
