"""Yun 2012's angular-rate FSM: heel and toe roll are not stance; hysteresis in both directions."""

import numpy as np
import pytest

from footzoo.detectors import AngularRateFSM, dated_and_online_states
from footzoo.evaluation.metrics import intervals, stance_scores
from footzoo.sim import simulate

from .sims import GAITS, RATES, walk


def test_a_dip_before_a_confirmed_run_is_dated_into_the_swing():
    """still ×6, roll ×2, dip ×1, swing ×6, still ×6 with Γ = 3: the roll and the dip belong to the swing."""
    c = np.array([1] * 6 + [0] * 2 + [1] + [0] * 6 + [1] * 6, dtype=bool)
    dated, online = dated_and_online_states(c, 3)
    np.testing.assert_array_equal(dated, [1] * 6 + [0] * 9 + [1] * 6)
    # the live machine switches when a run reaches Γ samples
    np.testing.assert_array_equal(online, [1] * 11 + [0] * 6 + [1] * 4)


def test_a_spike_in_stance_is_ignored():
    c = np.array([1] * 6 + [0] * 2 + [1] * 6, dtype=bool)
    dated, online = dated_and_online_states(c, 3)
    assert dated.all() and online.all()


def test_heel_and_toe_roll_are_not_stance_on_a_noise_free_physical_walk():
    rec = simulate(path="straight", n_strides=10, profile="physical", rate=100.0)
    d = AngularRateFSM().detect(rec.t, rec.acc, rec.gyr)
    s = stance_scores(d.stance_, rec.truth.stance)
    assert s["recall"] == 1.0
    assert s["precision"] > 0.95  # 0.84 when a swing was dated back only to after the toe-off dip
    # every detected stance starts after the heel roll's peak rate and ends before the toe roll's
    w = np.linalg.norm(rec.gyr, axis=1)
    for a, b in intervals(d.stance_)[1:-1]:
        assert w[a:b].max() < 1.0


@pytest.mark.parametrize("rate", [50.0, 100.0, 200.0, 1000.0])
def test_no_stance_sample_while_the_simulated_foot_moves(rate):
    """The stance's edge samples are tested over their interval: no stance sample while the foot moves fast.

    At 100 Hz the first sample of the heel rise has |ω| = 0.47 rad/s (below Ω_th) and 2.9 at the
    next one, while the simulated sensor already moves at 0.18 m/s: tested at its instant only, it
    was stance once per stride, and each swing's dedrift started from a wrong zero.
    With the interval test the fastest stance sample moves at 0.00, 0.00, 0.05 and 0.07 m/s at
    50, 100, 200 and 1000 Hz (|ω| below Ω_th as the toe roll starts).
    """
    rec = simulate(path="straight", n_strides=10, profile="physical", rate=rate)
    d = AngularRateFSM().detect(rec.t, rec.acc, rec.gyr)
    speed = np.linalg.norm(rec.truth.vel, axis=1)
    inner = np.ones(rec.n, bool)
    inner[: int(rate)] = inner[-int(rate):] = False  # away from the still start and end
    assert speed[d.stance_ & inner].max() < 0.1
    instant, _ = dated_and_online_states(d.statistic_ < 0.6, d.min_samples_)
    if rate == 100.0:
        assert speed[instant & inner].max() > 0.15


def test_the_interval_test_keeps_a_short_run_stance_at_a_low_rate():
    """A 4 m/s run at 50 Hz: Γ_th (0.1 s) is counted on the instants, so trimming the edges loses no stance."""
    rec = walk("run_4.0", 50.0)
    d = AngularRateFSM().detect(rec.t, rec.acc, rec.gyr)
    assert len(intervals(d.stance_)) == len(intervals(rec.truth.stance))


@pytest.mark.parametrize("gait", list(GAITS))
def test_stance_against_simulator_truth_at_every_rate(gait):
    f1 = []
    for rate in RATES:
        rec = walk(gait, rate)
        f1.append(stance_scores(AngularRateFSM().detect(rec.t, rec.acc, rec.gyr).stance_, rec.truth.stance)["f1"])
    assert min(f1) > 0.95
    assert max(f1) - min(f1) < 0.03
