"""``hsgeo lp-observations`` on the strips as a line scanner writes them (issue 38): ENVI cubes
(BIL, BIP and BSQ, little- and big-endian, a header offset, ``name.hdr`` and ``name.raw.hdr``,
``x start`` for a cube of some columns of the line, written here by an independent writer:
numpy ``tofile`` and a header by hand) with their line
times from a times file or the header's start time and line period give the very observation
table of the same strips as hsgeo's NetCDF LP line files. Bad input (a times file shorter than
the lines, a count of times files unlike the cubes', ``--line-times`` with NetCDF lines, a cube
without wavelengths, a header that disagrees with its file): one line, exit 2, nothing written.
"""

from __future__ import annotations

import hashlib

import numpy as np
import pandas as pd
import pytest

from hsgeo.cli import main

LAYOUTS = (  # (interleave, big-endian, header offset, header name, times file)
    ("bil", False, 0, "name.hdr", "plain"),
    ("bip", True, 128, "name.raw.hdr", "plain"),
    ("bsq", False, 16, "name.hdr", "csv"),
)


def _write_envi(path, lsb, wl_nm, *, interleave, big, offset, header, extra=""):
    """``lsb`` (line, sample, band) as a line scanner writes it: tofile after ``offset`` bytes
    and a header by hand (wavelengths in nm)."""
    order = {"bsq": (2, 0, 1), "bil": (0, 2, 1), "bip": (0, 1, 2)}[interleave]
    arr = np.ascontiguousarray(np.asarray(lsb, np.float32).transpose(order))
    arr = arr.astype(arr.dtype.newbyteorder(">" if big else "<"))
    with open(path, "wb") as fh:
        fh.write(b"\x00" * offset)
        arr.tofile(fh)
    hdr = path.with_suffix(".hdr") if header == "name.hdr" else path.parent / (path.name + ".hdr")
    n_l, n_s, n_b = lsb.shape
    hdr.write_text(
        f"ENVI\nsamples = {n_s}\nlines = {n_l}\nbands = {n_b}\nheader offset = {offset}\n"
        f"data type = 4\ninterleave = {interleave}\nbyte order = {int(big)}\n"
        "wavelength units = Nanometers\n"
        f"wavelength = {{{', '.join(repr(float(w)) for w in wl_nm)}}}\n" + extra
    )
    return hdr


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The strips of the rendered campaign (scale 0.05, seed 0) as NetCDF LP line files and
    as ENVI cubes in three layouts (each cube the strip's stored columns of the 1800-px line,
    ENVI's ``x start`` their first, 1-based), each with a times file (plain numbers, or a CSV
    with a t_s column) and the header's start time and line period; the navigation, the
    a-priori camera file and the squares."""
    from dataclasses import replace

    from hsgeo.io.lp_lines import write_lp_lines
    from hsgeo.io.navigation import write_trajectory
    from hsgeo.simulate.lp_campaign import simulate

    d = tmp_path_factory.mktemp("lp_envi")
    obs, _ = simulate(scale=0.05, rng=0)
    nc, envi, times = [], [], []
    for k, s in enumerate(obs.strips):
        il, big, off, hdr, tfrom = LAYOUTS[k % len(LAYOUTS)]
        s = replace(s, n_px_full=obs.n_px_full)
        write_lp_lines(d / f"{s.strip_id}.nc", s)
        nc.append(str(d / f"{s.strip_id}.nc"))
        raw = d / f"{s.strip_id}.raw"
        t = np.asarray(s.t_s, float)
        dt = np.diff(t)
        assert np.ptp(dt) < 1e-6 * dt.mean(), np.ptp(dt)  # regular lines: start + period
        extra = f"t0_s = {float(t[0])!r}\nline period_s = {float(t[-1] - t[0]) / (t.size - 1)!r}\n"
        extra += f"x start = {s.col0 + 1}\n"
        _write_envi(raw, s.lines, s.wavelengths_nm, interleave=il, big=big, offset=off,
                    header=hdr, extra=extra)  # fmt: skip
        envi.append(str(raw))
        tp = d / f"{s.strip_id}_times.txt"
        if tfrom == "csv":
            pd.DataFrame({"line": np.arange(t.size), "t_s": t}).to_csv(
                tp, index=False, float_format="%.17g"
            )
        else:
            tp.write_text("".join(f"{float(v)!r}\n" for v in t))
        times.append(str(tp))
    write_trajectory(d / "nav.csv", obs.navigation)
    cam = obs.camera
    la = ", ".join(f"{v:.6f}" for v in cam.lever_arm_m)
    (d / "cam.toml").write_text(
        f"[camera]\nn_bands = {len(cam.c_mm)}\npixel_mm = {cam.pixel_mm}\nc_mm = {cam.c_mm[0]}\n"
        f"x0_mm = {cam.x0_mm}\nlever_arm_m = [{la}]\n"
    )
    xyz = obs.square_xyz_m
    pd.DataFrame(
        {"point_id": list(obs.square_ids), "E_m": xyz[:, 0], "N_m": xyz[:, 1], "H_m": xyz[:, 2]}
    ).to_csv(d / "squares.csv", index=False, float_format="%.17g")
    return d, nc, envi, times


FULL = ("--line-pixels", "1800")  # the full line: the header says where the cube starts only


def _argv(d, lines, out, *extra):
    return [
        "lp-observations",
        *lines,
        "--trajectory",
        str(d / "nav.csv"),
        "--camera",
        str(d / "cam.toml"),
        "--squares",
        str(d / "squares.csv"),
        "--scene-lines",
        "100",
        "-o",
        str(out),
        *extra,
    ]


@pytest.mark.slow  # three retrievals of 20 strips: 11.5 min at load 17, 841 rows equal
def test_envi_cubes_give_the_netcdf_observation_table(files, capsys):
    """Every row of the observation table (point ids, bands, times, x, y, strips, lines) from
    the ENVI cubes with their times files equals the NetCDF lines' table exactly; with the
    headers' start time and line period instead, the same rows (times to 1e-9 s)."""
    d, nc, envi, times = files
    assert main(_argv(d, nc, d / "from_nc.parquet", "--json")) == 0, capsys.readouterr().err
    times_argv = [a for t in times for a in ("--line-times", t)]
    rc = main(_argv(d, envi, d / "from_envi.parquet", "--json", *FULL, *times_argv))
    assert rc == 0, capsys.readouterr().err
    a = pd.read_parquet(d / "from_nc.parquet")
    b = pd.read_parquet(d / "from_envi.parquet")
    n_points, n_strips = a["point_id"].nunique(), a["strip"].nunique()
    print(f"{len(a)} observations of {n_points} points in {n_strips} strips, identical")
    assert len(a) > 50 and a["strip"].nunique() >= 3
    pd.testing.assert_frame_equal(a, b)
    assert main(_argv(d, envi, d / "from_headers.parquet", "--json", *FULL)) == 0
    c = pd.read_parquet(d / "from_headers.parquet")
    pd.testing.assert_frame_equal(a, c, check_exact=False, rtol=0, atol=1e-9)


def _sha(d):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(d.iterdir())}


def _short_times(d, times):
    p = d / "short_times.txt"
    p.write_text("".join(open(times[0]).read().splitlines(keepends=True)[:-1]))
    return [a for t in (str(p), *times[1:]) for a in ("--line-times", t)]


def _copy_cube(d, envi, name, cut_bytes=0, drop_key=None):
    """A copy of the first cube (BIL, name.hdr) as ``name``, cut short or a header key dropped."""
    data = open(envi[0], "rb").read()
    (d / f"{name}.raw").write_bytes(data[: len(data) - cut_bytes])
    text = open(envi[0][:-4] + ".hdr").read().splitlines()
    keep = [ln for ln in text if drop_key is None or not ln.startswith(drop_key)]
    (d / f"{name}.hdr").write_text("\n".join(keep) + "\n")
    return str(d / f"{name}.raw")


BAD = {  # case: what the one line of stderr says
    "times-shorter-than-lines": "short_times.txt",
    "times-count-unlike-cubes": "one times file per ENVI cube",
    "times-for-netcdf-lines": "drop the times file",
    "cube-without-wavelengths": "no wavelength entry",
    "cube-cut-short": "cut short",
    "x-start-not-a-column": "x start",
}


@pytest.mark.parametrize("case", list(BAD))
def test_envi_scenes_bad_input_one_line_exit_2(files, capsys, case):
    d, nc, envi, times = files
    expect = BAD[case]
    out = d / "bad.parquet"
    lines, extra = list(envi), []
    if case == "times-shorter-than-lines":
        extra = _short_times(d, times)
    elif case == "times-count-unlike-cubes":
        extra = ["--line-times", times[0]]
    elif case == "times-for-netcdf-lines":
        lines = nc
        extra = [a for t in times for a in ("--line-times", t)]
    elif case == "cube-without-wavelengths":
        lines = [_copy_cube(d, envi, "nowl", drop_key="wavelength"), *envi[1:]]
    elif case == "cube-cut-short":
        lines = [_copy_cube(d, envi, "cut", cut_bytes=4), *envi[1:]]
    elif case == "x-start-not-a-column":
        q = _copy_cube(d, envi, "xs", drop_key="x start")
        with open(q[:-4] + ".hdr", "a") as f:
            f.write("x start = 0\n")
        lines = [q, *envi[1:]]
    before = _sha(d)
    rc = main(_argv(d, lines, out, *FULL, *extra))
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert expect in err and "\n" not in err and "Traceback" not in err, err
    assert not out.exists() and _sha(d) == before
