"""``make bench``: run every ``bench/bench_*.py`` (each writes ``bench/results/<name>.json``).

``python bench/run.py [NAME ...]`` runs only the named ones (``engine``, ``pushbroom_ba``,
``bal``, ``nist_strd``); each script also runs on its own with its options
(``python bench/bench_pushbroom_ba.py --help``).

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
for script in sorted(here.glob("bench_*.py")):
    if only and script.stem.removeprefix("bench_") not in only:
        continue
    print(
        f"== {script.name} (OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')})",
        flush=True,
    )
    sys.argv = [str(script)]  # each benchmark parses its own (default) arguments
    runpy.run_path(str(script), run_name="__main__")
