"""The simulated laboratory of the ImSpector V9 + PixelFly spatial calibration (000 §4, 001 §3.1).

A crown pattern (black triangles whose tips touch the line A–B, imaged as thin dark lines, 000
Fig. 4 / 001 Fig. 5) is seen at about 3 m from three stations whose rays intersect near 90°
(000 §4.1). Two side signals (a thin dark line on a small white plate) stand a few centimetres in
front of the pattern plane beyond A and B: they are the off-line control points that fix the
scale (see the ``line-calibration`` chapter). Everything lies in the scanner plane (x along A–B,
y towards the pattern; the pattern line is y = 0).

The sensor records raw 12-bit frames of 1024 spectral rows × 1280 columns (001 Table 1): columns
0–1169 see the scene, 1170–1279 the diffuse collector (001 §2.1). For every spectral row the true
inner orientation comes from 001 Table 2 (000 Table 1 at row 1000), interpolated across rows, and
the profile is rendered by tracing each sub-pixel's ray (:func:`hsgeo.sensors.line1d.tan_from_zeta`)
to the plates and the pattern, blurring with a wavelength-dependent Gaussian PSF, integrating over
the pixel, and adding shot noise, read noise and dark current.

An even distortion term outside 000's odd series (``LineLab.even_distortion_px``) is rendered by
default: the instrument effect the estimator does not model (GUIDE §4).

Assumptions (not in the papers, stated in the chapter): the wavelength of a row
(λ = 430 nm + 0.44 nm·row, so that row 1000 is the 870 nm of 000 Table 1), the tooth pitch (20 mm)
and line width (1.5 mm), the PSF width, the radiometry, the station scatter.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import PchipInterpolator
from scipy.ndimage import gaussian_filter1d

from hsgeo.errors import InputError
from hsgeo.papers import P000_TABLE1_CALIBRATED, P001_SENSOR, P001_TABLE2
from hsgeo.sensors import line1d
from hsgeo.simulate import as_rng
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = [
    "LineLab",
    "LineLabScenario",
    "LineCalibrationRow",
    "true_iop",
    "wavelength_nm",
    "stations",
    "pattern_points",
    "render_rows",
    "render_frame",
    "even_distortion_px",
    "LabRecording",
    "LabTruth",
    "record",
    "spectral_level",
]


@dataclass(frozen=True)
class LineLab:
    """Configuration of the simulated bench (defaults: the papers' values or stated assumptions)."""

    n_rows: int = P001_SENSOR["n_rows"]  # 001 Table 1
    n_columns: int = P001_SENSOR["n_columns"]  # 001 Table 1
    n_reflected: int = P001_SENSOR["n_reflected_columns"]  # 001 §2.1
    lambda0_nm: float = 430.0  # 001 Table 1, spectral range starts at 430 nm
    dlambda_nm_per_row: float = 0.44  # assumption: row 1000 = 870 nm (000 §4.1 / 001 Table 2)
    distance_m: float = 3.0  # 001 §3.1 "at a distance of 3 m"
    azimuths_deg: tuple[float, ...] = (
        -45.0,
        0.0,
        45.0,
    )  # 000 §4.1: rays intersect as close to 90° as possible
    station_sigma_m: float = 0.005  # assumption: tripod placed on marks to ±5 mm
    alpha_sigma_deg: float = 0.1  # assumption: pointed to ±0.1°
    tooth_pitch_m: float = 0.02  # assumption (000 Fig. 4 not in the text)
    tooth_half_extent_m: float = 0.26  # assumption: teeth fill ±310 px of the frontal view
    tooth_width_m: float = 0.0015  # assumption: width of the dark line where the tips cross A–B
    board_half_m: float = 0.40  # white board beyond the teeth
    side_x_m: float = 0.32  # side signals beyond A and B (000 §4.1 "two more signals")
    side_offset_m: float = 0.05  # design: they stand 5 cm in front of the pattern plane
    side_plate_m: float = 0.016  # white plate of a side signal
    side_line_m: float = 0.002  # its dark line
    r_max_px: float = 450.0  # the model's domain |ζ − ζ0| (001 Fig. 7 curves end at 450 px)
    white_e: float = 7000.0  # assumption: electrons of the white board at the spectral peak
    black_reflectance: float = 0.04
    white_reflectance: float = 0.90
    background_reflectance: float = 0.05  # the lab beyond the board and the domain
    gain_e_per_dn: float = 2.0
    offset_dn: float = 50.0
    dark_e: float = 20.0  # dark current during the exposure
    read_e: float = 12.0
    psf_sigma_px: tuple[float, ...] = (
        0.8,
        0.6,
    )  # σ = a + b·((λ − 430)/440)²: blurrier in the NIR (001 §4)
    supersample: int = 8
    zeta_sigma_px: float = 0.05  # a-priori σ of a measured minimum (σ0 rescales it)
    # the instrument effect the estimator does not model (GUIDE §4, on by default): an even
    # distortion term, δ_even = a·((ζ − ζ0)/r_max)², as of a slightly decentred lens or a tilted
    # detector, with a (px) its value at the domain's edge (ours; no odd series of 000 eq. (2)
    # represents it); 0 switches it off
    even_distortion_px: float = 0.1
    seed: int = 0
    rows: tuple[int, ...] = field(default=(100, 300, 500, 1000))  # 001 Table 2


@dataclass(frozen=True)
class LineCalibrationRow:
    """``[calibration]`` of ``line_lab.toml``: the spectral line of the written calibration."""

    row: int = 1000  # 000 Table 1 (870 nm) and 001 Table 2's last row


@dataclass(frozen=True)
class LineLabScenario:
    """``data_synthetic/line_lab.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`): its
    ``[lab]`` entries override :class:`LineLab`'s defaults (the fields are the schema).
    """

    scenario: ScenarioInfo
    calibration: LineCalibrationRow = LineCalibrationRow()
    lab: LineLab = LineLab()


def wavelength_nm(row, lab: LineLab = LineLab()):
    """Wavelength of a spectral row (assumed linear; row 1000 = 870 nm, 000 §4.1)."""
    return lab.lambda0_nm + lab.dlambda_nm_per_row * np.asarray(row, dtype=float)


def _truth_table():
    rows = np.array([r.row_px for r in P001_TABLE2], dtype=float)
    vals = np.array([[r.zeta0_px, r.c_px, r.K1, r.K2, r.K3] for r in P001_TABLE2])
    t = P000_TABLE1_CALIBRATED  # row 1000 with 000 Table 1's extra digits
    vals[-1] = [t.zeta0_px, t.c_px, t.K1, t.K2, t.K3]
    return rows, vals


def true_iop(row) -> dict:
    """True ζ0, c, K of a spectral row: 001 Table 2 (000 Table 1 at row 1000), PCHIP across rows.

    PCHIP keeps ζ0 nearly linear and c non-linear and monotone between the published lines, as
    001 §3.1 describes; outside rows 100–1000 the end values are held.
    """
    rows, vals = _truth_table()
    r = np.clip(np.asarray(row, dtype=float), rows[0], rows[-1])
    out = PchipInterpolator(rows, vals, axis=0)(r)
    return {"zeta0_px": out[..., 0], "c_px": out[..., 1], "K": out[..., 2:]}


def stations(lab: LineLab, rng=None) -> np.ndarray:
    """Stations ``(n, 3)``: x0_m, y0_m, alpha_rad on a circle around the pattern, looking at its
    centre, scattered by the configured σ when ``rng`` is given (the truth of one experiment).
    """
    a = np.deg2rad(np.asarray(lab.azimuths_deg, dtype=float))
    e = np.column_stack([lab.distance_m * np.sin(a), -lab.distance_m * np.cos(a), a])
    if rng is not None:
        rng = as_rng(rng)
        e = e + rng.normal(
            0.0,
            [lab.station_sigma_m, lab.station_sigma_m, np.deg2rad(lab.alpha_sigma_deg)],
            e.shape,
        )
    return e


def pattern_points(lab: LineLab) -> tuple[np.ndarray, list[str]]:
    """Control points ``(n, 2)`` [m] and their ids: teeth T01… along A–B, side signals S1, S2."""
    n = int(round(2 * lab.tooth_half_extent_m / lab.tooth_pitch_m)) + 1
    x = np.linspace(-lab.tooth_half_extent_m, lab.tooth_half_extent_m, n)
    xy = np.column_stack([x, np.zeros(n)])
    side = np.array([[-lab.side_x_m, -lab.side_offset_m], [lab.side_x_m, -lab.side_offset_m]])
    ids = [f"T{i + 1:02d}" for i in range(n)] + ["S1", "S2"]
    return np.vstack([xy, side]), ids


def _reflectance_along_rays(lab: LineLab, eop, tan):
    """Reflectance seen along rays ``tan θ`` (any shape) from station ``eop``."""
    x0, y0, a = eop
    ca, sa = np.cos(a), np.sin(a)
    dx = tan * ca - sa  # ray direction: tan·e_X + e_Y, e_X = (cos α, sin α), e_Y = (−sin α, cos α)
    dy = tan * sa + ca
    out = np.full(tan.shape, lab.background_reflectance)
    # the pattern plane y = 0
    s = -y0 / dy
    x = x0 + s * dx
    on_board = (s > 0) & (np.abs(x) <= lab.board_half_m)
    out[on_board] = lab.white_reflectance
    pts, _ = pattern_points(lab)
    teeth = pts[:-2, 0]
    near = np.min(np.abs(x[..., None] - teeth), axis=-1) <= lab.tooth_width_m / 2
    out[on_board & near] = lab.black_reflectance
    # side plates in front of the pattern (they occlude what lies behind)
    ys = -lab.side_offset_m
    s2 = (ys - y0) / dy
    xs = x0 + s2 * dx
    for sx in (-lab.side_x_m, lab.side_x_m):
        hit = (s2 > 0) & (np.abs(xs - sx) <= lab.side_plate_m / 2)
        out[hit] = lab.white_reflectance
        out[hit & (np.abs(xs - sx) <= lab.side_line_m / 2)] = lab.black_reflectance
    return out


def _spectral_level(lab: LineLab, lam_nm):
    """Relative signal of the white board: halogen lamp × CCD response (assumption)."""
    return np.exp(-(((np.asarray(lam_nm) - 650.0) / 260.0) ** 2))


#: The white board's relative signal per wavelength (public: the sharpness bench shares it).
spectral_level = _spectral_level


def render_rows(lab: LineLab, eop, rows, rng, iop: dict | None = None) -> np.ndarray:
    """Raw 12-bit rows ``(len(rows), n_columns)`` (uint16) of one frame from station ``eop``.

    ``iop`` overrides the true inner orientation (dict of arrays per row, as :func:`true_iop`).
    """
    rng = as_rng(rng)
    rows = np.atleast_1d(np.asarray(rows))
    if np.any((rows < 0) | (rows >= lab.n_rows)):
        raise InputError(f"rows must lie in 0..{lab.n_rows - 1}")
    iop = true_iop(rows) if iop is None else iop
    ss = int(lab.supersample)
    ncol = lab.n_reflected
    zs = (np.arange(ncol * ss) + 0.5) / ss - 0.5  # sub-pixel centres, pixel-centre origin
    out = np.empty((rows.size, lab.n_columns), dtype=np.uint16)
    lam = wavelength_nm(rows, lab)
    level = _spectral_level(lab, lam)
    for k in range(rows.size):
        z0 = float(np.atleast_1d(iop["zeta0_px"])[k])
        c = float(np.atleast_1d(iop["c_px"])[k])
        K = np.atleast_2d(iop["K"])[k]
        valid = np.abs(zs - z0) <= lab.r_max_px
        refl = np.full(zs.shape, lab.background_reflectance)
        t = line1d.tan_from_zeta(zs[valid], z0, c, K)
        if lab.even_distortion_px:
            t = t + even_distortion_px(zs[valid], z0, lab) / c  # tan θ = −(ζ − δ − ζ0)/c
        refl[valid] = _reflectance_along_rays(lab, eop, t)
        a, b = lab.psf_sigma_px
        sig = a + b * ((lam[k] - 430.0) / 440.0) ** 2
        refl = gaussian_filter1d(refl, sig * ss, mode="nearest")
        pix = refl.reshape(ncol, ss).mean(axis=1)
        e_sig = pix / lab.white_reflectance * lab.white_e * level[k]
        inc = np.full(lab.n_columns - ncol, 0.8 * lab.white_e * level[k])  # diffuse collector
        e = np.concatenate([e_sig, inc]) + lab.dark_e
        e = rng.poisson(e).astype(float) + lab.read_e * rng.standard_normal(e.size)
        dn = np.round(e / lab.gain_e_per_dn + lab.offset_dn)
        out[k] = np.clip(dn, 0, 2 ** P001_SENSOR["bits"] - 1).astype(np.uint16)
    return out


def even_distortion_px(zeta_px, zeta0_px: float, lab: LineLab) -> np.ndarray:
    """The distortion outside 000's odd series that the bench renders (``lab.even_distortion_px``
    at ``|ζ − ζ0| = lab.r_max_px``, quadratic in between), px.
    """
    u = (np.asarray(zeta_px, dtype=np.float64) - zeta0_px) / lab.r_max_px
    return lab.even_distortion_px * u**2


def render_frame(lab: LineLab, eop, rng, supersample: int = 4) -> np.ndarray:
    """A whole raw frame ``(n_rows, n_columns)`` uint16 (for figures; coarser supersampling)."""
    return render_rows(replace(lab, supersample=supersample), eop, np.arange(lab.n_rows), rng)


@dataclass(frozen=True)
class LabRecording:
    """What the bench records and the operator knows: raw rows and the surveyed control points.

    Attributes
    ----------
    row : int
        The spectral row (001 Table 2).
    frames_dn : (n_images, n_columns) uint16 ndarray
        The raw row of each station's frame.
    xy_m : (n_points, 2) ndarray
        Control-point coordinates in the scanner plane (surveyed).
    point_ids : list of str
    """

    row: int
    frames_dn: np.ndarray
    xy_m: np.ndarray
    point_ids: list


@dataclass(frozen=True)
class LabTruth:
    """The simulation's truth: station orientations ``(n_images, 3)`` and the row's IOP."""

    eop: np.ndarray
    iop: dict


def record(lab: LineLab, row: int, rng, eop_true=None) -> tuple[LabRecording, LabTruth]:
    """Render one spectral row from every station: ``(recording, truth)``.

    Parameters
    ----------
    lab : LineLab
    row : int
    rng : int or numpy.random.Generator
    eop_true : (n_images, 3) array_like, optional
        Station orientations (default: :func:`stations` drawn from ``rng``).
    """
    rng = as_rng(rng)
    eop_true = stations(lab, rng) if eop_true is None else np.asarray(eop_true, dtype=float)
    iop = true_iop(row)
    frames = np.array([render_rows(lab, e, [row], rng)[0] for e in eop_true])
    xy, ids = pattern_points(lab)
    truth = LabTruth(eop_true, {k: np.asarray(v) for k, v in iop.items()})
    return LabRecording(int(row), frames, xy, ids), truth
