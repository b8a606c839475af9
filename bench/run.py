"""``make bench``: run every ``bench/bench_*.py`` (each writes ``bench/results/<name>.json``).

``python bench/run.py [NAME ...]`` runs only the named ones (``engine``, ``pushbroom_ba``,
``pushbroom_scaling``, ``bal``, ``nist_strd``, ``mtf``, ``cube``, ``busy_machine``,
``lp_ransac``, ``lp_observations``, ``lp_parameters``, ``lp_scene_length``, ``orthomosaic``,
``cli_startup``, ``issue41_pairs``, ``issue41_audit``); each script also runs on its own with
its options (``python bench/bench_pushbroom_ba.py --help``).
``pushbroom_scaling`` is ``bench_pushbroom_ba.py --scaling …``, run after the pushbroom
benchmark (issue 14).

Benchmarks time whole operations at realistic sizes and report peak memory, against the obvious
alternative in the same run (GUIDE §7). They are scripts, never timed assertions.
"""

import os
import runpy
import sys
from pathlib import Path

here = Path(__file__).parent
(here / "results").mkdir(exist_ok=True)
only = sys.argv[1:]
jobs = []  # (name, script, arguments)
for script in sorted(here.glob("bench_*.py")):
    jobs.append((script.stem.removeprefix("bench_"), script, []))
    if (
        script.stem == "bench_pushbroom_ba"
    ):  # the scaling rows: bench/results/pushbroom_scaling.json
        jobs.append(("pushbroom_scaling", script, ["--scaling", "0.1,0.3,1,3,10"]))
#: run by issue41_pairs.py in a whole `make bench`, in turn with the issue's commit (their files
#: are written once, with the paired rounds); named alone they run as before
PAIRED = {"bal", "orthomosaic"}
for name, script, arguments in jobs:
    if (only and name not in only) or (not only and name in PAIRED):
        continue
    print(
        f"== {script.name} {' '.join(arguments)} "
        f"(OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')})",
        flush=True,
    )
    sys.argv = [str(script), *arguments]  # each benchmark parses its own arguments
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:  # a script's main() returning through sys.exit
        if e.code not in (0, None):
            raise
# issue 41's pairs: this checkout and the issue's commit in turn (a git worktree of it), so
# that the audit's verdicts do not depend on the machine's hour (bench/issue41_pairs.py)
if not only or "issue41_pairs" in only:
    print("== issue41_pairs.py", flush=True)
    sys.argv = [str(here / "issue41_pairs.py")]
    runpy.run_path(str(here / "issue41_pairs.py"), run_name="__main__")
# issue 41's table, each figure beside its goal, from the files just written
if not only or "issue41_audit" in only:
    print("== issue41_audit.py", flush=True)
    sys.argv = [str(here / "issue41_audit.py")]
    runpy.run_path(str(here / "issue41_audit.py"), run_name="__main__")
