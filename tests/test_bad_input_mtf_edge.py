"""``mtf-edge``'s region checks over every region of a masked target, not hand-picked (issue 42).

A chip with the area outside a rotated knife-edge target set to 0 (``tests/edge_reference.py``,
an independent generator), noisy and noise-free; regions on a 10-px grid of corners, 16–64 px
wide and 32–128 px high. Done means: a region holding any pixel of fill is refused (never
measured), no region ends in anything but an hsgeo error, and a measured region's LSF is at least
a pixel wide. Measured when written (5,304 regions): 4,826 touch the fill, all refused (38 were
measured before: 1–32 px of fill in a corner or beyond the ESF's window; 12 ended in an
IndexError); 170 of the 478 clean regions are measured (the others are too narrow across the
edge or hold no edge), FWHM ≥ 1.73 px.
"""

from __future__ import annotations

import edge_reference as ER
import numpy as np
import pytest

from hsgeo.errors import HsgeoError, ObservationError
from hsgeo.measure.edge import MIN_LSF_FWHM_PX, slanted_edge

WIDTHS, HEIGHTS = (16, 24, 40, 64), (32, 64, 128)


def region_sweep(noise: float, step: int = 10, size: int = 200) -> dict:
    """Every region of the grid: how many touch the fill, how many of those were measured,
    how many clean ones were measured, their least FWHM, and any error not an hsgeo error."""
    img, inside = ER.masked_target_chip(noise=noise)
    out = {"regions": 0, "touching_fill": 0, "fill_measured": [], "clean": 0, "clean_measured": 0}
    out["min_fwhm_px"], out["not_hsgeo_errors"] = float("inf"), []
    for x0 in range(0, size, step):
        for y0 in range(0, size, step):
            for w in WIDTHS:
                for h in HEIGHTS:
                    if x0 + w > size or y0 + h > size:
                        continue
                    roi = (x0, y0, x0 + w, y0 + h)
                    fill = int((~inside[y0 : y0 + h, x0 : x0 + w]).sum())
                    out["regions"] += 1
                    out["touching_fill" if fill else "clean"] += 1
                    try:
                        m = slanted_edge(img[y0 : y0 + h, x0 : x0 + w])
                    except HsgeoError:
                        continue
                    except Exception as exc:  # a traceback for the user
                        out["not_hsgeo_errors"].append((roi, repr(exc)))
                        continue
                    out["min_fwhm_px"] = min(out["min_fwhm_px"], m.lsf_fwhm_px)
                    if fill:
                        out["fill_measured"].append((roi, fill, m.lsf_fwhm_px))
                    else:
                        out["clean_measured"] += 1
    return out


@pytest.mark.slow
@pytest.mark.parametrize("noise", [5.0, 0.0])
def test_every_region_touching_fill_is_refused(noise):
    s = region_sweep(noise)
    assert s["touching_fill"] > 2000 and s["clean"] > 200
    assert not s["not_hsgeo_errors"], s["not_hsgeo_errors"][:5]
    assert not s["fill_measured"], s["fill_measured"][:5]
    assert s["min_fwhm_px"] >= MIN_LSF_FWHM_PX
    assert s["clean_measured"] >= 50  # valid regions are still measured (62 and 108 when written)


@pytest.mark.parametrize(
    "roi, noise",
    [
        ((70, 80, 134, 112), 5.0),  # 1 px of fill in a corner: was measured
        ((60, 40, 100, 72), 5.0),  # 32 px of fill beyond the ESF's window: was measured
        ((80, 100, 144, 132), 0.0),  # the step found outside the region: was an IndexError
        ((70, 40, 134, 72), 0.0),  # the same
    ],
)
def test_regions_touching_fill_found_by_the_sweep(roi, noise):
    img, inside = ER.masked_target_chip(noise=noise)
    x0, y0, x1, y1 = roi
    assert not inside[y0:y1, x0:x1].all()
    with pytest.raises(ObservationError, match="fill"):
        slanted_edge(img[y0:y1, x0:x1])


def test_a_dead_pixel_is_named():
    img = ER.slanted_edge_image((100, 80), 5.0, 0.7)
    img[10, 5] = 0.0
    with pytest.raises(ObservationError, match="dead or hot pixel"):
        slanted_edge(img)
    assert np.isfinite(slanted_edge(ER.slanted_edge_image((100, 80), 5.0, 0.7)).lsf_fwhm_px)
