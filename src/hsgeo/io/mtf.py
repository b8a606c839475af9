"""The files of ``hsgeo mtf`` and ``hsgeo mtf-edge``: bar profiles, the bar file, edge images.

* Profiles (CSV or Parquet): ``x_px`` (position along the line, pixel-centre coordinates) and
  ``intensity_dn`` (raw intensity), one row per sample; an optional integer column ``row`` (the
  spectral line) holds several profiles in one file.
* The bar file (TOML)::

      [target]
      pair_mm = [20.88, 18.60, ...]   # width of a black + white pair of each group, mm
      n_pairs = [2, 2, ...]           # pairs per group (groups follow each other, white first)
      white_reflectance = 0.90
      black_reflectance = 0.04
      [profile]
      gsd_mm = 0.4838                 # GSD along the line, mm (refined from the bars)
      start_px = 80.5                 # where the target starts on the profile, px (to ±3 px)
      dark_dn = 60.0                  # dark level to subtract (a dark frame's mean), DN
      saturation_dn = 4095            # samples at or above it on the target are an error

* Edge images: 8- or 16-bit PNG or TIFF, grey (colour images are averaged over channels).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_input_file
from hsgeo.io.config import Key, read_dataclass
from hsgeo.io.tables import read_table

__all__ = [
    "BarsFile",
    "BarsTargetTable",
    "BarsProfileTable",
    "read_bars",
    "read_profiles",
    "read_gray_image",
    "write_profiles",
    "write_bars",
    "write_columns",
]


def _key(kind: str, doc: str, **kw):
    return {"key": Key(kind, doc=doc, **kw)}


@dataclass(frozen=True, kw_only=True)
class BarsTargetTable:
    """``[target]`` of the bar file: the bar groups and the two reflectances."""

    pair_mm: tuple[float, ...] = field(
        metadata=_key("floats", "pair width per group, mm", positive=True)
    )
    n_pairs: tuple[float, ...] = field(metadata=_key("floats", "pairs per group", positive=True))
    white_reflectance: float = field(
        metadata=_key("float", "reflectance of the white bars", positive=True, limit=10.0)
    )
    black_reflectance: float = field(
        metadata=_key("float", "reflectance of the black bars", limit=10.0)
    )


@dataclass(frozen=True, kw_only=True)
class BarsProfileTable:
    """``[profile]`` of the bar file: where the target lies on a profile and its levels."""

    gsd_mm: float = field(metadata=_key("float", "GSD along the line, mm", positive=True))
    start_px: float = field(metadata=_key("float", "start of the target on the profile, px"))
    dark_dn: float = field(default=0.0, metadata=_key("float", "dark level, DN"))
    saturation_dn: float = field(
        default=4095.0, metadata=_key("float", "saturation, DN", positive=True)
    )


@dataclass(frozen=True, kw_only=True)
class BarsFile:
    """The bar file of ``hsgeo mtf`` (the schema :func:`read_bars` loads)."""

    target: BarsTargetTable
    profile: BarsProfileTable


def read_bars(path):
    """The bar file: ``(BarTarget, BarsProfileTable)``."""
    from hsgeo.mtf import BarTarget

    f = read_dataclass(path, BarsFile, "bar file")
    t = f.target
    if len(t.pair_mm) != len(t.n_pairs):
        raise InputError(
            f"bar file {path}: [target] pair_mm has {len(t.pair_mm)} groups, n_pairs "
            f"{len(t.n_pairs)}; give one pair count per pair width"
        )
    try:
        target = BarTarget(
            tuple(t.pair_mm),
            tuple(int(n) if float(n).is_integer() else n for n in t.n_pairs),
            white_reflectance=t.white_reflectance,
            black_reflectance=t.black_reflectance,
        )
    except InputError as exc:
        raise InputError(f"bar file {path}: [target] {exc}") from None
    return target, f.profile


def read_profiles(path) -> dict:
    """Profiles ``{row: (x_px, intensity_dn)}`` (row None without a ``row`` column), sorted."""
    df = read_table(path, ["x_px", "intensity_dn"], "profile", unique_rows=False)
    if "row" in df.columns:
        df = read_table(
            path, ["row", "x_px", "intensity_dn"], "profile", integer_columns=("row",),
            unique=[("row", "x_px")],
        )  # fmt: skip
        groups = {int(r): g for r, g in df.groupby("row", sort=True)}
    else:
        df = read_table(path, ["x_px", "intensity_dn"], "profile", unique=["x_px"])
        groups = {None: df}
    out = {}
    for r, g in groups.items():
        g = g.sort_values("x_px")
        out[r] = (g["x_px"].to_numpy(float), g["intensity_dn"].to_numpy(float))
    return out


def read_gray_image(path) -> np.ndarray:
    """An 8- or 16-bit PNG or TIFF as a float (rows, cols) array (colour: channel mean)."""
    import cv2

    path = check_input_file(Path(path), "image file")
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None or img.size == 0:
        raise InputError(
            f"image file {str(path)!r} is not a readable image; give an 8- or 16-bit PNG or TIFF"
        )
    if img.dtype not in (np.uint8, np.uint16, np.float32, np.float64):
        raise InputError(f"image file {str(path)!r}: pixel type {img.dtype} is not supported")
    img = img.astype(float)
    if img.ndim == 3:
        img = img[..., :3].mean(axis=2)
    if not np.all(np.isfinite(img)):
        raise InputError(f"image file {str(path)!r} holds NaN or infinite pixels")
    return img


def write_profiles(path, rows, x_px, profiles_dn) -> Path:
    """Write profiles (one per spectral row) as the CSV ``hsgeo mtf`` reads (atomically)."""
    lines = ["row,x_px,intensity_dn"]
    for r, prof in zip(rows, np.atleast_2d(profiles_dn), strict=True):
        lines += [f"{int(r)},{x:.17g},{v:.17g}" for x, v in zip(x_px, prof, strict=True)]
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return Path(path)


def write_bars(path, target, profile: dict) -> Path:
    """Write the bar file (``[target]`` from a :class:`~hsgeo.mtf.BarTarget`, ``[profile]`` from
    ``profile``: gsd_mm, start_px, dark_dn, saturation_dn) atomically.
    """
    unknown = set(profile) - {f.name for f in fields(BarsProfileTable)}
    if unknown:
        raise InputError(f"unknown [profile] keys {sorted(unknown)}")
    text = (
        "[target]\n"
        f"pair_mm = [{', '.join(f'{p:.17g}' for p in target.pair_mm)}]\n"
        f"n_pairs = [{', '.join(str(int(n)) for n in target.n_pairs)}]\n"
        f"white_reflectance = {target.white_reflectance!r}\n"
        f"black_reflectance = {target.black_reflectance!r}\n"
        "[profile]\n" + "".join(f"{k} = {float(v)!r}\n" for k, v in profile.items())
    )
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_columns(path, columns: dict) -> Path:
    """Write equal-length numeric columns as a CSV (``%.17g``) atomically."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    lines = [",".join(names)] + [",".join(f"{v:.17g}" for v in row) for row in data]
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return Path(path)
