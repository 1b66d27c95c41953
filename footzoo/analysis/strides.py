"""Step segmentation from the stance mask and the estimated trajectory."""

from __future__ import annotations

import numpy as np
import pandas as pd

STEP_COLUMNS = [
    "start", "end", "duration", "stride_length", "heading",
    "start_n", "start_e", "end_n", "end_e", "max_clearance",
]


def segment_steps(t: np.ndarray, stance: np.ndarray, pos: np.ndarray) -> pd.DataFrame:
    """One row per step: a swing bounded by stance on both sides.

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
        ``start``/``end`` (s, last stance sample before and first after the
        swing), ``duration`` (s), ``stride_length`` (m, horizontal distance
        between the two stances), ``heading`` (rad, direction of that
        displacement, north = 0, east = +π/2), start/end north and east (m),
        ``max_clearance`` (m, highest point above the start, up positive).
    """
    s = np.asarray(stance, dtype=bool)
    edges = np.flatnonzero(s[1:] != s[:-1]) + 1
    bounds = np.concatenate([[0], edges, [s.shape[0]]])
    rows = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        if s[a] or a == 0 or b >= s.shape[0]:
            continue
        i0, i1 = a - 1, b
        d = pos[i1, :2] - pos[i0, :2]
        rows.append(
            [t[i0], t[i1], t[i1] - t[i0], float(np.hypot(*d)), float(np.arctan2(d[1], d[0])),
             pos[i0, 0], pos[i0, 1], pos[i1, 0], pos[i1, 1], float(np.max(pos[i0, 2] - pos[i0:i1 + 1, 2]))]
        )
    return pd.DataFrame(rows, columns=STEP_COLUMNS)
