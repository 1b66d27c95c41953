"""The gyroscope–accelerometer consistency scan (footzoo.filters.consistency): where each swing is anchored, batch and
live alike, the time scale its residuals point to on real walks, and a running foot's quietest instants where a walking
foot's bounds find no swing."""

from __future__ import annotations

import math

import numpy as np
import pytest

import footzoo
from footzoo.core.conventions import GRAVITY
from footzoo.core.norms import row_norms
from footzoo.filters import consistency
from footzoo.filters.consistency import STATIC_ACC, STATIC_GYR, ConsistencyScan
from footzoo.sim import NoiseModel, simulate

from ..conftest import data_file

#: A heel that starts to rise at the end of a stance, as the accelerometer reads it: 1.5 m/s² forward and a pitch rate
#: of 0.5 rad/s, inside the scan's quasi-static bounds (0.8 rad/s, 2 m/s²): its tilt is off by atan(1.5 / g) = 0.15.
HEEL_RISE_ACC = np.array([1.5, 0.0, 0.0])
HEEL_RISE_GYR = np.array([0.0, 0.5, 0.0])


def _quasi_static_runs(acc: np.ndarray, gyr: np.ndarray, least: int) -> list[tuple[int, int]]:
    """The runs [a, b) of quasi-static samples (the scan's bounds) at least ``least`` samples long."""
    still = (row_norms(gyr) < STATIC_GYR) & (np.abs(row_norms(acc) - GRAVITY) < STATIC_ACC)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    return [(a, b) for a, b in zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True) if b - a >= least]


@pytest.fixture(scope="module")
def heel_rise():
    """A noise-free simulated walk whose stances each end with 5 samples (0.05 s) of a rising heel."""
    rec = simulate(n_strides=12, rate=100.0, profile="physical", magnetometer=False)
    acc, gyr = rec.acc.copy(), rec.gyr.copy()
    runs = _quasi_static_runs(acc, gyr, least=20)
    for a, b in runs:
        acc[b - 5:b] = acc[a + 5] + HEEL_RISE_ACC  # the still reading of this stance, pushed forward
        gyr[b - 5:b] = HEEL_RISE_GYR
    assert _quasi_static_runs(acc, gyr, least=20) == runs  # still quasi-static: the runs end where they did
    return rec, acc, gyr, runs


def _median_residual(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, rate: float) -> tuple[float, ConsistencyScan]:
    scan = ConsistencyScan(rate)
    scan.push_recording(t, acc, gyr)
    return float(np.median(np.asarray(scan.residuals)[:, 0])), scan


def test_a_rising_heel_at_the_end_of_a_stance_does_not_set_the_swing_tilt(heel_rise, monkeypatch):
    rec, acc, gyr, runs = heel_rise
    residual, scan = _median_residual(rec.t, acc, gyr, rec.rate)
    # each swing starts at a still sample before the rising heel (the stillest of its run's last 0.1 s) ...
    assert scan.swings and all(any(b - 10 <= k < b - 5 for _, b in runs) for k, _ in scan.swings)
    # ... so what is left is the rising heel's own 0.05 s: 0.075 m/s and 0.025 rad, about 0.04 of g T here
    assert residual < 0.04
    # anchored on the run's last samples instead, the swing starts 0.152 rad off: the residual is that tilt
    monkeypatch.setattr(consistency, "ANCHOR_WINDOW", 0.0)
    last, _ = _median_residual(rec.t, acc, gyr, rec.rate)
    assert last == pytest.approx(math.atan(1.5 / GRAVITY), rel=0.1)


def test_a_stream_in_small_chunks_anchors_every_swing_where_one_push_does():
    walk = simulate("rectangle", n_strides=16, rate=100.0, noise=NoiseModel(seed=7))
    one = ConsistencyScan(walk.rate)
    one.push(np.arange(walk.n), walk.t, walk.acc, walk.gyr)
    live = ConsistencyScan(walk.rate)
    sizes, lo = [1, 3, 7, 2, 23, 64], 0  # chunks shorter than the anchor window (10 samples) and longer
    for j in range(walk.n):
        hi = min(lo + sizes[j % len(sizes)], walk.n)
        live.push(np.arange(lo, hi), walk.t[lo:hi], walk.acc[lo:hi], walk.gyr[lo:hi])
        if hi == walk.n:
            break
        lo = hi
    assert len(one.swings) >= 16 and live.swings == one.swings
    np.testing.assert_array_equal(np.asarray(live.residuals), np.asarray(one.residuals))


@pytest.mark.parametrize("name", ["2017-11-22-11-27-30", "2017-11-22-11-49-03"])
def test_on_a_real_slow_walk_the_residual_is_lowest_at_the_real_time_scale(name):
    """PyShoe's slow walks whose relabelling at half their rate was named 150 Hz, not 100 (their residual, anchored
    on the stances' last samples, was lowest at 1.2–1.4 times the right time scale)."""
    rec = footzoo.load(data_file("pyshoe_vicon", f"{name}.mat"))
    for factor in (1.0, 0.5, 1.5, 2.0):  # declared at factor times the real rate, undone by scaling the time by it
        _, scan = _median_residual(rec.t / factor, rec.acc, rec.gyr, 200.0 * factor)
        evidence = scan.time_scales()
        lowest = float(evidence["scales"][np.argmin(evidence["residual"])])
        assert abs(math.log2(lowest / factor)) <= 1.0 / 8.0 + 1e-9, (factor, lowest)  # within one step of the grid


def test_the_stillest_sample_of_each_run_is_the_first_lowest_one():
    from footzoo.filters.consistency import _stillest

    stillness = np.array([3.0, 1.0, 1.0, 2.0, 0.5, 0.7, 0.5, 4.0, 9.0, 8.0])
    lo, hi = np.array([0, 4, 8]), np.array([4, 7, 10])  # [3, 1, 1, 2], [0.5, 0.7, 0.5], [9, 8]
    assert _stillest(stillness, lo, hi).tolist() == [1, 4, 9]  # ties: the first
    rng = np.random.default_rng(3)
    for _ in range(200):  # against argmin, range by range
        values = rng.integers(0, 4, 40).astype(float)
        cuts = np.sort(rng.choice(41, size=8, replace=False))
        lo, hi = cuts[::2], cuts[1::2]
        expected = [a + int(np.argmin(values[a:b])) for a, b in zip(lo, hi, strict=True)]
        assert _stillest(values, lo, hi).tolist() == expected
    assert _stillest(stillness, lo[:0], hi[:0]).size == 0


# --------------------------------------------------------------------------- a foot that is never still
def vibrating(rec: footzoo.Recording) -> np.ndarray:
    """``rec``'s gyroscope with, from its first step on, a 25 Hz vibration of 1 rad/s: a rate vector turning in the
    x–y plane (constant norm; the attitude it turns swings by 1 / (2π · 25) = 6 mrad). No sample of the steps is then
    within a walking foot's bounds (0.8 rad/s); the stances are within a running foot's (1.2 rad/s)."""
    first = int(np.argmax(row_norms(rec.gyr) > 1.0))
    phase = 2.0 * math.pi * 25.0 * rec.t
    shake = np.column_stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)])
    return rec.gyr + shake * (np.arange(rec.n) >= first)[:, None]


@pytest.fixture(scope="module")
def vibrating_run():
    rec = simulate(path="run", n_strides=16, rate=100.0, profile="physical", noise=NoiseModel(seed=2),
                   magnetometer=False)
    return rec, vibrating(rec)


@pytest.mark.parametrize("factor", [1.0, 2.0, 0.5, 1.5])
def test_a_foot_never_still_is_timed_between_its_quietest_instants(vibrating_run, factor):
    rec, gyr = vibrating_run
    scan = ConsistencyScan(rec.rate * factor)  # declared at factor times the real rate
    scan.push_recording(rec.t / factor, rec.acc, gyr)
    assert not scan.residuals  # no swing within a walking foot's bounds
    evidence = scan.time_scales()
    assert evidence["anchors"] == "running" and evidence["swings"] >= 12
    lowest = float(evidence["scales"][np.argmin(evidence["residual"])])
    assert abs(math.log2(lowest / factor)) <= 1.0 / 8.0 + 1e-9  # the scale that undoes the factor, within a step
    assert scan.time_scales(until=int(rec.n / 2))["swings"] < evidence["swings"]  # the swings ended by a sample


def test_without_a_running_foot_s_bounds_the_foot_never_still_gives_no_evidence(vibrating_run, monkeypatch):
    rec, gyr = vibrating_run
    monkeypatch.setattr(consistency, "RUNNING_STATIC_GYR", STATIC_GYR)
    monkeypatch.setattr(consistency, "RUNNING_STATIC_ACC", STATIC_ACC)
    scan = ConsistencyScan(rec.rate * 2.0)
    scan.push_recording(rec.t / 2.0, rec.acc, gyr)
    assert scan.time_scales() is None


def test_a_negated_axis_withholds_the_running_foot_s_evidence(vibrating_run):
    rec, gyr = vibrating_run
    flipped = gyr * np.array([1.0, -1.0, 1.0])  # the simulated foot turns about its pitch axis
    scan = ConsistencyScan(rec.rate)
    scan.push_recording(rec.t, rec.acc, flipped)
    # the running foot's swings are inconsistent, and negating gyr_y explains it: no evidence of the rate (and no axis
    # named from them: only a walking foot's swings name an axis map)
    assert scan.running_scan.residuals and scan.time_scales() is None and not scan.finish()


def test_a_walk_feeds_the_running_foot_s_scan_only_until_its_own_fourth_swing():
    walk = simulate("rectangle", n_strides=24, rate=100.0, noise=NoiseModel(seed=4))
    scan = ConsistencyScan(walk.rate)
    scan.push_recording(walk.t, walk.acc, walk.gyr)
    assert scan.time_scales()["anchors"] == "walking" and len(scan.residuals) == consistency.MAX_SWINGS
    assert scan.running_scan.seen <= consistency.BATCH_BLOCK // 4  # two pushes of an eighth of a block


def test_a_long_stillness_before_the_first_step_loses_no_swing_in_any_chunking():
    """Six seconds still, then a walk: chunks that hold the whole stillness and a little of the first swing used to
    make the buffer look too long to be a swing (from the stillness's start), and the first swing was lost."""
    walk = simulate(n_strides=8, rate=100.0, stand_start=6.0, noise=NoiseModel(seed=3))
    one = ConsistencyScan(walk.rate)
    one.push(np.arange(walk.n), walk.t, walk.acc, walk.gyr)
    assert len(one.swings) >= 8
    for block in (512, 640, 700, 64):  # 5.1–7 s chunks at 100 Hz: the stillness and the first swing in the first one
        chunked = ConsistencyScan(walk.rate)
        chunked.push_recording(walk.t, walk.acc, walk.gyr, block=block)
        assert chunked.swings == one.swings, block
