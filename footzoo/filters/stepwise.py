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
    :data:`MAX_SEGMENT` seconds or more after the segment's first, so that memory and latency
    stay bounded when the wearer stands still. :func:`segment_ends` is the rule; the batch run
    (:meth:`footzoo.filters.engine.KalmanEngine.run`) and the live stage
    (:class:`footzoo.runtime.stages.KalmanStage`) both use it, so a stream's final estimates
    equal the batch run's.

The backward pass of a segment ``(s₀, s]``
    The closed-loop RTS recursion of :mod:`footzoo.filters.smoother` (its Bryson–Frazier form,
    without a gain or an inverse), ``e_s = 0``, ``e_{k−1} = A_{k−1} (e_k + δx̂_k)``, run for
    k = s … s₀+2 (sample s₀ is the previous segment's end, ``e_{s₀} = 0``): the same kernel as the
    whole-recording smoother, over a stride instead of the whole recording.

What is kept
    A :class:`~footzoo.filters.structures.Record` (``P⁺_k``, Φ_k's blocks and the update rows), per
    sample of the open segment only, dropped once the segment has been smoothed: about 1 kB per
    sample at 9 states, one stride. Live, the Kalman stage holds them; on a whole recording the loop
    itself smooths each segment as soon as it has closed (a
    :class:`~footzoo.filters.structures.SegmentRecord`, :func:`close_segment`), while the record is
    in the cache.
"""

from __future__ import annotations

import numpy as np

from ..kernels.jit import njit
from .smoother import smooth_segment

#: What a live stream's smoothed estimate of a sample waits for (its latency, besides the one sample after it).
WAITS_FOR = "the end of the next stance"

#: Longest segment (s) before a stance sample closes it although the stance goes on (standing still);
#: a walking stride with its stance lasts about 1–1.5 s.
MAX_SEGMENT = 3.0


@njit(inline=True)
def ends_segment(stance, t, k, lo):
    """Whether sample k (not the last) ends the segment that began at sample ``lo`` (module docstring)."""
    return stance[k] and (not stance[k + 1] or t[k] - t[lo] >= MAX_SEGMENT)


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
    return out[:m]


@njit(inline=True)
def close_segment(rec, smoothed, k, stance, t, offs, use_ext, forward):
    """In the loop over a whole recording, before sample k: smooth the segment that sample k − 1 ended.

    The rule of :func:`segment_ends` (:func:`ends_segment`); ``rec`` (its ``offset``: the open
    segment's first sample) then starts afresh at sample k. ``forward``: the loop's outputs
    (a :class:`~footzoo.filters.structures.Trajectory`), copied into ``smoothed`` and smoothed there.
    """
    lo = rec.offset[0]
    if ends_segment(stance, t, k - 1, lo):
        smooth_copy(rec, smoothed, lo, k - 1, lo, offs, use_ext, forward)
        rec.offset[0] = k


@njit
def smooth_copy(rec, smoothed, lo, hi, off, offs, use_ext, forward):
    """Samples ``lo … hi`` of the ``forward`` trajectory into ``smoothed``, smoothed there (record rows ``k − off``)."""
    for k in range(lo, hi + 1):
        for i in range(4):
            smoothed.quat[k, i] = forward.quat[k, i]
        for i in range(3):
            smoothed.vel[k, i] = forward.vel[k, i]
            smoothed.pos[k, i] = forward.pos[k, i]
            smoothed.gyro_bias[k, i] = forward.gyro_bias[k, i]
            smoothed.acc_bias[k, i] = forward.acc_bias[k, i]
    n = rec.rows.h.shape[1]
    smooth_segment(rec, lo, hi, off, offs, use_ext, smoothed, np.empty(n), np.empty(n), np.empty(n))


def segment_ends(stance: np.ndarray, t: np.ndarray, closed: bool) -> np.ndarray:
    """Indices of the samples that end a segment, the first segment starting at sample 0 (module docstring).

    Sample k ends one when ``stance[k]`` and not ``stance[k + 1]``, or when ``stance[k]`` and
    ``stance[k + 1]`` but ``t[k]`` (s) is :data:`MAX_SEGMENT` or more after the segment's first
    sample; the last sample only when ``closed`` (the end of the data; live, its successor is
    not known yet).
    """
    return _segment_ends(np.ascontiguousarray(stance, dtype=np.bool_), np.ascontiguousarray(t, dtype=float),
                         bool(closed))
