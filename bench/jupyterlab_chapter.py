"""A chapter's ``.ipynb`` download opened in JupyterLab, as a reader opens it: a screenshot.

Issue 40 asks that a downloaded chapter, opened in JupyterLab from the pinned environment
(requirements.lock pins ``jupyterlab``), shows its numbers rather than MyST roles. This script
takes the download the built book offers (``book/_build/html/_sources/chapters/<name>.ipynb``),
starts the environment's own JupyterLab on it (no token, offline, a free local port), opens the
notebook in Debian's chromium (Playwright, as ``make check-book``), moves to the first text cell
that holds at least three of the page's glued values (myst-nb's ``<name>.glue.json``: the
numbers the HTML page shows) and saves a screenshot. It fails, writing nothing, when the
notebook still holds a ``{glue`` role, when no text cell holds three glued values, or when the
rendered cell does not show them.

Run after ``make book`` (any scale)::

    .venv/bin/python bench/jupyterlab_chapter.py [--chapter mtf] [--out FILE.png]

The PNG is reduced to a 64-colour palette (a small file to commit); the glued values it shows
are printed.
"""

from __future__ import annotations

import argparse
import json
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "book" / "_build"
#: Fewest glued values the shown cell holds.
MIN_VALUES = 3


def glued_strings(glue_json: Path) -> list[str]:
    """The page's glued values as text (myst-nb's text/plain, quotes stripped) that hold a digit
    and are at least three characters long: what a reader would look for in the notebook.
    """
    import ast

    data = json.loads(glue_json.read_text(encoding="utf-8"))
    out = []
    for value in data.values():
        text = (value.get("data") or {}).get("text/plain") if isinstance(value, dict) else None
        if not isinstance(text, str):
            continue
        try:
            text = str(ast.literal_eval(text))
        except (ValueError, SyntaxError):
            pass
        if len(text) >= 3 and any(ch.isdigit() for ch in text) and "\n" not in text:
            out.append(text)
    return out


def pick_cell(nb: dict, values: list[str]) -> tuple[int, list[str]]:
    """The index of the first markdown cell holding at least :data:`MIN_VALUES` glued values,
    and those values."""
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "markdown":
            continue
        text = "".join(cell["source"])
        found = [v for v in values if v in text]
        if len(found) >= MIN_VALUES:
            return i, found
    raise SystemExit(f"no text cell holds {MIN_VALUES} glued values: are they written in?")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_for(url: str, seconds: float) -> None:
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        try:
            urllib.request.urlopen(url, timeout=2)  # noqa: S310 (a local URL)
            return
        except OSError:
            time.sleep(1)
    raise SystemExit(f"JupyterLab did not answer at {url} within {seconds:.0f} s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--chapter", default="mtf")
    ap.add_argument("--out", type=Path, default=ROOT / "bench/results/jupyterlab_chapter.png")
    ap.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    ap.add_argument("--build", type=Path, default=BUILD, help="the book's _build folder")
    args = ap.parse_args(argv)

    download = args.build / "html" / "_sources" / "chapters" / f"{args.chapter}.ipynb"
    glue_json = args.build / "jupyter_execute" / "chapters" / f"{args.chapter}.glue.json"
    for path in (download, glue_json):
        if not path.is_file():
            raise SystemExit(f"{path} is missing: build the book first (make book)")
    nb = json.loads(download.read_text(encoding="utf-8"))
    raw = sum("{glue" in "".join(c["source"]) for c in nb["cells"])
    if raw:
        raise SystemExit(f"{download}: {raw} cells still hold a {{glue}} role")
    index, values = pick_cell(nb, glued_strings(glue_json))

    from PIL import Image
    from playwright.sync_api import sync_playwright

    port = _free_port()
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(download, Path(tmp) / download.name)
        lab = subprocess.Popen(  # the pinned environment's JupyterLab (this interpreter's)
            [
                sys.executable,
                "-m",
                "jupyterlab",
                "--no-browser",
                "--allow-root",  # a container or CI runner runs as root
                f"--port={port}",
                "--ServerApp.ip=127.0.0.1",
                "--IdentityProvider.token=",
                "--ServerApp.password=",
                f"--ServerApp.root_dir={tmp}",
                "--LabApp.news_url=",
                "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            base = f"http://127.0.0.1:{port}"
            _wait_for(f"{base}/lab", 120)
            with sync_playwright() as pw:
                browser = pw.chromium.launch(
                    executable_path=args.chromium, args=["--no-sandbox", "--disable-gpu"]
                )
                page = browser.new_page(viewport={"width": 1200, "height": 800})
                page.goto(f"{base}/lab/tree/{download.name}", timeout=180_000)
                page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=180_000)
                page.wait_for_timeout(3000)
                page.locator(".jp-Notebook .jp-Cell").first.click()
                page.keyboard.press("Escape")  # command mode: j moves down a cell
                for _ in range(index):
                    page.keyboard.press("j")
                page.wait_for_timeout(1500)
                active = page.locator(".jp-Notebook .jp-Cell.jp-mod-active").first
                active.scroll_into_view_if_needed()
                page.evaluate(
                    "() => document.querySelector('.jp-Notebook .jp-Cell.jp-mod-active')"
                    ".scrollIntoView({block: 'start'})"
                )
                page.wait_for_timeout(1500)
                shown = active.inner_text()
                missing = [v for v in values if v not in shown]
                if len(values) - len(missing) < MIN_VALUES:
                    raise SystemExit(f"the rendered cell does not show {values}: «{shown[:200]}»")
                no_news = page.get_by_role("button", name="No", exact=True)
                if no_news.count():  # JupyterLab's "notified about news?" toast
                    no_news.first.click()
                    page.wait_for_timeout(1000)
                png = Path(tmp) / "shot.png"
                page.screenshot(path=str(png))
                browser.close()
            args.out.parent.mkdir(parents=True, exist_ok=True)
            with Image.open(png) as im:
                im.convert("RGB").quantize(colors=64).save(args.out, optimize=True)
        finally:
            lab.terminate()
            lab.wait(timeout=30)
    shown_values = ", ".join(v for v in values if v not in missing)
    print(f"{args.out}: cell {index} of {download.name} shows {shown_values}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
