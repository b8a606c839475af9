"""The strips of ``hsgeo orthorectify``: line files of any scanning sensor → ortho.Strip.

Two line formats are read (both NetCDF, told apart by their variable):

* hsgeo's recorded flight line (``radiance(band, line, pixel)``, :func:`hsgeo.io.read_lines`):
  the line times ``t0_s + i / line_rate_hz``, the pixel coordinate ζ of the 000 line scanner or
  x (px from the line centre) of the 002 pushbroom camera;
* the LP line files (``lines(line, column, band)``, :mod:`hsgeo.io.lp_lines`), opened lazily:
  the times ``t_s(line)``, x of each column from ``col0`` and the full line's width.

Also :func:`adjustment_of`: the adjustment dict of an in-memory ``adjust-pushbroom`` result
(what :func:`hsgeo.sensors.adjusted` applies to any sensor and its trajectory).
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import HsgeoError, InputError
from hsgeo.ortho import Strip
from hsgeo.sensors.pushbroom import PushbroomCamera

__all__ = [
    "adjustment_of",
    "lp_strips",
    "line_strip",
    "select_bands",
    "pixel_keywords",
    "check_view_angles",
    "check_principal_point",
]


def select_bands(wavelength_nm, wanted_nm, source: str) -> list[int]:
    """Indices of the bands nearest the wanted wavelengths (within one band spacing); all
    bands when ``wanted_nm`` is None.
    """
    wl = np.asarray(wavelength_nm, dtype=float)
    if wanted_nm is None:
        return list(range(wl.size))
    step = float(np.median(np.abs(np.diff(wl)))) if wl.size > 1 else 1.0
    out = []
    for w in wanted_nm:
        i = int(np.argmin(np.abs(wl - w)))
        if abs(wl[i] - w) > step:
            raise InputError(
                f"--bands {w:g}: no band of {source} within {step:.3g} nm of {w:g} nm (its "
                f"bands: {wl.min():g}…{wl.max():g} nm); give wavelengths in nm, e.g. "
                "--bands 640,550,460"
            )
        out.append(i)
    return out


def adjustment_of(result) -> dict:
    """What :func:`hsgeo.io.sensors.read_adjustment` reads from ``adjust-pushbroom --json``,
    from the in-memory result (:class:`~hsgeo.workflows.pushbroom_ba.PushbroomResult`).
    """
    r = result.result
    return {
        "boresight_rad": np.asarray(r.value("boresight_rad"), float).ravel(),
        "lever_arm_m": np.asarray(r.value("lever_arm_m"), float).ravel(),
        "distortion": np.asarray(r.value("distortion"), float).ravel(),
        "c_mm": np.atleast_1d(np.asarray(r.value("c_mm"), float).ravel()),
        "t_nodes_s": np.asarray(result.nodes.t_nodes_s, float),
        "nodes": np.asarray(r.value("nodes"), float),
        "node_columns": tuple(r.params["nodes"].columns),
    }


def pixel_keywords(sensor, band, n_bands: int, source: str, option: str = "--band") -> dict:
    """What ``sensor.rays`` takes per pixel besides the pixels: ``band=`` of a pushbroom camera
    (``band``: the camera band whose geometry every mosaicked band uses; None: the middle of
    the ``n_bands`` selected bands' when the camera has them, else its band 0).
    """
    if not isinstance(sensor, PushbroomCamera):
        return {}
    n_cam = len(sensor.c_mm)
    if band is None:
        return {"band": 0 if n_cam != n_bands else None}
    if not (isinstance(band, int | np.integer) and 0 <= band < n_cam):
        raise InputError(f"{option} {band!r}: the camera file {source} has bands 0…{n_cam - 1}")
    return {"band": int(band)}


def lp_strips(
    lps, camera, trajectory, bands_nm, n_px_full: int, names=None, band=None, fwhm_nm=None
):
    """The :class:`~hsgeo.ortho.Strip` of LP strips (:class:`hsgeo.io.lp_lines.LpStrip`, numpy
    or Dask lines): the bands nearest ``bands_nm`` (None: all), the geometry of camera band
    ``band`` (None: the middle selected band's).

    Returns
    -------
    strips : list of Strip
    wavelength_nm : (n_bands,) ndarray
    fwhm_nm : (n_bands,) ndarray or None
    """
    strips, wl = [], None
    for k, lp in enumerate(lps):
        who = repr(str(names[k])) if names is not None else f"strip {lp.strip_id!r}"
        if wl is None:
            wl, first = lp.wavelengths_nm, who
            idx = select_bands(wl, bands_nm, who)
        elif lp.wavelengths_nm.shape != wl.shape or not np.allclose(lp.wavelengths_nm, wl):
            raise InputError(f"LINES {who}: its bands differ from those of {first}")
        kw = {}
        if isinstance(camera, PushbroomCamera):
            if len(camera.c_mm) != wl.size:
                raise InputError(
                    f"LINES {who} has {wl.size} bands, the camera (--sensor n_bands) "
                    f"{len(camera.c_mm)}: give the camera file of the camera that recorded "
                    "the lines"
                )
            kw = pixel_keywords(camera, band, wl.size, "--sensor")
            if kw["band"] is None:  # the middle band's geometry
                kw["band"] = min(idx[len(idx) // 2], len(camera.c_mm) - 1)
        x = lp.x_px(n_px_full)
        px = np.column_stack([x, np.zeros_like(x)]) if isinstance(camera, PushbroomCamera) else x
        strips.append(Strip(camera, trajectory, lp.t_s, px, lp.lines[:, :, idx], kw, lp.strip_id))
    fw = None if fwhm_nm is None else np.asarray(fwhm_nm, float)[idx]
    return strips, wl[idx], fw


def line_strip(da, t0_s, line_rate_hz, sensor, trajectory, *, bands_nm=None, band=None, name):
    """The :class:`~hsgeo.ortho.Strip` of a recorded flight line (:func:`hsgeo.io.read_lines`:
    ``radiance(band, line, pixel)``, times ``t0_s + i / line_rate_hz``). ``bands_nm`` selects
    bands by wavelength (the file's ``wavelength_nm``; None: all bands).

    Returns
    -------
    strip : Strip
    idx : list of int
        The selected bands.
    """
    n_lines = da.sizes["line"]
    if bands_nm is not None:
        if "wavelength_nm" not in da.coords:
            raise InputError(
                f"--bands: LINES {name!r} has no wavelength_nm(band); leave --bands out (all "
                "bands are orthorectified) or add the wavelengths to the file"
            )
        idx = select_bands(da["wavelength_nm"].values, bands_nm, repr(name))
    else:
        idx = list(range(da.sizes["band"]))
    pixel = np.asarray(da["pixel"].values, dtype=float)
    kw = pixel_keywords(sensor, band, len(idx), "--sensor")
    if kw.get("band", 0) is None:
        kw["band"] = min(idx[len(idx) // 2], len(sensor.c_mm) - 1)
    px = np.column_stack([pixel, np.zeros_like(pixel)]) if kw else pixel
    values = np.asarray(da.values)[idx].transpose(1, 2, 0)  # (line, pixel, band)
    t = t0_s + np.arange(n_lines) / line_rate_hz
    return Strip(sensor, trajectory, t, px, values, kw, str(name)), idx


def check_principal_point(sensor, pixel, source, lines) -> None:
    """The principal point lies on the recorded line: between its first and last pixel."""
    if isinstance(sensor, PushbroomCamera):
        pp, name = sensor.x0_mm / sensor.pixel_mm, "x0_mm / pixel_mm"
    elif hasattr(sensor, "geometry") and hasattr(sensor.geometry, "zeta0_px"):
        pp, name = float(sensor.geometry.zeta0_px), "zeta0_px"
    else:
        return
    lo, hi = float(np.min(pixel)), float(np.max(pixel))
    if not lo <= pp <= hi:
        raise InputError(
            f"sensor file {str(source)!r}: the principal point ({name} = {pp:.6g} px) is off "
            f"the line of {str(lines)!r}, whose pixels run {lo:g}…{hi:g} px; the likely causes: "
            "a principal point of another binning or crop of the detector, the LINES pixel "
            "coordinate counted from another origin, or a value in another unit"
        )


def check_view_angles(strip: Strip, source) -> None:
    """The rays of a strip's first line must look down, within 80° of the nadir."""
    nav, t0_s = strip.trajectory, strip.t_s[0]
    tt, pixels = strip.line_pixels(slice(0, 1))
    with np.errstate(all="ignore"):
        try:
            _, d = strip.sensor.rays(pixels, tt, nav, **strip.pixel_kw)
            ang = np.degrees(np.arccos(np.clip(-d[:, 2], -1.0, 1.0)))
        except HsgeoError:
            ang = np.array([np.nan])
    p = pixels[..., 0] if pixels.ndim == 2 else pixels
    if np.all(np.isfinite(ang)) and np.all(ang > 90.0):  # every ray looks up: the attitude
        roll, pitch = np.degrees(nav.pose(np.array([t0_s]))[1][0, :2])
        raise InputError(
            f"the rays of the first line of {strip.name!r} look up ({np.min(ang):.3g}…"
            f"{np.max(ang):.3g}° off the nadir; roll {roll:.4g}°, pitch {pitch:.4g}° in the "
            "navigation); the likely causes: the navigation's attitude in another convention "
            f"(the body upside down, z up instead of down), the boresight of {str(source)!r}, "
            "or angles in radians where degrees are expected"
        )
    if not (np.all(np.isfinite(ang)) and np.all(ang < 80.0)):
        raise InputError(
            f"sensor file {str(source)!r}: the pixels {p.min():g}…{p.max():g} px of "
            f"{strip.name!r} look {np.nanmin(ang):.3g}…{np.nanmax(ang):.3g}° off the nadir "
            "(over 80°, or not at all); check the principal point and distance (zeta0_px and "
            "c_px, or x0_mm and c_mm, in this sensor's units), the boresight and the LINES "
            "pixel coordinate"
        )
