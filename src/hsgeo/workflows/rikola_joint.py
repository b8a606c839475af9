"""The Rikola's joint model (003 §3.5, the paper's future work): one adjustment of all bands.

One exterior orientation per cube (sensor I's camera frame), ``f = a·gap + b`` per sensor (003
eq. (2)) plus a per-band deviation ``df`` with a prior, one principal point per sensor, one
distortion set, sensor II's rotation ``R_I_from_II`` (003 eq. (1)) and the drift of the exterior
orientation across the bands of a cube (003 §3.4, Fig. 5: a rotation rate per band, zero at the
middle band :data:`DRIFT_REF_BAND`); the residual block is
:class:`hsgeo.sensors.rikola.JointCentroids`. :func:`calibrate_joint` sets the problem up (the
one place it is set up) and adjusts it; :func:`predict_band` predicts a band the model did not
see; :func:`design_effect` measures how much the observations of one target in the bands of a
sensor share their error, by which the σ̂ of the joint model are scaled.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.adjust import AdjustmentResult, Parameters, adjust
from hsgeo.errors import ObservationError
from hsgeo.measure.targets import Observations
from hsgeo.sensors.frame import PHOTOGRAMMETRIC_DISTORTION, POSE_COLUMNS
from hsgeo.sensors.rikola import (
    DRIFT_COLUMNS,
    GAP_MODEL_COLUMNS,
    OFFSET_COLUMNS,
    ROTATION_COLUMNS,
    JointCentroids,
)
from hsgeo.workflows.rikola_bands import BANDS, initial_poses

__all__ = [
    "OFF_LINE_BANDS",
    "DRIFT_REF_BAND",
    "design_effect",
    "JointCalibration",
    "joint_block",
    "calibrate_joint",
    "predict_band",
]

#: Bands whose gaps are off the linear trend (003 §3.5): a free ``df`` and out of the gap line.
OFF_LINE_BANDS = (1, 11)

#: The band whose camera frame the EOP drift leaves in place (the middle of 1–25): the poses and
#: sensor II's rotation are those of band 13's frame (a parametrisation, not an assumption).
DRIFT_REF_BAND = 13


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


def joint_block(o: Observations, cubes, sigma_mm) -> JointCentroids:
    """The joint model's residual block of the observations ``o``, views indexed in ``cubes``."""
    return JointCentroids(
        np.searchsorted(cubes, o.cube),
        np.searchsorted(BANDS["band"], o.band),
        o.corners_obj,
        o.centroids_mm,
        sigma_mm,
        BANDS["gap_nm"],
        BANDS["sensor"],
        band_number=BANDS["band"],
        drift_ref_band=DRIFT_REF_BAND,
    )


def _joint_parameters(
    o: Observations, bands, cubes, f0_mm, scatter_mm, estimate_offset, model_drift=True
):
    """The parameter blocks of the joint model with their initial values and priors."""
    table = BANDS
    poses0 = initial_poses(o.select(o.band >= 11), f0_mm)
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
    sigma_df[np.isin(table["band"], OFF_LINE_BANDS)] = np.inf
    p.add(
        "df_mm",
        np.zeros(len(table)),
        free=present.copy(),
        prior_sigma=np.where(present, sigma_df, np.inf),
        rows=[f"band {b}" for b in table["band"]],
    )
    p.add("pp_mm", np.zeros((2, 2)), columns=("x0_mm", "y0_mm"), rows=["sensor I", "sensor II"])
    p.add("distortion_mm", np.zeros(5), columns=PHOTOGRAMMETRIC_DISTORTION)
    p.add("sensor2_rotation", np.zeros(3), columns=ROTATION_COLUMNS)
    p.add("sensor2_offset_mm", np.zeros(3), columns=OFFSET_COLUMNS)
    if not estimate_offset:
        p.fix("sensor2_offset_mm")
    p.add("eop_drift_rad_per_band", np.zeros(3), columns=DRIFT_COLUMNS)
    if not model_drift:
        p.fix("eop_drift_rad_per_band")
    return p


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
    model_drift: bool = True,
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
    model_drift : bool
        Estimate the drift of the exterior orientation across the bands (a rotation rate
        (dω, dφ, dκ) per band, zero at :data:`DRIFT_REF_BAND`; 003 §3.4, Fig. 5); False holds
        it at zero (the rigid model of 003 eq. (1)).

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    keep = ~np.isin(obs.band, np.asarray(exclude_bands, int))
    o = obs.select(keep)
    bands = np.unique(o.band)
    cubes = np.unique(o.cube)
    for s in (1, 2):
        on = [b for b in bands if BANDS["sensor"][b - 1] == s and b not in OFF_LINE_BANDS]
        if len(on) < 2:
            raise ObservationError(
                f"the joint model needs at least 2 on-line bands of sensor "
                f"{'I' if s == 1 else 'II'}, got {on}"
            )
    p = _joint_parameters(o, bands, cubes, f0_mm, scatter_mm, estimate_offset, model_drift)
    if init is not None:
        _init_from_bands(p, init, cubes)
    blk = joint_block(o, cubes, sigma_px * obs.pixel_mm)
    res = adjust(p, blk, reject_k=reject_k)
    j = JointCalibration(res, blk, cubes, bands, obs.pixel_mm)
    ok = ~res.outliers(0)  # one entry per centroid
    key = (o.cube * 1_000_000 + o.target * 10 + blk.srow + 1)[ok]
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


def predict_band(joint: JointCalibration, obs: Observations, band: int, df_mm=None) -> np.ndarray:
    """Predict the centroids of a band the joint model did not see: ``f = a·gap + b`` of its
    sensor (``df_mm`` = 0 unless given, one per band of the table), the sensor's principal
    point, the shared distortion, the cube's pose and the sensor rotation. Returns the
    residuals (predicted − measured) in px, (n, 2), y down.
    """
    sel = (obs.band == band) & np.isin(obs.cube, joint.cubes)
    if not sel.any():
        raise ObservationError(f"no observations of band {band} in the joint model's cubes")
    blk = joint_block(obs.select(sel), joint.cubes, 1.0)
    values = {k: v.copy() for k, v in joint.result.params.values().items()}
    if df_mm is None:
        values["df_mm"] = np.zeros_like(values["df_mm"])
    else:
        values["df_mm"] = np.asarray(df_mm, float)
    r = blk.evaluate(values, False)[0].reshape(-1, 2)
    return r / obs.pixel_mm * np.array([1.0, -1.0])
