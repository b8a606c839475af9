"""The result of an adjustment: estimates, σ0, covariance, residuals, a readable report."""

from __future__ import annotations

import html
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from hsgeo.adjust.parameters import Parameters
from hsgeo.adjust.threads import engine_threads
from hsgeo.errors import InputError

__all__ = ["AdjustmentResult"]


@dataclass
class AdjustmentResult:
    """Estimates and their quality (after lmfit's ``MinimizerResult``).

    Attributes
    ----------
    params : Parameters
        The estimated parameters (a copy; the input is untouched).
    converged : bool
    message : str
    iterations : int
        Accepted steps, over all rejection rounds.
    cost_history : list of float
        ½ Σ r_w² after each accepted step.
    sigma0 : float
        A-posteriori standard deviation of unit weight, sqrt(vᵀPv / dof).
    dof : int
        Redundancy: residual components (priors included, rejected excluded) − unknowns (+ the
        rank defect at the solution, if any: see ``undetermined_parameters``).
    n_observations : int
        Observation components used (rejected excluded, priors excluded).
    n_unknowns : int
    covariance : (n, n) ndarray
        σ0²·S⁻¹ of the free non-point parameters, in the order of ``labels``.
    labels : list of str
        Names of the free non-point parameters.
    seconds : float
        Wall time of the adjustment.
    reject_rounds : int
        Outlier-rejection rounds (or passes, in each-iteration mode).
    columns : dict of str to ndarray
        For each non-point block, the index in ``labels``/``covariance`` of each entry
        (flattened; -1 where fixed).
    dropped_points : list of int
        Points left out because their observations do not determine them (held at their
        initial values, their observations unused; ``SolverOptions.drop_undetermined_points``).
    undetermined_parameters : list of str
        Labels of the free non-point parameters that the normal matrix at the solution does not
        determine (a datum defect that appeared during the iterations); their rows and columns
        of ``covariance`` are NaN, the rest is the covariance of the estimable part
        (``SolverOptions.strict_covariance`` raises instead).
    seconds_split : dict of str to float
        Where ``seconds`` went: ``model`` (the residual blocks' own evaluation, residuals and
        derivatives; on the fused path, ``SolverOptions.fused``, also their whitening into the
        engine's arrays and the gradient and diagonal of those rows), ``jacobian`` (whitening
        the other blocks' derivatives into the engine's row-compressed arrays, the columns),
        ``formation`` (gradient, diagonal, point blocks and the reduced matrix), ``solve``
        (its factorisation and the back-substitution), ``rejection`` (outlier tests),
        ``datum`` (the rank check) and ``covariance`` (``S⁻¹`` at the solution); the rest is
        ``other``.
    """

    params: Parameters
    converged: bool
    message: str
    iterations: int
    cost_history: list
    sigma0: float
    dof: int
    n_observations: int
    n_unknowns: int
    covariance: np.ndarray
    labels: list
    seconds: float
    reject_rounds: int
    columns: dict = field(repr=False)
    _blocks: list = field(repr=False)
    _masks: list = field(repr=False)
    _residuals: dict = field(repr=False)
    #: ``f(points, chunk)`` → the points' cofactor blocks (None: the Jacobian was not kept)
    _point_cofactors: Callable | None = field(default=None, repr=False)
    _point_cov: np.ndarray | None = field(default=None, repr=False)
    seconds_split: dict = field(default_factory=dict, repr=False)
    dropped_points: list = field(default_factory=list)
    undetermined_parameters: list = field(default_factory=list)
    #: per block, the rows left out with the dropped points (not outliers)
    _dropped_rows: list | None = field(default=None, repr=False)

    # -- estimates and their σ ----------------------------------------------------------------
    def value(self, name: str) -> np.ndarray:
        """Estimated value of a block."""
        return self.params.value(name)

    def sigma(self, name: str) -> np.ndarray:
        """A-posteriori σ of a block's entries (same shape; NaN where fixed)."""
        b = self.params[name]
        if b.points:
            cov = self.point_covariance()
            out = np.sqrt(np.diagonal(cov, axis1=1, axis2=2)).copy()
            out[~b.free] = np.nan
            return out
        cm = self.columns[name]
        out = np.full(b.size, np.nan)
        sel = cm >= 0
        out[sel] = np.sqrt(np.diag(self.covariance)[cm[sel]])
        return out.reshape(b.shape)

    def covariance_of(self, *names: str) -> tuple[np.ndarray, list[str]]:
        """Covariance sub-matrix of the free entries of the named (non-point) blocks."""
        idx, labs = [], []
        for n in names:
            cm = self.columns[n]
            lab = self.params[n].labels()
            for i in np.flatnonzero(cm >= 0):
                idx.append(cm[i])
                labs.append(lab[i])
        idx = np.asarray(idx, dtype=int)
        return self.covariance[np.ix_(idx, idx)], labs

    def correlation(self) -> np.ndarray:
        """Correlation matrix of the free non-point parameters."""
        d = np.sqrt(np.diag(self.covariance))
        return self.covariance / np.outer(d, d)

    def point_covariance(
        self, chunk: int = 20000, index=None, *, joint: bool = False
    ) -> np.ndarray:
        """σ0²·(V⁻¹ + V⁻¹ Wᵀ S⁻¹ W V⁻¹) for every point: ``(n_points, p, p)``.

        Computed on first request, in chunks of points to bound the memory. With ``index``
        (point rows), only those points are computed: ``(len(index), p, p)``, not cached.
        Needs the Jacobian of the solution: adjust with ``keep_jacobian=True``.

        With ``joint=True`` (``index`` required), the joint covariance of those points:
        ``(len(index)·p, len(index)·p)``, ordered point by point (the point's coordinates
        within), σ0²·(blockdiag V_i⁻¹ + A S⁻¹ Aᵀ) with ``A_i = V_i⁻¹ W_iᵀ`` — the points'
        block of σ0² times the inverse of the full normal matrix. Its diagonal blocks are the
        ``joint=False`` blocks; the off-diagonal ones are what points share through the
        non-point unknowns (e.g. one datum error: a statistic over several points, a mean or a
        spread, needs them). NaN in the rows and columns of fixed coordinates and of points
        whose own block is singular.

        Raises
        ------
        InputError
            If the result was computed without ``keep_jacobian=True``, or ``joint=True``
            without ``index``.
        """
        if joint:
            return self._joint_point_covariance(index)
        if self._point_cov is not None and index is None:
            return self._point_cov
        pb = self.params.points_block
        if pb is None:
            raise ValueError("this problem has no points block")
        if self._point_cofactors is None:
            raise InputError(
                "the covariance of the points needs the Jacobian of the solution, which this "
                "result did not keep: adjust again with keep_jacobian=True"
            )
        p = pb.shape[1]
        pts = np.arange(pb.shape[0]) if index is None else np.atleast_1d(np.asarray(index))
        s2 = self.sigma0**2 if np.isfinite(self.sigma0) else 1.0
        # kernels parallel only for many observations (hsgeo.adjust.threads)
        with engine_threads("auto", int(self.n_observations)):
            out = self._point_cofactors(pts, chunk)
        out *= s2
        fixed = ~pb.free[pts]
        for j in range(p):
            out[fixed[:, j], j, :] = np.nan
            out[fixed[:, j], :, j] = np.nan
        if index is None:
            self._point_cov = out
        return out

    def _joint_point_covariance(self, index) -> np.ndarray:
        pb = self.params.points_block
        if pb is None:
            raise ValueError("this problem has no points block")
        if index is None:
            raise InputError(
                "point_covariance(joint=True) needs index=: the rows of the points whose joint "
                "covariance is wanted (the full matrix of every point is rarely affordable)"
            )
        if self._point_cofactors is None:
            raise InputError(
                "the covariance of the points needs the Jacobian of the solution, which this "
                "result did not keep: adjust again with keep_jacobian=True"
            )
        pts = np.atleast_1d(np.asarray(index, dtype=np.int64))
        s2 = self.sigma0**2 if np.isfinite(self.sigma0) else 1.0
        out = self._point_cofactors.joint(pts) * s2
        fixed = (~pb.free[pts]).ravel()
        out[fixed, :] = np.nan
        out[:, fixed] = np.nan
        return out

    # -- residuals ----------------------------------------------------------------------------
    def residuals(self, block: str | int = 0) -> np.ndarray:
        """Residuals model − observation of a residual block, in its units, at the solution
        (all rows, the rejected ones too).
        """
        return self._residuals[self._block_name(block)]

    def normalized_residuals(self, block: str | int = 0) -> np.ndarray:
        """Residuals divided by their a-priori σ and by σ0."""
        b = self._blocks[self._block_index(block)]
        return self.residuals(block) / b.sigma / self.sigma0

    def outliers(self, block: str | int = 0) -> np.ndarray:
        """Bool mask of the rejected observations (one entry per group; the observations of
        :attr:`dropped_points` are not outliers).
        """
        i = self._block_index(block)
        g = self._blocks[i].group_size
        kept = (
            self._masks[i] if self._dropped_rows is None else self._masks[i] | self._dropped_rows[i]
        )
        return ~kept.reshape(-1, g)[:, 0]

    def _block_index(self, block) -> int:
        if isinstance(block, int):
            return block
        for i, b in enumerate(self._blocks):
            if b.name == block:
                return i
        raise KeyError(f"no residual block {block!r}; known: {[b.name for b in self._blocks]}")

    def _block_name(self, block) -> str:
        return self._blocks[self._block_index(block)].name

    # -- quality --------------------------------------------------------------------------------
    def chi2_interval(self, alpha: float = 0.01) -> tuple[float, float]:
        """Two-sided (1−α) interval of σ0 under the model (χ² with ``dof`` degrees of freedom)."""
        from scipy import stats as sst  # 0.7 s to import: not for a command that stops early

        lo, hi = sst.chi2.ppf([alpha / 2, 1 - alpha / 2], self.dof)
        return float(np.sqrt(lo / self.dof)), float(np.sqrt(hi / self.dof))

    # -- reporting ----------------------------------------------------------------------------
    def to_frame(self, max_block_size: int | None = None):
        """A pandas DataFrame of the non-point parameters: value, σ, free, prior σ."""
        import pandas as pd

        rows = []
        for b in self.params.blocks():
            if b.points or (max_block_size is not None and b.size > max_block_size):
                continue
            sig = self.sigma(b.name).ravel()
            for lab, v, s, f, ps in zip(
                b.labels(), b.value.ravel(), sig, b.free.ravel(), b.prior_sigma.ravel(), strict=True
            ):
                rows.append(
                    {
                        "parameter": lab,
                        "value": v,
                        "sigma": s,
                        "free": bool(f),
                        "prior_sigma": ps if np.isfinite(ps) else np.nan,
                    }
                )
        return pd.DataFrame(rows).set_index("parameter")

    def _summary_lines(self) -> list[str]:
        n_rej = sum(int((~m).sum()) for m in self._masks)
        lo, hi = self.chi2_interval() if self.dof > 0 else (np.nan, np.nan)
        und = self.undetermined_parameters
        extra = (
            [
                f"not determined at the solution (σ NaN, covariance of the rest only): "
                f"{', '.join(und[:12])}{f', … ({len(und)} in all)' if len(und) > 12 else ''}"
            ]
            if und
            else []
        )
        return [
            f"converged: {self.converged} ({self.message}) after {self.iterations} iterations, "
            f"{self.seconds:.2f} s",
            f"observations: {self.n_observations} components ({n_rej} rejected in "
            f"{self.reject_rounds} rounds); unknowns: {self.n_unknowns}; redundancy: {self.dof}",
            f"sigma0 (a posteriori, unit weight): {self.sigma0:.4f}   "
            f"[99% chi2 interval under the model: {lo:.3f} … {hi:.3f}]",
        ] + extra

    def report(self, max_block_size: int = 60) -> str:
        """A plain-text report: summary, then value ± σ of every non-point parameter."""
        lines = ["Adjustment report", "================="] + self._summary_lines() + [""]
        lines.append(f"{'parameter':<36s} {'value':>16s} {'sigma':>12s}")
        skipped = []
        for b in self.params.blocks():
            if b.points or b.size > max_block_size:
                skipped.append(f"{b.name} {b.shape}")
                continue
            sig = self.sigma(b.name).ravel()
            for lab, v, s, f in zip(b.labels(), b.value.ravel(), sig, b.free.ravel(), strict=True):
                s_txt = f"{s:12.4g}" if f else "       fixed"
                lines.append(f"{lab:<36s} {v:16.8g} {s_txt}")
        if skipped:
            lines.append("(not listed: " + ", ".join(skipped) + ")")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.report()

    def _repr_html_(self) -> str:
        head = "<br>".join(html.escape(s) for s in self._summary_lines())
        return (
            f"<div><b>Adjustment result</b><br>{head}"
            f"{self.to_frame(max_block_size=60).to_html(float_format=lambda x: f'{x:.6g}')}"
            "</div>"
        )
