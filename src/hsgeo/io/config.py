"""TOML configuration files with a schema: unknown keys are errors with a suggestion.

A schema maps table names to :class:`Key` descriptions::

    SCHEMA = {"sensor": {"c_px": Key("float", required=True, doc="principal distance, px")}}

:func:`read_config` checks a file against it and returns plain values (floats, ints, strings,
tuples of floats) with the defaults filled in. Every problem of the file is reported at once, in
one :class:`~hsgeo.InputError` that names the file, the table and the key, and says what to do
(``[sensor] borsight_deg: unknown key; did you mean 'boresight_deg'?``).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from hsgeo.errors import InputError
from hsgeo.validate import unit_limits

__all__ = ["Key", "read_toml", "read_config", "closest", "did_you_mean", "dataclass_from_table"]

_KINDS = ("float", "int", "str", "floats")


@dataclass(frozen=True)
class Key:
    """One key of a configuration table.

    Attributes
    ----------
    kind : {"float", "int", "str", "floats"}
        ``"floats"`` is an array of numbers (of ``length`` entries, if given).
    required : bool
        A missing required key is an error.
    default : object, optional
        Value of an absent optional key; ``None``: the key is left out of the result.
    doc : str
        What the value is, with its unit (shown in error messages).
    choices : tuple of str
        Allowed values of a ``"str"`` key.
    length : int, optional
        Number of entries of a ``"floats"`` key.
    positive : bool
        Numbers must be > 0.
    limit : float, optional
        Numbers must not exceed this in magnitude (default: the plausible range of the unit
        the key's name ends in, :data:`hsgeo.validate.UNIT_LIMITS`).
    """

    kind: str
    required: bool = False
    default: object = None
    doc: str = ""
    choices: tuple = ()
    length: int | None = None
    positive: bool = False
    limit: float | None = None

    def __post_init__(self):
        if self.kind not in _KINDS:
            raise ValueError(f"Key kind must be one of {_KINDS}, got {self.kind!r}")


def closest(name: str, options) -> str | None:
    """The option closest to ``name`` (:func:`difflib.get_close_matches`), or ``None``."""
    close = difflib.get_close_matches(str(name), [str(o) for o in options], n=1, cutoff=0.6)
    return close[0] if close else None


def did_you_mean(name: str, options) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``options``, or ``""``."""
    c = closest(name, options)
    return f"; did you mean {c!r}?" if c is not None else ""


def read_toml(path, what: str = "file") -> dict:
    """Read a TOML file; a missing or malformed file raises :class:`~hsgeo.InputError`.

    ``what`` names the file's role in the message (``"sensor file"``, ``"board file"``).
    """
    import tomllib

    from hsgeo.io._files import read_text

    path = Path(path)
    text = read_text(path, what, "TOML")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{what} {path}: malformed TOML: {exc}; correct the file") from None


def _number(v, key: Key, where: str, problems: list) -> float | None:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        problems.append(f"{where}: expected a number, got {v!r}")
        return None
    if not math.isfinite(v):
        problems.append(f"{where}: must be a finite number, got {v!r}")
        return None
    if key.positive and not v > 0:
        problems.append(f"{where}: must be positive, got {v!r}")
        return None
    if key.limit is not None and abs(v) > key.limit:
        problems.append(
            f"{where}: {v!r} is outside [-{key.limit:g}, {key.limit:g}]"
            + (f" ({key.doc}: a wrong unit?)" if key.doc else "")
        )
        return None
    return float(v)


def _value(v, key: Key, where: str, problems: list):
    if key.kind == "float":
        return _number(v, key, where, problems)
    if key.kind == "int":
        if isinstance(v, bool) or not isinstance(v, int):
            problems.append(f"{where}: expected a whole number, got {v!r}")
            return None
        if key.positive and v <= 0:
            problems.append(f"{where}: must be positive, got {v!r}")
            return None
        return int(v)
    if key.kind == "str":
        if not isinstance(v, str):
            problems.append(f"{where}: expected a string in quotes, got {v!r}")
            return None
        if key.choices and v not in key.choices:
            allowed = ", ".join(repr(c) for c in key.choices)
            problems.append(
                f"{where} must be one of {allowed}, got {v!r}{did_you_mean(v, key.choices)}"
            )
            return None
        return v
    # floats
    if not isinstance(v, (list, tuple)):
        problems.append(f"{where}: expected an array of numbers like [1.0, 2.0], got {v!r}")
        return None
    if key.length is not None and len(v) != key.length:
        problems.append(f"{where}: needs {key.length} numbers, got {len(v)}")
        return None
    out = [_number(x, key, f"{where}[{i}]", problems) for i, x in enumerate(v)]
    return None if any(x is None for x in out) else tuple(out)


def read_config(
    path,
    schema: Mapping[str, Mapping[str, Key]],
    what: str = "file",
    *,
    required_tables: tuple[str, ...] = (),
) -> dict[str, dict]:
    """Read a TOML file and check it against ``schema``.

    Parameters
    ----------
    path : str or Path
    schema : mapping of table name to mapping of key name to :class:`Key`
    what : str
        The file's role, for messages (``"sensor file"``).
    required_tables : tuple of str
        Tables that must be present.

    Returns
    -------
    dict of dict
        One dict per table of the schema (empty if absent): the file's values converted to
        float / int / str / tuple of float, and the defaults of absent keys.

    Raises
    ------
    InputError
        One error listing every problem: unknown tables or keys (with the closest known name),
        missing required keys, values of the wrong type, NaN or infinite numbers.
    """
    path = Path(path)
    cfg = read_toml(path, what)
    problems: list[str] = []
    out: dict[str, dict] = {t: {} for t in schema}
    for t, table in cfg.items():
        if t not in schema:
            problems.append(
                f"[{t}]: unknown table{did_you_mean(t, schema)} (known: "
                f"{', '.join(f'[{s}]' for s in schema)})"
            )
        elif not isinstance(table, dict):
            problems.append(f"{t}: must be a table [{t}], got a value {table!r}")
    for t in required_tables:
        if t not in cfg:
            problems.append(f"[{t}]: missing table; add a [{t}] table")
    for t, keys in schema.items():
        table = cfg.get(t)
        if not isinstance(table, dict):
            table = {}
        for k in table:
            if k not in keys:
                problems.append(
                    f"[{t}] {k}: unknown key{did_you_mean(k, keys)} (known: {', '.join(keys)})"
                )
        for k, key in keys.items():
            where = f"[{t}] {k}"
            if key.limit is None and key.kind in ("float", "floats"):
                lim = unit_limits(k)
                if lim is not None:
                    key = replace(key, limit=lim[1])
            if k in table:
                v = _value(table[k], key, where, problems)
                if v is not None:
                    out[t][k] = v
            elif key.required:
                if t in cfg or t not in required_tables:
                    problems.append(
                        f"{where}: missing; add `{k} = ...`" + (f" ({key.doc})" if key.doc else "")
                    )
            elif key.default is not None:
                out[t][k] = key.default
    if problems:
        raise InputError(f"{what} {path}: " + "; ".join(problems))
    return out


def dataclass_from_table(cls, table: Mapping | None, what: str):
    """The dataclass ``cls`` with its defaults replaced by the entries of a TOML table.

    The fields of ``cls`` are the table's schema: an unknown key is an error that names the
    closest field (all unknown keys in one message); arrays become tuples. ``what`` names the
    table in the message (``"scenario line_lab [lab]"``).
    """
    import dataclasses

    if not table:
        return cls()
    names = [f.name for f in dataclasses.fields(cls)]
    bad = [k for k in table if k not in names]
    if bad:
        raise InputError(
            "; ".join(
                f"{what} {k}: unknown key{did_you_mean(k, names)} (known: {', '.join(names)})"
                for k in bad
            )
        )
    return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in table.items()})
