"""SpeedAdaptiveSHOE: swing speeds against the simulator's truth, hand-made cases, rates and speeds, PyShoe counts."""

import numpy as np
import pandas as pd
import pytest

import footzoo
from footzoo.detectors.adaptive_shoe import adaptive_threshold_kernel
from footzoo.detectors.runs import close_short_swings
from footzoo.detectors.shoe import SHOE
from footzoo.detectors.speed_adaptive_shoe import (
    SpeedAdaptiveSHOE,
    close_still_gaps,
    drop_pauses,
    speed_per_sample,
    swing_speeds,
)
from footzoo.evaluation.metrics import intervals, stance_scores

from ..conftest import KOROGLU_MOUNTING, data_file
from .sims import GAITS, RATES, walk


def _provisional(rec):
    d = SpeedAdaptiveSHOE()
    T = SHOE().detect(rec.t, rec.acc, rec.gyr).statistic_
    prov, _, _ = adaptive_threshold_kernel(rec.t, T, d.threshold, d.time_constant, d.max_threshold, rec.t[0])
    return close_short_swings(prov, int(round(d.min_swing * rec.rate)))


@pytest.mark.parametrize("gait", list(GAITS))
def test_swing_speeds_follow_the_simulated_foot(gait):
    """Each swing's peak speed from the levelled, dedrifted strapdown equals the simulator's within 3 %."""
    rec = walk(gait, 200.0)
    stance = _provisional(rec)
    starts, ends, peaks, speed = swing_speeds(rec.t, np.ascontiguousarray(rec.acc), np.ascontiguousarray(rec.gyr),
                                              stance, 0.1)
    true_speed = np.linalg.norm(rec.truth.vel, axis=1)
    inner = np.isfinite(peaks)
    assert inner.sum() >= 6
    for s, e, p in zip(starts[inner], ends[inner], peaks[inner], strict=True):
        assert p == pytest.approx(true_speed[s:e].max(), rel=0.03)
    assert np.all(speed[stance] == 0.0)


def test_swing_speeds_do_not_depend_on_the_mounting():
    """Upside down (half a turn about x) and yawed 40°: the same speeds."""
    rec = walk("walk_1.4", 100.0)
    stance = _provisional(rec)
    a = np.radians(40.0)
    yaw = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    flip = np.diag([1.0, -1.0, -1.0])
    r = flip @ yaw  # body vectors in the new sensor frame
    args = (np.ascontiguousarray(rec.acc @ r.T), np.ascontiguousarray(rec.gyr @ r.T))
    _, _, p0, _ = swing_speeds(rec.t, np.ascontiguousarray(rec.acc), np.ascontiguousarray(rec.gyr), stance, 0.1)
    _, _, p1, _ = swing_speeds(rec.t, *args, stance, 0.1)
    np.testing.assert_allclose(p1, p0, rtol=1e-9)


def test_the_threshold_follows_the_speed_of_the_bounding_swings():
    """Hand-made: swings at 2-3 s (peak 1 m/s) and 6-7 s (peak 4 m/s), reach 0.5 s, 10 Hz."""
    t = np.arange(0.0, 10.0, 0.1)
    starts = np.array([20, 60])
    ends = np.array([30, 70])
    v = speed_per_sample(t, starts, ends, np.array([1.0, 4.0]), 0.5)
    assert np.all(v[:15] == 0.0)  # still, further than 0.5 s from any swing
    assert np.all(v[15:35] == 1.0)  # the first swing and half a second on either side
    assert np.all(v[35:55] == 0.0)
    assert np.all(v[55:75] == 4.0)
    # a brief "swing" inside a stance (peak 0.05 m/s) next to a real one keeps the real one's speed
    v = speed_per_sample(t, np.array([20, 32]), np.array([30, 34]), np.array([3.0, 0.05]), 0.5)
    assert np.all(v[30:34] == 3.0)
    # unknown speeds (the recording's ends) take the nearest known one; none known: zero
    v = speed_per_sample(t, np.array([0, 60]), np.array([10, 70]), np.array([np.nan, 2.0]), 0.5)
    assert np.all(v[:10] == 2.0)
    assert not speed_per_sample(t, starts, ends, np.array([np.nan, np.nan]), 0.5).any()


def test_only_still_short_gaps_are_closed():
    s = np.array([1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 1], bool)
    speed = np.zeros(s.size)
    speed[6:8] = 2.0  # the foot moved in the second gap
    np.testing.assert_array_equal(close_still_gaps(s, 3, speed, 0.5),
                                  [1, 1, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 1])


def test_a_pause_in_the_air_is_not_a_stance():
    """Stance, 2 moving samples, a 2-sample pause, a long swing, 2-sample landing motion, stance (min 3 samples)."""
    s = np.array([1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1, 1], bool)
    np.testing.assert_array_equal(drop_pauses(s, 3),
                                  [1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1])
    # short stances a full swing apart (running) are kept
    r = np.array([0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0], bool)
    np.testing.assert_array_equal(drop_pauses(r, 3), r)


def test_the_simulated_foot_pausing_in_the_air_gives_no_extra_stances():
    """The simulator's physical run stops the foot after the push-off and before the landing (|v| = 0 in the
    air): raised thresholds see those pauses, :func:`drop_pauses` removes them (every stride found, none extra)."""
    from footzoo.evaluation.metrics import step_detection
    from footzoo.sim import simulate

    rec = simulate(path="run", n_strides=20, rate=200.0, profile="physical", noise={"scale": 1.0, "seed": 0})
    d = SpeedAdaptiveSHOE().detect(rec.t, rec.acc, rec.gyr)
    r = step_detection(d.stance_, rec.truth.stance, rec.t)
    assert r["missed"] == 0 and r["false_steps"] == 0 and r["split"] == 0


def test_the_threshold_grows_from_slow_walking_to_running():
    found = {g: SpeedAdaptiveSHOE().detect(walk(g, 200.0).t, walk(g, 200.0).acc, walk(g, 200.0).gyr) for g in GAITS}
    speed = {g: np.median(d.speed_) for g, d in found.items()}
    gamma = {g: np.median(d.threshold_) for g, d in found.items()}
    assert speed["slow_0.3"] < speed["walk_1.4"] < speed["run_4.0"]
    assert gamma["slow_0.3"] < gamma["walk_1.4"] <= gamma["run_4.0"] == SpeedAdaptiveSHOE().max_threshold


@pytest.mark.parametrize("gait", list(GAITS))
def test_navigation_holds_on_the_simulator_at_every_speed(gait):
    """A 9-state ZUPT filter with this detector tracks the simulated foot within 0.1 m (ARMSE), 100 and 200 Hz."""
    cfg = {"name": "x", "orientation": {"type": "ins"}, "detector": {"type": "speed_adaptive_shoe"},
           "navigation": {"attitude_noise": 1e-6, "velocity_noise": 0.03, "initial_attitude_std": 0.063},
           "corrections": [{"type": "zupt", "velocity_std": 0.03}]}
    for rate in (100.0, 200.0):
        res = footzoo.Pipeline.from_dict(cfg).run(walk(gait, rate))
        assert res.metrics["armse_3d_m"] < 0.1


def test_stance_is_stable_across_rates():
    for gait in GAITS:
        f1 = [stance_scores(SpeedAdaptiveSHOE().detect(walk(gait, r).t, walk(gait, r).acc, walk(gait, r).gyr).stance_,
                            walk(gait, r).truth.stance)["f1"] for r in RATES]
        assert min(f1) > 0.9, (gait, f1)
        assert max(f1) - min(f1) < 0.05, (gait, f1)


def test_pyshoe_strides_walking_and_running_match_the_hand_counts():
    """Köroğlu's hand counts on every PyShoe walking and running trial tagged bipedal: within 20 %.

    (A fixed SHOE threshold finds 3-17 of 13-43 running strides; the defaults were chosen on the
    trajectory error, not on these counts.)
    """
    import scipy.io

    trials = pd.read_csv(data_file("pyshoe_vicon", "trials.csv")).set_index("trial")
    chosen = trials[(trials["bipedal_tag_koroglu"] == 1) & trials.index.str.startswith("2017")]
    assert len(chosen) >= 25
    for trial, row in chosen.iterrows():
        m = scipy.io.loadmat(data_file("pyshoe_vicon", f"{trial}.mat"))
        imu, t = m["imu"], m["ts"].ravel()
        found = len(intervals(SpeedAdaptiveSHOE().detect(t, imu[:, :3], imu[:, 3:]).stance_)) - 1
        assert abs(found - row["n_strides_manual_koroglu"]) <= 0.2 * row["n_strides_manual_koroglu"], trial


# the mounting report finds these sensors' x axis pointing backwards (expected warning; strides do not depend on it)
@pytest.mark.filterwarnings(KOROGLU_MOUNTING)
@pytest.mark.parametrize("experiment", [31, 32, 33])
def test_koroglu_strides_exact_and_no_stance_in_mid_swing(experiment):
    """Köroğlu's walks (200 Hz): the hand-counted strides exactly.

    In experiment 33 a dip of SHOE's statistic in mid-swing (10 ms, 0.55 s after the stance
    before it) passes the raised threshold; the strapdown sees the foot moving there, faster
    than ``still_speed``, so it is no stance: after the first step no two stances start within
    0.4 s of each other.
    """
    rec = footzoo.load(data_file("koroglu_gcp", f"SensorConnectData_{experiment}.csv"), format="sensorconnect")
    if experiment == 33:
        d = SpeedAdaptiveSHOE().detect(rec.t, rec.acc, rec.gyr)
        onsets = rec.t[intervals(d.stance_)[:, 0]]
        assert np.diff(onsets)[2:].min() > 0.4
    cfg = {"name": "x", "orientation": {"type": "ins"}, "detector": {"type": "speed_adaptive_shoe"},
           "corrections": [{"type": "zupt"}]}
    assert footzoo.Pipeline.from_dict(cfg).run(rec).metrics["stride_count_error"] == 0


@pytest.mark.parametrize("rate", [250.0, 400.0])
def test_a_stop_in_the_air_before_a_stair_is_no_stance_without_the_provisional_closing(rate):
    """Simulated stairs at 250 and 400 Hz: every stance found, its edges within two samples and 20 ms.

    A foot that stops in the air before it lands on a step and moves again makes a short provisional
    swing; closing it hid its motion from the speed test (stances 0.14 s early at 250 Hz and above on a
    simulated foot that hovered with its pitch rate near zero). The physical simulator's foot keeps
    turning until the heel comes down (measured onset error of the closing setting now +5 ms), so only
    the setting's own stances are checked here."""
    from footzoo.evaluation.metrics import step_detection
    from footzoo.sim import simulate

    rec = simulate(path="stairs", n_strides=6, landing_strides=3, cycle=1.2, clearance=0.1, rate=rate,
                   profile="physical", noise={"scale": 1.0, "seed": 0}, magnetometer=False)
    before = SpeedAdaptiveSHOE().detect(rec.t, rec.acc, rec.gyr)
    after = SpeedAdaptiveSHOE(provisional_min_swing=0.0).detect(rec.t, rec.acc, rec.gyr)
    right = step_detection(after.stance_, rec.truth.stance, rec.t)
    assert right["error_rate"] == 0.0
    assert abs(right["onset_error_mean_s"]) < 2.0 / rate and abs(right["offset_error_mean_s"]) < 0.02
    # the default (None) is min_swing: the detector as before
    same = SpeedAdaptiveSHOE(provisional_min_swing=0.15).detect(rec.t, rec.acc, rec.gyr)
    np.testing.assert_array_equal(same.stance_, before.stance_)
