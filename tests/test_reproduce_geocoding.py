import json

import pytest

from hsgeo.reproduce import run


@pytest.mark.parametrize("seed", [0, 7])
def test_calibration_more_than_halves_sigma(seed):
    rep = run("geocoding", seed=seed, scale=0.5)  # 100 simulated flights
    ratio = rep.table("simulated, ratio").set_index("quantity")["reproduced"]
    assert ratio["sigma_ratio_y"] > 2 and ratio["sigma_ratio_x"] > 2
    out = json.loads(rep.to_json())
    tables = {r["table"] for r in out["rows"]}
    assert {
        "000 Table 2",
        "000 Table 3",
        "simulated, uncalibrated",
        "simulated, calibrated",
        "simulated, ratio",
    } <= tables
    printed = rep.table("000 Table 2").set_index("quantity")
    assert round(printed.loc["sigma_y_m", "reproduced"], 2) == 0.88
