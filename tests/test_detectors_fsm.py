"""Yun 2012's angular-rate FSM: heel and toe roll are not stance; hysteresis in both directions."""

import numpy as np
import pytest

from footzoo.detectors import AngularRateFSM, dated_and_online_states
from footzoo.metrics import intervals, stance_scores
from footzoo.sim import simulate

from .detector_sims import GAITS, RATES, walk


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


@pytest.mark.parametrize("gait", list(GAITS))
def test_stance_against_simulator_truth_at_every_rate(gait):
    f1 = []
    for rate in RATES:
        rec = walk(gait, rate)
        f1.append(stance_scores(AngularRateFSM().detect(rec.t, rec.acc, rec.gyr).stance_, rec.truth.stance)["f1"])
    assert min(f1) > 0.95
    assert max(f1) - min(f1) < 0.03
