"""The terminal side of the ``hsgeo`` command: text that prints in any locale, one line for
every way a run can end badly, progress only where someone watches, strict JSON.

Kept apart from :mod:`hsgeo.cli` (which parses and dispatches) so that the error handling is
one small module of its own:

* :func:`setup_streams` — stdout and stderr print in any encoding: a character the terminal
  cannot show (``Σ``, ``σ``, ``…``, ``→`` on an ASCII or Latin-1 terminal, ``LANG=C``,
  ``PYTHONIOENCODING=ascii``) is written in an ASCII spelling (``Sum``, ``sigma``, ``...``,
  ``->``) instead of ending the command with ``UnicodeEncodeError``;
* :func:`interrupted` — Ctrl-C, also when it arrives inside a numba-compiled kernel, where it
  surfaces as a ``SystemError`` whose cause is the ``KeyboardInterrupt``;
* :func:`error_line` — the one line of an operating system's refusal or of memory exhausted;
* :func:`progress_printer` — iteration progress on one self-clearing line of an interactive
  terminal, nothing on a redirected stream (where it would bury the one error line);
* :func:`json_text` — JSON without ``NaN`` / ``Infinity`` (null instead), as the GUIDE's
  JSON contract asks;
* :func:`keep_freed_memory` — the command's process keeps freed memory for reuse (glibc), as
  the Makefile's ``GLIBC_TUNABLES`` does for the tests and the book.
"""

from __future__ import annotations

import codecs
import ctypes
import json
import math
import os
import platform
import sys
import unicodedata

__all__ = [
    "ASCII_SPELLINGS",
    "setup_streams",
    "interrupted",
    "error_line",
    "progress_printer",
    "stage_printer",
    "progress_counter",
    "clear_progress",
    "json_text",
    "strict_values",
    "keep_freed_memory",
]

#: ASCII spellings of the non-ASCII characters hsgeo's reports use.
ASCII_SPELLINGS = {
    "Σ": "Sum",
    "σ": "sigma",
    "…": "...",
    "→": "->",
    "←": "<-",
    "↔": "<->",
    "µ": "u",
    "μ": "u",
    "½": "1/2",
    "²": "^2",
    "³": "^3",
    "⁻": "^-",
    "¹": "1",
    "λ": "lambda",
    "×": "x",
    "±": "+/-",
    "≤": "<=",
    "≥": ">=",
    "≠": "!=",
    "≈": "~",
    "−": "-",
    "–": "-",
    "—": "--",
    "°": " deg",
    "·": "*",
    "√": "sqrt",
    "∞": "inf",
    "χ": "chi",
    "Δ": "Delta",
    "δ": "delta",
    "ζ": "zeta",
    "ω": "omega",
    "φ": "phi",
    "κ": "kappa",
    "θ": "theta",
    "α": "alpha",
    "β": "beta",
    "γ": "gamma",
    "ε": "epsilon",
    "η": "eta",
    "ρ": "rho",
    "τ": "tau",
    "π": "pi",
    "ν": "nu",
    "‖": "||",
    "‘": "'",
    "’": "'",
    "“": '"',
    "”": '"',
    "\u2009": " ",
    "\u00a0": " ",
}

_HANDLER = "hsgeo-ascii"


def _ascii_fallback(exc: UnicodeError):
    """Codec error handler: each character the stream cannot encode, spelled in ASCII."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    out = []
    run = exc.object[exc.start : exc.end].replace("σ\u0302", "sigma_hat")  # σ̂: one symbol
    for ch in run:
        s = ASCII_SPELLINGS.get(ch)
        if s is None and unicodedata.combining(ch):
            s = ""  # a combining accent: the letter before it stands alone
        elif s is None:  # an accented letter loses its accent; anything else becomes '?'
            s = unicodedata.normalize("NFKD", ch).encode("ascii", "ignore").decode() or "?"
        out.append(s)
    return "".join(out), exc.end


codecs.register_error(_HANDLER, _ascii_fallback)


def setup_streams() -> None:
    """Make ``sys.stdout`` and ``sys.stderr`` write unencodable characters in ASCII spellings
    (:data:`ASCII_SPELLINGS`) instead of raising ``UnicodeEncodeError``; the encoding itself is
    kept (UTF-8 terminals see ``Σ``).
    """
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is None:
            continue
        try:
            reconfigure(errors=_HANDLER)
        except (ValueError, OSError):  # a closed or detached stream: leave it
            pass


def interrupted(exc: BaseException) -> bool:
    """``exc`` is Ctrl-C: a ``KeyboardInterrupt``, or an error raised because of one (numba
    turns a ``KeyboardInterrupt`` inside a compiled function into ``SystemError``).
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def error_line(exc: BaseException) -> str | None:
    """The one line for an error the command did not raise on purpose but a user can act on:
    an operating system's refusal (``OSError``) or memory exhausted (``MemoryError``); ``None``
    for anything else (a bug, which keeps its traceback).
    """
    if isinstance(exc, MemoryError):
        what = " ".join(str(exc).split())
        return (
            f"not enough memory{': ' + what if what else ''}; the likely causes: a size the "
            "input declares (a file header's counts), an option asking for more (a finer "
            "resolution or node interval), or a machine busy with other work"
        )
    if isinstance(exc, OSError):
        from hsgeo.io._files import os_error_message

        return os_error_message(exc)
    return None


_progress_shown = False


def progress_printer(stream=None):
    """The solver's progress callback for an interactive terminal: iteration, cost and λ on one
    line that each iteration rewrites (a carriage return) and :func:`clear_progress` erases;
    ``None`` (no progress) when ``stream`` (default stderr) is not a terminal.
    """
    stream = sys.stderr if stream is None else stream
    try:
        tty = stream.isatty()
    except (ValueError, AttributeError):
        tty = False
    if not tty:
        return None

    from hsgeo.adjust.solver import progress_text

    def show(info):
        global _progress_shown
        stream.write("\r\033[K" + progress_text(info))
        stream.flush()
        _progress_shown = True

    return show


def stage_printer(stream=None):
    """A ``progress(done, total, stage)`` callback for work in steps (strips, files, tiles):
    ``stage: done/total (percent)`` on one self-clearing line of an interactive terminal
    (:func:`clear_progress` erases it); ``None`` when ``stream`` (default stderr) is not a
    terminal.
    """
    stream = sys.stderr if stream is None else stream
    try:
        tty = stream.isatty()
    except (ValueError, AttributeError):
        tty = False
    if not tty:
        return None

    def show(done: int, total: int, stage: str) -> None:
        global _progress_shown
        stream.write(f"\r\033[K{stage}: {done}/{total} ({100.0 * done / max(1, total):.0f} %)")
        stream.flush()
        _progress_shown = True

    return show


def progress_counter(what: str, stream=None):
    """:func:`stage_printer` for one named stage: a ``progress(done, total)`` callback (tiles,
    lines), ``None`` when ``stream`` (default stderr) is not a terminal.
    """
    show = stage_printer(stream)
    if show is None:
        return None
    return lambda done, total: show(done, total, what)


def clear_progress(stream=None) -> None:
    """Erase the progress line of :func:`progress_printer`, if one is shown."""
    global _progress_shown
    if not _progress_shown:
        return
    stream = sys.stderr if stream is None else stream
    try:
        stream.write("\r\033[K")
        stream.flush()
    except (ValueError, OSError):
        pass
    _progress_shown = False


def strict_values(obj):
    """``obj`` with every NaN or infinite number as None, numpy scalars and arrays as Python
    numbers and lists: what strict JSON holds (``Reproduction.to_json``, :func:`json_text`).
    """
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: strict_values(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [strict_values(v) for v in obj]
    item = getattr(obj, "item", None)  # numpy scalars
    if item is not None and getattr(obj, "ndim", 1) == 0:
        return strict_values(item())
    tolist = getattr(obj, "tolist", None)  # numpy arrays
    if tolist is not None:
        return strict_values(tolist())
    return obj


def json_text(obj, **kwargs) -> str:
    """``json.dumps(obj, indent=1)`` with every NaN or infinite number written as ``null``
    (strict JSON: ``NaN`` and ``Infinity`` are not JSON, and most readers refuse them).
    """
    kwargs.setdefault("indent", 1)
    return json.dumps(strict_values(obj), allow_nan=False, **kwargs)


#: glibc's ``mallopt`` parameters (``malloc.h``)
_M_TRIM_THRESHOLD, _M_MMAP_MAX = -1, -4


def keep_freed_memory() -> bool:
    """Make glibc keep the memory this process frees for its own reuse: large blocks come from
    the heap instead of ``mmap`` (``M_MMAP_MAX`` 0) and the heap is never given back
    (``M_TRIM_THRESHOLD`` −1, ``mallopt(3)``), as the Makefile's ``GLIBC_TUNABLES`` does for
    ``make``'s processes.

    An adjustment allocates arrays of hundreds of MB in every iteration; unmapped when freed,
    each new one has its pages faulted in and zeroed by the kernel again. On the pushbroom
    adjustment at 10× the paper's size this was 1.0 M page faults and 22 s of the solve's
    124 CPU-s, against 17 k faults and 12 s with the memory kept: 67 s of wall time against 77
    (bench/results/pushbroom_malloc.json, one run each). The peak memory is the same (the freed
    blocks are reused, not added to).

    Called by the ``hsgeo`` command for its own process only; a program that imports hsgeo
    decides for itself (or sets ``GLIBC_TUNABLES``). Does nothing where ``GLIBC_TUNABLES``
    already sets a ``glibc.malloc`` parameter (the caller chose) or the C library is not glibc.
    Returns whether the settings were made.
    """
    if "glibc.malloc" in os.environ.get("GLIBC_TUNABLES", ""):
        return False
    if platform.libc_ver()[0] != "glibc":
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, -1))
