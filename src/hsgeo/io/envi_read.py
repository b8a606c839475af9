"""Reading ENVI cubes as line scanners write them: the header found under either
naming, BIL/BIP/BSQ in either byte order after a ``header offset``, memory-mapped (a cube of
hundreds of GB is never read whole), wavelengths in nm, and the line times.

**Naming.** A cube is the binary file ``name``, ``name.raw``, ``name.dat``, ``name.img``,
``name.bil``, ``name.bip`` or ``name.bsq`` beside its header ``name.hdr`` (ENVI's own naming) or
``name.ext.hdr`` (GDAL's, and :func:`hsgeo.io.write_envi`'s). :func:`find_envi` takes any of the
binary file, the header or the bare ``name``.

**Why not Spectral Python.** ``spectral.envi.open`` reads the same layouts, but it does not
check the file's size against the header (a cube cut short is read, or fails later with numpy's
message), maps no ``data ignore value``, converts no wavelength units, and raises its own
exception types; it is a test dependency of hsgeo (the independent reader of tests/test_cube.py
and tests/test_io_envi_lines.py), not a runtime one. The data path here is one
:class:`numpy.memmap`; the tests check it against ``spectral`` on every interleave.

**Wavelengths.** ``wavelength`` and ``fwhm`` are converted to nm from ``wavelength units``
(Nanometers / nm, Micrometers / Microns / um / µm, Millimeters, Wavenumber is refused). When the
units are absent or ``Unknown``, wavelengths all below 30 are taken as µm and all above 200 as
nm; anything else is an error that asks for the units.

**Line times** (:func:`line_times`): a times file with one time per line, or the header's start
time and line period (keys in :data:`START_KEYS`, :data:`PERIOD_KEYS`, :data:`RATE_KEYS`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "PERIOD_KEYS",
    "RATE_KEYS",
    "START_KEYS",
    "EnviCube",
    "find_envi",
    "line_times",
    "open_envi",
    "read_envi_header",
    "READ_TYPES",
    "DATA_EXTS",
]

#: ENVI ``data type`` codes hsgeo reads (complex types 6 and 9 are refused).
READ_TYPES = {
    1: np.dtype("uint8"),
    2: np.dtype("int16"),
    3: np.dtype("int32"),
    4: np.dtype("float32"),
    5: np.dtype("float64"),
    12: np.dtype("uint16"),
    13: np.dtype("uint32"),
    14: np.dtype("int64"),
    15: np.dtype("uint64"),
}

#: Extensions of the binary file tried beside ``name.hdr`` ("" = no extension).
DATA_EXTS = ("", ".raw", ".dat", ".img", ".bil", ".bip", ".bsq")

#: Header keys of the time of line 0: seconds on the navigation's time scale, or a clock
#: ``HH:MM:SS[.fff]`` (optionally after ``UTC TIME:``), read as seconds of day.
START_KEYS = ("t0_s", "start time_s", "line start time_s", "gps start time", "start time")
#: Header keys of the line period, s.
PERIOD_KEYS = ("line period_s", "line_period_s", "line period")
#: Header keys of the line rate, Hz (frames per second of a line scanner).
RATE_KEYS = ("line_rate_hz", "line rate_hz", "line rate", "fps", "framerate", "frame rate")

_UNITS_TO_NM = {
    "nanometers": 1.0,
    "nanometer": 1.0,
    "nm": 1.0,
    "micrometers": 1e3,
    "micrometer": 1e3,
    "microns": 1e3,
    "micron": 1e3,
    "um": 1e3,
    "µm": 1e3,
    "millimeters": 1e6,
    "mm": 1e6,
}


def find_envi(path) -> tuple[Path, Path]:
    """The binary file and the header of an ENVI cube (module docstring: naming).

    Parameters
    ----------
    path : str or Path
        The binary file, its header, or the name without extension.

    Returns
    -------
    (data_path, header_path) : (Path, Path)

    Raises
    ------
    InputError
        No header, no binary file, or two different headers (``name.hdr`` and
        ``name.ext.hdr``) for one file.
    """
    p = Path(path)
    if p.suffix.lower() == ".hdr":
        hdr, base = p, p.with_suffix("")
        if not hdr.is_file():
            raise InputError(f"ENVI header {str(hdr)!r} not found; give an existing .hdr file")
        if base.suffix.lower() in DATA_EXTS[1:] and base.is_file():  # name.ext.hdr
            return base, hdr
        found = [base.with_name(base.name + e) for e in DATA_EXTS]
        found = [f for f in found if f.is_file()]
        if len(found) != 1:
            what = "no binary file" if not found else f"{len(found)} binary files"
            raise InputError(
                f"ENVI header {str(hdr)!r}: {what} beside it (looked for "
                f"{', '.join(repr(base.name + e) for e in DATA_EXTS)}); give the binary file "
                "itself"
            )
        return found[0], hdr
    if p.is_file():  # the binary file: name.ext.hdr or name.hdr
        cands = [p.with_name(p.name + ".hdr")]
        if p.suffix:
            cands.append(p.with_suffix(".hdr"))
        cands = [c for c in cands if c.is_file()]
        if not cands:
            raise InputError(
                f"ENVI file {str(p)!r}: no header beside it (looked for {p.name + '.hdr'!r}"
                + (f" and {p.with_suffix('.hdr').name!r}" if p.suffix else "")
                + "); put the cube's .hdr next to it"
            )
        if len(cands) == 2 and cands[0].read_bytes() != cands[1].read_bytes():
            raise InputError(
                f"ENVI file {str(p)!r}: two different headers beside it ({cands[0].name!r}, "
                f"{cands[1].name!r}); remove the one that does not describe it"
            )
        return p, cands[0]
    hdr = p.with_name(p.name + ".hdr")
    if hdr.is_file():
        return find_envi(hdr)
    raise InputError(
        f"ENVI file {str(p)!r} not found (neither it nor {hdr.name!r} exists); give the cube's "
        "binary file or its .hdr"
    )


def read_envi_header(hpath) -> dict:
    """The entries of an ENVI header: keys lower-case, values strings (``{...}`` kept whole).

    Raises
    ------
    InputError
        The file does not start with ``ENVI``, or a ``{`` is never closed.
    """
    hpath = Path(hpath)
    try:
        text = hpath.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise InputError(f"ENVI header {str(hpath)!r}: cannot be read ({exc})") from None
    if not text.lstrip("\ufeff").startswith("ENVI"):
        raise InputError(
            f"{hpath}: not an ENVI header (first line must be 'ENVI'); give the cube's .hdr"
        )
    hdr: dict = {}
    key, buf, start = None, "", 0
    for n, line in enumerate(text.splitlines()[1:], start=2):
        if key is not None:
            buf += " " + line.strip()
            if "}" in line:
                hdr[key], key = buf.strip(), None
            continue
        if "=" not in line or line.lstrip().startswith(";"):
            continue
        k, v = (s.strip() for s in line.split("=", 1))
        if v.startswith("{") and "}" not in v:
            key, buf, start = k.lower(), v, n
        else:
            hdr[k.lower()] = v
    if key is not None:
        raise InputError(
            f"{hpath}: the entry {key!r} opened with '{{' on line {start} is never closed; "
            "add the closing '}'"
        )
    return hdr


def _list(hdr, key, hpath) -> np.ndarray:
    try:
        return np.array([float(x) for x in hdr[key].strip("{}").split(",") if x.strip()])
    except ValueError:
        raise InputError(f"{hpath}: the {key} entry is not a list of numbers") from None


def _wavelengths_nm(hdr, hpath, n_bands):
    """(wavelength_nm, fwhm_nm), each (bands,) or None (module docstring: wavelengths)."""
    if "wavelength" not in hdr:
        return None, None
    wl = _list(hdr, "wavelength", hpath)
    fw = _list(hdr, "fwhm", hpath) if "fwhm" in hdr else None
    for name, v in (("wavelength", wl), ("fwhm", fw)):
        if v is not None and v.shape != (n_bands,):
            raise InputError(
                f"{hpath}: {name} has {v.size} values for {n_bands} bands; give one per band"
            )
    unit = hdr.get("wavelength units", "").strip().lower()
    if unit in _UNITS_TO_NM:
        scale = _UNITS_TO_NM[unit]
    elif unit in ("", "unknown"):
        if np.all(wl < 30):
            scale = 1e3
        elif np.all(wl > 200):
            scale = 1.0
        else:
            raise InputError(
                f"{hpath}: wavelength units not given and the wavelengths "
                f"({wl.min():g} to {wl.max():g}) are neither all µm (< 30) nor all nm (> 200); "
                "add 'wavelength units = Nanometers' (or Micrometers) to the header"
            )
    else:
        raise InputError(
            f"{hpath}: wavelength units {hdr['wavelength units']!r} not understood; use "
            "Nanometers or Micrometers"
        )
    return wl * scale, (None if fw is None else fw * scale)


class EnviCube:
    """An ENVI cube opened by :func:`open_envi` (memory-mapped, nothing read yet).

    Attributes
    ----------
    data_path, header_path : Path
    header : dict
        The header's entries (strings).
    raw : numpy.memmap
        The values in the file's own order: ``(bands, lines, samples)`` for BSQ,
        ``(lines, bands, samples)`` for BIL, ``(lines, samples, bands)`` for BIP.
    interleave : {"bsq", "bil", "bip"}
    wavelength_nm, fwhm_nm : (bands,) ndarray or None
    ignore_value : float or None
        The header's ``data ignore value``.
    """

    def __init__(self, data_path, header_path, header, raw, interleave, wl, fw, ignore):
        self.data_path, self.header_path, self.header = data_path, header_path, header
        self.raw, self.interleave = raw, interleave
        self.wavelength_nm, self.fwhm_nm, self.ignore_value = wl, fw, ignore

    @property
    def bls(self) -> np.ndarray:
        """The values as a ``(bands, lines, samples)`` view of the memory map (no copy)."""
        order = {"bsq": (0, 1, 2), "bil": (1, 0, 2), "bip": (2, 0, 1)}[self.interleave]
        return self.raw.transpose(order)

    @property
    def lsb(self) -> np.ndarray:
        """The values as a ``(lines, samples, bands)`` view of the memory map (no copy)."""
        order = {"bsq": (1, 2, 0), "bil": (0, 2, 1), "bip": (0, 1, 2)}[self.interleave]
        return self.raw.transpose(order)

    @property
    def n_lines(self) -> int:
        return int(self.lsb.shape[0])


def _int_entry(hdr, key, hpath, default=None):
    if key not in hdr:
        if default is not None:
            return default
        raise InputError(
            f"{hpath}: the entry {key!r} is missing; an ENVI header needs samples, lines, "
            "bands and data type"
        )
    try:
        v = int(hdr[key].strip())
    except ValueError:
        raise InputError(f"{hpath}: {key} = {hdr[key]!r} is not an integer") from None
    if v < 0 or (key in ("samples", "lines", "bands") and v < 1):
        raise InputError(f"{hpath}: {key} = {v} must be positive")
    return v


def open_envi(path) -> EnviCube:
    """Open an ENVI cube memory-mapped, its size checked against its header.

    Parameters
    ----------
    path : str or Path
        The binary file, its header or the bare name (:func:`find_envi`).

    Returns
    -------
    EnviCube

    Raises
    ------
    InputError
        Naming the file and the remedy: no header or binary file, a header without samples,
        lines, bands or data type, an unknown data type, interleave or byte order, or a file
        whose size is not ``header offset`` + samples × lines × bands × bytes per value (a
        file cut short, or a header of another file).
    """
    dpath, hpath = find_envi(path)
    hdr = read_envi_header(hpath)
    s, n, b = (_int_entry(hdr, k, hpath) for k in ("samples", "lines", "bands"))
    code = _int_entry(hdr, "data type", hpath)
    if code not in READ_TYPES:
        raise InputError(
            f"{hpath}: data type = {code} is not one hsgeo reads (ENVI codes "
            f"{sorted(READ_TYPES)}; 6 and 9 are complex); convert the cube to a real type"
        )
    order = hdr.get("byte order", "0").strip()
    if order not in ("0", "1"):
        raise InputError(f"{hpath}: byte order = {order!r}; use 0 (little) or 1 (big endian)")
    dtype = READ_TYPES[code].newbyteorder("<" if order == "0" else ">")
    off = _int_entry(hdr, "header offset", hpath, default=0)
    inter = hdr.get("interleave", "bsq").strip().lower()
    shapes = {"bsq": (b, n, s), "bil": (n, b, s), "bip": (n, s, b)}
    if inter not in shapes:
        raise InputError(f"{hpath}: interleave = {inter!r} unknown; use bsq, bil or bip")
    want = off + s * n * b * dtype.itemsize
    size = dpath.stat().st_size
    if size != want:
        how = "is cut short" if size < want else "is larger than its header says"
        lines_held = max(size - off, 0) // max(s * b * dtype.itemsize, 1)
        raise InputError(
            f"ENVI file {str(dpath)!r} {how}: {size} bytes, the header says {want} "
            f"({hpath.name}: offset {off} + {s} samples × {n} lines × {b} bands × {dtype.itemsize} "
            f"bytes; the file holds {lines_held} whole lines); give the complete file, or "
            "correct lines/samples/bands/data type/header offset in the header"
        )
    raw = np.memmap(dpath, dtype=dtype, mode="r", offset=off, shape=shapes[inter])
    wl, fw = _wavelengths_nm(hdr, hpath, b)
    ignore = None
    if "data ignore value" in hdr:
        try:
            ignore = float(hdr["data ignore value"])
        except ValueError:
            raise InputError(
                f"{hpath}: data ignore value = {hdr['data ignore value']!r} is not a number"
            ) from None
    return EnviCube(dpath, hpath, hdr, raw, inter, wl, fw, ignore)


def _clock_s(text: str) -> float | None:
    m = re.search(r"(\d{1,2}):(\d{2}):(\d{2}(?:\.\d*)?)", text)
    if m is None:
        return None
    h, mi, sec = int(m[1]), int(m[2]), float(m[3])
    return h * 3600.0 + mi * 60.0 + sec


def _header_times(cube: EnviCube) -> np.ndarray:
    hdr, hpath = cube.header, cube.header_path
    start = next((k for k in START_KEYS if k in hdr), None)
    period = next((k for k in PERIOD_KEYS if k in hdr), None)
    rate = next((k for k in RATE_KEYS if k in hdr), None)
    if start is None or (period is None and rate is None):
        raise InputError(
            f"{hpath}: no line times: give a times file (one time per line), or add to the "
            f"header a start time (one of {', '.join(START_KEYS)}) and a line period (one of "
            f"{', '.join(PERIOD_KEYS)}, s) or rate (one of {', '.join(RATE_KEYS)}, Hz)"
        )
    v = hdr[start].strip().strip("{}")
    try:
        t0 = float(v)
    except ValueError:
        t0 = _clock_s(v)
    if t0 is None or not np.isfinite(t0):
        raise InputError(
            f"{hpath}: {start} = {hdr[start]!r} is neither seconds nor a clock HH:MM:SS"
        )
    key = period or rate
    try:
        x = float(hdr[key].strip().strip("{}").split()[0])
    except (ValueError, IndexError):
        x = float("nan")
    if not (np.isfinite(x) and x > 0):
        raise InputError(f"{hpath}: {key} = {hdr[key]!r} must be a positive number")
    dt = x if period else 1.0 / x
    return t0 + dt * np.arange(cube.n_lines)


def _times_file(path, n_lines: int) -> np.ndarray:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"times file {str(p)!r} not found; give one time per line of the cube")
    rows = [(i, ln.strip()) for i, ln in enumerate(p.read_text().splitlines(), start=1)]
    rows = [(i, ln) for i, ln in rows if ln and not ln.startswith("#")]
    col = 0
    if rows and not _is_number(rows[0][1].replace(";", ",").split(",")[0]):
        names = [c.strip().lower() for c in rows[0][1].replace(";", ",").split(",")]
        if "t_s" not in names:
            raise InputError(
                f"times file {str(p)!r}: line {rows[0][0]} is a header without a 't_s' column "
                f"({names}); name the time column t_s, or give one number per line"
            )
        col, rows = names.index("t_s"), rows[1:]
    t = np.empty(len(rows))
    for k, (i, ln) in enumerate(rows):
        cells = ln.replace(";", ",").split(",")
        try:
            t[k] = float(cells[col])
        except (ValueError, IndexError):
            raise InputError(
                f"times file {str(p)!r}, line {i}: {ln[:40]!r} has no time (s) in column "
                f"{col + 1}; correct it"
            ) from None
        if not np.isfinite(t[k]):
            raise InputError(f"times file {str(p)!r}, line {i}: the time is {ln!r}; give a number")
    if t.size != n_lines:
        raise InputError(
            f"times file {str(p)!r} has {t.size} times for a cube of {n_lines} lines; give "
            "exactly one time per line"
        )
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"times file {str(p)!r}, line {rows[k + 1][0]}: time {float(t[k + 1])!r} s does not "
            f"increase (previous {float(t[k])!r} s); the times must increase strictly, one per line"
        )
    return t


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def line_times(cube: EnviCube, times=None) -> np.ndarray:
    """The time of each line of ``cube`` (s).

    Parameters
    ----------
    cube : EnviCube
    times : str, Path or array_like, optional
        A times file: one time (s) per line, either plain numbers one per line or a CSV
        whose header row has a ``t_s`` column (``#`` lines skipped); or the times themselves.
        Without it, from the header's start time and line period (module docstring).

    Returns
    -------
    (lines,) ndarray
        Strictly increasing.

    Raises
    ------
    InputError
        A times file with more or fewer times than lines, a time that is not a number, or one
        that does not increase (the message names the file and its line).
    """
    if times is None:
        return _header_times(cube)
    if isinstance(times, (str, Path)):
        return _times_file(times, cube.n_lines)
    t = np.asarray(times, dtype=float)
    if t.shape != (cube.n_lines,) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError(
            f"line times for {str(cube.data_path)!r}: need {cube.n_lines} finite, strictly "
            f"increasing times, got shape {t.shape}"
        )
    return t
