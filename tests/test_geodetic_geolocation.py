"""End to end through the library, at six sites: an SBET (the test's own writer), a DSM GeoTIFF
in the site's UTM CRS with ellipsoidal heights, rays of known targets → hsgeo.io.read_navigation,
hsgeo.io.read_terrain, hsgeo.geocode.intersect, hsgeo.crs (frame → default output CRS), against
target positions computed with pyproj alone. Ignoring each record's NED rotation fails."""

import struct

import numpy as np
import pytest

from hsgeo.crs import default_output_crs
from hsgeo.geocode import DemTerrain, intersect
from hsgeo.io import read_navigation, read_terrain
from hsgeo.rotations import R_ENU_FROM_NED, R_from_rpy

SITES = {  # (lat, lon) of the line's centre; a 30 km east-west line, 2 km above the ground
    "Ås": (59.665, 10.775),
    "Sydney": (-33.9, 151.2),
    "Boulder": (40.0, -105.3),
    "Svalbard": (78.2, 15.6),
    "antimeridian": (-16.5, 179.95),
    "UTM 32/33 at 12 E": (48.0, 12.0),
}
GSD_M = 1.0  # the ground sample distance the 0.25 GSD criterion is of


def _terrain_h(lon, lat, lat0, lon0):
    x = ((np.asarray(lon) - lon0 + 180.0) % 360.0 - 180.0) * 111320.0 * np.cos(np.radians(lat0))
    y = (np.asarray(lat) - lat0) * 111320.0
    return 150.0 + 25.0 * np.sin(x / 2500.0) * np.cos(y / 1800.0)


def _flight(lat0, lon0):
    from pyproj import Geod

    g = Geod(ellps="WGS84")
    n = 301
    s = np.linspace(-15500.0, 15500.0, n)
    lon, lat, back = (np.asarray(v) for v in g.fwd([lon0] * n, [lat0] * n, [90.0] * n, s))
    az = (back + 180.0) % 360.0
    i = np.arange(n)
    rph = np.column_stack(
        [2.0 * np.sin(i / 17.0), 1.0 * np.cos(i / 23.0), az + 3.0 + 0.5 * np.sin(i / 11.0)]
    )
    h = 2150.0 + 3.0 * np.sin(i / 31.0)
    t = 200000.0 + s / 62.0
    return t, lat, lon, h, rph


def _sbet(path, t, lat, lon, h, rph):
    with open(path, "wb") as f:
        for k in range(t.size):
            wander = 0.7 - 0.001 * k
            r, p, hd = np.radians(rph[k])
            f.write(struct.pack("<17d", t[k], np.radians(lat[k]), np.radians(lon[k]), h[k],
                                0, 0, 0, r, p, hd + wander, wander, 0, 0, 0, 0, 0, 0))  # fmt: skip
    return path


def _dsm(path, lat0, lon0):
    """The analytic terrain as a GeoTIFF in the site's WGS 84 UTM zone, 25 m cells."""
    import rasterio
    from pyproj import Transformer
    from rasterio.transform import from_origin

    utm = default_output_crs(lon0, lat0, 4979)
    tr = Transformer.from_crs(4979, utm, always_xy=True)
    x0, y0 = tr.transform(lon0, lat0)
    cell = 25.0
    transform = from_origin(round(x0) - 17000.0, round(y0) + 4000.0, cell, cell)
    shape = (int(8000 / cell), int(34000 / cell))
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    x, y = transform @ (cols + 0.5, rows + 0.5)
    lon, lat = tr.transform(x, y, direction="INVERSE")
    z = _terrain_h(lon, lat, lat0, lon0).astype(np.float32)
    with rasterio.open(path, "w", driver="GTiff", width=shape[1], height=shape[0], count=1,
                       dtype="float32", crs=utm.to_wkt(), transform=transform) as dst:  # fmt: skip
        dst.write(z, 1)
    return path


def _targets(fl, lat0, lon0):
    """Targets on the terrain 0–1 km either side of the line, each seen from one record: their
    geodetic positions, the record, and the ray in the body frame (PROJ's topocentric frame at
    the aircraft, then the GNSS/INS attitude: what a calibrated sensor measures)."""
    from pyproj import Geod, Transformer

    t, lat, lon, h, rph = fl
    rng = np.random.default_rng(5)
    k = rng.integers(10, t.size - 10, 30)
    k[:2] = (10, t.size - 11)  # the two ends of the line, ≈ 15 km from the centre
    side = rng.uniform(-1000.0, 1000.0, k.size)
    g = Geod(ellps="WGS84")
    tlon, tlat, _ = (np.asarray(v) for v in g.fwd(lon[k], lat[k], rph[k, 2] - 3.0 + 90.0, side))
    th = _terrain_h(tlon, tlat, lat0, lon0)
    body = []
    for j, kk in enumerate(k):
        topo = Transformer.from_pipeline(
            "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
            "+step +proj=cart +ellps=WGS84 +step +proj=topocentric "
            f"+lat_0={float(lat[kk])!r} +lon_0={float(lon[kk])!r} +h_0={float(h[kk])!r} "
            "+ellps=WGS84"
        )
        v_enu = np.array(topo.transform(tlon[j], tlat[j], th[j]))
        R_ned_from_body = R_from_rpy(*np.radians(rph[kk]))
        body.append(R_ned_from_body.T @ (R_ENU_FROM_NED @ v_enu))
    return tlon, tlat, k, np.array(body)


@pytest.mark.parametrize("site", list(SITES))
def test_targets_in_the_output_crs_against_pyproj_alone(site, tmp_path):
    from pyproj import Transformer

    lat0, lon0 = SITES[site]
    fl = _flight(lat0, lon0)
    nav = read_navigation(_sbet(tmp_path / "sbet.out", *fl), crs="EPSG:4979")
    out = default_output_crs(nav.frame.lon_deg, nav.frame.lat_deg, 4979)
    assert nav.frame.map_epsg == out.to_epsg()
    E, N, _ = nav.trajectory.xyz_m.T
    bounds = (E.min() - 600, N.min() - 1600, E.max() + 600, N.max() + 1600)
    terrain = read_terrain(_dsm(tmp_path / "dsm.tif", lat0, lon0), nav.frame, bounds,
                           vertical="ellipsoidal")  # fmt: skip
    tlon, tlat, k, body = _targets(fl, lat0, lon0)
    tr = nav.trajectory
    O, _ = tr.pose(tr.t_s[k])
    truth = np.column_stack(Transformer.from_crs(4979, out, always_xy=True).transform(tlon, tlat))

    def located(R):
        d = np.einsum("nij,nj->ni", R, body)
        g = intersect(O, d, DemTerrain(terrain.dem))
        terrain.check_voids(g[:, 0], g[:, 1])
        x, y, _ = nav.frame.enu_to_crs(out, *g.T)
        return np.hypot(x - truth[:, 0], y - truth[:, 1])

    err = located(tr.R_map_from_body(tr.t_s[k]))
    rms = float(np.sqrt(np.mean(err**2)))
    assert rms < 0.25 * GSD_M and err.max() < 0.1, (site, rms, err.max())
    # the attitude taken as if against the frame's NED: metres off at the ends of the line
    rph = np.radians(fl[4][k])
    naive = located(R_ENU_FROM_NED @ R_from_rpy(rph[:, 0], rph[:, 1], rph[:, 2]))
    assert np.sqrt(np.mean(naive**2)) > 1.0 and naive[:2].max() > 2.0, (site, naive[:2])
