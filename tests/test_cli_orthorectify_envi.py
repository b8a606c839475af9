"""``hsgeo orthorectify`` on lines as line scanners write them (issue 38): ENVI cubes (written
here by an independent writer: numpy ``tofile`` and a header by hand) with their line times from a
times file or the header, and a view-angle sensor file whose table is computed here from the
analytic 002 camera."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from hsgeo.cli import main
from hsgeo.crs import SITE_AAS
from hsgeo.geocode import PlaneTerrain
from hsgeo.io import write_lines
from hsgeo.io.navigation import write_trajectory
from hsgeo.ortho import ground_points
from hsgeo.sensors import as_sensor
from hsgeo.sensors.line import CalibratedLine
from hsgeo.trajectory import Trajectory

CAL = CalibratedLine(486.8, 3539.0, (1.459, -0.1636, 0.00526))  # 000 Table 1
SITE = "59.665,10.775"  # the local-ENU navigation's origin, given explicitly
RATE_HZ = 8.0


def straight_nav(H=500.0, T=10.0, v=20.0):
    t = np.linspace(0, T, 401)
    EN = np.outer(v * t, [0.0, 1.0])
    rpy = np.column_stack([0.01 * np.sin(t), 0.005 * np.cos(t), np.zeros(t.size)])
    return Trajectory(t, np.column_stack([EN, np.full(t.size, H)]), rpy)


def write_envi(path, lsb, *, interleave="bil", big=False, offset=0, extra="", wl=True):
    """``lsb`` (line, sample, band) float32 as a line scanner writes it: tofile + a header."""
    order = {"bsq": (2, 0, 1), "bil": (0, 2, 1), "bip": (0, 1, 2)}[interleave]
    arr = np.ascontiguousarray(np.asarray(lsb, np.float32).transpose(order))
    arr = arr.astype(arr.dtype.newbyteorder(">" if big else "<"))
    with open(path, "wb") as fh:
        fh.write(b"\x00" * offset)
        arr.tofile(fh)
    n_b = lsb.shape[2]
    bands = ""
    if wl:
        bands = (
            "wavelength units = Micrometers\n"
            f"wavelength = {{{', '.join(f'{0.45 + 0.1 * k:.2f}' for k in range(n_b))}}}\n"
            f"fwhm = {{{', '.join(f'{0.005 + 0.001 * k:.3f}' for k in range(n_b))}}}\n"
        )
    path.with_suffix(".hdr").write_text(
        f"ENVI\nsamples = {lsb.shape[1]}\nlines = {lsb.shape[0]}\nbands = {n_b}\n"
        f"header offset = {offset}\ndata type = 4\ninterleave = {interleave}\n"
        f"byte order = {int(big)}\n" + bands + extra
    )


def _scene(tmp_path, n_lines=60):
    """The 000 line scanner over a plane 3 m high: each pixel records its own E and N; the
    lines as hsgeo's NetCDF and as an ENVI BIL cube (big-endian, 64-byte offset) with a
    times file. Returns the command line without LINES and -o."""
    nav = straight_nav()
    write_trajectory(tmp_path / "nav.csv", nav)
    zeta = np.arange(300.0)  # ENVI sample s is zeta = s
    t = np.arange(n_lines) / RATE_HZ
    g = ground_points(as_sensor(CAL), nav, t, zeta, PlaneTerrain(3.0))
    write_lines(
        tmp_path / "lines.nc", g[..., :2].transpose(2, 0, 1), zeta, t0_s=0.0, line_rate_hz=RATE_HZ
    )
    write_envi(tmp_path / "cube.raw", g[..., :2], big=True, offset=64)
    np.savetxt(tmp_path / "times.txt", t, fmt="%.17g")
    (tmp_path / "sensor.toml").write_text(
        "[sensor]\nmodel = 'calibrated'\nzeta0_px = 150.0\nc_px = 3539.0\n"
        "K = [1.459, -0.1636, 0.00526]\n"
    )
    argv = ["--trajectory", str(tmp_path / "nav.csv"), "--sensor", str(tmp_path / "sensor.toml")]
    argv += ["--height", "3", "--resolution", "0.5", "--site", SITE, "--quiet"]
    argv += ["--crs", SITE_AAS.local_crs()]
    return argv, t


def test_an_envi_cube_gives_the_netcdf_lines_raster(tmp_path):
    """The same lines as an ENVI cube (times file, or header start time + line period; the
    header named name.hdr or name.raw.hdr; given as .raw, .hdr or bare name) orthorectify to
    the very raster of hsgeo's NetCDF lines, and the header's wavelengths (µm) and FWHM reach
    the output in nm."""
    argv, t = _scene(tmp_path)
    # the NetCDF lines hold CAL's geometry with zeta0 = 486.8; the sensor file says 150:
    # both LINES are read with the same sensor file, so the rasters must agree exactly
    assert (
        main(["orthorectify", str(tmp_path / "lines.nc"), *argv, "-o", str(tmp_path / "a.nc")]) == 0
    )
    times = ["--line-times", str(tmp_path / "times.txt")]
    assert (
        main(
            [
                "orthorectify",
                str(tmp_path / "cube.raw"),
                *argv,
                *times,
                "-o",
                str(tmp_path / "b.nc"),
            ]
        )
        == 0
    )
    a, b = xr.open_dataset(tmp_path / "a.nc"), xr.open_dataset(tmp_path / "b.nc")
    va, vb = a["radiance"].values, b["radiance"].values
    assert np.isfinite(vb).mean() > 0.5
    np.testing.assert_array_equal(va, vb)
    np.testing.assert_allclose(b["band"].values, [450.0, 550.0])  # nm
    np.testing.assert_allclose(b["fwhm"].values, [5.0, 6.0])  # nm
    # the header's start time and line period instead of the times file; header name.raw.hdr
    (tmp_path / "cube.hdr").rename(tmp_path / "cube.raw.hdr")
    with open(tmp_path / "cube.raw.hdr", "a") as f:
        f.write(f"t0_s = 0.0\nline period_s = {1 / RATE_HZ!r}\n")
    assert (
        main(["orthorectify", str(tmp_path / "cube.raw.hdr"), *argv, "-o", str(tmp_path / "c.nc")])
        == 0
    )
    np.testing.assert_array_equal(xr.open_dataset(tmp_path / "c.nc")["radiance"].values, va)


def test_envi_lines_refused_by_name(tmp_path, capsys):
    """A times file shorter than the lines, --line-times for NetCDF lines, a count of times
    files unlike the cubes', a mix of ENVI and NetCDF LINES, and a cube of some columns of a
    wider line (header ``x start`` > 1: its samples are not the sensor's pixels 0…n−1): exit
    2, the file named."""
    argv, t = _scene(tmp_path, n_lines=20)
    np.savetxt(tmp_path / "short.txt", t[:-1])
    cube, nc = str(tmp_path / "cube.raw"), str(tmp_path / "lines.nc")
    (tmp_path / "part.raw").write_bytes((tmp_path / "cube.raw").read_bytes())
    (tmp_path / "part.hdr").write_text((tmp_path / "cube.hdr").read_text() + "x start = 101\n")
    out = ["-o", str(tmp_path / "o.nc")]
    times = ["--line-times", str(tmp_path / "times.txt")]
    cases = [
        ([str(tmp_path / "part.raw"), *argv, *times], "x start = 101"),
        ([cube, *argv, "--line-times", str(tmp_path / "short.txt")], "short.txt"),
        ([nc, *argv, "--line-times", str(tmp_path / "times.txt")], "--line-times"),
        ([cube, *argv], "no line times"),
        ([cube, nc, *argv], "mixes ENVI"),
        (
            [
                cube,
                *argv,
                "--line-times",
                str(tmp_path / "times.txt"),
                "--line-times",
                str(tmp_path / "times.txt"),
            ],
            "one times file per cube",
        ),
    ]
    for args, words in cases:
        assert main(["orthorectify", *args, *out]) == 2
        err = capsys.readouterr().err
        assert words in err and "Traceback" not in err
    assert not (tmp_path / "o.nc").exists()


# --- the view-angle sensor: a table computed from the analytic 002 camera -------------------

CAMERA = (
    "[camera]\nn_bands = 2\npixel_mm = 0.0065\nc_mm = 40.0\nc_band_mm = [36.0, 40.0]\n"
    "x0_mm = 0.01\ndistortion = [-4.0e-5, 3.0e-7, 2.5e-5, -3.0e-5]\n"
    "boresight_deg = [0.2, -0.1, 0.3]\nlever_arm_m = [0.1, 0.0, -0.2]\n"
)


def view_angles_of(camera, n_px, nav):
    """Each pixel's across- and along-track view angles (rad), one row per camera band, and
    the lever arm in the body frame: the camera's rays turned into the body frame here (its
    sample s is x = s − (n − 1)/2 px, y = 0), so that d_body = (tan β, tan α, 1)·z."""
    x = np.arange(n_px) - (n_px - 1) / 2.0
    t = np.full(n_px, 1.0)
    R = nav.R_map_from_body(t)
    across, along = [], []
    for b in range(len(camera.c_mm)):
        _, d = camera.rays(np.column_stack([x, np.zeros(n_px)]), t, nav, band=b)
        db = np.einsum("nji,nj->ni", R, d)  # R^T d: the body frame
        across.append(np.arctan2(db[:, 1], db[:, 2]))
        along.append(np.arctan2(db[:, 0], db[:, 2]))
    return np.array(across), np.array(along), np.asarray(camera.mount.lever_arm_m, float)


def test_a_view_angle_table_of_the_002_camera_places_every_pixel_as_the_camera(tmp_path):
    """A view-angle sensor file (one table per band, degrees written in full) computed from
    the analytic camera: the ground points of every pixel agree within 1e-6 m, and the
    command's rasters are the same cells with the same values."""
    from hsgeo.io import read_sensor
    from hsgeo.sensors.pushbroom import PushbroomCamera

    nav = straight_nav()
    write_trajectory(tmp_path / "nav.csv", nav)
    (tmp_path / "camera.toml").write_text(CAMERA)
    cam = read_sensor(tmp_path / "camera.toml")
    assert isinstance(cam, PushbroomCamera)
    n_px, n_lines = 240, 50
    across, along, lever = view_angles_of(cam, n_px, nav)
    rows = ["band,pixel,across_deg,along_deg"]
    for b in range(across.shape[0]):
        for p in range(n_px):
            rows.append(
                f"{b},{p},{float(np.rad2deg(across[b, p]))!r},{float(np.rad2deg(along[b, p]))!r}"
            )
    (tmp_path / "angles.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "va.toml").write_text(
        "[sensor]\nmodel = 'view-angle'\n"
        f"angles_csv = {str(tmp_path / 'angles.csv')!r}\n"
        f"lever_arm_m = [{', '.join(repr(float(v)) for v in lever)}]\n"
    )
    va = read_sensor(tmp_path / "va.toml")
    t = np.arange(n_lines) / RATE_HZ
    x = np.arange(n_px) - (n_px - 1) / 2.0
    g_cam = ground_points(cam, nav, t, np.column_stack([x, 0 * x]), PlaneTerrain(3.0), band=1)
    g_va = ground_points(va, nav, t, np.arange(n_px, dtype=float), PlaneTerrain(3.0), band=1)
    assert np.max(np.abs(g_cam - g_va)) < 1e-6
    # through the command: an ENVI cube of 2 bands recording each pixel's own E, N
    write_envi(tmp_path / "cube.dat", g_cam[..., :2], interleave="bip")
    np.savetxt(tmp_path / "times.txt", t, fmt="%.17g")
    base = [str(tmp_path / "cube.dat"), "--trajectory", str(tmp_path / "nav.csv")]
    base += ["--line-times", str(tmp_path / "times.txt"), "--height", "3", "--site", SITE]
    base += ["--resolution", "0.5", "--crs", SITE_AAS.local_crs(), "--quiet"]
    for s, o in (("camera.toml", "cam.nc"), ("va.toml", "va.nc")):
        assert (
            main(["orthorectify", *base, "--sensor", str(tmp_path / s), "-o", str(tmp_path / o)])
            == 0
        )
    a, b = (xr.open_dataset(tmp_path / o)["radiance"] for o in ("cam.nc", "va.nc"))
    np.testing.assert_array_equal(a["x"].values, b["x"].values)
    np.testing.assert_array_equal(a["y"].values, b["y"].values)
    np.testing.assert_array_equal(a.values, b.values)
    ok = np.isfinite(b.values[0])
    assert ok.mean() > 0.5
    X = np.broadcast_to(b["x"].values, ok.shape)
    assert np.max(np.abs(b.values[0][ok] - X[ok])) <= b.attrs["radius_of_influence_m"]


def test_a_view_angle_table_with_the_wrong_pixel_count_is_refused(tmp_path, capsys):
    nav = straight_nav()
    write_trajectory(tmp_path / "nav.csv", nav)
    a = np.linspace(-0.2, 0.2, 100)
    rows = ["pixel,across_deg,along_deg"] + [
        f"{i},{float(np.rad2deg(v))!r},0.0" for i, v in enumerate(a)
    ]
    (tmp_path / "angles.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "va.toml").write_text(
        f"[sensor]\nmodel = 'view-angle'\nangles_csv = {str(tmp_path / 'angles.csv')!r}\n"
    )
    write_envi(tmp_path / "cube.raw", np.ones((10, 120, 1)), extra="t0_s = 0\nline_rate_hz = 8\n")
    argv = ["orthorectify", str(tmp_path / "cube.raw"), "--sensor", str(tmp_path / "va.toml")]
    argv += ["--trajectory", str(tmp_path / "nav.csv"), "--height", "3", "--site", SITE]
    assert main([*argv, "--quiet", "-o", str(tmp_path / "o.nc")]) == 2
    err = capsys.readouterr().err
    assert "120 samples" in err and "100 pixels" in err


@pytest.mark.parametrize("interleave", ["bil", "bip", "bsq"])
def test_every_interleave_gives_the_same_raster(tmp_path, interleave):
    argv, t = _scene(tmp_path, n_lines=24)
    nav = straight_nav()
    zeta = np.arange(300.0)
    g = ground_points(as_sensor(CAL), nav, t, zeta, PlaneTerrain(3.0))
    write_envi(
        tmp_path / "x.bil",
        g[..., :2],
        interleave=interleave,
        extra=f"t0_s = 0\nline_rate_hz = {RATE_HZ}\n",
    )
    assert (
        main(["orthorectify", str(tmp_path / "lines.nc"), *argv, "-o", str(tmp_path / "a.nc")]) == 0
    )
    assert main(["orthorectify", str(tmp_path / "x.bil"), *argv, "-o", str(tmp_path / "b.nc")]) == 0
    np.testing.assert_array_equal(
        xr.open_dataset(tmp_path / "a.nc")["radiance"].values,
        xr.open_dataset(tmp_path / "b.nc")["radiance"].values,
    )
