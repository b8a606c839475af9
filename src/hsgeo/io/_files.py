"""Writing files safely: atomic replacement, and never over a file the command reads."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path

from hsgeo.errors import InputError

__all__ = [
    "atomic_path",
    "output_group",
    "refuse_inputs",
    "check_outputs",
    "check_input_file",
    "read_text",
    "os_error_message",
]

#: What to do about the operating system's refusals, by errno (the words of
#: :func:`os_error_message`).
_OS_REMEDY = {
    errno.ENAMETOOLONG: "the file name is too long for the file system (255 bytes a name); "
    "choose a shorter name",
    errno.EACCES: "permission denied; choose a folder you can write to, or check the file's "
    "permissions",
    errno.EPERM: "the operating system does not allow it; choose another folder or file",
    errno.EROFS: "the file system is read-only; choose another folder",
    errno.ENOSPC: "no space left on the device; free some space or choose another folder",
    errno.EDQUOT: "the disk quota is exceeded; free some space or choose another folder",
    errno.EISDIR: "is a folder, not a file; give a file name",
    errno.ENOTDIR: "a part of the path is a file, not a folder; check the path",
    errno.ELOOP: "too many symbolic links; check the path",
    errno.ENOENT: "no such file or folder (or no file can be created there); check the path",
    errno.EIO: "input/output error of the device; check the disk or choose another folder",
}


def os_error_message(exc: OSError, what: str = "") -> str:
    """One line for an operating system's refusal: the file, and what to do about it.

    Parameters
    ----------
    exc : OSError
        The error (its ``filename`` and ``errno`` are used; its text when the errno is not
        one of the common ones).
    what : str
        The file's role or the option that named it (``"-o/--output"``,
        ``"observation file"``), put before the file name.
    """
    name = exc.filename if exc.filename is not None else ""
    name = str(name)
    if len(name) > 80:
        name = name[:40] + "..." + name[-30:] + f" ({len(str(exc.filename))} characters)"
    remedy = _OS_REMEDY.get(exc.errno) or (exc.strerror or str(exc)).lower()
    head = " ".join(x for x in (what, repr(name) if name else "") if x)
    return f"{head}: {remedy}" if head else remedy


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
    A pipe or a device (``/dev/stdin``, a shell's process substitution ``<(...)``) is a file
    too: it is read once, as any input.
    """
    path = Path(path)
    try:
        path.stat()
    except FileNotFoundError:
        raise InputError(f"{what} {str(path)!r} not found; check the path") from None
    except OSError as exc:
        raise InputError(os_error_message(exc, what)) from None
    if path.is_dir():
        raise InputError(f"{what} {str(path)!r} is a directory, not a file; give the file")
    return path


#: The bytes of the pipes read so far (``/dev/stdin``, ``<(...)``), by device and inode: a pipe
#: can be read once, and a reader that looks at a file twice (its kind, then its content) gets
#: the same bytes the second time.
_PIPES: dict[tuple[int, int], bytes] = {}


def _read_bytes(path: Path) -> bytes:
    import stat

    st = path.stat()
    if stat.S_ISREG(st.st_mode):
        return path.read_bytes()
    key = (st.st_dev, st.st_ino)
    if key not in _PIPES:
        _PIPES[key] = path.read_bytes()
    return _PIPES[key]


def read_text(path, what: str, kind: str) -> str:
    """The text of a UTF-8 input file (a leading byte-order mark dropped, CRLF kept).

    A binary file (NUL bytes, or bytes that are not UTF-8) raises :class:`~hsgeo.InputError`
    naming the file and the ``kind`` of text expected (``"CSV table"``, ``"TOML"``).
    """
    path = check_input_file(path, what)
    try:
        data = _read_bytes(path)
    except OSError as exc:
        raise InputError(os_error_message(exc, what)) from None
    try:
        if b"\0" in data:
            raise UnicodeDecodeError("utf-8", data, data.index(b"\0"), len(data), "NUL byte")
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        known = _known_format(data[:8])
        if known:
            raise InputError(
                f"{what} {str(path)!r} is {known}, not a {kind} text file; give the {kind} "
                "file, saved as UTF-8 text"
            ) from None
        raise InputError(
            f"{what} {str(path)!r} is not a {kind} text file (binary or not UTF-8 at byte "
            f"{exc.start}); give the {kind} file, saved as UTF-8"
        ) from None
    return text


#: Leading bytes of formats a text file is mistaken for (a Parquet table or an
#: Excel workbook named .csv, a UTF-16 CSV, were "binary or not UTF-8 at byte N").
_MAGIC = (
    (b"PAR1", "a Parquet table (name it .parquet to read it as one)"),
    (b"PK\x03\x04", "a ZIP archive (an Excel workbook? export the sheet as CSV)"),
    (b"\xd0\xcf\x11\xe0", "an old Office document (an Excel .xls? export the sheet as CSV)"),
    (b"\xff\xfe", "UTF-16 text (Excel's 'Unicode text'; save it as UTF-8)"),
    (b"\xfe\xff", "UTF-16 text (save it as UTF-8)"),
    (b"\x1f\x8b", "gzip-compressed (decompress it: gunzip)"),
    (b"\x89HDF", "an HDF5 / NetCDF-4 file"),
    (b"CDF", "a NetCDF-3 file"),
)


def _known_format(head: bytes) -> str:
    for magic, name in _MAGIC:
        if head.startswith(magic):
            return name
    return ""


def check_outputs(outputs, inputs: Iterable = (), *, overwrite: bool = False) -> list[Path]:
    """Check the files a command will write, before it does any work.

    Each output's folder must exist and a file must be creatable in it (a temporary file is
    made and removed, as :func:`atomic_path` will: this finds a name too long, a read-only or
    virtual file system, a folder without permission), the output must not be a folder (nor
    end in ``/``), not one of the ``inputs``, not given twice, have one of the extensions
    its format allows, and an existing file is replaced only with ``overwrite``.

    Parameters
    ----------
    outputs : iterable of (path or None, str) or (path or None, str, dict)
        Each output with the option that names it (``(ortho, "-o")``) and optionally the
        extensions allowed, each with its format's name (``{".nc": "NetCDF"}``); ``None``
        paths skipped.
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
    for p, option, *formats in outputs:
        if p is None:
            continue
        if str(p).endswith(("/", os.sep)) or str(p) in (".", ".."):
            raise InputError(
                f"{option} {p}: names a folder (it ends in '/'), not a file; give a file name "
                f"in it, e.g. {os.path.join(str(p), 'out')}{_first(formats)}"
            )
        p = Path(p)
        try:
            _check_output(p, option, formats, inputs, seen, overwrite)
        except OSError as exc:  # a name too long, a folder without permission ...
            raise InputError(_creation_message(exc, option, p)) from None
        out.append((p, option, formats))
    for p, option, formats in out:  # after the clashes between outputs, which say more
        if formats:
            _check_format(p, option, formats[0])
    return [p for p, _, _ in out]


def _check_output(p: Path, option: str, formats, inputs, seen: dict, overwrite: bool) -> None:
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
    with _no_interrupt():  # the temporary file of atomic_path: can it be made there?
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".part", dir=folder)
        except OSError as exc:
            raise InputError(_creation_message(exc, option, p)) from None
        os.close(fd)
        os.unlink(tmp)


def _first(formats) -> str:
    return next(iter(formats[0]), "") if formats else ""


def _check_format(p: Path, option: str, formats: dict) -> None:
    """The extension of ``p`` is one of ``formats`` (``{".nc": "NetCDF"}``), case-insensitive."""
    suffix = p.suffix.lower()
    if suffix in formats:
        return
    by: dict[str, list[str]] = {}
    for k, v in formats.items():
        by.setdefault(v, []).append(k)
    names = "; ".join(f"{v}: {', '.join(ks)}" for v, ks in by.items())
    first = next(iter(formats))
    said = f"the extension {p.suffix!r} is not" if p.suffix else "no extension names"
    raise InputError(
        f"{option} {p}: {said} a format this command writes ({names}); "
        f"name the file {p.stem}{first}"
    )


def _creation_message(exc: OSError, option: str, p: Path) -> str:
    if exc.errno == errno.ENAMETOOLONG:
        return (
            f"{option}: the file name is too long for the file system ({len(p.name.encode())} "
            f"bytes; 255 a name, less the {len('..12345678.part')} of the temporary file); "
            "choose a shorter name"
        )
    return (
        f"{option} {p}: no file can be created in the folder {p.parent} "
        f"({exc.strerror or exc}); choose another folder"
    )


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
    tmp = None
    try:
        with _no_interrupt():  # Ctrl-C cannot fall between making the file and owning it
            try:
                fd, name = tempfile.mkstemp(
                    prefix=f".{path.name}.", suffix=".part", dir=path.parent
                )
            except OSError as exc:
                raise InputError(_creation_message(exc, "output", path)) from None
            tmp = Path(name)
            os.close(fd)
        # mkstemp makes the file 0600; the output gets the mode of any new file (0666 & ~umask)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        yield tmp
        group = getattr(_GROUP, "current", None)
        if group is not None:  # moved into place with the group's other files
            group.append((tmp, path))
            tmp = None
        else:
            os.replace(tmp, path)
    finally:
        if tmp is not None:
            tmp.unlink(missing_ok=True)


_GROUP = threading.local()


@contextlib.contextmanager
def output_group() -> Iterator[None]:
    """The files written through :func:`atomic_path` inside the block appear together or not at
    all (a set of outputs: an ENVI file and its header, the files of a flight).

    Each file's rename is deferred to the end of the block; then every one is moved into place,
    a file it replaces first moved aside. If a rename fails (the disk refuses, Ctrl-C is held
    back meanwhile), the files already moved are taken back out and the replaced ones restored:
    the folder is as it was. On an exception in the block nothing is moved. A file written in
    the block cannot be read back in it (it is not in place yet). Nested groups are one group.
    """
    if getattr(_GROUP, "current", None) is not None:
        yield
        return
    pending: list[tuple[Path, Path]] = []
    _GROUP.current = pending
    try:
        yield
        _GROUP.current = None
        with _no_interrupt():
            _commit(pending)
    finally:
        _GROUP.current = None
        for tmp, _ in pending:
            tmp.unlink(missing_ok=True)


def _commit(pending: list[tuple[Path, Path]]) -> None:
    """Move each (temporary, final) into place, all or none (see :func:`output_group`)."""
    done: list[tuple[Path, Path | None]] = []
    try:
        for tmp, final in pending:
            backup = None
            if os.path.lexists(final):
                backup = final.with_name(f".{final.name}.{os.getpid()}.previous.part")
                os.replace(final, backup)
            done.append((final, backup))
            os.replace(tmp, final)
    except BaseException:
        for final, backup in reversed(done):
            if backup is not None:
                os.replace(backup, final)
            else:
                final.unlink(missing_ok=True)
        raise
    for _, backup in done:
        if backup is not None:
            backup.unlink(missing_ok=True)


@contextlib.contextmanager
def _no_interrupt():
    """SIGINT held back for the block (main thread, POSIX), delivered right after it."""
    import signal
    import threading

    hold = (
        hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    )
    if hold:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        if hold:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


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
