"""Rotation-compensated LP image scenes (002 §3.1, eq. (1), Fig. 3) and the way back to the lines.

An LP image scene is ``n`` consecutive lines of one strip (002 Fig. 2). The lines are separate
exposures whose attitude differs by the platform's high-frequency motion, which bends straight
edges on the ground from line to line; key-point detectors need the 2-D neighbourhood of a
frame image, so each line is shifted along x by the rotation compensation of 002 eq. (1)::

    δ(t_e)[i] = (R_c^m(t_s))⁻¹ R_c^m(t_e) [x_i, 0, c]ᵀ − [x_i, 0, c]ᵀ

with ``R_c^m = R_map_from_body · R_body_from_camera`` from the GNSS/INS attitude and the
(a-priori) boresight (:attr:`PushbroomCamera.mount`), ``x_i`` the ideal image x of pixel i
(mm: ``x_px · pixel − x0``, undistorted with the camera's Brown terms if it has any) and ``c``
the band's principal distance. Only δx is used (002: δy ≈ 0 between adjacent lines), in px.

**The reference line** ``t_s`` is the scene's **first** line, as 002 defines it ("the exposure
time of the first LP image line in the LP image scene"): then the |δx| statistics of
:func:`dx_statistics` are the paper's (0.91 px RMS, 4.43 px max for 200-line scenes). A middle
reference would halve the largest shifts but not change the scene's geometry beyond a constant
rotation.

δx is the paper's first-order shift, the x component of the rotated vector, not its
re-projection ``c · v'_x / v'_z − x``; they differ by ``≈ x² Δφ / c`` (2 % of δx at the line's
end), immaterial for a neighbourhood that only has to look like a frame image.

**Scene pixels.** Scene pixel ``(u, v)``: ``u`` the row (0 … n − 1, line ``line0 + u`` of the
strip: along track, the time direction), ``v`` the column (0 … n_cols − 1, the strip's column
``col0 + v``, at ``x_s = col0 + v − (n_px_full − 1)/2`` px in the reference line's geometry).
Row ``u`` of the scene holds line ``line0 + u`` resampled so that the original pixel at ``x``
lands at ``x + δx(x)`` (linear interpolation in x, 002 §3.1); outside the line the edge value
is repeated. Note the order: OpenCV's key points are ``(x, y) = (v, u)``.
:func:`scene_to_line` undoes the compensation (002: "the rotation compensation is no longer
considered once key-point correspondences have been filtered"): the nearest original line and
the sub-pixel x of the original line, the exact inverse of the piecewise-linear map
:func:`line_to_scene`.

References
----------
Jonassen et al. (2024), 002 §3.1, eq. (1), Fig. 2–3, §4 (0.91 / 4.43 px), §5.1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io.lp_lines import LpStrip

__all__ = [
    "LpScene",
    "rotation_compensation_px",
    "make_scenes",
    "scene_to_line",
    "line_to_scene",
    "dx_statistics",
]


@dataclass(frozen=True)
class LpScene:
    """One rotation-compensated scene of ``n`` lines of a strip.

    Attributes
    ----------
    image : (n, n_cols, n_bands) float32
        The compensated scene (DN).
    line0 : int
        Index in the strip of the scene's first line (row 0).
    t_ref_s : float
        Exposure time of the reference line (the first), s.
    dx_px : (n, n_cols) float64
        δx of 002 eq. (1) of each original pixel (px): original x → ``x + δx`` in the scene.
    strip_id : str
    col0 : int
        The strip's first stored column in the full line.
    n_px_full : int
        Pixels of a full line (the x origin: ``x = col − (n_px_full − 1)/2``).
    """

    image: np.ndarray
    line0: int
    t_ref_s: float
    dx_px: np.ndarray
    strip_id: str
    col0: int
    n_px_full: int = 1800

    @property
    def n_lines(self) -> int:
        return int(self.image.shape[0])

    @property
    def x_px(self) -> np.ndarray:
        """``(n_cols,)`` x of each column (px from the full line's centre)."""
        return self.col0 + np.arange(self.image.shape[1]) - (self.n_px_full - 1) / 2


def _R_map_from_camera(trajectory, camera, t_s) -> np.ndarray:
    """``R_c^m(t) = R_map_from_body(t) · R_body_from_camera`` (the camera's mount), (m, 3, 3)."""
    return trajectory.R_map_from_body(t_s) @ camera.mount.R_body_from_sensor


def rotation_compensation_px(x_px, t_lines_s, t_ref_s, trajectory, camera, band=0) -> np.ndarray:
    """δx of 002 eq. (1) for pixels ``x_px`` of lines at ``t_lines_s`` against ``t_ref_s``.

    Parameters
    ----------
    x_px : (n_x,) array_like, px
        Image x of the pixels (from the full line's centre, pixel-centre origin).
    t_lines_s : (n_lines,) array_like, s
        Exposure times of the lines.
    t_ref_s : float, s
        Exposure time of the scene's reference line ``t_s`` (the first line, module docstring).
    trajectory : hsgeo.trajectory.Trajectory
        The GNSS/INS attitude (it must cover every time).
    camera : hsgeo.sensors.pushbroom.PushbroomCamera
        The (a-priori) camera: boresight, principal distance of ``band``, pixel, x0.
    band : int
        Band whose principal distance ``c`` enters eq. (1).

    Returns
    -------
    (n_lines, n_x) ndarray, px
        ``δx``: the pixel at ``x`` of line ``t_e`` lands at ``x + δx`` in the reference geometry.
    """
    from hsgeo.distortion import undistort_pushbroom_line

    x = np.atleast_1d(np.asarray(x_px, dtype=np.float64))
    t = np.atleast_1d(np.asarray(t_lines_s, dtype=np.float64))
    if x.ndim != 1 or t.ndim != 1:
        raise InputError("rotation_compensation_px: x_px and t_lines_s must be 1-D")
    x_mm = np.column_stack([x * camera.pixel_mm - camera.x0_mm, np.zeros(x.size)])
    if any(camera.distortion):
        x_mm = undistort_pushbroom_line(x_mm, camera.distortion)
    c_all = np.atleast_1d(np.asarray(camera.c_mm, dtype=np.float64))
    if int(band) != band or not 0 <= band < c_all.size:
        raise InputError(f"band {band!r} not in the camera's bands 0…{c_all.size - 1}")
    c = float(c_all[int(band)])
    v = np.column_stack([x_mm[:, 0], np.zeros(x.size), np.full(x.size, c)])  # (n_x, 3)
    R_ref = _R_map_from_camera(trajectory, camera, np.array([float(t_ref_s)]))[0]
    R_e = _R_map_from_camera(trajectory, camera, t)  # (n_lines, 3, 3)
    R_rel = R_ref.T @ R_e  # (R_c^m(t_s))⁻¹ R_c^m(t_e), 002 eq. (1)
    rotated_x = np.einsum("lj,xj->lx", R_rel[:, 0, :], v)
    return (rotated_x - v[None, :, 0]) / camera.pixel_mm


def _resample(line_vals, x, fwd, out):
    """``out[c] = line at the x whose forward image x + δx is x[c]`` (linear in x), all bands."""
    j = np.clip(np.searchsorted(fwd, x), 1, x.size - 1)
    w = np.clip((x - fwd[j - 1]) / (fwd[j] - fwd[j - 1]), 0.0, 1.0).astype(np.float32)
    out[:] = (1 - w)[:, None] * line_vals[j - 1] + w[:, None] * line_vals[j]


def make_scenes(
    strip: LpStrip, trajectory, camera, n_lines: int, n_px_full: int, band: int = 0
) -> list[LpScene]:
    """Cut a strip into rotation-compensated scenes of ``n_lines`` lines (002 §3.1).

    Parameters
    ----------
    strip : LpStrip
    trajectory : Trajectory
        GNSS/INS solution covering the strip's line times.
    camera : PushbroomCamera
        The a-priori camera (boresight, c).
    n_lines : int ≥ 2
        Lines per scene (002: 200). The strip's last scene holds the remaining lines when
        fewer are left (at least 2; a single last line joins no scene).
    n_px_full : int
        Pixels of a full line (the x origin).
    band : int
        Band whose principal distance enters eq. (1) (the bands' c differ by < 0.03 %).

    Returns
    -------
    list of LpScene
    """
    if not isinstance(strip, LpStrip):
        raise InputError(f"make_scenes needs an LpStrip, got {type(strip).__name__}")
    if int(n_lines) != n_lines or n_lines < 2:
        raise InputError(f"n_lines must be an integer ≥ 2 (lines per scene), got {n_lines!r}")
    if strip.col0 + strip.n_cols > n_px_full:
        raise InputError(
            f"strip {strip.strip_id}: columns {strip.col0}…{strip.col0 + strip.n_cols - 1} "
            f"do not fit a line of {n_px_full} px; check n_px_full"
        )
    n_lines = int(n_lines)
    x = strip.x_px(n_px_full)
    scenes = []
    for a in range(0, strip.n_lines, n_lines):
        b = min(a + n_lines, strip.n_lines)
        if b - a < 2:
            break
        t = strip.t_s[a:b]
        dx = rotation_compensation_px(x, t, t[0], trajectory, camera, band)
        img = np.empty((b - a,) + strip.lines.shape[1:], np.float32)
        for u in range(b - a):
            _resample(strip.lines[a + u], x, x + dx[u], img[u])
        scenes.append(LpScene(img, a, float(t[0]), dx, strip.strip_id, strip.col0, int(n_px_full)))
    return scenes


def _rows(scene: LpScene, u):
    u = np.asarray(u, dtype=np.float64)
    if not np.all(np.isfinite(u)):
        raise InputError("scene coordinates contain NaN or inf")
    return np.clip(np.rint(u).astype(np.int64), 0, scene.n_lines - 1)


def scene_to_line(scene: LpScene, uv) -> tuple[np.ndarray, np.ndarray]:
    """Scene pixels back to the original lines: undo the rotation compensation.

    Parameters
    ----------
    scene : LpScene
    uv : (m, 2) array_like
        Scene coordinates ``(u, v)``: row (along track) and column (module docstring).

    Returns
    -------
    line_index : (m,) int ndarray
        Index in the strip of the nearest original line (row ``round(u)``).
    x_px : (m,) ndarray, px
        The sub-pixel x in that original line whose forward image ``x + δx(x)`` is the scene
        column (the inverse of the piecewise-linear map; beyond the line's ends, the end's δx).
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    rows = _rows(scene, uv[:, 0])
    xs = scene.col0 + uv[:, 1] - (scene.n_px_full - 1) / 2
    x = scene.x_px
    out = np.empty(uv.shape[0])
    for r in np.unique(rows):
        k = rows == r
        fwd = x + scene.dx_px[r]
        xi = np.interp(xs[k], fwd, x)
        lo, hi = xs[k] < fwd[0], xs[k] > fwd[-1]
        xi[lo] = xs[k][lo] - scene.dx_px[r, 0]
        xi[hi] = xs[k][hi] - scene.dx_px[r, -1]
        out[k] = xi
    return scene.line0 + rows, out


def line_to_scene(scene: LpScene, line_index, x_px) -> np.ndarray:
    """The forward map of :func:`scene_to_line`: original line and x → scene ``(u, v)``.

    ``u = line_index − line0``; ``v`` the column of ``x + δx(x)`` with δx interpolated linearly
    between the columns (the end's δx beyond them). Returns ``(m, 2)``.
    """
    li = np.atleast_1d(np.asarray(line_index, dtype=np.int64))
    xq = np.atleast_1d(np.asarray(x_px, dtype=np.float64))
    u = li - scene.line0
    if np.any((u < 0) | (u >= scene.n_lines)):
        raise InputError(
            f"lines outside scene {scene.strip_id}:{scene.line0} "
            f"(lines {scene.line0}…{scene.line0 + scene.n_lines - 1})"
        )
    x = scene.x_px
    v = np.empty(xq.size)
    for r in np.unique(u):
        k = u == r
        v[k] = xq[k] + np.interp(xq[k], x, scene.dx_px[r])
    v += (scene.n_px_full - 1) / 2 - scene.col0
    return np.column_stack([u.astype(np.float64), v])


def dx_statistics(scenes) -> dict:
    """|δx| over every pixel of every scene: ``{"rms_px", "max_px", "n_scenes"}`` (002 §4:
    0.91 and 4.43 px for 200-line scenes).
    """
    scenes = list(scenes)
    if not scenes:
        raise InputError("dx_statistics: no scenes")
    ss = sum(float(np.sum(s.dx_px**2)) for s in scenes)
    n = sum(s.dx_px.size for s in scenes)
    mx = max(float(np.max(np.abs(s.dx_px))) for s in scenes)
    return {"rms_px": float(np.sqrt(ss / n)), "max_px": mx, "n_scenes": len(scenes)}
