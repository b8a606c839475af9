"""The reference squares in the scenes of one strip (:mod:`hsgeo.workflows.lp_observations`).

Each square's position in the strip is predicted from the navigation and the a-priori camera
(:func:`predict`: the line whose image y changes sign over the square's surveyed centre, and
the x there). That prediction is off by the a-priori boresight's error — a few tenths of a
degree, tens of pixels — which is as far as the squares lie from each other in a small block,
so the strongest bright blob near a prediction may be another square. The error is nearly the
same for every square of a strip (one boresight, one flying height, a slowly varying GNSS/INS
error), so:

1. :func:`candidates`: in every band of every scene, the bright square-sized blobs around each
   prediction (:func:`hsgeo.measure.targets_lp.square_candidates`) and their centroids
   (:func:`~hsgeo.measure.targets_lp.blob_centroid`);
2. :func:`choose`: the offset (candidate − prediction, in scene pixels) supported by the most
   (square, band) pairs of the strip — within ``box_px + 1`` px of each other — is the strip's
   prediction error; each square and band takes its candidate nearest prediction + offset,
   if one lies within that tolerance. A blob of a neighbouring square is off that common
   offset by the squares' spacing and is not taken.

The chosen centroid is registered at its sub-pixel x in the nearest line and at the time of its
sub-line row (:func:`_time_at`).
"""

from __future__ import annotations

import numpy as np

from hsgeo.workflows import _lp_geometry as geo

__all__ = ["predict", "candidates", "choose", "COLUMNS"]

#: Columns of the squares' diagnostics table (:attr:`LpResult.squares`).
COLUMNS = ["point_id", "band", "strip", "line", "t_s", "x_px", "u", "v", "snr", "ok"]


def predict(strip, inputs, height):
    """Each square's predicted fractional line and x in this strip, and the box size in px."""
    t_s = np.asarray(strip.t_s, float)
    line, x = geo.crossing_lines(inputs.camera, inputs.square_xyz_m, t_s, inputs.navigation)
    z = inputs.navigation.pose(t_s[t_s.size // 2])[0][0, 2]
    c = float(np.atleast_1d(inputs.camera.c_mm)[0])
    gsd_m = (z - height) * inputs.camera.pixel_mm / c
    return line, x, gsd_m


def candidates(sc, predicted, inputs, options, bands) -> list:
    """Candidate blobs of the squares predicted in this scene, in every band."""
    from hsgeo.measure.lp_scenes import scene_to_line
    from hsgeo.measure.targets_lp import blob_centroid, square_candidates

    line, x, gsd_m = predicted
    n = sc.image.shape[0]
    box = max(2, int(np.ceil(options.square_size_m / gsd_m)))
    h_px = (inputs.n_px_full - 1) / 2
    out = []
    for k in np.flatnonzero(np.isfinite(line)):
        u0 = line[k] - sc.line0
        if not (0 <= u0 <= n - 1):
            continue
        uv0 = np.array([u0, x[k] + h_px - sc.col0])  # δx is far inside the search window
        for b in bands:
            cand, snr = square_candidates(
                sc.image[:, :, b], uv0, box_px=box, search_px=options.square_search_px
            )
            for c, s in zip(cand, snr, strict=True):
                uv, ok = blob_centroid(sc.image[:, :, b], c, box_px=box)
                if not ok:
                    continue
                ln, xx = scene_to_line(sc, uv[None, :])
                out.append((k, b, uv0, c, float(s), uv, int(ln[0]), float(xx[0]), box))
    return out


def choose(cands: list, strip, predicted, inputs, options) -> list:
    """The strip's common prediction error by vote, and each square's blob there (rows)."""
    if not cands:
        return []
    t_s = np.asarray(strip.t_s, float)
    sq = np.array([c[0] for c in cands])
    band = np.array([c[1] for c in cands])
    off = np.array([c[3] - c[2] for c in cands], dtype=float)
    snr = np.array([c[4] for c in cands])
    tol = cands[0][8] + 1.0
    near = np.linalg.norm(off[:, None, :] - off[None, :, :], axis=2) <= tol
    pair = sq * 1000 + band
    support = np.array([np.unique(pair[near[i]]).size for i in range(len(cands))])
    best = np.lexsort((-snr, -support))[0]
    d = np.linalg.norm(off - off[best], axis=1)
    rows = []
    for key in np.unique(pair):
        i = np.flatnonzero((pair == key) & (d <= tol))
        if i.size == 0:
            continue
        k, b, _, _, s, uv, ln, xx, _ = cands[i[np.argmin(d[i])]]
        rows.append(
            {
                "point_id": str(inputs.square_ids[k]),
                "band": int(b),
                "strip": str(strip.strip_id),
                "line": ln,
                "t_s": _time_at(t_s, ln + (uv[0] - np.round(uv[0]))),
                "x_px": xx,
                "u": float(uv[0]),
                "v": float(uv[1]),
                "snr": s,
                "ok": True,
            }
        )
    return rows


def _time_at(t_s, line) -> float:
    """The time of a fractional line (the centroid's row between two lines, linear in time).

    A square's centroid measures its centre along the track too: the observation is registered
    at that time (``y_px = 0`` there), not at the nearest line's, so it carries no line
    rounding — which, shared by the k bands that see the square in one line, would count k
    times (:func:`hsgeo.measure.tie_points.one_band_per_feature` says why for tie points).
    """
    return float(np.interp(line, np.arange(t_s.size), t_s))
