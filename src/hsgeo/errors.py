"""One exception family for hsgeo.

Every error a user can provoke with bad input is an :class:`HsgeoError`; its message names the
problem and what to do about it.
"""

from __future__ import annotations

__all__ = [
    "HsgeoError",
    "InputError",
    "ObservationError",
    "DatumError",
    "ConvergenceError",
]


class HsgeoError(Exception):
    """Base class of every error raised by hsgeo on purpose."""


class InputError(HsgeoError, ValueError):
    """Malformed input: a file, an array of the wrong shape, NaN, an unknown name."""


class ObservationError(HsgeoError, ValueError):
    """Too few observations for the unknowns, or a design that cannot carry the estimate."""


class DatumError(HsgeoError):
    """The normal equations are rank deficient: some parameters are not determined by the data.

    Attributes
    ----------
    parameters : list of str
        Names of the parameters involved in the deficiency (largest null-space components).
    rank, n_unknowns : int
        Numerical rank of the reduced normal matrix and its size.
    """

    def __init__(self, message: str, parameters=(), rank=None, n_unknowns=None):
        super().__init__(message)
        self.parameters = list(parameters)
        self.rank = rank
        self.n_unknowns = n_unknowns


class ConvergenceError(HsgeoError):
    """An adjustment did not converge; ``.result`` holds the last iterate and its history."""

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result
