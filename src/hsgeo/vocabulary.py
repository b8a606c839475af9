"""Words a reader knows for the internal quantity keys and units of the result tables.

The rows of :mod:`hsgeo.report` carry machine keys (``c_minus_mean_band0_450nm_um``, unit
``um``): they are the stable names of ``hsgeo reproduce --json`` (GUIDE §5) and never change.
What a table *shows* is translated here, once, at display time: :func:`quantity_label` turns a
key into a label (``c − mean c, band 0 (450 nm)``), :func:`unit_label` a unit spelling into
typeset units (``µm``, ``mm⁻²``, ``°``). :func:`hsgeo.report.format_rows` (and so
``Reproduction.show``, ``Reproduction.to_text`` and the scoreboard) applies both.

A key is translated by, in order: an exact entry of :data:`LABELS`; the ``σ(…)`` wrapper; the
dotted form ``context.quantity`` (``even_distortion_on.mean_z_c_px`` → ``mean z of principal
distance c — even distortion term on``); space-separated words (``K1 line100 in 1sigma`` →
``K1, line 100, share within 1σ̂``); otherwise word by word on the underscores (:data:`WORDS`
and the patterns of :data:`_PATTERNS`), dropping a trailing unit word that the unit column
already shows. A new key therefore always gets a label without underscores; give it an entry in
:data:`LABELS` when the word-by-word label reads badly.

>>> quantity_label("c_minus_mean_band0_450nm_um")
'c − mean c, band 0 (450 nm)'
>>> unit_label("1/mm2"), unit_label("um"), unit_label("1")
('mm⁻²', 'µm', '—')
>>> quantity_label("zeta0_px line100 in 1sigma")
'principal point ζ0, line 100, share within 1σ̂'
"""

from __future__ import annotations

import re

__all__ = ["LABELS", "UNITS", "WORDS", "quantity_label", "unit_label", "display_unit", "CONTEXTS"]

_SUP = str.maketrans(
    "-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079"
)

#: Unit spellings of the rows (ASCII, as in the JSON) and how a table prints them.
UNITS = {
    "": "—",
    "1": "—",
    "um": "µm",
    "deg": "°",
    "fraction": "share",
    "cy/px": "cycles/px",
    "mm/nm": "mm/nm",
    "%": "%",
}

#: Whole keys with a label of their own (the word-by-word rule would read badly).
LABELS = {
    # frame cameras (OpenCV's names)
    "fx_px": "focal length fx",
    "fy_px": "focal length fy",
    "cx_px": "principal point cx",
    "cy_px": "principal point cy",
    "rms_px": "RMS of the image residuals",
    "sigma0": "a-posteriori σ̂0",
    "f_px_opencv_form": "focal length, OpenCV's form",
    "f_px_photogrammetric_form": "focal length, photogrammetric form",
    "rms_px_opencv_form": "RMS of the residuals, OpenCV's form",
    "rms_px_photogrammetric_form": "RMS of the residuals, photogrammetric form",
    # the line scanner
    "zeta0_px": "principal point ζ0",
    "c_px": "principal distance c",
    "sigma_zeta0_px": "σ̂ of ζ0",
    "sigma_c_px": "σ̂ of c",
    "max_distortion_line100_px": "largest distortion, line 100",
    "max_distortion_visible_px": "largest distortion, visible lines",
    "distortion_450px_line1000_px": "distortion 450 px from ζ0, line 1000",
    # geocoding (000 Tables 2-3)
    "bias_y_m": "mean deviation y",
    "bias_x_m": "mean deviation x",
    "sigma_y_m": "std. deviation y",
    "sigma_x_m": "std. deviation x",
    "sigma_ratio_y": "std. deviation ratio y (uncalibrated / calibrated)",
    "sigma_ratio_x": "std. deviation ratio x (uncalibrated / calibrated)",
    # pushbroom (002)
    "max_abs_c_minus_mean_um": "largest |c − mean c| over the bands",
    "chromatic_shift_at_edge_px": "chromatic shift at the line's end",
    # Rikola (003)
    "domega_deg": "Δω",
    "dphi_deg": "Δφ",
    "dkappa_deg": "Δκ",
    "tx_mm": "base component tx",
    "ty_mm": "base component ty",
    "tz_mm": "base component tz",
}

#: Single words of a key and what a reader calls them.
WORDS = {
    "zeta0": "ζ0",
    "sigma": "σ",
    "sigma0": "σ̂0",
    "sq": "²",
    "nmad": "NMAD",
    "rms": "RMS",
    "sd": "std. deviation",
    "std": "std. deviation",
    "over": "/",
    "rtk": "RTK",
    "seconds": "run time",
    "droll": "Δroll",
    "dpitch": "Δpitch",
    "dyaw": "Δyaw",
    "dE": "ΔE",
    "dN": "ΔN",
    "dH": "ΔH",
    "minus": "−",
    "abs": "|·|",
    "cp": "check-point",
    "tp": "tie-point",
    "en": "horizontal",
    "h": "height",
    "e": "east",
    "n": "north",
    "r2": "R²",
    "opencv": "OpenCV",
    "tau": "τ",
    "omega": "ω",
    "phi": "φ",
    "kappa": "κ",
    "subpix": "sub-pixel",
    "per": "per",
    "z": "z",
    "mean": "mean",
    "max": "max",
    "min": "min",
    "true": "true",
}

#: Contexts of the dotted keys (``context.quantity``).
CONTEXTS = {
    "even_distortion_on": "even distortion term on",
    "even_distortion_off": "even distortion term off",
    "dem_error_on": "with DEM error",
    "dem_error_off": "without DEM error",
    "ripple_on": "distortion ripple on",
    "ripple_off": "distortion ripple off",
    "ripple_shift_z": "pseudo-true − generating value, in σ̂ (distortion ripple)",
    "calibrated": "calibrated",
    "uncalibrated": "uncalibrated",
    "gauss_markov": "Gauss–Markov trajectory error",
    "no_ripple": "no distortion ripple",
}

# unit words that end a key (the unit column shows them)
_UNIT_WORDS = {"px", "m", "mm", "um", "deg", "rad", "s", "nm", "pct", "percent"}
_PATTERNS = (
    (re.compile(r"^band(\d+)$"), r"band \1"),
    (re.compile(r"^line(\d+)$"), r"line \1"),
    (re.compile(r"^sensor(\d+)$"), r"sensor \1"),
    (re.compile(r"^(\d+(?:\.\d+)?)nm$"), r"(\1 nm)"),
    (re.compile(r"^(\d+(?:\.\d+)?)px$"), r"\1 px"),
    (re.compile(r"^(\d+(?:\.\d+)?)s$"), r"\1 s"),
    (re.compile(r"^in (\d)sigma$"), r"share within \1σ̂"),
    (re.compile(r"^within (\d)sigma$"), r"share within \1σ̂"),
)
_TAIL = r"^(band|line|sensor)\d+$|^\d+(\.\d+)?s$"
_QUALIFIER = r"^(line|band|sensor)\d+$|^(un)?calibrated$"
_UNIT_POWER = re.compile(r"^1/([a-zµ]+)(\d*)$")
_POWER = re.compile(r"^([a-zµ]+)(\d+)$")


def unit_label(unit: str | None) -> str:
    """A unit as a table prints it: ``um`` → ``µm``, ``1/mm2`` → ``mm⁻²``, ``deg`` → ``°``,
    ``px2`` → ``px²``; ``""`` and ``"1"`` (a pure number) → ``—``.
    """
    if unit is None:
        return "—"
    u = unit.strip()
    if u in UNITS:
        return UNITS[u]
    u = u.replace("um", "µm")
    m = _UNIT_POWER.match(u)
    if m:
        return f"{m.group(1)}{('-' + (m.group(2) or '1')).translate(_SUP)}"
    m = _POWER.match(u)
    if m:
        return f"{m.group(1)}{m.group(2).translate(_SUP)}"
    return u


def display_unit(quantity: str, unit: str | None) -> str:
    """The unit shown next to ``quantity``: :func:`unit_label`, except where the key's unit is
    short for a longer one: the line scanner's K1–K3 (unit ``px``) are px of distortion per
    power of ``u = (ζ − ζ0) / 100 px`` (000 eq. (2), :func:`hsgeo.sensors.line1d.distortion_px`),
    so K1 is in px at ``|ζ − ζ0|`` = 100 px: ``px / (100 px)³``, K2 ``px / (100 px)⁵``, K3
    ``px / (100 px)⁷``.
    """
    m = re.match(r"^(?:σ\()?K([1-3])\b", quantity)
    if m and unit == "px":
        power = str(2 * int(m.group(1)) + 1).translate(_SUP)
        return f"px / (100 px){power}"
    return unit_label(unit)


def _word(w: str) -> str:
    if w in WORDS:
        return WORDS[w]
    for pattern, repl in _PATTERNS:
        if pattern.match(w):
            return pattern.sub(repl, w)
    return w


def _underscored(key: str) -> str:
    m = re.match(r"^(.+)_within_(\d)sigma$", key)
    if m:
        return f"{quantity_label(m.group(1))}, share within {m.group(2)}σ̂"
    m = re.match(r"^mean_z_(.+)$", key)
    if m:
        return f"mean z of {quantity_label(m.group(1))}"
    words = key.split("_")
    while len(words) > 1 and words[-1] in _UNIT_WORDS:
        words = words[:-1]
    # "mm_per_nm" and "per_mm2" are units, shown in the unit column
    for i, w in enumerate(words):
        if w != "per":
            continue
        if i > 0 and words[i - 1] in _UNIT_WORDS:
            words = words[: i - 1]
            break
        if i + 1 == len(words) or words[i + 1].rstrip("0123456789") in _UNIT_WORDS:
            words = words[:i]
            break
    # "tau_x2" is the correlation time scaled by 2
    words = [
        f"×{w[1:]}" if i > 0 and words[i - 1] == "tau" and re.match(r"^x[\d.]+$", w) else w
        for i, w in enumerate(words)
    ]
    if not words:
        return key.replace("_", " ")
    # "c minus mean" means "c − mean c"
    if len(words) >= 3 and words[1] == "minus" and words[2] == "mean":
        head = f"{_word(words[0])} − mean {_word(words[0])}"
        rest = [_word(w) for w in words[3:]]
        return ", ".join([head, " ".join(rest)]) if rest else head
    if words[0] == "max" and len(words) > 2 and words[1] == "abs":
        return "largest |" + _underscored("_".join(words[2:])) + "|"
    subject, tail = [], []
    for w in words:
        (tail if re.match(_TAIL, w) or tail else subject).append(_word(w))
    label = " ".join(subject)
    if tail:
        label += ", " + tail[0]
    if tail[1:]:
        label += f" ({' '.join(tail[1:])})"
    return label.replace(" ²", "²").replace("_", " ")


def _indexed(base: str, index: list[str]) -> str:
    """``name[i, column]`` of an adjustment's parameter labels (``nodes[3, dE_m]``)."""
    cols = [quantity_label(i) for i in index if not i.isdigit()]
    nums = [i for i in index if i.isdigit()]
    if base == "nodes":
        return ", ".join([f"node {nums[0]}" if nums else "node", *cols])
    if base == "c_mm":
        return ", ".join(["principal distance c", *(f"band {n}" for n in nums), *cols])
    head = _underscored(base)
    return " ".join([head, *cols, *nums])


def quantity_label(quantity: str) -> str:
    """The label a table shows for a row's internal ``quantity`` key (see the module docstring);
    a key that is already words (``MTF line 100 at 0.1 cy/px``) is returned as it is.
    """
    q = quantity.strip()
    if q in LABELS:
        return LABELS[q]
    m = re.match(r"^σ\((.*)\)$", q)
    if m:
        return f"σ̂ of {quantity_label(m.group(1))}"
    m = re.match(r"^(\w+)\[(.+)\]$", q)
    if m:
        return _indexed(m.group(1), [i.strip() for i in m.group(2).split(",")])
    if "." in q and " " not in q and not re.search(r"\d\.\d", q):
        *contexts, last = q.split(".")
        ctx = ", ".join(CONTEXTS.get(c, _underscored(c)) for c in contexts)
        return f"{quantity_label(last)} — {ctx}"
    if " " in q:
        m = re.search(r" (in|within) (\d)sigma$", q)
        if m:
            head = quantity_label(q[: m.start()])
            return f"{head}, share within {m.group(2)}σ̂"
        parts = q.split(" ")
        if "_" in parts[0] or parts[0] in LABELS or re.match(_QUALIFIER, parts[1]):
            rest = [_word(w) for w in parts[1:]]
            return ", ".join([quantity_label(parts[0]), " ".join(rest)])
        return " ".join(_underscored(w) if "_" in w else _word(w) for w in parts)
    if "_" in q:
        return _underscored(q)
    return _word(q)
