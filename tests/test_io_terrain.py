"""hsgeo.io.read_terrain: a DSM as delivered (any CRS, voids, a named vertical datum) into the
local frame, checked against an analytic terrain and PROJ."""

import numpy as np
import pytest

from hsgeo import InputError, ObservationError
from hsgeo.crs import LocalFrame, use_system_proj_grids

LAT0, LON0 = 47.0, 8.0
FRAME = LocalFrame(LAT0, LON0, 0.0, 32632, 4979)
BOUNDS = (-2500.0, -2500.0, 2500.0, 2500.0)
HAS_EGM96 = use_system_proj_grids() and __import__("os").path.exists("/usr/share/proj/egm96_15.gtx")


def h_ell(lon, lat):
    """The synthetic terrain: ellipsoidal height (WGS 84) of a geodetic point, smooth hills."""
    x = (np.asarray(lon) - LON0) * 76000.0
    y = (np.asarray(lat) - LAT0) * 111000.0
    return 420.0 + 35.0 * np.sin(x / 900.0) * np.cos(y / 1300.0) + 0.004 * x


def _write(path, crs, transform, shape, heights_of_lonlat, nodata=None, voids=()):
    import rasterio
    from pyproj import CRS, Transformer

    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    x, y = transform @ (cols + 0.5, rows + 0.5)
    pc = CRS.from_user_input(crs)
    to_geo = Transformer.from_crs(
        pc.sub_crs_list[0] if pc.is_compound else pc, 4326, always_xy=True
    )
    lon, lat = to_geo.transform(x, y)
    z = heights_of_lonlat(lon, lat).astype(np.float32)
    for r0, r1, c0, c1 in voids:
        z[r0:r1, c0:c1] = nodata
    with (
        rasterio.Env(GTIFF_REPORT_COMPD_CS=True),
        rasterio.open(
            path,
            "w",
            driver="GTiff",
            width=shape[1],
            height=shape[0],
            count=1,
            dtype="float32",
            crs=rasterio.crs.CRS.from_wkt(pc.to_wkt()),
            transform=transform,
            nodata=nodata,
        ) as dst,
    ):
        dst.write(z, 1)
    return path


def _geographic(path, heights=h_ell, crs="EPSG:4326", **kw):
    from rasterio.transform import from_origin

    d = 1e-4
    tr = from_origin(LON0 - 0.05, LAT0 + 0.035, d, d)
    return _write(path, crs, tr, (700, 1000), heights, **kw)


def _laea(path, **kw):
    from pyproj import Transformer
    from rasterio.transform import from_origin

    x0, y0 = Transformer.from_crs(4326, 3035, always_xy=True).transform(LON0, LAT0)
    tr = from_origin(round(x0) - 3500.0, round(y0) + 3500.0, 10.0, 10.0)
    return _write(path, "EPSG:3035", tr, (700, 700), h_ell, **kw)


def _egm96_heights(lon, lat):
    from pyproj import Transformer

    t = Transformer.from_crs(4979, "EPSG:4326+5773", always_xy=True, only_best=True)
    _, _, H = t.transform(lon, lat, h_ell(lon, lat))
    return np.asarray(H)


def _rays():
    rng = np.random.default_rng(7)
    n = 40
    O = np.column_stack(
        [rng.uniform(-1500, 1500, n), rng.uniform(-1500, 1500, n), np.full(n, 2400.0)]
    )
    d = np.column_stack([rng.uniform(-0.3, 0.3, n), rng.uniform(-0.3, 0.3, n), -np.ones(n)])
    return O, d


def _truth(O, d):
    """The first crossing of each ray with the analytic terrain, by bisection along the ray
    (geodetic coordinates of each ray point by the frame's PROJ pipeline)."""

    def f(s):
        X = O + s[:, None] * d
        lon, lat, h = FRAME.enu_to_lonlat(*X.T)
        return h - h_ell(lon, lat)

    lo, hi = np.zeros(len(O)), np.full(len(O), 2500.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        above = f(mid) > 0
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return O + (0.5 * (lo + hi))[:, None] * d


def _ground(terrain):
    from hsgeo.geocode import DemTerrain, intersect

    O, d = _rays()
    return intersect(O, d, DemTerrain(terrain.dem))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("dsm")
    out = {
        "4326": _geographic(tmp / "dsm_4326.tif"),
        "3035": _laea(tmp / "dsm_3035.tif"),
        "3035_voids": _laea(
            tmp / "dsm_3035_voids.tif", nodata=-9999.0, voids=[(0, 40, 0, 40), (650, 700, 600, 700)]
        ),
        "void_under": _laea(
            tmp / "dsm_void_under.tif", nodata=-9999.0, voids=[(330, 370, 330, 370)]
        ),
    }
    if HAS_EGM96:
        out["egm96"] = _geographic(
            tmp / "dsm_egm96.tif", heights=_egm96_heights, crs="EPSG:4326+5773"
        )
    return out


def test_the_same_terrain_in_any_crs_gives_the_same_ground_points(files):
    """EPSG:4326, EPSG:3035, EPSG:3035 with voids away from the rays, and EPSG:4326+5773 (EGM96
    heights through PROJ's geoid grid): the rays meet the terrain within 0.05 m of each other and
    of the analytic terrain."""
    from hsgeo.io.terrain import read_terrain

    O, d = _rays()
    truth = _truth(O, d)
    got = {}
    for key in ("4326", "3035", "3035_voids", "egm96"):
        if key not in files:
            continue
        vertical = None if key == "egm96" else "ellipsoidal"
        t = read_terrain(files[key], FRAME, BOUNDS, vertical=vertical)
        g = _ground(t)
        t.check_voids(g[:, 0], g[:, 1])
        got[key] = g
        err = np.linalg.norm(g - truth, axis=1)
        assert err.max() < 0.05, (key, err.max())
    assert len(got) == (4 if HAS_EGM96 else 3)
    for key, g in got.items():
        assert np.max(np.linalg.norm(g - got["4326"], axis=1)) < 0.05, key


@pytest.mark.skipif(not HAS_EGM96, reason="Debian's proj-data (EGM96 grid) is not installed")
def test_geoid_heights_are_not_ellipsoidal(files):
    """Read as ellipsoidal, the EGM96 heights are off by the geoid undulation (≈ 48 m here)."""
    import rasterio

    from hsgeo.io.terrain import read_terrain

    t = read_terrain(files["egm96"], FRAME, BOUNDS)
    assert "EGM96" in t.source
    with rasterio.open(files["egm96"]) as src:  # the same numbers, no vertical datum
        data, profile = src.read(1), src.profile
    profile["crs"] = rasterio.crs.CRS.from_epsg(4326)
    plain = files["egm96"].with_name("plain.tif")
    with rasterio.open(plain, "w", **profile) as dst:
        dst.write(data, 1)
    wrong = read_terrain(plain, FRAME, BOUNDS, vertical="ellipsoidal")
    assert 40 < float((t.dem - wrong.dem).mean()) < 55
    stated = read_terrain(plain, FRAME, BOUNDS, vertical="EPSG:5773")  # the datum stated
    assert float(np.abs(stated.dem - t.dem).max()) < 1e-6


def test_a_void_under_a_ray_is_refused_by_place(files):
    from hsgeo.io.terrain import read_terrain

    t = read_terrain(files["void_under"], FRAME, BOUNDS, vertical="ellipsoidal")
    assert t.void.any()
    O = np.array([[0.0, 0.0, 2400.0]])
    g = _ground_single(t, O)
    with pytest.raises(ObservationError, match=r"void \(nodata\).*E .* m, N .* m.*latitude.*Fill"):
        t.check_voids(g[:, 0], g[:, 1])


def _ground_single(t, O):
    from hsgeo.geocode import DemTerrain, intersect

    return intersect(O, np.array([[0.0, 0.0, -1.0]]), DemTerrain(t.dem))


def test_an_unknown_vertical_datum_is_refused_with_the_choice(files):
    from hsgeo.io.terrain import read_terrain

    with pytest.raises(InputError, match=r"no vertical datum.*--vertical ellipsoidal.*compound"):
        read_terrain(files["3035"], FRAME, BOUNDS)
    with pytest.raises(InputError, match="not a vertical CRS"):
        read_terrain(files["3035"], FRAME, BOUNDS, vertical="EPSG:4326")


def test_only_the_window_under_the_lines_is_read(files, monkeypatch):
    """The raster is read in one window about the bounds, not whole."""
    import rasterio

    from hsgeo.io.terrain import read_terrain

    seen = []
    orig = rasterio.io.DatasetReader.read

    def spy(self, *a, **kw):
        seen.append(kw.get("window"))
        return orig(self, *a, **kw)

    monkeypatch.setattr(rasterio.io.DatasetReader, "read", spy)
    read_terrain(files["3035"], FRAME, (-500.0, -500.0, 500.0, 500.0), vertical="ellipsoidal")
    (w,) = seen
    assert w is not None and w.width < 200 and w.height < 200


def test_a_vertical_datum_whose_geoid_grid_is_missing_is_refused(tmp_path):
    """Norway's DTM CRS, EPSG:25832+5941 (NN2000 heights): without PROJ's HREF2018B grid, PROJ
    would fall back to a 'ballpark' conversion that ignores the geoid (≈ 39.5 m at Ås); the
    reader refuses it, naming the grid."""
    import os

    from pyproj import Transformer
    from rasterio.transform import from_origin

    from hsgeo.io.terrain import read_terrain

    grid = "no_kv_HREF2018B_NN2000_EUREF89.tif"
    if os.path.exists(f"/usr/share/proj/{grid}"):
        pytest.skip("the NN2000 grid is installed")
    frame = LocalFrame(59.665, 10.775, 0.0, 25832, 4937)
    x0, y0 = Transformer.from_crs(4326, 25832, always_xy=True).transform(10.775, 59.665)
    tr = from_origin(round(x0) - 3000.0, round(y0) + 3000.0, 10.0, 10.0)
    p = _write(tmp_path / "nn2000.tif", "EPSG:25832+5941", tr, (600, 600), lambda lo, la: lo * 0)
    with pytest.raises(InputError, match=f"needs the grid {grid}, which is not installed"):
        read_terrain(p, frame, (-1000.0, -1000.0, 1000.0, 1000.0))
