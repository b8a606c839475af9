"""The command keeps freed memory for reuse (hsgeo.terminal.keep_freed_memory, issue 41).

Each case runs in a fresh interpreter without the Makefile's ``GLIBC_TUNABLES``: a 128 MB array
is written, freed, and a second one of the same size written; the page faults of the second tell
whether its memory was reused (a few) or mapped and zeroed again (one per page: at least one per
2 MB huge page, 64).
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(
    platform.system() != "Linux" or platform.libc_ver()[0] != "glibc", reason="glibc only"
)

_CHILD = """
import json, resource, sys
import numpy as np
from hsgeo.terminal import keep_freed_memory
made = keep_freed_memory() if sys.argv[1] == "keep" else None
if sys.argv[1] == "command":  # the hsgeo command's entry point, then the same allocations
    from hsgeo.cli import main
    try:
        main(["--version"])
    except SystemExit:
        pass
n = 16 * 2**20  # 128 MB of float64: above glibc's largest mmap threshold (32 MB)
a = np.empty(n); a[:] = 1.0; del a
f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
b = np.empty(n); b[:] = 2.0
f1 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
print(json.dumps({"made": made, "faults": f1 - f0}), file=sys.stderr)
"""


def _run(mode: str, tunables: str | None = None) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "GLIBC_TUNABLES"}
    if tunables is not None:
        env["GLIBC_TUNABLES"] = tunables
    p = subprocess.run(
        [sys.executable, "-c", _CHILD, mode], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(p.stderr.strip().splitlines()[-1])


def test_freed_arrays_are_reused_instead_of_faulted_in_again():
    kept, plain = _run("keep"), _run("plain")
    assert kept["made"] is True
    # the default: the freed block was unmapped, its pages zeroed again
    assert plain["faults"] >= 32, plain
    assert kept["faults"] < 8, kept


def test_left_alone_when_the_caller_set_glibc_malloc_tunables():
    got = _run("keep", "glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967296")
    assert got["made"] is False
    assert got["faults"] < 8  # the caller's settings do the same


def test_the_command_keeps_freed_memory():
    assert _run("command")["faults"] < 8
