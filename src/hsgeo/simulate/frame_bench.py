"""A simulated frame-camera calibration bench: a planar chessboard seen from varied poses.

The truth is OpenCV's calibration of its tutorial camera (``out_camera_data.yml``: fx = fy =
657.467 px, principal point at the centre, k1, k2, k3), so the simulated bench resembles the real
one of the ``frame-reference`` chapter; the poses are random but seeded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.sensors.frame import project_opencv
from hsgeo.simulate import as_rng

__all__ = ["simulate", "generate"]


def board_points(nx: int, ny: int, square: float) -> np.ndarray:
    """Inner corners of an nx × ny chessboard in row-major order, Z = 0: (nx·ny, 3)."""
    k = np.arange(nx * ny)
    return np.column_stack([square * (k % nx), square * (k // nx), np.zeros(k.size)])


def simulate(cfg: dict, rng) -> dict:
    """Truth and noisy observations of the bench.

    Returns
    -------
    dict with ``X`` (n_board, 3), ``poses`` (n_views, 6), ``intrinsics`` (4,), ``distortion``
    (5,), ``view`` (n,), ``point`` (n,), ``uv_px`` (n, 2) noisy, ``uv_true_px`` (n, 2).
    """
    rng = as_rng(rng)
    cam, board, geo = cfg["camera"], cfg["board"], cfg["geometry"]
    X = board_points(board["nx"], board["ny"], board["square_mm"])
    centre = X.mean(axis=0)
    poses, views, pts, uv = [], [], [], []
    w, h = cam["width_px"], cam["height_px"]
    intr = np.array([cam["fx_px"], cam["fy_px"], cam["cx_px"], cam["cy_px"]])
    dist = np.array(cam["distortion"])
    while len(poses) < geo["n_views"]:
        # camera on a sphere around the board centre, looking at it, with a random roll
        dist_mm = rng.uniform(*geo["distance_mm"])
        tilt = np.deg2rad(rng.uniform(0, geo["max_tilt_deg"]))
        azi = rng.uniform(0, 2 * np.pi)
        C = centre + dist_mm * np.array([np.sin(tilt) * np.cos(azi), np.sin(tilt) * np.sin(azi),
                                         -np.cos(tilt)])
        z = centre - C
        z /= np.linalg.norm(z)
        x = np.cross([0.0, 1.0, 0.0], z)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        roll = rng.uniform(-np.pi, np.pi)
        R = np.column_stack([x, y, z]) @ R_from_opk(0.0, 0.0, roll)  # R_world_from_cam (CV)
        pose = np.concatenate([opk_from_R(R), C])
        p = project_opencv(pose[None], np.zeros(len(X), int), X, intr, dist)
        if np.all((p > 10) & (p < [w - 10, h - 10])):
            i = len(poses)
            poses.append(pose)
            views.append(np.full(len(X), i))
            pts.append(np.arange(len(X)))
            uv.append(p)
    uv_true = np.concatenate(uv)
    noisy = uv_true + cam["sigma_px"] * rng.standard_normal(uv_true.shape)
    return {"X": X, "poses": np.array(poses), "intrinsics": intr, "distortion": dist,
            "view": np.concatenate(views), "point": np.concatenate(pts),
            "uv_px": noisy, "uv_true_px": uv_true}


def generate(cfg: dict, outdir: Path) -> list[Path]:
    """Write ``frame_bench_observations.csv`` and ``frame_bench_truth.csv``."""
    sim = simulate(cfg, cfg["scenario"]["seed"])
    obs = outdir / "frame_bench_observations.csv"
    X = sim["X"][sim["point"]]
    table = np.column_stack([sim["view"], sim["point"], X, sim["uv_px"]])
    np.savetxt(obs, table, delimiter=",", fmt=["%d", "%d"] + ["%.17g"] * 5,
               header="view,point,X_mm,Y_mm,Z_mm,u_px,v_px", comments="")
    truth = outdir / "frame_bench_truth.csv"
    np.savetxt(truth, sim["poses"], delimiter=",", fmt="%.17g",
               header="omega_rad,phi_rad,kappa_rad,X0_mm,Y0_mm,Z0_mm", comments="")
    return [obs, truth]
