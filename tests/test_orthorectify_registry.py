"""``hsgeo orthorectify`` with a sensor file of every model of the registry (issue 36).

One template for all (:data:`hsgeo.io.sensor_file.MODELS`: the line scanners, the pushbroom
camera, the panoramic scanner, the view-angle sensor, the OpenCV frame camera, the Rikola):
a sensor file with a lever arm and a boresight, a flight 100 m above a DSM with a building
(8 m) and 3 m targets (one on the roof), the recorded data rendered here by an INDEPENDENT
ray caster — the sensor's own face (``rays``; the frame cameras' at exposure poses computed
here from the navigation, not along the trajectory as the command does), then dense sampling
of each ray (5 cm steps) over the bilinear DSM and bisection, no hsgeo geolocation code —
written as ENVI files (lines with a times file; one file per frame with an exposure table),
then ``hsgeo orthorectify`` through ``hsgeo.cli.main``. The targets' centroids in the output
must lie within 1 GSD (RMS) of their true positions.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hsgeo.cli import main
from hsgeo.io import read_sensor
from hsgeo.io.navigation import write_trajectory
from hsgeo.io.sensor_file import MODELS, sensor_toml
from hsgeo.rotations import opk_from_R
from hsgeo.trajectory import Trajectory

H_M = 100.0  # flight height above the ground plane
SPEED_M_S = 10.0
GSD_M = 0.3  # nominal ground pixel at nadir of every sensor below
MOUNT = {"lever_arm_m": [0.3, -0.2, 0.5], "boresight_deg": [0.4, -0.3, 0.8]}
#: Targets (E, N) of 3 m × 3 m, m; the fourth is on the building's roof.
TARGETS = np.array([[-15.0, -25.0], [-10.0, 20.0], [18.0, -18.0], [12.0, 5.0], [-3.0, -2.0]])
TARGET_HALF_M = 1.5
BUILDING = (7.0, 17.0, 0.0, 10.0, 8.0)  # E0, E1, N0, N1, height m
DEM_CELL_M = 0.5
N_PX = 200  # pixels of a line, columns of a frame
FRAME_ROWS = 150
FRAME_T_S = (3.0, 5.0, 7.0)

#: Each model's sensor file (the mount added where the model has one) and its pixels.
SENSORS = {
    "line-scanner": {"zeta0_px": 99.5, "c_px": 333.0, "K": [0.05, -0.002, 0.0]},
    "line-scanner-linear-ifov": {"zeta0_px": 99.5, "c_px": 333.0},
    "pushbroom": {
        "n_bands": 1,
        "pixel_mm": 0.0065,
        "c_mm": 2.165,
        "distortion": [2e-3, 0.0, 1e-4, -1e-4],
        "boresight_deg": [0.3, -0.2, 0.1],
        "lever_arm_m": [0.1, 0.0, -0.2],
    },
    "panoramic": {"n_px": N_PX, "ifov_deg": 0.172},
    "view-angle": {
        "across_deg": [round(float(x), 9) for x in np.linspace(-17.0, 17.0, N_PX)],
        "along_deg": [round(0.3 * (float(x) / 17.0) ** 2, 9) for x in np.linspace(-17, 17, N_PX)],
    },
    "frame-opencv": {
        "fx_px": 333.0,
        "fy_px": 335.0,
        "cx_px": 101.0,
        "cy_px": 73.0,
        "distortion": [-0.05, 0.01, 1e-3, -5e-4, 0.0],
        "image_size_px": [N_PX, FRAME_ROWS],
    },
    "rikola": {
        "f_band_mm": [1.83, 1.85],
        "band_sensor": [1, 2],
        "bands": [1, 2],
        "pp_I_mm": [0.01, -0.005],
        "pp_II_mm": [-0.01, 0.005],
        "distortion": [-2e-3, 0.0, 0.0, 0.0, 0.0],
        "rotation_deg": [0.1, -0.05, 0.2],
        "offset_mm": [5.0, 0.0, 0.0],
        "image_size_px": [N_PX, FRAME_ROWS],
        "pixel_mm": 0.0055,
        # the Rikola's camera looks along −z: turned over (roll 180°) to look down
        "boresight_deg": [180.4, -0.3, 0.8],
    },
}


def test_every_model_of_the_registry_is_in_the_template():
    assert set(SENSORS) == set(MODELS)


def nav():
    t = np.linspace(0.0, 10.0, 1001)
    xyz = np.column_stack(
        [1.0 * np.sin(0.4 * t), -50.0 + SPEED_M_S * t, H_M + 0.5 * np.sin(0.3 * t)]
    )
    rph = np.column_stack(
        [0.01 * np.sin(0.9 * t), 0.008 * np.cos(0.6 * t), 0.02 + 0.01 * np.sin(0.2 * t)]
    )
    return Trajectory(t, xyz, rph)


def dem():
    """Heights (N, E) of the DSM: a gentle slope and the building (the terrain both the
    renderer and the command meet, bilinear between the cells)."""
    E = np.arange(-70.0, 70.0 + DEM_CELL_M / 2, DEM_CELL_M)
    N = np.arange(-80.0, 80.0 + DEM_CELL_M / 2, DEM_CELL_M)
    EE, NN = np.meshgrid(E, N)
    z = 0.02 * EE + 0.01 * NN
    e0, e1, n0, n1, h = BUILDING
    z = z + h * ((EE >= e0) & (EE <= e1) & (NN >= n0) & (NN <= n1))
    return E, N, z


def bilinear(E, N, z, e, n):
    """Independent bilinear interpolation of the DSM at points (e, n)."""
    i = np.clip((e - E[0]) / DEM_CELL_M, 0, E.size - 1.000001)
    j = np.clip((n - N[0]) / DEM_CELL_M, 0, N.size - 1.000001)
    i0, j0 = np.floor(i).astype(int), np.floor(j).astype(int)
    fi, fj = i - i0, j - j0
    return (
        z[j0, i0] * (1 - fi) * (1 - fj)
        + z[j0, i0 + 1] * fi * (1 - fj)
        + z[j0 + 1, i0] * (1 - fi) * fj
        + z[j0 + 1, i0 + 1] * fi * fj
    )


def first_hit(o, d, terrain, step_m=0.05):
    """Brute force: march each ray in ``step_m`` steps from above the highest cell, take the
    first sample below the DSM and bisect (60 halvings) between it and the previous one."""
    E, N, z = terrain
    top, low = z.max() + 0.5, z.min() - 0.5
    s_end = (o[:, 2] - low) / -d[:, 2]

    def below(s, i):
        p = o[i] + s[:, None] * d[i]
        return p[:, 2] <= bilinear(E, N, z, p[:, 0], p[:, 1])

    lo = (o[:, 2] - top) / -d[:, 2]  # above every cell
    hi = np.full(len(o), np.nan)
    todo = np.arange(len(o))
    while todo.size:
        s_next = lo[todo] + step_m
        hit = below(s_next, todo)
        hi[todo[hit]] = s_next[hit]
        lo[todo[~hit]] = s_next[~hit]
        todo = todo[~hit & (s_next < s_end[todo])]
    assert np.all(np.isfinite(hi)), "a ray missed the DSM"
    every = np.arange(len(o))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        b = below(mid, every)
        hi = np.where(b, mid, hi)
        lo = np.where(b, lo, mid)
    return o + hi[:, None] * d


def radiance(xyz):
    """1 inside a target, 0 elsewhere."""
    dx = np.abs(xyz[:, None, 0] - TARGETS[None, :, 0])
    dy = np.abs(xyz[:, None, 1] - TARGETS[None, :, 1])
    return np.any((dx <= TARGET_HALF_M) & (dy <= TARGET_HALF_M), axis=1).astype(np.float32)


def write_envi(path, lsb):
    """(lines, samples, bands) float32 as BSQ with a hand-written header."""
    np.ascontiguousarray(np.asarray(lsb, "<f4").transpose(2, 0, 1)).tofile(path)
    path.with_suffix(".hdr").write_text(
        f"ENVI\nsamples = {lsb.shape[1]}\nlines = {lsb.shape[0]}\nbands = {lsb.shape[2]}\n"
        "header offset = 0\ndata type = 4\ninterleave = bsq\nbyte order = 0\n"
    )


def render_lines(sensor, name, trajectory, terrain):
    """The scanning sensor's lines ``(n_lines, N_PX, 1)`` and their times."""
    t = np.arange(1.0, 9.0, GSD_M / SPEED_M_S)
    s = np.arange(float(N_PX))
    if name == "pushbroom":
        x = s - (N_PX - 1) / 2.0
        px, kw = np.column_stack([x, np.zeros_like(x)]), {"band": 0}
    else:
        px, kw = s, {}
    tt = np.repeat(t, N_PX)
    pp = np.tile(px, (t.size,) + (1,) * (px.ndim - 1))
    o, d = sensor.rays(pp, tt, trajectory, **kw)  # the sensor's face (its own mount)
    v = radiance(first_hit(o, d, terrain))
    return v.reshape(t.size, N_PX, 1), t


def render_frame(sensor, trajectory, t_s, terrain, band=None):
    """One frame ``(FRAME_ROWS, N_PX)`` through the camera's face at the exposure pose computed
    here (ω, φ, κ of R_map_from_body and the body's position at ``t_s``)."""
    pos, _ = trajectory.pose(np.array([t_s]))
    opk = opk_from_R(trajectory.R_map_from_body(np.array([t_s]))[0])
    poses = np.array([[*np.ravel(opk), *pos[0]]])
    u, v = np.meshgrid(np.arange(float(N_PX)), np.arange(float(FRAME_ROWS)))
    uv = np.column_stack([u.ravel(), v.ravel()])
    view = np.zeros(uv.shape[0], int)
    if band is None:
        o, d = sensor.rays(uv, poses, view)
    else:  # the face's lengths are the poses' (m here): sensor II's offset in m
        metric = replace(sensor, offset_mm=tuple(1e-3 * np.asarray(sensor.offset_mm)))
        o, d = metric.rays(uv, poses, view, band)
    return radiance(first_hit(o, d, terrain)).reshape(FRAME_ROWS, N_PX)


def target_errors(path):
    """Distance (m) of each target's centroid (cells > 0.5 within 3 m of the truth) in each
    output band from its true position, ``(n_bands, n_targets)``."""
    import xarray as xr

    with xr.open_dataset(path) as ds:
        r = ds["radiance"].values
        x, y = ds["x"].values, ds["y"].values
    X, Y = np.meshgrid(x, y)
    err = np.full((r.shape[0], len(TARGETS)), np.nan)
    for b in range(r.shape[0]):
        for k, (e, n) in enumerate(TARGETS):
            near = (np.abs(X - e) < 3.0) & (np.abs(Y - n) < 3.0) & (r[b] > 0.5)
            if near.sum() > 10:
                err[b, k] = np.hypot(X[near].mean() - e, Y[near].mean() - n)
    return err


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    import xarray as xr

    d = tmp_path_factory.mktemp("registry_ortho")
    trajectory = nav()
    write_trajectory(d / "nav.csv", trajectory)
    E, N, z = dem()
    xr.Dataset({"height": (("N", "E"), z)}, coords={"E": E, "N": N}).to_netcdf(
        d / "dem.nc", engine="h5netcdf"
    )
    return d, trajectory, (E, N, z)


def common_args(d):
    from ortho_inputs import FRAME, SITE_ARGS

    return [
        "--trajectory",
        str(d / "nav.csv"),
        "--dsm",
        str(d / "dem.nc"),
        "--resolution",
        str(GSD_M),
        "--crs",
        FRAME.local_crs(),
        *SITE_ARGS,
        "--quiet",
    ]


def write_case(name, d, trajectory, terrain):
    """The sensor file and the recorded data of ``name``; the command's arguments."""
    values = SENSORS[name]
    if "lever_arm_m" in MODELS[name].keys and name != "pushbroom":
        values = {**MOUNT, **values}
    (d / f"{name}.toml").write_text(sensor_toml(name, values))
    sensor = read_sensor(d / f"{name}.toml")
    argv = ["--sensor", str(d / f"{name}.toml"), *common_args(d)]
    if MODELS[name].kind == "scanning":
        lines, t = render_lines(sensor, name, trajectory, terrain)
        write_envi(d / f"{name}.raw", lines)
        np.savetxt(d / f"{name}_times.txt", t, fmt="%.17g")
        return [str(d / f"{name}.raw"), "--line-times", str(d / f"{name}_times.txt"), *argv]
    files, rows = [], ["file,time_s" + (",band" if name == "rikola" else "")]
    for i, t in enumerate(FRAME_T_S):
        p = d / f"{name}_f{i}.raw"
        if name == "rikola":  # each band exposed 0.05 s after the previous
            bands = [render_frame(sensor, trajectory, t + 0.05 * b, terrain, b + 1) for b in (0, 1)]
            rows += [f"{p.name},{t + 0.05 * b!r},{b + 1}" for b in (0, 1)]
            write_envi(p, np.stack(bands, axis=-1))
        else:
            write_envi(p, render_frame(sensor, trajectory, t, terrain)[..., None])
            rows.append(f"{p.stem},{t!r}")
        files.append(str(p))
    (d / f"{name}_frames.csv").write_text("\n".join(rows) + "\n")
    return [*files, "--frame-times", str(d / f"{name}_frames.csv"), *argv]


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_model_orthorectifies_its_targets_within_one_gsd(scene, name):
    d, trajectory, terrain = scene
    argv = write_case(name, d, trajectory, terrain)
    out = d / f"{name}.nc"
    assert main(["orthorectify", *argv, "-o", str(out)]) == 0
    err = target_errors(out)
    assert np.all(np.isfinite(err)), f"{name}: a target not found in the output: {err}"
    rms = float(np.sqrt(np.mean(err**2)))
    assert rms <= GSD_M, f"{name}: targets {rms:.3f} m RMS off (1 GSD = {GSD_M} m): {err}"


def test_a_tiff_frame_gives_the_raster_of_the_same_envi_frame(tmp_path):
    """The frame reader takes a (Geo)TIFF as it takes an ENVI file: the same values (3 bands,
    one NaN) at the same pixels give the identical raster."""
    import rasterio
    import xarray as xr

    write_trajectory(tmp_path / "nav.csv", nav())
    values = np.random.default_rng(1).random((30, 40, 3)).astype(np.float32)
    values[5, 7, 1] = np.nan
    write_envi(tmp_path / "f.raw", values)
    with rasterio.open(
        tmp_path / "f.tif", "w", driver="GTiff", width=40, height=30, count=3, dtype="float32"
    ) as dst:
        dst.write(values.transpose(2, 0, 1))
    (tmp_path / "t.csv").write_text("file,time_s\nf,5.0\n")
    (tmp_path / "cv.toml").write_text(
        sensor_toml("frame-opencv", {"fx_px": 60.0, "fy_px": 60.0, "cx_px": 19.5, "cy_px": 14.5})
    )
    from ortho_inputs import SITE_ARGS

    common = ["--frame-times", str(tmp_path / "t.csv"), "--sensor", str(tmp_path / "cv.toml")]
    common += ["--trajectory", str(tmp_path / "nav.csv"), "--height", "0", *SITE_ARGS, "--quiet"]
    for f in ("f.raw", "f.tif"):
        out = tmp_path / f"{f}.nc"
        assert main(["orthorectify", str(tmp_path / f), *common, "-o", str(out)]) == 0
    a = xr.open_dataset(tmp_path / "f.raw.nc")["radiance"].values
    b = xr.open_dataset(tmp_path / "f.tif.nc")["radiance"].values
    assert a.shape[0] == 3 and np.isfinite(a).mean() > 0.5
    np.testing.assert_array_equal(a, b)
