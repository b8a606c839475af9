"""The procedural ground of the LP campaign (:mod:`hsgeo.simulate.lp_campaign`): a multi-scale
textured reflectance raster per band, a DSM, and the ray–DSM intersection that renders it.

What the ground is made of (all drawn from one ``numpy.random.Generator``):

* **fields**: a jittered-grid Voronoi tessellation (cells of ``field_size_m``), each field one of
  grass, crop, bare soil or stubble with its own brightness and a row pattern (orientation,
  period, amplitude by material);
* **within-field texture**: multiplicative multi-octave value noise from 0.45 m to 29 m;
* **trees** (dark in the visible, bright in the near infrared), **roads** (asphalt) and
  **buildings** (rotated rectangles with a two-tone gabled roof, a few metres high on the DSM);
* the **white reference squares** on a plain grass patch (:func:`patch_radii_m`), rasterised
  with their exact cell coverage (anti-aliased), so that the blurred square's
  centroid is its centre;
* optionally, small **point targets** (``targets_en_m``, :attr:`LpConfig.target_side_m`
  squares of about two pixels, exact cell coverage): white and painted over the texture, or
  (:attr:`LpConfig.target_reflectance`, :attr:`LpConfig.target_surround_m`) of their own
  reflectance centred on a uniform dark square, as survey targets are — features whose ground
  centre is known, for judging the matcher's observations against an independent reference
  (:mod:`hsgeo.reproduce.lp_targets`); none by default, and with none the ground is the same to
  the bit;
* a gently undulating **terrain** under it all (the DSM, with the buildings' height steps).

The reflectance of each material in each band is :data:`SPECTRA` (ours, typical shapes:
vegetation dark in the visible and bright above the red edge at ~750 nm, 002 §5.3), at the
campaign's seven wavelengths; other wavelengths interpolate it.

The point-spread function is a Gaussian blur of the raster (``psf_sigma_m``) and, for the
motion blur of a line's integration (``motion_blur_m``: the ground the platform passes while the
line integrates, 002 §4 names it among the unmodelled effects), a box along north — every strip
flies north or south, so one raster serves all; the exposure's time stamp is its middle, so
the box is centred and moves no centroid. Both are applied once per band; a ray samples the
blurred raster bilinearly where it meets the DSM.

The rendering (the ray–DSM intersection and the sampling) is :mod:`hsgeo.simulate._lp_render`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from hsgeo.simulate._lp_render import Ground, _bilinear, dsm_height

__all__ = ["Ground", "MATERIALS", "SPECTRA", "make_ground"]

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
SPECTRA.setflags(write=False)
#: Strength of the within-field texture per material (relative brightness σ).
_TEXTURE = np.array([0.10, 0.14, 0.18, 0.16, 0.25, 0.06, 0.08, 0.0])
_TEXTURE.setflags(write=False)
#: Amplitude of the row pattern per field material (grass, crop, soil, stubble).
_ROWS = np.array([0.04, 0.30, 0.12, 0.22])
_ROWS.setflags(write=False)


# ------------------------------------------------------------------------------ compiled cores
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


@dataclass
class _Raster:
    """The raster being drawn: cell centres, material and brightness (mutable while drawing)."""

    E: np.ndarray
    N: np.ndarray
    cell: float
    material: np.ndarray
    bright: np.ndarray

    @property
    def shape(self):
        return self.material.shape

    def cells(self, fn, bbox):
        """``(slices, mask)`` of the cells of ``bbox`` where ``fn(E, N)``, or None."""
        return _cells_within(self.E, self.N, fn, bbox, self.cell, self.E[0], self.N[0], self.shape)

    def paint(self, fn, bbox, material, bright):
        hit = self.cells(fn, bbox)
        if hit is not None:
            sl, m = hit
            self.material[sl][m] = material
            self.bright[sl][m] = bright if np.ndim(bright) == 0 else bright[m]


def _field_raster(cfg, ext, rng) -> _Raster:
    """Fields (material, brightness, row pattern) over ``[-ext, ext]²``."""
    cell = cfg.ground_cell_m
    n = int(np.ceil(2 * ext / cell)) + 1
    E = -ext + cell * np.arange(n)
    N = -ext + cell * np.arange(n)
    idx, fmat, fbright, ftheta, fper = _fields(cfg, (n, n), -ext, -ext, rng)
    material = fmat[idx]
    bright = fbright[idx].astype(np.float32)
    for i0 in range(0, n, 512):  # rows in blocks: the row pattern's temporaries stay small
        rs = slice(i0, min(i0 + 512, n))
        k = idx[rs]
        phase = (E[None, :] * np.cos(ftheta[k]) + N[rs, None] * np.sin(ftheta[k])) / fper[k]
        bright[rs] *= (1 + _ROWS[fmat[k]] * np.sin(2 * np.pi * phase)).astype(np.float32)
    return _Raster(E, N, cell, material, bright)


def _trees_and_roads(cfg, r: _Raster, ext, rng) -> None:
    """Tree crowns (discs) and straight roads, painted on the raster."""
    area_km2 = (2 * ext) ** 2 / 1e6
    n_trees = rng.poisson(cfg.trees_per_km2 * area_km2)
    for (te, tn), rad, b in zip(
        rng.uniform(-ext, ext, (n_trees, 2)),
        rng.uniform(1.5, 4.0, n_trees),
        rng.uniform(0.8, 1.2, n_trees),
        strict=True,
    ):
        r.paint(
            lambda e, nn, te=te, tn=tn, rad=rad: (e - te) ** 2 + (nn - tn) ** 2 < rad * rad,
            (te - rad, te + rad, tn - rad, tn + rad),
            MATERIALS.index("tree"),
            b,
        )
    n_roads = max(1, rng.poisson(cfg.roads_per_km * 2 * ext / 1e3))
    for _ in range(n_roads):
        p = rng.uniform(-ext / 2, ext / 2, 2)
        a = rng.uniform(0, np.pi)
        w = rng.uniform(4.0, 8.0)
        ca, sa = np.cos(a), np.sin(a)
        r.paint(
            lambda e, nn, p=p, ca=ca, sa=sa, w=w: (
                np.abs(-(e - p[0]) * sa + (nn - p[1]) * ca) < w / 2
            ),
            (-ext, ext, -ext, ext),
            MATERIALS.index("asphalt"),
            1.0,
        )


def _buildings(cfg, r: _Raster, dsm, ext, squares_en, rng) -> None:
    """Buildings: rotated rectangles with a two-tone gabled roof, raised on the DSM."""
    dcell = cfg.dsm_cell_m
    De = -ext + dcell * np.arange(dsm.shape[1])
    Dn = -ext + dcell * np.arange(dsm.shape[0])
    n_bld = rng.poisson(cfg.buildings_per_km2 * (2 * ext) ** 2 / 1e6)
    for _ in range(n_bld):
        c = rng.uniform(-ext, ext, 2)
        L, W = rng.uniform(8, 25), rng.uniform(6, 14)
        a = rng.uniform(0, np.pi)
        h = rng.uniform(*cfg.building_height_m)
        tone = rng.uniform(0.7, 1.3)
        if len(squares_en) and np.min(np.hypot(*(squares_en - c).T)) < 30:
            continue  # the squares lie on open grass
        ca, sa = np.cos(a), np.sin(a)
        half_diag = np.hypot(L, W) / 2
        bbox = (c[0] - half_diag, c[0] + half_diag, c[1] - half_diag, c[1] + half_diag)

        def local(e, nn, c=c, ca=ca, sa=sa):
            return (e - c[0]) * ca + (nn - c[1]) * sa, -(e - c[0]) * sa + (nn - c[1]) * ca

        def inside(e, nn, L=L, W=W, local=local):
            x, y = local(e, nn)
            return (np.abs(x) < L / 2) & (np.abs(y) < W / 2)

        hit = r.cells(inside, bbox)
        if hit is not None:
            sl, m = hit
            y = local(r.E[sl[1]][None, :], r.N[sl[0]][:, None])[1]
            r.material[sl][m] = MATERIALS.index("roof")
            r.bright[sl][m] = (tone * np.where(y > 0, 1.0, 0.6))[m]
        hit = _cells_within(De, Dn, inside, bbox, dcell, -ext, -ext, dsm.shape)
        if hit is not None:
            sl, m = hit
            dsm[sl][m] += h


def _box_weights(width_cells: float) -> np.ndarray:
    """Weights of a centred box ``width_cells`` wide on a grid of unit cells (each the overlap
    of its cell with the box), summing to one.
    """
    k = int(np.ceil(width_cells / 2 + 0.5))
    x = np.arange(-k, k + 1)
    w = np.clip(
        np.minimum(x + 0.5, width_cells / 2) - np.maximum(x - 0.5, -width_cells / 2), 0, None
    )
    return w / w.sum()


def _coverage(r: _Raster, centres_en, side_m: float) -> np.ndarray:
    """Share of each raster cell covered by any of the axis-aligned squares of side ``side_m``
    centred at ``centres_en`` (exact, :func:`_square_coverage`), ``(n, n)`` float32.
    """
    cov = np.zeros(r.shape, np.float32)
    s = side_m
    for c in centres_en:
        hit = r.cells(
            lambda e, nn: np.ones(np.broadcast(e, nn).shape, bool),
            (c[0] - s, c[0] + s, c[1] - s, c[1] + s),
        )
        if hit is not None:
            sl, _ = hit
            cov[sl] = np.maximum(cov[sl], _square_coverage(r.E[sl[1]], r.N[sl[0]], r.cell, c, s))
    return cov


def _reflectance(cfg, r: _Raster, squares_en, wavelengths_nm, rng, targets_en=()) -> np.ndarray:
    """Blurred reflectance per band, ``(n_bands, n, n)`` float32: material spectra × brightness
    × (1 + texture), the white squares (and point targets) mixed in by their exact coverage,
    then the PSF.
    """
    from scipy.ndimage import convolve1d, gaussian_filter

    box = _box_weights(cfg.motion_blur_m / r.cell) if cfg.motion_blur_m > 0 else None
    tex = _texture(r.shape, r.cell, rng)
    spectra = _spectra(wavelengths_nm)
    mod = np.clip(r.bright * (1 + _TEXTURE[r.material] * tex), 0.05, 3.0)
    del tex
    cov = _coverage(r, squares_en, cfg.square_side_m)
    # the point targets: over the texture as white squares (the squares' coverage), or, as
    # survey targets, a square of their own reflectance on a uniform dark surround
    surround = cfg.target_surround_m
    t_refl = cfg.target_reflectance
    own = len(targets_en) and (surround > 0 or t_refl is not None)
    if len(targets_en) and not own:
        cov = np.maximum(cov, _coverage(r, targets_en, cfg.target_side_m))
    cov_t = _coverage(r, targets_en, cfg.target_side_m) if own else None
    cov_s = _coverage(r, targets_en, surround) if own and surround > 0 else None
    white = spectra[MATERIALS.index("white")]
    refl = np.empty((spectra.shape[1],) + r.shape, np.float32)
    for b in range(refl.shape[0]):
        r_b = spectra[:, b].astype(np.float32)[r.material] * mod
        if cov_s is not None:
            r_b = (1 - cov_s) * r_b + cov_s * np.float32(cfg.target_surround_reflectance)
        if cov_t is not None:
            tb = white[b] if t_refl is None else t_refl
            r_b = (1 - cov_t) * r_b + cov_t * np.float32(tb)
        r_b = (1 - cov) * r_b + cov * np.float32(white[b])
        r_b = gaussian_filter(r_b, cfg.psf_sigma_m / r.cell, mode="nearest")
        if box is not None:
            r_b = convolve1d(r_b, box, axis=0, mode="nearest")
        refl[b] = r_b
    return refl


def make_ground(
    cfg, half_m: float, squares_en_m, wavelengths_nm, rng, targets_en_m=()
) -> tuple[Ground, np.ndarray]:
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
    targets_en_m : (t, 2) array_like
        Centres of the point targets (E, N), m (squares of ``cfg.target_side_m``); none by
        default (the ground is then the same to the bit, the generator's draws unchanged).

    Returns
    -------
    ground : Ground
    squares_h_m : (k,) ndarray
        DSM height at each square's centre (flat grass there).
    targets_xyz_m : (t', 3) ndarray
        The point targets painted (those on open ground, :func:`_open_ground`): centre E, N
        and the DSM height there.
    """
    ext = half_m + cfg.ground_margin_m
    sq = np.asarray(squares_en_m, dtype=float).reshape(-1, 2)
    r = _field_raster(cfg, ext, rng)
    _trees_and_roads(cfg, r, ext, rng)
    nd = int(np.ceil(2 * ext / cfg.dsm_cell_m)) + 1
    grid = -ext + cfg.dsm_cell_m * np.arange(nd)
    dsm = _terrain(cfg, grid, grid, rng)
    _buildings(cfg, r, dsm, ext, sq, rng)
    for c, rad in zip(sq, patch_radii_m(sq), strict=True):  # each square on a grass patch
        r.paint(
            lambda e, nn, c=c, rad=rad: (e - c[0]) ** 2 + (nn - c[1]) ** 2 < rad * rad,
            (c[0] - rad, c[0] + rad, c[1] - rad, c[1] + rad),
            MATERIALS.index("grass"),
            1.0,
        )
    tg = _open_ground(r, np.asarray(targets_en_m, dtype=float).reshape(-1, 2), sq)
    refl = _reflectance(cfg, r, sq, wavelengths_nm, rng, tg)
    ground = Ground(-ext, -ext, r.cell, refl, r.material, dsm, float(cfg.dsm_cell_m))
    squares_h = dsm_height(ground, sq[:, 0], sq[:, 1]) if len(sq) else np.zeros(0)
    targets = np.column_stack([tg, dsm_height(ground, tg[:, 0], tg[:, 1]) if len(tg) else []])
    return ground, squares_h, targets.reshape(-1, 3)


#: Radius of the plain grass patch under a reference square, m; the share of the distance to the
#: nearest other square it may take; the smallest radius, m (an 11 × 11 px window around a square
#: stays on plain grass at 2500 m AGL, 0.41 m px: corners 2.9 m from its centre).
_PATCH_M, _PATCH_SHARE, _PATCH_MIN_M = 6.0, 0.3, 3.5


def patch_radii_m(squares_en_m) -> np.ndarray:
    """Radius of each square's plain grass patch, m: :data:`_PATCH_M`, but at most
    :data:`_PATCH_SHARE` of the distance to the nearest other square (and at least
    :data:`_PATCH_MIN_M`).

    The squares' layout shrinks with the rendered block (:mod:`hsgeo.simulate.lp_campaign`), the
    patches must shrink with it: at the smallest scale the squares are 5–10 m apart and 6 m
    patches covered 97–98 % of the 30 m block with plain grass (no fields, rows or roads), so
    that the block had almost no texture for the key points but the squares themselves (seed
    13: 6 of 1330 scene pairs with ≥ 11 matches, no tie point); with the cap they cover
    58–61 % of it (seeds 0–7; seed 13: 21983 matches, 19698 kept). At scale ≥ ~0.2, squares
    ≥ 20 m apart, every patch is 6 m as before.
    """
    sq = np.asarray(squares_en_m, dtype=float).reshape(-1, 2)
    if len(sq) < 2:
        return np.full(len(sq), _PATCH_M)
    d = np.hypot(*(sq[:, None, :] - sq[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(d, np.inf)
    return np.minimum(_PATCH_M, np.maximum(_PATCH_MIN_M, _PATCH_SHARE * d.min(axis=1)))


#: A point target is painted only where no roof lies within this distance (m: the DSM's height
#: step would occlude it from some strips and make its height ill-defined) and no reference
#: square's centre within the second (m: ten pixels, clear of the square's blob).
_TARGET_CLEAR_M, _TARGET_FROM_SQUARE_M = 1.5, 3.0


def _open_ground(r: _Raster, targets_en, squares_en) -> np.ndarray:
    """The targets that lie on open ground: no roof within :data:`_TARGET_CLEAR_M`, no square
    within :data:`_TARGET_FROM_SQUARE_M`; ``(t', 2)``.
    """
    keep = []
    roof = MATERIALS.index("roof")
    d = _TARGET_CLEAR_M
    for c in targets_en:
        if len(squares_en) and np.min(np.hypot(*(squares_en - c).T)) < _TARGET_FROM_SQUARE_M:
            continue
        hit = r.cells(
            lambda e, nn, c=c: (e - c[0]) ** 2 + (nn - c[1]) ** 2 <= d * d,
            (c[0] - d, c[0] + d, c[1] - d, c[1] + d),
        )
        if hit is None:
            continue
        sl, m = hit
        if not np.any(r.material[sl][m] == roof):
            keep.append(c)
    return np.asarray(keep, dtype=float).reshape(-1, 2)


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
