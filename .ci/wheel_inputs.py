"""Inputs for `make check-wheel`, written with the *installed* hsgeo (no repository files).

Usage: python wheel_inputs.py DIR. Writes under DIR: raw/ and dark/ frame folders (cube),
eight LP strips of the rendered campaign with their navigation, camera and squares
(lp-observations, adjust-pushbroom), a DSM around them (orthorectify) and a slanted-edge PNG
(mtf-edge). The same recipes as tests/test_bad_input.py and tests/test_cli_lp_observations.py.
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
from hsgeo.simulate.lp_campaign import simulate

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
(d / "CAM.toml").write_text(
    f"[camera]\nn_bands = {len(cam.c_mm)}\npixel_mm = {cam.pixel_mm}\nc_mm = {cam.c_mm[0]}\n"
    f"x0_mm = {cam.x0_mm}\nlever_arm_m = [{la}]\n"
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
print(f"inputs written to {d}")
