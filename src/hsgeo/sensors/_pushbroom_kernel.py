"""The compiled residual kernel of :class:`hsgeo.sensors.pushbroom.PushbroomLines` (002 eq. 2–4).

``_lines_kernel`` makes one pass per observation: the spline correction and the pose at the
trial time (``_spline``, ``_pose``), the projection and its partials (``_image``), the Newton on
the crossing time, the derivatives (``_derivatives``) and their chain through the crossing time
(``_through_time``); the helpers are inlined into the chunk function ``_lines_chunk``
(``inline="always"``), so the compiled loop is that of one function, and the chunks run on the
kernels' threads (:func:`hsgeo._chunks.over_chunks`: with numba's ``prange`` over them
the kernel's two compilations on a fresh cache took 28 s, without it 17 s; issue 41). The
values the Newton loop sets and only later lines read (x, y, xb, yb, gx, gy) are defined
before it: left undefined there, numba lost them under ``prange`` once the loop moved into
helpers (every x residual wrong at 64 chunks).

Moved out of :mod:`hsgeo.sensors.pushbroom` unchanged: one observation per iteration, the
crossing time by Newton (the residual across the line as a time) and the derivatives; see that
module's docstring for the model and the time residual. Since then (issue 41) the Newton's
tolerance is an argument (``NEWTON_TOL_S``, or ``TRIAL_TOL_S`` for a trial step's residuals),
and a time held at ``±T_MAX`` ends its Newton: evaluating the same time again gave the same
values (at the paper's size 31 % of the first linearisation's observations end there, and
that linearisation took 0.34 CPU-s instead of 0.23).
"""

from __future__ import annotations

import inspect

import numpy as np
from numba import njit

from hsgeo._chunks import over_items
from hsgeo._kernels import (
    bspline_weights,
    pushbroom_camera_point,
    pushbroom_image_mm,
    pushbroom_line_distortion_dcoeff,
    rpy_rotation,
)

__all__ = ["T_MAX", "NEWTON_TOL_S", "TRIAL_TOL_S", "TRIAL_PREDICTION_MAX_S"]

#: The crossing time is sought within ± this of the line time (s): 0.25 s is ~55 px of image
#: motion, beyond any gross error left after RANSAC; a trial step that throws a weakly
#: intersected point far off is held there (without the bound the time of such a point runs
#: off with the spline extrapolated, and the first iterations are damped to a crawl).
T_MAX = 0.25
#: Newton on the crossing time stops when its correction is below this (s); see the module
#: docstring for the error this leaves in the residuals (< 1e-13 px).
NEWTON_TOL_S = 1e-8
#: The same for the residuals alone at the solver's trial point of a step
#: (:meth:`~hsgeo.adjust.ResidualBlock.trial_residuals`), whose cost only decides whether the
#: step is taken: the residuals carry the last correction ``e`` to first order, so they are
#: exact to ``½ ÿ e²`` — 2.5e-6 px at 1e-4 s and the mount's ÿ of a few hundred px/s² (the
#: chapter's problem: ÿ ≤ 0.4 px/s² for 99 % of the observations, 2e-9 px), and the
#: linearisation at an accepted step, started from the corrected time, is converged in its
#: first pass as before.
TRIAL_TOL_S = 1e-4
#: The largest linear prediction of a crossing time's move (s) that a trial step's Newton
#: starts from (:meth:`~hsgeo.sensors.pushbroom.PushbroomLines.start_trial`); larger predicted
#: moves start where the last evaluation ended. The prediction's error grows with the square
#: of the move: the chapter's first trial, whose crossings move up to ``T_MAX``, took 0.126
#: CPU-s with predicted moves up to 0.1 s against 0.117 with this bound (single runs); 99 % of
#: the second trial's moves are below 2 ms (pushbroom_model_passes.json at e3e1350).
TRIAL_PREDICTION_MAX_S = 0.01


@njit(cache=True, inline="always")
def _spline(j, dt, u0, inv_dt, nodes, idx, xyz_rate, rpy_rate, w, dw, dl, rate):  # pragma: no cover
    """The spline correction of observation j at ``t_e + dt``: its weights (w, dw), the
    correction ``dl`` of the pose and the pose rate ``rate`` (navigation rate included).
    """
    bspline_weights(u0[j] + dt * inv_dt, inv_dt, w, dw)
    for a in range(6):
        acc = 0.0
        acc_r = 0.0
        for b in range(4):
            acc += w[b] * nodes[idx[j, b], a]
            acc_r += dw[b] * nodes[idx[j, b], a]
        dl[a] = acc
        rate[a] = acc_r + (xyz_rate[j, a] if a < 3 else rpy_rate[j, a - 3])


@njit(cache=True, inline="always")
def _pose(j, dt, P, pidx, xyz_nav, rpy_nav, xyz_rate, rpy_rate, dl, R, dR, d):  # pragma: no cover
    """The pose of observation j at ``t_e + dt`` (navigation moved by its rates, plus ``dl``):
    the rotation R (and ∂R in dR), and ``d = P − position``.
    """
    rpy_rotation(
        rpy_nav[j, 0] + dt * rpy_rate[j, 0] + dl[3],
        rpy_nav[j, 1] + dt * rpy_rate[j, 1] + dl[4],
        rpy_nav[j, 2] + dt * rpy_rate[j, 2] + dl[5],
        R,
        dR,
    )
    pt = pidx[j]
    for a in range(3):
        d[a] = P[pt, a] - xyz_nav[j, a] - dt * xyz_rate[j, a] - dl[a]


@njit(cache=True, inline="always")
def _image(R, dR, d, lever, beta, c, dist, x0, y0, k_px, q, p, Jp, JpB, d6):  # pragma: no cover
    """The image point (mm) and its partials: Jp w.r.t. the camera point (px), JpB through β,
    d6 w.r.t. the pose (position, attitude) of the platform; returns x, y, xb, yb, gx, gy.
    """
    pushbroom_camera_point(R, d, lever, beta, q, p)  # 002 eq. (4)
    xm, ym, xb, yb, iz, gx, gy = pushbroom_image_mm(
        p[0], p[1], p[2], c, dist[0], dist[1], dist[2], dist[3]
    )  # 002 eq. (3)
    a_ = c * iz
    Jp[0, 0] = gx * a_ * k_px
    Jp[0, 1] = 0.0
    Jp[0, 2] = -gx * xb * iz * k_px
    Jp[1, 0] = gy * a_ * k_px
    Jp[1, 1] = a_ * k_px
    Jp[1, 2] = (-yb * iz - gy * xb * iz) * k_px
    for u in range(2):
        for a in range(3):
            JpB[u, a] = Jp[u, 0] * beta[0, a] + Jp[u, 1] * beta[1, a] + Jp[u, 2] * beta[2, a]
    for u in range(2):
        for a in range(3):
            d6[u, a] = -(JpB[u, 0] * R[a, 0] + JpB[u, 1] * R[a, 1] + JpB[u, 2] * R[a, 2])
        for kk in range(3):
            v = 0.0
            for i in range(3):
                dq = dR[kk, 0, i] * d[0] + dR[kk, 1, i] * d[1] + dR[kk, 2, i] * d[2]
                v += JpB[u, i] * dq
            d6[u, 3 + kk] = v
    return xm + x0, ym + y0, xb, yb, gx, gy


@njit(cache=True, inline="always")
def _derivatives(
    j, d6, Jp, JpB, dbeta, q, c, xb, yb, gx, gy, k_px, dP, dN, dB, dL, dD, dC
):  # pragma: no cover - compiled
    """Rows 2j, 2j+1 (j: the destination pair, see ``dst`` of ``_lines_kernel``) of the
    derivatives w.r.t. the point, the spline nodes (× their weights), the boresight, the lever
    arm, the distortion and the principal distance.
    """
    for u in range(2):
        row = 2 * j + u
        for a in range(3):
            dP[row, a] = -d6[u, a]  # dp/dP = β Rᵀ = −dp/dx
            dN[row, a] = d6[u, a]  # × the spline weights (factored Jacobian)
            dL[row, a] = -JpB[u, a]
            dN[row, 3 + a] = d6[u, 3 + a]
        for kk in range(3):
            # boresight: dp/dbore_k = dβ_k q
            v = 0.0
            for i in range(3):
                v += Jp[u, i] * (
                    dbeta[kk, i, 0] * q[0] + dbeta[kk, i, 1] * q[1] + dbeta[kk, i, 2] * q[2]
                )
            dB[row, kk] = v
    dC[2 * j, 0] = gx * xb / c * k_px
    dC[2 * j + 1, 0] = (yb / c + gy * xb / c) * k_px
    x3, x5, x2_3, x2 = pushbroom_line_distortion_dcoeff(xb)  # 002 eq. (3), hsgeo._kernels
    dD[2 * j, 0] = x3 * k_px
    dD[2 * j, 1] = x5 * k_px
    dD[2 * j, 2] = x2_3 * k_px
    dD[2 * j, 3] = 0.0
    dD[2 * j + 1, 0] = 0.0
    dD[2 * j + 1, 1] = 0.0
    dD[2 * j + 1, 2] = 0.0
    dD[2 * j + 1, 3] = x2 * k_px


@njit(cache=True, inline="always")
def _through_time(j, fx, fy, dP, dN, dB, dL, dD, dC):  # pragma: no cover - compiled
    """Rows 2j, 2j+1 through the crossing time: x(t*(θ)) takes ∂x/∂θ − fx ∂y/∂θ (fx = ẋ/ẏ),
    ẏ_ref (t_e − t*) takes fy ∂y/∂θ (fy = ẏ_ref/ẏ).
    """
    rx, ry = 2 * j, 2 * j + 1
    for a in range(3):
        dP[rx, a] -= fx * dP[ry, a]
        dL[rx, a] -= fx * dL[ry, a]
        dB[rx, a] -= fx * dB[ry, a]
        dP[ry, a] *= fy
        dL[ry, a] *= fy
        dB[ry, a] *= fy
    for a in range(6):
        dN[rx, a] -= fx * dN[ry, a]
        dN[ry, a] *= fy
    for a in range(4):
        dD[rx, a] -= fx * dD[ry, a]
        dD[ry, a] *= fy
    dC[rx, 0] -= fx * dC[ry, 0]
    dC[ry, 0] *= fy


@njit(cache=True, inline="always")
def _whiten(t, w0, w1, wts, fw, dP, dN, dB, dL, dD, dC):  # pragma: no cover - compiled
    """Rows 2t, 2t+1 scaled by their whitening weights ``w0``, ``w1`` (1/σ), and the spline
    weights ``wts`` written as the rows' factored weights ``fw`` (fused path).
    """
    for u in range(2):
        row = 2 * t + u
        s = w0 if u == 0 else w1
        for a in range(3):
            dP[row, a] *= s
            dB[row, a] *= s
            dL[row, a] *= s
        for a in range(6):
            dN[row, a] *= s
        for a in range(4):
            dD[row, a] *= s
            fw[row, a] = wts[a]
        dC[row, 0] *= s


@njit(cache=True, inline="always")
def _accumulate(
    t, rw0, rw1, idx_j, wts, cam_cols, c_col, node_c0, g, dg, dN, dB, dL, dD, dC
):  # pragma: no cover - compiled
    """The gradient ``Jᵀ r`` and the diagonal ``diag(JᵀJ)`` of the non-point unknowns from the
    whitened rows 2t, 2t+1 (residuals ``rw0``, ``rw1``): camera columns ``cam_cols``
    (boresight, lever arm, distortion; -1 fixed), the band's ``c_col``, and the four nodes
    ``idx_j`` of the spline group at ``node_c0 + 6 idx + a`` with weights ``wts``.
    """
    for u in range(2):
        row = 2 * t + u
        ru = rw0 if u == 0 else rw1
        for a in range(10):
            col = cam_cols[a]
            if col >= 0:
                if a < 3:
                    v = dB[row, a]
                elif a < 6:
                    v = dL[row, a - 3]
                else:
                    v = dD[row, a - 6]
                g[col] += v * ru
                dg[col] += v * v
        if c_col >= 0:
            v = dC[row, 0]
            g[c_col] += v * ru
            dg[c_col] += v * v
        for b in range(4):
            if idx_j[b] < 0:
                continue
            base = node_c0 + 6 * idx_j[b]
            for a in range(6):
                v = wts[b] * dN[row, a]
                g[base + a] += v * ru
                dg[base + a] += v * v


def _lines_kernel(*args):
    """002 eq. (2)–(4) and their derivatives, one observation per iteration (rows 2j, 2j+1).

    ``timed``: the observation is evaluated at the model's crossing time ``t*`` of the line
    (``y(t*) = y_obs``, Newton from the line time ``t_e`` with the navigation pose moved by its
    rates and the spline piece of ``t_e`` continued); the residuals are ``x(t*) − x_obs`` and
    ``ẏ_ref (t_e − t*)``, and their derivatives follow from the implicit function theorem,
    ``∂t*/∂θ = −(∂y/∂θ)/ẏ``. The spline weights used are returned in ``w_out`` (unless it has
    no rows). ``dt_start``
    (in and out): ``t* − t_e`` at which Newton starts, overwritten with this evaluation's.

    Fused path (``dst.size == m``): the derivatives of observation j go to rows
    ``2 dst[j], 2 dst[j] + 1`` of the destination arrays (none if ``dst[j] < 0``: a rejected
    observation), scaled by ``w_row[2j], w_row[2j + 1]``, with the spline weights in ``fw``;
    otherwise to rows 2j, 2j + 1 unscaled (``dst``, ``w_row``, ``fw`` unused). With
    ``gd`` of shape ``(2, n_chunks, n_c)`` (fused path) each chunk of observations also
    accumulates the gradient (``gd[0]``) and the diagonal (``gd[1]``) of the non-point unknowns
    in its row (see ``_accumulate``; the caller sums the chunks in order).

    ``args`` are :func:`_lines_chunk`'s after ``ch`` and ``step`` (``P, pidx, idx, …, node_c0``).
    """
    if len(args) != len(_ARGS):
        raise TypeError(f"_lines_kernel takes {len(_ARGS)} arguments ({len(args)} given)")
    pidx, dst, gd = args[_ARGS.index("pidx")], args[_ARGS.index("dst")], args[_ARGS.index("gd")]
    m = pidx.size
    n_chunks = 64 if m > 6400 else 1
    if dst.size == m and gd.shape[1] > 0:  # fused, with the gradient: its chunks
        n_chunks = gd.shape[1]
    over_items(_lines_chunk, m, n_chunks, *args)


@njit(cache=True, nogil=True)
def _lines_chunk(
    ch,
    step,
    P,
    pidx,
    idx,
    u0,
    inv_dt,
    nodes,
    xyz_nav,
    rpy_nav,
    xyz_rate,
    rpy_rate,
    band,
    c_b,
    dist,
    beta,
    dbeta,
    lever,
    x0,
    y0,
    k_px,
    xy_obs,
    timed,
    n_newton,
    tol_s,
    y_rate_ref,
    jac,
    dt_start,
    r,
    w_out,
    dP,
    dN,
    dB,
    dL,
    dD,
    dC,
    dst,
    w_row,
    fw,
    gd,
    cam_cols,
    c_cols,
    node_c0,
):  # pragma: no cover
    """Chunk ``ch`` of :func:`_lines_kernel`: the observations ``ch·step … (ch+1)·step − 1``
    (run on the kernels' threads by :func:`~hsgeo._chunks.over_chunks`, not as the
    body of a ``prange`` loop, whose parallel passes cost compile time; issue 41).
    """
    fused = dst.size == pidx.size
    m = pidx.size
    keep_w = w_out.shape[0] == m  # the spline weights are wanted (an empty w_out: not)
    gradient = fused and gd.shape[1] > 0
    R = np.empty((3, 3))
    dR = np.empty((3, 3, 3))
    d = np.empty(3)
    q = np.empty(3)
    p = np.empty(3)
    dl = np.empty(6)
    rate = np.empty(6)
    Jp = np.empty((2, 3))
    JpB = np.empty((2, 3))
    d6 = np.empty((2, 6))
    w = np.empty(4)
    dw = np.empty(4)
    for j in range(ch * step, min(m, (ch + 1) * step)):
        dt = dt_start[j] if timed else 0.0  # t − t_e, from the last evaluation's t*
        xdot = 0.0
        ydot = 1.0
        ey = 0.0
        n_it = n_newton if timed else 0
        c = c_b[band[j]]
        # defined before the Newton loop: set only inside it and read only after it, they
        # would not survive the loop under prange
        x = y = xb = yb = gx = gy = 0.0
        for it in range(n_it + 1):
            _spline(j, dt, u0, inv_dt, nodes, idx, xyz_rate, rpy_rate, w, dw, dl, rate)
            _pose(j, dt, P, pidx, xyz_nav, rpy_nav, xyz_rate, rpy_rate, dl, R, dR, d)
            x, y, xb, yb, gx, gy = _image(
                R, dR, d, lever, beta, c, dist, x0, y0, k_px, q, p, Jp, JpB, d6
            )
            if not timed:
                break
            # image rates (px/s) along the trajectory: ∂(x, y)/∂pose · pose rate
            xdot = 0.0
            ydot = 0.0
            for a in range(6):
                xdot += d6[0, a] * rate[a]
                ydot += d6[1, a] * rate[a]
            # every real geometry has ẏ near ẏ_ref; a far-off trial point may not
            ydot = max(ydot, 0.25 * y_rate_ref)
            ey = (y * k_px - xy_obs[j, 1]) / ydot
            if abs(ey) < tol_s:
                # converged: the last correction is kept in the residual, which is then
                # exact to O(ey²)
                break
            if it < n_it:
                dt_next = min(max(dt - ey, -T_MAX), T_MAX)
                if dt_next == dt:
                    # held at the bound (or a correction below dt's last bit): evaluating
                    # again at the same time would give the same values
                    break
                dt = dt_next
        if keep_w:
            for b in range(4):
                w_out[j, b] = w[b]
        if timed:
            dt_start[j] = min(max(dt - ey, -T_MAX), T_MAX)
        r[2 * j] = x * k_px - xy_obs[j, 0] - xdot * ey  # x at t* (0 if not timed)
        if timed:
            # ẏ_ref (t_e − t*), t* = t_e + dt − ey (the last Newton correction included)
            r[2 * j + 1] = y_rate_ref * (ey - dt)
        else:
            r[2 * j + 1] = y * k_px - xy_obs[j, 1]
        if not jac:
            continue
        t = dst[j] if fused else j
        if t < 0:
            continue
        _derivatives(t, d6, Jp, JpB, dbeta, q, c, xb, yb, gx, gy, k_px, dP, dN, dB, dL, dD, dC)
        if timed:
            _through_time(t, xdot / ydot, y_rate_ref / ydot, dP, dN, dB, dL, dD, dC)
        if fused:
            _whiten(t, w_row[2 * j], w_row[2 * j + 1], w, fw, dP, dN, dB, dL, dD, dC)
        if gradient:
            _accumulate(
                t,
                r[2 * j] * w_row[2 * j],
                r[2 * j + 1] * w_row[2 * j + 1],
                idx[j],
                w,
                cam_cols,
                c_cols[band[j]],
                node_c0,
                gd[0, ch],
                gd[1, ch],
                dN,
                dB,
                dL,
                dD,
                dC,
            )


#: :func:`_lines_kernel`'s arguments: :func:`_lines_chunk`'s after ``ch`` and ``step``
_ARGS = tuple(inspect.signature(_lines_chunk.py_func).parameters)[2:]
