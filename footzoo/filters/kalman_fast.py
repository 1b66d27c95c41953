"""Compiled sample loop of the error-state Kalman filter.

The same equations as :func:`footzoo.filters.kalman_reference.run_reference`
(the reference, on filterpy's ``KalmanFilter``), with every correction's
measurement model called through its compiled functions (the contract is in
:mod:`footzoo.filters.measurement`); this module knows no correction.

The covariance prediction uses the sparsity of Φ = I + Δ
(``P ← P + ΔP + (P + ΔP)Δᵀ + Q``), the update filterpy's formulas with the
Joseph form, expanded so that only the nonzero entries of H are touched. The
loop allocates nothing per sample and writes its outputs into arrays the
caller allocates. A test keeps both engines equal to 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from .smoother import feed_back_attitude, smoother_gain, spd_inverse


@njit
def _add_block_rows(out, src, r0, c0, b):
    """out[r0:r0+3, :] += b @ src[c0:c0+3, :]"""
    n = src.shape[1]
    for i in range(3):
        for j in range(n):
            s = 0.0
            for m in range(3):
                s += b[i, m] * src[c0 + m, j]
            out[r0 + i, j] += s


@njit
def _add_block_cols(out, src, r0, c0, b):
    """out[:, r0:r0+3] += src[:, c0:c0+3] @ b.T"""
    n = src.shape[0]
    for i in range(n):
        for j in range(3):
            s = 0.0
            for m in range(3):
                s += src[i, c0 + m] * b[j, m]
            out[i, r0 + j] += s


@njit
def _add_identity_rows(out, src, r0, c0, s):
    """out[r0:r0+3, :] += s * src[c0:c0+3, :]"""
    for i in range(3):
        for j in range(src.shape[1]):
            out[r0 + i, j] += s * src[c0 + i, j]


@njit
def _add_identity_cols(out, src, r0, c0, s):
    """out[:, r0:r0+3] += s * src[:, c0:c0+3]"""
    for i in range(src.shape[0]):
        for j in range(3):
            out[i, r0 + j] += s * src[i, c0 + j]




@njit
def eskf_loop(signals, core, state, models, out, k0):
    """Run samples 1… of ``signals`` from ``state`` (updated in place); outputs into ``out``.

    Parameters
    ----------
    signals : tuple
        ``(t (N,) s, acc (N, 3) m/s², gyr (N, 3) rad/s, stance (N,) bool, quat_ext (N or 1, 4))``;
        sample 0 is the one ``state`` belongs to.
    core : tuple
        ``(idx (5,) int: offsets of att, gyro_bias, pos, vel, acc_bias, −1 if absent;
        q (n,) variance growth per second; gravity m/s²; use_ext bool: attitude from quat_ext;
        m_max int: most rows of one update)``.
    state : tuple
        ``(nav (16,): q, p, v, b_g, b_a; P (n, n) covariance; mems (s,) all models' memory)``.
    models : tuple
        ``(measures, feedbacks, afters, idx (L, w) int, par, par_off (L+1,), mem_off (L+1,),
        data (N, d), data_off (L+1,), hooks (L, 2) int: model j has a feedback / an after function)``:
        the corrections' functions and their arrays, in stacking order.
    out : tuple
        ``(quat (N, 4), vel, pos, acc_nav, gyro_bias, acc_bias (N, 3), P_diag (N or 0, n),
        gains (N or 0, n, n), dxs (N or 0, n))``; row 0 receives the incoming state. ``P_diag``,
        and the smoother's gains ``A_k`` and fed-back errors (:mod:`footzoo.filters.smoother`),
        with 0 rows are not written.
    k0 : int
        Index of sample 0 in the whole recording (a stream passes its running count).
    """
    t, acc, gyr, stance, quat_ext = signals
    idx, qn, gravity, use_ext, m_max = core
    nav, P, mems = state
    measures, feedbacks, afters, m_idx, par, par_off, mem_off, data, data_off, hooks = models
    quat, vel, pos, acc_nav, gb_out, ab_out, pdiag, gains, dxs = out
    N = t.shape[0]
    n = P.shape[0]
    smooth = gains.shape[0] == N
    sub = np.empty((n, n))
    Ls = np.empty((n, n))
    inv = np.empty((n, n))
    keep = np.empty(n, dtype=np.int64)
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    keep_p = pdiag.shape[0] == N
    z = np.zeros(m_max)
    H = np.zeros((m_max, n))
    rdiag = np.zeros(m_max)
    M = np.empty((n, n))
    T = np.empty((n, n))
    S = np.empty((m_max, m_max))
    SI = np.empty((m_max, m_max))
    L = np.empty((m_max, m_max))
    PHT = np.empty((n, m_max))
    THT = np.empty((n, m_max))
    nzc = np.zeros((m_max, n), dtype=np.int64)
    nnz = np.zeros(m_max, dtype=np.int64)
    K = np.empty((n, m_max))
    dx = np.empty(n)
    c = np.empty((3, 3))
    cdt = np.empty((3, 3))
    sdt = np.empty((3, 3))
    w = np.empty(3)
    f = np.empty(3)
    f_n = np.empty(3)
    a_n = np.empty(3)
    for i in range(4):
        quat[0, i] = nav[i]
    for i in range(3):
        pos[0, i] = nav[4 + i]
        vel[0, i] = nav[7 + i]
        gb_out[0, i] = nav[10 + i]
        ab_out[0, i] = nav[13 + i]
        acc_nav[0, i] = 0.0
    if keep_p:
        for i in range(n):
            pdiag[0, i] = P[i, i]
    for k in range(1, N):
        dt = t[k] - t[k - 1]
        for i in range(3):
            w[i] = gyr[k, i] - nav[10 + i]
            f[i] = acc[k, i] - nav[13 + i]
        pw, px, py, pz = nav[0], nav[1], nav[2], nav[3]
        if use_ext:
            for i in range(4):
                nav[i] = quat_ext[k, i]
        else:
            # q ⊗ exp(w dt), the exact form of Nguyen & La eq. 37
            rx, ry, rz = w[0] * dt, w[1] * dt, w[2] * dt
            angle = math.sqrt(rx * rx + ry * ry + rz * rz)
            half = 0.5 * angle
            kk = math.sin(half) / angle if angle > 1e-12 else 0.5 - angle * angle / 48.0
            dw, dx_, dy, dz = math.cos(half), kk * rx, kk * ry, kk * rz
            nav[0] = pw * dw - px * dx_ - py * dy - pz * dz
            nav[1] = pw * dx_ + px * dw + py * dz - pz * dy
            nav[2] = pw * dy - px * dz + py * dw + pz * dx_
            nav[3] = pw * dz + px * dy - py * dx_ + pz * dw
        dot = pw * nav[0] + px * nav[1] + py * nav[2] + pz * nav[3]
        sg = 1.0 if dot >= 0 else -1.0
        mw, mx, my, mz = nav[0] + sg * pw, nav[1] + sg * px, nav[2] + sg * py, nav[3] + sg * pz
        nm = math.sqrt(mw * mw + mx * mx + my * my + mz * mz)
        mw, mx, my, mz = mw / nm, mx / nm, my / nm, mz / nm
        c[0, 0] = 1 - 2 * (my * my + mz * mz)
        c[0, 1] = 2 * (mx * my - mw * mz)
        c[0, 2] = 2 * (mx * mz + mw * my)
        c[1, 0] = 2 * (mx * my + mw * mz)
        c[1, 1] = 1 - 2 * (mx * mx + mz * mz)
        c[1, 2] = 2 * (my * mz - mw * mx)
        c[2, 0] = 2 * (mx * mz - mw * my)
        c[2, 1] = 2 * (my * mz + mw * mx)
        c[2, 2] = 1 - 2 * (mx * mx + my * my)
        for i in range(3):
            f_n[i] = c[i, 0] * f[0] + c[i, 1] * f[1] + c[i, 2] * f[2]
            a_n[i] = f_n[i]
        a_n[2] += gravity
        for i in range(3):
            v_old = nav[7 + i]
            nav[7 + i] = v_old + a_n[i] * dt
            nav[4 + i] = nav[4 + i] + 0.5 * (v_old + nav[7 + i]) * dt
        # covariance prediction, eq. 44: P <- (I + Δ) P (I + Δ)ᵀ + Q
        for i in range(3):
            for j in range(3):
                cdt[i, j] = dt * c[i, j]
        sdt[0, 0], sdt[0, 1], sdt[0, 2] = 0.0, dt * f_n[2], -dt * f_n[1]
        sdt[1, 0], sdt[1, 1], sdt[1, 2] = -dt * f_n[2], 0.0, dt * f_n[0]
        sdt[2, 0], sdt[2, 1], sdt[2, 2] = dt * f_n[1], -dt * f_n[0], 0.0
        M[:, :] = P
        if att >= 0 and gb_i >= 0:
            _add_block_rows(M, P, att, gb_i, cdt)
        _add_identity_rows(M, P, pos_i, vel_i, dt)
        if att >= 0:
            _add_block_rows(M, P, vel_i, att, sdt)
        if ab_i >= 0:
            _add_block_rows(M, P, vel_i, ab_i, cdt)
        P[:, :] = M
        if att >= 0 and gb_i >= 0:
            _add_block_cols(P, M, att, gb_i, cdt)
        _add_identity_cols(P, M, pos_i, vel_i, dt)
        if att >= 0:
            _add_block_cols(P, M, vel_i, att, sdt)
        if ab_i >= 0:
            _add_block_cols(P, M, vel_i, ab_i, cdt)
        for i in range(n):
            P[i, i] += qn[i] * dt
        if smooth:  # M = Φ P⁺_{k−1}, P = P⁻_k
            smoother_gain(M, P, gains[k - 1], sub, Ls, inv, keep)
            for i in range(n):
                dxs[k, i] = 0.0
        # the corrections' measurement rows, stacked in order
        st = stance[k]
        m = 0
        for j in range(len(measures)):
            m = measures[j](k0 + k, t[k], nav, w, f, st, m_idx[j], par[par_off[j]:par_off[j + 1]],
                            mems[mem_off[j]:mem_off[j + 1]], data[k, data_off[j]:data_off[j + 1]], z, H, rdiag, m)
        if m > 0:
            # filterpy's update: K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form (eq. 45),
            # (I − KH) P (I − KH)ᵀ + K R Kᵀ, evaluated as T = P − K(HP), P = T − (THᵀ)Kᵀ + K R Kᵀ
            # with the nonzero columns of each row of H
            for a in range(m):
                cnt = 0
                for b in range(n):
                    if H[a, b] != 0.0:
                        nzc[a, cnt] = b
                        cnt += 1
                nnz[a] = cnt
            for i in range(n):
                for a in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        b = nzc[a, e]
                        acc_ += P[i, b] * H[a, b]
                    PHT[i, a] = acc_
            for a in range(m):
                for b2 in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        i = nzc[a, e]
                        acc_ += H[a, i] * PHT[i, b2]
                    S[a, b2] = acc_
                S[a, a] += rdiag[a]
            spd_inverse(S, m, L, SI)
            for i in range(n):
                for a in range(m):
                    acc_ = 0.0
                    for b2 in range(m):
                        acc_ += PHT[i, b2] * SI[b2, a]
                    K[i, a] = acc_
                acc_ = 0.0
                for a in range(m):
                    acc_ += K[i, a] * z[a]
                dx[i] = acc_
            for i in range(n):  # T = P − K (H P), with H P = (P Hᵀ)ᵀ
                for j in range(n):
                    acc_ = P[i, j]
                    for a in range(m):
                        acc_ -= K[i, a] * PHT[j, a]
                    T[i, j] = acc_
            for i in range(n):  # T Hᵀ
                for a in range(m):
                    acc_ = 0.0
                    for e in range(nnz[a]):
                        b = nzc[a, e]
                        acc_ += T[i, b] * H[a, b]
                    THT[i, a] = acc_
            for i in range(n):
                for j in range(i, n):
                    acc_ = T[i, j]
                    for a in range(m):
                        acc_ += K[j, a] * (K[i, a] * rdiag[a] - THT[i, a])
                    P[i, j] = acc_
                    P[j, i] = acc_
            for a in range(m):  # leave H all zero for the next sample
                for e in range(nnz[a]):
                    H[a, nzc[a, e]] = 0.0
            # feedback, eqs. 49-52: q <- exp(−δφ) ⊗ q, p <- p − δp, v <- v − δv, b <- b + δb
            if att >= 0 and not use_ext:
                feed_back_attitude(nav[0:4], dx[att], dx[att + 1], dx[att + 2])
            for i in range(3):
                nav[4 + i] -= dx[pos_i + i]
                nav[7 + i] -= dx[vel_i + i]
                if gb_i >= 0:
                    nav[10 + i] += dx[gb_i + i]
                if ab_i >= 0:
                    nav[13 + i] += dx[ab_i + i]
            for j in range(len(feedbacks)):
                if hooks[j, 0]:
                    feedbacks[j](dx, m_idx[j], par[par_off[j]:par_off[j + 1]],
                                 mems[mem_off[j]:mem_off[j + 1]])
            if smooth:
                for i in range(n):
                    dxs[k, i] = dx[i]
        for j in range(len(afters)):
            if hooks[j, 1]:
                afters[j](k0 + k, nav, st, m_idx[j], par[par_off[j]:par_off[j + 1]],
                          mems[mem_off[j]:mem_off[j + 1]])
        for i in range(4):
            quat[k, i] = nav[i]
        for i in range(3):
            pos[k, i] = nav[4 + i]
            vel[k, i] = nav[7 + i]
            gb_out[k, i] = nav[10 + i]
            ab_out[k, i] = nav[13 + i]
            acc_nav[k, i] = a_n[i]
        if keep_p:
            for i in range(n):
                pdiag[k, i] = P[i, i]
