"""Orthorectification and mosaicking of any sensor's lines or frames onto a map grid with a CRS.

The gridded half of :mod:`hsgeo.geocode` (which meets rays with the terrain): every pixel of
every line of a :class:`Strip` is geolocated (the sensor's ``rays`` at the line's time on its
:class:`~hsgeo.trajectory.Trajectory`, :func:`hsgeo.geocode.intersect` with the terrain in the
local ENU frame, then longitude and latitude on the frame's datum by
:class:`hsgeo.crs.LocalFrame`), and the swath is resampled onto a :class:`MapGrid` in the map CRS
(EPSG:25832 for 002) by nearest
neighbour within a radius of influence (every spectrum stays as it was measured, as is usual for
imaging spectrometers), found in the grid's own metres: by a compiled bucket search in the
tiles of :func:`orthomosaic` (:func:`hsgeo._nearest.nearest_cells`, the answer of a kd-tree at a
tenth of its cost), by pykdtree (pyresample's kd-tree) in :func:`resample_swath` (which says
why not through pyresample's geographic path).

**Mosaic rules** (:data:`MOSAIC_RULES`, ``hsgeo orthorectify --mosaic``). Within one strip a
map cell takes the strip's nearest pixel (within the radius of influence). Where strips overlap:

* ``nearest-nadir`` (the default): the pixel whose ray is closest to the nadir (smallest
  off-nadir angle ``arccos(−d_U)`` of its ray) among the nearest pixels of each strip. The rule
  needs nothing of a particular sensor (it is the ``|x|``-smallest rule of a pushbroom camera on
  a level platform; for the frames of a frame camera, each frame a strip whose lines are its
  image rows (:attr:`Strip.row_px`), it gives a cell to the frame that sees it most nearly from
  above);
* ``first``: the first strip given that covers the cell;
* ``mean``: the mean, band by band, of the strips' nearest pixels that cover the cell (spectra
  of different strips mixed: for display, not for spectral analysis).

**Chunks.** :func:`orthomosaic` returns an :class:`xarray.DataArray` ``(band, y, x)`` backed by
Dask, one chunk per output tile. Each line block is geolocated once, by its own task
(:func:`block_ground`: map x, y and off-nadir angle of its pixels, the poses computed once per
line; the frame's PROJ transforms of the block by a polynomial fitted to PROJ at a few nodes,
used only where its difference from PROJ, checked on the block, is within 1 mm:
:mod:`hsgeo._approx_transform`); a tile's task takes the blocks whose footprint (the
geolocated perimeter of the block, plus the radius of influence) meets the tile, with their
lines alone, finds each cell's
nearest pixel once for all bands and applies the rule: the cube may be a lazily generated
Dask array larger than memory, and the same graph runs on the threaded scheduler or on a
``dask.distributed`` cluster.

One module of about 640 lines: the strip, its blocks' geolocation and the tiles' mosaic share
the block layout and the graph that ties them; the CRS approximation and the compiled kernels
are modules of their own.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hsgeo._approx_transform import APPROX_TOL_M
from hsgeo._perline import PerLine as _PerLine
from hsgeo.errors import InputError
from hsgeo.geocode import intersect
from hsgeo.mapgrid import MapGrid

__all__ = [
    "Strip",
    "geolocate_lines",
    "strip_footprints",
    "resample_swath",
    "orthomosaic",
    "mosaic_tile",
    "block_ground",
    "ground_points",
    "OFF_NADIR_NAME",
    "MOSAIC_RULES",
]

OFF_NADIR_NAME = "off_nadir_deg"
#: The mosaic rules where strips overlap (module docstring), the default first.
MOSAIC_RULES = {
    "nearest-nadir": "nearest to nadir: the smallest off-nadir angle of the ray wins",
    "first": "first: the first strip given that covers the cell wins",
    "mean": "mean: band by band, of the strips' nearest pixels that cover the cell",
}


@dataclass(frozen=True)
class Strip:
    """One flight strip of any scanning sensor: its lines, their times, and its geometry.

    Parameters
    ----------
    sensor : a scanning sensor of :mod:`hsgeo.sensors` (``rays(pixels, t_s, trajectory, **kw)``)
    trajectory : hsgeo.trajectory.Trajectory
        The (adjusted) navigation of the body.
    t_s : (n_lines,) ndarray, s
        Time of each line.
    pixels : (n_px,) or (n_px, 2) ndarray
        One line's pixel coordinates in the sensor's convention (ζ of the 000 line scanner,
        ``(x, y = 0)`` px of the 002 LP camera), the same in every line.
    values : (n_lines, n_px, n_bands) array_like or None
        Radiance or reflectance; a Dask array is never loaded whole (None: the geometry only).
    pixel_kw : dict
        What else ``rays`` takes per pixel (``band=`` of a pushbroom camera).
    name : str
        The strip's id, for messages.
    row_px : (n_lines,) ndarray or None
        A frame's image rows: line ``i`` is image row ``v = row_px[i]``, added to the second
        pixel coordinate of ``pixels`` (``(u, 0)``), all lines at the frame's exposure time
        (:mod:`hsgeo.workflows._ortho_frames`). None: the same pixels in every line (a scanning
        sensor).
    """

    sensor: object
    trajectory: object
    t_s: np.ndarray
    pixels: np.ndarray
    values: object
    pixel_kw: dict = field(default_factory=dict)
    name: str = "strip"
    row_px: np.ndarray | None = None

    def __post_init__(self):
        t = np.asarray(self.t_s, dtype=float)
        px = np.asarray(self.pixels, dtype=float)
        if self.row_px is not None:
            rows = np.asarray(self.row_px, dtype=float)
            if rows.shape != t.shape or px.ndim != 2 or px.shape[1] != 2:
                raise InputError(
                    f"strip {self.name!r}: row_px must be one row per line ({t.size}) and the "
                    f"pixels (n_px, 2), got {rows.shape} and {px.shape}"
                )
            object.__setattr__(self, "row_px", rows)
        shape = tuple(np.shape(self.values)) if self.values is not None else None
        if shape is not None and (len(shape) != 3 or shape[:2] != (t.size, px.shape[0])):
            raise InputError(
                f"strip {self.name!r}: values must be (n_lines, n_px, n_bands) = ({t.size}, "
                f"{px.shape[0]}, …), got {shape}"
            )
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "pixels", px)

    @property
    def n_lines(self) -> int:
        return int(self.t_s.size)

    @property
    def n_bands(self) -> int:
        return int(np.shape(self.values)[2])

    def line_pixels(self, lines=slice(None), columns=slice(None)):
        """Times and pixel coordinates of pixels ``columns`` of ``lines``, line by line:
        ``(t_s (m·k,), pixels (m·k,) or (m·k, 2))`` (a frame's row added, ``row_px``).
        """
        t = self.t_s[lines]
        px = self.pixels[columns]
        m, k = t.size, px.shape[0]
        pp = np.tile(px, (m,) + (1,) * (px.ndim - 1))
        if self.row_px is not None:
            pp[:, 1] += np.repeat(self.row_px[lines], k)
        return np.repeat(t, k), pp

    def geometry(self) -> Strip:
        """The strip without its values (``values=None``): what a tile's task needs besides
        the line blocks it reads, so that a task never depends on the whole cube.
        """
        return replace(self, values=None)


def geolocate_lines(strip: Strip, terrain, frame, lines=slice(None), columns=slice(None)):
    """Ground points of pixels of lines of a strip: ENU, longitude/latitude and off-nadir angle.

    Parameters
    ----------
    strip : Strip
    terrain : PlaneTerrain, DemTerrain or MapTerrain (``height(E, N)`` in the local frame)
    frame : hsgeo.crs.LocalFrame
    lines, columns : slice or index array
        Which lines and pixels of a line.

    Returns
    -------
    enu_m : (m, k, 3) ndarray
        Ground points (E, N, U), m.
    lonlat_deg : (m, k, 2) ndarray
        ETRS89 longitude and latitude, degrees.
    off_nadir_deg : (m, k) ndarray
        Angle between each ray and the downward vertical of the local frame, degrees.
    """
    m, k = strip.t_s[lines].size, strip.pixels[columns].shape[0]
    X, off = _ground_off_nadir(strip, terrain, lines, columns)
    lon, lat, _ = frame.enu_to_lonlat(X[:, 0], X[:, 1], X[:, 2])
    return X.reshape(m, k, 3), np.stack([lon, lat], -1).reshape(m, k, 2), off.reshape(m, k)


def _ground_off_nadir(strip: Strip, terrain, lines, columns, crs_tol_m=None):
    """Ground points (ENU, ``(m·k, 3)``) and off-nadir angles (degrees, ``(m·k,)``) of pixels
    ``columns`` of ``lines`` (``crs_tol_m``: :func:`hsgeo.geocode.intersect`'s).
    """
    k = strip.pixels[columns].shape[0]
    tt, pp = strip.line_pixels(lines, columns)
    nav = _PerLine(strip.trajectory, strip.t_s[lines], tt, k)
    o, d = strip.sensor.rays(pp, tt, nav, **strip.pixel_kw)
    X = intersect(o, d, terrain, crs_tol_m=crs_tol_m)
    return X, np.degrees(np.arccos(np.clip(-d[:, 2], -1.0, 1.0)))


def strip_footprints(strip: Strip, terrain, frame, lines_per_block: int, crs: str):
    """Bounding boxes in ``crs`` of a strip's line blocks and its largest ground pixel spacings.

    Geolocates the perimeter of each block of ``lines_per_block`` lines (its first and last
    line, its first and last pixel of every line).

    Returns
    -------
    blocks : list of (line0, line1)
    bbox_m : (n_blocks, 4) ndarray
        ``x_min, y_min, x_max, y_max`` in ``crs``, m.
    spacing_m : (2,) tuple of float
        Largest distance between neighbouring pixels of a line (across track) and between
        neighbouring lines (along track), m.
    """
    from hsgeo.crs import lonlat_to_crs

    n = strip.n_lines
    blocks = [(a, min(n, a + lines_per_block)) for a in range(0, n, lines_per_block)]
    bbox = np.empty((len(blocks), 4))
    across = along = 0.0
    for i, (a, b) in enumerate(blocks):
        e1, l1, _ = geolocate_lines(strip, terrain, frame, np.unique([a, b - 1]))
        e2, l2, _ = geolocate_lines(strip, terrain, frame, slice(a, b), [0, -1])
        ll = np.concatenate([l1.reshape(-1, 2), l2.reshape(-1, 2)])
        x, y = lonlat_to_crs(crs, ll[:, 0], ll[:, 1], frame.datum_epsg)
        bbox[i] = np.min(x), np.min(y), np.max(x), np.max(y)
        if e1.shape[1] > 1:
            step = np.linalg.norm(np.diff(e1[..., :2], axis=1), axis=-1)
            across = max(across, float(step.max()))
        if b - a > 1:
            step = np.linalg.norm(np.diff(e2[..., :2], axis=0), axis=-1)
            along = max(along, float(step.max()))
    return blocks, bbox, (across, along)


def resample_swath(lonlat_deg, values, rank, grid: MapGrid, radius_m: float, datum_epsg: int):
    """Nearest swath pixel of every cell of ``grid`` within ``radius_m``, in the grid's CRS.

    The swath's pixels go into the grid's CRS (pyproj), and pykdtree (the kd-tree pyresample
    itself uses) finds each cell centre's nearest pixel in the grid's own metres. pyresample's
    ``kd_tree`` (used before) works through geographic coordinates only: the lon/lat of every
    cell (pyproj), geocentric x, y, z of cells and pixels, its radius on a 6370997 m sphere
    (0.3 % short at 60° N), then a second check in map metres; on a 0.9 M-pixel swath onto
    0.97 M cells of 0.3 m that took 1.16 CPU s against 0.22 s for the query here (+0.1 s for
    the pixels' projection), with the same cells filled.

    Parameters
    ----------
    lonlat_deg : (n, 2) ndarray
        Longitude and latitude of the swath pixels, degrees.
    values : (n, n_bands) ndarray
    rank : (n,) ndarray
        The mosaic's ranking of each pixel (the off-nadir angle, degrees): carried along.
    grid : MapGrid
    radius_m : float
        Radius of influence: cells farther from every pixel stay empty.
    datum_epsg : int
        The geographic CRS of ``lonlat_deg`` (the frame's datum, ``frame.datum_epsg``).

    Returns
    -------
    values : (n_bands, height, width) ndarray, NaN where empty
    rank : (height, width) ndarray, +inf where empty
    """
    from pykdtree.kdtree import KDTree

    from hsgeo.crs import lonlat_to_crs

    n_cells = grid.width * grid.height
    out = np.full((values.shape[1], n_cells), np.nan, dtype=np.float32)
    r = np.full(n_cells, np.inf)
    if lonlat_deg.shape[0]:
        px, py = lonlat_to_crs(grid.crs, lonlat_deg[:, 0], lonlat_deg[:, 1], datum_epsg)
        tree = KDTree(np.column_stack([px, py]))
        X, Y = np.meshgrid(grid.x_m, grid.y_m)
        dist, pix = tree.query(
            np.column_stack([X.ravel(), Y.ravel()]), k=1, distance_upper_bound=radius_m
        )
        cell = np.flatnonzero(np.isfinite(dist) & (dist <= radius_m))
        pix = pix[cell].astype(np.intp)
        out[:, cell] = values[pix].T
        r[cell] = rank[pix]
    return out.reshape(-1, grid.height, grid.width), r.reshape(grid.height, grid.width)


def ground_points(
    sensor, trajectory, t_s, pixels, terrain, *, chunk_lines: int = 2000, progress=None, **pixel_kw
) -> np.ndarray:
    """Ground point (E, N, U) of every pixel of every line: ``(n_lines, n_px, 3)``, m.

    Parameters
    ----------
    sensor : a scanning sensor of :mod:`hsgeo.sensors` (``rays(pixels, t_s, trajectory, **kw)``;
        a bare 000 :class:`~hsgeo.sensors.line.LineGeometry` is mounted with
        :func:`hsgeo.sensors.as_sensor` first)
    trajectory : hsgeo.trajectory.Trajectory
    t_s : (n_lines,) ndarray, s
        Time of each line.
    pixels : (n_px,) or (n_px, 2) ndarray
        One line's pixel coordinates in the sensor's convention, the same in every line.
    terrain : ``height(E, N)`` in the local frame (PlaneTerrain, DemTerrain, MapTerrain)
    chunk_lines : int
        Lines geolocated at once (memory).
    progress : callable, optional
        ``progress(done_lines, n_lines)`` after each chunk.
    **pixel_kw
        What else ``rays`` takes per pixel (``band=`` of a pushbroom camera).
    """
    t_s = np.asarray(t_s, dtype=float)
    px = np.asarray(pixels, dtype=float)
    n_lines, n_px = t_s.size, px.shape[0]
    out = np.empty((n_lines, n_px, 3))
    for a in range(0, n_lines, chunk_lines):
        b = min(n_lines, a + chunk_lines)
        m = b - a
        tt = np.repeat(t_s[a:b], n_px)
        pp = np.tile(px, (m,) + (1,) * (px.ndim - 1))
        o, d = sensor.rays(pp, tt, trajectory, **pixel_kw)
        out[a:b] = intersect(o, d, terrain).reshape(m, n_px, 3)
        if progress is not None:
            progress(b, n_lines)
    return out


def block_ground(
    strip: Strip, terrain, frame, lines: tuple, crs: str, crs_tol_m: float | None = None
) -> np.ndarray:
    """Map x, y (in ``crs``, m) and off-nadir angle (degrees) of every pixel of a line block.

    :func:`geolocate_lines` of lines ``line0 … line1 - 1`` (``lines``), the longitude and
    latitude taken to ``crs`` (pyproj): what every tile the block meets shares (one task per
    block in :func:`orthomosaic`'s graph: the geometry is never recomputed per tile or band).

    Parameters
    ----------
    crs_tol_m : float, optional
        The frame's PROJ transforms (the DSM intersection's, then ENU → ``crs``) replaced by a
        polynomial within this bound in metres, verified against PROJ on the block and exact
        where not met (:mod:`hsgeo._approx_transform`); None: PROJ on every pixel.

    Returns
    -------
    (3, m * k) float64 ndarray
        Rows x, y, off-nadir angle; pixels line by line.
    """
    from hsgeo.crs import lonlat_to_crs

    X, off = _ground_off_nadir(strip, terrain, slice(*lines), slice(None), crs_tol_m)

    def to_crs(E, N, U):
        lon, lat, _ = frame.enu_to_lonlat(E, N, U)
        return lonlat_to_crs(crs, lon, lat, frame.datum_epsg)

    if crs_tol_m is None:
        x, y = to_crs(X[:, 0], X[:, 1], X[:, 2])
    else:
        from hsgeo._approx_transform import approx_transform, tolerance_in_units

        tol = tolerance_in_units(crs, crs_tol_m)
        (x, y), _ = approx_transform(to_crs, (X[:, 0], X[:, 1], X[:, 2]), tol)
    return np.stack([np.asarray(x, float), np.asarray(y, float), off])


#: Added to the rank of a cell whose sample holds NaN in a band: any complete sample wins.
_INCOMPLETE_RANK = 1e3


def mosaic_tile(grid: MapGrid, parts, radius_m: float, n_bands: int, rule="nearest-nadir"):
    """One output tile: each strip's pixels near it, resampled, mosaicked by ``rule``.

    Parameters
    ----------
    grid : MapGrid
        The tile.
    parts : list of ([ground, ...], [values, ...])
        Per strip the line blocks that meet the tile: their :func:`block_ground` ``(3, m·k)``
        and their values ``(m, k, n_bands)``.
    radius_m : float
        Radius of influence.
    rule : str
        Where strips overlap (:data:`MOSAIC_RULES`): ``"nearest-nadir"``, ``"first"``,
        ``"mean"``.

    Returns
    -------
    (n_bands, height, width) float32 ndarray, NaN where no strip covers the cell.

    Notes
    -----
    A cell takes each strip's nearest pixel within ``radius_m`` (the compiled bucket search
    :func:`hsgeo._nearest.nearest_cells`: the kd-tree's answer), every band at once.
    """
    from hsgeo._nearest import nearest_cells

    n_cells = grid.height * grid.width
    best = np.full((n_cells, n_bands), np.nan, dtype=np.float32)
    best_rank = np.full(n_cells, np.inf)
    total = np.zeros((n_cells, n_bands)) if rule == "mean" else None
    count = np.zeros((n_cells, n_bands)) if rule == "mean" else None
    for grounds, values in parts:
        g = grounds[0] if len(grounds) == 1 else np.concatenate(grounds, axis=1)
        pix = nearest_cells(grid.x_m, grid.y_m, g[0], g[1], radius_m)
        cell = np.flatnonzero(pix >= 0)
        pix = pix[cell]
        v = _gather(values, pix, n_bands)
        # a NaN sample (a dropped pixel) yields to another strip's complete one
        r = g[2][pix] + np.where(np.isnan(v).any(axis=1), _INCOMPLETE_RANK, 0.0)
        if rule == "mean":  # per band, over the strips whose sample is finite
            ok = np.isfinite(v)
            total[cell] += np.where(ok, v, 0.0)
            count[cell] += ok
            continue
        if rule == "first":
            held = best_rank[cell]
            keep = ~np.isfinite(held) | ((held >= _INCOMPLETE_RANK) & (r < _INCOMPLETE_RANK))
        else:  # nearest-nadir: the ray nearest to nadir
            keep = r < best_rank[cell]
        best[cell[keep]] = v[keep]
        best_rank[cell[keep]] = r[keep]
    if rule == "mean":
        seen = count > 0
        best[seen] = (total[seen] / count[seen]).astype(np.float32)
    return np.ascontiguousarray(best.T).reshape(n_bands, grid.height, grid.width)


def _gather(values, pix, n_bands: int) -> np.ndarray:
    """``(len(pix), n_bands)`` float32: the pixels ``pix`` of the blocks' values, in order."""
    flats = [np.asarray(v).reshape(-1, n_bands) for v in values]
    flat = flats[0] if len(flats) == 1 else np.concatenate(flats)
    return flat[pix].astype(np.float32, copy=False)


def _tile_task(grid, layout, radius_m, n_bands, rule, *arrays):
    """:func:`mosaic_tile` with flat arguments (``layout``: per strip its number of blocks;
    ``arrays``: per strip its blocks' ground, then their values).
    """
    parts, k = [], 0
    for n in layout:
        parts.append((arrays[k : k + n], arrays[k + n : k + 2 * n]))
        k += 2 * n
    return mosaic_tile(grid, parts, radius_m, n_bands, rule)


def orthomosaic(
    strips,
    terrain,
    frame,
    *,
    grid: MapGrid | None = None,
    resolution_m: float | None = None,
    crs: str | None = None,
    band_names=None,
    wavelength_nm=None,
    fwhm_nm=None,
    rule: str = "nearest-nadir",
    tile_px: int = 512,
    lines_per_block: int = 256,
    radius_m: float | None = None,
    max_gib: float | None = None,
    crs_tol_m: float | None = APPROX_TOL_M,
):
    """The orthomosaic of strips of any scanning sensor: a Dask-backed DataArray with a CRS.

    Parameters
    ----------
    strips : sequence of Strip
        Their ``values`` all with the same bands (select the bands before, e.g. true colour).
    terrain : ``height(E, N)`` in the local frame (PlaneTerrain, DemTerrain, MapTerrain)
    frame : hsgeo.crs.LocalFrame
    grid : MapGrid, optional
        The output grid; default: the cells of ``resolution_m`` (default the strips' largest
        ground pixel spacing, 2 significant digits) in ``crs`` (default the frame's map CRS)
        that cover every strip's footprint.
    band_names : sequence of str, optional
    wavelength_nm, fwhm_nm : sequence of float, optional
        Each band's centre wavelength and full width at half maximum, nm (carried into the
        outputs).
    rule : str
        The mosaic rule where strips overlap (:data:`MOSAIC_RULES`; default nearest to nadir).
    tile_px : int
        Output chunk (tile) size, cells.
    lines_per_block : int
        Lines geolocated together (and the footprint granularity).
    radius_m : float, optional
        Radius of influence; default 0.55 × the diagonal of the largest ground pixel spacings
        across and along track plus half a cell (cells outside every swath stay NaN).
    max_gib : float, optional
        The largest mosaic (GiB of float32) built on ``resolution_m``; a larger one (cells far
        finer than the ground pixels), or one a single cell wide, is refused
        (:class:`~hsgeo.InputError`). Default: no size limit.
    crs_tol_m : float, optional
        Each line block's PROJ transforms (the DSM intersection's and into the grid's CRS) by
        a polynomial on PROJ at a few nodes, used only where its difference from PROJ, checked
        on the block, is within this bound, m (default :data:`hsgeo._approx_transform.
        APPROX_TOL_M`, 1 mm; :func:`block_ground`); None: PROJ on every pixel. (Briefly not
        the default: on ``make check-wheel``'s flat DSM it refused rays as outside the DSM,
        which was the compiled crossing's floor at the DSM's lowest height, not the
        approximation: :data:`hsgeo._raycast.FLOOR_MARGIN`.)

    Returns
    -------
    xarray.DataArray
        ``(band, y, x)`` float32, chunks ``(n_bands, tile_px, tile_px)``, coordinates of the
        cell centres, ``band`` names, ``wavelength_nm`` and ``fwhm_nm`` (when given); CRS and
        transform written by rioxarray (``da.rio.crs``, ``da.rio.transform()``).
    """
    if rule not in MOSAIC_RULES:
        raise InputError(
            f"--mosaic {rule!r}: not a mosaic rule; give one of {', '.join(MOSAIC_RULES)}"
        )
    strips = list(strips)
    if not strips:
        raise InputError("no strips to mosaic")
    n_bands = strips[0].n_bands
    if any(s.n_bands != n_bands for s in strips):
        raise InputError(f"strips with different band counts: {[s.n_bands for s in strips]}")
    crs = grid.crs if grid is not None else (crs or f"EPSG:{frame.map_epsg}")
    foot, across, along = [], 0.0, 0.0
    for s in strips:
        blocks, bbox, (ac, al) = strip_footprints(s, terrain, frame, lines_per_block, crs)
        foot.append((blocks, bbox))
        across, along = max(across, ac), max(along, al)
    spacing = max(across, along)
    if grid is None:
        if resolution_m is None:  # the strips' largest ground pixel spacing, 2 digits
            resolution_m = float(f"{spacing:.2g}")
        allb = np.concatenate([f[1] for f in foot])
        grid = MapGrid.covering(allb[:, [0, 2]].ravel(), allb[:, [1, 3]].ravel(), resolution_m, crs)
        _check_size(grid, n_bands, spacing, max_gib)
    if radius_m is None:
        radius_m = 0.55 * np.hypot(across, along) + 0.5 * grid.resolution_m
    data = _mosaic_array(
        strips, foot, grid, terrain, frame, radius_m, tile_px, lines_per_block, rule, crs_tol_m
    )
    bands = {"names": band_names, "wavelength_nm": wavelength_nm, "fwhm_nm": fwhm_nm}
    return _as_dataarray(data, grid, strips, bands, radius_m, rule)


def _check_size(grid: MapGrid, n_bands: int, spacing_m: float, max_gib: float | None) -> None:
    """Refuse a mosaic of more than ``max_gib`` GiB of float32 (None: any size), or of a
    single row or column of cells (a resolution coarser than the strips' extent).
    """
    gib = float(grid.width) * grid.height * n_bands * 4 / 2**30
    if min(grid.width, grid.height) < 2:
        raise InputError(
            f"--resolution {grid.resolution_m:g} m: the mosaic would be {grid.width} x "
            f"{grid.height} cells, coarser than the strips' extent; give a finer --resolution "
            f"(the strips' ground pixels are {spacing_m:.2g} m apart)"
        )
    if max_gib is not None and gib > max_gib:
        raise InputError(
            f"--resolution {grid.resolution_m:g} m: the mosaic would be {grid.width} x "
            f"{grid.height} cells x {n_bands} band(s) ({gib:.3g} GiB of float32), over "
            f"{max_gib:g} GiB; give a coarser --resolution (the strips' ground pixels are "
            f"{spacing_m:.2g} m apart)"
        )


def _mosaic_array(
    strips, foot, grid, terrain, frame, radius_m, tile_px, lines_per_block, rule, crs_tol_m
):
    """The Dask array ``(n_bands, height, width)``: one task per line block that geolocates it
    (:func:`block_ground`), one per tile that mosaics the blocks meeting it
    (:func:`mosaic_tile`).
    """
    import dask
    import dask.array as dsa

    n_bands = strips[0].n_bands
    g_terrain, g_frame = dask.delayed(terrain, pure=True), dask.delayed(frame, pure=True)
    values = [
        s.values
        if isinstance(s.values, dsa.Array)
        else dsa.from_array(np.asarray(s.values), chunks=(lines_per_block, -1, -1))
        for s in strips
    ]
    # one key per strip's geometry (dask would unpack a Strip dataclass with its values and make
    # every task depend on every chunk of the cube), one task per block's ground
    ground, block_values = [], []
    for st, v, (blocks, _) in zip(strips, values, foot, strict=True):
        g_strip = dask.delayed(st.geometry(), pure=True)
        task = dask.delayed(block_ground, pure=True)
        ground.append([task(g_strip, g_terrain, g_frame, ab, grid.crs, crs_tol_m) for ab in blocks])
        # each block's lines once, one key the tiles share (a slice of the Dask array per tile
        # and block cost ~3 ms of graph building each: 53 of them on the bench's swath)
        block_values.append([dask.delayed(v[slice(*ab)], pure=True) for ab in blocks])
    rows = []
    for r0 in range(0, grid.height, tile_px):
        r1 = min(grid.height, r0 + tile_px)
        row = []
        for c0 in range(0, grid.width, tile_px):
            c1 = min(grid.width, c0 + tile_px)
            tile = grid.window(r0, r1, c0, c1)
            x0, y0, x1, y1 = tile.extent_m
            layout, args = [], []
            for g, v, (_, bbox) in zip(ground, block_values, foot, strict=True):
                hit = np.flatnonzero(
                    (bbox[:, 0] - radius_m < x1)
                    & (bbox[:, 2] + radius_m > x0)
                    & (bbox[:, 1] - radius_m < y1)
                    & (bbox[:, 3] + radius_m > y0)
                )
                if hit.size:
                    layout.append(int(hit.size))
                    args += [g[i] for i in hit] + [v[i] for i in hit]
            shape = (n_bands, r1 - r0, c1 - c0)
            if layout:
                task = dask.delayed(_tile_task, pure=True)(
                    tile, layout, radius_m, n_bands, rule, *args
                )
                row.append(dsa.from_delayed(task, shape, dtype=np.float32))
            else:
                row.append(dsa.full(shape, np.nan, dtype=np.float32, chunks=shape))
        rows.append(row)
    return dsa.block(rows)


def _as_dataarray(data, grid, strips, bands, radius_m, rule):
    import rioxarray  # noqa: F401  (the .rio accessor)
    import xarray as xr

    n_bands = data.shape[0]
    names = bands["names"]
    names = [str(b) for b in (names if names is not None else range(n_bands))]
    coords = {"band": names, "y": grid.y_m, "x": grid.x_m}
    for key in ("wavelength_nm", "fwhm_nm"):
        if bands.get(key) is not None:
            coords[key] = ("band", np.asarray(bands[key], dtype=float))
    da = xr.DataArray(
        data,
        dims=("band", "y", "x"),
        coords=coords,
        name="radiance",
        attrs={
            "resampling": "nearest neighbour (in the grid's CRS)",
            "mosaic_rule": MOSAIC_RULES[rule],
            "radius_of_influence_m": float(radius_m),
            "resolution_m": grid.resolution_m,
            "strips": ",".join(s.name for s in strips),
        },
    )
    da["x"].attrs.update(units="m", long_name="easting")
    da["y"].attrs.update(units="m", long_name="northing")
    return da.rio.write_crs(grid.crs).rio.write_transform(grid.transform)
