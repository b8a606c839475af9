"""Deviations at ground control points, in the layout of 000 Tables 2–3.

For coordinate differences Δ (geocoded − reference) at n points, per axis: the bias
``n = ΣΔ / n``, the corrections ``v = Δ − n``, their squares ``v·v`` and the standard deviation
``σ = sqrt(Σ v·v / (n − 1))``. :func:`recompute_printed_table` recomputes every derived column of a
published table from its printed Δ and flags printed values that do not follow from them.

References
----------
Miljković, Gajski, Vela (2017), Geodetski list 2017/2, Tables 2 and 3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from hsgeo.errors import InputError, ObservationError

__all__ = [
    "deviation_table",
    "load_000_table",
    "recompute_printed_table",
    "Flag",
]


def deviation_table(dy_m, dx_m, ids=None) -> tuple[pd.DataFrame, dict[str, float]]:
    """The 000 Table 2/3 layout computed from coordinate differences.

    Parameters
    ----------
    dy_m, dx_m : (n,) array_like
        Deviations in y (east) and x (north), metres (the Croatian y/x convention of the paper).
    ids : (n,) array_like, optional
        Point labels.

    Returns
    -------
    table : pandas.DataFrame
        Columns ``dy_m, dx_m, dy_minus_n_m, vyvy_m2, dx_minus_n_m, vxvx_m2``, one row per point.
    summary : dict
        ``bias_y_m, bias_x_m, sigma_y_m, sigma_x_m`` (σ with n − 1), sums of every column, ``n``.
    """
    dy = np.asarray(dy_m, dtype=np.float64).ravel()
    dx = np.asarray(dx_m, dtype=np.float64).ravel()
    if dy.shape != dx.shape:
        raise InputError(f"dy and dx differ in length: {dy.size} vs {dx.size}")
    if not (np.all(np.isfinite(dy)) and np.all(np.isfinite(dx))):
        raise InputError("deviations contain NaN or inf: drop or fix those points first")
    n = dy.size
    if n < 2:
        raise ObservationError(f"σ with n − 1 needs at least 2 points, got {n}")
    ny, nx = dy.mean(), dx.mean()
    vy, vx = dy - ny, dx - nx
    table = pd.DataFrame(
        {
            "dy_m": dy,
            "dx_m": dx,
            "dy_minus_n_m": vy,
            "vyvy_m2": vy**2,
            "dx_minus_n_m": vx,
            "vxvx_m2": vx**2,
        },
        index=pd.Index(ids if ids is not None else np.arange(1, n + 1), name="gcp"),
    )
    summary = {
        "n": n,
        "bias_y_m": ny,
        "bias_x_m": nx,
        "sigma_y_m": float(np.sqrt((vy**2).sum() / (n - 1))),
        "sigma_x_m": float(np.sqrt((vx**2).sum() / (n - 1))),
        "sum_dy_m": dy.sum(),
        "sum_dx_m": dx.sum(),
        "sum_vyvy_m2": (vy**2).sum(),
        "sum_vxvx_m2": (vx**2).sum(),
    }
    return table, summary


def load_000_table(which: int) -> pd.DataFrame:
    """000 Table 2 (``which=2``, without calibration) or Table 3 (with calibration), as printed."""
    from hsgeo import papers

    if which not in (2, 3):
        raise InputError(f"000 has GCP tables 2 and 3, not {which}")
    rows = papers.P000_TABLE2_ROWS if which == 2 else papers.P000_TABLE3_ROWS
    return pd.DataFrame(rows, columns=papers.P000_GCP_COLUMNS).set_index("gcp")


@dataclass(frozen=True)
class Flag:
    """A printed value that does not follow from the printed deviations."""

    where: str
    printed: float
    recomputed: float
    decimals: int
    note: str

    def __str__(self) -> str:
        return (
            f"{self.where}: printed {self.printed:.{self.decimals}f}, recomputed "
            f"{self.recomputed:.4f} ({self.note})"
        )


def _follows(printed: float, value: float, decimals: int) -> bool:
    """True if ``printed`` is ``value`` rounded to ``decimals`` (either way at a tie)."""
    return abs(printed - value) <= 0.5 * 10.0**-decimals + 1e-9


def _why(printed: float, value: float, decimals: int) -> str:
    q = 10.0**decimals
    if abs(printed - np.trunc(value * q) / q) < 1e-9:
        return "consistent with truncation, not with rounding"
    return "does not follow by rounding"


def recompute_printed_table(which: int):
    """Recompute every derived column of 000 Table 2 or 3 from its printed Δy, Δx.

    Returns
    -------
    table : pandas.DataFrame
        The recomputed table (full precision).
    summary : dict
        Recomputed bias, σ and sums.
    flags : list of Flag
        Printed values (cells and footer) that do not follow from the printed deviations at the
        printed precision.
    """
    printed = load_000_table(which)
    table, summary = deviation_table(printed["dy_m"], printed["dx_m"], printed.index)
    flags: list[Flag] = []
    for col in ("dy_minus_n_m", "vyvy_m2", "dx_minus_n_m", "vxvx_m2"):
        for gcp, p, v in zip(printed.index, printed[col], table[col], strict=True):
            if not _follows(p, v, 2):
                flags.append(Flag(f"GCP {gcp} {col}", p, v, 2, _why(p, v, 2)))
    from hsgeo.papers import P000_GCP_FOOTERS

    for key, (p, dec) in P000_GCP_FOOTERS[f"000 Table {which}"].items():
        v = summary[key]
        if not _follows(p, v, dec):
            flags.append(Flag(f"footer {key}", p, v, dec, _why(p, v, dec)))
    return table, summary, flags
