"""The Rikola FPI camera (003), band by band: targets from pixels and one camera per band.

1. :func:`detect_targets_in_images` detects the ArUco targets (:mod:`hsgeo.measure.aruco`) and
   keeps each target's four corners and their centroid (003 §3.2);
2. :func:`calibrate_band` — self-calibrating bundle adjustment of one band, with the plate's
   known target coordinates as the datum (003 §3.3, Table 3);
3. :func:`gap_regression` — ``f = a·gap + b`` from the per-band focal lengths (003 eq. (2),
   Table 4 second).

The joint model is :mod:`hsgeo.workflows.rikola_joint`, the relative orientation and the whole
calibration of a Rikola :mod:`hsgeo.workflows.rikola`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.adjust import AdjustmentResult, Parameters, adjust
from hsgeo.errors import InputError, ObservationError
from hsgeo.io import read_band_split
from hsgeo.measure.targets import Observations
from hsgeo.sensors.frame import (
    PHOTOGRAMMETRIC_DISTORTION,
    PHOTOGRAMMETRIC_INTERIOR,
    POSE_COLUMNS,
)
from hsgeo.sensors.rikola import TargetCentroids, focal_from_gap_mm
from hsgeo.workflows._initial import pose_from_pnp

__all__ = [
    "BANDS",
    "detect_targets_in_images",
    "initial_poses",
    "initial_focal_mm",
    "BandCalibration",
    "band_problem",
    "calibrate_band",
    "gap_regression",
]

#: The Rikola FPI2015's band split (band, sensor, FPI air gap), an instrument description read
#: by :func:`hsgeo.io.read_band_split` (``hsgeo/data/instruments/rikola_fpi2015.toml``).
BANDS = read_band_split()
BANDS.setflags(write=False)


def detect_targets_in_images(
    images,
    corners_obj,
    target_ids,
    image_size,
    pixel_mm: float,
    *,
    dictionary: str = "DICT_4X4_100",
    refine: str = "subpix",
    compare_refine: str | None = None,
):
    """Detect the ArUco targets of a plate in a sequence of images (003 §3.2).

    Each target keeps its four corners and their centroid (the virtual point of 003 §3.2).

    Parameters
    ----------
    images : iterable of ((cube, band), image)
        The images in the order they are to be measured; ``image`` is ``(rows, cols)``, any
        dtype (:func:`hsgeo.measure.aruco.to_uint8` scales it). A generator keeps only one image
        in memory at a time.
    corners_obj : (n_targets, 4, 3) ndarray
        Object coordinates of each target's corners, indexed by target id.
    target_ids : (k,) int array_like
        The ids on the plate (detections of other ids are dropped).
    image_size : (int, int)
        Width and height in pixels.
    pixel_mm : float
        Pixel pitch.
    dictionary, refine : str
        ArUco dictionary and corner refinement (:func:`hsgeo.measure.aruco.make_detector`).
    compare_refine : str, optional
        A second refinement run on the same images (for the corner-bias comparison of §3.2).

    Returns
    -------
    Observations, and Observations or None (``compare_refine``)

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    from hsgeo.measure.aruco import detect_targets, make_detector, to_uint8

    dets = [make_detector(dictionary, refine=refine)]
    if compare_refine is not None:
        dets.append(make_detector(dictionary, refine=compare_refine))
    size = (int(image_size[0]), int(image_size[1]))
    rows = [{k: [] for k in ("cube", "band", "target", "corners")} for _ in dets]
    for (c, b), img in images:
        img8 = to_uint8(img)
        for det, rw in zip(dets, rows, strict=True):
            d = detect_targets(img8, det, valid_ids=target_ids)
            rw["cube"].append(np.full(len(d), c))
            rw["band"].append(np.full(len(d), b))
            rw["target"].append(d.ids)
            rw["corners"].append(d.corners_px)
    out = []
    for rw in rows:
        target = np.concatenate(rw["target"]).astype(np.int64)
        out.append(
            Observations(
                np.concatenate(rw["cube"]).astype(np.int64),
                np.concatenate(rw["band"]).astype(np.int64),
                target,
                np.concatenate(rw["corners"]),
                corners_obj[target],
                size,
                float(pixel_mm),
            )
        )
    return out[0], (out[1] if len(out) > 1 else None)


def initial_poses(obs: Observations, f_mm: float) -> dict[int, np.ndarray]:
    """Photogrammetric pose of each cube from ``cv2.solvePnP`` on the centroids (no distortion,
    principal point at the centre), for the initial values of an adjustment.
    """
    w, h = obs.image_size
    fpx = f_mm / obs.pixel_mm
    K = np.array([[fpx, 0, (w - 1) / 2], [0, fpx, (h - 1) / 2], [0, 0, 1.0]])
    out = {}
    for c in np.unique(obs.cube):
        m = obs.cube == c
        if m.sum() < 4:
            raise ObservationError(f"cube {c}: {m.sum()} targets; a pose needs at least 4")
        out[int(c)] = pose_from_pnp(
            obs.corners_obj[m].mean(axis=1),
            obs.centroids_px[m],
            K,
            frame="photogrammetric",
            what=f"cube {c}",
        )
    return out


def initial_focal_mm(obs: Observations) -> float:
    """Focal length from ``cv2.initCameraMatrix2D`` on the views of a planar board (Z = 0)."""
    import cv2

    views = np.unique(obs.cube)
    X = obs.corners_obj.mean(axis=1)
    if not np.allclose(X[:, 2], 0.0):
        raise InputError("initialisation needs a planar board with Z = 0 in board coordinates")
    objs = [X[obs.cube == c].astype(np.float32) for c in views]
    imgs = [obs.centroids_px[obs.cube == c].astype(np.float32) for c in views]
    K = cv2.initCameraMatrix2D(objs, imgs, tuple(int(s) for s in obs.image_size), 1.0)
    return float(np.sqrt(K[0, 0] * K[1, 1])) * obs.pixel_mm


@dataclass
class BandCalibration:
    """Self-calibration of one band (003 §3.3): ``result`` holds interior, distortion_mm and
    poses (one per cube, rows in ``cubes`` order).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """

    band: int
    cubes: np.ndarray
    result: AdjustmentResult
    block: TargetCentroids

    def value(self, name):
        return self.result.value(name)

    def sigma(self, name):
        return self.result.sigma(name)

    @property
    def iop(self) -> dict[str, tuple[float, float]]:
        """Table-3 style: name -> (value, σ̂)."""
        out = {}
        for blk, cols in (
            ("interior", PHOTOGRAMMETRIC_INTERIOR),
            ("distortion_mm", PHOTOGRAMMETRIC_DISTORTION),
        ):
            v, s = self.result.value(blk), self.result.sigma(blk)
            out.update({c: (float(v[i]), float(s[i])) for i, c in enumerate(cols)})
        return out

    def pose(self, cube: int) -> np.ndarray:
        return self.result.value("poses")[int(np.flatnonzero(self.cubes == cube)[0])]

    def pose_covariance(self, cube: int) -> np.ndarray:
        """(6, 6) covariance of a cube's pose."""
        cov, labels = self.result.covariance_of("poses")
        i = int(np.flatnonzero(self.cubes == cube)[0])
        return cov[6 * i : 6 * i + 6, 6 * i : 6 * i + 6]

    @property
    def residuals_px(self) -> np.ndarray:
        return self.result.residuals(0).reshape(-1, 2) / self.block_pixel_mm * [1.0, -1.0]

    block_pixel_mm: float  # the observations' pixel pitch, mm (no default: the user's camera)


def band_problem(obs: Observations, band: int, f0_mm: float, sigma_px: float):
    """Parameters and residual block of one band's self-calibration (003 §3.3).

    Returns
    -------
    params : Parameters
    block : TargetCentroids
    cubes : (k,) int ndarray
        The cubes (views) of the band, in the order of the ``poses`` block.

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    sel = obs.band == band
    if sel.sum() < 10:
        raise ObservationError(f"band {band}: only {sel.sum()} targets observed; need more cubes")
    o = obs.select(sel)
    cubes = np.unique(o.cube)
    view = np.searchsorted(cubes, o.cube)
    poses = initial_poses(o, f0_mm)
    p = Parameters()
    p.add("interior", [f0_mm, 0.0, 0.0], columns=PHOTOGRAMMETRIC_INTERIOR)
    p.add("distortion_mm", np.zeros(5), columns=PHOTOGRAMMETRIC_DISTORTION)
    p.add(
        "poses",
        np.array([poses[int(c)] for c in cubes]),
        columns=POSE_COLUMNS,
        rows=[f"cube {c}" for c in cubes],
    )
    blk = TargetCentroids(view, o.corners_obj, o.centroids_mm, sigma_px * obs.pixel_mm)
    return p, blk, cubes


def calibrate_band(
    obs: Observations,
    band: int,
    *,
    f0_mm: float | None = 9.0,
    sigma_px: float = 0.02,
    reject_k: float | None = 5.0,
) -> BandCalibration:
    """Self-calibrating bundle adjustment of one band (003 §3.3: each band a camera).

    The datum is the plate: the target coordinates are known (fixed), as on the paper's bench
    where the distances between the targets were known (003 §3.2); the initial values are the
    nominal focal length (003 Table 1; ``f0_mm=None``: from ``cv2.initCameraMatrix2D``), the image
    centre, zero distortion and ``solvePnP`` poses.

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    if f0_mm is None:
        f0_mm = initial_focal_mm(obs.select(obs.band == band))
    p, blk, cubes = band_problem(obs, band, f0_mm, sigma_px)
    res = adjust(p, blk, reject_k=reject_k)
    return BandCalibration(band, cubes, res, blk, block_pixel_mm=obs.pixel_mm)


def gap_regression(gap_nm, f_mm) -> dict[str, float]:
    """Straight line ``f = a·gap + b`` by ordinary least squares (003 eq. (2), Table 4 second).

    Returns
    -------
    dict with ``a``, ``b``, ``sigma_a``, ``sigma_b`` (from the residual scatter), ``r2`` (0–1)
    and ``s`` (residual standard deviation).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    g = np.asarray(gap_nm, float)
    f = np.asarray(f_mm, float)
    if g.shape != f.shape or g.size < 3:
        raise InputError("gap_regression needs at least 3 (gap, f) pairs of equal length")
    A = np.column_stack([g, np.ones_like(g)])
    coef, *_ = np.linalg.lstsq(A, f, rcond=None)
    res = f - focal_from_gap_mm(g, coef[0], coef[1])  # 003 eq. (2)
    dof = g.size - 2
    s2 = float(res @ res / dof)
    cov = s2 * np.linalg.inv(A.T @ A)
    r2 = 1.0 - float(res @ res) / float(np.sum((f - f.mean()) ** 2))
    return {
        "a": float(coef[0]),
        "b": float(coef[1]),
        "sigma_a": float(np.sqrt(cov[0, 0])),
        "sigma_b": float(np.sqrt(cov[1, 1])),
        "r2": r2,
        "s": float(np.sqrt(s2)),
    }
