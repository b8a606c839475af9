"""The least-squares solver: Levenberg–Marquardt on the Schur-reduced normal equations.

Kept as one file: one concern, the Levenberg–Marquardt iteration; the entry point, the state of
one solve (:class:`_Solve`: steps, trials, rejection rounds, chord steps) and its progress
display share that state and change together.

Gauss–Newton with Levenberg–Marquardt damping on the whitened observation equations
``r_w = (f(x) - l) / σ``, minimising ``½ Σ r_w²`` over the free parameters:

* the Jacobian is assembled sparse from the residual blocks (:mod:`hsgeo.adjust.system`);
  priors enter as pseudo-observations ``(x - μ) / σ_prior``;
* per-point unknowns (the ``points=True`` block) are eliminated by the Schur complement and
  damping is Marquardt's ``N + λ diag(N)`` with Nielsen's update of λ
  (:mod:`hsgeo.adjust.schur`);
* convergence: the decrease the Gauss–Newton step predicts at the current point is below
  ``ftol`` times the cost (the reduced matrix just formed then gives the covariance) and, with
  ``xtol``, that step is below ``xtol`` relative to each parameter; or the cost is below
  ``atol`` (noise-free data);
* before the first step the datum is checked (:mod:`hsgeo.adjust.datum`);
* optional outlier rejection (:mod:`hsgeo.adjust.robust`): in rounds after convergence, or in
  every iteration from a settled iterate on (``reject_every_iteration``, as 002 §3.4 does);
* from a settled iterate on, the compiled path takes chord steps (the last reduced matrix
  reused) and forms the matrix again at the final iterate;
* a refused step is retried with the few points that refused it held; before the first
  settled iterate, an accepted step that threw a few points far off is taken with them held
  when that costs less (:meth:`_Solve._hold_thrown`);
* optionally a robust loss until the first settled iterate (``robust_start``,
  :mod:`hsgeo.adjust.loss`), least squares after it;
* blocks that can write their whitened rows themselves (``fused``, :mod:`hsgeo.adjust._fused`)
  do so, with the gradient and diagonal of those rows, in their own pass;
* the seconds of each phase are in ``AdjustmentResult.seconds_split``;
* the a-posteriori σ0 and the covariance of the non-point parameters (points on request) are in
  the :class:`~hsgeo.adjust.result.AdjustmentResult`.

Every setting is a field of :class:`~hsgeo.adjust.options.SolverOptions`.

References
----------
Triggs, McLauchlan, Hartley, Fitzgibbon (2000): Bundle adjustment — a modern synthesis.
Madsen, Nielsen, Tingleff (2004): Methods for non-linear least squares problems, §3.2.
M. K. Transtrum, J. P. Sethna (2012): Improvements to the Levenberg–Marquardt algorithm
for nonlinear least-squares minimization. arXiv:1201.5885.
J. J. Moré (1978): The Levenberg–Marquardt algorithm: implementation and theory. Lecture
Notes in Mathematics 630, 105–116.
C. T. Kelley (1995): Iterative Methods for Linear and Nonlinear Equations, SIAM, ch. 5.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla

from hsgeo.adjust.datum import _check_datum, _undetermined_points
from hsgeo.adjust.options import SolverOptions
from hsgeo.adjust.parameters import Parameters
from hsgeo.adjust.residuals import ResidualBlock
from hsgeo.adjust.result import AdjustmentResult
from hsgeo.adjust.robust import _leverage, _reject
from hsgeo.adjust.schur import (
    _Normal,
    _normal,
    _OrderCache,
    _point_cofactor_function,
    _predicted_decrease,
    _reduced,
    _reduced_estimable_inverse,
    _reduced_inverse,
    _spd_solve,
    _step,
)
from hsgeo.adjust.system import _Buffers, _Clock, _evaluate, _Layout, _NonFinite, _System
from hsgeo.adjust.threads import engine_threads
from hsgeo.errors import ConvergenceError, DatumError, InputError, ObservationError

#: An accepted trial's cost may fall short of the exact cost at its point by this much,
#: relative, before the solver costs its trials exactly (see _Solve._confirm_trial)
_TRIAL_COST_RTOL = 1e-9

__all__ = ["adjust", "progress_text"]


def adjust(
    params: Parameters,
    blocks: Sequence[ResidualBlock] | ResidualBlock,
    options: SolverOptions | None = None,
    *,
    progress: bool | Callable[[dict], Any] | None = None,
    **overrides: Any,
) -> AdjustmentResult:
    """Adjust ``params`` to the observations of ``blocks`` by least squares.

    Parameters
    ----------
    params : Parameters
        Initial values, free/fixed flags and priors. Not modified: the estimate is in the result.
    blocks : ResidualBlock or sequence of them
        The observation equations.
    options : SolverOptions, optional
        Tolerances and switches (default: ``SolverOptions()``).
    progress : bool or callable, optional
        Print iteration, cost and λ to stderr (True) or call ``progress(info_dict)`` after
        every accepted step.
    **overrides
        Fields of :class:`SolverOptions` that replace those of ``options``, e.g.
        ``adjust(p, blocks, reject_k=5.0, ftol=1e-8)``.

    Returns
    -------
    AdjustmentResult

    Raises
    ------
    InputError
        An unknown or invalid setting (the message names the closest valid one).
    ObservationError
        No residual blocks, nothing free, or fewer observations than unknowns.
    DatumError
        The normal equations are rank deficient (``check_datum``), or singular at the solution.
    ConvergenceError
        No convergence and ``raise_on_failure`` (the last iterate is in ``.result``).

    Notes
    -----
    Levenberg–Marquardt on the Schur-reduced normal equations (the points eliminated). When
    the reduced matrix is formed point by point by the compiled kernel (the costly part of an
    iteration), the steps after a settled iterate (``SolverOptions.settled``) are *chord
    steps* (Kelley 1995, ch. 5): they reuse the last reduced matrix formed, with the gradient
    and the points' blocks of the current iterate, so they still descend to the same minimum,
    linearly. Where they have converged (to ``chord_end · ftol``), or when one fails to
    decrease the cost, the matrix is formed again; convergence is only declared with the
    matrix of the final iterate, which also gives the covariance.

    With ``reject_k``, rounds mode adjusts to convergence, rejects (see
    :mod:`hsgeo.adjust.robust`) and adjusts again until nothing is rejected or
    ``max_reject_rounds``; while outliers are still being rejected a round only iterates to
    ``reject_round_ftol``. Each-iteration mode (``reject_every_iteration``) tests after every
    step from a settled iterate on and has converged when the predicted decrease is below
    ``ftol`` and the last test rejected nothing.
    """
    opts = SolverOptions.resolve(options, overrides)
    blocks = [blocks] if isinstance(blocks, ResidualBlock) else list(blocks)
    if not blocks:
        raise ObservationError("no residual blocks given: nothing to adjust")
    # threads chosen by the size of the problem (hsgeo.adjust.threads): the speed, not the bits
    with engine_threads(opts.threads, sum(b.m for b in blocks), opts.blas_threads):
        return _adjust(params, blocks, opts, progress)


def _adjust(params, blocks, opts: SolverOptions, progress) -> AdjustmentResult:
    solve = _Solve(params.copy(), blocks, opts, progress)
    # rounds mode: while outliers are still being rejected, a round only needs to get close to
    # its minimum (the residuals that decide the rejection do not change at 1e-4 relative
    # cost); once a rejection pass finds nothing new, the iteration continues to ``ftol``
    final = opts.reject_k is None or solve.each
    rounds = 0
    while True:
        tol = opts.ftol if final else max(opts.ftol, opts.reject_round_ftol)
        sy = ne = None  # free the previous round's Jacobian first (peak memory)
        outcome, sy, ne = solve.minimise(tol, check_datum=opts.check_datum and rounds == 0)
        if outcome.rejected:  # each-iteration mode: a rejection at convergence, adjust again
            rounds += 1
            continue
        if not outcome.converged or final:
            break
        if rounds >= opts.max_reject_rounds:
            final = True
            continue
        # -- outlier rejection round
        new_any = solve.reject(sy, sy, ne)
        rounds += 1
        if not new_any:
            if tol <= opts.ftol:
                break
            final = True
    result = solve.result(sy, ne, outcome, rounds)
    if not outcome.converged and opts.raise_on_failure:
        raise ConvergenceError(
            f"the adjustment did not converge: {outcome.message} (last cost "
            f"{solve.history[-1]:.6g}). Check the initial values, increase max_iter, or look "
            "for gross errors; the last iterate is in the exception's .result.",
            result,
        )
    return result


@dataclass(frozen=True)
class _Outcome:
    """How one minimisation (a pass of the LM loop) ended."""

    converged: bool
    message: str
    rejected: bool = False  # each-iteration mode: stopped to adjust again with new masks


@dataclass
class _Trial:
    """An accepted (or, with ``lam > lambda_max``, the last refused) damped step."""

    system: _System  # residuals at the new point
    actual: float  # actual decrease of the cost
    pred: float  # decrease predicted by the linearised model
    lam: float
    nu: float


class _Solve:
    """The state of one adjustment: layout, masks, processing orders, history, counters."""

    def __init__(
        self, params: Parameters, blocks: list[ResidualBlock], options: SolverOptions, progress
    ):
        self.options = options
        self.blocks = blocks
        params._sync_ties()  # a tied entry starts at its target's value
        self.layout = _Layout(params)
        if self.layout.n_unknowns == 0:
            raise ObservationError(
                "every parameter is fixed: there is nothing to estimate (free some with "
                "Parameters.free())"
            )
        if options.geodesic is not None and self.layout.pblock is not None:
            raise InputError(
                f"SolverOptions.geodesic is not available with a points block "
                f"({self.layout.pblock.name!r}): set geodesic=None, or add the points as an "
                "ordinary block (points=False)"
            )
        self.masks = [np.ones(b.m, dtype=bool) for b in blocks]
        self.orders = _OrderCache()
        self.show = _progress_printer(progress)
        self.history: list[float] = []
        self.t0 = time.perf_counter()
        self.total_iter = 0
        self.each = options.reject_k is not None and options.reject_every_iteration
        self.D_max: np.ndarray | None = None  # damping_diagonal="max": the running maximum
        self.hold_count: dict[int, int] = {}  # times each point was held (at most options.hold_max)
        self.dropped_points: list[int] = []  # SolverOptions.drop_undetermined_points
        self.dropped_rows = [np.zeros(b.m, dtype=bool) for b in blocks]  # ... their rows
        self.settled_seen = False  # an iterate was settled (accepted steps no longer held)
        self.clock = _Clock()  # AdjustmentResult.seconds_split
        #: the Jacobian's arrays, written again by each linearisation (the previous system is
        #: always dropped first: see minimise)
        self.buffers = _Buffers()
        #: SolverOptions.robust_start: the loss until the first settled iterate, and the
        #: scales of the last linearisation (the trial steps are costed with the same)
        self.loss_on = options.robust_start is not None
        self.loss_c: dict | None = None
        #: trial steps without a loss are costed with the blocks' trial_residuals until one
        #: accepted trial's cost is found below the exact cost of the linearisation at its
        #: point (see _confirm_trial); from then on with evaluate, as the linearisations
        self.trial_residuals = True

    # -- the linearised system -------------------------------------------------------------
    def linearise(self, check_redundancy: bool = False) -> tuple[_System, _Normal]:
        """The whitened system and its normal equations at the current values."""
        layout, opts = self.layout, self.options
        sy = _evaluate(
            layout,
            self.blocks,
            self.masks,
            jacobian=True,
            compiled=opts.compiled,
            clock=self.clock,
            loss=(opts.robust_start, opts.robust_start_k, None) if self.loss_on else None,
            fused=opts.fused,
            buffers=self.buffers,
        )
        self.loss_c = sy.loss_c
        if check_redundancy:
            dof = sy.r.size - layout.n_unknowns
            if dof < 0 or (dof == 0 and sy.n_obs_rows < layout.n_unknowns):
                raise ObservationError(
                    f"fewer observations ({sy.r.size} residual components incl. priors) than "
                    f"unknowns ({layout.n_unknowns}): add observations, fix parameters or add "
                    "priors"
                )
        return sy, _normal(layout, sy, self.options, self.orders, self.clock)

    def trial(self, change: np.ndarray | None = None) -> _System:
        """The residuals at the current values (no Jacobian), under the loss of the last
        linearisation if the robust start is on; raises ``_NonFinite``. ``change``: the
        step's ``J h`` on the system's rows, given to the blocks first
        (:meth:`ResidualBlock.start_trial`).
        """
        opts = self.options
        if change is not None:
            self._start_trials(change)
        loss = None
        if self.loss_on and self.loss_c is not None:
            loss = (opts.robust_start, opts.robust_start_k, self.loss_c)
        return _evaluate(
            self.layout, self.blocks, self.masks, False, opts.compiled, self.clock, loss,
            trial=self.trial_residuals and loss is None,
        )  # fmt: skip

    def _start_trials(self, change: np.ndarray) -> None:
        """Each block that takes it (:meth:`ResidualBlock.start_trial`) is given its rows of the
        whitened ``change`` (the kept rows, in the system's order), in its units (× σ).
        """
        off = 0
        for blk, keep in zip(self.blocks, self.masks, strict=True):
            nk = int(np.count_nonzero(keep))
            if type(blk).start_trial is not ResidualBlock.start_trial:
                sigma = np.broadcast_to(np.asarray(blk.sigma, dtype=np.float64), (blk.m,))
                if nk == blk.m:  # every row kept: no selection
                    ch = change[off : off + nk] * sigma
                else:
                    ch = np.full(blk.m, np.nan)
                    ch[keep] = change[off : off + nk] * sigma[keep]
                blk.start_trial(ch)
            off += nk

    def _confirm_trial(self, trial_cost: float | None, cost: float) -> None:
        """Check an accepted trial's cost against the exact cost at its point.

        ``trial_cost``: the cost of the accepted trial step, with the same rows and without a
        loss as the linearisation at its point whose cost is ``cost`` (None: not comparable).
        :meth:`ResidualBlock.trial_residuals` may stop an internal iteration early, with an
        error of second order in what it still moves (≤ 3e-12 relative in the chapter's
        pushbroom adjustment); if the exact cost exceeds the trial's by more than 1e-9
        relative, the model is not that smooth here (grossly wrong inputs, a crossing time
        with two solutions), and every later trial is costed exactly (``evaluate``). The step
        already taken stays: the minimisation goes on from its point, as from a restart.
        """
        if trial_cost is None or not self.trial_residuals:
            return
        if not cost <= trial_cost + _TRIAL_COST_RTOL * abs(trial_cost):
            self.trial_residuals = False

    def reject(self, residuals: _System, sy: _System, ne: _Normal) -> bool:
        """Test the residuals of ``residuals`` (leverages from ``sy``, ``ne``); see robust."""
        t0 = time.perf_counter()
        out = _reject(
            self.blocks,
            self.masks,
            residuals,
            self.options.reject_k,
            self.layout.row_point,
            _leverage(ne, sy),
        )
        self.clock.add("rejection", t0)
        return out

    def _drop_undetermined(self, sy, ne):
        """Hold the free points that their observations do not determine (a singular 3 × 3
        block) and leave their observations out (``SolverOptions.drop_undetermined_points``);
        the system at the current values without them.
        """
        layout, opts = self.layout, self.options
        if layout.pblock is None:
            return sy, ne
        pts = _undetermined_points(layout, ne, opts.rank_rtol)  # 3 × 3 blocks: cheap
        if not pts or sy.pidx is None:
            return sy, ne
        # observation rows of the system, block by block, are the unmasked rows of each block
        drop = np.isin(sy.pidx[: sy.n_obs_rows], pts)
        row = 0
        for m, dropped in zip(self.masks, self.dropped_rows, strict=True):
            kept = np.flatnonzero(m)
            rows = kept[drop[row : row + kept.size]]
            m[rows] = False
            dropped[rows] = True
            row += kept.size
        layout.params.fix(layout.pblock.name, np.asarray(pts))
        layout.pfree[pts] = False
        self.dropped_points += [int(i) for i in pts]
        sy = ne = None
        sy, ne = self.linearise(check_redundancy=True)
        self._damping_diagonal(ne)
        return sy, ne

    # -- one pass of the Levenberg–Marquardt loop -------------------------------------------
    def minimise(self, tol: float, check_datum: bool = False):
        """Iterate from the current values to the minimum (to ``tol``) with the current masks.

        With ``check_datum``, the rank at the current values is checked first. Returns the
        outcome and the system and normal equations of the final iterate (the only Jacobian
        kept alive: each is dropped before the next is formed).
        """
        opts = self.options
        sy, ne = self.linearise(check_redundancy=True)
        self._damping_diagonal(ne)
        if check_datum:
            t0 = time.perf_counter()
            points_checked = False
            if opts.drop_undetermined_points:
                ne_before = ne
                sy, ne = self._drop_undetermined(sy, ne)
                # none dropped: the same normal equations, whose point blocks were just tested
                points_checked = ne is ne_before
            _check_datum(self.layout, ne, opts.rank_rtol, points_checked)
            self.clock.add("datum", t0)
        lam, nu = opts.lambda0, 2.0
        cost = sy.cost
        self.history.append(cost)
        rejecting = False  # each-iteration mode: rejection has started
        tested = False  # each-iteration mode: the current point passed the rejection test
        n_iter = 0
        while True:
            if cost <= opts.atol * sy.r.size and not self.loss_on:
                return _Outcome(True, "cost below atol (noise-free data)"), sy, ne
            dc, dp, pred = self._gauss_newton_step(ne, lam, tol, cost)
            converged = self._converged(ne, lam, pred, tol, cost) and self._small_step(dc, dp)
            if self.loss_on and converged:
                # the robust start ends at its own minimum: least squares from here on
                self.loss_on = False
                sy = ne = None
                sy, ne = self.linearise()
                self._damping_diagonal(ne)
                cost = sy.cost
                continue
            if converged:
                # converged before any rejection test (e.g. at the initial values)
                if self.each and not tested and self.reject(sy, sy, ne):
                    return _Outcome(False, "", rejected=True), sy, ne
                # the Gauss–Newton step would decrease the cost by less than ftol: this is the
                # minimum, and the reduced system just formed gives its covariance
                return _Outcome(True, "predicted decrease of the cost below ftol"), sy, ne
            if n_iter >= opts.max_iter:
                return (
                    _Outcome(False, f"not converged within max_iter={opts.max_iter} iterations"),
                    sy,
                    ne,
                )
            n_iter += 1
            self.total_iter += 1
            step = self._damped_step(ne, cost, lam, nu, dc, dp, pred, sy)
            lam, nu = step.lam, step.nu
            if lam > opts.lambda_max and self.loss_on:
                self.loss_on = False  # the robust start ends here: least squares from here on
                sy = ne = step = None
                sy, ne = self.linearise()
                self._damping_diagonal(ne)
                lam, nu, cost = opts.lambda0, 2.0, sy.cost
                continue
            if lam > opts.lambda_max:
                # no step decreases the cost: we are at the minimum to machine precision
                ok = step.pred <= 1e3 * tol * max(cost, 1e-300) or cost <= opts.atol * sy.r.size
                return (
                    _Outcome(
                        ok,
                        "no further decrease possible"
                        if ok
                        else ("the damping grew without bound: the cost could not be decreased"),
                    ),
                    sy,
                    ne,
                )
            new_cost = step.system.cost
            self.history.append(new_cost)
            tested = False
            settled = _settled(step.actual, step.pred, new_cost, opts.settled)
            self.settled_seen = self.settled_seen or settled
            switched = self.loss_on and settled
            if switched:
                # the robust start ends at the first settled iterate: from here on least
                # squares, and the rejection tests the plain residuals
                self.loss_on = False
                step.system = self.trial()
                self.history[-1] = new_cost = step.system.cost
            rejected_now = False
            if self.each and (rejecting or settled):
                # 002 §3.4: outliers are rejected in each iteration, on the residuals at the
                # new point, from the first settled iterate: before that, residuals reflect
                # the initial values, not gross errors
                rejecting = True
                rejected_now = self.reject(step.system, sy, ne)
                tested = not rejected_now
            # the trial's cost, if the linearisation at its point costs the same rows the
            # same way (no loss, no row rejected since)
            check = None if self.loss_on or rejected_now else new_cost
            self._report(new_cost, lam)
            # chord steps (Kelley 1995, ch. 5): from a settled iterate on, the reduced matrix
            # barely changes, so the next steps reuse the last one formed (the gradient and
            # the points' blocks are always those of the current point); it is formed again
            # where the convergence test passes, or when a chord step fails
            chord = (
                ne.reduced0[0]
                if settled and not switched and ne.compiled_schur and ne.reduced0 is not None
                else None
            )
            sy = ne = step = None  # free the old Jacobian before forming the new one
            sy, ne = self.linearise()
            self._damping_diagonal(ne)
            if chord is not None and ne.compiled_schur:
                ne.S_chord = chord
            cost = sy.cost  # (lower than new_cost when observations were just rejected)
            self._confirm_trial(check, cost)

    def _gauss_newton_step(self, ne: _Normal, lam: float, tol: float, cost: float):
        """The damped step at λ and its predicted decrease; converged chord steps are
        replaced by the step with the reduced matrix formed at this point.
        """
        layout = self.layout
        dc, dp = _step(layout, ne, lam)
        pred = _predicted_decrease(layout, ne, lam, dc, dp)
        chord_done = ne.S_chord is not None and pred <= self.options.chord_end * tol * cost
        if lam <= self.options.lambda_points_min and chord_done:
            # the chord steps have converged (they converge linearly, hence the margin):
            # form the reduced matrix here to confirm it, and for the covariance
            ne.exact()
            dc, dp = _step(layout, ne, lam)
            pred = _predicted_decrease(layout, ne, lam, dc, dp)
        return dc, dp, pred

    def _converged(self, ne: _Normal, lam: float, pred: float, tol: float, cost: float) -> bool:
        """The undamped Gauss–Newton step with this point's own matrix predicts a decrease
        below ``tol`` times the cost.

        With a points block and λ above ``lambda_points_min`` the step had damped point
        blocks; the decrease a damped step predicts never exceeds the undamped step's (it falls
        as λ grows), so only when it is already below ``tol`` the undamped step is formed and
        tested. Without points, convergence waits for λ ≤ ``lambda_points_min`` as before.
        """
        if pred > tol * cost or ne.S_chord is not None:
            return False
        if lam <= self.options.lambda_points_min:
            return True
        if ne.V is None:  # no point blocks: as before, wait for λ ≤ lambda_points_min
            return False
        dc, dp = _step(self.layout, ne, 0.0)
        return _predicted_decrease(self.layout, ne, 0.0, dc, dp) <= tol * cost

    def _damping_diagonal(self, ne: _Normal) -> None:
        """With ``damping_diagonal="max"``: damp by the largest diag(N_cc) seen (Moré 1978)."""
        if self.options.damping_diagonal != "max" or not self.layout.n_c:
            return
        d = ne.damping_diagonal()
        self.D_max = d.copy() if self.D_max is None else np.maximum(self.D_max, d)
        ne.D_c = self.D_max

    def _small_step(self, dc: np.ndarray, dp) -> bool:
        """``|Δx_i| ≤ xtol (|x_i| + xtol)`` for every free parameter (True if ``xtol`` is 0)."""
        xtol = self.options.xtol
        if xtol == 0.0:
            return True
        layout = self.layout
        for b in layout.cblocks:
            cm = layout.colmap[b.name]
            sel = cm >= 0
            if np.any(np.abs(dc[cm[sel]]) > xtol * (np.abs(b.value.ravel()[sel]) + xtol)):
                return False
        if layout.pblock is not None and dp is not None:
            x = layout.pblock.value
            if np.any(np.where(layout.pfree, np.abs(dp) - xtol * (np.abs(x) + xtol), 0.0) > 0):
                return False
        return True

    def _geodesic(self, sy: _System, ne: _Normal, lam: float, dc: np.ndarray, pred: float):
        """The step ``v + ½ a`` with geodesic acceleration and its predicted decrease, or None
        if ``a`` is too large (Transtrum & Sethna 2012, with their finite-difference ``r_vv``).
        """
        layout, h = self.layout, 0.1
        state = layout.get_state()
        layout.apply(h * dc, None)
        try:
            r_h = _evaluate(layout, self.blocks, self.masks, False, self.options.compiled).r
        except _NonFinite:
            return None
        finally:
            layout.set_state(state)
        # second directional derivative of the residuals along v (their eq. 12)
        r_vv = (2.0 / h) * ((r_h - sy.r) / h - sy.Jrc.matvec(dc))
        g_vv = sy.Jrc.rmatvec(r_vv)
        D = ne.damping_diagonal()
        S, _, _, _ = _reduced(layout, ne, lam)
        try:
            a = -_spd_solve(S, g_vv)
        except (np.linalg.LinAlgError, sla.LinAlgError):
            return None
        w = np.sqrt(np.maximum(D, 0.0))
        if np.linalg.norm(w * a) > self.options.geodesic * np.linalg.norm(w * dc):
            return None
        step = dc + 0.5 * a
        # the decrease the linearised model predicts for the accelerated step
        N = ne.Ncc
        pred_step = -float(ne.gc @ step) - 0.5 * float(step @ (N @ step))
        return step, pred_step if pred_step > 0 else pred

    def _damped_step(
        self,
        ne: _Normal,
        cost: float,
        lam: float,
        nu: float,
        dc,
        dp,
        pred: float,
        sy: _System | None = None,
    ) -> _Trial:
        """Take the step, or retry with more damping (Nielsen) until the cost decreases.

        A failed chord step is first retried with the matrix of this point. The parameters
        are at the new point on return, or back at the old one if λ exceeded ``lambda_max``.
        """
        from hsgeo.adjust._fast import matvec_points

        layout = self.layout
        state = layout.get_state()
        geodesic = self.options.geodesic is not None and sy is not None
        while True:
            if geodesic:
                acc = self._geodesic(sy, ne, lam, dc, pred)
                if acc is None:  # the acceleration is too large: a refused step
                    lam *= nu
                    nu *= 2.0
                    if lam > self.options.lambda_max:
                        return _Trial(sy, -np.inf, pred, lam, nu)
                    dc, dp = _step(layout, ne, lam)
                    pred = _predicted_decrease(layout, ne, lam, dc, dp)
                    continue
                dc, pred = acc
            # J h, for the test of points thrown by the step (_hold_thrown), computed before the
            # trial, which starts the blocks' internal iterations from it (start_trial)
            u = None
            if (
                sy is not None
                and dp is not None
                and self.options.hold_points
                and not self.settled_seen
                and ne.S_chord is None
                and not self.loss_on
                and not geodesic
            ):
                u = matvec_points(*sy.Jrc.arrays, np.ascontiguousarray(dc), sy.Jp, sy.pidx, dp)
            layout.apply(dc, dp)
            try:
                trial = self.trial(change=u)
            except _NonFinite:
                # the step left the model's domain (an overflow, a log of a negative): a step
                # that does not decrease the cost, refused like one
                trial = _System(np.array([np.inf]), None, None, None, 0)
            actual = cost - trial.cost
            rho = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
            if (
                not (rho > 0 and np.isfinite(trial.cost))
                and sy is not None
                and self.options.hold_points
            ):
                held = self._hold_points(sy, ne, trial, state, cost, dc, dp, u=u)
                if held is not None:
                    trial, actual, pred, rho = held
            if (
                rho > 0
                and np.isfinite(trial.cost)
                and sy is not None
                and self.options.hold_points
                and not self.settled_seen
                and ne.S_chord is None
            ):
                trial, actual, pred, rho = self._hold_thrown(
                    sy, ne, trial, state, cost, dc, dp, (trial, actual, pred, rho), u
                )
            if rho > 0 and np.isfinite(trial.cost):
                lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                nu = 2.0
                return _Trial(trial, actual, pred, lam, nu)
            layout.set_state(state)
            if ne.S_chord is not None:
                ne.exact()  # the chord step failed: retry with the matrix of this point
            else:
                lam *= nu
                nu *= 2.0
                if lam > self.options.lambda_max:
                    return _Trial(trial, actual, pred, lam, nu)
            dc, dp = _step(layout, ne, lam)
            pred = _predicted_decrease(layout, ne, lam, dc, dp)

    def _hold_thrown(self, sy, ne, trial, state, cost, dc, dp, accepted, u=None):
        """An accepted step that threw a few points: the same step with them held, if that
        costs less (see :meth:`_hold_points`; ``SolverOptions.thrown_share``). Returns
        ``(trial, actual, pred, rho)`` of the step taken, the parameters at it.

        Before the first settled iterate a Gauss–Newton step from poor initial values can
        decrease the cost by orders of magnitude and still throw a few weakly intersected
        points far off (at 7× the paper's pushbroom block: a cost 15 times the next
        iterate's); the following steps are then refused because of them, the damping grows
        by orders of magnitude and decays over many iterations.
        """
        held = self._hold_points(
            sy, ne, trial, state, cost, dc, dp, min_share=self.options.thrown_share, u=u
        )
        if held is not None and held[0].cost < trial.cost:
            return held
        self.layout.set_state(state)
        self.layout.apply(dc, dp)  # back at the accepted step
        return accepted

    def _hold_points(
        self, sy: _System, ne: _Normal, trial: _System, state, cost, dc, dp, min_share=None,
        u=None,
    ):  # fmt: skip
        """Retry a refused step with the few points that refused it held where they are.

        A Gauss–Newton step can throw one weakly intersected point far off (a tie point with a
        gross error among its three rays, before the rejection starts: 100 m at 10× the
        paper's pushbroom block), where its model is far from linear; that point alone then
        raises the cost by orders of magnitude, and the damping that refuses the step slows
        every other unknown down for many iterations. The excess of each row's actual over its
        linearly predicted squared residual is summed per point; if at most 0.1 % of the points
        (and at least one) carry 90 % of the total excess, the step is tried again with their
        increments set to zero, and its predicted decrease taken from the quadratic model
        ``−gᵀh − ½‖J h‖²``. Returns ``(trial, actual, pred, rho)`` of the retried step (the
        parameters at it), or None (the parameters back at ``state``). ``u``: ``J h`` of this
        step if the caller has it (not changed here).
        """
        from hsgeo.adjust._fast import matvec_points, point_excess, subtract_point_rows

        if dp is None or not np.all(np.isfinite(trial.r)) or trial.r.size != sy.r.size:
            return None
        given = u is not None
        if not given:
            u = matvec_points(*sy.Jrc.arrays, np.ascontiguousarray(dc), sy.Jp, sy.pidx, dp)
        per_pt = point_excess(trial.r, sy.r, u, sy.pidx, dp.shape[0])
        pos = np.sort(per_pt[per_pt > 0])[::-1]
        if not pos.size:
            return None
        if min_share is not None:
            # an accepted step: the points whose excess stands out from the points' typical
            # excess by options.thrown_ratio, if they carry min_share of the new cost (the spread
            # excess of every point's curvature can be as large as the thrown points' at a
            # long block's first step: a share of the total would then name them all)
            big = pos[pos > self.options.thrown_ratio * float(np.median(pos))]
            k = big.size
            if not k or big.sum() < min_share * trial.cost:
                return None
        else:
            k = int(np.searchsorted(np.cumsum(pos), 0.9 * pos.sum())) + 1
        if k > max(1, dp.shape[0] // 1000):
            return None  # the model fails broadly: more damping, as usual
        held = _largest(per_pt, k, pos[k - 1])
        if any(self.hold_count.get(int(i), 0) >= self.options.hold_max for i in held):
            # a point whose Gauss–Newton step keeps failing is not held again: its full step
            # would keep the convergence test from passing; the damping takes over
            return None
        dp_h = dp.copy()
        dp_h[held] = 0.0
        mask = np.zeros(dp.shape[0], dtype=bool)
        mask[held] = True
        u = u.copy() if given else u  # (the caller's J h is left as it was)
        subtract_point_rows(u, sy.Jp, sy.pidx, dp - dp_h, mask)  # u: J h with the points held
        pred = -float(ne.gc @ dc) - float(np.sum(ne.gp * dp_h)) - 0.5 * float(u @ u)
        layout = self.layout
        layout.set_state(state)
        layout.apply(dc, dp_h)
        try:
            trial = self.trial()
        except _NonFinite:
            layout.set_state(state)
            return None
        actual = cost - trial.cost
        rho = actual / pred if pred > 0 else -1.0
        if not (rho > 0 and np.isfinite(trial.cost)):
            layout.set_state(state)
            return None
        for i in held:
            self.hold_count[int(i)] = self.hold_count.get(int(i), 0) + 1
        return trial, actual, pred, rho

    def _report(self, cost: float, lam: float) -> None:
        if self.show:
            self.show(
                {
                    "iteration": self.total_iter,
                    "cost": cost,
                    "lambda": lam,
                    "seconds": time.perf_counter() - self.t0,
                    "rejected": int(sum((~m).sum() for m in self.masks)),
                }
            )

    # -- the result -------------------------------------------------------------------------
    def result(self, sy: _System, ne: _Normal, outcome: _Outcome, rounds: int) -> AdjustmentResult:
        """σ0, covariance and residuals at the final iterate, as an :class:`AdjustmentResult`."""
        layout, blocks = self.layout, self.blocks
        n_unk = layout.n_unknowns
        t_cov = time.perf_counter()
        bad, defect = np.zeros(0, dtype=int), 0
        try:
            S_inv = _reduced_inverse(layout, ne)
        except (np.linalg.LinAlgError, sla.LinAlgError) as exc:
            # a datum defect that appeared during the iterations (e.g. every observation of a
            # parameter rejected): the estimable part keeps its covariance, the rest is named
            # rather than the whole solve failing; SolverOptions.strict_covariance raises instead
            S_inv, bad, defect = _reduced_estimable_inverse(layout, ne)
            undetermined = [layout.labels_c[i] for i in bad]
            if self.options.strict_covariance or not bad.size:
                raise DatumError(
                    "the normal matrix at the solution is singular: the covariance cannot be "
                    "computed (a datum defect that appeared during the iteration); not "
                    f"determined: {_name_list(undetermined)}",
                    undetermined or layout.labels_c,
                ) from exc
        self.clock.add("covariance", t_cov)
        dof = int(sy.r.size - n_unk + defect)  # n − rank: the undetermined use no redundancy
        vtpv = float(sy.r @ sy.r)
        sigma0 = float(np.sqrt(vtpv / dof)) if dof > 0 else float("nan")
        s2 = sigma0**2 if np.isfinite(sigma0) else 1.0
        covariance = s2 * S_inv
        if bad.size:
            covariance[bad, :] = np.nan
            covariance[:, bad] = np.nan
        residuals = _all_residuals(layout, blocks, sy)
        cofactors = None
        if self.options.keep_jacobian and layout.pblock is not None:
            cofactors = _point_cofactor_function(ne, S_inv)
        seconds = time.perf_counter() - self.t0
        split = dict(self.clock.seconds)
        split["other"] = max(seconds - sum(split.values()), 0.0)
        return AdjustmentResult(
            params=layout.params,
            converged=outcome.converged,
            message=outcome.message,
            iterations=self.total_iter,
            cost_history=list(self.history),
            sigma0=sigma0,
            dof=dof,
            n_observations=int(sy.n_obs_rows),
            n_unknowns=n_unk,
            covariance=covariance,
            labels=list(layout.labels_c),
            seconds=seconds,
            reject_rounds=rounds,
            columns={name: cm.copy() for name, cm in layout.colmap.items()},
            _blocks=blocks,
            _masks=[m.copy() for m in self.masks],
            _residuals=residuals,
            _point_cofactors=cofactors,
            seconds_split=split,
            dropped_points=sorted(self.dropped_points),
            undetermined_parameters=[layout.labels_c[i] for i in bad],
            _dropped_rows=[d.copy() for d in self.dropped_rows],
        )


def _all_residuals(layout: _Layout, blocks, sy: _System) -> dict:
    """Each block's residuals of every row at the current values, in its units (the rows left
    out included): whitened and back (``r · (1/σ) · σ``, as :func:`_evaluate` gives them),
    from the linearisation ``sy`` if it was evaluated at these values (its evaluation had
    them all: at the paper's pushbroom size one pass of the model, 0.06 CPU-s, not repeated),
    else evaluated again.
    """
    from hsgeo.adjust._fast import kept_whitened

    raw = sy.residuals_at(layout.get_state()) if sy is not None else None
    if raw is None:
        full = _evaluate(layout, blocks, [np.ones(b.m, dtype=bool) for b in blocks], False)
        raw_w = [full.r[off : off + b.m] for off, b in zip(_offsets(blocks), blocks, strict=True)]
    else:
        raw_w = []
        for r, b in zip(raw, blocks, strict=True):
            sigma = np.broadcast_to(np.asarray(b.sigma, dtype=np.float64), (b.m,))
            out = np.empty(b.m)
            kept_whitened(r, np.ascontiguousarray(sigma), np.ones(b.m, dtype=bool), out)
            raw_w.append(out)
    return {b.name: w * b.sigma for w, b in zip(raw_w, blocks, strict=True)}


def _offsets(blocks) -> list[int]:
    """The first row of each block in a system of all their rows."""
    return np.concatenate([[0], np.cumsum([b.m for b in blocks])])[:-1].astype(int).tolist()


def _largest(values: np.ndarray, k: int, kth: float) -> np.ndarray:
    """The indices of the ``k`` largest ``values``, the largest first, ties by index:
    ``np.argsort(-values, kind="stable")[:k]``, given ``kth``, the k-th largest value, by a
    stable sort of those at or above it only (at 10× the paper's pushbroom block the full sort
    of 1.1 M points took 0.27 s over the solve's 3 calls; issue 41).
    """
    cand = np.flatnonzero(values >= kth)
    return cand[np.argsort(-values[cand], kind="stable")][:k]


def _name_list(names: list[str], most: int = 12) -> str:
    """``a, b, c`` (and ``… (N in all)`` beyond ``most``)."""
    if not names:
        return "(none identified)"
    head = ", ".join(names[:most])
    return head if len(names) <= most else f"{head}, … ({len(names)} in all)"


def _settled(actual: float, pred: float, new_cost: float, share: float) -> bool:
    """Whether an iterate is settled (see ``SolverOptions.settled``).

    The mismatch ``|actual − predicted|`` is the part of the decrease the linearised model did
    not explain; a Gauss–Newton step from the new point removes a decrease of that order (its
    gradient comes from the same second-order terms), so a small mismatch shows the new point
    near its minimum one iteration before the decrease itself does.
    """
    return max(min(actual, abs(actual - pred)), 0.0) <= share * new_cost


def progress_text(info: dict) -> str:
    """One iteration's progress line: iteration, cost, λ, seconds and rejections (if any); the
    solver's own ``progress=True`` and the command line's terminal progress both print it.
    """
    return (
        f"  iter {info['iteration']:3d}  cost {info['cost']:.6e}  λ {info['lambda']:.1e}"
        f"  {info['seconds']:.2f} s"
        + (f"  rejected {info['rejected']}" if info.get("rejected") else "")
    )


def _progress_printer(progress):
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress

    def show(info):
        print(progress_text(info), file=sys.stderr, flush=True)

    return show
