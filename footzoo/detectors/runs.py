"""Run-length logic shared by detectors that switch state after a minimum run."""

from __future__ import annotations

import numpy as np

from ..kernels.jit import njit
from ..plugins.incremental import run_starts


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
    c = np.ascontiguousarray(candidate, dtype=bool)
    dated = np.empty(c.shape[0], dtype=np.bool_)
    online = np.empty(c.shape[0], dtype=np.bool_)
    _two_state_kernel(c, max(int(min_samples), 1), bool(initial), dated, online)
    return dated, online


@njit
def _two_state_kernel(c: np.ndarray, g: int, initial: bool, dated: np.ndarray, online: np.ndarray) -> None:
    """:func:`dated_and_online_states` in three passes over the samples, with ``dated`` as the work array."""
    n = c.shape[0]
    # online: switch to the run's value when the run reaches g samples
    state = initial
    run = 0
    for k in range(n):
        run = 1 if k == 0 or c[k] != c[k - 1] else run + 1
        if run == g:
            state = c[k]
        online[k] = state
    # still: c without its short still runs that touch neither end of the recording (into `dated`)
    k = 0
    while k < n:
        s = k
        while k < n and c[k] == c[s]:
            k += 1
        keep = c[s] and not (k - s < g and s > 0 and k < n)
        for j in range(s, k):
            dated[j] = keep
    # dated: each run of `still` takes its value if it lasts g samples, else keeps the state before it
    state = initial
    k = 0
    while k < n:
        s = k
        value = dated[s]
        while k < n and dated[k] == value:
            k += 1
        if k - s >= g:
            state = value
        for j in range(s, k):
            dated[j] = state


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


def after_long_stance(candidate: np.ndarray, start: int, final: int, min_samples: int) -> int:
    """Restart point of :func:`dated_and_online_states` (see :class:`~footzoo.plugins.incremental.OverlapSave`).

    The latest sample ``r ≤ final`` (absolute; ``candidate`` starts at absolute ``start``) that starts
    a run of ``candidate == False`` right after a run of True at least ``min_samples`` long. There
    the three passes of the state machine are in a state that does not depend on anything before:
    the True run is kept (long enough), the machine is in stance, and the new run starts afresh.
    Returns ``start`` when there is none in the window.
    """
    c = np.asarray(candidate[: final - start + 1], dtype=bool)
    starts = run_starts(c)
    if starts.size < 2:
        return start
    lengths = np.diff(np.append(starts, c.size))
    # runs i >= 1 of False whose preceding run (i - 1) is True and long, and did not begin the window
    ok = ~c[starts[1:]] & (lengths[:-1] >= max(int(min_samples), 1)) & (starts[:-1] > 0)
    hits = np.flatnonzero(ok)
    return start + int(starts[1:][hits[-1]]) if hits.size else start
