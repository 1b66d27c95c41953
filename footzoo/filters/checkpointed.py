"""The whole-recording RTS smoother in bounded memory: checkpoints, and the record made again block by block.

The backward pass of :mod:`footzoo.filters.smoother` needs, for every sample, what the forward
pass knew there (``P⁺_k``, Φ_k's blocks, the update rows: about 1 kB per sample at 9 states,
1 GB for an hour at 250 Hz). Checkpointing (Griewank's trade of memory for recomputation, as
in reverse-mode differentiation) keeps instead the filter's state (nominal state, covariance
and the models' memory, about 0.8 kB) at the first sample of every block of :data:`BLOCK`
samples:

1. the forward pass: the compiled loop over the whole recording with a record in the mode
   :data:`~footzoo.filters.smoother.CHECKPOINTS` (:func:`checkpoint_record`): no row per
   sample, the state at each block's first sample;
2. :func:`backward`: the blocks from the last to the first: the loop run again over the block
   from its checkpoint, this time with a row per sample (for this block only, in a record the
   blocks share), and the closed-loop RTS recursion over it
   (:func:`~footzoo.filters.smoother.smooth_span`), ``λ`` carried from the block after (zero
   after the last sample).

The loop run again from a checkpoint repeats the same operations on the same numbers, so it
writes the rows the single forward pass would have written, bit for bit, and the smoothed
trajectory equals the RTS smoother's over one record of every sample exactly (a test keeps them
equal). The cost is a second forward pass; the memory is the checkpoints (< 1 byte per sample)
and one block's record, which stays in the processor's cache while the backward pass reads it:
the second run costs about what writing one record of every sample to memory and reading it back
did (docs/speed.md has the measurements).

Block ``j`` covers samples ``a_j = j·B … b_j = min(a_j + B, N − 1)``: consecutive blocks share
their end sample, as a stream's chunks do (row 0 of a chunk is the state it starts from, and
the update of sample ``b_j`` is in block ``j``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .smoother import CHECKPOINTS, record_arrays, smooth_span

#: Samples per block: its record (about 1 kB per sample at 9 states, 4 MB) stays in the processor's cache.
BLOCK = 4096


def blocks(n: int, block: int) -> int:
    """The number of blocks of ``block`` samples (sharing their end samples) over ``n`` samples: ⌈(n − 1) / B⌉, ≥ 1."""
    return max(1, (n - 2) // block + 1)


def checkpoint_record(n: int, n_state: int, n_mem: int, block: int) -> tuple:
    """The forward pass's record over ``n`` samples: no rows; the state at each block's first sample.

    In the form of :func:`~footzoo.filters.smoother.record_arrays` (mode
    :data:`~footzoo.filters.smoother.CHECKPOINTS`, ``block`` samples per checkpoint), its
    checkpoints ``(nav (J, 16), P (J, n, n), mems (J, s))``, one per block, filled by the loop
    (:func:`~footzoo.filters.smoother.take_checkpoint`). :func:`backward` takes the same ``block``.
    """
    empty = record_arrays(0, n_state, 1)
    j = blocks(n, block)
    checkpoints = np.empty((j, 16)), np.empty((j, n_state, n_state)), np.empty((j, n_mem))
    return (*empty[:5], np.array([CHECKPOINTS, 0, block], np.int64), empty[6], checkpoints)


def backward(run_block: Callable[[int, int, np.ndarray, np.ndarray, np.ndarray], None], checkpoints: tuple, n: int,
             block: int, record: tuple, smoothed: tuple, idx: np.ndarray, use_ext: bool) -> None:
    """The RTS backward pass over every block, last first, each block's record made again from its checkpoint.

    ``run_block(a, b, nav, P, mems)``: the compiled loop over samples ``a … b`` from the state
    given (a checkpoint's copy), writing a row per sample into ``record`` (one block's,
    :func:`~footzoo.filters.smoother.record_arrays` with at least ``block + 1`` rows);
    ``checkpoints``: the forward pass's (:func:`checkpoint_record`); ``smoothed``: ``(quat, vel,
    pos, gyro_bias, acc_bias)`` of the whole recording, the forward pass's, smoothed in place;
    ``idx``: the core blocks' offsets; ``use_ext``: the attitude is not a state.
    """
    snap_nav, snap_P, snap_mem = checkpoints
    if len(snap_nav) != blocks(n, block) or len(record[0]) < min(block, n - 1) + 1:
        raise ValueError("checkpointed.backward: the checkpoints or the record were made for another block length")
    n_state = snap_P.shape[1]
    lam, mu, e = np.zeros(n_state), np.empty(n_state), np.empty(n_state)  # λ carried from block to block
    for j in range(len(snap_nav) - 1, -1, -1):
        a = j * block
        b = min(a + block, n - 1)
        run_block(a, b, snap_nav[j].copy(), snap_P[j].copy(), snap_mem[j].copy())
        smooth_span(record, a, b, a, idx, use_ext, *smoothed, lam, mu, e)
