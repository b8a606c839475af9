"""The LP chapter's check points over campaigns: what ``bench/bench_lp_checkpoints.py`` recorded.

One campaign cannot say whether the adjustment's σ̂ of a check-point statistic is right, nor
whether a no-GCP height offset is noise: :func:`checkpoint_campaigns` reads the bench's runs
(one rendered block per seed, retrieved from pixels and adjusted with and without GCPs) and
returns, per statistic and per claim, the numbers the chapter prints:

* the **z of STD and NMAD of the heights** over the campaigns, each campaign's statistic minus
  the campaigns' mean over that campaign's σ̂ (from the check points' joint covariance,
  :func:`hsgeo.reproduce.lp_observations.stat_sigma`, and from the per-point blocks alone): a
  σ̂ that is right gives z with a standard deviation of 1 (1 ± 0.3 over 8 campaigns);
* the **no-GCP mean height** of the check points with its joint σ̂, and the **principal
  distances without GCPs minus the exact twin's** (the same observations moved to their true
  image position, adjusted alike) with the retrieved σ̂: how many campaigns are within 3σ̂;
* the tie-point observations' mean image error per strip grouped by **flying height and
  heading** (the observation-level place a height offset comes from).

No claim rests on fewer than :data:`hsgeo.report.MIN_RUNS` campaigns: ``enough`` says so.

References
----------
Jonassen et al. (2024), 002 Tables 2 and 3, §5.3.
"""

from __future__ import annotations

import numpy as np

from hsgeo.report import MIN_RUNS
from hsgeo.stats import nmad

__all__ = ["checkpoint_campaigns", "Z_LIMIT"]

#: |z| at most this counts as "within" (3σ̂).
Z_LIMIT = 3.0


def _sd(x) -> float:
    x = np.asarray(x, float)
    return float(np.std(x, ddof=1)) if x.size > 1 else float("nan")


def _z_spread(S, sg, i_stat: int) -> dict:
    """A statistic of the heights over the campaigns: its values, σ̂, the SD of its z about the
    campaigns' mean, and its SD over the campaigns beside the median σ̂.
    """
    x, s = S[:, 2, i_stat], sg[:, 2, i_stat]
    z = (x - x.mean()) / s
    return {
        "values_m": x.tolist(),
        "sigma_m": s.tolist(),
        "sd_z": _sd(z),
        "sd_over_campaigns_m": _sd(x),
        "median_sigma_m": float(np.median(s)),
    }


def _per_group(runs) -> list[dict]:
    """Mean image error (dx, dy px) of the tie-point observations per (flying height, heading)
    over every campaign's strips, weighted by the strips' observations; a heading is rounded to
    the nearest 10° so that the strips flown one way fall in one group.
    """
    acc: dict = {}
    for r in runs:
        for s in r.get("per_strip", []):
            if not s["n"] or s["mean_dx_px"] is None:
                continue
            key = (round(s["height_m"] / 50) * 50, int(round(s["heading_deg"] / 10) * 10) % 360)
            a = acc.setdefault(key, [0, 0.0, 0.0])
            a[0] += s["n"]
            a[1] += s["n"] * s["mean_dx_px"]
            a[2] += s["n"] * s["mean_dy_px"]
    return [
        {
            "height_m": float(h),
            "heading_deg": float(d),
            "n": int(n),
            "mean_dx_px": sx / n,
            "mean_dy_px": sy / n,
        }
        for (h, d), (n, sx, sy) in sorted(acc.items())
    ]


def _flying_height_cause(runs, way: str, i_std: int) -> dict:
    """The no-GCP heights' scale with the flying height, per campaign.

    Without GCPs a principal-distance error Δc moves every point along its rays by
    −AGL·Δc/c (the no-GCP height rows, :func:`hsgeo.reproduce.lp_observations._height_rows`):
    a check point observed only from the 2500 m strips moves 2500/1875 = 4/3 as far as one
    seen from the 1875 m strips — metres apart when Δc̄ is tens of metres of height, a point
    "far from the rest" that is no blunder. Fitted per campaign through the origin, H_i ≈ k ·
    AGL_i (AGL_i: the mean flying height above the squares of the lines that observe check
    point i, the bench's ``cp_agl_nogcp_m``): ``agl_k`` (k, m of height per m of AGL, i.e.
    −Δc/c), ``std_h_after_agl_m`` (the STD of H_i − k·AGL_i) beside ``std_h_m``, and
    ``h_farthest_after_agl_over_nmad``. Empty when the bench did not record the heights.
    """
    if not all(r[way].get("cp_agl_nogcp_m") for r in runs):
        return {}
    k_, s0, s1, far = [], [], [], []
    for r in runs:
        h = np.asarray(r[way]["cp_errors_nogcp_m"], float)[:, 2]
        a = np.asarray(r[way]["cp_agl_nogcp_m"], float)
        k = float(np.sum(a * h) / np.sum(a * a))
        e = h - k * a
        k_.append(k)
        s0.append(float(r[way]["table3"]["stats"][2][i_std]))
        s1.append(float(np.std(e, ddof=1)) if e.size > 1 else float("nan"))
        d = np.abs(e - np.median(e))
        far.append(float(d.max() / nmad(e)) if nmad(e) > 0 else float("nan"))
    return {
        "agl_k": k_,
        "std_h_m": s0,
        "std_h_after_agl_m": s1,
        "h_farthest_after_agl_over_nmad": far,
        "agl_mix_campaigns": int(sum(np.ptp(r[way]["cp_agl_nogcp_m"]) > 100 for r in runs)),
    }


def _twin_monte_carlo(runs) -> dict:
    """Without GCPs, retrieved − twin in the σ of the difference, per campaign.

    From the bench's ``nogcp_twin_mc`` (:func:`hsgeo.reproduce.lp_targets.twin_difference`
    with ``gcp=False``):

    * ``c_minus_twin_nogcp_z_mc``: the band of largest |z| of c − c_twin in the σ of the
      difference, and ``c_within_mc`` (campaigns whose every band is within :data:`Z_LIMIT`);
    * ``mean_h_minus_twin_m`` and its σ (RMS over the draws of draw − twin), ``..._z``,
      ``mean_h_minus_twin_within``;
    * the **c–H coupling** the draws show: ``coupling_corr`` (correlation over the draws of
      the check points' mean height with the bands' mean c), ``coupling_slope_m_per_um``
      (regression slope, m of height per µm of c), and ``mean_h_predicted_from_c_m`` = slope ·
      (c̄ − c̄_twin): the height offset from the twin that the c error alone predicts, with
      ``mean_h_residual_m`` (what the c error leaves) and its σ
      (``mean_h_residual_sigma_m``, the draws' scatter about their regression line).

    Empty when the runs have no ``nogcp_twin_mc`` (an older bench file).
    """
    mc = [r.get("nogcp_twin_mc") for r in runs]
    if not runs or not all(mc):
        return {}
    zc, cin, dh, sh, zh, corr, slope, pred, resid, sres = ([] for _ in range(10))
    for m in mc:
        lab = list(m["labels"])
        ic = [i for i, q in enumerate(lab) if q.startswith("c_mm")]
        z = np.asarray(m["z"], float)[ic]
        z = z[np.isfinite(z)]
        zc.append(float(z[np.argmax(np.abs(z))]) if z.size else float("nan"))
        cin.append(bool(z.size) and bool(np.all(np.abs(z) <= Z_LIMIT)))
        hd = np.asarray(m["mean_h_draws_m"], float)
        cd = 1e3 * np.asarray(m["c_mean_draws_mm"], float)  # µm
        d = float(m["mean_h_m"] - m["mean_h_twin_m"])
        s = float(np.sqrt(np.mean((hd - m["mean_h_twin_m"]) ** 2)))
        dh.append(d)
        sh.append(s)
        zh.append(d / s if s > 0 else float("nan"))
        ok = np.isfinite(hd) & np.isfinite(cd)
        if ok.sum() > 2 and np.std(cd[ok]) > 0:
            b = float(np.polyfit(cd[ok], hd[ok], 1)[0])
            r = float(np.corrcoef(cd[ok], hd[ok])[0, 1])
            e = hd[ok] - m["mean_h_twin_m"] - b * (cd[ok] - 1e3 * m["c_mean_twin_mm"])
            sr = float(np.sqrt(np.mean(e**2)))
        else:
            b = r = sr = float("nan")
        p = b * 1e3 * (m["c_mean_mm"] - m["c_mean_twin_mm"])
        slope.append(b)
        corr.append(r)
        pred.append(float(p))
        resid.append(float(d - p))
        sres.append(sr)
    zh_a = np.array(zh)
    res_z = np.array(resid) / np.array(sres)
    return {
        "c_minus_twin_nogcp_z_mc": zc,
        "c_within_mc": int(np.sum(cin)),
        "mean_h_minus_twin_m": dh,
        "mean_h_minus_twin_sigma_m": sh,
        "mean_h_minus_twin_z": zh,
        "mean_h_minus_twin_within": int(np.sum(np.abs(zh_a) <= Z_LIMIT)),
        "coupling_corr": corr,
        "coupling_slope_m_per_um": slope,
        "mean_h_predicted_from_c_m": pred,
        "mean_h_residual_m": resid,
        "mean_h_residual_sigma_m": sres,
        "mean_h_residual_z": res_z.tolist(),
        "mean_h_residual_within": int(np.sum(np.abs(res_z) <= Z_LIMIT)),
    }


def checkpoint_campaigns(doc: dict, way: str = "tie_point") -> dict:
    """The chapter's numbers over the campaigns of ``bench/results/lp_checkpoints_seeds.json``.

    Parameters
    ----------
    doc : dict
        The bench's JSON (``runs``: one record per seed; ``stats``: the names of
        :data:`hsgeo.papers.P002_STATS`).
    way : {"tie_point", "centroid"}
        The check points as 002 measured them (the matcher's tie points) or by their centroids.

    Returns
    -------
    dict
        ``n_campaigns``, ``enough`` (≥ :data:`~hsgeo.report.MIN_RUNS`), ``scale``,
        ``n_check_points`` (per campaign, with and without GCPs), ``rays_mean``; for
        ``table2``/``table3`` and ``std``/``nmad``: ``"{table}.{stat}_h"`` →
        :func:`_z_spread` with the joint σ̂ and ``"{table}.{stat}_h.blocks"`` with the per-point
        blocks' σ̂; ``mean_h_nogcp_m``, ``mean_h_nogcp_sigma_m``, ``mean_h_nogcp_z`` (per
        campaign) and ``mean_h_nogcp_within`` (campaigns with |z| ≤ :data:`Z_LIMIT`);
        ``twin_mean_h_nogcp_m``; ``h_farthest_m`` / ``h_farthest_over_nmad`` (per campaign
        without GCPs, the largest |H − median H| of a check point, and over the NMAD);
        ``c_minus_twin_nogcp_um`` (per campaign, the mean over the
        bands the observations see),
        ``c_minus_twin_nogcp_z`` (per campaign, the band of largest |z|), ``c_within`` (campaigns
        whose every band is within); ``c_minus_truth_nogcp_um``; ``corr_mean_h_c`` (mean height
        against the bands' mean c error over the campaigns); ``per_group`` (:func:`_per_group`).

    Raises
    ------
    ValueError
        ``doc`` has no runs.
    """
    runs = doc.get("runs") or []
    if not runs:
        raise ValueError("the bench JSON has no runs: run bench/bench_lp_checkpoints.py")
    stats = list(doc["stats"])
    i_std, i_nmad, i_mean = stats.index("std"), stats.index("nmad"), stats.index("mean")
    n = len(runs)
    out: dict = {
        "n_campaigns": n,
        "enough": n >= MIN_RUNS,
        "scale": doc.get("scale"),
        "seeds": [r["seed"] for r in runs],
        "n_check_points": [r[way]["table2"]["n"] for r in runs],
        "n_check_points_nogcp": [r[way]["table3"]["n"] for r in runs],
        "rays_mean": float(np.mean([np.mean(r[way]["rays"]) for r in runs])),
    }
    for tab in ("table2", "table3"):
        S = np.array([r[way][tab]["stats"] for r in runs], float)
        for kind, suffix in (("sigma_joint", ""), ("sigma_blocks", ".blocks")):
            sg = np.array([r[way][tab][kind] for r in runs], float)
            for st, i in (("std", i_std), ("nmad", i_nmad)):
                out[f"{tab}.{st}_h{suffix}"] = _z_spread(S, sg, i)
    # a check point far from the rest (a blunder no covariance predicts) moves the STD, not
    # the NMAD: per campaign the largest |H − median H| and its multiple of the NMAD
    far, far_x = [], []
    for r in runs:
        eh = np.asarray(r[way]["cp_errors_nogcp_m"], float)[:, 2]
        d = np.abs(eh - np.median(eh))
        far.append(float(d.max()))
        far_x.append(float(d.max() / r[way]["table3"]["stats"][2][i_nmad]))
    out.update(h_farthest_m=far, h_farthest_over_nmad=far_x)
    out.update(_flying_height_cause(runs, way, i_std))
    mh = np.array([r[way]["table3"]["stats"][2][i_mean] for r in runs], float)
    smh = np.array([r[way]["table3"]["mean_h_sigma_joint"] for r in runs], float)
    z = mh / smh
    out.update(
        mean_h_nogcp_m=mh.tolist(),
        mean_h_nogcp_sigma_m=smh.tolist(),
        mean_h_nogcp_z=z.tolist(),
        mean_h_nogcp_within=int(np.sum(np.abs(z) <= Z_LIMIT)),
        twin_mean_h_nogcp_m=[float(r["twin_nogcp_mean_h_m"]) for r in runs],
    )
    v = [np.asarray(r["c"]["nogcp"]["value"], float) for r in runs]
    s = [np.asarray(r["c"]["nogcp"]["sigma"], float) for r in runs]
    t = [np.asarray(r["c"]["nogcp"]["twin"], float) for r in runs]
    tr = [np.asarray(r["c"]["truth_mm"], float) for r in runs]
    zc, dct, dc = [], [], []
    for vi, si, ti, tri in zip(v, s, t, tr, strict=True):
        ok = np.isfinite(si) & (si > 0)  # a band no observation sees keeps its prior, fixed
        zi = (vi[ok] - ti[ok]) / si[ok]
        zc.append(float(zi[np.argmax(np.abs(zi))]))
        dct.append(float(1e3 * np.mean(vi[ok] - ti[ok])))
        dc.append(float(1e3 * np.mean(vi[ok] - tri[ok])))
    dc = np.array(dc)
    both = np.std(mh) > 0 and np.std(dc) > 0
    out.update(_twin_monte_carlo(runs))
    out.update(
        c_minus_twin_nogcp_um=dct,
        c_minus_twin_nogcp_z=zc,
        c_within=int(np.sum(np.abs(np.array(zc)) <= Z_LIMIT)),
        c_minus_truth_nogcp_um=dc.tolist(),
        corr_mean_h_c=float(np.corrcoef(mh, dc)[0, 1]) if n > 2 and both else float("nan"),
        per_group=_per_group(runs),
    )
    return out
