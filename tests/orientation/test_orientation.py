"""FQA and the adaptive-gain complementary filter (Yun 2012) against independent references."""

import numpy as np
import pytest
from ahrs.filters import FQA as AhrsFQA

from footzoo.core.conventions import quat_conj, quat_from_rotvec, quat_mul, quat_normalize, quat_rotate, quat_to_euler
from footzoo.orientation import FQAComplementary
from footzoo.orientation.fqa import fqa, fqa_tilt

rng = np.random.default_rng(7)
INCLINATION = np.radians(60.0)
M_REF = np.array([np.cos(INCLINATION), 0.0, np.sin(INCLINATION)])  # NED: north and down


def random_attitudes(n, max_pitch=1.3):
    rpy = np.column_stack([rng.uniform(-3, 3, n), rng.uniform(-max_pitch, max_pitch, n), rng.uniform(-3, 3, n)])
    from footzoo.core.conventions import quat_from_euler

    return quat_from_euler(*rpy.T)


def test_fqa_matches_ahrs_through_the_convention_adapter():
    # ahrs' FQA expects a level sensor to read [0, 0, -g] like FRD; its reference field is given in NED
    q = random_attitudes(200)
    f = quat_rotate(quat_conj(q), np.array([0.0, 0.0, -9.81]))
    m = quat_rotate(quat_conj(q), M_REF * 0.5)
    ours = fqa(f, m)
    ahrs = np.array([AhrsFQA(mag_ref=M_REF).estimate(f[i].copy(), m[i].copy()) for i in range(len(q))])
    same = np.abs(np.sum(ours * ahrs, axis=1))
    np.testing.assert_allclose(same, 1.0, atol=1e-9)
    # and both recover the true attitude
    np.testing.assert_allclose(np.abs(np.sum(ours * q, axis=1)), 1.0, atol=1e-9)


def test_fqa_tilt_recovers_roll_and_pitch_only():
    q = random_attitudes(100)
    f = quat_rotate(quat_conj(q), np.array([0.0, 0.0, -9.81]))
    e_true, e_est = quat_to_euler(q), quat_to_euler(fqa_tilt(f))
    np.testing.assert_allclose(e_est[:, :2], e_true[:, :2], atol=1e-9)
    np.testing.assert_allclose(e_est[:, 2], 0.0, atol=1e-9)


def test_zero_gain_reproduces_exact_gyro_integration():
    n, dt = 500, 0.01
    t = np.arange(n) * dt
    gyr = rng.normal(scale=2.0, size=(n, 3))
    q = np.array([1.0, 0, 0, 0])
    expected = [q]
    for k in range(1, n):
        q = quat_mul(q, quat_from_rotvec(gyr[k] * dt))
        expected.append(q)
    f = np.tile([0.0, 0.0, -9.81], (n, 1))
    out = FQAComplementary(0.0, 0.0).estimate(t, f, gyr, None, np.ones(n, bool), np.array([1.0, 0, 0, 0])).quat_
    np.testing.assert_allclose(out, np.array(expected), atol=1e-10)


def test_steady_state_tilt_error_is_bias_over_gain():
    # hand-derived: a still sensor with gyro bias b about x and gain k settles where k·e = b, e ≈ b/k (rad)
    b, k, n, dt = 0.01, 2.0, 3000, 0.01
    t = np.arange(n) * dt
    gyr = np.tile([b, 0.0, 0.0], (n, 1))
    f = np.tile([0.0, 0.0, -9.81], (n, 1))
    out = FQAComplementary(k, 0.0).estimate(t, f, gyr, None, np.ones(n, bool), np.array([1.0, 0, 0, 0])).quat_
    roll = quat_to_euler(out[-1])[0]
    assert roll == pytest.approx(b / k, rel=0.02)


def test_magnetometer_corrects_heading_and_without_it_heading_is_kept():
    n, dt = 2000, 0.01
    t = np.arange(n) * dt
    true = quat_normalize(np.array([np.cos(0.4), 0.0, 0.0, np.sin(0.4)]))  # heading 0.8 rad
    f = np.tile(quat_rotate(quat_conj(true), np.array([0, 0, -9.81])), (n, 1))
    m = np.tile(quat_rotate(quat_conj(true), M_REF), (n, 1))
    still = np.ones(n, bool)
    q0 = np.array([1.0, 0, 0, 0])
    with_mag = FQAComplementary(1.05).estimate(t, f, np.zeros((n, 3)), m, still, q0).quat_
    assert quat_to_euler(with_mag[-1])[2] == pytest.approx(0.8, abs=1e-6)
    q0_tilted = quat_normalize(np.array([1.0, 0.1, 0.0, 0.3]))
    no_mag = FQAComplementary(1.05).estimate(t, f, np.zeros((n, 3)), None, still, q0_tilted).quat_
    e0, e1 = quat_to_euler(q0_tilted), quat_to_euler(no_mag[-1])
    assert e1[0] == pytest.approx(0.0, abs=1e-6) and e1[1] == pytest.approx(0.0, abs=1e-6)
    assert e1[2] == pytest.approx(e0[2], abs=0.02)  # heading is not pulled to north


def test_gain_switches_with_the_gait_phase():
    n = 10
    t = np.arange(n) * 0.01
    stance = np.array([1, 1, 0, 0, 1, 0, 1, 1, 0, 0], bool)
    f = FQAComplementary(1.05, 0.2).estimate(t, np.tile([0, 0, -9.81], (n, 1)), np.zeros((n, 3)), None, stance,
                                             np.array([1.0, 0, 0, 0]))
    np.testing.assert_array_equal(f.gain_, np.where(stance, 1.05, 0.2))
