"""``hsgeo reproduce mtf``: image sharpness of the ImSpector per wavelength (001 §2.3, §3.1, §4).

The bar target of 001 §2.3 is rendered on ten spectral lines (rows 100, 200, …, 1000; 001 §3.1
"10 spectral lines … at intervals of 100 pixels") by :mod:`hsgeo.simulate.mtf_target`; the user's
pipeline (:func:`hsgeo.workflows.mtf.mtf_from_bars`) measures the CTF of each bar group and turns
it into the MTF by the Coltman series; a slanted edge through the same optics is measured by
ISO 12233 (:func:`hsgeo.workflows.mtf.mtf_from_edge`). Every estimate is compared with the
analytic MTF of the simulated optics. Every reproduced value is the mean over ``n_runs`` noise
realisations (the target's sub-pixel position and the operator's start guess change too) and its
σ the σ of that mean (one realisation's spread / √n_runs), so that z of a mean uses the mean's
σ (GUIDE §4). The methods' own biases — what the same pipeline gives on noise-free recordings with
the same distribution of phases and start guesses — are measured for every row (``meta["bias"]``):
a row beyond 3σ of its truth is either explained by that bias or named.

Tables: ``"001 Fig. 9"``, ``"slanted edge"``, ``"001 Table 3"``, ``"CTF as MTF"``,
``"001 eq. 6-7 as printed"``, ``"unmodelled effect"`` (5 % veiling glare).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hsgeo.measure.edge import slanted_edge
from hsgeo.mtf import (
    crossing_frequency,
    ctf_from_mtf,
    ctf_from_mtf_printed,
    mtf_from_ctf_printed,
)
from hsgeo.papers import GSD_001_TABLE3_MM, P001_MTF
from hsgeo.report import Reproduction, Row
from hsgeo.simulate.mtf_target import (
    BarRecording,
    MtfBench,
    MtfBenchScenario,
    bar_electrons,
    edge_electrons,
    mtf_true,
    render_bar_profiles,
    render_edge,
)
from hsgeo.simulate.scenarios import load_scenario
from hsgeo.workflows.mtf import (
    BORDERLINE_LEVEL,
    BarInputs,
    BarOptions,
    EdgeInputs,
    determined_gsd_mm,
    mtf_from_bars,
    mtf_from_edge,
)

__all__ = [
    "run",
    "SCENARIO",
    "generate",
    "simulate_runs",
    "LINES",
    "TABLE_LINES",
    "F_TABLE",
    "F_GRID",
    "STRAY_LIGHT",
    "GSD_DEFINITION",
    "method_bias",
    "bias_sentence",
]

#: The chapter's scenario, ``data_synthetic/mtf_bench.toml`` (its ``[bench]`` is the
#: :class:`~hsgeo.simulate.mtf_target.MtfBench` the run renders; the chapter reads it too).
SCENARIO = "mtf_bench"
#: The ten spectral lines (001 §3.1 and Fig. 8b: every 100 px).
LINES = tuple(range(100, 1001, 100))
#: The lines of 001 Table 3 and Fig. 9.
TABLE_LINES = (100, 500, 700, 1000)
#: Frequencies of the tables, cy/px.
F_TABLE = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5)
#: Frequencies of the MTF curves, cy/px.
F_GRID = tuple(np.round(np.arange(0.025, 0.5001, 0.0125), 5))
#: The definition of the determined GSD that 001 Table 3's verdicts rest on (ours: 001 gives none).
GSD_DEFINITION = (
    "with our definition of the determined GSD, GSD/(2 f₀.₁), f₀.₁ the frequency where the MTF "
    "falls to 0.1 (001 gives no definition)"
)
#: The unmodelled effect: veiling glare, a fraction of the mean signal added uniformly.
STRAY_LIGHT = 0.05


def _expected_dn(bench: MtfBench, e) -> np.ndarray:
    """The expected recording (DN, not rounded) of a noise-free signal ``e`` (electrons)."""
    lab = bench.lab
    return (np.asarray(e, float) + lab.dark_e) / lab.gain_e_per_dn + lab.offset_dn


def _grid(i: int, n: int) -> float:
    """The i-th of n equally spaced points of (0, 1): a quadrature of a uniform variable."""
    return (i + 0.5) / n


def _noise_free_bars(bench: MtfBench, lines, i: int, n: int) -> BarRecording:
    """The i-th of n noise-free bar recordings: the target's sub-pixel phase and the operator's
    start error spread over their ranges on a grid (a permuted one for the start error), the
    profile the expected DN.
    """
    true_start = bench.target_offset_px + _grid(i, n)
    err = (2 * _grid((3 * i + 1) % n, n) - 1) * bench.start_error_px
    dn = _expected_dn(bench, bar_electrons(bench, lines, true_start))
    return BarRecording(
        np.atleast_1d(np.asarray(lines)),
        np.arange(bench.lab.n_reflected, dtype=float),
        dn,
        float(true_start + err),
        bench.gsd_mm,
        bench.dark_dn,
        bench.saturation_dn,
        float(true_start),
    )


def simulate_runs(
    bench: MtfBench, n_runs: int, seed: int, lines=LINES, edge_lines=TABLE_LINES, *, noise=True
):
    """``n_runs`` noise realisations: bar profiles on ``lines`` and edges on ``edge_lines``.

    ``noise=False``: ``n_runs`` noise-free recordings instead (the expected DN), the target's
    phase, the operator's start error and the edge's phase on a grid over their ranges: what
    the methods give without noise, i.e. their own bias.

    Returns a dict of arrays: ``mtf_bars`` (runs, lines, F_GRID), ``borderline`` and
    ``gsd_det`` (runs, lines), ``ctf_f`` / ``ctf`` (groups; runs, lines, groups), ``f_edge``,
    ``mtf_edge`` (runs, edge_lines, f_edge), ``borderline_edge`` (runs, edge_lines), ``fwhm``,
    and one recording (``example``) for the figures.
    """
    f_edge = np.round(np.arange(0.0, 1.0001, 0.0125), 5)
    out = {
        "mtf_bars": np.full((n_runs, len(lines), len(F_GRID)), np.nan),
        "borderline": np.full((n_runs, len(lines)), np.nan),
        "gsd_det": np.full((n_runs, len(lines)), np.nan),
        "gsd_fit": np.full((n_runs, len(lines)), np.nan),
        "mtf_edge": np.full((n_runs, len(edge_lines), f_edge.size), np.nan),
        "borderline_edge": np.full((n_runs, len(edge_lines)), np.nan),
        "fwhm": np.full((n_runs, len(edge_lines)), np.nan),
        "f_edge": f_edge,
        "lines": tuple(lines),
        "edge_lines": tuple(edge_lines),
    }
    ctf = []
    for i in range(n_runs):
        rng = np.random.default_rng(np.random.SeedSequence([seed, i, 9]))
        if noise:
            rec = render_bar_profiles(bench, list(lines), rng)
        else:
            rec = _noise_free_bars(bench, list(lines), i, n_runs)
        if i == 0:
            out["example"] = rec
        row_ctf = []
        for j, _ in enumerate(lines):
            inp = BarInputs(
                rec.x_px,
                rec.profiles_dn[j],
                bench.target,
                rec.start_px,
                rec.gsd_mm,
                rec.dark_dn,
                rec.saturation_dn,
            )
            res = mtf_from_bars(inp, BarOptions(f_cy_px=F_GRID))
            out["mtf_bars"][i, j, : res.mtf.size] = res.mtf
            out["borderline"][i, j] = res.borderline_cy_px
            out["gsd_det"][i, j] = res.determined_gsd_mm
            out["gsd_fit"][i, j] = res.gsd_mm
            row_ctf.append(res.ctf)
            out["ctf_f"] = res.ctf_frequency_cy_px
        ctf.append(row_ctf)
        for j, r in enumerate(edge_lines):
            if noise:
                img = render_edge(bench, r, rng)
            else:
                ph = _grid(i, n_runs) - 0.5
                img = _expected_dn(bench, edge_electrons(bench, r, phase_px=ph))
            e = mtf_from_edge(EdgeInputs(img, (0, 0, img.shape[1], img.shape[0])))
            out["mtf_edge"][i, j] = np.interp(f_edge, e.frequency_cy_px, e.mtf)
            out["borderline_edge"][i, j] = e.borderline_cy_px
            out["fwhm"][i, j] = e.lsf_fwhm_px
    out["ctf"] = np.array(ctf)
    return out


def _of_mean(n_runs: int) -> dict:
    """The Row keywords of a mean over ``n_runs`` runs whose σ is the mean's."""
    return {"n_runs": n_runs, "mean_of_runs": True}


def _stats(a, axis=0):
    """Mean over runs and the σ of that mean (sample σ / √n, n the finite runs)."""
    a = np.asarray(a, float)
    n = np.sum(np.isfinite(a), axis=axis)
    return np.nanmean(a, axis=axis), np.nanstd(a, axis=axis, ddof=1) / np.sqrt(n)


def _truth_borderline(bench, r, angle_deg=0.0):
    f = np.linspace(0.0, 1.0, 20001)
    return crossing_frequency(f, mtf_true(bench, r, f, angle_deg), BORDERLINE_LEVEL)


def _fig9_rows(bench, sim, n_runs) -> list[Row]:
    rows = []
    fg = np.asarray(F_GRID)
    for r in TABLE_LINES:
        j = LINES.index(r)
        mean, sd = _stats(sim["mtf_bars"][:, j, :])
        for f in F_TABLE:
            k = int(np.argmin(np.abs(fg - f)))
            rows.append(
                Row(
                    table="001 Fig. 9",
                    quantity=f"MTF line {r} at {f:g} cy/px",
                    unit="1",
                    reproduced=mean[k],
                    sigma=sd[k],
                    truth=float(mtf_true(bench, r, f)),
                    **_of_mean(n_runs),
                    provenance="chosen",
                )
            )
    # 001 §4: "borderline frequency of around 0.3 cy/px for blue, and to 0.6 cy/px for NIR"
    for r, key in ((100, "borderline_blue_cy_px"), (1000, "borderline_nir_cy_px")):
        j = LINES.index(r)
        truth = _truth_borderline(bench, r)
        b = sim["borderline"][:, j]
        if np.all(np.isfinite(b)):
            m, s = _stats(b)
            # σ(λ) was tuned so that the true MTF falls to 0.1 at the paper's value: agreement
            # with the paper is by construction (report.Row.rule), recovery is the outcome
            row = Row(
                table="001 Fig. 9",
                quantity=f"borderline frequency (MTF 0.1) line {r}",
                unit="cy/px",
                paper=P001_MTF[key],
                reproduced=m,
                sigma=s,
                truth=truth,
                **_of_mean(n_runs),
                provenance="tuned",
            )
        else:
            fmax = float(sim["ctf_f"].max())
            m_end = float(np.nanmean(sim["mtf_bars"][:, j, -1]))
            row = Row(
                table="001 Fig. 9",
                quantity=f"borderline frequency (MTF 0.1) line {r}",
                unit="cy/px",
                paper=P001_MTF[key],
                truth=truth,
                **_of_mean(n_runs),
                verdict="not testable",
                reason=f"beyond the finest bars ({fmax:.2f} cy/px), where the MTF is still "
                f"{m_end:.2f}: bars cannot show it (the slanted edge can, see its table)",
                provenance="tuned",
            )
        rows.append(row)
    j = LINES.index(100)
    f0 = float(sim["ctf_f"].min())
    m0 = sim["mtf_bars"][:, j, 0]
    f07 = crossing_frequency(np.r_[0, F_GRID], np.r_[1, np.nanmean(sim["mtf_bars"][:, j], 0)], 0.7)
    mean, sd = _stats(m0)
    rows.append(
        Row(
            table="001 Fig. 9",
            quantity=f"MTF line 100 at {F_GRID[0]:g} cy/px ('initial value')",
            unit="1",
            paper=P001_MTF["mtf_initial"],
            reproduced=mean,
            sigma=sd,
            truth=float(mtf_true(bench, 100, F_GRID[0])),
            **_of_mean(n_runs),
            provenance="chosen",
            reason=f"an MTF normalised at zero frequency (001 eq. 4) is near 1 at the coarsest "
            f"bars ({f0:.3f} cy/px); it falls to 0.7 at {f07:.2f} cy/px on line 100 - the paper's "
            "curves start there, or carry a contrast loss (see 'unmodelled effect')",
        )
    )
    return rows


def _edge_rows(bench, sim, n_runs) -> list[Row]:
    rows = []
    fe = sim["f_edge"]
    ang = bench.edge_angle_deg
    for j, r in enumerate(TABLE_LINES):
        mean, sd = _stats(sim["mtf_edge"][:, j, :])
        for f in (*F_TABLE, 0.6, 0.75):
            k = int(np.argmin(np.abs(fe - f)))
            rows.append(
                Row(
                    table="slanted edge",
                    quantity=f"MTF line {r} at {f:g} cy/px",
                    unit="1",
                    reproduced=mean[k],
                    sigma=sd[k],
                    truth=float(mtf_true(bench, r, f, ang)),
                    **_of_mean(n_runs),
                    provenance="chosen",
                )
            )
        m, s = _stats(sim["fwhm"][:, j])
        rows.append(
            Row(
                table="slanted edge",
                quantity=f"LSF FWHM line {r}",
                unit="px",
                reproduced=m,
                sigma=s,
                **_of_mean(n_runs),
                provenance="chosen",
            )
        )
    for r in (100, 1000):  # the method's own bias: a noise-free edge (Hamming window, bins)
        e = slanted_edge(edge_electrons(bench, r))
        for f in (0.1, 0.2):
            rows.append(
                Row(
                    table="slanted edge",
                    quantity=f"MTF line {r} at {f:g} cy/px, noise-free edge",
                    unit="1",
                    reproduced=float(np.interp(f, e.f_cy_px, e.mtf)),
                    truth=float(mtf_true(bench, r, f, ang)),
                    provenance="chosen",
                )
            )
    for r, key in ((100, "borderline_blue_cy_px"), (1000, "borderline_nir_cy_px")):
        j = TABLE_LINES.index(r)
        m, s = _stats(sim["borderline_edge"][:, j])
        truth = _truth_borderline(bench, r, ang)
        rows.append(
            Row(
                table="slanted edge",
                quantity=f"borderline frequency (MTF 0.1) line {r}",
                unit="cy/px",
                paper=P001_MTF[key],
                reproduced=m,
                sigma=s,
                truth=truth,
                **_of_mean(n_runs),
                provenance="tuned",
            )
        )
    return rows


def _table3_rows(bench, sim, n_runs) -> list[Row]:
    g = bench.gsd_mm
    rows = [
        Row(
            table="001 Table 3",
            quantity="theoretical GSDv, binning 1",
            unit="mm",
            paper=GSD_001_TABLE3_MM["theoretical"],
            reproduced=g,
            truth=g,
            provenance="derived",
        )  # (1.7 m × 0.333)/1170: arithmetic
    ]
    # the lines of one run share the target's phase and the start guess: the runs' means are the
    # independent values
    m, s = _stats(np.nanmean(sim["gsd_fit"], axis=1))
    rows.append(
        Row(
            table="001 Table 3",
            quantity="GSDv fitted to the bar edges",
            unit="mm",
            reproduced=m,
            sigma=s,
            truth=g,
            **_of_mean(n_runs),
            provenance="derived",
        )
    )
    for r in TABLE_LINES:
        paper = GSD_001_TABLE3_MM["actual"][r]
        j = LINES.index(r)
        truth = determined_gsd_mm(g, _truth_borderline(bench, r))
        d = sim["gsd_det"][:, j]
        f_needed = g / (2 * paper)
        why = (
            f"{GSD_DEFINITION}: the paper's {paper:g} mm means an MTF of 0.1 at {f_needed:.3f} "
            f"cy/px, where the optics tuned to 001 §4 have "
            f"{float(mtf_true(bench, r, f_needed)):.3f}: Table 3 and §4 do not fit one threshold "
            "under this definition"
        )
        why_edge = why
        if np.all(np.isfinite(d)):
            mean, sd = _stats(d)
        else:  # no reproduced value: the rule says "not testable", with this reason
            mean = sd = None
            why = (
                "the MTF stays above 0.1 up to the finest bars "
                f"({float(sim['ctf_f'].max()):.2f} cy/px): bars cannot determine it, the slanted "
                "edge can (next row)"
            )
        rows.append(
            Row(
                table="001 Table 3",
                quantity=f"determined GSDv line {r} (bars)",
                unit="mm",
                paper=paper,
                reproduced=mean,
                sigma=sd,
                truth=truth,
                **_of_mean(n_runs),
                reason=why,
                provenance="chosen",
            )
        )
        k = TABLE_LINES.index(r)
        e = g / (2 * sim["borderline_edge"][:, k])
        mean, sd = _stats(e)
        truth_e = determined_gsd_mm(g, _truth_borderline(bench, r, bench.edge_angle_deg))
        rows.append(
            Row(
                table="001 Table 3",
                quantity=f"determined GSDv line {r} (slanted edge)",
                unit="mm",
                paper=paper,
                reproduced=mean,
                sigma=sd,
                truth=truth_e,
                n_runs=n_runs,
                mean_of_runs=True,
                reason=why_edge,
                provenance="chosen",
            )
        )
    return rows


def _ctf_as_mtf_rows(bench, sim, n_runs) -> list[Row]:
    rows = []
    fc = sim["ctf_f"]
    for r in TABLE_LINES:
        j = LINES.index(r)
        for f in F_TABLE:
            c = np.array([np.interp(f, fc, run[j]) for run in sim["ctf"]])
            mean, sd = _stats(c)
            rows.append(
                Row(
                    table="CTF as MTF",
                    quantity=f"CTF taken as MTF, line {r} at {f:g} cy/px",
                    unit="1",
                    reproduced=mean,
                    sigma=sd,
                    truth=float(mtf_true(bench, r, f)),
                    **_of_mean(n_runs),
                    provenance="chosen",
                )
            )
    return rows


def method_bias(bench: MtfBench, rows: list[Row], free: dict) -> dict:
    """The methods' own biases and how much of the rows' deviation from the truth they explain.

    ``free`` is :func:`simulate_runs` with ``noise=False`` on the lines of 001 Table 3: the same
    row builders applied to it give, per row, ``bias`` = noise-free mean − truth, with the σ of
    that mean (the phases and start errors differ between recordings). Per table
    (``"001 Fig. 9"``, ``"slanted edge"``, ``"001 Table 3"``, ``"CTF as MTF"``): ``n`` rows with
    a z, ``n_within_3`` of them within 3σ of the mean, ``n_within_3_bias`` within 3σ once their
    bias is taken off (``z_bias`` = (mean − truth − bias)/hypot(σ, σ of the bias)), the
    largest |bias|, the
    ``unexplained`` rows (beyond 3σ even after the bias) and ``rows``: quantity → (z, z_bias,
    bias).
    """
    n = free["mtf_bars"].shape[0]
    ref = (
        _fig9_rows(bench, _on_table_lines(free), n)
        + _edge_rows(bench, free, n)
        + _table3_rows(bench, _on_table_lines(free), n)
        + _ctf_as_mtf_rows(bench, _on_table_lines(free), n)
    )
    bias = {
        (r.table, r.quantity): (r.reproduced - r.truth, r.sigma or 0.0)
        for r in ref
        if r.reproduced is not None and r.truth is not None
    }
    out: dict = {}
    for r in rows:
        b, sb = bias.get((r.table, r.quantity), (None, 0.0))
        if r.z is None or b is None or not np.isfinite(b):
            continue
        t = out.setdefault(r.table, {"rows": {}})
        # the bias is itself a mean over the noise-free recordings' phases: its σ counts too
        s = math.hypot(r.sigma, sb if np.isfinite(sb) else 0.0)
        t["rows"][r.quantity] = (r.z, (r.reproduced - r.truth - b) / s, b)
    for t in out.values():
        z = np.array([v[0] for v in t["rows"].values()])
        zb = np.array([v[1] for v in t["rows"].values()])
        b = np.array([v[2] for v in t["rows"].values()])
        t.update(
            n=int(z.size),
            n_within_3=int(np.sum(np.abs(z) <= 3)),
            n_within_3_bias=int(np.sum(np.abs(zb) <= 3)),
            max_abs_bias=float(np.max(np.abs(b))),
            unexplained=[q for q, v in t["rows"].items() if abs(v[1]) > 3],
        )
    return out


def bias_sentence(rep: Reproduction, table: str, what: str = "values") -> str:
    """The chapter's sentence on one table's z (computed from ``rep.meta["bias"]``): how many
    rows lie within 3σ of the mean, how many once the method's own bias is taken off, and the
    rows still beyond, with where they lie (their sign and the largest truth among them).
    """
    b = rep.meta["bias"].get(table)
    if not b:
        return f"No {what} of this table have a σ to judge them by."
    n, k, kb = b["n"], b["n_within_3"], b["n_within_3_bias"]
    out = (
        f"{k} of {n} {what} lie within 3σ of their truth, σ being the σ of the mean of "
        f"{rep.meta['n_runs']} runs; with the method's own bias taken off (what the same "
        f"pipeline gives on {rep.meta['n_noise_free']} noise-free recordings over the same "
        f"phases and start errors, at most {b['max_abs_bias']:.4f}), {kb} of {n} do"
    )
    rest = b["unexplained"]
    if not rest:
        return out + "."
    rows = {r.quantity: r for r in rep.rows_of(table)}
    excess = {q: rows[q].reproduced - rows[q].truth - b["rows"][q][2] for q in rest}
    above = sum(v > 0 for v in excess.values())
    worst = max(excess, key=lambda q: abs(excess[q]))
    side = (
        "all above their truth"
        if above == len(rest)
        else ("all below" if above == 0 else f"{above} above and {len(rest) - above} below")
    )
    names = ", ".join(rest[:4]) + (f" and {len(rest) - 4} more" if len(rest) > 4 else "")
    out += (
        f". The {len(rest)} beyond ({names}) lie {side}, by up to {abs(excess[worst]):.4f} "
        f"beyond the noise-free bias, the most where the true MTF is {rows[worst].truth:.3f}"
    )
    if above == len(rest):
        out += (
            ": a bias that the noise adds to the estimate, which noise-free recordings cannot "
            "show (on edges of an independent generator, noise raises the slanted-edge MTF at "
            "mid and high frequencies, bench/bench_mtf_edge_independent.py)"
        )
    return out + "."


def _on_table_lines(free: dict) -> dict:
    """A noise-free run on :data:`TABLE_LINES` indexed as the row builders index :data:`LINES`
    (the other lines NaN; no builder reads them).
    """
    out = dict(free)
    idx = [LINES.index(r) for r in free["lines"]]
    for k in ("mtf_bars", "borderline", "gsd_det", "gsd_fit"):
        a = np.asarray(free[k])
        full = np.full((a.shape[0], len(LINES), *a.shape[2:]), np.nan)
        full[:, idx] = a
        out[k] = full
    c = np.asarray(free["ctf"])
    full = np.full((c.shape[0], len(LINES), *c.shape[2:]), np.nan)
    full[:, idx] = c
    out["ctf"] = full
    out["lines"] = LINES
    return out


def _printed_rows(bench, sim) -> list[Row]:
    """The error of 001 eq. (6)–(7) as printed against the corrected series (no noise)."""
    rows = []
    f = np.asarray(F_GRID)
    for r in (100, 1000):

        def m(x, r=r):
            return mtf_true(bench, r, x)

        ctf_true = ctf_from_mtf(m, f)
        e6 = np.max(np.abs(ctf_from_mtf_printed(m, f) - ctf_true))

        def ctf(x, m=m):
            return ctf_from_mtf(m, x)

        e7 = np.max(np.abs(mtf_from_ctf_printed(ctf, f) - m(f)))
        ecm = np.max(np.abs(ctf_true - m(f)))
        for q, v in (
            (f"max |eq. 6 as printed − Coltman CTF|, line {r}", e6),
            (f"max |eq. 7 as printed − MTF|, line {r}", e7),
            (f"max |CTF − MTF| (exact), line {r}", ecm),
        ):
            rows.append(
                Row(
                    table="001 eq. 6-7 as printed",
                    quantity=q,
                    unit="1",
                    reproduced=float(v),
                    provenance="chosen",
                )
            )
    return rows


def _unmodelled_rows(bench, sim, sim_glare, n_runs) -> list[Row]:
    rows = []
    fg = np.asarray(F_GRID)
    fe = sim["f_edge"]
    for r in (100, 1000):
        for f in (0.1, 0.3):
            k = int(np.argmin(np.abs(fg - f)))
            ke = int(np.argmin(np.abs(fe - f)))
            for name, s in (("without", sim), ("with", sim_glare)):
                j, je = s["lines"].index(r), s["edge_lines"].index(r)
                n_runs = s["mtf_bars"].shape[0]
                mean, sd = _stats(s["mtf_bars"][:, j, k])
                rows.append(
                    Row(
                        table="unmodelled effect",
                        quantity=f"bars: MTF line {r} at {f:g} cy/px, {name} glare",
                        unit="1",
                        reproduced=mean,
                        sigma=sd,
                        truth=float(mtf_true(bench, r, f)),
                        n_runs=n_runs,
                        mean_of_runs=True,
                        provenance="chosen",
                    )
                )
                mean, sd = _stats(s["mtf_edge"][:, je, ke])
                rows.append(
                    Row(
                        table="unmodelled effect",
                        quantity=f"edge: MTF line {r} at {f:g} cy/px, {name} glare",
                        unit="1",
                        reproduced=mean,
                        sigma=sd,
                        truth=float(mtf_true(bench, r, f, bench.edge_angle_deg)),
                        n_runs=n_runs,
                        mean_of_runs=True,
                        provenance="chosen",
                    )
                )
    return rows


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """The chapter's numbers. ``scale`` sets the noise realisations: max(8, round(24·scale))."""
    bench = load_scenario(SCENARIO).bench  # data_synthetic/mtf_bench.toml [bench]
    n_runs = max(8, int(round(24 * scale)))
    sim = simulate_runs(bench, n_runs, seed)
    glare = replace(bench, stray_light=STRAY_LIGHT)
    n_glare = 8
    sim_glare = simulate_runs(glare, n_glare, seed + 1, lines=(100, 1000), edge_lines=(100, 1000))
    measured = (
        _fig9_rows(bench, sim, n_runs)
        + _edge_rows(bench, sim, n_runs)
        + _table3_rows(bench, sim, n_runs)
        + _ctf_as_mtf_rows(bench, sim, n_runs)
    )
    n_bias = max(8, n_runs // 3)
    free = simulate_runs(bench, n_bias, seed, lines=TABLE_LINES, noise=False)
    rows = measured + _printed_rows(bench, sim) + _unmodelled_rows(bench, sim, sim_glare, n_glare)
    meta = {
        "n_runs": n_runs,
        "n_runs_glare": n_glare,
        "stray_light": STRAY_LIGHT,
        "gsd_mm": bench.gsd_mm,
        "lines": list(LINES),
        "edge_angle_deg": bench.edge_angle_deg,
        "sigma_vis_px": bench.sigma_vis_px,
        "sigma_nir_px": bench.sigma_nir_px,
        "f_max_bars_cy_px": float(sim["ctf_f"].max()),
        "f_min_bars_cy_px": float(sim["ctf_f"].min()),
        "n_noise_free": n_bias,
        "bias": method_bias(bench, measured, free),
    }
    return Reproduction(
        "mtf", seed, rows, meta, extras={"bench": bench, "sim": sim, "glare": sim_glare}
    )


def generate(cfg: MtfBenchScenario, outdir) -> list:
    """``make data`` (generator ``mtf_bench``): bar profiles of the lines of 001 Table 3 and the
    bar file, in the formats ``hsgeo mtf`` reads, and the analytic MTF (the truth).
    """
    from pathlib import Path

    from hsgeo.io.mtf import write_bars, write_columns, write_profiles

    bench = cfg.bench
    rows = [int(r) for r in cfg.bars.rows]
    rec = render_bar_profiles(bench, rows, int(cfg.scenario.seed))
    out = Path(outdir)
    prof = write_profiles(out / "mtf_bench_profiles.csv", rows, rec.x_px, rec.profiles_dn)
    profile = {"gsd_mm": rec.gsd_mm, "start_px": round(rec.start_px, 1),
               "dark_dn": rec.dark_dn, "saturation_dn": rec.saturation_dn}  # fmt: skip
    bars = write_bars(out / "mtf_bench_bars.toml", bench.target, profile)
    f = np.asarray(F_GRID)
    truth = {"f_cy_px": f, **{f"mtf_row{r}": mtf_true(bench, r, f) for r in rows}}
    tru = write_columns(out / "mtf_bench_truth.csv", truth)
    return [prof, bars, tru]
