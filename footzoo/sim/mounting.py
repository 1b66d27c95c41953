"""A simulated walk seen by a sensor turned on the foot: the 24 proper axis permutations, any rotation.

A sensor mounted with the rotation ``M`` (sensor axes in the original body frame: ``v_body = M · v_sensor``)
measures ``a' = Mᵀ a``, ``ω' = Mᵀ ω`` and ``m' = Mᵀ m``; its true attitude is ``q ⊗ q(M)``. Reading a
recording with a wrong but right-handed axis map is the same thing: the data of another proper mounting.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.conventions import axis_map_text, proper_axis_maps, quat_from_matrix, quat_mul
from ..core.data import Recording


def proper_axis_permutations() -> list[np.ndarray]:
    """The 24 signed permutation matrices with determinant +1 (the rotations of a cube), identity first
    (:func:`footzoo.core.conventions.proper_axis_maps`)."""
    return proper_axis_maps()


def axis_map_name(m: np.ndarray) -> str:
    """``[x, -z, y]``: the sensor axis that each body axis (rows of ``m``) is (core.conventions.axis_map_text)."""
    return axis_map_text(m)


def remount(rec: Recording, m: np.ndarray) -> Recording:
    """``rec`` as measured by a sensor mounted with the rotation ``m`` (3, 3) (``v_body = m · v_sensor``).

    The readings are rotated (``a' = mᵀ a``), the true attitude becomes ``q ⊗ q(m)``; positions,
    velocities, stances and events are the same physical ones.

    Raises
    ------
    ValueError
        ``m`` is not a rotation (orthonormal, determinant +1).
    """
    m = np.asarray(m, dtype=float)
    if m.shape != (3, 3) or not np.allclose(m @ m.T, np.eye(3), atol=1e-9) or np.linalg.det(m) < 0:
        raise ValueError(f"mounting {m.tolist()} is not a rotation matrix (orthonormal with determinant +1); "
                         "a mirror image is no mounting")

    def sensor(v: np.ndarray | None) -> np.ndarray | None:
        return None if v is None else v @ m  # rows: (mᵀ v)ᵀ = vᵀ m

    truth = rec.truth
    if truth is not None and truth.quat is not None:
        qm = np.broadcast_to(quat_from_matrix(m), truth.quat.shape)
        truth = replace(truth, quat=quat_mul(truth.quat, qm))
    meta = {k: v for k, v in rec.meta.items() if k != "axes"}  # the map it was read with no longer applies
    return replace(rec, acc=sensor(rec.acc), gyr=sensor(rec.gyr), mag=sensor(rec.mag), truth=truth, meta=meta)
