"""Initial attitude from the still period at the start of a recording."""

from __future__ import annotations

import numpy as np

from ..core.conventions import quat_conj, quat_from_rotvec, quat_mul
from ..core.errors import RecordingError
from ..orientation.fqa import fqa_sample


def initial_attitude(
    t: np.ndarray,
    acc: np.ndarray,
    gyr: np.ndarray,
    mag: np.ndarray | None,
    duration: float = 0.5,
    max_gyr: float = 0.6,
) -> np.ndarray:
    """Attitude (body -> NED) at the first sample, from the first still period.

    The first window of ``duration`` seconds in which |ω| stays below
    ``max_gyr`` is found; roll and pitch come from its mean specific force
    (gravity), heading from its mean magnetometer reading when given (FQA),
    otherwise heading 0 (north). When the recording does not start still, the
    attitude is carried back from that window to the first sample by
    integrating the gyro backwards, ``q_{k-1} = q_k ⊗ exp(−ω_k dt_k / 2)``.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    acc, gyr : (N, 3) ndarray
        Specific force (m/s²) and angular rate (rad/s), FRD.
    mag : (N, 3) ndarray or None
        Magnetic field (any unit), FRD.
    duration : float
        Length of the still period used (s).
    max_gyr : float
        Largest |ω| (rad/s) accepted as still during that period.

    Raises
    ------
    RecordingError
        When the recording has no still period of that length.
    """
    start, stop = first_still_window(t, gyr, duration, max_gyr)
    a = acc[start:stop].mean(axis=0)
    m = mag[start:stop].mean(axis=0) if mag is not None else None
    # FQA of this one sample, its per-sample function run as Python: the same arithmetic as the
    # compiled batch kernel, which a first run would otherwise compile (about half a second)
    args = (*a, *m, True) if m is not None else (*a, 0.0, 0.0, 0.0, False)
    q = np.array(getattr(fqa_sample, "py_func", fqa_sample)(*(float(x) for x in args[:6]), args[6]))
    for k in range(start, 0, -1):
        q = quat_mul(q, quat_conj(quat_from_rotvec(gyr[k] * (t[k] - t[k - 1]))))
    return q


def first_still_window(t: np.ndarray, gyr: np.ndarray, duration: float, max_gyr: float) -> tuple[int, int]:
    """Sample range ``[start, stop)`` of the first ``duration`` s with |ω| ≤ ``max_gyr`` throughout.

    Reads the recording from the start in growing chunks and stops at the first such window, so a
    long recording that starts still costs almost nothing.
    """
    n = len(t)
    m = min(n, 4096)
    while True:
        still = np.linalg.norm(gyr[:m], axis=1) <= max_gyr
        edges = np.flatnonzero(still[1:] != still[:-1]) + 1
        bounds = np.concatenate([[0], edges, [m]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            # a run cut by the end of the chunk (b == m < n) may still grow: decided only if already long enough
            if still[a] and t[b - 1] - t[a] >= duration:
                stop = int(np.searchsorted(t, t[a] + duration, side="right"))
                if stop - a >= 2:
                    return int(a), stop
        if m == n:
            break
        m = min(n, 4 * m)
    raise RecordingError(
        f"the recording has no still period of {duration} s (|ω| ≤ init.max_gyr = {max_gyr} rad/s) "
        "to align the initial attitude; record a moment of rest, shorten init.duration or raise init.max_gyr"
    )
