"""The claims scoreboard (issue 13) and the record of chapter results it reads."""

import json

from hsgeo.report import Reproduction, Row
from hsgeo.reproduce import RECORD_ENV, recorded, run
from hsgeo.reproduce.scoreboard import (
    PAPER_CHAPTERS,
    claims,
    counts,
    counts_by,
    overrides,
    planned_claims,
)


def test_claims_are_the_paper_tables_plus_planned():
    rep = Reproduction(
        "line-calibration",
        0,
        [
            Row(
                "000 Table 1",
                "c",
                "px",
                paper=3539,
                paper_sigma=14,
                reproduced=3541,
                sigma=12,
                truth=3539,
                provenance="paper",
            ),
            Row("000 Table 1", "unpublished", "px", reproduced=1.0),  # no paper value
            Row("distortion magnitudes", "d", "px", paper=1.0, reproduced=1.0),  # not a paper
            Row(
                "002 Table 2",
                "nmad_h_m",
                "m",
                paper=0.99,
                reproduced=0.3,
                sigma=0.05,
                n_runs=10,
                provenance="chosen",
            ),
            Row(
                "002 Table 2",
                "mean_h_m",
                "m",
                paper=-0.78,
                reproduced=0.0,
                sigma=0.05,
                n_runs=10,
                provenance="chosen",
                verdict="not testable",
                reason="an override, for the test",
            ),
            # an experiment against 002 Table 2's values, not a claim of its own
            Row("002 check-point factors", "rtk.cp_nmad_h_m", "m", paper=0.99, reproduced=0.5),
        ],
    )
    rows = claims({"line-calibration": rep})
    assert [r.quantity for r in rows[:3]] == ["c", "nmad_h_m", "mean_h_m"]
    assert rows[3:] == planned_claims() and all(r.verdict == "planned" for r in rows[3:])
    c = counts(rows)
    assert c["by construction"] == 1 and c["differs"] == 1 and c["planned"] == len(planned_claims())
    by_prov = counts_by(rows, "provenance")
    assert by_prov["paper"]["by construction"] == 1 and by_prov["chosen"]["differs"] == 1
    assert by_prov.get("none", {}).get("planned", 0) == len(planned_claims())
    assert counts_by(rows, "paper")["002"] == {
        **dict.fromkeys(c, 0),
        "differs": 1,
        "not testable": 1,
    }
    assert overrides(rows) == [
        {
            "table": "002 Table 2",
            "quantity": "mean_h_m",
            "verdict": "not testable",
            "rule": "differs",
            "reason": "an override, for the test",
        }
    ]
    assert set(PAPER_CHAPTERS) >= {"line-calibration", "geocoding", "pushbroom-ba", "rikola"}


def test_run_records_and_recorded_round_trips(tmp_path, monkeypatch):
    assert recorded("frame-reference") is None or RECORD_ENV in __import__("os").environ
    monkeypatch.setenv(RECORD_ENV, str(tmp_path / "rec"))
    rep = run("frame-reference", seed=1)
    back = recorded("frame-reference")
    assert back is not None and back.seed == 1 and back.meta["scale"] == 1.0
    assert [r.as_dict() for r in back.rows] == [r.as_dict() for r in rep.rows]
    assert json.loads((tmp_path / "rec" / "frame-reference.json").read_text())["chapter"] == (
        "frame-reference"
    )
    monkeypatch.delenv(RECORD_ENV)
    assert recorded("frame-reference") is None


def test_cube_chapter_claims_reach_the_scoreboard():
    """001 §3.2's printed acquisition numbers are claims of the cube chapter (they were not
    listed as planned before the chapter existed); its truth-recovery tables are not."""
    rep = Reproduction(
        "cube",
        0,
        [
            Row(
                "001 §3.2",
                "speed S of eq. (8)",
                "mm/s",
                paper=33.0,
                reproduced=34.15,
                verdict="differs",
                reason="eq. (8)",
                provenance="derived",
            ),
            Row("reflectance", "panel, NIR", "1", reproduced=0.5, sigma=1e-4, truth=0.5),
        ],
    )
    rows = claims({"cube": rep})
    assert "cube" in PAPER_CHAPTERS
    assert [r.quantity for r in rows if r.verdict != "planned"] == ["speed S of eq. (8)"]


def test_asf_chapter_claims_replace_the_planned_004_rows():
    """004's numbers were planned; the asf chapter's "004 text" rows are now the claims."""
    from hsgeo.papers import ASF_004

    assert "asf" in PAPER_CHAPTERS and planned_claims() == []
    rep = Reproduction(
        "asf",
        0,
        [
            Row("004 text", q, u, paper=v, reproduced=v, provenance="paper")
            for q, (v, u) in ASF_004.items()
        ]
        + [Row("004 ASF", "ASF at +40°, channel 1", "1", reproduced=0.96, sigma=0.001, truth=0.96)],
    )
    rows = claims({"asf": rep})
    assert [r.quantity for r in rows] == list(ASF_004)
