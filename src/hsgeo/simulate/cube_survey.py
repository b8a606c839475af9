"""The simulated vineyard survey of 001 §3.2: raw ImSpector frames, dark frames, their truth.

The sensor is the ImSpector V9 + PixelFly of :mod:`hsgeo.simulate.line_lab` (one sensor
description: format, offset, conversion gain, read noise and the wavelength of a spectral row
come from its :class:`~hsgeo.simulate.line_lab.LineLab`), binned by the factor of the survey
(001 §3.2: 2), with the frame layout of :func:`hsgeo.radiometry.frame_layout` (585 reflected and
55 incident columns at binning 2, 001 §2.1). The scanner looks down from 2.5 m (the tops of the
vines, 001 §3.2) and moves along track at the speed of eq. (8); each frame integrates, for the
exposure time, a strip of the ground as wide as the slit's footprint (0.00208·h, 001 §2.1)
smeared by the motion.

Radiometry (our stated choices, provenance ``chosen``): the signal of a perfect white
Lambertian reflector on the optical axis, q(λ) (sun × optics × CCD, a smooth curve); the reflected
part gets q·r·F(θ) with the lens's receiving pattern F(θ) = cos^n θ at the sample's view angle;
the diffuse collector's columns get q·F(α)·(1 + ε) with F(α) = cos α at the sun's zenith angle α
and an optional cosine error ε the pipeline does not model (the chapter's unmodelled effect).
Both parts share a slow illumination change along track (clouds), which the ratio of §2.1 must
cancel. Noise: shot noise (normal with the Poisson variance), the dark current's shot noise and
the read noise; values are rounded and clipped to 12 bit. Every pixel has a dark signal
h = a·T_exp + b (001 §2.4) with a lognormal dark current and a small share of hot pixels.

The scene (``chosen``): a vine row seen from above, its canopy in the centre of the swath in four
along-track sections — the irrigation variants A, B, C and the control of 001 §3.2 — with dark
plastic netting on one side, soil on the other and a grey panel on the soil. The spectra are
parametric curves (a green peak, chlorophyll absorption in the red, a logistic red edge, a
xanthophyll dip at 531 nm) whose parameters move with the water supply as the literature on
water stress describes qualitatively (more NIR, a red edge at longer wavelengths, less red
reflectance and a shallower 531 nm dip with more water); the numbers are ours, not the paper's.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hsgeo.errors import InputError
from hsgeo.papers import P001_CUBE
from hsgeo.radiometry import FULL_SCALE_DN, eq8_speed_m_s, frame_layout
from hsgeo.simulate import as_rng
from hsgeo.simulate.line_lab import LineLab, wavelength_nm
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = [
    "CubeSurvey",
    "CubeSurveyScenario",
    "MATERIALS",
    "material_spectra",
    "SurveyFrames",
    "SurveyTruth",
    "simulate",
    "simulate_dark",
    "at_speed",
    "true_reflectance_lines",
    "CANOPY",
]

#: Materials of the scene, in the order of the material map's ids.
MATERIALS = ("A", "B", "C", "control", "soil", "netting", "panel")

#: Canopy parameters per variant (chosen): NIR plateau, red floor, green peak, red-edge centre
#: (nm) and depth of the 531 nm dip; more water → more NIR, less red, a later edge, a smaller dip.
CANOPY = {
    "control": (0.38, 0.070, 0.110, 711.0, 0.014),
    "A": (0.43, 0.055, 0.120, 715.0, 0.009),
    "B": (0.47, 0.046, 0.126, 718.0, 0.006),
    "C": (0.50, 0.040, 0.130, 721.0, 0.003),
}


def _canopy(lam, nir, red, green, edge_nm, dip):
    vis = red + (green - red) * np.exp(-(((lam - 552.0) / 38.0) ** 2))
    vis = vis - dip * np.exp(-(((lam - 531.0) / 9.0) ** 2))
    step = 1.0 / (1.0 + np.exp(-(lam - edge_nm) / 11.0))
    return vis + (nir - vis) * step


def material_spectra(lam_nm) -> dict[str, np.ndarray]:
    """True reflectance of every material at the wavelengths ``lam_nm`` (chosen curves)."""
    lam = np.asarray(lam_nm, dtype=float)
    out = {v: _canopy(lam, *CANOPY[v]) for v in ("A", "B", "C", "control")}
    out["soil"] = 0.12 + 0.18 * (lam - 430.0) / 470.0  # dry reddish karst soil, rising
    out["netting"] = 0.035 + 0.02 * (lam - 430.0) / 470.0  # dark plastic netting (001 §3.2)
    out["panel"] = np.full(lam.shape, 0.50)  # a 50 % grey panel
    return out


@dataclass(frozen=True)
class CubeSurvey:
    """Configuration of the simulated survey (defaults: 001 §2.1/§3.2 or stated choices)."""

    lab: LineLab = field(default_factory=LineLab)  # the ImSpector V9 + PixelFly (line_lab)
    binning: int = P001_CUBE["binning"]  # 001 §3.2
    height_m: float = P001_CUBE["height_m"]  # 001 §3.2, lens to the tops of the vines
    exposure_s: float = P001_CUBE["exposure_s"]  # 001 §3.2
    speed_m_s: float | None = None  # None: eq. (8) with the paper's GSD (33 mm/s, 001 §3.2)
    length_m: float = 0.6  # chosen: along-track length (the paper's sections: 2.4 m)
    white_e: float = 6000.0  # chosen: electrons of a white reflector on axis at q's peak
    sun_zenith_deg: float = 30.0  # chosen: 30 July, 12:30–14:45 at 43.7° N (001 §3.2)
    lens_falloff: float = 4.0  # chosen: F(θ) = cos⁴ θ
    collector_error: float = 0.0  # unmodelled cosine error ε of the diffuse collector
    illumination_change: float = 0.04  # chosen: ±4 % slow change of the light along track
    # chosen, aperture closed: equally spaced, so that the least-squares σ̂ of a and b stays
    # right although the dark current's shot noise grows with the exposure time
    dark_exposures_s: tuple[float, ...] = (0.01, 0.21, 0.41, 0.61, 0.81)
    dark_frames_per_exposure: int = 4
    dark_rate_dn_s: float = 6.0  # chosen: median dark current of a binned pixel
    dark_rate_spread: float = 0.3  # lognormal σ of the dark current
    offset_spread_dn: float = 2.0  # fixed-pattern spread of b around the sensor's offset
    hot_fraction: float = 0.002  # chosen: share of hot pixels
    hot_rate_dn_s: tuple[float, ...] = (300.0, 3000.0)  # log-uniform dark current of a hot pixel
    canopy_half_width_m: float = 0.20  # the vine row's canopy across track
    # x0, x1, y0, y1 of the grey panel on the soil
    panel_m: tuple[float, ...] = (0.04, 0.16, 0.24, 0.36)
    supersample: tuple[int, ...] = (6, 3)  # sub-positions along track (slit × motion) and across

    @property
    def layout(self):
        """The frame layout (:func:`hsgeo.radiometry.frame_layout`)."""
        return frame_layout(self.binning)

    @property
    def gsd_m(self) -> float:
        """Across-track ground sampling distance, swath / reflected columns (001 §3.2)."""
        return P001_CUBE["swath_per_height"] * self.height_m / self.layout.n_reflected

    @property
    def slit_footprint_m(self) -> float:
        """Along-track width of the slit's footprint, 0.00208·h (001 §2.1, 'GSDh')."""
        return P001_CUBE["slit_per_height"] * self.height_m

    @property
    def speed(self) -> float:
        """Scanner speed, m/s: the configured one, or eq. (8) at the paper's GSDv."""
        if self.speed_m_s is not None:
            return float(self.speed_m_s)
        return P001_CUBE["speed_mm_s"] / 1000.0  # 001 §3.2 (eq. (8) with GSDv ≈ 1.4 mm)

    @property
    def n_lines(self) -> int:
        return int(np.floor(self.length_m / (self.speed / self.layout.frame_rate_hz)))

    def row_wavelength_nm(self) -> np.ndarray:
        """Wavelength of each binned spectral row (the line-lab row law, averaged over bins)."""
        b = self.binning
        rows = np.arange(self.layout.n_rows)[:, None] * b + np.arange(b)[None]
        return wavelength_nm(rows, self.lab).mean(axis=1)

    def row_fwhm_nm(self) -> np.ndarray:
        """Spectral resolution of a row: 4.4 nm (001 §2.1)."""
        return np.full(self.layout.n_rows, P001_CUBE["spectral_resolution_nm"])

    def f_theta(self) -> np.ndarray:
        """The lens's receiving pattern F(θ) = cos^n θ at every reflected sample (chosen)."""
        y = self.sample_y_m()
        return np.cos(np.arctan2(y, self.height_m)) ** self.lens_falloff

    def f_alpha(self) -> float:
        """The diffuse collector's receiving pattern at the sun's zenith angle, cos α."""
        return float(np.cos(np.deg2rad(self.sun_zenith_deg)))

    def sample_y_m(self) -> np.ndarray:
        """Across-track ground position of every reflected sample (a distortion-free nadir
        view: the calibrated geometry is the line-calibration chapter's subject).
        """
        n = self.layout.n_reflected
        return (np.arange(n) - (n - 1) / 2) * self.gsd_m

    def q_e(self) -> np.ndarray:
        """Electrons of a white reflector on axis per binned row at the exposure time."""
        lam = self.row_wavelength_nm()
        return self.white_e * np.exp(-(((lam - 600.0) / 250.0) ** 2))


@dataclass(frozen=True)
class CubeSurveyScenario:
    """``data_synthetic/cube_survey.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`): the
    001 vineyard survey of the cube chapter at scale 1, ``[survey]`` a :class:`CubeSurvey`.
    """

    scenario: ScenarioInfo
    survey: CubeSurvey = CubeSurvey()


def _material_at(cfg: CubeSurvey, x, y) -> np.ndarray:
    """Material id (index into :data:`MATERIALS`) at ground points x (along), y (across), m."""
    quarter = np.clip((x / cfg.length_m * 4).astype(int), 0, 3)
    order = np.array([0, 1, 2, 3])  # A, B, C, control along track
    mid = order[quarter]
    out = np.where(np.abs(y) <= cfg.canopy_half_width_m, mid, 0)
    out = np.where(y < -cfg.canopy_half_width_m, MATERIALS.index("netting"), out)
    out = np.where(y > cfg.canopy_half_width_m, MATERIALS.index("soil"), out)
    x0, x1, y0, y1 = cfg.panel_m
    panel = (x >= x0) & (x < x1) & (y >= y0) & (y < y1)
    return np.where(panel, MATERIALS.index("panel"), out)


def _fractions(cfg: CubeSurvey, lines: np.ndarray) -> np.ndarray:
    """Share of each material in every pixel of ``lines``: (lines, samples, materials)."""
    n_a, n_c = cfg.supersample
    f = cfg.layout.frame_rate_hz
    motion = cfg.speed * cfg.exposure_s
    # the slit's footprint (uniform) smeared by the motion during the exposure (uniform)
    us = ((np.arange(n_a) + 0.5) / n_a - 0.5) * cfg.slit_footprint_m
    um = ((np.arange(n_a) + 0.5) / n_a - 0.5) * motion
    du = (us[:, None] + um[None]).ravel()
    xc = lines / f * cfg.speed + motion / 2
    x = xc[:, None] + du[None]  # (lines, n_a²)
    dy = ((np.arange(n_c) + 0.5) / n_c - 0.5) * cfg.gsd_m
    y = cfg.sample_y_m()[:, None] + dy[None]  # (samples, n_c)
    ids = _material_at(cfg, x[:, None, :, None], y[None, :, None, :])
    ids = ids.reshape(lines.size, y.shape[0], -1)
    out = np.stack([(ids == k).mean(axis=-1) for k in range(len(MATERIALS))], axis=-1)
    return out


@dataclass(frozen=True)
class SurveyTruth:
    """The simulation's truth (for :mod:`hsgeo.reproduce` only).

    Attributes
    ----------
    a_dn_per_s, b_dn : (rows, columns) ndarray
        True dark current and offset of every (binned) pixel.
    hot : (rows, columns) bool ndarray
    spectra : dict of (rows,) ndarray
        True reflectance per material at every spectral row.
    material : (lines, samples) int ndarray
        The material of each pixel whose footprint holds a single material, else −1.
    """

    a_dn_per_s: np.ndarray
    b_dn: np.ndarray
    hot: np.ndarray
    spectra: dict
    material: np.ndarray


class SurveyFrames:
    """Raw frames of the survey, rendered on demand (never all in memory).

    The same interface as the frame files of :mod:`hsgeo.io.frames`: ``n_frames``,
    ``frame_shape``, ``exposure_s`` (per frame) and ``read(i0, i1)`` → (i1 − i0, rows, columns)
    uint16. Frame ``i`` is drawn from its own generator (seed, i): the same frame whatever the
    chunks it is read in.
    """

    def __init__(self, cfg: CubeSurvey, seed: int, a_dn_per_s, b_dn, n_frames: int | None = None):
        self.cfg = cfg
        self.seed = int(seed)
        self._a = a_dn_per_s
        self._b = b_dn
        self.n_frames = cfg.n_lines if n_frames is None else int(n_frames)
        lay = cfg.layout
        self.frame_shape = (lay.n_rows, lay.n_columns)
        self.exposure_s = np.full(self.n_frames, cfg.exposure_s)
        self._spectra = np.stack(list(material_spectra(cfg.row_wavelength_nm()).values()), axis=1)
        self._q = cfg.q_e()
        self._f_theta = cfg.f_theta()
        phase = np.random.default_rng([self.seed, 991]).uniform(0, 2 * np.pi)
        self._phase = phase

    def illumination(self, lines) -> np.ndarray:
        """The relative light level of each line (a slow change along track, chosen)."""
        t = np.asarray(lines, float) / self.cfg.layout.frame_rate_hz
        return 1.0 + self.cfg.illumination_change * np.sin(2 * np.pi * t / 7.0 + self._phase)

    def electrons(self, lines) -> np.ndarray:
        """Noise-free electrons of the scene and the collector: (lines, rows, columns)."""
        cfg, lay = self.cfg, self.cfg.layout
        lines = np.asarray(lines)
        frac = _fractions(cfg, lines)  # (L, S, M)
        refl = frac @ self._spectra.T  # (L, S, rows)
        light = self.illumination(lines)[:, None, None]
        e_ref = light * self._q[None, None] * refl * self._f_theta[None, :, None]
        e_inc = light[..., 0] * self._q[None] * cfg.f_alpha() * (1.0 + cfg.collector_error)
        out = np.empty((lines.size, lay.n_rows, lay.n_columns))
        out[:, :, : lay.n_reflected] = e_ref.transpose(0, 2, 1)
        out[:, :, lay.n_reflected :] = e_inc[:, :, None]
        return out

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Raw 12-bit frames ``i0 … i1 − 1`` as uint16."""
        lab, cfg = self.cfg.lab, self.cfg
        e = self.electrons(np.arange(i0, i1))
        out = np.empty(e.shape, dtype=np.uint16)
        for k in range(e.shape[0]):
            rng = np.random.default_rng([self.seed, 17, i0 + k])
            out[k] = _to_dn(e[k], cfg.exposure_s, self._a, self._b, lab, rng)
        return out


def _to_dn(e, exposure_s, a, b, lab: LineLab, rng) -> np.ndarray:
    """Electrons → raw DN: shot, dark and read noise, gain, offset, 12-bit clip."""
    dark_dn = a * exposure_s
    var_e = e + dark_dn * lab.gain_e_per_dn + lab.read_e**2
    dn = (e + np.sqrt(var_e) * rng.standard_normal(e.shape)) / lab.gain_e_per_dn + dark_dn + b
    return np.clip(np.round(dn), 0, FULL_SCALE_DN).astype(np.uint16)


def _dark_truth(cfg: CubeSurvey, rng):
    lay = cfg.layout
    shape = (lay.n_rows, lay.n_columns)
    a = cfg.dark_rate_dn_s * np.exp(cfg.dark_rate_spread * rng.standard_normal(shape))
    hot = rng.random(shape) < cfg.hot_fraction
    lo, hi = np.log(cfg.hot_rate_dn_s)
    a = np.where(hot, np.exp(rng.uniform(lo, hi, shape)), a)
    b = cfg.lab.offset_dn + cfg.offset_spread_dn * rng.standard_normal(shape)
    return a, b, hot


def simulate_dark(cfg: CubeSurvey, a_dn_per_s, b_dn, rng):
    """Dark frames (aperture closed) at the configured exposure times.

    Returns
    -------
    frames : (n, rows, columns) uint16 ndarray
    exposure_s : (n,) ndarray
    """
    rng = as_rng(rng)
    t = np.repeat(np.asarray(cfg.dark_exposures_s, float), cfg.dark_frames_per_exposure)
    frames = np.stack(
        [_to_dn(np.zeros(a_dn_per_s.shape), ti, a_dn_per_s, b_dn, cfg.lab, rng) for ti in t]
    )
    return frames, t


def simulate(cfg: CubeSurvey, rng) -> tuple[SurveyFrames, tuple, SurveyTruth]:
    """The survey: ``(frames, (dark_frames, dark_exposure_s), truth)``.

    ``rng`` must be an int seed (each frame draws from its own generator derived from it).
    """
    if not isinstance(rng, (int, np.integer)) or rng < 0:
        raise InputError(f"simulate needs a non-negative int seed, got {rng!r}")
    seed = int(rng)
    if cfg.n_lines < 8:
        raise InputError(f"length_m {cfg.length_m} gives {cfg.n_lines} lines; need at least 8")
    g = np.random.default_rng([seed, 1])
    a, b, hot = _dark_truth(cfg, g)
    dark = simulate_dark(cfg, a, b, g)
    frames = SurveyFrames(cfg, seed, a, b)
    frac = _fractions(cfg, np.arange(frames.n_frames))
    pure = frac.max(axis=-1) >= 1.0 - 1e-12
    material = np.where(pure, frac.argmax(axis=-1), -1)
    truth = SurveyTruth(a, b, hot, material_spectra(cfg.row_wavelength_nm()), material)
    return frames, dark, truth


def at_speed(cfg: CubeSurvey, factor: float) -> CubeSurvey:
    """The same survey at ``factor`` × the eq. (8) speed (the speed trade-off of the chapter)."""
    return replace(cfg, speed_m_s=factor * eq8_speed_m_s(cfg.gsd_m, cfg.layout.frame_rate_hz))


def true_reflectance_lines(cfg: CubeSurvey, lines, row: int) -> np.ndarray:
    """Noise-free reflectance seen by ``lines`` at one spectral row: (lines, samples).

    The mixture of materials in each pixel's footprint (slit width smeared by the motion), for
    figures of what the sampling along track does to the scene.
    """
    spectra = np.stack(list(material_spectra(cfg.row_wavelength_nm()[[row]]).values()), axis=1)
    out = []
    lines = np.asarray(lines)
    for k in range(0, lines.size, 64):
        out.append(_fractions(cfg, lines[k : k + 64]) @ spectra[0])
    return np.concatenate(out, axis=0)
