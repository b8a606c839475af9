"""TOML configuration files with a schema: unknown keys are errors with a suggestion.

The one loader of a configuration is :func:`read_dataclass`: a frozen dataclass is the schema
(its fields the keys, a nested dataclass field a table, the field defaults the defaults, the
type hints the types, ``field(metadata={"key": Key(...)})`` the units and limits), and the file
becomes an instance of it::

    @dataclass(frozen=True)
    class Flight:
        height_agl_m: float = 1000.0

    @dataclass(frozen=True)
    class Scenario:
        flight: Flight = Flight()

    cfg = read_dataclass("flight.toml", Scenario, "scenario")   # cfg.flight.height_agl_m

Every file of the package goes through it: the scenarios (:mod:`hsgeo.simulate.scenarios`), the
sensor files (:mod:`hsgeo.io.sensor_file`, one dataclass per model), the board, bar and
instrument files. A reader whose file holds one of several schemas (the sensor file names its
model) reads the TOML with :func:`read_toml`, picks the dataclass and hands the mapping to
:func:`load_dataclass`. Every problem of the file is reported at once, in one
:class:`~hsgeo.InputError` that names the file, the table and the key, and says what to do
(``[sensor] borsight_deg: unknown key; did you mean 'boresight_deg'?``). An optional key
without a default is a field ``X | None = None``; a table that must be present is a dataclass
field without a default (``[board]: missing table; add a [board] table``).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from hsgeo.errors import InputError
from hsgeo.validate import unit_limits

__all__ = [
    "Key",
    "read_toml",
    "read_dataclass",
    "load_dataclass",
    "closest",
    "did_you_mean",
]

_KINDS = ("float", "int", "str", "floats", "ints", "bool")


@dataclass(frozen=True)
class Key:
    """How a field of a configuration dataclass is checked: its kind, unit and limits
    (``field(metadata={"key": Key(...)})``; whether the key is required and its default are
    the field's own).

    Attributes
    ----------
    kind : {"float", "int", "str", "floats", "ints", "bool"}
        ``"floats"`` is an array of numbers, ``"ints"`` one of whole numbers (of ``length``
        entries, if given).
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


def _integer(v, key: Key, where: str, problems: list) -> int | None:
    if isinstance(v, bool) or not isinstance(v, int):
        problems.append(f"{where}: expected a whole number, got {v!r}")
        return None
    if key.positive and v <= 0:
        problems.append(f"{where}: must be positive, got {v!r}")
        return None
    return int(v)


def _value(v, key: Key, where: str, problems: list):
    if key.kind == "float":
        return _number(v, key, where, problems)
    if key.kind == "int":
        return _integer(v, key, where, problems)
    if key.kind == "bool":
        if not isinstance(v, bool):
            problems.append(f"{where}: expected true or false, got {v!r}")
            return None
        return v
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
    # floats, ints
    if not isinstance(v, (list, tuple)):
        problems.append(f"{where}: expected an array of numbers like [1.0, 2.0], got {v!r}")
        return None
    if key.length is not None and len(v) != key.length:
        problems.append(f"{where}: needs {key.length} numbers, got {len(v)}")
        return None
    one = _number if key.kind == "floats" else _integer
    out = [one(x, key, f"{where}[{i}]", problems) for i, x in enumerate(v)]
    return None if any(x is None for x in out) else tuple(out)


def _with_unit_limit(key: Key, name: str) -> Key:
    """``key`` with the plausible range of the unit ``name`` ends in, unless it has a limit."""
    if key.limit is None and key.kind in ("float", "floats"):
        lim = unit_limits(name)
        if lim is not None:
            return replace(key, limit=lim[1])
    return key


_SCALAR_KINDS = {float: "float", int: "int", str: "str", bool: "bool"}


def _field_kind(hint) -> tuple[str | None, type | None, bool]:
    """``(kind, dataclass, optional)`` of a field's type hint: a :class:`Key` kind for a
    value, or the dataclass of a nested table; ``optional``: the hint admits ``None``.
    """
    import dataclasses
    import types
    import typing

    optional = False
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(hint) if a is not type(None)]
        optional = len(args) < len(typing.get_args(hint))
        if len(args) != 1:
            raise TypeError(f"unsupported configuration type {hint!r}")
        hint = args[0]
        origin = typing.get_origin(hint)
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        return None, hint, optional
    if hint in _SCALAR_KINDS:
        return _SCALAR_KINDS[hint], None, optional
    if origin is tuple:
        args = typing.get_args(hint)
        if args and args[0] in (float, int):
            return ("floats" if args[0] is float else "ints"), None, optional
    raise TypeError(f"unsupported configuration type {hint!r}")


def _required_fields(cls) -> list[str]:
    """The fields of the dataclass ``cls`` without a default (the keys a table must give)."""
    import dataclasses

    return [
        f.name
        for f in dataclasses.fields(cls)
        if f.init and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]


def _load(cls, table: Mapping, path: str, problems: list):
    """``cls`` from one TOML table (nested tables for dataclass fields) at the dotted table
    ``path`` (``""``: the file's top level); problems appended.
    """
    import dataclasses
    import typing

    hints = typing.get_type_hints(cls)
    fields = [f for f in dataclasses.fields(cls) if f.init]
    names = [f.name for f in fields]
    where = f"[{path}]" if path else ""
    prefix = f"{where} " if where else ""
    n_before = len(problems)
    for k in table:
        if k not in names:
            what = "table" if isinstance(table[k], Mapping) else "key"
            name = f"[{k}]" if what == "table" and not where else k
            problems.append(
                f"{prefix}{name}: unknown {what}{did_you_mean(k, names)} "
                f"(known: {', '.join(names)})"
            )
    kwargs = {}
    for f in fields:
        kind, sub, optional = _field_kind(hints[f.name])
        has_default = (
            f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING
        )
        here = f"{path}.{f.name}" if path else f.name
        if f.name not in table:
            if sub is not None and not has_default and not optional:
                if _required_fields(sub):
                    problems.append(f"[{here}]: missing table; add a [{here}] table")
                kwargs[f.name] = _load(sub, {}, here, problems)
            elif not has_default:
                doc = f.metadata.get("key", Key("str")).doc
                problems.append(
                    f"{prefix}{f.name}: missing; add `{f.name} = ...`"
                    + (f" ({doc})" if doc else "")
                )
            continue
        v = table[f.name]
        if sub is not None:
            if not isinstance(v, Mapping):
                problems.append(f"{prefix}{f.name}: must be a table [{here}], got {v!r}")
                continue
            kwargs[f.name] = _load(sub, v, here, problems)
            continue
        key = f.metadata.get("key", Key(kind))
        out = _value(v, _with_unit_limit(key, f.name), f"{prefix}{f.name}", problems)
        if out is not None:
            kwargs[f.name] = out
    if len(problems) > n_before:
        return None
    try:
        return cls(**kwargs)
    except InputError as exc:  # a check of the dataclass itself (__post_init__)
        problems.append(f"{prefix}{exc}")
        return None


def load_dataclass(cls, table: Mapping | None, what: str = "configuration"):
    """The dataclass ``cls`` from a mapping read from TOML (see :func:`read_dataclass`).

    ``what`` names the source in the message (``"scenario file data_synthetic/x.toml"``).
    """
    problems: list[str] = []
    out = _load(cls, table or {}, "", problems)
    if problems:
        raise InputError(f"{what}: " + "; ".join(problems))
    return out


def read_dataclass(path, cls, what: str = "file"):
    """Read a TOML file into the frozen dataclass ``cls``: the one loader of a configuration.

    Parameters
    ----------
    path : str or Path
    cls : dataclass type
        The schema. Each field is a key; a field whose type is a dataclass is a table
        ``[name]`` (nested as deep as the dataclasses are); ``X | None`` is an optional key or
        table. Field types: ``float``, ``int``, ``str``, ``bool``, ``tuple[float, ...]``,
        ``tuple[int, ...]``, a dataclass. Absent keys take the field's default; a field
        without a default is required. ``field(metadata={"key": Key(...)})`` adds a doc, a
        length, ``positive``, ``choices`` or a ``limit``; numbers of a field named with a unit
        (``_px``, ``_m``, ``_deg`` …) must lie in that unit's plausible range
        (:data:`hsgeo.validate.UNIT_LIMITS`).
    what : str
        The file's role, for messages (``"scenario file"``).

    Returns
    -------
    instance of ``cls``

    Raises
    ------
    InputError
        One error naming the file and listing every problem: unknown tables or keys (with the
        closest known name, :func:`difflib.get_close_matches`), missing required keys, values
        of the wrong type, NaN, infinite or implausible numbers.
    """
    path = Path(path)
    return load_dataclass(cls, read_toml(path, what), f"{what} {path}")
