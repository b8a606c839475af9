"""The adjustment engine: named parameters, residual blocks, one least-squares solver."""

from hsgeo.adjust.engine import Identifiability, adjust, identifiability
from hsgeo.adjust.parameters import Block, Parameters
from hsgeo.adjust.residuals import Indexed, ResidualBlock
from hsgeo.adjust.result import AdjustmentResult

__all__ = [
    "Parameters",
    "Block",
    "ResidualBlock",
    "Indexed",
    "adjust",
    "identifiability",
    "Identifiability",
    "AdjustmentResult",
]
