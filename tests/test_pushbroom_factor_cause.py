"""The check-point factor runs (002 Table 2's candidate explanations) name the cause of every
"differs": what the run's factor does not produce, and which run does (issue 40)."""

from __future__ import annotations

import re

import numpy as np

from hsgeo.reproduce.pushbroom_runs import FACTORS, factor_rows

#: The bare distance the browser check refuses as a cause (tests/book/pagecheck.py).
_BARE = re.compile(r"^(tuning missed:\s*)?[\d.]+σ̂? (off|from the paper).*$")


def _fac(near_key: str = "image_y") -> dict:
    """Eight runs per factor: every factor far from 002 Table 2 but ``near_key``, which meets
    its mean height (−0.78 m)."""
    rng = np.random.default_rng(0)
    cp = {}
    for key in FACTORS:
        mean = np.array([0.05, 0.02, 0.08, -0.5, 2.5])
        if key == near_key:
            mean[3] = -0.78
        cp[key] = mean + 0.002 * rng.standard_normal((8, 5))
    return {"cp": cp}


def test_every_differing_factor_row_names_its_cause():
    rows = factor_rows(_fac())
    verdicts = {r.quantity: r.judge() for r in rows}
    differs = {q: why for q, (v, why) in verdicts.items() if v == "differs"}
    assert len(differs) > 10
    for q, why in differs.items():
        assert not _BARE.match(why), (q, why)
        assert "does not produce 002's" in why and "spread over 8 runs" in why
    # the mean height: the one run that meets it is named (computed from the rows)
    assert "the run (b) comes within 3σ of it" in differs["gauss_markov.cp_mean_h_m"]
    assert "motion blur" in differs["gauss_markov.cp_nmad_e_over_n"]  # no run meets it
    assert verdicts["image_y.cp_mean_h_m"][0] == "reproduced"


def test_rows_that_do_not_differ_keep_their_computed_reason():
    rows = factor_rows(_fac())
    assert all(r.reason == "" for r in rows if r.rule()[0] != "differs")
