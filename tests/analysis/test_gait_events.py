"""Gait events (IC, TO), strides from the first real step, errors against the references."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from footzoo.analysis.gait_events import CONTACT_WINDOW, detect_gait_events, segment_argext
from footzoo.analysis.strides import STEP_COLUMNS, real_stances, segment_steps
from footzoo.evaluation.metrics import match_strides, reference_steps, stride_errors
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import NoiseModel, simulate

from ..conftest import HARD_IRON_NOT_FITTED, data_file

YUN = "yun2012"
HUANG = "huang2016"


def test_segment_argext_matches_a_loop():
    rng = np.random.default_rng(0)
    x = rng.integers(0, 5, 300).astype(float)  # many ties: the first one must win
    cuts = np.sort(rng.choice(np.arange(1, 300), 40, replace=False))
    lo, hi = cuts[:-1], cuts[1:]
    for largest, f in ((True, np.argmax), (False, np.argmin)):
        expected = [a + f(x[a:b]) for a, b in zip(lo, hi, strict=True)]
        np.testing.assert_array_equal(segment_argext(x, lo, hi, largest), expected)


def test_events_of_a_hand_made_rate_signal():
    """A swing drawn by hand: push-off peak −5 rad/s at 1.00 s, mid-swing peak at 1.20 s, zero crossing at 1.405 s."""
    rate = 100.0
    t = np.arange(0.0, 3.0, 1 / rate)
    w = np.zeros_like(t)
    swing = (t > 0.9) & (t < 1.5)
    # a parabola-shaped dip centred at 1.0 s and a positive lobe with its zero at 1.405 s
    w[swing] = np.where(t[swing] < 1.1, -5.0 * (1 - ((t[swing] - 1.0) / 0.1) ** 2),
                        3.0 * np.sin(np.pi * (t[swing] - 1.1) / 0.305))
    w[(t > 1.405) & (t < 1.5)] = -1.0
    gyr = np.column_stack([np.zeros_like(t), w, np.zeros_like(t)])
    stances = np.array([[0, 95], [150, 300]])
    ev = detect_gait_events(t, gyr, stances)
    half = 0.5 / rate  # a sample is the mean over the period before it
    assert ev.from_rate.all()
    # TO: the rate back at half the peak, −2.5 rad/s, between the samples at 1.07 s (−2.55) and 1.08 s (−1.80)
    assert ev.to[0] == pytest.approx(1.07 + 0.01 * 0.05 / 0.75 - half, abs=1e-9)
    assert ev.to[0] == pytest.approx(1.0 + 0.1 * np.sqrt(0.5) - half, abs=1e-4)  # the dip's own half point
    # linear interpolation between the samples around the crossing (1.40 s: +, 1.41 s: −1)
    w0 = 3.0 * np.sin(np.pi * 0.30 / 0.305)
    assert ev.ic[0] == pytest.approx(1.40 + 0.01 * w0 / (w0 + 1.0) - half, abs=1e-9)


def test_the_half_level_uses_the_peak_between_the_samples():
    """The same dip, sampled off its centre: the level is half the parabola's vertex, not of the lower sample."""
    rate = 100.0
    t = np.arange(0.0, 3.0, 1 / rate) + 0.004
    w = np.where((t > 0.9) & (t < 1.1), -5.0 * (1 - ((t - 1.0) / 0.1) ** 2), 0.0)
    w[(t >= 1.1) & (t < 1.4)] = 3.0
    ev = detect_gait_events(t, np.column_stack([0 * t, w, 0 * t]), np.array([[0, 90], [150, 300]]))
    # the samples at 0.994 and 1.004 s read −4.982 and −4.992: the vertex, −5, sets the level −2.5
    assert ev.to[0] == pytest.approx(1.0 + 0.1 * np.sqrt(0.5) - 0.5 / rate, abs=2e-4)


def test_no_rate_pattern_falls_back_to_the_stance_edges():
    t = np.arange(0.0, 3.0, 0.01)
    gyr = np.zeros((t.size, 3))
    gyr[100:150, 1] = -2.0  # plantar-flexion only, never a positive swing peak
    ev = detect_gait_events(t, gyr, np.array([[0, 100], [150, 300]]))
    assert not ev.from_rate[0]
    assert ev.to[0] == t[100] and ev.ic[0] == t[150]


# yun2012 fits a hard-iron calibration, which this straight simulated walk cannot give (expected warning)
@pytest.mark.filterwarnings(HARD_IRON_NOT_FITTED)
@pytest.mark.parametrize("rate", [100.0, 200.0])
def test_simulated_walk_events_stance_and_swing(rate):
    """Physical profile: the rate's zero crossing is the true IC; TO is where the rate, turning in the air, is at half
    its push-off peak, a fixed delay after the true toe-off that follows from the foot model."""
    from footzoo.sim.gait import IC_ANGLE, PS_ANGLE, PUSH_RISE, PUSH_TURN, SWING_DECLINE
    from footzoo.sim.profiles import FootPitch

    cycle, stance_fraction, flat = 1.0, 0.6, 2.0 / 3.0
    rec = simulate(n_strides=20, rate=rate, profile="physical", noise=NoiseModel(seed=1))
    steps = Pipeline.from_yaml(YUN).run(rec).steps
    ref = reference_steps(rec.truth.steps)
    assert len(steps) == len(ref) == 20
    m = match_strides(steps, ref)
    assert len(m) == 20
    pre_swing = cycle * stance_fraction * (1 - flat) / 2  # 0.1 s rotation about the toe
    swing = cycle * (1 - stance_fraction)
    # the model's rate turns from −W to P as a raised cosine over the turn: −W/2 at u = acos(1 − W/(W + P)) / π
    f = FootPitch(pre_swing, swing, PS_ANGLE, IC_ANGLE, PUSH_RISE * pre_swing, PUSH_TURN * pre_swing,
                  SWING_DECLINE * swing)
    delay = np.arccos(1 - f.w / (f.w + f.p)) / np.pi * f.turn  # 8.0 ms
    period = 1.0 / rate
    # the simulated heel touches down at the largest pitch, without an impact: IC (the impact rule) finds the
    # loading response's onset a few milliseconds later (measured 5.3–5.5 ms); TO within 0.05 period of the
    # model's half point
    late = (m["est_end_s"] - m["end_s"]).to_numpy()
    assert (late >= 0).all() and (late <= 0.010).all()
    # the largest pitch (the rate's zero crossing) is the simulated touch-down: measured within 0.1 period
    np.testing.assert_allclose(m["est_largest_pitch_s"], m["end_s"], atol=0.25 * period)
    np.testing.assert_allclose(m["est_to_s"], m["to_s"] + delay, atol=0.25 * period)
    # the first row is the first step: no stride time (standing before it), all others one cycle
    assert np.isnan(steps["start_s"].iloc[0]) and np.isnan(steps["cadence_steps_min"].iloc[0])
    np.testing.assert_allclose(steps["stride_time_s"].iloc[1:], cycle, atol=0.5 * period)
    np.testing.assert_allclose(steps["cadence_steps_min"].iloc[1:], 120.0 / cycle, rtol=0.01)
    np.testing.assert_allclose(steps["swing_time_s"], swing - delay + late, atol=0.5 * period)
    np.testing.assert_allclose(steps["stance_time_s"].iloc[1:], cycle - swing + delay - late[:-1], atol=0.5 * period)


@pytest.mark.parametrize("rate", [100.0, 250.0, 400.0])
def test_simulated_events_within_10_ms_of_the_truth_at_any_rate(rate):
    """The simulator's own events (the toe leaving the floor, the heel touching it) at 100, 250 and 400 Hz."""
    rec = simulate(path="rectangle", length=10.0, width=5.0, rate=rate, profile="physical", clearance=0.15,
                   noise=NoiseModel(seed=0))
    m = match_strides(Pipeline.from_yaml("recommended").run(rec).steps, reference_steps(rec.truth.steps))
    assert len(m) == len(rec.truth.steps)
    ic, to = m["est_end_s"] - m["end_s"], m["est_to_s"] - m["to_s"]
    # measured: median IC −0.6 / +0.6 / +0.6 ms, TO +7.5 / +7.8 / +7.9 ms (100 / 250 / 400 Hz)
    assert abs(np.median(ic)) <= 0.010 and abs(np.median(to)) <= 0.010
    assert np.median(np.abs(ic)) <= 0.010 and np.median(np.abs(to)) <= 0.010


def test_a_shuffle_is_not_a_step_and_strides_start_at_the_first_real_step():
    t = np.arange(0.0, 6.0, 0.01)
    pos = np.zeros((t.size, 3))
    stance = np.ones(t.size, bool)
    stance[180:190] = False  # a twitch while standing: 5 mm
    pos[190:, 0] = 0.005
    stance[300:350] = False  # a real step of 1.3 m
    pos[350:, 0] = 1.305
    stance[450:500] = False  # and another
    pos[500:, 0] = 2.605
    st = real_stances(stance, pos, min_stride_length=0.1)
    np.testing.assert_array_equal(st, [[0, 300], [350, 450], [500, 600]])
    steps = segment_steps(t, stance, pos)
    assert list(steps.columns) == STEP_COLUMNS
    assert len(steps) == 2
    np.testing.assert_allclose(steps["stride_length_m"], [1.3, 1.3], atol=0.01)
    assert np.isnan(steps["start_s"].iloc[0])
    assert steps["stride_time_s"].iloc[1] == pytest.approx(t[500] - t[350])


def test_a_long_pause_starts_a_new_walking_bout():
    t = np.arange(0.0, 12.0, 0.01)
    stance = np.ones(t.size, bool)
    pos = np.zeros((t.size, 3))
    for k, a in enumerate([200, 300, 900]):  # the third step after a 5 s pause
        stance[a:a + 40] = False
        pos[a + 40:, 0] = 1.2 * (k + 1)
    steps = segment_steps(t, stance, pos, max_stance_time=2.0)
    assert len(steps) == 3
    assert np.isfinite(steps["stride_time_s"].iloc[1])
    assert np.isnan(steps["stride_time_s"].iloc[2]) and np.isnan(steps["start_s"].iloc[2])


def test_no_steps_gives_an_empty_table_with_the_columns():
    t = np.arange(0.0, 3.0, 0.01)
    steps = segment_steps(t, np.ones(t.size, bool), np.zeros((t.size, 3)))
    assert len(steps) == 0 and list(steps.columns) == STEP_COLUMNS


def test_stride_errors_against_a_hand_made_reference():
    est = pd.DataFrame({"start_s": [np.nan, 1.0, 2.0], "to_s": [0.7, 1.7, 2.7], "end_s": [1.01, 2.0, 3.02],
                        "stride_time_s": [np.nan, 1.0, 1.02], "stride_length_m": [1.3, 1.4, 1.5]})
    ref = pd.DataFrame({"start_s": [np.nan, 1.0, 2.0], "to_s": [0.69, 1.72, 2.7], "end_s": [1.0, 2.0, 3.0],
                        "stride_length_m": [1.3, 1.3, 1.5], "turn": [False, False, True]})
    e = stride_errors(est, ref)
    assert e["matched_strides"] == 3
    assert e["ic_error_median_abs_s"] == pytest.approx(0.01)
    assert e["to_error_median_abs_s"] == pytest.approx(0.01)
    # signed: IC +0.01, 0, +0.02 s and TO +0.01, −0.02, 0 s: medians +0.01 and 0
    assert e["ic_error_median_s"] == pytest.approx(0.01) and e["to_error_median_s"] == pytest.approx(0.0)
    # every matched stride: errors 0, 0.1 and 0 m; the straight ones (turn left out): 0 and 0.1 m
    assert e["stride_length_rms_error_m"] == pytest.approx(np.sqrt(0.1**2 / 3))
    assert e["stride_length_mean_error_m"] == pytest.approx(0.1 / 3)
    assert e["stride_length_rms_error_straight_m"] == pytest.approx(np.sqrt(0.1**2 / 2))
    assert e["stride_length_mean_error_straight_m"] == pytest.approx(0.1 / 2)
    # without a turn flag every stride is straight
    plain = stride_errors(est, ref.drop(columns="turn"))
    assert plain["stride_length_rms_error_straight_m"] == plain["stride_length_rms_error_m"]


def test_strides_pair_only_when_both_swing_borders_agree():
    # estimated: three swings (toe-off, next initial contact); the reference missed the stance between
    # the last two and takes them as one stride, from the second toe-off to the third contact
    est = pd.DataFrame({"to_s": [0.7, 1.7, 2.7], "end_s": [1.0, 2.0, 3.0], "stride_length_m": [1.3, 0.6, 0.7]})
    ref = pd.DataFrame({"to_s": [0.71, 1.72], "end_s": [1.01, 3.0], "stride_length_m": [1.3, 1.1]})
    m = match_strides(est, ref)
    # the toe-offs alone would pair the merged stride with the 0.6 m one; its contact is 1 s off
    assert list(m["to_s"]) == [0.71] and list(m["est_stride_length_m"]) == [1.3]
    assert len(match_strides(est, ref, on="to_s")) == 2  # pairing on the toe-off alone keeps it
    # one to one: two reference strides near one estimated stride, the nearer one pairs
    twice = pd.DataFrame({"to_s": [0.65, 0.72], "end_s": [1.0, 1.0], "stride_length_m": [1.2, 1.3]})
    m = match_strides(est, twice)
    assert list(m["to_s"]) == [0.72] and list(m["est_to_s"]) == [0.7]
    # a border the estimate does not know (NaN) is not checked
    m = match_strides(est.assign(end_s=[np.nan, 2.0, 3.0]), ref)
    assert list(m["est_to_s"]) == [0.7]


# ----------------------------------------------------------------------------- gaitmap example


def test_a_reference_stride_over_two_steps_stays_unpaired():
    """The left foot's 180° turn: the motion capture's events make one stride of two steps."""
    from footzoo.io import load
    from footzoo.io.gaitmap_reference import MOCAP_RATE, reference_strides

    folder = data_file("gaitmap_example", "imu_sample.csv").parent
    ref = reference_strides(folder, "left")
    long = ref.index[(ref["ms_end_s"] - ref["ms_start_s"]) > 2.0]
    assert list(long) == [13]  # 16.40 s to 18.68 s, twice the others' 1.1 s
    # the heel marker stands still in its middle, between two swings: a stance the events do not mark
    mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
    heel = mocap["L_FCC"][["x", "y", "z"]].to_numpy() / 1000.0
    speed = np.linalg.norm(np.gradient(heel, 1.0 / MOCAP_RATE, axis=0), axis=1)
    t0, t1 = ref.loc[13, "ms_start_s"], ref.loc[13, "ms_end_s"]
    inside = speed[int(t0 * MOCAP_RATE) + 50:int(t1 * MOCAP_RATE) - 50]
    still = np.flatnonzero(inside < 0.1)
    assert len(still) / MOCAP_RATE > 0.5  # measured 0.7 s
    assert inside[:still[0]].max() > 1.0 and inside[still[-1]:].max() > 1.0  # swings of 2.9 and 2.4 m/s
    steps = Pipeline.from_yaml(YUN).run(load(folder / "imu_sample.csv", foot="left")).steps
    assert ((steps["to_s"] > t0) & (steps["end_s"] < t1)).sum() == 2  # the estimate has both steps
    m = match_strides(steps, ref)
    assert len(m) == len(ref) - 1 and t0 not in set(m["ms_start_s"])


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_events_and_stride_length_against_motion_capture(foot):
    from footzoo.io import load

    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot=foot)
    assert rec.truth is not None and rec.truth.steps is not None
    m = Pipeline.from_yaml(HUANG).run(rec).metrics
    # every reference stride pairs but the left foot's 180° turn, which the reference takes as one
    # stride over two steps (see test_a_reference_stride_over_two_steps_stays_unpaired)
    assert m["ref_strides"] >= 28 and m["matched_strides"] == m["ref_strides"] - (foot == "left")
    # target 10 ms; measured (left / right): IC against the heel marker's touch-down 5.4 / 4.6 ms, TO 5.6 / 4.9 ms,
    # the largest pitch against the event file's IC (which marks it, 20 ms before the touch-down) 3.0 / 4.8 ms
    assert m["ic_error_median_abs_s"] <= 0.010
    assert m["to_error_median_abs_s"] <= 0.010
    assert m["largest_pitch_error_median_abs_s"] <= 0.010
    # straight strides: measured 0.043 m (left), 0.046 m (right); target 0.05 m
    assert m["stride_length_rms_error_straight_m"] <= 0.05
    # every paired stride: measured 0.042 m (left), 0.046 m (right)
    assert m["stride_length_rms_error_m"] <= 0.05


def test_gaitmap_motion_capture_is_in_step_with_the_imu():
    """The mocap clock against the IMU's: the foot's pitch rate from the markers against the gyro."""
    from footzoo.io import load

    folder = data_file("gaitmap_example", "imu_sample.csv").parent
    mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
    rec = load(folder / "imu_sample.csv", foot="left")
    axis = (mocap["L_TOE"][["x", "y", "z"]] - mocap["L_FCC"][["x", "y", "z"]]).to_numpy()
    pitch = np.unwrap(np.arctan2(axis[:, 2], np.hypot(axis[:, 0], axis[:, 1])))
    tm = np.arange(len(pitch)) / 100.0
    fine = np.arange(0.5, tm[-1] - 0.5, 0.001)
    marker_rate = np.interp(fine, tm, np.gradient(pitch, tm))
    lags = np.arange(-40, 41)  # ms
    corr = [np.corrcoef(marker_rate, np.interp(fine - lag / 1000.0, rec.t, rec.gyr[:, 1]))[0, 1] for lag in lags]
    # gaitmap's foot frame pitch (toe up) is FRD's +y rotation; measured: best at -2 ms, r = 0.99
    assert max(corr) > 0.95
    assert abs(lags[int(np.argmax(corr))]) <= 5


@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_reference_stride_length_is_gaitmaps_definition(foot):
    """gaitmap: stride length = horizontal heel displacement from the first to the last sample of the stride."""
    from footzoo.io.gaitmap_reference import reference_stride_positions, reference_strides

    folder = data_file("gaitmap_example", "imu_sample.csv").parent
    ref = reference_strides(folder, foot)
    positions = reference_stride_positions(folder, foot)
    if positions is None:
        pytest.skip("gaitmap's position_sample.csv is absent")
    per_stride = positions.groupby("stride")
    d = per_stride[["pos_x_m", "pos_y_m"]].last() - per_stride[["pos_x_m", "pos_y_m"]].first()
    # gaitmap's own per-stride heel trajectories, built from the same markers and events; measured ≤ 0.6 mm apart
    np.testing.assert_allclose(ref["stride_length_m"], np.hypot(d["pos_x_m"], d["pos_y_m"]), atol=0.002)
    # a 20 ms clock offset of the motion capture moves no reference length by more than a millimetre
    shifted = reference_strides(folder, foot, lag=0.02)
    np.testing.assert_allclose(shifted["stride_length_m"], ref["stride_length_m"], atol=0.001)


def test_gaitmap_first_stride_is_a_real_step():
    from footzoo.io import load

    rec = load(data_file("gaitmap_example", "imu_sample.csv"), foot="left")
    steps = Pipeline.from_yaml(YUN).run(rec).steps
    # the initial standing has a 5 mm twitch that used to be the first "stride" (0.005 m);
    # the first row is now the first step out of the standing (measured 1.30 m)
    assert steps["stride_length_m"].iloc[0] > 1.0
    assert np.isnan(steps["start_s"].iloc[0]) and steps["to_s"].iloc[0] > 1.0


def test_any_stance_mask_and_rate_give_a_consistent_table():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @settings(max_examples=60, deadline=None, derandomize=True, database=None)  # the same cases every CI run
    @given(st.lists(st.booleans(), min_size=3, max_size=400), st.integers(0, 2**32 - 1))
    def check(mask, seed):
        rng = np.random.default_rng(seed)
        n = len(mask)
        t = np.arange(n) / 100.0
        stance = np.asarray(mask)
        pos = np.cumsum(rng.normal(0.0, 0.05, (n, 3)), axis=0)
        gyr = rng.normal(0.0, 2.0, (n, 3))
        # half the cases with an attitude and a specific force: IC is then the contact after the largest pitch
        quat = rng.normal(size=(n, 4)) if seed % 2 else None
        quat = None if quat is None else quat / np.linalg.norm(quat, axis=1, keepdims=True)
        acc = rng.normal(0.0, 20.0, (n, 3))
        steps = segment_steps(t, stance, pos, gyr, quat=quat, acc=acc)
        assert list(steps.columns) == STEP_COLUMNS
        assert len(steps) == max(len(real_stances(stance, pos)) - 1, 0)
        if len(steps):
            assert (steps["swing_time_s"] > 0).all()
            assert (steps["stride_time_s"].dropna() > 0).all()
            assert steps["to_s"].between(t[0] - 0.01, t[-1]).all() and steps["end_s"].between(t[0], t[-1]).all()
            rate = steps[steps["events_from_rate"]]
            late = rate["end_s"] - rate["largest_pitch_s"]
            assert (late >= 0).all() and (late < CONTACT_WINDOW).all()
            if quat is None:  # no attitude: no navigation frame to take the impact in, IC is the largest pitch
                assert (late == 0).all()

    check()


# ----------------------------------------------------------------------------- IPOL hand-checked events


@pytest.mark.slow
def test_ipol_hand_checked_events_agree_on_toe_off_and_contact():
    """Voisard et al.'s annotations (18 trials, both feet): TO and IC within the ±15 ms target. The annotations mark
    the heel's touch-down, as footzoo's IC (the impact) does; the foot's largest pitch comes about 23 ms before."""
    import warnings

    from footzoo.core.errors import FootzooWarning
    from footzoo.io import load

    files = sorted(data_file("ipol_gait", "6-1_lf.txt").parent.glob("*_?f.txt"))
    ic, to, paired, strides = [], [], 0, 0
    for f in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FootzooWarning)  # the dropped packets are bridged with a warning
            rec = load(f)
            steps = Pipeline.from_yaml("recommended").run(rec).steps
        m = match_strides(steps, rec.truth.steps)
        ic.append(m["est_end_s"] - m["end_s"])
        to.append(m["est_to_s"] - m["to_s"])
        paired, strides = paired + len(m), strides + len(rec.truth.steps)
    ic, to = np.concatenate(ic), np.concatenate(to)
    assert paired / strides > 0.95  # measured 558 of 567
    assert abs(np.median(to)) <= 0.015  # measured +9.2 ms
    assert abs(np.median(ic)) <= 0.015  # measured −7.5 ms (the largest pitch: −22.8 ms)


def test_contact_is_the_impacts_onset_hand_derived():
    """A step of the acceleration inside one sample's interval: the contact where the change reaches 30 % of it.

    At 100 Hz the step of 20 m/s² starts half-way through sample 52's interval (0.515 s), so that sample holds half
    of it (10 m/s², the interval's mean) and the next ones all of it. 30 % of the largest change, 6 m/s², is reached
    between the middles of samples 51 (0) and 52 (10): 0.6 of the way from 0.505 s to 0.515 s, at 0.511 s.
    Without an impact (a change below 2 m/s²) the contact is the largest pitch itself.
    """
    from footzoo.analysis.gait_events import contact_times

    t = np.arange(100) * 0.01
    acc = np.zeros((100, 3))
    acc[52, 0], acc[53:, 0] = 10.0, 20.0
    ok = np.array([True])
    got = contact_times(t, acc, np.array([0.49]), np.array([90]), ok)
    assert got[0] == pytest.approx(0.511, abs=1e-12)
    # the window ends 60 ms after the largest pitch: an impact after it is not this contact
    assert contact_times(t, acc, np.array([0.44]), np.array([90]), ok)[0] == pytest.approx(0.44)
    # the search stops at the next stance's middle, and a change of 1.5 m/s² is no impact
    assert contact_times(t, acc, np.array([0.49]), np.array([52]), ok)[0] == pytest.approx(0.49)
    assert contact_times(t, 0.075 * acc, np.array([0.49]), np.array([90]), ok)[0] == pytest.approx(0.49)
    # the impact is never before the largest pitch, and a swing without one keeps its pitch
    assert contact_times(t, acc, np.array([0.512]), np.array([90]), ok)[0] >= 0.512
    assert contact_times(t, acc, np.array([0.49]), np.array([90]), np.array([False]))[0] == pytest.approx(0.49)
    # shapes that do not fit the samples or each other are refused, not read out of bounds
    from footzoo.core.errors import RecordingError

    with pytest.raises(RecordingError, match=r"acc must be \(N, 3\)"):
        contact_times(t, acc[:, :2], np.array([0.49]), np.array([90]), ok)
    with pytest.raises(RecordingError, match="quat"):
        contact_times(t, acc, np.array([0.49]), np.array([90]), ok, quat=np.ones((10, 4)))
    with pytest.raises(RecordingError, match="one entry per swing"):
        contact_times(t, acc, np.array([0.49, 0.6]), np.array([90]), ok)
