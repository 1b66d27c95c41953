"""Compiled sample loop of the error-state Kalman filter.

The same equations as :func:`footzoo.filters.kalman_reference.run_reference`
(the reference, on filterpy's ``KalmanFilter``), with every correction's
measurement model called through its compiled functions (the contract is in
:mod:`footzoo.filters.measurement`); this module knows no correction.

:func:`eskf_loop` runs, for each sample, the named steps below (each inlined by
numba into the loop): :func:`propagate` (the nominal state, Nguyen & La eqs.
37–40), :func:`predict_covariance` (eq. 44), :func:`measure` (the corrections'
rows, stacked), :func:`update_row` for each row (eq. 45), :func:`feed_back`
(eqs. 49–52) and :func:`store`.

The covariance prediction works in place on the nonzero blocks of Φ = I + Δ
(the rows of Φ P, then the columns of the rows that move, mirrored: P stays
exactly symmetric); the update is filterpy's, in the Joseph form, taking the
rows of H one at a time (R is diagonal) and touching only their nonzero
entries. Every array the models' functions get is a view that owns no
reference, so a call costs no reference counting. The loop allocates nothing:
its buffers (:func:`scratch`) and outputs are the caller's. A test keeps both
engines equal to 1e-9 relative.

Never trusting a model: each ``measure`` gets ``z``, ``H`` and ``R`` cut at the
rows its model declared (``max_rows``), and a plug-in's functions are compiled
with bounds checks (:mod:`footzoo.kernels.functions`), so no write lands outside
them; a ``measure`` that returns a row count outside ``[m, m + max_rows]`` stops
the model, the count and the sample in ``fault`` (the engine
raises it as the plug-in's :class:`~footzoo.core.errors.PluginError`).

The arguments of :func:`eskf_loop`:

``signals``
    ``(t (N,) s, acc (N, 3) m/s², gyr (N, 3) rad/s, stance (N,) bool, quat_ext (N or 1, 4))``;
    sample 0 is the one ``state`` belongs to.
``core``
    ``(idx (5,) int: offsets of att, gyro_bias, pos, vel, acc_bias, −1 if absent (in the
    order of :data:`~footzoo.filters.measurement.CORE_BLOCKS`); q (n,) variance growth per
    second; gravity m/s²; use_ext bool: attitude from quat_ext; m_max int: most rows of one
    update; impact s: velocity variance growth per squared motion acceleration; integration κ (1):
    velocity σ per sample per ``|Δf| dt``, :mod:`~footzoo.filters.velocity_noise`)``.
``state``
    ``(nav (16,): the nominal state, offsets Q, P, V, BG, BA of
    :mod:`~footzoo.filters.measurement`; P (n, n) covariance; mems (s,) all models' memory)``.
``models``
    ``(functions, arrays)``: ``functions = (measures, feedbacks, afters)``, the corrections'
    functions in stacking order; ``arrays = (idx (L, w) int, par, par_off (L+1,), mem_off
    (L+1,), data (N, d), data_off (L+1,), hooks (L, 2) int: model j has a feedback / an after
    function, rows (L,) int: each model's max_rows)``.
``out``
    ``(quat (N, 4), vel, pos, acc_nav, gyro_bias, acc_bias (N, 3), P_diag (N or 0, n), nis (N or
    0, 2))``; row 0 receives the incoming state. A bias without its error-state block stays zero
    and is not written: pass zeros. ``P_diag`` with 0 rows is not written, nor is ``nis``: per
    sample, the normalised innovation squared of its update, ``Σ_a ν_a² / s_a`` over the scalar
    rows (equal to the stacked ``νᵀ S⁻¹ ν``: R is diagonal), and the number of rows.
``k0``
    Index of sample 0 in the whole recording (a stream passes its running count).
``work``
    The loop's buffers, from :func:`scratch` (any content); its last, ``fault`` (3,) int, is
    ``(model, rows returned − m, sample)`` after a model broke its row count, ``(−1, 0, 0)``
    otherwise.
``record``
    For a smoother (:mod:`footzoo.filters.stepwise`: step-wise, or RTS over the whole recording), from
    :func:`footzoo.filters.smoother.record_arrays` with a row per sample: each sample's
    ``P⁺``, Φ's blocks and update rows are written (made ``in_loop``: each segment is smoothed
    in place as soon as it has closed, the last one left to the caller). For the RTS smoother in
    bounded memory (:mod:`footzoo.filters.checkpointed`): no rows, the state where each piece
    starts (mode ``CHECKPOINTS``: the forward pass), or the pieces a ``REPLAY`` record names, each
    run again from its checkpoint to its last update with a row per sample and no output written
    (``signals`` are then the whole recording's). ``None``: compiled without that code.
"""

from __future__ import annotations

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import unowned
from .measurement import ACC_BIAS, ATT, BA, BG, GYRO_BIAS, POS, VEL, P, Q, V
from .smoother import (
    CHECKPOINTS,
    REPLAY,
    feed_back_attitude,
    mark_update,
    record_covariance,
    record_row,
    record_transition,
    start_piece,
    take_checkpoint,
    unowned_record,
)
from .stepwise import close_segment
from .strapdown import mid_rotation, quat_product, rotvec_quat
from .velocity_noise import signal_velocity_variance


@njit
def eskf_loop(signals, core, state, models, out, k0, work, record):
    """Run samples 1… of ``signals`` from ``state`` (updated in place); outputs into ``out``.

    The arguments are described in the module docstring. When a model's ``measure`` returns a row
    count it did not declare, ``work``'s ``fault`` says which, where and how many.
    """
    # every array as a view that owns no reference (they are the caller's arguments, alive during the
    # whole call): handing them to the models' functions and to the inlined steps costs no
    # reference counting
    t, acc, gyr, stance, quat_ext = signals
    idx, qn, gravity, use_ext, m_max, impact, integration = core
    idx, qn = unowned(idx), unowned(qn)
    # the core blocks' offsets as integers, read once: the steps index P with them, and a store into P
    # cannot change an integer (as it could an array's entry), so the compiler keeps them in registers
    offs = (idx[ATT], idx[GYRO_BIAS], idx[POS], idx[VEL], idx[ACC_BIAS])
    functions, arrays = models
    nav_owned, P_owned, mems_owned = state
    n = P_owned.shape[0]
    keep_p = out[6].shape[0] == t.shape[0]
    z, H, rdiag, dx, w, f, u, kv, g, nzc, dyn, still, c, cdt, sdt, a_n, f_n, fault = work
    z, H, rdiag, dx, w, f = unowned(z), unowned(H), unowned(rdiag), unowned(dx), unowned(w), unowned(f)
    u, kv, g, nzc, dyn, still = unowned(u), unowned(kv), unowned(g), unowned(nzc), unowned(dyn), unowned(still)
    c, cdt, sdt, a_n, f_n = unowned(c), unowned(cdt), unowned(sdt), unowned(a_n), unowned(f_n)
    Pk, nav, mems = unowned(P_owned), unowned(nav_owned), unowned(mems_owned)
    m_idx, par, par_off, mem_off, data, data_off, hooks, rows = arrays
    data = unowned(data)
    views = (unowned(m_idx), unowned(par), unowned(par_off), unowned(mem_off), unowned(data_off), unowned(hooks),
             unowned(rows))
    fault[0], fault[1], fault[2] = -1, 0, 0
    rows_kept = False  # a record of the rows of every sample, or of the checkpoints only (read once)
    replaying = False  # the pieces of a record's checkpoints run again, each from its own
    j_lo, j_hi = 0, 1  # one piece: samples 0 … N − 1 from ``state``
    if record is not None:  # a smoother's record, its arrays as views that own no reference too
        rec = unowned_record(record)
        rows_kept, replaying = rec[5][0] != CHECKPOINTS, rec[5][0] == REPLAY
        if replaying:
            j_lo, j_hi = rec[5][2], rec[5][3]
    z[:m_max], rdiag[:m_max], H[:m_max] = 0.0, 0.0, 0.0
    n_dyn = moving_rows(offs, n, dyn, still)
    for piece in range(j_lo, j_hi):
        lo, hi = 0, t.shape[0] - 1
        if record is not None and replaying:  # from its checkpoint to its last update; no output written
            lo, hi = start_piece(rec, piece, nav, Pk, mems)
        else:
            store(0, nav, a_n, Pk, offs, out, keep_p, True, 0.0, 0)
        if record is not None and rows_kept:  # smoother: P⁺ of the incoming state
            record_covariance(rec, lo, Pk)
        for k in range(lo + 1, hi + 1):
            if record is not None and rows_kept:  # step-wise smoother, whole recording: smooth the segment that ended
                close_segment(rec, k, stance, t, idx, use_ext, out[0], out[1], out[2], out[4], out[5])
            elif record is not None:  # RTS in bounded memory: the state where a piece starts
                take_checkpoint(rec, k, stance, nav, Pk, mems)
            dt = t[k] - t[k - 1]
            propagate(nav, acc, gyr, quat_ext, k, use_ext, dt, gravity, w, f, c, a_n, f_n)
            for i in range(3):
                for j in range(3):
                    cdt[i, j] = dt * c[i, j]
            sdt[0, 0], sdt[0, 1], sdt[0, 2] = 0.0, dt * f_n[2], -dt * f_n[1]
            sdt[1, 0], sdt[1, 1], sdt[1, 2] = -dt * f_n[2], 0.0, dt * f_n[0]
            sdt[2, 0], sdt[2, 1], sdt[2, 2] = dt * f_n[1], -dt * f_n[0], 0.0
            if record is not None and rows_kept:  # smoother: Φ's blocks
                record_transition(rec, k, dt, sdt, cdt)
            propagate_rows(Pk, offs, dt, sdt, cdt)
            propagate_columns(Pk, offs, dt, sdt, cdt, dyn, still, n_dyn)
            add_process_noise(Pk, offs, qn, signal_velocity_variance(impact, integration, a_n, acc, k, dt), dt)
            st = stance[k]
            m = measure(functions[0], views, k0 + k, t[k], nav, w, f, st, mems, data[k], z, H, rdiag, fault)
            nis = 0.0
            if m > 0:
                for i in range(n):
                    dx[i] = 0.0
                for a in range(m):
                    cnt, scaled, innov = update_row(Pk, z, H, rdiag, a, dx, u, kv, g, nzc)
                    nis += innov * scaled
                    if record is not None and rows_kept:  # smoother: the row, its gain, ν / s
                        record_row(rec, k, H[a], kv, scaled)
                    for e in range(cnt):
                        H[a, nzc[e]] = 0.0  # leave H all zero for the next sample
                for i in range(n):
                    for j in range(i + 1, n):
                        Pk[j, i] = Pk[i, j]
                feed_back(nav, dx, offs, use_ext, functions[1], views, mems, k0 + k, t[k], w, f, st, data[k])
                if record is not None and not rows_kept:  # RTS in bounded memory: the piece's updates reach here
                    mark_update(rec, k)
            after(functions[2], views, k0 + k, t[k], nav, w, f, st, mems, data[k])
            if not replaying:
                store(k, nav, a_n, Pk, offs, out, keep_p, False, nis, m)
            if record is not None and rows_kept:  # smoother: P⁺_k
                record_covariance(rec, k, Pk)


@njit(inline=True)
def moving_rows(offs, n, dyn, still):
    """The rows of Φ − I that are not zero into ``dyn``, the others into ``still``; returns their count.

    pos; vel with att or acc_bias; att with gyro_bias — in the order the in-place products need;
    the other rows and columns of P keep their values.
    """
    att, gb_i, pos_i, vel_i, ab_i = offs
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
    return n_dyn


@njit(inline=True)
def propagate(nav, acc, gyr, quat_ext, k, use_ext, dt, gravity, w, f, c, a_n, f_n):
    """The nominal state over sample ``k``, in place (Nguyen & La eqs. 37–40).

    ``w``, ``f``: bias-corrected rate and specific force; ``c``: the body → NED rotation at the
    middle of the interval; ``f_n``: the specific force in NED; ``a_n``: the motion acceleration.
    """
    for i in range(3):
        w[i] = gyr[k, i] - nav[BG + i]
        f[i] = acc[k, i] - nav[BA + i]
    pw, px, py, pz = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    if use_ext:
        for i in range(4):
            nav[Q + i] = quat_ext[k, i]
    else:
        # q ⊗ exp(w dt), the exact form of Nguyen & La eq. 37
        dw, dx_, dy, dz = rotvec_quat(w[0] * dt, w[1] * dt, w[2] * dt)
        nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3] = quat_product(pw, px, py, pz, dw, dx_, dy, dz)
    mid_rotation(pw, px, py, pz, nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3], c)
    for i in range(3):
        a_n[i] = c[i, 0] * f[0] + c[i, 1] * f[1] + c[i, 2] * f[2]
        f_n[i] = a_n[i]
    a_n[2] += gravity
    for i in range(3):
        v_old = nav[V + i]
        nav[V + i] = v_old + a_n[i] * dt
        nav[P + i] = nav[P + i] + 0.5 * (v_old + nav[V + i]) * dt


@njit(inline=True)
def propagate_rows(Pk, offs, dt, sdt, cdt):
    """``P ← Φ P`` in place (the first half of eq. 44), on the rows of Φ − I that are not zero.

    The blocks of Δ = Φ − I (Nguyen & La eq. 33): Δ[att, gyro_bias] = C dt, Δ[pos, vel] = I dt,
    Δ[vel, att] = −[f^n×] dt, Δ[vel, acc_bias] = C dt; rows in the order pos (reads vel), vel
    (reads att, acc_bias), att (reads gyro_bias).
    """
    att, gb_i, pos_i, vel_i, ab_i = offs
    n = Pk.shape[0]
    for i in range(3):
        for j in range(n):
            Pk[pos_i + i, j] += dt * Pk[vel_i + i, j]
    for blk in range(3):  # P[r0:r0+3, :] += B P[c0:c0+3, :] for the 3×3 blocks B of Δ
        r0, c0, bm = (vel_i, att, sdt) if blk == 0 else (vel_i, ab_i, cdt) if blk == 1 else (att, gb_i, cdt)
        if r0 < 0 or c0 < 0:
            continue
        for i in range(3):
            b0, b1, b2 = bm[i, 0], bm[i, 1], bm[i, 2]
            for j in range(n):
                Pk[r0 + i, j] += b0 * Pk[c0, j] + b1 * Pk[c0 + 1, j] + b2 * Pk[c0 + 2, j]


@njit(inline=True)
def propagate_columns(Pk, offs, dt, sdt, cdt, dyn, still, n_dyn):
    """``(Φ P) Φᵀ`` in place, columns in the order of :func:`propagate_rows`, on the moving rows.

    Φ P Φᵀ is symmetric: of its moving block only the entries (dyn[e], dyn[e2]) with e ≤ e2 are
    computed (the columns of the block dyn[b:b+3] on the rows dyn[:b+3]), then mirrored, as are
    the other rows, which are those of Φ P.
    """
    att, gb_i, pos_i, vel_i, ab_i = offs
    n = Pk.shape[0]
    for e in range(3):
        i = dyn[e]
        for j in range(3):
            Pk[i, pos_i + j] += dt * Pk[i, vel_i + j]
    for blk in range(3):  # P[i, r0:r0+3] += P[i, c0:c0+3] Bᵀ
        r0, c0, bm = (vel_i, att, sdt) if blk == 0 else (vel_i, ab_i, cdt) if blk == 1 else (att, gb_i, cdt)
        if r0 < 0 or c0 < 0:
            continue
        for e in range(6 if blk < 2 else n_dyn):
            i = dyn[e]
            x0, x1, x2 = Pk[i, c0], Pk[i, c0 + 1], Pk[i, c0 + 2]
            for j in range(3):
                Pk[i, r0 + j] += x0 * bm[j, 0] + x1 * bm[j, 1] + x2 * bm[j, 2]
    for e in range(n_dyn):
        i = dyn[e]
        for e2 in range(n - n_dyn):
            j = still[e2]
            Pk[j, i] = Pk[i, j]
        for e2 in range(e + 1, n_dyn):
            j = dyn[e2]
            Pk[j, i] = Pk[i, j]


@njit(inline=True)
def add_process_noise(Pk, offs, qn, qv, dt):
    """``P ← P + Q dt`` (the second half of eq. 44), plus ``qv`` on each velocity axis.

    ``qv`` ((m/s)²): the sample's velocity noise that follows the signals (impacts, the integration
    over the interval: :func:`footzoo.filters.velocity_noise.signal_velocity_variance`).
    """
    for i in range(Pk.shape[0]):
        Pk[i, i] += qn[i] * dt
    if qv > 0.0:
        vel = offs[VEL]
        for i in range(3):
            Pk[vel + i, vel + i] += qv


@njit(inline=True)
def measure(measures, views, k, t_k, nav, w, f, st, mems, data_k, z, H, rdiag, fault):
    """The corrections' measurement rows of sample ``k`` (``data_k``: its row of inputs), stacked; returns their count.

    Each model gets ``z``, ``H`` and ``R`` cut at the rows it declared. A model whose ``measure``
    returns fewer rows than it was given or more than it declared is refused: the rows before it
    are kept, the first such fault is written to ``fault`` (the loop runs on, cheaper than a loop
    that can stop early; the engine then raises it).
    """
    m_idx, par, par_off, mem_off, data_off, hooks, rows = views
    m = 0
    for j in range(len(measures)):
        top = m + rows[j]
        m_new = measures[j](k, t_k, nav, w, f, st, m_idx[j], par[par_off[j]:par_off[j + 1]],
                            mems[mem_off[j]:mem_off[j + 1]], data_k[data_off[j]:data_off[j + 1]], z[:top], H[:top],
                            rdiag[:top], m)
        if m_new < m or m_new > top:  # refused; the first such fault is kept for the engine to raise
            if fault[0] < 0:
                fault[0], fault[1], fault[2] = j, m_new - m, k
            return m
        m = m_new
    return m


@njit(inline=True)
def update_row(Pk, z, H, rdiag, a, dx, u, kv, g, nzc):
    """filterpy's update with row ``a`` of the stacked measurement; returns its nonzero count, ν / s and ν.

    K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form (eq. 45), (I − KH) P (I − KH)ᵀ + K R Kᵀ, one row
    of H at a time: R is diagonal, so the rows are independent measurements and updating with
    each in turn gives the same estimate and covariance as the stacked update. For a row h with
    variance r: u = P hᵀ, s = h u + r, k = u / s, dx ← dx + k (z − h dx) and
    P ← P − k uᵀ − g kᵀ with g = u − k s, on the nonzero entries of h (their columns in ``nzc``;
    whole rows are computed, the upper triangle is mirrored by the caller after the last row).
    """
    n = Pk.shape[0]
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
            u[i] += Pk[b, i] * h
    hu = 0.0
    for e in range(cnt):
        b = nzc[e]
        hu += H[a, b] * u[b]
    s_ = hu + rdiag[a]
    for i in range(n):
        kv[i] = u[i] / s_
    for i in range(n):
        g[i] = u[i] - kv[i] * s_
        dx[i] += kv[i] * innov
    for i in range(n):
        ki, gi = kv[i], g[i]
        for j in range(n):  # whole rows (faster than the triangle: full vectors)
            Pk[i, j] -= ki * u[j] + gi * kv[j]
    return cnt, innov / s_, innov


@njit(inline=True)
def feed_back(nav, dx, offs, use_ext, feedbacks, views, mems, k, t_k, w, f, st, data_k):
    """The estimated error into the nominal state, eqs. 49–52, then into each model's memory.

    q ← exp(−δφ) ⊗ q, p ← p − δp, v ← v − δv, b ← b + δb. The models' ``feedback`` get sample ``k``
    (its corrected state; ``w`` and ``f`` as their ``measure`` got them).
    """
    m_idx, par, par_off, mem_off, data_off, hooks, rows = views
    att, gb_i, pos_i, vel_i, ab_i = offs
    if att >= 0 and not use_ext:
        feed_back_attitude(nav, dx[att], dx[att + 1], dx[att + 2])
    for i in range(3):
        nav[P + i] -= dx[pos_i + i]
        nav[V + i] -= dx[vel_i + i]
        if gb_i >= 0:
            nav[BG + i] += dx[gb_i + i]
        if ab_i >= 0:
            nav[BA + i] += dx[ab_i + i]
    for j in range(len(feedbacks)):
        if hooks[j, 0]:
            feedbacks[j](k, t_k, nav, w, f, st, m_idx[j], par[par_off[j]:par_off[j + 1]],
                         mems[mem_off[j]:mem_off[j + 1]], data_k[data_off[j]:data_off[j + 1]], dx)


@njit(inline=True)
def after(afters, views, k, t_k, nav, w, f, st, mems, data_k):
    """Each model's ``after`` function, once per sample after the update (bookkeeping on the corrected state)."""
    m_idx, par, par_off, mem_off, data_off, hooks, rows = views
    for j in range(len(afters)):
        if hooks[j, 1]:
            afters[j](k, t_k, nav, w, f, st, m_idx[j], par[par_off[j]:par_off[j + 1]],
                      mems[mem_off[j]:mem_off[j + 1]], data_k[data_off[j]:data_off[j + 1]])


@njit(inline=True)
def store(k, nav, a_n, Pk, offs, out, keep_p, first, nis_k, rows_k):
    """Sample ``k``'s estimates into the outputs (the motion acceleration of the incoming state: 0).

    With the covariance kept, also its diagonal and the update's NIS and rows.
    """
    quat, vel, pos, acc_nav, gb_out, ab_out, pdiag, nis = out
    for i in range(4):
        quat[k, i] = nav[Q + i]
    for i in range(3):
        pos[k, i] = nav[P + i]
        vel[k, i] = nav[V + i]
        if offs[GYRO_BIAS] >= 0:  # without the block the estimate stays 0 (the caller's zeros)
            gb_out[k, i] = nav[BG + i]
        if offs[ACC_BIAS] >= 0:
            ab_out[k, i] = nav[BA + i]
        acc_nav[k, i] = 0.0 if first else a_n[i]
    if keep_p:
        for i in range(Pk.shape[0]):
            pdiag[k, i] = Pk[i, i]
        nis[k, 0] = nis_k
        nis[k, 1] = rows_k


def scratch(n: int, m_max: int) -> tuple:
    """The buffers of :func:`eskf_loop`, allocated by the caller (so they outlive the views of them).

    ``z`` (m_max,), ``H`` (m_max, n), ``R`` (m_max,), ``dx`` (n,), ``w``, ``f`` (3,): handed to the
    models' functions; ``u``, ``k``, ``g`` (n,); nonzero columns, moving and still rows (n,) int;
    ``C``, ``C dt``, ``−[f^n×] dt`` (3, 3), ``a_n`` and ``f_n`` (3,); ``fault`` (3,) int.
    """
    i8 = np.int64
    return (np.zeros(m_max), np.zeros((m_max, n)), np.zeros(m_max), np.zeros(n), np.zeros(3), np.zeros(3),
            np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, i8), np.zeros(n, i8), np.zeros(n, i8), np.zeros((3, 3)),
            np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3), np.zeros(3), np.full(3, -1, i8))

