"""The local east-north-up frame of the simulations and its place on the Earth, by pyproj only.

The simulations and the sensor models work in a local east-north-up (ENU) frame in metres about
a site (the map frame of :mod:`hsgeo.sensors.mount`). :class:`LocalFrame` ties that frame to the
Earth: its origin is a point of a geodetic datum (latitude, longitude, ellipsoidal height; WGS 84
unless the frame names another, ``datum_epsg``), its axes are east, north and the ellipsoid
normal there (the topocentric frame of PROJ's ``+proj=topocentric``), and a map CRS (default the
UTM zone of the origin on its datum, :func:`default_output_crs`) is where the orthomosaic is
written. No site is a default: the origin is the caller's (a user's ``--site``, the centre of a
navigation) and the paper's site is passed as :data:`SITE_AAS`. Every transformation is a PROJ
pipeline built by :mod:`pyproj`; there is no hand-written projection maths here:

* ENU → geographic: ``+inv +proj=topocentric`` (ENU → geocentric), ``+inv +proj=cart``
  (geocentric → longitude, latitude, ellipsoidal height) on the datum's ellipsoid;
* geographic (``datum_epsg``) → the map CRS: :meth:`pyproj.Transformer.from_crs`.

The paper's site (002 §2: Ås, Norway, on ETRS89) is :data:`SITE_AAS`. Transformers are built once
per thread (PROJ objects are not shared between threads) and never pickled, so a :class:`LocalFrame`
travels to dask workers as five numbers.

The frame of a real flight is chosen from its data (:meth:`LocalFrame.about`: the centre of the
navigation, on the navigation's own datum, ``datum_epsg``); a GNSS/INS attitude, given against
the north-east-down at the aircraft, is carried into the frame by
:meth:`LocalFrame.R_enu_from_ned_at` (meridian convergence and the tilt of the ellipsoid normal).
The output CRS defaults to the UTM zone of the data's centre on that datum
(:func:`default_output_crs`); :func:`parse_crs` reads a user's ``--crs EPSG:n``.
"""

from __future__ import annotations

import functools
import re
import threading
from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "LocalFrame",
    "SITE_AAS",
    "ETRS89_GEOGRAPHIC_3D",
    "ETRS89_UTM32N",
    "WGS84_GEOGRAPHIC_3D",
    "lonlat_to_crs",
    "same_crs",
    "default_output_crs",
    "parse_crs",
    "geographic_3d_crs",
    "use_system_proj_grids",
    "SYSTEM_PROJ_DATA",
]

#: ETRS89 geographic 3D (longitude, latitude, ellipsoidal height).
ETRS89_GEOGRAPHIC_3D = 4937
#: ETRS89 / UTM zone 32N: the map CRS of the 002 orthomosaic.
ETRS89_UTM32N = 25832
#: WGS 84 geographic 3D: the datum of a frame that names none (a GNSS's own).
WGS84_GEOGRAPHIC_3D = 4979

_local = threading.local()


@dataclass(frozen=True)
class LocalFrame:
    """A local east-north-up frame (metres) about a geodetic point, and a map CRS.

    Parameters
    ----------
    lat_deg, lon_deg : float, degrees
        Latitude and longitude of the origin on the datum ``datum_epsg`` (no default: the
        origin is the data's or the user's; the 002 site is :data:`SITE_AAS`).
    h_m : float, m
        Ellipsoidal height of the origin: U = 0 there.
    map_epsg : int, optional
        EPSG code of the projected map CRS; default (None) the UTM zone of the origin on the
        datum (:func:`default_output_crs`).
    datum_epsg : int
        EPSG code of the geographic 3D CRS of the origin and of every geodetic coordinate in and
        out of the frame (default 4979, WGS 84; 4937 ETRS89 for the 002 site); its ellipsoid is
        the frame's (GRS80 for ETRS89 and NAD83, WGS 84's for EPSG:4979).

    Examples
    --------
    >>> f = LocalFrame(-33.9, 151.2)  # Sydney, on WGS 84
    >>> f.map_epsg  # WGS 84 / UTM zone 56S
    32756
    """

    lat_deg: float
    lon_deg: float
    h_m: float = 0.0
    map_epsg: int | None = None
    datum_epsg: int = WGS84_GEOGRAPHIC_3D

    def __post_init__(self):
        if not (np.isfinite(self.lat_deg) and -90 < self.lat_deg < 90):
            raise InputError(f"latitude {self.lat_deg!r}° of the local frame is not in (-90, 90)")
        if not (np.isfinite(self.lon_deg) and -180 <= self.lon_deg <= 180):
            raise InputError(f"longitude {self.lon_deg!r}° of the local frame is not in ±180")
        if not np.isfinite(self.h_m):
            raise InputError(f"height {self.h_m!r} m of the local frame is not finite")
        self._ellps()  # an unknown or non-geographic datum fails here
        if self.map_epsg is None:  # the UTM zone of the origin on its datum
            zone = default_output_crs(self.lon_deg, self.lat_deg, int(self.datum_epsg))
            object.__setattr__(self, "map_epsg", int(zone.to_epsg()))
        self.crs  # noqa: B018  (an unknown EPSG code fails here, once)

    @property
    def crs(self):
        """The map CRS, a :class:`pyproj.CRS`."""
        from pyproj import CRS
        from pyproj.exceptions import CRSError

        try:
            return CRS.from_epsg(int(self.map_epsg))
        except CRSError as exc:
            raise InputError(f"EPSG:{self.map_epsg} is not a CRS pyproj knows ({exc})") from exc

    def local_crs(self) -> str:
        """The local frame's horizontal plane as a CRS: PROJ's ellipsoidal orthographic projection
        about the origin (E, N of the foot of each point on the datum's ellipsoid; for points at
        ellipsoidal height h, distance d from the origin, within h·d/R of the topocentric E, N).
        """
        return (
            f"+proj=ortho +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} {self._ellps()} "
            "+units=m +no_defs +type=crs"
        )

    @property
    def datum_crs(self):
        """The geographic 3D CRS of the frame's geodetic coordinates, a :class:`pyproj.CRS`."""
        return geographic_3d_crs(f"EPSG:{int(self.datum_epsg)}")

    def _ellps(self) -> str:
        """The PROJ ellipsoid parameters of the datum (``+ellps=GRS80`` for ETRS89, as before)."""
        if int(self.datum_epsg) == ETRS89_GEOGRAPHIC_3D:
            return "+ellps=GRS80"
        d3 = self.datum_crs
        if d3.to_epsg() != int(self.datum_epsg):
            raise InputError(
                f"the frame's datum EPSG:{self.datum_epsg} is not a geographic 3D CRS: use its "
                f"3D form EPSG:{d3.to_epsg()} ({d3.name}, longitude, latitude, ellipsoidal height)"
            )
        e = d3.ellipsoid
        return f"+a={e.semi_major_metre!r} +rf={e.inverse_flattening!r}"

    def pipeline(self) -> str:
        """The PROJ pipeline ENU (m) → longitude, latitude (degrees), ellipsoidal height (m) on
        the frame's datum (``datum_epsg``).
        """
        ellps = self._ellps()
        return (
            "+proj=pipeline "
            f"+step +inv +proj=topocentric +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} "
            f"+h_0={self.h_m!r} {ellps} "
            f"+step +inv +proj=cart {ellps} "
            "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
        )

    def _transformers(self):
        """(ENU → geographic, geographic → map, ENU → map or None), built once per thread.

        ENU → map is one PROJ pipeline (the frame's steps followed by those of the geographic →
        map conversion, when PROJ states that as a pipeline): half the work of two transforms.
        """
        key = (self.lat_deg, self.lon_deg, self.h_m, self.map_epsg, self.datum_epsg)
        cache = getattr(_local, "cache", None)
        if cache is None:
            cache = _local.cache = {}
        if key not in cache:
            from pyproj import Transformer

            enu_geo = Transformer.from_pipeline(self.pipeline())
            geo_map = Transformer.from_crs(int(self.datum_epsg), self.crs, always_xy=True)
            steps = geo_map.definition.split()
            enu_map = None
            if steps and steps[0] == "proj=pipeline":
                tail = " ".join("+" + s for s in steps[1:])
                enu_map = Transformer.from_pipeline(f"{self.pipeline()} {tail}")
            cache[key] = (enu_geo, geo_map, enu_map)
        return cache[key]

    # ---- ENU <-> geographic ------------------------------------------------------------------
    def enu_to_lonlat(self, E_m, N_m, U_m):
        """Longitude, latitude (degrees) and ellipsoidal height (m) of ENU points, on the frame's
        datum (ETRS89 by default).
        """
        E, N, U = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (E_m, N_m, U_m)))
        lon, lat, h = self._transformers()[0].transform(E, N, U)
        return np.asarray(lon), np.asarray(lat), np.asarray(h)

    def lonlat_to_enu(self, lon_deg, lat_deg, h_m):
        """ENU (m) of longitudes, latitudes (degrees) and ellipsoidal heights (m) on the frame's
        datum (ETRS89 by default).
        """
        from pyproj.enums import TransformDirection

        lon, lat, h = np.broadcast_arrays(
            *(np.asarray(v, dtype=float) for v in (lon_deg, lat_deg, h_m))
        )
        E, N, U = self._transformers()[0].transform(
            lon, lat, h, direction=TransformDirection.INVERSE
        )
        return np.asarray(E), np.asarray(N), np.asarray(U)

    def lonlat_to_enu_precise(self, lon_deg, lat_deg, h_m):
        """ENU (m) of geodetic points, computed in extended precision (a navigation's records).

        The same conversion as :meth:`lonlat_to_enu` (geodetic → geocentric on the datum's
        ellipsoid, then the topocentric rotation about the origin, EPSG Guidance Note 7-2,
        methods 9602 and 9836), written out in ``numpy.longdouble`` (x87 80-bit on x86-64: 64-bit
        mantissa) because in float64 the geocentric coordinates of ≈ 6.4e6 m carry ≈ 1e-9 m of
        rounding into every E, N, U. Here the result is the float64 nearest to the exact one
        (measured against a 1e-12 m iterated inverse in ``tests/test_geodetic_002_flight.py``);
        on a platform whose ``longdouble`` is float64 it is as good as PROJ's.

        Parameters
        ----------
        lon_deg, lat_deg : array_like, degrees
            On the frame's datum.
        h_m : array_like, m
            Ellipsoidal height.

        Returns
        -------
        E_m, N_m, U_m : ndarray (float64)
        """
        ld = np.longdouble
        a_m, f = self._ellipsoid()
        lon, lat, h = np.broadcast_arrays(
            *(np.asarray(v, dtype=float).astype(ld) for v in (lon_deg, lat_deg, h_m))
        )
        X, Y, Z = _geocentric_ld(lon, lat, h, a_m, f)
        o = [
            np.asarray([v], dtype=float).astype(ld) for v in (self.lon_deg, self.lat_deg, self.h_m)
        ]
        X0, Y0, Z0 = _geocentric_ld(*o, a_m, f)
        dX, dY, dZ = X - X0, Y - Y0, Z - Z0
        lam0, phi0 = (v * (_PI_LD / 180) for v in o[:2])
        sl, cl, sp, cp = np.sin(lam0), np.cos(lam0), np.sin(phi0), np.cos(phi0)
        E = -sl * dX + cl * dY  # EPSG method 9836: the rows of R_ecef_from_enu(origin)ᵀ
        N = -sp * cl * dX - sp * sl * dY + cp * dZ
        U = cp * cl * dX + cp * sl * dY + sp * dZ
        return tuple(np.asarray(v, dtype=np.float64) for v in (E, N, U))

    def _ellipsoid(self) -> tuple[float, float]:
        """Semi-major axis (m) and flattening of the datum's ellipsoid (as :meth:`_ellps`)."""
        if int(self.datum_epsg) == ETRS89_GEOGRAPHIC_3D:
            return 6378137.0, 1 / np.longdouble("298.257222101")  # GRS80
        self._ellps()
        e = self.datum_crs.ellipsoid
        return e.semi_major_metre, 1 / np.longdouble(repr(e.inverse_flattening))

    # ---- ENU <-> map CRS ---------------------------------------------------------------------
    def enu_to_map(self, E_m, N_m, U_m):
        """Map coordinates (x east, y north in m; z the ellipsoidal height) of ENU points."""
        enu_map = self._transformers()[2]
        if enu_map is None:
            lon, lat, h = self.enu_to_lonlat(E_m, N_m, U_m)
            x, y, z = self._transformers()[1].transform(lon, lat, h)
        else:
            E, N, U = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (E_m, N_m, U_m)))
            x, y, z = enu_map.transform(E, N, U)
        return np.asarray(x), np.asarray(y), np.asarray(z)

    def map_to_enu(self, x_m, y_m, z_m):
        """ENU (m) of map coordinates (x, y in m; z the ellipsoidal height in m)."""
        from pyproj.enums import TransformDirection

        x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x_m, y_m, z_m)))
        inv = TransformDirection.INVERSE
        enu_map = self._transformers()[2]
        if enu_map is not None:
            E, N, U = enu_map.transform(x, y, z, direction=inv)
            return np.asarray(E), np.asarray(N), np.asarray(U)
        lon, lat, h = self._transformers()[1].transform(x, y, z, direction=inv)
        return self.lonlat_to_enu(lon, lat, h)

    # ---- a frame chosen from the data -------------------------------------------------------
    @classmethod
    def about(cls, lon_deg, lat_deg, datum_epsg: int, map_epsg: int | None = None) -> LocalFrame:
        """The frame about the centre of geodetic points (a navigation), on their datum.

        The origin is the geodetic point (height 0 on the ellipsoid) under the mean of the
        points' geocentric positions on the ellipsoid (PROJ ``+proj=cart``): the centre of the
        data, well defined across the antimeridian and near the poles.

        Parameters
        ----------
        lon_deg, lat_deg : (n,) array_like, degrees
            The points (e.g. every navigation record), on the datum ``datum_epsg``.
        datum_epsg : int
            EPSG code of their geographic (3D) CRS: 4979 WGS 84, 4937 ETRS89, 6319 NAD83(2011) …
        map_epsg : int, optional
            The output CRS; default :func:`default_output_crs` (the UTM zone of the centre on the
            same datum).

        Returns
        -------
        LocalFrame
        """
        from pyproj import Transformer

        datum = geographic_3d_crs(f"EPSG:{int(datum_epsg)}")
        epsg = datum.to_epsg()
        if epsg is None:
            raise InputError(f"{datum.name!r} has no EPSG code; name the datum by an EPSG code")
        probe = cls(0.0, 0.0, 0.0, ETRS89_UTM32N, epsg)._ellps()  # any map CRS: the ellipsoid
        cart = Transformer.from_pipeline(
            f"+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
            f"+step +proj=cart {probe}"
        )
        lon = np.asarray(lon_deg, float).ravel()
        lat = np.asarray(lat_deg, float).ravel()
        if lon.size == 0 or not (np.all(np.isfinite(lon)) and np.all(np.isfinite(lat))):
            raise InputError("the frame's centre needs finite longitudes and latitudes")
        X, Y, Z = cart.transform(lon, lat, np.zeros_like(lon))
        from pyproj.enums import TransformDirection

        lon0, lat0, _ = cart.transform(
            float(np.mean(X)),
            float(np.mean(Y)),
            float(np.mean(Z)),
            direction=TransformDirection.INVERSE,
        )
        lon0 = float((lon0 + 180.0) % 360.0 - 180.0)
        if map_epsg is None:
            map_epsg = default_output_crs(lon0, float(lat0), epsg).to_epsg()
        return cls(float(lat0), lon0, 0.0, int(map_epsg), epsg)

    def R_enu_from_ned_at(self, lon_deg, lat_deg) -> np.ndarray:
        """Rotation from the north-east-down at geodetic points to the frame's east-north-up.

        ``R = R_ecef_from_enu(origin)ᵀ @ R_ecef_from_enu(point) @ R_ENU_FROM_NED``, where the
        columns of ``R_ecef_from_enu`` are the east, north and up (ellipsoid normal) unit vectors
        at a geodetic longitude λ and latitude φ: ``(−sin λ, cos λ, 0)``,
        ``(−sin φ cos λ, −sin φ sin λ, cos φ)``, ``(cos φ cos λ, cos φ sin λ, sin φ)`` (the
        rotation of PROJ's ``+proj=topocentric``, EPSG Guidance Note 7-2, method 9837; checked
        against PROJ in ``tests/test_crs.py``). It holds the meridian convergence (≈ Δλ sin φ)
        and the tilt of the ellipsoid normal between the point and the origin.

        Parameters
        ----------
        lon_deg, lat_deg : (...) array_like, degrees
            Geodetic longitude and latitude on the frame's datum.

        Returns
        -------
        R_enu_from_ned : (..., 3, 3) ndarray
            Takes a vector in the point's north-east-down to the frame's east-north-up: a GNSS/INS
            attitude ``R_ned_from_body`` at the point becomes
            ``R_enu_from_body = R @ R_ned_from_body`` in the frame.
        """
        from hsgeo.rotations import R_ENU_FROM_NED

        R = _R_ecef_from_enu(np.asarray(lon_deg, float), np.asarray(lat_deg, float))
        R0 = _R_ecef_from_enu(np.asarray(self.lon_deg, float), np.asarray(self.lat_deg, float))
        return np.swapaxes(R0, -1, -2) @ R @ R_ENU_FROM_NED

    # ---- ENU <-> any CRS ---------------------------------------------------------------------
    def _to_crs(self, crs):
        """The transformer geographic 3D (frame's datum) → ``crs``, built once per thread."""
        from pyproj import CRS, Transformer

        target = parse_crs(crs) if isinstance(crs, str) else CRS.from_user_input(crs)
        key = (self.datum_epsg, target.to_wkt())
        cache = getattr(_local, "frame_to_crs", None)
        if cache is None:
            cache = _local.frame_to_crs = {}
        if key not in cache:
            cache[key] = Transformer.from_crs(self.datum_crs, target, always_xy=True)
        return cache[key]

    def enu_to_crs(self, crs, E_m, N_m, U_m):
        """Coordinates in any CRS pyproj reads of ENU points (PROJ, through the frame's datum).

        Parameters
        ----------
        crs : str, int or pyproj.CRS
            ``"EPSG:32633"``, a :class:`pyproj.CRS`, WKT … (see :func:`parse_crs`).
        E_m, N_m, U_m : array_like, m

        Returns
        -------
        x, y, z : ndarray
            In the CRS's axis order made x = east / longitude, y = north / latitude
            (``always_xy``); z the ellipsoidal height for a 2D CRS, else the CRS's third axis.
        """
        lon, lat, h = self.enu_to_lonlat(E_m, N_m, U_m)
        x, y, z = self._to_crs(crs).transform(lon, lat, h)
        return np.asarray(x), np.asarray(y), np.asarray(z)

    def crs_to_enu(self, crs, x, y, z):
        """ENU (m) of coordinates in any CRS (the inverse of :meth:`enu_to_crs`)."""
        from pyproj.enums import TransformDirection

        x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x, y, z)))
        lon, lat, h = self._to_crs(crs).transform(x, y, z, direction=TransformDirection.INVERSE)
        return self.lonlat_to_enu(lon, lat, h)

    def describe(self) -> str:
        """The frame in words: origin, datum and output CRS by name (for outputs and logs)."""
        return (
            f"local east-north-up frame about {self.lat_deg:.7f}°, {self.lon_deg:.7f}° "
            f"(h {self.h_m:g} m) on {self.datum_crs.name} (EPSG:{int(self.datum_epsg)}); "
            f"output CRS {self.crs.name} (EPSG:{int(self.map_epsg)})"
        )


def _R_ecef_from_enu(lon_deg, lat_deg) -> np.ndarray:
    """Columns east, north, up at geodetic (λ, φ) in geocentric axes (EPSG method 9837)."""
    lam, phi = np.deg2rad(lon_deg), np.deg2rad(lat_deg)
    sl, cl, sp, cp = np.sin(lam), np.cos(lam), np.sin(phi), np.cos(phi)
    z = np.zeros_like(sl)
    east = np.stack([-sl, cl, z], axis=-1)
    north = np.stack([-sp * cl, -sp * sl, cp], axis=-1)
    up = np.stack([cp * cl, cp * sl, sp], axis=-1)
    return np.stack([east, north, up], axis=-1)


#: π in extended precision.
_PI_LD = np.longdouble("3.14159265358979323846264338327950288")


def _geocentric_ld(lon_deg, lat_deg, h_m, a_m, f):
    """Geocentric X, Y, Z (m) of geodetic points in ``numpy.longdouble`` (EPSG method 9602)."""
    lam, phi = lon_deg * (_PI_LD / 180), lat_deg * (_PI_LD / 180)
    e2 = f * (2 - f)
    sp, cp = np.sin(phi), np.cos(phi)
    n_m = np.longdouble(a_m) / np.sqrt(1 - e2 * sp * sp)  # prime vertical radius of curvature
    return (
        (n_m + h_m) * cp * np.cos(lam),
        (n_m + h_m) * cp * np.sin(lam),
        (n_m * (1 - e2) + h_m) * sp,
    )


#: The 002 site, Ås (Norway): 59.665° N, 10.775° E (002 §2), map CRS ETRS89 / UTM 32N.
SITE_AAS = LocalFrame(59.665, 10.775, 0.0, ETRS89_UTM32N, ETRS89_GEOGRAPHIC_3D)


def lonlat_to_crs(crs: str, lon_deg, lat_deg, datum_epsg: int):
    """Coordinates in ``crs`` (any CRS pyproj reads) of longitudes and latitudes on a datum.

    ``datum_epsg`` is the geographic CRS of ``lon_deg``, ``lat_deg`` (2D or 3D EPSG code; a
    frame's ``datum_epsg``), never assumed: a WGS 84 or NAD83 navigation's points are
    transformed from their own datum, an ETRS89 one's (4258, 4937) from ETRS89.
    """
    datum_epsg = int(datum_epsg)
    key = (crs, datum_epsg)
    cache = getattr(_local, "to_crs", None)
    if cache is None:
        cache = _local.to_crs = {}
    if key not in cache:
        from pyproj import CRS, Transformer

        src = 4258 if datum_epsg in (4258, ETRS89_GEOGRAPHIC_3D) else CRS(datum_epsg).to_2d()
        cache[key] = Transformer.from_crs(src, crs, always_xy=True)
    x, y = cache[key].transform(np.asarray(lon_deg, float), np.asarray(lat_deg, float))
    return np.asarray(x), np.asarray(y)


def same_crs(a, b) -> bool:
    """Whether two CRS (anything :class:`pyproj.CRS` reads) are the same."""
    from pyproj import CRS

    return CRS.from_user_input(a) == CRS.from_user_input(b)


def parse_crs(text, what: str = "--crs"):
    """A CRS from a user's ``--crs`` (``EPSG:n``, ``n``, WKT, a PROJ string), or a clear error.

    Parameters
    ----------
    text : str or int or pyproj.CRS
    what : str
        Where the text comes from, for the message (the CLI option, a file's line).

    Returns
    -------
    pyproj.CRS

    Raises
    ------
    InputError
        If pyproj does not know it (the message names the text and the form expected).
    """
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    if isinstance(text, CRS):
        return text
    s = str(text).strip()
    if s.isdigit():
        s = f"EPSG:{s}"
    try:
        return CRS.from_user_input(s)
    except CRSError as exc:
        raise InputError(
            f"{what} {str(text)!r} is not a CRS pyproj knows ({exc}); give an EPSG code such as "
            "EPSG:32633 (WGS 84 / UTM 33N), EPSG:4979 (WGS 84 geographic 3D)"
        ) from exc


def geographic_3d_crs(crs):
    """The geographic 3D CRS (longitude, latitude, ellipsoidal height) of a geographic or
    geocentric CRS, as a :class:`pyproj.CRS` (a 2D geographic CRS is promoted to 3D).

    Raises
    ------
    InputError
        If ``crs`` is unknown, or projected, vertical or compound: a navigation's and a frame's
        datum is a geographic or geocentric CRS.
    """
    c = parse_crs(crs)
    if c.is_geocentric:  # EPSG names a geocentric CRS as its geographic 3D twin (4978: 4979)
        from pyproj.database import query_crs_info
        from pyproj.enums import PJType

        for info in query_crs_info(pj_types=PJType.GEOGRAPHIC_3D_CRS):
            if info.name == c.name and not info.deprecated:
                g = parse_crs(f"{info.auth_name}:{info.code}")
                if g.datum == c.datum:
                    return g
        raise InputError(
            f"the geocentric CRS {c.name!r} ({crs}) has no geographic 3D CRS of its datum that "
            f"PROJ knows; name the navigation's geographic 3D CRS instead (e.g. EPSG:4979)"
        )
    if not c.is_geographic:
        raise InputError(
            f"{c.name!r} ({crs}) is not a geographic or geocentric CRS: name the navigation's "
            "datum as a geographic 3D CRS, e.g. EPSG:4979 (WGS 84), EPSG:4937 (ETRS89), "
            "EPSG:6319 (NAD83(2011)), or a geocentric one (EPSG:4978)"
        )
    if len(c.axis_info) == 2:
        c = c.to_3d()
        epsg = c.to_epsg(min_confidence=70)
        if epsg is not None:
            c = parse_crs(f"EPSG:{epsg}")
    return c


@functools.lru_cache(maxsize=256)
def _utm_crs_infos(name: str, lon: float, lat: float) -> tuple:
    """PROJ's UTM CRSs of the datum ``name`` whose area of use holds the point, kept for the
    process: the database query takes 0.1 s, and a process that orthorectifies several times
    (a notebook, the test suite) asks for the same point again (issue 41).
    """
    from pyproj.aoi import AreaOfInterest
    from pyproj.database import query_utm_crs_info

    return tuple(
        query_utm_crs_info(datum_name=name, area_of_interest=AreaOfInterest(lon, lat, lon, lat))
    )


def default_output_crs(lon_deg: float, lat_deg: float, datum):
    """The UTM zone of a point on a datum: the default output CRS of the data centred there.

    pyproj's :func:`pyproj.database.query_utm_crs_info` lists the UTM CRSs of the datum whose
    area of use holds the point; of them, the zone whose central meridian is nearest (at a zone
    boundary such as 12° E, the eastern zone, as the UTM formula ``⌊(λ + 180°) / 6°⌋ + 1``).

    Parameters
    ----------
    lon_deg, lat_deg : float, degrees
        The centre of the data.
    datum : int or str or pyproj.CRS
        The navigation's datum: a geographic CRS (``4979``, ``"EPSG:4937"``) or the name that
        starts its UTM CRSs' names (``"WGS 84"``, ``"ETRS89"``, ``"NAD83"``).

    Returns
    -------
    pyproj.CRS
        E.g. EPSG:32756 (WGS 84 / UTM zone 56S) at Sydney on WGS 84.

    Raises
    ------
    InputError
        If the datum has no UTM zone there (e.g. ETRS89 outside Europe): pass ``--crs``.
    """
    from pyproj import CRS

    lon = float((float(lon_deg) + 180.0) % 360.0 - 180.0)
    lat = float(lat_deg)
    if (
        isinstance(datum, str)
        and not datum.strip().upper().startswith("EPSG")
        and (not datum.strip().isdigit())
    ):
        name = datum.strip()
    else:
        name = geographic_3d_crs(datum).to_2d().name
    infos = _utm_crs_infos(name, lon, lat)
    zones = {}
    for info in infos:  # easting-northing UTM only (not ETRS89's "UTM zone 32N (N-E)" variants)
        m = re.fullmatch(rf"{re.escape(name)} / UTM zone (\d+)([NS])", info.name)
        if m:
            zones[info] = int(m.group(1))
    if not zones:
        raise InputError(
            f"no UTM zone on the datum {name!r} covers {lat:.4f}°, {lon:.4f}°: pass the output CRS "
            "(--crs EPSG:n)"
        )

    def score(info):
        cm = -183.0 + 6.0 * zones[info]
        d = abs((lon - cm + 180.0) % 360.0 - 180.0)
        return (round(d, 9), -zones[info])

    best = min(zones, key=score)
    return CRS.from_authority(best.auth_name, best.code)


#: Where Debian's ``proj-data`` puts PROJ's grids (the EGM96 geoid ``egm96_15.gtx`` among them).
SYSTEM_PROJ_DATA = "/usr/share/proj"


def use_system_proj_grids() -> bool:
    """Let pyproj's PROJ find the system's grids (Debian ``proj-data``: geoids such as EGM96).

    pyproj's wheel carries its own PROJ data directory without grids; the system's directory is
    appended to PROJ's search path (:func:`pyproj.datadir.append_data_dir`), once. Nothing is
    downloaded.

    Returns
    -------
    bool
        Whether the system's directory exists (and is searched).
    """
    import os

    from pyproj import datadir

    if not os.path.isdir(SYSTEM_PROJ_DATA):
        return False
    if SYSTEM_PROJ_DATA not in datadir.get_data_dir().split(os.pathsep):
        datadir.append_data_dir(SYSTEM_PROJ_DATA)
    return True
