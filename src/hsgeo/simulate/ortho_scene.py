"""A flat-field scene with bright reference squares, seen by any scanning sensor, line by line.

The orthomosaic's test scene (002 Fig. 9: reference squares of 1.2 m on the ground, their
positions surveyed by RTK). The radiance of a pixel is the scene's value at the point where its
ray meets the terrain (the pixel centre, no point-spread function): a square's pixels are bright
(``square_value``), the rest is a smooth background. :func:`render_lines` renders lines of a
:class:`~hsgeo.ortho.Strip`'s geometry eagerly; :func:`lazy_cube` as a Dask array whose chunks
are rendered only when a task needs them (a cube larger than memory that never exists whole).

What the renderer shares with the estimator: the sensor model, the trajectory and the terrain
are the same (no inverse-crime hiding here: the test measures the resampling and mosaicking,
not the geometry).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.ortho import Strip, geolocate_lines

__all__ = ["SquaresScene", "render_lines", "lazy_cube", "straight_flight"]


@dataclass(frozen=True)
class SquaresScene:
    """Bright squares on a background, in the map CRS.

    Parameters
    ----------
    centres_xy_m : (k, 2) ndarray
        Square centres, map x, y in m.
    side_m : float
        Side of each square (002: 1.2 m), axis-aligned in the map.
    square_value, background : float
        Radiance of a square and the mean of the background.
    band_gain : (n_bands,) ndarray
        Each band's factor on the radiance (a spectrum).
    """

    centres_xy_m: np.ndarray
    side_m: float = 1.2
    square_value: float = 1000.0
    background: float = 100.0
    band_gain: tuple = (1.0, 0.8, 0.6)

    def radiance(self, x_m, y_m) -> np.ndarray:
        """Radiance ``(..., n_bands)`` at map points."""
        x, y = np.asarray(x_m, float), np.asarray(y_m, float)
        v = self.background * (1.0 + 0.2 * np.sin(x / 7.0) * np.cos(y / 11.0))
        h = self.side_m / 2
        for cx, cy in np.asarray(self.centres_xy_m, float).reshape(-1, 2):
            v = np.where((np.abs(x - cx) <= h) & (np.abs(y - cy) <= h), self.square_value, v)
        return v[..., None] * np.asarray(self.band_gain, float)


def render_lines(strip: Strip, scene: SquaresScene, terrain, frame, lines=slice(None)):
    """Radiance ``(m, n_px, n_bands)`` float32 of lines of ``strip``'s geometry."""
    enu, _, _ = geolocate_lines(strip, terrain, frame, lines)
    x, y, _ = frame.enu_to_map(enu[..., 0], enu[..., 1], enu[..., 2])
    return scene.radiance(x, y).astype(np.float32)


def lazy_cube(strip: Strip, scene: SquaresScene, terrain, frame, lines_per_chunk: int = 256):
    """The strip's cube ``(n_lines, n_px, n_bands)`` as a Dask array rendered chunk by chunk."""
    import dask.array as dsa

    n, n_px, nb = strip.n_lines, strip.pixels.shape[0], len(scene.band_gain)
    chunks = (
        tuple(min(lines_per_chunk, n - a) for a in range(0, n, lines_per_chunk)),
        (n_px,),
        (nb,),
    )

    def _render(block_info=None):
        a, b = block_info[None]["array-location"][0]
        return render_lines(strip, scene, terrain, frame, slice(a, b))

    return dsa.map_blocks(
        _render, chunks=chunks, dtype=np.float32, meta=np.empty((0, 0, 0), np.float32)
    )


def straight_flight(
    frame,
    *,
    start_xy_m,
    heading_deg: float,
    speed_m_s: float,
    height_m: float,
    duration_s: float,
    rate_hz: float = 50.0,
    roll_amp_deg: float = 0.0,
):
    """A straight, level flight in the local frame of ``frame`` (a :class:`Trajectory`).

    Starts above map point ``start_xy_m`` at ``height_m`` above the ellipsoid's local U = 0,
    heading ``heading_deg`` (from north, clockwise, in the local frame) at ``speed_m_s``;
    ``roll_amp_deg`` adds a slow sinusoidal roll (a period of 7 s).
    """
    from hsgeo.trajectory import Trajectory

    E0, N0, _ = frame.map_to_enu(start_xy_m[0], start_xy_m[1], 0.0)
    t = np.arange(0.0, duration_s + 1.0 / rate_hz, 1.0 / rate_hz)
    hd = np.radians(heading_deg)
    E = float(E0) + speed_m_s * t * np.sin(hd)
    N = float(N0) + speed_m_s * t * np.cos(hd)
    U = np.full_like(t, height_m)
    roll = np.radians(roll_amp_deg) * np.sin(2 * np.pi * t / 7.0)
    rph = np.column_stack([roll, np.zeros_like(t), np.full_like(t, hd)])
    return Trajectory(t, np.column_stack([E, N, U]), rph)
