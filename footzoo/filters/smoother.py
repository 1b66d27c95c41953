"""Rauch–Tung–Striebel smoothing of the closed-loop error-state filter, without a gain or an inverse.

The forward pass is unchanged; it keeps a record of what the backward pass needs
(:mod:`footzoo.filters.recorders`). Because the closed-loop filter feeds its error estimate back and resets
it to zero after every update, the backward pass of the RTS smoother (Rauch, Tung & Striebel
1965) for a span that ends at sample ``s`` reduces to

    e_s = 0,    e_{k−1} = A_{k−1} (e_k + δx̂_k),    A_{k−1} = P⁺_{k−1} Φ_kᵀ (P⁻_k)⁻¹,

``e_k`` being the smoothed error of the forward estimate at sample k and ``δx̂_k`` the error its
update fed back. ``e_k`` is applied as the feedback is (``p ← p − e_p``, ``v ← v − e_v``,
``q ← exp(−e_φ) ⊗ q``, ``b ← b + e_b``: :func:`correct_sample`). This is the error-state form of
the smoother that gaitmap's ``RtsKalman`` and OpenShoe's smoothed ZUPT filters run.

The recursion is evaluated without forming the gain — no inverse or factorisation of ``P⁻`` —
by carrying ``λ_k = (P⁻_k)⁻¹ (e_k + δx̂_k)`` backwards (the Bryson–Frazier form of the same
recursion; Bierman 1973)::

    λ ← 0                                      (at k = s: e_s = 0, before the update of s)
    λ ← λ + h_aᵀ (ν_a / s_a − k_aᵀ λ)          for the update rows a of sample k, last first
    μ = Φ_kᵀ λ                                 (= (P⁺_{k−1})⁻¹ e_{k−1})
    e_{k−1} = P⁺_{k−1} μ,   λ ← μ

with each scalar update row's ``h_a`` (1, n), gain ``k_a = P h_aᵀ / s_a``, innovation ``ν_a``
and its variance ``s_a`` (the compiled loop updates with one row at a time; the reference engine
records filterpy's stacked update as the same scalar rows). Because ``P⁺ = (I − K H) P⁻`` and
``K = P⁻ Hᵀ S⁻¹``, ``(P⁻_k)⁻¹ (P⁺_k μ + K_k y_k) = (I − K_k H_k)ᵀ μ + H_kᵀ S_k⁻¹ y_k``: the
recursion is exactly the RTS one, and states without variance (the position before the first
step) need no special case. Per sample it costs a few products of n-vectors, where forming the
gain took a Cholesky factorisation of ``P⁻`` and n triangular solves (8× the forward pass).

Two smoothers run it (:mod:`footzoo.filters.smoothing`): ``smoother: rts``, over the whole
recording as one segment ending at its last sample (offline: the compiled engine keeps checkpoints
and makes the record again where the filter was updated, :mod:`footzoo.filters.checkpointed`, its
pieces read by :func:`smooth_span`, the samples without an update in closed form by
:func:`smooth_free_span`; the reference engine keeps the record of every sample,
:func:`smooth_segments` with that one end), and ``smoother: stepwise``
(:mod:`footzoo.filters.stepwise`), over each stride as it closes.

What is kept per sample (a :class:`~footzoo.filters.structures.Record`)
    ``P⁺_k`` (n × n, its upper triangle), Φ_k's blocks (``dt``, ``−[f^n×] dt``, ``C dt``; Nguyen &
    La eq. 33, as :func:`footzoo.filters.eskf.transition`), and the update rows (``h``, ``k``,
    ``ν/s``, only the rows there are), written by the compiled loop
    (:mod:`footzoo.filters.recorders`) or the reference engine: about 1 kB per sample at 9 states.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import unowned
from .process_noise import unowned_noise, velocity_variance
from .strapdown import mid_rotation, quat_product, rotvec_quat
from .structures import ForwardPass, Record, Trajectory, Transitions, UpdateRows


@njit(inline=True)
def unowned_record(rec):
    """A :class:`~footzoo.filters.structures.Record` of views that own no reference."""
    tr, rows = rec.transitions, rec.rows
    return Record(unowned(rec.cov), Transitions(unowned(tr.dt), unowned(tr.skew_dt), unowned(tr.c_dt)),
                  UpdateRows(unowned(rows.h), unowned(rows.gain), unowned(rows.scaled), unowned(rows.nu),
                             unowned(rows.s)),
                  unowned(rec.first), unowned(rec.count), unowned(rec.offset))


@njit(inline=True)
def unowned_trajectory(traj):
    """A :class:`~footzoo.filters.structures.Trajectory` of views that own no reference."""
    return Trajectory(unowned(traj.quat), unowned(traj.vel), unowned(traj.pos), unowned(traj.gyro_bias),
                      unowned(traj.acc_bias))


@njit(inline=True)
def transition_transposed(tr, r, offs, lam, out):
    """``out = Φᵀ λ`` for Φ = I + Δ with the blocks of Nguyen & La eq. 33 (row ``r`` of ``tr``).

    Δ[pos, vel] = I dt, Δ[vel, att] = −[f^n×] dt, Δ[vel, acc_bias] = C dt, Δ[att, gyro_bias] = C dt.
    """
    att, gb_i, pos_i, vel_i, ab_i = offs.att, offs.gyro_bias, offs.pos, offs.vel, offs.acc_bias
    for i in range(lam.shape[0]):
        out[i] = lam[i]
    dt = tr.dt[r]
    for j in range(3):
        out[vel_i + j] += dt * lam[pos_i + j]
    if att >= 0:
        sk = tr.skew_dt
        for j in range(3):
            out[att + j] += sk[r, 0, j] * lam[vel_i] + sk[r, 1, j] * lam[vel_i + 1] + sk[r, 2, j] * lam[vel_i + 2]
    cd = tr.c_dt
    if ab_i >= 0:
        for j in range(3):
            out[ab_i + j] += cd[r, 0, j] * lam[vel_i] + cd[r, 1, j] * lam[vel_i + 1] + cd[r, 2, j] * lam[vel_i + 2]
    if att >= 0 and gb_i >= 0:
        for j in range(3):
            out[gb_i + j] += cd[r, 0, j] * lam[att] + cd[r, 1, j] * lam[att + 1] + cd[r, 2, j] * lam[att + 2]


@njit
def smooth_segment(rec, lo, hi, off, offs, use_ext, traj, lam, mu, e):
    """Smooth samples ``lo … hi − 1`` of ``traj`` in place, the segment ending at ``hi`` (``e_hi = 0``).

    ``rec`` (:class:`~footzoo.filters.structures.Record`) holds samples ``lo … hi``, sample k in its
    row ``k − off``; ``lam``, ``mu``, ``e`` (n,) are work arrays.
    """
    for i in range(lam.shape[0]):
        lam[i] = 0.0
    smooth_span(rec, lo, hi, off, offs, use_ext, traj, lam, mu, e)


@njit
def smooth_span(rec, lo, hi, off, offs, use_ext, traj, lam, mu, e):
    """:func:`smooth_segment`'s recursion over samples ``lo … hi − 1``, from the ``λ`` given (updated in place).

    ``λ`` comes from the samples after ``hi`` (zero at the end of a segment): the record of a
    long span can so be read in consecutive pieces, the last first, each ending where the next
    begins (:mod:`footzoo.filters.checkpointed`); the update of sample ``hi`` is in this piece.
    """
    # views that own no reference (the arguments outlive the call): the recursion reads and corrects them
    # at every sample, and reference counts there would cost more than the recursion itself
    rec, traj = unowned_record(rec), unowned_trajectory(traj)
    cov, rows, first, count = rec.cov, rec.rows, rec.first, rec.count
    h, gain, scaled = rows.h, rows.gain, rows.scaled
    lam, mu, e = unowned(lam), unowned(mu), unowned(e)
    n = lam.shape[0]
    for j_ in range(hi - off, lo - off, -1):
        k = j_ + off
        for r in range(first[j_] + count[j_] - 1, first[j_] - 1, -1):  # the update of sample k, last row first
            kl = 0.0
            for i in range(n):
                kl += gain[r, i] * lam[i]
            c = scaled[r] - kl
            for i in range(n):
                lam[i] += h[r, i] * c
        transition_transposed(rec.transitions, j_, offs, lam, mu)
        packed_times(cov, j_ - 1, mu, e)  # e_{k−1} = P⁺_{k−1} μ
        correct_sample(k - 1, e, offs, use_ext, traj)
        for i in range(n):
            lam[i] = mu[i]


@njit(inline=True)
def packed_times(cov, r, mu, e):
    """``e = P μ`` for the symmetric P kept as row ``r`` of ``cov``, its upper triangle (row by row)."""
    n = mu.shape[0]
    for i in range(n):
        e[i] = 0.0
    a = 0
    for i in range(n):
        mi = mu[i]
        e[i] += cov[r, a] * mi
        a += 1
        for j in range(i + 1, n):
            p = cov[r, a]
            e[i] += p * mu[j]
            e[j] += p * mi
            a += 1


@njit(inline=True)
def transition_row(fwd, k, gravity, with_c, c, tr, r):
    """Φ_k's blocks of a sample into row ``r`` of ``tr``, as the loop made them, from the forward pass's outputs.

    ``fwd`` (:class:`~footzoo.filters.structures.ForwardPass`): ``dt = t_k − t_{k−1}``; ``−[f^n×] dt``
    from the specific force in NED, ``acc_nav[k] − [0, 0, g]`` (``acc_nav`` is the loop's motion
    acceleration ``f^n + [0, 0, g]``); ``C dt`` (only ``with_c``: a bias block reads it) from the
    attitudes ``quat[k − 1]``, ``quat[k]`` (the forward pass's, before smoothing) as the loop's
    :func:`~footzoo.filters.strapdown.mid_rotation`; ``c`` (3, 3) work.
    """
    t, quat, acc_nav = fwd.t, fwd.quat, fwd.acc_nav
    dt = t[k] - t[k - 1]
    fx, fy, fz = acc_nav[k, 0], acc_nav[k, 1], acc_nav[k, 2] - gravity
    sk = tr.skew_dt
    tr.dt[r] = dt
    sk[r, 0, 0], sk[r, 0, 1], sk[r, 0, 2] = 0.0, dt * fz, -dt * fy
    sk[r, 1, 0], sk[r, 1, 1], sk[r, 1, 2] = -dt * fz, 0.0, dt * fx
    sk[r, 2, 0], sk[r, 2, 1], sk[r, 2, 2] = dt * fy, -dt * fx, 0.0
    if with_c:
        mid_rotation(quat[k - 1, 0], quat[k - 1, 1], quat[k - 1, 2], quat[k - 1, 3], quat[k, 0], quat[k, 1],
                     quat[k, 2], quat[k, 3], c)
        for i in range(3):
            for j in range(3):
                tr.c_dt[r, i, j] = dt * c[i, j]


@njit(inline=True)
def transition_apply(tr, r, offs, e):
    """``e ← Φ e`` in place for Φ = I + Δ (the blocks of :func:`transition_transposed`), each row from the old ``e``.

    In the order of the loop's ``propagate_rows``: pos (reads vel), vel (reads att, acc_bias), att
    (reads gyro_bias).
    """
    att, gb_i, pos_i, vel_i, ab_i = offs.att, offs.gyro_bias, offs.pos, offs.vel, offs.acc_bias
    dt = tr.dt[r]
    sk, cd = tr.skew_dt, tr.c_dt
    for i in range(3):
        e[pos_i + i] += dt * e[vel_i + i]
    if att >= 0:
        e0, e1, e2 = e[att], e[att + 1], e[att + 2]
        for i in range(3):
            e[vel_i + i] += sk[r, i, 0] * e0 + sk[r, i, 1] * e1 + sk[r, i, 2] * e2
    if ab_i >= 0:
        for i in range(3):
            e[vel_i + i] += cd[r, i, 0] * e[ab_i] + cd[r, i, 1] * e[ab_i + 1] + cd[r, i, 2] * e[ab_i + 2]
    if att >= 0 and gb_i >= 0:
        for i in range(3):
            e[att + i] += cd[r, i, 0] * e[gb_i] + cd[r, i, 1] * e[gb_i + 1] + cd[r, i, 2] * e[gb_i + 2]


@njit
def smooth_free_span(lo, hi, cov, r_lo, lam, fwd, noise, gravity, offs, use_ext, traj, work):
    """The recursion over samples ``lo + 1 … hi`` that have no update, in closed form; corrects ``lo … hi − 1``.

    Without an update ``P⁺_k = Φ_k P⁺_{k−1} Φ_kᵀ + Q_k`` and ``λ`` only moves with Φᵀ, so with
    ``μ_k = Φ_kᵀ μ_{k+1}`` (the ``μ`` of :func:`smooth_span`) the smoothed errors follow forwards from
    the one at the span's start::

        e_lo = P⁺_lo μ_{lo+1},    e_k = Φ_k e_{k−1} + Q_k μ_{k+1}     (k = lo + 1 … hi − 1)

    the same numbers as :func:`smooth_span`'s ``e_k = P⁺_k μ_{k+1}`` (to rounding), without
    ``P⁺_k``: the filter does not have to be run again over the span. ``λ`` (n,) comes in as
    ``μ_{hi+1}`` (the recursion of the samples after; zero after the last sample) and leaves as
    ``μ_{lo+1}``; ``P⁺_lo`` is row ``r_lo`` of ``cov`` (packed); ``fwd``: the forward pass
    (:class:`~footzoo.filters.structures.ForwardPass`), for Φ (:func:`transition_row`) and ``Q_k``
    (``noise``, :mod:`footzoo.filters.process_noise`; ``gravity`` m/s²);
    ``work`` (:class:`~footzoo.filters.structures.FreeSpanWork`): μ's (≥ hi − lo, n), Φ's
    (≥ hi − lo rows), ``e``, ``mu`` (n,), ``c`` (3, 3).
    """
    if hi <= lo:
        return
    # views that own no reference (the arguments outlive the call), read at every sample
    fwd = ForwardPass(unowned(fwd.t), unowned(fwd.quat), unowned(fwd.acc_nav), unowned(fwd.acc))
    noise = unowned_noise(noise)
    tr = work.transitions
    mus, phis = unowned(work.mus), Transitions(unowned(tr.dt), unowned(tr.skew_dt), unowned(tr.c_dt))
    e, mu, c, lam = unowned(work.e), unowned(work.mu), unowned(work.c), unowned(lam)
    traj = unowned_trajectory(traj)
    n = lam.shape[0]
    with_c = offs.gyro_bias >= 0 or offs.acc_bias >= 0
    for k in range(hi, lo, -1):  # backwards: μ_{k+1} kept for sample k, then μ_k = Φ_kᵀ μ_{k+1}
        r = k - lo - 1
        for i in range(n):
            mus[r, i] = lam[i]
        transition_row(fwd, k, gravity, with_c, c, phis, r)
        transition_transposed(phis, r, offs, lam, mu)
        for i in range(n):
            lam[i] = mu[i]
    for k in range(lo, hi):  # forwards: e_lo = P⁺_lo μ_{lo+1}, then e_k = Φ_k e_{k−1} + Q_k μ_{k+1}
        r = k - lo - 1
        if k == lo:
            packed_times(cov, r_lo, lam, e)
        else:
            free_step(phis, r, offs, noise, fwd, k, mus, e)
        correct_sample(k, e, offs, use_ext, traj)


@njit(inline=True)
def free_step(phis, r, offs, noise, fwd, k, mus, e):
    """``e ← Φ_k e + Q_k μ_{k+1}`` (:func:`smooth_free_span`), ``Q_k`` as the loop adds it."""
    transition_apply(phis, r, offs, e)
    dt = phis.dt[r]
    qn = noise.q
    for i in range(e.shape[0]):
        e[i] += qn[i] * dt * mus[r, i]
    qv = velocity_variance(noise, fwd.acc_nav[k], fwd.acc, k, dt)
    if qv > 0.0:
        vel_i = offs.vel
        for i in range(3):
            e[vel_i + i] += qv * mus[r, vel_i + i]


@njit
def smooth_segments(rec, ends, lo, off, offs, use_ext, traj):
    """Smooth every segment from sample ``lo`` up to each of ``ends`` (increasing) in turn (record rows ``k − off``)."""
    n = rec.rows.h.shape[1]
    lam, mu, e = np.zeros(n), np.zeros(n), np.zeros(n)
    for s in ends:
        smooth_segment(rec, lo, s, off, offs, use_ext, traj, lam, mu, e)
        lo = s + 1


@njit(inline=True)
def feed_back_attitude(q, ex, ey, ez):
    """``q ← exp(−e) ⊗ q``, normalised, in place (the attitude feedback of Nguyen & La eqs. 51–52)."""
    aw, ax, ay, az = rotvec_quat(-ex, -ey, -ez)
    qw, qx, qy, qz = quat_product(aw, ax, ay, az, q[0], q[1], q[2], q[3])
    nq = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    q[0], q[1], q[2], q[3] = qw / nq, qx / nq, qy / nq, qz / nq


@njit(inline=True)
def correct_sample(k, e, offs, use_ext, traj):
    """Apply the smoothed error ``e`` of sample k as the feedback is (``p ← p − e_p``, ``q ← exp(−e_φ) ⊗ q``, ...)."""
    att, gb_i, pos_i, vel_i, ab_i = offs.att, offs.gyro_bias, offs.pos, offs.vel, offs.acc_bias
    for i in range(3):
        traj.pos[k, i] -= e[pos_i + i]
        traj.vel[k, i] -= e[vel_i + i]
        if gb_i >= 0:
            traj.gyro_bias[k, i] += e[gb_i + i]
        if ab_i >= 0:
            traj.acc_bias[k, i] += e[ab_i + i]
    if att >= 0 and not use_ext:
        feed_back_attitude(traj.quat[k], e[att], e[att + 1], e[att + 2])
