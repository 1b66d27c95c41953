"""The velocity process noise that grows with the acceleration (``navigation.impact_noise``)."""

from __future__ import annotations

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.filters.engine import NavigationNoise
from footzoo.filters.eskf import ErrorStateFilter, Layout, transition
from footzoo.filters.process_noise import Noise, velocity_variance
from footzoo.sim import NoiseModel, simulate

BASE = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}]}


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=12, profile="physical", rate=100.0, noise=NoiseModel(seed=3))


def test_one_prediction_by_hand():
    layout = Layout([("pos", 3), ("vel", 3)])
    q = np.array([0.0, 0.0, 0.0, 0.01, 0.01, 0.01])
    noise = Noise(q, impact=2e-5, integration=0.0)
    kf = ErrorStateFilter(layout, np.zeros(6), noise)
    a = np.array([30.0, -10.0, 40.0])  # a heel strike's motion acceleration (m/s²)
    dt = 0.005
    kf.predict(transition(layout, np.eye(3), a, dt), dt, velocity_variance(noise, a, np.zeros((2, 3)), 1, dt))
    # from P = 0: P_vel = (q_v + impact |a|²) dt on each axis, P_pos still 0 (Φ moves it at the next step)
    np.testing.assert_allclose(np.diag(kf.P)[3:], (0.01 + 2e-5 * 2600.0) * dt, rtol=1e-15)
    np.testing.assert_array_equal(np.diag(kf.P)[:3], 0.0)


def test_compiled_loop_equals_the_reference_with_the_impact_noise_on(walk):
    p = Pipeline.from_dict({**BASE, "navigation": {"impact_noise": 3e-5}, "smoother": "rts"})
    ref = p.run(walk, engine="reference", covariance=True)
    fast = p.run(walk, engine="fast", covariance=True)
    np.testing.assert_allclose(fast.diagnostics["P_diag"], ref.diagnostics["P_diag"], rtol=1e-9, atol=1e-15)
    assert np.max(np.abs(fast.pos - ref.pos)) <= 1e-9 * max(np.abs(ref.pos).max(), 1.0)


def test_it_adds_velocity_uncertainty_where_the_foot_accelerates_only(walk):
    off = Pipeline.from_dict(BASE).run(walk, covariance=True).diagnostics["P_diag"]
    on = Pipeline.from_dict({**BASE, "navigation": {"impact_noise": 3e-5}}).run(walk, covariance=True)
    p_on = on.diagnostics["P_diag"]
    vel = slice(6, 9)  # att, pos, vel in the 9-state filter
    still = np.flatnonzero(walk.t <= walk.t[0] + 0.4)
    np.testing.assert_allclose(p_on[still][:, vel], off[still][:, vel], rtol=1e-3)  # at rest: |a| ≈ noise
    swing = ~walk.truth.stance
    assert np.median(p_on[swing][:, vel] / off[swing][:, vel]) > 1.3  # measured 1.42
    assert np.isfinite(on.pos).all()


def test_the_setting_is_validated_and_reported():
    with pytest.raises(ConfigError, match="impact_noise"):
        NavigationNoise(impact_noise=-1.0)
    p = Pipeline.from_dict({**BASE, "navigation": {"impact_noise": 1e-5}})
    assert p.to_dict()["navigation"]["impact_noise"] == 1e-5
    assert NavigationNoise().impact_noise == 0.0  # off by default: the papers' uniform noise
