"""hsgeo.reproduce.lp_campaigns: the LP check points over campaigns (issue 37)."""

from __future__ import annotations

import numpy as np
import pytest

from hsgeo.papers import P002_STATS
from hsgeo.reproduce.lp_campaigns import checkpoint_campaigns
from hsgeo.reproduce.lp_observations import stat_sigma
from hsgeo.stats import describe

I_STD, I_NMAD = P002_STATS.index("std"), P002_STATS.index("nmad")


def _joint_cov(k: int, s_point_m: float, s_shift_m: float) -> np.ndarray:
    """k check points, each alone σ ``s_point_m`` per axis, their heights sharing one datum
    shift of σ ``s_shift_m`` (a block without GCPs)."""
    C = np.kron(np.eye(k), np.eye(3) * s_point_m**2)
    h = np.arange(k) * 3 + 2
    C[np.ix_(h, h)] += s_shift_m**2
    return C


def _campaigns(n: int, k: int = 9, s_point: float = 0.3, s_shift: float = 2.0, seed: int = 0):
    """``n`` campaigns of check-point errors drawn from the joint covariance, with the σ̂ of
    their statistics from the joint covariance and from the per-point blocks: the records the
    bench writes."""
    rng = np.random.default_rng(seed)
    C = _joint_cov(k, s_point, s_shift)
    L = np.linalg.cholesky(C)
    blocks = np.array([C[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] for i in range(k)])
    sj = stat_sigma(C, rng, 400).tolist()
    sb = stat_sigma(blocks, rng, 400).tolist()
    h = np.arange(k) * 3 + 2
    runs = []
    for seed_i in range(n):
        E = (L @ rng.standard_normal(3 * k)).reshape(k, 3)
        tab = {
            "stats": [[describe(E[:, j])[s] for s in P002_STATS] for j in range(3)],
            "sigma_joint": sj,
            "sigma_blocks": sb,
            "mean_h_sigma_joint": float(np.sqrt(C[np.ix_(h, h)].sum()) / k),
            "n": k,
        }
        c_true = np.full(7, 40.3)
        runs.append(
            {
                "seed": seed_i,
                "tie_point": {
                    "rays": [6] * k,
                    "table2": tab,
                    "table3": tab,
                    "cp_errors_nogcp_m": E.tolist(),
                },
                "twin_nogcp_mean_h_m": 0.0,
                "c": {
                    "truth_mm": c_true.tolist(),
                    "nogcp": {
                        "value": (c_true + np.r_[[1e-3] * 6, 0.0]).tolist(),
                        "sigma": [1e-3] * 6 + [0.0],  # a band no observation sees: fixed
                        "twin": c_true.tolist(),
                    },
                },
                "per_strip": [
                    {
                        "height_m": 1875.0,
                        "heading_deg": 1.0,
                        "n": 10,
                        "mean_dx_px": 0.1,
                        "mean_dy_px": 0.0,
                    },
                    {
                        "height_m": 1875.0,
                        "heading_deg": 179.0,
                        "n": 30,
                        "mean_dx_px": -0.1,
                        "mean_dy_px": 0.2,
                    },
                ],
            }
        )
    return {"scale": 0.05, "stats": list(P002_STATS), "runs": runs}


def test_joint_sigma_gives_z_of_unit_spread_and_blocks_do_not():
    """Errors drawn from a joint covariance whose heights share a 2 m shift: the STD and NMAD
    of the heights over 200 campaigns, divided by the joint σ̂, spread by 1 (±0.15); by the
    per-point blocks' σ̂ (which see the 2 m shift in every point) far less."""
    out = checkpoint_campaigns(_campaigns(200))
    for st in ("std", "nmad"):
        assert out[f"table3.{st}_h"]["sd_z"] == pytest.approx(1.0, abs=0.15)
        assert out[f"table3.{st}_h.blocks"]["sd_z"] < 0.3
    # the mean height: 2 m of shift over a joint σ̂ that knows it, within 3σ̂ nearly always
    assert out["mean_h_nogcp_within"] >= 195
    assert out["enough"] and out["n_campaigns"] == 200
    # nine normal errors: the farthest from their median is within a few NMADs
    assert 0 < np.median(out["h_farthest_over_nmad"]) < 4


def test_counts_c_against_the_twin_and_groups_strips():
    out = checkpoint_campaigns(_campaigns(3))
    assert not out["enough"]  # fewer than 8 campaigns: no verdict
    # c − twin = 1 µm with σ̂ 1 µm in six bands (the fixed band is left out): z = 1, within 3
    assert out["c_minus_twin_nogcp_z"] == pytest.approx([1.0] * 3)
    assert out["c_within"] == 3
    assert out["c_minus_twin_nogcp_um"] == pytest.approx([1.0] * 3)
    g = out["per_group"]
    assert [(x["heading_deg"], x["n"]) for x in g] == [(0.0, 30), (180.0, 90)]
    assert g[1]["mean_dy_px"] == pytest.approx(0.2)


def test_no_runs_is_refused():
    with pytest.raises(ValueError, match="no runs"):
        checkpoint_campaigns({"stats": list(P002_STATS), "runs": []})


def test_the_recorded_bench_reads():
    """The committed bench result (the chapter reads it): every campaign has ≥ 2 check points
    with and without GCPs, σ̂ finite and positive, and the count it claims."""
    import json
    from pathlib import Path

    f = Path(__file__).parents[1] / "bench" / "results" / "lp_checkpoints_seeds.json"
    if not f.exists():
        pytest.skip("bench/results/lp_checkpoints_seeds.json not recorded")
    doc = json.loads(f.read_text())
    out = checkpoint_campaigns(doc)
    assert out["n_campaigns"] == len(doc["seeds"]) == len(set(doc["seeds"]))
    assert min(out["n_check_points"]) >= 2 and min(out["n_check_points_nogcp"]) >= 2
    s = np.array(out["mean_h_nogcp_sigma_m"] + out["table3.std_h"]["sigma_m"])
    assert np.all(np.isfinite(s) & (s > 0))
    assert out["enough"] == (out["n_campaigns"] >= 8)


def test_c_minus_twin_is_judged_in_the_sigma_of_the_difference_and_the_coupling_named():
    """Issue 37: c − c_twin was judged in the retrieval's σ̂ (1 µm here: z = 1, 'within'); in
    the σ of the difference (0.2 µm from the Monte Carlo) it is 5σ off and fails. The draws'
    mean heights follow their mean c (H = −0.05 m/µm · c): the coupling's correlation and
    slope are recovered, the retrieval's height offset from the twin is the c error's
    prediction, and the residual is judged in the draws' scatter about the line."""
    rng = np.random.default_rng(3)
    doc = _campaigns(8)
    for r in doc["runs"]:
        cd = 40.3 + 1e-3 * 0.2 * rng.standard_normal(16)  # mm; σ 0.2 µm about the twin
        hd = -0.05 * 1e3 * (cd - 40.3) + 0.002 * rng.standard_normal(16)
        r["nogcp_twin_mc"] = {
            "labels": [f"c_mm[{b}]" for b in range(7)],
            "z": [5.0] * 6 + [float("nan")],
            "mean_h_m": -0.05 * 1.0,  # c 1 µm off: −0.05 m
            "mean_h_twin_m": 0.0,
            "mean_h_draws_m": hd.tolist(),
            "c_mean_draws_mm": cd.tolist(),
            "c_mean_mm": 40.301,
            "c_mean_twin_mm": 40.3,
        }
    out = checkpoint_campaigns(doc)
    assert out["c_within"] == 8  # the old judge: the retrieval's σ̂ passes every campaign
    assert out["c_within_mc"] == 0 and out["c_minus_twin_nogcp_z_mc"] == pytest.approx([5.0] * 8)
    assert np.all(np.array(out["coupling_corr"]) < -0.9)
    assert out["coupling_slope_m_per_um"] == pytest.approx([-0.05] * 8, abs=0.01)
    assert out["mean_h_predicted_from_c_m"] == pytest.approx([-0.05] * 8, abs=0.01)
    assert out["mean_h_residual_within"] == 8
    # without the bench's Monte Carlo (an older file): nothing claimed
    assert "c_within_mc" not in checkpoint_campaigns(_campaigns(3))


def test_the_no_gcp_heights_scale_with_the_flying_height():
    """Issue 37, traced on seed 1 of bench_lp_checkpoints: the two check points "metres from
    the rest" (−46.3 and −45.6 m against −33.5 m) were the two seen only from the 2500 m
    strips; without GCPs a c error moves heights by −AGL·Δc/c, 4/3 as far from 2500 m. Heights
    k·AGL (k = −1.8 %) plus 0.5 m noise: the fit recovers k, and the STD about it is the noise's,
    not the metres of the flying-height mix."""
    rng = np.random.default_rng(5)
    doc = _campaigns(8)
    for r in doc["runs"]:
        a = np.array([1875.0] * 7 + [2500.0] * 2)
        h = -0.018 * a + 0.5 * rng.standard_normal(9)
        E = np.asarray(r["tie_point"]["cp_errors_nogcp_m"], float)
        E[:, 2] = h
        r["tie_point"]["cp_errors_nogcp_m"] = E.tolist()
        r["tie_point"]["table3"] = {**r["tie_point"]["table3"]}
        st = [list(x) for x in r["tie_point"]["table3"]["stats"]]
        st[2][I_STD] = float(np.std(h, ddof=1))
        r["tie_point"]["table3"]["stats"] = st
        r["tie_point"]["cp_agl_nogcp_m"] = a.tolist()
    out = checkpoint_campaigns(doc)
    assert out["agl_k"] == pytest.approx([-0.018] * 8, abs=0.001)
    assert np.all(np.array(out["std_h_m"]) > 4.0)  # the mix: metres
    assert np.all(np.array(out["std_h_after_agl_m"]) < 1.0)  # about k·AGL: the noise
    assert out["agl_mix_campaigns"] == 8
    assert "agl_k" not in checkpoint_campaigns(_campaigns(3))  # not recorded: nothing claimed
