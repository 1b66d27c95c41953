"""Compiled sample loop of the error-state Kalman filter.

The same equations as :func:`footzoo.filters.kalman_reference.run_reference`
(the reference, on filterpy's ``KalmanFilter``), with every correction's
measurement model called through its compiled functions (the contract is in
:mod:`footzoo.filters.measurement`); this module knows no correction.

The covariance prediction works in place on the nonzero blocks of Φ = I + Δ
(the rows of Φ P, then the columns of the rows that move, mirrored: P stays
exactly symmetric); the update is filterpy's, in the Joseph form, taking the
rows of H one at a time (R is diagonal) and touching only their nonzero
entries. Every array the models' functions get is a view that owns no
reference, so a call costs no reference counting. The loop allocates nothing:
its buffers (:func:`scratch`) and outputs are the caller's. A test keeps both
engines equal to 1e-9 relative.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..kernels import jit as _jit
from ..kernels.jit import njit
from .smoother import feed_back_attitude
from .stepwise import close_segment, record_covariance, record_row, record_transition
from .strapdown import quat_product, rotvec_quat


def _unowned(a):
    """``a`` itself (see below)."""
    return a


if _jit.HAVE_NUMBA:
    try:
        from numba.core import cgutils
        from numba.extending import intrinsic
        from numba.np.arrayobj import make_array
    except ImportError:  # pragma: no cover - a broken numba: the kernels run as Python
        pass
    else:

        @intrinsic
        def _unowned(typingctx, a):  # noqa: F811 - the compiled form of the function above
            """A view of array ``a`` without an owner: numba counts no references for it.

            Only for arrays that outlive every use of the view: the loop's arguments (a local
            array is freed after its last use, which may be the call of this function), handed
            to the models' functions, which return no array.
            """

            def codegen(context, builder, sig, args):
                ary = make_array(sig.args[0])(context, builder, value=args[0])
                ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
                ary.parent = cgutils.get_null_value(ary.parent.type)
                return ary._getvalue()

            return a(a), codegen


@njit
def eskf_loop(signals, core, state, models, out, k0, scratch, smoother, record):
    """Run samples 1… of ``signals`` from ``state`` (updated in place); outputs into ``out``.

    Parameters
    ----------
    signals : tuple
        ``(t (N,) s, acc (N, 3) m/s², gyr (N, 3) rad/s, stance (N,) bool, quat_ext (N or 1, 4))``;
        sample 0 is the one ``state`` belongs to.
    core : tuple
        ``(idx (5,) int: offsets of att, gyro_bias, pos, vel, acc_bias, −1 if absent;
        q (n,) variance growth per second; gravity m/s²; use_ext bool: attitude from quat_ext;
        m_max int: most rows of one update; impact s: velocity variance growth per squared
        motion acceleration)``.
    state : tuple
        ``(nav (16,): q, p, v, b_g, b_a; P (n, n) covariance; mems (s,) all models' memory)``.
    models : tuple
        ``(measures, feedbacks, afters, idx (L, w) int, par, par_off (L+1,), mem_off (L+1,),
        data (N, d), data_off (L+1,), hooks (L, 2) int: model j has a feedback / an after function)``:
        the corrections' functions and their arrays, in stacking order.
    out : tuple
        ``(quat (N, 4), vel, pos, acc_nav, gyro_bias, acc_bias (N, 3), P_diag (N or 0, n))``; row 0
        receives the incoming state. A bias without its error-state block stays zero and is not
        written: pass zeros. ``P_diag`` with 0 rows is not written.
    k0 : int
        Index of sample 0 in the whole recording (a stream passes its running count).
    scratch : tuple
        The loop's buffers, from :func:`scratch` (any content).
    smoother : tuple or None
        For an RTS smoother (:mod:`footzoo.filters.smoother`), from :func:`smoother_arrays`: its
        gains ``A_k`` (N, n, n) and fed-back errors (N, n) are written. ``None`` (no smoother):
        numba compiles the loop without the smoother's code.
    record : tuple or None
        For the step-wise smoother (:mod:`footzoo.filters.stepwise`), from
        :func:`footzoo.filters.stepwise.record_arrays` with a row per sample: each sample's
        ``P⁺``, Φ's blocks and update rows are written (made ``in_loop``: each segment is smoothed
        in place as soon as it has closed, the last one left to the caller). ``None``: compiled
        without that code.
    """
    t, acc, gyr, stance, quat_ext = signals
    idx, qn, gravity, use_ext, m_max, impact = core
    nav_owned, P_owned, mems_owned = state
    measures, feedbacks, afters, idx_owned, par_owned, par_off, mem_off, data_owned, data_off, hooks = models
    quat, vel, pos, acc_nav, gb_out, ab_out, pdiag = out
    N = t.shape[0]
    n = P_owned.shape[0]
    keep_p = pdiag.shape[0] == N
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    # the arrays the loop works on and hands to the models' functions, as views that own no
    # reference: handing them on costs no reference counting (they are the caller's arguments,
    # alive during the whole call)
    (z_owned, H_owned, r_owned, dx_owned, w_owned, f_owned, u_o, kv_o, g_o, nzc_o, dyn_o, still_o, c_o, cdt_o, sdt_o,
     an_o) = scratch
    if smoother is not None:
        gains, dxs, smoother_gain, M, sub, Ls, inv, keep = smoother
    P = _unowned(P_owned)
    u, kv, g, nzc, dyn, still = (_unowned(u_o), _unowned(kv_o), _unowned(g_o), _unowned(nzc_o), _unowned(dyn_o),
                                 _unowned(still_o))
    c, cdt, sdt, a_n = _unowned(c_o), _unowned(cdt_o), _unowned(sdt_o), _unowned(an_o)
    nav, mems, m_idx, par, data = (_unowned(nav_owned), _unowned(mems_owned), _unowned(idx_owned),
                                   _unowned(par_owned), _unowned(data_owned))
    z, H, rdiag, dx, w, f = (_unowned(z_owned), _unowned(H_owned), _unowned(r_owned), _unowned(dx_owned),
                             _unowned(w_owned), _unowned(f_owned))
    for a in range(m_max):
        z[a] = 0.0
        rdiag[a] = 0.0
        for b in range(n):
            H[a, b] = 0.0
    # the rows of Φ − I that are not zero (pos; vel with att or acc_bias; att with gyro_bias), in
    # the order the in-place products need; the other rows and columns of P keep their values
    vel_moves = att >= 0 or ab_i >= 0
    att_moves = att >= 0 and gb_i >= 0
    n_dyn = 3 + (3 if vel_moves else 0) + (3 if att_moves else 0)
    for i in range(3):
        dyn[i] = pos_i + i
        if vel_moves:
            dyn[3 + i] = vel_i + i
        if att_moves:
            dyn[n_dyn - 3 + i] = att + i
    e = 0
    for i in range(n):
        moves = False
        for e2 in range(n_dyn):
            if dyn[e2] == i:
                moves = True
        if not moves:
            still[e] = i
            e += 1
    for i in range(4):
        quat[0, i] = nav[i]
    for i in range(3):
        pos[0, i] = nav[4 + i]
        vel[0, i] = nav[7 + i]
        if gb_i >= 0:  # without the block the estimate stays 0 (the caller's zeros)
            gb_out[0, i] = nav[10 + i]
        if ab_i >= 0:
            ab_out[0, i] = nav[13 + i]
        acc_nav[0, i] = 0.0
    if keep_p:
        for i in range(n):
            pdiag[0, i] = P[i, i]
    if record is not None:  # step-wise smoother: P⁺ of the incoming state
        record_covariance(record, 0, P)
    for k in range(1, N):
        if record is not None:  # step-wise smoother, whole recording: smooth the segment that ended at k − 1
            close_segment(record, k, stance, t, idx, use_ext, quat, vel, pos, gb_out, ab_out)
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
            dw, dx_, dy, dz = rotvec_quat(w[0] * dt, w[1] * dt, w[2] * dt)
            nav[0], nav[1], nav[2], nav[3] = quat_product(pw, px, py, pz, dw, dx_, dy, dz)
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
            a_n[i] = c[i, 0] * f[0] + c[i, 1] * f[1] + c[i, 2] * f[2]
        fn0, fn1, fn2 = a_n[0], a_n[1], a_n[2]
        a_n[2] += gravity
        for i in range(3):
            v_old = nav[7 + i]
            nav[7 + i] = v_old + a_n[i] * dt
            nav[4 + i] = nav[4 + i] + 0.5 * (v_old + nav[7 + i]) * dt
        # covariance prediction, eq. 44: P <- Φ P Φᵀ + Q with Φ = I + Δ and the blocks of Δ
        # (Nguyen & La eq. 33): Δ[att, gyro_bias] = C dt, Δ[pos, vel] = I dt,
        # Δ[vel, att] = −[f^n×] dt, Δ[vel, acc_bias] = C dt
        for i in range(3):
            for j in range(3):
                cdt[i, j] = dt * c[i, j]
        sdt[0, 0], sdt[0, 1], sdt[0, 2] = 0.0, dt * fn2, -dt * fn1
        sdt[1, 0], sdt[1, 1], sdt[1, 2] = -dt * fn2, 0.0, dt * fn0
        sdt[2, 0], sdt[2, 1], sdt[2, 2] = dt * fn1, -dt * fn0, 0.0
        if record is not None:  # step-wise smoother: Φ's blocks
            record_transition(record, k, dt, sdt, cdt)
        # Φ P in place, rows in the order pos (reads vel), vel (reads att, acc_bias), att (reads gyro_bias)
        for i in range(3):
            for j in range(n):
                P[pos_i + i, j] += dt * P[vel_i + i, j]
        for blk in range(3):  # P[r0:r0+3, :] += B P[c0:c0+3, :] for the 3×3 blocks B of Δ
            r0, c0, bm = (vel_i, att, sdt) if blk == 0 else (vel_i, ab_i, cdt) if blk == 1 else (att, gb_i, cdt)
            if r0 < 0 or c0 < 0:
                continue
            for i in range(3):
                b0, b1, b2 = bm[i, 0], bm[i, 1], bm[i, 2]
                for j in range(n):
                    P[r0 + i, j] += b0 * P[c0, j] + b1 * P[c0 + 1, j] + b2 * P[c0 + 2, j]
        if smoother is not None:  # M = Φ P⁺_{k−1}
            for i in range(n):
                for j in range(n):
                    M[i, j] = P[i, j]
        # (Φ P) Φᵀ in place, columns in the same order, on the moving rows. Φ P Φᵀ is symmetric:
        # of its moving block only the entries (dyn[e], dyn[e2]) with e ≤ e2 are computed (the
        # columns of the block dyn[b:b+3] on the rows dyn[:b+3]), then mirrored, as are the
        # other rows, which are those of Φ P
        for e in range(3):
            i = dyn[e]
            for j in range(3):
                P[i, pos_i + j] += dt * P[i, vel_i + j]
        for blk in range(3):  # P[i, r0:r0+3] += P[i, c0:c0+3] Bᵀ
            r0, c0, bm = (vel_i, att, sdt) if blk == 0 else (vel_i, ab_i, cdt) if blk == 1 else (att, gb_i, cdt)
            if r0 < 0 or c0 < 0:
                continue
            for e in range(6 if blk < 2 else n_dyn):
                i = dyn[e]
                x0, x1, x2 = P[i, c0], P[i, c0 + 1], P[i, c0 + 2]
                for j in range(3):
                    P[i, r0 + j] += x0 * bm[j, 0] + x1 * bm[j, 1] + x2 * bm[j, 2]
        for e in range(n_dyn):
            i = dyn[e]
            for e2 in range(n - n_dyn):
                j = still[e2]
                P[j, i] = P[i, j]
            for e2 in range(e + 1, n_dyn):
                j = dyn[e2]
                P[j, i] = P[i, j]
        for i in range(n):
            P[i, i] += qn[i] * dt
        if impact > 0.0:  # accelerometer errors that grow with the acceleration (heel strikes)
            qa = impact * (a_n[0] * a_n[0] + a_n[1] * a_n[1] + a_n[2] * a_n[2]) * dt
            for i in range(3):
                P[vel_i + i, vel_i + i] += qa
        if smoother is not None:  # P = P⁻_k
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
            # filterpy's update, K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form (eq. 45),
            # (I − KH) P (I − KH)ᵀ + K R Kᵀ, one row of H at a time: R is diagonal, so the rows are
            # independent measurements and updating with each in turn gives the same estimate and
            # covariance as the stacked update. For a row h with variance r: u = P hᵀ, s = h u + r,
            # k = u / s, dx ← dx + k (z − h dx) and P ← P − k uᵀ − g kᵀ with g = u − k s (symmetric:
            # whole rows are computed, the upper triangle mirrored after the last row), on the nonzero
            # entries of h
            for i in range(n):
                dx[i] = 0.0
            for a in range(m):
                cnt = 0
                for b in range(n):
                    if H[a, b] != 0.0:
                        nzc[cnt] = b
                        cnt += 1
                innov = z[a]
                for i in range(n):
                    u[i] = 0.0
                for e in range(cnt):
                    b = nzc[e]
                    h = H[a, b]
                    innov -= h * dx[b]
                    for i in range(n):  # P is symmetric up to rounding
                        u[i] += P[b, i] * h
                hu = 0.0
                for e in range(cnt):
                    b = nzc[e]
                    hu += H[a, b] * u[b]
                s_ = hu + rdiag[a]
                for i in range(n):
                    kv[i] = u[i] / s_
                if record is not None:  # step-wise smoother: the row, its gain, ν / s
                    record_row(record, k, H[a], kv, innov / s_)
                for e in range(cnt):
                    H[a, nzc[e]] = 0.0  # leave H all zero for the next sample
                for i in range(n):
                    g[i] = u[i] - kv[i] * s_
                    dx[i] += kv[i] * innov
                for i in range(n):
                    ki, gi = kv[i], g[i]
                    for j in range(n):  # whole rows (faster than the triangle: full vectors)
                        P[i, j] -= ki * u[j] + gi * kv[j]
            for i in range(n):
                for j in range(i + 1, n):
                    P[j, i] = P[i, j]
            # feedback, eqs. 49-52: q <- exp(−δφ) ⊗ q, p <- p − δp, v <- v − δv, b <- b + δb
            if att >= 0 and not use_ext:
                feed_back_attitude(nav, dx[att], dx[att + 1], dx[att + 2])
            for i in range(3):
                nav[4 + i] -= dx[pos_i + i]
                nav[7 + i] -= dx[vel_i + i]
                if gb_i >= 0:
                    nav[10 + i] += dx[gb_i + i]
                if ab_i >= 0:
                    nav[13 + i] += dx[ab_i + i]
            for j in range(len(feedbacks)):
                if hooks[j, 0]:
                    feedbacks[j](dx, m_idx[j], par[par_off[j]:par_off[j + 1]], mems[mem_off[j]:mem_off[j + 1]])
            if smoother is not None:
                for i in range(n):
                    dxs[k, i] = dx[i]
        for j in range(len(afters)):
            if hooks[j, 1]:
                afters[j](k0 + k, nav, st, m_idx[j], par[par_off[j]:par_off[j + 1]], mems[mem_off[j]:mem_off[j + 1]])
        for i in range(4):
            quat[k, i] = nav[i]
        for i in range(3):
            pos[k, i] = nav[4 + i]
            vel[k, i] = nav[7 + i]
            if gb_i >= 0:
                gb_out[k, i] = nav[10 + i]
            if ab_i >= 0:
                ab_out[k, i] = nav[13 + i]
            acc_nav[k, i] = a_n[i]
        if keep_p:
            for i in range(n):
                pdiag[k, i] = P[i, i]
        if record is not None:  # step-wise smoother: P⁺_k
            record_covariance(record, k, P)


def scratch(n: int, m_max: int) -> tuple:
    """The buffers of :func:`eskf_loop`, allocated by the caller (so they outlive the views of them).

    ``z`` (m_max,), ``H`` (m_max, n), ``R`` (m_max,), ``dx`` (n,), ``w``, ``f`` (3,): handed to the
    models' functions; ``u``, ``k``, ``g`` (n,); nonzero columns, moving and still rows (n,) int;
    ``C``, ``C dt``, ``−[f^n×] dt`` (3, 3) and ``a_n`` (3,).
    """
    i8 = np.int64
    return (np.zeros(m_max), np.zeros((m_max, n)), np.zeros(m_max), np.zeros(n), np.zeros(3), np.zeros(3),
            np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, i8), np.zeros(n, i8), np.zeros(n, i8), np.zeros((3, 3)),
            np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3))


def smoother_arrays(gains: np.ndarray, dxs: np.ndarray, gain: Any) -> tuple:
    """The ``smoother`` argument of :func:`eskf_loop`: its outputs, gain function and work arrays.

    ``gains`` (N, n, n) and ``dxs`` (N, n) receive the smoother's gains and the fed-back errors;
    ``gain`` is :func:`footzoo.filters.smoother.smoother_gain`, compiled on its own; then ``M``
    and the gain function's work arrays, (n, n) ×4 and (n,) int.
    """
    n = dxs.shape[1]
    return (gains, dxs, gain, np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
            np.zeros(n, np.int64))
