"""``hsgeo reproduce CHAPTER``: the numbers of each book chapter, as tables or JSON (GUIDE §5).

Each chapter has a module here with a ``run(seed, scale) -> Reproduction`` function; the book
chapter calls the same function, so the chapter and the command print the same numbers.
"""

from __future__ import annotations

import importlib
import os
from dataclasses import dataclass
from pathlib import Path

from hsgeo.errors import InputError
from hsgeo.report import Reproduction

__all__ = [
    "Chapter",
    "CHAPTERS",
    "RECORD_ENV",
    "run",
    "recorded",
    "chapter_names",
    "paper_chapters",
]

#: When this environment variable names a directory, :func:`run` writes each chapter's result
#: there as ``<chapter>.json`` (the book build sets it, so that the scoreboard page reads the
#: chapters' results instead of computing them again).
RECORD_ENV = "HSGEO_RECORD_DIR"


@dataclass(frozen=True)
class Chapter:
    """One chapter of the book and of ``hsgeo reproduce`` (the recipe: CONTRIBUTING.md).

    Everything else that knows the chapter derives from this entry: the command's choices
    (:func:`chapter_names`), the scoreboard's list of chapters with claims and their links
    (:func:`paper_chapters`, :attr:`page`), and the tests that check the book's table of
    contents and the chapter list of ``book/intro.md`` against it.
    """

    #: Module of this package with the chapter's ``run(seed, scale) -> Reproduction``.
    module: str
    #: Whether the chapter's tables hold numbers published in a paper (tables named ``000 …``
    #: to ``004 …``): the scoreboard counts them.
    claims: bool = True
    #: The chapter's page, relative to ``book/`` without suffix (``chapters/<module>``), or
    #: None for a chapter with no page of its own.
    page: str | None = None

    def __post_init__(self) -> None:
        if self.page is None:
            object.__setattr__(self, "page", f"chapters/{self.module}")


#: chapter name -> :class:`Chapter`, in the scoreboard's order (the chapters with claims are
#: counted in this order).
CHAPTERS: dict[str, Chapter] = {
    "frame-reference": Chapter("frame_reference", claims=False),
    "line-calibration": Chapter("line_calibration"),
    "geocoding": Chapter("geocoding"),
    "pushbroom-ba": Chapter("pushbroom_ba"),
    "lp-observations": Chapter("lp_observations"),
    "rikola": Chapter("rikola"),
    "mtf": Chapter("mtf"),
    "cube": Chapter("cube"),
    "asf": Chapter("asf"),
    "scoreboard": Chapter("scoreboard", claims=False, page="scoreboard"),
}


def paper_chapters() -> tuple[str, ...]:
    """The chapters whose tables hold the papers' claims (:attr:`Chapter.claims`), in order."""
    return tuple(name for name, ch in CHAPTERS.items() if ch.claims)


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
    mod = importlib.import_module(f"hsgeo.reproduce.{CHAPTERS[chapter].module}")
    rep = mod.run(seed=seed, scale=scale)
    if chapter != "scoreboard":  # one chapter judges each published number
        from hsgeo.reproduce.scoreboard import mark_context

        mark_context(chapter, rep)
    rep.meta.setdefault("scale", scale)
    directory = os.environ.get(RECORD_ENV)
    if directory and chapter != "scoreboard":
        from hsgeo.io._files import write_text

        write_text(
            Path(directory) / f"{chapter}.json", rep.to_json(), atomic=True, make_parents=True
        )
    return rep


def recorded(chapter: str) -> Reproduction | None:
    """The result :func:`run` last recorded for ``chapter`` under ``$HSGEO_RECORD_DIR``, or None."""
    directory = os.environ.get(RECORD_ENV)
    path = Path(directory) / f"{chapter}.json" if directory else None
    if path is None or not path.is_file():
        return None
    return Reproduction.from_json(path.read_text(encoding="utf-8"))
