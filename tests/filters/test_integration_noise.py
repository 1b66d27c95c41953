"""Velocity noise for an interval whose specific force the samples do not resolve (``navigation.integration_noise``)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline, Stream
from footzoo.filters.engine import NavigationNoise
from footzoo.filters.eskf import ErrorStateFilter, Layout, transition
from footzoo.filters.process_noise import UNIFORM_TIMING, Noise, velocity_variance
from footzoo.sim import NoiseModel, simulate

BASE = {"orientation": {"type": "ins"}, "detector": {"type": "shoe"}, "corrections": [{"type": "zupt"}],
        "smoother": "rts"}
GAITMAP = Path(__file__).resolve().parents[3] / "shared" / "data" / "gaitmap_example"


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=12, profile="physical", rate=100.0, noise=NoiseModel(seed=3))


def with_kappa(kappa: float, **more) -> dict:
    return {**BASE, "navigation": {"integration_noise": kappa, **more}}


def unresolved_impacts(rec, size: float = 300.0):
    """The walk with a one-sample spike of ``size`` m/s² along x just before every stance (an impact the
    samples misread), and the first stance samples."""
    stance = np.asarray(rec.truth.stance, bool)
    starts = np.flatnonzero(stance[1:] & ~stance[:-1]) + 1
    starts = starts[starts > int(rec.rate)]  # after the still start
    acc = rec.acc.copy()
    acc[starts - 1, 0] += size
    return dataclasses.replace(rec, acc=acc), starts


def test_uniform_timing_is_the_sigma_of_a_uniform_instant():
    u = np.linspace(-0.5, 0.5, 2_000_001)
    assert math.isclose(UNIFORM_TIMING, float(np.sqrt(np.mean(u**2))), rel_tol=1e-6)


def test_one_prediction_by_hand():
    layout = Layout([("pos", 3), ("vel", 3)])
    q = np.array([0.0, 0.0, 0.0, 0.01, 0.01, 0.01])
    noise = Noise(q, impact=0.0, integration=0.3)
    kf = ErrorStateFilter(layout, np.zeros(6), noise)
    dt = 0.005
    # a heel strike between two samples: f_k − f_{k−1} = (120, −40, 90) m/s²
    acc = np.array([[1.0, 2.0, -9.8], [1.0 + 120.0, 2.0 - 40.0, -9.8 + 90.0]])
    kf.predict(transition(layout, np.eye(3), np.zeros(3), dt), dt, velocity_variance(noise, np.zeros(3), acc, 1, dt))
    # from P = 0: P_vel = q_v dt + (κ |Δf| dt)² on each axis (|Δf|² = 24100), P_pos still 0
    np.testing.assert_allclose(np.diag(kf.P)[3:], 0.01 * dt + (0.3 * dt) ** 2 * 24100.0, rtol=1e-15)
    np.testing.assert_array_equal(np.diag(kf.P)[:3], 0.0)


def test_compiled_loop_and_checkpointed_smoother_equal_the_reference(walk):
    rec, _ = unresolved_impacts(walk)
    p = Pipeline.from_dict(with_kappa(UNIFORM_TIMING, impact_noise=1e-5))
    ref = p.run(rec, engine="reference", covariance=True)
    fast = p.run(rec, engine="fast", covariance=True)
    np.testing.assert_allclose(fast.diagnostics["P_diag"], ref.diagnostics["P_diag"], rtol=1e-9, atol=1e-15)
    assert np.max(np.abs(fast.pos - ref.pos)) <= 1e-9 * max(np.abs(ref.pos).max(), 1.0)


def test_off_by_default_and_bit_for_bit_the_uniform_noise(walk):
    assert NavigationNoise().integration_noise == 0.0
    a = Pipeline.from_dict(BASE).run(walk)
    b = Pipeline.from_dict(with_kappa(0.0)).run(walk)
    np.testing.assert_array_equal(a.pos, b.pos)


def test_the_uncertainty_grows_where_the_specific_force_jumps_only(walk):
    rec, starts = unresolved_impacts(walk)
    off = Pipeline.from_dict(BASE).run(rec, covariance=True).diagnostics["P_diag"]
    on = Pipeline.from_dict(with_kappa(UNIFORM_TIMING)).run(rec, covariance=True).diagnostics["P_diag"]
    vel = slice(6, 9)  # att, pos, vel in the 9-state filter
    jump = on[starts - 1][:, vel] - off[starts - 1][:, vel]
    # the spike sample: |Δf| ≈ 300 m/s², κ|Δf|dt ≈ 0.87 m/s, variance ≈ 0.75 (m/s)² on each axis
    assert np.all(jump > 0.5)
    still = np.flatnonzero(walk.t <= walk.t[0] + 0.4)
    np.testing.assert_allclose(on[still][:, vel], off[still][:, vel], rtol=1e-3)  # at rest: noise only


def test_the_setting_is_validated_and_reported():
    with pytest.raises(ConfigError, match="integration_noise"):
        NavigationNoise(integration_noise=-0.1)
    p = Pipeline.from_dict(with_kappa(0.29))
    assert p.to_dict()["navigation"]["integration_noise"] == 0.29


@pytest.mark.skipif(not (GAITMAP / "mocap_sample.csv").exists(), reason="needs ../shared/data/gaitmap_example")
@pytest.mark.parametrize("foot", ["left", "right"])
def test_gaitmap_stride_lengths_against_motion_capture(foot):
    """gaitmap's example (204.8 Hz, hard heel strikes): the recommended setting with the impacts' timing
    noise against the motion-capture stride lengths (0.053 / 0.050 m RMS with the uniform noise)."""
    from footzoo.config.library import path
    from footzoo.io import load

    rec = load(GAITMAP / "imu_sample.csv", format="gaitmap", foot=foot)
    cfg = Pipeline.from_yaml(path("recommended")).to_dict()
    uniform = Pipeline.from_dict(cfg).run(rec).metrics["stride_length_rms_error_m"]
    cfg["navigation"] = {**cfg["navigation"], "integration_noise": UNIFORM_TIMING}
    timed = Pipeline.from_dict(cfg).run(rec).metrics["stride_length_rms_error_m"]
    assert timed < 0.03 < uniform - 0.015


@pytest.mark.slow  # the integration noise live with the step-wise smoother: kernels no shipped config uses (12 s)
def test_live_chunks_give_the_batch_numbers(walk):
    """The change ``f_k − f_{k−1}`` spans the chunks' borders: live (step-wise smoothing) equals the batch run."""
    rec, _ = unresolved_impacts(walk)
    p = Pipeline.from_dict({**with_kappa(UNIFORM_TIMING), "smoother": "stepwise"})
    final = Stream(p, rate=rec.rate).run(rec, chunk=np.random.default_rng(2).integers(1, 40, size=101))
    batch = p.run(rec)
    scale = max(float(np.abs(batch.pos).max()), 1.0)
    assert float(np.abs(final["pos"] - batch.pos).max()) <= 1e-9 * scale
    off = Pipeline.from_dict({**BASE, "smoother": "stepwise"}).run(rec)
    assert float(np.abs(off.pos - batch.pos).max()) > 1e-3  # the noise changed the estimate
