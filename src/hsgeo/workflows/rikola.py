"""The Rikola FPI camera (003): observations from pixels, per-band self-calibration, sensor
misalignment, the gap model, and the joint model the paper leaves as future work.

The road of the chapter ``rikola``:

1. :func:`observe` renders every band of every cube (:mod:`hsgeo.simulate.rikola`), detects the
   ArUco targets (:mod:`hsgeo.measure.aruco`) and keeps each target's four corners and their
   centroid (003 §3.2);
2. :func:`calibrate_band` — self-calibrating bundle adjustment of one band, with the plate's
   known target coordinates as the datum (003 §3.3, Table 3);
3. :func:`relative_orientation` — ``R = R_S1 R_S2⁻¹`` for pairs of bands from different sensors
   (003 eq. (1), Table 4 first); :func:`gap_regression` — ``f = a·gap + b`` (003 eq. (2), Table 4
   second);
4. :func:`calibrate_joint` — one adjustment of all bands: one exterior orientation per cube,
   ``f = a·gap + b`` per sensor, one distortion set, sensor II's rotation and offset;
   :func:`predict_band` predicts a held-out band.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.adjust import AdjustmentResult, Parameters, adjust
from hsgeo.distortion import ideal_from_measured_mm
from hsgeo.errors import InputError, ObservationError
from hsgeo.io import read_band_split
from hsgeo.measure.targets import Observations
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.sensors.frame import (
    PHOTOGRAMMETRIC_DISTORTION,
    PHOTOGRAMMETRIC_INTERIOR,
    POSE_COLUMNS,
    mm_to_pixel,
)
from hsgeo.sensors.rikola import (
    GAP_MODEL_COLUMNS,
    OFFSET_COLUMNS,
    ROTATION_COLUMNS,
    JointCentroids,
    TargetCentroids,
    project_measured_mm,
)
from hsgeo.workflows._initial import pose_from_pnp

__all__ = [
    "Observations",
    "detect_targets_in_images",
    "initial_poses",
    "BandCalibration",
    "calibrate_band",
    "band_problem",
    "initial_focal_mm",
    "relative_orientation",
    "gap_regression",
    "JointCalibration",
    "calibrate_joint",
    "design_effect",
    "predict_band",
    "predict_per_band",
    "mean_relative_orientation",
    "rop_mean_covariance",
    "rop_transformation_test",
    "cluster_keys",
]

#: The Rikola FPI2015's band split (band, sensor, FPI air gap), an instrument description read
#: by :func:`hsgeo.io.read_band_split` (``hsgeo/data/instruments/rikola_fpi2015.toml``).
BANDS = read_band_split()


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

    block_pixel_mm: float = 0.0055


def band_problem(obs: Observations, band: int, f0_mm: float, sigma_px: float):
    """Parameters and residual block of one band's self-calibration (003 §3.3).

    Returns
    -------
    params : Parameters
    block : TargetCentroids
    cubes : (k,) int ndarray
        The cubes (views) of the band, in the order of the ``poses`` block.
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
    """
    if f0_mm is None:
        f0_mm = initial_focal_mm(obs.select(obs.band == band))
    p, blk, cubes = band_problem(obs, band, f0_mm, sigma_px)
    res = adjust(p, blk, reject_k=reject_k)
    return BandCalibration(band, cubes, res, blk, block_pixel_mm=obs.pixel_mm)


def relative_orientation(pose_1, pose_2, cov_1=None, cov_2=None, step: float = 1e-7):
    """Relative orientation between the sensors, 003 eq. (1): ``R = R_S1 R_S2⁻¹``.

    ``R_S`` is the rotation of each sensor's image (``R_cam_from_world``, the transpose of
    hsgeo's ``R_world_from_cam``), so that ``R = R_camI_from_camII`` — the ``R_I_from_II`` of the
    simulation and of the joint model.

    Parameters
    ----------
    pose_1, pose_2 : (6,) ndarray
        Exterior orientations (ω, φ, κ, ...) of a sensor-I band and a sensor-II band of one cube.
    cov_1, cov_2 : (6, 6) ndarray, optional
        Their covariances (independent adjustments), propagated to the angles.

    Returns
    -------
    opk_rad : (3,) ndarray
    cov : (3, 3) ndarray or None
    """

    def f(a1, a2):
        R = R_from_opk(*a1).T @ R_from_opk(*a2)
        return opk_from_R(R)

    a1, a2 = np.asarray(pose_1[:3], float), np.asarray(pose_2[:3], float)
    ang = f(a1, a2)
    if cov_1 is None or cov_2 is None:
        return ang, None
    J = np.zeros((3, 6))
    for i in range(6):
        d = np.zeros(6)
        d[i] = step
        J[:, i] = (f(a1 + d[:3], a2 + d[3:]) - f(a1 - d[:3], a2 - d[3:])) / (2 * step)
    C = np.zeros((6, 6))
    C[:3, :3] = np.asarray(cov_1)[:3, :3]
    C[3:, 3:] = np.asarray(cov_2)[:3, :3]
    return ang, J @ C @ J.T


def gap_regression(gap_nm, f_mm) -> dict[str, float]:
    """Straight line ``f = a·gap + b`` by ordinary least squares (003 eq. (2), Table 4 second).

    Returns
    -------
    dict with ``a``, ``b``, ``sigma_a``, ``sigma_b`` (from the residual scatter), ``r2`` (0–1)
    and ``s`` (residual standard deviation).
    """
    g = np.asarray(gap_nm, float)
    f = np.asarray(f_mm, float)
    if g.shape != f.shape or g.size < 3:
        raise InputError("gap_regression needs at least 3 (gap, f) pairs of equal length")
    A = np.column_stack([g, np.ones_like(g)])
    coef, *_ = np.linalg.lstsq(A, f, rcond=None)
    res = f - A @ coef
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


def design_effect(residuals_px, cluster) -> dict[str, float]:
    """Intra-cluster correlation of residuals and the design effect of a cluster mean.

    The centroid of one target in one cube has an error part that every band of a sensor
    shares (the corner detector's response to the target's perspective and pixel phase), on
    top of the independent noise of each band. One-way analysis of variance of the residuals
    grouped by ``cluster`` gives the within-cluster σ, the between-cluster σ and
    ``rho = σ_b² / (σ_b² + σ_w²)``; a parameter estimated from clusters of ``m`` correlated
    observations has its variance multiplied by ``deff = 1 + (m − 1)·rho`` (Kish's design
    effect) — the factor the joint model's covariance, which assumes independent observations,
    is scaled by.

    Parameters
    ----------
    residuals_px : (n, 2) ndarray
    cluster : (n,) int ndarray

    Returns
    -------
    dict with ``sigma_within_px``, ``sigma_between_px``, ``rho``, ``m`` and ``deff`` (means of
    the two coordinates).
    """
    r = np.asarray(residuals_px, float)
    u, inv, cnt = np.unique(np.asarray(cluster), return_inverse=True, return_counts=True)
    if u.size < 2 or u.size == r.shape[0]:
        return {
            "sigma_within_px": float("nan"),
            "sigma_between_px": 0.0,
            "rho": 0.0,
            "m": 1.0,
            "deff": 1.0,
        }
    m = float(cnt.mean())
    out = []
    for k in range(r.shape[1]):
        x = r[:, k]
        means = np.bincount(inv, x) / cnt
        s2w = float(np.sum((x - means[inv]) ** 2) / (x.size - u.size))
        s2b = max(float(np.var(means)) - s2w / m, 0.0)
        out.append((s2w, s2b))
    s2w, s2b = np.mean(out, axis=0)
    rho = s2b / (s2b + s2w)
    return {
        "sigma_within_px": float(np.sqrt(s2w)),
        "sigma_between_px": float(np.sqrt(s2b)),
        "rho": float(rho),
        "m": m,
        "deff": float(1.0 + (m - 1.0) * rho),
    }


@dataclass
class JointCalibration:
    """The joint model's adjustment and its bookkeeping.

    ``sigma(name)`` is the adjustment's σ̂ scaled by the square root of the design effect of the
    target clusters (:func:`design_effect`); ``result.sigma(name)`` is the unscaled one.
    """

    result: AdjustmentResult
    block: JointCentroids
    cubes: np.ndarray
    bands: np.ndarray  # band numbers in the model (the held-out one excluded)
    pixel_mm: float
    clusters: dict = field(default_factory=dict)

    @property
    def residuals_px(self) -> np.ndarray:
        return self.result.residuals(0).reshape(-1, 2) / self.pixel_mm * [1.0, -1.0]

    def value(self, name):
        return self.result.value(name)

    def sigma(self, name):
        return self.result.sigma(name) * np.sqrt(self.clusters.get("deff", 1.0))


_OFF_LINE = (1, 11)  # bands whose gaps are off the linear trend (003 §3.5)


def calibrate_joint(
    obs: Observations,
    *,
    exclude_bands=(),
    scatter_mm=(0.0035, 0.0028),
    f0_mm: float = 9.0,
    sigma_px: float = 0.02,
    estimate_offset: bool = False,
    reject_k: float | None = 5.0,
    init=None,
) -> JointCalibration:
    """One adjustment of all bands (003 §3.5, the paper's future work).

    Parameters
    ----------
    obs : Observations
    exclude_bands : sequence of int
        Bands left out (to predict them afterwards with :func:`predict_band`).
    scatter_mm : (2,) floats
        Prior σ of the per-band deviation ``df`` from the gap line (sensor I, II); bands 1 and 11,
        off the line (003 §3.5), get a free ``df`` without prior.
    estimate_offset : bool
        Estimate sensor II's projection-centre offset; by default it is held at zero: both
        sensors sit behind one lens and the beam splitter (003 Fig. 1b), so they share the
        projection centre, and a free offset is sensitive to centroid systematics of
        thousandths of a pixel (its σ̂ is millimetres).
    init : BandCalibration dict, optional
        Per-band calibrations to start from (poses of a sensor-I band, mean distortion).
    """
    keep = ~np.isin(obs.band, np.asarray(exclude_bands, int))
    o = obs.select(keep)
    bands = np.unique(o.band)
    cubes = np.unique(o.cube)
    table = BANDS
    brow = np.searchsorted(table["band"], o.band)
    for s in (1, 2):
        on = [b for b in bands if table["sensor"][b - 1] == s and b not in _OFF_LINE]
        if len(on) < 2:
            raise ObservationError(
                f"the joint model needs at least 2 on-line bands of sensor "
                f"{'I' if s == 1 else 'II'}, got {on}"
            )
    s1 = o.band >= 11
    poses0 = initial_poses(o.select(s1), f0_mm)
    p = Parameters()
    p.add(
        "poses",
        np.array([poses0[int(c)] for c in cubes]),
        columns=POSE_COLUMNS,
        rows=[f"cube {c}" for c in cubes],
    )
    p.add(
        "gap_model",
        [[0.0, f0_mm], [0.0, f0_mm]],
        columns=GAP_MODEL_COLUMNS,
        rows=["sensor I", "sensor II"],
    )
    sigma_df = np.array([scatter_mm[table["sensor"][i] - 1] for i in range(len(table))], float)
    present = np.isin(table["band"], bands)
    free_df = present.copy()
    sigma_df[np.isin(table["band"], _OFF_LINE)] = np.inf
    p.add(
        "df_mm",
        np.zeros(len(table)),
        free=free_df,
        prior_sigma=np.where(present, sigma_df, np.inf),
        rows=[f"band {b}" for b in table["band"]],
    )
    p.add("pp_mm", np.zeros((2, 2)), columns=("x0_mm", "y0_mm"), rows=["sensor I", "sensor II"])
    p.add("distortion_mm", np.zeros(5), columns=PHOTOGRAMMETRIC_DISTORTION)
    p.add("sensor2_rotation", np.zeros(3), columns=ROTATION_COLUMNS)
    p.add("sensor2_offset_mm", np.zeros(3), columns=OFFSET_COLUMNS)
    if not estimate_offset:
        p.fix("sensor2_offset_mm")
    if init is not None:
        _init_from_bands(p, init, cubes)
    blk = JointCentroids(
        np.searchsorted(cubes, o.cube),
        brow,
        o.corners_obj,
        o.centroids_mm,
        sigma_px * obs.pixel_mm,
        table["gap_nm"],
        table["sensor"],
    )
    res = adjust(p, blk, reject_k=reject_k)
    j = JointCalibration(res, blk, cubes, bands, obs.pixel_mm)
    ok = ~res.outliers(0)  # one entry per centroid
    key = (o.cube * 1_000_000 + o.target * 10 + table["sensor"][brow])[ok]
    j.clusters = design_effect(j.residuals_px[ok], key)
    return j


def _init_from_bands(p: Parameters, cals: dict, cubes) -> None:
    """Start the joint model from per-band results: a sensor-I band's poses, mean IOPs."""
    s1 = [b for b in cals if b >= 11]
    if s1:
        c = cals[s1[0]]
        p.set(
            "poses",
            np.array(
                [
                    c.pose(int(k)) if k in c.cubes else p.value("poses")[i]
                    for i, k in enumerate(cubes)
                ]
            ),
        )
    p.set("distortion_mm", np.mean([c.value("distortion_mm") for c in cals.values()], axis=0))
    for s, rng in ((0, range(11, 26)), (1, range(1, 11))):
        fs = [cals[b].value("interior") for b in rng if b in cals]
        if fs:
            fs = np.array(fs)
            p.set("pp_mm", fs[:, 1:].mean(axis=0), index=s)
            p.set("gap_model", [0.0, fs[:, 0].mean()], index=s)


def predict_band(joint: JointCalibration, obs: Observations, band: int) -> np.ndarray:
    """Predict the centroids of a band the joint model did not see: ``f = a·gap + b`` of its
    sensor (df = 0), the sensor's principal point, the shared distortion, the cube's pose and
    the sensor rotation. Returns the residuals (predicted − measured) in px, (n, 2), y down.
    """
    sel = (obs.band == band) & np.isin(obs.cube, joint.cubes)
    if not sel.any():
        raise ObservationError(f"no observations of band {band} in the joint model's cubes")
    o = obs.select(sel)
    table = BANDS
    blk = JointCentroids(
        np.searchsorted(joint.cubes, o.cube),
        np.searchsorted(table["band"], o.band),
        o.corners_obj,
        o.centroids_mm,
        1.0,
        table["gap_nm"],
        table["sensor"],
    )
    values = {k: v.copy() for k, v in joint.result.params.values().items()}
    values["df_mm"] = np.zeros_like(values["df_mm"])
    r = blk.evaluate(values, False)[0].reshape(-1, 2)
    return r / obs.pixel_mm * np.array([1.0, -1.0])


def track_targets(obs: Observations, cube: int, ref_band: int) -> dict[str, tuple[int, dict]]:
    """Five targets of one cube — nearest the four image corners and the centre in a reference
    band — and their centroids (px) in every band (003 §3.2, Fig. 3–4).

    Returns
    -------
    dict label (ULC, URC, BLC, BRC, IC) -> (target id, {band: (col, row)})
    """
    w, h = obs.image_size
    ref = obs.select((obs.cube == cube) & (obs.band == ref_band))
    if len(ref.cube) < 5:
        raise ObservationError(f"cube {cube}, band {ref_band}: fewer than 5 targets")
    spots = {
        "ULC": (0, 0),
        "URC": (w - 1, 0),
        "BLC": (0, h - 1),
        "BRC": (w - 1, h - 1),
        "IC": ((w - 1) / 2, (h - 1) / 2),
    }
    out = {}
    for lab, p in spots.items():
        t = int(ref.target[np.argmin(np.linalg.norm(ref.centroids_px - p, axis=1))])
        track = {}
        for b in np.unique(obs.band):
            m = (obs.cube == cube) & (obs.band == b) & (obs.target == t)
            if m.any():
                track[int(b)] = tuple(obs.centroids_px[m][0])
        out[lab] = (t, track)
    return out


def radial_effect_px(KP, r_mm, pixel_mm: float) -> np.ndarray:
    """Magnitude of the symmetric radial correction ``r (K1 r² + K2 r⁴ + K3 r⁶)`` in px: the
    radial part of Brown's correction (:func:`hsgeo.distortion.brown_correction`) at ``(r, 0)``.
    """
    from hsgeo.distortion import brown_correction

    r = np.asarray(r_mm, float)
    xy = np.stack([r, np.zeros_like(r)], axis=-1)
    return brown_correction(xy, np.asarray(KP, float)[:3], np.zeros(2))[..., 0] / pixel_mm


def decentering_effect_px(KP, xy_mm, pixel_mm: float) -> np.ndarray:
    """The decentering part ``(δx, δy)`` of Brown's correction at a point, in px (003 Fig. 9)."""
    from hsgeo.distortion import brown_correction

    KP = np.asarray(KP, float)
    return brown_correction(np.asarray(xy_mm, float), np.zeros(3), KP[3:]) / pixel_mm


def cluster_keys(obs, cal) -> np.ndarray:
    """(cube, target, sensor) key of each observation of a band's adjustment, in its order."""
    sel = obs.band == cal.band
    sensor = BANDS["sensor"][cal.band - 1]
    return obs.cube[sel] * 1_000_000 + obs.target[sel] * 10 + sensor


def rop_mean_covariance(cal1, cal2, cubes, step: float = 1e-7) -> np.ndarray:
    """Covariance (3, 3) of the ROP averaged over cubes, from the full pose covariances of the
    two bands' adjustments.
    """
    J1 = np.zeros((3, 6 * len(cal1.cubes)))
    J2 = np.zeros((3, 6 * len(cal2.cubes)))
    for c in cubes:
        p1, p2 = cal1.pose(c), cal2.pose(c)
        i1 = int(np.flatnonzero(cal1.cubes == c)[0])
        i2 = int(np.flatnonzero(cal2.cubes == c)[0])
        for a in range(3):
            d = np.zeros(6)
            d[a] = step
            J1[:, 6 * i1 + a] = (
                relative_orientation(p1 + d, p2)[0] - relative_orientation(p1 - d, p2)[0]
            ) / (2 * step)
            J2[:, 6 * i2 + a] = (
                relative_orientation(p1, p2 + d)[0] - relative_orientation(p1, p2 - d)[0]
            ) / (2 * step)
    C1, _ = cal1.result.covariance_of("poses")
    C2, _ = cal2.result.covariance_of("poses")
    return (J1 @ C1 @ J1.T + J2 @ C2 @ J2.T) / len(cubes) ** 2


def mean_relative_orientation(cals: dict, obs: Observations, cubes, pairs, *, rop_all=None) -> dict:
    """The mean relative orientation of sensor II to sensor I over band pairs and cubes, with σ̂
    (003 eq. (1), Table 4 first).

    003 uses the bands of one cube; the ROPs of one cube share that cube's systematic centroid
    errors (their spread understates the error), so every cube is used. σ̂ of the mean
    propagates each band's full pose covariance (the poses of all cubes of a band are correlated
    through the band's interior orientation; bands independent, :func:`rop_mean_covariance`),
    times the square root of the design effect of a mean over pairs whose centroid errors are
    partly common to all bands of a sensor (:func:`design_effect` of the per-band residuals
    grouped by cube, target and sensor, :func:`cluster_keys`).

    Parameters
    ----------
    cals : dict band -> BandCalibration
    obs : Observations
    cubes : sequence of int
    pairs : sequence of (band of sensor II, band of sensor I)
    rop_all : (n_pairs, n_cubes, 3) ndarray, optional
        The per-pair, per-cube ROPs if already computed.

    Returns
    -------
    dict with ``rop_all`` (n_pairs, n_cubes, 3) rad, ``rop_pairs`` (n_pairs, 3) rad (mean over
    cubes), ``rop_mean`` (3,) rad, ``rop_mean_sigma`` (3,) rad, ``band_clusters`` (the
    :func:`design_effect` summary) and ``deff_pairs``.
    """
    if rop_all is None:
        rop_all = np.array(
            [
                [relative_orientation(cals[k1].pose(c), cals[k2].pose(c))[0] for c in cubes]
                for k2, k1 in pairs
            ]
        )  # k2 sensor II, k1 sensor I
    rop = rop_all.mean(axis=1)  # per pair, mean over cubes
    rop_mean = rop.mean(axis=0)
    # σ̂ of the mean: the poses of all cubes of a band are correlated through the band's
    # interior orientation, so propagate each band's full pose covariance (bands independent)
    var = np.zeros(3)
    for k2, k1 in pairs:
        var += np.diag(rop_mean_covariance(cals[k1], cals[k2], cubes))
    rop_mean_sigma = np.sqrt(var) / len(pairs)
    # ... and the pairs share part of their error: a target's centroid error is partly common
    # to all bands of a sensor (design_effect); its intra-cluster correlation, from the
    # per-band residuals grouped by cube, target and sensor, gives the design effect of a mean
    # over the pairs
    res_pb = np.concatenate([c.residuals_px for c in cals.values()])
    keys = np.concatenate([cluster_keys(obs, c) for c in cals.values()])
    pb_clusters = design_effect(res_pb, keys)
    deff_pairs = 1.0 + (len(pairs) - 1) * pb_clusters["rho"]
    rop_mean_sigma = rop_mean_sigma * np.sqrt(deff_pairs)
    return {
        "rop_all": rop_all,
        "rop_pairs": rop,
        "rop_mean": rop_mean,
        "rop_mean_sigma": rop_mean_sigma,
        "band_clusters": pb_clusters,
        "deff_pairs": deff_pairs,
    }


def predict_per_band(cals, obs, band, bands):
    """The per-band route to a band without its own calibration (003 §3.5): f from the gap
    regression of the other bands of its sensor, the mean principal point of the sensor, the
    mean distortion, and per cube the mean exterior orientation of the sensor's other bands.
    """
    s = BANDS["sensor"][band - 1]
    others = [b for b in bands if b != band and BANDS["sensor"][b - 1] == s and b not in (1, 11)]
    reg = gap_regression(
        BANDS["gap_nm"][np.array(others) - 1], [cals[b].value("interior")[0] for b in others]
    )
    f = reg["a"] * BANDS["gap_nm"][band - 1] + reg["b"]
    pp = np.mean([cals[b].value("interior")[1:] for b in others], axis=0)
    KP = np.mean([cals[b].value("distortion_mm") for b in cals if b != band], axis=0)
    sel = obs.band == band
    o = obs.select(sel)
    cubes = np.unique(o.cube)
    poses = np.array([np.mean([cals[b].pose(c) for b in others], axis=0) for c in cubes])
    blk = TargetCentroids(np.searchsorted(cubes, o.cube), o.corners_obj, o.centroids_mm, 1.0)
    r = blk.evaluate({"interior": np.r_[f, pp], "distortion_mm": KP, "poses": poses}, False)[0]
    return r.reshape(-1, 2) / obs.pixel_mm * np.array([1.0, -1.0])


def rop_transformation_test(obs, cals, pairs, rop_mean, cube: int):
    """003 §3.4: mean discrepancy (px) between a target's centroid in a sensor-II band and in
    its sensor-I partner of the same cube ``cube``, before and after rotating the sensor-II
    image rays by the estimated mean ROP (with each band's own interior orientation).

    Returns
    -------
    dict with ``before_mean_px``, ``after_mean_px`` (x, y) and ``before_rms_px``, ``after_rms_px``.
    """
    M = R_from_opk(*rop_mean)
    before, after = [], []
    for k2, k1 in pairs:
        c1, c2 = cals[k1], cals[k2]
        m1 = (obs.band == k1) & (obs.cube == cube)
        m2 = (obs.band == k2) & (obs.cube == cube)
        common, i1, i2 = np.intersect1d(obs.target[m1], obs.target[m2], return_indices=True)
        x1 = obs.centroids_mm[m1][i1]
        x2 = obs.centroids_mm[m2][i2]
        f1, x01, y01 = c1.value("interior")
        f2, x02, y02 = c2.value("interior")
        K2 = c2.value("distortion_mm")
        K1 = c1.value("distortion_mm")
        ideal2 = ideal_from_measured_mm(x2 - [x02, y02], K2[:3], K2[3:])
        ray2 = np.column_stack([ideal2, np.full(len(ideal2), -f2)])
        ray1 = ray2 @ M.T  # X_camI = R_I_from_II X_camII
        x2_in_1 = project_measured_mm(ray1, f1, np.array([x01, y01]), K1)
        px = obs.pixel_mm
        before.append(mm_to_pixel(x2, obs.image_size, px) - mm_to_pixel(x1, obs.image_size, px))
        after.append(mm_to_pixel(x2_in_1, obs.image_size, px) - mm_to_pixel(x1, obs.image_size, px))
    b, a = np.concatenate(before), np.concatenate(after)
    return {
        "before_mean_px": b.mean(axis=0).tolist(),
        "after_mean_px": a.mean(axis=0).tolist(),
        "before_rms_px": float(np.sqrt(np.mean(np.sum(b**2, 1)))),
        "after_rms_px": float(np.sqrt(np.mean(np.sum(a**2, 1)))),
    }
