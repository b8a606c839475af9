"""The browser check of the built book runs only under ``make check-book``.

It needs the built HTML book and a Chromium, so ``make test`` does not collect it: the Makefile
sets ``HSGEO_CHECK_BOOK=1``. Chromium is found as ``$HSGEO_CHROMIUM``, else ``chromium`` or
``chromium-browser`` on the PATH (Debian's package, installed by ``make browser``).
"""

from __future__ import annotations

import os
import shutil

import pytest

if os.environ.get("HSGEO_CHECK_BOOK") != "1":
    collect_ignore_glob = ["test_*.py"]


@pytest.fixture(scope="session")
def browser():
    """Debian's chromium driven by Playwright (its own browser download is not used)."""
    sync_api = pytest.importorskip("playwright.sync_api")
    executable = (
        os.environ.get("HSGEO_CHROMIUM")
        or shutil.which("chromium")
        or shutil.which("chromium-browser")
    )
    if not executable:
        pytest.fail("no chromium found: run `make browser` (apt-get install chromium, as root)")
    with sync_api.sync_playwright() as playwright:
        chromium = playwright.chromium.launch(
            executable_path=executable, args=["--no-sandbox", "--disable-gpu"]
        )
        yield chromium
        chromium.close()
