"""The strips of ``hsgeo orthorectify`` from frames of a frame camera.

The frame models of the sensor registry (``frame-opencv``:
:class:`~hsgeo.sensors.frame.FrameCamera`; ``rikola``: :class:`~hsgeo.sensors.rikola.
RikolaCamera`) go through the very engine of the scanning sensors, not a second
orthorectifier: a frame is a :class:`~hsgeo.ortho.Strip` whose lines are the image rows
(``row_px``), every row at the frame's exposure time, its pixels ``(u, v)`` in OpenCV's
convention (:mod:`hsgeo.io.frame_images`). The camera is carried along the navigation by
:class:`hsgeo.sensors.mount.OnTrajectory`: the body's pose at the exposure time composed with
the sensor file's mount (:meth:`hsgeo.sensors.mount.Mount.rays_along`, the scanning sensors'
composition); each pixel's ray (the camera's ``rays_along``) meets the terrain at its first
crossing (:func:`hsgeo.geocode.intersect`) and the cells are filled by
:func:`hsgeo.ortho.orthomosaic`.

**Overlapping frames.** Every frame is a strip of the mosaic, so ``--mosaic`` applies between
frames as between strips: ``nearest-nadir`` gives a cell to the frame whose ray to it is
closest to the downward vertical (the frame taken most nearly above the cell: for a camera
looking down, the frame whose centre ray lands closest to the cell), ``first`` to the first
frame given, ``mean`` averages them.

**The Rikola's bands** have their own geometry (focal length per band, sensor I or II) and,
with a ``band`` column in the exposure table, their own exposure times: each band of each frame
is a one-band strip, the bands are mosaicked one at a time on one common grid
(``layers`` of :class:`~hsgeo.workflows.orthorectify.OrthoInputs`), and stacked.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError
from hsgeo.ortho import Strip
from hsgeo.sensors.frame import FrameCamera
from hsgeo.sensors.mount import OnTrajectory
from hsgeo.sensors.rikola import RikolaCamera

__all__ = ["is_frame_sensor", "frame_strips", "frame_files"]


def is_frame_sensor(sensor) -> bool:
    """Whether ``sensor`` is a frame camera (exposure poses, not a scanning sensor)."""
    return isinstance(sensor, FrameCamera | RikolaCamera)


def _refuse_scanning_options(args, sensor_path) -> None:
    if args.get("line_times") is not None:
        raise InputError(
            f"--line-times: the sensor file {str(sensor_path)!r} is a frame camera, whose "
            "frames have one exposure time each; give them as --frame-times TIMES.csv (columns "
            "file, time_s) and leave --line-times out"
        )
    for opt, key in (("--band", "band"), ("--line-pixels", "line_pixels")):
        if args.get(key) is not None:
            raise InputError(
                f"{opt} is for the lines of a scanning sensor; the sensor file "
                f"{str(sensor_path)!r} is a frame camera: leave {opt} out"
            )


def _image_size(sensor):
    size = getattr(sensor, "image_size", None)
    return None if size is None else (int(size[0]), int(size[1]))


def _band_numbers(sensor) -> list[int]:
    if sensor.bands is None:
        return list(range(1, len(sensor.f_mm) + 1))
    return [int(b) for b in sensor.bands]


def _times_of(frames, times, table, sensor, sensor_path) -> dict:
    """``{(frame index, band or None): time_s}`` from the exposure table; every frame (and, with
    a ``band`` column, every band of the sensor) must have its row.
    """
    from hsgeo.io.frame_images import frame_key

    banded = any(b is not None for _, b in times)
    if banded and not isinstance(sensor, RikolaCamera):
        raise InputError(
            f"--frame-times {str(table)!r}: column band is for the Rikola's bands; the sensor "
            f"file {str(sensor_path)!r} is a frame camera with one exposure per frame: leave "
            "the column out"
        )
    known = set(_band_numbers(sensor)) if banded else set()
    for _, b in times:
        if banded and b not in known:
            raise InputError(
                f"--frame-times {str(table)!r}: column band names band {b}, not a band of the "
                f"sensor file {str(sensor_path)!r} (its bands: {sorted(known)}); give the band "
                "numbers of the sensor file's bands, or the sensor file of this camera"
            )
    out = {}
    for i, p in enumerate(frames):
        k = frame_key(p)
        for b in sorted(known) if banded else [None]:
            if (k, b) not in times:
                what = f"frame {str(p)!r}" + ("" if b is None else f" band {b}")
                row = f"{k}, TIME_S" if b is None else f"{k}, TIME_S, {b}"
                raise InputError(
                    f"{what} has no exposure time in --frame-times {str(table)!r} (column file "
                    f"matched by the name {k!r}); add the row '{row}' (columns file, time_s"
                    + (", band" if b is not None else "")
                    + ")"
                )
            out[(i, b)] = times[(k, b)]
    return out


def _check_covered(t_by, nav, table, max_gap_s, nav_path) -> None:
    from hsgeo.validate import check_navigation_covers

    t = np.array(list(t_by.values()), float)
    check_navigation_covers(
        nav.t_s,
        t,
        nav=repr(str(nav_path)),
        used=f"the exposure times of --frame-times {str(table)!r} (column time_s)",
        max_gap_s=max_gap_s,
    )


def frame_strips(frames, sensor, nav, args):
    """The strips of the frames (module docstring).

    Parameters
    ----------
    frames : list of str or Path
        One image file per frame (:mod:`hsgeo.io.frame_images`).
    sensor : FrameCamera or RikolaCamera
    nav : hsgeo.trajectory.Trajectory
        The body's navigation (adjusted when ``--adjustment`` is given).
    args : dict
        ``sensor`` (the sensor file), ``trajectory`` (the navigation file), ``frame_times``
        (the exposure table), ``bands``, ``line_times``, ``band``, ``line_pixels``,
        ``max_nav_gap_s``.

    Returns
    -------
    strips : list of Strip
    layers : tuple of int
        The output band of each strip (empty: each strip fills every band).
    wavelength_nm, fwhm_nm : (n_bands,) ndarray or None
    names : list of str
        The output bands' names.
    """
    from hsgeo.io.frame_images import open_frame, read_frame_times
    from hsgeo.workflows._ortho_strips import select_bands

    src = args["sensor"]
    _refuse_scanning_options(args, src)
    table = args.get("frame_times")
    if table is None:
        raise InputError(
            f"the sensor file {str(src)!r} is a frame camera: give the frames' exposure times "
            "as --frame-times TIMES.csv (columns file: the frame's file name; time_s: the "
            "exposure, s on the navigation's time scale)"
        )
    t_by = _times_of(frames, read_frame_times(table), table, sensor, src)
    _check_covered(t_by, nav, table, args.get("max_nav_gap_s", 1.0), args.get("trajectory"))
    rikola = isinstance(sensor, RikolaCamera)
    size = _image_size(sensor)
    strips, layers, first = [], [], None
    wl = fw = idx = None
    for i, p in enumerate(frames):
        values, info = open_frame(p)
        h, w, n_b = (int(x) for x in values.shape)
        who = repr(str(p))
        if size is not None and (w, h) != size:
            raise InputError(
                f"frame {who} is {w} x {h} px (width x height), the sensor file {str(src)!r} "
                f"image_size_px = [{size[0]}, {size[1]}]: give frames of that camera, whole "
                "(not cropped or binned), or the sensor file of the camera that took them"
            )
        if rikola and n_b != len(sensor.f_mm):
            raise InputError(
                f"frame {who} holds {n_b} band(s), the Rikola sensor file {str(src)!r} "
                f"{len(sensor.f_mm)} (bands {_band_numbers(sensor)}): a layer of the frame "
                "must be a band of the sensor file, in its order; give the sensor file of the "
                "calibration that covers the frame's bands"
            )
        if first is None:
            first, n_first = who, n_b
            w_nm = info["wavelength_nm"]
            if args.get("bands") is not None and w_nm is None:
                raise InputError(
                    f"--bands: frame {who} has no wavelengths; leave --bands out (all bands "
                    "are orthorectified) or give frames whose ENVI header has them"
                )
            idx = select_bands(w_nm, args["bands"], who) if args.get("bands") else list(range(n_b))
            if w_nm is not None:
                wl = np.asarray(w_nm, float)[idx]
                f = info["fwhm_nm"]
                fw = None if f is None else np.asarray(f, float)[idx]
        elif n_b != n_first:
            raise InputError(
                f"frame {who} holds {n_b} band(s), frame {first} {n_first}: give the frames of "
                "one camera"
            )
        u = np.arange(w, dtype=float)
        pixels = np.column_stack([u, np.zeros_like(u)])
        rows = np.arange(h, dtype=float)
        cam = OnTrajectory(sensor)
        if not rikola:
            t = np.full(h, t_by[(i, None)])
            vals = values[:, :, idx] if len(idx) != n_b else values
            strips.append(Strip(cam, nav, t, pixels, vals, {}, str(p), rows))
            continue
        nums = _band_numbers(sensor)
        for layer, k in enumerate(idx):
            t = np.full(h, t_by.get((i, nums[k]), t_by.get((i, None))))
            kw = {"band": nums[k]}
            name = f"{p} band {nums[k]}"
            strips.append(Strip(cam, nav, t, pixels, values[:, :, k : k + 1], kw, name, rows))
            layers.append(layer)
    if rikola:
        names = [f"band {_band_numbers(sensor)[k]}" for k in idx]
    elif wl is not None:
        names = [f"{x:g} nm" for x in wl]
    else:
        names = [str(k) for k in idx]
    return strips, tuple(layers), wl, fw, names


def frame_files(frames) -> list:
    """The files the frames are read from (inputs an output must not overwrite); a frame that
    cannot be found is left to the reader's message.
    """
    from pathlib import Path

    from hsgeo.io.envi_read import find_envi
    from hsgeo.io.frame_images import FRAME_TIFF_SUFFIXES

    out = []
    for p in frames:
        if Path(p).suffix.lower() in FRAME_TIFF_SUFFIXES:
            out.append(p)
            continue
        try:
            out.extend(find_envi(p))
        except InputError:
            pass
    return out
