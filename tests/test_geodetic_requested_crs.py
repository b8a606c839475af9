"""The six sites' targets in a CRS the user requests (``--crs``) instead of the data's UTM zone
(issue 38): the neighbouring UTM zone to the east on WGS 84 — across the antimeridian (zone 1S
for a line at 179.95° E), across the 32/33 boundary (zone 34N for its line, and 32N) — and Europe's
equal-area projection (EPSG:3035, LAEA) at Ås. Same flight, SBET and DSM as
tests/test_geodetic_geolocation.py; the truth by pyproj alone in the requested CRS; bar 0.25
GSD (1 m) RMS, as for the default CRS."""

from __future__ import annotations

import pytest
from test_geodetic_geolocation import GSD_M, SITES, _orthorectified, _rms_and_max

from hsgeo.crs import default_output_crs


def _next_zone(site):
    """The WGS 84 UTM zone east of the site's own (zone 60 → 1), same hemisphere."""
    lat0, lon0 = SITES[site]
    code = default_output_crs(lon0, lat0, 4979).to_epsg()
    base, zone = divmod(code, 100)
    return f"EPSG:{base * 100 + zone % 60 + 1}"


REQUESTED = [(s, _next_zone(s)) for s in SITES] + [
    ("UTM 32/33 at 12 E", "EPSG:32632"),
    ("Ås", "EPSG:3035"),
]


@pytest.mark.parametrize("site, crs", REQUESTED, ids=[f"{s}-{c}" for s, c in REQUESTED])
def test_targets_in_a_requested_crs_against_pyproj_alone(site, crs, tmp_path):
    xy, truth, _ = _orthorectified(site, tmp_path, crs=crs)
    rms, mx = _rms_and_max(xy, truth)
    print(f"{site} in {crs}: RMS {rms:.5f} m, max {mx:.5f} m")
    assert rms < 0.25 * GSD_M and mx < 0.1, (site, crs, rms, mx)


def test_the_antimeridian_zone_east_is_zone_1():
    assert _next_zone("antimeridian") == "EPSG:32701"
