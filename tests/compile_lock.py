"""Each compiled kernel compiled once per test session, by the first process that needs it.

Issue 41. The kernels (numba, ``cache=True``) are cached beside the sources and shared by every
process, but on a fresh clone a process that calls a kernel not yet in the cache compiles it
itself: two pytest-xdist workers (or a worker and a chapter's Jupyter kernel) reaching the same
kernel at the same time both compiled it (the pushbroom engine's 24 kernels: 137 CPU-s each).
Before, the xdist controller compiled 19 of them alone before the workers started (≈ 124 CPU-s
on one core while the other waited). Here a lock file per kernel makes a second process wait for
the first one's compilation and then load it from the cache, and no process waits for kernels it
does not need. The compiled code is numba's either way: who compiles it changes no bit of a
result.

Lock order: the in-process compiler lock first, then the kernels' lock files from caller to
callee (a kernel compiles its callees inside its own compilation): no two processes can hold
two locks in opposite orders, so no deadlock.
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

#: the folder of the session's lock files (set by tests/conftest.py; inherited by the chapters'
#: kernels and the CLI's subprocesses)
ENV = "HSGEO_TEST_COMPILE_LOCKS"

_held: set[str] = set()  # keys this process holds (a kernel compiling itself: re-entrant)


def install(directory: str | Path | None = None) -> None:
    """Wrap ``numba``'s ``Dispatcher.compile`` with a lock file per kernel under ``directory``
    (default ``$HSGEO_TEST_COMPILE_LOCKS``; a no-op when neither is set or already installed)."""
    directory = directory or os.environ.get(ENV)
    if not directory:
        return
    from numba.core import dispatcher
    from numba.core.compiler_lock import global_compiler_lock

    original = dispatcher.Dispatcher.compile
    if hasattr(original, "_unlocked"):
        return
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)

    def compile(self, sig):
        f = self.py_func
        key = f"{f.__module__}.{f.__qualname__}".replace("<", "_").replace(">", "_")
        with global_compiler_lock:  # before the file: the lock order of the module docstring
            if key in _held:
                return original(self, sig)
            with open(folder / f"{key}.lock", "w") as lock:
                fcntl.flock(lock, fcntl.LOCK_EX)  # another process compiling it: wait, then
                _held.add(key)  # numba loads its result from the cache
                try:
                    return original(self, sig)
                finally:
                    _held.discard(key)

    compile._unlocked = original
    dispatcher.Dispatcher.compile = compile
