"""Image sharpness from a user's recordings: MTF from bar-target profiles and from slanted edges.

The in-memory cores (frozen inputs and options → one :class:`MtfResult`) are what the ``mtf``
chapter and the command line both call:

* :func:`mtf_from_bars` — the CTF of each bar group (:func:`hsgeo.measure.ctf.measure_ctf`,
  001 eq. 4–5), then the MTF by the Coltman series (:func:`hsgeo.mtf.mtf_from_ctf_samples`,
  001 eq. 7 corrected), with the "borderline" frequency where it falls to 0.1 (001 §4) and the
  determined GSD (:func:`determined_gsd_mm`);
* :func:`mtf_from_edge` — the ISO 12233 slanted-edge MTF (:func:`hsgeo.measure.edge.slanted_edge`).

The file front ends :func:`bars_files` and :func:`edge_file` read through :mod:`hsgeo.io.mtf`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.errors import InputError
from hsgeo.measure.ctf import measure_ctf
from hsgeo.measure.edge import find_edge_roi, slanted_edge
from hsgeo.mtf import BarTarget, crossing_frequency, mtf_from_ctf_samples

__all__ = [
    "BarInputs",
    "BarOptions",
    "EdgeInputs",
    "EdgeOptions",
    "MtfResult",
    "BORDERLINE_LEVEL",
    "determined_gsd_mm",
    "mtf_from_bars",
    "mtf_from_edge",
    "bars_files",
    "BarProfilesResult",
    "edge_file",
    "parse_roi",
]

#: The MTF level of the "borderline frequency" (001 §4: the curves fall "to 0.1, with a
#: borderline frequency of around 0.3 cy/px for blue").
BORDERLINE_LEVEL = 0.1


def determined_gsd_mm(gsd_mm: float, f_borderline_cy_px: float) -> float:
    """The determined (actual) GSD: the bar width whose frequency the MTF falls to 0.1 at.

    A pair of period ``1/f`` px has bars of ``1/(2f)`` px; the finest bar the system still
    transfers at 10 % modulation is ``gsd_mm / (2 f_borderline)`` mm wide. It equals the
    theoretical GSD for a borderline frequency of 0.5 cy/px (Nyquist). Our definition (001
    does not give one).

    References
    ----------
    .. [1] Krtalić, A., Miljković, V., Gajski, D. and Racetin, I. (2019). Spatial distortion
           assessments of a low-cost laboratory and field hyperspectral imaging system. Sensors
           19(19), 4267 (paper 001).
    """
    return float(gsd_mm / (2.0 * f_borderline_cy_px))


@dataclass(frozen=True)
class BarInputs:
    """One bar-target profile and what is known about it (see :mod:`hsgeo.io.mtf`)."""

    x_px: np.ndarray
    intensity_dn: np.ndarray
    target: BarTarget
    start_px: float
    gsd_mm: float
    dark_dn: float = 0.0
    saturation_dn: float = np.inf


def _default_f():
    return tuple(np.round(np.arange(0.025, 0.5001, 0.025), 4))


@dataclass(frozen=True)
class BarOptions:
    """Frequencies of the output MTF (cy/px), the margin at group ends (px), registration."""

    f_cy_px: tuple = field(default_factory=_default_f)
    margin_px: float = 4.0
    register: bool = True


@dataclass(frozen=True)
class EdgeInputs:
    """An image holding a slanted edge and the region ``(x0, y0, x1, y1)`` around it (None:
    found automatically).
    """

    image: np.ndarray
    roi: tuple | None = None


@dataclass(frozen=True)
class EdgeOptions:
    """Oversampling of the ESF (ISO 12233: 4) and the finite-difference correction."""

    oversample: int = 4
    correct: bool = True


@dataclass(frozen=True)
class MtfResult:
    """An MTF estimate (from bars or from an edge) with what it was measured from.

    Attributes
    ----------
    method : {"bars", "edge"}
    frequency_cy_px, mtf : (M,) ndarray
    borderline_cy_px : float
        Where the MTF falls to :data:`BORDERLINE_LEVEL` (NaN if not within the frequencies).
    lsf_fwhm_px, edge_angle_deg : float
        Slanted edge only (NaN for bars).
    ctf_frequency_cy_px, ctf : (G,) ndarray
        Bars only: the measured CTF of each group.
    gsd_mm, start_px : float
        Bars only: the registration (the GSD refined from the bar edges).
    determined_gsd_mm : float
        Bars only: :func:`determined_gsd_mm` of the borderline frequency (NaN if beyond the bars).
    roi : tuple
        Edge only: the region used.
    """

    method: str
    frequency_cy_px: np.ndarray
    mtf: np.ndarray
    borderline_cy_px: float = float("nan")
    lsf_fwhm_px: float = float("nan")
    edge_angle_deg: float = float("nan")
    ctf_frequency_cy_px: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ctf: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gsd_mm: float = float("nan")
    start_px: float = float("nan")
    determined_gsd_mm: float = float("nan")
    roi: tuple | None = None

    def to_dict(self) -> dict:
        """Plain JSON-ready values (NaN → None)."""

        def num(v):
            v = float(v)
            return v if np.isfinite(v) else None

        out = {
            "method": self.method,
            "frequency_cy_px": [num(v) for v in self.frequency_cy_px],
            "mtf": [num(v) for v in self.mtf],
            "borderline_cy_px": num(self.borderline_cy_px),
            "borderline_level": BORDERLINE_LEVEL,
        }
        if self.method == "edge":
            out |= {
                "edge_angle_deg": num(self.edge_angle_deg),
                "lsf_fwhm_px": num(self.lsf_fwhm_px),
                "roi": list(self.roi) if self.roi is not None else None,
            }
        else:
            out |= {
                "ctf_frequency_cy_px": [num(v) for v in self.ctf_frequency_cy_px],
                "ctf": [num(v) for v in self.ctf],
                "gsd_mm": num(self.gsd_mm),
                "start_px": num(self.start_px),
                "determined_gsd_mm": num(self.determined_gsd_mm),
            }
        return out


def mtf_from_bars(inputs: BarInputs, options: BarOptions = BarOptions()) -> MtfResult:
    """CTF per bar group (001 eq. 5), then MTF by the Coltman series (001 eq. 7 corrected).

    The series needs the CTF at odd multiples of each frequency: it is interpolated linearly
    between the groups, and taken as 0 above the finest group's frequency.

    References
    ----------
    .. [1] Krtalić, A., Miljković, V., Gajski, D. and Racetin, I. (2019). Spatial distortion
           assessments of a low-cost laboratory and field hyperspectral imaging system. Sensors
           19(19), 4267 (paper 001).
    """
    m = measure_ctf(
        inputs.x_px,
        inputs.intensity_dn,
        inputs.target,
        inputs.start_px,
        inputs.gsd_mm,
        dark_dn=inputs.dark_dn,
        saturation_dn=inputs.saturation_dn,
        margin_px=options.margin_px,
        register=options.register,
    )
    f = np.asarray(options.f_cy_px, dtype=float)
    if f.ndim != 1 or f.size == 0 or np.any(~np.isfinite(f)) or np.any(f <= 0):
        raise InputError("the output frequencies must be positive finite numbers (cy/px)")
    f = f[f <= m.f_cy_px.max() + 1e-12]  # the bars say nothing beyond the finest group
    mtf = mtf_from_ctf_samples(m.f_cy_px, m.ctf, f, nyquist_cy_px=0.5)  # band-limited CTFs
    fb = crossing_frequency(np.r_[0.0, f], np.r_[1.0, mtf], BORDERLINE_LEVEL)
    return MtfResult(
        "bars",
        f,
        mtf,
        borderline_cy_px=fb,
        ctf_frequency_cy_px=m.f_cy_px,
        ctf=m.ctf,
        gsd_mm=m.gsd_mm,
        start_px=m.start_px,
        determined_gsd_mm=determined_gsd_mm(m.gsd_mm, fb) if np.isfinite(fb) else float("nan"),
    )


def mtf_from_edge(inputs: EdgeInputs, options: EdgeOptions = EdgeOptions()) -> MtfResult:
    """The ISO 12233 slanted-edge MTF of the region (found automatically when not given)."""
    img = np.asarray(inputs.image, dtype=float)
    if img.ndim != 2:
        raise InputError(f"the edge image must be 2-D (grey), got shape {img.shape}")
    roi = inputs.roi if inputs.roi is not None else find_edge_roi(img)
    x0, y0, x1, y1 = (int(v) for v in roi)
    if not (0 <= x0 < x1 <= img.shape[1] and 0 <= y0 < y1 <= img.shape[0]):
        raise InputError(
            f"--roi {x0},{y0},{x1},{y1} is not inside the {img.shape[1]} × {img.shape[0]} px "
            "image; give x0,y0,x1,y1 with x0 < x1, y0 < y1 in pixels"
        )
    e = slanted_edge(img[y0:y1, x0:x1], oversample=options.oversample, correct=options.correct)
    return MtfResult(
        "edge",
        e.f_cy_px,
        e.mtf,
        borderline_cy_px=crossing_frequency(e.f_cy_px, e.mtf, BORDERLINE_LEVEL),
        lsf_fwhm_px=e.lsf_fwhm_px,
        edge_angle_deg=e.edge_angle_deg,
        roi=(x0, y0, x1, y1),
    )


@dataclass(frozen=True)
class BarProfilesResult:
    """The MTF of every profile of a profile file (:func:`bars_files`).

    Attributes
    ----------
    by_row : dict
        ``{row: MtfResult}``, in the file's order; the row is None for a file of one profile.
    """

    by_row: dict

    def to_dict(self) -> dict:
        """``{"profiles": [{"row": row, **MtfResult.to_dict()}, ...]}``, or the one profile's
        dict (with its ``row``) for a file of one profile.
        """
        d = {"profiles": [{"row": r, **res.to_dict()} for r, res in self.by_row.items()]}
        return d["profiles"][0] if len(self.by_row) == 1 else d


def bars_files(profiles, bars, options: BarOptions = BarOptions()) -> BarProfilesResult:
    """``hsgeo mtf``: the MTF of every profile of the file (:class:`BarProfilesResult`)."""
    from hsgeo.errors import ObservationError
    from hsgeo.io.mtf import read_bars, read_profiles

    target, prof = read_bars(bars)
    out = {}
    for row, (x, y) in read_profiles(profiles).items():
        inp = BarInputs(x, y, target, prof.start_px, prof.gsd_mm, prof.dark_dn, prof.saturation_dn)
        try:
            out[row] = mtf_from_bars(inp, options)
        except (ObservationError, InputError) as exc:
            where = f"profile file {profiles}" + ("" if row is None else f", row {row}")
            raise type(exc)(f"{where}: {exc}") from None
    return BarProfilesResult(out)


def parse_roi(text: str | None) -> tuple | None:
    """``"x0,y0,x1,y1"`` → a tuple of 4 ints (None stays None), else a clear error."""
    if text is None:
        return None
    parts = text.split(",")
    try:
        vals = tuple(int(p) for p in parts)
    except ValueError:
        vals = ()
    if len(vals) != 4 or vals[0] >= vals[2] or vals[1] >= vals[3] or min(vals) < 0:
        raise InputError(
            f"--roi {text!r}: give four whole pixel numbers x0,y0,x1,y1 with x0 < x1 and y0 < y1"
        )
    return vals


def edge_file(image, roi: str | None = None, options: EdgeOptions = EdgeOptions()) -> MtfResult:
    """``hsgeo mtf-edge``: the slanted-edge MTF of an image file."""
    from hsgeo.errors import ObservationError
    from hsgeo.io.mtf import read_gray_image

    box = parse_roi(roi)
    img = read_gray_image(image)
    try:
        return mtf_from_edge(EdgeInputs(img, box), options)
    except ObservationError as exc:
        raise ObservationError(f"image file {image}: {exc}") from None
