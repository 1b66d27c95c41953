"""Strides and their parameters from the stance mask, the gait events and the trajectory.

Column names carry their unit (``_s``, ``_m``, ``_m_s``, ``_rad``, ``_steps_min``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..core.checks import check_positive
from ..evaluation.metrics import intervals
from .gait_events import detect_gait_events, sagittal_rate, segment_argext
from .inputs import check_mask, check_samples, check_stances, check_time

#: Columns of :func:`segment_steps`, units in the names.
STEP_COLUMNS = [
    "start_s", "to_s", "end_s", "largest_pitch_s", "stride_time_s", "stance_time_s", "swing_time_s",
    "cadence_steps_min", "stride_length_m", "speed_m_s", "heading_rad", "start_n_m", "start_e_m", "end_n_m", "end_e_m",
    "max_clearance_m", "events_from_rate",
]


def real_stances(stance: np.ndarray, pos: np.ndarray, min_stride_length: float = 0.1) -> np.ndarray:
    """Stance intervals ``(start, stop)`` with the gaps that are not steps closed.

    A gap between two stances is a step when the foot moved at least
    ``min_stride_length`` (m, horizontal) between the middles of the two stances;
    otherwise (a shuffle, a stance split by a twitch) the two stances are joined.
    Where the position is NaN the gap stays a step (its stride length is NaN, shown, not dropped).
    """
    fn = "real_stances"
    stance = check_mask(fn, "stance", stance, len(np.asarray(stance)))
    pos = check_samples(fn, "pos", pos, len(stance), (3,), "(position in NED, m)")
    min_stride_length = check_positive("min_stride_length", min_stride_length, allow_zero=True, unit="m")
    st = intervals(stance)
    if len(st) < 2:
        return st
    for _ in range(3):  # joining moves the middles; repeat until stable (usually once)
        mid = (st[:, 0] + st[:, 1] - 1) // 2
        d = np.hypot(*(pos[mid[1:], :2] - pos[mid[:-1], :2]).T)
        keep = ~(d < min_stride_length)  # a NaN position keeps its stride (NaN length), never drops it
        if keep.all():
            break
        st = np.column_stack([np.concatenate([st[:1, 0], st[1:, 0][keep]]),
                              np.concatenate([st[:-1, 1][keep], st[-1:, 1]])])
    return st


def segment_steps(t: np.ndarray, stance: np.ndarray, pos: np.ndarray, gyr: np.ndarray | None = None,
                  min_stride_length: float = 0.1, max_stance_time: float = 2.0,
                  quat: np.ndarray | None = None, stances: np.ndarray | None = None,
                  sagittal: np.ndarray | None = None, acc: np.ndarray | None = None) -> pd.DataFrame:
    """One row per stride: the stance from its initial contact, its toe-off, the swing to the next contact.

    Strides start at the first real step: the standing before the first toe-off
    is not a stride, and gaps between stances that do not move the foot
    (shuffles, split stances; see :func:`real_stances`) are not steps. The
    events come from the sagittal angular rate (:mod:`footzoo.analysis.gait_events`)
    when ``gyr`` is given — in the navigation frame, independent of the sensor's
    mounting, when ``quat`` is given too; ``gyr[:, 1]`` of a sensor aligned with the
    foot otherwise — and from the stance edges without ``gyr``. Vectorised: no Python
    loop over samples or strides.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    stance : (N,) bool ndarray
        Stance flag of the detector.
    pos : (N, 3) ndarray
        Position in NED (m).
    gyr : (N, 3) ndarray, optional
        Angular rate in the sensor frame (rad/s) for the gait events.
    min_stride_length : float
        Shortest displacement (m) between two stances that counts as a step.
    max_stance_time : float
        A stance longer than this (s) is a pause: the stride after it has no
        start (``start_s`` and the times that need it are NaN), like the first.
    quat : (N, 4) ndarray, optional
        Attitude (scalar-first, body to NED) that turns ``gyr`` into the navigation
        frame (:func:`footzoo.analysis.gait_events.sagittal_rate`).
    stances : (K + 1, 2) int ndarray, optional
        ``real_stances(stance, pos, min_stride_length)`` when the caller has it already.
    sagittal : (N,) ndarray, optional
        ``sagittal_rate(quat, gyr, pos, stances)`` (rad/s) when the caller has it already.
    acc : (N, 3) ndarray, optional
        Specific force in the sensor frame (m/s²): with it and ``quat``, IC is the heel's impact
        after the foot's largest pitch (:func:`footzoo.analysis.gait_events.contact_times`, in the
        navigation frame); otherwise IC is the largest pitch.

    Returns
    -------
    DataFrame
        Row i is the gait cycle around swing i: ``start_s`` (IC beginning the
        stance, s; NaN after standing), ``to_s`` (toe-off, s), ``end_s`` (IC ending
        the swing, s), ``largest_pitch_s`` (the foot's largest pitch before that IC, s;
        NaN without ``gyr``), ``stride_time_s`` = end − start, ``stance_time_s`` = TO −
        start, ``swing_time_s`` = end − TO, ``cadence_steps_min`` (two steps per
        stride of one foot: 120 / stride time), ``stride_length_m`` (horizontal
        displacement between the middles of the stances before and after the
        swing), ``speed_m_s`` (stride length / stride time), ``heading_rad``
        (direction of that displacement, north = 0, east = +π/2), ``start_n_m``,
        ``start_e_m``, ``end_n_m``, ``end_e_m`` (the two mid-stance positions, m),
        ``max_clearance_m`` (highest point of the swing above the first
        mid-stance, up positive) and ``events_from_rate`` (False where the events
        fell back to the stance edges).
    """
    fn = "segment_steps"
    t = check_time(fn, t)
    n = len(t)
    stance = check_mask(fn, "stance", stance, n)
    pos = check_samples(fn, "pos", pos, n, (3,), "(position in NED, m)")
    max_stance_time = check_positive("max_stance_time", max_stance_time, unit="s")
    for name, value, cols, what in (("gyr", gyr, 3, "(angular rate, rad/s)"),
                                    ("quat", quat, 4, "(attitude quaternions, scalar first)"),
                                    ("acc", acc, 3, "(specific force, m/s²)"), ("sagittal", sagittal, 0, "(rad/s)")):
        if value is not None:
            check_samples(fn, name, value, n, (cols,), what)
    st = real_stances(stance, pos, min_stride_length) if stances is None else check_stances(fn, stances, n)
    if len(st) < 2:
        return pd.DataFrame({c: pd.Series(dtype=bool if c == "events_from_rate" else float) for c in STEP_COLUMNS})
    a, b = st[:, 0], st[:, 1]
    mid = (a + b - 1) // 2
    if gyr is not None:
        rate = gyr if quat is None else sagittal if sagittal is not None else sagittal_rate(quat, gyr, pos, st)
        # the impact in the navigation frame: the foot's acceleration, without the turning of gravity's projection
        ev = detect_gait_events(t, rate, st, None if quat is None else acc, quat)
        to, ic, pitch, from_rate = ev.to, ev.ic, ev.largest_pitch, ev.from_rate
    else:
        to, ic, from_rate = t[np.minimum(b[:-1], n - 1)], t[a[1:]], np.zeros(len(st) - 1, bool)
        pitch = np.full(len(ic), np.nan)
    start = np.concatenate([[np.nan], ic[:-1]])
    stance_time = to - start
    start[stance_time > max_stance_time] = np.nan
    stride_time = ic - start
    d = pos[mid[1:], :2] - pos[mid[:-1], :2]
    length = np.hypot(d[:, 0], d[:, 1])
    # highest point (up = −d): the first minimum of pos_d, as the first maximum of −pos_d
    top = segment_argext(pos[:, 2], np.maximum(b[:-1] - 1, 0), np.minimum(a[1:] + 1, n), largest=False)
    return pd.DataFrame({
        "start_s": start, "to_s": to, "end_s": ic, "largest_pitch_s": pitch, "stride_time_s": stride_time,
        "stance_time_s": to - start,
        "swing_time_s": ic - to, "cadence_steps_min": 120.0 / stride_time, "stride_length_m": length,
        "speed_m_s": length / stride_time, "heading_rad": np.arctan2(d[:, 1], d[:, 0]),
        "start_n_m": pos[mid[:-1], 0], "start_e_m": pos[mid[:-1], 1], "end_n_m": pos[mid[1:], 0],
        "end_e_m": pos[mid[1:], 1], "max_clearance_m": pos[mid[:-1], 2] - pos[top, 2],
        "events_from_rate": from_rate,
    }, columns=STEP_COLUMNS)
