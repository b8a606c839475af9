"""Radiometry of the ImSpector V9 + PixelFly: dark signal and hot pixels, reflectance, band means.

The maths of building a reflectance cube from raw frames (001 §2.1, §2.4), with no file and no
simulation in it:

* the frame layout per binning factor (:func:`frame_layout`: reflected and incident columns);
* the per-pixel dark signal h = a·T_exp + b fitted in closed form to dark frames at several
  exposure times, with σ̂ per pixel (:func:`fit_dark`, :class:`DarkModel`), and the hot pixels
  (:func:`find_hot_pixels`);
* the reflection coefficient r = G_ref·E_ref·F(α) / (G_inc·E_inc·F(θ)) (:func:`reflectance`)
  with E_inc the diffuse collector's signal averaged along each spectral line
  (:func:`incident_mean`), and spectral rows averaged into bands (:func:`bin_rows`);
* the mean of a patch of the cube with a σ̂ that allows for errors shared by a column (the dark
  fit) or by a line (the incident signal) (:func:`patch_mean`);
* vegetation indices (:data:`INDICES`, :func:`vegetation_index`) with σ̂ by the delta method;
* the angular sensitivity function of a whiskbroom scanner from a cross-runway scan divided by
  the along-runway overflight (004 steps 2–3, :func:`asf_ratio`), and its parts even and odd in
  the scan angle (:func:`even_odd_parts`, :func:`combine_opposite_crossings`).

References
----------
Krtalić, Miljković, Gajski, Racetin (2019), Sensors 19(19) 4267 (paper 001 of this book).
Determination of the angular sensitivity of a multispectral line scanner from image data
(DAEDALUS AADS 1268; paper 004 of this book).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "FrameLayout",
    "frame_layout",
    "DarkModel",
    "fit_dark",
    "find_hot_pixels",
    "incident_mean",
    "reflectance",
    "bin_rows",
    "band_fwhm_nm",
    "patch_mean",
    "VegetationIndex",
    "INDICES",
    "vegetation_index",
    "eq8_speed_m_s",
    "AsfRatio",
    "asf_ratio",
    "even_odd_parts",
    "combine_opposite_crossings",
    "FULL_SCALE_DN",
]


@lru_cache(maxsize=1)
def _imspector() -> dict:
    """The ImSpector V9 + PixelFly description (``hsgeo/data/instruments/
    imspector_v9_pixelfly.toml``, :func:`hsgeo.io.read_frame_layouts`; 001 Table 1, §2.1).
    """
    from hsgeo.io import read_frame_layouts

    return read_frame_layouts()


#: Largest raw value of the 12-bit PixelFly (001 §2.1).
FULL_SCALE_DN = 2 ** _imspector()["bits"] - 1


@dataclass(frozen=True)
class FrameLayout:
    """Columns of a raw frame: ``[0, n_reflected)`` see the scene, the rest the diffuse collector.

    Attributes
    ----------
    binning : int
    n_rows, n_columns, n_reflected, n_incident : int
    frame_rate_hz : float
        The PixelFly's frame rate at this binning (001 Table 1).
    """

    binning: int
    n_rows: int
    n_columns: int
    n_reflected: int
    n_incident: int
    frame_rate_hz: float


def frame_layout(binning: int) -> FrameLayout:
    """The ImSpector V9 + PixelFly frame at binning factor 1 or 2 (001 §2.1, Table 1).

    >>> frame_layout(2).n_reflected, frame_layout(2).n_incident, frame_layout(2).n_columns
    (585, 55, 640)
    """
    layouts = _imspector()["layouts"]
    if binning not in tuple(layouts):  # compared by value, as (1, 2) was
        raise InputError(f"binning must be 1 or 2 (001 §2.1), got {binning!r}; use --binning 1|2")
    lay = layouts[binning]
    return FrameLayout(
        binning,
        lay["n_rows"],
        lay["n_columns"],
        lay["n_reflected"],
        lay["n_incident"],
        lay["frame_rate_hz"],
    )


def eq8_speed_m_s(gsd_m: float, frame_rate_hz: float) -> float:
    """The scanner speed for contiguous square sampling, S = GSD / f_i (001 eq. (8)).

    ``f_i`` is the imaging period 1 / frame rate, so S = GSD · frame rate.

    >>> round(eq8_speed_m_s(0.0014, 24.0) * 1000, 1)
    33.6
    """
    return gsd_m * frame_rate_hz  # 001 eq. (8): S = GSD / f_i, f_i = 1 / frame rate


# --- dark signal and hot pixels (001 §2.4) ---------------------------------------------------


@dataclass(frozen=True)
class DarkModel:
    """Per-pixel dark signal h = a·T_exp + b (001 §2.4) fitted by least squares.

    Attributes
    ----------
    a_dn_per_s, b_dn : (rows, columns) ndarray
        Slope (dark current) and intercept (offset) of every pixel.
    sigma_a_dn_per_s, sigma_b_dn : (rows, columns) ndarray
        Their σ̂ from the pixel's own residual scatter.
    cov_ab : (rows, columns) ndarray
        Covariance of a and b.
    sigma0_dn : (rows, columns) ndarray
        σ̂ of one dark value (residual RMS with n − 2 degrees of freedom).
    exposures_s : tuple of float
        The exposure times of the dark frames (one entry per frame).
    """

    a_dn_per_s: np.ndarray
    b_dn: np.ndarray
    sigma_a_dn_per_s: np.ndarray
    sigma_b_dn: np.ndarray
    cov_ab: np.ndarray
    sigma0_dn: np.ndarray
    exposures_s: tuple

    @property
    def shape(self) -> tuple:
        return self.a_dn_per_s.shape

    def predict(self, exposure_s: float) -> np.ndarray:
        """The dark value h = a·T_exp + b to subtract at this exposure time (001 §2.4)."""
        return self.a_dn_per_s * exposure_s + self.b_dn  # 001 §2.4, h_bg,ij = a_ij·T_exp + b_ij


def fit_dark(frames_dn: Iterable, exposure_s) -> DarkModel:
    """Fit h = a·T_exp + b to every pixel of dark frames (001 §2.4), in closed form.

    The frames are read once (an array or any iterable of 2-D frames, e.g. a generator reading
    files), accumulating per pixel Σy, Σ(T − T̄)y and Σy²; memory is a few frames whatever their
    number.

    Parameters
    ----------
    frames_dn : (n, rows, columns) array_like or iterable of (rows, columns) arrays
        Dark frames (aperture closed), raw DN.
    exposure_s : (n,) array_like
        Exposure time of each frame, s.

    Returns
    -------
    DarkModel

    Raises
    ------
    InputError
        Fewer than two distinct exposure times (a and b cannot be separated), fewer than three
        frames (no σ̂), frames of different sizes, or a count that does not match ``exposure_s``.
    """
    t = np.asarray(exposure_s, dtype=float).ravel()
    n = t.size
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        raise InputError("dark exposure times must be finite and ≥ 0 s")
    if np.unique(t).size < 2:
        raise InputError(
            f"the dark set has one exposure time ({t[0] if n else 'none'} s): h = a·T + b needs "
            "dark frames at two or more exposure times (001 §2.4); record the dark set at "
            "several exposure times"
        )
    if n < 3:
        raise InputError(f"{n} dark frames: at least 3 are needed for a σ̂ of a and b")
    tbar = t.mean()
    dt = t - tbar
    sxx = float(dt @ dt)
    s_y = s_ty = s_yy = None
    k = -1
    for k, frame in enumerate(frames_dn):
        if k >= n:
            raise InputError(f"more dark frames than the {n} exposure times given")
        y = np.asarray(frame, dtype=float)
        if s_y is None:
            s_y, s_ty, s_yy = np.zeros_like(y), np.zeros_like(y), np.zeros_like(y)
        elif y.shape != s_y.shape:
            raise InputError(
                f"dark frame {k} is {y.shape[0]} × {y.shape[1]} px, the first is "
                f"{s_y.shape[0]} × {s_y.shape[1]}: all dark frames must have one size"
            )
        s_y += y
        s_ty += dt[k] * y
        s_yy += y * y
    if k + 1 != n:
        raise InputError(f"{k + 1} dark frames for {n} exposure times")
    a = s_ty / sxx  # least squares slope with centred exposure times
    ybar = s_y / n
    b = ybar - a * tbar
    rss = np.maximum(s_yy - n * ybar**2 - a * a * sxx, 0.0)
    s2 = rss / (n - 2)
    var_a = s2 / sxx
    var_b = s2 * (1.0 / n + tbar**2 / sxx)
    cov = -tbar * var_a
    return DarkModel(a, b, np.sqrt(var_a), np.sqrt(var_b), cov, np.sqrt(s2), tuple(t.tolist()))


def find_hot_pixels(dark: DarkModel, k: float = 8.0) -> np.ndarray:
    """Hot pixels: a dark current far above the sensor's typical one (001 §2.4).

    A pixel is hot when its slope a exceeds the median slope by more than ``k`` robust standard
    deviations of the slopes (1.4826 × MAD) and by more than ``k`` of its own σ̂_a.

    Returns
    -------
    (rows, columns) bool ndarray
    """
    a = dark.a_dn_per_s
    med = np.median(a)
    nmad = 1.4826 * np.median(np.abs(a - med))
    excess = a - med
    return (excess > k * nmad) & (excess > k * dark.sigma_a_dn_per_s)


# --- reflectance (001 §2.1) --------------------------------------------------------------------


def incident_mean(incident_dn, hot=None) -> np.ndarray:
    """The diffuse collector's signal averaged along each spectral line (001 §2.4).

    Parameters
    ----------
    incident_dn : (..., rows, n_incident) ndarray
        Dark-corrected incident part of frames.
    hot : (rows, n_incident) bool ndarray, optional
        Pixels left out of the mean (hot pixels are noisier after correction).

    Returns
    -------
    (..., rows) ndarray
    """
    x = np.asarray(incident_dn, dtype=float)
    if hot is None or not np.any(hot):
        return x.mean(axis=-1)
    w = (~np.asarray(hot)).astype(float)
    return (x * w).sum(axis=-1) / np.maximum(w.sum(axis=-1), 1.0)


def reflectance(e_ref, e_inc, *, g_ref=1.0, g_inc=1.0, f_alpha=1.0, f_theta=1.0):
    """Reflection coefficient r = G_ref·E_ref·F(α) / (G_inc·E_inc·F(θ)) (001 §2.1).

    Parameters
    ----------
    e_ref : (..., rows, samples) ndarray
        Dark-corrected reflected signal.
    e_inc : (..., rows) ndarray
        Dark-corrected incident signal of the same frame(s) (:func:`incident_mean`).
    g_ref, g_inc : float or (rows,) array_like
        Gains of the bands measuring E_ref and E_inc (001 §3.2: 1).
    f_alpha : float or (rows,) array_like
        Receiving pattern of the diffuse collector at the incidence of the light, F(α).
    f_theta : float or (samples,) array_like
        Receiving pattern of the scanner's lens at each sample's view angle, F(θ).

    Returns
    -------
    (..., rows, samples) ndarray
    """
    e_ref = np.asarray(e_ref)
    if e_ref.dtype != np.float32:
        e_ref = e_ref.astype(float)
    g = np.asarray(g_ref, dtype=float) * np.asarray(f_alpha, dtype=float)
    per_row = g / (np.asarray(g_inc, dtype=float) * np.asarray(e_inc, dtype=float))
    per_sample = 1.0 / np.asarray(f_theta, dtype=float)
    # 001 §2.1, in the dtype of e_ref (float32 keeps a chunk of a cube small)
    return e_ref * per_row[..., None].astype(e_ref.dtype) * per_sample.astype(e_ref.dtype)


def bin_rows(x, rows_per_band: int, axis: int = -2) -> np.ndarray:
    """Average ``rows_per_band`` consecutive spectral rows into one band (a trailing remainder of
    rows is dropped).
    """
    x = np.asarray(x)
    k = int(rows_per_band)
    if k == 1:
        return x
    axis = axis % x.ndim
    n = x.shape[axis] // k
    x = np.take(x, np.arange(n * k), axis=axis)
    shape = x.shape[:axis] + (n, k) + x.shape[axis + 1 :]
    return x.reshape(shape).mean(axis=axis + 1)


def band_fwhm_nm(wavelength_nm, fwhm_nm, rows_per_band: int) -> tuple[np.ndarray, np.ndarray]:
    """Centre and FWHM of bands of ``rows_per_band`` rows: the mean centre, and the FWHM of a
    row's response widened by the span of the rows (added in quadrature, an approximation).
    """
    lam = bin_rows(np.asarray(wavelength_nm, float), rows_per_band, axis=0)
    fw = bin_rows(np.asarray(fwhm_nm, float), rows_per_band, axis=0)
    k = int(rows_per_band)
    if k == 1:
        return lam, fw
    step = np.abs(np.diff(np.asarray(wavelength_nm, float))).mean()
    return lam, np.hypot(fw, k * step)


# --- patch means and indices -------------------------------------------------------------------


def patch_mean(values) -> tuple[np.ndarray, np.ndarray]:
    """Mean of a rectangular patch (lines × samples) and its σ̂, per band.

    Errors shared by a whole column (the dark fit of a sensor column) or a whole line (the
    incident signal of a frame) do not average out like independent noise. With the two-way
    random-effects model y_ls = μ + c_s + l_l + e_ls the variance of the patch mean is
    σ_c²/S + σ_l²/L + σ_e²/(L·S) = (MS_col + MS_line − MS_err)/(L·S) in terms of the ANOVA mean
    squares; this σ̂ is what is returned (at least MS_err/(L·S)).

    Parameters
    ----------
    values : (L, S) or (L, S, bands) ndarray

    Returns
    -------
    mean, sigma : ndarray (scalars, or (bands,))
    """
    y = np.asarray(values, dtype=float)
    if y.ndim == 2:
        y = y[..., None]
    n_l, n_s = y.shape[:2]
    if n_l < 2 or n_s < 2:
        raise InputError(f"a patch needs at least 2 × 2 pixels, got {n_l} × {n_s}")
    m = y.mean(axis=(0, 1))
    col = y.mean(axis=0)  # (S, bands)
    line = y.mean(axis=1)  # (L, bands)
    ms_col = n_l * ((col - m) ** 2).sum(axis=0) / (n_s - 1)
    ms_line = n_s * ((line - m) ** 2).sum(axis=0) / (n_l - 1)
    e = y - col[None] - line[:, None] + m
    ms_err = (e**2).sum(axis=(0, 1)) / ((n_l - 1) * (n_s - 1))
    var = np.maximum(ms_col + ms_line - ms_err, ms_err) / (n_l * n_s)
    s = np.sqrt(var)
    if np.asarray(values).ndim == 2:
        return m[0], s[0]
    return m, s


@dataclass(frozen=True)
class VegetationIndex:
    """A narrow-band vegetation index: its name, formula, source and the wavelengths it uses."""

    name: str
    formula: str
    source: str
    wavelengths_nm: tuple
    fn: Callable


#: Indices of the family ENVI computes for vegetation (001 §3.2: "16 selected vegetation
#: indices", not named in the paper; these six are our choice), each with its source.
INDICES = {
    "NDVI": VegetationIndex(
        "NDVI",
        "(R800 − R670) / (R800 + R670)",
        "Rouse et al. (1974)",
        (800.0, 670.0),
        lambda n, r: (n - r) / (n + r),
    ),
    "SR": VegetationIndex("SR", "R800 / R670", "Jordan (1969)", (800.0, 670.0), lambda n, r: n / r),
    "EVI": VegetationIndex(
        "EVI",
        "2.5 (R800 − R670) / (R800 + 6 R670 − 7.5 R470 + 1)",
        "Huete et al. (2002)",
        (800.0, 670.0, 470.0),
        lambda n, r, b: 2.5 * (n - r) / (n + 6 * r - 7.5 * b + 1),
    ),
    "NDVI705": VegetationIndex(
        "NDVI705",
        "(R750 − R705) / (R750 + R705)",
        "Gitelson & Merzlyak (1994); Sims & Gamon (2002)",
        (750.0, 705.0),
        lambda n, r: (n - r) / (n + r),
    ),
    "PRI": VegetationIndex(
        "PRI",
        "(R531 − R570) / (R531 + R570)",
        "Gamon et al. (1992)",
        (531.0, 570.0),
        lambda a, b: (a - b) / (a + b),
    ),
    "VOG1": VegetationIndex(
        "VOG1", "R740 / R720", "Vogelmann et al. (1993)", (740.0, 720.0), lambda a, b: a / b
    ),
}


def vegetation_index(name: str, wavelength_nm, spectrum, sigma=None):
    """A vegetation index of a spectrum (bands interpolated linearly at its wavelengths).

    Parameters
    ----------
    name : str
        A key of :data:`INDICES`.
    wavelength_nm : (bands,) array_like
    spectrum : (..., bands) array_like
        Reflectance.
    sigma : (bands,) array_like, optional
        σ̂ of each band of a single spectrum, independent between bands: the index's σ̂ is then
        propagated by the delta method (numerical derivatives).

    Returns
    -------
    value, or (value, sigma) when ``sigma`` is given
    """
    if name not in INDICES:
        raise InputError(f"unknown vegetation index {name!r}; known: {', '.join(INDICES)}")
    vi = INDICES[name]
    lam = np.asarray(wavelength_nm, dtype=float)
    inside = lam.min() <= min(vi.wavelengths_nm) and max(vi.wavelengths_nm) <= lam.max()
    if lam.size < 2 or not inside:
        raise InputError(
            f"{name} needs reflectance at {vi.wavelengths_nm} nm; the cube covers "
            f"{lam.min():.0f}–{lam.max():.0f} nm"
        )
    x = np.asarray(spectrum, dtype=float)
    # linear interpolation at each wavelength as weights on the bands
    weights = np.array(
        [np.interp(w, lam, np.eye(lam.size)[j]) for w in vi.wavelengths_nm for j in range(lam.size)]
    ).reshape(len(vi.wavelengths_nm), lam.size)

    def value(s):
        return vi.fn(*np.moveaxis(s @ weights.T, -1, 0))

    v = value(x)
    if sigma is None:
        return v
    sig = np.asarray(sigma, dtype=float)
    grad = np.zeros(lam.size)
    for j in range(lam.size):
        h = 1e-6 * max(abs(x[j]), 1e-3)
        xp = x.copy()
        xp[j] += h
        grad[j] = (value(xp) - v) / h
    return v, float(np.sqrt(np.sum((grad * sig) ** 2)))


# --- the angular sensitivity function (004) ----------------------------------------------------


@dataclass(frozen=True)
class AsfRatio:
    """The ASF of each channel and pixel from one crossing (:func:`asf_ratio`).

    Attributes
    ----------
    asf : (bands, pixels) ndarray
        Cross / along, averaged over the runway width, normalised to nadir (NaN where a column
        has fewer than ``min_samples`` runway samples).
    sigma : (bands, pixels) ndarray
        σ̂ of ``asf`` from the scatter of the per-sample ratios over the width.
    n_samples : (pixels,) ndarray of int
        Runway samples averaged in each column.
    nadir : (bands,) ndarray
        The ratio at nadir that ``asf`` was divided by.
    """

    asf: np.ndarray
    sigma: np.ndarray
    n_samples: np.ndarray
    nadir: np.ndarray


def asf_ratio(
    cross, along, inside, scan_angle_rad, *, nadir_halfwidth_rad: float, min_samples: int = 10
) -> AsfRatio:
    """The angular sensitivity function: cross-runway scan / along-runway overflight (004).

    004 step 2: "Average the values over the width of the runway for both images"; step 3:
    "Divide the cross-runway scan by the along-runway scan. The ratio gives the ASF ... after
    normalization to nadir". ``along`` is the along-runway image already registered onto the
    cross scan (004 step 1), i.e. sampled at the ground points of the cross scan's pixels, so
    both averages run over the same ground.

    Parameters
    ----------
    cross, along : (bands, lines, pixels) ndarray
        Cross-runway scan and the along-runway image at the same ground points (NaN where the
        along image does not reach).
    inside : (lines, pixels) bool ndarray
        Samples on the runway (less a margin from its edges).
    scan_angle_rad : (pixels,) ndarray
        Scan angle of each column.
    nadir_halfwidth_rad : float
        The nadir value is the mean ratio of the columns with ``|θ| ≤`` this.
    min_samples : int
        Columns with fewer runway samples are NaN (not usable).

    Returns
    -------
    AsfRatio
    """
    c = np.asarray(cross, dtype=float)
    a = np.asarray(along, dtype=float)
    if c.ndim != 3 or a.shape != c.shape or np.shape(inside) != c.shape[1:]:
        raise InputError(
            f"cross {c.shape}, along {a.shape} and runway mask {np.shape(inside)} must be "
            "(bands, lines, pixels), (bands, lines, pixels) and (lines, pixels)"
        )
    th = np.asarray(scan_angle_rad, dtype=float)
    ok = np.asarray(inside, bool) & np.all(np.isfinite(a), axis=0) & np.all(np.isfinite(c), axis=0)
    ok &= np.all(a > 0, axis=0)
    n = ok.sum(axis=0)
    w = ok[None].astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        c_mean = np.where(w > 0, c, 0.0).sum(axis=1) / n  # 004 step 2
        a_mean = np.where(w > 0, a, 0.0).sum(axis=1) / n
        ratio = c_mean / a_mean  # 004 step 3
        # σ of a ratio of means (delta method): sd(c − ratio·a) / mean(a), over √n below
        d = np.where(w > 0, c - ratio[:, None, :] * a, 0.0)
        d_mean = d.sum(axis=1, keepdims=True) / n
        sd = np.sqrt((w * (d - d_mean) ** 2).sum(axis=1) / (n - 1)) / a_mean
    usable = n >= max(min_samples, 2)
    ratio = np.where(usable, ratio, np.nan)
    sigma = np.where(usable, sd / np.sqrt(np.maximum(n, 1)), np.nan)
    near = usable & (np.abs(th) <= nadir_halfwidth_rad)
    if not near.any():
        raise InputError(
            f"no usable column within ±{np.rad2deg(nadir_halfwidth_rad):.2f}° of nadir: the "
            "runway must be seen at nadir to normalise the ASF there"
        )
    nadir = ratio[:, near].mean(axis=1)  # 004: "after normalization to nadir"
    return AsfRatio(ratio / nadir[:, None], sigma / nadir[:, None], n, nadir)


def even_odd_parts(asf) -> tuple[np.ndarray, np.ndarray]:
    """The parts of an ASF even and odd in the scan angle, as factors: ``asf = even · odd``.

    ``even(θ) = sqrt(asf(θ)·asf(−θ))``, ``odd(θ) = sqrt(asf(θ)/asf(−θ))``, on a pixel grid
    symmetric about nadir (pixel ``i`` ↔ ``n − 1 − i``, as the 004 scanner's). A BRDF of a
    rotationally symmetric surface seen across the principal plane is even in θ, so the even
    part of the ASF cannot be told from it (004 § ASF: "Symmetric ASF effects cannot be detected
    by our procedure if the BRDF of the surface is unknown").
    """
    x = np.asarray(asf, dtype=float)
    flipped = x[..., ::-1]
    return np.sqrt(x * flipped), np.sqrt(x / flipped)


def combine_opposite_crossings(asf_a, asf_b) -> tuple[np.ndarray, np.ndarray]:
    """Two crossings of the runway with opposite headings: the ASF and the BRDF's odd part.

    With the heading reversed the scan sweeps the ground the other way round, so a BRDF factor
    odd in the scan angle changes sign relative to the pixels while the ASF does not:
    ``r_a = ASF·B_even·B_odd``, ``r_b = ASF·B_even/B_odd``. Hence ``sqrt(r_a·r_b) = ASF·B_even``
    (the odd part of the ASF freed of the BRDF's odd part) and ``sqrt(r_a/r_b) = B_odd`` (beyond
    004, which flew one crossing). The even parts of ASF and BRDF stay inseparable.

    Returns
    -------
    asf, brdf_odd : ndarray
    """
    a = np.asarray(asf_a, dtype=float)
    b = np.asarray(asf_b, dtype=float)
    return np.sqrt(a * b), np.sqrt(a / b)
