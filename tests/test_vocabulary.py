"""The words a table shows for the internal keys of report rows (hsgeo.vocabulary, issue 28).

``tests/data/report_quantities.json`` holds every (quantity, unit) pair that the chapters'
``hsgeo reproduce CHAPTER --json`` produced at seed 0 (the pushbroom nodes cut to the first two).
Regenerate it when a chapter adds rows::

    for ch in frame-reference line-calibration geocoding mtf rikola pushbroom-ba; do
      hsgeo reproduce $ch --scale 0.3 --json > /tmp/$ch.json; done

and collect ``[quantity, unit]`` of every row per chapter.
"""

from __future__ import annotations

import doctest
import json
import re
from pathlib import Path

import pytest

import hsgeo.vocabulary as vocabulary
from hsgeo.report import Reproduction, Row, format_rows
from hsgeo.vocabulary import display_unit, quantity_label, unit_label

DATA = Path(__file__).parent / "data" / "report_quantities.json"
PAIRS = [
    (chapter, q, u)
    for chapter, pairs in json.loads(DATA.read_text(encoding="utf-8")).items()
    if not chapter.startswith("_")
    for q, u in pairs
]
#: ASCII spellings that must not reach a page (as whole words of a label or as a unit).
ASCII_UNITS = {"um", "deg", "1/mm", "1/mm2", "1/mm4", "1/mm6", "mm2", "px2", "1", "fraction"}
ASCII_WORDS = re.compile(r"\b(sigma\w*|1sigma|\d+sigma|um|deg|zeta0|nmad|rms)\b")


def test_the_snapshot_covers_every_chapter():
    chapters = {c for c, _, _ in PAIRS}
    assert {"frame-reference", "line-calibration", "geocoding", "mtf", "rikola"} <= chapters
    assert "pushbroom-ba" in chapters and len(PAIRS) > 400


@pytest.mark.parametrize(("chapter", "quantity", "unit"), PAIRS, ids=lambda x: str(x)[:40])
def test_no_internal_key_or_ascii_unit_is_shown(chapter, quantity, unit):
    label, shown_unit = quantity_label(quantity), display_unit(quantity, unit)
    assert "_" not in label, f"{chapter}: {quantity!r} shows as {label!r}"
    assert not ASCII_WORDS.search(label), f"{chapter}: {quantity!r} shows as {label!r}"
    assert label.strip() and "  " not in label
    assert shown_unit not in ASCII_UNITS and "_" not in shown_unit, (quantity, unit, shown_unit)


def test_units_and_labels_a_reader_knows():
    assert unit_label("um") == "µm" and unit_label("1/mm2") == "mm⁻²" and unit_label("deg") == "°"
    assert unit_label("1/mm") == "mm⁻¹" and unit_label("px2") == "px²"
    assert unit_label("") == unit_label("1") == unit_label(None) == "—"
    assert quantity_label("c_minus_mean_band0_450nm_um") == "c − mean c, band 0 (450 nm)"
    assert quantity_label("K1 line100 in 1sigma") == "K1, line 100, share within 1σ̂"
    assert quantity_label("σ(fx_px)") == "σ̂ of focal length fx"
    assert quantity_label("nodes[3, dE_m]") == "node 3, ΔE"
    assert quantity_label("x0_band5") == "x0, band 5"
    # words stay words
    assert quantity_label("MTF line 100 at 0.1 cy/px") == "MTF line 100 at 0.1 cy/px"


def test_line_scanner_k_have_their_real_unit():
    """000 eq. (2): δ = K1 u³ + K2 u⁵ + K3 u⁷ px with u = (ζ − ζ0) / 100 px."""
    assert display_unit("K1", "px") == "px / (100 px)³"
    assert display_unit("K2 line300", "px") == "px / (100 px)⁵"
    assert display_unit("K3", "px") == "px / (100 px)⁷"
    assert display_unit("K1_band5", "1/mm2") == "mm⁻²"  # the frame camera's K1 is per mm²
    assert display_unit("k1", "1") == "—"


def test_tables_show_labels_and_the_json_keeps_the_keys():
    rows = [
        Row(
            table="002 Fig. 8",
            quantity="c_minus_mean_band0_450nm_um",
            unit="um",
            reproduced=1.5,
            sigma=0.4,
        ),
        Row(
            table="002 Fig. 8",
            quantity="K1 line100 in 1sigma",
            unit="fraction",
            reproduced=0.68,
            sigma=0.03,
        ),
    ]
    rep = Reproduction("x", 0, rows)
    before = rep.to_json()
    df = format_rows(rows)
    assert list(df["quantity"]) == ["c − mean c, band 0 (450 nm)", "K1, line 100, share within 1σ̂"]
    assert list(df["unit"]) == ["µm", "share"]
    text = rep.to_text()
    assert "c − mean c" in text and "c_minus_mean" not in text and " um " not in text
    html = rep.show("002 Fig. 8").to_html()
    assert "c_minus_mean" not in html and "µm" in html
    d = json.loads(rep.to_json())
    assert rep.to_json() == before  # displaying does not touch the rows
    assert [r["quantity"] for r in d["rows"]] == [r.quantity for r in rows]
    assert [r["unit"] for r in d["rows"]] == ["um", "fraction"]


def test_doctests():
    assert doctest.testmod(vocabulary).failed == 0
