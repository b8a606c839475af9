import json

import numpy as np

from hsgeo.reproduce import run


def test_contract_and_distortion_magnitudes():
    rep = run("line-calibration", seed=5, scale=0.01)
    d = json.loads(rep.to_json())
    assert d["chapter"] == "line-calibration" and d["seed"] == 5
    tables = {r["table"] for r in d["rows"]}
    assert {"000 Table 1", "001 Table 2", "distortion magnitudes"} <= tables
    q = {r["quantity"]: r for r in d["rows"] if r["table"] == "distortion magnitudes"}
    assert abs(q["max_distortion_line100_px"]["reproduced"] - 4.0) < 0.1
    assert q["distortion_450px_line1000_px"]["reproduced"] > 25.0
    for r in d["rows"]:
        if r["table"] in ("000 Table 1", "001 Table 2") and r["sigma"] is not None:
            assert abs(r["reproduced"] - r["truth"]) < 3 * r["sigma"], r["quantity"]
    cov3 = [r["reproduced"] for r in d["rows"] if "3sigma" in r["quantity"]]
    assert len(cov3) == 20 and np.mean(cov3) >= 0.9
