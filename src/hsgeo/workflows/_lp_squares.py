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

__all__ = [
    "check_placement",
    "predict",
    "candidates",
    "choose",
    "as_tie_points",
    "COLUMNS",
    "SQUARES_AS",
]

#: How the squares are measured: as the matcher's tie points (002 §4) or by their blobs' centroids.
SQUARES_AS = ("tie_point", "centroid")

#: Columns of the squares' diagnostics table (:attr:`LpResult.squares`).
COLUMNS = ["point_id", "band", "strip", "line", "t_s", "x_px", "u", "v", "snr", "ok", "box_px"]


def check_placement(inputs, footprints, margin_m: float = 0.0) -> None:
    """The squares lie on the ground the strips see, in the navigation's frame and units.

    Squares far outside the strips, in longitude/latitude, with E and N swapped or
    heights in mm gave an answer without the squares (or with blobs that are not them), exit 0.
    Refused: no square inside any strip's footprint (``footprints``: the strips' quadrilaterals
    on the terrain plane, :func:`hsgeo.workflows._lp_geometry.footprint`); more squares inside
    with E and N exchanged; heights that spread over more than the block's width or reach the
    aircraft.

    Raises
    ------
    InputError
    """
    from hsgeo.errors import InputError

    xyz = np.asarray(inputs.square_xyz_m, float)
    n = len(xyz)
    low = float(np.min(np.asarray(inputs.navigation.xyz_m, float)[:, 2]))
    if np.max(xyz[:, 2]) >= low:
        raise InputError(
            f"the squares (--squares) reach H_m {np.max(xyz[:, 2]):.6g} m, not below the "
            f"aircraft (U_m down to {low:.6g} m in the navigation): give H_m in metres, in the "
            "navigation's height system"
        )
    width = float(np.max(np.ptp(xyz[:, :2], axis=0))) if n > 1 else 0.0
    spread = float(np.ptp(xyz[:, 2])) if n > 1 else 0.0
    if spread > max(width, 10.0):
        raise InputError(
            f"the squares' heights (--squares H_m) spread over {spread:.6g} m across a block "
            f"{width:.6g} m wide: are they in mm? give H_m in metres"
        )

    def inside(EN):
        hit = np.zeros(n, bool)
        for fp in footprints:
            hit |= geo.inside_convex(EN, fp, margin_m)
        return int(hit.sum())

    given, swapped = inside(xyz[:, :2]), inside(xyz[:, 1::-1])
    if given == 0 and swapped == 0:
        E, N = xyz[:, 0], xyz[:, 1]
        P = np.concatenate(footprints)
        raise InputError(
            f"none of the {n} squares (--squares) lies on the ground the strips see (squares "
            f"at E {E.min():.6g}…{E.max():.6g}, N {N.min():.6g}…{N.max():.6g} m; the strips "
            f"cover E {P[:, 0].min():.6g}…{P[:, 0].max():.6g}, N {P[:, 1].min():.6g}…"
            f"{P[:, 1].max():.6g} m): give E_m, N_m in metres in the navigation's frame (not "
            "longitude/latitude), the navigation of these lines (on their time scale, not "
            "shifted; heading in degrees from north), or the squares of these strips"
        )
    if swapped > max(2 * given, given + 2):
        raise InputError(
            f"{given} of the {n} squares (--squares) lie on the ground the strips see, {swapped} "
            "with E_m and N_m exchanged: are the columns E_m and N_m swapped? give E_m east "
            "and N_m north"
        )


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
    found = []
    # each band as float64 once per scene (the measurers' own conversion is then a no-op),
    # not once per square and candidate; and each peak's blob once per band, however many
    # squares' search windows find it (issue 41)
    image, blobs = {}, {}
    for k in np.flatnonzero(np.isfinite(line)):
        u0 = line[k] - sc.line0
        if not (0 <= u0 <= n - 1):
            continue
        uv0 = np.array([u0, x[k] + h_px - sc.col0])  # δx is far inside the search window
        for b in bands:
            if b not in image:
                image[b] = np.asarray(sc.image[:, :, b], dtype=np.float64)
            cand, snr = square_candidates(
                image[b], uv0, box_px=box, search_px=options.square_search_px
            )
            for c, s in zip(cand, snr, strict=True):
                key = (b, int(c[0]), int(c[1]))
                if key not in blobs:
                    blobs[key] = blob_centroid(image[b], c, box_px=box)
                uv, ok = blobs[key]
                if ok:
                    found.append((k, b, uv0, c, float(s), uv.copy()))
    if not found:
        return []
    # back to the original lines, all candidates at once (element by element as one by one)
    ln, xx = scene_to_line(sc, np.array([f[5] for f in found]))
    return [(*f, int(ln[i]), float(xx[i]), box) for i, f in enumerate(found)]


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
        k, b, _, _, s, uv, ln, xx, box = cands[i[np.argmin(d[i])]]
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
                "box_px": int(box),
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


def as_tie_points(ties, centroids, score, *, min_on: int = 2):
    """The squares as 002 measured them: the matcher's tie points that lie on a square.

    002 §4: the check points are "tie points with known coordinates", found by the key-point
    matcher like any other and registered at the centre of their pixel (§3.1), "more often
    identified in the lower spectral bands" (§5.3) — so in the strips and bands where the matcher
    happens to find them, not in every strip and band that sees them. The square's blob
    (``centroids``, :func:`choose`) only says where the square is in each strip: a tie
    point's observation is *on* the square when it lies within half the square's box plus ½ px
    of the blob's centre (the median over the bands that measured it in that strip), in x and in
    line. A tie point with at least ``min_on`` observations on one square, and at least half of
    its observations there, is a candidate; in each band, each square takes the candidate with
    the most observations on it (then the most observations, then the lowest ``score``), and
    keeps all its observations, renamed to the square's id — of one ground feature: the best
    candidate's and another band's only where it found the same feature
    (:func:`_one_feature`). One tie point per band, as 002's
    matching is per band: "the reference squares are more often identified in the lower
    spectral bands and hence provide more observations in the lower spectral bands for the
    estimation of the principal distance correction" (§5.3) — a square found in k bands is
    observed k times in the lines where it was found (with their one line rounding).

    Parameters
    ----------
    ties : pandas.DataFrame
        Every band's tie-point observations: ``point_id``, ``point`` (its index), ``strip``,
        ``line``, ``x_keypoint_px`` (sub-pixel), ``line_offset``, ``feature`` and the table's
        columns.
    centroids : pandas.DataFrame
        The squares' blob measurements (``point_id``, ``band``, ``strip``, ``line``, ``x_px``,
        ``line_frac``, ``box_px``).
    score : (n_points,) ndarray
        Per tie point, lower is better.

    Returns
    -------
    rows : pandas.DataFrame
        The chosen tie points' observations with the square's id as ``point_id``.
    taken_features : ndarray
        Features of every candidate tie point (of any square): they are the squares, not free
        tie points, and leave the adjustment's tie points.
    """
    import pandas as pd

    empty = ties.iloc[:0].copy()
    if len(centroids) == 0 or len(ties) == 0:
        return empty, np.zeros(0, np.int64)
    c = (
        centroids.groupby(["point_id", "strip"])
        .agg(line=("line_frac", "median"), x=("x_px", "median"), r=("box_px", "max"))
        .reset_index()
    )
    c["r"] = c["r"] / 2 + 0.5
    line_obs = ties["line"].to_numpy(float) + ties["line_offset"].to_numpy(float)
    x_obs = ties["x_keypoint_px"].to_numpy(float)
    strip_obs = ties["strip"].to_numpy().astype(str)
    on_sq = np.full(len(ties), -1, np.int64)  # index into c of the square it lies on
    for i, (st, ln, x, r) in enumerate(
        zip(c["strip"].astype(str), c["line"], c["x"], c["r"], strict=True)
    ):
        hit = (strip_obs == st) & (np.abs(line_obs - ln) <= r) & (np.abs(x_obs - x) <= r)
        on_sq[hit & (on_sq < 0)] = i
    sq_of_obs = np.where(on_sq >= 0, c["point_id"].to_numpy().astype(str)[np.maximum(on_sq, 0)], "")
    df = pd.DataFrame({"point": ties["point"].to_numpy(), "sq": sq_of_obs})
    n_obs = df.groupby("point").size()
    on = df[df["sq"] != ""].groupby(["point", "sq"]).size().rename("n_on").reset_index()
    if on.empty:
        return empty, np.zeros(0, np.int64)
    on["n_obs"] = n_obs.loc[on["point"]].to_numpy()
    on = on[(on["n_on"] >= min_on) & (2 * on["n_on"] >= on["n_obs"])]
    if on.empty:
        return empty, np.zeros(0, np.int64)
    on["score"] = np.asarray(score, float)[on["point"].to_numpy()]
    band = ties.drop_duplicates("point").set_index("point")["band"]
    on["band"] = band.loc[on["point"].to_numpy()].to_numpy()
    on = on.sort_values(
        ["sq", "band", "n_on", "n_obs", "score", "point"], ascending=[1, 1, 0, 0, 1, 1]
    )
    chosen = on.drop_duplicates(["sq", "band"]).drop_duplicates("point")
    on_rows = on_sq >= 0
    chosen = _one_feature(
        chosen,
        ties["point"].to_numpy()[on_rows],
        strip_obs[on_rows],
        x_obs[on_rows],
        line_obs[on_rows],
    )
    feats = ties.drop_duplicates("point").set_index("point")["feature"]
    taken = np.unique(feats.loc[on["point"].to_numpy()].to_numpy()).astype(np.int64)
    name = dict(zip(chosen["point"], chosen["sq"], strict=True))
    rows = ties[ties["point"].isin(list(name))].copy()
    rows["point_id"] = rows["point"].map(name)
    return rows, taken


#: Two bands' tie points on a square are one ground feature when their observations in every
#: strip both have lie within this distance in x and in line, px.
SAME_FEATURE_PX = 1.0


def _one_feature(chosen, point, strip, x, line):
    """Per square, the candidates of one ground feature: the best one (most observations on
    the square, then most observations, then lowest score) and another band's only where it
    found the same feature (:data:`SAME_FEATURE_PX` in every strip where both lie on the
    square; ``point``, ``strip``, ``x``, ``line``: the observations on a square).

    A check point is one tie point with known coordinates (002 §4): one ground feature, seen in
    the bands that found it. BRISK finds a square's corners, not its centre, so tie points of
    different bands on one square are often different corners, ~1.2 m apart; renamed to one
    point they are inconsistent observations, which the adjustment's each-iteration rejection
    peels off a few at a time (at book size, seed 0: 288 of 970 rows over 50 iterations
    without converging).
    """
    import pandas as pd

    pos = (
        pd.DataFrame({"point": point, "strip": strip, "x": x, "ln": line})
        .groupby(["point", "strip"])
        .median()
    )
    keep = []
    for _, grp in chosen.groupby("sq", sort=False):
        g = grp.sort_values(["n_on", "n_obs", "score", "point"], ascending=[0, 0, 1, 1])
        best = g["point"].iloc[0]
        pb = pos.loc[best]
        keep.append(best)
        for q in g["point"].iloc[1:]:
            d = pos.loc[q].join(pb, how="inner", rsuffix="_b")
            if (
                len(d)
                and (
                    (np.abs(d["x"] - d["x_b"]) <= SAME_FEATURE_PX)
                    & (np.abs(d["ln"] - d["ln_b"]) <= SAME_FEATURE_PX)
                ).all()
            ):
                keep.append(q)
    return chosen[chosen["point"].isin(keep)]
