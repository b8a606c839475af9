"""Geocoding of a recorded flight line (000): orthorectification and GCP deviations.

:func:`geocode_files` (``hsgeo geocode``, the file front end) reads the recorded lines, the
navigation and the sensor description, checks them, and writes the orthoimage as NetCDF and, on
request, ENVI; the in-memory core :func:`orthorectify_lines` (:class:`GeocodeInputs`,
:class:`GeocodeOptions` -> :class:`GeocodeResult`) casts every pixel's ray onto a plane or a DEM
(:mod:`hsgeo.geocode`) and resamples it onto the map grid. :func:`gcp_deviations` geocodes GCP
observations after a GCP calibration of the boresight (as PARGE does, 000 Tables 2–3).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hsgeo.crs import SITE_AAS, LocalFrame
from hsgeo.errors import HsgeoError, InputError
from hsgeo.geocode import (
    DemTerrain,
    PlaneTerrain,
    calibrate_boresight,
    geocode_image,
    geocode_observations,
)
from hsgeo.io import read_dem, read_lines, read_scanning_sensor, to_map_files
from hsgeo.ortho import grid_swath
from hsgeo.sensors.line import LineGeometry
from hsgeo.sensors.pushbroom import PushbroomCamera

__all__ = [
    "geocode_files",
    "gcp_deviations",
    "GeocodeInputs",
    "GeocodeOptions",
    "GeocodeResult",
    "orthorectify_lines",
]


#: Default memory limit of the map grid and the ground coordinates (GiB), ``--max-grid-gib``.
MAX_GRID_GIB = 2.0
#: Default longest navigation gap interpolated across (s), ``--max-nav-gap-s``.
MAX_NAV_GAP_S = 1.0
_GIB = 2.0**30


def grid_bytes(n_cells: float, n_bands: int) -> float:
    """Memory of an orthorectification onto ``n_cells`` cells: the raster (float64 per band)
    and the nearest-neighbour query (cell coordinates, distances and indices, 5 × 8 bytes).
    """
    return float(n_cells) * (8.0 * n_bands + 40.0)


def geocode_files(
    lines,
    trajectory,
    sensor,
    *,
    output,
    dem=None,
    height_m=None,
    resolution_m=0.5,
    envi=None,
    progress=True,
    overwrite: bool = False,
    max_grid_gib: float = MAX_GRID_GIB,
    max_nav_gap_s: float = MAX_NAV_GAP_S,
    band: int = 0,
    site=None,
):
    """Orthorectify a recorded flight line from files (see ``hsgeo geocode --help``).

    ``site``: ``(latitude_deg, longitude_deg[, height_m])`` (ETRS89) of the navigation's local
    frame origin (``--site``; default the 002 site, :data:`hsgeo.crs.SITE_AAS`): the output's
    CRS.

    ``sensor``: the 000 sensor file (``[sensor]``, the LINES pixel coordinate is ζ) or the 002
    camera file (``[camera]``, the LINES pixel coordinate is x in px from the line centre; the
    geometry of camera band ``band`` is used for every band of the LINES file).

    Every check comes before the work: the outputs (folder exists and is writable, not an
    input, an existing file replaced only with ``overwrite``), the inputs (:mod:`hsgeo.io`),
    the geometry (navigation covering the lines without gaps over ``max_nav_gap_s``, terrain
    below the aircraft, view angles of the sensor model) and the memory of the grid (at most
    ``max_grid_gib``). The outputs are written atomically (all or nothing).
    """
    from hsgeo.io._files import check_outputs
    from hsgeo.io.navigation import read_trajectory
    from hsgeo.io.raster import MAP_FORMATS
    from hsgeo.validate import check_navigation_covers

    if (dem is None) == (height_m is None):
        raise InputError("give exactly one of --dem DEM.nc or --height H (a plane)")
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise InputError(f"--resolution must be a positive number of metres, got {resolution_m}")
    frame = _frame(site)
    inputs = (lines, trajectory, sensor, dem)
    outs = [(output, "-o/--output", MAP_FORMATS)]
    if envi is not None:
        outs += [(envi, "--envi"), (str(envi) + ".hdr", "--envi (its .hdr)")]
    check_outputs(outs, inputs, overwrite=overwrite)  # before the work, not after it
    da, t0, rate = read_lines(lines)
    nav = read_trajectory(trajectory)
    scanner = read_scanning_sensor(sensor)
    n_lines, n_px = da.sizes["line"], da.sizes["pixel"]
    t_lines = t0 + np.arange(n_lines) / rate
    check_navigation_covers(
        nav.t_s,
        t_lines,
        nav=repr(str(trajectory)),
        used=f"the lines of {str(lines)!r} (t0_s + line / line_rate_hz)",
        max_gap_s=max_nav_gap_s,
    )
    pixel = np.asarray(da["pixel"].values, dtype=float)
    pixels, pixel_kw = _line_pixels(scanner, pixel, band, sensor)
    _check_principal_point(scanner, pixel, sensor, lines)
    _check_view_angles(scanner, pixels, pixel_kw, t_lines[0], nav, sensor)
    need = n_lines * n_px * 3 * 8.0
    if need > max_grid_gib * _GIB:
        raise InputError(
            f"the ground coordinates of {n_lines} lines x {n_px} pixels need "
            f"{need / _GIB:.3g} GiB, over --max-grid-gib {max_grid_gib:g}; split the LINES file "
            "or raise --max-grid-gib"
        )
    terrain = _terrain(dem, height_m, nav.pose(t_lines)[0][:, 2])
    res = orthorectify_lines(
        GeocodeInputs(da, t0, rate, nav, scanner, terrain, pixels, pixel_kw),
        GeocodeOptions(resolution_m=resolution_m, max_grid_gib=max_grid_gib, frame=frame),
        attrs={"source": str(lines), "sensor": str(sensor)},
        progress=progress,
    )
    return res.ortho, to_map_files(res.ortho, output, envi, inputs=inputs)


def _frame(site):
    """The local frame of ``--site LAT,LON[,H]`` (default the 002 site)."""
    if site is None:
        return SITE_AAS
    site = tuple(float(v) for v in site)
    if len(site) not in (2, 3):
        raise InputError(f"--site needs LAT,LON or LAT,LON,H (degrees, metres), got {site}")
    return LocalFrame(*site)


def _terrain(dem, height_m, U):
    """The DEM or the plane, checked to lie below the aircraft (``U``: its heights, m)."""
    if dem is not None:
        dem_da = read_dem(dem)
        top = float(np.max(dem_da.values))
        if top >= U.min():
            raise InputError(
                f"DEM {str(dem)!r} reaches {top:.6g} m, not below the aircraft (U_m down to "
                f"{U.min():.6g} m in the navigation): are the DEM and the navigation in the same "
                "height system and unit?"
            )
        return DemTerrain(dem_da)
    if not height_m < U.min():
        raise InputError(
            f"--height {height_m:g} m is not below the aircraft (U_m down to {U.min():.6g} m "
            "in the navigation); give the terrain height in the navigation's height system"
        )
    return PlaneTerrain(float(height_m))


@dataclass(frozen=True)
class GeocodeInputs:
    """A recorded flight line and what geocoding it needs.

    Attributes
    ----------
    radiance : xarray.DataArray
        ``(band, line, pixel)`` as :func:`hsgeo.io.read_lines` returns it.
    t0_s, line_rate_hz : float
        Time of line 0 (s) and the line rate (Hz).
    nav : Trajectory
    scanner : a sensor with ``rays`` (:mod:`hsgeo.sensors`)
    terrain : DemTerrain or PlaneTerrain
    pixels : ndarray
        One line's pixel coordinates in the sensor's convention.
    pixel_kw : dict
        The sensor's per-pixel keywords (``band`` of a pushbroom camera).
    """

    radiance: object
    t0_s: float
    line_rate_hz: float
    nav: object
    scanner: object
    terrain: object
    pixels: np.ndarray
    pixel_kw: dict = field(default_factory=dict)


@dataclass(frozen=True)
class GeocodeOptions:
    """Cell size of the map grid (m), the largest memory it may take (GiB), and where the
    navigation's local east-north-up frame lies (:class:`hsgeo.crs.LocalFrame`; the grid's CRS
    is the frame's own plane, :meth:`~hsgeo.crs.LocalFrame.local_crs`).
    """

    resolution_m: float = 0.5
    max_grid_gib: float = MAX_GRID_GIB
    frame: object = SITE_AAS


@dataclass(frozen=True)
class GeocodeResult:
    """The orthoimage ``(band, N, E)`` and every pixel's ground coordinates ``(line, pixel, 3)``."""

    ortho: object
    ground_m: np.ndarray

    def to_dict(self) -> dict:
        """Bands, grid size and extent (m) of the orthoimage."""
        E, N = self.ortho["E"].values, self.ortho["N"].values
        return {
            "bands": int(self.ortho.sizes["band"]),
            "n_north": int(self.ortho.sizes["N"]),
            "n_east": int(self.ortho.sizes["E"]),
            "east_m": [float(E.min()), float(E.max())],
            "north_m": [float(N.min()), float(N.max())],
        }


def orthorectify_lines(
    inputs: GeocodeInputs, options: GeocodeOptions = GeocodeOptions(), *, attrs=None, progress=True
) -> GeocodeResult:
    """Every pixel's ray onto the terrain (:func:`hsgeo.geocode.geocode_image`), then onto a
    north-up grid (:func:`hsgeo.geocode.orthorectify`), once the grid fits in
    ``options.max_grid_gib``.
    """
    da = inputs.radiance
    ground = geocode_image(
        inputs.nav,
        inputs.scanner,
        da.sizes["line"],
        inputs.pixels,
        t0_s=inputs.t0_s,
        line_rate_hz=inputs.line_rate_hz,
        terrain=inputs.terrain,
        progress=progress,
        **inputs.pixel_kw,
    )
    EN = ground[..., :2].reshape(-1, 2)
    span = EN.max(axis=0) - EN.min(axis=0)
    resolution_m, max_grid_gib = options.resolution_m, options.max_grid_gib
    cells = float(np.prod(np.floor(span / resolution_m) + 2))
    need = grid_bytes(cells, da.sizes["band"])
    if need > max_grid_gib * _GIB:
        raise InputError(
            f"the map grid of the footprint ({span[0]:.6g} m x {span[1]:.6g} m) at --resolution "
            f"{resolution_m:g} m has {cells:.3g} cells x {da.sizes['band']} band(s) and needs "
            f"about {need / _GIB:.3g} GiB, over --max-grid-gib {max_grid_gib:g}; use a coarser "
            "--resolution, or raise --max-grid-gib"
        )
    ortho = _to_grid(da, ground, options, attrs)
    return GeocodeResult(ortho, ground)


def _to_grid(da, ground, options, attrs):
    """The swath onto the local frame's grid with a CRS (:func:`hsgeo.ortho.grid_swath`, the
    resampling of the orthomosaic: nearest neighbour, :func:`hsgeo.ortho.resample_swath`), as
    ``(band, N, E)``.
    """
    import rioxarray  # noqa: F401  (the .rio accessor)
    import xarray as xr

    frame = options.frame
    v, grid, radius = grid_swath(
        da.values.astype(np.float64), ground, frame, resolution_m=options.resolution_m
    )
    ortho = xr.DataArray(
        v.astype(np.float64),
        dims=("band", "N", "E"),
        coords={"band": da["band"].values, "N": grid.y_m, "E": grid.x_m},
        name="radiance",
        attrs={
            "crs": grid.crs,
            "local_frame_origin": f"{frame.lat_deg!r} N, {frame.lon_deg!r} E, {frame.h_m!r} m "
            "(ETRS89, ellipsoidal height)",
            "resolution_m": options.resolution_m,
            "resampling": "nearest neighbour (pykdtree in the grid's CRS)",
            "max_distance_m": radius,
            **(attrs or {}),
        },
    )
    ortho["E"].attrs.update(units="m", long_name="easting")
    ortho["N"].attrs.update(units="m", long_name="northing")
    ortho = ortho.rio.set_spatial_dims("E", "N").rio.write_crs(grid.crs)
    return ortho.rio.write_transform(grid.transform)


def _line_pixels(scanner, pixel, band, sensor):
    """The pixel coordinates of one line in the sensor's convention, and its per-pixel keywords."""
    if not isinstance(scanner, PushbroomCamera):  # a line scanner: ζ
        return pixel, {}
    n_bands = len(scanner.c_mm)
    if not (isinstance(band, int | np.integer) and 0 <= band < n_bands):
        raise InputError(
            f"--band {band!r}: the camera file {str(sensor)!r} has bands 0…{n_bands - 1}"
        )
    return np.column_stack([pixel, np.zeros_like(pixel)]), {"band": int(band)}


def _check_principal_point(scanner, pixel, sensor, lines) -> None:
    """The principal point lies on the recorded line: between its first and last pixel."""
    if isinstance(scanner, PushbroomCamera):
        pp, name = scanner.x0_mm / scanner.pixel_mm, "x0_mm / pixel_mm"
    else:
        pp, name = float(scanner.geometry.zeta0_px), "zeta0_px"
    lo, hi = float(np.min(pixel)), float(np.max(pixel))
    if not lo <= pp <= hi:
        raise InputError(
            f"sensor file {str(sensor)!r}: the principal point ({name} = {pp:.6g} px) is off "
            f"the line of {str(lines)!r}, whose pixels run {lo:g}…{hi:g} px; the likely causes: "
            "a principal point of another binning or crop of the detector, the LINES pixel "
            "coordinate counted from another origin, or a value in another unit"
        )


def _check_view_angles(scanner, pixels, pixel_kw, t0_s, nav, sensor):
    """The rays of the first line must look down, within 80° of the nadir."""
    with np.errstate(all="ignore"):
        try:
            _, d = scanner.rays(pixels, np.full(len(pixels), t0_s), nav, **pixel_kw)
            ang = np.degrees(np.arccos(np.clip(-d[:, 2], -1.0, 1.0)))
        except HsgeoError:
            ang = np.array([np.nan])
    p = np.asarray(pixels)[..., 0] if np.ndim(pixels) == 2 else np.asarray(pixels)
    if np.all(np.isfinite(ang)) and np.all(ang > 90.0):  # every ray looks up: the attitude
        roll, pitch = np.degrees(nav.pose(np.array([t0_s]))[1][0, :2])
        raise InputError(
            f"the rays of the first line look up ({np.min(ang):.3g}…{np.max(ang):.3g}° off the "
            f"nadir; roll {roll:.4g}°, pitch {pitch:.4g}° in the navigation); the likely "
            "causes: the navigation's attitude in another convention (the body upside down, z "
            f"up instead of down), the boresight of {str(sensor)!r}, or angles in radians "
            "where degrees are expected"
        )
    if not (np.all(np.isfinite(ang)) and np.all(ang < 80.0)):
        raise InputError(
            f"sensor file {str(sensor)!r}: the pixels {p.min():g}…{p.max():g} px of the LINES "
            f"file look {np.nanmin(ang):.3g}…{np.nanmax(ang):.3g}° off the nadir (over 80°, or "
            "not at all); check the principal point and distance (zeta0_px and c_px, or x0_mm "
            "and c_mm, in this sensor's units), the boresight and the LINES pixel coordinate"
        )


def gcp_deviations(
    nav,
    sensor: LineGeometry,
    line,
    zeta_px,
    gcp_enu_m,
    *,
    height_m: float,
    t0_s: float,
    line_rate_hz: float,
    sigma_m: float = 0.3,
):
    """GCP deviations (geocoded − surveyed) after a GCP calibration of the boresight.

    The boresight is calibrated on the GCPs (:func:`hsgeo.geocode.calibrate_boresight`, the
    "GCP-calibrated auxiliary data" of PARGE), then every GCP observation is geocoded onto the
    plane ``height_m`` with it.

    Parameters
    ----------
    nav : Trajectory
        The recorded navigation.
    sensor : LineGeometry
        The assumed sensor model (nominal or calibrated).
    line : (n,) array_like
        Measured (fractional) line of each GCP.
    zeta_px : (n,) array_like
        Measured pixel of each GCP, px.
    gcp_enu_m : (n, 3) array_like
        Surveyed GCP coordinates, E, N, U in m.
    height_m : float
        Height of the flat terrain, m.
    t0_s, line_rate_hz : float
        Time of line 0 (s) and the line rate (Hz).
    sigma_m : float
        A-priori σ of a GCP's horizontal position in the boresight calibration, m.

    Returns
    -------
    dev_EN_m : (n, 2) ndarray
        Geocoded minus surveyed E, N, m (000 Tables 2–3: Δy, Δx).
    result : AdjustmentResult
        The boresight calibration.
    """
    gcp_enu_m = np.asarray(gcp_enu_m, dtype=float)
    kw = {"t0_s": t0_s, "line_rate_hz": line_rate_hz}
    res = calibrate_boresight(
        nav, sensor, line, zeta_px, gcp_enu_m, height_m=height_m, sigma_m=sigma_m, **kw
    )
    X = geocode_observations(
        nav,
        sensor,
        line,
        zeta_px,
        terrain=PlaneTerrain(height_m),
        boresight_rad=res.value("boresight"),
        **kw,
    )
    return X[:, :2] - gcp_enu_m[:, :2], res
