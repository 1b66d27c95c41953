"""What a smoother keeps of the forward pass: the recorders the loop of :mod:`footzoo.filters.forward` takes.

The loop calls six hooks, each a function of the recorder chosen by the recorder's type
(:func:`footzoo.kernels.dispatch.by_type`: compiled into the loop for that type alone):

=====================  ===========================  ==============================  ====================
hook                   :class:`Record`              :class:`SegmentRecord`          :class:`CheckpointRecord`
=====================  ===========================  ==============================  ====================
``begin(lo)``          ``P⁺`` of the first sample   the same                        —
``before(k)``          —                            smooth the segment that sample  a checkpoint where a
                                                    k − 1 closed (step-wise)        piece starts
``transition(k)``      Φ_k's blocks                 the same                        —
``row(k)``             one scalar update row        the same                        —
``updated(k)``         —                            —                               the piece's last update
``end(k)``             ``P⁺_k``                     the same                        —
=====================  ===========================  ==============================  ====================

``None`` keeps nothing. A :class:`~footzoo.filters.structures.Record` keeps a row per sample (a
live chunk of the step-wise smoother; a piece of the RTS smoother run again,
:mod:`footzoo.filters.checkpointed`), a :class:`~footzoo.filters.structures.SegmentRecord` the open
stride of the step-wise smoother over a whole recording (:mod:`footzoo.filters.stepwise`), a
:class:`~footzoo.filters.structures.CheckpointRecord` the state where each piece of the RTS smoother
in bounded memory starts. The constructors are here too, and :func:`workspace`, the loop's buffers.

The loop gets the recorder from its caller as :func:`views` made it (every array a view without an
owner, :func:`footzoo.kernels.views.unowned`: the hooks then cost no reference counting), as an
argument: numba's dead-code elimination keeps the writes of an inlined hook into arrays it can trace
to an argument (a test keeps the records' content in check).
"""

from __future__ import annotations

import numpy as np

from ..kernels.dispatch import by_type
from ..kernels.jit import njit
from ..kernels.views import unowned
from .smoother import unowned_record, unowned_trajectory
from .stepwise import close_segment
from .structures import (
    CheckpointRecord,
    Checkpoints,
    Fault,
    Record,
    SegmentRecord,
    Trajectory,
    Transitions,
    UpdateRows,
    Workspace,
)

NONE = type(None)


# --------------------------------------------------------------------------- constructors
def workspace(n: int, m_max: int) -> Workspace:
    """The forward loop's buffers for an ``n``-state filter with at most ``m_max`` rows per sample."""
    i8 = np.int64
    fault = Fault(np.full(1, -1, i8), np.zeros(1, i8), np.zeros(1, i8))
    return Workspace(np.zeros(m_max), np.zeros((m_max, n)), np.zeros(m_max), np.zeros(n), np.zeros(3), np.zeros(3),
                     np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, i8), np.zeros(n, i8), np.zeros(n, i8),
                     np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3), np.zeros(3), fault)


def record(n_samples: int, n: int, m_max: int) -> Record:
    """An empty :class:`Record` of ``n_samples`` samples of an ``n``-state filter, room for ``m_max`` rows each."""
    rows = n_samples * max(m_max, 1)
    return Record(np.empty((n_samples, n * (n + 1) // 2)), transitions(n_samples),
                  UpdateRows(np.zeros((rows, n)), np.zeros((rows, n)), np.zeros(rows), np.zeros(rows), np.zeros(rows)),
                  np.zeros(n_samples, np.int64), np.zeros(n_samples, np.int64), np.zeros(1, np.int64))


def transitions(n_samples: int) -> Transitions:
    """Room for Φ's blocks of ``n_samples`` samples."""
    return Transitions(np.zeros(n_samples), np.zeros((n_samples, 3, 3)), np.zeros((n_samples, 3, 3)))


def trajectory(n_samples: int) -> Trajectory:
    """An all-zero :class:`Trajectory` of ``n_samples`` samples."""
    return Trajectory(np.zeros((n_samples, 4)), np.zeros((n_samples, 3)), np.zeros((n_samples, 3)),
                      np.zeros((n_samples, 3)), np.zeros((n_samples, 3)))


def segment_record(longest: int, n: int, m_max: int, n_samples: int) -> SegmentRecord:
    """The step-wise smoother's record over a whole recording of ``n_samples``: the open segment's rows
    (at most ``longest`` samples) and the smoothed trajectory."""
    return SegmentRecord(record(longest, n, m_max), trajectory(n_samples), np.zeros((3, n)))


def packed(P: np.ndarray) -> np.ndarray:
    """The upper triangle of the symmetric ``P`` (n, n), row by row: the record's form of ``P⁺`` (n(n+1)/2,)."""
    return P[np.triu_indices(P.shape[0])]


#: A record's per-sample arrays and per-row arrays by name (a live stream keeps them in its columns).
SAMPLE_KEYS = ("record_cov", "record_dt", "record_skew_dt", "record_c_dt", "record_first", "record_count")
ROW_KEYS = ("row_h", "row_gain", "row_scaled", "row_nu", "row_s")


def columns(rec: Record, n_samples: int, n_rows: int) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The first ``n_samples`` samples and ``n_rows`` rows of a record as named columns (:data:`SAMPLE_KEYS`,
    :data:`ROW_KEYS`)."""
    tr, rows = rec.transitions, rec.rows
    per_sample = (rec.cov, tr.dt, tr.skew_dt, tr.c_dt, rec.first, rec.count)
    return ({k: a[:n_samples] for k, a in zip(SAMPLE_KEYS, per_sample, strict=True)},
            {k: a[:n_rows] for k, a in zip(ROW_KEYS, rows, strict=True)})


def from_columns(samples: dict[str, np.ndarray], rows: dict[str, np.ndarray]) -> Record:
    """The :class:`Record` of columns made by :func:`columns` (sample k in row k, its ``first`` from row 0)."""
    cov, dt, skew_dt, c_dt, first, count = (np.ascontiguousarray(samples[k]) for k in SAMPLE_KEYS)
    return Record(cov, Transitions(dt, skew_dt, c_dt), UpdateRows(*(np.ascontiguousarray(rows[k]) for k in ROW_KEYS)),
                  first, count, np.zeros(1, np.int64))


# --------------------------------------------------------------------------- what the hooks write
@njit(inline=True)
def record_covariance(rec, k, P):
    """Keep ``P⁺_k``: its upper triangle, row by row (P is symmetric; half the memory)."""
    cov = rec.cov
    r = k - rec.offset[0]
    n = P.shape[0]
    a = 0
    for i in range(n):
        for j in range(i, n):
            cov[r, a] = P[i, j]
            a += 1


@njit(inline=True)
def record_transition(rec, k, dt, skew_dt, c_dt):
    """Keep Φ_k's blocks (``skew_dt = −[f^n×] dt``, ``c_dt = C dt``); sample k has no update row yet."""
    tr, first, count = rec.transitions, rec.first, rec.count
    r = k - rec.offset[0]
    tr.dt[r] = dt
    for i in range(3):
        for j in range(3):
            tr.skew_dt[r, i, j] = skew_dt[i, j]
            tr.c_dt[r, i, j] = c_dt[i, j]
    first[r] = first[r - 1] + count[r - 1] if r > 0 else 0
    count[r] = 0


@njit(inline=True)
def record_row(rec, k, h, gain, scaled, nu, s):
    """Keep one scalar update row of sample k: ``h`` (n,), its gain ``k`` (n,), ``ν / s``, ``ν`` and ``s``."""
    rows, first, count = rec.rows, rec.first, rec.count
    r = k - rec.offset[0]
    a = first[r] + count[r]
    for i in range(h.shape[0]):
        rows.h[a, i] = h[i]
        rows.gain[a, i] = gain[i]
    rows.scaled[a] = scaled
    rows.nu[a] = nu
    rows.s[a] = s
    count[r] += 1


@njit(inline=True)
def take_checkpoint(rec, k, stance, state):
    """Before sample k: keep the state after sample k − 1 if a piece starts there.

    A piece starts at sample 0; then where a stance starts (``stance[k]`` and not ``stance[k − 1]``)
    at least ``min_gap`` samples after the last piece's start, and wherever ``block`` samples have
    passed since it (:class:`~footzoo.filters.structures.CheckpointRecord`).
    """
    cp = rec.checkpoints
    j = rec.taken[0]
    s = k - 1
    if j > 0:
        gap = s - cp.first[j - 1]
        if gap < rec.block and not (stance[k] and not stance[k - 1] and gap >= rec.min_gap):
            return
    if j >= cp.first.shape[0]:  # more pieces than checkpoint_record made room for (it counts them: not reached)
        return
    rec.taken[0] = j + 1
    cp.first[j] = s
    cp.last_update[j] = s
    nav, P, mems = state.nav, state.P, state.mems
    for i in range(nav.shape[0]):
        cp.nav[j, i] = nav[i]
    for i in range(P.shape[0]):
        for c in range(P.shape[1]):
            cp.P[j, i, c] = P[i, c]
    for i in range(mems.shape[0]):
        cp.mems[j, i] = mems[i]


# --------------------------------------------------------------------------- the hooks, by recorder
def begin(recorder, lo, P):
    """Before the loop's first sample ``lo`` + 1: keep ``P⁺`` of sample ``lo``."""


def _begin_rows(recorder, lo, P):
    record_covariance(recorder, lo, P)


def _begin_segment(recorder, lo, P):
    record_covariance(recorder.record, lo, P)


def _begin_none(recorder, lo, P):
    return None


begin = by_type(begin, {NONE: _begin_none, Record: _begin_rows, SegmentRecord: _begin_segment,
                        CheckpointRecord: _begin_none})


def before(recorder, k, stance, t, offsets, use_ext, out, state):
    """Before sample k's prediction (``out`` the forward outputs, ``state`` the filter's state after k − 1)."""


def _before_none(recorder, k, stance, t, offsets, use_ext, out, state):
    return None


def _before_segment(recorder, k, stance, t, offsets, use_ext, out, state):
    close_segment(recorder.record, recorder.smoothed, k, stance, t, offsets, use_ext, out.trajectory, recorder.work)


def _before_checkpoint(recorder, k, stance, t, offsets, use_ext, out, state):
    take_checkpoint(recorder, k, stance, state)


before = by_type(before, {NONE: _before_none, Record: _before_none, SegmentRecord: _before_segment,
                          CheckpointRecord: _before_checkpoint})


def transition(recorder, k, dt, skew_dt, c_dt):
    """Φ_k's blocks, after sample k's prediction."""


def _transition_none(recorder, k, dt, skew_dt, c_dt):
    return None


def _transition_rows(recorder, k, dt, skew_dt, c_dt):
    record_transition(recorder, k, dt, skew_dt, c_dt)


def _transition_segment(recorder, k, dt, skew_dt, c_dt):
    record_transition(recorder.record, k, dt, skew_dt, c_dt)


transition = by_type(transition, {NONE: _transition_none, Record: _transition_rows,
                                  SegmentRecord: _transition_segment, CheckpointRecord: _transition_none})


def row(recorder, k, h, gain, scaled, nu, s):
    """One scalar update row of sample k (its ``h``, gain, ``ν / s``, ``ν`` and ``s``)."""


def _row_none(recorder, k, h, gain, scaled, nu, s):
    return None


def _row_rows(recorder, k, h, gain, scaled, nu, s):
    record_row(recorder, k, h, gain, scaled, nu, s)


def _row_segment(recorder, k, h, gain, scaled, nu, s):
    record_row(recorder.record, k, h, gain, scaled, nu, s)


row = by_type(row, {NONE: _row_none, Record: _row_rows, SegmentRecord: _row_segment, CheckpointRecord: _row_none})


def updated(recorder, k):
    """Sample k updated the filter."""


def _updated_none(recorder, k):
    return None


def _updated_checkpoint(recorder, k):
    recorder.checkpoints.last_update[recorder.taken[0] - 1] = k


updated = by_type(updated, {NONE: _updated_none, Record: _updated_none, SegmentRecord: _updated_none,
                            CheckpointRecord: _updated_checkpoint})


def end(recorder, k, P):
    """After sample k: keep ``P⁺_k``."""


def _end_rows(recorder, k, P):
    record_covariance(recorder, k, P)


def _end_segment(recorder, k, P):
    record_covariance(recorder.record, k, P)


def _end_none(recorder, k, P):
    return None


end = by_type(end, {NONE: _end_none, Record: _end_rows, SegmentRecord: _end_segment, CheckpointRecord: _end_none})


def views(recorder):
    """The recorder with every array a view that owns no reference (:func:`footzoo.kernels.views.unowned`).

    The loop reads and writes the record's arrays at every sample; taking an owned array out of a tuple
    costs two atomic reference counts each time. Only for a recorder that outlives the loop's call, and
    to be handed to the loop as an argument (the module docstring says why).
    """


def _views_none(recorder):
    return None


def _views_record(recorder):
    return unowned_record(recorder)


def _views_segment(recorder):
    return SegmentRecord(unowned_record(recorder.record), unowned_trajectory(recorder.smoothed),
                         unowned(recorder.work))


def _views_checkpoint(recorder):
    cp = recorder.checkpoints
    return CheckpointRecord(Checkpoints(unowned(cp.nav), unowned(cp.P), unowned(cp.mems), unowned(cp.first),
                                        unowned(cp.last_update)), unowned(recorder.taken), recorder.block,
                            recorder.min_gap)


views = by_type(views, {NONE: _views_none, Record: _views_record, SegmentRecord: _views_segment,
                        CheckpointRecord: _views_checkpoint}, inline=False)
