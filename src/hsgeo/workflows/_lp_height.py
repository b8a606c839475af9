"""The terrain height of :mod:`hsgeo.workflows.lp_observations` checked against the tie points.

``hsgeo lp-observations`` predicts every key point's ground point, and every scene's footprint,
on a plane at the mean terrain height (``--height``, or the squares' mean ``H_m``). Nothing in
the strips or the navigation states that height, so a wrong one used to give an answer (exit 0)
with a fraction of the observations: on the rendered campaign (tests/test_bad_input.py's four
strips, about 2,000 m above ground) a plane 400 m off kept 99 % of the observations, 600 m off
94 %, 800 m 41 %, 1,000 m 6 % (39 of 689).

The tie points themselves say where the ground is: the rays of one tie point from different
strips (the navigation and the a-priori camera) meet at its height. :func:`tie_point_heights`
intersects them (least squares: the point nearest to all its rays), and
:func:`check_terrain_height` refuses a plane farther from their median than
``MAX_HEIGHT_ERROR_OF_AGL`` of the height above them plus half the spread of the tie points'
heights (the relief): far enough that the footprints are predicted well (20 % kept 99 % of the
observations above), near enough that a plane that loses observations is refused. On that
campaign the tie points meet at 11 m (226 points, MAD 0.6 m) where the squares' mean is −0.4 m:
the a-priori camera's and navigation's errors move the intersection by about 1 % of the flying
height, well inside the tolerance.
"""

from __future__ import annotations

import numpy as np

from hsgeo.errors import InputError

__all__ = ["tie_point_heights", "check_terrain_height", "MAX_HEIGHT_ERROR_OF_AGL"]

#: A plane farther than this share of the height above ground from the tie points' median
#: height is refused (plus half their 5–95 % spread).
MAX_HEIGHT_ERROR_OF_AGL = 0.1
#: Fewer tie points seen in two strips than this: too few to tell (no check).
MIN_POINTS = 3


def tie_point_heights(table, camera, trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The height where the rays of each tie point seen in ≥ 2 strips meet, and the height of
    the camera above it.

    Parameters
    ----------
    table : pandas.DataFrame
        Observations ``point_id, band, t_s, x_px, y_px, strip`` (the table of
        :func:`hsgeo.workflows.lp_observations.retrieve`).
    camera : PushbroomCamera
        The a-priori camera (its ``rays``).
    trajectory : Trajectory
        The navigation (local east-north-up frame, U up).

    Returns
    -------
    height_m, agl_m : (n_points,) ndarray
        The least-squares intersection's U of each point (the point nearest to its rays in the
        sum of squared distances) and the mean U of its rays' origins less it.
    """
    import pandas as pd

    if len(table) == 0:
        return np.empty(0), np.empty(0)
    tab = pd.DataFrame(table).reset_index(drop=True)
    o = np.empty((len(tab), 3))
    d = np.empty((len(tab), 3))
    for b, g in tab.groupby("band"):
        xy = g[["x_px", "y_px"]].to_numpy(float)
        oo, dd = camera.rays(xy, g["t_s"].to_numpy(float), trajectory, band=int(b))
        o[g.index], d[g.index] = oo, dd
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    pid, point = np.unique(tab["point_id"].astype(str).to_numpy(), return_inverse=True)
    n_strips = tab.groupby(point)["strip"].nunique().to_numpy()
    P = np.eye(3)[None] - d[:, :, None] * d[:, None, :]  # projector across each ray
    A = np.zeros((pid.size, 3, 3))
    rhs = np.zeros((pid.size, 3))
    np.add.at(A, point, P)
    np.add.at(rhs, point, np.einsum("nij,nj->ni", P, o))
    top = np.bincount(point, weights=o[:, 2], minlength=pid.size) / np.bincount(point)
    keep = n_strips >= 2
    if not keep.any():
        return np.empty(0), np.empty(0)
    xyz = np.linalg.solve(A[keep], rhs[keep][..., None])[..., 0]
    return xyz[:, 2], top[keep] - xyz[:, 2]


def check_terrain_height(
    table, camera, trajectory, height_m: float, given_as: str, remedy: str
) -> None:
    """Refuse a terrain height far from where the tie points' rays meet.

    Parameters
    ----------
    table, camera, trajectory
        As :func:`tie_point_heights`.
    height_m : float
        The plane's height used for the footprints and predictions.
    given_as, remedy : str
        Where it came from and what to give instead, for the message (``--height``; the
        squares' mean ``H_m``).

    Raises
    ------
    InputError
        ``height_m`` farther than ``MAX_HEIGHT_ERROR_OF_AGL`` × the height above ground (plus
        half the 5–95 % spread of the tie points' heights) from their median height.
    """
    h, agl = tie_point_heights(table, camera, trajectory)
    ok = np.isfinite(h) & np.isfinite(agl) & (agl > 0)
    h, agl = h[ok], agl[ok]
    if h.size < MIN_POINTS:
        return
    h_med, agl_med = float(np.median(h)), float(np.median(agl))
    q05, q95 = np.percentile(h, [5.0, 95.0])
    tol = MAX_HEIGHT_ERROR_OF_AGL * agl_med + 0.5 * float(q95 - q05)
    if abs(height_m - h_med) <= tol:
        return
    raise InputError(
        f"{given_as} {height_m:.6g} m is not the height of the ground the strips see: the rays "
        f"of different strips meet at {h_med:.1f} m (median of {h.size} tie points, 5–95 %: "
        f"{q05:.1f} to {q95:.1f} m), {agl_med:.0f} m below the navigation; a plane "
        f"{abs(height_m - h_med):.0f} m off (more than {tol:.0f} m, "
        f"{MAX_HEIGHT_ERROR_OF_AGL:.0%} of the height above ground): the footprints and the "
        "matcher's search regions are predicted on that plane, and one this far off loses "
        f"observations without an error; {remedy.format(h=h_med)}"
    )
