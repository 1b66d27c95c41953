"""The whole-recording RTS smoother in bounded memory: checkpoints, the updates run again, the swings in closed form.

The backward pass of :mod:`footzoo.filters.smoother` needs, for every sample, what the forward
pass knew there (``P⁺_k``, Φ_k's blocks, the update rows: about 1 kB per sample at 9 states,
1 GB for an hour at 250 Hz). Checkpointing (Griewank's trade of memory for recomputation, as
in reverse-mode differentiation) keeps instead the filter's state (nominal state, covariance
and the models' memory, about 0.8 kB) at the first sample of every *piece*, and a piece needs
its record only where the filter was updated:

1. the forward pass: the compiled loop over the whole recording with a
   :class:`~footzoo.filters.structures.CheckpointRecord` (:func:`checkpoint_record`): no row per
   sample; the state where a piece starts (:func:`~footzoo.filters.recorders.take_checkpoint`:
   sample 0, each stance's start at least :data:`MIN_GAP` samples after the last piece's, and
   at least every :data:`BLOCK` samples) and the piece's last sample with an update;
2. :func:`backward`, the pieces from the last to the first, a batch at a time:

   - :func:`replay`: the loop run again over each piece of the batch from its checkpoint up to its
     last update, with a row per sample (in one :class:`~footzoo.filters.structures.Record` the
     batches share) and no output written;
   - :func:`smooth_pieces`: for each piece, last first, the samples after its last update (a
     swing: no update, so ``P⁺`` follows from the one before by the prediction alone) in closed
     form (:func:`~footzoo.filters.smoother.smooth_free_span`), then the closed-loop RTS
     recursion over the rows (:func:`~footzoo.filters.smoother.smooth_span`); ``λ`` carried from
     piece to piece (zero after the last sample).

The loop run again from a checkpoint repeats the same operations on the same numbers, so it
writes the rows the single forward pass would have written, bit for bit; the closed form of a
swing gives the numbers of the recursion to rounding (a test keeps the smoothed trajectory
equal to the RTS smoother's over one record of every sample to 1e-9). The cost is the filter
run again over the samples with an update (the stances, about 40 % of a walk) and a few
products of n-vectors per swing sample; the memory is the checkpoints (about 8 bytes per sample
for a 100 Hz walk) and one batch's record (:data:`BLOCK` samples), which stays in the
processor's cache while the backward pass reads it (docs/speed.md has the measurements).

Piece ``j`` covers samples ``a_j … a_{j+1}`` (the next piece's first sample; the last piece
ends at the last sample): consecutive pieces share their end sample, as a stream's chunks do
(row 0 of a chunk is the state it starts from).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..kernels.jit import njit
from .forward import forward_span
from .recorders import record, views
from .smoother import smooth_free_span, smooth_span
from .structures import CheckpointRecord, Checkpoints, Pieces, Record

#: Most samples per piece, and most rows of one batch's record: the record (about 1 kB per sample at
#: 9 states, 4 MB) stays in the processor's cache.
BLOCK = 4096

#: Fewest samples from a piece's start before a stance's start begins the next piece: a detector's
#: stance that flickers then costs a longer piece run again, never more checkpoints than one per
#: MIN_GAP samples (about 800 bytes each at 9 states).
MIN_GAP = 32


def checkpoint_record(stance: np.ndarray, n_state: int, n_mem: int, block: int, min_gap: int) -> CheckpointRecord:
    """The forward pass's recorder over the samples of ``stance`` (N,) bool: the state where each piece starts.

    Room for every piece the rule of :func:`~footzoo.filters.recorders.take_checkpoint` can start:
    sample 0, one per stance start, one per ``block`` samples, and at most one per
    ``min(min_gap, block)`` samples (a stance that flickers costs no more room).
    """
    n = len(stance)
    st = np.asarray(stance, dtype=bool)
    starts = int(np.count_nonzero(st[1:] & ~st[:-1])) if n > 1 else 0
    # every piece after the first starts at a stance's start or ``block`` samples after the last piece's start,
    # and at least min(min_gap, block) samples after it
    spacing = max(1, min(min_gap, block))
    j = min(1 + starts + max(n - 1, 0) // max(block, 1), 1 + max(n - 1, 0) // spacing) if n > 0 else 0
    checkpoints = Checkpoints(np.empty((j, 16)), np.empty((j, n_state, n_state)), np.empty((j, n_mem)),
                              np.zeros(j, np.int64), np.zeros(j, np.int64))
    return CheckpointRecord(checkpoints, np.zeros(1, np.int64), int(block), int(min_gap))


def pieces(recorder: CheckpointRecord, n: int) -> Pieces:
    """The pieces the forward pass started over ``n`` samples: each piece's first sample ``a_j``, its last sample
    with an update ``u_j`` (``a_j`` if none), its last sample ``b_j`` (the next piece's first; ``n − 1`` for the
    last)."""
    j = int(recorder.taken[0])
    cp = recorder.checkpoints
    first = cp.first[:j].copy()
    return Pieces(first, cp.last_update[:j].copy(), np.append(first[1:], n - 1).astype(np.int64))


def batches(spans: Pieces, rows: int) -> list[tuple[int, int]]:
    """Consecutive pieces ``[j0, j1)`` whose rows (``u_j − a_j + 1`` each) fit in a record of ``rows`` rows together."""
    need = spans.last_update - spans.first + 1
    out, j0, used = [], 0, 0
    for j, m in enumerate(need.tolist()):
        if m > rows:
            raise ValueError(f"checkpointed.batches: piece {j} needs {m} rows, the record has {rows}")
        if used + m > rows:
            out.append((j0, j))
            j0, used = j, 0
        used += m
    if len(need):
        out.append((j0, len(need)))
    return out


def replay_record(n_state: int, m_max: int, rows: int) -> Record:
    """The :class:`~footzoo.filters.structures.Record` the pieces of a batch are run again into (``rows`` rows)."""
    return record(rows, n_state, m_max)


@njit
def replay(signals, core, state, models, k0, work, rec, checkpoints, spans, j0, j1):
    """Run pieces ``j0 … j1 − 1`` again, each from its checkpoint to its last update, their rows one after the
    other in ``rec`` (from row 0); no output written. ``state`` is overwritten (a scratch state)."""
    r = 0
    for j in range(j0, j1):
        a, u = spans.first[j], spans.last_update[j]
        state.nav[:] = checkpoints.nav[j]
        state.P[:, :] = checkpoints.P[j]
        state.mems[:] = checkpoints.mems[j]
        rec.first[r] = rec.first[r - 1] + rec.count[r - 1] if r > 0 else 0
        rec.count[r] = 0
        rec.offset[0] = a - r
        forward_span(signals, core, state, models, None, k0, work, views(rec), a, u)
        r += u - a + 1


@njit
def smooth_pieces(rec, spans, j0, j1, lam, fwd, noise, gravity, offs, use_ext, smoothed, work):
    """The backward pass over pieces ``j1 − 1 … j0`` (their rows in ``rec``, run again); ``λ`` in place.

    ``spans``: :func:`pieces`; ``fwd``, ``noise``, ``gravity``, ``work``: as
    :func:`~footzoo.filters.smoother.smooth_free_span` takes them; ``smoothed``: the whole
    recording's :class:`~footzoo.filters.structures.Trajectory`, corrected in place.
    """
    cov = rec.cov
    r_end = 0
    for j in range(j0, j1):
        r_end += spans.last_update[j] - spans.first[j] + 1
    for j in range(j1 - 1, j0 - 1, -1):
        a, u, b = spans.first[j], spans.last_update[j], spans.last[j]
        r = r_end - (u - a + 1)  # the piece's first row
        smooth_free_span(u, b, cov, r + u - a, lam, fwd, noise, gravity, offs, use_ext, smoothed, work)
        smooth_span(rec, a, u, a - r, offs, use_ext, smoothed, lam, work.mu, work.e)
        r_end = r


def backward(run: Callable[[int, int], None], spans: Pieces, smooth: Callable[[int, int], None],
             rows: int) -> None:
    """The RTS backward pass over every piece, last first, a batch at a time (module docstring).

    ``run(j0, j1)``: :func:`replay` of pieces ``j0 … j1 − 1`` into a record of ``rows`` rows;
    ``smooth(j0, j1)``: :func:`smooth_pieces` of them; ``spans``: :func:`pieces`.
    """
    for j0, j1 in reversed(batches(spans, rows)):
        run(j0, j1)
        smooth(j0, j1)
