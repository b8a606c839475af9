"""The angular sensitivity function of a whiskbroom scanner from crossing flight lines (004).

The user's pipeline, truth-free (004 § Application, steps 1–3):

1. the scans are georegistered — each pixel's ground point from the scanner's rays and the
   navigation, by :mod:`hsgeo.geocode` (:func:`georegister`; with the panoramic model this is the
   correction for panoramic distortion) — and the along-runway image is registered onto the
   cross-runway scan by the landmarks at the runway's sides (:func:`register`: a Lucas–Kanade
   shift per window along both runway edges, their median, and the scatter between windows as
   the registration accuracy; 004: "about one pixel");
2. both are averaged over the runway width, the along image sampled at the ground points of the
   cross scan's pixels;
3. cross / along, normalised to nadir (:func:`hsgeo.radiometry.asf_ratio`).

The in-memory core :func:`asf_from_scans` (frozen :class:`AsfInputs`, :class:`AsfOptions` →
:class:`AsfResult`) is what ``hsgeo reproduce asf`` and the command line both call; the file
front end :func:`hsgeo.workflows.asf_flights.asf_files` reads through :mod:`hsgeo.io.scans`
(raw scans georegistered there, :mod:`hsgeo.workflows.asf_flights`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.spatial import cKDTree

from hsgeo.errors import InputError
from hsgeo.geocode import PlaneTerrain, geocode_rays
from hsgeo.radiometry import asf_ratio
from hsgeo.stats import nmad

__all__ = [
    "GeoScan",
    "AsfInputs",
    "AsfOptions",
    "Registration",
    "AsfResult",
    "georegister",
    "GroundSampler",
    "inside_polygon",
    "register",
    "asf_from_scans",
    "peak_to_peak_percent",
    "MIN_MEAN_NCC",
]


@dataclass(frozen=True)
class GeoScan:
    """A georegistered scan: values and the ground point of every pixel.

    Attributes
    ----------
    values : (bands, lines, pixels) ndarray
        Reflectance (or radiance) of each sample.
    scan_angle_rad : (pixels,) ndarray
        Scan angle of each column (positive to the right of the heading).
    E_m, N_m : (lines, pixels) ndarray
        Ground coordinates of each sample in the map frame.
    """

    values: np.ndarray
    scan_angle_rad: np.ndarray
    E_m: np.ndarray
    N_m: np.ndarray


def georegister(values, zeta_px, t0_s, line_rate_hz, sensor, trajectory, terrain=None) -> GeoScan:
    """Ground points of every sample of a scan by :func:`hsgeo.geocode.geocode_rays`.

    ``sensor`` needs ``times(line, ζ, t0_s, line_rate_hz)`` (each sample its own time, as a
    whiskbroom's) and ``scan_angle_rad(ζ)`` besides the sensor interface; ``terrain`` defaults
    to the plane at height 0.
    """
    v = np.asarray(values, dtype=float)
    zeta = np.asarray(zeta_px, dtype=float)
    n_lines = v.shape[1]
    L, Z = np.meshgrid(np.arange(n_lines, dtype=float), zeta, indexing="ij")
    t = sensor.times(L.ravel(), Z.ravel(), t0_s, line_rate_hz)
    g = geocode_rays(sensor, Z.ravel(), t, trajectory, terrain or PlaneTerrain(0.0))
    shape = L.shape
    return GeoScan(v, sensor.scan_angle_rad(zeta), g[:, 0].reshape(shape), g[:, 1].reshape(shape))


class GroundSampler:
    """Values of a georegistered scan at any ground points: the inverse of its (line, pixel) →
    (E, N) map by Newton's method on the bilinear interpolation of E and N, then bilinear
    interpolation of the values (NaN outside the scan).
    """

    def __init__(self, scan: GeoScan):
        self.scan = scan
        E, N = scan.E_m, scan.N_m
        self._tree = cKDTree(np.column_stack([E.ravel(), N.ravel()]))
        self._shape = E.shape
        self._dE = np.gradient(E)
        self._dN = np.gradient(N)

    def locate(self, E, N, start=None):
        """Fractional ``(line, pixel)`` of ground points (NaN outside the scan)."""
        E = np.asarray(E, float).ravel()
        N = np.asarray(N, float).ravel()
        if start is None:
            _, idx = self._tree.query(np.column_stack([E, N]))
            lp = np.array(np.unravel_index(idx, self._shape), dtype=float)
        else:
            lp = np.array(start, dtype=float)
        s = self.scan
        for _ in range(4):
            e = map_coordinates(s.E_m, lp, order=1, mode="nearest")
            n = map_coordinates(s.N_m, lp, order=1, mode="nearest")
            a, b = (map_coordinates(g, lp, order=1, mode="nearest") for g in self._dE)
            c, d = (map_coordinates(g, lp, order=1, mode="nearest") for g in self._dN)
            det = a * d - b * c
            re, rn = E - e, N - n
            lp = lp + np.stack([(d * re - b * rn) / det, (a * rn - c * re) / det])
        out = (lp < -0.5) | (lp > np.array(self._shape)[:, None] - 0.5)
        lp[:, out.any(axis=0)] = np.nan
        return lp

    def values(self, lp) -> np.ndarray:
        """Bilinear values ``(bands, n)`` at fractional ``(line, pixel)`` (NaN where NaN)."""
        ok = np.all(np.isfinite(lp), axis=0)
        v = self.scan.values
        out = np.full((v.shape[0], lp.shape[1]), np.nan)
        q = lp[:, ok]
        for k in range(v.shape[0]):
            out[k, ok] = map_coordinates(v[k], q, order=1, mode="nearest")
        return out


def inside_polygon(E, N, polygon_m, margin_m: float = 0.0) -> np.ndarray:
    """Points inside a polygon ``(k, 2)`` of (E, N) corners and at least ``margin_m`` from its
    edges (even–odd rule).
    """
    P = np.asarray(polygon_m, float)
    E = np.asarray(E, float)
    N = np.asarray(N, float)
    inside = np.zeros(E.shape, bool)
    dist = np.full(E.shape, np.inf)
    for i in range(P.shape[0]):
        (x0, y0), (x1, y1) = P[i], P[(i + 1) % P.shape[0]]
        cross = (y0 > N) != (y1 > N)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = x0 + (N - y0) * (x1 - x0) / (y1 - y0)
        inside ^= cross & (E < xs)
        dx, dy = x1 - x0, y1 - y0
        u = np.clip(((E - x0) * dx + (N - y0) * dy) / (dx * dx + dy * dy), 0, 1)
        dist = np.minimum(dist, np.hypot(E - x0 - u * dx, N - y0 - u * dy))
    return inside & (dist >= margin_m)


@dataclass(frozen=True)
class AsfOptions:
    """Settings of the ASF workflow (chosen; see the ``asf`` chapter).

    Attributes
    ----------
    margin_m : float
        Samples closer than this to the runway's edge are left out of the averages.
    nadir_halfwidth_deg : float
        The nadir value is the mean over the columns within ± this of nadir.
    min_samples : int
        A column needs this many runway samples to be usable.
    register : bool
        Register the along-runway image onto the cross scan (else take the navigation as is).
    window_m, window_step_m : float
        Registration windows: squares of this side, centred on the runway's long edges every
        ``window_step_m``.
    registration_bands : tuple of int, optional
        Bands whose normalised mean is registered (default all).
    search_m, search_step_m : float
        The coarse search of the shift: a grid of ± ``search_m`` in steps of ``search_step_m``
        (every third sample), then ± half a step in quarter steps.
    smooth_px : int
        Local quadratic fit over this many columns (odd) before the peak-to-peak variation is
        taken (:func:`peak_to_peak_percent`).
    reject_k : float or None
        Samples whose ratio cross / along departs from its column's median by more than this
        many robust σ (NMAD over the column, in any band) are left out of the averages: a
        marking narrower than the runway (the centre line's paint) seen by one scan and not by
        the other at the same ground point — at a dash's end, where one pixel of registration
        error or the two scans' different footprints put paint in one and asphalt in the
        other. ``None`` averages every sample (004's "average over the width").

    References
    ----------
    .. [1] Meister, G., Jupp, D., Rothkirch, A. and Spitzer, H. (1999). Determination of the angular
           sensitivity of a multispectral line scanner from image data. IGARSS 1999, vol. 1, 458
           (paper 004).
    """

    margin_m: float = 2.0
    nadir_halfwidth_deg: float = 1.0
    min_samples: int = 10
    register: bool = True
    window_m: float = 24.0
    window_step_m: float = 15.0
    registration_bands: tuple | None = None
    search_m: float = 4.0
    search_step_m: float = 0.8
    smooth_px: int = 31
    reject_k: float | None = 5.0


@dataclass(frozen=True)
class AsfInputs:
    """The cross-runway scan, the along-runway image and the runway polygon (E, N corners);
    ``names``: how messages name the two scans (the file front end gives the files).
    """

    cross: GeoScan
    along: GeoScan
    runway_polygon_m: np.ndarray
    names: tuple = ("the cross scan", "the along image")


@dataclass(frozen=True)
class Registration:
    """The along image's offset from the cross scan, ``shift_m`` (E, N): sample the along image
    at ``cross ground point + shift_m``. ``window_shifts_m`` per window; ``scatter_px`` the
    robust spread (NMAD) of the window shifts and ``sigma_px`` the standard error of the median,
    in nadir pixels of the cross scan (``gsd_m``).
    """

    shift_m: np.ndarray
    window_shifts_m: np.ndarray
    window_centres_m: np.ndarray
    scatter_px: float
    sigma_px: float
    gsd_m: float
    sigma_m: np.ndarray  # (E, N) standard errors of the median shift

    @property
    def n_windows(self) -> int:
        return int(self.window_shifts_m.shape[0])


def _nadir_gsd_m(scan: GeoScan) -> float:
    j = int(np.argmin(np.abs(scan.scan_angle_rad)))
    j1 = j + 1 if j + 1 < scan.E_m.shape[1] else j - 1
    d = np.hypot(scan.E_m[:, j1] - scan.E_m[:, j], scan.N_m[:, j1] - scan.N_m[:, j])
    return float(np.median(d))


def _window_centres(polygon_m, cross: GeoScan, options: AsfOptions) -> np.ndarray:
    """Points every ``window_step_m`` along the polygon's two longest edges, within the scan."""
    P = np.asarray(polygon_m, float)
    edges = [(P[i], P[(i + 1) % len(P)]) for i in range(len(P))]
    edges.sort(key=lambda e: -np.hypot(*(e[1] - e[0])))
    tree = cKDTree(np.column_stack([cross.E_m.ravel(), cross.N_m.ravel()]))
    out = []
    for a, b in edges[:2]:
        length = np.hypot(*(b - a))
        for s in np.arange(options.window_step_m / 2, length, options.window_step_m):
            c = a + (b - a) * s / length
            d, _ = tree.query(c)
            if d < 1.0:
                out.append(c)
    return np.array(out).reshape(-1, 2)


def _normalised_mean(values, bands) -> np.ndarray:
    """The registration image: the mean over ``bands`` of each band divided by its mean."""
    v = np.asarray(values, float)[list(bands)]
    return (v / np.nanmean(v, axis=(1, 2), keepdims=True)).mean(axis=0)


class _Linearised:
    """Along-image values near fixed ground points P at P + d: ``lp(P + d) ≈ lp(P) + J⁻¹ d``
    (the along scan's ground map is smooth over a few metres).
    """

    def __init__(self, sampler: GroundSampler, image, E, N):
        self.lp0 = sampler.locate(E, N)
        s = sampler
        a, b = (map_coordinates(g, self.lp0, order=1, mode="nearest") for g in s._dE)
        c, d = (map_coordinates(g, self.lp0, order=1, mode="nearest") for g in s._dN)
        det = a * d - b * c
        self.Jinv = np.array([[d, -b], [-c, a]]) / det  # (2, 2, n): (line, pixel) per (E, N)
        self.image = image
        self.shape = np.array(image.shape)[:, None]

    def subset(self, idx) -> _Linearised:
        """The same map at the points ``idx`` only: a search or a window evaluates it at the
        same points hundreds of times, and taking the points once is most of a call's cost.
        """
        out = object.__new__(_Linearised)
        out.lp0, out.Jinv = self.lp0[:, idx], self.Jinv[:, :, idx]
        out.image, out.shape = self.image, self.shape
        return out

    def __call__(self, dE, dN):
        lp = self.lp0 + self.Jinv[:, 0] * dE + self.Jinv[:, 1] * dN
        v = map_coordinates(self.image, lp, order=1, mode="constant", cval=np.nan)
        return np.where(np.any((lp < 0) | (lp > self.shape - 1), axis=0), np.nan, v)


def _ncc_sum(c, a, win, n_win) -> float:
    """Sum over windows of the normalised cross-correlation of c and a (NaN samples left out)."""
    ok = np.isfinite(a)
    w = win[ok]
    cc, aa = c[ok], a[ok]
    n = np.bincount(w, minlength=n_win).astype(float)
    mc = np.bincount(w, cc, n_win) / np.maximum(n, 1)
    ma = np.bincount(w, aa, n_win) / np.maximum(n, 1)
    dc, da = cc - mc[w], aa - ma[w]
    num = np.bincount(w, dc * da, n_win)
    den = np.sqrt(np.bincount(w, dc * dc, n_win) * np.bincount(w, da * da, n_win))
    good = (n >= 20) & (den > 0)
    return float(np.sum(num[good] / den[good]))


def _lucas_kanade(c, lin, d0, h=0.2, n_iter=10):
    """Shift (E, N) and gain/offset of one window, c ≈ g·a(P + d) + o, by Gauss–Newton
    (``lin``: the along image at the window's points, :meth:`_Linearised.subset`).
    """
    d = np.array(d0, float)
    g, o = 1.0, 0.0
    for _ in range(n_iter):
        a = lin(d[0], d[1])
        ae = (lin(d[0] + h, d[1]) - lin(d[0] - h, d[1])) / (2 * h)
        an = (lin(d[0], d[1] + h) - lin(d[0], d[1] - h)) / (2 * h)
        ok = np.isfinite(a) & np.isfinite(ae) & np.isfinite(an)
        if ok.sum() < 20:
            return None
        J = np.column_stack([g * ae, g * an, a, np.ones_like(a)])[ok]
        r = (c - g * a - o)[ok]
        JtJ = J.T @ J
        ev = np.linalg.eigvalsh(JtJ[:2, :2])
        if ev[0] <= 0 or ev[1] / ev[0] > 50:
            return None  # no landmark in the window: the shift along the edge is undetermined
        step = np.linalg.solve(JtJ, J.T @ r)
        d += step[:2]
        g += step[2]
        o += step[3]
        if np.abs(step[:2]).max() < 1e-4:
            break
    return d if np.all(np.abs(d - d0) < 2.0) else None


def register(
    cross: GeoScan, along: GeoScan, polygon_m, options: AsfOptions = AsfOptions(), sampler=None
) -> Registration:
    """Register the along-runway image onto the cross scan by the landmarks (004 step 1).

    A coarse search of the common shift (the sum of the windows' normalised cross-correlations
    on a grid of ±``search_m``), then a Lucas–Kanade shift (with gain and offset) per window
    from there; the median of the windows' shifts is the registration.

    References
    ----------
    .. [1] Meister, G., Jupp, D., Rothkirch, A. and Spitzer, H. (1999). Determination of the angular
           sensitivity of a multispectral line scanner from image data. IGARSS 1999, vol. 1, 458
           (paper 004).
    """
    sampler = sampler or GroundSampler(along)
    bands = list(options.registration_bands or range(cross.values.shape[0]))
    gsd = _nadir_gsd_m(cross)
    rc = _normalised_mean(cross.values, bands)
    ra = _normalised_mean(along.values, bands)
    w = options.window_m / 2
    cen, sel = [], []
    for c in _window_centres(polygon_m, cross, options):
        m = (np.abs(cross.E_m - c[0]) <= w) & (np.abs(cross.N_m - c[1]) <= w)
        if m.sum() >= 30:
            cen.append(c)
            sel.append(np.flatnonzero(m))
    if not sel:
        raise InputError(
            "no registration window: the runway's edges are not seen by the cross scan; check "
            "the runway file's corners (E_m, N_m) and the scans' map frame"
        )
    win = np.concatenate([np.full(len(k), i) for i, k in enumerate(sel)])
    pts = np.concatenate(sel)
    E, N = cross.E_m.ravel()[pts], cross.N_m.ravel()[pts]
    cval = rc.ravel()[pts]
    lin = _Linearised(sampler, ra, E, N)
    d0 = np.zeros(2)
    sub = np.arange(0, pts.size, 3)
    for half, step, idx in (
        (options.search_m, options.search_step_m, sub),
        (options.search_step_m / 2, options.search_step_m / 4, sub),
    ):
        g = np.arange(-half, half + 1e-9, step)
        lin_idx, c_idx, w_idx = lin.subset(idx), cval[idx], win[idx]
        score = np.array(
            [
                [_ncc_sum(c_idx, lin_idx(d0[0] + de, d0[1] + dn), w_idx, len(sel)) for dn in g]
                for de in g
            ]
        )
        if not np.any(np.nan_to_num(score) != 0):
            break  # the along image covers no window: the check of the windows below says so
        i, j = np.unravel_index(np.nanargmax(score), score.shape)
        if half == options.search_m:
            _check_coarse_match(score, i, j, len(sel), options)
        d0 = d0 + [g[i], g[j]]
    centres, shifts = [], []
    for k in range(len(sel)):
        idx = np.flatnonzero(win == k)
        d = _lucas_kanade(cval[idx], lin.subset(idx), d0)
        if d is not None:
            centres.append(cen[k])
            shifts.append(d)
    if len(shifts) < 3:
        raise InputError(
            f"only {len(shifts)} registration windows along the runway's edges found contrast "
            "seen by both scans: do the scans cross over the runway, and does the runway file "
            "give its corners (E_m, N_m) in the scans' map frame?"
        )
    S = np.array(shifts)
    med = np.median(S, axis=0)
    spread = nmad(S, axis=0)
    scatter = float(np.hypot(*spread)) / gsd
    se = np.sqrt(np.pi / 2) / np.sqrt(len(S))  # standard error of a median, normal errors
    return Registration(med, S, np.array(centres), scatter, se * scatter, gsd, se * spread)


#: The smallest mean normalised cross-correlation of the registration windows at the best
#: shift of the coarse search (chosen: landmarks seen by both scans correlate at 0.6–0.9 on the
#: simulated runway; scans whose navigation is off by more than the search correlate at < 0.3).
MIN_MEAN_NCC = 0.4


def _check_coarse_match(score, i, j, n_windows, options: AsfOptions) -> None:
    """Refuse a coarse registration that found no match: the best shift on the edge of the
    search grid, or windows that hardly correlate there.
    """
    last = score.shape[0] - 1
    mean_ncc = float(score[i, j]) / max(n_windows, 1)
    edge = i in (0, last) or j in (0, last)
    if mean_ncc < MIN_MEAN_NCC or edge:
        where = ", at the edge of the search" if edge else ""
        raise InputError(
            f"the landmarks of the two scans do not match within ±{options.search_m:g} m "
            f"(best mean correlation of the {n_windows} registration windows "
            f"{mean_ncc:.2f}{where}): "
            "the along scan's navigation is off by more than the search (a time or position "
            "offset?) or the scans do not show the same runway; correct the navigation, or "
            "widen the search (AsfOptions.search_m)"
        )


def peak_to_peak_percent(asf, usable, smooth_px: int) -> np.ndarray:
    """Max − min of each band's ASF over the usable columns, % of nadir, smoothed first.

    The max − min of a noisy curve is biased upwards by its noise; a local quadratic fit over
    ``smooth_px`` columns (Savitzky–Golay, polynomial fits at the ends) takes most of that bias
    away and leaves a smooth curve — slopes and curvature at the ends of the scan included —
    as it is.
    """
    from scipy.signal import savgol_filter

    a = np.asarray(asf, float)[:, np.asarray(usable, bool)]
    if smooth_px > 2 and a.shape[1] > smooth_px:
        a = savgol_filter(a, int(smooth_px) | 1, 2, axis=1, mode="interp")
    return 100.0 * (a.max(axis=1) - a.min(axis=1))


@dataclass(frozen=True)
class AsfResult:
    """The ASF per band and column, the registration, and what each column averaged."""

    scan_angle_rad: np.ndarray
    asf: np.ndarray  # (bands, pixels)
    sigma: np.ndarray
    n_samples: np.ndarray
    usable: np.ndarray  # (pixels,) bool
    registration: Registration | None
    smooth_px: int = 31

    @property
    def scan_angle_deg(self) -> np.ndarray:
        return np.rad2deg(self.scan_angle_rad)

    @property
    def peak_to_peak_percent(self) -> np.ndarray:
        """Max − min of each band's ASF over the usable columns, % of nadir, after a local
        quadratic smoothing over ``smooth_px`` columns (:func:`peak_to_peak_percent`).
        """
        return peak_to_peak_percent(self.asf, self.usable, self.smooth_px)

    def table(self):
        """One row per column: scan angle, samples, the ASF and σ̂ of every band (pandas)."""
        import pandas as pd

        cols = {"scan_angle_deg": self.scan_angle_deg, "n_samples": self.n_samples}
        for b in range(self.asf.shape[0]):
            cols[f"asf_{b + 1}"] = self.asf[b]
            cols[f"sigma_{b + 1}"] = self.sigma[b]
        return pd.DataFrame(cols)

    def to_dict(self) -> dict:
        def num(a):
            a = np.asarray(a, float)
            return [None if not np.isfinite(x) else round(float(x), 6) for x in a.ravel()]

        reg = self.registration
        return {
            "scan_angle_deg": num(self.scan_angle_deg),
            "usable": [bool(u) for u in self.usable],
            "n_samples": [int(n) for n in self.n_samples],
            "asf": [num(a) for a in self.asf],
            "sigma": [num(s) for s in self.sigma],
            "peak_to_peak_percent": num(self.peak_to_peak_percent),
            "registration": None
            if reg is None
            else {
                "shift_m": num(reg.shift_m),
                "n_windows": reg.n_windows,
                "scatter_px": round(reg.scatter_px, 4),
                "sigma_px": round(reg.sigma_px, 4),
                "gsd_m": round(reg.gsd_m, 4),
            },
        }


def _disagreeing_samples(c, a, inside, k: float) -> np.ndarray:
    """Samples whose log ratio c / a lies more than ``k`` robust σ from its column's median in
    any band, ``(lines, pixels)`` bool (the column's σ: 1.4826 × the median absolute deviation,
    at least 0.1 %).
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.log(c / a)
    r = np.where(inside[None] & np.isfinite(r), r, np.nan)
    out = np.zeros(inside.shape, bool)
    cols = np.flatnonzero(np.isfinite(r).any(axis=(0, 1)))
    if cols.size == 0:
        return out
    rc = r[:, :, cols]
    med = np.nanmedian(rc, axis=1, keepdims=True)
    dev = np.abs(rc - med)
    sd = np.maximum(1.4826 * np.nanmedian(dev, axis=1, keepdims=True), 1e-3)
    with np.errstate(invalid="ignore"):
        out[:, cols] = np.any(dev > k * sd, axis=0)
    return out


def asf_from_scans(inputs: AsfInputs, options: AsfOptions = AsfOptions()) -> AsfResult:
    """The ASF from a cross-runway scan and an along-runway image (004 steps 1–3).

    References
    ----------
    .. [1] Meister, G., Jupp, D., Rothkirch, A. and Spitzer, H. (1999). Determination of the angular
           sensitivity of a multispectral line scanner from image data. IGARSS 1999, vol. 1, 458
           (paper 004).
    """
    cross, along = inputs.cross, inputs.along
    if cross.values.shape[0] != along.values.shape[0]:
        raise InputError(
            f"{inputs.names[0]} has {cross.values.shape[0]} bands, {inputs.names[1]} "
            f"{along.values.shape[0]}: give scans of the same channels"
        )
    from hsgeo.workflows.asf_checks import check_pair

    check_pair(inputs)
    inside = inside_polygon(cross.E_m, cross.N_m, inputs.runway_polygon_m, options.margin_m)
    if inside.sum() == 0:
        raise InputError(
            "the runway polygon lies outside the cross scan (no sample of the cross scan falls "
            "on it): check the runway file's corners (E_m, N_m) and the scan's map frame"
        )
    sampler = GroundSampler(along)
    reg = (
        register(cross, along, inputs.runway_polygon_m, options, sampler)
        if options.register
        else None
    )
    shift = reg.shift_m if reg is not None else np.zeros(2)
    E, N = cross.E_m[inside], cross.N_m[inside]
    lp = sampler.locate(E + shift[0], N + shift[1])
    if not np.any(np.all(np.isfinite(lp), axis=0)):
        raise InputError(
            "the along-runway image does not cover the runway where the cross scan sees it: "
            "do the two scans cross?"
        )
    a = np.full(cross.values.shape, np.nan)
    a[:, inside] = sampler.values(lp)
    if options.reject_k is not None:
        inside = inside & ~_disagreeing_samples(cross.values, a, inside, options.reject_k)
    r = asf_ratio(
        cross.values,
        a,
        inside,
        cross.scan_angle_rad,
        nadir_halfwidth_rad=np.deg2rad(options.nadir_halfwidth_deg),
        min_samples=options.min_samples,
    )
    usable = np.all(np.isfinite(r.asf), axis=0)
    return AsfResult(
        cross.scan_angle_rad, r.asf, r.sigma, r.n_samples, usable, reg, options.smooth_px
    )
