"""``hsgeo reproduce rikola``: 003 Tables 3 and 4 and the joint model, from rendered pixels.

``scale`` = 1 renders the paper's bench (20 cubes × 25 bands); below 1 fewer cubes and ten bands
(the chapter's reduced size for the tests).
"""

from __future__ import annotations

import time

import numpy as np

from hsgeo.adjust import identifiability
from hsgeo.measure.aruco import detection_rate
from hsgeo.measure.targets import Observations
from hsgeo.papers import (
    RIKOLA_BANDS,
    RIKOLA_TABLE3,
    RIKOLA_TABLE3_SIGMA0_SQ,
    RIKOLA_TABLE4_GAP_MODEL,
    RIKOLA_TABLE4_ROP_MEAN_DEG,
)
from hsgeo.report import Reproduction, Row
from hsgeo.sensors.frame import mm_to_pixel
from hsgeo.workflows.rikola import (
    band_problem,
    calibrate_band,
    calibrate_joint,
    detect_targets_in_images,
    gap_regression,
    mean_relative_orientation,
    predict_band,
    predict_per_band,
    relative_orientation,
    rop_transformation_test,
)

__all__ = ["run", "setup", "observe", "corner_bias", "band_identifiability"]

SMALL_BANDS = (1, 2, 5, 8, 10, 11, 12, 15, 16, 20)
HELD_OUT = (8, 16)  # one band of each sensor, inside the gap range
TABLE3_BANDS = (5, 20)  # 003 Table 3
ROP_CUBE = 0  # 003 Table 4 (first) uses the bands of one cube


def observe(
    cfg: dict,
    truth,
    seed: int,
    cubes,
    bands,
    *,
    refine: str = "subpix",
    compare_refine: str | None = None,
    keep_images=(),
):
    """Render the bands of the cubes and measure them as a user would (the experiment of 003 §3.2).

    The images are rendered one at a time (:class:`hsgeo.simulate.rikola.Renderer`) and measured
    by the truth-free :func:`hsgeo.workflows.rikola.detect_targets_in_images`; the truth only
    counts the targets fully in view, for the detection rate.

    Returns
    -------
    obs : Observations
    obs_compare : Observations or None
        With the ``compare_refine`` refinement.
    images : dict
        ``(cube, band) -> image`` of ``keep_images``.
    expected : dict
        ``(cube, band) -> number of targets fully in view`` (from the truth), for the detection
        rate (:func:`hsgeo.measure.aruco.detection_rate`).
    """
    from hsgeo.simulate.rikola import Renderer

    r = Renderer(cfg, truth)
    plate = r.plate
    cam = cfg["camera"]
    size = (int(cam["width_px"]), int(cam["height_px"]))
    obj = plate.corners()
    expected, images = {}, {}
    keep = set(map(tuple, keep_images))

    def rendered():
        for c in cubes:
            for b in bands:
                img = r.render(c, b, seed)
                if (c, b) in keep:
                    images[(c, b)] = img
                true_px = mm_to_pixel(truth.project(c, b, obj), size, cam["pixel_mm"])
                inside = np.all((true_px > 2) & (true_px < np.array(size) - 3), axis=(1, 2))
                expected[(c, b)] = int(inside.sum())
                yield (c, b), img

    obs, obs_cmp = detect_targets_in_images(
        rendered(),
        obj,
        plate.ids,
        size,
        float(cam["pixel_mm"]),
        dictionary=plate.dictionary,
        refine=refine,
        compare_refine=compare_refine,
    )
    return obs, obs_cmp, images, expected


def band_identifiability(obs: Observations, band: int, truth) -> object:
    """Rank of the per-band design at the truth (:func:`hsgeo.adjust.identifiability`)."""
    p, blk, cubes = band_problem(obs, band, 9.0, 0.02)
    p.set("interior", truth.interior(band))
    p.set("distortion_mm", truth.KP)
    p.set("poses", np.array([truth.band_pose(int(c), band) for c in cubes]))
    return identifiability(p, blk)


def corner_bias(obs: Observations, truth) -> dict[int, dict[str, float]]:
    """Corner displacement with exposure (003 §3.2), per band, against the simulated truth.

    Returns
    -------
    dict band -> ``outward_px`` (mean displacement of the detected corners away from the
    target's centre; negative: the target looks smaller), ``scale`` (mean ratio of detected to
    true side length, the paper's scale factor), ``centroid_mean_px`` (x, y) and
    ``centroid_sd_px`` (x, y) of the centroid error.
    """
    out = {}
    for b in np.unique(obs.band):
        o = obs.select(obs.band == b)
        true = np.stack(
            [
                mm_to_pixel(truth.project(int(c), int(b), X), obs.image_size, obs.pixel_mm)
                for c, X in zip(o.cube, o.corners_obj, strict=True)
            ]
        )
        e = o.corners_px - true
        centre = true.mean(axis=1, keepdims=True)
        u = true - centre
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        side = lambda c: np.linalg.norm(np.roll(c, -1, axis=1) - c, axis=-1)  # noqa: E731
        ce = o.centroids_px - true.mean(axis=1)
        out[int(b)] = {
            "outward_px": float(np.mean(np.sum(e * u, axis=-1))),
            "scale": float(np.mean(side(o.corners_px) / side(true))),
            "centroid_mean_px": ce.mean(axis=0).tolist(),
            "centroid_sd_px": ce.std(axis=0).tolist(),
        }
    return out


def setup(seed: int = 0, scale: float = 1.0):
    """Configuration, truth, cubes and bands for a seed and size."""
    from hsgeo.simulate.rikola import make_truth
    from hsgeo.simulate.scenarios import load_scenario

    cfg = load_scenario("rikola_bench")
    n_full = int(cfg["geometry"]["n_cubes"])
    if scale >= 1.0:
        n_cubes, bands = n_full, tuple(int(b) for b in RIKOLA_BANDS["band"])
    else:
        n_cubes, bands = max(8, int(round(n_full * scale))), SMALL_BANDS
    truth = make_truth(cfg, np.random.default_rng([int(seed), 0]), n_cubes=n_cubes)
    return cfg, truth, list(range(n_cubes)), list(bands)


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """The chapter's tables; below scale 1: 8 cubes × 10 bands instead of 20 × 25."""
    t_start = time.time()
    cfg, truth, cubes, bands = setup(seed, scale)
    sigma_px = float(cfg["measure"]["sigma_px"])
    t0 = time.time()
    obs, obs_contour, images, expected = observe(
        cfg,
        truth,
        seed,
        cubes,
        bands,
        compare_refine="contour",
        keep_images=[(ROP_CUBE, b) for b in (1, 5, 20)],
    )
    t_observe = time.time() - t0
    # 003 §3.3: every band its own camera
    t0 = time.time()
    cals = {b: calibrate_band(obs, b, sigma_px=sigma_px) for b in bands}
    t_bands = time.time() - t0
    rows: list[Row] = []
    tbl = RIKOLA_BANDS
    # --- 003 Table 3
    for b in TABLE3_BANDS:
        c = cals[b]
        tr = dict(
            zip(
                (
                    "f_mm",
                    "x0_mm",
                    "y0_mm",
                    "K1_per_mm2",
                    "K2_per_mm4",
                    "K3_per_mm6",
                    "P1_per_mm",
                    "P2_per_mm",
                ),
                np.r_[truth.interior(b), truth.KP],
                strict=True,
            )
        )
        for q, (v, s) in c.iop.items():
            pv, ps = RIKOLA_TABLE3[b][q]
            unit = q.split("_", 1)[1] if "_" in q else ""
            row = Row(
                "003 Table 3",
                f"{q.split('_')[0]}_band{b}",
                unit.replace("per_", "1/"),
                pv,
                ps,
                v,
                s,
                tr[q],
                # issue 22: the truth is the paper's x0, y0 (band 20: sensor I, band 5: II), or
                # computed from the paper (f: its gap line + scatter; K, P: the two bands' mean,
                # K2 = K3 = 0 as "not significant")
                provenance="derived",
            )
            if row.truth_is_paper():
                row.provenance = "paper"
            if q == "f_mm" and row.z_paper is not None:
                # used only if the verdict is "differs"
                row.reason = (
                    f"{abs(row.z_paper):.1f}σ from the paper: the simulated f of a band is the "
                    "paper's gap line (003 Table 4) plus a random scatter, not its Table 3 value"
                )
            if q[0] in "KP" and row.z_paper is not None:
                # used only if the verdict is "differs": the truth is one set for all bands
                row.reason = (
                    f"{abs(row.z_paper):.1f}σ from the paper: the simulation has one distortion "
                    "set for all bands (means of 003 Table 3's bands 5 and 20; K2 = K3 = 0), "
                    "and the paper's two bands differ from each other"
                )
            rows.append(row)
        rows.append(
            Row(
                "003 Table 3",
                f"sigma0_sq_band{b}",
                "",
                RIKOLA_TABLE3_SIGMA0_SQ[b],
                None,
                c.result.sigma0**2,
                None,
                1.0,
                verdict="not testable",
                reason="σ0² scales with the a-priori σ of a centroid; the paper's was 1 in an "
                "unstated unit",
                provenance="chosen",
            )
        )
    # --- 003 Table 4 (first): ROP from pairs (k, k+10). The paper uses one cube; the ROPs of
    # one cube share that cube's systematic centroid errors (their spread understates the
    # error), so every cube is used: rop_all[pair, cube], and σ̂ of the mean from the scatter
    # of the per-cube means between cubes.
    pairs = [(k, k + 10) for k in range(1, 11) if k in cals and k + 10 in cals]
    rop_all = np.array(
        [
            [relative_orientation(cals[k1].pose(c), cals[k2].pose(c))[0] for c in cubes]
            for k2, k1 in pairs
        ]
    )  # k2 sensor II, k1 sensor I
    rop_cov = [
        relative_orientation(
            cals[k1].pose(ROP_CUBE),
            cals[k2].pose(ROP_CUBE),
            cals[k1].pose_covariance(ROP_CUBE),
            cals[k2].pose_covariance(ROP_CUBE),
        )[1]
        for k2, k1 in pairs
    ]
    m = mean_relative_orientation(cals, obs, cubes, pairs, rop_all=rop_all)
    rop, rop_mean, rop_mean_sigma = m["rop_pairs"], m["rop_mean"], m["rop_mean_sigma"]
    pb_clusters, deff_pairs = m["band_clusters"], m["deff_pairs"]
    rop_cube0 = rop_all[:, cubes.index(ROP_CUBE)]
    for i, q in enumerate(("domega_deg", "dphi_deg", "dkappa_deg")):
        rows.append(
            Row(
                "003 Table 4 ROP",
                q,
                "deg",
                RIKOLA_TABLE4_ROP_MEAN_DEG[i],
                None,
                np.rad2deg(rop_mean[i]),
                np.rad2deg(rop_mean_sigma[i]),
                np.rad2deg(truth.rotation_rad[i]),
                provenance="paper",
            )
        )
    # transformation test (003 §3.4): discrepancies of the sensor-II centroids from the
    # sensor-I ones of the same cube and target, before and after applying the mean ROP
    disc = rop_transformation_test(obs, cals, pairs, rop_mean, ROP_CUBE)
    # --- 003 Table 4 (second): f against gap, bands 1 and 11 excluded (003 §3.5)
    gaps, f_hat, f_sig = {}, {}, {}
    reg, reg_truth = {}, {}
    for s in (1, 2):
        bs = [b for b in bands if tbl["sensor"][b - 1] == s and b not in (1, 11)]
        g = tbl["gap_nm"][np.array(bs) - 1]
        fh = np.array([cals[b].value("interior")[0] for b in bs])
        gaps[s], f_hat[s] = g, fh
        f_sig[s] = np.array([cals[b].sigma("interior")[0] for b in bs])
        reg[s] = gap_regression(g, fh)
        reg_truth[s] = gap_regression(g, truth.f_mm[np.array(bs) - 1])
        pm = RIKOLA_TABLE4_GAP_MODEL[s]
        rows += [
            Row(
                "003 Table 4 gap model",
                f"a_sensor{s}_mm_per_nm",
                "mm/nm",
                pm["a_mm_per_nm"][0],
                pm["a_mm_per_nm"][1],
                reg[s]["a"],
                reg[s]["sigma_a"],
                truth.gap_model[s - 1, 0],
                provenance="paper",
            ),
            Row(
                "003 Table 4 gap model",
                f"b_sensor{s}_mm",
                "mm",
                pm["b_mm"][0],
                pm["b_mm"][1],
                reg[s]["b"],
                reg[s]["sigma_b"],
                truth.gap_model[s - 1, 1],
                provenance="paper",
            ),
            Row(
                "003 Table 4 gap model",
                f"r2_sensor{s}",
                "%",
                pm["r2_percent"],
                None,
                100 * reg[s]["r2"],
                None,
                100 * reg_truth[s]["r2"],
                # the scatter of f about the gap line was chosen to give the paper's R² in
                # expectation (rikola_bench.toml)
                provenance="tuned",
            ),
        ]
    # --- 003 §3.2: corners move with exposure, centroids do not (against the truth)
    biases = {"contour": corner_bias(obs_contour, truth), "subpix": corner_bias(obs, truth)}
    for name, bb in biases.items():
        o = np.array([v["outward_px"] for v in bb.values()])
        cm = np.array([v["centroid_mean_px"] for v in bb.values()])
        cs = np.array([v["centroid_sd_px"] for v in bb.values()])
        t = "003 §3.2 corners and centroids"
        rows += [
            Row(t, f"corner_shift_min_{name}", "px", reproduced=float(o.min())),
            Row(t, f"corner_shift_max_{name}", "px", reproduced=float(o.max())),
            Row(t, f"centroid_bias_max_{name}", "px", reproduced=float(np.abs(cm).max())),
            Row(t, f"centroid_sd_{name}", "px", reproduced=float(cs.mean())),
        ]
    # --- the joint model (003 §3.5 future work); σ of a centroid from the per-band σ0
    sigma0_pool = float(np.sqrt(np.mean([c.result.sigma0**2 for c in cals.values()])))
    sigma_joint = sigma_px * sigma0_pool
    f_sd = np.sqrt(np.mean(np.concatenate(list(f_sig.values())) ** 2))
    scatter = tuple(
        float(np.sqrt(max(reg[s]["s"] ** 2 - f_sd**2, (0.5 * f_sd) ** 2))) for s in (1, 2)
    )
    t0 = time.time()
    joint = calibrate_joint(obs, sigma_px=sigma_joint, scatter_mm=scatter, init=cals)
    t_joint = time.time() - t0
    R = joint  # value() and sigma() with the design effect of the target clusters
    jrows = [
        (
            "a_sensor1_mm_per_nm",
            "mm/nm",
            R.value("gap_model")[0, 0],
            R.sigma("gap_model")[0, 0],
            truth.gap_model[0, 0],
            RIKOLA_TABLE4_GAP_MODEL[1],
        ),
        (
            "b_sensor1_mm",
            "mm",
            R.value("gap_model")[0, 1],
            R.sigma("gap_model")[0, 1],
            truth.gap_model[0, 1],
            None,
        ),
        (
            "a_sensor2_mm_per_nm",
            "mm/nm",
            R.value("gap_model")[1, 0],
            R.sigma("gap_model")[1, 0],
            truth.gap_model[1, 0],
            None,
        ),
        (
            "b_sensor2_mm",
            "mm",
            R.value("gap_model")[1, 1],
            R.sigma("gap_model")[1, 1],
            truth.gap_model[1, 1],
            None,
        ),
    ]
    paper_gap = {
        "a_sensor1_mm_per_nm": RIKOLA_TABLE4_GAP_MODEL[1]["a_mm_per_nm"],
        "b_sensor1_mm": RIKOLA_TABLE4_GAP_MODEL[1]["b_mm"],
        "a_sensor2_mm_per_nm": RIKOLA_TABLE4_GAP_MODEL[2]["a_mm_per_nm"],
        "b_sensor2_mm": RIKOLA_TABLE4_GAP_MODEL[2]["b_mm"],
    }
    for q, u, v, s, t, _ in jrows:
        rows.append(
            Row("joint model", q, u, paper_gap[q][0], paper_gap[q][1], v, s, t, provenance="paper")
        )
    for i, q in enumerate(("x0_sensor1_mm", "y0_sensor1_mm", "x0_sensor2_mm", "y0_sensor2_mm")):
        paper = RIKOLA_TABLE3[20 if i < 2 else 5]["x0_mm" if i % 2 == 0 else "y0_mm"]
        rows.append(
            Row(
                "joint model",
                q,
                "mm",
                paper[0],
                paper[1],
                R.value("pp_mm").ravel()[i],
                R.sigma("pp_mm").ravel()[i],
                truth.pp_mm.ravel()[i],
                provenance="paper",
            )
        )
    for i, q in enumerate(("K1_per_mm2", "K2_per_mm4", "K3_per_mm6", "P1_per_mm", "P2_per_mm")):
        rows.append(
            Row(
                "joint model",
                q,
                q.split("_", 1)[1].replace("per_", "1/"),
                None,
                None,
                R.value("distortion_mm")[i],
                R.sigma("distortion_mm")[i],
                truth.KP[i],
            )
        )
    for i, q in enumerate(("domega_deg", "dphi_deg", "dkappa_deg")):
        rows.append(
            Row(
                "joint model",
                q,
                "deg",
                RIKOLA_TABLE4_ROP_MEAN_DEG[i],
                None,
                np.rad2deg(R.value("sensor2_rotation")[i]),
                np.rad2deg(R.sigma("sensor2_rotation")[i]),
                np.rad2deg(truth.rotation_rad[i]),
                provenance="paper",
            )
        )
    for i, q in enumerate(("tx_mm", "ty_mm", "tz_mm")):
        rows.append(
            Row(
                "joint model",
                q,
                "mm",
                None,
                None,
                R.value("sensor2_offset_mm")[i],
                R.sigma("sensor2_offset_mm")[i],
                truth.offset_mm[i],
            )
        )
    rows.append(Row("joint model", "sigma0", "", None, None, R.result.sigma0, None, 1.0))
    # --- held-out bands: joint model vs the per-band route
    t0 = time.time()
    held = {}
    for h in HELD_OUT:
        if h not in bands:
            continue
        jh = calibrate_joint(
            obs,
            exclude_bands=[h],
            sigma_px=sigma_joint,
            scatter_mm=scatter,
            init={b: c for b, c in cals.items() if b != h},
        )
        r_joint = predict_band(jh, obs, h)
        # the same prediction with the band's true focal length (an oracle): what is left is
        # the error of everything but f
        vals = {k: v.copy() for k, v in jh.result.params.values().items()}
        s_row = RIKOLA_BANDS["sensor"] - 1
        line = vals["gap_model"][s_row, 0] * RIKOLA_BANDS["gap_nm"] + vals["gap_model"][s_row, 1]
        r_oracle = _predict_with(jh, obs, h, vals, df=truth.f_mm - line)
        r_perband = predict_per_band(cals, obs, h, bands)
        held[h] = {
            "joint": _rms(r_joint),
            "joint_true_f": _rms(r_oracle),
            "per_band": _rms(r_perband),
            "calibrated": _rms(cals[h].residuals_px),
        }
        for k, v in held[h].items():
            rows.append(Row("held-out band", f"rms_band{h}_{k}", "px", None, None, v, None, None))
    t_held = time.time() - t0
    meta = {
        "scale": scale,
        "n_cubes": len(cubes),
        "bands": bands,
        "images": len(cubes) * len(bands),
        "targets": int(len(obs.cube)),
        "detection_rate": detection_rate(len(obs.cube), sum(expected.values())),
        "detection_rate_contour": detection_rate(len(obs_contour.cube), sum(expected.values())),
        "sigma_px_apriori": sigma_px,
        "sigma0_pooled_bands": sigma0_pool,
        "sigma_px_joint": sigma_joint,
        "df_prior_mm": list(scatter),
        "rop_pairs": [list(p) for p in pairs],
        "band_clusters": pb_clusters,
        "rop_deff_pairs": deff_pairs,
        "rop_pairs_deg": np.rad2deg(rop).tolist(),
        "rop_pairs_cube0_deg": np.rad2deg(rop_cube0).tolist(),
        "rop_cube0_mean_deg": np.rad2deg(rop_cube0.mean(axis=0)).tolist(),
        "rop_cube0_mean_sigma_deg": np.rad2deg(
            np.sqrt(np.diag(np.sum(rop_cov, axis=0))) / len(pairs)
        ).tolist(),
        "rop_discrepancy_px": disc,
        "held_out": {str(k): v for k, v in held.items()},
        "rms_px_per_band": _rms(np.concatenate([c.residuals_px for c in cals.values()])),
        "rms_px_joint": _rms(joint.residuals_px),
        "sigma0_joint": R.result.sigma0,
        "joint_clusters": joint.clusters,
    }
    # wall times vary from run to run: they stay out of the (bit-reproducible) JSON
    extras = {
        "cfg": cfg,
        "truth": truth,
        "obs": obs,
        "obs_contour": obs_contour,
        "images": images,
        "cals": cals,
        "joint": joint,
        "rop": rop,
        "rop_cube0": rop_cube0,
        "rop_cube0_cov": np.array(rop_cov),
        "corner_bias": biases,
        "rop_all": rop_all,
        "pairs": pairs,
        "regression": reg,
        "regression_truth": reg_truth,
        "gaps": gaps,
        "f_hat": f_hat,
        "f_sigma": f_sig,
        "seconds": {
            "observe": t_observe,
            "per_band": t_bands,
            "joint": t_joint,
            "held_out": t_held,
            "total": time.time() - t_start,
        },
    }
    return Reproduction("rikola", seed, rows, meta, extras)


def _rms(r) -> float:
    return float(np.sqrt(np.mean(np.sum(np.asarray(r) ** 2, axis=1))))


def _predict_with(joint, obs, band, values, df):
    from hsgeo.sensors.rikola import JointCentroids

    sel = (obs.band == band) & np.isin(obs.cube, joint.cubes)
    o = obs.select(sel)
    blk = JointCentroids(
        np.searchsorted(joint.cubes, o.cube),
        np.searchsorted(RIKOLA_BANDS["band"], o.band),
        o.corners_obj,
        o.centroids_mm,
        1.0,
        RIKOLA_BANDS["gap_nm"],
        RIKOLA_BANDS["sensor"],
    )
    values = dict(values)
    values["df_mm"] = np.asarray(df, float)
    return blk.evaluate(values, False)[0].reshape(-1, 2) / obs.pixel_mm * np.array([1.0, -1.0])
