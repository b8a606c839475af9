"""ENVI line cubes as line scanners write them (issue 38): files written here by an
independent writer (numpy ``tofile`` + a hand-written header), read by hsgeo.io."""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo.errors import HsgeoError, InputError
from hsgeo.io import open_envi, open_line_strip, read_envi, read_line_cube

N_L, N_S, N_B = 5, 4, 3
WL_NM = np.array([450.0, 550.5, 870.25])


def _cube(dtype="float32"):
    """(line, sample, band) values, distinct everywhere."""
    v = np.arange(N_L * N_S * N_B, dtype=float).reshape(N_L, N_S, N_B) + 1.5
    return v.astype(dtype)


def _write(
    tmp_path,
    name,
    lsb,
    *,
    interleave="bil",
    big=False,
    offset=0,
    hdr_name=None,
    extra="",
    dtype_code=4,
):
    """Write ``lsb`` as an ENVI file the way a line scanner does: tofile + a header by hand."""
    order = {"bsq": (2, 0, 1), "bil": (0, 2, 1), "bip": (0, 1, 2)}[interleave]
    arr = np.ascontiguousarray(lsb.transpose(order))
    arr = arr.astype(arr.dtype.newbyteorder(">" if big else "<"))
    p = tmp_path / name
    with open(p, "wb") as fh:
        fh.write(b"\x07" * offset)
        arr.tofile(fh)
    hdr = tmp_path / (hdr_name or (p.stem + ".hdr"))
    hdr.write_text(
        "ENVI\n"
        "description = {a line scanner's cube}\n"
        f"samples = {lsb.shape[1]}\nlines = {lsb.shape[0]}\nbands = {lsb.shape[2]}\n"
        f"header offset = {offset}\nfile type = ENVI Standard\ndata type = {dtype_code}\n"
        f"interleave = {interleave}\nbyte order = {int(big)}\n"
        "wavelength = {\n 450.0, 550.5,\n 870.25}\n"
        "wavelength units = Nanometers\nfwhm = {5.0, 6.0, 7.0}\n" + extra
    )
    return p, hdr


@pytest.mark.parametrize("interleave", ["bil", "bip", "bsq"])
@pytest.mark.parametrize("big", [False, True])
@pytest.mark.parametrize("offset", [0, 512])
def test_round_trip_layouts(tmp_path, interleave, big, offset):
    v = _cube()
    p, hdr = _write(tmp_path, "line.raw", v, interleave=interleave, big=big, offset=offset)
    cube = open_envi(p)
    assert isinstance(cube.raw, np.memmap)  # lazily mapped, not read
    np.testing.assert_array_equal(cube.lsb, v)
    data, h = read_envi(hdr)  # the header, ENVI's name.hdr
    np.testing.assert_array_equal(data, v.transpose(2, 0, 1))
    np.testing.assert_array_equal(h["wavelength_nm"], WL_NM)
    # the independent reader agrees (Spectral Python)
    import spectral.io.envi as envi

    ref = envi.open(str(hdr), str(p)).load()
    np.testing.assert_array_equal(np.asarray(ref), v)


@pytest.mark.parametrize("ext", ["", ".raw", ".dat", ".img"])
def test_naming_name_hdr_and_name_ext_hdr(tmp_path, ext):
    v = _cube("uint16")
    p, hdr = _write(tmp_path, "strip" + ext, v, dtype_code=12)
    for given in (p, hdr, tmp_path / "strip"):
        assert open_envi(given).data_path == p
    # GDAL's / hsgeo's naming name.ext.hdr
    p2, hdr2 = _write(tmp_path, "other" + ext, v, dtype_code=12, hdr_name="other" + ext + ".hdr")
    if ext:
        np.testing.assert_array_equal(open_envi(p2).lsb, v)
        np.testing.assert_array_equal(open_envi(hdr2).lsb, v)


def test_two_different_headers_refused(tmp_path):
    p, hdr = _write(tmp_path, "a.raw", _cube())
    (tmp_path / "a.raw.hdr").write_text(hdr.read_text().replace("bil", "bsq"))
    with pytest.raises(InputError, match="two different headers"):
        open_envi(p)


def test_read_line_cube_nodata_units_and_times(tmp_path):
    v = _cube()
    v[2, 1, 0] = -9999.0
    extra = "data ignore value = -9999\nstart time_s = 1000.5\nline period_s = 0.01\n"
    p, hdr = _write(tmp_path, "l.dat", v, extra=extra)
    hdr.write_text(
        hdr.read_text()
        .replace("Nanometers", "Micrometers")
        .replace("450.0, 550.5", "0.45, 0.5505")
        .replace("870.25", "0.87025")
    )
    da, info = read_line_cube(p)
    assert da.dims == ("line", "sample", "band") and da.dtype == np.float32
    np.testing.assert_allclose(da["wavelength_nm"], WL_NM)
    np.testing.assert_allclose(da["fwhm_nm"], [5000.0, 6000.0, 7000.0])
    np.testing.assert_allclose(da["t_s"], 1000.5 + 0.01 * np.arange(N_L))
    out = da.values
    assert np.isnan(out[2, 1, 0]) and np.isnan(out).sum() == 1
    np.testing.assert_array_equal(out[~np.isnan(out)], v[~np.isnan(out)])
    assert info["ignore_value"] == -9999.0 and info["format"] == "envi"
    strip = open_line_strip(p)
    assert strip.n_lines == N_L and strip.n_px_full == N_S


def test_times_files(tmp_path):
    p, _ = _write(tmp_path, "l.raw", _cube())
    t = 3600.0 + 0.005 * np.arange(N_L)
    plain = tmp_path / "times.txt"
    plain.write_text("\n".join(repr(float(x)) for x in t) + "\n")
    np.testing.assert_array_equal(read_line_cube(p, plain)[0]["t_s"], t)
    csv = tmp_path / "times.csv"
    csv.write_text("line,t_s\n" + "".join(f"{i},{float(x)!r}\n" for i, x in enumerate(t)))
    np.testing.assert_array_equal(read_line_cube(p, csv)[0]["t_s"], t)
    # from the header: a clock and a line rate
    hdr = tmp_path / "l.hdr"
    hdr.write_text(hdr.read_text() + "GPS Start Time = UTC TIME: 10:32:14.5\nfps = 200\n")
    np.testing.assert_allclose(read_line_cube(p)[0]["t_s"], 37934.5 + 0.005 * np.arange(N_L))


@pytest.mark.parametrize(
    "text, match",
    [
        ("1\n2\n3\n4\n", "4 times for a cube of 5 lines"),
        ("1\n2\n3\n4\n5\n6\n", "6 times for a cube of 5 lines"),
        ("1\n2\n2\n4\n5\n", "line 3: time 2.0 s does not increase"),
        ("1\n2\nnan\n4\n5\n", "line 3"),
        ("1\n2\nabc\n4\n5\n", "line 3"),
        ("time\n1\n2\n3\n4\n5\n", "without a 't_s' column"),
    ],
)
def test_bad_times_file(tmp_path, text, match):
    p, _ = _write(tmp_path, "l.raw", _cube())
    f = tmp_path / "t.txt"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as e:
        read_line_cube(p, f)
    assert "t.txt" in str(e.value)


def test_no_header_times(tmp_path):
    p, _ = _write(tmp_path, "l.raw", _cube())
    with pytest.raises(InputError, match="no line times: give a times file"):
        read_line_cube(p)


def _bad(tmp_path, what):
    p, hdr = _write(tmp_path, "bad.raw", _cube())
    if what == "truncated":
        p.write_bytes(p.read_bytes()[:-10])
    elif what == "sizes":
        hdr.write_text(hdr.read_text().replace("lines = 5", "lines = 6"))
    elif what == "dtype":
        hdr.write_text(hdr.read_text().replace("data type = 4", "data type = 6"))
    elif what == "nohdr":
        hdr.unlink()
    elif what == "units":
        hdr.write_text(hdr.read_text().replace("wavelength units = Nanometers\n", ""))
        hdr.write_text(hdr.read_text().replace("450.0", "10.0"))
    elif what == "wlcount":
        hdr.write_text(hdr.read_text().replace("fwhm = {5.0, 6.0, 7.0}", "fwhm = {5.0}"))
    elif what == "interleave":
        hdr.write_text(hdr.read_text().replace("interleave = bil", "interleave = bxl"))
    return p


@pytest.mark.parametrize(
    "what, match",
    [
        ("truncated", "cut short.*holds 4 whole lines"),
        ("sizes", "cut short"),
        ("dtype", "data type = 6"),
        ("nohdr", "no header beside it"),
        ("units", "wavelength units not given"),
        ("wlcount", "fwhm has 1 values for 3 bands"),
        ("interleave", "interleave = 'bxl' unknown"),
    ],
)
def test_bad_cubes(tmp_path, what, match):
    p = _bad(tmp_path, what)
    with pytest.raises(HsgeoError, match=match) as e:
        open_envi(p)
    assert "bad." in str(e.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        open_envi(tmp_path / "nothing")


def test_netcdf_lines_by_suffix(tmp_path):
    from hsgeo.io import LpStrip, write_lp_lines

    v = _cube()
    strip = LpStrip(v, 10.0 + np.arange(N_L) * 0.1, 2, WL_NM, "s1", n_px_full=10)
    write_lp_lines(tmp_path / "s1.nc", strip)
    da, info = read_line_cube(tmp_path / "s1.nc")
    np.testing.assert_array_equal(da.values, v)
    assert info["format"] == "netcdf" and info["col0"] == 2
    np.testing.assert_array_equal(open_line_strip(tmp_path / "s1.nc").t_s, strip.t_s)
    with pytest.raises(InputError, match="carries its own line times"):
        read_line_cube(tmp_path / "s1.nc", [1, 2, 3, 4, 5])


def test_read_line_cube_is_lazy(tmp_path):
    """Nothing is read when the cube is opened: bytes changed afterwards are what is computed
    (Dask given a memmap ndarray would copy it whole into its graph)."""
    v = _cube()
    p, _ = _write(tmp_path, "lazy.raw", v, extra="start time_s = 0\nline_rate_hz = 100\n")
    da, _ = read_line_cube(p, lines_per_chunk=2)
    assert type(da.data).__module__.startswith("dask")
    (2 * v).astype("<f4").transpose(0, 2, 1).tofile(p)  # the same size, new values (BIL)
    np.testing.assert_array_equal(da.values, 2 * v)


def test_ignore_value_compared_exactly(tmp_path):
    """int32 16777217 marks no-data; 16777216 (the same float32) stays a value. A uint16 cube
    with a negative ignore value has no no-data (and no error)."""
    v = _cube("int32")
    v[0, 0, 0], v[0, 0, 1] = 16777217, 16777216
    extra = "data ignore value = 16777217\nstart time_s = 0\nline_rate_hz = 100\n"
    p, _ = _write(tmp_path, "i.raw", v, extra=extra, dtype_code=3)
    out = read_line_cube(p)[0].values
    assert np.isnan(out[0, 0, 0]) and out[0, 0, 1] == 16777216 and np.isnan(out).sum() == 1
    extra = "data ignore value = -9999\nstart time_s = 0\nline_rate_hz = 100\n"
    p, _ = _write(tmp_path, "u.raw", _cube("uint16"), extra=extra, dtype_code=12)
    assert not np.isnan(read_line_cube(p)[0].values).any()
