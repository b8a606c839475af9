"""Tables (CSV or Parquet) with required columns whose names carry their units.

One reader, :func:`read_table`, for every table a command reads: observations, control points,
GCPs, trajectories. Columns named with a unit suffix (``zeta_px``, ``x_m``, ``t_s``,
``roll_rad`` ...) must hold finite numbers; id columns (``point``, ``point_id``) may hold any
text. Every error names the file, the line and the column, and what to do.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import check_input_file, read_text
from hsgeo.io.config import closest

__all__ = [
    "read_table",
    "write_table",
    "write_csv_array",
    "write_csv_lines",
    "UNIT_SUFFIXES",
    "TABLE_FORMATS",
]

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


def _data_lines(text: str) -> list[int]:
    """1-based file line numbers of the data rows of a CSV (after the header; no blank lines,
    no ``#`` comment lines), as pandas counts its rows.
    """
    lines = []
    header = False
    for i, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if header:
            lines.append(i)
        header = True
    return lines


def _header(text: str) -> list[str]:
    """The column names of a CSV's header line (the first line not blank nor a comment)."""
    import csv

    for line in text.splitlines():
        s = line.strip()
        if s and not s.startswith("#"):
            return [c.strip() for c in next(csv.reader([s]))]
    return []


def _looks_like_text(path) -> bool:
    """The file's first kilobyte is UTF-8 text with a line end (a CSV named .parquet)."""
    with open(path, "rb") as f:
        head = f.read(1024)
    try:
        head.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return b"\0" not in head and b"\n" in head


def _parse(path, text, parquet: bool, name: str, columns, text_columns):
    """The table as pandas reads it; a parser error becomes an :class:`InputError`."""
    import pandas as pd

    try:
        if parquet:
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(
                io.StringIO(text),
                comment="#",
                skipinitialspace=True,
                dtype={c: str for c in text_columns},
            )
    except pd.errors.EmptyDataError:
        raise InputError(
            f"{name} is empty; it needs a header line with the columns "
            f"{', '.join(columns)} and one row per record"
        ) from None
    except Exception as exc:  # noqa: BLE001 - any parser error becomes an InputError
        if parquet and _looks_like_text(path):
            raise InputError(
                f"{name} is text (a CSV table?), not Parquet: name it .csv to read it as CSV"
            ) from None
        kind = "Parquet" if parquet else "CSV"
        msg = " ".join(str(exc).split())
        raise InputError(f"{name} is not a readable {kind} table: {msg}") from None
    df.columns = [str(c).strip() for c in df.columns]
    return df


#: Separators other than the comma that spreadsheets write (a semicolon-separated
#: table was told to rename its one header column to a required name).
_OTHER_SEPARATORS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}


def _check_separator(name: str, header: list[str], columns) -> None:
    """A header read as one column that another separator splits into the required names is a
    table separated by that character, not a table lacking those columns.
    """
    if len(header) != 1:
        return
    for sep, words in _OTHER_SEPARATORS.items():
        parts = [c.strip() for c in header[0].split(sep)]
        if len(parts) > 1 and any(c in parts for c in columns):
            raise InputError(
                f"{name}: the columns are separated by {words} ({sep!r}), not commas; save it "
                "as comma-separated CSV with '.' as the decimal mark (or as Parquet)"
            )


def _check_dtype(df, c: str, name: str) -> None:
    """A Parquet column states its type: a quantity must be stored as numbers (text
    columns were parsed silently, dates and durations read as nanoseconds).
    """
    import pandas as pd

    kind = df[c].dtype
    if pd.api.types.is_datetime64_any_dtype(kind) or pd.api.types.is_timedelta64_dtype(kind):
        raise InputError(
            f"{name}, column {c}: holds dates or durations ({kind}), not numbers; store {c} "
            "as a float column in the unit its name says"
        )
    if not (pd.api.types.is_numeric_dtype(kind) and not pd.api.types.is_bool_dtype(kind)):
        raise InputError(
            f"{name}, column {c}: stored as {kind} (text), not numbers; store {c} as a float "
            "column in the unit its name says"
        )


def _check_header(df, name: str, columns, header: list[str]) -> None:
    """Every column once (``header`` as the file spells it: pandas would rename a second
    'zeta_px' to 'zeta_px.1' and read the first silently), every required column present, and
    at least one data row.
    """
    _check_separator(name, header, columns)
    dup = sorted({c for c in header if header.count(c) > 1}, key=header.index)
    if dup:
        raise InputError(
            f"{name}: the header names column {dup[0]} {header.count(dup[0])} times; keep one "
            "(or rename the others)"
        )
    missing = [c for c in columns if c not in df.columns]
    if missing:
        # a suggestion only among the columns no other required name claims
        spare = [c for c in df.columns if c not in columns]
        near = {c: closest(c, spare) for c in missing}
        hints = "".join(f"; rename {n!r} to {c!r}?" for c, n in near.items() if n)
        found = ", ".join(df.columns)
        if len(found) > 120:
            found = found[:120] + "..."
        raise InputError(
            f"{name}: missing column(s) {', '.join(missing)}; the header must "
            f"name {', '.join(columns)} (found: {found}){hints}"
        )
    if len(df) == 0:
        raise InputError(f"{name} has a header but no data rows; add one row per record")


def _check_column(df, c: str, name: str, where, text_columns, integer_columns, limits) -> None:
    """One required column: text stripped, numbers parsed, no empty or non-finite value, whole
    numbers where asked, inside the unit's range (``df`` is updated in place).
    """
    import pandas as pd

    from hsgeo.validate import check_range, unit_limits

    col = df[c]
    if c in text_columns:
        na = col.isna()
        col = col.astype(str).str.strip().where(~na, "")
        df[c] = col
        bad = col == ""
    elif _has_unit(c) or c in integer_columns:
        num = pd.to_numeric(col, errors="coerce")
        txt = col.notna() & num.isna()
        if txt.any():
            r = int(np.flatnonzero(txt.to_numpy())[0])
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
    if c in integer_columns:
        v = df[c].to_numpy(dtype=float)
        frac = v != np.round(v)
        if frac.any():
            r = int(np.flatnonzero(frac)[0])
            raise InputError(
                f"{name}, {where(r)}, column {c}: {v[r]:g} is not a whole number; correct the value"
            )
        df[c] = v.astype(np.int64)
    lim = limits.get(c) or (unit_limits(c) if c not in text_columns else None)
    if lim is not None:
        check_range(df[c].to_numpy(dtype=float), *lim, f"{name}, column {c}", where=where)


def read_table(
    path,
    columns,
    what: str = "table",
    *,
    text_columns=(),
    integer_columns=(),
    unique=(),
    limits=None,
    unique_rows: bool = True,
):
    """Read a CSV (``#`` comments allowed) or Parquet table with the required ``columns``.

    Parameters
    ----------
    path : str or Path
        ``.parquet`` / ``.pq``: Parquet; anything else: CSV with a header line (UTF-8, a
        byte-order mark and CRLF line ends allowed).
    columns : sequence of str
        Required columns (extra columns are kept and not checked; any order). Those whose name
        ends in a unit (:data:`UNIT_SUFFIXES`) must hold finite numbers inside the unit's
        plausible range (:data:`hsgeo.validate.UNIT_LIMITS`, or ``limits``).
    what : str
        The table's role in messages (``"observation"``, ``"control"``, ``"GCP"``).
    text_columns : sequence of str
        Columns read as text (stripped of blanks), e.g. ids that must not be parsed as numbers.
    integer_columns : sequence of str
        Columns that must hold whole numbers (read as int64).
    unique : sequence of str or tuple of str
        Columns (or combinations) whose values must not repeat, e.g. ``"point_id"``.
    limits : dict of str to (lo, hi), optional
        Allowed ranges of columns, instead of the unit's default.
    unique_rows : bool
        A row repeated exactly (in the required columns) is an error.

    Returns
    -------
    pandas.DataFrame
        The whole table; column names stripped of blanks.

    Raises
    ------
    InputError
        The file does not exist, is a folder, binary or cannot be parsed, is empty, lacks a
        required column (the message suggests a close name), has an empty, NaN, non-numeric or
        out-of-range value in a required column, or repeats an id or a row (the message gives
        the lines and the column).
    """
    from hsgeo.validate import check_unique

    path = Path(path)
    columns = list(columns)
    name = f"{what} file {str(path)!r}"
    check_input_file(path, f"{what} file")
    parquet = path.suffix.lower() in _PARQUET
    text = None if parquet else read_text(path, f"{what} file", "CSV table")
    df = _parse(path, text, parquet, name, columns, text_columns)
    _check_header(df, name, columns, list(df.columns) if parquet else _header(text))
    lines = None if parquet else _data_lines(text)

    def where(row: int) -> str:
        if lines is not None and row < len(lines):
            return f"line {lines[row]}"
        return f"row {row + 1}"

    limits = dict(limits or {})
    if parquet:
        for c in columns:
            if c not in text_columns and (_has_unit(c) or c in integer_columns):
                _check_dtype(df, c, name)
    for c in columns:
        _check_column(df, c, name, where, text_columns, integer_columns, limits)
    for u in unique:
        cols = [u] if isinstance(u, str) else list(u)
        keys = list(df[cols].itertuples(index=False, name=None))
        if len(cols) == 1:
            keys = [k[0] for k in keys]
        check_unique(keys, name, " ".join(cols), where=where)
    if unique_rows:
        first: dict = {}
        for i, k in enumerate(df[columns].itertuples(index=False, name=None)):
            if k in first:
                raise InputError(
                    f"{name}: {where(i)} repeats {where(first[k])} exactly (a row given twice "
                    "would count twice); delete one"
                )
            first[k] = i
    return df


def write_csv_array(path, table, *, fmt, header: str):
    """Write a numeric table as CSV (comma-separated, one header line, no comment marker).

    ``np.savetxt(path, table, delimiter=",", fmt=fmt, header=header, comments="")``: the
    generated data files of ``make data`` (their bytes are in ``MANIFEST.sha256``).

    Returns
    -------
    pathlib.Path
    """
    from pathlib import Path

    np.savetxt(path, table, delimiter=",", fmt=fmt, header=header, comments="")
    return Path(path)


def write_csv_lines(path, header: str, lines) -> object:
    """Write CSV text: the header line, then each already formatted line, newline-ended.

    Returns
    -------
    pathlib.Path
    """
    from pathlib import Path

    with Path(path).open("w") as fh:
        fh.write(header + "\n")
        for line in lines:
            fh.write(line + "\n")
    return Path(path)


#: The formats :func:`write_table` writes, by suffix (for ``check_outputs``).
TABLE_FORMATS = {".parquet": "Parquet", ".pq": "Parquet", ".csv": "CSV"}


def write_table(path, df, *, inputs=()) -> Path:
    """Write a table (a pandas DataFrame) as Parquet (``.parquet``, ``.pq``) or CSV, atomically.

    CSV floats are written with 17 significant digits (they read back to the same bits);
    an input of the command is never overwritten (``inputs``, :func:`~hsgeo.io.atomic_path`).

    Returns
    -------
    pathlib.Path
    """
    from hsgeo.io._files import atomic_path

    path = Path(path)
    with atomic_path(path, inputs) as tmp:
        if path.suffix.lower() in _PARQUET:
            df.to_parquet(tmp, index=False)
        else:
            df.to_csv(tmp, index=False, float_format="%.17g")
    return path
