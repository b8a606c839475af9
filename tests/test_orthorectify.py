"""The orthorectification workflow's core (:mod:`hsgeo.workflows.orthorectify`): the mosaic
rules, the line scanner's recorded line through ``hsgeo orthorectify``, the one raster writer."""

import numpy as np
import pytest
from ortho_inputs import FRAME, GSD_M, SITE_ARGS, flight

from hsgeo.mapgrid import MapGrid
from hsgeo.ortho import Strip, orthomosaic


@pytest.fixture(scope="module")
def two_strips():
    return flight("lp", length_m=120.0)


@pytest.mark.parametrize("rule", ["nearest-nadir", "first", "mean"])
def test_mosaic_rules(two_strips, rule):
    """Outside the strips' overlap every rule gives each strip's own cells; in it, `first` gives
    strip 1's cells, `mean` the mean of both strips' cells, `nearest-nadir` one of the two
    (each of them somewhere)."""
    fl = two_strips
    one = orthomosaic(fl.strips[:1], fl.terrain, FRAME, resolution_m=1.0)
    grid = MapGrid(
        float(one.x.values[0]) - 40.5, float(one.y.values[0]) + 30.5, 1.0, 160, 190, "EPSG:25832"
    )
    kw = dict(grid=grid, radius_m=1.0)
    a = orthomosaic(fl.strips[:1], fl.terrain, FRAME, rule=rule, **kw).values
    b = orthomosaic(fl.strips[1:], fl.terrain, FRAME, rule=rule, **kw).values
    both = orthomosaic(fl.strips, fl.terrain, FRAME, rule=rule, **kw)
    assert both.attrs["mosaic_rule"].startswith(rule.replace("-", " ").split()[0])
    both = both.values
    only1, only2 = np.isfinite(a) & np.isnan(b), np.isfinite(b) & np.isnan(a)
    assert only1.sum() > 100 and only2.sum() > 100
    np.testing.assert_array_equal(both[only1], a[only1])
    np.testing.assert_array_equal(both[only2], b[only2])
    lap = np.isfinite(a) & np.isfinite(b)
    assert lap.sum() > 100
    if rule == "first":
        np.testing.assert_array_equal(both[lap], a[lap])
    elif rule == "mean":
        np.testing.assert_allclose(both[lap], (a[lap] + b[lap]) / 2, rtol=1e-6)
    else:
        assert np.all((both[lap] == a[lap]) | (both[lap] == b[lap]))
        assert np.any(both[lap] != a[lap]) and np.any(both[lap] != b[lap])


def test_an_unknown_mosaic_rule_is_refused(two_strips):
    from hsgeo.errors import InputError

    with pytest.raises(InputError, match="--mosaic 'median'"):
        orthomosaic(two_strips.strips, two_strips.terrain, FRAME, resolution_m=1.0, rule="median")


def test_the_default_resolution_is_the_ground_pixel_spacing(two_strips):
    m = orthomosaic(two_strips.strips[:1], two_strips.terrain, FRAME)
    assert m.attrs["resolution_m"] == pytest.approx(GSD_M, rel=0.1)


def test_a_line_scanner_line_through_the_command(tmp_path, capsys):
    """The 000 line scanner's recorded line (radiance(band, line, pixel), ζ) through `hsgeo
    orthorectify` with a plane: the squares within 1 GSD (RMS) of their positions, in the
    NetCDF, the ENVI and the COG alike."""
    import json

    import rioxarray  # noqa: F401
    import xarray as xr
    from ortho_inputs import dsm, squares_xy

    from hsgeo.cli import main
    from hsgeo.io import write_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.mapgrid import MapTerrain
    from hsgeo.measure.squares import square_centroids

    fl = flight("line", length_m=120.0)
    s = fl.strips[0]
    write_lines(
        tmp_path / "line.nc",
        np.moveaxis(np.asarray(s.values), -1, 0),
        s.pixels,
        t0_s=float(s.t_s[0]),
        line_rate_hz=float(1.0 / (s.t_s[1] - s.t_s[0])),
        wavelength_nm=[640.0, 550.0, 460.0, 800.0],
    )
    write_trajectory(tmp_path / "nav.csv", s.trajectory)
    zeta0 = (s.pixels.size - 1) / 2
    (tmp_path / "scanner.toml").write_text(
        f"[sensor]\nmodel = 'linear-ifov'\nzeta0_px = {zeta0!r}\nc_px = {40.0 / 0.0065!r}\n"
    )
    z, g = dsm()
    assert isinstance(fl.terrain, MapTerrain)
    from hsgeo.io.geotiff import write_geotiff

    write_geotiff(tmp_path / "dsm.tif", z, g.transform, 25832)
    for suffix in (".nc", ".hdr", ".tif"):
        out = tmp_path / f"o{suffix}"
        rc = main(
            [
                "orthorectify",
                str(tmp_path / "line.nc"),
                "--sensor",
                str(tmp_path / "scanner.toml"),
                "--trajectory",
                str(tmp_path / "nav.csv"),
                *SITE_ARGS,
                "--dsm",
                str(tmp_path / "dsm.tif"),
                "-o",
                str(out),
                "--json",
            ]
        )
        assert rc == 0, capsys.readouterr().err
        summary = json.loads(capsys.readouterr().out)
        assert summary["bands"] == ["640 nm", "550 nm", "460 nm", "800 nm"]
        if suffix == ".nc":
            m = xr.open_dataset(out, decode_coords="all")["radiance"]
        elif suffix == ".hdr":
            m = rioxarray.open_rasterio(out.with_suffix(""))
        else:
            m = rioxarray.open_rasterio(out)
        m = m.assign_coords(band=summary["bands"])
        inside = [k for k, xy in enumerate(squares_xy()) if _imaged(m, xy, 3.0)]
        assert len(inside) >= 2
        xy, _ = square_centroids(m, squares_xy()[inside], search_m=3.0)
        err = np.hypot(*(xy - squares_xy()[inside]).T)
        assert np.sqrt(np.nanmean(err**2)) < GSD_M, (suffix, err)


def test_a_panoramic_scanner_line_through_the_command(tmp_path, capsys):
    """The 004 panoramic (whiskbroom) scanner from its sensor file (io.read_sensor's registry)
    on a rendered line: the squares within 1 GSD (RMS) of their positions in the COG. (The
    renderer shares the geolocation: this checks the command's path for the model, not the
    model's rays.)"""
    import rioxarray
    from ortho_inputs import HEIGHT_M, dsm, flight_trajectory, scene, squares_xy

    from hsgeo.cli import main
    from hsgeo.io import read_sensor, write_lines
    from hsgeo.io.geotiff import write_geotiff
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.mapgrid import MapTerrain
    from hsgeo.measure.squares import square_centroids
    from hsgeo.simulate.ortho_scene import render_lines

    ifov_deg = float(np.degrees(GSD_M / (HEIGHT_M + 100.0)))
    (tmp_path / "scanner.toml").write_text(
        f'[sensor]\nmodel = "panoramic"\nn_px = 300\nifov_deg = {ifov_deg!r}\n'
        "boresight_deg = [0.2, -0.1, 0.3]\n"
    )
    scanner = read_sensor(tmp_path / "scanner.toml")
    nav, (t, _) = flight_trajectory(120.0)
    z, g = dsm()
    zeta = np.arange(300, dtype=float)
    shell = Strip(scanner, nav, t, zeta, np.zeros((t.size, 300, 4), np.float32))
    vals = render_lines(shell, scene(), MapTerrain(z, g, FRAME), FRAME)
    write_lines(
        tmp_path / "line.nc",
        np.moveaxis(vals, -1, 0),
        zeta,
        t0_s=float(t[0]),
        line_rate_hz=float(1.0 / (t[1] - t[0])),
        wavelength_nm=[640.0, 550.0, 460.0, 800.0],
    )
    write_trajectory(tmp_path / "nav.csv", nav)
    write_geotiff(tmp_path / "dsm.tif", z, g.transform, 25832)
    argv = ["orthorectify", str(tmp_path / "line.nc"), "--sensor", str(tmp_path / "scanner.toml")]
    argv += ["--trajectory", str(tmp_path / "nav.csv"), "--dsm", str(tmp_path / "dsm.tif")]
    argv += SITE_ARGS
    assert main([*argv, "-o", str(tmp_path / "o.tif"), "--quiet"]) == 0, capsys.readouterr().err
    m = rioxarray.open_rasterio(tmp_path / "o.tif")
    m = m.assign_coords(band=["640 nm", "550 nm", "460 nm", "800 nm"])
    inside = [k for k, xy in enumerate(squares_xy()) if _imaged(m, xy, 3.0)]
    assert len(inside) >= 2
    xy, _ = square_centroids(m, squares_xy()[inside], search_m=3.0)
    err = np.hypot(*(xy - squares_xy()[inside]).T)
    assert np.sqrt(np.mean(err**2)) < GSD_M, err


def _imaged(m, xy, margin_m):
    """Every cell within ``margin_m`` of ``xy`` holds a pixel (the square lies in the swath)."""
    x, y = xy
    w = m.isel(band=0).sel(x=slice(x - margin_m, x + margin_m))
    w = w.sel(y=slice(y + margin_m, y - margin_m))
    return w.size > 0 and bool(np.isfinite(w.values).all())


def test_the_writer_refuses_an_unknown_suffix(two_strips, tmp_path):
    from hsgeo.errors import InputError
    from hsgeo.io import write_raster

    m = orthomosaic(two_strips.strips[:1], two_strips.terrain, FRAME, resolution_m=2.0)
    with pytest.raises(InputError, match=r"\.png"):
        write_raster(m, tmp_path / "o.png")
    assert not (tmp_path / "o.png").exists()
