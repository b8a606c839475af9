"""The 002 campaign as LP image lines: a textured ground rendered through the true pushbroom camera.

The pixels behind :mod:`hsgeo.simulate.pushbroom_campaign`'s observations (002 §3.1, §4). The
flight is that campaign's (:func:`~hsgeo.simulate.pushbroom_campaign._strip_plan`: 24 strips,
8 lines at 1875 m and 4 at 2500 m AGL, each flown both ways, 67 m/s, 200 lines/s, 1800 px of
6.5 µm, c ≈ 40.3 mm, seven bands ~77 nm apart), and so are the camera's truth (per-band
principal distance, Brown terms, boresight, lever arm) and the GNSS/INS error (first-order
Gauss–Markov per axis, :func:`~hsgeo.simulate.pushbroom_campaign._trajectory_error`): both are
imported, not copied.

What is rendered
----------------
A procedural ground (:mod:`hsgeo.simulate._lp_ground`: fields with row patterns and multi-scale
texture, trees, roads, buildings a few metres high on a DSM, the seventeen 1.2 m white squares on
grass) is seen by every line of every strip through the **true** camera at the **true** pose at
the line's exposure time, which includes the high-frequency attitude motion of the stabilised
mount (:func:`~hsgeo.simulate.pushbroom_campaign._mount_motion`, amplitude
:attr:`LpConfig.mount_motion_rad`, tuned to 002's |δx|); per band with its own principal
distance: each pixel's ray (:meth:`hsgeo.sensors.pushbroom.PushbroomCamera.rays_at`) meets the
DSM and samples the blurred reflectance there (a Gaussian PSF of about a pixel's footprint, and
the motion blur of the line's integration along track, :attr:`LpConfig.motion_blur_m`). The
reflectance becomes DN with a band-dependent responsivity (vegetation close to saturation above
the red edge, 002 §5.3), shot and read noise, rounding and clipping at ``dn_max``.

The navigation a user has is the truth minus the Gauss–Markov error, sampled at every line time
of every strip (a :class:`~hsgeo.trajectory.Trajectory`; between strips it interpolates across
the turns, where no line is exposed). The a-priori camera is the nominal one (c = 40 mm in every
band, no distortion, zero boresight, the tape-measured lever arm, the calibrated principal point).

What the renderer shares with the estimator: the camera model itself (002 eq. (2)–(4), the
same :class:`~hsgeo.sensors.pushbroom.PushbroomCamera`) maps the ground to the pixels. What the
estimator does not model: the PSF and the motion blur, the DSM's occlusions, the texture's
effect on where a key point is found, the noise and saturation of the DN.

Scale
-----
``scale`` ∈ [0.05, 1] renders the central ``600·scale`` m × ``600·scale`` m of 002's 600 m × 600 m
block, i.e. the fraction ``scale²`` of the campaign's area and (within a few per cent) of its
pixels: every strip keeps 002's flight line, height and speed, and stores only the lines and
columns whose ground lies over the rendered block (``col0``; a strip that sees fewer than
:data:`MIN_COLUMNS` columns of it is left out). The seventeen squares keep 002's layout (4 GCPs
at the corners, 13 check points, :data:`~hsgeo.simulate.pushbroom_campaign.REFERENCE_EN_M`, each
moved by up to ±20 m) shrunk with the block, ``scale ·`` their positions, so that every scale
has its GCPs and check points.

Sizes and cost (measured 2026-11-27 on the shared 2-core machine under a load of 4–6 from other
sessions, so the times are upper bounds): at scale 1 the 24 strips hold 3.9·10⁸ pixel-bands
(1.56 GB as float32; peak memory 2.6 GB with the ground raster) and :func:`simulate` takes 92 s,
0.24 s per million pixel-bands (a strip alone renders at 0.17 s per million; the compiled
ray–DSM intersection and sampling, :mod:`hsgeo.simulate._lp_render`, is most of it, measured
between 0.04 and 0.13 s per million as the load varied). Work and memory scale with
``scale²``. The default, 0.35, renders 12 % of the campaign (5.3·10⁷ pixel-bands, 12 s, 0.7 GB),
leaving the chapter's detection, matching and adjustment most of its 3-minute budget.

References
----------
Jonassen et al. (2024), 002 §3.1, eq. (1), §4, §5.3.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io.lp_lines import LpStrip
from hsgeo.sensors.pushbroom import BLOCK_NAMES, PushbroomCamera
from hsgeo.simulate import as_rng
from hsgeo.simulate._lp_ground import make_ground
from hsgeo.simulate._lp_render import Ground, render_lines, render_rays
from hsgeo.simulate.pushbroom_campaign import (
    REFERENCE_EN_M,
    _camera_truth,
    _strip_plan,
    _trajectory_error,
    _true_pose,
)
from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
from hsgeo.trajectory import (
    R_BODY_FROM_PLATFORM,
    SplineNodes,
    Trajectory,
    rph_from_platform_rpy,
)

__all__ = ["LpConfig", "LpObservations", "LpTruth", "simulate", "MIN_COLUMNS", "MIN_SCALE", "DEG"]

DEG = np.pi / 180
#: The smallest scale: a 30 m block (the 17 squares, 1.2 m each, still ≥ 7 m apart).
MIN_SCALE = 0.05
#: A strip that sees fewer columns of the rendered block is left out.
MIN_COLUMNS = 64


@dataclass(frozen=True)
class LpConfig:
    """The LP campaign: 002's geometry (:attr:`campaign`) and the ground and radiometry (ours)."""

    campaign: CampaignConfig = field(default_factory=CampaignConfig)
    # TUNED (provenance "tuned"): amplitude of the mount's residual attitude motion (the shape
    # of pushbroom_campaign._mount_motion, sines of 0.3–2.3 Hz), chosen so that |δx| of 002
    # eq. (1) over the 200-line scenes of the whole block (scale 1, first line as reference)
    # has 002 §4's RMS of 0.91 px: 0.911 px (100 / 300 lines: 0.73 / 0.86 px). Its max is then
    # 2.46 px against 002's 4.43 px: a few sines have a smaller crest factor than a real
    # mount's motion.
    mount_motion_rad: float = 0.0108 * DEG
    # -- ground (ours)
    ground_cell_m: float = 0.15  # reflectance raster: half the 0.30 m GSD at 1875 m
    dsm_cell_m: float = 0.5
    ground_margin_m: float = 40.0  # raster beyond the block (boresight and attitude offsets)
    field_size_m: float = 70.0
    trees_per_km2: float = 1500.0
    roads_per_km: float = 3.0
    buildings_per_km2: float = 120.0
    building_height_m: tuple[float, ...] = (3.0, 8.0)  # "small height steps"
    terrain_relief_m: float = 4.0  # peak-to-peak of the terrain's long waves, roughly
    square_side_m: float = 1.2  # 002 §4
    # a Gaussian PSF of σ 0.15 m (FWHM 0.35 m ≈ the pixel footprint, 0.30–0.41 m at
    # 1875–2500 m AGL), applied to the ground raster
    psf_sigma_m: float = 0.15
    # motion blur: the ground passed during a line's integration (ours: integration = the line
    # period 1/200 s, time stamp at mid-exposure: 67 m/s / 200 = 0.335 m along track); 0: off.
    # Not in the pinhole model of 002 eq. (2) (002 §4 lists it among the unmodelled effects)
    motion_blur_m: float = 67.0 / 200.0
    # where in the exposure a line's time stamp lies: "middle" (the blur is centred on the
    # stamped pose and moves no key point) or "start" (the stamp is half an integration
    # earlier than the blur's centre: every line is rendered at t + ½·motion_blur_m/speed, a
    # shift along track of half the blur that the estimator, which takes t as the line's
    # time, does not model; it moves key points by half the blur, opposite for opposite
    # headings)
    exposure_stamp: str = "middle"
    # the principal point the operator has (x0, y0 of the a-priori camera, fixed in the
    # adjustment as 002's calibrated camera) is off the truth by a calibration error of this σ
    # per axis (ours: a tenth of a pixel); 0: the truth itself
    sigma_pp_calibration_px: float = 0.1
    # point targets (ours; for judging the matcher against features of known position,
    # :mod:`hsgeo.reproduce.lp_targets`): white squares of ``target_side_m`` (about two pixels)
    # on a jittered grid of this spacing over the block, on open ground (no roof within 1.5 m,
    # no reference square within 3 m), their positions drawn from a spawned stream so that the
    # campaign's other draws do not move; 0 (the default): none, the chapter's campaign
    target_spacing_m: float = 0.0
    target_side_m: float = 0.6
    # the point targets as survey targets are made (ours): a grey square of reflectance
    # ``target_reflectance`` (None: the white squares' spectrum, saturated in every band at
    # this radiometry) centred on a uniform dark square of side ``target_surround_m`` and
    # reflectance ``target_surround_reflectance`` (0: none, the target painted over the
    # texture). On the uniform surround the target's image is symmetric about its centre, so
    # a corner detector fires at the centre (its recorded reference), not where the texture
    # or a clipped plateau happens to put the highest score
    target_reflectance: float | None = None
    target_surround_m: float = 0.0
    target_surround_reflectance: float = 0.05
    # -- radiometry (ours): DN per unit reflectance per band, one integration time; vegetation
    # (ρ ≈ 0.48) reaches ~90 % of dn_max above the red edge (002 §5.3: "close to saturation")
    dn_max: float = 4095.0
    dn_per_reflectance: tuple[float, ...] = (5600.0, 6800.0, 7400.0, 7600.0, 7700.0, 7700.0, 7300.0)
    electrons_per_dn: float = 10.0  # shot noise: σ² = DN / electrons_per_dn (in DN²)
    read_noise_dn: float = 2.0


@dataclass(frozen=True)
class LpObservations:
    """What the operator of the simulated LP campaign has (nothing here is truth).

    Attributes
    ----------
    strips : list of LpStrip
        The image lines of each strip over the block (flight order).
    navigation : Trajectory
        GNSS/INS solution (truth minus the Gauss–Markov error) at every line time.
    camera : PushbroomCamera
        The a-priori camera (nominal c in every band, no distortion, zero boresight, the
        tape-measured lever arm).
    square_ids : tuple of str
        Names of the 17 reference squares (4 GCPs first).
    square_xyz_m : (17, 3) ndarray
        Their RTK centres (E, N, U, m; σ ``campaign.sigma_gcp_m``).
    gcp_ids : tuple of str
        The 4 corner squares used as GCPs.
    n_px_full : int
        Pixels of a full line (1800).
    scale : float
    """

    strips: list
    navigation: Trajectory
    camera: PushbroomCamera
    square_ids: tuple
    square_xyz_m: np.ndarray
    gcp_ids: tuple
    n_px_full: int
    scale: float


@dataclass(frozen=True)
class LpTruth:
    """The truth of one simulated LP campaign (for :mod:`hsgeo.reproduce` and tests only).

    Attributes
    ----------
    trajectory : Trajectory
        The true poses (with the mount's motion) at every line time.
    camera : PushbroomCamera
        The true camera (per-band c, distortion, boresight, lever arm).
    terrain : hsgeo.geocode.DemTerrain
        The DSM.
    square_xyz_m : (17, 3) ndarray
        True centres of the squares.
    ground : Ground
        The rendered ground (reflectance raster, materials, DSM).
    cfg : LpConfig
    plan : list of tuple
        The flight plan (t_start_s, t_end_s, east_m, agl_m, heading sign) of all 24 strips.
    strip_index : (n_strips,) int ndarray
        Row of :attr:`plan` of each rendered strip.
    nav_error : callable
        ``nav_error(t_s) -> (m, 6)``: true minus navigation (E, N, H m; platform roll, pitch,
        yaw rad).
    target_xyz_m : (t, 3) ndarray
        Centres of the point targets (E, N, and the DSM height there, m); none unless
        :attr:`LpConfig.target_spacing_m` > 0.
    """

    trajectory: Trajectory
    camera: PushbroomCamera
    terrain: object
    square_xyz_m: np.ndarray
    ground: Ground
    cfg: LpConfig
    plan: list
    strip_index: np.ndarray
    nav_error: object = None
    target_xyz_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def ground_points(self, t_s, x_px, band) -> np.ndarray:
        """True ground point (E, N, U, m) seen by pixels ``x_px`` of the lines at ``t_s``.

        The true ray (:meth:`PushbroomCamera.rays` of :attr:`camera` on :attr:`trajectory`)
        meets the DSM where the renderer sampled it: for judging a retrieved observation
        against its true image position (project the point with ``camera.project``).

        Parameters
        ----------
        t_s, x_px : (m,) array_like
            Line times (s) and x along the line (px from the full line's centre).
        band : int or (m,) int array_like

        Returns
        -------
        (m, 3) ndarray
        """
        x = np.atleast_1d(np.asarray(x_px, dtype=np.float64))
        o, d = self.camera.rays(
            np.column_stack([x, np.zeros(x.size)]), np.atleast_1d(t_s), self.trajectory, band
        )
        en, _ = render_rays(o, d, self.ground)
        return np.column_stack([en, self.terrain.height(en[:, 0], en[:, 1])])


def _line_times(cfg: CampaignConfig, plan) -> list[np.ndarray]:
    """Every line's exposure time of each strip: ``t_start + k / line_rate``."""
    out = []
    for t0, t1, *_ in plan:
        n = int(np.floor((t1 - t0) * cfg.line_rate_hz + 1e-9)) + 1
        out.append(t0 + np.arange(n) / cfg.line_rate_hz)
    return out


def _trajectories(cfg: LpConfig, plan, times, nav_err):
    """True and navigation :class:`Trajectory` over every line of every strip."""
    c = cfg.campaign
    t = np.concatenate(times)
    strip = np.concatenate([np.full(tt.size, i) for i, tt in enumerate(times)])
    xyz, rpy = _true_pose(plan, strip, t, cfg.mount_motion_rad, c.speed_m_s)
    err = nav_err(t)
    true = Trajectory(t, xyz, rph_from_platform_rpy(rpy))
    nav = Trajectory(t, xyz - err[:, :3], rph_from_platform_rpy(rpy - err[:, 3:]))
    return true, nav


def _window(camera, traj, t, n_px, half_m, h_mean, agl):
    """Lines and columns of one strip whose ground lies over the block ``[-half_m, half_m]²``.

    From the true pose (so boresight and lever arm are accounted for): the columns from the
    strip's middle line, the lines from the ground N of the middle pixel of each line.
    Returns ``(line_slice, col_slice)`` or None.
    """
    x = np.arange(n_px) - (n_px - 1) / 2
    tm = t[t.size // 2]
    pos, _ = traj.pose(np.full(n_px, tm))
    R = traj.R_map_from_body(np.full(n_px, tm)) @ R_BODY_FROM_PLATFORM
    o, d = camera.rays_at(np.column_stack([x, np.zeros(n_px)]), 0, pos, R)
    s = (h_mean - o[:, 2]) / d[:, 2]
    E = o[:, 0] + s * d[:, 0]
    margin = 2.0
    cols = np.flatnonzero(np.abs(E) <= half_m + margin)
    if cols.size < MIN_COLUMNS:
        return None
    pos_l, _ = traj.pose(t)
    N_ground = o[n_px // 2, 1] + s[n_px // 2] * d[n_px // 2, 1] - pos[0, 1] + pos_l[:, 1]
    lines = np.flatnonzero(np.abs(N_ground) <= half_m + margin)
    if lines.size < 2:
        return None
    return slice(lines[0], lines[-1] + 1), slice(cols[0], cols[-1] + 1)


def _render_strip(cfg: LpConfig, camera, traj, t, cols, ground: Ground, rng) -> np.ndarray:
    """DN of every line, column and band of one strip, ``(n_lines, n_cols, n_bands)`` float32.

    Per band the platform-frame ray of each column is computed once
    (:meth:`PushbroomCamera.rays_at` at the identity pose, which inverts the distortion and
    applies c_b and the boresight), then turned by each line's true attitude and shifted to its
    projection centre: ``O = x + R l^p``, ``D = R βᵀ (x̄, ȳ, c_b)`` — the formula of
    :meth:`~PushbroomCamera.rays_at`, factored per line.
    """
    c = cfg.campaign
    n_px = c.pixels_per_line
    x = cols - (n_px - 1) / 2
    nc = x.size
    nb = len(camera.c_mm)
    pos, _ = traj.pose(t)
    R = traj.R_map_from_body(t) @ R_BODY_FROM_PLATFORM  # map from platform
    o_plat, _ = camera.rays_at(np.zeros((1, 2)), 0, np.zeros((1, 3)), np.eye(3)[None])
    origins_line = pos + R @ o_plat[0]  # (nl, 3): x + R l^p
    xy = np.column_stack([x, np.zeros(nc)])
    eye = np.broadcast_to(np.eye(3), (nc, 3, 3))
    d_plat = np.stack([camera.rays_at(xy, b, np.zeros((nc, 3)), eye)[1] for b in range(nb)])
    out = render_lines(R, origins_line, d_plat, ground)
    # radiometry: DN, shot and read noise, quantisation, saturation
    dn = out * np.asarray(cfg.dn_per_reflectance[:nb], np.float32)
    sigma = np.sqrt(dn / np.float32(cfg.electrons_per_dn) + np.float32(cfg.read_noise_dn) ** 2)
    dn += sigma * rng.standard_normal(dn.shape, dtype=np.float32)
    np.clip(np.round(dn), 0, cfg.dn_max, out=dn)
    return dn


def _stamp_offset_s(cfg: LpConfig) -> float:
    """Time from a line's stamp to the middle of its exposure (0 for a mid-exposure stamp)."""
    if cfg.exposure_stamp == "middle":
        return 0.0
    return 0.5 * cfg.motion_blur_m / cfg.campaign.speed_m_s


def _checked(scale, cfg):
    if not (isinstance(scale, (int, float, np.floating)) and np.isfinite(scale)):
        raise InputError(f"scale must be a number in (0, 1], got {scale!r}")
    if not MIN_SCALE <= scale <= 1:
        raise InputError(
            f"scale must be in [{MIN_SCALE}, 1] (the share of 002's 600 m block side rendered; "
            f"below {MIN_SCALE} the 17 squares crowd a block of under 30 m), got {scale}"
        )
    cfg = cfg or LpConfig()
    for name in (
        "ground_cell_m",
        "dsm_cell_m",
        "field_size_m",
        "dn_max",
        "electrons_per_dn",
        "target_side_m",
    ):
        v = getattr(cfg, name)
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"LpConfig.{name} must be a positive number, got {v!r}")
    if not all(
        getattr(cfg, k) >= 0
        for k in (
            "psf_sigma_m",
            "motion_blur_m",
            "read_noise_dn",
            "mount_motion_rad",
            "sigma_pp_calibration_px",
            "target_spacing_m",
            "target_surround_m",
            "target_surround_reflectance",
        )
    ):
        raise InputError(
            "LpConfig: psf_sigma_m, motion_blur_m, read_noise_dn, mount_motion_rad, "
            "sigma_pp_calibration_px, target_spacing_m, target_surround_m and "
            "target_surround_reflectance must be ≥ 0"
        )
    if cfg.target_reflectance is not None and not (
        np.isfinite(cfg.target_reflectance) and 0 < cfg.target_reflectance <= 1
    ):
        raise InputError(
            f"LpConfig.target_reflectance must be None or in (0, 1], got {cfg.target_reflectance!r}"
        )
    if cfg.exposure_stamp not in ("middle", "start"):
        raise InputError(
            f"LpConfig.exposure_stamp must be 'middle' or 'start', got {cfg.exposure_stamp!r}"
        )
    nb = len(cfg.campaign.c_offsets_um)
    if len(cfg.dn_per_reflectance) < nb or len(cfg.campaign.wavelengths_nm) != nb:
        raise InputError(
            f"LpConfig: {nb} bands need {nb} wavelengths and dn_per_reflectance values"
        )
    return cfg


def simulate(
    scale: float = 0.35, rng=0, cfg: LpConfig | None = None, progress=None
) -> tuple[LpObservations, LpTruth]:
    """Render the LP campaign's strips over the central ``600·scale`` m block (module docstring).

    Parameters
    ----------
    scale : float in [MIN_SCALE, 1]
        Side of the rendered block as a share of 002's 600 m (area and pixels ∝ ``scale²``).
    rng : int or numpy.random.Generator
    cfg : LpConfig, optional
    progress : callable, optional
        Called as ``progress(done, total)`` after each strip.

    Returns
    -------
    observations : LpObservations
    truth : LpTruth
    """
    from hsgeo.geocode import DemTerrain

    cfg = _checked(scale, cfg)
    rng = as_rng(rng)
    c = replace(cfg.campaign, mount_motion_rad=cfg.mount_motion_rad)
    plan = _strip_plan(c)
    t_end = plan[-1][1]
    nodes = SplineNodes(0.0, t_end, c.node_interval_s)
    node_err, _, _, nav_err = _trajectory_error(c, nodes, plan, t_end, rng)
    names = BLOCK_NAMES
    tv = _camera_truth(c, node_err)
    bore = np.asarray(tv[names["boresight"]], float)
    lever = np.asarray(tv[names["lever_arm"]], float)
    cam_true = PushbroomCamera(
        c_mm=tuple(np.asarray(tv[names["c"]], float)),
        pixel_mm=c.pixel_mm,
        distortion=tuple(np.asarray(tv[names["distortion"]], float)),
        x0_mm=c.x0_mm,
        y0_mm=c.y0_mm,
        boresight_rad=tuple(bore),
        lever_arm_m=tuple(lever),
    )
    lever_measured = lever + c.sigma_lever_m * rng.standard_normal(3)
    nb = len(cam_true.c_mm)
    # the operator's calibrated principal point: the truth plus a calibration error (drawn
    # from a spawned stream, so the campaign's other draws do not move)
    pp_err = cfg.sigma_pp_calibration_px * c.pixel_mm * rng.spawn(1)[0].standard_normal(2)
    cam_prior = PushbroomCamera(
        c_mm=(c.c_nominal_mm,) * nb,
        pixel_mm=c.pixel_mm,
        x0_mm=c.x0_mm + float(pp_err[0]),
        y0_mm=c.y0_mm + float(pp_err[1]),
        lever_arm_m=tuple(lever_measured),
    )
    times = _line_times(c, plan)
    traj_true, traj_nav = _trajectories(cfg, plan, times, nav_err)
    # the squares (002's layout shrunk with the block) and the ground
    half = c.area_m / 2 * scale
    sq_en = (np.asarray(REFERENCE_EN_M, float) + rng.uniform(-20, 20, (17, 2))) * scale
    tg_en = _target_grid(cfg, half, rng)
    ground, sq_h, tg_xyz = make_ground(cfg, half, sq_en, c.wavelengths_nm[:nb], rng, tg_en)
    sq_true = np.column_stack([sq_en, sq_h])
    sq_rtk = sq_true + c.sigma_gcp_m * rng.standard_normal(sq_true.shape)
    h_mean = float(ground.dsm.mean())
    strips, index = [], []
    for i, (tt, p) in enumerate(zip(times, plan, strict=True)):
        w = _window(cam_true, traj_true, tt, c.pixels_per_line, half, h_mean, p[3])
        if w is not None:
            ls, cs = w
            cols = np.arange(c.pixels_per_line)[cs]
            t_render = tt[ls] + _stamp_offset_s(cfg)
            lines = _render_strip(cfg, cam_true, traj_true, t_render, cols, ground, rng)
            strips.append(
                LpStrip(
                    lines,
                    tt[ls],
                    int(cols[0]),
                    np.asarray(c.wavelengths_nm[:nb]),
                    f"s{i:02d}",
                    n_px_full=c.pixels_per_line,
                )
            )
            index.append(i)
        if progress is not None:
            progress(i + 1, len(plan))
    ids = tuple(f"sq{k:02d}" for k in range(17))
    obs = LpObservations(
        strips=strips,
        navigation=traj_nav,
        camera=cam_prior,
        square_ids=ids,
        square_xyz_m=sq_rtk,
        gcp_ids=ids[:4],
        n_px_full=c.pixels_per_line,
        scale=float(scale),
    )
    truth = LpTruth(
        trajectory=traj_true,
        camera=cam_true,
        terrain=DemTerrain(ground.dsm_dataarray()),
        square_xyz_m=sq_true,
        ground=ground,
        cfg=cfg,
        plan=plan,
        strip_index=np.asarray(index, dtype=np.int64),
        nav_error=nav_err,
        target_xyz_m=tg_xyz,
    )
    return obs, truth


def _target_grid(cfg: LpConfig, half_m: float, rng) -> np.ndarray:
    """Centres (E, N) of the point targets: a grid of ``cfg.target_spacing_m`` over the block
    (half a spacing in from its edges), each jittered by up to a quarter spacing, from a spawned
    stream (the campaign's own draws do not move); ``(0, 2)`` when the spacing is 0.
    """
    s = cfg.target_spacing_m
    if s <= 0:
        return np.zeros((0, 2))
    g = np.arange(-half_m + s / 2, half_m - s / 2 + 1e-9, s)
    en = np.stack(np.meshgrid(g, g, indexing="xy"), axis=-1).reshape(-1, 2)
    return en + rng.spawn(1)[0].uniform(-s / 4, s / 4, en.shape)
