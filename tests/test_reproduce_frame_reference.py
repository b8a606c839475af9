"""``hsgeo reproduce frame-reference``: verdicts without a σ, and the chapter's parameters."""

from __future__ import annotations

from pathlib import Path

import pytest

from hsgeo.reproduce import frame_reference as fr

jupytext = pytest.importorskip("jupytext")

BOOK = Path(__file__).resolve().parents[1] / "book" / "chapters"


def _parameter_cell(name: str) -> dict:
    """Execute a chapter's first code cell (parameters only: literals) and return its names."""
    nb = jupytext.read(BOOK / f"{name}.md", fmt="md:myst")
    cell = next(c for c in nb.cells if c.cell_type == "code")
    ns: dict = {}
    exec(compile(cell.source, f"{name}.md parameters", "exec"), ns)  # noqa: S102
    return ns


def test_chapter_parameters_match_the_module():
    p = _parameter_cell("frame_reference")
    assert p["PIXEL_PITCH_MM"] == fr.PIXEL_PITCH_MM
    assert len(p["BINS"]) == 2 and isinstance(p["SEED"], int)


def test_same_verdict_uses_the_relative_tolerance():
    assert fr._same(1.0 + 0.5 * fr.SAME_REL, 1.0, "x")[0] == "reproduced"
    verdict, why = fr._same(1.0 + 2 * fr.SAME_REL, 1.0, "the RMS residuals")
    assert verdict == "differs" and "2.0e-03 relative" in why


def test_opencv_sigmas_are_positive_and_ordered():
    views, size, _ = fr.chessboard_views()
    s = fr.opencv_sigmas(views, size)
    assert s.shape == (9,) and (s > 0).all()
    assert s[0] > s[2]  # σ(fx) well above σ(cx) on this board (weak distance–fx separation)


def test_largest_paper_deviation_names_the_worst_row():
    from hsgeo.report import Reproduction, Row

    rows = [
        Row(table="T", quantity="fx", unit="px", paper=100.0, reproduced=100.2, sigma=0.1),  # 2σ̂
        Row(
            table="T", quantity="k1", unit="1", paper=0.1, reproduced=0.07, sigma=0.01
        ),  # −3σ̂: the largest
        Row(table="T", quantity="rms", unit="px", paper=0.4, reproduced=9.0),  # no σ̂: not counted
    ]
    assert fr.largest_paper_deviation(Reproduction("x", 0, rows), "T") == "3σ̂ (largest: k1)"
