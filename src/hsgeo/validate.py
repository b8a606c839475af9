"""Validation at the boundary: one place for the checks every public function makes."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.errors import InputError

__all__ = ["finite_array"]


def finite_array(a: ArrayLike, name: str) -> NDArray[np.float64]:
    """Convert to a finite float64 array, or raise :class:`~hsgeo.InputError` naming ``name``."""
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"{name} could not be converted to a float array ({exc}); pass numbers."
        ) from exc
    if not np.all(np.isfinite(arr)):
        n_bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise InputError(
            f"{name} contains {n_bad} non-finite value(s) (NaN or inf); "
            "remove or replace them before calling."
        )
    return arr
