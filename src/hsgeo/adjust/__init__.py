"""The adjustment engine: named parameters, residual blocks, one least-squares solver.

Layout: :mod:`~hsgeo.adjust.parameters` (named blocks), :mod:`~hsgeo.adjust.residuals`
(observation equations), :mod:`~hsgeo.adjust.options` (solver settings),
:mod:`~hsgeo.adjust.solver` (the Levenberg–Marquardt loop), :mod:`~hsgeo.adjust.system`
(linearisation), :mod:`~hsgeo.adjust.schur` (normal equations, Schur complement),
:mod:`~hsgeo.adjust.datum` (identifiability), :mod:`~hsgeo.adjust.robust` (outlier
rejection), :mod:`~hsgeo.adjust.result` (estimates and their quality).
"""

from hsgeo.adjust.datum import Identifiability, identifiability
from hsgeo.adjust.options import SolverOptions
from hsgeo.adjust.parameters import Block, Parameters
from hsgeo.adjust.residuals import Indexed, ResidualBlock
from hsgeo.adjust.result import AdjustmentResult
from hsgeo.adjust.solver import adjust

__all__ = [
    "Parameters",
    "Block",
    "ResidualBlock",
    "Indexed",
    "SolverOptions",
    "adjust",
    "identifiability",
    "Identifiability",
    "AdjustmentResult",
]
