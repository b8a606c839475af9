"""Writing files safely: atomic replacement, and never over a file the command reads."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from hsgeo.errors import InputError

__all__ = ["atomic_path", "refuse_inputs"]


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
