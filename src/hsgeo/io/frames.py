"""Folders of raw ImSpector frames (``hsgeo cube RAW_DIR --dark DARK_DIR``).

A frame folder holds

* the frames, in file-name order: 16-bit grayscale TIFF (``.tif``/``.tiff``, one frame per
  file) or NumPy (``.npy``: one frame ``(rows, columns)`` or a stack ``(n, rows, columns)``),
  raw DN of the 12-bit camera (0–4095), spectral rows down, spatial columns across;
* ``exposures.csv`` with columns ``file, exposure_s``: the exposure time of every frame file
  (one value for all the frames of a ``.npy`` stack);
* for the survey folder, ``wavelengths.csv`` with columns ``row, wavelength_nm, fwhm_nm``:
  the centre and width of every spectral row of the frame (its spectral calibration).

:class:`FrameFolder` reads frames on demand (stacks are memory-mapped), so a long survey never
sits in memory whole.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io.tables import read_table

__all__ = ["FrameFolder", "read_wavelengths", "write_frame_folder", "FRAME_SUFFIXES"]

FRAME_SUFFIXES = (".tif", ".tiff", ".npy")


def _frame_shape(path: Path):
    """(n_frames, rows, columns) of a frame file, without reading its pixels when possible."""
    if path.suffix.lower() == ".npy":
        try:
            arr = np.load(path, mmap_mode="r")
        except (ValueError, OSError, EOFError) as exc:
            raise InputError(
                f"frame file {str(path)!r} is not a readable .npy array: {exc}"
            ) from None
        if arr.dtype.kind not in "ui" or arr.dtype.itemsize < 2:
            raise InputError(
                f"frame file {str(path)!r} holds {arr.dtype} values; a frame is the camera's "
                "raw DN as unsigned 16-bit integers (uint16): 8-bit or scaled frames have lost "
                "the 12-bit levels the dark and reflectance corrections need; export the raw "
                "frames"
            )
        if arr.ndim == 2:
            return (1, *arr.shape)
        if arr.ndim == 3:
            return arr.shape
        raise InputError(
            f"frame file {str(path)!r} holds a {arr.ndim}-D array; a frame is (rows, columns), "
            "a stack (n, rows, columns)"
        )
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            if getattr(im, "n_frames", 1) != 1 or im.mode not in ("I;16", "I;16B", "I;16L", "I"):
                raise InputError(
                    f"frame file {str(path)!r} is a {im.mode} TIFF with "
                    f"{getattr(im, 'n_frames', 1)} page(s); give one 16-bit grayscale frame "
                    "per file"
                )
            return (1, im.height, im.width)
    except (UnidentifiedImageError, OSError) as exc:
        raise InputError(f"frame file {str(path)!r} is not a readable TIFF: {exc}") from None


#: Files of other frame formats that a frame folder must not hold (they would be left out)
_OTHER_FRAME_SUFFIXES = (".hdr", ".raw", ".img", ".bsq", ".bil", ".bip", ".png", ".jpg", ".bmp")


def _check_frame_names(folder: Path, files: list, what: str) -> None:
    """The frame files are one numbered series: one name pattern, no number missing, and no
    frames in another format beside them (a lost frame, a stray file or ENVI frames would
    otherwise be taken silently).
    """
    import re

    others = sorted(p.name for p in folder.iterdir() if p.suffix.lower() in _OTHER_FRAME_SUFFIXES)
    if others:
        raise InputError(
            f"{what} {str(folder)!r} holds {others[0]}"
            + (f" and {len(others) - 1} more" if len(others) > 1 else "")
            + ": frames are read only as 16-bit TIFF or .npy (ENVI or 8-bit images are not "
            "frames); convert them, or move other files out of the folder"
        )
    pat = re.compile(r"^(.*?)(\d+)(\.[^.]+)$")
    parts = [pat.match(p.name) for p in files]
    if len(files) < 2 or not all(parts):
        return  # names without a number: the name order is the only order there is
    stems = {(m.group(1), m.group(3).lower()) for m in parts}
    if len(stems) > 1:
        common = max(stems, key=lambda k: sum((m.group(1), m.group(3).lower()) == k for m in parts))
        odd = next(
            p.name
            for p, m in zip(files, parts, strict=True)
            if (m.group(1), m.group(3).lower()) != common
        )
        raise InputError(
            f"{what} {str(folder)!r}: {odd} is not one of the series {common[0]}NNNN{common[1]}; "
            "move files that are not frames of this run out of the folder"
        )
    nums = np.array([int(m.group(2)) for m in parts])
    gaps = np.flatnonzero(np.diff(nums) != 1)
    if gaps.size:
        i = int(gaps[0])
        raise InputError(
            f"{what} {str(folder)!r}: the frame numbers jump from {files[i].name} to "
            f"{files[i + 1].name} ({int(nums[i + 1] - nums[i] - 1)} frame(s) missing): the "
            "lines would be stacked without them; restore the missing frames"
        )


def _read_file(path: Path) -> np.ndarray:
    if path.suffix.lower() == ".npy":
        arr = np.load(path, mmap_mode="r")
        return arr[None] if arr.ndim == 2 else arr
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im, dtype=np.uint16)[None]


class FrameFolder:
    """The frames of one folder with their exposure times, read on demand.

    Attributes
    ----------
    folder : Path
    files : list of Path
        The frame files in name order.
    n_frames : int
    frame_shape : (rows, columns)
    exposure_s : (n_frames,) ndarray
    what : str
        The folder's role in messages (``"RAW_DIR"``, ``"--dark"``).

    Raises
    ------
    InputError
        The folder is missing or holds no frames, ``exposures.csv`` is missing or does not list
        every frame file, or the frames are not all of one size (the message names the first
        file that differs).
    """

    def __init__(self, folder, what: str = "RAW_DIR"):
        self.folder = Path(folder)
        self.what = what
        if not self.folder.is_dir():
            raise InputError(
                f"{what} {str(self.folder)!r} is not a folder of frames; check the path"
            )
        self.files = sorted(
            p for p in self.folder.iterdir() if p.suffix.lower() in FRAME_SUFFIXES and p.is_file()
        )
        if not self.files:
            raise InputError(
                f"{what} {str(self.folder)!r} holds no frames (.tif, .tiff or .npy files)"
            )
        _check_frame_names(self.folder, self.files, what)
        exp = self.folder / "exposures.csv"
        df = read_table(
            exp, ["file", "exposure_s"], "exposure", text_columns=["file"], unique=["file"]
        )
        by_file = dict(zip(df["file"], df["exposure_s"].to_numpy(float), strict=True))
        missing = [p.name for p in self.files if p.name not in by_file]
        if missing:
            raise InputError(
                f"exposure file {str(exp)!r} lists no exposure_s for {missing[0]}"
                + (f" and {len(missing) - 1} more frame file(s)" if len(missing) > 1 else "")
                + "; add a row 'file,exposure_s' for every frame file"
            )
        names = {p.name for p in self.files}
        absent = [f for f in by_file if f not in names]
        if absent:
            raise InputError(
                f"exposure file {str(exp)!r} lists {absent[0]}"
                + (f" and {len(absent) - 1} more file(s)" if len(absent) > 1 else "")
                + f", not in {what} {str(self.folder)!r}: a frame file lost or renamed? restore "
                "it, or delete its row"
            )
        bad = [f for f, t in by_file.items() if not (0.0 < t < 100.0)]
        if bad:
            raise InputError(
                f"exposure file {str(exp)!r}: exposure_s of {bad[0]} is {by_file[bad[0]]:g}; "
                "give the exposure time in seconds (0 < exposure_s < 100)"
            )
        shapes = [_frame_shape(p) for p in self.files]
        first = shapes[0][1:]
        for p, s in zip(self.files, shapes, strict=True):
            if s[1:] != first:
                raise InputError(
                    f"{what}: frames of mixed sizes: {p.name} is {s[1]} × {s[2]} px, "
                    f"{self.files[0].name} is {first[0]} × {first[1]} px; give frames of one "
                    "size (one binning)"
                )
        self.frame_shape = tuple(int(x) for x in first)
        counts = np.array([s[0] for s in shapes])
        self._starts = np.concatenate([[0], np.cumsum(counts)])
        self.n_frames = int(self._starts[-1])
        self.exposure_s = np.repeat([by_file[p.name] for p in self.files], counts)

    def locate(self, i: int) -> tuple[Path, int]:
        """The file holding frame ``i`` and the frame's index in it."""
        k = int(np.searchsorted(self._starts, i, side="right") - 1)
        return self.files[k], int(i - self._starts[k])

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Frames ``i0 … i1 − 1`` as a (n, rows, columns) uint16 array."""
        out = np.empty((i1 - i0, *self.frame_shape), dtype=np.uint16)
        i = i0
        while i < i1:
            k = int(np.searchsorted(self._starts, i, side="right") - 1)
            j0 = i - self._starts[k]
            j1 = min(i1, self._starts[k + 1]) - self._starts[k]
            data = _read_file(self.files[k])[j0:j1]
            if data.dtype.kind not in "ui" or (
                data.size and (data.min() < 0 or data.max() > 65535)
            ):
                raise InputError(
                    f"frame file {self.files[k].name}: values must be unsigned 16-bit raw DN"
                )
            out[i - i0 : i - i0 + (j1 - j0)] = data
            i += j1 - j0
        return out


def read_wavelengths(path, n_rows: int):
    """The spectral calibration of the frame rows: ``(wavelength_nm, fwhm_nm)``, each (n_rows,).

    Raises
    ------
    InputError
        The file is missing, or does not give one row for every spectral row 0 … n_rows − 1
        (the message names the missing rows).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(
            f"wavelength file {str(path)!r} not found: RAW_DIR needs wavelengths.csv with "
            f"columns row, wavelength_nm, fwhm_nm for its {n_rows} spectral rows"
        )
    df = read_table(
        path,
        ["row", "wavelength_nm", "fwhm_nm"],
        "wavelength",
        integer_columns=["row"],
        unique=["row"],
        limits={"wavelength_nm": (100.0, 3000.0), "fwhm_nm": (1e-3, 500.0)},
    )
    rows = df["row"].to_numpy()
    missing = np.setdiff1d(np.arange(n_rows), rows)
    if missing.size:
        ex = ", ".join(str(r) for r in missing[:5]) + (" …" if missing.size > 5 else "")
        raise InputError(
            f"wavelength file {str(path)!r}: missing wavelengths for {missing.size} of the "
            f"{n_rows} spectral rows ({ex}); give row, wavelength_nm, fwhm_nm for rows "
            f"0–{n_rows - 1}"
        )
    extra = rows[(rows < 0) | (rows >= n_rows)]
    if extra.size:
        raise InputError(
            f"wavelength file {str(path)!r}: row {int(extra[0])} is outside the frame's "
            f"{n_rows} spectral rows (0–{n_rows - 1}); check --binning"
        )
    order = np.argsort(rows)
    return (
        df["wavelength_nm"].to_numpy(float)[order],
        df["fwhm_nm"].to_numpy(float)[order],
    )


def write_frame_folder(
    folder, frames, exposure_s, *, wavelength_nm=None, fwhm_nm=None, fmt: str = "npy"
) -> list[Path]:
    """Write frames in the folder format of :class:`FrameFolder` (the folder is created).

    Parameters
    ----------
    folder : str or Path
    frames : (n, rows, columns) uint16 array_like
    exposure_s : (n,) array_like
    wavelength_nm, fwhm_nm : (rows,) array_like, optional
        Written as ``wavelengths.csv`` when given.
    fmt : {"npy", "tif"}
        One ``.npy`` file per frame, or one 16-bit TIFF per frame.

    Returns
    -------
    list of Path
        The files written.
    """
    from hsgeo.io._files import atomic_path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    frames = np.asarray(frames, dtype=np.uint16)
    t = np.asarray(exposure_s, dtype=float)
    if fmt not in ("npy", "tif"):
        raise InputError(f"frame format {fmt!r}: use 'npy' or 'tif'")
    out, names = [], []
    for i, frame in enumerate(frames):
        name = f"frame_{i:06d}.{fmt}"
        with atomic_path(folder / name) as tmp:
            if fmt == "npy":
                with open(tmp, "wb") as fh:
                    np.save(fh, frame)
            else:
                from PIL import Image

                Image.fromarray(np.ascontiguousarray(frame)).save(tmp, format="TIFF")  # I;16
        names.append(name)
        out.append(folder / name)
    with atomic_path(folder / "exposures.csv") as tmp:
        Path(tmp).write_text(
            "file,exposure_s\n"
            + "".join(f"{n},{float(ti)!r}\n" for n, ti in zip(names, t, strict=True))
        )
    out.append(folder / "exposures.csv")
    if wavelength_nm is not None:
        lam = np.asarray(wavelength_nm, dtype=float)
        fw = np.full(lam.shape, np.nan) if fwhm_nm is None else np.asarray(fwhm_nm, float)
        with atomic_path(folder / "wavelengths.csv") as tmp:
            Path(tmp).write_text(
                "row,wavelength_nm,fwhm_nm\n"
                + "".join(
                    f"{i},{float(w)!r},{float(f)!r}\n"
                    for i, (w, f) in enumerate(zip(lam, fw, strict=True))
                )
            )
        out.append(folder / "wavelengths.csv")
    return out
