"""Conformance of the conventions module: NED/FRD, scalar-first body->nav quaternions."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from footzoo.core.conventions import (
    axis_map_text,
    proper_axis_maps,
    quat_conj,
    quat_from_euler,
    quat_from_matrix,
    quat_from_rotvec,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_to_euler,
    quat_to_matrix,
    skew,
    tilt_from_specific_force,
    wrap_angle,
)
from footzoo.orientation import FQAComplementary
from footzoo.orientation.fqa import fqa

rng = np.random.default_rng(42)


def random_quats(n):
    q = quat_normalize(rng.normal(size=(n, 4)))
    q[q[:, 0] < 0] *= -1
    return q


def to_scipy(q):
    return Rotation.from_quat(q[..., [1, 2, 3, 0]])


def test_matrix_matches_scipy_and_round_trips():
    q = random_quats(50)
    np.testing.assert_allclose(quat_to_matrix(q), to_scipy(q).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(quat_from_matrix(quat_to_matrix(q)), q, atol=1e-12)


def test_product_composes_rotations_and_conjugate_inverts():
    p, q = random_quats(20), random_quats(20)
    np.testing.assert_allclose(quat_to_matrix(quat_mul(p, q)), quat_to_matrix(p) @ quat_to_matrix(q), atol=1e-12)
    v = rng.normal(size=(20, 3))
    np.testing.assert_allclose(quat_rotate(quat_conj(q), quat_rotate(q, v)), v, atol=1e-12)
    # q ⊗ v ⊗ q* with v as a pure quaternion equals the matrix rotation
    vq = np.concatenate([np.zeros((20, 1)), v], axis=1)
    np.testing.assert_allclose(quat_mul(quat_mul(q, vq), quat_conj(q))[:, 1:], quat_rotate(q, v), atol=1e-12)


def test_euler_is_zyx_and_round_trips():
    rpy = np.column_stack([rng.uniform(-3, 3, 30), rng.uniform(-1.5, 1.5, 30), rng.uniform(-3, 3, 30)])
    q = quat_from_euler(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    ref = Rotation.from_euler("ZYX", rpy[:, ::-1]).as_matrix()  # intrinsic yaw, pitch, roll
    np.testing.assert_allclose(quat_to_matrix(q), ref, atol=1e-12)
    np.testing.assert_allclose(quat_to_euler(q), rpy, atol=1e-9)


def test_euler_into_a_strided_out_array_is_written_in_place_with_the_same_numbers():
    """``out`` (here the transpose of a (3, N) array, as the result table passes it) is filled and returned,
    bit for bit what a new array gets; a 90° turn to the east about down is yaw +π/2 (hand-derived)."""
    rpy = np.column_stack([rng.uniform(-3, 3, 40), rng.uniform(-1.5, 1.5, 40), rng.uniform(-3, 3, 40)])
    q = quat_from_euler(rpy[:, 0], rpy[:, 1], rpy[:, 2])
    columns = np.full((3, 40), np.nan)
    got = quat_to_euler(q, out=columns.T)
    assert got.base is columns and np.array_equal(columns.T, quat_to_euler(q))
    east = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])  # +90° about NED z (down): north -> east
    np.testing.assert_allclose(quat_to_euler(east), [0.0, 0.0, np.pi / 2], atol=1e-15)


def test_pitch_up_90_degrees_gives_pitch_plus_90():
    # pitch up: rotation of +90° about the body y axis (right); the toe (body x) then points up (NED -z)
    q = quat_from_rotvec(np.array([0.0, np.pi / 2, 0.0]))
    np.testing.assert_allclose(quat_rotate(q, [1.0, 0.0, 0.0]), [0.0, 0.0, -1.0], atol=1e-12)
    assert np.degrees(quat_to_euler(q)[1]) == pytest.approx(90.0, abs=1e-6)


def test_level_and_still_gives_identity():
    f = np.tile([0.0, 0.0, -9.81], (10, 1))
    m = np.tile([0.2, 0.0, 0.4], (10, 1))  # field pointing north and down
    np.testing.assert_allclose(fqa(f, m), np.tile([1.0, 0, 0, 0], (10, 1)), atol=1e-12)
    roll, pitch = tilt_from_specific_force(f[0])
    assert roll == pytest.approx(0.0) and pitch == pytest.approx(0.0)
    t = np.arange(200) / 100.0
    filt = FQAComplementary().estimate(t, f[[0] * 200], np.zeros((200, 3)), m[[0] * 200], np.ones(200, bool),
                                       np.array([1.0, 0, 0, 0]))
    np.testing.assert_allclose(filt.quat_[-1], [1, 0, 0, 0], atol=1e-12)


def test_positive_z_rate_turns_heading_from_north_toward_east():
    t = np.arange(101) / 100.0
    gyr = np.tile([0.0, 0.0, 0.5], (101, 1))  # +z (down) rate
    f = np.tile([0.0, 0.0, -9.81], (101, 1))
    filt = FQAComplementary(static_gain=0.0).estimate(t, f, gyr, None, np.zeros(101, bool), np.array([1.0, 0, 0, 0]))
    yaw = quat_to_euler(filt.quat_)[:, 2]
    assert yaw[-1] == pytest.approx(0.5, abs=1e-9)
    # the toe, which pointed north, now points between north and east
    toe = quat_rotate(filt.quat_[-1], [1.0, 0, 0])
    assert toe[0] > 0 and toe[1] > 0


def test_skew_and_wrap():
    a, b = rng.normal(size=3), rng.normal(size=3)
    np.testing.assert_allclose(skew(a) @ b, np.cross(a, b))
    assert wrap_angle(3 * np.pi) == pytest.approx(np.pi)
    assert wrap_angle(-3 * np.pi / 2) == pytest.approx(np.pi / 2)


def test_the_proper_axis_maps_are_the_24_rotations_of_a_cube():
    maps = proper_axis_maps()
    assert len({axis_map_text(m) for m in maps}) == 24 and axis_map_text(maps[0]) == "[x, y, z]"
    for m in maps:  # each a rotation: orthonormal, determinant +1, one ±1 per row
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=0)
        assert np.linalg.det(m) == pytest.approx(1.0) and np.all(np.count_nonzero(m, axis=1) == 1)
