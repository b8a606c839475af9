"""The settings of the least-squares solver, in one frozen dataclass.

Every tolerance and switch of :func:`hsgeo.adjust.adjust` is a field of :class:`SolverOptions`;
the solver keeps no module-level state. ``adjust(p, blocks, reject_k=5.0)`` is shorthand for
``adjust(p, blocks, SolverOptions(reject_k=5.0))``.
"""

from __future__ import annotations

import difflib
import math
import numbers
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from hsgeo.errors import InputError

__all__ = ["SolverOptions"]


@dataclass(frozen=True)
class SolverOptions:
    """Settings of the Levenberg–Marquardt solver (see :mod:`hsgeo.adjust.solver`).

    Costs are ``½ Σ r_w²`` of the whitened residuals ``r_w = (f(x) − l) / σ`` (dimensionless);
    the damping λ is relative to the diagonal of the normal matrix (dimensionless).

    Parameters
    ----------
    max_iter : int, default 50
        Maximum number of accepted Gauss–Newton/LM steps per rejection round.
    ftol : float, default 1e-10
        Convergence when the decrease of the cost the Gauss–Newton step predicts is below
        ``ftol`` times the cost (relative, dimensionless).
    xtol : float, default 0
        With ``xtol > 0``, convergence also needs the Gauss–Newton step of every free
        parameter to be small: ``|Δx_i| ≤ xtol · (|x_i| + xtol)`` (relative, dimensionless),
        the test that bounds the number of correct digits of the estimate (e.g. ``1e-12``
        for the NIST StRD problems). ``0``: the cost test alone (``ftol``).
    atol : float, default 1e-24
        Convergence when the cost per residual component falls below it (noise-free data).
    lambda0 : float, default 1e-6
        Initial Marquardt damping; small means Gauss–Newton first.
    damping_diagonal : {"current", "max"}, default "current"
        The diagonal ``D`` of Marquardt's damping ``N + λ D`` for the non-point unknowns:
        ``"current"``, ``diag(N)`` at the current point; ``"max"``, the largest ``diag(N)``
        seen so far in the solve, entry by entry (Moré 1978, as MINPACK's ``lmder``), which
        keeps a parameter damped where its column of the Jacobian has faded (a saturated
        exponential), so the step cannot run away along it.
    geodesic : float or None, default None
        Geodesic acceleration (Transtrum & Sethna 2012) with this bound ``α`` (e.g. 0.75):
        each damped step ``v`` gets the second-order correction ``½ a``, ``a`` the damped
        solution for the residuals' second directional derivative along ``v`` (one extra
        evaluation of the residuals, by finite differences), and a step with
        ``‖a‖ > α ‖v‖`` (in the damping's scaled norm) is refused like one that does not
        decrease the cost. It follows curved valleys (MGH10) and keeps the first steps out of
        saturated regions (BoxBOD). Only for problems without a points block. ``None``: off.
    lambda_points_min : float, default 1e-4
        Below this damping the points' blocks are not damped (only the reduced system is), so
        one reduced matrix per linearisation point serves the datum check, the damped retries
        and the covariance.
    lambda_max : float, default 1e16
        Damping at which the step search gives up: no step decreases the cost.
    reject_k : float or None, default None
        Reject observations whose standardised residual (whitened, divided by ``√(1 − h)``
        with ``h`` the leverage on its point) exceeds ``reject_k`` robust σ (NMAD). ``None``:
        no outlier rejection.
    reject_every_iteration : bool, default False
        With ``reject_k``: test the residuals after every iteration from a settled iterate on
        (002 §3.4) instead of in rounds after convergence.
    max_reject_rounds : int, default 10
        Maximum number of rejection rounds (rounds mode).
    reject_round_ftol : float, default 1e-4
        Relative cost decrease at which an intermediate rejection round stops (rounds mode);
        the final round iterates to ``ftol``.
    settled : float, default 1e-2
        An iterate is *settled* when the last step decreased the cost by less than this share
        of it, or the actual decrease matched the predicted one to this share of the new cost.
        From a settled iterate on, each-iteration rejection tests the residuals and the
        compiled path takes chord steps. ``inf``: every iterate counts as settled.
    chord_end : float, default 1e-3
        Chord steps end when their predicted decrease falls below ``chord_end · ftol · cost``.
    hold_points : bool, default True
        With a points block: a step refused because of a few points (at most 0.1 % of them
        carrying 90 % of the excess of the actual over the linearly predicted squared
        residuals) is tried again with those points held in place before the damping grows;
        a point at most ``hold_max`` times a solve (its full step would otherwise keep the
        convergence test from passing).
    hold_max : int, default 3
        With ``hold_points``: most times one point is held in place in a solve.
    thrown_ratio : float, default 1000
        With ``hold_points``: an accepted step before the first settled iterate is tried again
        with a few points held (at most 0.1 % of them) when their rows' excess over the linear
        prediction exceeds ``thrown_ratio`` times the points' median excess ...
    thrown_share : float, default 0.25
        ... and sums to at least ``thrown_share`` of the step's cost (at 7× the paper's
        pushbroom block two points carried 1.2e8 of a 7.2e7 cost, the median point 3; at 1× no
        point passes 1000 times the median).
    robust_start : {None, "cauchy", "huber"}, default None
        Iterate with a robust loss ``ρ`` of each group's squared whitened residual (Ceres'
        ``CauchyLoss``/``HuberLoss``, as COLMAP's bundle adjustment does) from the first
        iteration until the first settled iterate, then with least squares (and the outlier
        rejection, if any) to the minimum: gross errors cannot throw their points before
        they are tested. The minimum is that of least squares either way. ``None``: least
        squares throughout. On the 002 pushbroom block it took 6 iterations
        against 4 at the paper's size and, with the rejection, rejected 301 good observations
        against 66 (1,060 of 1,304 gross errors against 1,175): the workflow does not use it.
    robust_start_k : float, default 3.0
        Scale of the robust loss in robust σ (NMAD of the whitened residuals, taken afresh
        at each linearisation).
    check_datum : bool, default True
        Check the rank before the first step; raise :class:`~hsgeo.DatumError` if deficient.
    drop_undetermined_points : bool, default False
        With ``check_datum``: a free point whose own normal block is singular (too few or
        degenerate rays) is held at its initial value and its observations are left out
        instead of stopping the adjustment; the result names them
        (``AdjustmentResult.dropped_points``). Any other deficiency still raises.
    strict_covariance : bool, default False
        If the normal matrix at the solution is singular (a datum defect that appeared during
        the iterations: e.g. every observation of a band rejected), raise
        :class:`~hsgeo.DatumError`. Default: the covariance of the estimable part is returned
        (a generalised inverse, unique for estimable functions) and the parameters the data
        no longer determine are named (``AdjustmentResult.undetermined_parameters``, NaN
        rows and columns of ``covariance``).
    rank_rtol : float, default 1e-11
        Relative eigenvalue threshold of the datum check (see
        :func:`~hsgeo.adjust.identifiability`).
    raise_on_failure : bool, default True
        Raise :class:`~hsgeo.ConvergenceError` (carrying the result) if the iteration does not
        converge; otherwise return the result with ``converged=False``.
    compiled : bool, default True
        Form the normal equations with the compiled row-compressed kernels
        (:mod:`hsgeo.adjust._fast`); ``False``: the generic scipy.sparse path (same equations,
        no chord steps; for tests and debugging).
    fused : bool, default True
        On the compiled path, let residual blocks that can (``ResidualBlock.evaluate_into``,
        e.g. :class:`~hsgeo.sensors.pushbroom.PushbroomLines`) write their whitened
        derivatives straight into the engine's row-compressed arrays instead of returning a
        Jacobian the engine copies; ``False``: every block through its ``evaluate`` (the
        reference the tests compare against; same equations).
    keep_jacobian : bool, default False
        Keep the Jacobian of the final iterate in the result, which
        :meth:`~hsgeo.adjust.AdjustmentResult.point_covariance` (and ``sigma`` of the points)
        needs. Off by default: the Jacobian can be the largest array of a solve.
    threads : "auto" or int, default "auto"
        Threads of the compiled kernels during the solve (:mod:`hsgeo.adjust.threads`).
        ``"auto"``: one thread below ``PARALLEL_MIN_ROWS`` (400,000) residual rows and
        numba's pool above (measured idle and with one core busy:
        ``bench/results/busy_machine.json``); an integer: that many. Only the speed depends on
        it, never the numbers (bit for bit).
    blas_threads : int, default 1
        Threads of BLAS/LAPACK (the dense reduced system) during the solve, whatever the
        shell's ``OPENBLAS_NUM_THREADS``. Results differ in the last digits with the count,
        the decisions taken from them (rank, datum, covariance) do not.

    Raises
    ------
    InputError
        If a value is out of its range (the message names the field and the valid range).
    """

    max_iter: int = 50
    ftol: float = 1e-10
    xtol: float = 0.0
    atol: float = 1e-24
    lambda0: float = 1e-6
    damping_diagonal: str = "current"
    geodesic: float | None = None
    lambda_points_min: float = 1e-4
    lambda_max: float = 1e16
    reject_k: float | None = None
    reject_every_iteration: bool = False
    max_reject_rounds: int = 10
    reject_round_ftol: float = 1e-4
    settled: float = 1e-2
    chord_end: float = 1e-3
    hold_points: bool = True
    hold_max: int = 3
    thrown_ratio: float = 1000.0
    thrown_share: float = 0.25
    robust_start: str | None = None
    robust_start_k: float = 3.0
    check_datum: bool = True
    drop_undetermined_points: bool = False
    strict_covariance: bool = False
    rank_rtol: float = 1e-11
    raise_on_failure: bool = True
    compiled: bool = True
    fused: bool = True
    keep_jacobian: bool = False
    threads: int | str = "auto"
    blas_threads: int = 1

    def __post_init__(self) -> None:
        for name in ("max_iter", "max_reject_rounds", "blas_threads", "hold_max"):
            v = getattr(self, name)
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral) or v < 0:
                raise InputError(f"SolverOptions.{name} must be a non-negative integer, got {v!r}")
        if self.blas_threads < 1:
            raise InputError(f"SolverOptions.blas_threads must be ≥ 1, got {self.blas_threads!r}")
        positive = (
            "ftol",
            "lambda0",
            "lambda_points_min",
            "lambda_max",
            "reject_round_ftol",
            "chord_end",
            "rank_rtol",
            "robust_start_k",
            "thrown_ratio",
            "thrown_share",
        )
        for name in positive:
            v = getattr(self, name)
            if not _is_real(v) or not (0.0 < v < math.inf):
                raise InputError(
                    f"SolverOptions.{name} must be a finite positive number, got {v!r}"
                )
        for name in ("xtol", "atol", "settled"):
            v = getattr(self, name)
            if not _is_real(v) or math.isnan(v) or v < 0.0:
                raise InputError(f"SolverOptions.{name} must be a number ≥ 0, got {v!r}")
        if self.lambda0 > self.lambda_max:
            raise InputError(
                f"SolverOptions.lambda0 ({self.lambda0!r}) exceeds lambda_max "
                f"({self.lambda_max!r}): no step could be tried"
            )
        if self.damping_diagonal not in ("current", "max"):
            raise InputError(
                "SolverOptions.damping_diagonal must be 'current' (diag(N) at the current "
                f"point) or 'max' (the largest seen), got {self.damping_diagonal!r}"
            )
        if self.geodesic is not None and (
            not _is_real(self.geodesic) or not (0.0 < self.geodesic < math.inf)
        ):
            raise InputError(
                "SolverOptions.geodesic must be None (off) or the bound α of the acceleration "
                f"relative to the step, a positive number such as 0.75; got {self.geodesic!r}"
            )
        if self.robust_start not in (None, "cauchy", "huber"):
            raise InputError(
                "SolverOptions.robust_start must be None (least squares throughout), "
                f"'cauchy' or 'huber'; got {self.robust_start!r}"
            )
        if self.reject_k is not None and (
            not _is_real(self.reject_k) or not (0.0 < self.reject_k < math.inf)
        ):
            raise InputError(
                f"SolverOptions.reject_k must be None (no rejection) or a finite positive "
                f"number of robust σ, e.g. 5.0; got {self.reject_k!r}"
            )
        for name in (
            "reject_every_iteration",
            "check_datum",
            "drop_undetermined_points",
            "strict_covariance",
            "raise_on_failure",
            "compiled",
            "fused",
            "keep_jacobian",
            "hold_points",
        ):
            v = getattr(self, name)
            if not isinstance(v, (bool, np.bool_)):
                raise InputError(f"SolverOptions.{name} must be True or False, got {v!r}")

        t = self.threads
        if not (
            t == "auto"
            if isinstance(t, str)
            else isinstance(t, numbers.Integral) and not isinstance(t, (bool, np.bool_)) and t >= 1
        ):
            raise InputError(
                f"SolverOptions.threads must be 'auto' (chosen by the size of the problem) or a "
                f"positive number of threads, got {t!r}"
            )

    @classmethod
    def field_names(cls) -> list[str]:
        """The names of the settings, in declaration order."""
        return [f.name for f in fields(cls)]

    def replace(self, **changes: Any) -> SolverOptions:
        """A copy with some fields changed; an unknown name raises :class:`InputError`.

        The error names the closest valid field (``ftoll`` → ``ftol``).
        """
        valid = self.field_names()
        for key in changes:
            if key not in valid:
                close = difflib.get_close_matches(key, valid, n=1)
                hint = f" Did you mean {close[0]!r}?" if close else ""
                raise InputError(
                    f"unknown solver option {key!r}.{hint} Valid options: {', '.join(valid)}"
                )
        return replace(self, **changes) if changes else self

    @classmethod
    def resolve(cls, options: SolverOptions | None, overrides: dict[str, Any]) -> SolverOptions:
        """``options`` (default: the defaults) with ``overrides`` applied (see :meth:`replace`)."""
        if options is None:
            options = cls()
        elif not isinstance(options, cls):
            raise InputError(
                f"options must be a SolverOptions, got {type(options).__name__}; pass single "
                "settings as keywords, e.g. adjust(params, blocks, ftol=1e-8)"
            )
        return options.replace(**overrides)


def _is_real(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))
