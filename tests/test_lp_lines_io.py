"""The LP line file (hsgeo.io.lp_lines): round trip (in memory and lazy), overwrite refusal, bad
files, the full-line width convention."""

import numpy as np
import pytest
import xarray as xr

from hsgeo.errors import InputError
from hsgeo.io.lp_lines import (
    DEFAULT_N_PX_FULL,
    LpStrip,
    full_line_px,
    open_lp_lines,
    read_lp_lines,
    write_lp_lines,
)


def _strip(n_lines=5, n_cols=7, n_bands=3, seed=0):
    rng = np.random.default_rng(seed)
    return LpStrip(
        lines=rng.uniform(0, 4095, (n_lines, n_cols, n_bands)).astype(np.float32),
        t_s=100.0 + np.arange(n_lines) / 200.0,
        col0=123,
        wavelengths_nm=np.linspace(450, 912, n_bands),
        strip_id="s07",
    )


def test_round_trip_is_exact(tmp_path):
    s = _strip()
    p = write_lp_lines(tmp_path / "a.nc", s)
    r = read_lp_lines(p)
    assert r.lines.dtype == np.float32 and r.lines.shape == s.lines.shape
    assert np.array_equal(r.lines, s.lines)
    assert np.array_equal(r.t_s, s.t_s)
    assert np.array_equal(r.wavelengths_nm, s.wavelengths_nm)
    assert (r.col0, r.strip_id) == (123, "s07")


def test_a_users_own_file_reads(tmp_path):
    """The recipe of the module docstring (dimensions in another order, integer DN)."""
    dn = np.arange(2 * 3 * 4, dtype=np.uint16).reshape(4, 3, 2)  # band, column, line order below
    ds = xr.Dataset(
        {
            "lines": (("band", "column", "line"), dn),
            "t_s": ("line", [1.0, 1.005]),
            "wavelength_nm": ("band", [450.0, 527.0, 604.0, 681.0]),
        },
        attrs={"col0": 10, "strip_id": "mine"},
    )
    ds.to_netcdf(tmp_path / "u.nc", engine="h5netcdf")
    r = read_lp_lines(tmp_path / "u.nc")
    assert r.lines.shape == (2, 3, 4)
    assert r.lines[1, 2, 3] == dn[3, 2, 1]


def test_existing_file_is_not_overwritten(tmp_path):
    p = write_lp_lines(tmp_path / "a.nc", _strip(seed=0))
    before = p.read_bytes()
    with pytest.raises(InputError, match="exists"):
        write_lp_lines(p, _strip(seed=1))
    assert p.read_bytes() == before
    write_lp_lines(p, _strip(seed=1), overwrite=True)
    assert np.array_equal(read_lp_lines(p).lines, _strip(seed=1).lines)


def test_wrong_extension_and_type(tmp_path):
    with pytest.raises(InputError, match="NetCDF"):
        write_lp_lines(tmp_path / "a.txt", _strip())
    with pytest.raises(InputError, match="LpStrip"):
        write_lp_lines(tmp_path / "a.nc", np.zeros((2, 2, 2)))


def _write(tmp_path, **over):
    s = _strip()
    data = {
        "lines": (("line", "column", "band"), s.lines),
        "t_s": ("line", s.t_s),
        "wavelength_nm": ("band", s.wavelengths_nm),
    }
    attrs = {"col0": 3, "strip_id": "x"}
    for k, v in over.items():
        if k in ("col0", "strip_id", "n_px_full"):
            if v is None:
                attrs.pop(k)
            else:
                attrs[k] = v
        elif v is None:
            data.pop(k)
        else:
            data[k] = v
    p = tmp_path / "bad.nc"
    xr.Dataset(data, attrs=attrs).to_netcdf(p, engine="h5netcdf")
    return p


@pytest.mark.parametrize(
    "over, match",
    [
        ({"t_s": None}, "t_s"),
        ({"wavelength_nm": None}, "wavelength_nm"),
        ({"col0": None}, "col0"),
        ({"strip_id": None}, "strip_id"),
        ({"lines": (("line", "pixel", "band"), np.zeros((5, 7, 3), np.float32))}, "dimensions"),
        ({"t_s": ("line", [0.0, 1.0, 1.0, 2.0, 3.0])}, "increase strictly"),
        ({"n_px_full": 9}, "n_px_full = 9 must be an integer of at least"),
        ({"n_px_full": 1800.5}, "n_px_full = 1800.5 must be an integer"),
    ],
)
@pytest.mark.parametrize("reader", [read_lp_lines, open_lp_lines])
def test_bad_files_say_what_is_wrong(tmp_path, over, match, reader):
    p = _write(tmp_path, **over)
    with pytest.raises(InputError, match=match):
        reader(p)


def test_missing_file_and_not_netcdf(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_lp_lines(tmp_path / "none.nc")
    (tmp_path / "t.nc").write_text("hello")
    with pytest.raises(InputError, match="not a NetCDF"):
        read_lp_lines(tmp_path / "t.nc")


def test_strip_checks_its_arrays():
    s = _strip()
    with pytest.raises(InputError, match="increase strictly"):
        LpStrip(s.lines, s.t_s[::-1], 0, s.wavelengths_nm, "a")
    with pytest.raises(InputError, match="n_lines, n_cols, n_bands"):
        LpStrip(s.lines[0], s.t_s, 0, s.wavelengths_nm, "a")
    with pytest.raises(InputError, match="wavelengths_nm"):
        LpStrip(s.lines, s.t_s, 0, s.wavelengths_nm[:2], "a")
    with pytest.raises(InputError, match="col0"):
        LpStrip(s.lines, s.t_s, -1, s.wavelengths_nm, "a")
    with pytest.raises(InputError, match="strip_id"):
        LpStrip(s.lines, s.t_s, 0, s.wavelengths_nm, "")
    assert np.allclose(s.x_px(1800)[:2], [123 - 899.5, 124 - 899.5])


def test_lazy_round_trip(tmp_path):
    """open_lp_lines: the same strip as read_lp_lines, its lines a Dask array read in chunks;
    a Dask strip writes chunk by chunk."""
    import dask.array as dsa

    s = _strip(n_lines=50, n_cols=20, n_bands=4, seed=3)
    lazy = LpStrip(
        dsa.from_array(s.lines, chunks=(16, -1, -1)),
        s.t_s,
        100,
        s.wavelengths_nm,
        "A7",
        n_px_full=1800,
    )
    p = write_lp_lines(tmp_path / "a.nc", lazy)
    r = open_lp_lines(p, lines_per_chunk=16)
    assert isinstance(r.lines, dsa.Array) and r.lines.chunks[0][0] == 16
    assert r.lines.dtype == np.float32
    np.testing.assert_array_equal(r.lines.compute(), s.lines)
    m = read_lp_lines(p)
    np.testing.assert_array_equal(m.lines, s.lines)
    assert (
        (r.col0, r.strip_id, r.n_px_full) == (m.col0, m.strip_id, m.n_px_full) == (100, "A7", 1800)
    )
    np.testing.assert_array_equal(r.t_s, s.t_s)
    # column j is column col0 + j of the full line, x from its centre (1800 px)
    np.testing.assert_allclose(r.x_px(), 100 + np.arange(20) - 899.5)
    with pytest.raises(InputError, match="lines_per_chunk"):
        open_lp_lines(p, lines_per_chunk=0)


def test_full_line_width_convention(tmp_path):
    """--line-pixels overrides the files; else their n_px_full; else 1800 (002 §4)."""
    s = _strip()  # col0 123, 7 columns
    p = write_lp_lines(tmp_path / "a.nc", s)
    r = read_lp_lines(p)
    assert r.n_px_full is None and "n_px_full" not in xr.open_dataset(p).attrs
    assert full_line_px([r]) == DEFAULT_N_PX_FULL == 1800
    np.testing.assert_allclose(r.x_px(), r.x_px(1800))
    w = LpStrip(s.lines, s.t_s, s.col0, s.wavelengths_nm, "w", n_px_full=400)
    r400 = read_lp_lines(write_lp_lines(tmp_path / "w.nc", w))
    assert r400.n_px_full == 400 and full_line_px([r400, r]) == 400
    np.testing.assert_allclose(r400.x_px(), 123 + np.arange(7) - 199.5)
    assert full_line_px([r400], 1000) == 1000  # the option overrides the file
    other = LpStrip(s.lines, s.t_s, 0, s.wavelengths_nm, "o", n_px_full=500)
    with pytest.raises(InputError, match=r"different full-line widths .*\[400, 500\]"):
        full_line_px([r400, other])
    assert full_line_px([r400, other], 600) == 600
    with pytest.raises(InputError, match="do not fit a line of 100 px .*--line-pixels"):
        full_line_px([r], 100)
    with pytest.raises(InputError, match="n_px_full = 129"):
        LpStrip(s.lines, s.t_s, s.col0, s.wavelengths_nm, "x", n_px_full=129)
