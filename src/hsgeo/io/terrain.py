"""Terrain as delivered: a DSM/DEM GDAL reads, in any CRS and vertical datum, into the local frame.

:func:`read_terrain` reads a raster GDAL opens (GeoTIFF, COG, VRT …) through rasterio, only the
window under the lines, and gives the terrain surface as heights ``U(E, N)`` in the local
east-north-up frame of the computation (:class:`hsgeo.crs.LocalFrame`), on a regular grid about
as fine as the file's cells: the ``dem`` of :class:`hsgeo.geocode.DemTerrain`.

Every coordinate goes through PROJ (pyproj): the frame's grid node (E, N, U) → longitude,
latitude on the frame's datum → the file's horizontal CRS (projected or geographic) → the file's
height there (bilinear) → with the file's vertical datum to an ellipsoidal height on the frame's
datum. Because the ellipsoid normal under a node is tilted against the frame's up (0.13° at
15 km), the node's U is found by a fixed-point iteration: the point (E, N, U) whose ellipsoidal
height equals the terrain's there (three to four steps to 0.1 mm).

The vertical datum comes from the file's CRS: a geographic 3D CRS (ellipsoidal heights), or a
compound CRS whose vertical part PROJ converts with its geoid grid (EGM96 ``egm96_15.gtx`` of
Debian's ``proj-data``, found through :func:`hsgeo.crs.use_system_proj_grids`); PROJ is asked
for its best transformation only, so a missing grid is an error, never a silently ignored geoid.
A 2D CRS has no vertical datum: the caller states it (``vertical="ellipsoidal"`` or a vertical
CRS such as ``"EPSG:5773"``), or the file is refused with that choice named.

Voids (nodata) are kept as a mask and filled with their nearest valid height so the surface is
defined everywhere; :meth:`RasterTerrain.check_voids` refuses ground points that land in one
(naming the place and the remedy), and voids elsewhere do not matter.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError, ObservationError

__all__ = ["RasterTerrain", "read_terrain", "MAX_GRID_NODES"]

#: The most nodes of the frame grid read at once (≈ 1.6 GB of working arrays).
MAX_GRID_NODES = 20_000_000

#: Convergence of the node heights' fixed-point iteration (m) and its most steps.
_TOL_M = 1e-4
_MAX_ITER = 10

_VERTICAL_CHOICE = (
    "state it: --vertical ellipsoidal (heights above the ellipsoid of the CRS's datum) or "
    "--vertical EPSG:n (the vertical CRS of the heights, e.g. EPSG:5773 EGM96 height), or give "
    "the file a compound CRS (e.g. EPSG:25832+5941)"
)


@dataclass(frozen=True)
class RasterTerrain:
    """A DSM read into the local frame.

    Attributes
    ----------
    dem : xarray.DataArray
        ``U`` (m) of the terrain surface on a regular ``(N, E)`` grid of the frame (1-D
        coordinates ``E``, ``N`` in m), voids filled with the nearest valid height: give it to
        :class:`hsgeo.geocode.DemTerrain`.
    void : (n_N, n_E) bool ndarray
        Grid nodes whose height the file does not give (nodata, or outside the file).
    source : str
        The file, its CRS and vertical datum in words.
    frame : hsgeo.crs.LocalFrame
    """

    dem: object
    void: np.ndarray
    source: str
    frame: object

    def check_voids(self, E_m, N_m) -> None:
        """Refuse ground points whose bilinear cell touches a void of the DSM.

        Parameters
        ----------
        E_m, N_m : array_like, m
            Ground points (e.g. where the rays met the terrain) in the frame.

        Raises
        ------
        ObservationError
            Naming how many points land in a void, the first one's place (frame E, N; latitude,
            longitude) and the remedy.
        """
        E = np.asarray(E_m, float).ravel()
        N = np.asarray(N_m, float).ravel()
        e = self.dem["E"].values
        n = self.dem["N"].values
        fe = (E - e[0]) / (e[1] - e[0])
        fn = (N - n[0]) / (n[1] - n[0])
        inside = (fe >= 0) & (fe <= e.size - 1) & (fn >= 0) & (fn <= n.size - 1)
        inside &= np.isfinite(fe) & np.isfinite(fn)
        bad = ~inside
        i0 = np.clip(np.floor(np.where(inside, fe, 0)).astype(int), 0, e.size - 2)
        j0 = np.clip(np.floor(np.where(inside, fn, 0)).astype(int), 0, n.size - 2)
        v = self.void
        touch = v[j0, i0] | v[j0, i0 + 1] | v[j0 + 1, i0] | v[j0 + 1, i0 + 1]
        bad |= inside & touch
        if not np.any(bad):
            return
        k = int(np.flatnonzero(bad)[0])
        lon, lat, _ = self.frame.enu_to_lonlat(E[k], N[k], 0.0)
        what = "a void (nodata) of" if inside[k] else "outside the part read of"
        raise ObservationError(
            f"{int(bad.sum())} of {E.size} ground points land in a void (nodata) or outside "
            f"{self.source}; the first lands in {what} it at E {E[k]:.1f} m, N {N[k]:.1f} m of "
            f"the local frame (latitude {float(lat):.6f}°, longitude {float(lon):.6f}°). Fill "
            "the voids there (e.g. gdal_fillnodata.py, or a DTM under the DSM), give a DSM that "
            "covers the lines, or a plane height (--height)"
        )


def read_terrain(path, frame, bounds, vertical=None, *, cell_m: float | None = None):
    """Read the part of a DSM/DEM under ``bounds`` into the local frame.

    Parameters
    ----------
    path : str or path-like
        Any raster GDAL opens (GeoTIFF, COG, VRT …), band 1 the heights in metres.
    frame : hsgeo.crs.LocalFrame
        The local frame of the computation.
    bounds : (E_min, N_min, E_max, N_max), m
        The region of the frame the rays can reach (e.g. the lines' footprint and a margin).
    vertical : str, optional
        For a file whose CRS is 2D: ``"ellipsoidal"`` or a vertical CRS (``"EPSG:5773"``).
        Refused when the file names its own vertical datum (compound or 3D CRS).
    cell_m : float, optional
        The frame grid's spacing (m); default the file's cell size there.

    Returns
    -------
    RasterTerrain

    Raises
    ------
    InputError
        The file cannot be opened, has no CRS, an unknown vertical datum (naming the choice), a
        vertical datum PROJ cannot convert (a missing geoid grid: install ``proj-data``), does
        not overlap ``bounds``, or has no valid height under them.
    """
    import rasterio
    from rasterio.errors import RasterioError

    from hsgeo.crs import use_system_proj_grids
    from hsgeo.io.geotiff import check_dsm_bands

    use_system_proj_grids()
    path = Path(path)
    name = f"DSM {str(path)!r}"
    E0, N0, E1, N1 = (float(b) for b in bounds)
    if not (E1 > E0 and N1 > N0):
        raise InputError(f"terrain bounds {bounds!r} are not (E_min, N_min, E_max, N_max)")
    try:
        with rasterio.Env(GTIFF_REPORT_COMPD_CS=True), rasterio.open(path) as src:
            if src.crs is None:
                raise InputError(
                    f"{name} has no CRS: assign it (gdal_edit.py -a_srs EPSG:n, with the "
                    "vertical datum, e.g. EPSG:25832+5941)"
                )
            check_dsm_bands(src, name)
            horiz, to_datum, vdesc = _crs_chain(name, src.crs.to_wkt(), vertical, frame)
            grid = _frame_grid(src, frame, horiz, (E0, N0, E1, N1), cell_m)
            win, z, affine = _read_window(src, name, horiz, frame, grid)
            nodata = src.nodata
            scale, offset = float(src.scales[0]), float(src.offsets[0])
    except RasterioError as exc:
        raise InputError(f"{name} cannot be read by GDAL ({exc})") from exc
    source = f"{name} ({horiz.name}; heights {vdesc})"
    if nodata is not None:
        z = np.where(z == nodata, np.nan, z)
    z = z * scale + offset  # a scaled-integer DSM (GDAL's scale and offset): metres
    U, void = _heights(frame, horiz, to_datum, z, affine, grid)
    if np.all(void):
        raise InputError(f"{name} has no valid height under the lines ({source})")
    import xarray as xr

    Ue = _fill_nearest(U, void)
    E, N = grid
    dem = xr.DataArray(
        Ue, dims=("N", "E"), coords={"N": N, "E": E}, name="height", attrs={"source": source}
    )
    return RasterTerrain(dem, void, source, frame)


def _crs_chain(name, wkt, vertical, frame):
    """(horizontal CRS, transformer file 3D → frame's geographic 3D, vertical in words)."""
    from pyproj import CRS
    from pyproj.crs import CompoundCRS

    from hsgeo.crs import parse_crs

    crs = CRS.from_wkt(wkt)
    if crs.is_compound:
        horiz, vert = crs.sub_crs_list[0], crs.sub_crs_list[1]
        if vertical is not None:
            raise InputError(
                f"{name} names its vertical datum ({vert.name}): drop --vertical {vertical}"
            )
        src3d, vdesc = crs, f"{vert.name} ({vert.to_string()})"
    elif len(crs.axis_info) == 3:
        if vertical is not None:
            raise InputError(
                f"{name} has ellipsoidal heights ({crs.name}): drop --vertical {vertical}"
            )
        horiz, src3d, vdesc = crs.to_2d(), crs, f"ellipsoidal on {crs.name}"
    else:
        horiz = crs
        if vertical is None:
            raise InputError(
                f"{name}: its CRS {crs.name!r} ({crs.to_string()}) names no vertical datum, so "
                f"its heights are of unknown meaning; {_VERTICAL_CHOICE}"
            )
        if str(vertical).strip().lower() == "ellipsoidal":
            src3d, vdesc = crs.to_3d(), f"ellipsoidal on {crs.geodetic_crs.name} (as stated)"
        else:
            vert = parse_crs(vertical)
            if not vert.is_vertical:
                raise InputError(
                    f"--vertical {vertical}: {vert.name!r} is not a vertical CRS; "
                    f"{_VERTICAL_CHOICE}"
                )
            src3d = CompoundCRS(f"{crs.name} + {vert.name}", [crs, vert])
            vdesc = f"{vert.name} ({vert.to_string()}, as stated)"
    to_datum = _best_transformer(name, src3d, frame, vdesc)
    return horiz, to_datum, vdesc


def _best_transformer(name, src3d, frame, vdesc):
    """PROJ's best transformation of the file's heights to ellipsoidal heights on the frame's
    datum, refused when its grid is missing or when PROJ would ignore the geoid (a "ballpark"
    vertical transformation: tens of metres off, silently).
    """
    from pyproj.transformer import TransformerGroup

    group = TransformerGroup(src3d, frame.datum_crs, always_xy=True)
    if not group.best_available or not group.transformers:
        grids = sorted(
            {
                g.short_name
                for op in group.unavailable_operations
                for g in op.grids
                if not g.available
            }
        )
        raise InputError(
            f"{name}: PROJ's transformation of its heights ({vdesc}) to ellipsoidal heights on "
            f"{frame.datum_crs.name} needs the grid {', '.join(grids) or '(unnamed)'}, which is "
            "not installed. Install it into /usr/share/proj (Debian's proj-data has EGM96; "
            "others: projsync --file NAME, or from cdn.proj.org), or give the DSM with "
            "ellipsoidal heights (--vertical ellipsoidal on a 2D CRS)"
        )
    to_datum = group.transformers[0]
    if "ballpark vertical" in to_datum.description.lower():
        raise InputError(
            f"{name}: PROJ knows no transformation of its heights ({vdesc}) to ellipsoidal "
            f"heights on {frame.datum_crs.name} (it offers only one that ignores the geoid: "
            f"{to_datum.description}); give the DSM with ellipsoidal heights or in a vertical "
            "CRS PROJ can convert (e.g. EPSG:5773, EGM96 height)"
        )
    return to_datum


def _frame_grid(src, frame, horiz, bounds, cell_m):
    """The frame grid's E, N nodes, spaced about as the file's cells (or ``cell_m``)."""
    E0, N0, E1, N1 = bounds
    if cell_m is None:
        from pyproj import Transformer

        t = Transformer.from_crs(horiz, frame.datum_crs.to_2d(), always_xy=True)
        Ec, Nc = 0.5 * (E0 + E1), 0.5 * (N0 + N1)
        lon, lat, _ = frame.enu_to_lonlat(Ec, Nc, 0.0)
        inv = t.transform(float(lon), float(lat), direction="INVERSE")
        a = src.transform
        px = [inv, (inv[0] + a.a, inv[1] + a.d), (inv[0] + a.b, inv[1] + a.e)]
        lo, la = t.transform([p[0] for p in px], [p[1] for p in px])
        e, n, _ = frame.lonlat_to_enu(lo, la, np.zeros(3))
        cell_m = float(min(np.hypot(e[1] - e[0], n[1] - n[0]), np.hypot(e[2] - e[0], n[2] - n[0])))
    if not (np.isfinite(cell_m) and cell_m > 0):
        raise InputError(f"terrain grid spacing {cell_m!r} m is not positive")
    nE = int(np.ceil((E1 - E0) / cell_m)) + 1
    nN = int(np.ceil((N1 - N0) / cell_m)) + 1
    if nE * nN > MAX_GRID_NODES:
        need = cell_m * np.sqrt(nE * nN / MAX_GRID_NODES)
        raise InputError(
            f"the terrain under the lines would be {nN} × {nE} nodes at {cell_m:.3g} m (more "
            f"than {MAX_GRID_NODES:,}): give a coarser grid spacing (cell_m ≥ {need:.2g} m) or "
            "read the lines in parts"
        )
    return E0 + cell_m * np.arange(nE), N0 + cell_m * np.arange(nN)


def _read_window(src, name, horiz, frame, grid):
    """The file's window under the grid (a margin of 2 cells), read as float64."""
    from pyproj import Transformer
    from rasterio.windows import Window, from_bounds

    E, N = grid
    k = 33
    e = np.concatenate([np.linspace(E[0], E[-1], k)] * 2 + [np.full(k, E[0]), np.full(k, E[-1])])
    n = np.concatenate([np.full(k, N[0]), np.full(k, N[-1])] + [np.linspace(N[0], N[-1], k)] * 2)
    t = Transformer.from_crs(frame.datum_crs.to_2d(), horiz, always_xy=True)
    xs, ys = [], []
    for u in (-500.0, 0.0, 3000.0):  # terrain heights the ground can have
        lon, lat, _ = frame.enu_to_lonlat(e, n, np.full(e.size, u))
        x, y = t.transform(lon, lat)
        xs.append(x)
        ys.append(y)
    x, y = np.concatenate(xs), np.concatenate(ys)
    w = from_bounds(x.min(), y.min(), x.max(), y.max(), src.transform)
    c0, r0 = int(np.floor(w.col_off)) - 2, int(np.floor(w.row_off)) - 2
    c1 = int(np.ceil(w.col_off + w.width)) + 2
    r1 = int(np.ceil(w.row_off + w.height)) + 2
    c0, r0, c1, r1 = max(c0, 0), max(r0, 0), min(c1, src.width), min(r1, src.height)
    if c1 <= c0 or r1 <= r0:
        raise InputError(
            f"{name} does not cover the lines: their region is x {x.min():.6g}…{x.max():.6g}, "
            f"y {y.min():.6g}…{y.max():.6g} in {horiz.name}, the file's "
            f"{src.bounds.left:.6g}…{src.bounds.right:.6g}, {src.bounds.bottom:.6g}…"
            f"{src.bounds.top:.6g}"
        )
    win = Window(c0, r0, c1 - c0, r1 - r0)
    z = src.read(1, window=win).astype(np.float64)
    if src.nodata is not None and np.isnan(src.nodata):
        z = np.where(np.isnan(z), np.nan, z)
    return win, z, src.window_transform(win)


def _heights(frame, horiz, to_datum, z, affine, grid):
    """U of the terrain under each grid node: (E, N, U) with the terrain's ellipsoidal height."""
    from pyproj import Transformer
    from scipy.ndimage import map_coordinates

    E, N = np.meshgrid(*grid)
    t = Transformer.from_crs(frame.datum_crs.to_2d(), horiz, always_xy=True)
    inv = ~affine
    U = np.zeros_like(E)
    for _ in range(_MAX_ITER):
        lon, lat, h_now = frame.enu_to_lonlat(E, N, U)
        x, y = t.transform(lon, lat)
        col, row = inv @ (x, y)
        H = map_coordinates(z, [row - 0.5, col - 0.5], order=1, mode="constant", cval=np.nan)
        _, _, h_ter = to_datum.transform(x, y, H)
        g = np.asarray(h_now) - np.asarray(h_ter)
        void = ~np.isfinite(g)
        U = np.where(void, U, U - g)
        if np.all(void) or np.nanmax(np.abs(g)) < _TOL_M:
            break
    return U, void


def _fill_nearest(U, void):
    if not np.any(void):
        return U
    from scipy.ndimage import distance_transform_edt

    idx = distance_transform_edt(void, return_distances=False, return_indices=True)
    return U[tuple(idx)]
