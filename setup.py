"""The wheel carries the scenarios: ``data_synthetic/`` is copied into ``hsgeo/data/scenarios``.

Everything else is declared in ``pyproject.toml``. The repository keeps the scenario TOMLs, their
checksum manifest and the committed generated files at its top (``make data``, the book and the
tests read them there); an installed hsgeo has no repository, so the build copies them into the
package, where :func:`hsgeo.simulate.scenarios.data_dir` finds them (``hsgeo reproduce`` and
``hsgeo data`` from any folder; issue 42).
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
SCENARIOS = HERE / "data_synthetic"


class BuildPyWithScenarios(build_py):
    """``build_py`` plus ``data_synthetic/{*.toml,MANIFEST.sha256,generated/*}``."""

    def run(self):
        super().run()
        if self.editable_mode:  # an editable install reads the repository's own folder
            return
        dest = Path(self.build_lib) / "hsgeo" / "data" / "scenarios"
        files = [*SCENARIOS.glob("*.toml"), SCENARIOS / "MANIFEST.sha256"]
        files += sorted((SCENARIOS / "generated").glob("*"))
        for src in files:
            if not src.is_file():
                continue
            target = dest / src.relative_to(SCENARIOS)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, target)


setup(cmdclass={"build_py": BuildPyWithScenarios})
