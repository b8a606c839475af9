"""Bundle adjustment of a BAL problem ("Bundle Adjustment in the Large"), ``hsgeo adjust-bal``.

Agarwal, Snavely, Seitz, Szeliski (2010). The cameras are Snavely's
(:class:`hsgeo.sensors.bal.SnavelyReprojection`), the points are eliminated by the Schur
complement, the cost is ``½ Σ r²`` in px² (σ = 1 px: Ceres' definition).

**Observations.** An observation of a point that lies behind its camera at the initial values
(``P_z ≥ 0``, BAL's camera looks down −z) cannot be an image of it; COLMAP (and so Ceres through
pycolmap) leaves such observations out, and :func:`prepare` does the same
(31 of 31,843 in the Ladybug problem 49-7776), so both solvers see one observation set. Points
left without observations (10 there) are held fixed: they are not part of the problem.

**Gauge.** The cost is invariant under a similarity of the whole block (7 parameters: rotation,
translation, scale). Ceres' BAL examples leave that freedom in and let the LM damping keep the
steps finite; COLMAP fixes it (``BundleAdjustmentGauge.TWO_CAMS_FROM_WORLD``), and so does
photogrammetric practice with minimal constraints. :func:`gauge_fix` fixes the pose of camera 0
(6 entries: rotation vector and t) and, for the scale, the component of camera 1's t that
changes most under a scaling about camera 0's centre. A gauge fix changes no cost (every
configuration has a similar one that satisfies the constraints, with the same reprojections),
so the final costs of both solvers are comparable; it keeps hsgeo's datum check and the
covariance of the reduced system meaningful (a free gauge makes the normal matrix singular).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.adjust import AdjustmentResult, Parameters, SolverOptions, adjust
from hsgeo.errors import InputError
from hsgeo.io.bal import CAMERA_COLUMNS, BALProblem
from hsgeo.rotations import R_from_rotvec
from hsgeo.sensors.bal import SnavelyReprojection, in_front

__all__ = ["BALFit", "prepare", "gauge_fix", "adjust_bal", "BAL_OPTIONS", "adjust_bal_file"]

#: Solver settings of ``hsgeo adjust-bal``, as Ceres' Levenberg–Marquardt starts and damps:
#: initial damping 1e-4 (Ceres' initial trust-region radius 1e4), point blocks damped at every
#: λ (``lambda_points_min`` ≈ 0; undamped points behind damped cameras gave poor steps here
#: and a λ stuck near 1e-4), convergence when the Gauss–Newton step predicts a relative
#: decrease below 1e-6 (Ceres stops on an *actual* relative decrease below its
#: ``function_tolerance`` 1e-6, a weaker test on a linearly converging iteration); no outlier
#: rejection (the problem is adjusted as published).
BAL_OPTIONS = SolverOptions(max_iter=200, lambda0=1e-4, lambda_points_min=1e-300, ftol=1e-6)


@dataclass(frozen=True)
class BALFit:
    """The outcome of :func:`adjust_bal` (the workflow's one result type, GUIDE §2).

    Attributes
    ----------
    result : AdjustmentResult
    initial_cost, final_cost : float
        ``½ Σ r²`` in px² at the initial values and at the solution.
    n_observations : int
        Observations adjusted (after :func:`prepare`).
    n_dropped : int
        Observations of points behind their camera, left out.
    fixed : list of (int, int)
        The gauge: (camera, column) entries of the cameras block held fixed.
    n_cameras, n_points : int
    file : str, optional
        The BAL file adjusted (:func:`adjust_bal_file`); None for a problem given in memory.
        Size of the problem as read.
    """

    result: AdjustmentResult
    initial_cost: float
    final_cost: float
    n_observations: int
    n_dropped: int
    fixed: list
    n_cameras: int = 0
    n_points: int = 0
    file: str | None = None

    @property
    def iterations(self) -> int:
        return self.result.iterations

    @property
    def seconds(self) -> float:
        return self.result.seconds

    def to_dict(self) -> dict:
        """``n_cameras``, ``n_points``, ``n_observations`` (adjusted), ``n_dropped`` (behind
        their camera), ``initial_cost`` and ``final_cost`` (½ Σ r², px²), ``iterations``,
        ``seconds`` (solver), ``converged``, ``message``, ``gauge``.
        """
        out = {} if self.file is None else {"file": self.file}
        return out | {
            "n_cameras": self.n_cameras,
            "n_points": self.n_points,
            "n_observations": self.n_observations,
            "n_dropped": self.n_dropped,
            "initial_cost": self.initial_cost,
            "final_cost": self.final_cost,
            "iterations": self.iterations,
            "seconds": self.seconds,
            "converged": self.result.converged,
            "message": self.result.message,
            "gauge": "fixed: camera 0's rotation and translation, one translation component of "
            f"camera 1 (column {CAMERA_COLUMNS[self.fixed[-1][1]]})",
        }


def prepare(problem: BALProblem) -> tuple[BALProblem, int]:
    """Leave out observations of points behind their camera (as COLMAP does).

    Returns
    -------
    problem : BALProblem
        The problem with the remaining observations.
    n_dropped : int
    """
    keep = in_front(problem.cameras, problem.points, problem.camera_index, problem.point_index)
    return problem.subset(keep), int((~keep).sum())


def gauge_fix(cameras: np.ndarray) -> list[tuple[int, int]]:
    """The 7 entries of the cameras block that fix the similarity gauge (module docstring).

    Camera 0's rotation vector and t (columns 0–5), and column ``3 + k`` of camera 1 with
    ``k = argmax |R_1 (C_1 − C_0)|``: ``∂t_1/∂s = −R_1 (C_1 − C_0)`` under a scaling ``s`` about
    camera 0's projection centre ``C_0 = −R_0ᵀ t_0``.

    Raises
    ------
    InputError
        Fewer than two cameras, or cameras 0 and 1 at the same centre (no scale from them).
    """
    if cameras.shape[0] < 2:
        raise InputError("a BAL problem needs at least two cameras to fix the gauge")
    R = R_from_rotvec(cameras[:2, :3])
    C = -np.einsum("nji,nj->ni", R, cameras[:2, 3:6])
    d = R[1] @ (C[1] - C[0])
    if not np.linalg.norm(d) > 0:
        raise InputError("cameras 0 and 1 share their projection centre: cannot fix the scale")
    k = int(np.argmax(np.abs(d)))
    return [(0, j) for j in range(6)] + [(1, 3 + k)]


def adjust_bal(
    problem: BALProblem,
    options: SolverOptions | None = None,
    *,
    progress=None,
) -> BALFit:
    """Adjust a BAL problem: cameras (9 each) and points, gauge fixed (:func:`gauge_fix`).

    Parameters
    ----------
    problem : BALProblem
        As read by :func:`hsgeo.io.bal.read_bal`; observations behind their camera are left
        out first (:func:`prepare`).
    options : SolverOptions, optional
        Default :data:`BAL_OPTIONS`.
    progress : bool or callable, optional
        Passed to :func:`hsgeo.adjust.adjust`.

    Returns
    -------
    BALFit
    """
    prob, n_dropped = prepare(problem)
    if prob.n_observations == 0:
        raise InputError(
            f"every one of the {problem.n_observations} observations is of a point behind its "
            "camera, so none is left to adjust; the likely causes: the points' or the cameras' "
            "signs (BAL cameras look down -z), rotations given as R_world_from_cam instead of "
            "R_cam_from_world, or points and cameras in different coordinate systems"
        )
    block = SnavelyReprojection(prob.camera_index, prob.point_index, prob.xy_px)
    params = Parameters()
    params.add("cameras", prob.cameras, columns=CAMERA_COLUMNS)
    params.add("points", prob.points, columns=("X", "Y", "Z"), points=True)
    fixed = gauge_fix(prob.cameras)
    for i, j in fixed:
        params.fix("cameras", index=(i, j))
    # points whose every observation was left out are not part of the problem (as in COLMAP)
    seen = np.bincount(prob.point_index, minlength=prob.n_points) > 0
    if not seen.all():
        params.fix("points", index=~seen)
    r0, _ = block.evaluate(params.values(), jacobian=False)
    result = adjust(params, [block], options or BAL_OPTIONS, progress=progress)
    return BALFit(
        result=result,
        initial_cost=0.5 * float(r0 @ r0),
        final_cost=result.cost_history[-1],
        n_observations=prob.n_observations,
        n_dropped=n_dropped,
        fixed=fixed,
        n_cameras=problem.n_cameras,
        n_points=problem.n_points,
    )


def adjust_bal_file(path, options: SolverOptions | None = None, *, progress=None) -> BALFit:
    """Read a BAL file (``.txt`` or ``.txt.bz2``), adjust it, and summarise (``hsgeo adjust-bal``):
    the file front end of :func:`adjust_bal`.

    Returns
    -------
    BALFit
        :func:`adjust_bal`'s result with ``file`` set (its :meth:`BALFit.to_dict` names it).
    """
    from dataclasses import replace

    from hsgeo.io.bal import read_bal

    problem = read_bal(path)
    fit = adjust_bal(problem, options, progress=progress)
    return replace(fit, file=str(path))
