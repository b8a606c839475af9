"""``hsgeo orthorectify``'s local frame: a geodetic navigation's (a CSV/Parquet or an SBET), or
the ``--site`` of a local-ENU one (required: no site is a default, :func:`site_frame`).

The local frame comes from the data (:meth:`hsgeo.crs.LocalFrame.about` the trajectory's centre,
:func:`hsgeo.io.read_navigation`); the output CRS defaults to :func:`hsgeo.crs.default_output_crs`
of that centre on the navigation's datum; a DSM GeoTIFF in any CRS is read into the frame by
:func:`hsgeo.io.read_terrain` under the lines' footprint, and the lines' ground points are checked
against its voids (:meth:`hsgeo.io.terrain.RasterTerrain.check_voids`).
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError, ObservationError

__all__ = [
    "FLOOR_U_M",
    "MARGIN_M",
    "read_nav",
    "site_frame",
    "output_crs",
    "terrain_bounds",
    "check_voids",
]

#: The plane (frame U, m) the lines' edge rays are followed down to for the DSM's bounds: below
#: the ellipsoidal height of any land near the frame's origin (the Dead Sea shore: about −400 m).
FLOOR_U_M = -500.0
#: Added on every side of the bounds, m (the ellipsoid falls 18 m below the frame's plane 15 km
#: from the origin).
MARGIN_M = 100.0


def read_nav(trajectory, nav_crs, gps_week, site, vertical, crs=None):
    """The navigation (:class:`hsgeo.io.Navigation`), the options checked against its kind; a
    geodetic one's frame maps to the projected ``--crs`` when given (else its centre's UTM zone).
    """
    from hsgeo.crs import parse_crs
    from hsgeo.io import read_navigation

    map_crs = None
    if crs is not None:
        c = parse_crs(crs)
        map_crs = c.to_epsg() if c.is_projected else None
    nav = read_navigation(trajectory, crs=nav_crs, gps_week=gps_week, map_crs=map_crs)
    local = nav.source_crs == "local ENU"
    if local:
        for opt, v in (("--gps-week", gps_week), ("--vertical", vertical)):
            if v is not None:
                raise InputError(
                    f"{opt} {v}: navigation file {str(trajectory)!r} is in a local east-north-up "
                    f"frame (t_s, E_m, N_m, U_m), where {opt} has no meaning; leave it out (the "
                    "frame is --site's) or give a geodetic navigation (lat_deg, lon_deg, h_m or "
                    "an SBET)"
                )
        if site is None:
            raise InputError(
                f"--site LAT,LON[,H] is needed: navigation file {str(trajectory)!r} is in a local "
                "east-north-up frame (t_s, E_m, N_m, U_m) whose origin is not in the file; give "
                "the origin's latitude, longitude (degrees) and ellipsoidal height (m), e.g. "
                "--site=-33.9,151.2,40 (on WGS 84; --nav-crs EPSG:n for another datum), or a "
                "geodetic navigation (lat_deg, lon_deg, h_m or an SBET)"
            )
    elif site is not None:
        raise InputError(
            f"--site: navigation file {str(trajectory)!r} is geodetic ({nav.source_crs}); its "
            "local frame comes from the data, leave --site out"
        )
    return nav


def site_frame(site, nav_crs, crs):
    """The local frame of a local-ENU navigation: its origin ``--site LAT,LON[,H]`` on the datum
    ``--nav-crs`` (default WGS 84, EPSG:4979); its map CRS the projected ``--crs`` when it has an
    EPSG code, else the UTM zone of the site on that datum (:func:`hsgeo.crs.default_output_crs`,
    as a geodetic navigation's centre).
    """
    from hsgeo.crs import WGS84_GEOGRAPHIC_3D, LocalFrame, geographic_3d_crs, parse_crs

    site = tuple(float(v) for v in site)
    if len(site) not in (2, 3):
        raise InputError(f"--site needs LAT,LON or LAT,LON,H (degrees, metres), got {site}")
    datum = WGS84_GEOGRAPHIC_3D
    if nav_crs is not None:
        d3 = geographic_3d_crs(nav_crs)
        if d3.to_epsg() is None:
            raise InputError(
                f"--nav-crs {nav_crs}: {d3.name!r} has no EPSG code; name the datum of --site by "
                "one, e.g. EPSG:4979 (WGS 84), EPSG:4937 (ETRS89)"
            )
        datum = int(d3.to_epsg())
    map_epsg = None
    if crs is not None:
        c = parse_crs(crs)
        if c.is_projected and c.to_epsg() is not None:
            map_epsg = int(c.to_epsg())
    try:
        return LocalFrame(*site, map_epsg=map_epsg, datum_epsg=datum)
    except InputError as exc:
        raise InputError(f"--site {','.join(f'{v:g}' for v in site)}: {exc}") from None


def output_crs(frame) -> str:
    """``EPSG:n`` of the UTM zone of the frame's origin on its datum."""
    from hsgeo.crs import default_output_crs

    c = default_output_crs(frame.lon_deg, frame.lat_deg, int(frame.datum_epsg))
    return f"EPSG:{c.to_epsg()}"


def _edge_points(strips, terrain, frame, lattice: bool):
    """Ground points of every line's first and last pixel and of every pixel of the first and
    last line (with ``lattice``: of about 64 lines spread over each strip).
    """
    from hsgeo.ortho import geolocate_lines

    pts = []
    for s in strips:
        n = s.n_lines
        rows = np.linspace(0, n - 1, min(n, 64)).astype(int) if lattice else [0, n - 1]
        rows = np.unique(rows)
        pts.append(geolocate_lines(s, terrain, frame, rows)[0].reshape(-1, 3))
        pts.append(geolocate_lines(s, terrain, frame, slice(None), [0, -1])[0].reshape(-1, 3))
    return np.concatenate(pts)


def terrain_bounds(strips, frame) -> tuple:
    """``(E_min, N_min, E_max, N_max)`` of the frame the rays can reach: the lines' edge rays
    followed down to the plane U = :data:`FLOOR_U_M`, plus :data:`MARGIN_M`.
    """
    from hsgeo.geocode import PlaneTerrain

    g = _edge_points(strips, PlaneTerrain(FLOOR_U_M), frame, lattice=False)
    E, N = g[:, 0], g[:, 1]
    return (
        float(E.min()) - MARGIN_M,
        float(N.min()) - MARGIN_M,
        float(E.max()) + MARGIN_M,
        float(N.max()) + MARGIN_M,
    )


def check_voids(strips, raster, terrain, frame) -> None:
    """The strips' perimeter and about 64 whole lines each met with the terrain must not land
    in a void of the DSM (filled by the nearest height there: a silently wrong ground).
    """
    g = _edge_points(strips, terrain, frame, lattice=True)
    try:
        raster.check_voids(g[:, 0], g[:, 1])
    except ObservationError as exc:
        raise InputError(f"--dsm: {exc}") from None
