"""The 27 NIST StRD nonlinear-regression models as residual blocks.

NIST's Statistical Reference Datasets (https://www.itl.nist.gov/div898/strd/nls/nls_main.shtml)
are the engine's public yardstick (GUIDE §8). Each model here is a function
``f(b, x) → (y, ∂y/∂b)`` with its analytic Jacobian, written out from the model line of its
file; :class:`NistModel` makes it a :class:`~hsgeo.adjust.ResidualBlock`
(``r = f(b, x) − y``, unit a-priori σ, one parameter block ``"b"``), so the engine's
a-posteriori covariance ``σ0² (JᵀJ)⁻¹`` with ``σ0² = RSS / (n − p)`` is the one NIST
certifies.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hsgeo.adjust import ResidualBlock
from hsgeo.errors import InputError
from hsgeo.io.nist_strd import NistProblem

__all__ = ["MODELS", "NistModel", "model_for", "residuals", "Model"]

Model = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]

#: π to the precision of the evaluation (Roszman1's and ENSO's models; NIST gives 31 digits).
_PI = np.longdouble("3.141592653589793238462643383279")


# -- the model functions: (b, x (n, k)) → (y (n,), J (n, p)) ------------------------------------
def _exp_saturation(b, x):
    """Misra1a, BoxBOD: y = b1 (1 − exp(−b2 x))."""
    x = x[:, 0]
    e = np.exp(-b[1] * x)
    return b[0] * (1.0 - e), np.column_stack([1.0 - e, b[0] * x * e])


def _chwirut(b, x):
    """Chwirut1, Chwirut2: y = exp(−b1 x) / (b2 + b3 x)."""
    x = x[:, 0]
    d = b[1] + b[2] * x
    f = np.exp(-b[0] * x) / d
    return f, np.column_stack([-x * f, -f / d, -x * f / d])


def _exp_sum(b, x):
    """Lanczos1–3: y = Σₖ b₂ₖ₋₁ exp(−b₂ₖ x), k = 1..3."""
    x = x[:, 0]
    y = np.zeros_like(x)
    J = np.empty((x.size, b.size), dtype=x.dtype)
    for k in range(0, b.size, 2):
        e = np.exp(-b[k + 1] * x)
        y += b[k] * e
        J[:, k] = e
        J[:, k + 1] = -x * b[k] * e
    return y, J


def _gauss(b, x):
    """Gauss1–3: y = b1 exp(−b2 x) + b3 exp(−(x−b4)²/b5²) + b6 exp(−(x−b7)²/b8²)."""
    x = x[:, 0]
    e = np.exp(-b[1] * x)
    y = b[0] * e
    J = np.empty((x.size, 8), dtype=x.dtype)
    J[:, 0] = e
    J[:, 1] = -x * b[0] * e
    for a, c, w in ((2, 3, 4), (5, 6, 7)):
        u = x - b[c]
        g = np.exp(-(u**2) / b[w] ** 2)
        y = y + b[a] * g
        J[:, a] = g
        J[:, c] = b[a] * g * 2.0 * u / b[w] ** 2
        J[:, w] = b[a] * g * 2.0 * u**2 / b[w] ** 3
    return y, J


def _danwood(b, x):
    """DanWood: y = b1 x^b2."""
    x = x[:, 0]
    p = x ** b[1]
    return b[0] * p, np.column_stack([p, b[0] * p * np.log(x)])


def _misra1b(b, x):
    """Misra1b: y = b1 (1 − (1 + b2 x / 2)⁻²)."""
    x = x[:, 0]
    u = 1.0 + 0.5 * b[1] * x
    return b[0] * (1.0 - u**-2), np.column_stack([1.0 - u**-2, b[0] * x * u**-3])


def _misra1c(b, x):
    """Misra1c: y = b1 (1 − (1 + 2 b2 x)^(−1/2))."""
    x = x[:, 0]
    u = 1.0 + 2.0 * b[1] * x
    s = 1.0 / np.sqrt(u)
    return b[0] * (1.0 - s), np.column_stack([1.0 - s, b[0] * x * s / u])


def _misra1d(b, x):
    """Misra1d: y = b1 b2 x / (1 + b2 x)."""
    x = x[:, 0]
    u = 1.0 + b[1] * x
    return b[0] * b[1] * x / u, np.column_stack([b[1] * x / u, b[0] * x / u**2])


def _rational(n_num: int) -> Model:
    """(b1 + b2 x + … ) / (1 + b_{n+1} x + …): numerator of ``n_num`` terms (Kirby2, Hahn1…)."""

    def f(b, x):
        x = x[:, 0]
        n_den = b.size - n_num
        P = x[:, None] ** np.arange(n_num)
        Q = x[:, None] ** np.arange(1, n_den + 1)
        num = P @ b[:n_num]
        den = 1.0 + Q @ b[n_num:]
        y = num / den
        return y, np.column_stack([P / den[:, None], -Q * (y / den)[:, None]])

    f.__doc__ = f"Rational model: a polynomial of {n_num} terms over 1 + a polynomial in x."
    return f


def _nelson(b, x):
    """Nelson: log y = b1 − b2 x1 exp(−b3 x2) (the residual is in log y)."""
    x1, x2 = x[:, 0], x[:, 1]
    e = np.exp(-b[2] * x2)
    return b[0] - b[1] * x1 * e, np.column_stack([np.ones_like(x1), -x1 * e, b[1] * x1 * x2 * e])


def _mgh17(b, x):
    """MGH17: y = b1 + b2 exp(−x b4) + b3 exp(−x b5)."""
    x = x[:, 0]
    e4, e5 = np.exp(-x * b[3]), np.exp(-x * b[4])
    y = b[0] + b[1] * e4 + b[2] * e5
    return y, np.column_stack([np.ones_like(x), e4, e5, -x * b[1] * e4, -x * b[2] * e5])


def _roszman1(b, x):
    """Roszman1: y = b1 − b2 x − arctan(b3 / (x − b4)) / π."""
    x = x[:, 0]
    d = x - b[3]
    t = b[2] / d
    k = 1.0 / (_PI * (1.0 + t**2))
    y = b[0] - b[1] * x - np.arctan(t) / _PI
    return y, np.column_stack([np.ones_like(x), -x, -k / d, -k * b[2] / d**2])


def _enso(b, x):
    """ENSO: y = b1 + b2 cos(2πx/12) + b3 sin(2πx/12) + b5 cos(2πx/b4) + b6 sin(2πx/b4)
    + b8 cos(2πx/b7) + b9 sin(2πx/b7).
    """
    x = x[:, 0]
    w = 2.0 * _PI * x
    J = np.empty((x.size, 9), dtype=x.dtype)
    J[:, 0] = 1.0
    J[:, 1], J[:, 2] = np.cos(w / 12.0), np.sin(w / 12.0)
    y = b[0] + b[1] * J[:, 1] + b[2] * J[:, 2]
    for p_, c, s in ((3, 4, 5), (6, 7, 8)):
        th = w / b[p_]
        co, si = np.cos(th), np.sin(th)
        y = y + b[c] * co + b[s] * si
        J[:, c], J[:, s] = co, si
        J[:, p_] = (-b[c] * si + b[s] * co) * (-w / b[p_] ** 2)
    return y, J


def _mgh09(b, x):
    """MGH09: y = b1 (x² + x b2) / (x² + x b3 + b4)."""
    x = x[:, 0]
    N = x**2 + x * b[1]
    D = x**2 + x * b[2] + b[3]
    y = b[0] * N / D
    return y, np.column_stack([N / D, b[0] * x / D, -y * x / D, -y / D])


def _rat42(b, x):
    """Rat42: y = b1 / (1 + exp(b2 − b3 x))."""
    x = x[:, 0]
    e = np.exp(b[1] - b[2] * x)
    u = 1.0 / (1.0 + e)
    return b[0] * u, np.column_stack([u, -b[0] * e * u**2, b[0] * x * e * u**2])


def _mgh10(b, x):
    """MGH10: y = b1 exp(b2 / (x + b3))."""
    x = x[:, 0]
    d = x + b[2]
    e = np.exp(b[1] / d)
    return b[0] * e, np.column_stack([e, b[0] * e / d, -b[0] * e * b[1] / d**2])


def _eckerle4(b, x):
    """Eckerle4: y = (b1 / b2) exp(−½ ((x − b3) / b2)²)."""
    x = x[:, 0]
    z = (x - b[2]) / b[1]
    g = np.exp(-0.5 * z**2)
    y = b[0] / b[1] * g
    return y, np.column_stack([g / b[1], y * (z**2 - 1.0) / b[1], y * z / b[1]])


def _rat43(b, x):
    """Rat43: y = b1 / (1 + exp(b2 − b3 x))^(1/b4)."""
    x = x[:, 0]
    e = np.exp(b[1] - b[2] * x)
    u = 1.0 + e
    p = u ** (-1.0 / b[3])
    y = b[0] * p
    de = -y / (b[3] * u) * e  # ∂y/∂b2 (∂e/∂b2 = e)
    return y, np.column_stack([p, de, -de * x, y * np.log(u) / b[3] ** 2])


def _bennett5(b, x):
    """Bennett5: y = b1 (b2 + x)^(−1/b3)."""
    x = x[:, 0]
    v = b[1] + x
    p = v ** (-1.0 / b[2])
    y = b[0] * p
    return y, np.column_stack([p, -y / (b[2] * v), y * np.log(v) / b[2] ** 2])


#: The model function of each problem, by dataset name.
MODELS: dict[str, Model] = {
    "Misra1a": _exp_saturation,
    "BoxBOD": _exp_saturation,
    "Chwirut1": _chwirut,
    "Chwirut2": _chwirut,
    "Lanczos1": _exp_sum,
    "Lanczos2": _exp_sum,
    "Lanczos3": _exp_sum,
    "Gauss1": _gauss,
    "Gauss2": _gauss,
    "Gauss3": _gauss,
    "DanWood": _danwood,
    "Misra1b": _misra1b,
    "Misra1c": _misra1c,
    "Misra1d": _misra1d,
    "Kirby2": _rational(3),
    "Hahn1": _rational(4),
    "Thurber": _rational(4),
    "Nelson": _nelson,
    "MGH17": _mgh17,
    "Roszman1": _roszman1,
    "ENSO": _enso,
    "MGH09": _mgh09,
    "Rat42": _rat42,
    "MGH10": _mgh10,
    "Eckerle4": _eckerle4,
    "Rat43": _rat43,
    "Bennett5": _bennett5,
}


def model_for(problem: NistProblem) -> Model:
    """The model function of ``problem`` (by its dataset name)."""
    try:
        return MODELS[problem.name]
    except KeyError:
        raise InputError(
            f"no model for the NIST StRD problem {problem.name!r}; known: {', '.join(MODELS)}"
        ) from None


def _response(problem: NistProblem) -> np.ndarray:
    """The fitted response: y, or log y for Nelson (its model is written for log y)."""
    return np.log(problem.y) if problem.name == "Nelson" else problem.y


def residuals(problem: NistProblem, b, jacobian: bool = True):
    """Residuals ``f(b, x) − y`` and the Jacobian ``∂f/∂b``, both as float64.

    The model is evaluated in extended precision (``numpy.longdouble``: 64-bit significand on
    x86-64 Linux) and the difference rounded once: Lanczos1's residuals are 1e-13 of its
    responses, so a float64 evaluation would leave them, and the residual σ certified from
    them, with 2–3 correct digits. hsgeo and scipy fit the same residuals.
    """
    f = model_for(problem)
    bl = np.asarray(b, dtype=np.float64).astype(np.longdouble)
    # a trial step may overflow (exp of a large argument): the engine refuses a step whose
    # cost is not finite, so the floating-point warnings carry no information here
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        y, J = f(bl, problem.x.astype(np.longdouble))
        r = (y - _response(problem).astype(np.longdouble)).astype(np.float64)
        J = np.asarray(J, dtype=np.float64) if jacobian else None
    return r, J


class NistModel(ResidualBlock):
    """A NIST StRD problem as a residual block: ``r = f(b, x) − y`` with unit a-priori σ.

    Parameters
    ----------
    problem : NistProblem
        The problem (:func:`~hsgeo.io.nist_strd.read_nist_strd`).
    blocks : mapping, optional
        Renames the parameter block (role ``"b"``, default name ``"b"``).
    """

    name = "NIST StRD"
    BLOCKS = {"b": "b"}

    def __init__(self, problem: NistProblem, blocks=None):
        super().__init__(np.ones(problem.y.size), name=problem.name, blocks=blocks)
        self.problem = problem
        model_for(problem)  # an unknown problem fails here, not in the solver

    def evaluate(self, values, jacobian):
        r, J = residuals(self.problem, values[self.blocks["b"]], jacobian)
        return r, ({self.blocks["b"]: J} if jacobian else None)
