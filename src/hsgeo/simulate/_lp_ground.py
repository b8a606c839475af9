"""The procedural ground of the LP campaign (:mod:`hsgeo.simulate.lp_campaign`): a multi-scale
textured reflectance raster per band, a DSM, and the ray–DSM intersection that renders it.

What the ground is made of (all drawn from one ``numpy.random.Generator``):

* **fields**: a jittered-grid Voronoi tessellation (cells of ``field_size_m``), each field one of
  grass, crop, bare soil or stubble with its own brightness and a row pattern (orientation,
  period, amplitude by material);
* **within-field texture**: multiplicative multi-octave value noise from 0.45 m to 29 m;
* **trees** (dark in the visible, bright in the near infrared), **roads** (asphalt) and
  **buildings** (rotated rectangles with a two-tone gabled roof, a few metres high on the DSM);
* the **white reference squares** on a grass patch, rasterised with their exact cell coverage
  (anti-aliased), so that the blurred square's centroid is its centre;
* a gently undulating **terrain** under it all (the DSM, with the buildings' height steps).

The reflectance of each material in each band is :data:`SPECTRA` (ours, typical shapes:
vegetation dark in the visible and bright above the red edge at ~750 nm, 002 §5.3), at the
campaign's seven wavelengths; other wavelengths interpolate it.

The point-spread function is a Gaussian blur of the raster (``psf_sigma_m``), applied once per
band; a ray samples the blurred raster bilinearly where it meets the DSM.

The intersection (:func:`render_rays`) is our own compiled kernel rather than
:func:`hsgeo.geocode.intersect`: the latter's fixed-point iteration on the height diverges where
a building's wall is steeper than the ray's cotangent (slope × tan(view angle) > 1 near the
swath's edge), and evaluates scipy's interpolator on every ray each iteration. Ours marches
down the ray from the DSM's highest point in steps of at most half a DSM cell horizontally and
``0.5 m`` vertically, then bisects the first crossing to 1e-6 m: robust on walls, with the same
bilinear DSM as :class:`hsgeo.geocode.DemTerrain` (checked against it in the tests).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

__all__ = [
    "Ground",
    "MATERIALS",
    "SPECTRA",
    "make_ground",
    "render_rays",
    "render_lines",
    "dsm_height",
]

#: Materials of the ground, by index of the material raster.
MATERIALS = ("grass", "crop", "soil", "stubble", "tree", "asphalt", "roof", "white")

_SPECTRA_NM = (450.0, 527.0, 604.0, 681.0, 758.0, 835.0, 912.0)
#: Reflectance (0…1) of each material at :data:`_SPECTRA_NM` (ours: typical shapes, vegetation
#: with the red edge between 681 and 758 nm, 002 §5.3; the white squares bright everywhere).
SPECTRA = np.array(
    [
        [0.040, 0.095, 0.055, 0.040, 0.42, 0.48, 0.49],  # grass
        [0.050, 0.120, 0.070, 0.050, 0.36, 0.45, 0.46],  # crop
        [0.090, 0.125, 0.165, 0.205, 0.240, 0.270, 0.290],  # bare soil
        [0.130, 0.175, 0.220, 0.255, 0.290, 0.320, 0.335],  # stubble
        [0.025, 0.055, 0.035, 0.025, 0.30, 0.36, 0.37],  # tree crowns
        [0.075, 0.085, 0.095, 0.105, 0.115, 0.125, 0.130],  # asphalt
        [0.160, 0.120, 0.130, 0.190, 0.230, 0.250, 0.260],  # roofs (reddish tiles)
        [0.860, 0.875, 0.880, 0.885, 0.885, 0.880, 0.870],  # white reference square
    ]
)
#: Strength of the within-field texture per material (relative brightness σ).
_TEXTURE = np.array([0.10, 0.14, 0.18, 0.16, 0.25, 0.06, 0.08, 0.0])
#: Amplitude of the row pattern per field material (grass, crop, soil, stubble).
_ROWS = np.array([0.04, 0.30, 0.12, 0.22])


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
    side = 0
    for _ in range(60):  # Illinois regula falsi on the bracket [a, b]
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
    """``out[l, c]``: reflectance where the ray of column ``c`` of line ``l`` meets the DSM,
    the ray being ``O[l] + s R[l] d_plat[c]``.
    """
    nl = R.shape[0]
    nc = d_plat.shape[0]
    for li in prange(nl):
        for c in range(nc):
            dx = (
                R[li, 0, 0] * d_plat[c, 0] + R[li, 0, 1] * d_plat[c, 1] + R[li, 0, 2] * d_plat[c, 2]
            )
            dy = (
                R[li, 1, 0] * d_plat[c, 0] + R[li, 1, 1] * d_plat[c, 1] + R[li, 1, 2] * d_plat[c, 2]
            )
            dz = (
                R[li, 2, 0] * d_plat[c, 0] + R[li, 2, 1] * d_plat[c, 1] + R[li, 2, 2] * d_plat[c, 2]
            )
            s = _hit(
                O[li, 0],
                O[li, 1],
                O[li, 2],
                dx,
                dy,
                dz,
                dsm,
                e0,
                n0,
                dcell,
                hmax,
                hmin,
                bcell,
                hmid,
            )
            E = O[li, 0] + s * dx
            N = O[li, 1] + s * dy
            out[li, c] = _bilinear(refl, (E - e0) / gcell, (N - n0) / gcell)


@njit(cache=True)
def _voronoi(nr, nc, cell, e0, n0, seeds, spacing):  # pragma: no cover - compiled
    """Index of the nearest jittered-grid seed (``seeds[a, b] = (E, N)``) of every cell."""
    out = np.empty((nr, nc), np.int32)
    sa, sb = seeds.shape[0], seeds.shape[1]
    for i in range(nr):
        y = n0 + i * cell
        a0 = int((y - n0) / spacing)
        for j in range(nc):
            x = e0 + j * cell
            b0 = int((x - e0) / spacing)
            best = 1e300
            arg = 0
            for a in range(max(a0 - 1, 0), min(a0 + 2, sa)):
                for b in range(max(b0 - 1, 0), min(b0 + 2, sb)):
                    d = (seeds[a, b, 0] - x) ** 2 + (seeds[a, b, 1] - y) ** 2
                    if d < best:
                        best = d
                        arg = a * sb + b
            out[i, j] = arg
    return out


@njit(cache=True, parallel=True)
def _upsample_add(out, coarse, step, weight):  # pragma: no cover - compiled
    """``out += weight · bilinear(coarse)`` with ``step`` coarse cells per fine cell."""
    nr, nc = out.shape
    for i in prange(nr):
        for j in range(nc):
            out[i, j] += weight * _bilinear(coarse, j * step, i * step)


# ------------------------------------------------------------------------------ the numpy faces
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


def render_lines(
    R_map_from_platform, origins_m, d_platform, ground: Ground, band: int
) -> np.ndarray:
    """Reflectance of ``band`` seen by each column of each line: ``(n_lines, n_cols)`` float32.

    The ray of column ``c`` of line ``l`` is ``origins_m[l] + s R[l] d_platform[c]`` (the
    factored form of :meth:`hsgeo.sensors.pushbroom.PushbroomCamera.rays_at`).
    """
    R = np.ascontiguousarray(R_map_from_platform, dtype=np.float64)
    O = np.ascontiguousarray(origins_m, dtype=np.float64)
    d = np.ascontiguousarray(d_platform, dtype=np.float64)
    out = np.empty((R.shape[0], d.shape[0]), np.float32)
    _render_lines_kernel(
        R,
        O,
        d,
        ground.dsm,
        ground.e0_m,
        ground.n0_m,
        ground.dsm_cell_m,
        *_bounds(ground),
        ground.reflectance[band],
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


def _spectra(wavelengths_nm) -> np.ndarray:
    """``(n_materials, n_bands)`` reflectance at the given wavelengths (linear in λ)."""
    w = np.asarray(wavelengths_nm, dtype=np.float64)
    return np.stack([np.interp(w, _SPECTRA_NM, s) for s in SPECTRA])


def _fields(cfg, shape, e0, n0, rng):
    """Field index, material and brightness of every cell, plus each field's row pattern."""
    nr, nc = shape
    sp = cfg.field_size_m
    na, nb = (
        int(np.ceil(nr * cfg.ground_cell_m / sp)) + 1,
        int(np.ceil(nc * cfg.ground_cell_m / sp)) + 1,
    )
    grid = np.stack(np.meshgrid(np.arange(na), np.arange(nb), indexing="ij"), axis=-1)[..., ::-1]
    seeds = (grid + 0.5 + rng.uniform(-0.4, 0.4, (na, nb, 2))) * sp + np.array([e0, n0])
    idx = _voronoi(nr, nc, cfg.ground_cell_m, e0, n0, seeds, sp)
    nf = na * nb
    mat = rng.choice(4, nf, p=(0.35, 0.25, 0.2, 0.2)).astype(np.uint8)
    bright = rng.uniform(0.8, 1.2, nf)
    theta = rng.uniform(0, np.pi, nf)
    period = rng.uniform(0.8, 3.0, nf)
    return idx, mat, bright, theta, period


def _texture(shape, cell, rng, scales_m=(0.45, 0.9, 1.8, 3.6, 7.2, 14.4, 28.8)):
    """Multi-octave value noise (σ ≈ 1) on the raster."""
    tex = np.zeros(shape, np.float32)
    weights = np.array(scales_m) ** 0.25
    weights /= np.sqrt(np.sum(weights**2) * 0.44)  # a bilinear octave keeps ≈ 0.44 of σ²
    for L, w in zip(scales_m, weights, strict=True):
        step = cell / L
        cr = int(shape[0] * step) + 3
        cc = int(shape[1] * step) + 3
        _upsample_add(tex, rng.standard_normal((cr, cc)), step, float(w))
    return tex


def _cells_within(E, N, fn, bbox, cell, e0, n0, shape):
    """Row/col slices of the raster for a box and the mask ``fn(E, N)`` inside it."""
    e_lo, e_hi, n_lo, n_hi = bbox
    j0, j1 = max(int((e_lo - e0) / cell), 0), min(int((e_hi - e0) / cell) + 2, shape[1])
    i0, i1 = max(int((n_lo - n0) / cell), 0), min(int((n_hi - n0) / cell) + 2, shape[0])
    if j1 <= j0 or i1 <= i0:
        return None
    return (slice(i0, i1), slice(j0, j1)), fn(E[j0:j1][None, :], N[i0:i1][:, None])


def _square_coverage(E, N, cell, centre, side):
    """Exact share of each cell covered by an axis-aligned square (anti-aliasing)."""

    def overlap(x, c):
        lo = np.maximum(x - cell / 2, c - side / 2)
        hi = np.minimum(x + cell / 2, c + side / 2)
        return np.clip(hi - lo, 0, None) / cell

    return overlap(N, centre[1])[:, None] * overlap(E, centre[0])[None, :]


def make_ground(cfg, half_m: float, squares_en_m, wavelengths_nm, rng) -> tuple[Ground, np.ndarray]:
    """Draw and rasterise the ground over ``[-half_m, half_m]²`` (plus ``cfg.ground_margin_m``).

    Parameters
    ----------
    cfg : LpConfig
        Ground settings (``ground_cell_m``, ``dsm_cell_m``, ``field_size_m``, densities, heights,
        ``psf_sigma_m``, ``square_side_m``).
    half_m : float
        Half the side of the rendered block, m.
    squares_en_m : (k, 2) ndarray
        Centres of the white squares (E, N), m.
    wavelengths_nm : (n_bands,) sequence
    rng : numpy.random.Generator

    Returns
    -------
    ground : Ground
    squares_h_m : (k,) ndarray
        DSM height at each square's centre (flat grass there).
    """
    from scipy.ndimage import gaussian_filter

    cell, dcell = cfg.ground_cell_m, cfg.dsm_cell_m
    ext = half_m + cfg.ground_margin_m
    e0 = n0 = -ext
    n = int(np.ceil(2 * ext / cell)) + 1
    shape = (n, n)
    E = e0 + cell * np.arange(n)
    N = n0 + cell * np.arange(n)
    area_km2 = (2 * ext) ** 2 / 1e6
    sq = np.asarray(squares_en_m, dtype=float).reshape(-1, 2)

    # fields: material, brightness and row pattern
    idx, fmat, fbright, ftheta, fper = _fields(cfg, shape, e0, n0, rng)
    material = fmat[idx]
    bright = fbright[idx].astype(np.float32)
    for i0 in range(0, n, 512):  # rows in blocks: the row pattern's temporaries stay small
        rs = slice(i0, min(i0 + 512, n))
        k = idx[rs]
        phase = (E[None, :] * np.cos(ftheta[k]) + N[rs, None] * np.sin(ftheta[k])) / fper[k]
        bright[rs] *= (1 + _ROWS[fmat[k]] * np.sin(2 * np.pi * phase)).astype(np.float32)
    del idx
    # trees: discs of crowns
    n_trees = rng.poisson(cfg.trees_per_km2 * area_km2)
    for (te, tn), r, b in zip(
        rng.uniform(-ext, ext, (n_trees, 2)),
        rng.uniform(1.5, 4.0, n_trees),
        rng.uniform(0.8, 1.2, n_trees),
        strict=True,
    ):
        hit = _cells_within(
            E,
            N,
            lambda e, nn, te=te, tn=tn, r=r: (e - te) ** 2 + (nn - tn) ** 2 < r * r,
            (te - r, te + r, tn - r, tn + r),
            cell,
            e0,
            n0,
            shape,
        )
        if hit is not None:
            sl, m = hit
            material[sl][m] = 4
            bright[sl][m] = b
    # roads: straight lines across the block
    n_roads = max(1, rng.poisson(cfg.roads_per_km * 2 * ext / 1e3))
    for _ in range(n_roads):
        p = rng.uniform(-ext / 2, ext / 2, 2)
        a = rng.uniform(0, np.pi)
        w = rng.uniform(4.0, 8.0)
        ca, sa = np.cos(a), np.sin(a)
        for i0 in range(0, n, 512):
            rs = slice(i0, min(i0 + 512, n))
            d = np.abs(-(E[None, :] - p[0]) * sa + (N[rs, None] - p[1]) * ca)
            m = d < w / 2
            material[rs][m] = 5
            bright[rs][m] = 1.0
    # buildings: rotated rectangles with a gabled roof (two tones), on the DSM
    nd = int(np.ceil(2 * ext / dcell)) + 1
    De = e0 + dcell * np.arange(nd)
    Dn = n0 + dcell * np.arange(nd)
    dsm = _terrain(cfg, De, Dn, rng)
    n_bld = rng.poisson(cfg.buildings_per_km2 * area_km2)
    for _ in range(n_bld):
        c = rng.uniform(-ext, ext, 2)
        if len(sq) and np.min(np.hypot(*(sq - c).T)) < 30:
            continue  # the squares lie on open grass
        L, W = rng.uniform(8, 25), rng.uniform(6, 14)
        a = rng.uniform(0, np.pi)
        h = rng.uniform(*cfg.building_height_m)
        tone = rng.uniform(0.7, 1.3)
        ca, sa = np.cos(a), np.sin(a)
        r = np.hypot(L, W) / 2

        def inside(e, nn, c=c, ca=ca, sa=sa, L=L, W=W):
            x = (e - c[0]) * ca + (nn - c[1]) * sa
            y = -(e - c[0]) * sa + (nn - c[1]) * ca
            return (np.abs(x) < L / 2) & (np.abs(y) < W / 2), y

        bbox = (c[0] - r, c[0] + r, c[1] - r, c[1] + r)
        hit = _cells_within(E, N, lambda e, nn: inside(e, nn)[0], bbox, cell, e0, n0, shape)
        if hit is not None:
            sl, m = hit
            y = inside(E[sl[1]][None, :], N[sl[0]][:, None])[1]
            material[sl][m] = 6
            bright[sl][m] = (tone * np.where(y > 0, 1.0, 0.6))[m]
        hit = _cells_within(De, Dn, lambda e, nn: inside(e, nn)[0], bbox, dcell, e0, n0, dsm.shape)
        if hit is not None:
            sl, m = hit
            dsm[sl][m] += h
    # the squares: a grass patch, then the white square with its exact coverage
    for c in sq:
        hit = _cells_within(
            E,
            N,
            lambda e, nn, c=c: (e - c[0]) ** 2 + (nn - c[1]) ** 2 < 36.0,
            (c[0] - 6, c[0] + 6, c[1] - 6, c[1] + 6),
            cell,
            e0,
            n0,
            shape,
        )
        if hit is not None:
            sl, m = hit
            material[sl][m] = 0
            bright[sl][m] = 1.0
    tex = _texture(shape, cell, rng)
    spectra = _spectra(wavelengths_nm)
    strength = _TEXTURE[material]
    refl = np.empty((len(spectra[0]),) + shape, np.float32)
    cov = np.zeros(shape, np.float32)
    for c in sq:
        s = cfg.square_side_m
        hit = _cells_within(
            E,
            N,
            lambda e, nn: np.ones(np.broadcast(e, nn).shape, bool),
            (c[0] - s, c[0] + s, c[1] - s, c[1] + s),
            cell,
            e0,
            n0,
            shape,
        )
        if hit is not None:
            sl, _ = hit
            cov[sl] = np.maximum(cov[sl], _square_coverage(E[sl[1]], N[sl[0]], cell, c, s))
    mod = np.clip(bright * (1 + strength * tex), 0.05, 3.0)
    del tex, strength, bright
    white = spectra[MATERIALS.index("white")]
    for b in range(refl.shape[0]):
        r_b = spectra[:, b].astype(np.float32)[material] * mod
        r_b = (1 - cov) * r_b + cov * np.float32(white[b])
        refl[b] = gaussian_filter(r_b, cfg.psf_sigma_m / cell, mode="nearest")
    ground = Ground(float(e0), float(n0), float(cell), refl, material, dsm, float(dcell))
    squares_h = dsm_height(ground, sq[:, 0], sq[:, 1]) if len(sq) else np.zeros(0)
    return ground, squares_h


def _terrain(cfg, De, Dn, rng) -> np.ndarray:
    """Gently undulating terrain heights (m) on the DSM grid: a few long cosine waves."""
    z = np.zeros((Dn.size, De.size))
    for _ in range(4):
        k = rng.uniform(1 / 600, 1 / 150) * 2 * np.pi
        a = rng.uniform(0, 2 * np.pi)
        ph = rng.uniform(0, 2 * np.pi)
        z += (cfg.terrain_relief_m / 4) * np.cos(
            k * (De[None, :] * np.cos(a) + Dn[:, None] * np.sin(a)) + ph
        )
    return z
