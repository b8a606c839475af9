"""1D spatial calibration of a line scanner from a user's files (000 §4, ``hsgeo calibrate-line``).

The model (000 eq. (1)–(3)), its residual block, the design checks and the resection live in
:mod:`hsgeo.sensors.line1d`; this module strings them into the calibration a user runs:
read the measured minima and the control points, check the minimum-observation rule, resect
every image for initial values, and adjust in stages (:func:`calibrate`).
"""

from __future__ import annotations

import re

import numpy as np

from hsgeo.adjust import Parameters, adjust
from hsgeo.errors import HsgeoError, InputError, ObservationError
from hsgeo.io import read_table
from hsgeo.measure.line_minima import associate_by_order, find_minima
from hsgeo.sensors.line1d import (
    LineObservations,
    check_minimum_observations,
    make_parameters,
    resect,
)

__all__ = ["observe_rows", "calibrate", "calibrate_files"]


def observe_rows(
    frames_dn,
    xy_m,
    *,
    offset_dn: float = 0.0,
    n_columns: int | None = None,
    method: str = "parabola",
    row: int | None = None,
):
    """Measured ζ of the control points on raw rows, associated with the points by their order.

    The dark lines of the pattern are the minima of each row (:func:`~hsgeo.measure.line_minima.
    find_minima`); ζ grows as the point's x decreases (000 eq. (2): ζ − ζ0 ∝ −X, for stations
    looking along +y), so the k-th minimum is the point with the k-th largest x.

    Parameters
    ----------
    frames_dn : (n_images, n_columns_total) array_like
        One raw row per image.
    xy_m : (n_points, 2) array_like
        Control-point coordinates in the scanner plane.
    offset_dn : float
        Dark offset subtracted before the search.
    n_columns : int, optional
        Only the first ``n_columns`` see the scene (001 §2.1: 1170 of 1280).
    method : str
        Sub-pixel method of :func:`~hsgeo.measure.line_minima.find_minima`.
    row : int, optional
        The spectral row, for error messages.

    Returns
    -------
    image, point : (m,) int ndarrays
        Image index and point index (into ``xy_m``) of each observation.
    zeta_px : (m,) ndarray
    """
    xy = np.asarray(xy_m, dtype=float)
    order = np.argsort(-xy[:, 0], kind="stable")
    img, pt, zz = [], [], []
    for i, dn in enumerate(frames_dn):
        prof = np.asarray(dn, dtype=float)[:n_columns] - offset_dn
        z, _ = find_minima(prof, method=method)
        p, z = associate_by_order(z, order, f"image {i}, row {row}")
        img.append(np.full(p.size, i))
        pt.append(p)
        zz.append(z)
    return np.concatenate(img), np.concatenate(pt), np.concatenate(zz)


def calibrate(params: Parameters, block: LineObservations, *, stages: bool = True, **kw):
    """Adjust a 1D calibration from rough initial values, freeing the unknowns in stages.

    Starting from nominal inner orientation (e.g. 000 Table 1 'uncalibrated': 485 / 3600 px,
    no distortion) a direct adjustment of all unknowns can fall into a wrong minimum (the
    7th-order polynomial bends to absorb the exterior orientation errors). The stages are:
    (1) exterior orientation only; (2) plus ζ0 and c; (3) everything free in ``params``. Each
    stage starts from the previous estimate; the last one is the result (with its datum check).

    Parameters
    ----------
    params : Parameters
        From :func:`make_parameters`; its free/fixed flags and priors define the final stage.
    block : LineObservations
    **kw
        Passed to :func:`hsgeo.adjust.adjust` in the final stage (e.g. ``reject_k``).

    Returns
    -------
    AdjustmentResult
    """
    p = params.copy()
    if stages:
        final_free = {n: p[n].free.copy() for n in ("zeta0_px", "c_px", "K")}
        p.fix("zeta0_px")
        p.fix("c_px")
        p.fix("K")
        p = adjust(p, block, check_datum=False, raise_on_failure=False).params
        for n in ("zeta0_px", "c_px"):
            p[n].free = final_free[n].copy()
        p = adjust(p, block, check_datum=False, raise_on_failure=False).params
        p["K"].free = final_free["K"].copy()
    return adjust(p, block, **kw)


def calibrate_files(
    observations,
    control,
    *,
    zeta0_px: float = 485.0,
    c_px: float = 3600.0,
    sigma_px: float = 0.1,
    reject_k: float | None = None,
) -> dict:
    """Calibrate one spectral line from a user's files (``hsgeo calibrate-line``).

    Parameters
    ----------
    observations : path
        CSV with header ``image,point,zeta_px``: image id, point id, measured ζ [px] (pixel-centre
        origin at column 0), one row per measured minimum.
    control : path
        CSV with header ``point,x_m,y_m``: control point id and its coordinates [m] in the scanner
        plane. Every observed point must be a control point; off-line points (e.g. side signals
        in front of the pattern) make the scale determinable (see the ``line-calibration``
        chapter).
    zeta0_px, c_px : float
        Initial inner orientation (default: 000 Table 1 'uncalibrated').
    sigma_px : float
        A-priori σ of a measured ζ.

    Returns
    -------
    dict with ``result`` (AdjustmentResult), ``image_ids``, ``point_ids``, ``residuals_px``.
    """
    obs = read_table(
        observations,
        ("image", "point", "zeta_px"),
        "observation",
        text_columns=("image", "point"),
        unique=(("image", "point"),),
    )
    ctl = read_table(
        control,
        ("point", "x_m", "y_m"),
        "control",
        text_columns=("point",),
        unique=("point",),
        limits={"x_m": (-100.0, 100.0), "y_m": (-100.0, 100.0)},
    )
    pid = ctl["point"].tolist()
    xy = ctl[["x_m", "y_m"]].to_numpy(dtype=float)
    z = obs["zeta_px"].to_numpy(dtype=float)
    index = {p: i for i, p in enumerate(pid)}
    missing = sorted(set(obs["point"]) - set(index))
    if missing:
        raise InputError(
            f"observed points without control coordinates: {missing[:10]}; add them "
            f"to the control file {str(control)!r}"
        )
    image_ids = list(dict.fromkeys(obs["image"]))
    img = np.array([image_ids.index(i) for i in obs["image"]])
    pt = np.array([index[p] for p in obs["point"]])
    blk = LineObservations(img, pt, z, sigma_px)  # NaN check
    try:
        check_minimum_observations(img, pt, np.ones(len(pid), bool), len(image_ids))
    except ObservationError as exc:  # the user's image id instead of its index
        msg = re.sub(r"^image (\d+)", lambda m: f"image {image_ids[int(m.group(1))]}", str(exc))
        raise ObservationError(f"observation file {str(observations)!r}: {msg}") from None
    seen = xy[np.unique(pt)]
    if np.linalg.svd(seen - seen.mean(axis=0), compute_uv=False)[-1] <= 1e-9 * max(
        1.0, float(np.abs(seen).max())
    ):
        raise InputError(
            f"control file {str(control)!r}: the observed points all lie on one line (x_m, y_m "
            "collinear): the scale c is undetermined; add control points off the pattern line "
            "(e.g. side signals in front of it)"
        )
    eop = []
    for i, name in enumerate(image_ids):
        try:
            eop.append(resect(xy[pt[img == i]], z[img == i], zeta0_px, c_px).eop)
        except HsgeoError as exc:
            raise InputError(
                f"observation file {str(observations)!r}, image {name}: {exc}; check its zeta_px "
                "values and point ids, and --zeta0-px / --c-px"
            ) from None
    eop = np.array(eop)
    p = make_parameters(
        eop,
        zeta0_px,
        c_px,
        [0.0, 0.0, 0.0],
        xy,
        np.ones(len(pid), bool),
        image_ids=image_ids,
        point_ids=pid,
    )
    res = calibrate(p, blk, reject_k=reject_k)
    return {
        "result": res,
        "image_ids": image_ids,
        "point_ids": pid,
        "residuals_px": res.residuals(blk.name),
    }
