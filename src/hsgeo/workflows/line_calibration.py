"""1D spatial calibration of a line scanner from a user's files (000 §4, ``hsgeo calibrate-line``).

The model (000 eq. (1)–(3)), its residual block, the design checks and the resection live in
:mod:`hsgeo.sensors.line1d`; this module strings them into the calibration a user runs:
read the measured minima and the control points, check the minimum-observation rule, resect
every image for initial values, and adjust in stages (:func:`calibrate`).

The in-memory core (GUIDE §2): :class:`LineInputs` and :class:`LineOptions` ->
:func:`calibrate_line` -> :class:`LineCalibration` (with ``to_dict()``); ``hsgeo
calibrate-line`` (:func:`calibrate_files`, the file front end) and ``hsgeo reproduce
line-calibration`` both call it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

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

__all__ = [
    "observe_rows",
    "calibrate",
    "calibrate_files",
    "LineInputs",
    "LineOptions",
    "LineCalibration",
    "calibrate_line",
]


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

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    .. [2] Krtalić, A., Miljković, V., Gajski, D. and Racetin, I. (2019). Spatial distortion
           assessments of a low-cost laboratory and field hyperspectral imaging system. Sensors
           19(19), 4267 (paper 001).
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

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
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


@dataclass(frozen=True)
class LineInputs:
    """The observations of one spectral line and the control points.

    Attributes
    ----------
    image, point : (m,) int ndarray
        Image and point index of every measured ζ.
    zeta_px : (m,) ndarray
        Measured ζ, px (pixel-centre origin at column 0).
    xy_m : (n_points, 2) ndarray
        Control-point coordinates in the scanner plane, m.
    image_ids, point_ids : sequence, optional
        The user's ids (labels of the parameters).
    initial_eop : (n_images, 3) ndarray, optional
        Initial exterior orientation; None: each image resected (:func:`~hsgeo.sensors.line1d.
        resect`) from the initial ζ0 and c.
    """

    image: np.ndarray
    point: np.ndarray
    zeta_px: np.ndarray
    xy_m: np.ndarray
    image_ids: tuple | None = None
    point_ids: tuple | None = None
    initial_eop: np.ndarray | None = None


@dataclass(frozen=True)
class LineOptions:
    """Initial inner orientation (000 Table 1 'uncalibrated': 485 / 3600 px), the a-priori σ
    of ζ, outlier rejection and the staged start of :func:`calibrate`.

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """

    zeta0_px: float = 485.0
    c_px: float = 3600.0
    sigma_px: float = 0.1
    reject_k: float | None = None
    stages: bool = True


@dataclass(frozen=True)
class LineCalibration:
    """One calibrated spectral line.

    Attributes
    ----------
    result : hsgeo.adjust.AdjustmentResult
    image_ids, point_ids : list or None
    residuals_px : (m,) ndarray
        Residuals of the measured ζ (model − observed), px.
    """

    result: object
    image_ids: list | None
    point_ids: list | None
    residuals_px: np.ndarray

    def parameters(self) -> list[tuple[str, float, float]]:
        """``(name, value, σ̂)`` of ζ0, c, K1, K2, K3 (px)."""
        res = self.result
        out = [("zeta0_px", res.value("zeta0_px"), res.sigma("zeta0_px"))]
        out += [("c_px", res.value("c_px"), res.sigma("c_px"))]
        out += [
            (k, a, s)
            for k, a, s in zip(("K1", "K2", "K3"), res.value("K"), res.sigma("K"), strict=True)
        ]
        return out

    def residual_stats(self) -> dict:
        """σ0, degrees of freedom, RMS and largest |residual| (px), number of observations."""
        v = self.residuals_px
        return {
            "sigma0": self.result.sigma0,
            "dof": self.result.dof,
            "rms_px": float(np.sqrt(np.mean(v**2))),
            "max_abs_px": float(np.max(np.abs(v))),
            "n_observations": int(v.size),
        }

    def to_dict(self) -> dict:
        """``{"parameters": {name: {"value", "sigma"}}, "residuals": residual_stats()}``."""
        return {
            "parameters": {
                k: {"value": float(a), "sigma": float(s)} for k, a, s in self.parameters()
            },
            "residuals": self.residual_stats(),
        }


def calibrate_line(inputs: LineInputs, options: LineOptions = LineOptions()) -> LineCalibration:
    """Calibrate one spectral line: the minimum-observation rule (000 §4.1), initial exterior
    orientation (given, or resected per image), then :func:`calibrate` in stages.

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """
    xy = np.asarray(inputs.xy_m, dtype=float)
    control = np.ones(len(xy), bool)
    blk = LineObservations(inputs.image, inputs.point, inputs.zeta_px, options.sigma_px)
    check_minimum_observations(inputs.image, inputs.point, control)
    eop = inputs.initial_eop
    if eop is None:
        z, img, pt = blk.zeta_px, blk.image, blk.point
        eop = np.array(
            [
                resect(xy[pt[img == i]], z[img == i], options.zeta0_px, options.c_px).eop
                for i in range(int(img.max()) + 1)
            ]
        )
    ids = {} if inputs.image_ids is None else {"image_ids": inputs.image_ids}
    if inputs.point_ids is not None:
        ids["point_ids"] = inputs.point_ids
    p = make_parameters(eop, options.zeta0_px, options.c_px, [0.0, 0.0, 0.0], xy, control, **ids)
    res = calibrate(p, blk, stages=options.stages, reject_k=options.reject_k)
    return LineCalibration(res, inputs.image_ids, inputs.point_ids, res.residuals(blk.name))


def calibrate_files(
    observations,
    control,
    *,
    zeta0_px: float = 485.0,
    c_px: float = 3600.0,
    sigma_px: float = 0.1,
    reject_k: float | None = None,
) -> LineCalibration:
    """Calibrate one spectral line from a user's files (``hsgeo calibrate-line``): the file
    front end of :func:`calibrate_line`.

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
    LineCalibration

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
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
    LineObservations(img, pt, z, sigma_px)  # the NaN check, before the design checks
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
    cal = calibrate_line(
        LineInputs(img, pt, z, xy, image_ids, pid, initial_eop=np.array(eop)),
        LineOptions(zeta0_px=zeta0_px, c_px=c_px, sigma_px=sigma_px, reject_k=reject_k),
    )
    return cal
