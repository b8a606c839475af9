"""Reference squares in an orthomosaic: each bright square's centroid in map coordinates.

002 Fig. 9 places reference squares of 1.2 m (white targets, their centres surveyed by RTK) in
the orthomosaic. :func:`square_centroids` finds, near each given map position, the bright blob
of the mosaic and returns its centroid: the background (the median of the search window) is
subtracted, the blob is the connected set of cells brighter than halfway between background and
the window's maximum that lies nearest the given position, grown by one cell (so that the cells
the square covers in part count with their part), and the centroid is the mean of the cell
centres weighted by their excess over the background. On cells that average the scene over
their area this centroid is the square's centre exactly; on a nearest-neighbour mosaic its
error is a fraction of a cell.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError, ObservationError

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
    from scipy import ndimage

    if not np.any(np.isfinite(win)):
        return None
    bg = float(np.nanmedian(win))
    top = float(np.nanmax(win))
    if not top > bg:
        return None
    bright = np.nan_to_num(win, nan=bg) > bg + 0.5 * (top - bg)
    lab, n_lab = ndimage.label(bright)
    if n_lab == 0:
        return None
    X, Y = np.meshgrid(xs, ys)
    d = [np.min(np.hypot(X[lab == i] - px, Y[lab == i] - py)) for i in range(1, n_lab + 1)]
    blob = ndimage.binary_dilation(lab == 1 + int(np.argmin(d)), structure=np.ones((3, 3), bool))
    w = np.where(blob & np.isfinite(win), np.clip(win - bg, 0.0, None), 0.0)
    if not w.sum() > 0:
        raise ObservationError("a square's cells are not brighter than the background")
    return (float((w * X).sum() / w.sum()), float((w * Y).sum() / w.sum())), int(blob.sum())
