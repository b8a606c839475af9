"""Writing files safely: atomic replacement, and never over a file the command reads."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from hsgeo.errors import InputError

__all__ = ["atomic_path", "refuse_inputs", "check_outputs", "check_input_file", "read_text"]


def refuse_inputs(output, inputs: Iterable = ()) -> Path:
    """Raise :class:`~hsgeo.InputError` if ``output`` is one of ``inputs`` (same file on disk).

    Parameters
    ----------
    output : str or Path
        The file about to be written.
    inputs : iterable of str or Path or None
        The files the command reads (``None`` entries are skipped).

    Returns
    -------
    Path
        ``output`` as a Path.
    """
    out = Path(output)
    target = out.resolve()
    for p in inputs:
        if p is None:
            continue
        p = Path(p)
        same = os.path.samefile(out, p) if out.exists() and p.exists() else target == p.resolve()
        if same:
            raise InputError(
                f"{out}: this is an input of the command and would be overwritten; "
                "write the output to another file name"
            )
    return out


def check_input_file(path, what: str) -> Path:
    """The input file ``path`` exists and is a file; :class:`~hsgeo.InputError` otherwise.

    ``what`` names its role (``"observation file"``, ``"LINES file"``).
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{what} {str(path)!r} is a directory, not a file; give the file")
    if not path.is_file():
        raise InputError(f"{what} {str(path)!r} not found; check the path")
    return path


def read_text(path, what: str, kind: str) -> str:
    """The text of a UTF-8 input file (a leading byte-order mark dropped, CRLF kept).

    A binary file (NUL bytes, or bytes that are not UTF-8) raises :class:`~hsgeo.InputError`
    naming the file and the ``kind`` of text expected (``"CSV table"``, ``"TOML"``).
    """
    path = check_input_file(path, what)
    data = path.read_bytes()
    try:
        if b"\0" in data:
            raise UnicodeDecodeError("utf-8", data, data.index(b"\0"), len(data), "NUL byte")
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{what} {str(path)!r} is not a {kind} text file (binary or not UTF-8 at byte "
            f"{exc.start}); give the {kind} file, saved as UTF-8"
        ) from None
    return text


def check_outputs(outputs, inputs: Iterable = (), *, overwrite: bool = False) -> list[Path]:
    """Check the files a command will write, before it does any work.

    Each output's folder must exist and be writable, the output must not be a folder, not one
    of the ``inputs``, not given twice, and an existing file is replaced only with
    ``overwrite``.

    Parameters
    ----------
    outputs : iterable of (path or None, str)
        Each output with the option that names it (``(ortho, "-o")``); ``None`` paths skipped.
    inputs : iterable of path
        The files the command reads.
    overwrite : bool
        The command's ``--overwrite``.

    Returns
    -------
    list of Path
    """
    inputs = [p for p in inputs if p is not None]
    seen: dict[Path, str] = {}
    out = []
    for p, option in outputs:
        if p is None:
            continue
        p = Path(p)
        refuse_inputs(p, inputs)
        key = p.resolve()
        if key in seen:
            raise InputError(
                f"{option} {p}: the same file as {seen[key]}; give each output its own name"
            )
        seen[key] = option
        if p.is_dir():
            raise InputError(f"{option} {p}: is a directory; give a file name in it")
        folder = p.parent
        if not folder.is_dir():
            raise InputError(f"{option} {p}: the folder {folder} does not exist; create it first")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise InputError(
                f"{option} {p}: the folder {folder} is not writable; choose another folder"
            )
        if p.exists() and not overwrite:
            raise InputError(f"{option} {p}: the file exists; use --overwrite to replace it")
        out.append(p)
    return out


@contextlib.contextmanager
def atomic_path(path, inputs: Iterable = ()) -> Iterator[Path]:
    """A temporary file next to ``path`` that replaces ``path`` only if the block succeeds.

    The caller writes to the yielded path; on success it is moved over ``path`` with
    :func:`os.replace` (atomic on one file system), on an exception it is removed and ``path``
    stays as it was.

    Parameters
    ----------
    path : str or Path
        The final file.
    inputs : iterable of path, optional
        Files the command reads: writing over one of them raises :class:`~hsgeo.InputError`
        (:func:`refuse_inputs`).
    """
    path = refuse_inputs(path, inputs)
    if not path.parent.is_dir():
        raise InputError(f"{path}: the folder {path.parent} does not exist; create it first")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    # mkstemp makes the file 0600; the output gets the mode of any new file (0666 & ~umask)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path, text: str, *, atomic: bool = False, make_parents: bool = False) -> Path:
    """Write ``text`` to ``path`` (UTF-8); ``atomic``: through :func:`atomic_path`;
    ``make_parents``: create the missing folders first. The one text writer outside the
    format modules (scoreboard records, ``hsgeo data``'s manifest).
    """
    path = Path(path)
    if make_parents:
        path.parent.mkdir(parents=True, exist_ok=True)
    if atomic:
        with atomic_path(path) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
    else:
        path.write_text(text, encoding="utf-8")
    return path


def make_folder(path, *, parents: bool = False) -> Path:
    """Create the folder ``path`` (an existing one is fine)."""
    path = Path(path)
    path.mkdir(parents=parents, exist_ok=True)
    return path


def copy_file(src, dest) -> Path:
    """Copy the bytes of ``src`` to ``dest``."""
    import shutil

    shutil.copyfile(src, dest)
    return Path(dest)
