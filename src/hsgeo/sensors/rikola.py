"""The Rikola FPI frame camera (003): target-centroid observations, per band and jointly.

The camera model is :class:`hsgeo.sensors.frame.FramePhotogrammetric`'s — collinearity in mm,
camera frame x right, y up, z backward, and Brown's corrections evaluated at the *measured*
coordinates reduced to the principal point (003 Table 3)::

    x̄ + δ(x̄) = −f·X_c/Z_c,    x̄ = x − x0                                    (collinearity)

What is observed is different. The paper measures the four corners of each ArUco target and uses
their centroid as a single virtual point (003 §3.2). The centroid of four *imaged* corners is
not the image of the target's centre: perspective moves it by ``h·a/Z`` (``h`` the half-size of
the target in the image, ``a`` the depth difference across it) — a third of a pixel for a
60 mm target at 1.4 m tilted by 35° — and the curvature of the distortion adds about a tenth of
a pixel in the image corners. Both are far above the noise of a centroid, so the observation
equation here predicts the centroid exactly: each corner is projected to its *measured*
position by inverting the correction (Newton, :func:`hsgeo.distortion.measured_from_ideal_mm`),
and the four are averaged::

    x_k = x0 + x̄_k,  x̄_k + δ(x̄_k) = −f·q_k,   q_k = (X_c/Z_c, Y_c/Z_c) of corner k
    x_centroid = ¼ Σ_k x_k                                                   (model)

The residual is model − observed centroid, in mm. The Jacobian follows from the implicit
function theorem: ``(I + ∂δ/∂x̄) dx̄ = −q df − f dq − ∂δ/∂(K, P) d(K, P)``.

Two residual blocks use it:

* :class:`TargetCentroids` — one camera (one band): blocks ``interior`` (f, x0, y0),
  ``distortion_mm`` (K1, K2, K3, P1, P2) and ``poses`` (one per cube), as in 003 §3.3 where
  "each image band was approached as a single camera";
* :class:`JointCentroids` — the model the paper leaves as future work (003 §3.5): one exterior
  orientation per cube (the camera frame of sensor I), focal length ``f = a·gap + b`` per sensor
  (003 eq. (2)) plus a per-band deviation ``df`` (a random effect with a prior), a principal point
  per sensor, one distortion set, and the rotation ``R_I_from_II`` (ω, φ, κ; 003 eq. (1)) and
  offset ``t_I`` (mm, in sensor I's frame) of sensor II, so that
  ``X_camII = R_I_from_IIᵀ (X_camI − t_I)``.

:class:`RikolaCamera` is the camera as a sensor (:mod:`hsgeo.sensors.mount`): ``project`` and
``rays`` of any band at given poses, with a :class:`~hsgeo.sensors.mount.Mount`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from hsgeo.adjust import Indexed, ResidualBlock
from hsgeo.distortion import (
    brown_correction_jacobian,
    ideal_from_measured_mm,
    measured_from_ideal_mm,
)
from hsgeo.errors import InputError
from hsgeo.rotations import R_from_opk, dR_dopk
from hsgeo.sensors.frame import (
    _dproj,
    body_frames,
    camera_coordinates,
    mm_to_pixel,
    pixel_to_mm,
)
from hsgeo.sensors.mount import Mount, unit

__all__ = [
    "project_measured_mm",
    "camera_II_from_I",
    "centroid_model",
    "TargetCentroids",
    "JointCentroids",
    "focal_from_gap_mm",
    "RikolaCamera",
    "GAP_MODEL_COLUMNS",
    "ROTATION_COLUMNS",
    "OFFSET_COLUMNS",
    "DRIFT_COLUMNS",
]

GAP_MODEL_COLUMNS = ("a_mm_per_nm", "b_mm")
ROTATION_COLUMNS = ("domega_rad", "dphi_rad", "dkappa_rad")
OFFSET_COLUMNS = ("tx_mm", "ty_mm", "tz_mm")
#: Columns of the joint model's drift rate across the bands (:class:`JointCentroids`).
DRIFT_COLUMNS = ("domega_rad_per_band", "dphi_rad_per_band", "dkappa_rad_per_band")


def focal_from_gap_mm(gap_nm, a_mm_per_nm, b_mm):
    """The focal length of a band from its Fabry-Pérot air gap: ``f = a·gap + b`` (003 eq. (2),
    the straight line of 003 Table 4, second part). The one implementation: the simulator, the
    joint model and the chapter's tables all call it.

    >>> float(focal_from_gap_mm(1000.0, 1e-4, 9.0))
    9.1

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    return np.asarray(a_mm_per_nm) * np.asarray(gap_nm, dtype=np.float64) + np.asarray(
        b_mm
    )  # 003 eq. (2)


def _ideal_mm(Xc, f_mm):
    """Ideal image coordinates ``−f·q`` (mm) and ``q = (X_c/Z_c, Y_c/Z_c)`` of camera-frame
    points ``(..., 3)``: the collinearity of 003 (the one place it is coded; ``f_mm`` broadcasts
    against ``Xc[..., 0]``).
    """
    q = Xc[..., :2] / Xc[..., 2:3]
    return -np.asarray(f_mm, dtype=np.float64)[..., None] * q, q


def camera_II_from_I(Xc_rel_mm, rotation_rad):
    """Points in sensor II's camera frame: ``X_camII = R_I_from_IIᵀ (X_camI − t_I)``.

    The one place the relative orientation of 003 eq. (1) is applied to points: the face
    (:class:`RikolaCamera`) and the joint block (:class:`JointCentroids`) both call it.

    Parameters
    ----------
    Xc_rel_mm : (..., 3) ndarray
        Points in sensor I's camera frame minus sensor II's projection centre ``t_I``.
    rotation_rad : (3,) array_like
        (dω, dφ, dκ) of ``R_I_from_II = R_from_opk(dω, dφ, dκ)``.

    Returns
    -------
    X_camII : (..., 3) ndarray
    R_I_from_II : (3, 3) ndarray

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """
    M = R_from_opk(*rotation_rad)  # R_I_from_II
    return np.einsum("ji,...j->...i", M, Xc_rel_mm), M


def project_measured_mm(Xc, f_mm, pp_mm, KP) -> np.ndarray:
    """Measured image coordinates (mm, y up) of camera-frame points.

    Parameters
    ----------
    Xc : (..., 3) ndarray
        Points in the camera frame (x right, y up, z backward; visible points have z < 0).
    f_mm : float or (...) ndarray
    pp_mm : (2,) or (..., 2) ndarray
        Principal point (x0, y0).
    KP : (5,) ndarray
        (K1, K2, K3, P1, P2) of :func:`hsgeo.distortion.brown_correction`.

    Returns
    -------
    xy_mm : (..., 2) ndarray
    """
    Xc = np.asarray(Xc, dtype=np.float64)
    if np.any(Xc[..., 2] >= 0):
        raise InputError("points behind the camera (the photogrammetric camera looks along −z)")
    ideal, _ = _ideal_mm(Xc, f_mm)  # 003 collinearity
    KP = np.asarray(KP, dtype=np.float64)
    return measured_from_ideal_mm(ideal, KP[:3], KP[3:]) + np.asarray(pp_mm)


def centroid_model(Xc, f_mm, pp_mm, KP, jacobian: bool):
    """Predicted centroid of the four imaged corners of each target (module docstring).

    Parameters
    ----------
    Xc : (n, 4, 3) ndarray
        The four corners of each target in the camera frame.
    f_mm : (n,) ndarray
    pp_mm : (n, 2) ndarray
    KP : (5,) ndarray
    jacobian : bool

    Returns
    -------
    xy_mm : (n, 2) ndarray
    jac : dict or None
        ``f`` (n, 2), ``KP`` (n, 2, 5), ``Xc`` (n, 4, 2, 3) — derivatives of the centroid; the
        derivative w.r.t. the principal point is the identity.
    """
    if np.any(Xc[..., 2] >= 0):
        raise InputError(
            f"{int(np.sum(Xc[..., 2] >= 0))} target corners lie behind the camera (the "
            "photogrammetric camera looks along −z): check the initial poses"
        )
    f4 = np.asarray(f_mm, dtype=np.float64)[:, None, None]
    ideal, q = _ideal_mm(Xc, f4[..., 0])  # (n, 4, 2)
    xbar = measured_from_ideal_mm(ideal, KP[:3], KP[3:])  # 003 collinearity, inverted
    xy = xbar.mean(axis=1) + pp_mm
    if not jacobian:
        return xy, None
    J_xy, J_K, J_P = brown_correction_jacobian(xbar, KP[:3], KP[3:])
    A_inv = np.linalg.inv(np.eye(2) + J_xy)  # (n, 4, 2, 2): dx̄ = A⁻¹ d(ideal − δ_params)
    d_f = np.einsum("nkab,nkb->na", A_inv, -q) / 4.0
    J_KP = np.concatenate([J_K, J_P], axis=-1)  # (n, 4, 2, 5)
    d_KP = -np.einsum("nkab,nkbc->nac", A_inv, J_KP) / 4.0
    n = Xc.shape[0]
    dq = _dproj(Xc.reshape(-1, 3)).reshape(n, 4, 2, 3)
    d_Xc = np.einsum("nkab,nkbc->nkac", A_inv, -f4[..., None] * dq) / 4.0
    return xy, {"f": d_f, "KP": d_KP, "Xc": d_Xc}


def _check_obs(name, view, corners, xy):
    view = np.asarray(view)
    corners = np.asarray(corners, dtype=np.float64)
    xy = np.asarray(xy, dtype=np.float64)
    n = xy.shape[0] if xy.ndim == 2 else -1
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"{name}: centroids must be (n, 2) in mm, got {xy.shape}")
    if corners.shape != (n, 4, 3):
        raise InputError(
            f"{name}: target corners must be (n, 4, 3) object coordinates, got "
            f"{corners.shape} for {n} centroids"
        )
    if view.shape != (n,) or not np.issubdtype(view.dtype, np.integer):
        raise InputError(f"{name}: view/cube indices must be (n,) integers")
    if not (np.all(np.isfinite(xy)) and np.all(np.isfinite(corners))):
        raise InputError(f"{name}: NaN or inf in the centroids or the target corners")
    return view.astype(np.int64), corners, xy


class TargetCentroids(ResidualBlock):
    """Centroid observations of one camera (one band): 003 §3.3, one IOP set per band.

    Parameter blocks: ``interior`` (f, x0, y0) mm, ``distortion_mm`` (K1, K2, K3, P1, P2) and
    ``poses`` (n_views, 6) ``(ω, φ, κ, X0, Y0, Z0)`` of ``R_world_from_cam``.

    Parameters
    ----------
    view : (n,) int ndarray
        The view (cube) of each centroid.
    corners : (n, 4, 3) ndarray
        Object coordinates of the target's four corners.
    xy_mm : (n, 2) ndarray
        Measured centroids, mm from the image centre, y up.
    sigma_mm : float or (n, 2) ndarray
    blocks : mapping, optional
        Parameter-block names by role (``interior``, ``distortion``, ``poses``; defaults
        ``interior``, ``distortion_mm``, ``poses``), see :class:`~hsgeo.adjust.ResidualBlock`.

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """

    name = "target centroids"
    group_size = 2
    BLOCKS = MappingProxyType(
        {"interior": "interior", "distortion": "distortion_mm", "poses": "poses"}
    )

    def __init__(self, view, corners, xy_mm, sigma_mm, *, blocks=None, name=None):
        view, corners, xy = _check_obs(type(self).__name__, view, corners, xy_mm)
        super().__init__(
            np.broadcast_to(np.asarray(sigma_mm, float), xy.shape).ravel(), name=name, blocks=blocks
        )
        self.view, self.corners, self.xy = view, corners, xy

    def predict(self, values) -> np.ndarray:
        """Model centroids (n, 2) mm."""
        return self._model(values, False)[0]

    def _model(self, values, jacobian):
        f, x0, y0 = values[self.blocks["interior"]]
        n = self.xy.shape[0]
        Xc, d_pose, _ = camera_coordinates(
            values[self.blocks["poses"]],
            np.repeat(self.view, 4),
            self.corners.reshape(-1, 3),
            jacobian,
        )
        xy, J = centroid_model(
            Xc.reshape(n, 4, 3),
            np.full(n, f),
            np.array([x0, y0]),
            values[self.blocks["distortion"]],
            jacobian,
        )
        return xy, J, d_pose

    def evaluate(self, values, jacobian):
        xy, J, d_pose = self._model(values, jacobian)
        r = xy - self.xy
        if not jacobian:
            return r.ravel(), None
        n = r.shape[0]
        d_int = np.zeros((n, 2, 3))
        d_int[:, :, 0] = J["f"]
        d_int[:, 0, 1] = 1.0
        d_int[:, 1, 2] = 1.0
        dp = np.einsum("nkac,nkcj->naj", J["Xc"], d_pose.reshape(n, 4, 3, 6))
        nm = self.blocks
        jac = {
            nm["interior"]: d_int.reshape(2 * n, 3),
            nm["distortion"]: J["KP"].reshape(2 * n, 5),
            nm["poses"]: Indexed(np.repeat(self.view, 2), dp.reshape(2 * n, 6)),
        }
        return r.ravel(), jac


class JointCentroids(ResidualBlock):
    """Centroid observations of all bands of all cubes in one model (003 §3.5, future work).

    Parameter blocks (default names; ``blocks={role: name}`` renames them, roles ``poses``,
    ``gap``, ``df``, ``pp``, ``distortion``, ``rotation``, ``offset`` in this order):

    ``poses`` (n_cubes, 6)
        Exterior orientation of sensor I's camera frame per cube (the camera is static during a
        cube, 003 §3.4).
    ``gap_model`` (2, 2)
        Rows sensor I, sensor II; columns (a mm/nm, b mm): ``f = a·gap + b`` (003 eq. (2)).
    ``df_mm`` (n_bands,)
        Per-band deviation from the line (give it a prior; bands off the line free).
    ``pp_mm`` (2, 2)
        Principal point (x0, y0) per sensor (rows I, II).
    ``distortion_mm`` (5,)
        One set (K1, K2, K3, P1, P2) for all bands (003 §3.5, Fig. 8).
    ``sensor2_rotation`` (3,)
        (dω, dφ, dκ) of ``R_I_from_II`` (003 eq. (1), Table 4).
    ``sensor2_offset_mm`` (3,)
        Projection centre of sensor II in sensor I's frame.
    ``eop_drift_rad_per_band`` (3,), optional
        The drift of the exterior orientation across the bands of a cube (003 §3.4, Fig. 5: "φ
        and X0 … decrease as a linear function" of the band): a rotation of each band's camera
        frame about its projection centre by (dω, dφ, dκ)·(band − ``drift_ref_band``), after
        the sensor's rigid orientation — ``R_world_from_band = R_rigid · R(rate·(b − b_ref))``,
        as :meth:`hsgeo.simulate.rikola.RikolaTruth.band_pose` applies it. Absent from the
        values: no drift (the model of the paper's eq. (1)).

    Parameters
    ----------
    cube : (n,) int ndarray
    band_index : (n,) int ndarray
        Index into ``gap_nm`` / ``sensor`` (0-based rows of the band table).
    corners, xy_mm, sigma_mm : as in :class:`TargetCentroids`.
    gap_nm : (n_bands,) ndarray
    sensor : (n_bands,) int ndarray
        1 or 2 for each band.
    band_number : (n_bands,) ndarray, optional
        The band numbers of the table's rows (default 1, 2, …): the drift's abscissa.
    drift_ref_band : float
        The band whose camera frame the drift leaves in place (the middle band, 13, by default):
        a choice of parametrisation only — another reference moves the poses and sensor II's
        rotation by a constant rotation and leaves the predictions the same.

    References
    ----------
    .. [1] Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A. and Honkavaara, E.
           (2018). A study on the variations of inner orientation parameters of a hyperspectral
           frame camera. Int. Arch. Photogramm. Remote Sens. Spatial Inf. Sci. XLII-1 (paper 003).
    """

    name = "target centroids (joint model)"
    group_size = 2

    BLOCKS = MappingProxyType(
        {
            "poses": "poses",
            "gap": "gap_model",
            "df": "df_mm",
            "pp": "pp_mm",
            "distortion": "distortion_mm",
            "rotation": "sensor2_rotation",
            "offset": "sensor2_offset_mm",
            "drift": "eop_drift_rad_per_band",
        }
    )

    def __init__(
        self,
        cube,
        band_index,
        corners,
        xy_mm,
        sigma_mm,
        gap_nm,
        sensor,
        *,
        band_number=None,
        drift_ref_band: float = 13.0,
        blocks=None,
        name=None,
    ):
        cube, corners, xy = _check_obs(type(self).__name__, cube, corners, xy_mm)
        band_index = np.asarray(band_index)
        gap_nm = np.asarray(gap_nm, dtype=np.float64)
        sensor = np.asarray(sensor)
        if band_index.shape != cube.shape or not np.issubdtype(band_index.dtype, np.integer):
            raise InputError("JointCentroids: band_index must be (n,) integers")
        if gap_nm.shape != sensor.shape or np.any(~np.isin(sensor, (1, 2))):
            raise InputError("JointCentroids: gap_nm and sensor must be (n_bands,), sensor 1 or 2")
        if band_index.min() < 0 or band_index.max() >= gap_nm.size:
            raise InputError("JointCentroids: band_index outside the band table")
        super().__init__(
            np.broadcast_to(np.asarray(sigma_mm, float), xy.shape).ravel(), name=name, blocks=blocks
        )
        self.cube, self.band, self.corners, self.xy = cube, band_index.astype(np.int64), corners, xy
        self.gap = gap_nm[self.band]
        self.srow = sensor[self.band].astype(np.int64) - 1  # 0: sensor I, 1: sensor II
        numbers = np.arange(1, gap_nm.size + 1) if band_number is None else band_number
        numbers = np.asarray(numbers, dtype=np.float64)
        if numbers.shape != gap_nm.shape:
            raise InputError("JointCentroids: band_number must be (n_bands,), like gap_nm")
        self.band_steps = numbers - float(drift_ref_band)  # per row of the band table

    def predict(self, values) -> np.ndarray:
        return self._model(values, False)[0]

    def _model(self, values, jacobian):
        nm = self.blocks
        n = self.xy.shape[0]
        ab = values[nm["gap"]]
        f = focal_from_gap_mm(self.gap, ab[self.srow, 0], ab[self.srow, 1])
        f = f + values[nm["df"]][self.band]
        pp = values[nm["pp"]][self.srow]
        XcI, d_pose, _ = camera_coordinates(
            values[nm["poses"]], np.repeat(self.cube, 4), self.corners.reshape(-1, 3), jacobian
        )
        XcI = XcI.reshape(n, 4, 3)
        rot = values[nm["rotation"]]
        t = values[nm["offset"]]
        two = self.srow == 1
        Xs = XcI.copy()  # the sensor's rigid camera frame
        Xs[two], M = camera_II_from_I(XcI[two] - t, rot)  # X_camII = Mᵀ (X_camI − t)
        rate = values.get(nm["drift"])
        if rate is None:  # no drift block: the rigid model
            D = dD = None
            Xc = Xs
        else:  # the band's frame: X_band = D_bᵀ X_sensor, D_b = R(rate·(b − b_ref))
            D, dD = _drift_rotations(np.asarray(rate, float), self.band_steps)
            Xc = np.einsum("nji,nkj->nki", D[self.band], Xs)
        xy, J = centroid_model(Xc, f, pp, values[nm["distortion"]], jacobian)
        return xy, J, (d_pose, XcI, M, two, t, rot, Xs, D, dD)

    def evaluate(self, values, jacobian):
        nm = self.blocks
        xy, J, aux = self._model(values, jacobian)
        r = xy - self.xy
        if not jacobian:
            return r.ravel(), None
        d_pose, XcI, M, two, t, rot, Xs, D, dD = aux
        n = r.shape[0]
        JXs = J["Xc"]  # (n, 4, 2, 3) ∂centroid/∂X in the band's frame → the sensor's frame
        d_drift = None
        if D is not None:
            JXs = np.einsum("nkac,nci->nkai", J["Xc"], D[self.band].transpose(0, 2, 1))
            # ∂X_band/∂rate_j = (∂D_bᵀ/∂angle_j · step_b) X_sensor
            dXb = np.einsum("naji,nkj->nkia", dD[self.band], Xs)  # (n, 4, 3 xyz, 3 angles)
            dXb = dXb * self.band_steps[self.band][:, None, None, None]
            d_drift = np.einsum("nkac,nkcj->naj", J["Xc"], dXb)
        # chain through sensor II's rotation: dXc = Mᵀ dXcI for sensor II rows
        dXcI = JXs.copy()
        dXcI[two] = np.einsum("nkac,ci->nkai", JXs[two], M.T)
        dp = np.einsum("nkac,nkcj->naj", dXcI, d_pose.reshape(n, 4, 3, 6))
        d_rot = np.zeros((n, 2, 3))
        d_off = np.zeros((n, 2, 3))
        if np.any(two):
            dM = dR_dopk(*rot)  # (3, 3, 3): ∂M/∂angle
            v = XcI[two] - t  # (m, 4, 3)
            dXc_drot = np.einsum("aji,nkj->nkia", dM, v)  # (m, 4, 3 xyz, 3 angles)
            d_rot[two] = np.einsum("nkac,nkcj->naj", JXs[two], dXc_drot)
            d_off[two] = -np.einsum("nkac,ci->nai", JXs[two], M.T)
        d_ab = np.stack([J["f"] * self.gap[:, None], J["f"]], axis=-1)  # (n, 2, 2)
        jac = {
            nm["poses"]: Indexed(np.repeat(self.cube, 2), dp.reshape(2 * n, 6)),
            nm["gap"]: Indexed(np.repeat(self.srow, 2), d_ab.reshape(2 * n, 2)),
            nm["df"]: Indexed(np.repeat(self.band, 2), J["f"].reshape(2 * n, 1)),
            nm["pp"]: Indexed(np.repeat(self.srow, 2), np.tile(np.eye(2), (n, 1))),
            nm["distortion"]: J["KP"].reshape(2 * n, 5),
            nm["rotation"]: d_rot.reshape(2 * n, 3),
            nm["offset"]: d_off.reshape(2 * n, 3),
        }
        if d_drift is not None:
            jac[nm["drift"]] = d_drift.reshape(2 * n, 3)
        return r.ravel(), jac


def _drift_rotations(rate_rad, band_steps):
    """Per band of the table: D_b = R(rate·step_b) (n_bands, 3, 3) and ∂D_b/∂angle (n_bands, 3,
    3, 3), the angles (dω, dφ, dκ) = rate·step_b (:func:`hsgeo.rotations.R_from_opk`).
    """
    D = np.empty((band_steps.size, 3, 3))
    dD = np.empty((band_steps.size, 3, 3, 3))
    for i, s in enumerate(band_steps):
        a = rate_rad * s
        D[i] = R_from_opk(*a)
        dD[i] = dR_dopk(*a)
    return D, dD


# ----------------------------------------------------------------------------------------------
# The sensor interface (hsgeo.sensors.mount): pixels ↔ rays of a band
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RikolaCamera:
    """The Rikola as a sensor: ``project`` and ``rays`` of a band at given poses.

    The joint model's geometry (:class:`JointCentroids`): per band a focal length and its
    sensor's principal point, one distortion set, sensor II rotated by ``R_I_from_II`` and
    offset by ``offset_mm`` in sensor I's frame.

    Parameters
    ----------
    f_mm : (n_bands,) sequence
        Focal length of each band (rows of ``bands``).
    sensor : (n_bands,) sequence of 1 or 2
    pp_mm : (2, 2) sequence
        Principal point (x0, y0) per sensor (rows I, II).
    KP : (5,) sequence
        (K1, K2, K3, P1, P2) of :func:`hsgeo.distortion.brown_correction`.
    rotation_rad, offset_mm : (3,) sequence
        (dω, dφ, dκ) of ``R_I_from_II`` and sensor II's projection centre in sensor I's frame.
    image_size : (int, int)
        Width and height, px.
    pixel_mm : float
    bands : (n_bands,) sequence of int, optional
        Band numbers (default 1 … n_bands).
    mount : Mount
        Sensor I's photogrammetric camera frame (x right, y up, z backward) on the body; the
        identity mount makes the poses sensor I's own.

    The poses are rows ``(ω, φ, κ, X0, Y0, Z0)`` of the body (``R_world_from_body =
    R_from_opk(ω, φ, κ)``), ``view`` the pose of each pixel or point, ``band`` a band number
    (scalar or one per pixel or point); lengths in the poses' unit (mm on the bench).
    """

    f_mm: tuple
    sensor: tuple
    pp_mm: tuple
    KP: tuple
    rotation_rad: tuple = (0.0, 0.0, 0.0)
    offset_mm: tuple = (0.0, 0.0, 0.0)
    # the FPI2015 (003 Table 1, hsgeo.papers.RIKOLA_CAMERA: typed here, as workflows may not
    # import papers; tests/test_config_loader.py checks both agree; hsgeo.io.sensor_file
    # takes its defaults from here)
    image_size: tuple = (1017, 648)
    pixel_mm: float = 0.0055
    bands: tuple | None = None
    mount: Mount = field(default_factory=Mount)

    def _band(self, band, n):
        nums = np.arange(1, len(self.f_mm) + 1) if self.bands is None else np.asarray(self.bands)
        b = np.broadcast_to(np.asarray(band), (n,))
        row = np.searchsorted(nums, b)
        if np.any(row >= nums.size) or np.any(nums[np.minimum(row, nums.size - 1)] != b):
            raise InputError(f"band(s) {sorted(set(b.tolist()) - set(nums.tolist()))} not known")
        two = np.asarray(self.sensor)[row] == 2
        f = np.asarray(self.f_mm, float)[row]
        pp = np.asarray(self.pp_mm, float)[np.asarray(self.sensor)[row] - 1]
        return f, pp, two

    def _frames(self, poses, view):
        return body_frames(poses, view)

    def sensor_directions(self, uv_px, band) -> tuple[np.ndarray, np.ndarray]:
        """Directions ``(n, 3)`` in sensor I's camera frame (not normalised) of pixels
        ``(n, 2)`` of ``band``, and which pixels sensor II records (``(n,)`` bool).
        """
        uv = np.atleast_2d(np.asarray(uv_px, dtype=float))
        f, pp, two = self._band(band, uv.shape[0])
        KP = np.asarray(self.KP, float)
        ideal = ideal_from_measured_mm(
            pixel_to_mm(uv, self.image_size, self.pixel_mm) - pp, KP[:3], KP[3:]
        )
        d = np.column_stack([ideal, -f])  # the band's camera frame
        M = R_from_opk(*self.rotation_rad)  # R_I_from_II
        d[two] = d[two] @ M.T
        return d, two

    def rays(self, uv_px, poses, view, band) -> tuple[np.ndarray, np.ndarray]:
        """Origins and unit directions (world frame) of the rays of pixels ``(n, 2)``."""
        d, two = self.sensor_directions(uv_px, band)
        X0, R = self._frames(poses, view)
        o = self.mount.origins(X0, R)
        if np.any(two):
            t = np.broadcast_to(np.asarray(self.offset_mm, float), (int(two.sum()), 3))
            o[two] = o[two] + self.mount.directions(R[two], t)
        return o, unit(self.mount.directions(R, d))

    def rays_along(self, uv_px, t_s, trajectory, band) -> tuple[np.ndarray, np.ndarray]:
        """The rays of pixels ``(n, 2)`` of ``band`` exposed at times ``t_s`` on a body
        ``trajectory`` (metres): the body's pose composed with the mount as every scanning
        sensor does (:meth:`hsgeo.sensors.mount.Mount.rays_along`); sensor II's centre moved by
        ``offset_mm`` converted to m.
        """
        d, two = self.sensor_directions(uv_px, band)
        o, u = self.mount.rays_along(d, t_s, trajectory)
        if np.any(two):
            t2 = np.asarray(t_s, float)[two] if np.ndim(t_s) else np.full(int(two.sum()), t_s)
            R = trajectory.R_map_from_body(t2)
            off_m = np.broadcast_to(1e-3 * np.asarray(self.offset_mm, float), (t2.size, 3))
            o[two] = o[two] + self.mount.directions(R, off_m)
        return o, u

    def project(self, xyz_world, poses, view, band) -> np.ndarray:
        """Pixels ``(n, 2)`` of world points seen from the poses ``view`` in ``band``."""
        X = np.atleast_2d(np.asarray(xyz_world, dtype=float))
        f, pp, two = self._band(band, X.shape[0])
        X0, R = self._frames(poses, view)
        Xc = self.mount.to_sensor(X, X0, R)  # sensor I's camera frame
        Xc[two], _ = camera_II_from_I(
            Xc[two] - np.asarray(self.offset_mm, float), self.rotation_rad
        )
        xy = project_measured_mm(Xc, f, pp, self.KP)
        return mm_to_pixel(xy, self.image_size, self.pixel_mm)
