"""A north-up map grid in a projected CRS, and a DSM on such a grid for rays in the local frame.

:class:`MapGrid` is the output grid of :mod:`hsgeo.ortho` (and a DSM's grid): cell edges, cell
size, the affine transform GDAL writes. :class:`MapTerrain` is
a DSM in the map CRS offered as the terrain of :func:`hsgeo.geocode.intersect` (heights in the
local east-north-up frame of :class:`hsgeo.crs.LocalFrame`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError, ObservationError

__all__ = ["MapGrid", "MapTerrain"]


@dataclass(frozen=True)
class MapGrid:
    """A north-up grid of square cells in a projected CRS.

    Parameters
    ----------
    x_min_m, y_max_m : float, m
        West and north edges of the grid (cell edges, not centres).
    resolution_m : float, m
        Cell size.
    width, height : int
        Columns (east) and rows (south).
    crs : str
        The CRS, anything :class:`pyproj.CRS` reads (e.g. ``"EPSG:32756"``, or
        :meth:`hsgeo.crs.LocalFrame.local_crs` for the local frame); no default: the data's.
    """

    x_min_m: float
    y_max_m: float
    resolution_m: float
    width: int
    height: int
    crs: str

    def __post_init__(self):
        if not (np.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise InputError(
                f"the resolution must be a positive number of metres, got {self.resolution_m}"
            )
        if self.width < 1 or self.height < 1:
            raise InputError(f"the grid needs at least one cell, got {self.width} x {self.height}")

    @classmethod
    def covering(cls, x_range_m, y_range_m, resolution_m: float, crs: str) -> MapGrid:
        """The grid of cells on multiples of ``resolution_m`` that covers the ranges."""
        r = float(resolution_m)
        if not (np.isfinite(r) and r > 0):
            raise InputError(
                f"--resolution must be a positive number of metres, got {resolution_m}"
            )
        x0 = np.floor(min(x_range_m) / r) * r
        x1 = np.ceil(max(x_range_m) / r) * r
        y0 = np.floor(min(y_range_m) / r) * r
        y1 = np.ceil(max(y_range_m) / r) * r
        return cls(
            float(x0), float(y1), r, max(1, round((x1 - x0) / r)), max(1, round((y1 - y0) / r)), crs
        )

    @property
    def transform(self):
        """The affine transform (GDAL convention: the north-west corner of cell (0, 0))."""
        from affine import Affine

        r = self.resolution_m
        return Affine(r, 0.0, self.x_min_m, 0.0, -r, self.y_max_m)

    @property
    def x_m(self) -> np.ndarray:
        """Cell-centre eastings, ``(width,)``, m."""
        return self.x_min_m + (np.arange(self.width) + 0.5) * self.resolution_m

    @property
    def y_m(self) -> np.ndarray:
        """Cell-centre northings, ``(height,)``, m, north first."""
        return self.y_max_m - (np.arange(self.height) + 0.5) * self.resolution_m

    @property
    def extent_m(self) -> tuple:
        """``(x_min, y_min, x_max, y_max)`` of the cell edges, m."""
        r = self.resolution_m
        return (
            self.x_min_m,
            self.y_max_m - self.height * r,
            self.x_min_m + self.width * r,
            self.y_max_m,
        )

    def window(self, row0: int, row1: int, col0: int, col1: int) -> MapGrid:
        """The sub-grid of rows ``row0:row1`` and columns ``col0:col1``."""
        r = self.resolution_m
        return MapGrid(
            self.x_min_m + col0 * r, self.y_max_m - row0 * r, r, col1 - col0, row1 - row0, self.crs
        )


class MapTerrain:
    """A DSM in the map CRS (heights above the GRS80 ellipsoid), for rays in the local frame.

    ``height(E, N)`` returns the local-frame U of the DSM surface below ENU points: (E, N, U)
    → map (x, y) by the frame (twice: with the DSM's mean U, then with the U found), the DSM is
    interpolated bilinearly at (x, y) and the surface point (x, y, h) is taken back to ENU.

    Parameters
    ----------
    height_m : (rows, cols) ndarray
        Ellipsoidal heights, m, rows from north to south.
    grid : MapGrid
        The DSM's cells.
    frame : hsgeo.crs.LocalFrame
    source : str
        The DSM's name for messages (its file).
    """

    def __init__(self, height_m, grid: MapGrid, frame, source: str = "the DSM"):
        from scipy.interpolate import RegularGridInterpolator

        z = np.asarray(height_m, dtype=float)
        if z.shape != (grid.height, grid.width):
            raise InputError(
                f"{source}: heights {z.shape} do not match the grid {(grid.height, grid.width)}"
            )
        if not np.all(np.isfinite(z)):
            raise InputError(
                f"{source}: {int(np.sum(~np.isfinite(z)))} cells without a height (nodata or "
                "NaN): fill them (gdal_fillnodata.py) or crop the DSM to its data"
            )
        from hsgeo.crs import same_crs

        if not same_crs(grid.crs, f"EPSG:{frame.map_epsg}"):
            raise InputError(
                f"{source} is in {grid.crs}, the mosaic in EPSG:{frame.map_epsg}: reproject "
                f"the DSM (gdalwarp -t_srs EPSG:{frame.map_epsg}) or give a DSM in the mosaic's CRS"
            )
        self.grid, self.frame, self.source = grid, frame, source
        self._f = RegularGridInterpolator(
            (grid.y_m[::-1], grid.x_m),
            z[::-1],
            method="linear",
            bounds_error=False,
            fill_value=np.nan,
        )
        c = frame.map_to_enu(grid.x_m[[0, -1]].mean(), grid.y_m[[0, -1]].mean(), float(z.mean()))
        self.mean_height_m = float(c[2])
        from hsgeo._raycast import GridSurface

        #: the DSM on its own grid (rows northward) for :func:`hsgeo.geocode.intersect`
        self.map_surface = GridSurface.from_heights(
            z[::-1], grid.x_m[0], grid.y_m[-1], grid.resolution_m, grid.resolution_m
        )
        #: local U the DSM spans (its lowest node at the corners, its highest over the centre
        #: or the frame's origin, whichever is higher, 1 m apart)
        xc = grid.x_m[[0, -1, 0, -1]]
        yc = grid.y_m[[0, 0, -1, -1]]
        u_lo = frame.map_to_enu(xc, yc, np.full(4, z.min()))[2].min()
        u_hi = max(float(c[2]) + z.max() - z.mean(), z.max() - frame.h_m)
        self.u_range_m = (float(u_lo) - 1.0, float(u_hi) + 1.0)
        self.cell_m = grid.resolution_m

    def __reduce__(self):  # the interpolator is rebuilt on a worker from the heights
        return (_rebuild_map_terrain, (self._f.values[::-1], self.grid, self.frame, self.source))

    @property
    def height_range_m(self):
        """Local U the DSM spans, m (:attr:`u_range_m`)."""
        return self.u_range_m

    def height(self, E, N, *, outside: str = "raise"):
        """Local U of the DSM below (E, N); outside it an error (``outside="raise"``) or NaN."""
        E, N = np.broadcast_arrays(np.asarray(E, float), np.asarray(N, float))
        U0 = np.full(E.shape, self.mean_height_m)
        U = self._surface_u(E, N, U0, outside)
        # the map position of (E, N) moves with U by about ΔU·d/R: a second pass where > 1 mm
        redo = np.abs(U - U0) * np.hypot(E, N) / 6.37e6 > 1e-3
        if np.any(redo):
            U[redo] = self._surface_u(E[redo], N[redo], U[redo], outside)
        return U

    def _surface_u(self, E, N, U, outside="raise"):
        x, y, _ = self.frame.enu_to_map(E, N, U)
        h = self._f(np.stack([np.ravel(y), np.ravel(x)], axis=1)).reshape(E.shape)
        if outside == "raise" and np.any(~np.isfinite(h)):
            x0, y0, x1, y1 = self.grid.extent_m
            raise ObservationError(
                f"{int(np.sum(~np.isfinite(h)))} rays reach the ground outside {self.source} "
                f"(x {x0:.0f}…{x1:.0f}, y {y0:.0f}…{y1:.0f} m in {self.grid.crs}): "
                "give a DSM that covers the lines"
            )
        return self.frame.map_to_enu(x, y, h)[2]

    def _outside_message(self, n: int) -> str:
        x0, y0, x1, y1 = self.grid.extent_m
        return (
            f"{n} rays reach the ground outside {self.source} (x {x0:.0f}…{x1:.0f}, "
            f"y {y0:.0f}…{y1:.0f} m in {self.grid.crs}): give a DSM that covers the lines"
        )


def _rebuild_map_terrain(z, grid, frame, source):
    return MapTerrain(z, grid, frame, source)
