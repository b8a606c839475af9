"""hsgeo.ortho: any sensor's strips -> map grid (pykdtree) -> mosaic -> COG (rasterio)."""

import numpy as np
import pytest
from ortho_inputs import FRAME, GSD_M, WAVELENGTH_NM, flight, squares_xy

from hsgeo.errors import InputError, ObservationError
from hsgeo.mapgrid import MapGrid, MapTerrain
from hsgeo.measure.squares import square_centroids
from hsgeo.ortho import Strip, orthomosaic


def test_map_grid_cells_and_transform():
    g = MapGrid.covering((600000.05, 600010.0), (6615000.0, 6615003.1), 0.3, "EPSG:25832")
    assert (g.x_min_m, g.y_max_m) == (pytest.approx(600000.0), pytest.approx(6615003.3))
    np.testing.assert_allclose(np.diff(g.x_m), 0.3)
    t = g.transform
    # the centre of cell (row 2, col 3) through the affine transform
    np.testing.assert_allclose(t @ (3.5, 2.5), (g.x_m[3], g.y_m[2]))
    w = g.window(2, 5, 3, 7)
    np.testing.assert_allclose(w.x_m, g.x_m[3:7])
    np.testing.assert_allclose(w.y_m, g.y_m[2:5])


def _cast_independently(o, d, z, grid):
    """Map x, y where rays (local frame) first meet the DSM ``z`` on ``grid``, by a caster that
    shares nothing with :func:`hsgeo.geocode.intersect` but the frame's pyproj transforms.

    Each ray's chord between local heights 2 m above and below the DSM's range is taken to the
    map CRS (its two ends; the image of a straight ray departs from that chord by L²/(8 R) ≈
    5 µm over its 20 m), sampled every 0.25 m of height against scipy's bilinear DSM, and the
    first sample under it is bisected with its predecessor to 10 µm. On this hill (slopes
    < 0.1) a ray < 1.5° off nadir cannot dip under the surface and out again within 0.25 m.
    """
    from scipy.interpolate import RegularGridInterpolator

    dsm_h = RegularGridInterpolator(
        (grid.y_m[::-1], grid.x_m), z[::-1], bounds_error=False, fill_value=np.nan
    )
    u_top, u_bot = z.max() - FRAME.h_m + 2.0, z.min() - FRAME.h_m - 2.0
    ends = [o + ((u - o[:, 2]) / d[:, 2])[:, None] * d for u in (u_top, u_bot)]
    A, B = (np.column_stack(FRAME.enu_to_map(*e.T)) for e in ends)

    def above(tau):  # is the chord's point at tau (0 top, 1 bottom) above the DSM?
        P = A + tau[:, None] * (B - A)
        return P[:, 2] > dsm_h(P[:, [1, 0]])

    n = int(np.ceil((u_top - u_bot) / 0.25))
    lo, hi = np.zeros(len(o)), np.full(len(o), np.nan)
    for k in range(1, n + 1):
        tau = np.full(len(o), k / n)
        todo = np.isnan(hi)
        hit = todo & ~above(tau)
        hi[hit] = tau[hit]
        lo[todo & ~hit] = tau[todo & ~hit]
    assert np.all(np.isfinite(hi)), "a ray did not meet the DSM"
    while np.max((hi - lo) * np.linalg.norm(B - A, axis=1)) > 1e-5:
        mid = 0.5 * (lo + hi)
        up = above(mid)
        lo, hi = np.where(up, mid, lo), np.where(up, hi, mid)
    P = A + hi[:, None] * (B - A)
    return P[:, 0], P[:, 1]


def _flight_rendered_independently(sensor):
    """:func:`ortho_inputs.flight`'s two strips, their lines rendered by
    :func:`_cast_independently` (not by the geolocation the mosaic then uses)."""
    from ortho_inputs import Flight, dsm, flight_trajectory, line_scanner, lp_camera, lp_pixels
    from ortho_inputs import scene as make_scene

    z, grid = dsm()
    nav, times = flight_trajectory()
    if sensor == "lp":
        sen, px, kw = lp_camera(), lp_pixels(), {"band": 0}
    else:
        sen, px, kw = line_scanner(300), np.arange(300, dtype=float), {}
    strips = []
    for i, t in enumerate(times):
        m, k = t.size, px.shape[0]
        pp = np.tile(px, (m,) + (1,) * (px.ndim - 1))
        o, d = sen.rays(pp, np.repeat(t, k), nav, **kw)
        x, y = _cast_independently(o, d, z, grid)
        vals = make_scene().radiance(x, y).astype(np.float32).reshape(m, k, -1)
        strips.append(Strip(sen, nav, t, px, vals, kw, f"s{i + 1}"))
    return Flight(tuple(strips), MapTerrain(z, grid, FRAME), (nav, nav))


@pytest.fixture(scope="module", params=["lp", "line"])
def mosaic(request):
    fl = _flight_rendered_independently(request.param)
    m = orthomosaic(
        fl.strips,
        fl.terrain,
        FRAME,
        resolution_m=0.3,
        band_names=list("RGBN"),
        wavelength_nm=WAVELENGTH_NM,
        tile_px=256,
    )
    return request.param, fl, m.persist()  # still Dask-backed, computed once


def test_squares_within_one_gsd_any_sensor(mosaic):
    """The 002 LP camera and the 000 line scanner through the same code: every reference
    square's centroid in the mosaic within 1 GSD (RMS) of its true position."""
    _, _, m = mosaic
    assert m.chunks[1][0] == 256 and m.rio.crs.to_epsg() == 25832
    xy, n = square_centroids(m.compute(), squares_xy())
    err = np.hypot(*(xy - squares_xy()).T)
    assert np.all(n >= 9)
    assert np.sqrt(np.mean(err**2)) < GSD_M
    assert err.max() < 1.5 * GSD_M


def test_cells_take_their_nearest_pixel_and_background(mosaic):
    """Every filled cell's value is the scene's value at a point within the radius of
    influence (background cells: a smooth field known in closed form)."""
    from ortho_inputs import scene

    _, _, m = mosaic
    v = m.isel(band=0).values
    X, Y = np.meshgrid(m["x"].values, m["y"].values)
    sc = scene()
    far = (
        np.min(
            np.hypot(X[..., None] - sc.centres_xy_m[:, 0], Y[..., None] - sc.centres_xy_m[:, 1]), -1
        )
        > 3
    )
    ok = np.isfinite(v) & far
    assert ok.mean() > 0.8
    truth = sc.radiance(X[ok], Y[ok])[:, 0]
    # the field's gradient is ≤ 100·0.2/7 per m: a nearest pixel within r differs by ≤ 2.9·r
    r = m.attrs["radius_of_influence_m"]
    assert np.max(np.abs(v[ok] - truth)) <= 2.9 * r + 1e-3


def test_nearest_to_nadir_rule():
    """Where two strips overlap, the cell takes the strip whose flight line is nearer (smaller
    off-nadir angle on a level flight): strip 1 all 1, strip 2 all 2."""
    fl = flight("lp")
    strips = [
        Strip(
            s.sensor,
            s.trajectory,
            s.t_s,
            s.pixels,
            np.full(s.values.shape[:2] + (1,), i + 1.0, np.float32),
            s.pixel_kw,
            s.name,
        )
        for i, s in enumerate(fl.strips)
    ]
    m = orthomosaic(strips, fl.terrain, FRAME, resolution_m=0.5).compute()
    v = m.values[0]
    X, Y = np.meshgrid(m["x"].values, m["y"].values)
    E, N, _ = FRAME.map_to_enu(X, Y, 100.0)
    e1 = fl.trajectories[0].pose(fl.strips[0].t_s[0])[0][0, 0]
    e2 = fl.trajectories[0].pose(fl.strips[1].t_s[0])[0][0, 0]  # the lines (true north, local)
    both = np.isfinite(v) & (np.abs(N) < 100)  # both strips' lines span N = ±120 m
    # the overlap is ±16 m about the middle; the ±0.05° roll moves a nadir by < 2 m
    d1, d2 = np.abs(E - e1), np.abs(E - e2)
    near1 = both & (d1 < d2 - 3) & (d1 > 14)
    near2 = both & (d2 < d1 - 3) & (d2 > 14)
    assert near1.sum() > 1000 and near2.sum() > 1000
    assert np.all(v[near1] == 1.0), np.unique(v[near1], return_counts=True)
    assert np.all(v[near2] == 2.0), np.unique(v[near2], return_counts=True)


def test_square_centroids_exact_on_area_weighted_mosaic():
    """Cells that average the scene over their area: the centroid is the square's centre."""
    import xarray as xr

    r = 0.3
    x = 600000 + (np.arange(200) + 0.5) * r
    y = 6615000 - (np.arange(150) + 0.5) * r
    centres = np.array([[600010.123, 6614990.456], [600040.77, 6614980.01]])
    img = np.full((150, 200), 50.0)
    for cx, cy in centres:
        ox = np.clip(np.minimum(x + r / 2, cx + 0.6) - np.maximum(x - r / 2, cx - 0.6), 0, None)
        oy = np.clip(np.minimum(y + r / 2, cy + 0.6) - np.maximum(y - r / 2, cy - 0.6), 0, None)
        img += 900.0 * np.outer(oy, ox) / r**2
    m = xr.DataArray(img[None], dims=("band", "y", "x"), coords={"x": x, "y": y})
    xy, n = square_centroids(m, centres + [[0.8, -0.5], [-1.0, 0.9]])
    np.testing.assert_allclose(xy, centres, atol=1e-9)
    assert np.all(n >= 16)
    xy, _ = square_centroids(m, [[600030.0, 6614970.0]], search_m=2.0)  # nothing there
    assert np.all(np.isnan(xy))


def test_cog_reads_back_in_rasterio(tmp_path, mosaic):
    import rasterio

    from hsgeo.io.geotiff import write_cog

    _, _, m = mosaic
    p = write_cog(m, tmp_path / "m.tif")
    with rasterio.open(p) as src:
        assert src.crs.to_epsg() == 25832
        t = src.transform
        assert (t.a, t.e, t.b, t.d) == (0.3, -0.3, 0.0, 0.0)
        np.testing.assert_allclose((t.c, t.f), (m["x"].values[0] - 0.15, m["y"].values[0] + 0.15))
        assert src.overviews(1), "a COG has overviews"
        assert src.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG"
        assert src.descriptions == ("R", "G", "B", "N")
        assert [float(src.tags(b)["wavelength_nm"]) for b in (1, 2, 3, 4)] == list(WAVELENGTH_NM)
        np.testing.assert_array_equal(src.read(), m.values)
    with pytest.raises(InputError, match="exists"):
        write_cog(m, p)
    write_cog(m.isel(band=[0]), p, overwrite=True)
    with rasterio.open(p) as src:
        assert src.count == 1


def test_dsm_must_cover_and_match_crs():
    from ortho_inputs import dsm

    fl = flight("lp")
    z, g = dsm(pad_m=60.0)
    small = MapTerrain(z, g, FRAME, source="DSM.tif")
    with pytest.raises(ObservationError, match="outside DSM.tif"):
        orthomosaic(fl.strips, small, FRAME, resolution_m=0.3)
    g2 = MapGrid(g.x_min_m, g.y_max_m, g.resolution_m, g.width, g.height, "EPSG:32632")
    with pytest.raises(InputError, match="EPSG:32632"):
        MapTerrain(z, g2, FRAME)


def test_corrected_trajectory():
    from hsgeo.trajectory import (
        SplineNodes,
        Trajectory,
        corrected_trajectory,
        platform_rpy_from_rph,
    )

    t = np.linspace(0, 30, 301)
    tr = Trajectory(
        t,
        np.column_stack([t, 2 * t, np.full_like(t, 500)]),
        np.column_stack([0.01 * np.sin(t), 0.02 * np.cos(t), np.full_like(t, 1.0)]),
    )
    nodes = SplineNodes(0.0, 30.0, 10.0)
    v = np.tile(
        [0.1, -0.2, 0.3, 1e-3, -2e-3, 3e-3], (nodes.n_nodes, 1)
    )  # constant: B-spline sums to 1
    c = corrected_trajectory(tr, nodes, v)
    np.testing.assert_allclose(c.xyz_m - tr.xyz_m, np.tile(v[0, :3], (t.size, 1)), atol=1e-12)
    d = platform_rpy_from_rph(c.roll_pitch_heading_rad) - platform_rpy_from_rph(
        tr.roll_pitch_heading_rad
    )
    np.testing.assert_allclose(d, np.tile(v[0, 3:], (t.size, 1)), atol=1e-12)
    np.testing.assert_allclose(corrected_trajectory(tr, nodes, 0 * v).xyz_m, tr.xyz_m)
    with pytest.raises(InputError, match="node corrections"):
        corrected_trajectory(tr, nodes, v[:, :3])


@pytest.mark.parametrize("angle_deg", [0.0, 15.0, 30.0, 45.0])
def test_intersect_on_a_map_dsm_is_the_first_crossing(angle_deg):
    """A DSM in the map CRS (the hill with a 12 m block on it, walls over one 2 m cell): rays
    0°–45° off nadir, some aimed behind the block, meet it where a 1 mm march down the ray in
    the local frame (the DSM read through :meth:`MapTerrain.height`, 1 cm steps, bisected to
    1 µm) first goes under it."""
    from ortho_inputs import dsm, origin_xy

    from hsgeo._raycast import first_crossing_reference
    from hsgeo.geocode import intersect

    z, g = dsm()
    x0, y0 = origin_xy()
    X, Y = np.meshgrid(g.x_m - x0, g.y_m - y0)
    z = np.where((np.abs(X - 10) < 15) & (np.abs(Y + 5) < 10), z + 12.0, z)
    terrain = MapTerrain(z, g, FRAME)
    rng = np.random.default_rng(int(angle_deg))
    n = 40
    az = rng.uniform(0, 2 * np.pi, n)
    t = np.tan(np.radians(angle_deg))
    d = np.column_stack([t * np.sin(az), t * np.cos(az), -np.ones(n)])
    target = np.column_stack([rng.uniform(-20, 40, n), rng.uniform(-30, 20, n), np.full(n, 102.0)])
    O = target - 300.0 * d
    got = intersect(O, d, terrain)
    ref = first_crossing_reference(
        O, d, lambda e, n: terrain.height(e, n, outside="nan"), terrain.u_range_m, 1e-2, 1e-6
    )
    np.testing.assert_allclose(got, O + ref[:, None] * d, atol=1e-3, rtol=0)
    on_block = np.abs(got[:, 2] - terrain.height(got[:, 0], got[:, 1])) < 1e-3
    assert on_block.all()
    if angle_deg >= 30:  # some rays stop on the block's roof or walls
        assert np.sum(got[:, 2] > 105.0 - FRAME.h_m) >= 3
