"""The verified polynomial in place of PROJ on every pixel (hsgeo._approx_transform, issue 41).

Against PROJ (the frame's exact transforms) on blocks of points like a block of lines' ground
points, at sites across the globe: within APPROX_TOL_M (1 mm) in a UTM zone, in the neighbouring
zone (across the 12° E boundary and the antimeridian) and in a geographic CRS (the difference
taken to metres); exact where the check fails (a longitude wrapping at ±180°, a box too large),
for few points and for NaN. Then the orthomosaic's block geometry and cells, approximate vs exact.
"""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo import _approx_transform as ax
from hsgeo.crs import LocalFrame

SITES = {  # name: (lat, lon, datum)
    "Sydney": (-33.9, 151.2, 4979),
    "Svalbard": (78.2, 15.6, 4979),
    "antimeridian": (-16.5, 179.95, 4979),
    "12 E, UTM 32/33": (48.0, 12.0, 4979),
    "Ås": (59.665, 10.775, 4937),
}
#: metres of one degree at most (a meridian degree at the poles, 111.7 km)
M_PER_DEG = 111_700.0


def _block(n=20_000, centre=(1200.0, -2500.0, 100.0), size=(300.0, 90.0, 40.0), seed=0):
    """A block of lines' ground points: ENU scattered in a box."""
    rng = np.random.default_rng(seed)
    c, s = np.asarray(centre), np.asarray(size)
    return rng.uniform(c - s / 2, c + s / 2, size=(n, 3)).T


def _next_zone(frame):
    base, zone = divmod(int(frame.map_epsg), 100)
    return f"EPSG:{base * 100 + zone % 60 + 1}"


CASES = [(s, k) for s in SITES for k in ("own zone", "next zone", "geographic")]


@pytest.mark.parametrize("site, kind", CASES, ids=[f"{s}-{k}" for s, k in CASES])
def test_enu_to_crs_within_the_bound(site, kind):
    lat, lon, datum = SITES[site]
    f = LocalFrame(lat, lon, 0.0, None, datum)
    crs = {"own zone": f"EPSG:{f.map_epsg}", "next zone": _next_zone(f), "geographic": "EPSG:4326"}
    crs = crs[kind]

    def exact(E, N, U):
        return f.enu_to_crs(crs, E, N, U)[:2]

    E, N, U = _block()
    (x, y), info = ax.approx_transform(exact, (E, N, U), ax.tolerance_in_units(crs))
    xe, ye = exact(E, N, U)
    assert info["approx"], info
    scale = M_PER_DEG if kind == "geographic" else 1.0
    err_m = max(np.abs(x - xe).max(), np.abs(y - ye).max()) * scale
    print(f"{site} {crs}: largest difference {err_m:.2e} m, check {info['max_check_error']}")
    assert err_m <= ax.APPROX_TOL_M


@pytest.mark.parametrize("site", list(SITES))
def test_frame_map_both_ways_within_the_bound(site):
    """The DSM intersection's transforms: ENU → map (x, y, h) and map → ENU."""
    f = LocalFrame(*SITES[site][:2], 0.0, None, SITES[site][2])
    E, N, U = _block(size=(280.0, 80.0, 6.0))
    got, info = ax.approx_transform(f.enu_to_map, (E, N, U), (ax.APPROX_TOL_M,) * 3)
    want = f.enu_to_map(E, N, U)
    assert info["approx"]
    assert max(np.abs(g - w).max() for g, w in zip(got, want, strict=True)) <= ax.APPROX_TOL_M
    back = ax.map_to_enu(f, *want)
    assert max(np.abs(b - v).max() for b, v in zip(back, (E, N, U), strict=True)) <= 1e-3
    again = ax.enu_to_map(f, E, N, U)
    assert max(np.abs(g - w).max() for g, w in zip(again, want, strict=True)) <= 1e-3


def test_a_flat_axis_is_fitted_as_constant():
    """The chord ends of the intersection lie on one height: U is the same everywhere."""
    f = LocalFrame(*SITES["Ås"][:2], 0.0, None, 4937)
    E, N, _ = _block()
    U = np.full(E.shape, 120.0)
    got, info = ax.approx_transform(f.enu_to_map, (E, N, U), (ax.APPROX_TOL_M,) * 3)
    assert info["approx"]
    want = f.enu_to_map(E, N, U)
    assert max(np.abs(g - w).max() for g, w in zip(got, want, strict=True)) <= ax.APPROX_TOL_M


def test_longitude_wrapping_at_the_antimeridian_falls_back_to_proj():
    """Geographic output across ±180°: the check fails, every point goes through PROJ."""
    f = LocalFrame(-16.5, 179.9995, 0.0, None, 4979)
    E, N, U = _block(centre=(0.0, 0.0, 50.0), size=(600.0, 200.0, 20.0))

    def exact(E, N, U):
        return f.enu_to_crs("EPSG:4326", E, N, U)[:2]

    (x, y), info = ax.approx_transform(exact, (E, N, U), ax.tolerance_in_units("EPSG:4326"))
    xe, ye = exact(E, N, U)
    assert xe.min() < -179.99 and xe.max() > 179.99  # the block does wrap
    assert not info["approx"] and info["max_check_error"][0] > 1.0
    np.testing.assert_array_equal(x, xe)
    np.testing.assert_array_equal(y, ye)
    # in the UTM zone (no wrap) the same block is approximated within the bound
    (x, y, _), info = ax.approx_transform(f.enu_to_map, (E, N, U), (ax.APPROX_TOL_M,) * 3)
    assert info["approx"]
    xe, ye, _ = f.enu_to_map(E, N, U)
    assert max(np.abs(x - xe).max(), np.abs(y - ye).max()) <= ax.APPROX_TOL_M


def test_too_large_a_box_few_points_and_nan_go_through_proj():
    f = LocalFrame(*SITES["Ås"][:2], 0.0, None, 4937)
    E, N, U = _block(size=(8e5, 8e5, 3000.0))  # 800 km: a cubic is not within 1 mm
    got, info = ax.approx_transform(f.enu_to_map, (E, N, U), (ax.APPROX_TOL_M,) * 3)
    assert not info["approx"] and max(info["max_check_error"]) > ax.CHECK_MARGIN * 1e-3
    for g, w in zip(got, f.enu_to_map(E, N, U), strict=True):
        np.testing.assert_array_equal(g, w)
    E, N, U = _block(n=ax.MIN_POINTS - 1)
    assert not ax.approx_transform(f.enu_to_map, (E, N, U), (1e-3,) * 3)[1]["approx"]
    E, N, U = _block()
    E[7] = np.nan
    got, info = ax.approx_transform(f.enu_to_map, (E, N, U), (1e-3,) * 3)
    assert not info["approx"] and info["max_check_error"] is None


def test_tolerance_in_units():
    assert ax.tolerance_in_units("EPSG:25832", 1e-3) == (1e-3, 1e-3)
    tx, ty = ax.tolerance_in_units("EPSG:4326", 1e-3)
    assert tx == ty and 1e-3 / M_PER_DEG > tx > 0.9e-3 / M_PER_DEG
    ftx, _ = ax.tolerance_in_units("EPSG:2227", 1e-3)  # California III, US survey feet
    assert ftx == pytest.approx(1e-3 / 0.3048006096)


def test_the_approximation_is_the_default():
    import inspect

    from hsgeo.ortho import orthomosaic

    assert inspect.signature(orthomosaic).parameters["crs_tol_m"].default == ax.APPROX_TOL_M


def test_block_geometry_and_mosaic_against_proj_on_every_pixel():
    """The orthomosaic's block ground (map x, y) within 1 mm of PROJ on every pixel, and its
    cells the same (every cell, here: the differences are nanometres)."""
    from ortho_inputs import FRAME, flight

    from hsgeo.ortho import block_ground, orthomosaic

    fl = flight()
    s = fl.strips[0].geometry()
    lines = (0, min(s.n_lines, 256))
    fast = block_ground(s, fl.terrain, FRAME, lines, "EPSG:25832", ax.APPROX_TOL_M)
    exact = block_ground(s, fl.terrain, FRAME, lines, "EPSG:25832", None)
    assert fast.shape[1] >= ax.MIN_POINTS
    d = np.abs(fast[:2] - exact[:2]).max()
    print(f"block ground: largest difference {d:.2e} m")
    assert 0 < d <= ax.APPROX_TOL_M
    np.testing.assert_array_equal(fast[2], exact[2])
    a = orthomosaic(fl.strips, fl.terrain, FRAME, resolution_m=0.3).values  # default: 1 mm
    b = orthomosaic(fl.strips, fl.terrain, FRAME, resolution_m=0.3, crs_tol_m=None).values
    np.testing.assert_array_equal(a, b)


def _flat_flight(height_m):
    """The test flight's strips over a flat DSM at ``height_m``: every ray ends at the DSM's
    lowest height, where the old floor of the compiled crossing lost rays by rounding (of
    ``oz + s dz`` near a height of a few decimetres: there its last bit is finer than the
    chord top's)."""
    from ortho_inputs import FRAME, dsm, flight

    from hsgeo.mapgrid import MapTerrain

    fl = flight()
    z, g = dsm()
    return fl, MapTerrain(np.full_like(z, height_m), g, FRAME)


@pytest.mark.parametrize("height_m", [-0.43510901927948, 0.3])
def test_flat_dsm_mosaic_approximate_equals_exact_under_threads(height_m):
    """``make check-wheel``'s failure in small: strips over a flat DSM (the wheel check's height;
    0.3 m), the approximate transform under dask's threads (4 workers), twice, and PROJ on every
    pixel: every ray a hit, the same cells bit for bit each time. Before the floor margin of
    hsgeo._raycast the first block refused 19,329 of 76,800 rays as outside the DSM with the
    approximation at -0.435 m, and all 76,800 at 0.3 m with PROJ on every pixel too."""
    import dask
    from ortho_inputs import FRAME

    from hsgeo.ortho import orthomosaic

    fl, flat = _flat_flight(height_m)
    kw = dict(resolution_m=0.3, lines_per_block=128)
    with dask.config.set(scheduler="threads", num_workers=4):
        runs = [
            orthomosaic(fl.strips, flat, FRAME, crs_tol_m=ax.APPROX_TOL_M, **kw).values
            for _ in range(2)
        ]
    exact = orthomosaic(fl.strips, flat, FRAME, crs_tol_m=None, **kw).values
    assert np.isfinite(exact).mean() > 0.5
    for a in runs:
        np.testing.assert_array_equal(a, exact)


def test_block_ground_concurrent_equals_serial():
    """The suspected race (PROJ transformers or compiled kernels shared between dask's threads):
    every block's ground computed on 8 threads at once, three times over, equals the serial
    computation bit for bit (hsgeo.crs keeps one transformer per thread; the kernels own no
    state)."""
    from concurrent.futures import ThreadPoolExecutor

    from ortho_inputs import FRAME

    from hsgeo.ortho import block_ground

    fl, flat = _flat_flight(-0.43510901927948)
    jobs = [
        (s.geometry(), terrain, (a, a + 64))
        for s in fl.strips
        for terrain in (fl.terrain, flat)
        for a in range(0, s.n_lines - 64, 64)
    ]

    def one(job):
        return block_ground(job[0], job[1], FRAME, job[2], "EPSG:25832", ax.APPROX_TOL_M)

    serial = [one(j) for j in jobs]
    with ThreadPoolExecutor(8) as pool:
        threaded = list(pool.map(one, jobs * 3))
    for k, got in enumerate(threaded):
        np.testing.assert_array_equal(got, serial[k % len(jobs)])
