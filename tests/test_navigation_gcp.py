import numpy as np
import pytest

from hsgeo import InputError, ObservationError
from hsgeo.gcp import deviation_table, recompute_printed_table
from hsgeo.io import read_envi, write_envi


def test_deviation_table_by_hand():
    # Δy = (1, 2, 3): n = 2, v = (-1, 0, 1), Σvv = 2, σ = sqrt(2 / 2) = 1
    t, s = deviation_table([1.0, 2.0, 3.0], [0.0, 0.0, 0.3])
    assert s["bias_y_m"] == 2.0 and s["sigma_y_m"] == 1.0
    np.testing.assert_allclose(t["vyvy_m2"], [1, 0, 1])
    with pytest.raises(ObservationError):
        deviation_table([1.0], [1.0])
    with pytest.raises(InputError, match="NaN"):
        deviation_table([1.0, np.nan], [1.0, 2.0])


def test_000_tables_recomputed():
    _, s2, f2 = recompute_printed_table(2)
    _, s3, f3 = recompute_printed_table(3)
    # the printed σ of Table 2 and σ_x of Table 3 follow by rounding (000 Tables 2–3)
    assert round(s2["sigma_y_m"], 2) == 0.88 and round(s2["sigma_x_m"], 2) == 0.65
    assert round(s3["sigma_x_m"], 2) == 0.29
    assert f2 == []
    # Table 3's σ_y = sqrt(1.4912 / 9) = 0.4070 is printed as 0.40: truncated, not rounded
    assert [f.where for f in f3] == ["footer sigma_y_m"]
    assert "truncation" in f3[0].note


def test_envi_round_trip_and_errors(tmp_path):
    data = np.arange(2 * 3 * 4, dtype=np.float32).reshape(2, 3, 4)
    p, h = write_envi(
        tmp_path / "cube", data, map_info=(100.0, 200.0, 0.5, 0.5), wavelength_nm=[450.0, 870.0]
    )
    back, hdr = read_envi(p)
    np.testing.assert_array_equal(back, data)
    assert hdr["map_info"] == (100.0, 200.0, 0.5, 0.5)
    with pytest.raises(InputError, match="dtype"):
        write_envi(tmp_path / "c2", data.astype(np.complex64))
    h.write_text("ENVI\nsamples = 4\nlines = 3\nbands = 9\ndata type = 4\n")
    with pytest.raises(InputError, match="header says"):
        read_envi(p)
    h.write_text("not envi\n")
    with pytest.raises(InputError, match="not an ENVI header"):
        read_envi(p)
