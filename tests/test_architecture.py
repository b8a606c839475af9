"""The layout's rules (GUIDE §2) as import-linter contracts in pyproject.toml: run them here so
that `make test` fails when a module breaks them, as `make lint` does."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_kept():
    exe = Path(sys.executable).with_name("lint-imports")
    out = subprocess.run([str(exe), "--no-cache"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]


def test_a_broken_contract_is_reported(tmp_path):
    # the check can fail: a contract forbidding what the package does import is reported broken
    cfg = tmp_path / "contracts.toml"
    cfg.write_text(
        '[tool.importlinter]\nroot_package = "hsgeo"\n\n[[tool.importlinter.contracts]]\n'
        'name = "reproduce may not use workflows (false on purpose)"\ntype = "forbidden"\n'
        'source_modules = ["hsgeo.reproduce"]\nforbidden_modules = ["hsgeo.workflows"]\n'
    )
    exe = Path(sys.executable).with_name("lint-imports")
    out = subprocess.run(
        [str(exe), "--no-cache", "--config", str(cfg)], cwd=ROOT, capture_output=True, text=True
    )
    assert out.returncode != 0 and "BROKEN" in out.stdout
