"""Judges of the LP retrieval that do not share what they judge.

Two judges of ``hsgeo reproduce lp-observations`` whose reference is independent of the
retrieval's own observations:

* **Point targets** (:func:`target_judge`): the same campaign rendered again with small
  targets of known ground centre (:attr:`hsgeo.simulate.lp_campaign.LpConfig.target_spacing_m`,
  :data:`TARGET_SPACING_M`; the chapter's own campaign has none, so its rows do not move),
  retrieved by the same pipeline. A target is made as survey targets are: a 0.6 m grey square
  (:data:`TARGET_REFLECTANCE`, unsaturated in every band) centred on a uniform dark square of
  :data:`TARGET_SURROUND_M`, wider than the corner detector's circle in every strip — its image
  is symmetric about its centre, so BRISK's FAST score peaks there, and the recorded centre is
  where the detector fires. (White 2-px squares painted over the texture, as before, saturate
  in every band and take the texture's asymmetry: BRISK found them up to 0.4 m from their
  centre, a corner or edge, and 4 of 8 campaigns had < 95 % within 1 px of the centre while
  the same observations were ≥ 95 % within 1 px of their tie point's other rays: the
  reference, not the measurement, was off.) A tie point is *on* a target when the median of
  the true ground points its observations see lies within :data:`ON_TARGET_M` of the target's
  recorded centre; each of its observations is then judged against the target's centre
  projected through the **true** camera and trajectory at the observation's line time
  (:func:`hsgeo.reproduce.lp_judge.observation_errors_px` with the targets as known points).
  Beside it, on the same retrieval, the shares against the median of the tie point's own
  observations (the chapter's reference, which shares the observation it judges) and against
  the median of the others (leave-one-out).

  What this judge shares with what it judges: (i) the renderer's camera model and true
  trajectory, which both drew the pixels and project the reference (the truth, by design);
  (ii) *which* tie points are judged — those whose own observations' median ground point lies
  within :data:`ON_TARGET_M` of a target (a tie point the matcher put off every target is not
  judged; on the bench's campaigns the on-target tie points lie ≤ 0.18 m from a centre and
  none between that and 0.6 m, so the radius cuts no continuum). What it does not share: the
  reference position — the target's recorded centre, fixed before any pixel is rendered — is
  moved by no observation, no median and no adjustment.
* **Retrieved − twin** (:func:`twin_difference`): the exact twin
  (:func:`hsgeo.reproduce.lp_runs.exact_twin`) shares the navigation error, the priors and the
  tie points with the retrieval, so the retrieved σ̂ (which holds the priors' and the
  navigation's part) is not the σ of their difference. Monte Carlo over the retrieval's
  observation noise on the same campaign: the twin's observations (at their true image
  positions) plus the retrieval's own errors, each point's errors with a random sign (one sign
  per point: the *cluster wild bootstrap*, Cameron, Gelbach & Miller 2008), adjusted with the
  same settings, ``n_draws`` times; the σ of the difference is the RMS over the draws of
  (draw − twin), and z = (retrieved − twin) / that σ. For a linear adjustment
  (estimate = A·observations) the draws' covariance is Σ_p (A e_p)(A e_p)ᵀ over the points p,
  the cluster-robust sandwich: a point's errors keep their size, place and correlation (they
  share the point's median reference; a check point's key point sits on one corner of its
  square in every strip), so what the free point absorbs stays absorbed and an outlier stays
  on the observation the adjustment rejects. Drawing every error independently from the pool
  instead (``method="resample"``) breaks that structure: on the first two campaigns it gave an
  RMS z of 0.63, the σ too large.

References
----------
Jonassen et al. (2024), 002 §3.1, §4.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hsgeo.reproduce.lp_judge import observation_errors_px, within_fractions

__all__ = [
    "TARGET_SPACING_M",
    "TARGET_REFLECTANCE",
    "TARGET_SURROUND_M",
    "ON_TARGET_M",
    "N_DRAWS",
    "target_config",
    "targets_on",
    "target_judge",
    "twin_difference",
    "target_rows",
    "twin_rows",
    "judge_campaign",
    "parameter_units",
    "leave_one_out_rows",
]

#: Spacing (m) of the point targets' jittered grid in the judge's campaign (ours: ~13 px at
#: 0.30 m GSD, wider than a BRISK descriptor's core, so neighbours do not share a descriptor).
TARGET_SPACING_M = 4.0
#: Reflectance of a point target (ours: 0.45 in every band, 2500–3470 DN at this radiometry,
#: below ``dn_max`` = 4095 in every band; the white squares' 0.86–0.885 clip at 4095 in all seven,
#: a flat plateau whose highest corner score the texture or the noise picks).
TARGET_REFLECTANCE = 0.45
#: Side (m) of the uniform dark square (reflectance 0.05) each target is centred on (ours: FAST's
#: 16-pixel circle, radius 3 px, reaches 0.9 m from the centre at the 1875 m strips' 0.30 m GSD
#: and 1.2 m at the 2500 m strips' 0.40 m; half this side, 1.5 m, keeps the circle on the
#: surround in every strip, so the target's image is symmetric about its centre whatever the
#: texture around it — to 0.1 % at 0.9 m; at 1.2 m the PSF and the motion blur leak up to 0.04
#: of reflectance, ~10 % of the contrast, along track in the near infrared).
TARGET_SURROUND_M = 3.0
#: A tie point whose observations' true ground points have their median within this distance
#: (m, horizontal) of a target's centre is on that target (ours: the target's side, 2 px).
ON_TARGET_M = 0.6
#: Monte Carlo draws of the retrieval's observation noise for σ of retrieved − twin (t with 16
#: degrees of freedom: its RMS z is √(16/14) ≈ 1.07 when σ is right).
N_DRAWS = 16


def target_config(cfg=None):
    """The campaign's configuration with the point targets on: :data:`TARGET_SPACING_M`, a
    grey square of :data:`TARGET_REFLECTANCE` on a dark surround of :data:`TARGET_SURROUND_M`
    (module docstring).
    """
    from hsgeo.simulate.lp_campaign import LpConfig

    return replace(
        cfg or LpConfig(),
        target_spacing_m=TARGET_SPACING_M,
        target_reflectance=TARGET_REFLECTANCE,
        target_surround_m=TARGET_SURROUND_M,
    )


def targets_on(table, truth, square_ids=()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which tie points of ``table`` lie on a point target (module docstring).

    Returns
    -------
    point_ids : (p,) ndarray of str
        Tie points on a target.
    target_index : (p,) int ndarray
        Row of :attr:`LpTruth.target_xyz_m` of each.
    distance_m : (p,) ndarray
        Horizontal distance of each one's median true ground point from the target's centre.
    """
    tg = np.asarray(truth.target_xyz_m, float).reshape(-1, 3)
    pid = table["point_id"].to_numpy().astype(str)
    tie = ~np.isin(pid, np.asarray(square_ids, str))
    none = (np.zeros(0, str), np.zeros(0, np.int64), np.zeros(0))
    if not tg.shape[0] or not tie.any():
        return none
    g = truth.ground_points(
        table["t_s"].to_numpy(float)[tie],
        table["x_px"].to_numpy(float)[tie],
        table["band"].to_numpy()[tie],
    )
    ids, inv = np.unique(pid[tie], return_inverse=True)
    med = np.array([np.nanmedian(g[inv == k, :2], axis=0) for k in range(ids.size)])
    d = np.hypot(med[:, None, 0] - tg[None, :, 0], med[:, None, 1] - tg[None, :, 1])
    d = np.where(np.isfinite(d), d, np.inf)
    k = np.argmin(d, axis=1)
    dk = d[np.arange(ids.size), k]
    on = dk <= ON_TARGET_M
    return ids[on], k[on].astype(np.int64), dk[on]


def target_judge(table, truth, square_ids=(), square_xyz_m=None) -> dict:
    """The retrieval's tie-point observations judged three ways (module docstring).

    Parameters
    ----------
    table : pandas.DataFrame
        The observation table that reaches the adjustment.
    truth : hsgeo.simulate.lp_campaign.LpTruth
        With point targets (:func:`target_config`).
    square_ids, square_xyz_m
        The reference squares (left out of the shares).

    Returns
    -------
    dict
        ``targets`` (painted), ``targets_found`` (with a tie point on them),
        ``n_observations_on_targets``, ``errors_target_px`` ``(m, 2)``, ``within_target``
        ``{1.0, 0.5}``, ``within_median`` / ``within_leave_one_out`` (every tie point's
        observations, the chapter's two references) and the same restricted to the targets'
        tie points (``within_median_on_targets``, ``within_leave_one_out_on_targets``),
        ``on_target_distance_m``, ``per_tie_point`` (each on-target tie point's id, target,
        band, distance, observations, share within 1 px and largest error).
    """
    pid = table["point_id"].to_numpy().astype(str)
    is_sq = np.isin(pid, np.asarray(square_ids, str))
    ids, k, dist = targets_on(table, truth, square_ids)
    tg = np.asarray(truth.target_xyz_m, float).reshape(-1, 3)
    on = np.isin(pid, ids) & ~is_sq
    e_t = (
        observation_errors_px(table[on], truth, tuple(ids), tg[k]) if on.any() else np.zeros((0, 2))
    )
    per_point = []
    if on.any():
        e_len = np.hypot(e_t[:, 0], e_t[:, 1])
        pid_on, band_on = pid[on], table["band"].to_numpy()[on]
        for i, kk, dd in zip(ids, k, dist, strict=True):
            m = pid_on == i
            per_point.append(
                {
                    "point_id": str(i),
                    "target": int(kk),
                    "band": int(band_on[m][0]),
                    "distance_m": float(dd),
                    "n": int(m.sum()),
                    "within_1px": float(np.mean(e_len[m] <= 1.0)),
                    "max_error_px": float(e_len[m].max()),
                }
            )
    sq_xyz = None if square_xyz_m is None else np.asarray(square_xyz_m, float)
    e_med = observation_errors_px(table, truth, square_ids, sq_xyz)
    e_loo = observation_errors_px(table, truth, square_ids, sq_xyz, leave_one_out=True)
    return {
        "targets": int(tg.shape[0]),
        "targets_found": int(np.unique(k).size),
        "n_observations_on_targets": int(on.sum()),
        "n_tie_observations": int((~is_sq).sum()),
        "errors_target_px": e_t,
        "within_target": within_fractions(e_t),
        "within_median": within_fractions(e_med[~is_sq]),
        "within_leave_one_out": within_fractions(e_loo[~is_sq]),
        "within_median_on_targets": within_fractions(e_med[on]),
        "within_leave_one_out_on_targets": within_fractions(e_loo[on]),
        "on_target_distance_m": dist,
        "per_tie_point": per_point,
    }


def _flat_parameters(pz) -> tuple[list, np.ndarray, np.ndarray]:
    """Labels, values and σ̂ of :func:`hsgeo.reproduce.lp_runs.parameter_z`, flattened."""
    lab = [str(x) for p in pz.values() for x in p[0]]
    v = np.concatenate([np.asarray(p[1], float).ravel() for p in pz.values()])
    s = np.concatenate([np.asarray(p[2], float).ravel() for p in pz.values()])
    return lab, v, s


def _mean_h_error(r, cp_ids, h_true_m) -> float:
    """Mean height error (m) of the check points ``cp_ids`` an adjustment determined."""
    pos = {str(v): j for j, v in enumerate(r.point_ids)}
    have = [j for j, i in enumerate(cp_ids) if i in pos]
    z = r.result.value("points_m")[[pos[cp_ids[j]] for j in have], 2]
    return float(np.mean(z - h_true_m[have])) if have else float("nan")


def _c_mean(r) -> float:
    """Mean principal distance (mm) over the bands an adjustment estimated."""
    c, sc = r.result.value("c_mm").ravel(), r.result.sigma("c_mm").ravel()
    ok = np.isfinite(sc) & (sc > 0)
    return float(np.mean(c[ok]))


def twin_difference(
    ev: dict,
    obs,
    truth,
    twin: dict,
    *,
    n_draws: int = N_DRAWS,
    rng=0,
    method: str = "sign",
    gcp: bool = True,
) -> dict:
    """σ of retrieved − twin by Monte Carlo over the retrieval's observation noise (module
    docstring).

    Parameters
    ----------
    ev : dict
        :func:`hsgeo.reproduce.lp_runs.evaluate` of the campaign.
    obs, truth
        The campaign.
    twin : dict
        :func:`hsgeo.reproduce.lp_runs.exact_twin` of ``ev``.
    n_draws : int
        Monte Carlo draws (each one adjustment).
    rng : int or numpy.random.Generator
    method : {"sign", "resample"}
        ``"sign"``: each point's own errors with one random sign per point (module docstring);
        ``"resample"``: every observation's error drawn with replacement from the errors of
        its kind (tie points, check-point squares, GCPs).
    gcp : bool
        The adjustment with the GCPs (``ev["parameters"]`` against ``twin["parameters"]``) or
        without them (``ev["adjusted_nogcp"]`` against the twin adjusted without GCPs,
        ``twin["adjusted"]``; and the check points' mean height, ``mean_h_*``).

    Returns
    -------
    dict
        ``labels``, ``difference`` (retrieved − twin, the model's units), ``sigma_difference``
        (RMS over the draws of draw − twin), ``sigma_retrieved`` (the retrieved σ̂), ``z``
        (difference / σ of the difference; NaN for a fixed parameter), ``z_retrieved_sigma``
        (difference / retrieved σ̂, the chapter's former judge), ``draws`` ``(n_draws, p)``,
        ``n_draws``, ``failed_draws``; without GCPs also ``mean_h_m`` (the retrieval's
        check points' mean height error), ``mean_h_twin_m``, ``mean_h_draws_m`` (per draw)
        and ``c_mean_draws_mm`` (per draw, the mean principal distance over the bands seen).
    """
    from hsgeo.reproduce.lp_runs import _adjust, camera_prior, parameter_z

    g = np.random.default_rng(rng)
    res = ev["retrieval"]
    err = np.asarray(ev["obs_errors_px"], float)
    base = res.table.copy()
    base["x_px"] = base["x_px"].to_numpy(float) - err[:, 0]
    base["y_px"] = base["y_px"].to_numpy(float) - err[:, 1]
    pid = base["point_id"].to_numpy().astype(str)
    is_sq = np.asarray(ev["is_square"], bool)
    is_gcp = np.isin(pid, np.asarray(ev["gcp_ids"], str))
    groups = [~is_sq, is_sq & ~is_gcp, is_gcp]
    finite = np.all(np.isfinite(err), axis=1)
    cam = camera_prior(obs, truth.cfg)
    if gcp:
        lab, v_ret, s_ret = _flat_parameters(ev["parameters"])
    else:
        lab, v_ret, s_ret = _flat_parameters(parameter_z(ev["adjusted_nogcp"].result, truth.camera))
    _, v_twin, _ = _flat_parameters(twin["parameters"])
    cp = [str(x) for x in ev.get("cp_ids_nogcp", [])] if not gcp else []
    k_cp = [list(map(str, obs.square_ids)).index(i) for i in cp]
    h_true = np.asarray(truth.square_xyz_m, float)[k_cp, 2]

    def mean_h(r):
        return _mean_h_error(r, cp, h_true)

    c_mean = _c_mean
    mh_draws, c_draws = [], []
    if method not in ("sign", "resample"):
        raise ValueError(f"method must be 'sign' or 'resample', got {method!r}")
    _, cluster = np.unique(pid, return_inverse=True)
    e0 = np.where(np.isfinite(err), err, 0.0)
    draws, failed = [], 0
    for _ in range(int(n_draws)):
        noise = np.zeros_like(err)
        if method == "sign":
            noise = e0 * g.choice((-1.0, 1.0), cluster.max() + 1)[cluster][:, None]
        else:
            for m in groups:
                rows = np.flatnonzero(m)
                pool = err[m & finite]
                if rows.size and pool.shape[0]:
                    noise[rows] = pool[g.integers(0, pool.shape[0], rows.size)]
        t = base.copy()
        t["x_px"] = base["x_px"].to_numpy(float) + noise[:, 0]
        t["y_px"] = base["y_px"].to_numpy(float) + noise[:, 1]
        try:
            r, _, _ = _adjust(replace(res, table=t), obs, cam, gcp, ev["gcp_ids"])
        except Exception:  # noqa: BLE001 - a draw the solver cannot adjust is counted, not fatal
            failed += 1
            continue
        draws.append(_flat_parameters(parameter_z(r.result, truth.camera))[1])
        if not gcp:
            mh_draws.append(mean_h(r))
            c_draws.append(c_mean(r))
    D = np.array(draws).reshape(-1, v_ret.size) - v_twin
    sd = np.sqrt(np.mean(D**2, axis=0)) if D.shape[0] else np.full(v_ret.size, np.nan)
    fixed = ~(np.isfinite(s_ret) & (s_ret > 0))
    sd = np.where(fixed, np.nan, sd)
    d = v_ret - v_twin
    with np.errstate(invalid="ignore", divide="ignore"):
        z = d / sd
        z_r = d / s_ret
    extra = {}
    if not gcp:
        extra = {
            "mean_h_m": mean_h(ev["adjusted_nogcp"]),
            "mean_h_twin_m": mean_h(twin["adjusted"]),
            "mean_h_draws_m": np.array(mh_draws),
            "c_mean_draws_mm": np.array(c_draws),
            "c_mean_mm": c_mean(ev["adjusted_nogcp"]),
            "c_mean_twin_mm": c_mean(twin["adjusted"]),
        }
    return {
        **extra,
        "gcp": gcp,
        "labels": lab,
        "difference": d,
        "sigma_difference": sd,
        "sigma_retrieved": s_ret,
        "z": z,
        "z_retrieved_sigma": z_r,
        "draws": D,
        "n_draws": int(D.shape[0]),
        "failed_draws": failed,
        "method": method,
    }


def _rms(z) -> float:
    z = np.asarray(z, float)
    z = z[np.isfinite(z)]
    return float(np.sqrt(np.mean(z**2))) if z.size else float("nan")


def target_rows(j: dict):
    """Rows of table ``"independent judges"`` from :func:`target_judge` of the judge's campaign
    (the chapter's campaign with point targets).
    """
    from hsgeo.report import Row

    T = "independent judges"
    rows = [
        Row(table=T, quantity="targets_painted", unit="1", reproduced=float(j["targets"])),
        Row(table=T, quantity="targets_found", unit="1", reproduced=float(j["targets_found"])),
        Row(
            table=T,
            quantity="observations_on_targets",
            unit="1",
            reproduced=float(j["n_observations_on_targets"]),
        ),
    ]
    for lim, name in ((1.0, "within_1px_fraction"), (0.5, "within_half_px_fraction")):
        for key, suf, why in (
            (
                "within_target",
                "_vs_targets",
                "against the targets' true centres projected "
                "through the true geometry: a reference no observation moves",
            ),
            (
                "within_median",
                "_vs_median_targets_run",
                "against the median of each tie "
                "point's own observations (shares what it judges), same retrieval",
            ),
            (
                "within_leave_one_out",
                "_vs_leave_one_out_targets_run",
                "against the median of the tie point's other observations, same retrieval",
            ),
        ):
            v = j[key][lim]
            rows.append(
                Row(
                    table=T,
                    quantity=f"{name}{suf}",
                    unit="1",
                    reproduced=None if not np.isfinite(v) else v,
                    reason=f"the chapter's campaign rendered with point targets: {why}",
                )
            )
    return rows


def twin_rows(td: dict, units: dict):
    """Rows of table ``"retrieved minus twin"``: each camera parameter's retrieved − twin with
    the σ of the difference (Monte Carlo, :func:`twin_difference`; truth 0), and the RMS z over
    the parameters both ways. ``units``: label → (unit, factor) of the chapter's parameter rows.
    """
    from hsgeo.report import Row

    T = "retrieved minus twin"
    rows = []
    for q, d, s in zip(td["labels"], td["difference"], td["sigma_difference"], strict=True):
        unit, f = units.get(q, ("1", 1.0))
        qq = q.replace("_rad", "_deg") if unit == "deg" else q
        ok = np.isfinite(s) and s > 0
        rows.append(
            Row(
                table=T,
                quantity=qq,
                unit=unit,
                reproduced=float(d * f),
                sigma=float(s * f) if ok else None,
                truth=0.0,
                provenance="derived",
            )
        )
    rows += [
        Row(
            table=T,
            quantity="rms_z_sigma_of_difference",
            unit="1",
            reproduced=_rms(td["z"]),
            reason=f"σ of retrieved − twin from {td['n_draws']} Monte Carlo draws of the "
            "retrieval's observation errors on the same campaign (each point's errors with a "
            "random sign); 1 when σ is right, ≈1.07 for 16 draws",
        ),
        Row(
            table=T,
            quantity="rms_z_retrieved_sigma",
            unit="1",
            reproduced=_rms(td["z_retrieved_sigma"]),
            reason="the same differences in the retrieved σ̂, which holds the priors' and the "
            "navigation's part the twin shares",
        ),
        Row(table=T, quantity="monte_carlo_draws", unit="1", reproduced=float(td["n_draws"])),
    ]
    return rows


def judge_campaign(scale_sim: float, seed: int, cfg=None, progress=None) -> dict:
    """The chapter's campaign (``simulate(scale_sim, rng=seed)``) rendered again with point
    targets, retrieved as :func:`hsgeo.reproduce.lp_runs.evaluate` retrieves (the check points
    as tie points, the GCPs by their centroids; no adjustment), judged by :func:`target_judge`.
    """
    from hsgeo.reproduce.lp_runs import gcps_by_centroid, retrieval_inputs
    from hsgeo.simulate.lp_campaign import simulate
    from hsgeo.workflows.lp_observations import LpOptions, retrieve

    obs, truth = simulate(scale_sim, rng=seed, cfg=target_config(cfg))
    res = retrieve(
        retrieval_inputs(obs), LpOptions(rng=seed, squares_as="tie_point"), progress=progress
    )
    table = gcps_by_centroid(res, obs.gcp_ids)
    return target_judge(table, truth, obs.square_ids, truth.square_xyz_m)


def parameter_units(ev: dict) -> dict:
    """Label → (unit, factor) of each reported camera parameter (the chapter's rows' units)."""
    from hsgeo.workflows.pushbroom_ba import REPORTED_PARAMETERS

    return {
        str(lab): (unit, f)
        for name, unit, f in REPORTED_PARAMETERS
        for lab in ev["parameters"][name][0]
    }


def leave_one_out_rows(ev: dict, obs, truth):
    """The chapter's campaign's tie-point observations within 1 px and ½ px of the median of
    their tie point's *other* observations (table ``"independent judges"``).
    """
    from hsgeo.report import Row

    e = observation_errors_px(
        ev["retrieval"].table, truth, obs.square_ids, truth.square_xyz_m, leave_one_out=True
    )
    w = within_fractions(e[~np.asarray(ev["is_square"], bool)])
    return [
        Row(
            table="independent judges",
            quantity=f"{name}_leave_one_out",
            unit="1",
            reproduced=w[lim] if np.isfinite(w[lim]) else None,
            reason="against the median of the tie point's other observations (a reference "
            "that does not share the observation it judges)",
        )
        for lim, name in ((1.0, "within_1px_fraction"), (0.5, "within_half_px_fraction"))
    ]
