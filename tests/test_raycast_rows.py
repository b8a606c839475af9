"""The compiled first crossing on one thread and on numba's threads: the same values (issue 41:
one thread below PARALLEL_MIN_RAYS rays)."""

import numpy as np
import pytest

from hsgeo import _raycast as rc
from hsgeo._chunks import over_chunks
from hsgeo.adjust.threads import engine_threads


@pytest.mark.parametrize("threads", [1, 2])
def test_serial_and_parallel_rows_agree_bit_for_bit(threads):
    """One chunk on one thread (first_crossing_rows below PARALLEL_MIN_RAYS) and 7 or 64
    chunks on one or two threads: the same values, bit for bit."""
    rng = np.random.default_rng(4)
    y, x = np.mgrid[0:60, 0:80]
    z = 100.0 + 3.0 * np.sin(x / 7.0) * np.cos(y / 5.0) + rng.normal(0, 0.2, x.shape)
    surf = rc.GridSurface.from_heights(z, 0.0, 0.0, 2.0, 2.0)
    n = 5000
    O = np.column_stack([rng.uniform(10, 150, n), rng.uniform(10, 110, n), np.full(n, 400.0)])
    D = np.column_stack([rng.normal(0, 0.1, n), rng.normal(0, 0.1, n), -np.ones(n)])
    out = []
    with engine_threads(threads, 10**9):
        s, st = np.empty(n), np.empty(n, np.int8)
        rc.first_crossing_rows(O, D, *surf.args(), s, st)
        out.append((s, st))
        for n_chunks in (7, 64):
            s, st = np.full(n, np.nan), np.full(n, -99, np.int8)
            step = (n + n_chunks - 1) // n_chunks
            over_chunks(rc._rows_chunk, n_chunks, step, O, D, *surf.args(), s, st)
            out.append((s, st))
    assert (out[0][1] == rc.HIT).mean() > 0.5  # most rays meet the surface
    for s, st in out[1:]:
        np.testing.assert_array_equal(s, out[0][0])
        np.testing.assert_array_equal(st, out[0][1])


def _cast_chord_numpy(O, d, u_top, u_bottom, frame, surf):
    """The numpy steps hsgeo.geocode._cast_chord took before issue 41 (PROJ on every point)."""
    from hsgeo.geocode import cast_rays

    u_top = np.broadcast_to(u_top, O.shape[:1])
    u_bottom = np.broadcast_to(u_bottom, O.shape[:1])
    P = [O + ((u - O[:, 2]) / d[:, 2])[:, None] * d for u in (u_top, u_bottom)]
    top_above = O[:, 2] > u_top
    P[0][~top_above] = O[~top_above]
    M = [np.column_stack(frame.enu_to_map(p[:, 0], p[:, 1], p[:, 2])) for p in P]
    s, status = cast_rays(M[0], M[1] - M[0], surf)
    hit = status == rc.HIT
    X = np.full(O.shape, np.nan)
    if hit.any():
        Mh = M[0][hit] + s[hit, None] * (M[1][hit] - M[0][hit])
        Q = np.column_stack(frame.map_to_enu(Mh[:, 0], Mh[:, 1], Mh[:, 2]))
        Oh, dh = O[hit], d[hit]
        t = np.einsum("ij,ij->i", Q - Oh, dh) / np.einsum("ij,ij->i", dh, dh)
        X[hit] = Oh + t[:, None] * dh
    return X, status


def test_compiled_chords_equal_the_numpy_steps_bit_for_bit():
    """hsgeo._raycast.cast_chords with PROJ on every point: the very numbers of the numpy steps
    it replaced (rays from above the top height and from under it; rays that miss the DSM)."""
    from ortho_inputs import FRAME, dsm

    from hsgeo.mapgrid import MapTerrain

    t = MapTerrain(*dsm(), FRAME)
    rng = np.random.default_rng(9)
    n = 3000
    O = np.column_stack([rng.uniform(-300, 300, n), rng.uniform(-300, 300, n), np.full(n, 1975.0)])
    O[:50, 2] = t.u_range_m[1] - 0.5  # under the top height: from their own centres
    D = np.column_stack([rng.normal(0, 0.05, n), rng.normal(0, 0.05, n), -np.ones(n)])
    u_lo, u_hi = t.u_range_m
    want = _cast_chord_numpy(O, D, u_hi, u_lo, FRAME, t.map_surface)
    got = rc.cast_chords(O, D, u_hi, u_lo, FRAME.enu_to_map, FRAME.map_to_enu, t.map_surface)
    assert 0.5 < (want[1] == rc.HIT).mean() < 1.0  # hits and misses
    np.testing.assert_array_equal(got[1], want[1])
    np.testing.assert_array_equal(got[0], want[0])
