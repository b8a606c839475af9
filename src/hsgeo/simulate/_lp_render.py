"""Rendering of the LP campaign's ground (:mod:`hsgeo.simulate._lp_ground`): where rays meet the
DSM, and the blurred reflectance there (compiled kernels and their numpy faces).

The intersection (:func:`render_rays`) is our own compiled kernel rather than
:func:`hsgeo.geocode.intersect`: the latter's fixed-point iteration on the height diverges where
a building's wall is steeper than the ray's cotangent (slope × tan(view angle) > 1 near the
swath's edge), and evaluates scipy's interpolator on every ray each iteration. Ours brackets
the crossing between the DSM's local highest and lowest points (over blocks of
:data:`BLOCK_CELLS` cells, dilated by a block), marches down the ray from the top in steps of
at most half a DSM cell horizontally and 0.5 m vertically, and refines the first sign change by
the Illinois variant of regula falsi to 1e-7 m: robust on walls (the first crossing, so
buildings occlude), with the same bilinear DSM as :class:`hsgeo.geocode.DemTerrain` (checked
against :func:`hsgeo.geocode.intersect` in the tests where that converges).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

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


@njit(cache=True)
def _hit(ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid):  # pragma: no cover
    """Ray parameter ``s`` of the first crossing of ``O + s D`` with the bilinear DSM.

    The local height bounds ``hmax``/``hmin`` (per block of ``bcell`` m, dilated by one block)
    bracket the crossing; the ray is marched down from the upper bound in steps of at most
    half a DSM cell horizontally and 0.5 m vertically, and the first sign change is refined by
    the Illinois variant of regula falsi to 1e-7 m.
    """
    # the block under the ray where it passes the DSM's mean level (its horizontal travel over
    # the whole height range is far below a block: tan(view angle) · range ≲ 2 m)
    nb_r, nb_c = hmax.shape
    s_mid = (hmid - oz) / dz
    bj = int((ox + s_mid * dx - e0) / bcell)
    bi = int((oy + s_mid * dy - n0) / bcell)
    bj = min(max(bj, 0), nb_c - 1)
    bi = min(max(bi, 0), nb_r - 1)
    s_top = (hmax[bi, bj] + 0.01 - oz) / dz
    s_bot = (hmin[bi, bj] - 0.01 - oz) / dz
    horiz = np.sqrt(dx * dx + dy * dy) * (s_bot - s_top)
    vert = (s_bot - s_top) * (-dz)
    n_steps = int(max(horiz / (0.5 * dcell), vert / 0.5)) + 1
    ds = (s_bot - s_top) / n_steps
    a = s_top
    fa = oz + a * dz - _bilinear(dsm, (ox + a * dx - e0) / dcell, (oy + a * dy - n0) / dcell)
    b = s_bot
    fb = -1.0
    for _ in range(n_steps):
        s = a + ds
        f = oz + s * dz - _bilinear(dsm, (ox + s * dx - e0) / dcell, (oy + s * dy - n0) / dcell)
        if f <= 0.0:
            b = s
            fb = f
            break
        a = s
        fa = f
    return _refine(a, fa, b, fb, ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell)


@njit(cache=True)
def _refine(a, fa, b, fb, ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell):  # pragma: no cover
    """Illinois regula falsi on a bracket ``f(a) > 0 ≥ f(b)`` of ``f(s) = z(s) − DSM(s)``."""
    side = 0
    for _ in range(60):
        if fa - fb == 0.0 or (b - a) * (-dz) < 1e-7:
            break
        s = (a * fb - b * fa) / (fb - fa)
        f = oz + s * dz - _bilinear(dsm, (ox + s * dx - e0) / dcell, (oy + s * dy - n0) / dcell)
        if abs(f) < 1e-7:
            return s
        if f > 0.0:
            a = s
            fa = f
            if side == 1:
                fb *= 0.5
            side = 1
        else:
            b = s
            fb = f
            if side == -1:
                fa *= 0.5
            side = -1
    return 0.5 * (a + b)


@njit(cache=True)
def _hit_near(
    s0, ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid
):  # pragma: no cover
    """:func:`_hit` for a ray next to one that met the DSM at ``s0`` (another band's ray of the
    same pixel: ≤ 0.3 px apart): a bracket of ±0.25 m in height around ``s0`` first, the full
    search if it does not bracket a crossing. A crossing before the bracket would need the
    DSM to rise 0.25 m within the rays' ≤ 0.1 m horizontal offset and the ray to leave a
    building again above the ground, which 6 m wide buildings seen at ≤ 8.3° do not allow.
    """
    h = 0.25 / (-dz)
    a = s0 - h
    b = s0 + h
    fa = oz + a * dz - _bilinear(dsm, (ox + a * dx - e0) / dcell, (oy + a * dy - n0) / dcell)
    fb = oz + b * dz - _bilinear(dsm, (ox + b * dx - e0) / dcell, (oy + b * dy - n0) / dcell)
    if fa > 0.0 and fb <= 0.0:
        return _refine(a, fa, b, fb, ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell)
    return _hit(ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid)


@njit(cache=True, parallel=True)
def _render_kernel(
    O, D, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid, refl, gcell, out_en, out_v
):  # pragma: no cover
    for k in prange(O.shape[0]):
        s = _hit(
            O[k, 0],
            O[k, 1],
            O[k, 2],
            D[k, 0],
            D[k, 1],
            D[k, 2],
            dsm,
            e0,
            n0,
            dcell,
            hmax,
            hmin,
            bcell,
            hmid,
        )
        E = O[k, 0] + s * D[k, 0]
        N = O[k, 1] + s * D[k, 1]
        out_en[k, 0] = E
        out_en[k, 1] = N
        if refl.shape[0] > 0:
            out_v[k] = _bilinear(refl, (E - e0) / gcell, (N - n0) / gcell)


@njit(cache=True, parallel=True)
def _render_lines_kernel(
    R, O, d_plat, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid, refl, gcell, out
):  # pragma: no cover
    """``out[l, c, b]``: reflectance of band ``b`` where the ray ``O[l] + s R[l] d_plat[b, c]``
    of column ``c`` of line ``l`` meets the DSM (band 0 searched in full, the others next to
    it, :func:`_hit_near`).
    """
    nl = R.shape[0]
    nb = d_plat.shape[0]
    nc = d_plat.shape[1]
    for li in prange(nl):
        ox, oy, oz = O[li, 0], O[li, 1], O[li, 2]
        for c in range(nc):
            s = 0.0
            for b in range(nb):
                px, py, pz = d_plat[b, c, 0], d_plat[b, c, 1], d_plat[b, c, 2]
                dx = R[li, 0, 0] * px + R[li, 0, 1] * py + R[li, 0, 2] * pz
                dy = R[li, 1, 0] * px + R[li, 1, 1] * py + R[li, 1, 2] * pz
                dz = R[li, 2, 0] * px + R[li, 2, 1] * py + R[li, 2, 2] * pz
                if b == 0:
                    s = _hit(ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid)
                    s_b = s
                else:
                    s_b = _hit_near(
                        s, ox, oy, oz, dx, dy, dz, dsm, e0, n0, dcell, hmax, hmin, bcell, hmid
                    )
                E = ox + s_b * dx
                N = oy + s_b * dy
                out[li, c, b] = _bilinear(refl[b], (E - e0) / gcell, (N - n0) / gcell)


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
    _render_kernel(
        O,
        D,
        ground.dsm,
        ground.e0_m,
        ground.n0_m,
        ground.dsm_cell_m,
        *_bounds(ground),
        refl,
        ground.cell_m,
        en,
        val,
    )
    return en, (val if band is not None else None)


#: DSM cells per block of the local height bounds of :func:`_bounds`.
BLOCK_CELLS = 16


def _bounds(ground: Ground):
    """Local height bounds for the intersection: ``(hmax, hmin, block_m)``, the max and min of
    the DSM over blocks of :data:`BLOCK_CELLS` cells, each dilated by one block (cached).
    """
    cached = getattr(ground, "_bounds_cache", None)
    if cached is not None:
        return cached
    from scipy.ndimage import maximum_filter, minimum_filter

    B = BLOCK_CELLS
    z = ground.dsm
    nr, nc = -(-z.shape[0] // B) * B, -(-z.shape[1] // B) * B
    zp = np.pad(z, ((0, nr - z.shape[0]), (0, nc - z.shape[1])), mode="edge")
    blocks = zp.reshape(nr // B, B, nc // B, B)
    hmax = maximum_filter(blocks.max(axis=(1, 3)), size=3, mode="nearest")
    hmin = minimum_filter(blocks.min(axis=(1, 3)), size=3, mode="nearest")
    out = (
        np.ascontiguousarray(hmax),
        np.ascontiguousarray(hmin),
        B * ground.dsm_cell_m,
        float(0.5 * (z.max() + z.min())),
    )
    object.__setattr__(ground, "_bounds_cache", out)
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
    _render_lines_kernel(
        R,
        O,
        d,
        ground.dsm,
        ground.e0_m,
        ground.n0_m,
        ground.dsm_cell_m,
        *_bounds(ground),
        ground.reflectance,
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
