"""Tables of results: paper | reproduced | σ̂ | truth (GUIDE §4–§5).

:class:`Row` is one quantity of a table and :class:`Reproduction` a set of tables with metadata;
``hsgeo reproduce`` and the workflows that print tables (``hsgeo calibrate-frame``) return them,
as text (:meth:`Reproduction.to_text`), strict JSON (:meth:`Reproduction.to_json`, ``null`` for
absent or non-finite values) or a pandas DataFrame (:meth:`Reproduction.table`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

from hsgeo.errors import InputError

__all__ = ["Row", "Reproduction"]


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
            {
                "chapter": self.chapter,
                "seed": self.seed,
                "rows": [r.as_dict() for r in self.rows],
                "meta": self.meta,
            },
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
            out.append(
                f"  {'quantity':<28s}{'unit':>8s}{'paper':>14s}{'reproduced':>14s}"
                f"{'sigma':>12s}{'truth':>14s}"
            )
            for r in self.rows:
                if r.table != t:
                    continue
                d = r.as_dict()
                f = lambda x, w: f"{x:{w}.6g}" if x is not None else " " * (w - 1) + "–"  # noqa: E731
                out.append(
                    f"  {r.quantity:<28s}{r.unit:>8s}{f(d['paper'], 14)}"
                    f"{f(d['reproduced'], 14)}{f(d['sigma'], 12)}{f(d['truth'], 14)}"
                )
        return "\n".join(out)
