"""Frame-camera self-calibration with the hsgeo engine, in OpenCV's and the photogrammetric form.

Initial values come from OpenCV (``cv2.initCameraMatrix2D`` for the focal length and
``cv2.solvePnP`` for each view's pose, both without distortion); from there the estimation is
hsgeo's own adjustment (:func:`hsgeo.adjust.adjust`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hsgeo.adjust import AdjustmentResult, Parameters, adjust
from hsgeo.errors import InputError, ObservationError
from hsgeo.rotations import R_from_opk, R_photogrammetric_from_opencv_cam, opk_from_R
from hsgeo.sensors.frame import (
    OPENCV_DISTORTION,
    OPENCV_INTRINSICS,
    PHOTOGRAMMETRIC_DISTORTION,
    PHOTOGRAMMETRIC_INTERIOR,
    POSE_COLUMNS,
    FrameOpenCV,
    FramePhotogrammetric,
    pixel_to_mm,
)
from hsgeo.workflows._initial import pose_from_pnp

__all__ = [
    "View",
    "FrameCalibration",
    "calibrate_opencv",
    "calibrate_photogrammetric",
    "initial_poses",
    "calibrate_frame_files",
    "Estimate",
    "FrameFilesResult",
    "MIN_VIEWS",
]


@dataclass(frozen=True)
class View:
    """The observations of one image: object points and their measured pixel coordinates.

    Attributes
    ----------
    X : (n, 3) ndarray
        Object (board) coordinates, any length unit.
    uv_px : (n, 2) ndarray
        Measured pixel coordinates (OpenCV convention).
    ids : (n,) ndarray, optional
        Point ids (board corner numbers), for reports.
    """

    X: np.ndarray
    uv_px: np.ndarray
    ids: np.ndarray | None = None


def _check_views(views: Sequence[View], image_size) -> list[View]:
    views = list(views)
    if len(views) < 2:
        raise ObservationError(
            f"self-calibration needs at least 2 views of the board (3 or more for all "
            f"intrinsics), got {len(views)}"
        )
    out = []
    for i, v in enumerate(views):
        X = np.asarray(v.X, dtype=np.float64)
        uv = np.asarray(v.uv_px, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != 3 or uv.shape != (X.shape[0], 2):
            raise InputError(
                f"view {i}: X must be (n, 3) and uv_px (n, 2); got {X.shape}, {uv.shape}"
            )
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(uv))):
            raise InputError(f"view {i}: NaN or inf in the object or image points")
        if X.shape[0] < 4:
            raise ObservationError(f"view {i} has {X.shape[0]} points; a pose needs at least 4")
        out.append(View(X, uv, v.ids))
    w, h = image_size
    if w <= 0 or h <= 0:
        raise InputError(f"image_size must be positive (width, height), got {image_size}")
    return out


def initial_poses(views: Sequence[View], K: np.ndarray) -> np.ndarray:
    """Per-view pose from ``cv2.solvePnP`` (:func:`hsgeo.workflows._initial.pose_from_pnp`).

    Returns
    -------
    (n_views, 6) ndarray of ``(ω, φ, κ, X0, Y0, Z0)`` for the OpenCV camera frame.
    """
    return np.array(
        [
            pose_from_pnp(v.X, v.uv_px, K, frame="opencv", what=f"view {i}")
            for i, v in enumerate(views)
        ]
    )


def _initial_K(views, image_size) -> np.ndarray:
    import cv2

    obj = [v.X.astype(np.float32) for v in views]
    img = [v.uv_px.astype(np.float32) for v in views]
    if not all(np.allclose(v.X[:, 2], 0) for v in views):
        raise InputError("initialisation needs planar boards with Z = 0 in board coordinates")
    K = cv2.initCameraMatrix2D(obj, img, tuple(int(s) for s in image_size), 1.0)
    return np.asarray(K, dtype=np.float64)


@dataclass
class FrameCalibration:
    """A calibrated frame camera and its adjustment.

    Attributes
    ----------
    form : {"opencv", "photogrammetric"}
    result : AdjustmentResult
    image_size : (int, int)
    views : list of View
    pixel_pitch_mm : float or None
    """

    form: str
    result: AdjustmentResult
    image_size: tuple[int, int]
    views: list[View]
    pixel_pitch_mm: float | None = None
    _blocks: tuple[str, str] = field(default=("intrinsics", "distortion"), repr=False)

    @property
    def residuals_px(self) -> np.ndarray:
        """(n, 2) reprojection residuals (model − observed) in px (mm forms converted)."""
        r = self.result.residuals(0).reshape(-1, 2)
        if self.form == "photogrammetric":
            r = r / self.pixel_pitch_mm * np.array([1.0, -1.0])
        return r

    @property
    def rms_px(self) -> float:
        """sqrt(mean ‖e‖²) over all points: OpenCV's "RMS re-projection error"."""
        r = self.residuals_px
        return float(np.sqrt(np.mean(np.sum(r**2, axis=1))))

    def values(self) -> dict[str, float]:
        """Interior orientation and distortion by name."""
        out = {}
        for blk in self._blocks:
            b = self.result.params[blk]
            out.update(dict(zip(b.columns, b.value.ravel().tolist(), strict=True)))
        return out

    def sigmas(self) -> dict[str, float]:
        """A-posteriori σ by name (NaN where fixed)."""
        out = {}
        for blk in self._blocks:
            b = self.result.params[blk]
            out.update(dict(zip(b.columns, self.result.sigma(blk).ravel().tolist(), strict=True)))
        return out

    def to_dict(self) -> dict:
        """Plain types: form, image size, σ0, RMS residual (px), values and σ̂ by name (None
        where fixed).
        """
        return {
            "form": self.form,
            "image_size": list(self.image_size),
            "sigma0": float(self.result.sigma0),
            "rms_px": self.rms_px,
            "values": self.values(),
            "sigmas": {k: (v if v == v else None) for k, v in self.sigmas().items()},
        }


def _stack(views):
    view = np.concatenate([np.full(v.X.shape[0], i) for i, v in enumerate(views)])
    X = np.concatenate([v.X for v in views])
    uv = np.concatenate([v.uv_px for v in views])
    return view, X, uv


def calibrate_opencv(
    views: Sequence[View],
    image_size: tuple[int, int],
    *,
    fix_principal_point: bool = False,
    square_pixels: bool = False,
    zero_tangent: bool = False,
    fix_k3: bool = False,
    sigma_px: float = 1.0,
    reject_k: float | None = None,
    progress=None,
) -> FrameCalibration:
    """Self-calibrate a frame camera in OpenCV's form with hsgeo's engine.

    The flags mirror ``cv2.calibrateCamera``'s ``CALIB_FIX_PRINCIPAL_POINT`` (at the image
    centre), ``CALIB_FIX_ASPECT_RATIO`` (with aspect 1), ``CALIB_ZERO_TANGENT_DIST`` and
    ``CALIB_FIX_K3``.

    Parameters
    ----------
    views : sequence of View
    image_size : (width_px, height_px)
    sigma_px : float
        A-priori σ of an image coordinate; σ0 then says how well it was guessed.

    Returns
    -------
    FrameCalibration
    """
    views = _check_views(views, image_size)
    K = _initial_K(views, image_size)
    w, h = image_size
    cx, cy = ((w - 1) / 2, (h - 1) / 2) if fix_principal_point else (K[0, 2], K[1, 2])
    f0 = float(np.sqrt(K[0, 0] * K[1, 1]))
    K = np.array([[f0, 0, cx], [0, f0, cy], [0, 0, 1.0]])
    p = Parameters()
    p.add("intrinsics", [f0, f0, cx, cy], columns=OPENCV_INTRINSICS)
    p.add("distortion", np.zeros(5), columns=OPENCV_DISTORTION)
    p.add("poses", initial_poses(views, K), columns=POSE_COLUMNS)
    if fix_principal_point:
        p.fix("intrinsics", index=[2, 3])
    if square_pixels:  # fy = fx: one unknown
        p.tie("intrinsics", index=1, to=("intrinsics", 0))
    if zero_tangent:
        p.fix("distortion", index=[2, 3])
    if fix_k3:
        p.fix("distortion", index=4)
    view, X, uv = _stack(views)
    blk = FrameOpenCV(view, uv, sigma_px, X=X)
    res = adjust(p, blk, reject_k=reject_k, progress=progress)
    return FrameCalibration("opencv", res, (int(w), int(h)), views)


def calibrate_photogrammetric(
    views: Sequence[View],
    image_size: tuple[int, int],
    pixel_pitch_mm: float,
    *,
    fix_principal_point: bool = False,
    zero_decentering: bool = False,
    fix_K3: bool = False,
    sigma_px: float = 1.0,
    reject_k: float | None = None,
    progress=None,
) -> FrameCalibration:
    """Self-calibrate a frame camera in the photogrammetric form.

    Millimetre image coordinates, corrections at the measured coordinates; see
    :class:`hsgeo.sensors.frame.FramePhotogrammetric`.

    Parameters
    ----------
    pixel_pitch_mm : float
        Pixel size; square pixels are assumed (the mm image frame is isotropic).
    fix_principal_point : bool
        Hold (x0, y0) at the image centre.
    zero_decentering : bool
        Hold P1 = P2 = 0.
    """
    views = _check_views(views, image_size)
    if not pixel_pitch_mm > 0:
        raise InputError(f"pixel_pitch_mm must be positive, got {pixel_pitch_mm}")
    K = _initial_K(views, image_size)
    w, h = image_size
    f0 = float(np.sqrt(K[0, 0] * K[1, 1]))
    K = np.array([[f0, 0, (w - 1) / 2], [0, f0, (h - 1) / 2], [0, 0, 1.0]])
    poses = initial_poses(views, K)
    # OpenCV camera frame -> photogrammetric camera frame
    R = R_from_opk(poses[:, 0], poses[:, 1], poses[:, 2]) @ R_photogrammetric_from_opencv_cam().T
    poses[:, :3] = opk_from_R(R)
    p = Parameters()
    p.add("interior", [f0 * pixel_pitch_mm, 0.0, 0.0], columns=PHOTOGRAMMETRIC_INTERIOR)
    p.add("distortion_mm", np.zeros(5), columns=PHOTOGRAMMETRIC_DISTORTION)
    p.add("poses", poses, columns=POSE_COLUMNS)
    if fix_principal_point:
        p.fix("interior", index=[1, 2])
    if zero_decentering:
        p.fix("distortion_mm", index=[3, 4])
    if fix_K3:
        p.fix("distortion_mm", index=2)
    view, X, uv = _stack(views)
    blk = FramePhotogrammetric(
        view, pixel_to_mm(uv, image_size, pixel_pitch_mm), sigma_px * pixel_pitch_mm, X=X
    )
    res = adjust(p, blk, reject_k=reject_k, progress=progress)
    return FrameCalibration(
        "photogrammetric",
        res,
        (int(w), int(h)),
        views,
        pixel_pitch_mm,
        _blocks=("interior", "distortion_mm"),
    )


# ----------------------------------------------------------------------------------------------
# ``hsgeo calibrate-frame``: a board in image files, per band or jointly (moved from rikola.py)
# ----------------------------------------------------------------------------------------------
#: Fewest views (images of the board) of a band for a self-calibration: a planar board gives
#: two constraints on the interior orientation per view (Zhang 2000, §3.1).
MIN_VIEWS = 3


def _check_images(images) -> list:
    """The image files exist, are files, and none is given twice (same path or same bytes)."""
    import hashlib

    from hsgeo.io._files import check_input_file

    images = [Path(p) for p in images]
    seen_path: dict = {}
    seen_hash: dict = {}
    for p in images:
        check_input_file(p, "image file")
        key = p.resolve()
        if key in seen_path:
            raise InputError(
                f"image file {str(p)!r} is given twice (as {str(seen_path[key])!r}); give each "
                "view once"
            )
        seen_path[key] = p
        h = hashlib.sha256(p.read_bytes()).hexdigest()
        if h in seen_hash:
            raise InputError(
                f"image files {str(seen_hash[h])!r} and {str(p)!r} are the same image (identical "
                "bytes); give each view once"
            )
        seen_hash[h] = p
    return images


def _check_regex(option: str, rx: str, images) -> None:
    """``rx`` compiles, has one group, and takes a whole number from every file name."""
    import re

    try:
        pat = re.compile(rx)
    except re.error as exc:
        raise InputError(f"{option} {rx!r} is not a regular expression ({exc})") from None
    if pat.groups != 1:
        raise InputError(
            f"{option} {rx!r} has {pat.groups} groups; it needs exactly one, e.g. 'band(\\d+)'"
        )
    for p in images:
        m = pat.search(p.name)
        if m is None or m.group(1) is None or not m.group(1).isdigit():
            raise InputError(
                f"{option} {rx!r} takes no number from the file name {p.name!r}; its group must "
                "match the digits of the band or cube number"
            )


@dataclass(frozen=True)
class Estimate:
    """One estimated parameter of ``hsgeo calibrate-frame``.

    Attributes
    ----------
    group : str
        ``"interior band N"`` (per band) or ``"joint model"``.
    name : str
        ``f``, ``x0``, ``y0``, ``K1``–``K3``, ``P1``, ``P2`` (per band) or the joint model's
        parameter label.
    unit : str
        ``mm`` (``mm``, ``1/mm2`` …) or, without ``camera.pixel_mm`` in the board file, ``px``.
    value, sigma : float
        The estimate and its a-posteriori σ̂.
    """

    group: str
    name: str
    unit: str
    value: float
    sigma: float


@dataclass(frozen=True)
class FrameFilesResult:
    """What ``hsgeo calibrate-frame`` found: the estimates and a summary.

    Attributes
    ----------
    estimates : tuple of Estimate
    meta : dict
        ``images``, ``points``, ``length_unit``, ``board``; per band (``"band N"``) σ0, the
        number of points, the RMS residual (px) and of views, or for the joint model σ0 and
        ``rms_px``.
    """

    estimates: tuple[Estimate, ...]
    meta: dict

    def table(self):
        """The estimates as a pandas DataFrame (group, name, unit, value, sigma)."""
        import pandas as pd

        return pd.DataFrame(
            [vars(e) for e in self.estimates], columns=["group", "name", "unit", "value", "sigma"]
        )

    def to_dict(self) -> dict:
        """Plain types: ``{"estimates": [{group, name, unit, value, sigma}, ...], "meta": ...}``."""
        return {
            "estimates": [
                {**vars(e), "value": float(e.value), "sigma": float(e.sigma)}
                for e in self.estimates
            ],
            "meta": self.meta,
        }


def _px_power(name: str) -> int:
    """Power of the pixel pitch that turns a per-band estimate in mm units into px units:
    lengths /p, K_i ·p^(2i), P ·p.
    """
    return {"f": -1, "x0": -1, "y0": -1, "K1": 2, "K2": 4, "K3": 6, "P1": 1, "P2": 1}[name]


def _joint_estimates(obs, sigma_px: float) -> tuple[list[Estimate], dict]:
    from hsgeo.workflows.rikola_bands import initial_focal_mm
    from hsgeo.workflows.rikola_joint import calibrate_joint

    j = calibrate_joint(obs, f0_mm=initial_focal_mm(obs), sigma_px=sigma_px)
    R = j.result
    est = []
    for blk in ("gap_model", "pp_mm", "distortion_mm", "sensor2_rotation"):
        b = R.params[blk]
        for lab, v, s in zip(b.labels(), b.value.ravel(), R.sigma(blk).ravel(), strict=True):
            est.append(Estimate("joint model", lab, "", v, s))
    meta = {
        "sigma0": R.sigma0,
        "rms_px": float(np.sqrt(np.mean(np.sum(j.residuals_px**2, axis=1)))),
    }
    return est, meta


def _band_estimates(obs, band: int, sigma_px: float, unit: str) -> tuple[list[Estimate], dict]:
    from hsgeo.workflows.rikola_bands import calibrate_band

    c = calibrate_band(obs, band, f0_mm=None, sigma_px=sigma_px)
    est = []
    for q, (v, s) in c.iop.items():
        u = q.split("_", 1)[1].replace("per_", "1/") if "_" in q else ""
        name = q.split("_")[0]
        if unit == "px":  # nominal pitch -> px
            v, s = v * obs.pixel_mm ** _px_power(name), s * obs.pixel_mm ** _px_power(name)
        est.append(Estimate(f"interior band {band}", name, u.replace("mm", unit), v, s))
    meta = {
        "sigma0": c.result.sigma0,
        "points": int(np.sum(obs.band == band)),
        "rms_px": float(np.sqrt(np.mean(np.sum(c.residuals_px**2, 1)))),
        "views": int(len(c.cubes)),
    }
    return est, meta


def calibrate_frame_files(
    images,
    board_path,
    *,
    joint: bool = False,
    band_regex=None,
    cube_regex=None,
    sigma_px: float = 0.1,
) -> FrameFilesResult:
    """``hsgeo calibrate-frame``: detect a board in image files and self-calibrate, per band
    (:func:`hsgeo.workflows.rikola_bands.calibrate_band`) or jointly
    (:func:`hsgeo.workflows.rikola_joint.calibrate_joint`, Rikola band numbering).

    Returns
    -------
    FrameFilesResult
        Estimates ``interior band N`` (f, x0, y0, K1–K3, P1, P2 with σ̂, in mm or — without
        ``camera.pixel_mm`` in the board file — px) or ``joint model``; ``meta`` has σ0, the
        RMS residual and the number of points per band. :func:`hsgeo.report.from_estimates`
        turns it into report rows.
    """
    from hsgeo.io import read_board
    from hsgeo.measure.boards import observe_files

    board = read_board(board_path)
    images = _check_images(images)
    for option, rx in (("--band-regex", band_regex), ("--cube-regex", cube_regex)):
        if rx is not None:
            _check_regex(option, rx, images)
    if joint and (band_regex is None or cube_regex is None):
        raise InputError(
            "--joint needs --band-regex and --cube-regex (which band and cube each file is)"
        )
    obs = observe_files(images, board, band_regex=band_regex, cube_regex=cube_regex)
    for band in np.unique(obs.band):
        views = np.unique(obs.cube[obs.band == band]).size
        if views < MIN_VIEWS:
            raise InputError(
                f"band {band} has {views} image(s) of the board; a self-calibration needs at "
                f"least {MIN_VIEWS} views from different directions (Zhang 2000): add images"
            )
    unit = "mm" if board.pixel_mm is not None else "px"
    meta = {
        "images": len(list(images)),
        "points": int(len(obs.cube)),
        "length_unit": unit,
        "board": board.type,
    }
    if joint:
        est, m = _joint_estimates(obs, sigma_px)
        meta.update(m)
        return FrameFilesResult(tuple(est), meta)
    est = []
    for band in np.unique(obs.band):
        e, meta[f"band {band}"] = _band_estimates(obs, int(band), sigma_px, unit)
        est += e
    return FrameFilesResult(tuple(est), meta)
