"""``hsgeo data flight --site LAT,LON --out DIR`` (issue 38): a simulated flight about any site
in the formats a real one is delivered in, run through ``hsgeo orthorectify`` with the command
it writes (ENVI lines + times file, geodetic navigation, a view-angle sensor file, a DSM
GeoTIFF); each target found in the orthoimage (a Gaussian fitted to its cells) lies within
0.25 ground pixel (RMS) of its true position computed here with pyproj alone."""

from __future__ import annotations

import shlex

import numpy as np
import pandas as pd
import pytest

from hsgeo.cli import main

SITES = {
    "aas": (59.665, 10.775),
    "sydney": (-33.9, 151.2),
    "boulder": (40.0, -105.3),
    "svalbard": (78.2, 15.6),
    "antimeridian": (-16.5, 179.95),
    "utm-32-33": (47.0, 12.0),
}
FAST = ("aas", "sydney")


def _fit_centre(x, y, v, background, sigma):
    """The centre of a Gaussian blob (amplitude, centre, σ free; the background known)."""
    from scipy.optimize import least_squares

    i = np.argmax(v)
    p0 = [v[i] - background, x[i], y[i], sigma]

    def r(p):
        a, cx, cy, s = p
        return background + a * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s**2)) - v

    return least_squares(r, p0).x[1:3]


def _flight_and_ortho(tmp_path, site, capsys):
    lat, lon = SITES[site]
    d = tmp_path / site
    assert main(["data", "flight", f"--site={lat},{lon}", "--out", str(d), "--length-km", "3"]) == 0
    said = capsys.readouterr().out
    argv = shlex.split((d / "command.txt").read_text())
    assert argv[:2] == ["hsgeo", "orthorectify"] and shlex.join(argv) in said
    assert main([*argv[1:], "--quiet", "--json"]) == 0, capsys.readouterr().err
    capsys.readouterr()
    return d


@pytest.mark.parametrize(
    "site", [s if s in FAST else pytest.param(s, marks=pytest.mark.slow) for s in SITES]
)
def test_targets_land_where_pyproj_puts_them(tmp_path, site, capsys):
    import rioxarray
    from pyproj import Transformer

    d = _flight_and_ortho(tmp_path, site, capsys)
    crs_line = (d / "targets.csv").read_text().splitlines()[0]
    epsg = int(crs_line.split("EPSG:")[1])
    tg = pd.read_csv(d / "targets.csv", comment="#")
    # the truth with pyproj alone: the targets' WGS 84 positions in the output CRS
    tx, ty = Transformer.from_crs(4979, epsg, always_xy=True).transform(
        tg["lon_deg"].values, tg["lat_deg"].values
    )
    np.testing.assert_allclose(tg["x_m"], tx, atol=1e-6)
    np.testing.assert_allclose(tg["y_m"], ty, atol=1e-6)
    m = rioxarray.open_rasterio(d / "ortho.tif")
    assert m.rio.crs.to_epsg() == epsg
    assert m.shape[0] == 3  # the cube's three bands, their ENVI header's wavelengths and FWHM
    import rasterio  # … in GDAL's standard keys of the COG

    with rasterio.open(d / "ortho.tif") as src:
        um = [float(src.tags(b, ns="IMAGERY")["CENTRAL_WAVELENGTH_UM"]) for b in (1, 2, 3)]
        fw = [float(src.tags(b, ns="IMAGERY")["FWHM_UM"]) for b in (1, 2, 3)]
    np.testing.assert_allclose(um, [0.46, 0.55, 0.64])
    np.testing.assert_allclose(fw, [0.009, 0.010, 0.011])
    from hsgeo.simulate.geo_flight import FlightConfig, view_angles

    cfg = FlightConfig(*SITES[site])
    a, _ = view_angles(cfg.n_px, cfg.fov_deg)
    gsd = cfg.agl_m * float(np.mean(np.diff(np.tan(a))))
    X, Y = np.meshgrid(m["x"].values, m["y"].values)
    v = m.values[0].astype(float)
    err = []
    for x0, y0 in zip(tx, ty, strict=True):
        near = (np.abs(X - x0) < 6 * gsd) & (np.abs(Y - y0) < 6 * gsd) & np.isfinite(v)
        assert near.sum() > 50, (site, x0, y0)
        cx, cy = _fit_centre(X[near], Y[near], v[near], 100.0, 1.5 * gsd)
        err.append((cx - x0, cy - y0))
    err = np.array(err)
    rms = float(np.sqrt(np.mean(np.sum(err**2, axis=1))))
    assert rms < 0.25 * gsd, (site, rms, gsd, err)
