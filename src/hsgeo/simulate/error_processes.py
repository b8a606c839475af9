"""Error processes of the simulated campaigns: a GNSS/INS solution's error (first-order
Gauss–Markov), its best spline fit, and atmospheric refraction.

Used by :mod:`hsgeo.simulate.pushbroom_campaign` and its scenario types
(:mod:`hsgeo.simulate.pushbroom_campaign_types`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from hsgeo.errors import InputError
from hsgeo.trajectory import SplineNodes

__all__ = ["gauss_markov", "spline_fit", "refraction_k", "RIDGE"]

#: Weight of the ridge of :func:`spline_fit`, in samples per node.
RIDGE = 0.1


def _imaged(plan, t_s):
    """The times of ``t_s`` that lie within a strip of ``plan``."""
    t = np.asarray(t_s, dtype=np.float64)
    inside = np.zeros(t.shape, bool)
    for p in plan:
        inside |= (t >= p[0]) & (t <= p[1])
    return t[inside]


def gauss_markov(n: int, dt_s: float, tau_s, sigma, rng) -> np.ndarray:
    r"""Stationary first-order Gauss–Markov processes sampled every ``dt_s``.

    The exact discrete recursion of the continuous process
    :math:`\dot x = -x/\tau + w`: :math:`x_{k+1} = e^{-\Delta t/\tau} x_k +
    \sigma\sqrt{1 - e^{-2\Delta t/\tau}}\, w_k`, :math:`w_k \sim N(0, 1)`, started from the
    stationary distribution :math:`x_0 \sim N(0, \sigma^2)`; its autocorrelation is
    :math:`\sigma^2 e^{-|\Delta t|/\tau}` at every lag.

    Parameters
    ----------
    n : int
        Number of samples.
    dt_s : float
        Sample interval, s.
    tau_s, sigma : (k,) array_like
        Correlation time (s) and stationary σ (any unit) of each of the ``k`` processes.
    rng : int or numpy.random.Generator

    Returns
    -------
    (n, k) ndarray
    """
    rng = np.random.default_rng(rng)
    tau = np.atleast_1d(np.asarray(tau_s, dtype=np.float64))
    sig = np.atleast_1d(np.asarray(sigma, dtype=np.float64)) * np.ones_like(tau)
    if np.any(tau <= 0) or not dt_s > 0:
        raise InputError("correlation times and the sample interval must be positive")
    phi = np.exp(-dt_s / tau)
    q = sig * np.sqrt(1.0 - phi**2)
    w = rng.standard_normal((n, tau.size))
    x = np.empty((n, tau.size))
    if n:
        x[0] = sig * w[0]
        _recursion(phi, q, w, x)
    return x


@njit(cache=True)
def _recursion(phi, q, w, x):  # pragma: no cover - compiled
    """``x[k] = phi x[k−1] + q w[k]`` for k ≥ 1, each product and the sum rounded as numpy's
    row expressions rounded them (no fastmath, so no fused multiply-add): the same bits. A
    Python loop over the rows took 59 ms a process of 18,000 steps, 4.5 of the 50 CPU-s of
    ``hsgeo reproduce pushbroom-ba --scale 0.01`` (76 processes; issue 41).
    """
    for k in range(1, x.shape[0]):
        for j in range(x.shape[1]):
            x[k, j] = phi[j] * x[k - 1, j] + q[j] * w[k, j]


def spline_fit(nodes: SplineNodes, t_s, values) -> np.ndarray:
    r"""Least-squares node values of the cubic B-spline ``nodes`` that best fit ``values``.

    Parameters
    ----------
    nodes : SplineNodes
    t_s : (m,) array_like
        Sample times, s, within the span of ``nodes``.
    values : (m, k) array_like
        The samples.

    Returns
    -------
    (n_nodes, k) ndarray
        Minimises :math:`\sum_i \|\,\delta(t_i) - v_i\|^2` with :math:`\delta` the spline of
        :meth:`SplineNodes.evaluate`, plus a ridge :math:`0.1 \sum_j \|c_j\|^2` (a tenth of a sample
        per node) that holds nodes the samples barely touch near zero.
    """
    t = np.asarray(t_s, dtype=np.float64).ravel()
    v = np.asarray(values, dtype=np.float64).reshape(t.size, -1)
    idx, w = nodes.basis(t)
    rows = np.repeat(np.arange(t.size), 4)
    A = sp.csr_matrix((w.ravel(), (rows, idx.ravel())), shape=(t.size, nodes.n_nodes))
    # a ridge of a tenth of a sample per node: the end nodes, which only the tails of their
    # basis functions touch, would otherwise wander (untouched nodes stay zero)
    N = (A.T @ A + RIDGE * sp.identity(nodes.n_nodes)).tocsc()
    return np.asarray(spla.spsolve(N, A.T @ v)).reshape(nodes.n_nodes, -1)


def refraction_k(flying_asl_m, ground_asl_m) -> np.ndarray:
    """Photogrammetric refraction constant K (rad) of the ARDC standard atmosphere.

    ``K = 2410 H / (H² − 6 H + 250) − 2410 h² / ((h² − 6 h + 250) H)`` µrad with H, h the
    flying and ground heights above sea level in km; the image point moves radially outward by
    ``Δr = K (r + r³ / c²)``. As commonly quoted from Wolf, Dewitt & Wilkinson, *Elements of
    Photogrammetry* (§ on atmospheric refraction; the book itself was not at hand to check).
    At 1875 and 2500 m AGL over ground 90 m a.s.l., K ≈ 20 and 26 µrad.
    """
    H = np.asarray(flying_asl_m, dtype=np.float64) / 1e3
    h = np.asarray(ground_asl_m, dtype=np.float64) / 1e3
    k_urad = 2410 * H / (H**2 - 6 * H + 250) - 2410 * h**2 / ((h**2 - 6 * h + 250) * H)
    return k_urad * 1e-6
