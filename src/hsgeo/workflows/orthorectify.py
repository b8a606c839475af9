"""Orthorectify any sensor of the registry, one line, many strips or a frame camera's frames:
``hsgeo orthorectify``.

The in-memory core :func:`orthorectify` (:class:`OrthoInputs`, :class:`OrthoOptions` → a lazy
``(band, y, x)`` :class:`xarray.DataArray` with a CRS, :func:`hsgeo.ortho.orthomosaic`) is what
the chapters call; the file front end :func:`orthorectify_files` reads the lines (hsgeo's
recorded flight line or LP line files: :mod:`hsgeo.workflows._ortho_strips`), the navigation,
the sensor file (:func:`hsgeo.io.read_sensor`, any model of :data:`hsgeo.io.sensor_file.MODELS`:
the 000 line scanner, the 002 pushbroom camera read in full — principal distance per band,
distortion, boresight and lever arm —, the 004 panoramic scanner, a view-angle table, or a
frame camera, ``frame-opencv`` or ``rikola``, whose frames, one ENVI or TIFF file each, are
placed at their exposure times of ``--frame-times``: :mod:`hsgeo.workflows._ortho_frames`;
every sensor through the same first-crossing intersection and mosaic), optionally an
``hsgeo adjust-pushbroom --json`` result (applied by
:func:`hsgeo.sensors.adjusted`), and the terrain (a DSM GeoTIFF in the map CRS, a DEM
NetCDF in the local frame, or a plane); checks them all before the work; and writes the raster
in the format of the output's suffix through the one writer :func:`hsgeo.io.raster.write_raster`
(Cloud-Optimized GeoTIFF, CF-1.8 NetCDF or ENVI). Every pixel's spectrum stays as it was
measured (nearest neighbour); where strips overlap the mosaic rule decides
(:data:`hsgeo.ortho.MOSAIC_RULES`, default nearest to nadir). Tiles are computed with Dask
(``scheduler``: on that ``dask.distributed`` cluster).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field, fields

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.ortho import MOSAIC_RULES, orthomosaic
from hsgeo.workflows._ortho_strips import adjustment_of, line_strip, lp_strips

__all__ = [
    "OrthoInputs",
    "SCHEDULER_GREETING_S",
    "OrthoOptions",
    "OrthoResult",
    "orthorectify",
    "orthorectify_files",
    "adjustment_of",
    "line_strip",
    "lp_strips",
    "MAX_MOSAIC_GIB",
    "SCHEDULER_TIMEOUT_S",
]

#: How long ``--scheduler`` waits for the scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 10.0
#: How long a TCP --scheduler may take to send its handshake (a dask scheduler sends it at once).
SCHEDULER_GREETING_S = 5.0
#: The largest raster built, GiB of float32 (a --resolution far finer than the ground pixels).
MAX_MOSAIC_GIB = 64.0


@dataclass(frozen=True)
class OrthoOptions:
    """How the lines become a raster.

    Attributes
    ----------
    resolution_m : float or None
        Cell size, m; None: the strips' largest ground pixel spacing (2 significant digits).
    mosaic : str
        The rule where strips overlap (:data:`hsgeo.ortho.MOSAIC_RULES`): ``nearest-nadir``
        (default), ``first``, ``mean``.
    crs : str or None
        The output CRS (anything pyproj reads); None: the frame's map CRS
        (``EPSG:{frame.map_epsg}``).
    frame : hsgeo.crs.LocalFrame or None
        Where the navigation's local east-north-up frame lies: required (None is refused; the
        002 site is :data:`hsgeo.crs.SITE_AAS`).
    tile_px, lines_per_block : int
        Output tile (cells) and lines geolocated together.
    max_gib : float
        The largest raster, GiB of float32.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    resolution_m: float | None = None
    mosaic: str = "nearest-nadir"
    crs: str | None = None
    frame: object = None
    tile_px: int = 512
    lines_per_block: int = 256
    max_gib: float = MAX_MOSAIC_GIB


@dataclass(frozen=True)
class OrthoResult:
    """What ``hsgeo orthorectify`` wrote: the output and its files, the grid (CRS, cell size,
    width × height cells, the cell centres' x and y range in the CRS's units), the bands, the
    strips (or frames) mosaicked by the rule ``mosaic``, whether an adjustment was applied, the
    navigation's CRS and the Dask scheduler used (None: threads).
    """

    output: str
    files: tuple
    crs: str
    resolution_m: float
    mosaic: str
    width: int
    height: int
    x_m: tuple
    y_m: tuple
    bands: tuple
    strips: tuple
    line_pixels: int | None
    adjusted: bool
    navigation: str | None
    scheduler: str | None

    def to_dict(self) -> dict:
        """Plain JSON-ready values (what ``hsgeo orthorectify --json`` prints)."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}


@dataclass(frozen=True)
class OrthoInputs:
    """Strips (:class:`hsgeo.ortho.Strip`), the terrain, band names, wavelengths and FWHM (nm)."""

    strips: tuple
    terrain: object
    band_names: tuple = ()
    wavelength_nm: tuple = ()
    fwhm_nm: tuple = ()
    meta: dict = field(default_factory=dict)
    #: The output band each strip fills (one-band strips of a sensor whose bands have their
    #: own geometry, the Rikola's); empty: every strip fills every band.
    layers: tuple = ()


def orthorectify(inputs: OrthoInputs, options: OrthoOptions = OrthoOptions()):
    """The lazy orthoimage / mosaic ``(band, y, x)`` (:func:`hsgeo.ortho.orthomosaic`).

    Returns
    -------
    xarray.DataArray
        float32, Dask-backed (``.compute()`` for memory, or :func:`hsgeo.io.raster.
        write_raster`), CRS and transform through rioxarray, coordinates ``wavelength_nm`` and
        ``fwhm_nm`` of the bands when given.
    """
    if options.frame is None:
        raise InputError("OrthoOptions.frame: give the navigation's local frame (hsgeo.crs)")
    kw = {
        "crs": options.crs,
        "rule": options.mosaic,
        "tile_px": options.tile_px,
        "lines_per_block": options.lines_per_block,
    }
    bands = {
        "band_names": list(inputs.band_names) or None,
        "wavelength_nm": list(inputs.wavelength_nm) or None,
        "fwhm_nm": list(inputs.fwhm_nm) or None,
    }
    try:
        if not inputs.layers:
            return orthomosaic(
                inputs.strips,
                inputs.terrain,
                options.frame,
                resolution_m=options.resolution_m,
                max_gib=options.max_gib,
                **bands,
                **kw,
            )
        return _layered(inputs, options, bands, kw)
    except ObservationError as exc:
        raise InputError(str(exc)) from None


def _layered(inputs: OrthoInputs, options: OrthoOptions, bands: dict, kw: dict):
    """Strips of one band each (``inputs.layers``): one :func:`~hsgeo.ortho.orthomosaic` per
    output band on the grid of all the strips' footprints (the first, lazy call of all strips
    together sets it and checks its size), stacked along ``band``.
    """
    import xarray as xr

    layers = np.asarray(inputs.layers)
    every = orthomosaic(
        inputs.strips,
        inputs.terrain,
        options.frame,
        resolution_m=options.resolution_m,
        max_gib=options.max_gib / max(int(layers.max()) + 1, 1),
        **kw,
    )
    from hsgeo.mapgrid import MapGrid

    res = float(every.attrs["resolution_m"])
    x, y = every["x"].values, every["y"].values
    crs = options.crs or f"EPSG:{options.frame.map_epsg}"
    grid = MapGrid(float(x[0]) - res / 2, float(y[0]) + res / 2, res, x.size, y.size, crs)
    parts = []
    for k in range(int(layers.max()) + 1):
        strips = [s for s, lay in zip(inputs.strips, layers, strict=True) if lay == k]
        parts.append(orthomosaic(strips, inputs.terrain, options.frame, grid=grid, **kw))
    out = xr.concat(parts, dim="band", combine_attrs="override")
    names = bands["band_names"] or [str(k) for k in range(len(parts))]
    out = out.assign_coords(band=[str(b) for b in names])
    for key in ("wavelength_nm", "fwhm_nm"):
        if bands[key] is not None:
            out = out.assign_coords({key: ("band", np.asarray(bands[key], dtype=float))})
    out.attrs["strips"] = ",".join(s.name for s in inputs.strips)
    return out.rio.write_crs(grid.crs).rio.write_transform(grid.transform)


def _terrain(dsm, height_m, frame, U_m, strips=None):
    """The terrain: ``--dsm`` a GeoTIFF (map CRS) or a NetCDF DEM (local frame), or a plane;
    checked to lie below the aircraft (``U_m``: its heights in the navigation).
    """
    from pathlib import Path

    from hsgeo.geocode import DemTerrain, PlaneTerrain
    from hsgeo.io.geotiff import read_dsm
    from hsgeo.io.raster import read_dem
    from hsgeo.mapgrid import MapTerrain

    if (dsm is None) == (height_m is None):
        raise InputError("give exactly one of --dsm DSM (GeoTIFF or NetCDF) or --height H_M")
    low = float(np.min(U_m))
    if dsm is None:
        if not height_m < low:
            raise InputError(
                f"--height {height_m:g} m is not below the aircraft (U_m down to {low:.6g} m "
                "in the navigation); give the terrain height in the navigation's height system"
            )
        return PlaneTerrain(float(height_m))
    if Path(dsm).suffix.lower() in (".nc", ".nc4", ".cdf", ".netcdf"):
        dem = read_dem(dsm)
        top = float(np.max(dem.values))
        if top >= low:
            raise InputError(
                f"DEM {str(dsm)!r} reaches {top:.6g} m, not below the aircraft (U_m down to "
                f"{low:.6g} m in the navigation): are the DEM and the navigation in the same "
                "height system and unit?"
            )
        return DemTerrain(dem)
    z, grid = read_dsm(dsm)
    source = f"--dsm {str(dsm)!r}"
    void = ~np.isfinite(z)
    if strips is None or not void.any() or void.all():
        return MapTerrain(z, grid, frame, source=source)
    return _terrain_with_voids(z, void, grid, frame, source, strips)


def _terrain_with_voids(z, void, grid, frame, source, strips):
    """A DSM with voids (nodata) away from the lines is accepted (a nodata corner far
    from the strips was refused): the voids take their nearest height, and the lines' edge rays
    and about 64 whole lines per strip must not meet the ground in a cell touching one.
    """
    from scipy.ndimage import distance_transform_edt

    from hsgeo.mapgrid import MapTerrain
    from hsgeo.workflows._ortho_geodetic import _edge_points

    idx = distance_transform_edt(void, return_distances=False, return_indices=True)
    terrain = MapTerrain(z[tuple(idx)], grid, frame, source=source)
    g = _edge_points(strips, terrain, frame, lattice=True)
    x, y, _ = frame.enu_to_map(g[:, 0], g[:, 1], g[:, 2])
    r = grid.resolution_m
    col = (np.asarray(x) - grid.x_min_m) / r - 0.5  # cell-centre coordinates
    row = (grid.y_max_m - np.asarray(y)) / r - 0.5
    c0 = np.clip(np.floor(col).astype(int), 0, grid.width - 1)
    r0 = np.clip(np.floor(row).astype(int), 0, grid.height - 1)
    c1, r1 = np.minimum(c0 + 1, grid.width - 1), np.minimum(r0 + 1, grid.height - 1)
    touch = void[r0, c0] | void[r0, c1] | void[r1, c0] | void[r1, c1]
    if touch.any():
        raise InputError(
            f"{source}: {int(void.sum())} cells without a height (nodata or NaN), "
            f"{int(touch.sum())} of {touch.size} sampled ground points of the lines among "
            "them: fill them (gdal_fillnodata.py) or give a DSM with heights under the lines"
        )
    return terrain


def _geodetic_terrain(dsm, height_m, frame, U_m, strips, vertical):
    """The terrain of a geodetic navigation: ``--dsm`` a raster in any CRS read into the frame
    under the lines' footprint (:func:`hsgeo.io.read_terrain`; the ground points checked
    against its voids), or a plane ``--height`` (the frame's U).
    """
    from pathlib import Path

    from hsgeo.geocode import DemTerrain
    from hsgeo.io import read_terrain
    from hsgeo.workflows import _ortho_geodetic as geo

    if dsm is None or height_m is not None:
        return _terrain(dsm, height_m, frame, U_m)
    if Path(dsm).suffix.lower() in (".nc", ".nc4", ".cdf", ".netcdf"):
        raise InputError(
            f"--dsm {str(dsm)!r}: a NetCDF DEM is in a local frame, but the navigation is "
            "geodetic (its frame comes from the data); give the DSM as a GeoTIFF with its CRS"
        )
    raster = read_terrain(dsm, frame, geo.terrain_bounds(strips, frame), vertical)
    top, low = float(np.max(raster.dem.values)), float(np.min(U_m))
    if top >= low:
        raise InputError(
            f"{raster.source} reaches U {top:.6g} m in the local frame, not below the aircraft "
            f"(U down to {low:.6g} m): check its vertical datum (--vertical) and unit"
        )
    terrain = DemTerrain(raster.dem)
    geo.check_voids(strips, raster, terrain, frame)
    return terrain


def _read_strips(lines, nav, sensor, args):
    """The strips of the LINES files (all of one kind), their wavelengths and FWHM."""
    from hsgeo.workflows._ortho_envi import envi_lines

    envi = envi_lines(lines, sensor, nav, args)
    if envi is not None:  # ENVI cubes and their line times
        return envi
    from hsgeo.io.lines import line_file_kind, read_band_widths, read_lines
    from hsgeo.io.lp_lines import full_line_px, open_lp_lines
    from hsgeo.workflows._ortho_strips import check_principal_point

    kinds = {str(p): line_file_kind(p) for p in lines}
    if len(set(kinds.values())) > 1:
        raise InputError(
            "LINES mixes recorded flight lines (radiance) and LP line files (lines): "
            + ", ".join(f"{p!r}: {k}" for p, k in kinds.items())
            + "; give lines of one sensor"
        )
    fwhm = read_band_widths(lines[0])
    if next(iter(kinds.values())) == "lp":
        lps = [open_lp_lines(p) for p in lines]
        n_px_full = full_line_px(lps, args["line_pixels"])
        strips, wl, fw = lp_strips(
            lps, sensor, nav, args["bands"], n_px_full, names=lines, band=args["band"], fwhm_nm=fwhm
        )
        return strips, wl, fw, n_px_full
    strips, wl, fw = [], None, None
    for p in lines:
        da, t0, rate = read_lines(p)
        strip, idx = line_strip(
            da, t0, rate, sensor, nav, bands_nm=args["bands"], band=args["band"], name=str(p)
        )
        check_principal_point(sensor, da["pixel"].values, args["sensor"], p)
        if wl is None and "wavelength_nm" in da.coords:
            wl = np.asarray(da["wavelength_nm"].values, float)[idx]
            fw = None if fwhm is None else np.asarray(fwhm, float)[idx]
        strips.append(strip)
    if len({s.n_bands for s in strips}) > 1:
        raise InputError(
            "LINES have different band counts: "
            + ", ".join(f"{s.name!r}: {s.n_bands}" for s in strips)
        )
    return strips, wl, fw, None


def _strips_of(lines, nav, sensor, args):
    """The strips of LINES: a frame camera's frames (:mod:`hsgeo.workflows._ortho_frames`) or
    a scanning sensor's lines; ``(strips, layers, wavelength_nm, fwhm_nm, n_px_full, names)``.
    """
    from hsgeo.workflows._ortho_frames import frame_strips, is_frame_sensor

    if is_frame_sensor(sensor):
        strips, layers, wl, fw, names = frame_strips(lines, sensor, nav, args)
        return strips, layers, wl, fw, None, names
    if args["frame_times"] is not None:
        raise InputError(
            f"--frame-times is for the frames of a frame camera; the sensor file "
            f"{str(args['sensor'])!r} is a scanning sensor, whose lines carry their times (or "
            "take --line-times): leave --frame-times out"
        )
    strips, wl, fw, n_px_full = _read_strips(lines, nav, sensor, args)
    n_b = strips[0].n_bands
    names = [f"{w:g} nm" for w in wl] if wl is not None else [str(i) for i in range(n_b)]
    return strips, (), wl, fw, n_px_full, names


def _check_nav(strips, nav, trajectory, max_nav_gap_s, adjustment) -> None:
    """The navigation covers every strip's lines; the adjustment's node span too."""
    from hsgeo.validate import check_navigation_covers

    for s in strips:
        check_navigation_covers(
            nav.t_s,
            s.t_s,
            nav=repr(str(trajectory)),
            used=f"the lines of {s.name!r} (t_s)",
            max_gap_s=max_nav_gap_s,
        )
    if adjustment is None:
        return
    t = adjustment["t_nodes_s"]
    dt = float(t[2] - t[1])
    lo, hi = float(t[1]) - dt, float(t[-2]) + dt
    for s in strips:
        if s.t_s[0] < lo or s.t_s[-1] > hi:
            raise InputError(
                f"the lines of {s.name!r} (t_s {s.t_s[0]:.6g}…{s.t_s[-1]:.6g} s) lie outside "
                f"the node times of --adjustment ({t[1]:.6g}…{t[-2]:.6g} s): give the "
                "adjustment of this flight (adjust-pushbroom on observations of these strips)"
            )


def orthorectify_files(
    lines,
    trajectory,
    sensor,
    *,
    output,
    dsm=None,
    height_m=None,
    adjustment=None,
    resolution_m: float | None = None,
    bands=None,
    band: int | None = None,
    mosaic: str = "nearest-nadir",
    crs: str | None = None,
    site=None,
    scheduler=None,
    overwrite: bool = False,
    progress=None,
    max_nav_gap_s: float = 1.0,
    line_pixels: int | None = None,
    max_gib: float = MAX_MOSAIC_GIB,
    tile_px: int = 512,
    nav_crs: str | None = None,
    gps_week: int | None = None,
    vertical: str | None = None,
    line_times=None,
    frame_times=None,
) -> OrthoResult:
    """Orthorectify line files into one raster (see ``hsgeo orthorectify --help``).

    Every check comes before the work: the output (its suffix names the format; refused if it
    exists, unless ``overwrite``, or if it is an input), the inputs, the bands, the navigation
    covering every line, the view angles, the terrain below the aircraft and covering every
    strip's footprint, the raster's size. Returns an :class:`OrthoResult` (grid, bands,
    strips, files).

    A local-ENU navigation needs ``site`` (LAT, LON[, H], the frame's origin on the datum
    ``nav_crs``, default WGS 84); the output CRS defaults to the UTM zone of the site on that
    datum. A geodetic navigation (a geodetic CSV/Parquet or an SBET; ``nav_crs``, ``gps_week``:
    see :func:`hsgeo.io.read_navigation`) brings its own local frame (``site`` refused) and the
    output CRS defaults to the UTM zone of its centre on its datum; its DSM GeoTIFF may be in
    any CRS (``vertical``: ``"ellipsoidal"`` or ``"EPSG:n"`` for a file with a 2D CRS).

    LINES may be ENVI cubes (:mod:`hsgeo.workflows._ortho_envi`), their line times from
    ``line_times`` (one times file per cube) or their headers.

    With a frame camera's sensor file (models ``frame-opencv`` and ``rikola``), LINES are its
    frames, one ENVI or TIFF file each (:mod:`hsgeo.io.frame_images`), and ``frame_times``
    the exposure table (columns ``file``, ``time_s``; for the Rikola optionally ``band``): each
    frame is placed by the navigation at its exposure time composed with the sensor file's
    mount, and mosaicked with the others by ``mosaic`` (:mod:`hsgeo.workflows._ortho_frames`).
    """
    from hsgeo.io import read_sensor
    from hsgeo.io._files import check_outputs
    from hsgeo.io.raster import RASTER_FORMATS, raster_outputs, write_raster
    from hsgeo.io.sensors import read_adjustment
    from hsgeo.sensors import adjusted
    from hsgeo.workflows import _ortho_geodetic as geo
    from hsgeo.workflows._ortho_strips import check_view_angles

    lines = list(lines)
    if not lines:
        raise InputError("give at least one LINES file")
    _check_distinct(lines)
    if resolution_m is not None and not (np.isfinite(resolution_m) and resolution_m > 0):
        raise InputError(f"--resolution must be a positive number of metres, got {resolution_m}")
    if mosaic not in MOSAIC_RULES:
        raise InputError(f"--mosaic {mosaic!r}: give one of {', '.join(MOSAIC_RULES)}")
    from hsgeo.workflows._ortho_envi import envi_files

    inputs = [*lines, trajectory, sensor, dsm, adjustment, *(line_times or ()), frame_times]
    inputs += envi_files(lines)
    check_outputs(raster_outputs(output, RASTER_FORMATS), inputs, overwrite=overwrite)
    navigation = geo.read_nav(trajectory, nav_crs, gps_week, site, vertical, crs)
    geodetic = navigation.source_crs != "local ENU"
    frame = navigation.frame if geodetic else geo.site_frame(site, nav_crs, crs)
    if geodetic and crs is None:
        crs = geo.output_crs(frame)
    adj = read_adjustment(adjustment) if adjustment is not None else None
    try:  # the one sensor reader and the one way to apply an adjustment (any sensor)
        cam, nav = adjusted(read_sensor(sensor), navigation.trajectory, adj)
    except InputError as exc:
        msg = str(exc)
        raise InputError("--" + msg if msg.startswith("adjustment:") else msg) from None
    args = {"line_pixels": line_pixels, "bands": bands, "band": band, "sensor": sensor}
    args.update(line_times=line_times, frame_times=frame_times, trajectory=trajectory)
    args["max_nav_gap_s"] = max_nav_gap_s
    strips, layers, wl, fw, n_px_full, names = _strips_of(lines, nav, cam, args)
    _check_nav(strips, nav, trajectory, max_nav_gap_s, adj)
    for s in strips:
        check_view_angles(s, sensor)
    U = np.concatenate([nav.pose(s.t_s)[0][:, 2] for s in strips])
    if geodetic:
        terrain = _geodetic_terrain(dsm, height_m, frame, U, strips, vertical)
    else:
        terrain = _terrain(dsm, height_m, frame, U, strips)
    opts = OrthoOptions(
        resolution_m=resolution_m,
        mosaic=mosaic,
        crs=crs,
        frame=frame,
        max_gib=max_gib,
        tile_px=tile_px,
    )
    ortho = orthorectify(
        OrthoInputs(
            tuple(strips),
            terrain,
            tuple(names),
            tuple(wl) if wl is not None else (),
            tuple(fw) if fw is not None else (),
            layers=layers,
        ),
        opts,
    )
    with _client(scheduler):
        written = write_raster(ortho, output, overwrite=overwrite, inputs=inputs, progress=progress)
    x, y = ortho["x"].values, ortho["y"].values
    return OrthoResult(
        output=str(output),
        files=tuple(str(p) for p in written),
        crs=str(ortho.rio.crs),
        resolution_m=float(ortho.attrs["resolution_m"]),
        mosaic=mosaic,
        width=int(x.size),
        height=int(y.size),
        x_m=(float(x.min()), float(x.max())),
        y_m=(float(y.min()), float(y.max())),
        bands=tuple(names),
        strips=tuple(s.name for s in strips),
        line_pixels=n_px_full,
        adjusted=adjustment is not None,
        navigation=navigation.source_crs,
        scheduler=scheduler,
    )


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


def _probe_scheduler(scheduler: str) -> None:
    """A TCP ``--scheduler`` must greet as dask's does: its end of the handshake comes first,
    unasked (at an HTTP port, which waits for a request, ``Client(timeout=...)``
    waited for ever — a TimeoutError traceback after 20 s in an earlier version).
    """
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, loc = parse_address(scheduler)
        if scheme != "tcp":
            return  # tls, ucx, inproc: Client's own checks
        host, port = parse_host_port(loc)
    except (ValueError, TypeError):
        return  # Client names a malformed address itself
    t = SCHEDULER_GREETING_S
    try:
        with socket.create_connection((host, int(port)), timeout=t) as sock:
            sock.settimeout(t)
            greeting = sock.recv(8)
    except TimeoutError:
        raise InputError(
            f"--scheduler {scheduler}: a server answers there but sends no dask handshake "
            f"within {t:g} s (a web server or another service?); give the address of a dask "
            "scheduler (dask scheduler prints it) or leave the option out"
        ) from None
    except OSError as exc:
        raise InputError(
            f"--scheduler {scheduler}: no dask scheduler answers there ({type(exc).__name__}: "
            f"{exc.strerror or exc}); start one (dask scheduler; dask worker ADDRESS) or leave "
            "the option out"
        ) from None
    if not greeting:
        raise InputError(
            f"--scheduler {scheduler}: the server there closed the connection without a dask "
            "handshake; give the address of a dask scheduler or leave the option out"
        )


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

    _probe_scheduler(scheduler)
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
