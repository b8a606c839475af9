"""Fits of the NIST StRD problems by hsgeo and by scipy, scored against the certified values.

:func:`fit_hsgeo` and :func:`fit_scipy` fit one problem from one start; :func:`score` gives
the log relative errors (:func:`hsgeo.stats.lre`) against the certified values;
:func:`certify` runs all 27 × 2 (the table of the book page "The engine, certified" and of
``bench/bench_nist_strd.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgeo.adjust import Parameters, SolverOptions, adjust
from hsgeo.errors import ConvergenceError, DatumError, InputError
from hsgeo.io.nist_strd import NistProblem, read_nist_strd
from hsgeo.nist.models import NistModel, residuals
from hsgeo.stats import lre

__all__ = [
    "NIST_OPTIONS",
    "NistFit",
    "certify",
    "covariance_sigma",
    "fit_hsgeo",
    "fit_scipy",
    "option_steps",
    "score",
]


@dataclass(frozen=True)
class NistFit:
    """One fit of one problem from one start, scored against the certified values.

    Attributes
    ----------
    problem, start : str, int
        Dataset name and start (1 or 2).
    solver : str
        ``"hsgeo"``, ``"scipy-lm"`` or ``"scipy-trf"``.
    converged : bool
        The solver's own verdict.
    params, sigma : (p,) ndarray
        Estimates and their standard deviations ``sqrt(diag(s² (JᵀJ)⁻¹))``, ``s² = RSS/(n−p)``
        (NaN where they could not be computed).
    rss : float
        Residual sum of squares at the estimate.
    lre_params, lre_sigma : (p,) ndarray
        LRE of each parameter and σ against the certified values (:func:`hsgeo.stats.lre`).
    lre_rss : float
        LRE of the residual sum of squares.
    iterations : int
    message : str
    """

    problem: str
    start: int
    solver: str
    converged: bool
    params: np.ndarray
    sigma: np.ndarray
    rss: float
    lre_params: np.ndarray
    lre_sigma: np.ndarray
    lre_rss: float
    iterations: int
    message: str

    @property
    def lre_params_min(self) -> float:
        return float(np.min(self.lre_params))

    @property
    def lre_sigma_min(self) -> float:
        return float(np.min(self.lre_sigma))

    def passed(self, params_min: float = 6.0, sigma_min: float = 3.0) -> bool:
        """LRE ≥ ``params_min`` for every parameter and ≥ ``sigma_min`` for every σ."""
        return self.lre_params_min >= params_min and self.lre_sigma_min >= sigma_min


def score(
    problem: NistProblem,
    params,
    sigma,
    rss: float,
    *,
    start: int,
    solver: str,
    converged: bool,
    iterations: int = 0,
    message: str = "",
) -> NistFit:
    """Score estimates against the certified values of ``problem`` (LRE per entry)."""
    params = np.asarray(params, dtype=np.float64)
    sigma = np.asarray(sigma, dtype=np.float64)
    return NistFit(
        problem=problem.name,
        start=int(start),
        solver=solver,
        converged=bool(converged),
        params=params,
        sigma=sigma,
        rss=float(rss),
        lre_params=lre(params, problem.certified),
        lre_sigma=lre(sigma, problem.certified_sigma),
        lre_rss=float(lre(rss, problem.rss)),
        iterations=int(iterations),
        message=message,
    )


def _start(problem: NistProblem, start: int) -> np.ndarray:
    if start not in (1, 2):
        raise InputError(f"NIST StRD problems have starts 1 and 2, got start={start!r}")
    return problem.starts[start - 1].copy()


#: The engine's settings for the 54 fits (the same for all; :func:`option_steps` measures
#: what each contributes):
#:
#: * ``xtol`` 1e-12: stop when the Gauss–Newton step is below 1e-12 of each parameter (the
#:   default cost test, ``ftol`` 1e-10 of the cost, stops at 5–6 correct digits);
#: * ``atol`` 0: Lanczos1's residuals of 1e-13 are its data, not noise-free zeros;
#: * ``check_datum`` off: the rank test at the start refuses MGH17's Start 1, where two columns
#:   of the Jacobian coincide to 1e-11, although the certified solution is regular (a singular
#:   normal matrix at the solution still raises);
#: * ``damping_diagonal`` "max": Moré's scaling of the damping;
#: * ``geodesic`` 0.75: geodesic acceleration (Transtrum & Sethna 2012).
NIST_OPTIONS = SolverOptions(
    max_iter=2000,
    xtol=1e-12,
    atol=0.0,
    damping_diagonal="max",
    geodesic=0.75,
    check_datum=False,
    raise_on_failure=False,
)


def option_steps() -> dict[str, SolverOptions]:
    """The engine's settings from its defaults to :data:`NIST_OPTIONS`, one change at a time.

    Every step keeps ``max_iter`` 2000, ``check_datum`` off and ``raise_on_failure`` off, so
    that every fit returns a result to score.
    """
    base = SolverOptions(max_iter=2000, check_datum=False, raise_on_failure=False)
    tight = base.replace(xtol=1e-12, atol=0.0)
    more = tight.replace(damping_diagonal="max")
    return {
        "defaults": base,
        "+ xtol 1e-12, atol 0": tight,
        "+ Moré damping": more,
        "+ geodesic acceleration": more.replace(geodesic=0.75),
    }


def fit_hsgeo(
    problem: NistProblem | str, start: int, options: SolverOptions | None = None
) -> NistFit:
    """Fit ``problem`` from ``start`` with :func:`hsgeo.adjust.adjust` and score it.

    Parameters
    ----------
    problem : NistProblem or str
        The problem, or the name of a shipped one (``"Misra1a"``).
    start : {1, 2}
        NIST's Start 1 or Start 2.
    options : SolverOptions, optional
        Default: :data:`NIST_OPTIONS`.

    Returns
    -------
    NistFit
    """
    if not isinstance(problem, NistProblem):
        problem = read_nist_strd(problem)
    if options is None:
        options = NIST_OPTIONS
    p = Parameters()
    p.add("b", _start(problem, start), columns=tuple(f"b{i + 1}" for i in range(problem.n_params)))
    block = NistModel(problem)
    try:
        res = adjust(p, [block], options)
    except (DatumError, ConvergenceError) as exc:
        res = getattr(exc, "result", None)
        if res is None:
            nan = np.full(problem.n_params, np.nan)
            return score(
                problem, nan, nan, np.nan, start=start, solver="hsgeo", converged=False,
                message=str(exc),
            )  # fmt: skip
    b = res.value("b")
    r, _ = residuals(problem, b, jacobian=False)
    return score(
        problem,
        b,
        res.sigma("b"),
        float(r @ r),
        start=start,
        solver="hsgeo",
        converged=res.converged,
        iterations=res.iterations,
        message=res.message,
    )


def fit_scipy(
    problem: NistProblem | str, start: int, method: str = "lm", jac: str = "analytic"
) -> NistFit:
    """Fit ``problem`` from ``start`` with :func:`scipy.optimize.least_squares` and score it.

    Parameters
    ----------
    problem : NistProblem or str
    start : {1, 2}
    method : {"lm", "trf"}
        scipy's MINPACK Levenberg–Marquardt or its trust-region reflective method.
    jac : {"analytic", "2-point"}
        The models' analytic Jacobian, or scipy's forward differences.

    Notes
    -----
    scipy's tolerances are tightened to ``ftol = xtol = gtol = 1e-15`` (its defaults, 1e-8,
    stop far from 11 certified digits) with up to 10⁵ function evaluations; σ is
    ``sqrt(diag(s² (JᵀJ)⁻¹))`` from the analytic Jacobian at scipy's estimate, so that the
    comparison is of the estimates, not of the covariance formulas.
    """
    from scipy.optimize import least_squares

    if not isinstance(problem, NistProblem):
        problem = read_nist_strd(problem)
    if method not in ("lm", "trf") or jac not in ("analytic", "2-point"):
        raise InputError(
            f"fit_scipy: method must be 'lm' or 'trf' and jac 'analytic' or '2-point', got "
            f"{method!r}, {jac!r}"
        )

    def fun(b):
        return residuals(problem, b, jacobian=False)[0]

    def jacobian(b):
        return residuals(problem, b)[1]

    tol = 1e-15
    # From some of the hard starts scipy's trust region steps into overflow; the fit then fails
    # and is scored as failed (its message says why). numpy's RuntimeWarning on the way would
    # only print a path and a line of scipy's source into the book's engine page.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        sol = least_squares(
            fun,
            _start(problem, start),
            jac=jacobian if jac == "analytic" else "2-point",
            method=method,
            ftol=tol,
            xtol=tol,
            gtol=tol,
            max_nfev=100_000,
        )
    b = sol.x
    r = fun(b)
    rss = float(r @ r)
    sigma = covariance_sigma(jacobian(b), rss)
    return score(
        problem,
        b,
        sigma,
        rss,
        start=start,
        solver=f"scipy-{method}",
        converged=bool(sol.success),
        iterations=int(sol.nfev),
        message=str(sol.message),
    )


def covariance_sigma(J: np.ndarray, rss: float) -> np.ndarray:
    """``sqrt(diag(s² (JᵀJ)⁻¹))`` with ``s² = rss / (n − p)``, via the SVD of ``J``.

    NaN if ``J`` is not finite or rank deficient.
    """
    n, p = J.shape
    if not np.all(np.isfinite(J)) or n <= p:
        return np.full(p, np.nan)
    # column-scaled SVD: (JᵀJ)⁻¹ = D⁻¹ V Σ⁻² Vᵀ D⁻¹ for J D⁻¹ = U Σ Vᵀ
    d = np.linalg.norm(J, axis=0)
    if np.any(d == 0):
        return np.full(p, np.nan)
    _, s, Vt = np.linalg.svd(J / d, full_matrices=False)
    if s[-1] <= s[0] * 1e-15:
        return np.full(p, np.nan)
    C = (Vt.T / s**2) @ Vt / np.outer(d, d)
    return np.sqrt(rss / (n - p) * np.diag(C))


def certify(
    names=None, options: SolverOptions | None = None, scipy_jac: str | None = "analytic"
) -> list[dict]:
    """Fit every problem from both starts with hsgeo and scipy (``lm``, ``trf``): the table.

    Parameters
    ----------
    names : iterable of str, optional
        Problems (default: all 27, in NIST's order of difficulty).
    options : SolverOptions, optional
        The engine's settings (default :data:`NIST_OPTIONS`).
    scipy_jac : {"analytic", "2-point"} or None
        scipy's Jacobian; None: no scipy fits.

    Returns
    -------
    list of dict
        One row per problem and start: ``problem``, ``difficulty``, ``start``, ``converged``,
        ``lre_params_min``, ``lre_sigma_min``, ``lre_rss``, ``iterations``, ``passed`` and,
        with scipy, ``scipy_{lm,trf}_lre_params_min``, ``…_lre_sigma_min``, ``…_passed``.
    """
    from hsgeo.io.nist_strd import NIST_STRD_NAMES

    if names is None:
        names = [n for group in NIST_STRD_NAMES.values() for n in group]
    rows = []
    for name in names:
        problem = read_nist_strd(name)
        for start in (1, 2):
            f = fit_hsgeo(problem, start, options)
            row = {
                "problem": problem.name,
                "difficulty": problem.difficulty,
                "start": start,
                "converged": f.converged,
                "lre_params_min": round(f.lre_params_min, 2),
                "lre_sigma_min": round(f.lre_sigma_min, 2),
                "lre_rss": round(f.lre_rss, 2),
                "iterations": f.iterations,
                "passed": f.passed(),
            }
            if scipy_jac is not None:
                for method in ("lm", "trf"):
                    g = fit_scipy(problem, start, method, scipy_jac)
                    row[f"scipy_{method}_lre_params_min"] = round(g.lre_params_min, 2)
                    row[f"scipy_{method}_lre_sigma_min"] = round(g.lre_sigma_min, 2)
                    row[f"scipy_{method}_passed"] = g.passed()
            rows.append(row)
    return rows
