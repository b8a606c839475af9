"""``hsgeo reproduce CHAPTER``: the numbers of each book chapter, as tables or JSON (GUIDE §5).

Each chapter has a module here with a ``run(seed, scale) -> Reproduction`` function; the book
chapter calls the same function, so the chapter and the command print the same numbers.
"""

from __future__ import annotations

import importlib

from hsgeo.errors import InputError
from hsgeo.report import Reproduction, Row

__all__ = ["Row", "Reproduction", "CHAPTERS", "run", "chapter_names"]

#: chapter name -> module (relative to this package) with a ``run(seed, scale)`` function.
CHAPTERS: dict[str, str] = {
    "frame-reference": "frame_reference",
    "line-calibration": "line_calibration",
    "geocoding": "geocoding",
    "rikola": "rikola",
    "pushbroom-ba": "pushbroom_ba",
}


def chapter_names() -> list[str]:
    """Chapters that ``hsgeo reproduce`` knows."""
    return list(CHAPTERS)


def run(chapter: str, seed: int = 0, scale: float = 1.0) -> Reproduction:
    """Run a chapter's computation and return its tables."""
    if chapter not in CHAPTERS:
        raise InputError(f"unknown chapter {chapter!r}; known chapters: {', '.join(CHAPTERS)}")
    if not (isinstance(seed, int) and seed >= 0):
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    if not (0 < scale <= 1.0):
        raise InputError(f"scale must be in (0, 1], got {scale!r}")
    mod = importlib.import_module(f"hsgeo.reproduce.{CHAPTERS[chapter]}")
    return mod.run(seed=seed, scale=scale)
