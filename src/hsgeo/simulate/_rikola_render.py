"""The per-pixel geometry of the Rikola bench's renderer (:class:`hsgeo.simulate.rikola.Renderer`),
compiled: the ray of each (supersampled) pixel, where it meets the plate ``Z = 0``, and the texel
coordinates there, in one pass over the pixels.

Every operand is ``float32`` and the operations run in the order of the numpy expressions this
kernel replaced (``R[i,0]·x + R[i,1]·y − R[i,2]·f``, ``t = −Z0 / d_z``, ``X = X0 + t·d_x`` …;
no ``fastmath``), so the maps are bit-identical to them (tested in
``tests/test_simulate_rikola_render.py``) while the nine full-size temporaries of the numpy form
are not allocated (issue 41: 0.12 s of 0.37 s a frame at 3× supersampling).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["plate_texel_maps"]


@njit(cache=True, error_model="numpy")
def _texel_kernel(ideal, R, f, X0, Y0, mZ0, x_min, y_max, texel, col, row):  # pragma: no cover
    half = np.float32(0.5)
    far = np.float32(-1e6)
    zero = np.float32(0.0)
    Rf0 = R[0, 2] * f
    Rf1 = R[1, 2] * f
    Rf2 = R[2, 2] * f
    for i in range(ideal.shape[0]):
        for j in range(ideal.shape[1]):
            ix = ideal[i, j, 0]
            iy = ideal[i, j, 1]
            # the ray in the world: R_world_from_cam (x, y, −f)
            d0 = R[0, 0] * ix + R[0, 1] * iy - Rf0
            d1 = R[1, 0] * ix + R[1, 1] * iy - Rf1
            d2 = R[2, 0] * ix + R[2, 1] * iy - Rf2
            t = mZ0 / d2  # meets Z = 0 (the plate)
            if t > zero:
                col[i, j] = (X0 + t * d0 - x_min) / texel - half
                row[i, j] = (y_max - (Y0 + t * d1)) / texel - half
            else:  # behind the camera, parallel, or NaN: outside the texture
                col[i, j] = far
                row[i, j] = far


def plate_texel_maps(ideal, R, f_mm, pose, x_min_mm, y_max_mm, texel_mm):
    """Texel coordinates (col, row) where each pixel's ray meets the plate ``Z = 0``.

    Parameters
    ----------
    ideal : (H, W, 2) float32 ndarray, mm
        Ideal image coordinates of the pixels (reduced to the principal point).
    R : (3, 3) float32 ndarray
        ``R_world_from_cam`` of the band.
    f_mm : float
        The band's focal length.
    pose : (6,) ndarray
        (ω, φ, κ, X0, Y0, Z0) of the band's camera, mm.
    x_min_mm, y_max_mm, texel_mm : float
        The plate's texture: left edge, top edge and texel size.

    Returns
    -------
    col, row : (H, W) float32 ndarray
        Fractional texel coordinates for ``cv2.remap``; ``-1e6`` where the ray does not meet
        the plate in front of the camera.
    """
    f32 = np.float32
    H, W = ideal.shape[:2]
    col = np.empty((H, W), np.float32)
    row = np.empty((H, W), np.float32)
    _texel_kernel(
        np.ascontiguousarray(ideal, dtype=np.float32),
        np.ascontiguousarray(R, dtype=np.float32),
        f32(f_mm),
        f32(pose[3]),
        f32(pose[4]),
        f32(-pose[5]),
        f32(x_min_mm),
        f32(y_max_mm),
        f32(texel_mm),
        col,
        row,
    )
    return col, row
