"""The gait between a foot's quiet instants (footzoo.filters.consistency): each swing's length, clearance, rotation and
peak rate by strapdown with its velocity error removed as a zero-velocity update does, and the strides they make."""

from __future__ import annotations

import math

import numpy as np
import pytest

from footzoo.core.conventions import GRAVITY
from footzoo.core.plausibility import stride_summary
from footzoo.filters.consistency import ConsistencyScan, _swing_gait
from footzoo.sim import NoiseModel, simulate

RATE = 200.0
T = 0.8  # s, each hand-made swing


def _hand_made_swings() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Two swings of T s, level sensor (FRD on NED), each starting still. The first moves forward by A T² / (2π)
    (a_x = A sin(2π τ / T)) and up and back down by H (height H (1 − cos(2π τ / T))² / 4), with a forward acceleration
    error of 0.3 m/s² after its first sample (0.3 T m/s left at the end, 0.3 T² / 2 m of drift); the second turns about
    the vertical at 5 rad/s, still: 4 rad in all, nothing moves."""
    n = round(T * RATE)
    tau = np.arange(n + 1) / RATE
    mid = tau + 0.5 / RATE  # samples are means over their interval: the middle of each
    amp, height, w = 6.0, 0.12, 2.0 * math.pi / T
    s, c = np.sin(w * mid), np.cos(w * mid)
    up = height / 2.0 * w**2 * (s * s + (1.0 - c) * c)  # the second derivative of the height
    acc1 = np.column_stack([amp * s + 0.3 * (tau > 0), np.zeros(n + 1), -GRAVITY - up])
    acc1[0] = [0.0, 0.0, -GRAVITY]  # still at the anchor
    acc2 = np.tile([0.0, 0.0, -GRAVITY], (n + 1, 1))
    gyr = np.zeros((2 * n + 2, 3))
    gyr[n + 1:, 2] = 5.0
    t = np.concatenate([tau, T + 1.0 / RATE + tau])
    return t, np.vstack([acc1, acc2]), gyr, np.array([0, n + 1]), np.array([n, 2 * n + 1])


def test_a_hand_made_swing_s_length_clearance_rotation_and_peak():
    t, acc, gyr, first, last = _hand_made_swings()
    out = np.empty((2, 4))
    _swing_gait(t, acc, gyr, first, last, GRAVITY, out)
    # the acceleration error's drift grows as τ² (0.3 T² / 2 at the end): the linear velocity correction takes it back
    assert out[0, 0] == pytest.approx(6.0 * T**2 / (2.0 * math.pi), rel=0.02)
    assert out[0, 1] == pytest.approx(0.12, rel=0.03)
    assert out[0, 2] == 0.0 and out[0, 3] == 0.0
    assert out[1, 0] == pytest.approx(0.0, abs=1e-9) and out[1, 1] == pytest.approx(0.0, abs=1e-9)
    assert out[1, 2] == pytest.approx(5.0 * T, rel=1e-9) and out[1, 3] == pytest.approx(5.0)


def test_the_strides_between_quiet_instants_of_a_simulated_walk_are_its_strides():
    rec = simulate(n_strides=16, stride_length=1.3, cycle=1.0, clearance=0.1, rate=100.0, profile="physical",
                   noise=NoiseModel(seed=5), magnetometer=False)
    scan = ConsistencyScan(rec.rate)
    scan.push_recording(rec.t, rec.acc, rec.gyr)
    strides = scan.time_scales()["strides"]
    assert len(strides) >= 14  # 16 swings: every one but the last, whose next swing is missing, and a turn or so
    gait = stride_summary(strides)
    assert gait["cadence_steps_min"] == pytest.approx(120.0, rel=0.02)  # 1 s per stride
    assert gait["stride_length_m"] == pytest.approx(1.3, rel=0.05)
    assert 0.24 <= gait["rolling_m_rad"] <= 0.45  # the ranges of human gait (core.plausibility)
    # a recording declared at 1.5 times its rate: durations / 1.5, lengths / 1.5², the angular rate unchanged
    fast = ConsistencyScan(rec.rate * 1.5)
    fast.push_recording(rec.t / 1.5, rec.acc, rec.gyr)
    relabelled = stride_summary(fast.time_scales()["strides"])
    assert relabelled["cadence_steps_min"] == pytest.approx(1.5 * gait["cadence_steps_min"], rel=0.02)
    # (the attitude integrated over two thirds of the time turns the foot by two thirds of its angle: gravity leaks into
    # the velocity, and the length is within 10 % of the law's, 6 % short here)
    assert relabelled["stride_length_m"] == pytest.approx(gait["stride_length_m"] / 1.5**2, rel=0.1)
    assert relabelled["peak_rate_rad_s"] == pytest.approx(gait["peak_rate_rad_s"], rel=1e-6)
