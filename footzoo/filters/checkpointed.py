"""The whole-recording RTS smoother in bounded memory: checkpoints, and the record made again block by block.

The backward pass of :mod:`footzoo.filters.smoother` needs, for every sample, what the forward
pass knew there (``P⁺_k``, Φ_k's blocks, the update rows: about 1 kB per sample at 9 states,
1 GB for an hour at 250 Hz). Checkpointing (Griewank's trade of memory for recomputation, as
in reverse-mode differentiation) keeps instead the filter's state (nominal state, covariance
and the models' memory, about 0.8 kB) at the first sample of every block of :data:`BLOCK`
samples:

1. :func:`forward`: the filter over the whole recording, block after block, a checkpoint at
   each block's first sample, no record;
2. :func:`backward`: the blocks from the last to the first: the filter run again over the
   block from its checkpoint, this time with the record (for this block only, in a buffer
   the blocks share), and the closed-loop RTS recursion over it (:func:`~footzoo.filters.
   smoother.smooth_span`), ``λ`` carried from the block after (zero after the last sample).

The filter run again from a checkpoint repeats the same operations on the same numbers, so it
writes the record the single forward pass would have written, bit for bit, and the smoothed
trajectory equals the RTS smoother's over one record of every sample exactly (a test keeps them
equal). The cost is a second forward pass; the memory is the checkpoints (< 1 byte per sample)
and one block's record, which stays in the processor's cache while the backward pass reads it.

Block ``j`` covers samples ``a_j = j·B … b_j = min(a_j + B, N − 1)``: consecutive blocks share
their end sample, as a stream's chunks do (row 0 of a chunk is the state it starts from). The
compiled loop writes the incoming state into row 0 (with no motion acceleration and no update),
so the forward pass keeps that row of the previous block's outputs.
"""

from __future__ import annotations

import numpy as np

from ..kernels.jit import njit
from .kalman_fast import eskf_loop
from .smoother import smooth_span

#: Samples per block: its record (about 1 kB per sample at 9 states) stays in the cache of one core.
BLOCK = 1024


@njit
def blocks(n: int, block: int) -> int:
    """The number of blocks of ``block`` samples (sharing their end samples) over ``n`` samples: ⌈(n − 1) / B⌉, ≥ 1."""
    return max(1, (n - 2) // block + 1)


def checkpoint_arrays(n: int, n_state: int, n_mem: int, block: int) -> tuple:
    """Empty checkpoints for ``n`` samples in blocks of ``block``: ``(nav (J, 16), P (J, n, n), mems (J, s))``.

    One per block; :func:`forward` and :func:`backward` take the same ``block``.
    """
    j = blocks(n, block)
    return np.empty((j, 16)), np.empty((j, n_state, n_state)), np.empty((j, n_mem))


@njit
def _block_signals(signals, a, b):
    t, acc, gyr, stance, quat_ext = signals  # quat_ext: one row when not used; its slice is then empty
    return t[a:b + 1], acc[a:b + 1], gyr[a:b + 1], stance[a:b + 1], quat_ext[a:b + 1]


@njit
def _block_models(models, a, b):
    functions, arrays = models
    m_idx, par, par_off, mem_off, data, data_off, hooks, rows = arrays
    return functions, (m_idx, par, par_off, mem_off, data[a:b + 1], data_off, hooks, rows)


@njit
def _block_out(out, a, b):
    quat, vel, pos, acc_nav, gb, ab, pdiag, nis = out  # P_diag and nis without rows stay so
    return (quat[a:b + 1], vel[a:b + 1], pos[a:b + 1], acc_nav[a:b + 1], gb[a:b + 1], ab[a:b + 1], pdiag[a:b + 1],
            nis[a:b + 1])


@njit
def forward(signals, core, state, models, out, k0, work, checkpoints, block):
    """The filter over the whole recording (as :func:`~footzoo.filters.kalman_fast.eskf_loop`), with checkpoints.

    ``checkpoints`` (:func:`checkpoint_arrays`) receive the state at each block's first sample.
    Stops after a block in which a model broke its contract (``work``'s fault is then set).
    """
    nav, P, mems = state
    n = signals[0].shape[0]
    snap_nav, snap_P, snap_mem = checkpoints
    if snap_nav.shape[0] != blocks(n, block):
        raise ValueError("checkpointed.forward: the checkpoints were made for another block length")
    acc_nav, nis = out[3], out[7]
    keep = out[6].shape[0] > 0
    for j in range(snap_nav.shape[0]):
        a = j * block
        b = min(a + block, n - 1)
        snap_nav[j, :] = nav
        snap_P[j, :, :] = P
        snap_mem[j, :] = mems
        # row 0 of a block is the previous block's last sample: keep what that block wrote there
        a0, a1, a2 = acc_nav[a, 0], acc_nav[a, 1], acc_nav[a, 2]
        n0, n1 = (nis[a, 0], nis[a, 1]) if keep else (0.0, 0.0)
        eskf_loop(_block_signals(signals, a, b), core, state, _block_models(models, a, b), _block_out(out, a, b),
                  k0 + a, work, None)
        if j > 0:
            acc_nav[a, 0], acc_nav[a, 1], acc_nav[a, 2] = a0, a1, a2
            if keep:
                nis[a, 0], nis[a, 1] = n0, n1
        if work[-1][0] >= 0:
            return


@njit
def backward(signals, core, state, models, k0, work, checkpoints, block, record, scratch_out, smoothed):
    """The RTS backward pass over every block, last first, each block's record made again from its checkpoint.

    ``state``: arrays the checkpoints are copied into (overwritten); ``record``: one block's
    (:func:`~footzoo.filters.smoother.record_arrays` with ``block + 1`` rows); ``scratch_out``: the
    loop's outputs for one block (``block + 1`` rows, not read); ``smoothed``: ``(quat, vel, pos,
    gyro_bias, acc_bias)`` of the whole recording, the forward pass's, smoothed in place.
    """
    nav, P, mems = state
    n = signals[0].shape[0]
    snap_nav, snap_P, snap_mem = checkpoints
    if snap_nav.shape[0] != blocks(n, block) or record[0].shape[0] < min(block, n - 1) + 1:
        raise ValueError("checkpointed.backward: the checkpoints or the record were made for another block length")
    quat, vel, pos, gyro_bias, acc_bias = smoothed
    idx, use_ext = core[0], core[3]
    n_state = P.shape[0]
    lam, mu, e = np.zeros(n_state), np.empty(n_state), np.empty(n_state)
    for j in range(snap_nav.shape[0] - 1, -1, -1):
        a = j * block
        b = min(a + block, n - 1)
        nav[:] = snap_nav[j]
        P[:, :] = snap_P[j]
        mems[:] = snap_mem[j]
        eskf_loop(_block_signals(signals, a, b), core, state, _block_models(models, a, b),
                  _block_out(scratch_out, 0, b - a), k0 + a, work, record)
        if work[-1][0] >= 0:
            return
        smooth_span(record, a, b, a, idx, use_ext, quat, vel, pos, gyro_bias, acc_bias, lam, mu, e)
