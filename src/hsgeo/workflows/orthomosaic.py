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
    "orthomosaic_files",
]

#: How long ``--scheduler`` waits for the scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 10.0
#: The true-colour bands' wavelengths (R, G, B), nm: the default ``--bands``.
TRUE_COLOUR_NM = (640.0, 550.0, 460.0)


@dataclass(frozen=True)
class MosaicOptions:
    """Cell size (m), output tile (cells), lines per geolocated block, the local frame."""

    resolution_m: float = 0.3
    tile_px: int = 512
    lines_per_block: int = 256
    frame: object = SITE_AAS


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


def camera_from_files(camera, adjustment=None):
    """The LP camera (:class:`~hsgeo.sensors.pushbroom.PushbroomCamera`) from the camera TOML,
    with the parameters of an ``adjust-pushbroom --json`` result when given.
    """
    from hsgeo.sensors.pushbroom import PushbroomCamera
    from hsgeo.workflows.pushbroom_ba import read_camera

    prior = read_camera(camera)
    kw = dict(
        c_mm=(float(prior.c_mm),) * int(prior.n_bands),
        pixel_mm=prior.pixel_mm,
        x0_mm=prior.x0_mm,
        y0_mm=prior.y0_mm,
        lever_arm_m=tuple(prior.lever_arm_m),
    )
    if adjustment is not None:
        c = np.broadcast_to(adjustment["c_mm"], (int(prior.n_bands),))
        kw.update(
            c_mm=tuple(c),
            boresight_rad=tuple(adjustment["boresight_rad"]),
            lever_arm_m=tuple(adjustment["lever_arm_m"]),
            distortion=tuple(adjustment["distortion"]),
        )
    return PushbroomCamera(**kw)


def _trajectory(trajectory, adjustment):
    from hsgeo.io.navigation import read_trajectory
    from hsgeo.trajectory import CORRECTION_COLUMNS, SplineNodes, corrected_trajectory

    nav = read_trajectory(trajectory)
    if adjustment is None:
        return nav
    t = adjustment["t_nodes_s"]
    if adjustment["node_columns"] != CORRECTION_COLUMNS:
        raise InputError(
            f"--adjustment: node columns {adjustment['node_columns']} are not {CORRECTION_COLUMNS}"
        )
    dt = float(t[2] - t[1])
    nodes = SplineNodes(float(t[1]), float(t[1] + (t.size - 3) * dt), dt)
    if not np.allclose(nodes.t_nodes_s, t, atol=1e-6 * dt):
        raise InputError("--adjustment: the node times are not evenly spaced")
    return corrected_trajectory(nav, nodes, adjustment["nodes"])


def _strips(lines, nav, cam, band_idx, max_nav_gap_s, trajectory):
    from hsgeo.io.lp_strips import open_lp_strip
    from hsgeo.validate import check_navigation_covers

    strips, wl = [], None
    for path in lines:
        lp = open_lp_strip(path)
        if wl is None:
            wl = lp.wavelength_nm
            idx = select_bands(wl, band_idx, repr(str(path)))
        elif lp.wavelength_nm.shape != wl.shape or not np.allclose(lp.wavelength_nm, wl):
            raise InputError(
                f"LINES {str(path)!r}: its bands differ from those of {str(lines[0])!r}"
            )
        check_navigation_covers(
            nav.t_s,
            lp.t_s,
            nav=repr(str(trajectory)),
            used=f"the lines of {str(path)!r} (t_s)",
            max_gap_s=max_nav_gap_s,
        )
        band = min(idx[len(idx) // 2], len(cam.c_mm) - 1)  # the middle band's geometry
        px = np.column_stack([lp.x_px, np.zeros_like(lp.x_px)])
        strips.append(
            Strip(cam, nav, lp.t_s, px, lp.values[:, :, idx], {"band": band}, lp.strip_id)
        )
    return strips, wl[idx]


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
) -> dict:
    """Orthomosaic LP line files into a COG (see ``hsgeo orthomosaic --help``).

    Every check comes before the work: the output (refused if it exists, unless ``overwrite``),
    the inputs, the bands, the navigation covering every line, the DSM's CRS and its cover of
    every strip's footprint. Returns a summary (grid, bands, strips, file).
    """
    from hsgeo.io._files import check_outputs
    from hsgeo.io.geotiff import GEOTIFF_FORMATS, read_dsm, write_cog
    from hsgeo.io.lp_strips import read_adjustment

    lines = list(lines)
    if not lines:
        raise InputError("give at least one LINES file")
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
    strips, wl = _strips(lines, nav, cam, bands, max_nav_gap_s, trajectory)
    names = [f"{w:g} nm" for w in wl]
    try:
        mosaic = build_mosaic(MosaicInputs(tuple(strips), terrain, tuple(names), tuple(wl)), opts)
    except ObservationError as exc:
        raise InputError(str(exc)) from None
    client = _client(scheduler)
    try:
        write_cog(mosaic, output, overwrite=overwrite, inputs=inputs, progress=progress)
    finally:
        if client is not None:
            client.close()
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
        "adjusted": adjustment is not None,
        "scheduler": scheduler,
    }


def _client(scheduler):
    """A ``dask.distributed`` client of the scheduler at ``scheduler`` (None: threads here)."""
    if scheduler is None:
        return None
    from distributed import Client

    try:
        return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s", set_as_default=True)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"--scheduler {scheduler}: no dask scheduler answers there ({type(exc).__name__}); "
            "start one (dask scheduler; dask worker ADDRESS) or leave the option out"
        ) from None
