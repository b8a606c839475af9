"""Every module-level numpy array of hsgeo is read-only: a constant (a paper's table, a frame
convention, a band split read at import) cannot be changed in place by one caller for all the
others."""

import dataclasses
import importlib
import pkgutil

import numpy as np
import pytest

import hsgeo


def _arrays(value, where: str, depth: int = 0):
    """``(where, array)`` of every ndarray in ``value``, looking into dicts, lists, tuples and
    dataclass instances (a few levels deep)."""
    if isinstance(value, np.ndarray):
        yield where, value
    elif depth > 3:
        return
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _arrays(v, f"{where}[{k!r}]", depth + 1)
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            yield from _arrays(v, f"{where}[{i}]", depth + 1)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            yield from _arrays(getattr(value, f.name), f"{where}.{f.name}", depth + 1)


def _modules():
    names = ["hsgeo"]
    names += [m.name for m in pkgutil.walk_packages(hsgeo.__path__, "hsgeo.")]
    return names


def test_every_module_level_array_is_read_only():
    writable, n_arrays = [], 0
    for name in _modules():
        mod = importlib.import_module(name)
        for attr, value in vars(mod).items():
            if isinstance(value, type) or callable(value) and not isinstance(value, np.ndarray):
                continue
            for where, arr in _arrays(value, f"{name}.{attr}"):
                n_arrays += 1
                if arr.flags.writeable:
                    writable.append(where)
    assert not writable, f"writable module-level arrays: {writable}"
    assert n_arrays >= 10  # the walk found the package's constants (RIKOLA_BANDS, BANDS, …)


def test_a_constant_cannot_be_changed_in_place():
    from hsgeo.papers import RIKOLA_BANDS
    from hsgeo.sensors.pushbroom import BETA0_CAM_FROM_PLATFORM

    with pytest.raises(ValueError, match="read-only"):
        BETA0_CAM_FROM_PLATFORM[0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        RIKOLA_BANDS["gap_nm"][0] = 0
    # a copy is the caller's own
    bands = RIKOLA_BANDS.copy()
    bands["gap_nm"][0] = 0
    assert RIKOLA_BANDS["gap_nm"][0] == 337
