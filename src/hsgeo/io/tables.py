"""Tables (CSV or Parquet) with required columns whose names carry their units.

One reader, :func:`read_table`, for every table a command reads: observations, control points,
GCPs, trajectories. Columns named with a unit suffix (``zeta_px``, ``x_m``, ``t_s``,
``roll_rad`` ...) must hold finite numbers; id columns (``point``, ``point_id``) may hold any
text. Every error names the file, the line and the column, and what to do.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io.config import closest

__all__ = ["read_table", "UNIT_SUFFIXES"]

#: Column-name endings that mark a physical quantity (the column must be numeric and finite).
UNIT_SUFFIXES = (
    "_px",
    "_m",
    "_mm",
    "_um",
    "_nm",
    "_s",
    "_rad",
    "_deg",
    "_hz",
    "_m_s",
    "_rad_s",
    "_dn",
)

_PARQUET = (".parquet", ".pq")


def _has_unit(column: str) -> bool:
    return any(column.endswith(s) for s in UNIT_SUFFIXES)


def _data_lines(path: Path) -> list[int]:
    """1-based file line numbers of the data rows of a CSV (after the header; no blank lines,
    no ``#`` comment lines), as pandas counts its rows.
    """
    lines = []
    header = False
    with path.open(encoding="utf-8", errors="replace") as fh:
        for i, line in enumerate(fh, 1):
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            if header:
                lines.append(i)
            header = True
    return lines


def read_table(path, columns, what: str = "table", *, text_columns=()):
    """Read a CSV (``#`` comments allowed) or Parquet table with the required ``columns``.

    Parameters
    ----------
    path : str or Path
        ``.parquet`` / ``.pq``: Parquet; anything else: CSV with a header line.
    columns : sequence of str
        Required columns (extra columns are kept and not checked). Those whose name ends in a
        unit (:data:`UNIT_SUFFIXES`) must hold finite numbers.
    what : str
        The table's role in messages (``"observation"``, ``"control"``, ``"GCP"``).
    text_columns : sequence of str
        Columns read as text (stripped of blanks), e.g. ids that must not be parsed as numbers.

    Returns
    -------
    pandas.DataFrame
        The whole table; column names stripped of blanks.

    Raises
    ------
    InputError
        The file does not exist or cannot be parsed, is empty, lacks a required column (the
        message suggests a close name), or has an empty, NaN or non-numeric value in a required
        column (the message gives the line and column).
    """
    import pandas as pd

    path = Path(path)
    columns = list(columns)
    name = f"{what} file {str(path)!r}"
    if not path.is_file():
        raise InputError(f"{name} not found; check the path")
    parquet = path.suffix.lower() in _PARQUET
    try:
        if parquet:
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(
                path, comment="#", skipinitialspace=True, dtype={c: str for c in text_columns}
            )
    except pd.errors.EmptyDataError:
        raise InputError(
            f"{name} is empty; it needs a header line with the columns "
            f"{', '.join(columns)} and one row per record"
        ) from None
    except Exception as exc:  # noqa: BLE001 - any parser error becomes an InputError
        kind = "Parquet" if parquet else "CSV"
        raise InputError(f"{name} is not a readable {kind} table: {exc}") from None
    df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in columns if c not in df.columns]
    if missing:
        near = {c: closest(c, df.columns) for c in missing}
        hints = "".join(f"; rename {n!r} to {c!r}?" for c, n in near.items() if n)
        raise InputError(
            f"{name}: missing column(s) {', '.join(missing)}; the header must "
            f"name {', '.join(columns)} (found: {', '.join(df.columns)}){hints}"
        )
    if len(df) == 0:
        raise InputError(f"{name} has a header but no data rows; add one row per record")
    lines = None if parquet else _data_lines(path)

    def where(row: int) -> str:
        if lines is not None and row < len(lines):
            return f"line {lines[row]}"
        return f"row {row + 1}"

    for c in columns:
        col = df[c]
        if c in text_columns:
            col = col.str.strip()
            df[c] = col
            bad = col.isna() | (col == "")
        elif _has_unit(c):
            num = pd.to_numeric(col, errors="coerce")
            text = col.notna() & num.isna()
            if text.any():
                r = int(np.flatnonzero(text.to_numpy())[0])
                raise InputError(
                    f"{name}, {where(r)}, column {c}: {col.iloc[r]!r} is not a "
                    "number; correct the value"
                )
            df[c] = num
            bad = ~np.isfinite(num.to_numpy(dtype=float))
        else:
            bad = col.isna().to_numpy()
        bad = np.asarray(bad)
        if bad.any():
            r = int(np.flatnonzero(bad)[0])
            more = int(bad.sum()) - 1
            raise InputError(
                f"{name}, {where(r)}, column {c}: empty, NaN or infinite value"
                + (f" (and {more} more)" if more else "")
                + "; fill it in or delete the row"
            )
    return df
