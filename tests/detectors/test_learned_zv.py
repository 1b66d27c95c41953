"""The learned zero-velocity detector: features, network, weights files, training, behaviour on unseen data."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo.core.conventions import GRAVITY, quat_from_euler, quat_to_matrix
from footzoo.core.errors import ConfigError
from footzoo.detectors import learned_zv_train as training
from footzoo.detectors.learned_zv import FLOORS, WINDOWS, LearnedZV, features, load_weights, probability
from footzoo.sim import simulate

from ..conftest import data_file


def test_features_of_a_still_level_sensor_are_the_floors():
    """Hand-derived: no rotation, the specific force exactly −g along z: every variance and deviation is zero."""
    n = 200
    acc = np.tile([0.0, 0.0, -GRAVITY], (n, 1))
    x = features(acc, np.zeros((n, 3)), 100.0)
    assert x.shape == (n, 4 * len(WINDOWS))
    np.testing.assert_allclose(x, np.tile(np.log(FLOORS), len(WINDOWS))[None, :].repeat(n, axis=0), atol=1e-9)


def test_features_do_not_depend_on_the_mounting():
    """Norms only: the same motion measured by a sensor turned on the foot gives the same features (to the
    rounding of ``mean ‖a‖² − ‖mean a‖²``, a difference of two numbers near g², next to its 1e-6 floor)."""
    rec = simulate("straight", n_strides=3, rate=100.0, seed=2)
    r = quat_to_matrix(quat_from_euler(0.4, -1.1, 2.5))
    np.testing.assert_allclose(features(rec.acc @ r.T, rec.gyr @ r.T, rec.rate), features(rec.acc, rec.gyr, rec.rate),
                               rtol=1e-9, atol=1e-6)


def test_probability_is_the_logistic_network_by_hand():
    rng = np.random.default_rng(0)
    w = {"mean": rng.normal(size=16), "std": rng.uniform(0.5, 2, 16), "w1": rng.normal(size=(16, 12)),
         "b1": rng.normal(size=12), "w2": rng.normal(size=12), "b2": np.asarray(0.3)}
    x = rng.normal(size=(5, 16))
    h = np.tanh(((x - w["mean"]) / w["std"]) @ w["w1"] + w["b1"])
    np.testing.assert_allclose(probability(x, w), 1.0 / (1.0 + np.exp(-(h @ w["w2"] + 0.3))), rtol=1e-12)


@pytest.mark.parametrize("rate", [100.0, 400.0])
def test_on_the_simulator_it_finds_every_stance_inside_the_true_one(rate):
    """Trained on PyShoe's real trials only: on simulated walks (another foot, another sensor, any rate) every
    detected stance lies inside a true one, and every stride is found."""
    rec = simulate("straight", n_strides=10, rate=rate, seed=1)
    det = LearnedZV().detect(rec.t, rec.acc, rec.gyr)
    truth = rec.truth.stance
    assert np.mean(det.stance_ & ~truth) < 0.01  # (almost) no stance in a swing
    onsets = np.flatnonzero(det.stance_[1:] & ~det.stance_[:-1])
    true_onsets = np.flatnonzero(truth[1:] & ~truth[:-1])
    assert len(onsets) == len(true_onsets)
    assert 0.6 < det.stance_.sum() / truth.sum() <= 1.0


def test_the_same_walk_at_two_rates_gives_the_same_stance_durations():
    """Every window is a duration: the stance fraction does not move with the rate."""
    fractions = [LearnedZV().detect(r.t, r.acc, r.gyr).stance_.mean()
                 for r in (simulate("straight", n_strides=8, rate=rate, seed=4) for rate in (100.0, 250.0, 1000.0))]
    assert max(fractions) - min(fractions) < 0.01


def test_a_bad_weights_file_is_a_config_error_naming_the_fix(tmp_path):
    with pytest.raises(ConfigError, match="does not exist.*learned_zv_train"):
        load_weights(str(tmp_path / "missing.npz"))
    bad = tmp_path / "bad.npz"
    np.savez(bad, mean=np.zeros(3))
    with pytest.raises(ConfigError, match="not a weights file"):
        load_weights(str(bad))
    wrong = tmp_path / "wrong.npz"
    np.savez(wrong, mean=np.zeros(3), std=np.ones(3), w1=np.zeros((3, 12)), b1=np.zeros(12), w2=np.zeros(12),
             b2=np.asarray(0.0))
    with pytest.raises(ConfigError, match="shape"):
        load_weights(str(wrong))


def test_training_is_reproducible_and_learns_the_simulators_stance(tmp_path):
    """Trained on simulated walks with their true stance, it separates stance and swing of another walk."""
    trials = [(features(r.acc, r.gyr, r.rate), r.truth.stance)
              for r in (simulate("straight", n_strides=6, rate=100.0, seed=s) for s in (1, 2))]
    a = training.train(trials, max_iter=150)
    b = training.train(trials, max_iter=150)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])
    test = simulate("straight", n_strides=6, rate=100.0, seed=3)
    assert training.accuracy(a, (features(test.acc, test.gyr, test.rate), test.truth.stance)) > 0.95
    path = training.save(a, tmp_path / "sim.npz")
    det = LearnedZV(weights=str(path)).detect(test.t, test.acc, test.gyr)
    assert np.mean(det.stance_ == test.truth.stance) > 0.95


def test_the_shipped_weights_agree_with_pyshoes_labels_on_a_walking_trial():
    """In-sample (the shipped weights saw this trial): the decision matches the labels PyShoe navigated best with."""
    path = data_file("pyshoe_vicon", "2017-11-22-11-22-03.mat")
    assert training.accuracy(load_weights(str(training.SHIPPED_WEIGHTS)), training.trial_data(path)) > 0.85
