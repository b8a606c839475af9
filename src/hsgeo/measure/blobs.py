"""The intensity-weighted centroid of a bright blob: the one equation both square measurers use.

A white reference square (002 §4, Fig. 6 and 9) is measured the same way in an LP scene
(:func:`hsgeo.measure.targets_lp.blob_centroid`) and in an orthomosaic
(:func:`hsgeo.measure.squares.square_centroids`); they differ only in how they find the window
and its background. :func:`weighted_blob_centroid` is the common core: in a window with the
background subtracted, the cells above half the window's maximum form 8-connected blobs; the one
nearest a given cell, grown by one cell (so that the cells the square covers in part count with
their part, on every side), is the blob, and its centroid is the mean of the cell positions
weighted by the excess (negative values as 0).
"""

from __future__ import annotations

import numpy as np

__all__ = ["weighted_blob_centroid"]

_EIGHT = np.ones((3, 3), bool)
_EIGHT.setflags(write=False)


def weighted_blob_centroid(excess, near_rc):
    """Centroid of the half-maximum blob nearest a cell (module docstring).

    Parameters
    ----------
    excess : (rows, cols) ndarray
        The window minus its background (NaN counts as 0).
    near_rc : (2,) array_like
        Row, column (cells) the blob is chosen nearest to (e.g. the peak, or a predicted
        position).

    Returns
    -------
    rc : (2,) ndarray or None
        Row, column of the centroid (cells, sub-cell; None when nothing is brighter than 0).
    blob : (rows, cols) bool ndarray or None
        The grown blob's cells.
    """
    from scipy.ndimage import binary_dilation, label

    w = np.nan_to_num(np.asarray(excess, dtype=np.float64), nan=0.0)
    top = float(w.max()) if w.size else 0.0
    if not top > 0:
        return None, None
    lab, _ = label(w > 0.5 * top, structure=_EIGHT)
    rr, cc = np.nonzero(lab)
    d = np.hypot(rr - near_rc[0], cc - near_rc[1])
    best = lab[rr[np.argmin(d)], cc[np.argmin(d)]]
    blob = binary_dilation(lab == best, structure=_EIGHT)
    br, bc = np.nonzero(blob)
    ww = np.maximum(w[br, bc], 0.0)
    if not ww.sum() > 0:
        return None, blob
    return np.array([np.sum(ww * br), np.sum(ww * bc)]) / ww.sum(), blob
