"""The contrast (square-wave response, CTF) of each group of a bar target on a profile (001 eq. 5).

A profile along the line crosses the groups of a :class:`hsgeo.mtf.BarTarget`. Two steps:

1. :func:`register_target` — where the target lies on the profile: the 50 % crossings of the
   coarse groups' bar edges are found near their nominal positions (the operator's approximate
   start and GSD) and a straight line ``x_px = start_px + x_mm / gsd_mm`` is fitted to them.
2. :func:`measure_ctf` — per group, the samples inside the group (a margin from its ends, where
   the neighbouring groups' bars blur in) are fitted, by linear least squares, with the group's
   periodic response: a mean and the odd harmonics ``k f`` of the bar frequency that lie below
   the Nyquist frequency (cos and sin, so that a small error of the registered phase costs
   little). The group's ``I_max`` and ``I_min`` are the fitted period's values at the centres of
   its white and black bars (the average intensity of the bars' centres), and its CTF their
   modulation (001 eq. 5) divided by the target's own modulation (001 eq. 4).

Above 1/6 cy/px the third harmonic lies beyond Nyquist: a sampled profile carries no separate
information on it (it aliases), so the fitted period holds the fundamental only there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.mtf import BarTarget, modulation

__all__ = ["CtfMeasurement", "register_target", "measure_ctf", "check_profile", "MIN_GROUPS"]

#: A profile must cross at least this many whole groups.
MIN_GROUPS = 5


@dataclass(frozen=True)
class CtfMeasurement:
    """The CTF of each bar group on one profile.

    Attributes
    ----------
    group : (G,) int ndarray
        Index of the group in the target.
    f_cy_px : (G,) ndarray
        Bar frequency, cycles per pixel (GSD / pair width).
    ctf : (G,) ndarray
        Contrast transfer (output modulation / input modulation, 001 eq. 4–5).
    n_samples : (G,) int ndarray
        Samples used per group.
    start_px, gsd_mm : float
        The registration of the target on the profile.
    """

    group: np.ndarray
    f_cy_px: np.ndarray
    ctf: np.ndarray
    n_samples: np.ndarray
    start_px: float
    gsd_mm: float


def check_profile(x_px, intensity_dn, saturation_dn=np.inf, where: str = "profile"):
    """Finite, increasing positions and finite, unsaturated intensities, else a clear error."""
    x = np.asarray(x_px, dtype=float)
    y = np.asarray(intensity_dn, dtype=float)
    if x.ndim != 1 or x.shape != y.shape:
        raise InputError(f"{where}: positions and intensities must be 1-D of equal length")
    if x.size < 20:
        raise ObservationError(f"{where}: {x.size} samples; a bar profile needs many more")
    bad = ~(np.isfinite(x) & np.isfinite(y))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{where}: NaN or infinite value at sample {i} (x = {x[i]!r})")
    if np.any(np.diff(x) <= 0):
        raise InputError(f"{where}: positions x_px must increase strictly; sort the profile")
    return x, y


def _edge_crossings(x, y, edges_px, window_px):
    """The 50 % level crossing nearest each nominal edge (NaN where none is clear)."""
    out = np.full(edges_px.size, np.nan)
    for i, e in enumerate(edges_px):
        sel = np.flatnonzero(np.abs(x - e) <= window_px)
        if sel.size < 4:
            continue
        ys = y[sel]
        lo, hi = np.percentile(ys, 10), np.percentile(ys, 90)
        if hi - lo <= 0:
            continue
        half = 0.5 * (lo + hi)
        s = np.sign(ys - half)
        cross = np.flatnonzero(s[:-1] * s[1:] < 0)
        if cross.size != 1:
            continue
        j = cross[0]
        t = (half - ys[j]) / (ys[j + 1] - ys[j])
        out[i] = x[sel[j]] + t * (x[sel[j + 1]] - x[sel[j]])
    return out


def register_target(x_px, intensity, target: BarTarget, start_px: float, gsd_mm: float):
    """Refine the target's start (px) and the GSD (mm) from the coarse groups' bar edges.

    Returns ``(start_px, gsd_mm)``. Raises :class:`ObservationError` when fewer than 6 edges are
    found near their nominal positions (a wrong ``start_px`` or GSD, or no target).
    """
    x, y = np.asarray(x_px, float), np.asarray(intensity, float)
    for _ in range(2):
        edges_mm, halfbar = [], []
        for s, p, n in zip(target.group_start_mm(), target.pair_mm, target.n_pairs, strict=True):
            if p / 2 / gsd_mm >= 6.0:  # bars at least 6 px wide
                e = s + p / 2 * np.arange(1, 2 * n)  # the group's inner edges
                edges_mm.append(e)
                halfbar.append(np.full(e.size, p / 4 / gsd_mm))
        if not edges_mm:
            raise ObservationError(
                "no bar group is wide enough (6 px per bar) to register the target"
            )
        e_mm = np.concatenate(edges_mm)
        win = np.concatenate(halfbar)
        nominal = start_px + e_mm / gsd_mm
        found = np.array(
            [_edge_crossings(x, y, np.array([e]), w)[0] for e, w in zip(nominal, win, strict=True)]
        )
        ok = np.isfinite(found)
        if ok.sum() < 6:
            raise ObservationError(
                f"found {int(ok.sum())} of the target's {e_mm.size} coarse bar edges near their "
                "expected positions; check start_px and gsd_mm of the bar file"
            )
        A = np.column_stack([np.ones(ok.sum()), e_mm[ok]])
        (start_px, inv_gsd), *_ = np.linalg.lstsq(A, found[ok], rcond=None)
        gsd_mm = 1.0 / inv_gsd
    return float(start_px), float(gsd_mm)


def _harmonics(f: float) -> np.ndarray:
    """The odd harmonics of ``f`` below Nyquist (the fundamental always)."""
    k = np.arange(1, 100, 2)
    return k[(k * f < 0.5) | (k == 1)]


def _group_ctf(x, y, f, x_white):
    """Fit the periodic response of one group; returns (I_max, I_min) of its band-limited part."""
    k = _harmonics(f)
    ph = 2 * np.pi * f * (x - x_white)
    cols = [np.ones_like(x)]
    for kk in k:
        cols += [np.cos(kk * ph), np.sin(kk * ph)]
    A = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    # the fitted band-limited period at the white and the black bar's centre (phase 0 and π):
    # values at fixed points are unbiased by noise, unlike the fitted curve's extremes
    w = np.full(2, coef[0])
    for i, kk in enumerate(k):
        w += coef[1 + 2 * i] * np.cos(kk * np.array([0.0, np.pi]))
    return float(w[0]), float(w[1])


def measure_ctf(
    x_px,
    intensity_dn,
    target: BarTarget,
    start_px: float,
    gsd_mm: float,
    *,
    dark_dn: float = 0.0,
    saturation_dn: float = np.inf,
    margin_px: float = 4.0,
    register: bool = True,
) -> CtfMeasurement:
    """The CTF of every group that lies wholly on the profile (001 eq. 4–5).

    Parameters
    ----------
    x_px, intensity_dn : (N,) array_like
        The profile: pixel positions along the line and raw intensities.
    target : BarTarget
    start_px, gsd_mm : float
        Approximate position of the target's start on the profile (px, to a few px) and the GSD
        (mm); refined by :func:`register_target` unless ``register`` is False.
    dark_dn : float
        Dark level subtracted from the intensities (a dark frame's mean).
    saturation_dn : float
        Samples at or above it inside the target are an error (saturated bars).
    margin_px : float
        Samples this close to a group's ends are left out (≥ 3σ of the blur).

    Raises
    ------
    InputError
        NaN or infinite values, positions not increasing.
    ObservationError
        Saturated samples, fewer than :data:`MIN_GROUPS` groups on the profile, a group with too
        few samples, a registration that finds no edges.
    """
    x, y = check_profile(x_px, intensity_dn)
    if not (np.isfinite(start_px) and np.isfinite(gsd_mm) and gsd_mm > 0):
        raise InputError("start_px must be finite and gsd_mm positive")
    end_px = start_px + target.length_mm() / gsd_mm
    inside = (x >= start_px - 2) & (x <= end_px + 2)
    if saturation_dn > 255 and np.all(y == np.round(y)) and 0 <= y.min() and y.max() <= 255:
        raise InputError(  # 8-bit profiles were once measured against a 12-bit bar file
            f"the profile holds 8-bit values (whole numbers 0…255, at most {y.max():g} DN) but "
            f"the bar file's saturation_dn is {saturation_dn:g}: give saturation_dn = 255 and "
            "dark_dn in the profile's DN (or the profile as recorded, in the bar file's DN)"
        )
    sat = inside & (y >= saturation_dn)
    if sat.any():
        i = int(np.flatnonzero(sat)[0])
        raise ObservationError(
            f"the profile is saturated on the target ({int(sat.sum())} samples at ≥ "
            f"{saturation_dn:g} DN, first at x = {x[i]:g} px); record it with a shorter exposure"
        )
    y = y - dark_dn
    level = float(np.median(y[inside])) if inside.any() else float(np.median(y))
    if not level > 0:
        raise InputError(
            f"dark_dn = {dark_dn:g} DN is at or above the profile's median level on the target "
            f"({level + dark_dn:g} DN): the dark level must be below the bars' signal; check "
            "dark_dn of the bar file (a dark frame's mean, in the profile's DN)"
        )
    if register:
        start_px, gsd_mm = register_target(x, y, target, start_px, gsd_mm)
    starts = start_px + target.group_start_mm() / gsd_mm
    groups, fs, ctfs, ns = [], [], [], []
    m_in = target.input_modulation()
    for g, (s, p, n) in enumerate(zip(starts, target.pair_mm, target.n_pairs, strict=True)):
        p_px = p / gsd_mm
        e = s + n * p_px
        if s < x[0] or e > x[-1]:
            continue
        sel = (x >= s + margin_px) & (x <= e - margin_px)
        f = gsd_mm / p
        if sel.sum() < 2 * _harmonics(f).size + 4:
            raise ObservationError(
                f"bar group {g} ({p:g} mm pairs) has {int(sel.sum())} samples inside its "
                f"{margin_px:g}-px margins; its bars are too few for the blur"
            )
        i_max, i_min = _group_ctf(x[sel], y[sel], f, s + p_px / 4)
        if p_px >= 12.0 and i_max < i_min:  # a resolved group dark where it should be white
            raise ObservationError(
                f"bar group {g} ({p:g} mm pairs, {p_px:.0f} px) is dark where its white bars "
                "should be: the profile is mirrored or shifted by half a pair, or pair_mm lists "
                "the groups in reverse order; give the profile in the target's direction "
                "(coarse groups first) and check start_px"
            )
        groups.append(g)
        fs.append(f)
        ctfs.append(float(modulation(i_max, i_min)) / m_in)  # 001 eq. (5) and (4)
        ns.append(int(sel.sum()))
    if len(groups) < MIN_GROUPS:
        raise ObservationError(
            f"the profile crosses {len(groups)} whole bar groups; at least {MIN_GROUPS} are "
            "needed (check start_px, gsd_mm and that the profile covers the target)"
        )
    return CtfMeasurement(
        np.array(groups), np.array(fs), np.array(ctfs), np.array(ns), start_px, gsd_mm
    )
