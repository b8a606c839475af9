"""Error statistics: bias, standard deviation, RMS, NMAD and summary tables.

The statistics of the papers' accuracy tables:

* 000 Tables 2-3 (GCP deviations): bias ``n = mean(Δ)`` and ``σ = sqrt(Σ v² / (n − 1))``
  with ``v = Δ − n``;
* 002 Tables 1-3 (reprojection and check-point errors): min, max, median, mean, STD and
  NMAD ``= 1.4826 · median(|x − median(x)|)`` (Höhle & Höhle 2009).

NaN policy
----------
Every function takes ``nan_policy``: ``"raise"`` (default) raises
:class:`~hsgeo.errors.InputError` when the data contain a non-finite value (NaN or ±inf);
``"omit"`` drops the non-finite values before computing. ``n`` counts the values used.

References
----------
.. [1] Höhle, J., Höhle, M. (2009). Accuracy assessment of digital elevation models by means
   of robust statistical methods. ISPRS J. Photogramm. Remote Sens. 64(4), 398-406.
.. [2] McCullough, B. D. (1998). Assessing the reliability of statistical software: Part I.
   The American Statistician 52(4), 358-366.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import InputError, ObservationError

if TYPE_CHECKING:  # pandas (0.45 s to import) only where a table is asked for
    import pandas as pd

__all__ = [
    "bias",
    "std",
    "rms",
    "nmad",
    "describe",
    "describe_table",
    "lre",
    "NMAD_SCALE",
    "STATISTICS",
    "NanPolicy",
]

#: 1 / Φ⁻¹(3/4): makes the NMAD a consistent estimator of σ for normal data.
NMAD_SCALE = 1.4826

#: Statistics reported by :func:`describe`, in the column order of 002 Table 1, then RMS, n.
STATISTICS = ("min", "max", "median", "mean", "std", "nmad", "rms", "n")

NanPolicy = Literal["raise", "omit"]


def _prepare(
    x: ArrayLike, nan_policy: str, axis: int | None, min_count: int, what: str
) -> tuple[NDArray[np.float64], int | None]:
    """Validate and return the data (non-finite values set to NaN when omitted)."""
    if nan_policy not in ("raise", "omit"):
        raise InputError(f"nan_policy must be 'raise' or 'omit', got {nan_policy!r}.")
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"{what}: data could not be converted to a float array ({exc}); pass numbers."
        ) from exc
    if axis is None:
        arr = arr.ravel()
        axis = 0
    elif not (-arr.ndim <= axis < arr.ndim):
        raise InputError(f"{what}: axis {axis} is out of range for data of shape {arr.shape}.")
    finite = np.isfinite(arr)
    if not np.all(finite):
        n_bad = int(arr.size - np.count_nonzero(finite))
        if nan_policy == "raise":
            raise InputError(
                f"{what}: data contain {n_bad} non-finite value(s) (NaN or inf); remove them "
                "or pass nan_policy='omit' to ignore them."
            )
        arr = np.where(finite, arr, np.nan)
    count = np.count_nonzero(finite, axis=axis)
    if np.any(count < min_count):
        raise ObservationError(
            f"{what} needs at least {min_count} finite value(s), got {int(np.min(count))}; "
            "supply more observations."
        )
    return arr, axis


def bias(x: ArrayLike, *, axis: int | None = None, nan_policy: NanPolicy = "raise") -> NDArray:
    """Bias: the mean error (000 Table 2, ``n_x = Σ Δx / n``).

    Parameters
    ----------
    x : array_like
        Errors (e.g. check-point deviations in m, residuals in px); any shape.
    axis : int or None, optional
        Axis to reduce; ``None`` (default) reduces all values.
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    bias : float or ndarray
        Mean, in the unit of ``x``; the shape of ``x`` without ``axis``.

    Raises
    ------
    InputError
        Non-finite values with ``nan_policy="raise"``, non-numeric data or a bad ``axis``.
    ObservationError
        No finite value (along ``axis``).
    """
    arr, ax = _prepare(x, nan_policy, axis, 1, "bias")
    return np.nanmean(arr, axis=ax)


def std(x: ArrayLike, *, axis: int | None = None, nan_policy: NanPolicy = "raise") -> NDArray:
    """Sample standard deviation with n − 1 (000 Table 2, ``σ = sqrt(Σ v² / (n − 1))``).

    Parameters
    ----------
    x : array_like
        Errors; any shape.
    axis : int or None, optional
        Axis to reduce; ``None`` (default) reduces all values.
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    std : float or ndarray
        Standard deviation about the mean, in the unit of ``x``.

    Raises
    ------
    InputError
        Non-finite values with ``nan_policy="raise"``, non-numeric data or a bad ``axis``.
    ObservationError
        Fewer than 2 finite values (along ``axis``).
    """
    arr, ax = _prepare(x, nan_policy, axis, 2, "std")
    return np.nanstd(arr, axis=ax, ddof=1)


def rms(x: ArrayLike, *, axis: int | None = None, nan_policy: NanPolicy = "raise") -> NDArray:
    """Root mean square, ``sqrt(Σ x² / n)`` (about zero, not about the mean).

    Parameters
    ----------
    x : array_like
        Errors; any shape.
    axis : int or None, optional
        Axis to reduce; ``None`` (default) reduces all values.
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    rms : float or ndarray
        RMS, in the unit of ``x``.

    Raises
    ------
    InputError
        Non-finite values with ``nan_policy="raise"``, non-numeric data or a bad ``axis``.
    ObservationError
        No finite value (along ``axis``).
    """
    arr, ax = _prepare(x, nan_policy, axis, 1, "rms")
    return np.sqrt(np.nanmean(arr * arr, axis=ax))


def nmad(x: ArrayLike, *, axis: int | None = None, nan_policy: NanPolicy = "raise") -> NDArray:
    """Normalised median absolute deviation, ``1.4826 · median(|x − median(x)|)``.

    A robust estimate of σ (002 Tables 1-3; Höhle & Höhle 2009): equal to σ for normally
    distributed errors, insensitive to a minority of outliers.

    Parameters
    ----------
    x : array_like
        Errors; any shape.
    axis : int or None, optional
        Axis to reduce; ``None`` (default) reduces all values.
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    nmad : float or ndarray
        NMAD, in the unit of ``x``.

    Raises
    ------
    InputError
        Non-finite values with ``nan_policy="raise"``, non-numeric data or a bad ``axis``.
    ObservationError
        No finite value (along ``axis``).

    Examples
    --------
    >>> round(float(nmad([1.0, 2.0, 3.0, 4.0, 100.0])), 4)
    1.4826
    """
    arr, ax = _prepare(x, nan_policy, axis, 1, "nmad")
    med = np.nanmedian(arr, axis=ax, keepdims=True)
    return NMAD_SCALE * np.nanmedian(np.abs(arr - med), axis=ax)


def describe(x: ArrayLike, *, nan_policy: NanPolicy = "raise") -> dict[str, float]:
    """Summary statistics of one error sample, as in 002 Table 1.

    Parameters
    ----------
    x : array_like
        Errors; any shape (all values are pooled).
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    stats : dict of str to float
        Keys ``min, max, median, mean, std, nmad, rms, n`` (in that order), in the unit of
        ``x`` except ``n`` (an int: the number of values used). ``mean`` is the bias and
        ``std`` uses n − 1.

    Raises
    ------
    InputError
        Non-finite values with ``nan_policy="raise"`` or non-numeric data.
    ObservationError
        Fewer than 2 finite values.
    """
    arr, _ = _prepare(x, nan_policy, None, 2, "describe")
    return {
        "min": float(np.nanmin(arr)),
        "max": float(np.nanmax(arr)),
        "median": float(np.nanmedian(arr)),
        "mean": float(bias(arr, nan_policy="omit")),
        "std": float(std(arr, nan_policy="omit")),
        "nmad": float(nmad(arr, nan_policy="omit")),
        "rms": float(rms(arr, nan_policy="omit")),
        "n": int(np.count_nonzero(np.isfinite(arr))),
    }


def describe_table(
    columns: dict[str, ArrayLike], *, nan_policy: NanPolicy = "raise"
) -> pd.DataFrame:
    """Table of :func:`describe` statistics, one column per input.

    Parameters
    ----------
    columns : dict of str to array_like
        Named error samples, e.g. ``{"E": dE_m, "N": dN_m, "H": dH_m}``; lengths may differ.
    nan_policy : {"raise", "omit"}, optional
        What to do with non-finite values.

    Returns
    -------
    table : pandas.DataFrame
        Index ``min, max, median, mean, std, nmad, rms, n`` (named ``"statistic"``), one
        float column per input in the order given. 002 Table 1 prints the transpose (one row
        per coordinate); use ``table.T`` for that layout.

    Raises
    ------
    InputError
        ``columns`` empty or not a mapping; non-finite values with ``nan_policy="raise"``
        (the message names the column).
    ObservationError
        A column with fewer than 2 finite values.

    Examples
    --------
    >>> describe_table({"x": [0.1, -0.2, 0.3], "y": [1.0, 2.0, 4.0]}).loc["median"].tolist()
    [0.1, 2.0]
    """
    import pandas as pd

    if not isinstance(columns, dict) or len(columns) == 0:
        raise InputError(
            "columns must be a non-empty dict mapping a name to an array of values, "
            f"got {'an empty dict' if isinstance(columns, dict) else type(columns).__name__}."
        )
    data = {}
    for name, values in columns.items():
        try:
            data[name] = describe(values, nan_policy=nan_policy)
        except (InputError, ObservationError) as exc:
            raise type(exc)(f"column {name!r}: {exc}") from exc
    table = pd.DataFrame(data, index=list(STATISTICS), dtype=np.float64)
    table.index.name = "statistic"
    return table


def lre(estimate: ArrayLike, certified: ArrayLike, digits: float = 11.0) -> NDArray:
    """Log relative error: the number of correct significant digits of ``estimate``.

    ``LRE = −log10(|x − c| / |c|)``, or the log absolute error ``−log10 |x|`` where the
    certified value ``c`` is 0, as NIST's StRD and McCullough (1998) [2]_ score solver
    accuracy. The result is clipped to ``[0, digits]``: an exact match scores ``digits`` (the
    number of certified digits: 11 for NIST StRD), an estimate off by 100 % or more, or not
    finite, scores 0.

    Parameters
    ----------
    estimate, certified : array_like
        Same shape (or broadcastable); any units, the same for both.
    digits : float, default 11
        The cap: the number of significant digits the certified values carry.

    Returns
    -------
    ndarray
        LRE of each entry (dimensionless, digits).

    Examples
    --------
    >>> round(float(lre(1.000001, 1.0)), 6)  # off by 1e-6 relative: 6 digits
    6.0
    >>> round(float(lre(2.5e-9, 0.0)), 2)  # certified 0: log absolute error
    8.6
    """
    x = np.asarray(estimate, dtype=np.float64)
    c = np.asarray(certified, dtype=np.float64)
    if not np.all(np.isfinite(c)):
        raise InputError("lre: the certified values must be finite")
    x, c = np.broadcast_arrays(x, c)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(c == 0.0, np.abs(x), np.abs(x - c) / np.abs(np.where(c == 0.0, 1.0, c)))
        out = -np.log10(err)
    out = np.where(np.isfinite(x), out, 0.0)
    return np.clip(out, 0.0, digits)
