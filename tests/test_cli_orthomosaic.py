"""``hsgeo orthomosaic``: LP line files -> COG; bad input -> one line, exit 2."""

import json

import numpy as np
import pytest
from ortho_inputs import GSD_M, squares_xy, write_ortho_inputs

from hsgeo.cli import main


def _argv(f, out, *extra, adjustment=True):
    argv = [
        "orthomosaic",
        *map(str, f["lines"]),
        "--trajectory",
        str(f["nav"]),
        "--camera",
        str(f["camera"]),
        "--dsm",
        str(f["dsm"]),
        "--resolution",
        "0.3",
        "-o",
        str(out),
    ]
    if adjustment and "adjustment" in f:
        argv += ["--adjustment", str(f["adjustment"])]
    return argv + list(extra)


@pytest.fixture(scope="module")
def adjusted(tmp_path_factory):
    d = tmp_path_factory.mktemp("ortho_adj")
    return d, write_ortho_inputs(d, adjusted=True)


def _square_errors(path):
    import rioxarray

    from hsgeo.measure.squares import square_centroids

    m = rioxarray.open_rasterio(path)
    m = m.assign_coords(band=[str(b) for b in m.attrs.get("long_name", m["band"].values)])
    xy, _ = square_centroids(m, squares_xy(), search_m=3.0)
    return np.hypot(*(xy - squares_xy()).T)


def test_adjustment_puts_the_squares_in_place(adjusted, capsys):
    """Lines rendered along the true trajectory, the navigation file lacking known node
    corrections (1.2 m E, -0.9 m N, ...): with --adjustment the squares lie within 1 GSD (RMS)
    of their positions, without it about 1.5 m off."""
    d, f = adjusted
    rc = main(_argv(f, d / "adj.tif", "--json", "--bands", "640,550,460"))
    assert rc == 0, capsys.readouterr().err
    out = json.loads(capsys.readouterr().out)
    assert out["crs"] == "EPSG:25832" and out["bands"] == ["640 nm", "550 nm", "460 nm"]
    assert out["adjusted"] and out["strips"] == ["s1", "s2"]
    assert out["line_pixels"] == 300  # the files' n_px_full attribute (io.lp_lines)
    err = _square_errors(d / "adj.tif")
    assert np.sqrt(np.mean(err**2)) < GSD_M
    assert main(_argv(f, d / "raw.tif", adjustment=False)) == 0
    raw = _square_errors(d / "raw.tif")
    assert np.all(raw > 1.0)


@pytest.mark.parametrize(
    "edit, expect",
    [
        ("exists", "exists"),
        ("band", "--bands 1200: no band"),
        ("dsm_small", "outside --dsm"),
        ("dsm_crs", "EPSG:32632"),
        ("scheduler", "--scheduler"),
        ("nav_short", "navigation"),
        ("line_pixels", "do not fit a line of 299 px (from --line-pixels)"),
    ],
)
def test_bad_input_one_line_exit_2(adjusted, tmp_path, capsys, monkeypatch, edit, expect):
    from ortho_inputs import dsm

    from hsgeo.io.geotiff import write_geotiff
    from hsgeo.io.navigation import read_trajectory, write_trajectory
    from hsgeo.trajectory import Trajectory

    _, f = adjusted
    f = dict(f)
    out = tmp_path / "m.tif"
    extra = []
    if edit == "exists":
        out.write_bytes(b"keep me")
    elif edit == "band":
        extra = ["--bands", "640,1200"]
    elif edit == "dsm_small":
        z, g = dsm(pad_m=40.0)
        f["dsm"] = write_geotiff(tmp_path / "small.tif", z, g.transform, 25832)
    elif edit == "dsm_crs":
        z, g = dsm()
        f["dsm"] = write_geotiff(tmp_path / "utm_wgs84.tif", z, g.transform, 32632)
    elif edit == "scheduler":
        monkeypatch.setattr("hsgeo.workflows.orthomosaic.SCHEDULER_TIMEOUT_S", 1.0)
        extra = ["--scheduler", "tcp://127.0.0.1:9"]
    elif edit == "line_pixels":  # the option overrides the files' n_px_full (300)
        extra = ["--line-pixels", "299"]
    elif edit == "nav_short":
        nav = read_trajectory(f["nav"])
        keep = nav.t_s < nav.t_s[-1] / 2
        short = Trajectory(nav.t_s[keep], nav.xyz_m[keep], nav.roll_pitch_heading_rad[keep])
        f["nav"] = write_trajectory(tmp_path / "short.csv", short)
        f.pop("adjustment")
    rc = main(_argv(f, out, *extra))
    err = capsys.readouterr().err
    assert rc == 2
    assert len(err.strip().splitlines()) == 1, err
    assert expect in err, err
    assert "Traceback" not in err
    if edit == "exists":
        assert out.read_bytes() == b"keep me"
    else:
        assert not out.exists()


def test_overwrite_replaces(adjusted, tmp_path, capsys):
    _, f = adjusted
    out = tmp_path / "m.tif"
    out.write_bytes(b"old")
    assert main(_argv(f, out, "--overwrite", "--bands", "640")) == 0
    import rasterio

    with rasterio.open(out) as src:
        assert src.count == 1 and src.descriptions == ("640 nm",)


def test_a_failed_scheduler_leaves_no_default_client(adjusted, tmp_path, capsys):
    """A --scheduler that does not answer is refused, and the next mosaic in the same process
    is computed here (a failed Client made the default made every later compute wait on it)."""
    from distributed.client import _get_global_client

    _, f = adjusted
    assert main(_argv(f, tmp_path / "a.tif", "--scheduler", "nowhere", "--bands", "640")) == 2
    assert "--scheduler nowhere" in capsys.readouterr().err
    assert _get_global_client() is None
    assert main(_argv(f, tmp_path / "b.tif", "--bands", "640", "--resolution", "1")) == 0
