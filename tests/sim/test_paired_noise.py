"""Paired noise: one white-noise path sampled at several rates (NoiseModel.paired_rate)."""

import numpy as np
import pytest

from footzoo.sim import NoiseModel, simulate
from footzoo.sim.sensors import interval_means


def test_a_sample_is_the_mean_of_the_paths_draws_over_its_interval():
    """Hand-derived: at 100 Hz on a 1000 Hz path, sample k is the mean of the 1000 Hz samples 10(k−1)+1..10k."""
    fast = interval_means(np.random.default_rng(3), np.arange(10_000) / 1000.0, 1000.0)
    slow = interval_means(np.random.default_rng(3), np.arange(1_000) / 100.0, 1000.0)
    blocks = fast[1:9991].reshape(-1, 10, 3).mean(axis=1) * np.sqrt(10)  # unit σ at 100 Hz
    np.testing.assert_allclose(slow[1:], blocks[: slow.shape[0] - 1], rtol=1e-9, atol=1e-12)
    for x in (fast, slow):
        assert np.std(x) == pytest.approx(1.0, rel=0.05)
        assert abs(np.corrcoef(x[1:, 0], x[:-1, 0])[0, 1]) < 0.1  # white


def test_the_same_seed_gives_the_same_noise_density_at_every_rate():
    """The noise in the simulated signals, averaged over 0.1 s, is the same at 100 and 400 Hz (σ density held)."""
    walks = {}
    for rate in (100.0, 400.0):
        kw = {"n_strides": 3, "rate": rate, "profile": "physical", "magnetometer": False}
        clean = simulate(**kw, noise=NoiseModel(scale=0.0, biases=()))
        noisy = simulate(**kw, noise=NoiseModel(scale=float(np.sqrt(rate / 100.0)), biases=(), seed=5,
                                                paired_rate=4000.0))
        m = int(rate / 10)  # samples per 0.1 s
        n = (clean.t.size - 1) // m * m
        walks[rate] = [(noisy.acc - clean.acc)[1 : n + 1].reshape(-1, m, 3).mean(axis=1),
                       (noisy.gyr - clean.gyr)[1 : n + 1].reshape(-1, m, 3).mean(axis=1)]
    for a, b in zip(walks[100.0], walks[400.0], strict=True):
        k = min(len(a), len(b))
        np.testing.assert_allclose(a[:k], b[:k], rtol=1e-9, atol=1e-12)


def test_without_paired_rate_the_noise_is_drawn_per_sample_as_before():
    rng = np.random.default_rng(4)
    acc, gyr = np.zeros((50, 3)), np.zeros((50, 3))
    noisy = NoiseModel(seed=4, biases=()).apply(acc, gyr, None)
    np.testing.assert_array_equal(noisy[0], rng.standard_normal((50, 3)) * NoiseModel.acc_sigma)
    np.testing.assert_array_equal(noisy[1], rng.standard_normal((50, 3)) * NoiseModel.gyr_sigma)


def test_bad_paired_rates_are_refused_with_the_reason():
    with pytest.raises(ValueError, match="paired_rate must be a rate in Hz > 0"):
        NoiseModel(paired_rate=0.0)
    with pytest.raises(ValueError, match=r"paired_rate 50 Hz must be at least the recording's rate \(100 Hz\)"):
        simulate(n_strides=2, rate=100.0, noise=NoiseModel(paired_rate=50.0))
    with pytest.raises(ValueError, match="needs the sample times"):
        NoiseModel(paired_rate=1000.0).apply(np.zeros((5, 3)), np.zeros((5, 3)), None)


def test_the_path_drawn_block_by_block_is_the_path_drawn_at_once(monkeypatch):
    """Memory stays one block of draws; the random stream and the sums continue across the blocks exactly."""
    from footzoo.sim import sensors

    t = np.arange(3_000) / 300.0  # off the 1 kHz grid: interpolated edges fall in every block
    whole = interval_means(np.random.default_rng(9), t, 1000.0)
    monkeypatch.setattr(sensors, "PATH_BLOCK", 7)
    np.testing.assert_allclose(interval_means(np.random.default_rng(9), t, 1000.0), whole, rtol=1e-9, atol=1e-9)
    assert np.std(whole) == pytest.approx(1.0, rel=0.1)  # off the grid: a little less than 1 (interpolation)
