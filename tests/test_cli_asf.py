"""``hsgeo asf`` on a small simulated runway campaign: the recovered ASF against the truth, from
raw scans (georegistered by the command) and from scans georegistered elsewhere; and hostile
input (issue 42): one clear line and exit 2, never a traceback or a silent answer."""

import json
import shutil

import numpy as np
import pytest
import xarray as xr
from asf_inputs import raw_argv, true_asf_normalised, write_asf_inputs

from hsgeo.cli import main


@pytest.fixture(scope="module")
def asf_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("asf")
    info = write_asf_inputs(d)
    return d, info


def test_asf_command_recovers_the_true_asf(asf_dir, capsys):
    d, info = asf_dir
    rc = main([
        "asf", str(d / "cross.nc"), str(d / "along.nc"), "--runway", str(d / "runway.csv"),
        "--json",
    ])  # fmt: skip
    out = capsys.readouterr()
    assert rc == 0, out.err
    res = json.loads(out.out)
    asf = np.array(res["asf"], float)
    tr = info["truth"]
    ref = true_asf_normalised(tr)
    assert ref.shape == asf.shape
    usable = np.array(res["usable"])
    assert usable.all()
    assert np.nanmax(np.abs(asf - ref)[:, usable]) < 0.01
    shift = np.array(res["registration"]["shift_m"])
    assert np.all(np.abs(shift - tr.shift_m) < 0.1)


def test_asf_command_from_raw_scans_georegisters_them(asf_dir, capsys):
    """The raw scans, the sensor file and the navigation give the same ASF as the scans
    georegistered beforehand (the same georegistration, done by the command)."""
    d, info = asf_dir
    rc = main(raw_argv(d, "--json"))
    out = capsys.readouterr()
    assert rc == 0, out.err
    raw = json.loads(out.out)
    rc = main(["asf", str(d / "cross.nc"), str(d / "along.nc"), "--runway", str(d / "runway.csv"),
               "--json"])  # fmt: skip
    geo = json.loads(capsys.readouterr().out)
    a, b = np.array(raw["asf"], float), np.array(geo["asf"], float)
    assert np.nanmax(np.abs(a - b)) < 1e-4  # the georegistered files hold float32 values
    ref = true_asf_normalised(info["truth"])
    assert np.nanmax(np.abs(a - ref)) < 0.01


def test_asf_command_combines_two_opposite_crossings(asf_dir, capsys):
    d, info = asf_dir
    rc = main(raw_argv(d, "--reverse", str(d / "reverse_raw.nc"), "--json"))
    out = capsys.readouterr()
    assert rc == 0, out.err
    res = json.loads(out.out)
    comb = np.array(res["combined"]["asf"], float)
    tr = info["truth"]
    ref = true_asf_normalised(tr)
    assert np.nanmax(np.abs(comb - ref)) < 0.01
    assert np.nanmax(np.abs(np.array(res["combined"]["brdf_odd"], float) - 1)) < 0.01
    rc = main(raw_argv(d, "--reverse", str(d / "reverse_raw.nc")))
    text = capsys.readouterr().out
    assert rc == 0 and "two opposite crossings combined" in text


def test_asf_files_returns_one_result_type_for_every_input(asf_dir):
    """The file front end's one result shape: georegistered scans and raw scans (with and
    without the reverse crossing) all give a FlightsResult whose to_dict has the same keys."""
    from hsgeo.workflows.asf_flights import FlightsResult, asf_files

    d, _ = asf_dir
    geo = asf_files(d / "cross.nc", d / "along.nc", d / "runway.csv")
    argv = raw_argv(d)
    kw = {"sensor_path": argv[argv.index("--sensor") + 1]}
    kw["trajectory_path"] = argv[argv.index("--trajectory") + 1]
    raw = asf_files(argv[1], argv[2], argv[argv.index("--runway") + 1], **kw)
    for res in (geo, raw):
        assert type(res) is FlightsResult and res.reverse is None and res.brdf_odd is None
        assert res.asf is res.cross.asf and res.usable is res.cross.usable
        assert set(res.geo) == {"cross", "along"}
    assert geo.to_dict().keys() == raw.to_dict().keys() == geo.cross.to_dict().keys()


def test_asf_command_prints_a_table(asf_dir, capsys):
    d, _ = asf_dir
    rc = main(["asf", str(d / "cross.nc"), str(d / "along.nc"), "--runway", str(d / "runway.csv")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "registration" in out and "columns usable" in out and "scan_angle_deg" in out


# --- hostile input (issue 42) ------------------------------------------------------------------


def _nc(name, fn):
    def edit(d):
        p = d / name
        with xr.open_dataset(p) as ds:
            new = fn(ds.load())
        p.unlink()
        new.to_netcdf(p, engine="scipy")

    return edit


def _csv_rows(fn):
    def edit(d):
        p = d / "runway.csv"
        head, *rows = p.read_text().splitlines()
        p.write_text("\n".join([head, *fn(rows)]) + "\n")

    return edit


def _geo(d, cross="cross.nc", along="along.nc"):
    return ["asf", str(d / cross), str(d / along), "--runway", str(d / "runway.csv")]


def _swap12(rows):
    rows = list(rows)
    rows[1], rows[2] = rows[2], rows[1]
    return rows


def _sensor_radians(d):
    p = d / "sensor.toml"
    lines = p.read_text().splitlines()
    out = [f"ifov_deg = {np.deg2rad(0.12):.6g}" if x.startswith("ifov_deg") else x for x in lines]
    p.write_text("\n".join(out) + "\n")


def _nav_late(d):
    p = d / "nav.csv"
    head, *rows = p.read_text().splitlines()
    rows = [",".join([str(float(r.split(",")[0]) + 1000.0), *r.split(",")[1:]]) for r in rows]
    p.write_text("\n".join([head, *rows]) + "\n")


HOSTILE = {
    "scan-angle-in-radians": (
        _nc("cross.nc", lambda ds: ds.assign(scan_angle_deg=np.deg2rad(ds["scan_angle_deg"]))),
        _geo, "radians",
    ),
    "scan-angle-in-pixels": (
        _nc("cross.nc", lambda ds: ds.assign(scan_angle_deg=ds["scan_angle_deg"] / 0.12)),
        _geo, "px",
    ),
    "negative-radiance": (
        _nc("cross_raw.nc", lambda ds: ds.assign(radiance=ds["radiance"] - 0.3)),
        raw_argv, "negative",
    ),
    "negative-reflectance": (
        _nc("along.nc", lambda ds: ds.assign(reflectance=-ds["reflectance"])),
        _geo, "negative",
    ),
    "same-file-twice": (None, lambda d: _geo(d, along="cross.nc"), "same file"),
    "same-scan-twice": (
        lambda d: shutil.copy(d / "cross.nc", d / "along.nc"), _geo, "same samples",
    ),
    "scans-swapped": (None, lambda d: _geo(d, "along.nc", "cross.nc"), "swapped"),
    "along-shifted-40-m": (
        _nc("along.nc", lambda ds: ds.assign(E_m=ds["E_m"] + 40.0)), _geo, "do not match",
    ),
    "runway-corners-swapped": (_csv_rows(_swap12), _geo, "not in order"),
    "wrong-shape-E_m": (
        _nc("cross.nc", lambda ds: ds.assign(E_m=ds["E_m"].isel(line=0))),
        _geo, "E_m must have dimensions (line, pixel)",
    ),
    "wrong-dims-E_m": (
        _nc("along.nc", lambda ds: ds.assign(
            E_m=(("y", "x"), ds["E_m"].values))), _geo, "E_m must have dimensions",
    ),
    "sensor-without-trajectory": (
        None, lambda d: raw_argv(d)[:-2], "--trajectory",
    ),
    "sensor-ifov-in-radians": (_sensor_radians, raw_argv, "radians"),
    "navigation-not-covering": (_nav_late, raw_argv, "not covered by the navigation"),
    "raw-scan-without-sensor": (
        None, lambda d: _geo(d, "cross_raw.nc", "along_raw.nc"), "--sensor",
    ),
}  # fmt: skip


@pytest.mark.parametrize("name", list(HOSTILE))
def test_hostile_input_is_one_clear_error(name, asf_dir, tmp_path, capsys):
    src, _ = asf_dir
    d = tmp_path / "in"
    shutil.copytree(src, d)
    edit, argv, expect = HOSTILE[name]
    if edit is not None:
        edit(d)
    rc = main(argv(d))
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert rc == 2, out.err[-2000:] + out.out[-500:]
    assert len(lines) == 1 and "Traceback" not in out.err, out.err
    assert expect.lower() in lines[0].lower(), lines[0]
    assert out.out == ""


def test_runway_closed_by_repeating_its_first_corner_is_accepted(asf_dir, tmp_path, capsys):
    src, _ = asf_dir
    d = tmp_path / "in"
    shutil.copytree(src, d)
    _csv_rows(lambda rows: [*rows, rows[0]])(d)
    rc = main(_geo(d) + ["--json"])
    out = capsys.readouterr()
    assert rc == 0, out.err
    assert json.loads(out.out)["usable"]
