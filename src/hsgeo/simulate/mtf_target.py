"""The simulated sharpness bench of the ImSpector V9 + PixelFly (001 §2.3, §3.1).

The bar target of 001 §2.3 (black/white pairs from 20.88 mm to 0.92 mm, shrinking by 2^(1/6))
is seen at 1.7 m with the slit perpendicular to the bars, binning 1 (001 §3.1): one frame whose
rows are the spectral lines. Every spectral row sees the target through optics whose point
spread is an isotropic Gaussian of σ(λ) px, then the PixelFly's square 6.7 µm pixel: the MTF is
analytic, ``exp(−2π²σ²f²)·|sinc f|`` (:func:`mtf_true`), so every estimate has a truth. The
profile is computed exactly (each bar edge's blurred step integrated over the pixel, no
supersampling), then shot noise, read noise, dark current and 12-bit quantisation are added with
the sensor of :class:`hsgeo.simulate.line_lab.LineLab` (one sensor description, shared with the
line-calibration chapter).

Beyond the paper, a slanted edge is rendered through the same optics (a 2-D recording of a
scanned edge, with the same Gaussian and pixel box in both directions).

Chosen (not in the paper, stated in the chapter): the number of pairs per group (at least 2, and
at least 12 mm per group), the target's position on the line, profiles averaged over 4 frames,
σ(λ) as a logistic step from the visible to the NIR at 700 nm, and the edge's 5° slant. Tuned:
σ at the ends of the step, so that the MTF falls to 0.1 at 0.3 cy/px on line 100 (blue) and at
0.6 cy/px on line 1000 (NIR), 001 §4.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.special import ndtr

from hsgeo.errors import InputError
from hsgeo.mtf import BarTarget, mtf_gaussian, mtf_pixel
from hsgeo.papers import P001_MTF, P001_SENSOR
from hsgeo.simulate import as_rng
from hsgeo.simulate.line_lab import LineLab, spectral_level, wavelength_nm
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = [
    "MtfBench",
    "MtfBenchScenario",
    "BarRows",
    "paper_target",
    "sigma_px",
    "mtf_true",
    "render_bar_profiles",
    "render_edge",
    "BarRecording",
    "bar_electrons",
    "edge_electrons",
]


def paper_target(min_group_mm: float = 12.0, lab: LineLab | None = None) -> BarTarget:
    """The bar target of 001 §2.3 (pairs 20.88 → 0.92 mm by 2^(1/6)); reflectances of the lab."""
    lab = lab or LineLab()
    return BarTarget.geometric(
        P001_MTF["widest_pair_mm"],
        P001_MTF["narrowest_pair_mm"],
        P001_MTF["pair_ratio"],
        min_group_mm=min_group_mm,  # chosen: ≥ 12 mm per group (≈ 25 px: a beat at 0.52 cy/px)
        min_pairs=2,  # chosen
        white_reflectance=lab.white_reflectance,
        black_reflectance=lab.black_reflectance,
    )


@dataclass(frozen=True)
class MtfBench:
    """The sharpness bench: the sensor (``lab``), the target, the optics, the edge."""

    lab: LineLab = field(default_factory=LineLab)  # the ImSpector + PixelFly (line_lab)
    distance_m: float = P001_MTF["distance_m"]  # 001 §3.1 "at a distance of 1.7 m"
    fov_ratio: float = P001_MTF["fov_ratio"]  # 001 §3.1 "(1.7 m × 0.333)/1170"
    min_group_mm: float = 12.0  # chosen
    target_offset_px: float = 80.0  # chosen: the target starts ≈ 80 px into the line
    start_error_px: float = 2.0  # chosen: the operator knows the start to ±2 px (uniform)
    sigma_vis_px: float = 1.1001  # tuned: MTF(0.3 cy/px) = 0.1 on line 100 (001 §4)
    sigma_nir_px: float = 0.4772  # tuned: MTF(0.6 cy/px) = 0.1 on line 1000 (001 §4)
    step_nm: float = 700.0  # chosen: visible → NIR step of the blur (001 §3.1: visible equal)
    step_width_nm: float = 20.0  # chosen
    n_frames: int = 4  # chosen: the static target's profiles are the mean of 4 frames
    stray_light: float = 0.0  # unmodelled effect: veiling glare, fraction of the mean signal
    edge_angle_deg: float = 5.0  # chosen (ISO 12233 recommends about 5°)
    edge_shape_px: tuple[int, ...] = (256, 64)  # chosen region of the rendered edge: rows, columns

    @property
    def gsd_mm(self) -> float:
        """Theoretical GSD along the line (001 §3.1: (1.7 m × 0.333)/1170)."""
        return self.distance_m * 1e3 * self.fov_ratio / self.lab.n_reflected

    @property
    def target(self) -> BarTarget:
        return paper_target(self.min_group_mm, self.lab)

    @property
    def dark_dn(self) -> float:
        """Expected dark level, DN (offset + dark current): what a dark frame gives."""
        return self.lab.offset_dn + self.lab.dark_e / self.lab.gain_e_per_dn

    @property
    def saturation_dn(self) -> float:
        return float(2 ** P001_SENSOR["bits"] - 1)


@dataclass(frozen=True)
class BarRows:
    """``[bars]`` of ``mtf_bench.toml``: the spectral lines whose bar profiles are written."""

    rows: tuple[int, ...] = (100, 500, 700, 1000)  # 001 Table 3


@dataclass(frozen=True)
class MtfBenchScenario:
    """``data_synthetic/mtf_bench.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`): the
    mtf chapter's bench (``[bench]``, a :class:`MtfBench`) and the bar profiles ``make data``
    writes (``[bars]``).
    """

    scenario: ScenarioInfo
    bench: MtfBench = MtfBench()
    bars: BarRows = BarRows()


def sigma_px(bench: MtfBench, row) -> np.ndarray:
    """σ of the Gaussian blur of a spectral row, px (a logistic step at ``step_nm``)."""
    lam = wavelength_nm(row, bench.lab)
    w = 1.0 / (1.0 + np.exp((lam - bench.step_nm) / bench.step_width_nm))
    return bench.sigma_nir_px + (bench.sigma_vis_px - bench.sigma_nir_px) * w


def mtf_true(bench: MtfBench, row, f_cy_px, angle_deg: float = 0.0) -> np.ndarray:
    """The analytic MTF of a row: Gaussian × pixel box, perpendicular to an edge slanted by
    ``angle_deg`` (0: along the line).
    """
    t = np.radians(angle_deg)
    f = np.asarray(f_cy_px, dtype=float)
    s = sigma_px(bench, row)
    return mtf_gaussian(f, s) * mtf_pixel(f * np.cos(t)) * mtf_pixel(f * np.sin(t))


def _psi(t):
    """Antiderivative of the normal CDF: t Φ(t) + φ(t)."""
    return t * ndtr(t) + np.exp(-0.5 * t * t) / np.sqrt(2 * np.pi)


def _pixel_step(x_px, edge_px, sigma):
    """A unit step at ``edge_px`` blurred by N(0, σ²), averaged over pixels centred at x_px."""
    a = (x_px + 0.5 - edge_px) / sigma
    b = (x_px - 0.5 - edge_px) / sigma
    return (_psi(a) - _psi(b)) * sigma


def _to_dn(e_signal, lab: LineLab, rng, bits: int) -> np.ndarray:
    """Electrons → 12-bit DN with shot, read and dark noise (the sensor of line_lab)."""
    e = e_signal + lab.dark_e
    e = rng.poisson(e).astype(float) + lab.read_e * rng.standard_normal(e.shape)
    dn = np.round(e / lab.gain_e_per_dn + lab.offset_dn)
    return np.clip(dn, 0, 2**bits - 1).astype(np.uint16)


@dataclass(frozen=True)
class BarRecording:
    """What the operator has: profiles, the nominal layout, the dark level.

    Attributes
    ----------
    rows : (n,) int ndarray
        The spectral rows.
    x_px : (n_columns,) ndarray
        Column (pixel-centre) coordinates.
    profiles_dn : (n, n_columns) ndarray
        The mean of ``n_frames`` raw 12-bit frames, DN.
    start_px : float
        The operator's approximate position of the target's start (±``start_error_px``).
    gsd_mm : float
        Nominal GSD (001 §3.1).
    dark_dn, saturation_dn : float
    true_start_px : float
        The truth (for the chapter; the workflow does not get it).
    """

    rows: np.ndarray
    x_px: np.ndarray
    profiles_dn: np.ndarray
    start_px: float
    gsd_mm: float
    dark_dn: float
    saturation_dn: float
    true_start_px: float


def bar_electrons(bench: MtfBench, rows, start_px: float) -> np.ndarray:
    """Noise-free signal (electrons) of each row's profile, ``(len(rows), n_reflected)``."""
    lab = bench.lab
    rows = np.atleast_1d(np.asarray(rows))
    if np.any((rows < 0) | (rows >= lab.n_rows)):
        raise InputError(f"rows must lie in 0..{lab.n_rows - 1}")
    x = np.arange(lab.n_reflected, dtype=float)
    tgt = bench.target
    edges_px = start_px + tgt.edges_mm() / bench.gsd_mm
    # reflectance = white − Σ steps; at each edge the reflectance goes down (into black) or up
    mid = 0.5 * (edges_px[1:] + edges_px[:-1])
    refl_mid = tgt.reflectance((mid - start_px) * bench.gsd_mm)
    levels = np.concatenate([[tgt.white_reflectance], refl_mid, [tgt.white_reflectance]])
    jumps = np.diff(levels)  # the step at each edge
    lam = wavelength_nm(rows, lab)
    level = spectral_level(lab, lam)
    out = np.empty((rows.size, x.size))
    for i, r in enumerate(rows):
        s = float(sigma_px(bench, r))
        refl = tgt.white_reflectance + (jumps[None, :] * _pixel_step(x[:, None], edges_px, s)).sum(
            1
        )
        e = refl / lab.white_reflectance * lab.white_e * level[i]
        out[i] = e + bench.stray_light * e.mean()
    return out


def render_bar_profiles(bench: MtfBench, rows, rng) -> BarRecording:
    """Spectral rows ``rows`` seeing the bar target: the mean of ``bench.n_frames`` frames
    (one noise realisation of the experiment).
    """
    rng = as_rng(rng)
    lab = bench.lab
    true_start = bench.target_offset_px + rng.uniform(0.0, 1.0)  # sub-pixel phase of the target
    e = bar_electrons(bench, rows, true_start)
    frames = [_to_dn(e, lab, rng, P001_SENSOR["bits"]) for _ in range(int(bench.n_frames))]
    dn = np.mean(frames, axis=0)  # the mean of n_frames frames of the static target
    guess = true_start + rng.uniform(-bench.start_error_px, bench.start_error_px)
    return BarRecording(
        np.atleast_1d(np.asarray(rows)),
        np.arange(lab.n_reflected, dtype=float),
        dn,
        float(guess),
        bench.gsd_mm,
        bench.dark_dn,
        bench.saturation_dn,
        float(true_start),
    )


def edge_electrons(bench: MtfBench, row: int, shape=None, phase_px=0.0):
    """Noise-free slanted edge (dark left, white right) of a row's optics, electrons."""
    lab = bench.lab
    n_rows, n = (int(v) for v in (shape or bench.edge_shape_px))
    s = float(sigma_px(bench, row))
    tan_t = np.tan(np.radians(bench.edge_angle_deg))
    cos_t = np.cos(np.radians(bench.edge_angle_deg))
    x = np.arange(n, dtype=float)[None, :, None]
    v = (np.arange(16) + 0.5) / 16 - 0.5  # 16 sub-rows: the pixel box along the columns
    y = np.arange(n_rows, dtype=float)[:, None, None] + v[None, None, :]
    edge = (n - 1) / 2 + phase_px + (y - (n_rows - 1) / 2) * tan_t
    # a step blurred by N(0, σ²) across the edge, i.e. by N(0, (σ/cos θ)²) along a row; exact
    # over the pixel's width
    step = _pixel_step(x, edge, s / cos_t).mean(axis=2)
    black, white = lab.black_reflectance, lab.white_reflectance
    refl = black + (white - black) * step
    e = refl / white * lab.white_e * float(spectral_level(lab, wavelength_nm(row, lab)))
    return e + bench.stray_light * e.mean()


def render_edge(bench: MtfBench, row: int, rng, shape=None) -> np.ndarray:
    """A recorded slanted edge (uint16 DN, ``shape`` rows × columns, default
    ``bench.edge_shape_px``) of a spectral row's optics (one noise realisation).
    """
    rng = as_rng(rng)
    e = edge_electrons(bench, row, shape, phase_px=rng.uniform(-0.5, 0.5))
    return _to_dn(e, bench.lab, rng, P001_SENSOR["bits"])
