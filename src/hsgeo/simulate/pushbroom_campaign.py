"""The aerial HySpex VNIR-1800 campaign of 002 §4, simulated with its published values as truth.

Geometry (002 §4, Fig. 5): a 600 m × 600 m area; 8 flight lines at 1875 m AGL and 4 at 2500 m
AGL (the 2500 m ones over the centre), each flown twice with opposite headings (24 strips), at
67 m/s, 200 lines per second, 1800 px of 6.5 µm, principal distance ≈ 40 mm (FoV 16.6°), seven
bands ~77 nm apart. One continuous trajectory, turns included (the turns carry no observations;
their spline nodes are held by the GNSS/INS priors).

Truth and errors:

* the platform attitude has high-frequency motion of a gyro-stabilised mount, which the INS
  records exactly (it is in both the truth and the navigation solution);
* the navigation solution differs from the truth by the error of a post-processed GNSS/INS
  solution (``trajectory_error="gauss-markov"``, the default): one first-order Gauss–Markov
  process per axis (E, N, H, roll, pitch, yaw), stationary, with the σ of 002 §4 for the
  positions (< 1.3 cm E/N, < 2.0 cm H) and of the POS-AV 510 class for the attitude (heading
  worst), and correlation times from seconds to minutes (:func:`gauss_markov`). It is sampled at
  10 Hz and interpolated by a cubic spline between the samples (the INS carries the solution
  smoothly between GNSS epochs), so the navigation rates are its derivative. This is *not* the
  estimator's model (a B-spline with nodes every 10 s): the node corrections have no exact
  true value, and :attr:`CampaignTruth.values` holds in their place the best least-squares
  spline fit (:func:`spline_fit`) of the true error at the campaign's node interval over the
  imaged parts of the flight (the strips; the turns carry no observations).
  ``trajectory_error="spline"`` makes the error a local cubic B-spline with nodes every 10 s
  whose node values are drawn from the same σ (the estimator's own model, for the noise-free
  and identifiability tests: there the node corrections have an exact true value);
* boresight of a few tenths of a degree, a lever arm measured to 2 cm, Brown K1, K2, P1, P2 of a
  few tenths of a pixel at the line's end, and one principal distance per band whose spread
  about the 40.3 mm mean is ≤ 11.8 µm (002 Fig. 8);
* tie points: ``round(113758 · scale)`` (002 §4), each seen in one band in ≥ 3 lines of ≥ 3
  different strips (on average 3.88 observations, 441587 / 113758, 002 §4), registered at the
  pixel centre (uniform error within the pixel) in the line closest in time to the point's
  crossing, plus 0.3 % gross errors;
* 17 reference squares (4 GCPs, 13 CPs, RTK σ ≈ 1 cm). The 4 GCPs are seen in every strip
  that covers them; the 13 check points, "tie points with known coordinates" (002 §4), are seen
  in as many strips as a tie point (``cp_rays="tie points"``, the default: ≥ 3, 3.88 on
  average) or, as the simulator once did, in every covering strip (``cp_rays="all strips"``, 14–20
  rays; one factor of the check-point factor table).

Beyond the paper (``scale > 1``, for the scaling benchmark): the block grows along track (north),
not by duplicating data. Tie points are drawn over ``area_m`` (east) × ``area_m · scale`` (north,
:func:`block_length_m`), ``round(113758 · scale)`` of them (the paper's density); every strip's
imaged length grows by ``area_m · (scale − 1)`` (so each strip still covers the whole block with
the same margins); the 24 strips, the turns and the per-point statistics (≥ 3 strips, 3.88
observations on average, 0.3 % gross errors) are the same. The 17 reference squares stay in
the central 600 m: the GNSS/INS priors hold the rest of the block. Up to ``scale = 1`` the
output is bit-identical to the simulator before it accepted ``scale > 1``.

``noise_free=True`` records the exact image coordinates of each line (no pixel quantisation,
no gross errors, and the GCP coordinates exact): the adjustment must then recover the truth to
numerical precision.
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

import numpy as np
from scipy.interpolate import CubicSpline

from hsgeo.errors import InputError
from hsgeo.sensors.pushbroom import (
    BETA0_CAM_FROM_PLATFORM,
    BLOCK_NAMES,
    PushbroomObservations,
    project,
)
from hsgeo.simulate.error_processes import (
    _imaged,
    gauss_markov,
    refraction_k,
    spline_fit,
)
from hsgeo.simulate.pushbroom_campaign_types import (
    CP_RAYS,
    TRAJECTORY_ERRORS,
    CampaignConfig,
    CampaignObservations,
    CampaignTruth,
)
from hsgeo.trajectory import SplineNodes

__all__ = [
    "block_length_m",
    "distortion_ripple_px",
    "noise_free_twin",
    "simulate",
    "DEG",
    "CHUNK_ROWS",
    "REFERENCE_EN_M",
]

DEG = np.pi / 180


def block_length_m(cfg: CampaignConfig, scale: float) -> float:
    """North extent of the simulated block, m.

    ``cfg.area_m`` up to scale 1, ``cfg.area_m · scale`` beyond (see :func:`simulate`).
    """
    return cfg.area_m * max(float(scale), 1.0)


def _strip_plan(cfg: CampaignConfig, extra_m: float = 0.0):
    """Strips in flight order: (t_start, t_end, east_m, agl_m, direction ±1).

    ``extra_m`` lengthens every strip's imaged part (m, half at each end): the block beyond
    the paper's 600 m (``scale > 1``).
    """
    L = 2 * (cfg.strip_half_length_m + extra_m / 2) / cfg.speed_m_s
    plan = []
    t = 0.0
    lines = [(e, cfg.agl_low_m) for e in cfg.lines_low_east_m] + [
        (e, cfg.agl_high_m) for e in cfg.lines_high_east_m
    ]
    for e, h in lines:
        for direction in (+1, -1):
            plan.append((t, t + L, e, h, direction))
            t += L + cfg.turn_s
    return plan


#: Rows per chunk of the simulator's row-wise work (the Newton search of the line times):
#: bounds its temporaries (≈ 1 kB per row) at any scale.
CHUNK_ROWS = 1 << 18


def distortion_ripple_px(x_px, cfg: CampaignConfig) -> np.ndarray:
    """The distortion residual outside 002 eq. (3) at image x (px from the principal point).

    ``a · (sin(2π k x / n_px) − p(x))`` with ``a = cfg.distortion_ripple_px`` and ``k`` periods
    over the ``n_px`` pixels of the line, where ``p`` is the least-squares fit of the sine over
    the line by what the estimator can represent along it (a constant: the roll; x: the
    principal distance; x², x³, x⁵: the Brown terms P2, K1, K2 of 002 eq. (3) at y = 0). The
    ripple is thus the part of a lens ripple that no parameter of the model absorbs: it stays
    in the residuals and moves what they move, without redefining the camera's true parameters.
    """
    half = cfg.pixels_per_line / 2
    k = cfg.distortion_ripple_periods / cfg.pixels_per_line

    def basis(u):
        return np.stack([np.ones_like(u), u, u**2, u**3, u**5], axis=-1)

    grid = np.linspace(-1.0, 1.0, 2001)
    coef = np.linalg.lstsq(basis(grid), np.sin(2 * np.pi * k * half * grid), rcond=None)[0]
    x = np.asarray(x_px, dtype=np.float64)
    return cfg.distortion_ripple_px * (np.sin(2 * np.pi * k * x) - basis(x / half) @ coef)


def _row_chunks(m: int):
    """Slices of ``range(m)`` of at most :data:`CHUNK_ROWS` rows."""
    return [slice(a, min(a + CHUNK_ROWS, m)) for a in range(0, m, CHUNK_ROWS)]


def _mount_motion(t, amp):
    """High-frequency residual attitude of the stabilised mount (recorded by the INS)."""
    roll = amp * (0.6 * np.sin(2 * np.pi * 0.7 * t) + 0.4 * np.sin(2 * np.pi * 1.9 * t + 1.0))
    pitch = amp * (0.5 * np.sin(2 * np.pi * 0.5 * t + 2.0) + 0.3 * np.sin(2 * np.pi * 2.3 * t))
    yaw = amp * 0.5 * np.sin(2 * np.pi * 0.3 * t + 0.5)
    return np.column_stack([roll, pitch, yaw])


def _mount_motion_rate(t, amp):
    """Time derivative of :func:`_mount_motion`, rad/s."""
    w = 2 * np.pi
    roll = amp * (0.6 * w * 0.7 * np.cos(w * 0.7 * t) + 0.4 * w * 1.9 * np.cos(w * 1.9 * t + 1.0))
    pitch = amp * (0.5 * w * 0.5 * np.cos(w * 0.5 * t + 2.0) + 0.3 * w * 2.3 * np.cos(w * 2.3 * t))
    yaw = amp * 0.5 * w * 0.3 * np.cos(w * 0.3 * t + 0.5)
    return np.column_stack([roll, pitch, yaw])


def _true_pose(plan, strip, t, amp, speed_m_s):
    """True platform position and attitude at times ``t`` within strips ``strip``."""
    t0 = np.array([p[0] for p in plan])[strip]
    t1 = np.array([p[1] for p in plan])[strip]
    east = np.array([p[2] for p in plan])[strip]
    agl = np.array([p[3] for p in plan])[strip]
    dirn = np.array([p[4] for p in plan], dtype=float)[strip]
    tc = 0.5 * (t0 + t1)
    north = dirn * (t - tc) * speed_m_s
    xyz = np.column_stack([east, north, agl])
    yaw = np.where(dirn > 0, np.pi / 2, -np.pi / 2)  # ENU yaw: platform x → north or south
    rpy = _mount_motion(t, amp)
    rpy[:, 2] += yaw
    return xyz, rpy


#: The 17 reference squares' nominal east, north (m) about the block centre: 4 GCPs at the
#: corners, then the 13 check points (each moved by up to ±20 m at random).
REFERENCE_EN_M = (
    (-270, -270),
    (270, -270),
    (-270, 270),
    (270, 270),  # 4 GCPs (corners)
    (0, 0),
    (-150, 0),
    (150, 0),
    (0, -150),
    (0, 150),
    (-150, -150),
    (150, 150),
    (-150, 150),
    (150, -150),
    (-270, 0),
    (270, 0),
    (0, -270),
    (0, 270),
)


def _camera_truth(cfg: CampaignConfig, node_err) -> dict:
    """The true values of the node corrections, boresight, lever arm, distortion and the
    per-band principal distances (their spread about the mean: 002 Fig. 8).
    """
    names = BLOCK_NAMES
    return {
        names["nodes"]: node_err,
        names["boresight"]: np.array(cfg.boresight_deg) * DEG,
        names["lever_arm"]: np.array(cfg.lever_arm_m),
        names["distortion"]: np.array(cfg.distortion),
        names["c"]: cfg.c_mean_mm + (np.array(cfg.c_offsets_um) - np.mean(cfg.c_offsets_um)) * 1e-3,
    }


def _checked_config(scale, noise_free, cfg, trajectory_error) -> CampaignConfig:
    if not (np.isfinite(scale) and scale > 0):
        raise InputError(f"scale must be a positive number, got {scale!r}")
    cfg = cfg or CampaignConfig()
    if trajectory_error is not None:
        cfg = replace(cfg, trajectory_error=trajectory_error)
    if cfg.trajectory_error not in TRAJECTORY_ERRORS:
        raise InputError(
            f"trajectory_error must be one of {TRAJECTORY_ERRORS}, got {cfg.trajectory_error!r}"
        )
    if cfg.cp_rays not in CP_RAYS:
        raise InputError(f"cp_rays must be one of {CP_RAYS}, got {cfg.cp_rays!r}")
    if noise_free and cfg.trajectory_error != "spline":
        raise InputError(
            "noise_free=True needs trajectory_error='spline' (only the estimator's own model "
            "has exact node corrections)"
        )
    return cfg


def _trajectory_error(cfg: CampaignConfig, nodes, plan, t_end, rng):
    """The navigation error (true minus navigation): ``(node_err, err_t, err_x, nav_err)`` with
    ``nav_err(t, rate=False)`` the error (or its rate) at times ``t``.
    """
    sigma_nav = np.r_[cfg.sigma_pos_m, cfg.sigma_att_rad]
    if cfg.trajectory_error == "spline":
        node_err = rng.standard_normal((nodes.n_nodes, 6)) * sigma_nav
        err_t = err_x = None

        def nav_err(tt, rate=False):
            return (nodes.evaluate_rate if rate else nodes.evaluate)(node_err, tt)

    else:  # post-processed GNSS/INS errors: first-order Gauss–Markov per axis (002 §4 σ)
        n_s = int(np.ceil(t_end / cfg.error_sample_s)) + 2
        err_t = np.arange(n_s) * cfg.error_sample_s
        err_x = gauss_markov(
            n_s, cfg.error_sample_s, np.r_[cfg.tau_pos_s, cfg.tau_att_s], sigma_nav, rng
        )
        err_cs = CubicSpline(err_t, err_x, axis=0)
        t_fit = _imaged(plan, np.arange(0.0, t_end, 0.1))
        node_err = spline_fit(nodes, t_fit, err_cs(t_fit))
        err_rate_cs = err_cs.derivative()

        def nav_err(tt, rate=False):
            return (err_rate_cs if rate else err_cs)(tt)

    return node_err, err_t, err_x, nav_err


def _points(cfg: CampaignConfig, scale, length_m, nb, rng):
    """Reference squares first, then tie points: ``(P, is_ref, band_of_point)``."""
    half = cfg.area_m / 2
    n_tie = max(int(round(cfg.n_tie_points_full * scale)), 50)
    ref_en = np.array(REFERENCE_EN_M, dtype=float)
    ref_en += rng.uniform(-20, 20, ref_en.shape)
    # east × north: area_m × block_length_m (the same draws as a square block when scale ≤ 1)
    tie_en = rng.uniform([-half, -length_m / 2], [half, length_m / 2], (n_tie, 2))
    en = np.vstack([ref_en, tie_en])
    h = np.r_[rng.uniform(0, 2, len(ref_en)), rng.uniform(0, cfg.terrain_relief_m, n_tie)]
    P = np.column_stack([en, h])
    is_ref = np.zeros(len(P), bool)
    is_ref[: len(ref_en)] = True
    band_of_point = np.r_[rng.integers(0, 3, len(ref_en)), rng.integers(0, nb, n_tie)]
    return P, is_ref, band_of_point


def _strips_of_points(cfg: CampaignConfig, plan, P, is_ref, length_m, rng):
    """Which strips see which points: inside the swath (with a 3 % margin) and the strip;
    ``(pidx, strip)``, one row per observation.
    """
    en, h = P[:, :2], P[:, 2]
    n_pts = len(P)
    c_fov = cfg.c_nominal_mm
    half_line_mm = cfg.pixels_per_line / 2 * cfg.pixel_mm
    east = np.array([p[2] for p in plan])
    agl = np.array([p[3] for p in plan])
    half_swath = 0.97 * half_line_mm / c_fov * (agl - 0)  # m on the ground
    covers = np.abs(en[:, 0:1] - east[None, :]) < half_swath[None, :] * (
        1 - h[:, None] / agl[None, :]
    )
    covers &= np.abs(en[:, 1:2]) < cfg.strip_half_length_m + (length_m - cfg.area_m) / 2 - 30
    ncov = covers.sum(axis=1)
    if np.any(ncov < 3):
        raise InputError("simulated flight plan leaves points seen by fewer than 3 strips")
    extra = cfg.obs_per_point_mean - 3.0
    n_obs = np.where(is_ref, ncov, np.minimum(ncov, 3 + rng.poisson(extra, n_pts)))
    # the strips of each point: all for a reference square (the check points keep a subset at
    # the end, cp_rays="tie points"), a random n_obs of them for a tie point. One
    # Generator.choice per point (its draws cannot be vectorised without changing the random
    # stream); the candidates come from one np.nonzero (row-major, as flatnonzero per row did)
    cand_strip = np.nonzero(covers)[1]
    cand_end = np.cumsum(ncov)
    strip_list, n_choose = [], n_obs.tolist()
    for i, (b, e) in enumerate(zip((cand_end - ncov).tolist(), cand_end.tolist(), strict=True)):
        cand = cand_strip[b:e]
        strip_list.append(cand if is_ref[i] else rng.choice(cand, n_choose[i], replace=False))
    pidx = np.repeat(np.arange(n_pts), n_obs)
    strip = np.concatenate(strip_list)
    return pidx, strip


def _line_times(cfg: CampaignConfig, plan, true_xy, P, pidx, strip, is_ref, noise_free, rng):
    """The line that sees each point: Newton on the true y image coordinate in time, in chunks
    of rows (every operation is row-wise: the same bits as all rows at once, without the
    temporaries of millions of rows at scale > 1), then the key-point localisation error.

    Returns ``(t_line, loc)``: the registered line times and the localisation error (px).
    """
    m = pidx.size
    t0s = np.array([p[0] for p in plan])
    t1s = np.array([p[1] for p in plan])
    dirs = np.array([p[4] for p in plan], float)
    t = np.empty(m)
    deriv = np.empty(m)
    for rows in _row_chunks(m):
        tt = 0.5 * (t0s + t1s)[strip[rows]] + dirs[strip[rows]] * P[pidx[rows], 1] / cfg.speed_m_s
        for _ in range(6):
            xy, _ = true_xy(tt, rows)
            dt = 1e-3
            xy2, _ = true_xy(tt + dt, rows)
            deriv[rows] = (xy2[:, 1] - xy[:, 1]) / dt
            tt = tt - xy[:, 1] / deriv[rows]  # the line is y = 0 (pixel centre of the line)
        t[rows] = tt
    line_dt = 1.0 / cfg.line_rate_hz
    # key-point localisation error (ours, see CampaignConfig): x along the line, and in y an
    # error of the matched line, i.e. of the time
    sigma_kp = np.broadcast_to(np.asarray(cfg.sigma_keypoint_px, dtype=np.float64), (2,))
    loc = (0.0 if noise_free else sigma_kp) * rng.standard_normal((m, 2))
    ref_loc = rng.standard_normal((m, 2))  # drawn always: the same stream with or without
    if cfg.sigma_ref_image_px is not None and not noise_free:
        on_ref = is_ref[pidx]
        loc[on_ref] = cfg.sigma_ref_image_px * ref_loc[on_ref]
    t_loc = t - loc[:, 1] * cfg.pixel_mm / deriv
    t_line = np.round(t_loc / line_dt) * line_dt
    return t_line, loc


def _true_image_px(
    cfg: CampaignConfig, plan, true_xy, c_true_mm, P, pidx, strip, band, t_line, noise_free
):
    """The true image coordinates (px) at the registered line times, with refraction and the
    unmodelled distortion ripple.
    """
    m = pidx.size
    xy_true_mm = np.empty((m, 2))
    for rows in _row_chunks(m):
        xy_true_mm[rows], pc = true_xy(t_line[rows], rows)
        if np.any(pc[:, 2] <= 0):
            raise InputError("simulated points behind the camera: check the flight plan")
    if cfg.refraction:  # the ray bends: the image point moves radially outward
        agl_obs = np.array([p[3] for p in plan])[strip]
        k = refraction_k(agl_obs + cfg.terrain_asl_m, P[pidx, 2] + cfg.terrain_asl_m)
        d = xy_true_mm - np.array([cfg.x0_mm, cfg.y0_mm])
        r2 = np.sum(d**2, axis=1) / c_true_mm[band] ** 2
        xy_true_mm = xy_true_mm + (k * (1 + r2))[:, None] * d
    xy_true_px = xy_true_mm / cfg.pixel_mm
    if cfg.distortion_ripple_px and not noise_free:
        # a distortion residual outside 002 eq. (3) (not modelled): a ripple along the line
        xy_true_px[:, 0] += distortion_ripple_px(xy_true_px[:, 0], cfg)
    return xy_true_px


def _navigation(cfg: CampaignConfig, plan, strip, t_line, nav_err):
    """The navigation solution at the line times, truth minus the error (row-wise, in chunks),
    and its rates: ``(xyz_nav, rpy_nav, xyz_rate_nav, rpy_rate_nav)``.
    """
    m = t_line.size
    dirs = np.array([p[4] for p in plan], float)
    xyz_nav, rpy_nav, xyz_rate_nav, rpy_rate_nav = (np.empty((m, 3)) for _ in range(4))
    for rows in _row_chunks(m):
        tl = t_line[rows]
        xyz_true, rpy_true = _true_pose(plan, strip[rows], tl, cfg.mount_motion_rad, cfg.speed_m_s)
        delta = nav_err(tl)
        xyz_nav[rows] = xyz_true - delta[:, :3]
        rpy_nav[rows] = rpy_true - delta[:, 3:]
        # and its rates (a GNSS/INS solution gives velocity and angular rate): the observation
        # is a time, and its residual needs the image motion across the line (PushbroomLines)
        ddelta = nav_err(tl, rate=True)
        n = tl.size
        xyz_rate_true = np.column_stack(
            [np.zeros(n), dirs[strip[rows]] * cfg.speed_m_s, np.zeros(n)]
        )
        xyz_rate_nav[rows] = xyz_rate_true - ddelta[:, :3]
        rpy_rate_nav[rows] = _mount_motion_rate(tl, cfg.mount_motion_rad) - ddelta[:, 3:]
    return xyz_nav, rpy_nav, xyz_rate_nav, rpy_rate_nav


def _register(cfg: CampaignConfig, xy_true_px, loc, P, noise_free, rng):
    """What is recorded: ``(xy_obs, outlier, gcp_xyz)``, the image coordinates registered at the
    pixel centre along the line and in the line itself (y = 0), with gross errors, and the
    surveyed GCPs.
    """
    m = len(xy_true_px)
    if noise_free:
        return xy_true_px.copy(), np.zeros(m, bool), P[:4].copy()
    xy_obs = np.column_stack([np.floor(xy_true_px[:, 0] + loc[:, 0]) + 0.5, np.zeros(m)])
    outlier = rng.random(m) < cfg.outlier_share
    n_out = int(outlier.sum())
    mag = rng.uniform(3, 20, n_out) * rng.choice([-1, 1], n_out)
    comp = rng.integers(0, 2, n_out)
    xy_obs[np.flatnonzero(outlier), comp] += mag
    gcp_xyz = P[:4] + cfg.sigma_gcp_m * rng.standard_normal((4, 3))
    return xy_obs, outlier, gcp_xyz


def _check_point_rows(cfg: CampaignConfig, pidx, rng) -> np.ndarray:
    """``cp_rays="tie points"``: a check point keeps as many of its strips as a tie point sees
    (≥ 3, 3 + Poisson), drawn after every other draw: the tie points and the GCPs are those of
    "all strips". Returns the rows kept.
    """
    extra = cfg.obs_per_point_mean - 3.0
    keep = np.ones(pidx.size, bool)
    for i in range(4, len(REFERENCE_EN_M)):
        rows_i = np.flatnonzero(pidx == i)
        k = min(rows_i.size, 3 + int(rng.poisson(extra)))
        keep[rng.choice(rows_i, rows_i.size - k, replace=False)] = False
    return keep


def simulate(
    scale: float = 1.0,
    rng=0,
    noise_free: bool = False,
    cfg: CampaignConfig | None = None,
    trajectory_error: str | None = None,
) -> tuple[CampaignObservations, CampaignTruth]:
    """Simulate the campaign at ``scale`` (the share of the paper's tie points).

    Parameters
    ----------
    scale : float > 0
        Up to 1: thins the tie points (1.0: 113,758 as in 002 §4); the flight, the reference
        squares and the parameters do not change. Beyond 1: a block ``scale`` times longer
        along track, ``cfg.area_m`` (600 m) east × ``cfg.area_m · scale`` m north, with
        ``round(113758 · scale)`` tie points (the paper's density) and every strip
        ``cfg.area_m · (scale − 1)`` m longer; the 24 strips, the turns and the 17 reference
        squares (in the central 600 m) stay (see the module docstring). The per-observation
        work runs in chunks of :data:`CHUNK_ROWS` rows: memory grows with the outputs only.
    rng : int or numpy.random.Generator
    noise_free : bool
        Exact image coordinates, no outliers, exact GCPs (for the noise-free recovery test).
    cfg : CampaignConfig, optional
        Defaults to 002's values.
    trajectory_error : {"gauss-markov", "spline"}, optional
        Overrides ``cfg.trajectory_error``. The noise-free mode needs ``"spline"`` (only then
        do the node corrections have an exact value).

    Returns
    -------
    observations : CampaignObservations
        What the adjustment may use.
    truth : CampaignTruth
        What only :mod:`hsgeo.reproduce` compares with.
    """
    cfg = _checked_config(scale, noise_free, cfg, trajectory_error)
    rng = np.random.default_rng(rng)
    length_m = block_length_m(cfg, scale)
    plan = _strip_plan(cfg, extra_m=length_m - cfg.area_m)
    t_end = plan[-1][1]
    nodes = SplineNodes(0.0, t_end, cfg.node_interval_s)
    nb = len(cfg.c_offsets_um)
    names = BLOCK_NAMES

    # -- truth of the camera and the trajectory errors (true minus navigation)
    node_err, err_t, err_x, nav_err = _trajectory_error(cfg, nodes, plan, t_end, rng)
    truth = _camera_truth(cfg, node_err)
    lever_measured = truth[names["lever_arm"]] + (
        0.0 if noise_free else 1.0
    ) * cfg.sigma_lever_m * (rng.standard_normal(3))
    # -- points (reference squares first, then tie points) and the strips that see them
    P, is_ref, band_of_point = _points(cfg, scale, length_m, nb, rng)
    truth[names["points"]] = P
    n_pts = len(P)
    pidx, strip = _strips_of_points(cfg, plan, P, is_ref, length_m, rng)
    band = band_of_point[pidx]

    # truth = nav + δ(t): project with the true pose, zero corrections
    beta0 = BETA0_CAM_FROM_PLATFORM
    vals = dict(truth)
    vals[names["nodes"]] = np.zeros_like(node_err)

    def true_xy(tt, rows):
        xyz, rpy = _true_pose(plan, strip[rows], tt, cfg.mount_motion_rad, cfg.speed_m_s)
        return project(
            vals, names, nodes, tt, xyz, rpy, pidx[rows], band[rows], beta0, cfg.x0_mm, cfg.y0_mm
        )

    t_line, loc = _line_times(cfg, plan, true_xy, P, pidx, strip, is_ref, noise_free, rng)
    xy_true_px = _true_image_px(
        cfg, plan, true_xy, truth[names["c"]], P, pidx, strip, band, t_line, noise_free
    )
    xyz_nav, rpy_nav, xyz_rate_nav, rpy_rate_nav = _navigation(cfg, plan, strip, t_line, nav_err)
    xy_obs, outlier, gcp_xyz = _register(cfg, xy_true_px, loc, P, noise_free, rng)
    if cfg.cp_rays == "tie points":
        keep = _check_point_rows(cfg, pidx, rng)
        pidx, band, t_line, xy_obs, strip = (a[keep] for a in (pidx, band, t_line, xy_obs, strip))
        xyz_nav, rpy_nav = xyz_nav[keep], rpy_nav[keep]
        xyz_rate_nav, rpy_rate_nav = xyz_rate_nav[keep], rpy_rate_nav[keep]
        outlier, xy_true_px = outlier[keep], xy_true_px[keep]
    lines = PushbroomObservations(
        point=pidx,
        band=band,
        t_s=t_line,
        xy_px=xy_obs,
        xyz_nav_m=xyz_nav,
        rpy_nav_rad=rpy_nav,
        xyz_rate_nav_m_s=xyz_rate_nav,
        rpy_rate_nav_rad_s=rpy_rate_nav,
    )
    observations = CampaignObservations(
        lines=lines,
        n_points=n_pts,
        gcp_index=np.arange(4),
        gcp_xyz_m=gcp_xyz,
        lever_arm_m=lever_measured,
        node_prior_mean=node_err.copy() if noise_free else np.zeros_like(node_err),
        t_span_s=(0.0, float(t_end)),
    )
    truth = CampaignTruth(
        cfg=cfg,
        scale=scale,
        values=MappingProxyType(truth),
        nodes=nodes,
        strips=plan,
        strip=strip,
        cp_index=np.arange(4, 17),
        outlier=outlier,
        xy_true_px=xy_true_px,
        trajectory_error=cfg.trajectory_error,
        error_t_s=err_t,
        error_samples=err_x,
    )
    return observations, truth


def noise_free_twin(obs: CampaignObservations, truth: CampaignTruth) -> CampaignObservations:
    """The noise-free twin of a simulated campaign: the same observation rows (points, bands,
    strips, registered line times) with everything random taken out and the unmodelled
    effects (the distortion ripple, refraction) kept.

    The image coordinates are the true ones at the registered line times (no key-point error,
    no pixel quantisation, no gross errors), the navigation is the true pose (no GNSS/INS
    error: the node corrections' truth and prior mean are zero), the GCPs and the lever arm
    are exact. No random number is drawn: the geometry is that of ``obs`` bit for bit. Its
    adjustment gives the pseudo-true values of the parameters (what the misspecified model
    converges to on this geometry); with no unmodelled effect on, the truth itself.
    """
    cfg, names = truth.cfg, BLOCK_NAMES

    def no_error(tt, rate=False):
        return np.zeros((np.size(tt), 6))

    lines = obs.lines
    xyz, rpy, xyz_rate, rpy_rate = _navigation(cfg, truth.strips, truth.strip, lines.t_s, no_error)
    exact = PushbroomObservations(
        point=lines.point,
        band=lines.band,
        t_s=lines.t_s,
        xy_px=truth.xy_true_px.copy(),
        xyz_nav_m=xyz,
        rpy_nav_rad=rpy,
        xyz_rate_nav_m_s=xyz_rate,
        rpy_rate_nav_rad_s=rpy_rate,
    )
    return replace(
        obs,
        lines=exact,
        gcp_xyz_m=truth.values[names["points"]][obs.gcp_index].copy(),
        lever_arm_m=np.array(truth.values[names["lever_arm"]]),
        node_prior_mean=np.zeros_like(obs.node_prior_mean),
    )
