"""NIST's certified nonlinear least-squares problems: the engine's public yardstick.

* :mod:`hsgeo.nist.models` — the 27 models as residual blocks, with analytic Jacobians;
* :mod:`hsgeo.nist.fits` — fits by hsgeo and scipy, scored by LRE against the certified values.

The files and their reader are in :mod:`hsgeo.io.nist_strd`. This package sits beside
:mod:`hsgeo.adjust` rather than in it: the engine knows no problem (GUIDE §2), and these
models are problems like a sensor's.
"""

from hsgeo.nist.fits import (
    NIST_OPTIONS,
    NistFit,
    certify,
    covariance_sigma,
    fit_hsgeo,
    fit_scipy,
    option_steps,
    score,
)
from hsgeo.nist.models import MODELS, NistModel, model_for, residuals

__all__ = [
    "MODELS",
    "NistModel",
    "model_for",
    "residuals",
    "NIST_OPTIONS",
    "NistFit",
    "certify",
    "covariance_sigma",
    "fit_hsgeo",
    "fit_scipy",
    "option_steps",
    "score",
]
