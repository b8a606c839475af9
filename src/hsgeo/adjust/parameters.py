"""Named parameter blocks for the adjustment engine (after lmfit's ``Parameters``).

A :class:`Parameters` object is an ordered set of named blocks. Each block is an array of any
shape whose entries can be *free*, *fixed*, or free with a Gaussian *prior* (mean, σ). One block
may be marked ``points=True``: an ``(n_points, p)`` array of per-point unknowns (tie-point or
object coordinates) that the engine eliminates by the Schur complement, so that a problem with
hundreds of thousands of points only ever factorises the small system of the other unknowns.

Examples
--------
>>> import numpy as np
>>> from hsgeo.adjust import Parameters
>>> p = Parameters()
>>> p.add("c_px", 3600.0)
<block 'c_px' shape=() free=1/1>
>>> p.add("K", [0.0, 0.0, 0.0], columns=("K1", "K2", "K3"))
<block 'K' shape=(3,) free=3/3>
>>> p.add("eop", np.zeros((3, 3)), columns=("x0_m", "y0_m", "alpha_rad"))
<block 'eop' shape=(3, 3) free=9/9>
>>> p.fix("K", index=2)
>>> p.n_free
12

An equality *tie* makes one entry an alias of another: both are estimated as one unknown (one
column of the normal equations), so the result reports them equal, with the same σ̂:

>>> p.add("f_px", [3500.0, 3600.0], columns=("fx", "fy"))
<block 'f_px' shape=(2,) free=2/2>
>>> p.tie("f_px", index=1, to=("f_px", 0))
>>> p.value("f_px")
array([3500., 3500.])
>>> p.n_free
13
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np

from hsgeo.errors import InputError

__all__ = ["Block", "Parameters"]


@dataclass
class Block:
    """One named parameter array.

    Attributes
    ----------
    name : str
    value : ndarray of float64, any shape
    free : ndarray of bool, same shape
        True where the entry is estimated.
    prior_mean, prior_sigma : ndarray of float64, same shape
        A Gaussian prior on free entries where ``prior_sigma`` is finite (``inf``: none).
    columns : tuple of str or None
        Names of the last axis (e.g. ``("omega_rad", "phi_rad", ...)``), for reports.
    rows : sequence of str or None
        Names of the first axis (e.g. image or point ids), for reports.
    points : bool
        A per-point block ``(n_points, p)``, eliminated by the Schur complement.
    """

    name: str
    value: np.ndarray
    free: np.ndarray
    prior_mean: np.ndarray
    prior_sigma: np.ndarray
    columns: tuple[str, ...] | None = None
    rows: Sequence[str] | None = None
    points: bool = False
    _labels: list[str] | None = field(default=None, repr=False)

    @property
    def size(self) -> int:
        return int(self.value.size)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.value.shape)

    @property
    def has_prior(self) -> np.ndarray:
        """Bool mask of free entries that carry a prior."""
        return self.free & np.isfinite(self.prior_sigma)

    def labels(self) -> list[str]:
        """A readable name for every entry, in C order: ``eop[2, alpha_rad]``, ``c_px``."""
        if self._labels is not None:
            return self._labels
        if self.value.ndim == 0:
            out = [self.name]
        else:
            out = []
            for idx in np.ndindex(*self.value.shape):
                parts = []
                for axis, i in enumerate(idx):
                    if axis == self.value.ndim - 1 and self.columns is not None:
                        parts.append(str(self.columns[i]))
                    elif axis == 0 and self.rows is not None:
                        parts.append(str(self.rows[i]))
                    else:
                        parts.append(str(i))
                out.append(f"{self.name}[{', '.join(parts)}]")
        self._labels = out
        return out

    def __repr__(self) -> str:
        n_free = int(self.free.sum())
        kind = "points" if self.points else "block"
        return f"<{kind} {self.name!r} shape={self.shape} free={n_free}/{self.size}>"


def _as_float_array(name: str, value) -> np.ndarray:
    arr = np.array(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise InputError(
            f"parameter {name!r} has non-finite values (NaN or inf) at "
            f"{np.argwhere(~np.isfinite(arr)).tolist()[:5]}; give finite initial values."
        )
    return arr


def _broadcast(name: str, what: str, x, shape, dtype) -> np.ndarray:
    try:
        return np.array(np.broadcast_to(np.asarray(x, dtype=dtype), shape))
    except ValueError as exc:
        raise InputError(
            f"{what} of parameter {name!r} has shape {np.shape(x)}, which does not broadcast "
            f"to the parameter's shape {shape}."
        ) from exc


class Parameters:
    """An ordered collection of named parameter blocks.

    See the module docstring for an example. Blocks are accessed with ``params["name"]`` (the
    :class:`Block`) and their current values with ``params.value("name")``.
    """

    def __init__(self) -> None:
        self._blocks: dict[str, Block] = {}
        #: (block, flat index) of a tied entry → (block, flat index) of the entry it equals
        self._ties: dict[tuple[str, int], tuple[str, int]] = {}

    # -- construction -----------------------------------------------------------------------
    def add(
        self,
        name: str,
        value,
        *,
        free=True,
        prior_mean=None,
        prior_sigma=None,
        columns: Sequence[str] | None = None,
        rows: Sequence[str] | None = None,
        points: bool = False,
    ) -> Block:
        """Add a block.

        Parameters
        ----------
        name : str
            Unique name; use units in names where a number could be misread (``c_px``).
        value : array_like
            Initial values (any shape; ``(n_points, p)`` for ``points=True``).
        free : bool or array_like of bool
            Which entries are estimated (broadcast to the value's shape).
        prior_mean, prior_sigma : array_like, optional
            Gaussian prior (pseudo-observation) on free entries; ``prior_mean`` defaults to the
            initial value, ``prior_sigma`` to none (``inf``).
        columns, rows : sequence of str, optional
            Names of the last and first axes for reports.
        points : bool
            Mark a per-point block to be eliminated by the Schur complement.
        """
        if not isinstance(name, str) or not name:
            raise InputError(f"a parameter name must be a non-empty string, got {name!r}")
        if name in self._blocks:
            raise InputError(f"parameter {name!r} exists already; use another name or .set()")
        val = _as_float_array(name, value)
        if points:
            if val.ndim != 2:
                raise InputError(
                    f"points block {name!r} must be a 2-D array (n_points, p), got shape "
                    f"{val.shape}"
                )
            if any(b.points for b in self._blocks.values()):
                raise InputError(
                    "only one points block per problem is supported; stack the point "
                    "coordinates into one (n_points, p) block"
                )
        fr = _broadcast(name, "free", free, val.shape, bool)
        pm = (
            val.copy()
            if prior_mean is None
            else _broadcast(name, "prior_mean", prior_mean, val.shape, np.float64)
        )
        ps = (
            np.full(val.shape, np.inf)
            if prior_sigma is None
            else _broadcast(name, "prior_sigma", prior_sigma, val.shape, np.float64)
        )
        self._check_prior(name, pm, ps)
        if columns is not None:
            columns = tuple(columns)
            if val.ndim == 0 or len(columns) != val.shape[-1]:
                raise InputError(
                    f"parameter {name!r}: {len(columns)} column names for a last axis of "
                    f"length {val.shape[-1] if val.ndim else 0}"
                )
        block = Block(name, val, fr, pm, ps, columns, rows, points)
        self._blocks[name] = block
        return block

    @staticmethod
    def _check_prior(name, mean, sigma):
        if np.any(np.isnan(mean)) or np.any(np.isnan(sigma)):
            raise InputError(f"prior of parameter {name!r} contains NaN")
        if np.any(sigma <= 0):
            raise InputError(
                f"prior σ of parameter {name!r} must be positive (use fix() for a known value, "
                "inf for no prior)"
            )

    # -- access -----------------------------------------------------------------------------
    def __getitem__(self, name: str) -> Block:
        try:
            return self._blocks[name]
        except KeyError:
            raise InputError(
                f"no parameter named {name!r}; known: {', '.join(self._blocks) or '(none)'}"
            ) from None

    def __contains__(self, name: str) -> bool:
        return name in self._blocks

    def __iter__(self) -> Iterator[str]:
        return iter(self._blocks)

    def __len__(self) -> int:
        return len(self._blocks)

    def blocks(self) -> list[Block]:
        """The blocks in insertion order."""
        return list(self._blocks.values())

    def value(self, name: str) -> np.ndarray:
        """The current value of a block (a view: do not modify in place)."""
        return self[name].value

    def values(self) -> dict[str, np.ndarray]:
        """All current values, by name."""
        return {k: b.value for k, b in self._blocks.items()}

    @property
    def points_block(self) -> Block | None:
        """The block marked ``points=True``, if any."""
        for b in self._blocks.values():
            if b.points:
                return b
        return None

    @property
    def n_free(self) -> int:
        """Number of estimated unknowns (points included; a tied entry is not one of its own)."""
        n = int(sum(b.free.sum() for b in self._blocks.values()))
        return n - sum(1 for (name, i) in self._ties if self[name].free.ravel()[i])

    @property
    def ties(self) -> dict[tuple[str, int], tuple[str, int]]:
        """The equality ties: ``(block, flat index)`` of a tied entry → that of its target."""
        return dict(self._ties)

    # -- modification -----------------------------------------------------------------------
    def set(self, name: str, value, index=...) -> None:
        """Set values of a block (``index`` selects entries, numpy-style)."""
        b = self[name]
        new = b.value.copy()
        new[index] = value
        b.value = _as_float_array(name, new)

    def fix(self, name: str, index=..., value=None) -> None:
        """Hold entries of a block at their value (or at ``value``)."""
        b = self[name]
        if value is not None:
            self.set(name, value, index)
        b.free[index] = False

    def free(self, name: str, index=...) -> None:
        """Estimate entries of a block."""
        self[name].free[index] = True

    def set_prior(self, name: str, sigma, index=..., mean=None) -> None:
        """Put a Gaussian prior N(mean, σ²) on entries (mean defaults to the current value)."""
        b = self[name]
        ps = b.prior_sigma.copy()
        pm = b.prior_mean.copy()
        ps[index] = sigma
        pm[index] = b.value[index] if mean is None else mean
        self._check_prior(name, pm, ps)
        b.prior_sigma, b.prior_mean = ps, pm

    def tie(self, name: str, index, to: tuple[str, object]) -> None:
        """Tie one entry to another: both are estimated as one unknown (equality constraint).

        The tied entry takes the target's value now and at every step of the adjustment, and
        the result reports the target's σ̂ for it (e.g. square pixels: ``fy = fx``).

        Parameters
        ----------
        name : str
            Block of the tied entry (not the points block).
        index : int or tuple of int
            The tied entry (numpy-style index selecting exactly one entry).
        to : (str, index)
            Block and index of the entry it equals (free, not itself tied, not a points block).

        Raises
        ------
        InputError
            A points block, an index that does not select one entry, a target that is fixed
            or itself tied, a tie of an entry to itself, or a prior on the tied entry.
        """
        i = self._flat_index(name, index, "tied entry")
        if not (isinstance(to, tuple) and len(to) == 2):
            raise InputError(f"tie(): 'to' must be a (block name, index) pair, got {to!r}")
        j = self._flat_index(to[0], to[1], "tie target")
        tname = to[0]
        if (name, i) == (tname, j):
            raise InputError(f"tie(): entry {self[name].labels()[i]} cannot be tied to itself")
        if (tname, j) in self._ties:
            root = self._ties[(tname, j)]
            raise InputError(
                f"tie(): the target {self[tname].labels()[j]} is itself tied to "
                f"{self[root[0]].labels()[root[1]]}; tie to that entry directly"
            )
        if any(t == (name, i) for t in self._ties.values()):
            raise InputError(
                f"tie(): other entries are tied to {self[name].labels()[i]}; it cannot be tied "
                "in turn (tie them all to one entry)"
            )
        b, t = self[name], self[tname]
        if not t.free.ravel()[j]:
            raise InputError(
                f"tie(): the target {t.labels()[j]} is fixed; fix the tied entry instead, or "
                "free the target first"
            )
        if np.isfinite(b.prior_sigma.ravel()[i]):
            raise InputError(
                f"tie(): {b.labels()[i]} has a prior; put the prior on the target "
                f"{t.labels()[j]} instead"
            )
        self._ties[(name, i)] = (tname, j)
        np.put(b.free, i, True)  # estimated (through the target's unknown)
        v = b.value.ravel().copy()
        v[i] = t.value.ravel()[j]
        b.value = v.reshape(b.shape)

    def _flat_index(self, name: str, index, what: str) -> int:
        b = self[name]
        if b.points:
            raise InputError(
                f"tie(): {what} in the points block {name!r}: ties between per-point unknowns "
                "are not supported"
            )
        try:
            sel = np.arange(b.size).reshape(b.shape)[index]
        except (IndexError, TypeError) as exc:
            raise InputError(
                f"tie(): index {index!r} is not valid for {name!r} of shape {b.shape}"
            ) from exc
        sel = np.atleast_1d(sel)
        if sel.size != 1:
            raise InputError(
                f"tie(): {what} index {index!r} selects {sel.size} entries of {name!r}; a tie "
                "joins exactly one entry to one other"
            )
        return int(sel[0])

    def _sync_ties(self) -> None:
        """Give every tied entry its target's current value."""
        for (name, i), (tname, j) in self._ties.items():
            b = self[name]
            v = b.value.ravel().copy()
            v[i] = self[tname].value.ravel()[j]
            b.value = v.reshape(b.shape)

    def copy(self) -> Parameters:
        """A deep copy."""
        return copy.deepcopy(self)

    def free_labels(self, names: Iterable[str] | None = None) -> list[str]:
        """Labels of the free entries of the given blocks (default: all), in engine order.

        A tied entry is not listed: it shares the unknown of its target.
        """
        names = list(self._blocks) if names is None else list(names)
        out: list[str] = []
        for n in names:
            b = self[n]
            lab = b.labels()
            out.extend(lab[i] for i in np.flatnonzero(b.free.ravel()) if (n, i) not in self._ties)
        return out

    def __repr__(self) -> str:
        inner = ", ".join(repr(b) for b in self._blocks.values())
        return f"Parameters({inner})"
