"""The strips of ``hsgeo orthorectify`` from ENVI cubes, as line scanners write them.

A LINES argument is an ENVI cube when it is not NetCDF (:func:`is_envi`: by content, the
NetCDF/HDF5 signature, then by suffix): the binary file (``.raw``, ``.dat``, ``.bil`` …), its
header (``name.hdr`` or ``name.ext.hdr``) or the bare name, read lazily by
:func:`hsgeo.io.line_cube.read_line_cube` (BIL/BIP/BSQ, either byte order, ``header offset``,
``data ignore value`` → NaN). The line times come from ``--line-times`` (one file per cube,
one time per line) or from the header's start time and line period.

**The pixel coordinate of a cube's sample** *s* (0-based column, pixel-centre origin) in the
sensor's convention: x = s − (n − 1)/2 px from the line centre for the 002 pushbroom camera (the
convention of :meth:`hsgeo.io.lp_lines.LpStrip.x_px` with a full line of the cube's n
samples), ζ = s for every other scanning sensor (the 000 line scanner's ζ, the panoramic
scanner's pixel, the view-angle table's ``pixel``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.ortho import Strip
from hsgeo.sensors.pushbroom import PushbroomCamera
from hsgeo.sensors.view_angle import ViewAngleScanner
from hsgeo.workflows._ortho_strips import check_principal_point, pixel_keywords, select_bands

__all__ = ["is_envi", "envi_strips", "sample_pixels", "view_angle_keywords"]

#: Leading bytes of NetCDF classic (``CDF``) and NetCDF-4 / HDF5 files.
_NETCDF_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")
_NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf")


def is_envi(path) -> bool:
    """Whether a LINES argument is an ENVI cube (else hsgeo's NetCDF lines): a file that begins
    with the NetCDF/HDF5 signature is NetCDF whatever its name; a ``.hdr``, a file beginning
    with ``ENVI``, a name whose ``name.hdr`` exists, or any other suffix than NetCDF's is ENVI.
    """
    p = Path(path)
    if p.is_file():
        with open(p, "rb") as f:
            head = f.read(8)
        if any(head.startswith(m) for m in _NETCDF_MAGIC):
            return False
        if head.startswith(b"ENVI") or p.suffix.lower() == ".hdr":
            return True
    return p.suffix.lower() not in _NETCDF_SUFFIXES


def sample_pixels(sensor, n_samples: int) -> np.ndarray:
    """The pixel coordinates of a cube's samples 0 … n−1 (module docstring): ``(n, 2)``
    ``(x, 0)`` for a pushbroom camera, ``(n,)`` ζ otherwise.
    """
    s = np.arange(int(n_samples), dtype=float)
    if isinstance(sensor, PushbroomCamera):
        x = s - (n_samples - 1) / 2.0
        return np.column_stack([x, np.zeros_like(x)])
    return s


def view_angle_keywords(sensor, band, idx, n_bands: int, source) -> dict:
    """``band=`` of a view-angle sensor with one table per band (``band``: the table every
    kept band's geometry uses; None: the middle kept band's when the tables are the cube's
    bands). Empty for one table, or another sensor.
    """
    if not isinstance(sensor, ViewAngleScanner) or sensor.n_bands == 1:
        return {}
    if band is not None:
        if not 0 <= int(band) < sensor.n_bands:
            raise InputError(
                f"--band {band}: the view-angle tables of {str(source)!r} are bands 0…"
                f"{sensor.n_bands - 1}"
            )
        return {"band": int(band)}
    if sensor.n_bands != n_bands:
        raise InputError(
            f"sensor file {str(source)!r} has {sensor.n_bands} view-angle tables (one per band), "
            f"the lines {n_bands} bands: give the calibration of the sensor that recorded them, "
            "or --band K to use table K for every band"
        )
    return {"band": int(idx[len(idx) // 2])}


def _times_per_cube(lines, line_times):
    """One times file (or None: the header) per cube."""
    if line_times is None:
        return [None] * len(lines)
    line_times = list(line_times)
    if len(line_times) != len(lines):
        raise InputError(
            f"--line-times is given {len(line_times)} time(s) for {len(lines)} LINES cubes; give "
            "one times file per cube, in the order of LINES (or none: the headers' start time "
            "and line period)"
        )
    return line_times


def envi_strips(lines, sensor, nav, *, sensor_path, bands_nm=None, band=None, line_times=None):
    """The :class:`~hsgeo.ortho.Strip` of ENVI cubes (Dask-backed, nothing read yet).

    Parameters
    ----------
    lines : list of str or Path
        The cubes (any of the names :func:`hsgeo.io.envi_read.find_envi` takes).
    sensor : a scanning sensor of :mod:`hsgeo.sensors`
    nav : hsgeo.trajectory.Trajectory
    sensor_path : str
        The sensor file, for messages.
    bands_nm : list of float, optional
        The wavelengths to keep (nearest band each); None: all bands.
    band : int, optional
        The band whose geometry every kept band uses (a pushbroom camera, a view-angle sensor
        with one table per band).
    line_times : list of str or Path, optional
        One times file per cube; None: the headers' start time and line period.

    Returns
    -------
    strips : list of Strip
    wavelength_nm, fwhm_nm : (n_bands,) ndarray or None
        Of the kept bands (None when the headers have none).
    """
    from hsgeo.io.line_cube import read_line_cube

    strips, first, wl, fw = [], None, None, None
    for p, times in zip(lines, _times_per_cube(lines, line_times), strict=True):
        cube, info = read_line_cube(p, times)
        who = repr(str(p))
        if info["col0"]:  # sample s is ζ = s / x of a full line (module docstring)
            raise InputError(
                f"LINES {who}: its header's x start = {info['col0'] + 1} says the cube holds "
                "columns of a wider line; orthorectify takes full lines (x start = 1): give "
                "the full lines, or the strip as hsgeo's NetCDF lines with col0 and n_px_full"
            )
        n_l, n_s, n_b = (int(v) for v in cube.shape)
        if n_l < 2 or n_s < 2:
            raise InputError(
                f"LINES {who}: {n_l} line(s) of {n_s} sample(s); an image needs at least 2 of each"
            )
        w = cube["wavelength_nm"].values
        has_wl = bool(np.all(np.isfinite(w)))
        if first is None:
            first, first_w = who, w
            if bands_nm is not None and not has_wl:
                raise InputError(
                    f"--bands: the ENVI header {str(info['header_path'])!r} has no wavelength "
                    "entry; leave --bands out (all bands are orthorectified) or add "
                    "'wavelength = {...}' and 'wavelength units = Nanometers' to it"
                )
            idx = select_bands(w, bands_nm, who) if bands_nm is not None else list(range(n_b))
            if has_wl:
                wl = w[idx]
                f = cube["fwhm_nm"].values[idx]
                fw = f if np.all(np.isfinite(f)) else None
        elif w.shape != first_w.shape or not np.allclose(w, first_w, equal_nan=True):
            raise InputError(
                f"LINES {who}: its bands ({n_b}) differ from those of {first} "
                f"({first_w.size}); give cubes of one sensor"
            )
        if isinstance(sensor, ViewAngleScanner):
            sensor.check_samples(n_s, f"the lines of {who}")
        px = sample_pixels(sensor, n_s)
        kw = pixel_keywords(sensor, band, len(idx), "--sensor")
        if isinstance(sensor, PushbroomCamera) and band is None:
            n_cam = len(sensor.c_mm)
            if n_cam not in (1, n_b):
                raise InputError(
                    f"LINES {who} has {n_b} bands, the camera (--sensor n_bands) {n_cam}: give "
                    "the camera file of the camera that recorded the lines, or --band K"
                )
            kw["band"] = 0 if n_cam == 1 else int(idx[len(idx) // 2])
        kw.update(view_angle_keywords(sensor, band, idx, n_b, sensor_path))
        check_principal_point(sensor, px[:, 0] if px.ndim == 2 else px, sensor_path, p)
        values = cube.data[:, :, idx] if len(idx) != n_b else cube.data
        strips.append(Strip(sensor, nav, cube["t_s"].values, px, values, kw, str(p)))
    return strips, wl, fw


def envi_lines(lines, sensor, nav, args):
    """The strips of LINES when they are ENVI cubes (:func:`envi_strips`), else None (hsgeo's
    NetCDF lines, read by the caller). ``args``: ``sensor``, ``bands``, ``band``,
    ``line_times`` of ``orthorectify_files``.

    Raises
    ------
    InputError
        LINES mixing ENVI cubes and NetCDF lines, or ``--line-times`` with NetCDF lines (they
        carry their own times).
    """
    kinds = {str(p): is_envi(p) for p in lines}
    if not any(kinds.values()):
        if args.get("line_times") is not None:
            raise InputError(
                "--line-times is for ENVI cubes; the NetCDF LINES carry their own line times "
                "(t0_s and line_rate_hz, or t_s): leave --line-times out"
            )
        return None
    if not all(kinds.values()):
        raise InputError(
            "LINES mixes ENVI cubes and NetCDF lines: "
            + ", ".join(f"{p!r}: {'ENVI' if e else 'NetCDF'}" for p, e in kinds.items())
            + "; give the lines of one sensor in one format"
        )
    strips, wl, fw = envi_strips(
        lines,
        sensor,
        nav,
        sensor_path=args["sensor"],
        bands_nm=args.get("bands"),
        band=args.get("band"),
        line_times=args.get("line_times"),
    )
    return strips, wl, fw, None


def envi_files(lines) -> list:
    """The binary files and headers of the ENVI cubes among LINES (inputs an output must not
    overwrite); a cube that cannot be found is left to the reader's message.
    """
    from hsgeo.io.envi_read import find_envi

    out = []
    for p in lines:
        if is_envi(p):
            try:
                out.extend(find_envi(p))
            except InputError:
                pass
    return out
