"""hsgeo.io.lp_strips (LP line files, adjust-pushbroom JSON) and hsgeo.io.geotiff.read_dsm."""

import json

import numpy as np
import pytest

from hsgeo.errors import InputError
from hsgeo.io.lp_strips import open_lp_strip, read_adjustment, write_lp_strip


def test_lp_strip_round_trip_lazy(tmp_path):
    import dask.array as dsa

    rng = np.random.default_rng(3)
    v = rng.random((50, 20, 4), dtype=np.float32)
    t = 10.0 + np.arange(50) * 0.01
    write_lp_strip(
        tmp_path / "a.nc",
        dsa.from_array(v, chunks=(16, -1, -1)),
        t,
        [450, 550, 650, 750],
        strip_id="A7",
        col0=100,
        n_detector_px=1800,
    )
    s = open_lp_strip(tmp_path / "a.nc", lines_per_chunk=16)
    assert isinstance(s.values, dsa.Array) and s.values.chunks[0][0] == 16
    np.testing.assert_array_equal(s.values.compute(), v)
    np.testing.assert_array_equal(s.t_s, t)
    assert s.strip_id == "A7"
    # column j is detector column col0 + j; x from the line centre of 1800 px
    np.testing.assert_allclose(s.x_px, 100 + np.arange(20) - 899.5)
    with pytest.raises(InputError, match="exists"):
        write_lp_strip(tmp_path / "a.nc", v, t, [1, 2, 3, 4], strip_id="A7")


def test_lp_strip_bad_files(tmp_path):
    import xarray as xr

    xr.Dataset({"lines": (("line", "column", "band"), np.zeros((3, 2, 1)))}).to_netcdf(
        tmp_path / "no_t.nc"
    )
    with pytest.raises(InputError, match="no variable 't_s'"):
        open_lp_strip(tmp_path / "no_t.nc")
    write_lp_strip(tmp_path / "b.nc", np.zeros((3, 2, 1)), [0.0, 0.0, 1.0], [500], strip_id="b")
    with pytest.raises(InputError, match="increasing"):
        open_lp_strip(tmp_path / "b.nc")


def test_read_adjustment(tmp_path):
    from ortho_inputs import adjustment_json, flight_trajectory, node_corrections

    nav, _ = flight_trajectory()
    nodes, v = node_corrections(nav)
    p = tmp_path / "r.json"
    p.write_text(adjustment_json(nodes, v))
    a = read_adjustment(p)
    np.testing.assert_array_equal(a["nodes"], v)
    np.testing.assert_array_equal(a["t_nodes_s"], nodes.t_nodes_s)
    assert a["boresight_rad"].shape == (3,) and a["c_mm"].tolist() == [40.0]
    d = json.loads(p.read_text())
    del d["nodes"]["value"]
    p.write_text(json.dumps(d))
    with pytest.raises(InputError, match="adjust-pushbroom --json"):
        read_adjustment(p)


def test_read_dsm(tmp_path):
    from affine import Affine

    from hsgeo.io.geotiff import read_dsm, write_geotiff

    z = np.arange(12, dtype=float).reshape(3, 4)
    write_geotiff(tmp_path / "d.tif", z, Affine(2.0, 0, 600000.0, 0, -2.0, 6615000.0), 25832)
    h, g = read_dsm(tmp_path / "d.tif")
    np.testing.assert_array_equal(h, z)
    assert (g.x_min_m, g.y_max_m, g.resolution_m, g.width, g.height, g.crs) == (
        600000.0,
        6615000.0,
        2.0,
        4,
        3,
        "EPSG:25832",
    )
    (tmp_path / "x.tif").write_text("not a raster")
    with pytest.raises(InputError, match="not a raster"):
        read_dsm(tmp_path / "x.tif")
    with pytest.raises(InputError, match="not found"):
        read_dsm(tmp_path / "missing.tif")
