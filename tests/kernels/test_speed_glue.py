"""The compiled glue (strapdown helpers, dedrift, FPA, sample table) gives the numbers of the numpy code it replaced.

Each ``_reference_*`` below is the previous implementation, kept verbatim (vectorised numpy or a
Python loop over swings / heel strikes), run on a simulated walk. Speed itself: benchmarks/.
"""

import numpy as np
import pandas as pd
import pytest

from footzoo import Pipeline
from footzoo.analysis.fpa import HuangFPA
from footzoo.core.conventions import gravity_ned, quat_mul, quat_normalize, quat_rotate, quat_to_euler, wrap_angle
from footzoo.core.table import samples_frame
from footzoo.corrections.zvu_dedrift import swing_segments, zvu_dedrift
from footzoo.evaluation.metrics import intervals
from footzoo.filters.strapdown import integrate_position, integrate_velocity, motion_acceleration, sample_intervals
from footzoo.sim import NoiseModel, simulate


def _reference_motion_acceleration(q, acc, g):
    prev = np.concatenate([q[:1], q[:-1]])
    prev = np.where(np.sum(prev * q, axis=1, keepdims=True) < 0, -prev, prev)
    return quat_rotate(quat_normalize(prev + q), acc) + gravity_ned(g)


def _reference_integrate_velocity(acc_nav, dt, v0=None):
    v = np.cumsum(acc_nav * dt[:, None], axis=0)
    return v if v0 is None else v + v0


def _reference_integrate_position(vel, dt, p0=None):
    steps = np.zeros_like(vel)
    steps[1:] = 0.5 * (vel[1:] + vel[:-1]) * dt[1:, None]
    p = np.cumsum(steps, axis=0)
    return p if p0 is None else p + p0


def _reference_zvu_dedrift(t, acc_nav, stance):
    n = t.shape[0]
    vel = np.zeros((n, 3))
    dt = sample_intervals(t)
    biases = []
    for i0, stop in swing_segments(stance):
        end = min(stop + 1, n)
        v = np.cumsum(acc_nav[i0:end] * dt[i0:end, None], axis=0)
        if stop < n:
            elapsed = t[i0:end] - t[i0 - 1]
            eps = v[-1] / elapsed[-1]
            v = v - eps[None, :] * elapsed[:, None]
            biases.append(eps)
        vel[i0:stop] = v[: stop - i0]
    return vel, _reference_integrate_position(vel, dt), np.array(biases).reshape(-1, 3)


def _reference_fpa(fpa_plugin, t, quat, pos, stance, side):
    f_s = np.asarray(fpa_plugin.foot_vector, float)
    f_s = f_s / np.linalg.norm(f_s)
    f_e = quat_rotate(quat, f_s)
    psi_f = np.arctan2(f_e[:, 1], f_e[:, 0])
    hs = intervals(stance)[:, 0]
    fpa = np.full(len(hs), np.nan)
    h = None
    for i in range(1, len(hs)):
        r = pos[hs[i], :2] - pos[hs[i - 1], :2]
        h = r if h is None else fpa_plugin.alpha * r + (1 - fpa_plugin.alpha) * h
        if np.linalg.norm(h) == 0:
            continue
        stride = t[hs[i + 1]] - t[hs[i]] if i + 1 < len(hs) else t[hs[i]] - t[hs[i - 1]]
        stance_time = fpa_plugin.stance_fraction * stride
        lo = np.searchsorted(t, t[hs[i]] + fpa_plugin.window[0] * stance_time, side="left")
        hi = np.searchsorted(t, t[hs[i]] + fpa_plugin.window[1] * stance_time, side="right")
        if hi <= lo:
            continue
        fpa[i] = float(np.mean(side * wrap_angle(psi_f[lo:hi] - np.arctan2(h[1], h[0]))))
    return fpa


@pytest.fixture(scope="module")
def walk():
    """A noisy simulated walk with toe-out, its truth attitude and a detector's stance mask."""
    rec = simulate(n_strides=25, profile="physical", rate=100.0, noise=NoiseModel(seed=3), fpa=0.15)
    return rec


def _close(a, b):
    scale = max(float(np.max(np.abs(b))), 1.0)
    assert a.shape == b.shape
    assert np.max(np.abs(a - b)) <= 1e-9 * scale


def test_strapdown_helpers_equal_the_numpy_code(walk):
    q, acc, dt = walk.truth.quat, walk.acc, sample_intervals(walk.t)
    flipped = q * np.where(np.arange(len(q)) % 7 == 3, -1.0, 1.0)[:, None]  # sign flips: same attitude
    for quat in (q, flipped):
        _close(motion_acceleration(quat, acc, 9.81), _reference_motion_acceleration(quat, acc, 9.81))
    a = motion_acceleration(q, acc, 9.81)
    _close(integrate_velocity(a, dt), _reference_integrate_velocity(a, dt))
    v0, p0 = np.array([0.1, -0.2, 0.3]), np.array([1.0, 2.0, -3.0])
    _close(integrate_velocity(a, dt, v0), _reference_integrate_velocity(a, dt, v0))
    _close(integrate_position(walk.truth.vel, dt, p0), _reference_integrate_position(walk.truth.vel, dt, p0))


def test_motion_acceleration_rejects_mismatched_shapes():
    with pytest.raises(ValueError, match="quat"):
        motion_acceleration(np.ones((5, 4)), np.ones((4, 3)))


@pytest.mark.parametrize("lead", [True, False])
def test_dedrift_equals_the_swing_loop(walk, lead):
    """With a leading swing (skipped) and an open swing at the end; and starting in stance."""
    a = motion_acceleration(walk.truth.quat, walk.acc, 9.81)
    stance = walk.truth.stance.copy()
    end = np.flatnonzero(~stance)[-1] - 3  # cut inside the last swing: it stays open
    t, a, stance = walk.t[:end], a[:end], stance[:end]
    if lead:
        stance[:5] = False
    got, ref = zvu_dedrift(t, a, stance), _reference_zvu_dedrift(t, a, stance)
    assert got[2].shape == ref[2].shape and ref[2].shape[0] > 10
    for x, y in zip(got, ref, strict=True):
        _close(x, y)


def test_fpa_equals_the_heel_strike_loop(walk):
    p = Pipeline.from_dict({"orientation": {"type": "madgwick"}, "detector": {"type": "huang_stance"},
                            "corrections": [{"type": "zvu_dedrift"}]})
    res = p.run(walk)
    fpa = HuangFPA(foot="right")
    for side in ("right", "left"):
        fpa.foot = side
        got = fpa.analyze(walk.t, res.quat, res.pos, res.stance, {}).fpa_
        ref = _reference_fpa(fpa, walk.t, res.quat, res.pos, res.stance, 1 if side == "right" else -1)
        assert np.isfinite(ref).sum() > 10
        np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))
        _close(got[np.isfinite(got)], ref[np.isfinite(ref)])


def test_sample_table_equals_the_dict_frame(walk):
    q, t = walk.truth.quat, walk.t
    pos, vel = walk.truth.pos, walk.truth.vel
    acc = motion_acceleration(q, walk.acc)
    euler = quat_to_euler(q)
    ref = pd.DataFrame({
        "t": t, "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2], "qz": q[:, 3],
        "roll": euler[:, 0], "pitch": euler[:, 1], "yaw": euler[:, 2],
        "pos_n": pos[:, 0], "pos_e": pos[:, 1], "pos_d": pos[:, 2],
        "vel_n": vel[:, 0], "vel_e": vel[:, 1], "vel_d": vel[:, 2],
        "acc_n": acc[:, 0], "acc_e": acc[:, 1], "acc_d": acc[:, 2], "stance": walk.truth.stance})
    got = samples_frame(t, q, pos, vel, acc, walk.truth.stance)
    assert list(got.columns) == list(ref.columns)
    assert (got.dtypes == ref.dtypes).all()
    for col in ref.columns[:-1]:
        _close(got[col].to_numpy(), ref[col].to_numpy())
    np.testing.assert_array_equal(got["stance"].to_numpy(), ref["stance"].to_numpy())


def _reference_complementary(q0, acc, gyr, mag, dt, gain):
    """The previous two-pass filter: the FQA quaternion of every sample first, then the sample loop."""
    import math

    from footzoo.orientation.fqa import fqa_sample

    n = len(dt)
    q_s, yaw = np.empty((n, 4)), np.empty(n)
    for k in range(n):
        if mag is not None:
            w, x, y, z = fqa_sample(*acc[k], *mag[k], True)
        else:
            w, x, y, z = fqa_sample(*acc[k], 0.0, 0.0, 0.0, False)
        r = gyr[k] * 0.5 * dt[k]
        angle = math.sqrt(float(r @ r))
        kk = math.sin(0.5 * angle) / angle if angle > 1e-12 else 0.5 - angle * angle / 48.0
        d = np.array([math.cos(0.5 * angle), *(kk * r)])
        q_s[k] = quat_mul(np.array([w, x, y, z]), d)
        yaw[k] = math.atan2(2.0 * (q_s[k, 0] * q_s[k, 3] + q_s[k, 1] * q_s[k, 2]),
                            1.0 - 2.0 * (q_s[k, 2] ** 2 + q_s[k, 3] ** 2))
    out = np.empty((n, 4))
    q = np.asarray(q0, float)
    for k in range(n):
        g = gyr[k] * dt[k]
        ang = math.sqrt(float(g @ g))
        d = np.array([math.cos(0.5 * ang), *(g * math.sin(0.5 * ang) / ang)]) if ang > 1e-12 else \
            np.array([1.0, *(0.5 * g)])
        p = quat_mul(q, d)
        kk = gain[k] * dt[k]
        if kk != 0.0:
            s = q_s[k].copy()
            if mag is None:
                psi = math.atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] ** 2 + q[3] ** 2)) - yaw[k]
                s = quat_mul(np.array([math.cos(0.5 * psi), 0.0, 0.0, math.sin(0.5 * psi)]), s)
            if s @ p < 0.0:
                s = -s
            p = p + kk * (s - p)
        q = p / math.sqrt(float(p @ p))
        out[k] = q
    return out


@pytest.mark.parametrize("use_mag", [True, False])
def test_complementary_filter_equals_the_two_pass_loop(walk, use_mag):
    from footzoo.orientation import FQAComplementary

    n = 1500
    t, acc, gyr, mag = walk.t[:n], walk.acc[:n], walk.gyr[:n], walk.mag[:n]
    stance = walk.truth.stance[:n]
    # the two-pass loop has no disturbance rejection: compared without it (the simulated push-off turns the foot
    # fast while |f| passes g, where the dip test takes a few samples for disturbed)
    f = FQAComplementary(static_gain=1.05, dynamic_gain=0.3, use_magnetometer=use_mag, mag_rejection=False)
    got = f.estimate(t, acc, gyr, mag, stance, walk.truth.quat[0]).quat_
    ref = _reference_complementary(walk.truth.quat[0], acc, gyr, mag if use_mag else None, sample_intervals(t),
                                   f.gain_)
    _close(got, ref)


def _reference_first_still_window(t, gyr, duration, max_gyr):
    still = np.linalg.norm(gyr, axis=1) <= max_gyr
    edges = np.flatnonzero(still[1:] != still[:-1]) + 1
    bounds = np.concatenate([[0], edges, [still.shape[0]]])
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        if still[a] and t[b - 1] - t[a] >= duration:
            stop = int(np.searchsorted(t, t[a] + duration, side="right"))
            if stop - a >= 2:
                return int(a), stop
    return None


@pytest.mark.parametrize("still_from", [0, 4090, 5000, 20000, None])
def test_first_still_window_reads_chunks_but_finds_the_same_window(still_from):
    from footzoo.core.errors import RecordingError
    from footzoo.runtime.alignment import first_still_window

    rng = np.random.default_rng(0)
    n = 30000
    t = np.arange(n) / 100.0
    gyr = rng.normal(0.0, 1.0, (n, 3))
    gyr[::7] = 0.0  # many short still runs that are too short
    if still_from is not None:
        gyr[still_from:still_from + 60] = 0.01  # 0.6 s still
    ref = _reference_first_still_window(t, gyr, 0.5, 0.6)
    if ref is None:
        with pytest.raises(RecordingError, match="still period"):
            first_still_window(t, gyr, 0.5, 0.6)
    else:
        assert abs(ref[0] - still_from) <= 1  # a zeroed sample may join the still run
        assert first_still_window(t, gyr, 0.5, 0.6) == ref


def _reference_hdr(quat, acc_nav, stance, threshold):
    """The previous per-stride loop of HDR without a Kalman filter (eqs. 23–27)."""
    import math

    from footzoo.core.conventions import quat_yaw

    yaw = quat_yaw(quat)
    out = acc_nav.copy()
    ends, biases = [], []
    st = intervals(stance)
    for j, (_start, b) in enumerate(st):
        d = None
        if len(ends) >= 2:
            a0, b0 = ends[-1], ends[-2]
            mean = math.atan2(math.sin(a0) + math.sin(b0), math.cos(a0) + math.cos(b0))
            d = float(wrap_angle(yaw[b - 1] - mean))
            d = d if abs(d) <= threshold else None
        ends.append(float(yaw[b - 1]))
        biases.append(np.nan if d is None else d)
        if d is None:
            continue
        stop = st[j + 1, 0] if j + 1 < len(st) else len(stance)
        c, s = math.cos(-d), math.sin(-d)
        n, e = out[b:stop, 0].copy(), out[b:stop, 1].copy()
        out[b:stop, 0] = c * n - s * e
        out[b:stop, 1] = s * n + c * e
    return out, np.array(biases)


def test_hdr_swing_rotation_equals_the_stride_loop(walk):
    from footzoo.core.conventions import quat_from_euler
    from footzoo.corrections.hdr import HDR

    rng = np.random.default_rng(4)
    stance = walk.truth.stance
    # the true attitude with a heading that wanders by up to ±0.6 rad between strides: some δψ kept, some rejected
    steps = np.cumsum(~stance[1:] & stance[:-1])
    wander = np.concatenate([[0.0], rng.uniform(-0.6, 0.6, steps[-1] + 1)[steps]])
    quat = quat_mul(quat_from_euler(np.zeros_like(wander), np.zeros_like(wander), wander), walk.truth.quat)
    acc = motion_acceleration(quat, walk.acc)
    h = HDR(threshold=0.3)
    got = h.apply_acceleration(quat, acc, stance)
    ref, ref_bias = _reference_hdr(quat, acc, stance, 0.3)
    assert np.isfinite(ref_bias).sum() >= 3 and np.isnan(ref_bias[2:]).sum() >= 3
    np.testing.assert_array_equal(np.isnan(h.bias_), np.isnan(ref_bias))
    _close(h.bias_[np.isfinite(ref_bias)], ref_bias[np.isfinite(ref_bias)])
    _close(got, ref)
