"""Validation at the boundary: one place for the checks every reader, workflow and command makes.

* :func:`finite_array` — numbers, all finite;
* :func:`check_range` — values inside the range physics allows for their unit;
* :func:`check_unique` — no id or row given twice (the lines and ids named);
* :func:`check_navigation_covers` — a navigation solution covers the times it is used at,
  without gaps longer than a tolerance;
* :func:`check_memory` — a request that cannot fit in the machine's memory is refused up
  front, with the estimate;
* :func:`option_number` — command-line numbers (finite, positive, in a range), as argparse
  types whose errors name the option.

Every failure is an :class:`~hsgeo.InputError` with a one-line message that names the file, the
line / column / id or the option, and the remedy.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import InputError

__all__ = [
    "finite_array",
    "check_range",
    "check_unique",
    "check_navigation_covers",
    "option_number",
    "check_memory",
    "physical_memory_bytes",
    "UNIT_LIMITS",
    "unit_limits",
]

#: The largest magnitude a value of a unit can plausibly have, by column-name ending: beyond it
#: the value is a typo, a unit mistake or an uninitialised field (1e300). Pixels: no sensor has a
#: million pixels across; metres: 1e8 m holds any projected or local coordinate; seconds: 1e10 s
#: holds GPS and Unix time; angles: one turn either way (angles in other ranges are checked per
#: column, e.g. pitch).
UNIT_LIMITS = {
    "_px": 1e6,
    "_m": 1e8,
    "_mm": 1e5,
    "_um": 1e8,
    "_nm": 1e6,
    "_s": 1e10,
    "_deg": 360.0,
    "_rad": 2 * math.pi,
    "_hz": 1e7,
    "_m_s": 1e4,
    "_rad_s": 1e3,
    "_dn": 1e12,
}


def unit_limits(name: str) -> tuple[float, float] | None:
    """``(lo, hi)`` for a column or key named with a unit suffix (:data:`UNIT_LIMITS`)."""
    for suffix in sorted(UNIT_LIMITS, key=len, reverse=True):
        if name.endswith(suffix):
            m = UNIT_LIMITS[suffix]
            return -m, m
    return None


def finite_array(a: ArrayLike, name: str) -> NDArray[np.float64]:
    """Convert to a finite float64 array, or raise :class:`~hsgeo.InputError` naming ``name``."""
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"{name} could not be converted to a float array ({exc}); pass numbers."
        ) from exc
    if not np.all(np.isfinite(arr)):
        n_bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise InputError(
            f"{name} contains {n_bad} non-finite value(s) (NaN or inf); "
            "remove or replace them before calling."
        )
    return arr


def _where(where: Callable[[int], str] | None, i: int) -> str:
    return where(i) if where is not None else f"row {i + 1}"


def check_range(
    values: ArrayLike,
    lo: float,
    hi: float,
    what: str,
    *,
    where: Callable[[int], str] | None = None,
    remedy: str = "correct the value (is the unit the one the name says?)",
) -> None:
    """Raise :class:`~hsgeo.InputError` if a value lies outside ``[lo, hi]``.

    Parameters
    ----------
    values : array_like
        Finite numbers.
    lo, hi : float
        The allowed range, inclusive.
    what : str
        Where the values come from, for the message (``"observation file 'o.csv', column t_s"``).
    where : callable, optional
        Index -> location (``"line 12"``) of a value.
    remedy : str
        What to do.
    """
    v = np.asarray(values, dtype=float).ravel()
    bad = ~((v >= lo) & (v <= hi))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        more = int(bad.sum()) - 1
        raise InputError(
            f"{what}, {_where(where, i)}: {v[i]:.6g} is outside [{lo:g}, {hi:g}]"
            + (f" (and {more} more)" if more else "")
            + f"; {remedy}"
        )


def check_unique(
    keys: Sequence, what: str, label: str, *, where: Callable[[int], str] | None = None
) -> None:
    """Raise :class:`~hsgeo.InputError` if a key occurs twice (ids or whole rows).

    Parameters
    ----------
    keys : sequence of hashable
        One key per row (an id, or a tuple of the row's values).
    what : str
        The file, for the message.
    label : str
        What the key is (``"point"``, ``"row"``, ``"point_id"``).
    where : callable, optional
        Index -> location (``"line 12"``).
    """
    first: dict = {}
    for i, k in enumerate(keys):
        if k in first:
            shown = k if not isinstance(k, tuple) else ", ".join(map(str, k))
            raise InputError(
                f"{what}: {label} {shown} is given twice ({_where(where, first[k])} and "
                f"{_where(where, i)}); keep one row per {label.split(' ')[0]}"
            )
        first[k] = i


def check_navigation_covers(
    nav_t_s: ArrayLike,
    t_s: ArrayLike,
    *,
    nav: str,
    used: str,
    max_gap_s: float,
    gap_option: str = "--max-nav-gap-s",
) -> None:
    """The navigation covers the times ``t_s`` it is interpolated to, without long gaps.

    Parameters
    ----------
    nav_t_s : (n,) array_like
        Record times of the navigation, strictly increasing (s).
    t_s : array_like
        Times the navigation is used at (s).
    nav : str
        The navigation file, for the message.
    used : str
        What the times are (``"the lines of 'l.nc' (t0_s + line / line_rate_hz)"``).
    max_gap_s : float
        The longest interval between records that is interpolated across (s).
    gap_option : str
        The option that sets ``max_gap_s``, named in the message.
    """
    tn = np.asarray(nav_t_s, dtype=float)
    t = np.asarray(t_s, dtype=float).ravel()
    lo, hi = float(t.min()), float(t.max())
    if lo < tn[0] or hi > tn[-1]:
        raise InputError(
            f"navigation file {nav} covers t_s {tn[0]:.6g} to {tn[-1]:.6g} s but "
            f"{used} run from {lo:.6g} to {hi:.6g} s; "
            + _time_scale_hint(tn, t)
            + "give the navigation of the whole acquisition, on the same time scale"
        )
    step = float(np.median(np.diff(tn))) if tn.size > 1 else 0.0
    if step > max_gap_s:  # most intervals "gaps": a unit or a logging rate, not a gap
        raise InputError(
            f"navigation file {nav}: its records are {step:.6g} s apart (the median), "
            f"farther than {gap_option} {max_gap_s:g} everywhere; the likely causes: t_s in "
            f"another unit than seconds (milliseconds: records {step / 1000:.6g} s apart?), "
            f"or a navigation logged this sparsely (then allow it with {gap_option})"
        )
    # a gap matters where the navigation is interpolated across it: a time strictly between
    # two records farther apart than max_gap_s (times on a record use it as it is)
    k = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, tn.size - 2)
    on_record = np.isclose(t, tn[k], rtol=0, atol=1e-9) | np.isclose(
        t, tn[k + 1], rtol=0, atol=1e-9
    )
    gap = tn[k + 1] - tn[k]
    bad = (gap > max_gap_s) & ~on_record
    if bad.any():
        j = int(k[np.flatnonzero(bad)[np.argmax(gap[bad])]])
        raise InputError(
            f"navigation file {nav}: a gap of {tn[j + 1] - tn[j]:.6g} s between the records at "
            f"t_s = {tn[j]:.6g} and {tn[j + 1]:.6g} s (data rows {j + 1} and {j + 2}) is "
            f"interpolated across for {used}, longer than {gap_option} {max_gap_s:g}; fill the "
            f"gap, or allow it with {gap_option}"
        )


def _time_scale_hint(tn: np.ndarray, t: np.ndarray) -> str:
    """A hint when the two time spans differ by a factor of about 1000 (ms against s)."""
    a = float(np.ptp(tn)) if tn.size else 0.0
    b = float(np.ptp(t)) if t.size else 0.0
    if a > 0 and b > 0 and 300.0 < max(a / b, b / a) < 3000.0:
        return "one of them in milliseconds? (the spans differ by a factor of about 1000); "
    return ""


def option_number(
    *,
    positive: bool = False,
    lo: float | None = None,
    hi: float | None = None,
    integer: bool = False,
) -> Callable[[str], float]:
    """An argparse ``type`` for a number option: finite, and optionally positive / in a range.

    The error (argparse prints ``argument --sigma-px: must be a positive number, got '0'``)
    names the option and the value.
    """
    if integer:
        need = "a whole number"
    else:
        need = "a positive number" if positive else "a finite number"
    if lo is not None or hi is not None:
        # a positive number has the open bound 0 below it unless a lower one is given
        left = f"[{lo:g}" if lo is not None else ("(0" if positive else "[-inf")
        need += f" in {left}, {'inf' if hi is None else f'{hi:g}'}]"

    def parse(text: str):
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {need}, got {text!r}") from None
        ok = math.isfinite(v) and (not positive or v > 0)
        ok = ok and (lo is None or v >= lo) and (hi is None or v <= hi)
        if not ok:
            raise argparse.ArgumentTypeError(f"must be {need}, got {text!r}")
        return v

    parse.__name__ = "number"
    return parse


def physical_memory_bytes() -> float:
    """The machine's physical memory in bytes (``inf`` where the system does not say)."""
    import os

    try:
        return float(os.sysconf("SC_PAGE_SIZE")) * float(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return math.inf


def check_memory(need_bytes: float, what: str, remedy: str) -> None:
    """Refuse up front what cannot fit in memory: :class:`~hsgeo.InputError` if ``need_bytes``
    (a lower bound of what ``what`` will allocate) exceeds the machine's physical memory.

    Parameters
    ----------
    need_bytes : float
        The estimate (a lower bound: the refusal must not turn away a run that would fit).
    what : str
        What needs it, in the user's terms (the option and the sizes it leads to).
    remedy : str
        What to do (the option to change).
    """
    have = physical_memory_bytes()
    if need_bytes > have:
        gib = 2.0**30
        raise InputError(
            f"{what} needs at least {need_bytes / gib:.3g} GiB of memory, more than this "
            f"machine's {have / gib:.3g} GiB; {remedy}"
        )
