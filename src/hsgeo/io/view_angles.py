"""The view-angle table of a line scanner (the ``view-angle`` model of
:mod:`hsgeo.io.sensor_file`): a CSV beside the sensor file.

===============  ===========  ====================================================
column           unit         meaning
===============  ===========  ====================================================
``pixel``        (integer)    0-based pixel of the line (the cube's sample)
``across_deg``   degrees      across-track view angle, positive to the right
``along_deg``    degrees      along-track view angle, positive forward
``band``         (integer)    optional: 0-based band, for one table per band
===============  ===========  ====================================================

Every pixel 0 … n−1 once (per band; every band 0 … B−1 with the same pixels).

**Radians under ``_deg`` are refused**: a table whose across-track field of view is below
:data:`MIN_FOV_DEG` while it would be a line scanner's 5° or more read as radians (no airborne
line scanner has a field of view below 1°).
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = ["MIN_FOV_DEG", "read_view_angles"]

#: The smallest across-track field of view taken as degrees (below: radians, see above).
MIN_FOV_DEG = 1.0


def read_view_angles(path) -> tuple[np.ndarray, np.ndarray]:
    """Read a view-angle table (module docstring).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    across_deg, along_deg : (n_bands, n_px) ndarray, degrees
        ``n_bands`` = 1 without a ``band`` column.

    Raises
    ------
    InputError
        Missing columns or file, a pixel missing or repeated (naming it), bands with different
        pixels, angles beyond ±89°, or radians under ``_deg``.
    """
    from hsgeo.io.tables import read_table

    what = f"view-angle table {str(path)!r}"
    kw = dict(
        integer_columns=["pixel"], limits={"across_deg": (-89.0, 89.0), "along_deg": (-89.0, 89.0)}
    )
    cols = ["pixel", "across_deg", "along_deg"]
    head = read_table(path, cols, "view-angle", unique_rows=False, **kw)
    has_band = "band" in head.columns
    if not has_band:  # a row given twice, named by its lines (one per band is not a repeat)
        head = read_table(path, cols, "view-angle", **kw)
    if has_band:
        try:
            bands = np.asarray(head["band"], dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{what}: column band must hold whole numbers (0-based)") from None
        if not np.all(np.isfinite(bands)) or np.any(bands != np.round(bands)) or np.any(bands < 0):
            raise InputError(f"{what}: column band must hold whole numbers ≥ 0 (0-based band)")
        bands = bands.astype(int)
    else:
        bands = np.zeros(len(head), dtype=int)
    px = np.asarray(head["pixel"], dtype=int)
    a = np.asarray(head["across_deg"], dtype=float)
    b = np.asarray(head["along_deg"], dtype=float)
    n_b = int(bands.max()) + 1
    present = set(bands.tolist())
    if present != set(range(n_b)):
        miss = sorted(set(range(n_b)) - present)
        raise InputError(f"{what}: band(s) {miss} missing; give every band 0..{n_b - 1}")
    n_px = int(px.max()) + 1
    across = np.full((n_b, n_px), np.nan)
    along = np.full((n_b, n_px), np.nan)
    seen = np.zeros((n_b, n_px), dtype=int)
    if np.any(px < 0):
        raise InputError(f"{what}: pixel {int(px.min())} is negative; pixels are 0-based")
    np.add.at(seen, (bands, px), 1)
    across[bands, px], along[bands, px] = a, b
    if np.any(seen > 1):
        k, p = (int(x[0]) for x in np.nonzero(seen > 1))
        raise InputError(
            f"{what}: pixel {p}" + (f" of band {k}" if has_band else "") + " appears twice"
        )
    if np.any(seen == 0):
        k, p = (int(x[0]) for x in np.nonzero(seen == 0))
        hint = " (pixels are 0-based: subtract 1 from a 1-based table)" if p == 0 else ""
        raise InputError(
            f"{what}: pixel {p}" + (f" of band {k}" if has_band else "") + " is missing; give "
            f"every pixel 0..{n_px - 1}{hint}"
        )
    fov = np.ptp(across, axis=1)
    if np.any(fov < MIN_FOV_DEG) and np.all(np.rad2deg(fov) >= 5.0):
        raise InputError(
            f"{what}: across_deg spans only {fov.min():.4g}°, {np.rad2deg(fov.min()):.3g}° if "
            "the values are radians; give degrees (multiply radians by 57.2958)"
        )
    return across, along
