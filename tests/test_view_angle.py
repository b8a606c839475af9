"""The view-angle sensor (issue 38): per-pixel across/along angles from a CSV beside the sensor
file, one table or one per band; checked against the 000 linear-IFOV line scanner (other code)
and for its bad inputs. The registry's template (tests/test_sensor_registry.py) covers it too."""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo.errors import HsgeoError, InputError
from hsgeo.io import read_sensor
from hsgeo.io.sensor_file import model_of
from hsgeo.sensors.line import LinearIFOV, LineScanner
from hsgeo.sensors.mount import Mount
from hsgeo.trajectory import Trajectory

N_PX = 200
MOUNT = "lever_arm_m = [0.3, -0.2, 0.5]\nboresight_deg = [0.4, -0.3, 0.8]\n"


def nav():
    t = np.linspace(0.0, 20.0, 2001)
    xyz = np.column_stack([50.0 * t, 5.0 * t, 1200.0 + np.sin(0.3 * t)])
    rph = np.column_stack([0.02 * np.sin(0.7 * t), 0.01 * np.cos(0.5 * t), 0.1 + 0 * t])
    return Trajectory(t, xyz, rph)


def write_sensor(tmp_path, rows, header="pixel,across_deg,along_deg", csv="angles.csv"):
    (tmp_path / csv).write_text(
        header + "\n" + "".join(",".join(map(repr, r)) + "\n" for r in rows)
    )
    p = tmp_path / "sensor.toml"
    p.write_text(f'[sensor]\nmodel = "view-angle"\nangles_csv = "{csv}"\n' + MOUNT)
    return p


def linear_rows(zeta0=99.5, c=400.0):
    z = np.arange(N_PX)
    return [(int(i), float(np.rad2deg(-(i - zeta0) / c)), 0.0) for i in z]


def test_equals_linear_ifov_line_scanner_at_whole_pixels(tmp_path):
    s = read_sensor(write_sensor(tmp_path, linear_rows()))
    assert model_of(s) == "view-angle" and s.n_px == N_PX and s.n_bands == 1
    ref = LineScanner(
        LinearIFOV(99.5, 400.0), Mount.from_rpy(np.deg2rad([0.4, -0.3, 0.8]), [0.3, -0.2, 0.5])
    )
    zeta = np.arange(0, N_PX, 7.0)
    t = np.linspace(1, 19, zeta.size)
    o, d = s.rays(zeta, t, nav())
    o2, d2 = ref.rays(zeta, t, nav())
    np.testing.assert_allclose(o, o2, atol=1e-9)
    np.testing.assert_allclose(d, d2, atol=1e-12)


def test_per_band_tables_round_trip_and_line_time(tmp_path):
    rows = []
    for b in range(3):  # keystone: each band shifted, smile: along angle per band
        for i in range(N_PX):
            a = -15.0 + 30.0 * i / (N_PX - 1) + 0.02 * b
            rows.append((i, a, 0.01 * b + 0.03 * (a / 15.0) ** 2, b))
    s = read_sensor(write_sensor(tmp_path, rows, "pixel,across_deg,along_deg,band"))
    assert s.n_bands == 3
    rng = np.random.default_rng(0)
    n = 40
    zeta, t, band = rng.uniform(0, N_PX - 1, n), rng.uniform(2, 18, n), rng.integers(0, 3, n)
    o, d = s.rays(zeta, t, nav(), band=band)
    X = o + rng.uniform(800, 1500, n)[:, None] * d
    px = s.project(X, t, nav(), band=band)
    np.testing.assert_allclose(px[:, 0], zeta, atol=1e-8)
    np.testing.assert_allclose(px[:, 1], 0.0, atol=1e-8)
    # the band matters: band 0's pixel of a band-2 ray is elsewhere
    assert np.max(np.abs(s.project(X, t, nav(), band=0)[:, 0] - zeta)[band == 2]) > 0.1
    t_found = s.line_time(X, nav(), t + 0.3, band=band)
    np.testing.assert_allclose(t_found, t, atol=1e-7)
    with pytest.raises(InputError, match="one table per band"):
        s.rays(zeta, t, nav())


def test_pixel_count_must_match_the_lines(tmp_path):
    s = read_sensor(write_sensor(tmp_path, linear_rows()))
    s.check_samples(N_PX)
    with pytest.raises(InputError, match=f"384 samples per line, the view-angle table {N_PX}"):
        s.check_samples(384, "ENVI file 'x.raw'")


@pytest.mark.parametrize(
    "case, match",
    [
        ("missing", "pixel 17 is missing"),
        ("one_based", "pixel 0 is missing.*0-based"),
        ("twice", "pixel 5 appears twice"),
        ("radians", "radians"),
        ("not_monotone", "strictly monotonically"),
        ("no_column", "along_deg"),
        ("band_missing", r"band\(s\) \[1\] missing"),
    ],
)
def test_bad_tables(tmp_path, case, match):
    rows = linear_rows()
    header = "pixel,across_deg,along_deg"
    if case == "missing":
        rows = rows[:17] + rows[18:]
    elif case == "one_based":
        rows = [(i + 1, a, b) for i, a, b in rows]
    elif case == "twice":
        rows = rows + [rows[5]]
        rows[-1] = (5, rows[5][1] + 0.001, 0.0)
    elif case == "radians":
        rows = [(i, float(np.deg2rad(a)), b) for i, a, b in rows]
    elif case == "not_monotone":
        rows[50] = (50, rows[48][1], 0.0)
    elif case == "no_column":
        rows, header = [(i, a) for i, a, _ in rows], "pixel,across_deg"
    elif case == "band_missing":
        rows, header = [(i, a, b, 2 * (i % 2)) for i, a, b in rows], header + ",band"
    with pytest.raises(HsgeoError, match=match) as e:
        read_sensor(write_sensor(tmp_path, rows, header))
    assert "angles.csv" in str(e.value) or "sensor.toml" in str(e.value)


def test_csv_or_lists_not_both(tmp_path):
    p = write_sensor(tmp_path, linear_rows())
    p.write_text(p.read_text() + "across_deg = [-1.0, 1.0]\n")
    with pytest.raises(InputError, match="either as angles_csv"):
        read_sensor(p)
    p.write_text('[sensor]\nmodel = "view-angle"\n')
    with pytest.raises(InputError, match="either as angles_csv"):
        read_sensor(p)
    p.write_text('[sensor]\nmodel = "view-angle"\nangles_csv = "nothing.csv"\n')
    with pytest.raises(InputError, match="nothing.csv"):
        read_sensor(p)
