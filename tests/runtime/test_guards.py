"""Pipeline guards: stance at the stillest instants of an over-long swing; the speed bound; reports and warnings."""

import warnings

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.core.errors import GuardWarning
from footzoo.runtime.guards import StanceGuard, check_speed
from footzoo.sim import NoiseModel, simulate


def _dips(rate: float):
    """A 6 s swing at |ω| = 5 rad/s with a dip to 0.2 rad/s every 0.7 s, between two 1 s stances."""
    t = np.arange(int(8 * rate)) / rate
    w = np.full(t.size, 5.0)
    centres = np.arange(1.5, 7.0, 0.7)
    for c in centres:
        w = np.minimum(w, 0.2 + 40.0 * np.abs(t - c))  # a V-shaped dip, 0.1 s below 2 rad/s
    stance = (t < 1.0) | (t >= 7.0)
    w[stance] = 0.05
    gyr = np.zeros((t.size, 3))
    gyr[:, 1] = w
    return t, gyr, stance, centres


@pytest.mark.parametrize("rate", [50.0, 200.0, 1000.0])
def test_an_over_long_swing_gets_a_stance_at_each_still_dip_at_any_rate(rate):
    t, gyr, stance, centres = _dips(rate)
    out, report = StanceGuard().apply(t, gyr, stance)
    added = out & ~stance
    runs = np.flatnonzero(np.diff(np.concatenate([[0], added.astype(np.int8), [0]]))).reshape(-1, 2)
    assert len(runs) == len(centres) == report["stances_added"]
    mid = t[(runs[:, 0] + runs[:, 1] - 1) // 2]
    np.testing.assert_allclose(mid, centres, atol=1.5 / rate + 0.011)
    assert report["long_swings"] == [[pytest.approx(1.0, abs=1 / rate), pytest.approx(7.0 - 1 / rate, abs=1e-9)]]
    assert report["longest_swing"] == pytest.approx(6.0, abs=1.5 / rate)
    np.testing.assert_array_equal(out[stance], True)  # the detector's stances stay
    assert report["samples_added"] == len(centres)  # one sample per instant by default
    wide, _ = StanceGuard(half_width=0.05).apply(t, gyr, stance)
    wide_added = wide & ~stance
    assert wide_added.sum() > added.sum() and np.all(wide_added[added])
    # widened only over samples whose averaged rate stays below 1 rad/s: within 0.03 s of the bottom
    assert np.all(np.abs(t[wide_added][:, None] - centres[None, :]).min(axis=1) <= 0.03 + 1.5 / rate)


def test_a_swing_without_a_still_instant_stays_a_swing_and_short_swings_are_left_alone():
    rate = 200.0
    t, gyr, stance, _ = _dips(rate)
    gyr[~stance, 1] = 5.0  # no dip: the foot never stops turning
    out, report = StanceGuard().apply(t, gyr, stance)
    np.testing.assert_array_equal(out, stance)
    assert report["long_swings"] and report["stances_added"] == 0
    t, gyr, stance, _ = _dips(rate)
    out, report = StanceGuard(max_swing=7.0).apply(t, gyr, stance)
    np.testing.assert_array_equal(out, stance)
    assert report["long_swings"] == [] and report["longest_swing"] == pytest.approx(6.0, abs=0.01)
    out, _ = StanceGuard(max_swing=0.0).apply(t, gyr, stance)
    np.testing.assert_array_equal(out, stance)


@pytest.fixture(scope="module")
def sprint():
    """A 4 m/s run whose stance holds the foot still for 0.04 s, with a consumer sensor's biases.

    The angular-rate machine (Γ_th = 0.1 s) finds none of its stances: one 8 s "swing".
    """
    return simulate(path="straight", n_strides=12, stride_length=2.8, cycle=0.7, stance_fraction=0.4, clearance=0.3,
                    flat_fraction=0.15, rate=200.0, profile="physical",
                    noise=NoiseModel(gyr_bias=0.01, acc_bias=0.1, seed=0), magnetometer=False, seed=0)


def _run(config: str, rec, guards: dict):
    d = Pipeline.from_yaml(config).to_dict()
    d["guards"] = guards
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = Pipeline.from_dict(d).run(rec)
    return r, [w for w in caught if issubclass(w.category, GuardWarning)]


def test_missed_running_stances_degrade_instead_of_running_away_against_simulator_truth(sprint):
    """yun2012 on the run: the travelled distance is 4.7 m off without the guard, within 1 % with it."""
    truth = np.linalg.norm(sprint.truth.pos[-1, :2] - sprint.truth.pos[0, :2])
    err = {}
    for key, guards in (("off", {"max_swing": 0}), ("on", {})):
        r, caught = _run("yun2012", sprint, guards)
        err[key] = abs(np.linalg.norm(r.pos[-1, :2] - r.pos[0, :2]) - truth)
        report = r.diagnostics["guards"]
        assert report["longest_swing"] > 8.0
        if key == "on":
            assert len(caught) == 1 and "found no stance for 8." in str(caught[0].message)
            # one per true stance between the standing start and end (the last stride lands in the final standing,
            # which the detector finds); the foot lands rolling, so |ω| stays above 1 rad/s at heel strike and no
            # still instant is taken there
            true_runs = np.count_nonzero(np.diff(sprint.truth.stance.astype(int)) == 1) + 1
            assert report["stances_added"] == true_runs - 2
            added = r.stance & ~r.diagnostics["detector_stance"]
            assert np.all(sprint.truth.stance[added])  # every added instant is where the simulated foot stands
        else:
            assert not caught and report["stances_added"] == 0
    assert err["off"] > 2.0
    assert err["on"] < 0.01 * truth


def test_the_guard_does_not_fire_on_the_papers_simulated_walks():
    rec = simulate(path="straight", n_strides=8, profile="physical", rate=100.0, noise=NoiseModel(seed=0), seed=0)
    for config in ("yun2012", "nguyen2016", "duong2015_zupt"):
        r, caught = _run(config, rec, {})
        assert not caught, config
        assert r.diagnostics["guards"]["stances_added"] == 0
        assert r.diagnostics["guards"]["longest_swing"] < 1.5
        np.testing.assert_array_equal(r.stance, r.diagnostics["detector_stance"])


def test_speed_bound_reports_a_diverged_estimate():
    t = np.arange(100) / 100.0
    vel = np.zeros((100, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_speed(t, vel, 50.0, "rec")["over_max_speed"] == 0
    vel[60:, 0] = np.linspace(10.0, 80.0, 40)
    with pytest.warns(GuardWarning, match="diverged"):
        report = check_speed(t, vel, 50.0, "rec")
    assert report["max_speed"] == pytest.approx(80.0)
    assert report["first_over_t"] == pytest.approx(t[60 + int(np.ceil((50 - 10) / (70 / 39)))])
    vel[70, 1] = np.nan
    with pytest.warns(GuardWarning):
        assert check_speed(t, vel, 50.0, "rec")["max_speed"] == np.inf


def test_guards_in_a_config_are_validated_and_round_trip():
    base = {"orientation": {"type": "fqa_complementary"}, "detector": {"type": "angular_rate_fsm"},
            "corrections": [{"type": "zvu_dedrift"}]}
    p = Pipeline.from_dict({**base, "guards": {"max_swing": 2.0}})
    assert p.to_dict()["guards"]["max_swing"] == 2.0
    assert Pipeline.from_dict(p.to_dict()).guards == p.guards
    with pytest.raises(ConfigError, match="did you mean 'max_swing'"):
        Pipeline.from_dict({**base, "guards": {"max_swng": 2.0}})
    with pytest.raises(ConfigError, match="guards.still_rate"):
        Pipeline.from_dict({**base, "guards": {"still_rate": -1.0}})
    with pytest.raises(ConfigError, match="mapping"):
        Pipeline.from_dict({**base, "guards": 3})


@pytest.mark.parametrize("config", ["yun2012", "duong2015_zupt"])
def test_real_running_trial_within_a_metre_with_the_guard(config):
    """PyShoe 2017-11-27-11-19-16 (running): the angular-rate machine finds 2 of 26 stances, the windowed
    test 2 as well; without the guard the dedrift ends 30 m off and the Kalman filter 35 m."""
    from footzoo import load
    from footzoo.evaluation.metrics import pyshoe_error

    from ..conftest import data_file

    rec = load(data_file("pyshoe_vicon", "2017-11-27-11-19-16.mat"), format="pyshoe")
    err = {}
    for key, guards in (("off", {"max_swing": 0}), ("on", {})):
        r, caught = _run(config, rec, guards)
        err[key] = pyshoe_error(r.pos, rec.truth.pos)
        assert bool(caught) == (key == "on")
    assert err["off"] > 10.0
    assert err["on"] < 0.5


def test_bias_estimates_stay_within_the_bias_guard():
    """A stance that turns at 0.2 rad/s about z for a minute (a foot pivoting in place, or a gyro far off).

    The zero-rate update takes all of it for gyro bias (0.2 rad/s, 11 °/s, 45 times the paper's
    initial bias specification); with the guard (10 initial σ = 0.044 rad/s) the estimate stays
    at the bound, the other axes' biases are estimated as without it, and the run reports it.
    """
    from footzoo import Recording

    rate, n = 100.0, 6000
    rng = np.random.default_rng(0)
    t = np.arange(n) / rate
    acc = np.tile([0.0, 0.0, -9.81], (n, 1)) + rng.normal(scale=0.01, size=(n, 3))
    gyr = np.tile([0.01, -0.02, 0.2], (n, 1)) + rng.normal(scale=0.002, size=(n, 3))
    rec = Recording(t=t, acc=acc, gyr=gyr)
    out = {}
    for limit in (0.0, 10.0):
        cfg = {"orientation": {"type": "ins"}, "detector": {"type": "angular_rate_fsm"},
               "corrections": [{"type": "ekf_zupt", "bias_limit": limit}]}
        out[limit] = Pipeline.from_dict(cfg).run(rec).diagnostics
    bound = 10.0 * np.radians(0.25)
    assert out[0.0]["gyro_bias"][-1, 2] == pytest.approx(0.2, abs=0.005)
    assert out[0.0]["bias_guard_rows"] == 0
    assert bound < out[10.0]["gyro_bias"][-1, 2] < 1.1 * bound
    np.testing.assert_allclose(out[10.0]["gyro_bias"][-1, :2], [0.01, -0.02], atol=1e-3)
    assert out[10.0]["bias_guard_rows"] > 0
    assert np.abs(out[10.0]["gyro_bias"]).max() < 1.1 * bound


def test_a_live_stream_guards_each_long_swing_once_it_has_ended_and_warns(sprint):
    """Live, the guard marks a long swing's stillest instants once it ends: the batch's stances, and a warning."""
    from footzoo.runtime.stream import Stream

    p = Pipeline.from_yaml("nguyen2016")
    batch, _ = _run("nguyen2016", sprint, {})
    assert batch.diagnostics["guards"]["stances_added"] > 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        live = Stream(p, rate=sprint.rate).run(sprint, chunk=13)
    messages = [str(w.message) for w in caught if issubclass(w.category, GuardWarning)]
    assert messages and "found no stance for" in messages[0] and "marked" in messages[0]
    np.testing.assert_array_equal(live["stance"], batch.stance)
    np.testing.assert_allclose(live["pos"], batch.pos, rtol=0, atol=1e-9)


def test_a_long_swing_without_a_still_instant_does_not_blame_the_detector():
    """The guard names the detector only when the data show the stances it missed (a still instant in the swing)."""
    t = np.arange(0.0, 10.0, 0.01)
    stance = t < 1.0  # the detector found the still start, then nothing
    for rate, blamed in ((3.0, False), (0.5, True)):  # the foot turns at 3 rad/s throughout, or lies still
        gyr = np.tile([0.0, rate, 0.0], (t.size, 1))
        gyr[t < 1.0] = 0.0
        guard = StanceGuard()
        _, report = guard.apply(t, gyr, stance)
        with pytest.warns(GuardWarning) as caught:
            guard.warn(report, "fsm", "walk")
        message = str(caught[0].message)
        assert ("misses the stances of this motion: loosen its threshold" in message) == blamed
        assert ("the detector is not shown to be at fault" in message) == (not blamed)
        assert (report["stances_added"] > 0) == blamed
