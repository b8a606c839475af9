"""The orthomosaic of LP strips (002 §5.1, Fig. 9): ``hsgeo orthomosaic``.

:func:`orthomosaic_files` (the file front end) reads the LP line files, the navigation, the
camera TOML of ``hsgeo adjust-pushbroom`` and optionally its ``--json`` result (camera
parameters and node corrections: the adjusted trajectory, :func:`hsgeo.trajectory.
corrected_trajectory`), and a DSM GeoTIFF in EPSG:25832; checks them all before the work; and
writes the true-colour (or chosen bands') mosaic as a Cloud-Optimized GeoTIFF
(:func:`hsgeo.io.geotiff.write_cog`). The core :func:`build_mosaic` (:class:`MosaicInputs`,
:class:`MosaicOptions`) returns the lazy mosaic (:func:`hsgeo.ortho.orthomosaic`), which a
chapter can compute in memory or write. With ``scheduler`` (``--scheduler ADDRESS``) the tiles
are computed on that ``dask.distributed`` cluster.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from hsgeo.crs import SITE_AAS
from hsgeo.errors import InputError, ObservationError
from hsgeo.ortho import MapTerrain, Strip, orthomosaic

__all__ = [
    "TRUE_COLOUR_NM",
    "MosaicInputs",
    "MosaicOptions",
    "build_mosaic",
    "select_bands",
    "camera_from_files",
    "adjustment_of",
    "adjusted_camera",
    "adjusted_trajectory",
    "lp_mosaic_strips",
    "orthomosaic_files",
]

#: How long ``--scheduler`` waits for the scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 10.0
#: The true-colour bands' wavelengths (R, G, B), nm: the default ``--bands``.
TRUE_COLOUR_NM = (640.0, 550.0, 460.0)


#: The largest mosaic built, GiB of float32 (a --resolution far finer than the ground pixels).
MAX_MOSAIC_GIB = 64.0


@dataclass(frozen=True)
class MosaicOptions:
    """Cell size (m), output tile (cells), lines per geolocated block, the local frame, the
    largest mosaic (GiB of float32).
    """

    resolution_m: float = 0.3
    tile_px: int = 512
    lines_per_block: int = 256
    frame: object = SITE_AAS
    max_gib: float = MAX_MOSAIC_GIB


@dataclass(frozen=True)
class MosaicInputs:
    """Strips (:class:`hsgeo.ortho.Strip`), the terrain, band names and wavelengths (nm)."""

    strips: tuple
    terrain: object
    band_names: tuple = ()
    wavelength_nm: tuple = ()
    meta: dict = field(default_factory=dict)


def build_mosaic(inputs: MosaicInputs, options: MosaicOptions = MosaicOptions()):
    """The lazy mosaic ``(band, y, x)`` in the frame's map CRS (:func:`hsgeo.ortho.orthomosaic`)."""
    return orthomosaic(
        inputs.strips,
        inputs.terrain,
        options.frame,
        resolution_m=options.resolution_m,
        band_names=list(inputs.band_names) or None,
        wavelength_nm=list(inputs.wavelength_nm) or None,
        tile_px=options.tile_px,
        lines_per_block=options.lines_per_block,
        max_gib=options.max_gib,
    )


def select_bands(wavelength_nm, wanted_nm, source: str) -> list[int]:
    """Indices of the bands nearest the wanted wavelengths (within one band spacing)."""
    wl = np.asarray(wavelength_nm, dtype=float)
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


def adjusted_camera(prior, adjustment=None):
    """The LP camera (:class:`~hsgeo.sensors.pushbroom.PushbroomCamera`) ``prior`` with the
    adjusted c (per band), boresight, lever arm and distortion of ``adjustment`` (the dict of
    :func:`adjustment_of` / :func:`hsgeo.io.sensors.read_adjustment`; None: ``prior``).
    """
    from dataclasses import replace

    if adjustment is None:
        return prior
    n = len(prior.c_mm)
    if adjustment["c_mm"].size not in (1, n):
        raise InputError(
            f"--adjustment: {adjustment['c_mm'].size} values of c_mm for a camera of {n} bands "
            "(--camera n_bands); give the adjustment of this camera"
        )
    c = np.broadcast_to(adjustment["c_mm"], (n,))
    return replace(
        prior,
        c_mm=tuple(float(v) for v in c),
        boresight_rad=tuple(adjustment["boresight_rad"]),
        lever_arm_m=tuple(adjustment["lever_arm_m"]),
        distortion=tuple(adjustment["distortion"]),
    )


def camera_from_files(camera, adjustment=None):
    """The LP camera (:class:`~hsgeo.sensors.pushbroom.PushbroomCamera`) from the camera TOML,
    with the parameters of an ``adjust-pushbroom --json`` result when given.
    """
    from hsgeo.sensors.pushbroom import PushbroomCamera
    from hsgeo.workflows.pushbroom_ba import read_camera

    prior = read_camera(camera)
    cam = PushbroomCamera(
        c_mm=(float(prior.c_mm),) * int(prior.n_bands),
        pixel_mm=prior.pixel_mm,
        x0_mm=prior.x0_mm,
        y0_mm=prior.y0_mm,
        lever_arm_m=tuple(prior.lever_arm_m),
    )
    return adjusted_camera(cam, adjustment)


def adjusted_trajectory(nav, adjustment=None):
    """The navigation ``nav`` with the node corrections of ``adjustment`` (002 eq. 4,
    :func:`hsgeo.trajectory.corrected_trajectory`; None: ``nav``).
    """
    from hsgeo.trajectory import CORRECTION_COLUMNS, SplineNodes, corrected_trajectory

    if adjustment is None:
        return nav
    t = adjustment["t_nodes_s"]
    if tuple(adjustment["node_columns"]) != CORRECTION_COLUMNS:
        raise InputError(
            f"--adjustment: node columns {adjustment['node_columns']} are not {CORRECTION_COLUMNS}"
        )
    dt = float(t[2] - t[1])
    nodes = SplineNodes(float(t[1]), float(t[1] + (t.size - 3) * dt), dt)
    if not np.allclose(nodes.t_nodes_s, t, atol=1e-6 * dt):
        raise InputError("--adjustment: the node times are not evenly spaced")
    return corrected_trajectory(nav, nodes, adjustment["nodes"])


def lp_mosaic_strips(lps, camera, trajectory, bands_nm, n_px_full: int, names=None):
    """The mosaic's :class:`~hsgeo.ortho.Strip` of LP strips (:class:`hsgeo.io.lp_lines.LpStrip`,
    numpy or Dask lines): the bands nearest ``bands_nm``, the middle one's geometry.

    Returns
    -------
    strips : list of Strip
    wavelength_nm : (n_bands,) ndarray
    """
    strips, wl = [], None
    for k, lp in enumerate(lps):
        who = repr(str(names[k])) if names is not None else f"strip {lp.strip_id!r}"
        if wl is None:
            wl, first = lp.wavelengths_nm, who
            idx = select_bands(wl, bands_nm, who)
        elif lp.wavelengths_nm.shape != wl.shape or not np.allclose(lp.wavelengths_nm, wl):
            raise InputError(f"LINES {who}: its bands differ from those of {first}")
        if len(camera.c_mm) != wl.size:
            raise InputError(
                f"LINES {who} has {wl.size} bands, the camera (--camera n_bands) "
                f"{len(camera.c_mm)}: give the camera TOML of the camera that recorded the lines"
            )
        band = min(idx[len(idx) // 2], len(camera.c_mm) - 1)  # the middle band's geometry
        x = lp.x_px(n_px_full)
        px = np.column_stack([x, np.zeros_like(x)])
        strips.append(
            Strip(camera, trajectory, lp.t_s, px, lp.lines[:, :, idx], {"band": band}, lp.strip_id)
        )
    return strips, wl[idx]


def _trajectory(trajectory, adjustment):
    from hsgeo.io.navigation import read_trajectory

    return adjusted_trajectory(read_trajectory(trajectory), adjustment)


def _check_nodes_cover(adjustment, lines, lps) -> None:
    """Every strip's lines within one node interval of the adjustment's node span (outside it
    the correction is held at its end value: a result of another flight would pass silently).
    """
    t = adjustment["t_nodes_s"]
    dt = float(t[2] - t[1])
    lo, hi = float(t[1]) - dt, float(t[-2]) + dt
    for path, lp in zip(lines, lps, strict=True):
        if lp.t_s[0] < lo or lp.t_s[-1] > hi:
            raise InputError(
                f"the lines of {str(path)!r} (t_s {lp.t_s[0]:.6g}…{lp.t_s[-1]:.6g} s) lie outside "
                f"the node times of --adjustment ({t[1]:.6g}…{t[-2]:.6g} s): give the "
                "adjustment of this flight (adjust-pushbroom on observations of these strips)"
            )


def _strips(lines, nav, cam, bands_nm, max_nav_gap_s, trajectory, line_pixels, adjustment):
    from hsgeo.io.lp_lines import full_line_px, open_lp_lines
    from hsgeo.validate import check_navigation_covers

    lps = [open_lp_lines(p) for p in lines]
    n_px_full = full_line_px(lps, line_pixels)
    for path, lp in zip(lines, lps, strict=True):
        check_navigation_covers(
            nav.t_s,
            lp.t_s,
            nav=repr(str(trajectory)),
            used=f"the lines of {str(path)!r} (t_s)",
            max_gap_s=max_nav_gap_s,
        )
    if adjustment is not None:
        _check_nodes_cover(adjustment, lines, lps)
    strips, wl = lp_mosaic_strips(lps, cam, nav, bands_nm, n_px_full, names=lines)
    return strips, wl, n_px_full


def orthomosaic_files(
    lines,
    trajectory,
    camera,
    *,
    dsm,
    output,
    resolution_m: float = 0.3,
    bands=TRUE_COLOUR_NM,
    adjustment=None,
    scheduler=None,
    overwrite: bool = False,
    progress=None,
    max_nav_gap_s: float = 1.0,
    options: MosaicOptions | None = None,
    line_pixels: int | None = None,
) -> dict:
    """Orthomosaic LP line files into a COG (see ``hsgeo orthomosaic --help``).

    Every check comes before the work: the output (refused if it exists, unless ``overwrite``),
    the inputs, the bands, the navigation covering every line, the DSM's CRS and its cover of
    every strip's footprint. ``line_pixels`` (``--line-pixels``) is the full line's width; it
    overrides the files' ``n_px_full`` attribute (default: that attribute, else 1800 px:
    :func:`hsgeo.io.lp_lines.full_line_px`, the convention ``hsgeo lp-observations`` shares).
    Returns a summary (grid, bands, strips, file).
    """
    from hsgeo.io._files import check_outputs
    from hsgeo.io.geotiff import GEOTIFF_FORMATS, read_dsm, write_cog
    from hsgeo.io.sensors import read_adjustment

    lines = list(lines)
    if not lines:
        raise InputError("give at least one LINES file")
    _check_distinct(lines)
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise InputError(f"--resolution must be a positive number of metres, got {resolution_m}")
    inputs = [*lines, trajectory, camera, dsm, adjustment]
    check_outputs([(output, "-o/--output", GEOTIFF_FORMATS)], inputs, overwrite=overwrite)
    opts = options or MosaicOptions(resolution_m=resolution_m)
    adj = read_adjustment(adjustment) if adjustment is not None else None
    cam = camera_from_files(camera, adj)
    nav = _trajectory(trajectory, adj)
    z, grid = read_dsm(dsm)
    terrain = MapTerrain(z, grid, opts.frame, source=f"--dsm {str(dsm)!r}")
    strips, wl, n_px_full = _strips(
        lines, nav, cam, bands, max_nav_gap_s, trajectory, line_pixels, adj
    )
    names = [f"{w:g} nm" for w in wl]
    try:
        mosaic = build_mosaic(MosaicInputs(tuple(strips), terrain, tuple(names), tuple(wl)), opts)
    except ObservationError as exc:
        raise InputError(str(exc)) from None
    with _client(scheduler):
        write_cog(mosaic, output, overwrite=overwrite, inputs=inputs, progress=progress)
    x, y = mosaic["x"].values, mosaic["y"].values
    return {
        "output": str(output),
        "crs": str(mosaic.rio.crs),
        "resolution_m": opts.resolution_m,
        "width": int(x.size),
        "height": int(y.size),
        "x_m": [float(x.min()), float(x.max())],
        "y_m": [float(y.min()), float(y.max())],
        "bands": names,
        "strips": [s.name for s in strips],
        "line_pixels": n_px_full,
        "adjusted": adjustment is not None,
        "scheduler": scheduler,
    }


def _check_distinct(lines) -> None:
    """No LINES file given twice (it would be mosaicked twice, silently)."""
    from pathlib import Path

    seen = {}
    for p in lines:
        key = Path(p).resolve()
        if key in seen:
            raise InputError(
                f"LINES {str(p)!r} is given twice (also as {str(seen[key])!r}); give each strip "
                "once"
            )
        seen[key] = p


@contextmanager
def _client(scheduler):
    """The tiles computed on the ``dask.distributed`` scheduler at ``scheduler`` (None: threads
    here) while the context lasts. The client is not made the process's default: a failed
    ``Client(..., set_as_default=True)`` stays registered, and every later compute in the
    process would wait on a scheduler that is not there.
    """
    if scheduler is None:
        yield None
        return
    import dask
    from distributed import Client

    try:
        client = Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"--scheduler {scheduler}: no dask scheduler answers there ({type(exc).__name__}); "
            "start one (dask scheduler; dask worker ADDRESS) or leave the option out"
        ) from None
    try:
        with dask.config.set(scheduler=client.get):
            yield client
    finally:
        client.close()
