"""Bundle adjustment of LP lines with spline trajectory corrections (002 §3.4): set-up and run.

Kept as one file: one workflow in GUIDE §2's template — the set-up, the in-memory core
(:class:`PushbroomInputs`, :class:`PushbroomOptions` -> :func:`adjust_pushbroom` ->
:class:`PushbroomResult`) and its thin file front end (:func:`adjust_files`) belong together.

:func:`build_problem` turns observations, the navigation poses at the line times, a camera and
optional GCPs into the engine's :class:`~hsgeo.adjust.Parameters` and residual blocks;
:func:`intersect_two_rays` gives the tie points their initial coordinates (002 §3.4: "the point
of intersection between the image rays from two observations"). The book chapter, ``hsgeo
reproduce pushbroom-ba`` and ``hsgeo adjust-pushbroom`` all go through these functions.

What is estimated (002 §4): six corrections per trajectory node (GNSS/INS priors with their σ),
the boresight (3), K1, K2, P1, P2, one principal distance per band, the lever arm (with the
prior of its tape measurement) and the tie-point coordinates (eliminated by the Schur
complement). The principal point is fixed (002 §3.4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.adjust import Parameters
from hsgeo.errors import InputError
from hsgeo.io import read_table
from hsgeo.rotations import R_from_rpy
from hsgeo.sensors.pushbroom import (
    BLOCK_NAMES,
    PushbroomCamera,
    PushbroomLines,
    PushbroomObservations,
)
from hsgeo.trajectory import CORRECTION_COLUMNS, SplineNodes

__all__ = [
    "CameraPrior",
    "build_problem",
    "solve",
    "REJECT_K",
    "FTOL",
    "CHORD_END",
    "Y_AS_TIME",
    "REPORTED_PARAMETERS",
    "intersect_two_rays",
    "adjust_files",
    "fit_verdict",
    "PushbroomInputs",
    "PushbroomOptions",
    "PushbroomResult",
    "adjust_pushbroom",
    "observations_from_table",
    "OBS_COLUMNS",
    "GCP_COLUMNS",
    "read_camera",
    "summary",
    "POOR_FIT_SIGMA0_FACTOR",
    "POOR_FIT_REJECTED_SHARE",
]


#: 002's solver settings, once (``hsgeo adjust-pushbroom``, ``hsgeo reproduce pushbroom-ba`` and
#: the chapter): the reject threshold in robust σ of the standardised residuals (ours: about the
#: largest residual / NMAD ratio of 002 Table 1, ≈ 6, with a margin) ...
REJECT_K = 5.0
#: ... the relative cost decrease at which the iteration stops (at full size 1e-6 of the cost
#: is ≈ 0.3, below half a unit of χ², far below any statistical effect) ...
FTOL = 1e-6
#: ... the chord steps' end (``SolverOptions.chord_end``): the reduced matrix is formed afresh
#: to confirm convergence as soon as a chord step predicts less than FTOL of the cost, not
#: 1e-3 of it (the engine's default): one to three iterations fewer (5 → 4 at the paper's
#: size, 8 → 5 at five times it), to the same minimum within FTOL ...
CHORD_END = 1.0
#: ... and the residual across the line as a time (:func:`build_problem`): with the image y of
#: 002 eq. (2) the principal distance and the pitch corrections are biased (the chapter shows by
#: how much).
Y_AS_TIME = True
#: The estimated camera and mount blocks reported by both faces: (block, unit shown, factor).
REPORTED_PARAMETERS = (
    ("boresight_rad", "deg", 180 / np.pi),
    ("lever_arm_m", "m", 1.0),
    ("distortion", "", 1.0),
    ("c_mm", "mm", 1.0),
)


@dataclass(frozen=True, kw_only=True)
class CameraPrior:
    """A-priori camera and GNSS/INS values (the adjustment's starting point and priors).

    The camera's starting values are those of its sensor file (:func:`read_camera`): one
    principal distance per band (``c_band_mm``, default ``c_mm`` for every band), the
    distortion of 002 eq. (3) and the boresight (ω, φ, κ on the nominal mount, rad); the
    adjustment starts from them, not from zero. :meth:`camera` is that camera as a sensor.
    The a-priori σ have no defaults: they are the user's instruments' (a chapter passes its
    campaign's, :func:`hsgeo.reproduce.pushbroom_runs.camera_prior`).

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    n_bands: int
    pixel_mm: float
    c_mm: float
    sigma_lever_m: float
    sigma_pos_m: tuple
    sigma_att_rad: tuple
    sigma_obs_px: float
    sigma_gcp_m: float
    x0_mm: float = 0.0
    y0_mm: float = 0.0
    lever_arm_m: tuple = (0.0, 0.0, 0.0)
    c_band_mm: tuple | None = None
    distortion: tuple = (0.0, 0.0, 0.0, 0.0)
    boresight_rad: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        if self.c_band_mm is not None and len(self.c_band_mm) != self.n_bands:
            raise InputError(
                f"CameraPrior: c_band_mm has {len(self.c_band_mm)} values for n_bands = "
                f"{self.n_bands}; give one principal distance per band"
            )

    @property
    def c_per_band_mm(self) -> np.ndarray:
        """The starting principal distance of each band, mm (``(n_bands,)``)."""
        if self.c_band_mm is None:
            return np.full(self.n_bands, float(self.c_mm))
        return np.asarray(self.c_band_mm, dtype=float)

    def camera(self) -> PushbroomCamera:
        """The camera the priors start from, as a sensor (what :func:`hsgeo.io.read_sensor`
        gives for the same file).
        """
        return PushbroomCamera(
            tuple(float(c) for c in self.c_per_band_mm),
            self.pixel_mm,
            tuple(self.distortion),
            self.x0_mm,
            self.y0_mm,
            tuple(self.boresight_rad),
            tuple(self.lever_arm_m),
        )


def intersect_two_rays(point, origin, direction, n_points, min_angle_deg: float = 20.0):
    """Initial point coordinates from the two most divergent rays of each point.

    For each point, its most vertical ray and the ray making the largest angle with it are
    intersected (midpoint of their closest approach). The rays are chosen by their directions,
    not by their place in the table, so the initial points (and the adjustment from them) do
    not depend on the order of the observation rows. When the first ray was each point's first
    row, the chapter's campaign (002's size) with its rows in a random order ended with 2 more
    residual rows rejected (of 884,242) and points up to 84 m apart; now the two orders give
    the same initial points, bit for bit, and points within 2e-11 m.

    An intersection is only as good as the angle between the rays: before the adjustment the
    boresight is unknown (a few tenths of a degree, i.e. ~10 m across the ray at 2 km), so a
    ray pair at 3° puts the point ~200 m off along the ray,
    far outside the range where the model is nearly linear (the first Gauss–Newton steps then
    fail and the damping grows). Points whose best pair meets at less than ``min_angle_deg``
    are therefore put where their most vertical ray meets the plane of the median intersection
    height (the usual "mean terrain height" start of aerial triangulation: on that ray a height
    error moves the point least across); at the 16.6° field of view of 002 that is every point.

    Returns
    -------
    xyz : (n_points, 3) ndarray

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    point = np.asarray(point)
    # by point, each point's most vertical ray first (ties, which distinct rays do not have,
    # in the table's order)
    order = np.lexsort((-np.abs(direction[:, 2]), point))
    ps = point[order]
    starts = np.searchsorted(ps, np.arange(n_points))
    counts = np.bincount(ps, minlength=n_points)
    if np.any(counts < 2):
        bad = np.flatnonzero(counts < 2)[:5].tolist()
        raise InputError(
            f"points {bad} have fewer than two observations: a tie point needs two rays "
            "(drop them from the observation table)"
        )
    first = order[starts]
    cosang = np.einsum("mi,mi->m", direction[order], direction[first][ps])
    # per point, the ray with the smallest cosine to the most vertical one
    key = np.lexsort((cosang, ps))
    second = order[key[starts]]
    o1, d1, o2, d2 = origin[first], direction[first], origin[second], direction[second]
    w = o1 - o2
    b = np.einsum("mi,mi->m", d1, d2)
    dd = np.einsum("mi,mi->m", d1, w)
    e = np.einsum("mi,mi->m", d2, w)
    den = np.maximum(1 - b * b, 1e-12)
    s = (b * e - dd) / den
    u = (e - b * dd) / den
    xyz = 0.5 * (o1 + s[:, None] * d1 + o2 + u[:, None] * d2)
    # nearly parallel rays (e.g. the two headings of one flight line) do not intersect well:
    # put those points on the plane of the median height of the others instead
    good = (b < np.cos(np.deg2rad(0.5))) & (s > 0) & (u > 0)
    h_med = np.median(xyz[good, 2]) if good.any() else 0.0
    far = np.abs(xyz[:, 2] - h_med) > 0.25 * np.median(np.abs(o1[:, 2] - h_med))
    bad = ~good | far | (b > np.cos(np.deg2rad(min_angle_deg)))
    lam = (h_med - o1[bad, 2]) / np.where(np.abs(d1[bad, 2]) > 1e-9, d1[bad, 2], -1e-9)
    xyz[bad] = o1[bad] + lam[:, None] * d1[bad]
    return xyz


def _parameters(P0, nodes, cam: CameraPrior, gcp_index, gcp_xyz_m, node_prior_mean):
    """The unknowns of 002 §4 with their priors: points (GCPs with theirs), node corrections,
    boresight, lever arm, distortion and one principal distance per band.
    """
    names = BLOCK_NAMES
    p = Parameters()
    p.add(names["points"], P0, points=True, columns=("E_m", "N_m", "H_m"))
    p.add(
        names["nodes"],
        np.zeros((nodes.n_nodes, 6)),
        columns=CORRECTION_COLUMNS,
        prior_mean=0.0 if node_prior_mean is None else node_prior_mean,
        prior_sigma=np.r_[cam.sigma_pos_m, cam.sigma_att_rad][None, :],
    )
    p.add(
        names["boresight"],
        np.asarray(cam.boresight_rad, float),  # the sensor file's, not zero
        columns=("omega_rad", "phi_rad", "kappa_rad"),
    )
    p.add(
        names["lever_arm"],
        np.asarray(cam.lever_arm_m, float),
        columns=("x_m", "y_m", "z_m"),
        prior_sigma=cam.sigma_lever_m,
    )
    p.add(names["distortion"], np.asarray(cam.distortion, float), columns=("K1", "K2", "P1", "P2"))
    p.add(names["c"], cam.c_per_band_mm)
    if gcp_index is not None:
        gi = np.asarray(gcp_index)
        p.set(names["points"], np.asarray(gcp_xyz_m, float), index=gi)
        p.set_prior(names["points"], cam.sigma_gcp_m, index=gi, mean=np.asarray(gcp_xyz_m, float))
    return p


def _time_residual(obs: PushbroomObservations, cam: CameraPrior, P0) -> dict:
    """The GNSS/INS rates and the reference rate of the residual across the line as a time."""
    if not obs.has_rates:
        raise InputError(
            "y_as_time needs the GNSS/INS rates at the line times (xyz_rate_nav_m_s, "
            "rpy_rate_nav_rad_s): give them (hsgeo.trajectory.Trajectory.rates, converted by "
            "hsgeo.trajectory.platform_rpy_rate_from_rph_rate) or use y_as_time=False"
        )
    z_ref = float(np.median(obs.xyz_nav_m[:, 2] - P0[obs.point, 2]))
    v_ref = float(np.median(np.linalg.norm(obs.xyz_rate_nav_m_s, axis=1)))
    return {
        "xyz_rate_m_s": obs.xyz_rate_nav_m_s,
        "rpy_rate_rad_s": obs.rpy_rate_nav_rad_s,
        "y_rate_ref_px_s": cam.c_mm * v_ref / (z_ref * cam.pixel_mm),
    }


def build_problem(
    obs: PushbroomObservations,
    n_points: int,
    cam: CameraPrior,
    *,
    node_interval_s: float = 10.0,
    gcp_index=None,
    gcp_xyz_m=None,
    t_span_s=None,
    node_prior_mean=None,
    y_as_time: bool = Y_AS_TIME,
):
    """Parameters and residual blocks of the LP bundle adjustment.

    Parameters
    ----------
    obs : PushbroomObservations
        The observations and the GNSS/INS pose at their line times, the attitude as the
        model's platform angles (``R_map_from_platform = R_from_rpy``, ENU;
        :func:`hsgeo.trajectory.platform_rpy_from_rph` converts a GNSS/INS attitude); with
        ``y_as_time`` also the GNSS/INS velocity and platform-angle rates there.
    n_points : int
    cam : CameraPrior
    node_interval_s : float
        Spacing of the trajectory-correction nodes (002 §4: 10 s).
    gcp_index, gcp_xyz_m : optional
        Rows of the points that are GCPs and their surveyed coordinates (prior σ
        ``cam.sigma_gcp_m``). None: no GCPs (002 Table 3).
    t_span_s : (float, float), optional
        Time span of the nodes (default: the observations' span).
    node_prior_mean : (n_nodes, 6) ndarray, optional
        Prior mean of the node corrections (default zero: the GNSS/INS solution as it is).
    y_as_time : bool
        Default :data:`Y_AS_TIME` (True). Residual across the line as a *time* (the line a
        point is registered in) rather than
        the image y of 002 eq. (2): the line time minus the model's crossing time of the line
        (:class:`~hsgeo.sensors.pushbroom.PushbroomLines`), in pixels at the reference rate
        ``c_ref V / (Z_ref pixel)`` (``c_ref`` the initial principal distance, ``V`` the median
        speed, ``Z_ref`` the median initial depth). Its derivatives, taken at the crossing, do
        not contain the error itself, as those of the image y do when the error is one of
        time. See the chapter for the bias this avoids.

    Returns
    -------
    params : Parameters
    blocks : list of ResidualBlock
    nodes : SplineNodes

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    if not isinstance(obs, PushbroomObservations):
        raise InputError(
            f"build_problem takes a PushbroomObservations, got {type(obs).__name__}: wrap the "
            "arrays with hsgeo.workflows.pushbroom_ba.PushbroomObservations(point=..., ...)"
        )
    t = obs.t_s
    if t.size == 0:
        raise InputError("no observations")
    t0, t1 = (t.min(), t.max()) if t_span_s is None else t_span_s
    nodes = SplineNodes(float(t0), float(t1), float(node_interval_s))
    if np.any(obs.band >= cam.n_bands):
        raise InputError(f"band index ≥ the camera's {cam.n_bands} bands")
    rpy = obs.rpy_nav_rad
    o, d = cam.camera().rays_at(
        obs.xy_px, obs.band, obs.xyz_nav_m, R_from_rpy(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    )
    P0 = intersect_two_rays(obs.point, o, d, n_points)
    p = _parameters(P0, nodes, cam, gcp_index, gcp_xyz_m, node_prior_mean)
    # a band without observations (a small block, a band the matcher found nothing in) cannot
    # determine its principal distance: it keeps its a-priori value, and the summary names it
    # (a small --scale had stopped on "no observation depends on c_mm[4]")
    unseen = np.setdiff1d(np.arange(cam.n_bands), np.unique(obs.band))
    if unseen.size:
        p.fix(BLOCK_NAMES["c"], index=unseen)
    timed = _time_residual(obs, cam, P0) if y_as_time else {}
    blk = PushbroomLines(
        obs.point,
        obs.band,
        t,
        obs.xy_px,
        obs.xyz_nav_m,
        obs.rpy_nav_rad,
        nodes,
        cam.pixel_mm,
        cam.sigma_obs_px,
        cam.x0_mm,
        cam.y0_mm,
        **timed,
    )
    return p, [blk], nodes


def solve(
    params,
    blocks,
    *,
    reject_k: float | None = REJECT_K,
    ftol: float = FTOL,
    progress=None,
    keep_jacobian: bool = False,
    raise_on_failure: bool = True,
    **overrides,
):
    """Adjust a problem of :func:`build_problem` with 002's solver settings (002 §3.4: outliers
    rejected at every iteration) and :data:`CHORD_END`; the one place they are spelled.
    ``overrides``: other :class:`~hsgeo.adjust.SolverOptions` fields (e.g.
    ``robust_start="cauchy"``).

    Returns
    -------
    hsgeo.adjust.AdjustmentResult

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    from hsgeo.adjust import adjust

    return adjust(
        params,
        blocks,
        reject_k=reject_k,
        ftol=ftol,
        progress=progress,
        reject_every_iteration=True,  # 002 §3.4
        # a tie point its rays do not determine is left out and named, not a reason to stop
        # (lp-observations --seed 6062 had stopped on one such point)
        drop_undetermined_points=True,
        keep_jacobian=keep_jacobian,
        raise_on_failure=raise_on_failure,
        **{"chord_end": CHORD_END, **overrides},
    )


# ----------------------------------------------------------------------------------------------
# The in-memory core: inputs and options -> one result (the CLI and hsgeo.reproduce both call it)
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PushbroomInputs:
    """What one LP bundle adjustment is given.

    Attributes
    ----------
    observations : PushbroomObservations
        The image observations and the GNSS/INS poses (and rates) at their line times.
    n_points : int
        Number of tie points (``observations.point`` indexes them).
    camera : CameraPrior
    gcp_index, gcp_xyz_m : ndarray, optional
        Rows of the points that are GCPs and their surveyed coordinates; None: no GCPs.
    point_ids : ndarray, optional
        The user's point ids, in point order (for the report; default ``0 … n_points − 1``).
    t_span_s : (float, float), optional
        Time span of the trajectory-correction nodes (default: the observations').
    node_prior_mean : (n_nodes, 6) ndarray, optional
        Prior mean of the node corrections (default zero).
    """

    observations: PushbroomObservations
    n_points: int
    camera: CameraPrior
    gcp_index: np.ndarray | None = None
    gcp_xyz_m: np.ndarray | None = None
    point_ids: np.ndarray | None = None
    t_span_s: tuple | None = None
    node_prior_mean: np.ndarray | None = None


@dataclass(frozen=True)
class PushbroomOptions:
    """How to adjust: 002's settings (:data:`REJECT_K`, :data:`FTOL`, :data:`Y_AS_TIME`) by
    default, and the node interval of 002 §4.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    node_interval_s: float = 10.0
    reject_k: float | None = REJECT_K
    ftol: float = FTOL
    y_as_time: bool = Y_AS_TIME
    keep_jacobian: bool = False
    raise_on_failure: bool = True


@dataclass(frozen=True)
class PushbroomResult:
    """One LP bundle adjustment: the engine's result, the problem it solved and a summary.

    Attributes
    ----------
    result : hsgeo.adjust.AdjustmentResult
    params : Parameters
        The problem's parameters as set up (initial values and priors).
    blocks : list of ResidualBlock
    nodes : SplineNodes
    point_ids : ndarray
    n_observations_2d : int
    node_interval_s : float
    setup_seconds : float
    """

    result: object
    params: Parameters
    blocks: list
    nodes: SplineNodes
    point_ids: np.ndarray
    n_observations_2d: int
    node_interval_s: float
    setup_seconds: float

    def to_dict(self) -> dict:
        """Counts, σ0, the camera parameters with σ̂, nodes, points and the fit verdict
        (:func:`summary`).
        """
        return summary(
            self.result, self.nodes, self.point_ids, self.n_observations_2d, self.node_interval_s
        )


def adjust_pushbroom(
    inputs: PushbroomInputs, options: PushbroomOptions = PushbroomOptions(), *, progress=None
) -> PushbroomResult:
    """Set up (:func:`build_problem`) and adjust (:func:`solve`) one LP bundle adjustment.

    ``hsgeo adjust-pushbroom`` (:func:`adjust_files`) and ``hsgeo reproduce pushbroom-ba`` both
    call this, so 002's solver settings and the set-up exist once.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    import time

    t0 = time.perf_counter()
    obs = inputs.observations
    p, blocks, nodes = build_problem(
        obs,
        inputs.n_points,
        inputs.camera,
        node_interval_s=options.node_interval_s,
        gcp_index=inputs.gcp_index,
        gcp_xyz_m=inputs.gcp_xyz_m,
        t_span_s=inputs.t_span_s,
        node_prior_mean=inputs.node_prior_mean,
        y_as_time=options.y_as_time,
    )
    setup_s = time.perf_counter() - t0
    res = solve(
        p,
        blocks,
        reject_k=options.reject_k,
        ftol=options.ftol,
        progress=progress,
        keep_jacobian=options.keep_jacobian,
        raise_on_failure=options.raise_on_failure,
    )
    ids = np.arange(inputs.n_points) if inputs.point_ids is None else inputs.point_ids
    return PushbroomResult(
        res, p, blocks, nodes, ids, int(obs.point.size), options.node_interval_s, setup_s
    )


# ----------------------------------------------------------------------------------------------
# Files: ``hsgeo adjust-pushbroom``
# ----------------------------------------------------------------------------------------------
#: Required columns of the input tables (CSV or Parquet).
OBS_COLUMNS = ("point_id", "band", "t_s", "x_px", "y_px")
GCP_COLUMNS = ("point_id", "E_m", "N_m", "H_m")


def read_camera(path, need_gcp_sigma: bool = True) -> CameraPrior:
    """Camera and GNSS/INS priors from a sensor file of model ``pushbroom`` (or the former
    ``[camera]`` file): the camera as :func:`hsgeo.io.read_sensor` reads it (per-band c,
    distortion, boresight and lever arm: the adjustment starts from them), the σ keys and
    tables (``sigma_lever_m``, ``[gnss_ins]``, ``[observations]``, ``[gcp]``) as given. Every
    σ is required (``[gcp] sigma_m`` only with ``need_gcp_sigma``): a missing one is refused by
    name, as no paper's σ is the right default for a user's instruments.
    """
    from hsgeo.io.sensor_file import read_sensor, read_sensor_tables

    name, tables, table = read_sensor_tables(path)
    if name != "pushbroom":
        raise InputError(
            f"camera file {path}: model {name!r}; hsgeo adjust-pushbroom adjusts the 002 "
            'pushbroom camera: give a sensor file with model = "pushbroom"'
        )
    camera = read_sensor(path)
    cam, nav = tables["sensor"], tables["gnss_ins"]
    c = tuple(float(v) for v in camera.c_mm)
    kw = {
        "n_bands": len(c),
        "pixel_mm": camera.pixel_mm,
        "c_mm": cam["c_mm"],
        "x0_mm": camera.x0_mm,
        "y0_mm": camera.y0_mm,
        "lever_arm_m": tuple(camera.lever_arm_m),
        "c_band_mm": None if all(v == cam["c_mm"] for v in c) else c,
        "distortion": tuple(camera.distortion),
        "boresight_rad": tuple(camera.boresight_rad),
    }
    # the a-priori σ are the user's instruments' (a paper's values are never a default here)
    obs, gcp = tables["observations"], tables["gcp"]
    wanted = [  # (table, key, the table's values, what it is)
        ("camera", "sigma_lever_m", cam, "σ of the measured lever arm, m"),
        ("gnss_ins", "sigma_pos_m", nav, "σ of the GNSS/INS positions E, N, H, m"),
        ("gnss_ins", "sigma_att_deg", nav, "σ of the GNSS/INS roll, pitch, yaw, degrees"),
        ("observations", "sigma_px", obs, "σ of an image coordinate, px"),
    ]
    if need_gcp_sigma:
        wanted.append(("gcp", "sigma_m", gcp, "σ of a GCP coordinate, m"))
    missing = [f"[{t}] {k} ({what})" for t, k, have, what in wanted if k not in have]
    if missing:
        raise InputError(
            f"camera file {path}: no a-priori σ for " + "; ".join(missing) + ". hsgeo "
            "adjust-pushbroom weights the navigation, the lever arm, the image observations and "
            "the GCPs by these: add each key under its table with your instruments' values "
            "(the GNSS/INS's post-processing report, the matcher's precision, the survey's)"
        )
    kw.update(
        sigma_lever_m=cam["sigma_lever_m"],
        sigma_pos_m=nav["sigma_pos_m"],
        sigma_att_rad=tuple(np.deg2rad(nav["sigma_att_deg"])),
        sigma_obs_px=obs["sigma_px"],
        sigma_gcp_m=gcp.get("sigma_m", np.nan),  # used only with GCPs
    )
    return CameraPrior(**kw)


def adjust_files(
    observations,
    trajectory,
    camera,
    gcp=None,
    *,
    node_interval_s: float = 10.0,
    reject_k: float | None = REJECT_K,
    progress=None,
    y_as_time: bool = Y_AS_TIME,
    max_nav_gap_s: float = 1.0,
    nav_crs=None,
    site=None,
) -> PushbroomResult:
    """Adjust a user's pushbroom observations (``hsgeo adjust-pushbroom``).

    Parameters
    ----------
    observations : path
        CSV or Parquet with ``point_id, band, t_s, x_px, y_px``: tie point, band index
        (0-based), exposure time of the line (s, the navigation's time scale), image
        coordinates in pixels from the line centre (x along the line, y across it; 0 = the line).
    trajectory : path
        The navigation file of every command (:mod:`hsgeo.io.navigation`): CSV or Parquet with
        ``t_s, E_m, N_m, U_m, roll_deg, pitch_deg, heading_deg``, the GNSS/INS solution
        (positions of the platform reference point east-north-up; attitude of the body, x
        forward, y right, z down, in north-east-down). It is interpolated linearly to the line
        times and converted to the model's platform angles
        (:func:`hsgeo.trajectory.platform_rpy_from_rph`); its velocity and angular rates (for
        the time residual, ``y_as_time``) are central differences of that interpolation.
    camera : path
        The sensor file (:func:`hsgeo.io.read_sensor`, model ``pushbroom``, or the former
        ``[camera]`` table): ``n_bands, pixel_mm, c_mm, c_band_mm, x0_mm, y0_mm, distortion,
        boresight_deg, lever_arm_m, sigma_lever_m`` (the adjustment starts from the file's
        camera), ``[gnss_ins] sigma_pos_m = [E, N, H], sigma_att_deg = [roll, pitch, yaw]``,
        ``[observations] sigma_px``, ``[gcp] sigma_m``.
    gcp : path, optional
        CSV or Parquet with ``point_id, E_m, N_m, H_m`` (points of the observation table).
    max_nav_gap_s : float
        The longest gap between navigation records interpolated across (s).
    nav_crs : str or int, optional
        The CRS of a navigation as delivered (geodetic CSV or Parquet, Applanix SBET; see
        :func:`hsgeo.io.navigation.read_line_navigation`): ``--nav-crs``.
    site : (lat_deg, lon_deg[, h_m]), optional
        The origin of the local frame of the GCPs (``--site``); required with a geodetic
        navigation and ``gcp``.

    Returns
    -------
    PushbroomResult
        The in-memory core's result (:func:`adjust_pushbroom`): ``to_dict()`` gives the
        summary, the camera parameters with σ̂, the node corrections, the adjusted points and
        ``fit``, the plausibility verdict of :func:`fit_verdict` (``hsgeo adjust-pushbroom``
        exits 2 on a poor fit unless ``--accept-poor-fit``); ``result`` the engine's.
    """
    from hsgeo.io.navigation import read_line_navigation

    obs_df = read_table(  # the files in this order: the first bad one is reported
        observations,
        OBS_COLUMNS,
        "observation",
        text_columns=("point_id",),
        integer_columns=("band",),
    )
    traj, _ = read_line_navigation(
        trajectory, crs=nav_crs, site=site, frame_needed_by="--gcp" if gcp is not None else None
    )
    cam = read_camera(camera, need_gcp_sigma=gcp is not None)
    obs, ids = _observations(obs_df, observations, trajectory, traj, cam, max_nav_gap_s)
    _check_node_memory(obs.t_s, node_interval_s)
    gi = gx = None
    if gcp is not None:
        gi, gx = _read_gcp(gcp, ids, observations, trajectory, traj)
    inputs = PushbroomInputs(obs, ids.size, cam, gcp_index=gi, gcp_xyz_m=gx, point_ids=ids)
    options = PushbroomOptions(
        node_interval_s=node_interval_s,
        reject_k=reject_k,
        y_as_time=y_as_time,
        raise_on_failure=False,  # no convergence is a verdict of the fit (fit_verdict)
    )
    return adjust_pushbroom(inputs, options, progress=progress)


def observations_from_table(
    obs_df,
    traj,
    cam: CameraPrior,
    *,
    source: str = "observation table",
    nav: str = "navigation",
    max_nav_gap_s: float = 1.0,
):
    """An observation table (``point_id, band, t_s, x_px, y_px``, a DataFrame) with the
    navigation at its line times: ``(PushbroomObservations, point_ids)``.

    The one path from a table to the adjustment's observations: ``hsgeo adjust-pushbroom``
    (:func:`adjust_files`) and the LP observations retrieved from pixels
    (:func:`hsgeo.workflows.lp_observations.to_pushbroom_inputs`) both go through it, with its
    checks (bands of the camera, points seen twice, the navigation covering the lines).
    ``source`` and ``nav`` name the table and the navigation in messages.
    """
    return _observations(obs_df, source, nav, traj, cam, max_nav_gap_s)


def _observations(obs_df, observations, trajectory, traj, cam: CameraPrior, max_nav_gap_s):
    """The observation table with the navigation at its line times: ``(obs, point_ids)``."""
    from hsgeo.trajectory import platform_rpy_from_rph, platform_rpy_rate_from_rph_rate
    from hsgeo.validate import check_navigation_covers, check_range

    check_range(
        obs_df["band"].to_numpy(),
        0,
        cam.n_bands - 1,
        f"observation file {str(observations)!r}, column band",
        where=lambda i: f"row {i + 1}",
        remedy=f"bands are numbered 0 to n_bands - 1 (n_bands = {cam.n_bands} in the camera file)",
    )
    ids, point = np.unique(obs_df["point_id"].to_numpy(), return_inverse=True)
    once = ids[np.bincount(point, minlength=ids.size) < 2]
    if once.size:
        raise InputError(
            f"observation file {str(observations)!r}: point_id(s) {', '.join(once[:5])}"
            + (f" (and {once.size - 5} more)" if once.size > 5 else "")
            + " observed in one row only; a tie point needs two rays: add its other "
            "observations or delete the row"
        )
    t = obs_df["t_s"].to_numpy(dtype=float)
    check_navigation_covers(
        traj.t_s,
        t,
        nav=repr(str(trajectory)),
        used=f"the observations' t_s in {str(observations)!r}",
        max_gap_s=max_nav_gap_s,
    )
    xyz, rph = traj.pose(t)
    vel, rph_rate = traj.rates(t)
    obs = PushbroomObservations(
        point=point.astype(np.int64),
        band=obs_df["band"].to_numpy().astype(np.int64),
        t_s=t,
        xy_px=obs_df[["x_px", "y_px"]].to_numpy(dtype=float),
        xyz_nav_m=xyz,
        rpy_nav_rad=platform_rpy_from_rph(rph),  # the model's ENU platform angles (002)
        xyz_rate_nav_m_s=vel,
        rpy_rate_nav_rad_s=platform_rpy_rate_from_rph_rate(rph_rate),
    )
    return obs, ids


def _read_gcp(gcp, ids, observations, trajectory, traj):
    """The GCP table: rows of the points that are GCPs and their coordinates ``(gi, gx)``."""
    g = read_table(gcp, GCP_COLUMNS, "GCP", text_columns=("point_id",), unique=("point_id",))
    pos = {v: i for i, v in enumerate(ids)}
    unknown = [v for v in g["point_id"] if v not in pos]
    if unknown:
        raise InputError(
            f"GCP file {str(gcp)!r}: point_id(s) {', '.join(map(str, unknown[:5]))} are not "
            f"in the observation file {str(observations)!r}; correct the id or delete the row"
        )
    gi = np.array([pos[v] for v in g["point_id"]])
    gx = g[["E_m", "N_m", "H_m"]].to_numpy(dtype=float)
    low = float(traj.xyz_m[:, 2].min())
    high = int(np.argmax(gx[:, 2]))
    if gx[high, 2] >= low:
        raise InputError(
            f"GCP file {str(gcp)!r}: point_id {g['point_id'].iloc[high]} at H_m = "
            f"{gx[high, 2]:.6g} m is not below the aircraft (U_m down to {low:.6g} m in the "
            f"navigation file {str(trajectory)!r}); are both heights in metres, in one system?"
        )
    return gi, gx


def _check_node_memory(t_s, node_interval_s: float) -> None:
    """The trajectory corrections' nodes fit in memory: their 6 unknowns each meet in the
    reduced normal matrix, dense (8 bytes a cell, and its factor beside it).
    """
    from hsgeo.trajectory import SplineNodes
    from hsgeo.validate import check_memory

    span = float(np.max(t_s) - np.min(t_s))
    n_nodes = SplineNodes(float(np.min(t_s)), float(np.max(t_s)), float(node_interval_s)).n_nodes
    n_c = 6 * n_nodes
    check_memory(
        2 * 8.0 * float(n_c) ** 2,
        f"--node-interval {node_interval_s:g} s over the observations' {span:.6g} s "
        f"({n_nodes} nodes, a reduced normal matrix of {n_c} x {n_c})",
        "use a longer --node-interval (002 §4: 10 s)",
    )


def summary(res, nodes, point_ids, n_observations_2d: int, node_interval_s: float) -> dict:
    """What ``hsgeo adjust-pushbroom`` reports of a solve: counts, σ0, the camera parameters
    (:data:`REPORTED_PARAMETERS`) with σ̂, the node corrections, the points and the fit verdict.
    """
    ids, n_obs = point_ids, n_observations_2d
    out = {
        "converged": res.converged,
        "iterations": res.iterations,
        "sigma0": res.sigma0,
        "n_observations_2d": n_obs,
        "n_points": int(ids.size),
        "n_unknowns": int(res.n_unknowns),
        "rejected": int(res.outliers(0).sum()),
        "solver_seconds": res.seconds,
        "node_interval_s": node_interval_s,
        "parameters": {},
    }
    for name, _, f in REPORTED_PARAMETERS:
        key = name.replace("_rad", "_deg")
        out["parameters"][key] = {
            "value": (res.value(name) * f).tolist(),
            "sigma": (res.sigma(name) * f).tolist(),
        }
    out["nodes"] = {
        "t_s": nodes.t_nodes_s.tolist(),
        "value": res.value("nodes").tolist(),
        "sigma": res.sigma("nodes").tolist(),
        "columns": list(res.params["nodes"].columns),
    }
    out["points"] = {"point_id": ids.tolist(), "xyz_m": res.value("points_m").tolist()}
    c_free = np.asarray(res.params[BLOCK_NAMES["c"]].free).ravel()
    out["not_estimated"] = {
        "parameters": [f"{BLOCK_NAMES['c']}[{k}]" for k in np.flatnonzero(~c_free)],
        "reason": "no observation in the band: the a-priori principal distance is kept",
    }
    dropped = list(getattr(res, "dropped_points", []))
    g = res._blocks[0].group_size
    rows = res._dropped_rows[0] if dropped and res._dropped_rows is not None else None
    out["dropped_points"] = {
        "point_id": ids[dropped].tolist(),
        "n_observations_2d": 0 if rows is None else int(rows.reshape(-1, g)[:, 0].sum()),
        "reason": "not determined by their observations (too few or degenerate rays): held at "
        "their initial values, their observations left out",
    }
    und = list(getattr(res, "undetermined_parameters", []))
    out["undetermined_parameters"] = {
        "parameters": und,
        "reason": "the normal matrix at the solution does not determine them (a datum defect "
        "that appeared during the iterations, e.g. every observation of a band rejected): "
        "their σ is null, the σ of the rest is that of the estimable part",
    }
    out["fit"] = fit_verdict(res, n_obs)
    return out


#: A fit is implausible when σ0 is off by more than this factor (either way): the a-priori σ,
#: the units or the model are wrong, far beyond the χ² spread of σ0 at these sizes.
POOR_FIT_SIGMA0_FACTOR = 3.0
#: ... or when more than this share of the observations was rejected as outliers.
POOR_FIT_REJECTED_SHARE = 0.05


def fit_verdict(res, n_observations_2d: int) -> dict:
    """Is the adjustment plausible? σ0, its χ² interval, the rejected share and a verdict.

    Parameters
    ----------
    res : AdjustmentResult
    n_observations_2d : int
        Image observations (rows of the observation table).

    Returns
    -------
    dict
        ``sigma0``, ``sigma0_interval_99`` (two-sided 99 % interval under the model),
        ``rejected_share``, ``verdict`` (``"ok"`` or ``"poor"``) and ``reasons``: one sentence
        per problem, in the terms of the input files; ``warnings``: what was estimated only in
        part (parameters the data do not determine at the solution).
    """
    s0 = float(res.sigma0)
    share = float(res.outliers(0).sum()) / max(1, n_observations_2d)
    reasons = []
    if not res.converged:
        reasons.append(f"the adjustment did not converge in {res.iterations} iterations")
    if not np.isfinite(s0):
        reasons.append("σ0 is not finite: the observations do not determine the unknowns")
    elif s0 > POOR_FIT_SIGMA0_FACTOR or s0 < 1 / POOR_FIT_SIGMA0_FACTOR:
        reasons.append(
            f"σ0 = {s0:.3g}: the model does not fit the data by a factor of {max(s0, 1 / s0):.3g};"
            " the likely causes: a unit — image coordinates x_px, y_px not in pixels (in mm?),"
            " navigation angles not in degrees (roll_deg, pitch_deg, heading_deg), the camera's"
            " c_mm, pixel_mm or lever_arm_m in"
            " another unit — or an a-priori σ of the camera file that is not realistic"
        )
    if share > POOR_FIT_REJECTED_SHARE:
        reasons.append(
            f"{100 * share:.1f} % of the observations were rejected as outliers (more than "
            f"{100 * POOR_FIT_REJECTED_SHARE:.0f} %); the likely causes: a wrong GCP or point_id in"
            " the input tables, or observations in another unit than pixels"
        )
    warnings = []
    und = list(getattr(res, "undetermined_parameters", []))
    if und:
        names = ", ".join(und[:8]) + (f", … ({len(und)} in all)" if len(und) > 8 else "")
        warnings.append(
            f"the data do not determine {names} at the solution: their σ is not given, the σ "
            "of the rest is that of the estimable part; add observations or GCPs that see "
            "them, or fix them in the camera file"
        )
    return {
        "sigma0": s0,
        "sigma0_interval_99": list(res.chi2_interval(0.01)) if res.dof > 0 else None,
        "warnings": warnings,
        "rejected_share": share,
        "verdict": "poor" if reasons else "ok",
        "reasons": reasons,
    }
