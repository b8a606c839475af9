"""Compiled kernels' chunks on Python threads (issue 41): :func:`over_chunks`.

A module of its own, importing numba alone, so that the orthorectification's ray casting
(:mod:`hsgeo._raycast`) uses it without importing the adjustment engine; re-exported by
:mod:`hsgeo.adjust.threads`.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numba

__all__ = ["over_chunks", "over_items"]


def over_chunks(chunk: Callable, n_chunks: int, *args) -> list:
    """``[chunk(ch, *args) for ch in range(n_chunks)]``, on the kernels' threads.

    ``chunk`` is a compiled function of one chunk (``nogil=True``), run on
    ``numba.get_num_threads()`` Python threads (the number
    :func:`hsgeo.adjust.threads.engine_threads` sets).
    Why not numba's ``prange`` over the chunks: its parallel passes optimise the chunk's body
    once more inside the parallel region, which took 12 of the 21 s that the reduced-matrix
    kernel took to compile on a fresh cache (issue 41; a first run of ``hsgeo adjust-pushbroom``
    compiles it). The chunks write disjoint outputs, so the order they run in changes nothing;
    threads that wait do not spin (GNU OpenMP's do: :mod:`hsgeo.adjust.threads`).
    """
    n = min(numba.get_num_threads(), n_chunks)
    if n <= 1:
        return [chunk(ch, *args) for ch in range(n_chunks)]
    with ThreadPoolExecutor(max_workers=n, thread_name_prefix="hsgeo-chunk") as pool:
        return list(pool.map(lambda ch: chunk(ch, *args), range(n_chunks)))


def over_items(chunk: Callable, n_items: int, n_chunks: int, *args) -> list:
    """:func:`over_chunks` over ``n_items`` items in ``n_chunks`` chunks of ``step`` items
    (the last one shorter): ``chunk(ch, step, *args)`` handles items ``ch·step …
    min((ch+1)·step, n_items) − 1``. The chunks are set by the problem's size, never by the
    threads, so their partial results are the same on any machine.
    """
    step = (n_items + n_chunks - 1) // n_chunks
    return over_chunks(chunk, n_chunks, step, *args)
