"""Valid inputs of ``hsgeo mtf`` and ``hsgeo mtf-edge`` from the simulated bench (shared by
tests/test_cli_mtf.py and tests/test_bad_input.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

ROWS = (100, 1000)


def write_bar_inputs(d: Path, seed: int = 4, rows=ROWS) -> None:
    """``profiles.csv`` (row, x_px, intensity_dn) and ``bars.toml`` of the simulated bench."""
    from hsgeo.simulate import mtf_target as T

    bench = T.MtfBench()
    rec = T.render_bar_profiles(bench, list(rows), seed)
    lines = ["row,x_px,intensity_dn"]
    for r, prof in zip(rows, rec.profiles_dn, strict=True):
        lines += [f"{r},{x:g},{v:.2f}" for x, v in zip(rec.x_px, prof, strict=True)]
    (d / "profiles.csv").write_text("\n".join(lines) + "\n")
    t = bench.target
    (d / "bars.toml").write_text(
        "[target]\n"
        f"pair_mm = [{', '.join(repr(p) for p in t.pair_mm)}]\n"
        f"n_pairs = [{', '.join(str(n) for n in t.n_pairs)}]\n"
        f"white_reflectance = {t.white_reflectance}\n"
        f"black_reflectance = {t.black_reflectance}\n"
        "[profile]\n"
        f"gsd_mm = {rec.gsd_mm!r}\n"
        f"start_px = {round(rec.start_px, 1)!r}\n"
        f"dark_dn = {rec.dark_dn!r}\n"
        f"saturation_dn = {rec.saturation_dn!r}\n"
    )


def write_edge_image(path: Path, seed: int = 4, row: int = 1000, bits: int = 16) -> None:
    """A recorded slanted edge (PNG; 16-bit DN, or scaled to 8 bits)."""
    import cv2

    from hsgeo.simulate import mtf_target as T

    img = T.render_edge(T.MtfBench(), row, seed, (200, 160))
    if bits == 8:
        img = np.round(img / 4095.0 * 255.0).astype(np.uint8)
    cv2.imwrite(str(path), img)
