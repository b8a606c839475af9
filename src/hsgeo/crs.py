"""The local east-north-up frame of the simulations and its place on the Earth, by pyproj only.

The simulations and the sensor models work in a local east-north-up (ENU) frame in metres about
a site (the map frame of :mod:`hsgeo.sensors.mount`). :class:`LocalFrame` ties that frame to the
Earth: its origin is a point of ETRS89 (latitude, longitude, ellipsoidal height), its axes are
east, north and the ellipsoid normal there (the topocentric frame of PROJ's
``+proj=topocentric``), and a map CRS (default ETRS89 / UTM 32N, EPSG:25832) is where the
orthomosaic is written. Every transformation is a PROJ pipeline built by :mod:`pyproj`; there is
no hand-written projection maths here:

* ENU → ETRS89 geographic: ``+inv +proj=topocentric`` (ENU → geocentric), ``+inv +proj=cart``
  (geocentric → longitude, latitude, ellipsoidal height) on the GRS80 ellipsoid;
* ETRS89 geographic (EPSG:4937) → the map CRS: :meth:`pyproj.Transformer.from_crs`.

The paper's site (002 §2: Ås, Norway) is :data:`SITE_AAS`. Transformers are built once per
thread (PROJ objects are not shared between threads) and never pickled, so a :class:`LocalFrame`
travels to dask workers as four numbers.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError

__all__ = [
    "LocalFrame",
    "SITE_AAS",
    "ETRS89_GEOGRAPHIC_3D",
    "ETRS89_UTM32N",
    "lonlat_to_crs",
    "same_crs",
]

#: ETRS89 geographic 3D (longitude, latitude, ellipsoidal height).
ETRS89_GEOGRAPHIC_3D = 4937
#: ETRS89 / UTM zone 32N: the map CRS of the 002 orthomosaic.
ETRS89_UTM32N = 25832

_local = threading.local()


@dataclass(frozen=True)
class LocalFrame:
    """A local east-north-up frame (metres) about an ETRS89 point, and a map CRS.

    Parameters
    ----------
    lat_deg, lon_deg : float, degrees
        ETRS89 latitude and longitude of the origin.
    h_m : float, m
        Ellipsoidal (GRS80) height of the origin: U = 0 there.
    map_epsg : int
        EPSG code of the projected map CRS (default 25832, ETRS89 / UTM 32N).

    Examples
    --------
    >>> f = LocalFrame(59.665, 10.775)
    >>> x, y, z = f.enu_to_map(0.0, 0.0, 0.0)
    >>> round(float(x), 3), round(float(y), 3)  # doctest: +SKIP
    """

    lat_deg: float = 59.665
    lon_deg: float = 10.775
    h_m: float = 0.0
    map_epsg: int = ETRS89_UTM32N

    def __post_init__(self):
        if not (np.isfinite(self.lat_deg) and -90 < self.lat_deg < 90):
            raise InputError(f"latitude {self.lat_deg!r}° of the local frame is not in (-90, 90)")
        if not (np.isfinite(self.lon_deg) and -180 <= self.lon_deg <= 180):
            raise InputError(f"longitude {self.lon_deg!r}° of the local frame is not in ±180")
        if not np.isfinite(self.h_m):
            raise InputError(f"height {self.h_m!r} m of the local frame is not finite")
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
        about the origin (E, N of the foot of each point on the GRS80 ellipsoid; for points at
        ellipsoidal height h, distance d from the origin, within h·d/R of the topocentric E, N).
        """
        return (
            f"+proj=ortho +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} +ellps=GRS80 "
            "+units=m +no_defs +type=crs"
        )

    def pipeline(self) -> str:
        """The PROJ pipeline ENU (m) → ETRS89 longitude, latitude (degrees), height (m)."""
        return (
            "+proj=pipeline "
            f"+step +inv +proj=topocentric +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} "
            f"+h_0={self.h_m!r} +ellps=GRS80 "
            "+step +inv +proj=cart +ellps=GRS80 "
            "+step +proj=unitconvert +xy_in=rad +xy_out=deg"
        )

    def _transformers(self):
        """(ENU → geographic, geographic → map, ENU → map or None), built once per thread.

        ENU → map is one PROJ pipeline (the frame's steps followed by those of the geographic →
        map conversion, when PROJ states that as a pipeline): half the work of two transforms.
        """
        key = (self.lat_deg, self.lon_deg, self.h_m, self.map_epsg)
        cache = getattr(_local, "cache", None)
        if cache is None:
            cache = _local.cache = {}
        if key not in cache:
            from pyproj import Transformer

            enu_geo = Transformer.from_pipeline(self.pipeline())
            geo_map = Transformer.from_crs(ETRS89_GEOGRAPHIC_3D, self.crs, always_xy=True)
            steps = geo_map.definition.split()
            enu_map = None
            if steps and steps[0] == "proj=pipeline":
                tail = " ".join("+" + s for s in steps[1:])
                enu_map = Transformer.from_pipeline(f"{self.pipeline()} {tail}")
            cache[key] = (enu_geo, geo_map, enu_map)
        return cache[key]

    # ---- ENU <-> geographic ------------------------------------------------------------------
    def enu_to_lonlat(self, E_m, N_m, U_m):
        """ETRS89 longitude, latitude (degrees) and ellipsoidal height (m) of ENU points."""
        E, N, U = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (E_m, N_m, U_m)))
        lon, lat, h = self._transformers()[0].transform(E, N, U)
        return np.asarray(lon), np.asarray(lat), np.asarray(h)

    def lonlat_to_enu(self, lon_deg, lat_deg, h_m):
        """ENU (m) of ETRS89 longitude, latitude (degrees) and ellipsoidal height (m)."""
        from pyproj.enums import TransformDirection

        lon, lat, h = np.broadcast_arrays(
            *(np.asarray(v, dtype=float) for v in (lon_deg, lat_deg, h_m))
        )
        E, N, U = self._transformers()[0].transform(
            lon, lat, h, direction=TransformDirection.INVERSE
        )
        return np.asarray(E), np.asarray(N), np.asarray(U)

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

    def map_to_lonlat(self, x_m, y_m):
        """ETRS89 longitude, latitude (degrees) of map coordinates."""
        from pyproj.enums import TransformDirection

        x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        lon, lat = self._transformers()[1].transform(x, y, direction=TransformDirection.INVERSE)
        return np.asarray(lon), np.asarray(lat)


#: The 002 site, Ås (Norway): 59.665° N, 10.775° E (002 §2), map CRS ETRS89 / UTM 32N.
SITE_AAS = LocalFrame(59.665, 10.775, 0.0, ETRS89_UTM32N)


def lonlat_to_crs(crs: str, lon_deg, lat_deg):
    """Coordinates in ``crs`` (any CRS pyproj reads) of ETRS89 longitudes and latitudes."""
    cache = getattr(_local, "to_crs", None)
    if cache is None:
        cache = _local.to_crs = {}
    if crs not in cache:
        from pyproj import Transformer

        cache[crs] = Transformer.from_crs(4258, crs, always_xy=True)
    x, y = cache[crs].transform(np.asarray(lon_deg, float), np.asarray(lat_deg, float))
    return np.asarray(x), np.asarray(y)


def same_crs(a, b) -> bool:
    """Whether two CRS (anything :class:`pyproj.CRS` reads) are the same."""
    from pyproj import CRS

    return CRS.from_user_input(a) == CRS.from_user_input(b)
