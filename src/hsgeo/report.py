"""Tables of results: paper | reproduced | σ̂ | truth | z | verdict (GUIDE §4–§5).

Kept as one file: one concern, the table of a reproduction — the row model, the verdict rules
and the one way tables and agreement words are formatted read the same fields (σ̂, z,
provenance) and change together.

:class:`Row` is one quantity of a table and :class:`Reproduction` a set of tables with metadata;
``hsgeo reproduce`` and the workflows that print tables (``hsgeo calibrate-frame``) return them,
as text (:meth:`Reproduction.to_text`), strict JSON (:meth:`Reproduction.to_json`, ``null`` for
absent or non-finite values), a pandas DataFrame of numbers (:meth:`Reproduction.table`) or the
formatted table a chapter shows (:meth:`Reproduction.show`). Every chapter and the command line
format their tables here, in one way:

* ``z`` is ``(reproduced − truth) / σ̂``: how far the estimate lies from the simulation's truth,
  in units of its own standard deviation (σ̂ from the adjustment, or the spread over ``n_runs``
  repeated simulations for statistics such as an NMAD that have no σ̂ of their own — the σ of
  the mean when the value is a mean of the runs, :meth:`Row.from_runs`); a "not testable" row
  shows no z;
* the **verdict** says whether the paper's value was reproduced (:data:`VERDICTS`), with its
  reason; it is computed from the numbers and the truth's **provenance** (:meth:`Row.rule`,
  GUIDE §4): agreement built in (the truth is the paper's value, computed from it, or tuned to
  it) is ``"by construction"``, never ``"reproduced"``; a tuning that missed by more than
  3σ (or by more than 10 % without a σ) and a paper-valued truth recovered more than 3σ̂ off
  (a failed recovery) are ``"differs"``; a spread from fewer than 8 runs, or a "reproduced"
  whose σ exceeds half the paper's value, is ``"not testable"``. A number that another
  chapter owns is shown as ``"context"`` (:attr:`Row.judged_in`). A chapter may state another
  verdict (an *override*, e.g. ``"planned"``) only with a reason, which the scoreboard prints
  (:meth:`Row.overridden`);
* words about agreement in a chapter's prose come from :func:`agreement` and :func:`summarize`,
  never typed.
"""

from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import dataclass, field

from hsgeo.errors import InputError
from hsgeo.terminal import strict_values
from hsgeo.vocabulary import display_unit, quantity_label

__all__ = [
    "glue_figure",
    "highlight_below",
    "glue_value",
    "Row",
    "Reproduction",
    "VERDICTS",
    "PROVENANCES",
    "Z_LIMIT",
    "MIN_RUNS",
    "TUNED_MISS",
    "SIGMA_OVER_PAPER",
    "agreement",
    "summarize",
    "format_value",
    "format_rows",
    "styled",
    "NUMERIC_COLUMNS",
    "as_text",
    "glue_text",
    "from_estimates",
    "VERDICT_MEANING",
    "true_minus",
    "with_data_labels",
    "with_toggle",
    "drop_empty_columns",
    "MAX_TABLE_ROWS",
    "panel_columns",
    "PANEL_COLUMNS_KEY",
    "MAX_PANEL_COLUMNS",
]

#: The verdicts of a claim (ReScience style). ``by construction``: the truth (or the outcome) is
#: the paper's value, computed from the paper's values or tuned to meet them, so agreement with
#: the paper was built in and only ``z`` (the recovery of the truth) is an outcome.
VERDICTS = ("reproduced", "differs", "by construction", "not testable", "planned")

#: One sentence per verdict: what it means (the scoreboard prints them).
VERDICT_MEANING = {
    "reproduced": "an independent outcome (our chosen assumptions, no paper value built into its "
    "truth) lies within 3σ of the paper's value, σ combining our σ̂ or run spread with the "
    "paper's σ",
    "differs": "the outcome lies more than 3σ from the paper's value; for a tuned or "
    "paper-derived truth this means the tuning missed (a tuning without σ misses beyond 10 %), "
    "and for a truth that is the paper's value (or computed from it) recovered more than 3σ̂ "
    "from it, the recovery failed",
    "by construction": "the truth is the paper's value, computed from the paper's values or "
    "tuned so that the outcome meets them: agreement was built in and is not counted as "
    "reproduced (the reason gives how well the estimate recovered its truth)",
    "not testable": "there is no reproduced value, or neither side has a σ to judge a "
    "difference by, or our value or σ rests on fewer than 8 runs, or our σ exceeds half the "
    "paper's value (a comparison that could not fail), or the chapter states why the "
    "comparison carries no information; no z is shown",
    "planned": "the chapter that reproduces the claim is not written yet",
}

#: Where a row's truth comes from (GUIDE §4): ``paper`` (the paper's value used as truth),
#: ``derived`` (computed from the paper's values, or the pseudo-true value a misspecified model
#: reaches on noise-free data of the same simulation), ``chosen`` (our stated assumption), ``tuned``
#: (chosen so that an outcome meets a paper value).
PROVENANCES = ("paper", "derived", "chosen", "tuned")

#: |z| up to which a value counts as agreeing (3σ, GUIDE §6).
Z_LIMIT = 3.0

#: Fewest repeated simulations whose spread may decide a verdict (GUIDE §4, "claims need seeds").
MIN_RUNS = 8

#: Relative miss of the paper's value beyond which a tuning without any σ missed (10 %).
TUNED_MISS = 0.10

#: A "reproduced" whose σ exceeds this fraction of the paper's value could not have failed: it is
#: "not testable" (GUIDE §4).
SIGMA_OVER_PAPER = 0.5

_MINUS = "\u2212"
_SUPERSCRIPT = str.maketrans(
    "-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079"
)


def _clean(x) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True, kw_only=True)
class Row:
    """One quantity of a table: paper | reproduced | σ̂ | truth, with z and a verdict (GUIDE §5).

    Frozen and built by keyword (``Row(table=..., quantity=..., unit=..., paper=...)``); a
    changed copy is :func:`dataclasses.replace`.

    Parameters
    ----------
    table, quantity, unit : str
        The table's name (``"000 Table 1"``), the quantity (``"c"``) and its unit (``"px"``;
        ``""`` or ``"1"`` for a number).
    paper, paper_sigma : float, optional
        The paper's value and the standard deviation it gives.
    reproduced, sigma : float, optional
        Our value and its standard deviation (the σ that ``z`` divides by): σ̂ of the
        adjustment, or the spread over ``n_runs`` repeated simulations — of one run's value, or
        of the mean's when ``reproduced`` is the mean of the runs (``mean_of_runs``; build such
        a row with :meth:`Row.from_runs`).
    truth : float, optional
        The simulation's true value.
    n_runs : int, optional
        Set when ``sigma`` is the spread over this many simulations (not an adjustment's σ̂).
    verdict, reason : str, optional
        A verdict stated by the chapter (one of :data:`VERDICTS`) and its reason; computed by
        :meth:`judge` when absent.
    provenance : str, optional
        Where the truth comes from, one of :data:`PROVENANCES` (GUIDE §4).
    mean_of_runs : bool
        ``reproduced`` is the mean over ``n_runs`` runs and ``sigma`` the σ of that mean
        (one run's spread / √n_runs), not one run's value and spread.
    judged_in : str, optional
        The chapter that owns (judges) this published number when it is another chapter: the
        row is shown here as context, its verdict ``"context"`` (never counted), its reason
        naming the owner and what this chapter's numbers alone would give
        (:data:`hsgeo.reproduce.scoreboard.OWNERS`).
    """

    table: str
    quantity: str
    unit: str
    paper: float | None = None
    paper_sigma: float | None = None
    reproduced: float | None = None
    sigma: float | None = None
    truth: float | None = None
    n_runs: int | None = None
    verdict: str | None = None
    reason: str = ""
    provenance: str | None = None
    mean_of_runs: bool = False
    judged_in: str | None = None

    def __post_init__(self):
        if self.verdict is not None and self.verdict not in VERDICTS:
            raise InputError(f"verdict {self.verdict!r} of {self.quantity}: use one of {VERDICTS}")
        if self.verdict == "reproduced" and not _reproduced_bar(
            self.n_runs, self.sigma, self.paper
        ):
            raise InputError(
                f"verdict 'reproduced' of {self.quantity} is stated for a value that rests on "
                f"{self.n_runs} runs or whose σ ({self.sigma}) exceeds half the paper's value "
                f"({self.paper}): such a comparison could not fail; leave verdict unset "
                "(Row.rule judges it 'not testable')"
            )
        if self.verdict is not None and not self.reason:
            raise InputError(
                f"verdict {self.verdict!r} of {self.quantity} is stated without a reason: a "
                "chapter may override the computed verdict only with a reason (Row.reason)"
            )
        if self.mean_of_runs and not self.n_runs:
            raise InputError(
                f"{self.quantity}: a mean of runs (mean_of_runs) needs n_runs, the number of runs"
            )
        if self.provenance is not None and self.provenance not in PROVENANCES:
            raise InputError(
                f"provenance {self.provenance!r} of {self.quantity}: use one of {PROVENANCES}"
            )

    @classmethod
    def from_runs(cls, table: str, quantity: str, unit: str, values, *, mean: bool, **kw) -> Row:
        """A row whose spread comes from repeated simulations: ``values`` holds one value per
        run (non-finite ones dropped). With ``mean=True`` the row reports their mean and the σ
        of that mean (sample σ / √n), so that ``z`` of a mean uses the mean's σ (GUIDE §4); with
        ``mean=False`` the first run's value (the chapter's campaign) and one run's σ. Other
        keywords (``paper``, ``truth``, ``provenance`` …) go to the row.

        >>> r = Row.from_runs("T", "q", "m", [1.0, 2.0, 3.0, 4.0], mean=True)
        >>> r.reproduced, round(r.sigma, 4), r.n_runs, r.mean_of_runs
        (2.5, 0.6455, 4, True)
        """
        import numpy as np

        v = np.asarray(values, dtype=float).ravel()
        v = v[np.isfinite(v)]
        n = int(v.size)
        sd = float(np.std(v, ddof=1)) if n > 1 else None
        if mean:
            rep = float(v.mean()) if n else None
            sigma = sd / math.sqrt(n) if sd is not None else None
        else:
            rep = float(v[0]) if n else None
            sigma = sd
        return cls(
            table=table,
            quantity=quantity,
            unit=unit,
            reproduced=rep,
            sigma=sigma,
            n_runs=n,
            mean_of_runs=mean,
            **kw,
        )

    @property
    def z(self) -> float | None:
        """``(reproduced − truth) / σ``, or None when any of them is absent or σ = 0."""
        r, t, s = _clean(self.reproduced), _clean(self.truth), _clean(self.sigma)
        if r is None or t is None or not s:
            return None
        return (r - t) / s

    @property
    def z_paper(self) -> float | None:
        """``(reproduced − paper) / hypot(σ, paper σ)``, or None without a spread to judge by."""
        r, p = _clean(self.reproduced), _clean(self.paper)
        s = math.hypot(_clean(self.sigma) or 0.0, _clean(self.paper_sigma) or 0.0)
        if r is None or p is None or s == 0.0:
            return None
        return (r - p) / s

    def truth_is_paper(self) -> bool:
        """True when the simulation took the paper's value as its truth."""
        p, t = _clean(self.paper), _clean(self.truth)
        if p is None or t is None:
            return False
        return abs(p - t) <= 1e-9 * max(abs(p), abs(t)) or (p == 0.0 == t)

    def judge(self) -> tuple[str | None, str]:
        """The verdict on the paper's value and its reason (None for a row without a paper value):
        the verdict the chapter stated (with its reason), else :meth:`rule`'s.
        """
        if self.judged_in is not None and _clean(self.paper) is not None:
            v, why = (self.verdict, self.reason) if self.verdict is not None else self.rule()
            return "context", f"judged in the {self.judged_in} chapter; here: {v}, {why}"
        if self.verdict is not None:
            return self.verdict, self.reason
        return self.rule()

    @property
    def overridden(self) -> bool:
        """True when the chapter stated a verdict other than :meth:`rule`'s (``planned`` is a
        status, not an override).
        """
        return (
            self.verdict is not None
            and self.judged_in is None
            and self.verdict != "planned"
            and self.verdict != self.rule()[0]
        )

    def rule(self) -> tuple[str | None, str]:
        """The verdict computed from the numbers and the provenance (GUIDE §4).

        In this order:

        1. None for a row without a paper value; ``not testable`` without a reproduced value, or
           when it rests on fewer than :data:`MIN_RUNS` runs (``n_runs``, with or without a σ:
           such a value decides nothing);
        2. when the truth is the paper's value (provenance ``paper``, or truth = paper), was
           computed from the paper's values (``derived``) or tuned to meet them (``tuned``):
           ``differs`` beyond 3σ of the paper ("tuning missed" for ``tuned``, "recovery failed"
           when its estimate is also beyond 3σ̂ of the tuned truth); ``differs``
           ("recovery failed") when a ``paper`` or ``derived`` truth was recovered more than
           3σ̂ from it — a failed recovery is no agreement built in; ``differs`` ("tuning
           missed") when a ``tuned`` row without any σ misses the paper's value by more than
           :data:`TUNED_MISS` (10 %); otherwise ``by construction``;
        3. otherwise (``chosen``, or no provenance): ``reproduced`` / ``differs`` by
           |z_paper| ≤ 3, z_paper combining our σ (σ̂ or the spread over runs) with the paper's;
           ``not testable`` when neither side has a σ, and a ``reproduced`` whose σ exceeds
           :data:`SIGMA_OVER_PAPER` (half) of the paper's value is ``not testable`` (it could
           not have failed).

        ``reason`` (set by the chapter without a verdict) replaces the computed reason of a
        ``differs`` or ``not testable``.
        """
        if _clean(self.paper) is None:
            return None, ""
        if _clean(self.reproduced) is None:
            return "not testable", self.reason or "no reproduced value"
        if self.n_runs is not None and self.n_runs < MIN_RUNS:
            # with or without a σ: a value from fewer runs decides nothing (without a σ it
            # would be judged by the paper's σ alone, on one or two campaigns)
            return "not testable", self.reason or (
                f"its σ is the spread over only {self.n_runs} runs; a verdict needs at least "
                f"{MIN_RUNS}"
                if _clean(self.sigma) is not None
                else f"it rests on only {self.n_runs} runs, without a σ; a verdict needs at "
                f"least {MIN_RUNS}"
            )
        zp = self.z_paper
        spread = self._spread_words()
        built_in = self.provenance in ("paper", "derived", "tuned") or self.truth_is_paper()
        if built_in:
            return self._rule_built_in(zp, spread)
        if zp is None:
            return "not testable", self.reason or "neither the paper nor the reproduction has a σ"
        if abs(zp) <= Z_LIMIT:
            s, p = _clean(self.sigma), abs(_clean(self.paper))
            if s is not None and p > 0 and s > SIGMA_OVER_PAPER * p:
                return "not testable", self.reason or (
                    f"our σ ({s:.3g}) exceeds half the paper's value ({p:.3g}): agreement "
                    "could not have failed"
                )
            return "reproduced", f"{agreement(zp)} of the paper (our {spread} and the paper's σ)"
        return "differs", self.reason or f"{abs(zp):.1f}σ from the paper ({spread})"

    def _spread_words(self) -> str:
        if self.mean_of_runs:
            return f"σ of a mean of {self.n_runs} runs"
        return f"spread over {self.n_runs} runs" if self.n_runs else "σ̂"

    def _rule_built_in(self, zp, spread) -> tuple[str, str]:
        """:meth:`rule` for a truth that is, or was computed from or tuned to, the paper's value."""
        tuned = self.provenance == "tuned"
        if tuned:
            what = "tuned so that it meets the paper's value"
        elif self.provenance == "derived":
            what = "its truth was computed from the paper's values"
        else:
            what = "simulated with the paper's value as truth"
        z = self.z
        if z is not None and abs(z) > Z_LIMIT and not tuned:
            return "differs", self.reason or (
                f"recovery failed: {what}, recovered {abs(z):.1f}σ̂ from it"
            )
        if zp is not None and abs(zp) > Z_LIMIT:
            if tuned and z is not None and abs(z) > Z_LIMIT:  # the estimate, not the tuning
                return "differs", self.reason or (
                    f"recovery failed: {what}, recovered {abs(z):.1f}σ̂ from its truth and "
                    f"{abs(zp):.1f}σ from the paper ({spread})"
                )
            missed = "tuning missed" if tuned else what
            return "differs", self.reason or f"{missed}: {abs(zp):.1f}σ from the paper ({spread})"
        if tuned and zp is None:
            r, p = _clean(self.reproduced), _clean(self.paper)
            off = abs(r - p) / abs(p) if p else (0.0 if r == p else math.inf)
            if off > TUNED_MISS:
                return "differs", self.reason or (
                    f"tuning missed: {100 * off:.0f} % from the paper's value (no σ to judge "
                    f"by; a tuning without σ misses beyond {100 * TUNED_MISS:.0f} %)"
                )
        if z is not None:
            how = f"recovered {agreement(z)} of its truth"
        elif zp is not None:
            how = f"{agreement(zp)} of the paper ({spread})"
        elif tuned:
            how = f"no σ to judge by, within {100 * TUNED_MISS:.0f} % of the paper"
        else:
            how = "no σ to judge by"
        return "by construction", f"{what}; {how}"

    def as_dict(self) -> dict:
        """Strict-JSON-ready dict: absent or non-finite numbers are None."""
        verdict, reason = self.judge()
        z = None if verdict == "not testable" or self.rule()[0] == "not testable" else self.z
        return {
            "table": self.table,
            "quantity": self.quantity,
            "unit": self.unit,
            "paper": _clean(self.paper),
            "paper_sigma": _clean(self.paper_sigma),
            "reproduced": _clean(self.reproduced),
            "sigma": _clean(self.sigma),
            "truth": _clean(self.truth),
            "z": _clean(z),
            "n_runs": self.n_runs,
            "verdict": verdict,
            "reason": reason,
            "provenance": self.provenance,
            "override": self.overridden,
            "mean_of_runs": self.mean_of_runs,
            "judged_in": self.judged_in,
        }


def agreement(z: float | None) -> str:
    """Words for a z-score: ``"within 1σ"`` … ``"within 3σ"``, else ``"4.2σ off"``.

    >>> agreement(0.4), agreement(-2.56), agreement(3.3)
    ('within 1σ', 'within 3σ', '3.3σ off')
    """
    if z is None or not math.isfinite(z):
        return "without a σ to judge"
    a = abs(z)
    for k in (1, 2, 3):
        if a <= k:
            return f"within {k}σ"
    return f"{a:.1f}σ off"


def summarize(rows: list[Row], what: str = "parameters") -> dict:
    """Computed words about the z-scores of ``rows`` (those with a z), for a chapter's prose.

    Returns a dict with ``n``, ``n_within_1``, ``n_within_3``, ``max_abs_z``, ``worst`` (the
    quantity with the largest |z|), ``n_negative``, ``n_positive``, ``sign_p`` (two-sided sign
    test probability of a sign balance at least this lopsided under zero-mean errors) and
    ``sentence``, e.g. "7 of 8 parameters lie within 3σ̂ of the truth; the largest deviation is
    K1, band 5 at 1.8σ̂." (the quantity in a reader's words, :mod:`hsgeo.vocabulary`; ``worst``
    keeps the key).
    """
    zs = [(r.quantity, r.z) for r in rows if r.z is not None]
    n = len(zs)
    if n == 0:
        return {"n": 0, "sentence": f"No {what} have a σ̂ to judge them by."}
    within1 = sum(abs(z) <= 1 for _, z in zs)
    within3 = sum(abs(z) <= Z_LIMIT for _, z in zs)
    worst, zw = max(zs, key=lambda qz: abs(qz[1]))
    neg = sum(z < 0 for _, z in zs)
    pos = n - neg
    k = min(neg, pos)
    sign_p = min(1.0, 2 * sum(math.comb(n, i) for i in range(k + 1)) / 2**n)
    if within3 == n:
        head = (
            f"all {n} {what} lie within 3σ̂ of the truth"
            if n > 1
            else f"the {what[:-1]} lies within 3σ̂ of the truth"
        )
    else:
        head = f"{within3} of {n} {what} lie within 3σ̂ of the truth"
    sentence = (
        f"{head[0].upper()}{head[1:]}; the largest deviation is {quantity_label(worst)} at "
        f"{abs(zw):.1f}σ̂"
    )
    if n >= 4 and k == 0:
        side = "below" if neg else "above"
        sentence += f"; all {n} lie {side} the truth (sign test p = {sign_p:.2g})"
    return {
        "n": n,
        "n_within_1": within1,
        "n_within_3": within3,
        "max_abs_z": abs(zw),
        "worst": worst,
        "n_negative": neg,
        "n_positive": pos,
        "sign_p": sign_p,
        "sentence": sentence + ".",
    }


def _sci(x: float, digits: int) -> str:
    mant, exp = f"{x:.{digits}e}".split("e")
    return f"{mant} × 10{str(int(exp)).translate(_SUPERSCRIPT)}".replace("-", _MINUS)


def format_value(x, sigma=None, sig: int = 4) -> str:
    """A number for a table: rounded to σ's second significant digit when σ is given, else to
    ``sig`` significant digits; scientific notation (× 10ⁿ) below 1e-3 and from 1e6; ``—`` when
    absent or not finite; a true minus sign.

    >>> format_value(3539.123, 14.2), format_value(-0.00414), format_value(None)
    ('3539', '−0.004140', '—')
    """
    x = _clean(x)
    if x is None:
        return "—"
    if x == 0.0:
        return "0"
    s = _clean(sigma)
    mag = math.floor(math.log10(abs(x))) if x != 0 else 0
    place = math.floor(math.log10(s)) - 1 if s else mag - (sig - 1)
    tiny = place < -6 if s else (x != 0 and mag < -3)
    if tiny or mag >= 6:
        return _sci(x, max(0, mag - place))
    return f"{x:.{max(0, -place)}f}".replace("-", _MINUS)


def _format_paper(x) -> str:
    """The paper's value as printed: the shortest repr of the stored float (at most 6 digits)."""
    x = _clean(x)
    if x is None:
        return "—"
    text = repr(x) if len(repr(x).lstrip("-0.").replace(".", "")) <= 6 else f"{x:.6g}"
    if "e" in text:
        mant, exp = text.split("e")
        text = f"{mant} × 10{str(int(exp)).translate(_SUPERSCRIPT)}"
    elif text.endswith(".0"):
        text = text[:-2]
    return text.replace("-", _MINUS)


#: Columns of :func:`format_rows` that hold numbers (right-aligned by :func:`styled`).
NUMERIC_COLUMNS = ("paper", "reproduced", "σ̂", "truth", "z")


def format_rows(rows: list[Row]):
    """The rows as a DataFrame of display strings: quantity | unit | paper | reproduced | σ̂ |
    truth | z | verdict (no index; σ is marked ``(n runs)`` when it is a spread over runs).

    Quantities and units are shown in a reader's words (:mod:`hsgeo.vocabulary`: ``um`` → µm,
    ``c_minus_mean_band0_450nm_um`` → "c − mean c, band 0 (450 nm)"); the rows themselves, and
    so ``to_json``, keep their internal keys.
    """
    import pandas as pd

    out = []
    for r in rows:
        verdict, _ = r.judge()
        paper = _format_paper(r.paper)
        if _clean(r.paper_sigma) is not None:
            paper += f" ± {_format_paper(r.paper_sigma)}"
        sig = format_value(r.sigma, r.sigma, sig=2) if _clean(r.sigma) else "—"
        if r.n_runs and sig != "—":
            sig += f" (mean of {r.n_runs})" if r.mean_of_runs else f" ({r.n_runs} runs)"
        z = None if "not testable" in (verdict, r.rule()[0]) else r.z
        out.append(
            {
                "quantity": quantity_label(r.quantity),
                "unit": display_unit(r.quantity, r.unit),
                "paper": paper,
                "reproduced": format_value(r.reproduced, r.sigma),
                "σ̂": sig,
                "truth": format_value(r.truth, r.sigma),
                "z": "—" if z is None else f"{z:+.1f}".replace("-", _MINUS),
                "verdict": verdict or "—",
            }
        )
    cols = ["quantity", "unit", "paper", "reproduced", "σ̂", "truth", "z", "verdict"]
    return pd.DataFrame(out, columns=cols)


#: Cell padding of the book's tables (also in book/_static/hsgeo.css, for tables made elsewhere).
_PAD = "0.3em 0.5em"


def highlight_below(df, limits: dict, *, fmt: str = "{:.1f}", colour: str = "#f4b6b6"):
    """A pandas Styler of ``df`` without index: the columns named in ``limits`` formatted with
    ``fmt``, their cells below that column's limit shaded ``colour`` (e.g. a fit whose LRE fails
    a certification criterion). As every table of the book, it carries :func:`with_data_labels`
    and goes under a toggle when it has more than :data:`MAX_TABLE_ROWS` rows.
    """

    def shade(col):
        return [f"background-color: {colour}" if v < limits[col.name] else "" for v in col]

    cols = list(limits)
    style = _card_styler()(df).apply(shade, subset=cols).format(fmt, subset=cols)
    return style.hide(axis="index")


_RUNS = re.compile(r"^(.*\S) (\((?:mean of )?\d+(?: runs)?\))$")


#: A hyphen-minus written as a minus sign: at the start of a word, before a digit ("-0.8 σ̂",
#: "(-3.1, 2.0)"), not inside one ("2-3 s", "2026-11-28", "EPSG:25832+5941").
_HYPHEN_MINUS = re.compile(r"(?:(?<=^)|(?<=[\s(\[=:,;/]))-(?=\d)")


def true_minus(value) -> str:
    """A text cell with a true minus sign (U+2212) where a hyphen-minus starts a number."""
    return _HYPHEN_MINUS.sub("\u2212", str(value))


_BREAK = re.compile(r" (?=[±×] )")


def _unbroken(text: str) -> str:
    """A number's text as spans that never break inside (``class="hsgeo-nw"``), with a break
    allowed before its "± σ" and its "× 10ⁿ": "8.661 ± 0.003" may take two lines in a narrow
    column, so that a table of eight columns fits the book's column on a wide screen.
    """
    import html as html_mod

    parts = _BREAK.split(text)
    if len(parts) == 1:
        return html_mod.escape(text, quote=False)
    return " ".join(
        f'<span class="hsgeo-nw">{html_mod.escape(p, quote=False)}</span>' for p in parts
    )


def _runs_on_own_line(value) -> str:
    """A number cell's HTML: its "(n runs)" / "(mean of n)" note below the number, a break
    allowed before "±" and "×" (:func:`_unbroken`).
    """
    text = true_minus(value)
    m = _RUNS.match(text)
    if m:
        return f'{_unbroken(m[1])}<br><span class="hsgeo-runs">{m[2]}</span>'
    return _unbroken(text)


_HEAD = re.compile(r'<th [^>]*class="col_heading level0 col(\d+)"[^>]*>(.*?)</th>', re.S)
_CELL = re.compile(r'<td (?!data-label)([^>]*class="data row\d+ col(\d+)[ "])')


def with_data_labels(html: str) -> str:
    """A Styler's HTML table whose every body cell names its column (``data-label``), so that
    the book's CSS can show each row as a card on a phone, every value beside its column's name
    (the verdict never beyond a sideways scroll).
    """
    import html as html_mod

    names = {
        int(col): html_mod.escape(re.sub(r"<[^>]+>", "", text).strip(), quote=True)
        for col, text in _HEAD.findall(html)
    }
    return _CELL.sub(lambda m: f'<td data-label="{names.get(int(m[2]), "")}" {m[1]}', html)


#: The most rows a table shown in view may have; a longer one is shown under a toggle whose
#: summary counts its rows and verdicts (``make check-book`` asserts it).
MAX_TABLE_ROWS = 20


def with_toggle(html: str, df) -> str:
    """A table's HTML as the book shows it: as it is when ``df`` has at most
    :data:`MAX_TABLE_ROWS` rows, else under a toggle (``<details>``) whose summary says how many
    rows it holds and, for a table with a verdict column, how many of each verdict.
    """
    n = len(df)
    if n <= MAX_TABLE_ROWS:
        return html
    what = f"{n} rows"
    if "verdict" in df.columns:
        counts = df["verdict"].value_counts()
        judged = [f"{k_n} {k}" for k, k_n in counts.items() if k != "—"]
        if judged:
            what += ": " + ", ".join(judged)
    return (
        f'<details class="hsgeo-long-table"><summary>The table ({what}) — show</summary>'
        f"{html}</details>"
    )


def drop_empty_columns(df):
    """``df`` without the columns whose every cell is "—" (nothing to read in them)."""
    if not len(df):
        return df
    empty = [c for c in df.columns if (df[c].astype(str).str.strip() == "—").all()]
    return df.drop(columns=empty)


@functools.cache
def _card_styler():
    """The pandas Styler whose HTML carries :func:`with_data_labels` (created on first use: pandas
    is imported lazily).
    """
    from pandas.io.formats.style import Styler

    class CardStyler(Styler):
        def to_html(self, *args, **kwargs):
            html = super().to_html(*args, **kwargs)
            return with_data_labels(html) if isinstance(html, str) else html

        def _repr_html_(self):  # pandas' own calls to_html; labels are added once either way
            html = super()._repr_html_()
            if not isinstance(html, str):
                return html
            return with_toggle(with_data_labels(html), self.data)

    return CardStyler


def styled(df, numeric: tuple[str, ...] = NUMERIC_COLUMNS):
    """A DataFrame of display strings as the book shows a table: a pandas Styler without index,
    class ``hsgeo-table``, every cell padded, the ``numeric`` columns right-aligned (header too,
    class ``hsgeo-num``) and the others left-aligned (``hsgeo-text``). Columns whose every cell
    is "—" are left out (:func:`drop_empty_columns`); a table of more than
    :data:`MAX_TABLE_ROWS` rows is shown under a toggle (:func:`with_toggle`).
    """
    import pandas as pd

    df = drop_empty_columns(df)

    num = [c for c in df.columns if c in numeric]
    text = [c for c in df.columns if c not in numeric]
    classes = pd.DataFrame(
        [["hsgeo-num" if c in num else "hsgeo-text" for c in df.columns]] * len(df),
        index=df.index,
        columns=df.columns,
    )
    heads = {
        c: [{"selector": "th", "props": f"text-align: {'right' if c in num else 'left'}"}]
        for c in df.columns
    }
    style = (
        _card_styler()(df)
        .hide(axis="index")
        .set_table_attributes('class="hsgeo-table"')
        .set_td_classes(classes)
        .set_table_styles([{"selector": "th, td", "props": f"padding: {_PAD}"}])
        .set_table_styles(heads, overwrite=False)
    )
    if num:
        style = style.set_properties(subset=num, **{"text-align": "right"})
        # "0.0052 (24 runs)": the count on a line of its own, and "8.661 ± 0.003" may break
        # before its "±", so a table fits its column on a wide screen (a number never breaks)
        style = style.format(_runs_on_own_line, subset=num)
    if text:
        style = style.set_properties(subset=text, **{"text-align": "left"})
        style = style.format(true_minus, subset=text)  # "ASF at −20°", as the numbers have
    return style


class _Prose(str):
    """Text glued into a chapter's prose: ``{glue:text}`` reads its text/plain (the string),
    ``{glue}`` its text/markdown (the same text, Markdown-escaped), so neither shows a Python
    repr (``np.float64(…)``, quotes) or a code box.
    """

    def _repr_markdown_(self) -> str:
        return "".join("\\" + ch if ch in _MD_SPECIAL else ch for ch in self)


_MD_SPECIAL = set("\\`*_{}[]<>|$~#")


def as_text(value, sigma=None, *, unit: str = "", sig: int = 4) -> str:
    """A value as a chapter's prose shows it: an integer (Python or numpy) as digits, a float
    through :func:`format_value` (rounded to σ when given, else to ``sig`` significant digits,
    a true minus sign, "—" when absent), anything else as ``str``; ``unit`` appended after a
    space, shown in a reader's spelling (:func:`hsgeo.vocabulary.unit_label`: ``um`` → µm).

    >>> import numpy as np
    >>> as_text(np.float64(1.23456)), as_text(np.int64(8)), as_text(-0.0213, 0.004, unit="um")
    ('1.235', '8', '−0.0213 µm')
    """
    from numbers import Integral, Real

    from hsgeo.vocabulary import unit_label

    if isinstance(value, bool):
        text = str(value)
    elif isinstance(value, Integral):
        text = str(int(value)).replace("-", _MINUS)
    elif isinstance(value, Real) or value is None:
        text = format_value(value, sigma, sig=sig)
    else:
        text = str(value)
    if unit and text != "—":
        shown = unit_label(unit)
        text += "" if shown == "—" else f" {shown}"
    return text


def _myst_glue():
    """myst-nb's ``glue``: the chapters' glue needs the book's optional extra (``hsgeo[book]``);
    the library and the command line do not, so it is imported here only, when a chapter glues.
    """
    try:
        from myst_nb import glue
    except ImportError as exc:  # a wheel installed without the book extra
        raise ImportError(
            "hsgeo.report.glue_* need myst-nb, part of the book's extra: pip install 'hsgeo[book]'"
        ) from exc
    return glue


def glue_text(name: str, value, sigma=None, *, unit: str = "", sig: int = 4) -> str:
    """Glue ``value`` for a chapter's prose as formatted text (:func:`as_text`), never as a
    Python repr: ``{glue:text}`name``` and ``{glue}`name``` both show e.g. ``1.235 µm``. Returns
    the text. Needs myst-nb (the book's environment).
    """
    glue = _myst_glue()
    text = _Prose(as_text(value, sigma, unit=unit, sig=sig))
    glue(name, text, display=False)
    return str(text)


def glue_value(name: str, value) -> None:
    """Glue ``value`` as it is, hidden, for a chapter's ``{glue}`` roles and later cells (a
    numpy scalar as the Python number it holds). Returns None, as ``glue`` does, so that a cell
    ending with it shows nothing. Needs myst-nb.
    """
    import numpy as np

    glue = _myst_glue()
    if isinstance(value, np.generic):
        value = value.item()
    glue(name, value, display=False)


#: The PNG text key under which :func:`glue_figure` records a figure's panel columns, read
#: back from the built book by ``make check-book`` (tests/book/pagecheck.py).
PANEL_COLUMNS_KEY = "hsgeo panel columns"
#: The most panel columns a figure may have: wider, its panels are a few px wide on a phone.
MAX_PANEL_COLUMNS = 2


def panel_columns(fig) -> int:
    """The number of panel columns of a matplotlib figure: the distinct grid columns in which a
    visible subplot starts (colour bars and axes placed by hand are not panels); 1 for a figure
    without subplots.
    """
    starts = set()
    for ax in fig.axes:
        spec = ax.get_subplotspec() if hasattr(ax, "get_subplotspec") else None
        if spec is None or not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        # the figure's own grid (a colour bar nests its panel's cell in a grid of its own)
        starts.add(spec.get_topmost_subplotspec().colspan.start)
    return max(1, len(starts))


class _GluedFigure:
    """A figure's PNG as IPython's inline backend makes it (``bbox_inches="tight"``, the
    figure's dpi and colours), with its panel columns in a PNG text chunk
    (:data:`PANEL_COLUMNS_KEY`).
    """

    def __init__(self, fig):
        try:
            from IPython.core.pylabtools import print_figure
        except ImportError as exc:  # a wheel installed without the book extra
            raise ImportError(
                "hsgeo.report.glue_figure needs IPython, part of the book's extra: "
                "pip install 'hsgeo[book]'"
            ) from exc

        self.panel_columns = panel_columns(fig)
        self._png = print_figure(fig, "png", metadata={PANEL_COLUMNS_KEY: str(self.panel_columns)})

    def _repr_png_(self) -> bytes:
        return self._png

    def __repr__(self) -> str:
        return f"<a figure of {self.panel_columns} panel column(s)>"


def glue_figure(name: str, fig) -> None:
    """Glue a matplotlib figure for a ``{glue:figure}`` directive, hidden, and close it (so the
    cell does not show it a second time). The PNG records the figure's panel columns
    (:func:`panel_columns`); a figure of more than :data:`MAX_PANEL_COLUMNS` is refused, as its
    panels would be unreadable on a phone (``make check-book`` checks the built pages too).
    Needs myst-nb.
    """
    import matplotlib.pyplot as plt

    glue = _myst_glue()
    n = panel_columns(fig)
    if n > MAX_PANEL_COLUMNS:
        plt.close(fig)
        raise InputError(
            f"figure {name!r} has {n} panel columns: lay its panels out in at most "
            f"{MAX_PANEL_COLUMNS} columns (more rows), or split it into figures"
        )
    glue(name, _GluedFigure(fig), display=False)
    plt.close(fig)


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
                "meta": strict_values(self.meta),
            },
            indent=1,
            allow_nan=False,
        )

    @classmethod
    def from_json(cls, text: str) -> Reproduction:
        """The inverse of :meth:`to_json` (rows and meta; ``extras`` are not serialized)."""
        d = json.loads(text)
        fields = ("table", "quantity", "unit", "paper", "paper_sigma", "reproduced", "sigma")
        rows = [
            Row(
                **{k: r[k] for k in fields},
                truth=r["truth"],
                n_runs=r.get("n_runs"),
                # as judged when written (the same numbers: an override stays one, a computed
                # verdict equals Row.rule's); "tuned" is the former name of "by construction"
                verdict=_stored_verdict(r),
                reason=_stored_reason(r),
                provenance=r.get("provenance"),
                mean_of_runs=bool(r.get("mean_of_runs", False)),
                judged_in=r.get("judged_in"),
            )
            for r in d["rows"]
        ]
        return cls(d["chapter"], d["seed"], rows, d.get("meta") or {})

    def tables(self) -> list[str]:
        """The table names, in order."""
        return list(dict.fromkeys(r.table for r in self.rows))

    def rows_of(self, name: str) -> list[Row]:
        """The rows of one table (an error naming the known tables if there is none)."""
        rows = [r for r in self.rows if r.table == name]
        if not rows:
            raise InputError(f"no table {name!r} in {self.chapter}; tables: {self.tables()}")
        return rows

    def row(self, table: str, quantity: str) -> Row:
        """The row of ``quantity`` in ``table`` (an error naming the table's quantities if none)."""
        rows = self.rows_of(table)
        for r in rows:
            if r.quantity == quantity:
                return r
        raise InputError(
            f"no quantity {quantity!r} in table {table!r}; quantities: {[r.quantity for r in rows]}"
        )

    def verdict_counts(self, table: str) -> str:
        """The verdicts of one table counted, most frequent first: ``"3 reproduced, 1 differs"``."""
        import pandas as pd

        counts = pd.Series([r.judge()[0] for r in self.rows_of(table)]).value_counts()
        return ", ".join(f"{n} {k}" for k, n in counts.items())

    def table(self, name: str | None = None):
        """The rows as a pandas DataFrame of numbers (one table, or all with a ``table`` column)."""
        import pandas as pd

        rows = self.rows if name is None else self.rows_of(name)
        df = pd.DataFrame([r.as_dict() for r in rows])
        if name is not None:
            df = df.drop(columns="table")
        return df.reset_index(drop=True)

    def show(self, name: str, columns: list[str] | None = None):
        """One table as the book shows it (a pandas Styler without index; see :func:`format_rows`).

        ``columns`` selects and orders columns, e.g.
        ``["quantity", "unit", "paper", "reproduced"]``.
        """
        df = format_rows(self.rows_of(name))
        if columns is not None:
            df = df[columns]
        return styled(df)

    def verdicts(self, tables: list[str] | None = None):
        """The chapter's "What reproduced, what did not, and why": one line per claim (rows with
        a paper value) of ``tables`` (default: all), with its verdict, the provenance of its
        truth and the reason (a Styler).
        """
        import pandas as pd

        rows = [r for r in self.rows if tables is None or r.table in tables]
        recs = [
            {
                "table": r.table,
                "quantity": quantity_label(r.quantity),
                "verdict": v,
                "provenance": r.provenance or "—",
                "why": why,
            }
            for r in rows
            for v, why in [r.judge()]
            if v is not None
        ]
        df = pd.DataFrame(recs, columns=["table", "quantity", "verdict", "provenance", "why"])
        return styled(df, numeric=())

    def summarize(self, name: str, what: str = "parameters") -> dict:
        """:func:`summarize` over one table's rows."""
        return summarize(self.rows_of(name), what)

    def to_text(self) -> str:
        """All tables as aligned plain text (the same strings as :meth:`show`)."""
        out = [f"{self.chapter} (seed {self.seed})"]
        for t in self.tables():
            df = format_rows(self.rows_of(t))
            widths = {c: max(len(c), *(len(v) for v in df[c])) for c in df.columns}
            out.append(f"\n{t}")
            out.append(
                "  "
                + "  ".join(
                    c.ljust(widths[c]) if c not in NUMERIC_COLUMNS else c.rjust(widths[c])
                    for c in df.columns
                )
            )
            for _, rec in df.iterrows():
                out.append(
                    "  "
                    + "  ".join(
                        rec[c].ljust(widths[c])
                        if c not in NUMERIC_COLUMNS
                        else rec[c].rjust(widths[c])
                        for c in df.columns
                    ).rstrip()
                )
        return "\n".join(out)


def _reproduced_bar(n_runs, sigma, paper) -> bool:
    """True when a "reproduced" may rest on these numbers: at least :data:`MIN_RUNS` runs (or
    none, an adjustment's σ̂) and σ at most :data:`SIGMA_OVER_PAPER` of the paper's value.
    """
    s, p = _clean(sigma), _clean(paper)
    if n_runs is not None and n_runs < MIN_RUNS:
        return False
    return s is None or p is None or s <= SIGMA_OVER_PAPER * abs(p)


def _rejudged(r: dict) -> bool:
    """A stored "reproduced" that the bar of :func:`_reproduced_bar` no longer allows (a file
    written under older rules): read without its verdict, so that :meth:`Row.rule` judges it.
    """
    return r.get("verdict") == "reproduced" and not _reproduced_bar(
        r.get("n_runs"), r.get("sigma"), r.get("paper")
    )


def _stored_verdict(r: dict) -> str | None:
    """The verdict of a row as written by :meth:`Reproduction.to_json` ("tuned" was the verdict's
    former name, read as "by construction"; "context" is recomputed from ``judged_in``, and so is
    a "reproduced" the current bar does not allow).
    """
    v = {"tuned": "by construction"}.get(r.get("verdict"), r.get("verdict"))
    return None if v == "context" or _rejudged(r) else v


def _stored_reason(r: dict) -> str:
    """The reason stored with the verdict (none for a recomputed one)."""
    return "" if r.get("verdict") == "context" or _rejudged(r) else (r.get("reason") or "")


def from_estimates(name: str, result) -> Reproduction:
    """A workflow's estimates as report rows (reproduced and σ̂ only): ``result`` has
    ``estimates`` (each with ``group``, ``name``, ``unit``, ``value``, ``sigma``) and ``meta``,
    as :class:`hsgeo.workflows.frame_calibration.FrameFilesResult`; the rows' tables are the
    groups. ``hsgeo calibrate-frame`` prints this, and the chapter shows it.
    """
    rows = [
        Row(
            table=e.group,
            quantity=e.name,
            unit=e.unit,
            reproduced=e.value,
            sigma=e.sigma,
        )
        for e in result.estimates
    ]
    return Reproduction(name, 0, rows, result.meta)
