import numpy as np
import pytest

from hsgeo import InputError
from hsgeo.io import read_csv_table, read_opencv_storage
from hsgeo.simulate.scenarios import load_scenario


def test_read_opencv_storage_bad_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_opencv_storage(tmp_path / "missing.yml")
    bad = tmp_path / "bad.yml"
    bad.write_text("%YAML:1.0\ncamera_matrix: [1, 2\n  : :\n")
    with pytest.raises(InputError):
        read_opencv_storage(bad)
    ok = tmp_path / "ok.yml"
    ok.write_text("%YAML:1.0\nimage_width: 640\n")
    assert read_opencv_storage(ok)["image_width"] == 640
    with pytest.raises(InputError, match="missing entries"):
        read_opencv_storage(ok, required=("camera_matrix",))


def test_read_csv_table(tmp_path):
    p = tmp_path / "obs.csv"
    p.write_text("image,point,zeta_px\n1,2,3.5\n1,3,\n")
    with pytest.raises(InputError, match="NaN"):
        read_csv_table(p, ("image", "point", "zeta_px"))
    with pytest.raises(InputError, match="missing columns"):
        read_csv_table(p, ("image", "x_m"))
    p.write_text("image,point,zeta_px\n1,2,3.5\n")
    assert read_csv_table(p, ("image", "point", "zeta_px"))["zeta_px"].to_numpy() == \
        pytest.approx(np.array([3.5]))


def test_load_scenario_errors(tmp_path, monkeypatch):
    with pytest.raises(InputError, match="no scenario"):
        load_scenario("nope")
    d = tmp_path / "data_synthetic"
    d.mkdir()
    (d / "broken.toml").write_text("[scenario\n")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="malformed TOML"):
        load_scenario("broken")
