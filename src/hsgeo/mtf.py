"""Image sharpness: CTF ↔ MTF (the Coltman series), bar targets, and MTF from an edge spread.

Base maths of the ``mtf`` chapter (001 §2.3, eq. 3–7):

* the modulation of a signal (001 eq. 3 and 5) and the MTF as the ratio of output to input
  modulation (001 eq. 4);
* the series between the square-wave response (CTF, contrast transfer function, of a bar
  target) and the sine-wave response (MTF) of Coltman (1954): :func:`ctf_from_mtf` (the
  forward series, 001 eq. 6 corrected) and :func:`mtf_from_ctf` (its inverse, 001 eq. 7
  corrected), with the paper's printed forms kept as :func:`ctf_from_mtf_printed` and
  :func:`mtf_from_ctf_printed` so that their error can be shown;
* the layout of a bar target (:class:`BarTarget`: groups of black/white pairs whose widths shrink
  geometrically);
* analytic MTFs: a Gaussian blur, the pixel aperture;
* the slanted-edge steps after the edge is projected (ISO 12233): ESF → LSF → MTF with the
  Hamming window and the finite-difference correction (:func:`mtf_from_esf`).

The derivation of the series. A bar target of unit contrast is the square wave
``s(x) = (4/π) Σ_{k odd} (−1)^((k−1)/2) cos(2π k f x) / k`` (x = 0 at a white bar's centre). A
linear system multiplies each harmonic by ``MTF(k f)``; the image's modulation is its value at
the white bar's centre, so

    CTF(f) = (4/π) Σ_{k odd} (−1)^((k−1)/2) MTF(k f) / k                       (Coltman eq. 5)

Inverting the series term by term (a Möbius inversion over the odd integers) gives

    MTF(f) = (π/4) Σ_{k odd} B_k CTF(k f) / k,
    B_k = (−1)^m (−1)^((k−1)/2) for square-free k with m distinct prime factors, else 0,

i.e. ``MTF(f) = (π/4)[CTF(f) + CTF(3f)/3 − CTF(5f)/5 + CTF(7f)/7 + CTF(11f)/11 − CTF(13f)/13
− CTF(15f)/15 + CTF(17f)/17 + …]``. 001 prints eq. (6) with π/4 in place of 4/π and with the
inverse series' signs, and both (6) and (7) truncated after the 11th harmonic.

References
----------
Coltman, J. W. (1954). The specification of imaging properties by response to a sine wave
input. J. Opt. Soc. Am. 44(6), 468–471.
ISO 12233:2017, Photography — Electronic still picture imaging — Resolution and spatial
frequency responses (the slanted-edge method, Annex D).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "modulation",
    "odd_harmonics",
    "coltman_ctf_coefficients",
    "coltman_mtf_coefficients",
    "ctf_from_mtf",
    "mtf_from_ctf",
    "mtf_from_ctf_samples",
    "ctf_band_limited",
    "ctf_from_mtf_printed",
    "mtf_from_ctf_printed",
    "mtf_gaussian",
    "mtf_pixel",
    "BarTarget",
    "mtf_from_esf",
    "crossing_frequency",
    "K_MAX",
]

#: Harmonics kept by default in the series: odd k up to this (beyond, the terms are < 1/K_MAX).
K_MAX = 99


def modulation(i_max, i_min):
    """``(I_max − I_min) / (I_max + I_min)`` (001 eq. 3 and 5).

    >>> float(modulation(3.0, 1.0))
    0.5
    """
    i_max = np.asarray(i_max, dtype=float)
    i_min = np.asarray(i_min, dtype=float)
    return (i_max - i_min) / (i_max + i_min)  # 001 eq. (3), (5)


def odd_harmonics(k_max: int = K_MAX) -> np.ndarray:
    """The odd integers 1, 3, …, ≤ ``k_max``."""
    return np.arange(1, int(k_max) + 1, 2)


def _n_prime_factors_if_squarefree(k: int) -> int | None:
    """Number of distinct prime factors of ``k``, or None when a square divides it."""
    m, p, n = 0, 2, k
    while p * p <= n:
        if n % p == 0:
            n //= p
            if n % p == 0:
                return None
            m += 1
        p += 1
    return m + (1 if n > 1 else 0)


def coltman_ctf_coefficients(k_max: int = K_MAX) -> tuple[np.ndarray, np.ndarray]:
    """Odd ``k`` and the forward series' coefficients ``(−1)^((k−1)/2) / k`` (times 4/π)."""
    k = odd_harmonics(k_max)
    return k, np.where(((k - 1) // 2) % 2 == 0, 1.0, -1.0) / k


def coltman_mtf_coefficients(k_max: int = K_MAX) -> tuple[np.ndarray, np.ndarray]:
    """Odd ``k`` and the inverse series' coefficients ``B_k / k`` (times π/4), Coltman (1954).

    >>> k, c = coltman_mtf_coefficients(15)
    >>> [int(round(x)) for x in c * k]
    [1, 1, -1, 1, 0, 1, -1, -1]
    """
    k = odd_harmonics(k_max)
    b = np.zeros(k.size)
    for i, kk in enumerate(k):
        m = _n_prime_factors_if_squarefree(int(kk))
        if m is not None:
            b[i] = (-1.0) ** m * (-1.0) ** ((kk - 1) // 2)
    return k, b / k


def ctf_from_mtf(mtf, f_cy_px, k_max: int = K_MAX):
    """Square-wave response from the sine-wave response (Coltman 1954; 001 eq. 6 corrected).

    Parameters
    ----------
    mtf : callable
        ``mtf(f) -> ndarray``, the MTF at any frequency (cy/px), vectorised.
    f_cy_px : array_like
        Frequencies of the bar target.
    k_max : int
        Last odd harmonic of the series.
    """
    f = np.asarray(f_cy_px, dtype=float)
    k, c = coltman_ctf_coefficients(k_max)
    terms = mtf(f[..., None] * k) * c
    return 4.0 / np.pi * terms.sum(axis=-1)  # Coltman (1954) eq. (5); 001 eq. (6) corrected


def mtf_from_ctf(ctf, f_cy_px, k_max: int = K_MAX):
    """Sine-wave response from the square-wave response (Coltman 1954; 001 eq. 7 corrected).

    ``ctf`` is a callable ``ctf(f)``; for measured CTFs, interpolate them (and return 0 above
    the highest measured frequency, where the series then stops).
    """
    f = np.asarray(f_cy_px, dtype=float)
    k, c = coltman_mtf_coefficients(k_max)
    terms = ctf(f[..., None] * k) * c
    return np.pi / 4.0 * terms.sum(axis=-1)  # Coltman (1954) eq. (6); 001 eq. (7)


def mtf_from_ctf_samples(
    f_measured, ctf_measured, f_cy_px, k_max: int = K_MAX, nyquist_cy_px: float | None = None
):
    """MTF from CTFs measured at some frequencies (bar groups).

    The series of :func:`mtf_from_ctf` runs on the CTF interpolated linearly between the
    measured frequencies and taken as **0 above the highest measured one** (the series stops
    there). With ``nyquist_cy_px`` (0.5 for pixels), the measured CTFs are taken as
    *band-limited*: the square-wave response made of the harmonics below Nyquist only (what a
    sampled profile holds, :mod:`hsgeo.measure.ctf`); then the harmonics ``k ≥ 3`` with
    ``k f ≥ nyquist`` are left out of the series too, which inverts the band-limited forward
    series exactly (the Möbius sum runs over the same products ``j k``).
    """
    fm = np.asarray(f_measured, dtype=float)
    cm = np.asarray(ctf_measured, dtype=float)
    order = np.argsort(fm)
    fm, cm = fm[order], cm[order]
    f = np.asarray(f_cy_px, dtype=float)
    k, c = coltman_mtf_coefficients(k_max)
    fk = f[..., None] * k
    if nyquist_cy_px is None:
        ctf = np.where(fk <= fm[-1], np.interp(fk, fm, cm), 0.0)
    else:
        ctf = np.where(fk <= fm[-1], _interp_band_limited(fk, fm, cm, nyquist_cy_px), 0.0)
        ctf = np.where((k >= 3) & (fk >= nyquist_cy_px), 0.0, ctf)
    return np.pi / 4.0 * (ctf * c).sum(axis=-1)  # Coltman (1954) eq. (6); 001 eq. (7)


def _interp_band_limited(fq, fm, cm, nyquist):
    """Linear interpolation of a band-limited CTF, which jumps where a harmonic crosses
    Nyquist (f = nyquist / k, k = 3, 5, …): across a jump, the value is extrapolated from the
    two measurements on the query's side of it.
    """
    fq = np.asarray(fq, dtype=float)
    out = np.interp(fq, fm, cm)
    i = np.clip(np.searchsorted(fm, fq) - 1, 0, fm.size - 2)  # segment [fm[i], fm[i+1]]
    kk = np.floor(nyquist / fm[i])  # harmonics below Nyquist at the segment's ends
    kk1 = np.floor(nyquist / fm[i + 1])
    jump = (kk != kk1) & (fq > fm[0]) & (fq < fm[-1])
    if not np.any(jump):
        return out
    # the jump closest below fm[i]'s harmonic count: f_j = nyquist / (largest odd k ≤ kk)
    k_odd = np.where(kk % 2 == 1, kk, kk - 1)
    f_jump = nyquist / np.maximum(k_odd, 1)
    left = jump & (fq < f_jump)
    right = jump & ~left
    il = np.clip(i - 1, 0, fm.size - 2)  # left pair (fm[i-1], fm[i])
    ir = np.clip(i + 1, 0, fm.size - 2)  # right pair (fm[i+1], fm[i+2])
    for sel, j in ((left, il), (right, ir)):
        if np.any(sel):
            f0, f1 = fm[j][sel], fm[j + 1][sel]
            c0, c1 = cm[j][sel], cm[j + 1][sel]
            out[sel] = c0 + (c1 - c0) * (fq[sel] - f0) / (f1 - f0)
    return out


def ctf_band_limited(mtf, f_cy_px, nyquist_cy_px: float = 0.5, k_max: int = K_MAX):
    """The square-wave response made of the harmonics below Nyquist only (the fundamental
    always): what a bar group's sampled profile holds (:mod:`hsgeo.measure.ctf`).
    """
    f = np.asarray(f_cy_px, dtype=float)
    k, c = coltman_ctf_coefficients(k_max)
    fk = f[..., None] * k
    keep = (fk < nyquist_cy_px) | (k == 1)
    return 4.0 / np.pi * np.where(keep, mtf(fk) * c, 0.0).sum(axis=-1)


_PRINTED_K = np.array([1, 3, 5, 7, 11])
_PRINTED_K.setflags(write=False)
_PRINTED_SIGN = np.array([1.0, 1.0, -1.0, 1.0, 1.0])
_PRINTED_SIGN.setflags(write=False)


def ctf_from_mtf_printed(mtf, f_cy_px):
    """001 eq. (6) as printed: ``(π/4)|M(f) + M(3f)/3 − M(5f)/5 + M(7f)/7 + M(11f)/11|``.

    Wrong (kept to show its error): the factor is 4/π and the signs alternate; see
    :func:`ctf_from_mtf`.
    """
    f = np.asarray(f_cy_px, dtype=float)
    terms = mtf(f[..., None] * _PRINTED_K) * _PRINTED_SIGN / _PRINTED_K
    return np.abs(np.pi / 4.0 * terms.sum(axis=-1))  # 001 eq. (6) as printed


def mtf_from_ctf_printed(ctf, f_cy_px):
    """001 eq. (7) as printed: the inverse series truncated after the 11th harmonic."""
    f = np.asarray(f_cy_px, dtype=float)
    terms = ctf(f[..., None] * _PRINTED_K) * _PRINTED_SIGN / _PRINTED_K
    return np.abs(np.pi / 4.0 * terms.sum(axis=-1))  # 001 eq. (7) as printed


def mtf_gaussian(f_cy_px, sigma_px):
    """MTF of a Gaussian blur of standard deviation ``sigma_px``: exp(−2π²σ²f²)."""
    f = np.asarray(f_cy_px, dtype=float)
    return np.exp(-2.0 * np.pi**2 * np.asarray(sigma_px, dtype=float) ** 2 * f**2)


def mtf_pixel(f_cy_px, width_px: float = 1.0):
    """MTF of a square pixel aperture of ``width_px``: |sinc(w f)| (100 % fill factor)."""
    return np.abs(np.sinc(width_px * np.asarray(f_cy_px, dtype=float)))


@dataclass(frozen=True)
class BarTarget:
    """A bar target: groups of black/white pairs laid out one after another along a line.

    Attributes
    ----------
    pair_mm : tuple of float
        Width of one black + white pair of each group (the period), mm.
    n_pairs : tuple of int
        Number of pairs of each group.
    white_reflectance, black_reflectance : float
        Reflectances of the bars (the input modulation, 001 eq. 4, is their modulation).

    Each group starts with a white bar; group ``g`` starts where group ``g − 1`` ends, at
    :meth:`group_start_mm` from the target's start. Before and after the target lies white.
    """

    pair_mm: tuple
    n_pairs: tuple
    white_reflectance: float = 0.90
    black_reflectance: float = 0.04

    def __post_init__(self):
        p, n = np.asarray(self.pair_mm, float), np.asarray(self.n_pairs, float)
        if p.ndim != 1 or p.size == 0 or p.shape != n.shape:
            raise InputError("a bar target needs as many pair widths as pair counts (≥ 1 group)")
        if not (np.all(np.isfinite(p)) and np.all(p > 0)):
            raise InputError("the bar target's pair widths must be positive numbers (mm)")
        if not np.all((n >= 1) & (n == np.round(n))):
            raise InputError("the bar target's pair counts must be whole numbers ≥ 1")
        if not (0 <= self.black_reflectance < self.white_reflectance):
            raise InputError("the target's black reflectance must be below its white one")

    @classmethod
    def geometric(
        cls,
        widest_pair_mm: float,
        narrowest_pair_mm: float,
        ratio: float,
        min_group_mm: float = 0.0,
        min_pairs: int = 2,
        **kw,
    ) -> BarTarget:
        """Pairs shrinking by ``ratio`` from the widest to the narrowest; each group has
        ``min_pairs`` pairs, or more so that it spans at least ``min_group_mm``.
        """
        n = int(np.floor(np.log(widest_pair_mm / narrowest_pair_mm) / np.log(ratio) + 0.5)) + 1
        p = widest_pair_mm / ratio ** np.arange(n)
        k = np.maximum(min_pairs, np.ceil(min_group_mm / p - 1e-9)).astype(int)
        return cls(tuple(float(x) for x in p), tuple(int(x) for x in k), **kw)

    @property
    def n_groups(self) -> int:
        return len(self.pair_mm)

    def group_start_mm(self) -> np.ndarray:
        """Start of each group (its first white bar's left edge), mm from the target's start."""
        w = np.asarray(self.pair_mm) * np.asarray(self.n_pairs)
        return np.concatenate([[0.0], np.cumsum(w)[:-1]])

    def length_mm(self) -> float:
        return float(np.sum(np.asarray(self.pair_mm) * np.asarray(self.n_pairs)))

    def input_modulation(self) -> float:
        """Modulation of the target itself (the denominator of 001 eq. 4)."""
        return float(modulation(self.white_reflectance, self.black_reflectance))

    def edges_mm(self) -> np.ndarray:
        """Every bar edge (white → black and black → white), mm from the target's start."""
        out = []
        for s, p, n in zip(self.group_start_mm(), self.pair_mm, self.n_pairs, strict=True):
            out.append(s + p / 2 * np.arange(2 * n + 1))
        return np.unique(np.concatenate(out))

    def reflectance(self, x_mm) -> np.ndarray:
        """Reflectance at ``x_mm`` from the target's start (white outside the target)."""
        x = np.asarray(x_mm, dtype=float)
        out = np.full(x.shape, self.white_reflectance)
        start = self.group_start_mm()
        for s, p, n in zip(start, self.pair_mm, self.n_pairs, strict=True):
            u = x - s
            inside = (u >= 0) & (u < p * n)
            black = inside & (np.mod(u, p) >= p / 2)
            out[black] = self.black_reflectance
        return out


def mtf_from_esf(esf, bin_px: float, *, correct: bool = True):
    """MTF from an oversampled edge spread function (ISO 12233 Annex D steps 4–6).

    Parameters
    ----------
    esf : (N,) ndarray
        The edge spread function on bins of ``bin_px`` (e.g. 0.25 px for 4× oversampling).
    bin_px : float
        Bin width, px.
    correct : bool
        Divide by the MTF of the 3-tap derivative, ``sinc(2 f Δ)``, and of the bin's box,
        ``sinc(f Δ)`` (ISO 12233:2017 corrects the derivative; the box is corrected too here).

    Returns
    -------
    f_cy_px : (N // 2 + 1,) ndarray
    mtf : (N // 2 + 1,) ndarray, 1 at f = 0
    lsf : (N,) ndarray, the windowed line spread function
    """
    esf = np.asarray(esf, dtype=float)
    n = esf.size
    lsf = np.zeros(n)
    lsf[1:-1] = 0.5 * (esf[2:] - esf[:-2])  # ISO 12233 [-1/2, 0, 1/2] derivative
    lsf[0], lsf[-1] = lsf[1], lsf[-2]
    if abs(lsf.min()) > abs(lsf.max()):  # a falling edge: the same LSF, upright
        lsf = -lsf
    w = np.clip(lsf, 0.0, None)
    centre = float(np.sum(w * np.arange(n)) / np.sum(w)) if np.sum(w) > 0 else (n - 1) / 2
    half = max(centre, n - 1 - centre)  # a Hamming window centred on the LSF (ISO 12233)
    lsf = lsf * (0.54 + 0.46 * np.cos(np.pi * (np.arange(n) - centre) / half))
    spec = np.abs(np.fft.rfft(lsf))
    mtf = spec / spec[0]
    f = np.fft.rfftfreq(n, d=bin_px)
    if correct:
        mtf = mtf / np.clip(np.sinc(2.0 * f * bin_px) * np.sinc(f * bin_px), 0.1, None)
    return f, mtf, lsf


def crossing_frequency(f_cy_px, mtf, level: float) -> float:
    """The lowest frequency where ``mtf`` falls to ``level`` (linear interpolation), or NaN."""
    f = np.asarray(f_cy_px, dtype=float)
    m = np.asarray(mtf, dtype=float)
    below = np.flatnonzero(m <= level)
    if below.size == 0 or below[0] == 0:
        return float("nan")
    i = below[0]
    t = (m[i - 1] - level) / (m[i - 1] - m[i])
    return float(f[i - 1] + t * (f[i] - f[i - 1]))
