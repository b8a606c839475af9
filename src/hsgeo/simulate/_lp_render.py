"""Rendering of the LP campaign's ground (:mod:`hsgeo.simulate._lp_ground`): where rays meet the
DSM, and the blurred reflectance there (compiled kernels and their numpy faces).

The intersection is hsgeo's one ray–terrain intersection, :func:`hsgeo._raycast.first_crossing`
(the compiled core of :func:`hsgeo.geocode.intersect`): the first crossing of each ray with the
bilinear DSM, exact to rounding, so buildings occlude (the same bilinear DSM as
:class:`hsgeo.geocode.DemTerrain`). A ray that leaves the DSM before it meets it gets NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from hsgeo._chunks import over_items
from hsgeo._raycast import HIT, GridSurface, first_crossing

__all__ = ["Ground", "render_rays", "render_lines", "dsm_height", "BLOCK_CELLS"]


@dataclass(frozen=True)
class Ground:
    """The rasterised ground.

    Attributes
    ----------
    e0_m, n0_m : float
        Map E, N of the centre of raster cell (0, 0) (rows increase northward).
    cell_m : float
        Cell size of the reflectance raster.
    reflectance : (n_bands, n_rows, n_cols) float32
        Blurred reflectance per band.
    material : (n_rows, n_cols) uint8
        Index into :data:`MATERIALS` (for figures).
    dsm : (n_rows_dsm, n_cols_dsm) float64
        Surface heights (m) on a grid of ``dsm_cell_m`` starting at ``(e0_m, n0_m)``.
    dsm_cell_m : float
    """

    e0_m: float
    n0_m: float
    cell_m: float
    reflectance: np.ndarray
    material: np.ndarray
    dsm: np.ndarray
    dsm_cell_m: float

    def dsm_dataarray(self):
        """The DSM as an ``xarray.DataArray`` with coordinates ``N``, ``E`` (m)."""
        import xarray as xr

        n, m = self.dsm.shape
        return xr.DataArray(
            self.dsm,
            dims=("N", "E"),
            coords={
                "N": self.n0_m + self.dsm_cell_m * np.arange(n),
                "E": self.e0_m + self.dsm_cell_m * np.arange(m),
            },
            name="height_m",
        )


# ------------------------------------------------------------------------------ compiled cores
@njit(cache=True, inline="always")
def _bilinear(a, u, v):  # pragma: no cover - compiled
    """Bilinear value of ``a[row, col]`` at fractional (row ``v``, col ``u``), clamped."""
    nr, nc = a.shape
    if u < 0.0:
        u = 0.0
    if v < 0.0:
        v = 0.0
    if u > nc - 1.000001:
        u = nc - 1.000001
    if v > nr - 1.000001:
        v = nr - 1.000001
    j = int(u)
    i = int(v)
    fu = u - j
    fv = v - i
    return (1.0 - fv) * ((1.0 - fu) * a[i, j] + fu * a[i, j + 1]) + fv * (
        (1.0 - fu) * a[i + 1, j] + fu * a[i + 1, j + 1]
    )


#: Chunks of the rendering kernels' loops, run on the kernels' threads
#: (:func:`hsgeo._chunks.over_chunks`; a ``prange`` loop's parallel passes cost compile time,
#: 12.6 and 10.3 s for these two kernels on a fresh cache, issue 41). Each ray is independent of
#: the others, so the number of chunks changes no value.
N_CHUNKS = 64


@njit(cache=True, nogil=True)
def _render_chunk(
    ch, step, O, D, z, e0, n0, de, dn, bmax, blk, zmin, zmax, refl, ge0, gn0, gcell, out_en, out_v
):  # pragma: no cover
    """Rays ``ch·step … (ch+1)·step − 1`` of :func:`render_rays`."""
    for k in range(ch * step, min(O.shape[0], (ch + 1) * step)):
        s, status = first_crossing(
            O[k, 0], O[k, 1], O[k, 2], D[k, 0], D[k, 1], D[k, 2], z, e0, n0, de, dn, bmax, blk,
            zmin, zmax,
        )  # fmt: skip
        if status != HIT:
            out_en[k, 0] = np.nan
            out_en[k, 1] = np.nan
            out_v[k] = np.nan
            continue
        E = O[k, 0] + s * D[k, 0]
        N = O[k, 1] + s * D[k, 1]
        out_en[k, 0] = E
        out_en[k, 1] = N
        if refl.shape[0] > 0:
            out_v[k] = _bilinear(refl, (E - ge0) / gcell, (N - gn0) / gcell)


@njit(cache=True, nogil=True)
def _render_lines_chunk(
    ch, step, R, O, d_plat, z, e0, n0, de, dn, bmax, blk, zmin, zmax, refl, ge0, gn0, gcell, out
):  # pragma: no cover
    """Lines ``ch·step … (ch+1)·step − 1`` of :func:`render_lines`: ``out[l, c, b]``, the
    reflectance of band ``b`` where the ray ``O[l] + s R[l] d_plat[b, c]`` of column ``c`` of
    line ``l`` first meets the DSM (NaN where it leaves the DSM first).
    """
    nb = d_plat.shape[0]
    nc = d_plat.shape[1]
    for li in range(ch * step, min(R.shape[0], (ch + 1) * step)):
        ox, oy, oz = O[li, 0], O[li, 1], O[li, 2]
        for c in range(nc):
            for b in range(nb):
                px, py, pz = d_plat[b, c, 0], d_plat[b, c, 1], d_plat[b, c, 2]
                dx = R[li, 0, 0] * px + R[li, 0, 1] * py + R[li, 0, 2] * pz
                dy = R[li, 1, 0] * px + R[li, 1, 1] * py + R[li, 1, 2] * pz
                dz = R[li, 2, 0] * px + R[li, 2, 1] * py + R[li, 2, 2] * pz
                s, status = first_crossing(
                    ox, oy, oz, dx, dy, dz, z, e0, n0, de, dn, bmax, blk, zmin, zmax
                )
                if status != HIT:
                    out[li, c, b] = np.nan
                    continue
                E = ox + s * dx
                N = oy + s * dy
                out[li, c, b] = _bilinear(refl[b], (E - ge0) / gcell, (N - gn0) / gcell)


def _over(chunk, n: int, *args) -> None:
    """``chunk`` over ``n`` rays or lines in :data:`N_CHUNKS` chunks (fewer when n is small)."""
    over_items(chunk, n, max(1, min(N_CHUNKS, n)), *args)


def render_rays(origins_m, directions, ground: Ground, band: int | None = None):
    """Where rays meet the DSM, and the blurred reflectance of ``band`` there.

    Parameters
    ----------
    origins_m, directions : (n, 3) ndarray
        Ray origins (E, N, U, m) and directions (map frame, pointing down).
    ground : Ground
    band : int, optional
        Band of :attr:`Ground.reflectance` to sample (None: intersection only).

    Returns
    -------
    en_m : (n, 2) ndarray
        Ground E, N of each ray.
    value : (n,) ndarray or None
        The reflectance there.
    """
    O = np.ascontiguousarray(origins_m, dtype=np.float64)
    D = np.ascontiguousarray(directions, dtype=np.float64)
    refl = ground.reflectance[band] if band is not None else np.zeros((0, 0), np.float32)
    en = np.empty((O.shape[0], 2))
    val = np.empty(O.shape[0])
    _over(
        _render_chunk,
        O.shape[0],
        O,
        D,
        *_surface(ground).args(),
        refl,
        ground.e0_m,
        ground.n0_m,
        ground.cell_m,
        en,
        val,
    )
    return en, (val if band is not None else None)


#: DSM cells per block of the intersection's block maxima (:class:`hsgeo._raycast.GridSurface`).
BLOCK_CELLS = 16


def _surface(ground: Ground) -> GridSurface:
    """The DSM prepared for the intersection (cached on the ground)."""
    cached = getattr(ground, "_surface_cache", None)
    if cached is not None:
        return cached
    c = ground.dsm_cell_m
    out = GridSurface.from_heights(ground.dsm, ground.e0_m, ground.n0_m, c, c, BLOCK_CELLS)
    object.__setattr__(ground, "_surface_cache", out)
    return out


def render_lines(R_map_from_platform, origins_m, d_platform, ground: Ground) -> np.ndarray:
    """Reflectance seen by each column of each line in each band: ``(n_lines, n_cols, n_bands)``.

    Parameters
    ----------
    R_map_from_platform : (n_lines, 3, 3) ndarray
    origins_m : (n_lines, 3) ndarray
        Projection centre of each line (map frame).
    d_platform : (n_bands, n_cols, 3) ndarray
        Ray direction of each column in each band in the platform frame: the ray of column
        ``c`` of line ``l`` in band ``b`` is ``origins_m[l] + s R[l] d_platform[b, c]`` (the
        factored form of :meth:`hsgeo.sensors.pushbroom.PushbroomCamera.rays_at`).

    Returns
    -------
    (n_lines, n_cols, n_bands) float32
    """
    R = np.ascontiguousarray(R_map_from_platform, dtype=np.float64)
    O = np.ascontiguousarray(origins_m, dtype=np.float64)
    d = np.ascontiguousarray(d_platform, dtype=np.float64)
    nb = d.shape[0]
    if ground.reflectance.shape[0] < nb:
        raise ValueError("more bands of rays than of the ground's reflectance")
    out = np.empty((R.shape[0], d.shape[1], nb), np.float32)
    _over(
        _render_lines_chunk,
        R.shape[0],
        R,
        O,
        d,
        *_surface(ground).args(),
        ground.reflectance,
        ground.e0_m,
        ground.n0_m,
        ground.cell_m,
        out,
    )
    return out


def dsm_height(ground: Ground, e_m, n_m) -> np.ndarray:
    """Bilinear DSM height (m) at map E, N (as :class:`~hsgeo.geocode.DemTerrain`)."""
    u = (np.asarray(e_m, float) - ground.e0_m) / ground.dsm_cell_m
    v = (np.asarray(n_m, float) - ground.n0_m) / ground.dsm_cell_m
    j = np.clip(np.floor(u).astype(int), 0, ground.dsm.shape[1] - 2)
    i = np.clip(np.floor(v).astype(int), 0, ground.dsm.shape[0] - 2)
    fu, fv = u - j, v - i
    a = ground.dsm
    return (1 - fv) * ((1 - fu) * a[i, j] + fu * a[i, j + 1]) + fv * (
        (1 - fu) * a[i + 1, j] + fu * a[i + 1, j + 1]
    )
