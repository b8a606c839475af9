"""Calibrating a Rikola FPI camera (003): the in-memory core and its file front end.

:func:`calibrate_rikola` takes the target observations of a bench (frozen :class:`RikolaOptions`)
and returns one :class:`RikolaResult` with tables and ``to_dict()``:

1. every band its own camera (:func:`hsgeo.workflows.rikola_bands.calibrate_band`, 003 §3.3);
2. the relative orientation of sensor II to sensor I from band pairs of the same cube
   (:func:`relative_orientation`, 003 eq. (1); :func:`mean_relative_orientation` over pairs and
   cubes with σ̂);
3. the gap line of each sensor from the per-band focal lengths
   (:func:`hsgeo.workflows.rikola_bands.gap_regression`, 003 eq. (2));
4. the joint model of all bands (:func:`hsgeo.workflows.rikola_joint.calibrate_joint`, the
   paper's future work), its prior on the per-band deviations from the gap lines' scatter.

:func:`calibrate_rikola_files` is the file front end (a board file and images). The analyses
that only compare with the paper (the tracks of 003 Fig. 3–4, the distortion effects of
Fig. 8–9, the transformation test of §3.4, the per-band route to a held-out band) are in
:mod:`hsgeo.reproduce.rikola_analyses`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.errors import InputError
from hsgeo.measure.targets import Observations
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.workflows.rikola_bands import (
    BANDS,
    calibrate_band,
    gap_regression,
    initial_focal_mm,
)
from hsgeo.workflows.rikola_joint import (
    OFF_LINE_BANDS,
    JointCalibration,
    calibrate_joint,
    design_effect,
)

__all__ = [
    "relative_orientation",
    "rop_per_cube",
    "rop_mean_covariance",
    "mean_relative_orientation",
    "cluster_keys",
    "paper_pairs",
    "RikolaOptions",
    "RikolaResult",
    "calibrate_rikola",
    "calibrate_rikola_files",
]


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

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
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


def rop_per_cube(cals: dict, cubes, pairs) -> np.ndarray:
    """003 eq. (1) for every pair and cube: ``(n_pairs, n_cubes, 3)`` rad, pairs given as
    (band of sensor II, band of sensor I).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    return np.array(
        [
            [relative_orientation(cals[k1].pose(c), cals[k2].pose(c))[0] for c in cubes]
            for k2, k1 in pairs
        ]
    )  # k2 sensor II, k1 sensor I


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

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    if rop_all is None:
        rop_all = rop_per_cube(cals, cubes, pairs)
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


def paper_pairs(bands) -> list[tuple[int, int]]:
    """The band pairs (k, k + 10) of 003 §3.4 — band k of sensor II, band k + 10 of sensor I —
    of which both bands are in ``bands``.

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    have = {int(b) for b in bands}
    return [(k, k + 10) for k in range(1, 11) if k in have and k + 10 in have]


@dataclass(frozen=True)
class RikolaOptions:
    """How :func:`calibrate_rikola` calibrates.

    Attributes
    ----------
    sigma_px : float
        A-priori σ of a centroid coordinate in a per-band adjustment, px.
    f0_mm : float or None
        Initial focal length (003 Table 1: 9 mm); None: from ``cv2.initCameraMatrix2D``.
    reject_k : float or None
        Outlier rejection threshold of the adjustments (in σ).
    pairs : tuple of (int, int), optional
        Band pairs (sensor II, sensor I) of the relative orientation; default :func:`paper_pairs`.
    joint : bool
        Also adjust the joint model.
    scatter_mm : (float, float), optional
        Prior σ of a band's deviation from the gap line (sensor I, II) in the joint model;
        default: the scatter of the per-band focal lengths about their gap line less their σ̂.
    estimate_offset : bool
        Estimate sensor II's projection-centre offset (:func:`calibrate_joint`).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """

    sigma_px: float = 0.02
    f0_mm: float | None = 9.0
    reject_k: float | None = 5.0
    pairs: tuple | None = None
    joint: bool = True
    scatter_mm: tuple | None = None
    estimate_offset: bool = False


@dataclass(frozen=True)
class RikolaResult:
    """What :func:`calibrate_rikola` found.

    Attributes
    ----------
    options : RikolaOptions
    bands : dict band -> BandCalibration
    cubes : (n,) int ndarray
        The cubes of the relative orientation (seen in every paired band).
    pairs : list of (int, int)
    relative : dict
        :func:`mean_relative_orientation` (empty without pairs).
    gap : dict sensor -> dict
        Per sensor (1, 2): ``bands``, ``gap_nm``, ``f_mm``, ``f_sigma_mm`` and ``line``
        (:func:`gap_regression`) of the on-line bands.
    sigma0_pooled : float
        RMS of the per-band σ0.
    sigma_px_joint : float
        A-priori σ of a centroid in the joint model: ``sigma_px`` · ``sigma0_pooled``.
    scatter_mm : (float, float)
        The joint model's prior σ of ``df`` (sensor I, II).
    joint : JointCalibration or None
    """

    options: RikolaOptions
    bands: dict
    cubes: np.ndarray
    pairs: list
    relative: dict = field(default_factory=dict)
    gap: dict = field(default_factory=dict)
    sigma0_pooled: float = float("nan")
    sigma_px_joint: float = float("nan")
    scatter_mm: tuple = ()
    joint: JointCalibration | None = None

    def tables(self) -> dict[str, list[dict]]:
        """Table name -> rows ``{quantity, unit, value, sigma}`` (angles in degrees)."""
        out: dict[str, list[dict]] = {}
        for b, c in self.bands.items():
            out[f"interior band {b}"] = [
                _row(q.split("_")[0], q.split("_", 1)[1].replace("per_", "1/"), v, s)
                for q, (v, s) in c.iop.items()
            ]
        if self.relative:
            m, s = (
                np.rad2deg(self.relative["rop_mean"]),
                np.rad2deg(self.relative["rop_mean_sigma"]),
            )
            out["relative orientation"] = [
                _row(q, "deg", m[i], s[i]) for i, q in enumerate(("domega", "dphi", "dkappa"))
            ]
        rows = []
        for s, g in self.gap.items():
            ln = g["line"]
            rows += [
                _row(f"a_sensor{s}", "mm/nm", ln["a"], ln["sigma_a"]),
                _row(f"b_sensor{s}", "mm", ln["b"], ln["sigma_b"]),
                _row(f"r2_sensor{s}", "%", 100 * ln["r2"], None),
            ]
        if rows:
            out["gap model"] = rows
        if self.joint is not None:
            R = self.joint.result
            rows = []
            for blk in ("gap_model", "pp_mm", "distortion_mm", "sensor2_rotation"):
                b = R.params[blk]
                v, s = b.value.ravel(), self.joint.sigma(blk).ravel()
                rows += [_row(lab, "", v[i], s[i]) for i, lab in enumerate(b.labels())]
            out["joint model"] = rows
        return out

    def to_dict(self) -> dict:
        """Plain JSON-ready values (NaN → None)."""
        out = {
            "options": {k: getattr(self.options, k) for k in self.options.__dataclass_fields__},
            "tables": self.tables(),
            "sigma0_per_band": {str(b): _num(c.result.sigma0) for b, c in self.bands.items()},
            "pairs": [list(p) for p in self.pairs],
            "sigma0_pooled": _num(self.sigma0_pooled),
            "sigma_px_joint": _num(self.sigma_px_joint),
            "scatter_mm": [_num(v) for v in self.scatter_mm],
        }
        if self.joint is not None:
            out["sigma0_joint"] = _num(self.joint.result.sigma0)
            out["joint_clusters"] = {k: _num(v) for k, v in self.joint.clusters.items()}
        return out


def _num(v):
    v = float(v)
    return v if np.isfinite(v) else None


def _row(q, unit, v, s) -> dict:
    return {"quantity": q, "unit": unit, "value": _num(v), "sigma": None if s is None else _num(s)}


def _gap_lines(cals: dict) -> dict:
    """The gap line of each sensor from its on-line bands (003 §3.5: bands 1 and 11 out)."""
    out = {}
    for s in (1, 2):
        bs = [b for b in cals if BANDS["sensor"][b - 1] == s and b not in OFF_LINE_BANDS]
        if len(bs) < 3:
            continue
        g = BANDS["gap_nm"][np.array(bs) - 1]
        fh = np.array([cals[b].value("interior")[0] for b in bs])
        out[s] = {
            "bands": bs,
            "gap_nm": g,
            "f_mm": fh,
            "f_sigma_mm": np.array([cals[b].sigma("interior")[0] for b in bs]),
            "line": gap_regression(g, fh),
        }
    return out


def _df_scatter(gap: dict) -> tuple[float, float]:
    """Prior σ of ``df`` per sensor: the scatter about the gap line less the σ̂ of f (at least
    half of that σ̂).
    """
    if set(gap) != {1, 2}:
        raise InputError(
            "the joint model's prior on the per-band focal lengths needs at least 3 bands off "
            "bands 1 and 11 on each sensor; give RikolaOptions(scatter_mm=(σ_I, σ_II))"
        )
    f_sd = np.sqrt(np.mean(np.concatenate([gap[s]["f_sigma_mm"] for s in (1, 2)]) ** 2))
    return tuple(
        float(np.sqrt(max(gap[s]["line"]["s"] ** 2 - f_sd**2, (0.5 * f_sd) ** 2))) for s in (1, 2)
    )


def calibrate_rikola(obs: Observations, options: RikolaOptions = RikolaOptions()) -> RikolaResult:
    """Calibrate a Rikola from its target observations: every band, the relative orientation,
    the gap lines and (``options.joint``) the joint model (module docstring).
    """
    o = options
    cals = {
        int(b): calibrate_band(obs, int(b), f0_mm=o.f0_mm, sigma_px=o.sigma_px, reject_k=o.reject_k)
        for b in np.unique(obs.band)
    }
    pairs = paper_pairs(cals) if o.pairs is None else [tuple(map(int, p)) for p in o.pairs]
    for p in pairs:
        if p[0] not in cals or p[1] not in cals:
            raise InputError(f"ROP pair {p}: band {p[0] if p[0] not in cals else p[1]} not seen")
    cubes = np.unique(obs.cube)
    for b in {b for p in pairs for b in p}:
        cubes = np.intersect1d(cubes, cals[b].cubes)
    relative = mean_relative_orientation(cals, obs, cubes, pairs) if pairs else {}
    gap = _gap_lines(cals)
    sigma0_pool = float(np.sqrt(np.mean([c.result.sigma0**2 for c in cals.values()])))
    sigma_joint = o.sigma_px * sigma0_pool
    joint, scatter = None, tuple(o.scatter_mm or ())
    if o.joint:
        scatter = scatter or _df_scatter(gap)
        joint = calibrate_joint(
            obs,
            sigma_px=sigma_joint,
            scatter_mm=scatter,
            f0_mm=initial_focal_mm(obs) if o.f0_mm is None else o.f0_mm,
            estimate_offset=o.estimate_offset,
            reject_k=o.reject_k,
            init=cals,
        )
    return RikolaResult(
        o, cals, cubes, pairs, relative, gap, sigma0_pool, sigma_joint, scatter, joint
    )


def calibrate_rikola_files(
    images,
    board_path,
    *,
    band_regex: str,
    cube_regex: str,
    options: RikolaOptions = RikolaOptions(),
) -> RikolaResult:
    """The file front end: detect the board of ``board_path`` (:func:`hsgeo.io.read_board`) in
    the image files, the band and cube of each from its name, and :func:`calibrate_rikola`.
    """
    from hsgeo.io import read_board
    from hsgeo.measure.boards import observe_files

    board = read_board(board_path)
    obs = observe_files(list(images), board, band_regex=band_regex, cube_regex=cube_regex)
    return calibrate_rikola(obs, options)
