"""Angular-rate FSM (Yun 2012) and zero-velocity dedrift on hand-made cases."""

import numpy as np
import pytest

from footzoo.corrections.zvu_dedrift import swing_segments, zvu_dedrift
from footzoo.detectors import AngularRateFSM, dated_and_online_states


def test_state_machine_ignores_short_runs_and_dates_switches_back():
    c = np.array([1, 1, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 1, 1], bool)
    dated, online = dated_and_online_states(c, 3)
    # the 4-sample swing run at 5..8 switches; the 2-sample still run at 3..4 is too short to be stance, so
    # the swing is dated back across it to the motion at 2 (a toe roll before the toe-off dip);
    # the 1-sample blip at 9 is ignored; stance run at 12..15 switches back, dated to 12
    np.testing.assert_array_equal(dated, [1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1])
    # the live machine learns each switch Γ_th - 1 samples later
    np.testing.assert_array_equal(online, [1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 1, 1])


def test_detector_threshold_and_sample_count_from_seconds():
    rate = 100.0
    t = np.arange(100) / rate
    w = np.zeros((100, 3))
    w[30:60, 1] = 3.0  # 0.3 s of swing
    w[45:47, 1] = 0.1  # a 20 ms dip inside the swing
    det = AngularRateFSM(threshold=0.6, min_duration=0.05).detect(t, np.zeros((100, 3)), w)
    assert det.min_samples_ == 5
    expected = np.ones(100, bool)
    # the rate steps from 0 to 3 rad/s between samples 29 and 30 (and back between 59 and 60): linearly
    # interpolated it crosses 0.6 rad/s at 29.2 and 59.8, inside the intervals of samples 29 and 60
    expected[29:61] = False
    np.testing.assert_array_equal(det.stance_, expected)
    np.testing.assert_allclose(det.statistic_, np.linalg.norm(w, axis=1))


@pytest.mark.parametrize("bad", [{"threshold": -1}, {"threshold": "x"}, {"min_duration": -0.1}])
def test_detector_rejects_bad_parameters(bad):
    from footzoo.core.errors import ConfigError
    from footzoo.plugins.registry import build

    name = next(iter(bad))
    with pytest.raises(ConfigError, match=name):
        build("detector", {"type": "angular_rate_fsm", **bad})
    with pytest.raises(ConfigError, match=name):
        AngularRateFSM(**bad).check_params()


def test_dedrift_removes_a_constant_bias_exactly():
    # hand-derived: swing of T = 0.5 s with a(t) = A sin(2πt/T) (velocity returns to 0) plus a bias ε
    rate, T, A, eps = 1000.0, 0.5, 10.0, np.array([0.3, -0.2, 0.5])
    t = np.arange(int(2.0 * rate) + 1) / rate
    stance = ~((t > 0.5) & (t < 0.5 + T))
    a = np.zeros((t.size, 3))
    sw = ~stance
    # interval-average acceleration of sample k over (t[k-1], t[k]]
    tk, tk1 = t[sw] - 0.5, t[sw] - 0.5 - 1 / rate
    avg = A * T / (2 * np.pi) * (np.cos(2 * np.pi * tk1 / T) - np.cos(2 * np.pi * tk / T)) * rate
    a[sw, 0] = avg
    a[sw] += eps
    vel, pos, bias = zvu_dedrift(t, a, stance)
    assert bias.shape == (1, 3)
    # the mean over the swing interval including the closing sample
    np.testing.assert_allclose(bias[0], eps * (T - 1 / rate) / T, rtol=0, atol=0.02)
    v_true = A * T / (2 * np.pi) * (1 - np.cos(2 * np.pi * (t - 0.5) / T)) * sw
    assert np.abs(vel[:, 0] - v_true).max() < 0.01
    # displacement of the swing: ∫ v = A T² / (2π)
    assert pos[-1, 0] == pytest.approx(A * T**2 / (2 * np.pi), rel=2e-3)
    np.testing.assert_allclose(pos[-1, 1:], 0.0, atol=2e-3)
    assert np.all(vel[stance] == 0.0)


def test_swing_segments_skip_a_leading_swing_and_mark_an_open_one():
    s = np.array([0, 0, 1, 1, 0, 0, 1, 0, 0], bool)
    assert swing_segments(s) == [(4, 6), (7, 9)]
