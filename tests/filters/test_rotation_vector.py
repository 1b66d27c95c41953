"""The quaternion of a rotation vector (:func:`footzoo.filters.strapdown.rotvec_quat`) against scipy's rotations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from footzoo.filters.strapdown import SERIES_HALF_ANGLE, rotvec_quat, series_rotvec_quat


def scipy_quat(r: np.ndarray) -> np.ndarray:
    """Scalar-first unit quaternion of the rotation vector r (rad), sign fixed to a non-negative scalar."""
    x, y, z, w = Rotation.from_rotvec(r).as_quat()
    return np.array([w, x, y, z])


def directions(n: int, seed: int) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


# half-angles from a still foot's noise to a sprint at a low rate, both sides of the series' bound
HALF_ANGLES = [0.0, 1e-9, 1e-4, 0.01, 0.1, SERIES_HALF_ANGLE * (1 - 1e-12), SERIES_HALF_ANGLE * (1 + 1e-12), 0.5,
               1.5, 3.0]


@pytest.mark.parametrize("half", HALF_ANGLES)
def test_rotvec_quat_equals_scipy_to_rounding(half):
    for u in directions(20, seed=int(half * 1e6) % 1000):
        r = 2.0 * half * u
        q = np.array(rotvec_quat(*r))
        np.testing.assert_allclose(q, scipy_quat(r), rtol=0, atol=4e-16)
        assert abs(np.linalg.norm(q) - 1.0) < 4e-16


@pytest.mark.parametrize("half", [0.05, 0.25, 0.5])
def test_the_series_is_exact_to_its_documented_bound(half):
    """The series alone (as the consistency scan uses it up to h = 0.5): omitted terms below 1e-15."""
    for u in directions(20, seed=3):
        r = 2.0 * half * u
        np.testing.assert_allclose(np.array(series_rotvec_quat(*r)), scipy_quat(r), rtol=0,
                                   atol=1e-15 if half == 0.5 else 4e-16)
