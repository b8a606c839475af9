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
    xs, ys = lonlat_to_crs("EPSG:25832", 10.775, 59.665, 4258)
    np.testing.assert_allclose([x0, y0], [xs, ys], atol=1e-6)


def test_local_crs_is_the_frame_plane_near_the_ground():
    """The local frame's CRS (ellipsoidal orthographic) gives E, N of ground points to < 1 mm."""
    E, N = np.meshgrid(np.linspace(-1500, 1500, 7), np.linspace(-1500, 1500, 7))
    lon, lat, _ = SITE_AAS.enu_to_lonlat(E, N, np.zeros_like(E))
    e, n = lonlat_to_crs(SITE_AAS.local_crs(), lon, lat, SITE_AAS.datum_epsg)
    np.testing.assert_allclose(e, E, atol=1e-3)
    np.testing.assert_allclose(n, N, atol=1e-3)


def test_bad_frames():
    with pytest.raises(InputError, match="latitude"):
        LocalFrame(95.0, 10.0)
    with pytest.raises(InputError, match="EPSG:1"):
        LocalFrame(59.0, 10.0, 0.0, 1)
    assert same_crs("EPSG:25832", SITE_AAS.crs)
    assert not same_crs("EPSG:32632", "EPSG:25832")


# ---- the frame chosen from the data, the output CRS of the data ------------------------------
SITES = {  # name: (lat, lon, datum, expected UTM EPSG) — pyproj's UTM areas of use
    "Sydney": (-33.9, 151.2, 4979, 32756),
    "Boulder": (40.0, -105.3, 4979, 32613),
    "Boulder NAD83(2011)": (40.0, -105.3, 6319, 6342),
    "Svalbard": (78.2, 15.6, 4979, 32633),
    "antimeridian": (-16.5, 179.95, 4979, 32760),
    "12 E, UTM 32/33": (48.0, 12.0, 4979, 32633),
    "Ås": (59.665, 10.775, 4937, 25832),
}


@pytest.mark.parametrize("site", list(SITES))
def test_default_output_crs_is_the_utm_zone_of_the_centre(site):
    from hsgeo.crs import default_output_crs

    lat, lon, datum, epsg = SITES[site]
    assert default_output_crs(lon, lat, datum).to_epsg() == epsg


@pytest.mark.parametrize("site", list(SITES))
def test_local_frame_to_output_crs_against_pyproj_alone(site):
    """A 30 km line about the site (across 12° E for the 32/33 case, across 180° for the
    antimeridian): the frame is its centre; ENU → output CRS equals the test's own ENU →
    geocentric (the topocentric rotation at the origin, EPSG method 9837) → pyproj's
    geocentric → UTM, to 1 mm."""
    from pyproj import CRS, Geod, Transformer

    from hsgeo.crs import LocalFrame, default_output_crs

    lat, lon, datum, epsg = SITES[site]
    ellps = CRS.from_epsg(datum).ellipsoid
    g = Geod(a=ellps.semi_major_metre, rf=ellps.inverse_flattening)
    s = np.linspace(-15000, 15000, 31)
    lons, lats, _ = g.fwd(np.full(31, lon), np.full(31, lat), np.full(31, 90.0), s)
    frame = LocalFrame.about(lons, lats, datum)
    assert frame.map_epsg == epsg
    assert abs(frame.lat_deg - lat) < 0.02 and abs((frame.lon_deg - lon + 180) % 360 - 180) < 1e-6
    out = default_output_crs(frame.lon_deg, frame.lat_deg, datum)
    rng = np.random.default_rng(3)
    enu = rng.uniform([-15000, -15000, -50], [15000, 15000, 3000], size=(40, 3))
    x, y, z = frame.enu_to_crs(out, *enu.T)
    # pyproj alone: the origin's geocentric position and axes, then geocentric -> UTM
    geocentric = CRS.from_epsg(datum).to_3d()
    to_xyz = Transformer.from_crs(
        geocentric,
        {"proj": "geocent", "a": ellps.semi_major_metre, "rf": ellps.inverse_flattening},
        always_xy=True,
    )
    X0 = np.array(to_xyz.transform(frame.lon_deg, frame.lat_deg, 0.0))
    lam, phi = np.radians(frame.lon_deg), np.radians(frame.lat_deg)
    R = np.array([
        [-np.sin(lam), -np.sin(phi) * np.cos(lam), np.cos(phi) * np.cos(lam)],
        [np.cos(lam), -np.sin(phi) * np.sin(lam), np.cos(phi) * np.sin(lam)],
        [0.0, np.cos(phi), np.sin(phi)],
    ])  # fmt: skip
    XYZ = X0 + enu @ R.T
    lo, la, h = to_xyz.transform(*XYZ.T, direction="INVERSE")
    xr, yr = Transformer.from_crs(geocentric, out, always_xy=True).transform(lo, la)[:2]
    np.testing.assert_allclose(x, xr, atol=1e-3, rtol=0)
    np.testing.assert_allclose(y, yr, atol=1e-3, rtol=0)
    np.testing.assert_allclose(z, h, atol=1e-3, rtol=0)
    back = np.column_stack(frame.crs_to_enu(out, x, y, z))
    np.testing.assert_allclose(back, enu, atol=1e-6)


def test_R_enu_from_ned_at_is_projs_topocentric_rotation():
    """The rotation from a point's NED to the frame's ENU equals PROJ's: 1 m steps north, east
    and down at a point 20 km away, mapped through the frame's pipeline."""
    from hsgeo.crs import LocalFrame

    frame = LocalFrame(60.0, 10.0, 0.0, 32632, 4979)
    lon, lat, h = 10.36, 60.05, 1500.0
    from pyproj import Transformer

    topo = Transformer.from_pipeline(
        f"+proj=pipeline +step +inv +proj=topocentric +lat_0={lat} +lon_0={lon} +h_0={h} "
        "+ellps=WGS84 +step +inv +proj=cart +ellps=WGS84 "
        "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
    )
    P0 = np.ravel(frame.lonlat_to_enu(lon, lat, h))
    cols = []
    for ned in ([100.0, 0, 0], [0, 100.0, 0], [0, 0, 100.0]):
        enu_local = (ned[1], ned[0], -ned[2])
        cols.append((np.ravel(frame.lonlat_to_enu(*topo.transform(*enu_local))) - P0) / 100.0)
    np.testing.assert_allclose(frame.R_enu_from_ned_at(lon, lat), np.column_stack(cols), atol=1e-8)


def test_parse_crs_and_its_errors():
    from hsgeo.crs import default_output_crs, geographic_3d_crs, parse_crs

    assert parse_crs("EPSG:32633").to_epsg() == 32633
    assert parse_crs("25832").to_epsg() == 25832
    with pytest.raises(InputError, match=r"--crs 'EPSG:999999' is not a CRS.*EPSG:32633"):
        parse_crs("EPSG:999999")
    with pytest.raises(InputError, match="not a geographic or geocentric CRS"):
        geographic_3d_crs("EPSG:32633")
    assert geographic_3d_crs(4326).to_epsg() == 4979
    assert geographic_3d_crs("EPSG:4978").to_epsg() == 4979
    with pytest.raises(InputError, match=r"no UTM zone on the datum 'ETRS89'.*--crs"):
        default_output_crs(151.2, -33.9, 4937)
    with pytest.raises(InputError, match="not a geographic"):
        LocalFrame(59.0, 10.0, 0.0, 25832, 25832)
    with pytest.raises(InputError, match=r"EPSG:4326 is not a geographic 3D CRS: use .*EPSG:4979"):
        LocalFrame(59.0, 10.0, 0.0, 32632, 4326)
    words = LocalFrame(59.0, 10.0, 0.0, 32632, 4979).describe()
    assert "on WGS 84 (EPSG:4979)" in words and "WGS 84 / UTM zone 32N (EPSG:32632)" in words


def test_lonlat_to_crs_starts_from_the_points_own_datum():
    """Points on a WGS 84 or NAD83 frame go to the output CRS from their own datum (the mosaic
    once took every frame's longitudes and latitudes as ETRS89); ETRS89 stays bit for bit."""
    from pyproj import Transformer

    from hsgeo.crs import lonlat_to_crs

    lon, lat = np.array([151.2, 151.21]), np.array([-33.9, -33.91])
    want = Transformer.from_crs(4326, 32756, always_xy=True).transform(lon, lat)
    np.testing.assert_array_equal(lonlat_to_crs("EPSG:32756", lon, lat, 4979), want)
    lon, lat = np.array([-105.3, -105.29]), np.array([40.0, 40.01])
    want = Transformer.from_crs(6318, 6342, always_xy=True).transform(lon, lat)
    np.testing.assert_array_equal(lonlat_to_crs("EPSG:6342", lon, lat, 6319), want)
    lon, lat = np.array([10.775]), np.array([59.665])
    np.testing.assert_array_equal(
        lonlat_to_crs("EPSG:25832", lon, lat, 4937), lonlat_to_crs("EPSG:25832", lon, lat, 4258)
    )
