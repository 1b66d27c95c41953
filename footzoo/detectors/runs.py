"""Run-length logic shared by detectors that switch state after a minimum run."""

from __future__ import annotations

import numpy as np


def dated_and_online_states(
    candidate: np.ndarray, min_samples: int, initial: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Two-state machine that switches after ``min_samples`` consecutive samples.

    The state follows ``candidate`` (True = stance) only when ``candidate`` has
    stayed on the other side for ``min_samples`` consecutive samples; shorter
    runs are ignored (momentary dips and spikes).

    Parameters
    ----------
    candidate : (N,) bool ndarray
        Per-sample vote (True = looks like stance).
    min_samples : int
        Γ_th: consecutive samples needed to switch.
    initial : bool
        State before the first long run (True = stance).

    Returns
    -------
    dated : (N,) bool ndarray
        State with each switch dated back to where its run began (what Yun's
        FIFOs achieve); available ``min_samples - 1`` samples late. A stance
        needs stillness for its whole extent: a below-threshold run shorter
        than ``min_samples`` never is stance, also when the machine is dating a
        swing back. So a swing is dated back across the momentary dip at toe-off
        to the start of the toe roll, and a heel roll after the dip at heel
        strike stays swing (see ``AngularRateFSM``).
    online : (N,) bool ndarray
        State as a live machine knows it at each sample (switch when the run
        reaches ``min_samples``).
    """
    c = np.asarray(candidate, dtype=bool)
    n = c.shape[0]
    g = max(int(min_samples), 1)
    idx = np.arange(n)

    def runs(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        change = np.flatnonzero(x[1:] != x[:-1]) + 1
        starts = np.concatenate([[0], change]).astype(np.int64)
        return starts, np.diff(np.concatenate([starts, [n]]))

    def fill(x: np.ndarray, switch_at: np.ndarray, value_at: np.ndarray) -> np.ndarray:
        src = np.full(n, -1)
        src[switch_at] = idx[value_at]
        src = np.maximum.accumulate(src)
        return np.where(src >= 0, x[np.maximum(src, 0)], initial)

    starts, lengths = runs(c)
    long_starts = starts[lengths >= g]
    online = fill(c, long_starts + g - 1, long_starts)
    # dated: short still runs are motion; then the machine ignores the short motion runs left (spikes in stance)
    short_still = c[starts] & (lengths < g) & (starts > 0) & (starts + lengths < n)
    still = c & ~np.repeat(short_still, lengths)
    starts, lengths = runs(still)
    long_starts = starts[lengths >= g]
    dated = fill(still, long_starts, long_starts)
    return dated, online


def close_short_swings(stance: np.ndarray, min_samples: int) -> np.ndarray:
    """Stance mask with every swing run shorter than ``min_samples`` between two stance runs filled in.

    Stance runs are kept whatever their length (a running stance can be a few
    samples long); only momentary spikes of the test inside a stance go.
    """
    s = np.asarray(stance, dtype=bool)
    n = s.shape[0]
    if n == 0 or min_samples <= 1:
        return s.copy()
    change = np.flatnonzero(s[1:] != s[:-1]) + 1
    starts = np.concatenate([[0], change]).astype(np.int64)
    lengths = np.diff(np.concatenate([starts, [n]]))
    short_gap = ~s[starts] & (lengths < min_samples) & (starts > 0) & (starts + lengths < n)
    return s | np.repeat(short_gap, lengths)
