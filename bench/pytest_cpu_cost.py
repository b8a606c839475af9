"""A pytest plugin that records each test's CPU seconds and wall seconds (issue 41).

Load it with ``-p pytest_cpu_cost`` (``bench/`` on ``PYTHONPATH``) and name the output with
the environment variable ``HSGEO_TEST_COST_OUT`` (and ``HSGEO_TEST_COST_LIVE`` for one JSON
line per finished test): at the end of the session a JSON file maps
each test file to its CPU seconds (user + system of the pytest process and the children it
waited for, ``resource.getrusage``), wall seconds and test count, setup and teardown included
(a module-scoped fixture is charged to the file's first test). It never asserts a time.
Under pytest-xdist each worker writes its own file (``HSGEO_TEST_COST_OUT`` with ``.gw0``,
``.gw1``, … inserted before the suffix), and the live lines of all workers go to the one
``HSGEO_TEST_COST_LIVE`` file (appended line by line).
"""

from __future__ import annotations

import json
import os
import resource
import time
from collections import defaultdict

_rows: dict[str, dict] = defaultdict(lambda: {"cpu_s": 0.0, "wall_s": 0.0, "tests": 0})
_tests: list[tuple[str, float, float]] = []


def _cpu_s() -> float:
    s = resource.getrusage(resource.RUSAGE_SELF)
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


def pytest_runtest_protocol(item, nextitem):  # noqa: D103
    item._cost0 = (_cpu_s(), time.perf_counter())


def pytest_runtest_makereport(item, call):  # noqa: D103
    if call.when != "teardown" or not hasattr(item, "_cost0"):
        return
    cpu0, wall0 = item._cost0
    cpu, wall = _cpu_s() - cpu0, time.perf_counter() - wall0
    row = _rows[item.nodeid.split("::")[0]]
    row["cpu_s"] += cpu
    row["wall_s"] += wall
    row["tests"] += 1
    _tests.append((item.nodeid, cpu, wall))
    live = os.environ.get("HSGEO_TEST_COST_LIVE")
    if live:  # one line per test as it finishes: a stopped run still tells where its time went
        with open(live, "a") as f:
            f.write(
                json.dumps({"test": item.nodeid, "cpu_s": round(cpu, 3), "wall_s": round(wall, 3)})
            )
            f.write("\n")


def pytest_sessionfinish(session, exitstatus):  # noqa: D103
    out = os.environ.get("HSGEO_TEST_COST_OUT")
    if not out:
        return
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker:  # one file per worker, or the last worker to finish would overwrite the others
        root, ext = os.path.splitext(out)
        out = f"{root}.{worker}{ext}"
    files = dict(sorted(_rows.items(), key=lambda kv: -kv[1]["cpu_s"]))
    top = sorted(_tests, key=lambda t: -t[1])[:120]
    doc = {
        "loadavg_at_end": list(os.getloadavg()),
        "total_cpu_s": round(_cpu_s(), 1),
        "files": {k: {kk: round(v, 2) for kk, v in r.items()} for k, r in files.items()},
        "top_tests": [{"test": n, "cpu_s": round(c, 2), "wall_s": round(w, 2)} for n, c, w in top],
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
