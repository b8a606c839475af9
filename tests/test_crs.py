"""hsgeo.crs: the local ENU frame <-> ETRS89 <-> EPSG:25832 (pyproj pipelines)."""

import numpy as np
import pytest

from hsgeo.crs import SITE_AAS, LocalFrame, lonlat_to_crs, same_crs
from hsgeo.errors import InputError


def test_round_trip_enu_map_enu():
    rng = np.random.default_rng(1)
    enu = rng.uniform([-3000, -3000, -50], [3000, 3000, 2500], size=(200, 3))
    back = np.column_stack(SITE_AAS.map_to_enu(*SITE_AAS.enu_to_map(*enu.T)))
    np.testing.assert_allclose(back, enu, atol=1e-6)
    back = np.column_stack(SITE_AAS.lonlat_to_enu(*SITE_AAS.enu_to_lonlat(*enu.T)))
    np.testing.assert_allclose(back, enu, atol=1e-6)


def test_one_pipeline_equals_two_transforms():
    """ENU -> map in one PROJ pipeline equals ENU -> ETRS89 -> EPSG:25832 in two."""
    from pyproj import Transformer

    rng = np.random.default_rng(2)
    enu = rng.uniform([-2000, -2000, 0], [2000, 2000, 2000], size=(50, 3))
    lon, lat, h = SITE_AAS.enu_to_lonlat(*enu.T)
    x, y, z = Transformer.from_crs(4937, 25832, always_xy=True).transform(lon, lat, h)
    np.testing.assert_allclose(
        np.column_stack(SITE_AAS.enu_to_map(*enu.T)), np.column_stack([x, y, z]), atol=1e-6
    )


def test_epsg_guidance_note_topocentric_example():
    """EPSG Guidance Note 7-2, method 9837 (geographic/topocentric) example: origin 55° N, 5° E,
    h 200 m; the point X 3771793.968, Y 140253.342, Z 5124304.349 m (geocentric) has
    topocentric U -189013.869, V -128642.040, W -4220.171 m (GRS80 here, WGS84 there: the
    ellipsoids differ by 0.1 mm in the semi-minor axis)."""
    from pyproj import Transformer

    geo = Transformer.from_pipeline(
        "+proj=pipeline +step +inv +proj=cart +ellps=GRS80 "
        "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    lon, lat, h = geo.transform(3771793.968, 140253.342, 5124304.349)
    enu = LocalFrame(55.0, 5.0, 200.0).lonlat_to_enu(lon, lat, h)
    np.testing.assert_allclose(np.ravel(enu), [-189013.869, -128642.040, -4220.171], atol=2e-3)


def test_site_origin_axes_and_grid_convergence():
    """The origin is 59.665 N, 10.775 E; U is the ellipsoid normal; grid north is turned from
    true north by the meridian convergence γ ≈ Δλ sin φ (first order, Δλ from 9° E)."""
    lon, lat, h = SITE_AAS.enu_to_lonlat(0.0, 0.0, 100.0)
    np.testing.assert_allclose([lon, lat, h], [10.775, 59.665, 100.0], atol=1e-9)
    x0, y0, _ = SITE_AAS.enu_to_map(0.0, 0.0, 0.0)
    x1, y1, _ = SITE_AAS.enu_to_map(0.0, 1000.0, 0.0)
    gamma = np.degrees(np.arctan2(-(x1 - x0), y1 - y0))
    assert abs(gamma - 1.775 * np.sin(np.radians(59.665))) < 0.01
    # UTM scale at Δλ = 1.775°: k ≈ 0.9996 (1 + (Δλ cos φ)² / 2)
    k = np.hypot(x1 - x0, y1 - y0) / 1000.0
    dl = np.radians(1.775) * np.cos(np.radians(59.665))
    assert abs(k - 0.9996 * (1 + dl**2 / 2)) < 2e-6
    # the geographic <-> map transformation of the site agrees with pyproj's EPSG:4258
    xs, ys = lonlat_to_crs("EPSG:25832", 10.775, 59.665)
    np.testing.assert_allclose([x0, y0], [xs, ys], atol=1e-6)


def test_local_crs_is_the_frame_plane_near_the_ground():
    """The local frame's CRS (ellipsoidal orthographic) gives E, N of ground points to < 1 mm."""
    E, N = np.meshgrid(np.linspace(-1500, 1500, 7), np.linspace(-1500, 1500, 7))
    lon, lat, _ = SITE_AAS.enu_to_lonlat(E, N, np.zeros_like(E))
    e, n = lonlat_to_crs(SITE_AAS.local_crs(), lon, lat)
    np.testing.assert_allclose(e, E, atol=1e-3)
    np.testing.assert_allclose(n, N, atol=1e-3)


def test_bad_frames():
    with pytest.raises(InputError, match="latitude"):
        LocalFrame(95.0, 10.0)
    with pytest.raises(InputError, match="EPSG:1"):
        LocalFrame(59.0, 10.0, 0.0, 1)
    assert same_crs("EPSG:25832", SITE_AAS.crs)
    assert not same_crs("EPSG:32632", "EPSG:25832")
