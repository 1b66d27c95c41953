"""Public analysis functions and HuangFPA.analyze refuse arrays their compiled loops cannot read, naming the argument.

Hand-built cases: 200 samples at 100 Hz, three stances; every bad argument must give a footzoo error
whose message names the argument (the compiled loops read without bounds checks, so an index past the
samples must never reach them).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from footzoo import ConfigError, RecordingError
from footzoo.analysis import HuangFPA, calibrate_foot_vector, detect_gait_events, real_stances, segment_steps

N = 200
T = np.arange(N) / 100.0
ST = np.array([[0, 20], [60, 80], [120, 140]])
STANCE = np.zeros(N, bool)
for a, b in ST:
    STANCE[a:b] = True
POS = np.column_stack([np.cumsum(~STANCE) * 0.02, np.zeros(N), np.zeros(N)])
GYR = np.column_stack([np.zeros(N), np.sin(np.arange(N) / 6.0), np.zeros(N)])
ACC = np.tile([0.0, 0.0, -9.81], (N, 1))
QUAT = np.tile([1.0, 0.0, 0.0, 0.0], (N, 1))

T_REPEAT = T.copy()
T_REPEAT[50] = T_REPEAT[49]


@pytest.mark.parametrize("call, words", [
    (lambda: detect_gait_events(T, GYR, ST + 500), ["stances", "200"]),
    (lambda: detect_gait_events(T, GYR, ST - 30), ["stance 0", "(-30, -10)"]),
    (lambda: detect_gait_events(T, GYR, ST + 0.5), ["stances", "whole"]),
    (lambda: detect_gait_events(T, GYR, ST.ravel()), ["stances", "(k, 2)"]),
    (lambda: detect_gait_events(T, GYR, ST[::-1]), ["stance 1", "in order"]),
    (lambda: detect_gait_events(T, GYR, ST[:, ::-1]), ["stance 0", "start < stop"]),
    (lambda: detect_gait_events(T, GYR[:100], ST), ["gyr", "(100, 3)"]),
    (lambda: detect_gait_events(T, GYR[:, :2], ST), ["gyr", "(200, 2)"]),
    (lambda: detect_gait_events(T, GYR.astype(complex), ST), ["gyr", "complex"]),
    (lambda: detect_gait_events(T, GYR.astype(str), ST), ["gyr", "real numbers"]),
    (lambda: detect_gait_events(T[:150], GYR, ST), ["gyr", "n = 150"]),
    (lambda: detect_gait_events(T[::-1], GYR, ST), ["t must increase", "t[1]"]),
    (lambda: detect_gait_events(T_REPEAT, GYR, ST), ["t must increase", "t[50]"]),
    (lambda: detect_gait_events(np.ones(N, bool), GYR, ST), ["t", "bool"]),
    (lambda: detect_gait_events(T[:, None], GYR, ST), ["t", "1-d"]),
    (lambda: detect_gait_events(T, GYR, ST, acc=ACC, quat=QUAT.astype(complex)), ["quat", "complex"]),
    (lambda: segment_steps(T, STANCE * 0.7, POS, GYR), ["stance", "0 and 1"]),
    (lambda: segment_steps(T, STANCE[:100], POS, GYR), ["stance", "(100,)"]),
    (lambda: segment_steps(T, STANCE, POS[:, :2], GYR), ["pos", "(200, 2)"]),
    (lambda: segment_steps(T, STANCE, POS, GYR, quat=QUAT[:10]), ["quat", "(10, 4)"]),
    (lambda: segment_steps(T, STANCE, POS, GYR, quat=QUAT, sagittal=np.zeros(10)), ["sagittal", "(10,)"]),
    (lambda: segment_steps(T, STANCE, POS, GYR, stances=ST + 500), ["segment_steps", "stance"]),
    (lambda: segment_steps(T, STANCE, POS, GYR, max_stance_time="2"), ["max_stance_time"]),
    (lambda: segment_steps(T[:50], STANCE, POS, GYR), ["stance", "n = 50"]),
    (lambda: real_stances(STANCE, POS[:100]), ["pos", "(100, 3)"]),
    (lambda: real_stances(STANCE, POS, -1.0), ["min_stride_length"]),
    (lambda: real_stances(STANCE, POS, float("nan")), ["min_stride_length"]),
    (lambda: HuangFPA(foot="right").analyze(T, QUAT[:10], POS, STANCE, {}), ["quat", "(10, 4)"]),
    (lambda: HuangFPA(foot="right").analyze(T, QUAT, POS, STANCE[:10], {}), ["stance", "(10,)"]),
    (lambda: calibrate_foot_vector(np.zeros((100, 7))), ["recording", "ndarray"]),
])
def test_bad_array_names_the_argument(call, words):
    with pytest.raises((RecordingError, ConfigError)) as err:
        call()
    msg = str(err.value).lower()
    assert all(w in msg for w in words), msg


def test_lists_and_tables_give_the_arrays_result():
    ev = detect_gait_events(T, GYR, ST)
    for stances in (ST.tolist(), pd.DataFrame(ST, columns=["a", "b"])):
        other = detect_gait_events(list(T), pd.DataFrame(GYR), stances)
        np.testing.assert_array_equal(other.ic, ev.ic)
        np.testing.assert_array_equal(other.to, ev.to)
    steps = segment_steps(T, STANCE, POS, GYR)
    pd.testing.assert_frame_equal(segment_steps(T.tolist(), STANCE.astype(int), POS.tolist(), GYR.tolist()), steps)


def test_nan_position_keeps_the_strides_with_nan_length():
    pos = POS.copy()
    pos[:] = np.nan
    np.testing.assert_array_equal(real_stances(STANCE, pos), ST)  # the gaps' lengths are unknown, not zero
    steps = segment_steps(T, STANCE, pos)
    assert len(steps) == len(ST) - 1 and steps["stride_length_m"].isna().all()
