"""Rauch–Tung–Striebel smoothing of the closed-loop error-state filter, without a gain or an inverse.

The forward pass is unchanged; it keeps a record of what the backward pass needs
(:func:`record_arrays`). Because the closed-loop filter feeds its error estimate back and resets
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

Two smoothers run it: ``smoother: rts``, over the whole recording as one span ending at its last
sample (offline: the compiled loop keeps checkpoints and makes the record again where the filter
was updated, :mod:`footzoo.filters.checkpointed`, its pieces read by :func:`smooth_span`, the
samples without an update in closed form by :func:`smooth_free_span`; the reference loop keeps
the record of every sample, :func:`smooth_segments` with that one end), and ``smoother:
stepwise`` (:mod:`footzoo.filters.stepwise`), over each stride as it closes.

What is kept per sample (:func:`record_arrays`)
    ``P⁺_k`` (n × n), Φ_k's blocks (``dt``, ``−[f^n×] dt``, ``C dt``; Nguyen & La eq. 33, as
    :func:`footzoo.filters.eskf.transition`), and the update rows (``h``, ``k``, ``ν/s``: 2n+1
    each, only the rows there are), written by the compiled loop
    (:func:`footzoo.filters.kalman_fast.eskf_loop`'s ``record``) or the reference loop: about
    1 kB per sample at 9 states.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import unowned
from .strapdown import mid_rotation, quat_product, rotvec_quat
from .velocity_noise import signal_velocity_variance

#: Per-sample width of Φ's blocks in the record: dt, −[f^n×] dt (3×3), C dt (3×3).
PHI_WIDTH = 19


#: The modes of a record (its ``segment[0]``): a row per sample, smoothed by the caller (a live chunk);
#: each stride smoothed by the loop as it closes (:mod:`footzoo.filters.stepwise`); no row at all, the
#: filter's state at the start of each piece (the forward pass of :mod:`footzoo.filters.checkpointed`,
#: :func:`take_checkpoint`); a row per sample of the pieces ``segment[2] … segment[3] − 1`` of the
#: record's checkpoints, each run again from its checkpoint to its last update (:func:`start_piece`; the
#: loop then writes no output).
ROWS, IN_LOOP, CHECKPOINTS, REPLAY = 0, 1, 2, 3


def record_arrays(n_samples: int, n: int, m_max: int, in_loop: int = 0) -> tuple:
    """Empty record of the forward pass for ``n_samples`` samples of an ``n``-state filter (``m_max`` rows at most).

    ``(cov (N, n(n+1)/2): P⁺'s upper triangle, row by row (:func:`packed`), phi (N, 19): Φ's
    blocks, rows (R, 2n+1): the update rows h, k, ν/s one after the other, first (N,) int: each
    sample's first row in ``rows``, count (N,) int: its number of rows, segment (3,) int: the mode
    (:data:`ROWS`, :data:`IN_LOOP`, :data:`CHECKPOINTS`), the first sample of the open segment (of
    the next checkpoint's block), the samples per checkpoint; smoothed (quat (M, 4), vel, pos,
    gyro_bias, acc_bias (M, 3)), checkpoints (nav (J, 16), P (J, n, n), mems (J, s), spans (J, 2) int))``. ``rows``
    has room for ``m_max`` rows per sample; only the rows written are touched.

    ``in_loop`` (a whole recording of that many samples): the compiled loop smooths each segment
    as soon as it has closed (:func:`footzoo.filters.stepwise.close_segment`), while its record is
    in the cache, into ``smoothed`` (the loop's outputs stay the forward pass's), and the record
    holds the open segment only (sample k in row ``k − segment[1]``): ``n_samples`` is then the longest
    segment's. Otherwise (0: a live chunk) sample k is in row k and the caller smooths. (The
    checkpoints' record: :func:`footzoo.filters.checkpointed.checkpoint_record`.)
    """
    m = int(in_loop)
    smoothed = (np.zeros((m, 4)), np.zeros((m, 3)), np.zeros((m, 3)), np.zeros((m, 3)), np.zeros((m, 3)))
    return (np.empty((n_samples, n * (n + 1) // 2)), np.zeros((n_samples, PHI_WIDTH)),
            np.zeros((n_samples * max(m_max, 1), 2 * n + 1)), np.zeros(n_samples, np.int64),
            np.zeros(n_samples, np.int64), np.array([IN_LOOP if m > 0 else ROWS, 0, 0], np.int64), smoothed,
            no_checkpoints(n))


def no_checkpoints(n: int, n_mem: int = 0) -> tuple:
    """Checkpoints of an ``n``-state filter with no entry (a record that keeps rows)."""
    return np.zeros((0, 16)), np.zeros((0, n, n)), np.zeros((0, n_mem)), np.zeros((0, 2), np.int64)


#: The record's per-sample arrays (in :meth:`KalmanEngine.advance`'s outputs), then its rows.
RECORD_KEYS = ("record_cov", "record_phi", "record_first", "record_count")
ROWS_KEY = "record_rows"


def packed(P: np.ndarray) -> np.ndarray:
    """The upper triangle of the symmetric ``P`` (n, n), row by row: the record's form of ``P⁺`` (n(n+1)/2,)."""
    return P[np.triu_indices(P.shape[0])]


def record_tuple(out: dict[str, np.ndarray], n: int) -> tuple:
    """The record (of a live chunk, ``n`` states) in the order of :func:`record_arrays` from a dict of its arrays."""
    cov, phi, first, count = (out[k] for k in RECORD_KEYS)
    none = np.zeros((0, 3))
    return (cov, phi, out[ROWS_KEY], first, count, np.zeros(3, np.int64), (np.zeros((0, 4)), none, none, none, none),
            no_checkpoints(n))


@njit(inline=True)
def unowned_record(record):
    """The record with every array a view that owns no reference (:func:`footzoo.kernels.views.unowned`).

    The loop reads the record's arrays at every sample; taking an owned array out of the tuple
    costs two atomic reference counts each time (4× the loop's time without a record, measured).
    Only for a record that outlives the loop's call (its argument).
    """
    cov, phi, rows, first, count, segment, smoothed, checkpoints = record
    sq, sv, sp, sg, sa = smoothed
    cn, cp, cm, cs = checkpoints
    return (unowned(cov), unowned(phi), unowned(rows), unowned(first), unowned(count), unowned(segment),
            (unowned(sq), unowned(sv), unowned(sp), unowned(sg), unowned(sa)),
            (unowned(cn), unowned(cp), unowned(cm), unowned(cs)))


@njit(inline=True)
def record_transition(record, k, dt, sdt, cdt):
    """Keep Φ_k's blocks (``sdt = −[f^n×] dt``, ``cdt = C dt``); sample k has no update row yet."""
    phi, first, count = record[1], record[3], record[4]
    r = k - record[5][1]
    phi[r, 0] = dt
    for i in range(3):
        for j in range(3):
            phi[r, 1 + 3 * i + j] = sdt[i, j]
            phi[r, 10 + 3 * i + j] = cdt[i, j]
    first[r] = first[r - 1] + count[r - 1] if r > 0 else 0
    count[r] = 0


@njit(inline=True)
def record_row(record, k, h, gain, scaled_innovation):
    """Keep one scalar update row of sample k: ``h`` (n,), its gain ``k`` (n,) and ``ν / s``."""
    rows, first, count = record[2], record[3], record[4]
    s = k - record[5][1]
    r = first[s] + count[s]
    n = h.shape[0]
    for i in range(n):
        rows[r, i] = h[i]
        rows[r, n + i] = gain[i]
    rows[r, 2 * n] = scaled_innovation
    count[s] += 1


@njit(inline=True)
def record_covariance(record, k, P):
    """Keep ``P⁺_k``: its upper triangle, row by row (P is symmetric; half the memory)."""
    cov = record[0]
    r = k - record[5][1]
    n = P.shape[0]
    a = 0
    for i in range(n):
        for j in range(i, n):
            cov[r, a] = P[i, j]
            a += 1


@njit(inline=True)
def take_checkpoint(record, k, stance, nav, P, mems):
    """Before sample k (a :data:`CHECKPOINTS` record): keep the state after sample k − 1 if a piece starts there.

    A piece starts at sample 0; then where a stance starts (``stance[k]`` and not ``stance[k − 1]``)
    at least ``segment[3]`` samples after the last piece's start, and wherever ``segment[2]`` samples
    have passed since it. Its ``spans`` row is (its first sample, its last sample with an update so
    far: :func:`mark_update`); ``segment[1]`` counts the pieces.
    """
    segment = record[5]
    snap_nav, snap_P, snap_mem, spans = record[7]
    j = segment[1]
    s = k - 1
    if j > 0:
        gap = s - spans[j - 1, 0]
        if gap < segment[2] and not (stance[k] and not stance[k - 1] and gap >= segment[3]):
            return
    if j >= spans.shape[0]:  # more pieces than checkpoint_record made room for (it counts them: not reached)
        return
    segment[1] = j + 1
    spans[j, 0] = s
    spans[j, 1] = s
    for i in range(nav.shape[0]):
        snap_nav[j, i] = nav[i]
    for i in range(P.shape[0]):
        for c in range(P.shape[1]):
            snap_P[j, i, c] = P[i, c]
    for i in range(mems.shape[0]):
        snap_mem[j, i] = mems[i]


@njit(inline=True)
def mark_update(record, k):
    """Sample k updated the filter: the last sample with an update of the open piece (a :data:`CHECKPOINTS` record)."""
    record[7][3][record[5][1] - 1, 1] = k


@njit(inline=True)
def start_piece(record, j, nav, P, mems):
    """Piece j of a :data:`REPLAY` record: its checkpoint into the state, its rows next; returns its (a, u).

    ``a``: the piece's first sample (the checkpoint's), ``u``: its last with an update (the loop
    runs samples a + 1 … u). Its rows follow the previous piece's: ``segment[4]`` is the next free
    row, ``segment[1]`` becomes the offset that puts sample a there (row = sample − ``segment[1]``).
    """
    segment, first, count = record[5], record[3], record[4]
    snap_nav, snap_P, snap_mem, spans = record[7]
    a, u = spans[j, 0], spans[j, 1]
    for i in range(nav.shape[0]):
        nav[i] = snap_nav[j, i]
    for i in range(P.shape[0]):
        for c in range(P.shape[1]):
            P[i, c] = snap_P[j, i, c]
    for i in range(mems.shape[0]):
        mems[i] = snap_mem[j, i]
    r = segment[4]
    first[r] = first[r - 1] + count[r - 1] if r > 0 else 0
    count[r] = 0
    segment[1] = a - r
    segment[4] = r + u - a + 1
    return a, u


@njit(inline=True)
def transition_transposed(phi, k, idx, lam, out):
    """``out = Φ_kᵀ λ`` for Φ = I + Δ with the blocks of Nguyen & La eq. 33 (kept by :func:`record_transition`).

    Δ[pos, vel] = I dt, Δ[vel, att] = −[f^n×] dt, Δ[vel, acc_bias] = C dt, Δ[att, gyro_bias] = C dt.
    """
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    for i in range(lam.shape[0]):
        out[i] = lam[i]
    dt = phi[k, 0]
    for j in range(3):
        out[vel_i + j] += dt * lam[pos_i + j]
    if att >= 0:
        for j in range(3):
            out[att + j] += phi[k, 1 + j] * lam[vel_i] + phi[k, 4 + j] * lam[vel_i + 1] + phi[k, 7 + j] * lam[vel_i + 2]
    if ab_i >= 0:
        for j in range(3):
            out[ab_i + j] += (phi[k, 10 + j] * lam[vel_i] + phi[k, 13 + j] * lam[vel_i + 1]
                              + phi[k, 16 + j] * lam[vel_i + 2])
    if att >= 0 and gb_i >= 0:
        for j in range(3):
            out[gb_i + j] += phi[k, 10 + j] * lam[att] + phi[k, 13 + j] * lam[att + 1] + phi[k, 16 + j] * lam[att + 2]


@njit
def smooth_segment(record, lo, hi, off, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e):
    """Smooth samples ``lo … hi − 1`` in place, the span ending at ``hi`` (``e_hi = 0``; module docstring).

    ``record`` (:func:`record_arrays`) holds samples ``lo … hi``, sample k in its row ``k − off``;
    ``lam``, ``mu``, ``e`` (n,) are work arrays.
    """
    for i in range(lam.shape[0]):
        lam[i] = 0.0
    smooth_span(record, lo, hi, off, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e)


@njit
def smooth_span(record, lo, hi, off, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e):
    """:func:`smooth_segment`'s recursion over samples ``lo … hi − 1``, from the ``λ`` given (updated in place).

    ``λ`` comes from the samples after ``hi`` (zero at the end of a segment): the record of a
    long span can so be read in consecutive pieces, the last first, each ending where the next
    begins (:mod:`footzoo.filters.checkpointed`); the update of sample ``hi`` is in this piece.
    """
    # views that own no reference (the arguments outlive the call): the recursion reads and corrects them
    # at every sample, and reference counts there would cost more than the recursion itself
    cov, phi, rows, first, count = (unowned(record[0]), unowned(record[1]), unowned(record[2]), unowned(record[3]),
                                    unowned(record[4]))
    quat, vel, pos = unowned(quat), unowned(vel), unowned(pos)
    gyro_bias, acc_bias = unowned(gyro_bias), unowned(acc_bias)
    lam, mu, e, idx = unowned(lam), unowned(mu), unowned(e), unowned(idx)
    n = lam.shape[0]
    for j_ in range(hi - off, lo - off, -1):
        k = j_ + off
        for r in range(first[j_] + count[j_] - 1, first[j_] - 1, -1):  # the update of sample k, last row first
            kl = 0.0
            for i in range(n):
                kl += rows[r, n + i] * lam[i]
            c = rows[r, 2 * n] - kl
            for i in range(n):
                lam[i] += rows[r, i] * c
        transition_transposed(phi, j_, idx, lam, mu)
        packed_times(cov, j_ - 1, mu, e)  # e_{k−1} = P⁺_{k−1} μ
        correct_sample(k - 1, e, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias)
        for i in range(n):
            lam[i] = mu[i]


@njit(inline=True)
def packed_times(cov, r, mu, e):
    """``e = P μ`` for the symmetric P kept as row ``r`` of ``cov``, its upper triangle (:func:`record_covariance`)."""
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
def transition_row(t, quat, acc_nav, k, gravity, with_c, c, phi, r):
    """Φ_k's blocks of a sample into row ``r`` of ``phi``, as the loop made them, from the forward pass's outputs.

    ``dt = t_k − t_{k−1}``; ``−[f^n×] dt`` from the specific force in NED, ``acc_nav[k] − [0, 0, g]``
    (``acc_nav`` is the loop's motion acceleration ``f^n + [0, 0, g]``); ``C dt`` (only ``with_c``: a
    bias block reads it) from the attitudes ``quat[k − 1]``, ``quat[k]`` (the forward pass's, before
    smoothing) as the loop's :func:`~footzoo.filters.strapdown.mid_rotation`; ``c`` (3, 3) work.
    """
    dt = t[k] - t[k - 1]
    fx, fy, fz = acc_nav[k, 0], acc_nav[k, 1], acc_nav[k, 2] - gravity
    phi[r, 0] = dt
    phi[r, 1], phi[r, 2], phi[r, 3] = 0.0, dt * fz, -dt * fy
    phi[r, 4], phi[r, 5], phi[r, 6] = -dt * fz, 0.0, dt * fx
    phi[r, 7], phi[r, 8], phi[r, 9] = dt * fy, -dt * fx, 0.0
    if with_c:
        mid_rotation(quat[k - 1, 0], quat[k - 1, 1], quat[k - 1, 2], quat[k - 1, 3], quat[k, 0], quat[k, 1],
                     quat[k, 2], quat[k, 3], c)
        for i in range(3):
            for j in range(3):
                phi[r, 10 + 3 * i + j] = dt * c[i, j]


@njit(inline=True)
def transition_apply(phi, r, idx, e):
    """``e ← Φ e`` in place for Φ = I + Δ (the blocks of :func:`transition_transposed`), each row from the old ``e``.

    In the order of the loop's ``propagate_rows``: pos (reads vel), vel (reads att, acc_bias), att
    (reads gyro_bias).
    """
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    dt = phi[r, 0]
    for i in range(3):
        e[pos_i + i] += dt * e[vel_i + i]
    if att >= 0:
        e0, e1, e2 = e[att], e[att + 1], e[att + 2]
        for i in range(3):
            e[vel_i + i] += phi[r, 1 + 3 * i] * e0 + phi[r, 2 + 3 * i] * e1 + phi[r, 3 + 3 * i] * e2
    if ab_i >= 0:
        for i in range(3):
            e[vel_i + i] += (phi[r, 10 + 3 * i] * e[ab_i] + phi[r, 11 + 3 * i] * e[ab_i + 1]
                             + phi[r, 12 + 3 * i] * e[ab_i + 2])
    if att >= 0 and gb_i >= 0:
        for i in range(3):
            e[att + i] += (phi[r, 10 + 3 * i] * e[gb_i] + phi[r, 11 + 3 * i] * e[gb_i + 1]
                           + phi[r, 12 + 3 * i] * e[gb_i + 2])


@njit
def smooth_free_span(lo, hi, cov, r_lo, lam, forward, noise, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias,
                     mus, phis, e, work):
    """The recursion over samples ``lo + 1 … hi`` that have no update, in closed form; corrects ``lo … hi − 1``.

    Without an update ``P⁺_k = Φ_k P⁺_{k−1} Φ_kᵀ + Q_k`` and ``λ`` only moves with Φᵀ, so with
    ``μ_k = Φ_kᵀ μ_{k+1}`` (the ``μ`` of :func:`smooth_span`) the smoothed errors follow forwards from
    the one at the span's start::

        e_lo = P⁺_lo μ_{lo+1},    e_k = Φ_k e_{k−1} + Q_k μ_{k+1}     (k = lo + 1 … hi − 1)

    the same numbers as :func:`smooth_span`'s ``e_k = P⁺_k μ_{k+1}`` (to rounding), without
    ``P⁺_k``: the filter does not have to be run again over the span. ``λ`` (n,) comes in as
    ``μ_{hi+1}`` (the recursion of the samples after; zero after the last sample) and leaves as
    ``μ_{lo+1}``; ``P⁺_lo`` is row ``r_lo`` of ``cov`` (packed); ``forward`` = (t (N,) s, quat
    (N, 4), acc_nav (N, 3) m/s²: the forward pass's outputs, for Φ: :func:`transition_row`; acc (N, 3)
    m/s²: the specific force the loop integrated); ``noise`` = (q (n,) variance growth per second,
    impact s, gravity m/s², integration κ), the loop's ``Q_k`` (``add_process_noise``); ``mus``
    (≥ hi − lo, n), ``phis`` (≥ hi − lo, 19), ``e`` (n,) and
    ``work`` = (μ (n,), C (3, 3)) are work arrays.
    """
    if hi <= lo:
        return
    t, fq, acc_nav, acc = forward
    qn, impact, gravity, integration = noise
    mu, c = work
    n = lam.shape[0]
    vel_i = idx[3]
    with_c = idx[1] >= 0 or idx[4] >= 0
    for k in range(hi, lo, -1):  # backwards: μ_{k+1} kept for sample k, then μ_k = Φ_kᵀ μ_{k+1}
        r = k - lo - 1
        for i in range(n):
            mus[r, i] = lam[i]
        transition_row(t, fq, acc_nav, k, gravity, with_c, c, phis, r)
        transition_transposed(phis, r, idx, lam, mu)
        for i in range(n):
            lam[i] = mu[i]
    for k in range(lo, hi):  # forwards: e_lo = P⁺_lo μ_{lo+1}, then e_k = Φ_k e_{k−1} + Q_k μ_{k+1}
        r = k - lo - 1
        if k == lo:
            packed_times(cov, r_lo, lam, e)
        else:
            transition_apply(phis, r, idx, e)
            dt = phis[r, 0]
            for i in range(n):
                e[i] += qn[i] * dt * mus[r, i]
            qv = signal_velocity_variance(impact, integration, acc_nav[k], acc, k, dt)
            if qv > 0.0:
                for i in range(3):
                    e[vel_i + i] += qv * mus[r, vel_i + i]
        correct_sample(k, e, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias)


@njit
def smooth_segments(record, ends, lo, off, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias):
    """Smooth every segment from sample ``lo`` up to each of ``ends`` (increasing) in turn (record rows ``k − off``)."""
    n = (record[2].shape[1] - 1) // 2
    lam, mu, e = np.zeros(n), np.zeros(n), np.zeros(n)
    for s in ends:
        smooth_segment(record, lo, s, off, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e)
        lo = s + 1



@njit(inline=True)
def feed_back_attitude(q, ex, ey, ez):
    """``q ← exp(−e) ⊗ q``, normalised, in place (the attitude feedback of Nguyen & La eqs. 51–52)."""
    aw, ax, ay, az = rotvec_quat(-ex, -ey, -ez)
    qw, qx, qy, qz = quat_product(aw, ax, ay, az, q[0], q[1], q[2], q[3])
    nq = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    q[0], q[1], q[2], q[3] = qw / nq, qx / nq, qy / nq, qz / nq


@njit(inline=True)
def correct_sample(k, e, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias):
    """Apply the smoothed error ``e`` of sample k as the feedback is (``p ← p − e_p``, ``q ← exp(−e_φ) ⊗ q``, ...)."""
    att, gb_i, pos_i, vel_i, ab_i = idx[0], idx[1], idx[2], idx[3], idx[4]
    for i in range(3):
        pos[k, i] -= e[pos_i + i]
        vel[k, i] -= e[vel_i + i]
        if gb_i >= 0:
            gyro_bias[k, i] += e[gb_i + i]
        if ab_i >= 0:
            acc_bias[k, i] += e[ab_i + i]
    if att >= 0 and not use_ext:
        feed_back_attitude(quat[k], e[att], e[att + 1], e[att + 2])
