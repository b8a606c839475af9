"""The compiled residual kernel of :class:`hsgeo.sensors.pushbroom.PushbroomLines` (002 eq. 2–4).

``_lines_kernel`` makes one pass per observation: the spline correction and the pose at the
trial time (``_spline``, ``_pose``), the projection and its partials (``_image``), the Newton on
the crossing time, and the derivatives (``_derivatives``), each entry chained through the
crossing time and whitened as it is written (``_pair``); the helpers are inlined into the chunk
function ``_lines_chunk`` (``inline="always"``), so the compiled loop is that of one function,
and the chunks run on the kernels' threads (:func:`hsgeo._chunks.over_chunks`: with numba's
``prange`` over them the kernel's two compilations on a fresh cache took 28 s, without it 17 s;
issue 41). The
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

The helpers pass their results as values (tuples of floats), not through small arrays: held in
local variables, the compiler keeps them in registers, where each store to a small array went
to memory and each later read came back from it. With the same arithmetic in the same order
(bit-identical outputs), one pass at the paper's size took 0.034 instead of 0.056 CPU-s
without derivatives and 0.065 instead of 0.092 with them (issue 41, one thread). Tuples are
indexed by constants only: a loop over a tuple's entries made the derivative pass slower than
before (0.098).
"""

from __future__ import annotations

import inspect

import numpy as np
from numba import njit

from hsgeo._chunks import over_items
from hsgeo._kernels import (
    bspline_weights_values,
    pushbroom_camera_point_values,
    pushbroom_image_mm,
    pushbroom_line_distortion_dcoeff,
    rpy_rotation_values,
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
def _spline(j, dt, u0, inv_dt, nodes, idx, xyz_rate, rpy_rate, dl, rate):  # pragma: no cover
    """The spline correction of observation j at ``t_e + dt``: writes the correction ``dl`` of
    the pose and the pose rate ``rate`` (navigation rate included); returns the weights
    ``(w0, w1, w2, w3)``.
    """
    w0, w1, w2, w3, dw0, dw1, dw2, dw3 = bspline_weights_values(u0[j] + dt * inv_dt, inv_dt)
    i0, i1, i2, i3 = idx[j, 0], idx[j, 1], idx[j, 2], idx[j, 3]
    for a in range(6):
        n0, n1, n2, n3 = nodes[i0, a], nodes[i1, a], nodes[i2, a], nodes[i3, a]
        acc = 0.0
        acc += w0 * n0
        acc += w1 * n1
        acc += w2 * n2
        acc += w3 * n3
        acc_r = 0.0
        acc_r += dw0 * n0
        acc_r += dw1 * n1
        acc_r += dw2 * n2
        acc_r += dw3 * n3
        dl[a] = acc
        rate[a] = acc_r + (xyz_rate[j, a] if a < 3 else rpy_rate[j, a - 3])
    return w0, w1, w2, w3


@njit(cache=True, inline="always")
def _pose(j, dt, P, pidx, xyz_nav, rpy_nav, xyz_rate, rpy_rate, dl):  # pragma: no cover
    """The pose of observation j at ``t_e + dt`` (navigation moved by its rates, plus ``dl``):
    returns the rotation R and ∂R (:func:`~hsgeo._kernels.rpy_rotation_values`) and
    ``d = P − position`` (three values).
    """
    R, dR = rpy_rotation_values(
        rpy_nav[j, 0] + dt * rpy_rate[j, 0] + dl[3],
        rpy_nav[j, 1] + dt * rpy_rate[j, 1] + dl[4],
        rpy_nav[j, 2] + dt * rpy_rate[j, 2] + dl[5],
    )
    pt = pidx[j]
    d0 = P[pt, 0] - xyz_nav[j, 0] - dt * xyz_rate[j, 0] - dl[0]
    d1 = P[pt, 1] - xyz_nav[j, 1] - dt * xyz_rate[j, 1] - dl[1]
    d2 = P[pt, 2] - xyz_nav[j, 2] - dt * xyz_rate[j, 2] - dl[2]
    return R, dR, d0, d1, d2


@njit(cache=True, inline="always")
def _sum3(a0, a1, a2, b0, b1, b2):  # pragma: no cover - compiled
    """``a·b`` summed from 0.0 in order (the order the kernel's loops had)."""
    v = 0.0
    v += a0 * b0
    v += a1 * b1
    v += a2 * b2
    return v


@njit(cache=True, inline="always")
def _image(R, dR, d0, d1, d2, lever, beta, c, dist, x0, y0, k_px):  # pragma: no cover
    """The image point (mm) and its partials: returns ``x, y, xb, yb, gx, gy``, ``q`` (the
    platform-frame point, 3), ``Jp`` (w.r.t. the camera point, px, 2 × 3 row by row), ``JpB``
    (through β, 2 × 3) and ``d6`` (w.r.t. the pose: position, attitude; 2 × 6 row by row).
    """
    q0, q1, q2, p0, p1, p2 = pushbroom_camera_point_values(
        R, d0, d1, d2, lever, beta
    )  # 002 eq. (4)
    xm, ym, xb, yb, iz, gx, gy = pushbroom_image_mm(
        p0, p1, p2, c, dist[0], dist[1], dist[2], dist[3]
    )  # 002 eq. (3)
    a_ = c * iz
    J00 = gx * a_ * k_px
    J01 = 0.0
    J02 = -gx * xb * iz * k_px
    J10 = gy * a_ * k_px
    J11 = a_ * k_px
    J12 = (-yb * iz - gy * xb * iz) * k_px
    B00 = J00 * beta[0, 0] + J01 * beta[1, 0] + J02 * beta[2, 0]
    B01 = J00 * beta[0, 1] + J01 * beta[1, 1] + J02 * beta[2, 1]
    B02 = J00 * beta[0, 2] + J01 * beta[1, 2] + J02 * beta[2, 2]
    B10 = J10 * beta[0, 0] + J11 * beta[1, 0] + J12 * beta[2, 0]
    B11 = J10 * beta[0, 1] + J11 * beta[1, 1] + J12 * beta[2, 1]
    B12 = J10 * beta[0, 2] + J11 * beta[1, 2] + J12 * beta[2, 2]
    # ∂q/∂angle_k = ∂Rᵀ/∂angle_k d: dq[k][i] = Σ_a dR[k, a, i] d_a
    r0 = dR[0] * d0 + dR[3] * d1 + dR[6] * d2
    r1 = dR[1] * d0 + dR[4] * d1 + dR[7] * d2
    r2 = dR[2] * d0 + dR[5] * d1 + dR[8] * d2
    t0 = dR[9] * d0 + dR[12] * d1 + dR[15] * d2
    t1 = dR[10] * d0 + dR[13] * d1 + dR[16] * d2
    t2 = dR[11] * d0 + dR[14] * d1 + dR[17] * d2
    s0 = dR[18] * d0 + dR[21] * d1 + dR[24] * d2
    s1 = dR[19] * d0 + dR[22] * d1 + dR[25] * d2
    s2 = dR[20] * d0 + dR[23] * d1 + dR[26] * d2
    d6 = (
        -(B00 * R[0] + B01 * R[1] + B02 * R[2]),  # position: −JpB Rᵀ
        -(B00 * R[3] + B01 * R[4] + B02 * R[5]),
        -(B00 * R[6] + B01 * R[7] + B02 * R[8]),
        _sum3(B00, B01, B02, r0, r1, r2),  # attitude: JpB ∂q/∂angle
        _sum3(B00, B01, B02, t0, t1, t2),
        _sum3(B00, B01, B02, s0, s1, s2),
        -(B10 * R[0] + B11 * R[1] + B12 * R[2]),
        -(B10 * R[3] + B11 * R[4] + B12 * R[5]),
        -(B10 * R[6] + B11 * R[7] + B12 * R[8]),
        _sum3(B10, B11, B12, r0, r1, r2),
        _sum3(B10, B11, B12, t0, t1, t2),
        _sum3(B10, B11, B12, s0, s1, s2),
    )
    Jp = (J00, J01, J02, J10, J11, J12)
    JpB = (B00, B01, B02, B10, B11, B12)
    return xm + x0, ym + y0, xb, yb, gx, gy, (q0, q1, q2), Jp, JpB, d6


@njit(cache=True, inline="always")
def _pair(vx, vy, timed, fx, fy, fused, s0, s1):  # pragma: no cover - compiled
    """One column of rows 2j, 2j+1: through the crossing time (if ``timed``), x(t*(θ)) takes
    ∂x/∂θ − fx ∂y/∂θ (fx = ẋ/ẏ) and ẏ_ref (t_e − t*) takes fy ∂y/∂θ (fy = ẏ_ref/ẏ); then
    scaled by the rows' whitening weights ``s0``, ``s1`` (1/σ, fused path).
    """
    if timed:
        vx -= fx * vy
        vy *= fy
    if fused:
        vx *= s0
        vy *= s1
    return vx, vy


@njit(cache=True, inline="always")
def _derivatives(
    t, tf, q, Jp, JpB, d6, dbeta, c, xb, yb, gx, gy, k_px, dP, dN, dB, dL, dD, dC
):  # pragma: no cover - compiled
    """Rows 2t, 2t+1 (t: the destination pair, see ``dst`` of ``_lines_kernel``) of the
    derivatives w.r.t. the point, the spline nodes (× their weights), the boresight, the lever
    arm, the distortion and the principal distance, each column through :func:`_pair` with
    ``tf = (timed, fx, fy, fused, s0, s1)``. Each entry is written once.
    """
    timed, fx, fy, fused, s0, s1 = tf
    rx, ry = 2 * t, 2 * t + 1
    # dp/dP = β Rᵀ = −dp/dx (unrolled: the values are tuples, indexed by constants)
    dP[rx, 0], dP[ry, 0] = _pair(-d6[0], -d6[6], timed, fx, fy, fused, s0, s1)
    dP[rx, 1], dP[ry, 1] = _pair(-d6[1], -d6[7], timed, fx, fy, fused, s0, s1)
    dP[rx, 2], dP[ry, 2] = _pair(-d6[2], -d6[8], timed, fx, fy, fused, s0, s1)
    # the nodes, × the spline weights (factored Jacobian)
    dN[rx, 0], dN[ry, 0] = _pair(d6[0], d6[6], timed, fx, fy, fused, s0, s1)
    dN[rx, 1], dN[ry, 1] = _pair(d6[1], d6[7], timed, fx, fy, fused, s0, s1)
    dN[rx, 2], dN[ry, 2] = _pair(d6[2], d6[8], timed, fx, fy, fused, s0, s1)
    dN[rx, 3], dN[ry, 3] = _pair(d6[3], d6[9], timed, fx, fy, fused, s0, s1)
    dN[rx, 4], dN[ry, 4] = _pair(d6[4], d6[10], timed, fx, fy, fused, s0, s1)
    dN[rx, 5], dN[ry, 5] = _pair(d6[5], d6[11], timed, fx, fy, fused, s0, s1)
    dL[rx, 0], dL[ry, 0] = _pair(-JpB[0], -JpB[3], timed, fx, fy, fused, s0, s1)
    dL[rx, 1], dL[ry, 1] = _pair(-JpB[1], -JpB[4], timed, fx, fy, fused, s0, s1)
    dL[rx, 2], dL[ry, 2] = _pair(-JpB[2], -JpB[5], timed, fx, fy, fused, s0, s1)
    for kk in range(3):
        # boresight: dp/dbore_k = dβ_k q
        b0 = dbeta[kk, 0, 0] * q[0] + dbeta[kk, 0, 1] * q[1] + dbeta[kk, 0, 2] * q[2]
        b1 = dbeta[kk, 1, 0] * q[0] + dbeta[kk, 1, 1] * q[1] + dbeta[kk, 1, 2] * q[2]
        b2 = dbeta[kk, 2, 0] * q[0] + dbeta[kk, 2, 1] * q[1] + dbeta[kk, 2, 2] * q[2]
        dB[rx, kk], dB[ry, kk] = _pair(
            _sum3(Jp[0], Jp[1], Jp[2], b0, b1, b2),
            _sum3(Jp[3], Jp[4], Jp[5], b0, b1, b2),
            timed,
            fx,
            fy,
            fused,
            s0,
            s1,
        )
    dC[rx, 0], dC[ry, 0] = _pair(
        gx * xb / c * k_px, (yb / c + gy * xb / c) * k_px, timed, fx, fy, fused, s0, s1
    )
    x3, x5, x2_3, x2 = pushbroom_line_distortion_dcoeff(xb)  # 002 eq. (3), hsgeo._kernels
    dD[rx, 0], dD[ry, 0] = _pair(x3 * k_px, 0.0, timed, fx, fy, fused, s0, s1)
    dD[rx, 1], dD[ry, 1] = _pair(x5 * k_px, 0.0, timed, fx, fy, fused, s0, s1)
    dD[rx, 2], dD[ry, 2] = _pair(x2_3 * k_px, 0.0, timed, fx, fy, fused, s0, s1)
    dD[rx, 3], dD[ry, 3] = _pair(0.0, x2 * k_px, timed, fx, fy, fused, s0, s1)


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
    dl = np.empty(6)
    rate = np.empty(6)
    w = np.empty(4)
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
        w0 = w1 = w2 = w3 = 0.0
        q = (0.0, 0.0, 0.0)
        Jp = JpB = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        d6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        for it in range(n_it + 1):
            w0, w1, w2, w3 = _spline(j, dt, u0, inv_dt, nodes, idx, xyz_rate, rpy_rate, dl, rate)
            R, dR, d0, d1, d2 = _pose(j, dt, P, pidx, xyz_nav, rpy_nav, xyz_rate, rpy_rate, dl)
            x, y, xb, yb, gx, gy, q, Jp, JpB, d6 = _image(
                R, dR, d0, d1, d2, lever, beta, c, dist, x0, y0, k_px
            )
            if not timed:
                break
            # image rates (px/s) along the trajectory: ∂(x, y)/∂pose · pose rate
            xdot = 0.0
            ydot = 0.0
            xdot += d6[0] * rate[0]  # unrolled: d6 is a tuple, indexed by constants
            xdot += d6[1] * rate[1]
            xdot += d6[2] * rate[2]
            xdot += d6[3] * rate[3]
            xdot += d6[4] * rate[4]
            xdot += d6[5] * rate[5]
            ydot += d6[6] * rate[0]
            ydot += d6[7] * rate[1]
            ydot += d6[8] * rate[2]
            ydot += d6[9] * rate[3]
            ydot += d6[10] * rate[4]
            ydot += d6[11] * rate[5]
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
        w[0], w[1], w[2], w[3] = w0, w1, w2, w3
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
        tf = (
            timed,
            xdot / ydot if timed else 0.0,
            y_rate_ref / ydot if timed else 1.0,
            fused,
            w_row[2 * j] if fused else 1.0,
            w_row[2 * j + 1] if fused else 1.0,
        )
        _derivatives(t, tf, q, Jp, JpB, d6, dbeta, c, xb, yb, gx, gy, k_px, dP, dN, dB, dL, dD, dC)
        if fused:  # the rows' spline weights (factored Jacobian)
            for a in range(4):
                fw[2 * t, a] = w[a]
                fw[2 * t + 1, a] = w[a]
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
