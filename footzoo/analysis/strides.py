"""Stride segmentation and per-stride parameters from the stance mask and the trajectory."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..metrics import intervals

STEP_COLUMNS = [
    "start", "end", "stride_time", "cadence", "stride_length", "speed", "heading",
    "start_n", "start_e", "end_n", "end_e", "max_clearance",
]


def segment_steps(t: np.ndarray, stance: np.ndarray, pos: np.ndarray) -> pd.DataFrame:
    """One row per stride: from one stance onset (heel strike) to the next.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    stance : (N,) bool ndarray
        Stance flag.
    pos : (N, 3) ndarray
        Position in NED (m).

    Returns
    -------
    DataFrame
        ``start``, ``end`` (s, the two stance onsets), ``stride_time`` (s),
        ``cadence`` (steps/min, two steps per stride of one foot),
        ``stride_length`` (m, horizontal distance between the middles of the two
        stances), ``speed`` (m/s), ``heading`` (rad, direction of that
        displacement, north = 0, east = +π/2), start/end north and east (m),
        ``max_clearance`` (m, highest point of the swing above the first stance,
        up positive).
    """
    st = intervals(stance)
    rows = []
    for (a0, b0), (a1, b1) in zip(st[:-1], st[1:], strict=True):
        m0, m1 = (a0 + b0 - 1) // 2, (a1 + b1 - 1) // 2
        d = pos[m1, :2] - pos[m0, :2]
        length = float(np.hypot(*d))
        stride_time = float(t[a1] - t[a0])
        rows.append([
            t[a0], t[a1], stride_time, 120.0 / stride_time, length, length / stride_time,
            float(np.arctan2(d[1], d[0])), pos[m0, 0], pos[m0, 1], pos[m1, 0], pos[m1, 1],
            float(np.max(pos[m0, 2] - pos[b0 - 1:a1 + 1, 2])),
        ])
    return pd.DataFrame(rows, columns=STEP_COLUMNS)
