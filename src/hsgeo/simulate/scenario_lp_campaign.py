"""The scenario file of the LP campaign: ``data_synthetic/lp_campaign.toml``, read into
:class:`LpCampaignScenario` by :func:`hsgeo.simulate.scenarios.load_scenario` (the one loader
of configurations): ``[lp]`` an :class:`~hsgeo.simulate.lp_campaign.LpConfig`, its
``[lp.campaign]`` the 002 geometry (``CampaignConfig`` of
:mod:`hsgeo.simulate.pushbroom_campaign_types`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hsgeo.simulate.lp_campaign import LpConfig
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = ["LpCampaignScenario"]


@dataclass(frozen=True)
class LpCampaignScenario:
    """``data_synthetic/lp_campaign.toml``: the LP campaign of 002 (the ground and radiometry
    are ours), ``[lp]`` an :class:`~hsgeo.simulate.lp_campaign.LpConfig` whose keys left out
    of the file keep its defaults (002's geometry among them).
    """

    scenario: ScenarioInfo
    lp: LpConfig = field(default_factory=LpConfig)
