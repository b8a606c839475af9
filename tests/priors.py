"""The a-priori camera of the simulated 002 campaign for tests that build a pushbroom problem.

:class:`hsgeo.workflows.pushbroom_ba.CameraPrior` has no defaults for its σ (a user's
instruments' values, never a paper's): tests take them from the campaign's scenario, as the
chapters do (:func:`hsgeo.reproduce.pushbroom_runs.camera_prior`).
"""

from __future__ import annotations


def campaign_prior(n_bands: int | None = None, **kw):
    """:class:`CameraPrior` with :class:`CampaignConfig`'s values; ``kw`` overrides them."""
    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig
    from hsgeo.workflows.pushbroom_ba import CameraPrior

    cfg = CampaignConfig()
    base = {
        "n_bands": len(cfg.c_offsets_um) if n_bands is None else n_bands,
        "pixel_mm": cfg.pixel_mm,
        "c_mm": cfg.c_nominal_mm,
        "sigma_lever_m": cfg.sigma_lever_m,
        "sigma_pos_m": tuple(cfg.sigma_pos_m),
        "sigma_att_rad": tuple(cfg.sigma_att_rad),
        "sigma_obs_px": cfg.sigma_obs_px,
        "sigma_gcp_m": cfg.sigma_gcp_m,
    }
    return CameraPrior(**(base | kw))


def priors_toml() -> str:
    """The campaign's a-priori σ as a camera file's keys, to append right after the
    ``[camera]``/``[sensor]`` table's own keys (``sigma_lever_m`` belongs to that table)."""
    import numpy as np

    from hsgeo.simulate.pushbroom_campaign_types import CampaignConfig

    cfg = CampaignConfig()
    pos = ", ".join(repr(float(v)) for v in cfg.sigma_pos_m)
    att = ", ".join(repr(float(v)) for v in np.rad2deg(cfg.sigma_att_rad))
    return (
        f"sigma_lever_m = {cfg.sigma_lever_m!r}\n[gnss_ins]\nsigma_pos_m = [{pos}]\n"
        f"sigma_att_deg = [{att}]\n[observations]\nsigma_px = {cfg.sigma_obs_px!r}\n"
        f"[gcp]\nsigma_m = {cfg.sigma_gcp_m!r}\n"
    )
