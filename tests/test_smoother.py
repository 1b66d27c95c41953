"""RTS smoothing of the Kalman pipelines: forward pass unchanged, both engines equal, closer to the truth."""

import numpy as np
import pytest

from footzoo import ConfigError, Pipeline
from footzoo.sim import NoiseModel, simulate


@pytest.fixture(scope="module")
def walk():
    return simulate(n_strides=20, profile="physical", rate=100.0, noise=NoiseModel(seed=3), clearance=0.1)


def _pipeline(name, smoother):
    d = Pipeline.from_yaml(name).to_dict()
    return Pipeline.from_dict({**d, "smoother": smoother})


def _rmse(pos, truth):
    return float(np.sqrt(np.mean(np.sum((pos - truth) ** 2, axis=1))))


def test_the_smoother_leaves_the_forward_pass_unchanged_and_gets_closer_to_the_truth(walk):
    forward = _pipeline("duong2015_zupt", "none").run(walk)
    smoothed = _pipeline("duong2015_zupt", "rts").run(walk)
    np.testing.assert_array_equal(smoothed.diagnostics["pos_forward"], forward.pos)
    assert smoothed.config["smoother"] == "rts"
    # the heading (unobservable) dominates the position error; the velocity shows the smoothing
    before, after = _rmse(forward.vel, walk.truth.vel), _rmse(smoothed.vel, walk.truth.vel)
    assert after < 0.9 * before, (before, after)
    # the last sample has seen all data already: the smoother leaves it as it is
    np.testing.assert_allclose(smoothed.pos[-1], forward.pos[-1], atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["duong2015_zupt", "nguyen2016"])
def test_both_engines_smooth_alike(walk, name):
    p = _pipeline(name, "rts")
    fast, ref = p.run(walk, engine="fast"), p.run(walk, engine="reference")
    scale = np.abs(ref.pos).max()
    assert np.abs(fast.pos - ref.pos).max() <= 1e-9 * scale
    assert np.abs(fast.quat - ref.quat).max() <= 1e-9


def test_smoothing_needs_a_kalman_filter_and_a_known_name():
    with pytest.raises(ConfigError, match="smooths the Kalman filter, and this pipeline has none"):
        _pipeline("yun2012", "rts")
    with pytest.raises(ConfigError, match=r"smoother must be one of \['none', 'rts'\]"):
        _pipeline("duong2015_zupt", "kalman")


def test_the_error_state_backward_pass_equals_filterpys_rts_smoother_on_a_linear_system():
    """A closed-loop error-state filter on x' = F x + w, z = H x + v, smoothed with footzoo's
    backward pass, equals filterpy's standard RTS smoother on the same system."""
    from filterpy.kalman import KalmanFilter

    from footzoo.filters.smoother import rts_backward, smoother_gain

    rng = np.random.default_rng(0)
    dt, n_steps = 0.01, 300
    F = np.eye(6)
    F[:3, 3:] = dt * np.eye(3)
    Q = np.diag([1e-4] * 3 + [1e-2] * 3) * dt
    H = np.hstack([np.zeros((3, 3)), np.eye(3)])
    R = np.eye(3) * 0.01**2
    x = np.zeros(6)
    zs, measured = [], []
    for k in range(n_steps):
        x = F @ x + rng.multivariate_normal(np.zeros(6), Q)
        zs.append(H @ x + rng.normal(0, 0.01, 3))
        measured.append((k // 40) % 2 == 0)  # "stance" every other 40 samples
    p0 = np.diag([1e-6] * 3 + [1e-4] * 3)
    # filterpy, standard form
    kf = KalmanFilter(dim_x=6, dim_z=3)
    kf.F, kf.Q, kf.H, kf.R, kf.P = F, Q, H, R, p0.copy()
    means, covs = [kf.x[:, 0].copy()], [kf.P.copy()]
    for k in range(1, n_steps):
        kf.predict()
        if measured[k]:
            kf.update(zs[k])
        means.append(kf.x[:, 0].copy())
        covs.append(kf.P.copy())
    expected, *_ = kf.rts_smoother(np.array(means)[:, :, None], np.array(covs), Fs=[F] * n_steps, Qs=[Q] * n_steps)
    # closed-loop error-state form: nominal estimate, error estimate fed back and reset
    nominal = np.zeros((n_steps, 6))
    P = p0.copy()
    gains, dxs = np.zeros((n_steps, 6, 6)), np.zeros((n_steps, 6))
    work = (np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty(6, dtype=np.int64))
    for k in range(1, n_steps):
        nominal[k] = F @ nominal[k - 1]
        M = F @ P
        P = M @ F.T + Q
        smoother_gain(M, P, gains[k - 1], *work)
        if measured[k]:
            S = H @ P @ H.T + R
            K = P @ H.T @ np.linalg.inv(S)
            dx = K @ (H @ nominal[k] - zs[k])  # residual: predicted − measured = H δ
            nominal[k] -= dx
            dxs[k] = dx
            P = (np.eye(6) - K @ H) @ P @ (np.eye(6) - K @ H).T + K @ R @ K.T
    np.testing.assert_allclose(nominal, np.array(means), atol=1e-12)
    pos, vel = nominal[:, :3].copy(), nominal[:, 3:].copy()
    rts_backward(gains, dxs, np.array([-1, -1, 0, 3, -1]), True, np.zeros((n_steps, 4)), vel, pos,
                 np.zeros((n_steps, 3)), np.zeros((n_steps, 3)))
    np.testing.assert_allclose(np.hstack([pos, vel]), expected[:, :, 0], atol=1e-9)
