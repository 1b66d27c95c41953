"""The swing residuals of the gyroscope-accelerometer scan against a plain strapdown written with scipy's rotations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from footzoo.core.conventions import GRAVITY
from footzoo.filters.consistency import _SCALE, _SIGNS, SERIES_HALF_ANGLE, _residuals
from footzoo.sim import NoiseModel, simulate


def reference(t, acc, gyr, a, b, scale, signs, g):
    """|v| / (g T) per column: q <- q ⊗ exp(ω s dt / 2), v <- v + (R(q) f + [0, 0, g]) s dt, from the tilt at ``a``."""
    fx, fy, fz = acc[a]
    roll, pitch = np.arctan2(-fy, -fz), np.arctan2(fx, np.hypot(fy, fz))
    out = []
    for s, sign in zip(scale, signs, strict=True):
        q = Rotation.from_euler("ZYX", [0.0, pitch, roll])  # body -> NED, yaw 0
        v = np.zeros(3)
        for i in range(a, b):
            dt = (t[i + 1] - t[i]) * s
            v += q.apply(acc[i]) * dt + np.array([0.0, 0.0, g]) * dt
            q = q * Rotation.from_rotvec(gyr[i] * sign * dt)
        out.append(np.linalg.norm(v) / (g * (t[b] - t[a]) * s))
    return np.array(out)


@pytest.mark.parametrize("rate", [100.0, 12.0])  # 12 Hz: a sample's rotation beyond the series' range
def test_every_column_equals_a_plain_strapdown(rate):
    walk = simulate(n_strides=3, rate=rate, profile="physical", noise=NoiseModel(seed=0))
    stance = walk.truth.stance
    edges = np.flatnonzero(np.diff(stance.astype(int)))
    a, b = int(edges[0]), int(edges[1]) + 1  # the first swing: its last stance sample to its first
    half = 0.5 * np.max(np.linalg.norm(walk.gyr[a:b], axis=1) * np.diff(walk.t[a:b + 1])) * _SCALE.max()
    assert (half <= SERIES_HALF_ANGLE) == (rate == 100.0)  # both ways of integrating are exercised
    out = np.empty((1, len(_SCALE)))
    _residuals(walk.t, walk.acc, walk.gyr, np.array([a]), np.array([b]), _SCALE, _SIGNS, GRAVITY, out)
    expected = reference(walk.t, walk.acc, walk.gyr, a, b, _SCALE, _SIGNS, GRAVITY)
    np.testing.assert_allclose(out[0], expected, rtol=1e-10, atol=1e-13)


def test_a_sensor_at_rest_leaves_no_residual_in_any_column():
    n = 50
    t = np.arange(n) / 100.0
    acc = np.tile([0.0, 0.0, -GRAVITY], (n, 1))  # level, at rest: the specific force is -g along down
    out = np.empty((1, len(_SCALE)))
    _residuals(t, acc, np.zeros((n, 3)), np.array([0]), np.array([n - 1]), _SCALE, _SIGNS, GRAVITY, out)
    np.testing.assert_allclose(out, 0.0, atol=1e-15)
