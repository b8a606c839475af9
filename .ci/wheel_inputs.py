"""Inputs for `make check-wheel`, written with the *installed* hsgeo (no repository files).

Usage: ``python wheel_inputs.py DIR`` writes under DIR: raw/ and dark/ frame folders (cube),
eight LP strips of the rendered campaign with their navigation, camera and squares
(lp-observations, adjust-pushbroom), a DSM around them (orthorectify), a slanted-edge PNG
(mtf-edge), a crossing and an along scan of the simulated runway with its corners (asf), and
three Rikola frames with their exposure table, navigation, sensor file and DSM (orthorectify of
a frame camera). The same recipes as tests/test_bad_input.py, tests/asf_inputs.py,
tests/test_orthorectify_registry.py and tests/test_cli_lp_observations.py.

``python wheel_inputs.py --sbet FLIGHT`` turns the folder that ``hsgeo data flight`` wrote into
the README's real-flight line: its geodetic navigation as an Applanix SBET (``FLIGHT.sbet``, in
:mod:`hsgeo.io.sbet`'s field order), its ENVI lines as one NetCDF line file (``LINE.nc``) and
its DSM with EGM96 heights (``DSM_egm96.tif``, PROJ's geoid through
:func:`hsgeo.crs.use_system_proj_grids`).
"""

import sys
from math import erf, radians, sqrt, tan
from pathlib import Path

import numpy as np
import pandas as pd
from PIL import Image

from hsgeo.crs import SITE_AAS
from hsgeo.io.frames import write_frame_folder
from hsgeo.io.geotiff import write_geotiff
from hsgeo.io.lp_lines import write_lp_lines
from hsgeo.io.navigation import write_trajectory
from hsgeo.mapgrid import MapGrid
from hsgeo.simulate import cube_survey as CS
from hsgeo.simulate.lp_campaign import LpConfig, simulate


def sbet(flight: Path) -> None:
    """FLIGHT.sbet, LINE.nc and DSM_egm96.tif from a ``hsgeo data flight`` folder."""
    import rasterio
    from pyproj import Transformer

    from hsgeo.crs import use_system_proj_grids
    from hsgeo.io import write_lines
    from hsgeo.io.envi import read_envi
    from hsgeo.io.sbet import SBET_FIELDS

    nav = pd.read_csv(flight / "nav.csv", comment="#")
    rec = np.zeros((len(nav), len(SBET_FIELDS)))
    col = {f: i for i, f in enumerate(SBET_FIELDS)}
    wander_rad = 0.3  # any wander angle: platform heading = true heading + wander
    rec[:, col["time_s"]] = nav["gps_sow_s"]
    rec[:, col["lat_rad"]] = np.radians(nav["lat_deg"])
    rec[:, col["lon_rad"]] = np.radians(nav["lon_deg"])
    rec[:, col["h_m"]] = nav["h_m"]
    rec[:, col["roll_rad"]] = np.radians(nav["roll_deg"])
    rec[:, col["pitch_rad"]] = np.radians(nav["pitch_deg"])
    rec[:, col["platform_heading_rad"]] = np.radians(nav["heading_deg"]) + wander_rad
    rec[:, col["wander_rad"]] = wander_rad
    rec.astype("<f8").tofile(flight / "FLIGHT.sbet")

    lines, _ = read_envi(flight / "lines.raw")  # (bands, lines, samples)
    t = pd.read_csv(flight / "line_times.csv")["t_s"].to_numpy(float)
    rate_hz = (t.size - 1) / (t[-1] - t[0])
    assert np.allclose(np.diff(t), 1.0 / rate_hz, rtol=0.0, atol=1e-6), "irregular line times"
    write_lines(flight / "LINE.nc", lines, np.arange(float(lines.shape[2])), t0_s=float(t[0]),
                line_rate_hz=float(rate_hz))  # fmt: skip

    use_system_proj_grids()  # EGM96 (egm96_15.gtx) of Debian's proj-data
    with rasterio.open(flight / "dsm.tif") as src:
        z = src.read(1).astype(float)
        transform, crs = src.transform, src.crs
    rows, cols = np.indices(z.shape)
    x, y = rasterio.transform.xy(transform, rows.ravel(), cols.ravel())
    lon, lat = Transformer.from_crs(crs, 4326, always_xy=True).transform(x, y)
    geoid = Transformer.from_crs("EPSG:4979", "EPSG:4326+5773", always_xy=True)
    _, _, h_egm96 = geoid.transform(lon, lat, z.ravel(), errcheck=True)
    n_m = z.ravel() - np.asarray(h_egm96)
    assert np.all(np.abs(n_m) > 1.0), "the EGM96 grid was not found (geoid height 0)"
    write_geotiff(flight / "DSM_egm96.tif", np.reshape(h_egm96, z.shape), transform,
                  crs.to_epsg())  # fmt: skip
    print(f"SBET, LINE.nc, DSM_egm96.tif (geoid height {n_m.mean():.2f} m) in {flight}")


if sys.argv[1] == "--sbet":
    sbet(Path(sys.argv[2]))
    sys.exit(0)
d = Path(sys.argv[1])
d.mkdir(parents=True, exist_ok=True)

cfg = CS.CubeSurvey(length_m=0.02)
frames, (dark, t), _ = CS.simulate(cfg, 4)
write_frame_folder(
    d / "raw",
    frames.read(0, frames.n_frames),
    frames.exposure_s,
    wavelength_nm=cfg.row_wavelength_nm(),
    fwhm_nm=cfg.row_fwhm_nm(),
)
write_frame_folder(d / "dark", dark, t)

obs, _ = simulate(scale=0.1, rng=2)
for s in obs.strips[:10:2] + obs.strips[12:15]:
    write_lp_lines(d / f"STRIP_{s.strip_id}.nc", s)
write_trajectory(d / "NAV.csv", obs.navigation)
cam = obs.camera
la = ", ".join(f"{v:.6f}" for v in cam.lever_arm_m)
c = LpConfig().campaign  # the campaign's instruments (simulate's default LpConfig)
pos = ", ".join(repr(float(v)) for v in c.sigma_pos_m)
att = ", ".join(repr(float(v)) for v in np.rad2deg(c.sigma_att_rad))
(d / "CAM.toml").write_text(
    f"[camera]\nn_bands = {len(cam.c_mm)}\npixel_mm = {cam.pixel_mm}\nc_mm = {cam.c_mm[0]}\n"
    f"x0_mm = {cam.x0_mm}\nlever_arm_m = [{la}]\n"
    # the a-priori σ of the campaign's instruments (a camera file states them: no default)
    f"sigma_lever_m = {c.sigma_lever_m!r}\n[gnss_ins]\nsigma_pos_m = [{pos}]\n"
    f"sigma_att_deg = [{att}]\n[observations]\nsigma_px = {c.sigma_obs_px!r}\n"
    f"[gcp]\nsigma_m = {c.sigma_gcp_m!r}\n"
)
xyz = obs.square_xyz_m
sq = pd.DataFrame(
    {"point_id": list(obs.square_ids), "E_m": xyz[:, 0], "N_m": xyz[:, 1], "H_m": xyz[:, 2]}
)
sq.to_csv(d / "SQUARES.csv", index=False, float_format="%.17g")
sq[sq["point_id"].isin(obs.gcp_ids)].to_csv(d / "GCP.csv", index=False, float_format="%.17g")

# a flat DSM at the squares' height around the strips (EPSG:25832, the campaign's site)

nav = obs.navigation
e, n_, h = SITE_AAS.enu_to_map(xyz[:, 0], xyz[:, 1], xyz[:, 2])
xs, ys, _ = SITE_AAS.enu_to_map(nav.xyz_m[:, 0], nav.xyz_m[:, 1], nav.xyz_m[:, 2])
grid = MapGrid.covering(
    (xs.min() - 1500, xs.max() + 1500),
    (ys.min() - 1500, ys.max() + 1500),
    20.0,
    f"EPSG:{SITE_AAS.map_epsg}",
)
z = np.full((grid.y_m.size, grid.x_m.size), float(np.median(h)))
write_geotiff(d / "DSM.tif", z, grid.transform, SITE_AAS.map_epsg)

# a slanted edge (5 deg), Gaussian blur sigma 0.6 px, 8x supersampled pixel aperture

n, ss = 96, 8
u = (np.arange(n * ss) + 0.5) / ss
x, y = np.meshgrid(u, u)
dist = (x - n / 2) - (y - n / 2) * tan(radians(5.0))
verf = np.vectorize(erf)
fine = 0.5 * (1 + verf(dist / (0.6 * sqrt(2))))
img = fine.reshape(n, ss, n, ss).mean(axis=(1, 3))

Image.fromarray(np.round(20 + 200 * img).astype(np.uint8)).save(d / "EDGE.png")

# asf: the simulated runway (a 200-pixel scanner, a 400 m runway), both scans georegistered

from dataclasses import replace  # noqa: E402

from hsgeo.io.scans import write_geoscan  # noqa: E402
from hsgeo.sensors.panoramic import PanoramicScanner  # noqa: E402
from hsgeo.simulate.asf_runway import RunwayScene, simulate_runway  # noqa: E402
from hsgeo.workflows.asf import georegister  # noqa: E402

scene = replace(RunwayScene(), sensor=PanoramicScanner(n_px=200), runway_length_m=400.0)
runway, _ = simulate_runway(scene, 4, reverse=False)
for name, s in (("CROSS", runway.cross), ("ALONG", runway.along)):
    g = georegister(s.values, s.zeta_px, s.t0_s, s.line_rate_hz, s.sensor, s.trajectory)
    write_geoscan(d / f"{name}.nc", g.values, g.scan_angle_rad, g.E_m, g.N_m)
P = runway.runway_polygon_m
pd.DataFrame({"E_m": P[:, 0], "N_m": P[:, 1]}).to_csv(d / "RUNWAY.csv", index=False)

# Rikola frames: the 003 camera's two sensors (two bands), three frames 100 m above flat ground
# at 59.665 N, 10.775 E, one ENVI file per frame, TIMES.csv (file, time_s, band)

from hsgeo.io.envi import write_envi  # noqa: E402
from hsgeo.io.sensor_file import sensor_toml  # noqa: E402
from hsgeo.trajectory import Trajectory  # noqa: E402

fr = d / "FRAMES"
fr.mkdir(exist_ok=True)
(d / "RIKOLA.toml").write_text(
    sensor_toml(
        "rikola",
        {
            "f_band_mm": [1.83, 1.85],
            "band_sensor": [1, 2],
            "bands": [1, 2],
            "pp_I_mm": [0.01, -0.005],
            "pp_II_mm": [-0.01, 0.005],
            "image_size_px": [200, 150],
            "pixel_mm": 0.0055,
            "boresight_deg": [180.0, 0.0, 0.0],  # the camera looks along -z: turned over
        },
    )
)
tf = np.arange(0.0, 10.01, 0.1)
frames_nav = Trajectory(
    tf, np.column_stack([np.zeros_like(tf), 10.0 * tf - 50.0, np.full(tf.size, 100.0)]),
    np.zeros((tf.size, 3)),
)  # fmt: skip
write_trajectory(d / "FRAMES_NAV.csv", frames_nav)
v, u = np.mgrid[0:150, 0:200]
rows = ["file,time_s,band"]
for i, t0 in enumerate((3.0, 5.0, 7.0)):
    img = np.stack([(u // 20 + v // 20 + i + b) % 2 for b in (0, 1)]).astype(np.float32)
    write_envi(fr / f"f{i}.raw", img)
    rows += [f"f{i}.raw,{t0 + 0.05 * b!r},{b + 1}" for b in (0, 1)]
(d / "TIMES.csv").write_text("\n".join(rows) + "\n")
# flat ground at the site's height (0 m) in the site's WGS 84 UTM zone (32N: no --nav-crs)
from pyproj import Transformer  # noqa: E402

xc, yc = Transformer.from_crs(4326, 32632, always_xy=True).transform(10.775, 59.665)
grid = MapGrid.covering((xc - 500.0, xc + 500.0), (yc - 500.0, yc + 500.0), 5.0, "EPSG:32632")
write_geotiff(d / "FRAMES_DSM.tif", np.zeros((grid.y_m.size, grid.x_m.size)), grid.transform, 32632)
print(f"inputs written to {d}")
