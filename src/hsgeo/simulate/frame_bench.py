"""A simulated frame-camera calibration bench: a planar chessboard seen from varied poses.

The truth is OpenCV's calibration of its tutorial camera (``out_camera_data.yml``: fx = fy =
657.467 px, principal point at the centre, k1, k2, k3), so the simulated bench resembles the real
one of the ``frame-reference`` chapter; the poses are random but seeded.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hsgeo.io.config import Key
from hsgeo.io.tables import write_csv_array
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.sensors.frame import project_opencv
from hsgeo.simulate import as_rng
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = [
    "BenchCamera",
    "BenchBoard",
    "BenchGeometry",
    "FrameBenchScenario",
    "BenchObservations",
    "BenchTruth",
    "board_points",
    "simulate",
    "generate",
]


@dataclass(frozen=True)
class BenchCamera:
    """``[camera]`` of ``frame_bench.toml``: the true camera (OpenCV model) and its noise.

    Attributes
    ----------
    width_px, height_px : int
        Image size, px.
    fx_px, fy_px, cx_px, cy_px : float
        Focal lengths and principal point, px (OpenCV convention).
    distortion : tuple of 5 float
        k1, k2, p1, p2, k3 (OpenCV).
    sigma_px : float
        Noise of a measured corner, px.
    """

    width_px: int
    height_px: int
    fx_px: float
    fy_px: float
    cx_px: float
    cy_px: float
    distortion: tuple[float, ...] = field(
        metadata={"key": Key("floats", length=5, doc="k1 k2 p1 p2 k3")}
    )
    sigma_px: float = field(metadata={"key": Key("float", doc="noise of a corner, px")})


@dataclass(frozen=True)
class BenchBoard:
    """``[board]``: a chessboard of ``nx`` × ``ny`` inner corners, ``square_mm`` apart."""

    nx: int = field(metadata={"key": Key("int", positive=True)})
    ny: int = field(metadata={"key": Key("int", positive=True)})
    square_mm: float = field(metadata={"key": Key("float", positive=True)})


@dataclass(frozen=True)
class BenchGeometry:
    """``[geometry]``: ``n_views`` views from ``distance_mm`` (min, max), tilted up to
    ``max_tilt_deg``.
    """

    n_views: int = field(metadata={"key": Key("int", positive=True)})
    distance_mm: tuple[float, ...] = field(metadata={"key": Key("floats", length=2)})
    max_tilt_deg: float


@dataclass(frozen=True)
class FrameBenchScenario:
    """``data_synthetic/frame_bench.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`)."""

    scenario: ScenarioInfo
    camera: BenchCamera
    board: BenchBoard
    geometry: BenchGeometry


@dataclass(frozen=True)
class BenchObservations:
    """What the bench records and the operator knows: nothing here is truth.

    Attributes
    ----------
    X_mm : (n_board, 3) ndarray
        Board corners (the board's design), mm, row-major, Z = 0.
    view : (n,) int ndarray
        View of each observation.
    point : (n,) int ndarray
        Board corner of each observation (row of ``X_mm``).
    uv_px : (n, 2) ndarray
        Measured image coordinates, px (OpenCV convention), with noise.
    image_size_px : (int, int)
        Width and height of the images, px.
    sigma_px : float
        A-priori σ of an image coordinate, px.
    """

    X_mm: np.ndarray
    view: np.ndarray
    point: np.ndarray
    uv_px: np.ndarray
    image_size_px: tuple
    sigma_px: float

    @property
    def n_views(self) -> int:
        """Number of views."""
        return int(self.view.max()) + 1 if self.view.size else 0


@dataclass(frozen=True)
class BenchTruth:
    """The truth of a simulated bench (for :mod:`hsgeo.reproduce` only).

    Attributes
    ----------
    poses : (n_views, 6) ndarray
        ω, φ, κ (rad) and the projection centre X0, Y0, Z0 (mm) of each view.
    intrinsics : (4,) ndarray
        fx, fy, cx, cy, px.
    distortion : (5,) ndarray
        k1, k2, p1, p2, k3 (OpenCV).
    uv_true_px : (n, 2) ndarray
        Exact image coordinates of each observation, px.
    """

    poses: np.ndarray
    intrinsics: np.ndarray
    distortion: np.ndarray
    uv_true_px: np.ndarray


def board_points(nx: int, ny: int, square: float) -> np.ndarray:
    """Inner corners of an nx × ny chessboard in row-major order, Z = 0: (nx·ny, 3)."""
    k = np.arange(nx * ny)
    return np.column_stack([square * (k % nx), square * (k // nx), np.zeros(k.size)])


def simulate(cfg: FrameBenchScenario, rng) -> tuple[BenchObservations, BenchTruth]:
    """Noisy observations and the truth of the bench.

    Parameters
    ----------
    cfg : FrameBenchScenario
        The ``frame_bench`` scenario (``load_scenario("frame_bench")``).
    rng : int or numpy.random.Generator

    Returns
    -------
    observations : BenchObservations
    truth : BenchTruth
    """
    rng = as_rng(rng)
    cam, board, geo = cfg.camera, cfg.board, cfg.geometry
    X = board_points(board.nx, board.ny, board.square_mm)
    centre = X.mean(axis=0)
    poses, views, pts, uv = [], [], [], []
    w, h = cam.width_px, cam.height_px
    intr = np.array([cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px])
    dist = np.array(cam.distortion)
    while len(poses) < geo.n_views:
        # camera on a sphere around the board centre, looking at it, with a random roll
        dist_mm = rng.uniform(*geo.distance_mm)
        tilt = np.deg2rad(rng.uniform(0, geo.max_tilt_deg))
        azi = rng.uniform(0, 2 * np.pi)
        C = centre + dist_mm * np.array(
            [np.sin(tilt) * np.cos(azi), np.sin(tilt) * np.sin(azi), -np.cos(tilt)]
        )
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
    noisy = uv_true + cam.sigma_px * rng.standard_normal(uv_true.shape)
    obs = BenchObservations(
        X,
        np.concatenate(views),
        np.concatenate(pts),
        noisy,
        (int(w), int(h)),
        float(cam.sigma_px),
    )
    return obs, BenchTruth(np.array(poses), intr, dist, uv_true)


def generate(cfg: FrameBenchScenario, outdir: Path) -> list[Path]:
    """Write ``frame_bench_observations.csv`` and ``frame_bench_truth.csv``."""
    sim, truth = simulate(cfg, cfg.scenario.seed)
    obs = outdir / "frame_bench_observations.csv"
    X = sim.X_mm[sim.point]
    table = np.column_stack([sim.view, sim.point, X, sim.uv_px])
    write_csv_array(
        obs,
        table,
        fmt=["%d", "%d"] + ["%.17g"] * 5,
        header="view,point,X_mm,Y_mm,Z_mm,u_px,v_px",
    )
    truth_csv = outdir / "frame_bench_truth.csv"
    write_csv_array(
        truth_csv,
        truth.poses,
        fmt="%.17g",
        header="omega_rad,phi_rad,kappa_rad,X0_mm,Y0_mm,Z0_mm",
    )
    return [obs, truth_csv]
