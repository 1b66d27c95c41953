"""Step-wise smoothing of the ZUPT-aided error-state filter: one stride at a time, live.

Colomar, Nilsson & Händel 2012 ("Smoothing for ZUPT-aided INSs", IPIN 2012) smooth a
zero-velocity-aided INS step by step: the velocity error is observed at every zero-velocity
instant, so the errors of one step depend little on the measurements of the later steps, and
the Rauch–Tung–Striebel smoother run over each segment between zero-velocity instants, started
from the filtered estimate at the segment's end, comes close to the whole-recording smoother
with the memory and the latency of one step. (On PyShoe's trials, ``recommended``: within
0.3 mm of the whole-recording smoother's median error per motion class, better on running;
``benchmarks/smoother_accuracy.py``.)

Where a segment ends
    At the **last sample of every stance** — sample k with ``stance[k]`` and not
    ``stance[k+1]`` (known once sample k+1 has been seen) — and at the last sample of the
    recording. There the forward filter has used every zero-velocity update of the stance;
    its estimate is taken as the smoothed one (``e_k = 0``). A segment holds the samples after
    the previous end up to this one: a swing and the stance after it (the first segment, the
    still start too). A stance that goes on (standing) also ends a segment at its first sample
    :data:`MAX_SEGMENT` seconds or more after the segment's first and :data:`SETTLE` seconds or more
    into the stance (its first updates stay with the swing they correct), so that memory and latency
    stay bounded when the wearer stands still. :func:`segment_ends` is the rule; the batch run
    (:meth:`footzoo.filters.engine.KalmanEngine.run`) and the live stage
    (:class:`footzoo.runtime.stages.KalmanStage`) both use it, so a stream's final estimates
    equal the batch run's.

The backward pass of a segment ``(s₀, s]``
    The closed-loop RTS recursion of :mod:`footzoo.filters.smoother` (its Bryson–Frazier form,
    without a gain or an inverse), ``e_s = 0``, ``e_{k−1} = A_{k−1} (e_k + δx̂_k)``, run for
    k = s … s₀+2: the same kernel as the whole-recording smoother, over a stride instead of the
    whole recording. It gives ``e_k`` such that ``x̂_k − e_k = E[x_k | y_1 … y_s]``: every
    sample of the stride smoothed with all the data up to the end of its stance.

Why that alone jumps
    Sample s₀ (the previous segment's end) was emitted with the data up to s₀; sample s₀ + 1, its
    successor, with the data up to s. What the stance that ends at s tells about the past is
    applied to s₀ + 1 and not to s₀: the first correction of the segment, ``e_{s₀+1}``, is a jump
    at the toe-off. It is not local: the position is unobservable, so ``P⁺`` carries its
    correlation with the attitude (the heading) and the velocity built over every stride before,
    and ``e_{s₀+1} = P⁺_{s₀+1} μ_{s₀+2}`` moves the position by that correlation times what the
    stance learnt of them (the heading the swing's accelerations reveal, or what the filter takes
    for it when a swing is wrong, e.g. with a clipped gyroscope). The whole-recording smoother
    applies the same information to every earlier sample (a rotation of the whole past about the
    start), so it stays continuous; a segment can only apply it to its own samples. Measured
    (``benchmarks/stepwise_continuity.md``): on Köroğlu's experiment 33 the toe-off jumps reached
    0.124 m (the RTS estimate's largest per-sample move: 0.023 m), on gaitmap's right foot 0.084 m
    (0.023 m), on PyShoe's 2017-12-15-18-03-05 (running) 0.130 m (0.030 m).

The start of a segment pinned (Colomar, Nilsson & Händel 2012, with the emitted start held)
    Sample s₀ is final; the correction ``u = e_{s₀+1}`` the segment would make at its first sample
    cannot be made continuous with it. It is taken back and handed out along the stride::

        ẽ_k = e_k − w_k u,    w_k = 1 − ℓ_k / ℓ_s,    k = s₀+1 … s                       (1)

    with ``ℓ_k`` the smoothed path length from sample s₀ + 1 to k (m). So ``ẽ_{s₀+1} = 0`` (the
    stride starts at the filter's estimate, one sample of motion from the emitted s₀), ``ẽ_s =
    e_s = 0`` (it ends where it ended before), and the correction grows with the distance the foot
    travels: a stance (no path) is not moved, so a standing foot stays still, and the extra move
    of a sample is ``|u_p| · |p_k − p_{k−1}| / ℓ_s``, a share of the foot's own move. Applied as the
    feedback is::

        p_k ← p_k + w_k u_p,   v_k ← v_k + w_k u_v,   q_k ← exp(w_k u_φ) ⊗ q_k,   b_k ← b_k − w_k u_b   (2)

    The velocity is not given the rate of the position's share, ``ẇ_k u_p``: ``u_p`` is what the
    next stance tells of where the past was (mostly its heading), not a motion of the foot, and the
    smoothed velocity is the better estimate of the foot's motion (measured on a simulated walk,
    ``duong2015_zupt``, velocity RMSE against the truth: 0.0327 m/s without it, 0.0396 with it, the
    filter's 0.0369, RTS 0.0301). Inside a stride the position so moves by ``u_p`` more than the
    velocity integrates to, spread as the foot moves.

    When the foot does not move in a segment (ℓ_s = 0, a stance split by :data:`MAX_SEGMENT`)
    ``w_k = 1 − (t_k − t_{s₀+1}) / (t_s − t_{s₀+1})``                                      (3)

    Every segment is so pinned, the first one (sample 0) too: a run, a stream and the reference
    engine smooth alike (:func:`smooth_stride`). The rigorous alternative, a fixed-start smoother
    (each segment conditioned on its emitted start, ``P_{s₀} = 0``), needs the covariance run again
    over every stride and, unless its end is pinned too, drifts from the filter by every heading
    correction it can no longer apply; (1) needs nothing but the segment's own pass.

What it cannot do
    The data after the end of a stance moves the whole-recording estimate of that stance: the
    step-wise estimate equals the filter's there (``e_s = 0``), and no smoother that emits a stride
    at the end of the next stance has seen more. Where that later information is large (a long
    walk whose heading the later strides correct), the step-wise estimate stays as far from the
    RTS one as the filtered estimate is: on Köroğlu's experiment 33 the forward filter at the ends
    of the stances is up to 1.06 m from the RTS estimate, and the step-wise estimate up to 1.06 m;
    with the data up to 8 strides after a stance end it would still be 0.82 m
    (``benchmarks/stepwise_continuity.md`` gives every recording). The pinned start gives up, at
    the start of each stride, what the strides smoothed alone took from its stance: on PyShoe's 36
    trials (``recommended_live``, PyShoe's 2-D error) the median 0.0477 m against 0.0474 m, the
    worst trial 0.1555 m against 0.1551 m, each trial within 0.8 mm (16 better, 20 worse).

What is kept
    A :class:`~footzoo.filters.structures.Record` (``P⁺_k``, Φ_k's blocks and the update rows), per
    sample of the open segment only, dropped once the segment has been smoothed: about 1 kB per
    sample at 9 states, one stride. Live, the Kalman stage holds them; on a whole recording the loop
    itself smooths each segment as soon as it has closed (a
    :class:`~footzoo.filters.structures.SegmentRecord`, :func:`close_segment`), while the record is
    in the cache.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import read_only
from .smoother import feed_back_attitude, smooth_segment

#: What a live stream's smoothed estimate of a sample waits for (its latency, besides the one sample after it).
WAITS_FOR = "the end of the next stance"

#: Longest segment (s) before a stance sample closes it although the stance goes on (standing still);
#: a walking stride with its stance lasts about 1–1.5 s.
MAX_SEGMENT = 3.0
#: A stance that goes on closes a segment of :data:`MAX_SEGMENT` or more only once it has lasted this long (s):
#: its first updates (the zero-velocity rows, a height row) correct the swing before it, and the backward pass
#: carries those corrections into the swing only if they are in the swing's segment. Closed at the stance's first
#: sample, a segment after a long swing (PyShoe 2017-11-27-11-12-44: 4 s of fast steps in which the detector found no
#: stance) left the correction to the next segment, a stance with no path to spread it along: an 8 cm jump.
SETTLE = 0.2


@njit(inline=True)
def settled(stance, t, k, lo):
    """Whether the segment from sample ``lo`` has been in stance for the last :data:`SETTLE` s up to sample k."""
    j = k
    while j > lo and t[k] - t[j] < SETTLE:
        j -= 1
        if not stance[j]:
            return False
    return t[k] - t[j] >= SETTLE


@njit(inline=True)
def ends_segment(stance, t, k, lo):
    """Whether sample k (not the last) ends the segment that began at sample ``lo`` (module docstring)."""
    return stance[k] and (not stance[k + 1] or (t[k] - t[lo] >= MAX_SEGMENT and settled(stance, t, k, lo)))


@njit
def _segment_ends(stance, t, closed):
    n = stance.shape[0]
    out = np.empty(n, np.int64)
    m = 0
    lo = 0
    for k in range(n - 1):
        if ends_segment(stance, t, k, lo):
            out[m] = k
            m += 1
            lo = k + 1
    if closed and n > 0 and (m == 0 or out[m - 1] != n - 1):
        out[m] = n - 1
        m += 1
    return out[:m].copy()  # a stride's worth, not a view that keeps 8 bytes per sample


@njit(inline=True)
def close_segment(rec, smoothed, k, stance, t, offs, use_ext, forward, work):
    """In the loop over a whole recording, before sample k: smooth the segment that sample k − 1 ended.

    The rule of :func:`segment_ends` (:func:`ends_segment`); ``rec`` (its ``offset``: the open
    segment's first sample) then starts afresh at sample k. ``forward``: the loop's outputs
    (a :class:`~footzoo.filters.structures.Trajectory`), copied into ``smoothed`` and smoothed there;
    ``work`` (3, n) the backward pass's.
    """
    lo = rec.offset[0]
    if ends_segment(stance, t, k - 1, lo):
        smooth_copy(rec, smoothed, lo, k - 1, lo, offs, use_ext, forward, t, work)
        rec.offset[0] = k


@njit
def smooth_copy(rec, smoothed, lo, hi, off, offs, use_ext, forward, t, work):
    """Samples ``lo … hi`` of the ``forward`` trajectory into ``smoothed``, smoothed there (record rows ``k − off``):
    :func:`smooth_stride` (``work`` (3, n): its λ, μ, e)."""
    for k in range(lo, hi + 1):
        for i in range(4):
            smoothed.quat[k, i] = forward.quat[k, i]
        for i in range(3):
            smoothed.vel[k, i] = forward.vel[k, i]
            smoothed.pos[k, i] = forward.pos[k, i]
            smoothed.gyro_bias[k, i] = forward.gyro_bias[k, i]
            smoothed.acc_bias[k, i] = forward.acc_bias[k, i]
    smooth_stride(rec, lo, hi, off, offs, use_ext, smoothed, t, work[0], work[1], work[2])


@njit
def smooth_stride(rec, lo, hi, off, offs, use_ext, traj, t, lam, mu, e):
    """One segment ``lo … hi`` of ``traj`` smoothed in place: the backward pass, then its start pinned.

    :func:`~footzoo.filters.smoother.smooth_segment` (``e_hi = 0``), which leaves the correction of
    the first sample ``e_lo`` in ``e``; :func:`pin_start` takes it back along the stride's path.
    ``t`` (N,) s; ``lam``, ``mu``, ``e`` (n,) work arrays.
    """
    smooth_segment(rec, lo, hi, off, offs, use_ext, traj, lam, mu, e)
    if hi > lo:
        pin_start(traj, t, lo, hi, e, offs, use_ext)


@njit
def smooth_strides(rec, ends, lo, off, offs, use_ext, traj, t):
    """:func:`smooth_stride` over every segment from sample ``lo`` up to each of ``ends`` (increasing) in turn."""
    n = rec.rows.h.shape[1]
    lam, mu, e = np.zeros(n), np.zeros(n), np.zeros(n)
    for s in ends:
        smooth_stride(rec, lo, s, off, offs, use_ext, traj, t, lam, mu, e)
        lo = s + 1


@njit(inline=True)
def step_length(pos, k, x, y, z):
    """``|pos[k] − (x, y, z)|`` (m), ``(x, y, z)`` the position before sample k."""
    return math.sqrt((pos[k, 0] - x) ** 2 + (pos[k, 1] - y) ** 2 + (pos[k, 2] - z) ** 2)


@njit
def pin_start(traj, t, lo, hi, u, offs, use_ext):
    """Take the correction ``u = e_lo`` of a smoothed segment's first sample back, restored along its path.

    ``ẽ_k = e_k − w_k u`` for k = lo … hi − 1 (module docstring, eqs. (1)–(3)): the position and
    velocity ``p_k + w_k u_p``, ``v_k + w_k u_v``, the attitude ``exp(w_k u_φ) ⊗ q_k``,
    the biases ``b_k − w_k u_b``, with ``w_k = 1 − ℓ_k / ℓ_hi`` (``ℓ_k``: the smoothed path length
    from sample lo to k, m); by time when the foot did not move. Sample hi stays as it is.
    """
    att, gb_i, pos_i, vel_i, ab_i = offs.att, offs.gyro_bias, offs.pos, offs.vel, offs.acc_bias
    pos, vel = traj.pos, traj.vel
    total = 0.0
    for k in range(lo + 1, hi + 1):
        total += step_length(pos, k, pos[k - 1, 0], pos[k - 1, 1], pos[k - 1, 2])
    span = t[hi] - t[lo]
    x, y, z = pos[lo, 0], pos[lo, 1], pos[lo, 2]
    ell = 0.0
    for k in range(lo, hi):
        ell += step_length(pos, k, x, y, z) if k > lo else 0.0
        x, y, z = pos[k, 0], pos[k, 1], pos[k, 2]  # before this sample is moved
        w = 1.0 - (ell / total if total > 0.0 else (t[k] - t[lo]) / span if span > 0.0 else 0.0)
        for i in range(3):
            pos[k, i] += w * u[pos_i + i]
            vel[k, i] += w * u[vel_i + i]
            if gb_i >= 0:
                traj.gyro_bias[k, i] -= w * u[gb_i + i]
            if ab_i >= 0:
                traj.acc_bias[k, i] -= w * u[ab_i + i]
        if att >= 0 and not use_ext:
            feed_back_attitude(traj.quat[k], -w * u[att], -w * u[att + 1], -w * u[att + 2])


def segment_ends(stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
    """Indices of the samples that end a segment, the first segment starting at sample 0 (module docstring).

    Sample k ends one when ``stance[k]`` and not ``stance[k + 1]``, or when ``stance[k]`` and
    ``stance[k + 1]`` but ``t[k]`` (s) is :data:`MAX_SEGMENT` or more after the segment's first
    sample and the segment has been in stance for the last :data:`SETTLE` s; the last sample only
    when ``closed`` (the end of the data; live, its successor is not known yet).
    """
    return _segment_ends(read_only(stance, np.bool_), read_only(t), bool(closed))
