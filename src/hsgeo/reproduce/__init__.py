"""``hsgeo reproduce CHAPTER``: the numbers of each book chapter, as tables or JSON (GUIDE §5).

Each chapter has a module here with a ``run(seed, scale) -> Reproduction`` function; the book
chapter calls the same function, so the chapter and the command print the same numbers.
"""

from __future__ import annotations

import importlib
import json
import math
from dataclasses import dataclass, field

from hsgeo.errors import InputError

__all__ = ["Row", "Reproduction", "CHAPTERS", "run", "chapter_names"]

#: chapter name -> module (relative to this package) with a ``run(seed, scale)`` function.
CHAPTERS: dict[str, str] = {
    "frame-reference": "frame_reference",
    "line-calibration": "line_calibration",
    "geocoding": "geocoding",
    "rikola": "rikola",
    "pushbroom-ba": "pushbroom_ba",
}


@dataclass
class Row:
    """One quantity of a table: paper | reproduced | truth, with σ̂ (GUIDE §5)."""

    table: str
    quantity: str
    unit: str
    paper: float | None = None
    paper_sigma: float | None = None
    reproduced: float | None = None
    sigma: float | None = None
    truth: float | None = None

    def as_dict(self) -> dict:
        def clean(x):
            if x is None:
                return None
            x = float(x)
            return None if not math.isfinite(x) else x

        return {
            "table": self.table,
            "quantity": self.quantity,
            "unit": self.unit,
            "paper": clean(self.paper),
            "paper_sigma": clean(self.paper_sigma),
            "reproduced": clean(self.reproduced),
            "sigma": clean(self.sigma),
            "truth": clean(self.truth),
        }


@dataclass
class Reproduction:
    """The rows of a chapter's tables and free-form metadata (``meta``), plus chapter objects."""

    chapter: str
    seed: int
    rows: list[Row]
    meta: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict, repr=False)  # results the chapter plots

    def to_json(self) -> str:
        return json.dumps(
            {"chapter": self.chapter, "seed": self.seed,
             "rows": [r.as_dict() for r in self.rows], "meta": self.meta},
            indent=1,
        )

    def table(self, name: str | None = None):
        """The rows as a pandas DataFrame (one table, or all with a ``table`` column)."""
        import pandas as pd

        df = pd.DataFrame([r.as_dict() for r in self.rows])
        if name is not None:
            df = df[df["table"] == name].drop(columns="table")
            if df.empty:
                known = sorted({r.table for r in self.rows})
                raise InputError(f"no table {name!r} in {self.chapter}; tables: {known}")
        return df.reset_index(drop=True)

    def to_text(self) -> str:
        out = [f"{self.chapter} (seed {self.seed})"]
        for t in dict.fromkeys(r.table for r in self.rows):
            out.append(f"\n{t}")
            out.append(f"  {'quantity':<28s}{'unit':>8s}{'paper':>14s}{'reproduced':>14s}"
                       f"{'sigma':>12s}{'truth':>14s}")
            for r in self.rows:
                if r.table != t:
                    continue
                d = r.as_dict()
                f = lambda x, w: f"{x:{w}.6g}" if x is not None else " " * (w - 1) + "–"  # noqa: E731
                out.append(f"  {r.quantity:<28s}{r.unit:>8s}{f(d['paper'], 14)}"
                           f"{f(d['reproduced'], 14)}{f(d['sigma'], 12)}{f(d['truth'], 14)}")
        return "\n".join(out)


def chapter_names() -> list[str]:
    """Chapters that ``hsgeo reproduce`` knows."""
    return list(CHAPTERS)


def run(chapter: str, seed: int = 0, scale: float = 1.0) -> Reproduction:
    """Run a chapter's computation and return its tables."""
    if chapter not in CHAPTERS:
        raise InputError(
            f"unknown chapter {chapter!r}; known chapters: {', '.join(CHAPTERS)}"
        )
    if not (isinstance(seed, int) and seed >= 0):
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    if not (0 < scale <= 1.0):
        raise InputError(f"scale must be in (0, 1], got {scale!r}")
    mod = importlib.import_module(f"hsgeo.reproduce.{CHAPTERS[chapter]}")
    return mod.run(seed=seed, scale=scale)
