"""Simulators: one module per instrument scenario; every function takes ``rng`` (int/Generator)."""

import numpy as np

__all__ = ["as_rng"]


def as_rng(rng) -> np.random.Generator:
    """A ``numpy.random.Generator`` from an int seed or a Generator (same seed, same bytes)."""
    if isinstance(rng, np.random.Generator):
        return rng
    if isinstance(rng, (int, np.integer)) and rng >= 0:
        return np.random.default_rng(int(rng))
    from hsgeo.errors import InputError

    raise InputError(f"rng must be a non-negative int seed or a numpy Generator, got {rng!r}")
