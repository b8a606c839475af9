"""Reference squares in an orthomosaic: each bright square's centroid in map coordinates.

002 Fig. 9 places reference squares of 1.2 m (white targets, their centres surveyed by RTK) in
the orthomosaic. :func:`square_centroids` finds, near each given map position, the bright blob
of the mosaic and returns its centroid: the background (the median of the search window) is
subtracted, and the centroid is :func:`hsgeo.measure.blobs.weighted_blob_centroid` (the one
shared with the LP-scene measurer :mod:`hsgeo.measure.targets_lp`) of the blob nearest the
given position, in map coordinates. On cells that average the scene over their area this
centroid is the square's centre exactly; on a nearest-neighbour mosaic its error is a fraction
of a cell. Kept apart from :mod:`hsgeo.measure.targets_lp`: a map window around a known
position, no detection among the scene's bright things, x/y coordinates of a georeferenced
grid.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = ["square_centroids"]


def square_centroids(mosaic, positions_xy_m, *, search_m: float = 3.0, band=None):
    """Centroids of bright squares near given map positions.

    Parameters
    ----------
    mosaic : xarray.DataArray
        ``(band, y, x)`` or ``(y, x)`` with cell-centre coordinates ``x``, ``y`` in m (the
        mosaic of :func:`hsgeo.ortho.orthomosaic`; a Dask array is read window by window).
    positions_xy_m : (k, 2) array_like
        Approximate square centres (their RTK positions), map x, y in m.
    search_m : float
        Half width of the square window searched around each position, m.
    band : int or str, optional
        Band to measure in (default: the sum of all bands).

    Returns
    -------
    xy_m : (k, 2) ndarray
        Centroids, m (NaN where no blob was found: no data, or nothing brighter).
    n_cells : (k,) int ndarray
        Cells of each blob.
    """
    P = np.atleast_2d(np.asarray(positions_xy_m, dtype=float))
    if P.shape[1] != 2 or not np.all(np.isfinite(P)):
        raise InputError(f"square positions must be finite (k, 2) map x, y, got shape {P.shape}")
    if not search_m > 0:
        raise InputError(f"search_m must be positive, got {search_m}")
    img = mosaic
    if "band" in img.dims:
        img = (
            img.sum("band", skipna=False)
            if band is None
            else (img.isel(band=band) if isinstance(band, int | np.integer) else img.sel(band=band))
        )
    x, y = img["x"].values, img["y"].values
    out = np.full((P.shape[0], 2), np.nan)
    n = np.zeros(P.shape[0], dtype=int)
    for k, (px, py) in enumerate(P):
        cols = np.flatnonzero(np.abs(x - px) <= search_m)
        rows = np.flatnonzero(np.abs(y - py) <= search_m)
        if cols.size < 3 or rows.size < 3:
            continue
        win = np.asarray(
            img.isel(y=slice(rows[0], rows[-1] + 1), x=slice(cols[0], cols[-1] + 1)).values, float
        )
        res = _blob_centroid(win, x[cols[0] : cols[-1] + 1], y[rows[0] : rows[-1] + 1], px, py)
        if res is not None:
            out[k], n[k] = res
    return out, n


def _blob_centroid(win, xs, ys, px, py):
    from hsgeo.measure.blobs import weighted_blob_centroid

    if not np.any(np.isfinite(win)):
        return None
    bg = float(np.nanmedian(win))
    w = np.where(np.isfinite(win), win - bg, 0.0)
    near = (
        np.interp(py, ys, np.arange(ys.size))
        if ys[0] < ys[-1]
        else np.interp(-py, -ys, np.arange(ys.size)),
        np.interp(px, xs, np.arange(xs.size)),
    )
    rc, blob = weighted_blob_centroid(w, near)
    if rc is None:
        return None
    # cell centres are evenly spaced: the centroid's row/column maps linearly to y/x
    x = xs[0] + rc[1] * (xs[-1] - xs[0]) / max(xs.size - 1, 1)
    y = ys[0] + rc[0] * (ys[-1] - ys[0]) / max(ys.size - 1, 1)
    return (float(x), float(y)), int(blob.sum())
