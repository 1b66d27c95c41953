"""The whole-recording RTS smoother in bounded memory: checkpoints, the updates run again, the swings in closed form.

The backward pass of :mod:`footzoo.filters.smoother` needs, for every sample, what the forward
pass knew there (``P⁺_k``, Φ_k's blocks, the update rows: about 1 kB per sample at 9 states,
1 GB for an hour at 250 Hz). Checkpointing (Griewank's trade of memory for recomputation, as
in reverse-mode differentiation) keeps instead the filter's state (nominal state, covariance
and the models' memory, about 0.8 kB) at the first sample of every *piece*, and a piece needs
its record only where the filter was updated:

1. the forward pass: the compiled loop over the whole recording with a record in the mode
   :data:`~footzoo.filters.smoother.CHECKPOINTS` (:func:`checkpoint_record`): no row per
   sample; the state where a piece starts (:func:`~footzoo.filters.smoother.take_checkpoint`:
   sample 0, each stance's start at least :data:`MIN_GAP` samples after the last piece's, and
   at least every :data:`BLOCK` samples) and the piece's last sample with an update;
2. :func:`backward`, the pieces from the last to the first, a batch at a time:

   - the loop run again over each piece of the batch from its checkpoint up to its last update,
     with a row per sample (in one record the batches share: :func:`replay_record`, mode
     :data:`~footzoo.filters.smoother.REPLAY`);
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
from .smoother import CHECKPOINTS, REPLAY, record_arrays, smooth_free_span, smooth_span

#: Most samples per piece, and most rows of one batch's record: the record (about 1 kB per sample at
#: 9 states, 4 MB) stays in the processor's cache.
BLOCK = 4096

#: Fewest samples from a piece's start before a stance's start begins the next piece: a detector's
#: stance that flickers then costs a longer piece run again, never more checkpoints than one per
#: MIN_GAP samples (about 800 bytes each at 9 states).
MIN_GAP = 32


def checkpoint_record(stance: np.ndarray, n_state: int, n_mem: int, block: int, min_gap: int) -> tuple:
    """The forward pass's record over the samples of ``stance`` (N,) bool: no rows; the state where each piece starts.

    In the form of :func:`~footzoo.filters.smoother.record_arrays` (mode
    :data:`~footzoo.filters.smoother.CHECKPOINTS`, ``segment`` = (mode, pieces taken, ``block``,
    ``min_gap``)), its checkpoints ``(nav (J, 16), P (J, n, n), mems (J, s), spans (J, 2) int)``
    with room for every piece the rule of :func:`~footzoo.filters.smoother.take_checkpoint` can
    start: sample 0, one per stance start, one per ``block`` samples, and at most one per
    ``min(min_gap, block)`` samples (a stance that flickers costs no more room).
    """
    n = len(stance)
    st = np.asarray(stance, dtype=bool)
    starts = int(np.count_nonzero(st[1:] & ~st[:-1])) if n > 1 else 0
    # every piece after the first starts at a stance's start or ``block`` samples after the last piece's start,
    # and at least min(min_gap, block) samples after it
    spacing = max(1, min(min_gap, block))
    j = min(1 + starts + max(n - 1, 0) // max(block, 1), 1 + max(n - 1, 0) // spacing) if n > 0 else 0
    empty = record_arrays(0, n_state, 1)
    checkpoints = (np.empty((j, 16)), np.empty((j, n_state, n_state)), np.empty((j, n_mem)),
                   np.zeros((j, 2), np.int64))
    return (*empty[:5], np.array([CHECKPOINTS, 0, block, min_gap], np.int64), empty[6], checkpoints)


def replay_record(forward: tuple, n_state: int, m_max: int, rows: int) -> tuple:
    """The record the pieces are run again into: ``rows`` rows, the checkpoints of the forward pass's ``forward``.

    Mode :data:`~footzoo.filters.smoother.REPLAY`; :func:`backward` sets its ``segment`` to each
    batch's pieces (``(REPLAY, offset, j0, j1, next free row)``). The same types as ``forward``: the
    loop is compiled once for both.
    """
    record = record_arrays(rows, n_state, m_max)
    return (*record[:5], np.array([REPLAY, 0, 0, 0, 0], np.int64), record[6], forward[7])


def pieces(record: tuple, n: int) -> np.ndarray:
    """The pieces the forward pass started (its record from :func:`checkpoint_record`), (J, 3) int.

    Each row: the first sample ``a_j``, the last sample with an update ``u_j`` (``a_j`` if none), the
    last sample ``b_j`` (the next piece's first; ``n − 1`` for the last).
    """
    spans = record[7][3][: int(record[5][1])]
    out = np.empty((len(spans), 3), np.int64)
    out[:, :2] = spans
    out[:-1, 2] = spans[1:, 0]
    out[-1:, 2] = n - 1
    return out


def batches(spans: np.ndarray, rows: int) -> list[tuple[int, int]]:
    """Consecutive pieces ``[j0, j1)`` whose rows (``u_j − a_j + 1`` each) fit in a record of ``rows`` rows together."""
    need = spans[:, 1] - spans[:, 0] + 1
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


@njit
def smooth_pieces(record, spans, j0, j1, lam, forward, noise, idx, use_ext, smoothed, buffers):
    """The backward pass over pieces ``j1 − 1 … j0`` (their rows in ``record``, run again); ``λ`` in place.

    ``spans``: :func:`pieces`; ``forward``, ``noise``: as :func:`~footzoo.filters.smoother.smooth_free_span`
    takes them; ``smoothed``: (quat, vel, pos, gyro_bias, acc_bias) of the whole recording, corrected in
    place; ``buffers``: (μ's (BLOCK, n), Φ's (BLOCK, 19), μ, e (n,), C (3, 3)).
    """
    quat, vel, pos, gyro_bias, acc_bias = smoothed
    mus, phis, mu, e, c = buffers
    cov = record[0]
    r_end = 0
    for j in range(j0, j1):
        r_end += spans[j, 1] - spans[j, 0] + 1
    for j in range(j1 - 1, j0 - 1, -1):
        a, u, b = spans[j, 0], spans[j, 1], spans[j, 2]
        r = r_end - (u - a + 1)  # the piece's first row
        smooth_free_span(u, b, cov, r + u - a, lam, forward, noise, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias,
                         mus, phis, e, (mu, c))
        smooth_span(record, a, u, a - r, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e)
        r_end = r


def backward(run: Callable[[], None], record: tuple, spans: np.ndarray, smooth: Callable[[int, int], None],
             block: int) -> None:
    """The RTS backward pass over every piece, last first, a batch at a time (module docstring).

    ``run()``: the loop over the pieces that ``record`` (:func:`replay_record`, ``block + 1`` rows at
    least) names, writing their rows into it; ``smooth(j0, j1)``: :func:`smooth_pieces` of them;
    ``spans``: :func:`pieces`.
    """
    segment = record[5]
    for j0, j1 in reversed(batches(spans, min(len(record[0]), block + 1))):
        segment[:] = (REPLAY, 0, j0, j1, 0)
        run()
        smooth(j0, j1)
