"""Bad input for the navigation and terrain as delivered: one clear InputError each, naming the
file, the place and the remedy (never a traceback, never a silently wrong trajectory)."""

import struct

import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.io.navigation import read_navigation
from hsgeo.io.sbet import SBET_RECORD_BYTES, read_sbet


def _records(n=50, lat=60.0, lon=10.0):
    t = 1000.0 + np.arange(n) * 0.5
    lons = lon + np.arange(n) * 30.0 / (111320.0 * np.cos(np.radians(lat)))
    return t, np.full(n, lat), lons, np.full(n, 2000.0)


def _csv(path, heading, crs="EPSG:4979", time_col="gps_sow_s", extra=""):
    t, lat, lon, h = _records()
    lines = [f"# crs: {crs}"] if crs else []
    lines.append(f"{time_col},lat_deg,lon_deg,h_m,roll_deg,pitch_deg,heading_deg{extra}")
    for k in range(t.size):
        row = (t[k], lat[k], lon[k], h[k], 0.5, 1.0, heading[k])
        lines.append(",".join(f"{v:.17g}" for v in row))
    path.write_text("\n".join(lines) + "\n")
    return path


def _sbet(path, n=50):
    t, lat, lon, h = _records(n)
    with open(path, "wb") as f:
        for k in range(n):
            f.write(
                struct.pack(
                    "<17d",
                    t[k],
                    np.radians(lat[k]),
                    np.radians(lon[k]),
                    h[k],
                    *([0.0] * 5),
                    np.radians(90.0),
                    *([0.0] * 7),
                )
            )
    return path


def test_truncated_sbet(tmp_path):
    p = _sbet(tmp_path / "sbet.out")
    data = p.read_bytes()
    p.write_bytes(data[:-20])
    with pytest.raises(
        InputError,
        match=r"not a whole number of 136-byte records \(49 records "
        r"and 116 bytes left over\).*truncated",
    ):
        read_sbet(p)
    with pytest.raises(InputError, match="truncated"):
        read_navigation(p, crs="EPSG:4979")
    p.write_bytes(b"")
    with pytest.raises(InputError, match="0 records"):
        read_sbet(p)


def test_sbet_in_degrees_or_big_endian(tmp_path):
    p = _sbet(tmp_path / "sbet.out")
    raw = bytearray(p.read_bytes())
    raw[SBET_RECORD_BYTES * 3 + 8 : SBET_RECORD_BYTES * 3 + 16] = struct.pack("<d", 60.0)
    p.write_bytes(bytes(raw))
    with pytest.raises(
        InputError,
        match=r"record 4 \(byte 408\), field lat_rad = 60 is not a "
        "latitude in radians",
    ):
        read_sbet(p)
    swapped = np.frombuffer(_sbet(tmp_path / "b.out").read_bytes(), "<f8").astype(">f8")
    (tmp_path / "big.out").write_bytes(swapped.tobytes())
    with pytest.raises(InputError, match="not an Applanix SBET"):
        read_sbet(tmp_path / "big.out")


def test_sbet_needs_its_datum_named(tmp_path):
    with pytest.raises(InputError, match=r"does not name its CRS.*--nav-crs.*EPSG:4979"):
        read_navigation(_sbet(tmp_path / "sbet.out"))


def test_unknown_epsg_and_a_projected_crs(tmp_path):
    heading = np.full(50, 90.0)
    with pytest.raises(
        InputError, match=r"a.csv', line '# crs:' 'EPSG:999999' is not a CRS pyproj knows"
    ):
        read_navigation(_csv(tmp_path / "a.csv", heading, crs="EPSG:999999"))
    with pytest.raises(InputError, match=r"need a geographic CRS.*UTM"):
        read_navigation(_csv(tmp_path / "b.csv", heading, crs="EPSG:32632"))
    with pytest.raises(InputError, match=r"does not name its CRS.*# crs: EPSG:4979"):
        read_navigation(_csv(tmp_path / "c.csv", heading, crs=None))


def test_heading_in_radians_under_deg(tmp_path):
    """East-bound at 60 m/s with the heading written as 1.5708 (radians) in heading_deg."""
    with pytest.raises(
        InputError,
        match=r"column heading_deg: the heading differs from the "
        r"course over ground by 88\.\d°.*not radians",
    ):
        read_navigation(_csv(tmp_path / "rad.csv", np.full(50, np.pi / 2)))
    nav = read_navigation(_csv(tmp_path / "deg.csv", np.full(50, 90.0)))
    assert nav.trajectory.xyz_m.shape == (50, 3)


def test_no_time_scale_or_a_latitude_out_of_range(tmp_path):
    heading = np.full(50, 90.0)
    with pytest.raises(InputError, match=r"state its time scale.*gps_sow_s.*sod_s"):
        read_navigation(_csv(tmp_path / "t.csv", heading, time_col="time"))
    p = _csv(tmp_path / "lat.csv", heading)
    lines = p.read_text().splitlines()
    assert ",60," in lines[2]
    lines[2] = lines[2].replace(",60,", ",600,", 1)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"column lat_deg, line 3: 600 is outside \[-90, 90\]"):
        read_navigation(p)


def test_times_that_go_back(tmp_path):
    p = _csv(tmp_path / "t.csv", np.full(50, 90.0))
    lines = p.read_text().splitlines()
    lines[10], lines[11] = lines[11], lines[10]
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(
        InputError,
        match=r"line 12, column gps_sow_s: 1004 s does not come after 1004.5 s of line 11",
    ):
        read_navigation(p)


def test_a_datum_without_a_3d_epsg_code_names_the_realisations(tmp_path):
    with pytest.raises(InputError, match=r"'NAD83'.*no geographic 3D form.*EPSG:6319"):
        read_navigation(_csv(tmp_path / "n.csv", np.full(50, 90.0), crs="EPSG:4269"))


def test_a_terrain_grid_too_large_names_the_spacing(tmp_path):
    from hsgeo.crs import LocalFrame
    from hsgeo.io.terrain import read_terrain

    p = tmp_path / "dsm.tif"
    import rasterio
    from rasterio.transform import from_origin

    tr = from_origin(500000, 6600000, 1, 1)
    kw = dict(driver="GTiff", width=10, height=10, count=1, dtype="float32", crs="EPSG:32632")
    with rasterio.open(p, "w", transform=tr, **kw) as d:
        d.write(np.zeros((1, 10, 10), np.float32))
    frame = LocalFrame(59.5, 9.0, 0.0, 32632, 4979)
    with pytest.raises(InputError, match=r"coarser grid spacing \(cell_m ≥"):
        read_terrain(p, frame, (-20000, -5000, 20000, 5000), vertical="ellipsoidal")
