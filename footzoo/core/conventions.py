"""Frames, units and quaternion algebra: the only place footzoo defines them.

Conventions (binding for every module):

* Navigation frame **NED**: x north, y east, z down. Gravity is ``[0, 0, +g]``.
* Body frame **FRD**: x toward the toe, y to the right, z down. A level sensor at
  rest measures the specific force ``[0, 0, -g]``.
* Quaternions are scalar first ``[w, x, y, z]`` and rotate body -> navigation:
  ``v_n = q ⊗ v_b ⊗ q*``.
* Euler angles use the aerospace **Z-Y-X** sequence (yaw ψ about z, then pitch θ
  about the new y, then roll φ about the new x): ``R = Rz(ψ) Ry(θ) Rx(φ)``.
  Positive pitch lifts the toe, positive yaw turns north toward east.
* Units: s, m, m/s², rad/s, rad. Magnetometer readings may be in any unit.
* Axis maps (how a sensor's axes become FRD) are written ``[x, -y, -z]``: the sensor axis
  that each FRD axis is, in the order x, y, z (:func:`axis_map_text`); a map that is no signed
  permutation is its rotation matrix, by rows: ``[[0.866025, 0, -0.5], [0, 1, 0], [0.5, 0, 0.866025]]``.

All functions accept a single quaternion/vector or a stack of them (leading
axes broadcast) and never modify their inputs.
"""

from __future__ import annotations

import itertools

import numpy as np

#: Standard gravity used by default (m/s²).
GRAVITY: float = 9.81

#: Units footzoo uses internally, by signal.
SI_UNITS: dict[str, str] = {
    "t": "s",
    "acc": "m/s^2",
    "gyr": "rad/s",
    "mag": "any (direction only)",
    "dist": "m",
    "pos": "m",
    "vel": "m/s",
}

#: Factors that convert a declared unit into footzoo's internal unit.
ACC_UNITS: dict[str, float] = {"m/s^2": 1.0, "m/s2": 1.0, "g": GRAVITY, "mg": GRAVITY / 1000.0}
GYR_UNITS: dict[str, float] = {"rad/s": 1.0, "deg/s": np.pi / 180.0}
DIST_UNITS: dict[str, float] = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}
#: Units of a time column (seconds per unit).
TIME_UNITS: dict[str, float] = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9, "min": 60.0, "h": 3600.0}


def axis_map_text(rows: np.ndarray) -> str:
    """An axis map as footzoo writes it in every message, document and option: ``[x, -y, -z]``.

    ``rows`` (3, 3): the FRD axes in sensor coordinates (``v_FRD = rows · v_sensor``). A signed
    permutation is written as the sensor axis each FRD axis is (``[x, -y, -z]``: FRD x is the
    sensor's x, FRD y its −y, FRD z its −z); any other matrix as its rows to 6 significant digits
    (``[[0.866025, 0, -0.5], [0, 1, 0], [0.5, 0, 0.866025]]``). Both forms read back as they are
    (``axes=`` of every reader, ``axes:`` of a sidecar).
    """
    m = np.asarray(rows, dtype=float)
    names = []
    for row in m:
        k = int(np.argmax(np.abs(row)))
        if not np.isclose(abs(row[k]), 1.0) or np.count_nonzero(np.round(row, 12)) != 1:
            return "[" + ", ".join("[" + ", ".join(f"{v:.6g}" if v else "0" for v in r) + "]" for r in m) + "]"
        names.append(("-" if row[k] < 0 else "") + "xyz"[k])
    return "[" + ", ".join(names) + "]"


def proper_axis_maps() -> list[np.ndarray]:
    """The 24 axis maps that are rotations (signed permutations with determinant +1), ``[x, y, z]`` first."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            m = np.zeros((3, 3))
            m[np.arange(3), perm] = signs
            if np.linalg.det(m) > 0:
                out.append(m)
    return out


def gravity_ned(g: float = GRAVITY) -> np.ndarray:
    """Gravity vector in NED (m/s²): ``[0, 0, +g]``."""
    return np.array([0.0, 0.0, float(g)])


def quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` of scalar-first quaternions (..., 4)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def quat_conj(q: np.ndarray) -> np.ndarray:
    """Conjugate ``q*`` (the inverse of a unit quaternion), (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternion(s) ``q / |q|``; raises on a zero quaternion."""
    q = np.asarray(q, dtype=float)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(n == 0.0):
        raise ValueError("cannot normalise a zero quaternion")
    return q / n


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vector(s) ``v`` (..., 3) by unit quaternion(s) ``q``: ``q ⊗ v ⊗ q*``.

    With body->nav quaternions this maps body-frame vectors into NED.
    """
    return np.einsum("...ij,...j->...i", quat_to_matrix(q), np.asarray(v, dtype=float))


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix (..., 3, 3) of unit quaternion(s) ``q`` (body -> nav)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = np.moveaxis(q, -1, 0)
    r = np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        axis=-1,
    )
    return r.reshape(q.shape[:-1] + (3, 3))


def quat_from_matrix(r: np.ndarray) -> np.ndarray:
    """Unit quaternion(s) with ``w >= 0`` from rotation matrices (..., 3, 3).

    Uses the numerically stable branch selection of Shepperd's method.
    """
    r = np.asarray(r, dtype=float)
    flat = r.reshape(-1, 3, 3)
    q = np.empty((flat.shape[0], 4))
    tr = np.trace(flat, axis1=1, axis2=2)
    diag = np.stack([flat[:, 0, 0], flat[:, 1, 1], flat[:, 2, 2]], axis=1)
    branch = np.argmax(np.column_stack([tr, diag]), axis=1)
    for i, m in enumerate(flat):
        b = branch[i]
        if b == 0:
            s = 2.0 * np.sqrt(1.0 + tr[i])
            q[i] = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
        elif b == 1:
            s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
            q[i] = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
        elif b == 2:
            s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
            q[i] = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
        else:
            s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
            q[i] = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q[q[:, 0] < 0] *= -1.0
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    return q.reshape(r.shape[:-2] + (4,))


def quat_from_euler(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Quaternion(s) from Z-Y-X Euler angles (rad): ``q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)``."""
    hr, hp, hy = np.asarray(roll) / 2, np.asarray(pitch) / 2, np.asarray(yaw) / 2
    cr, sr, cp, sp, cy, sy = np.cos(hr), np.sin(hr), np.cos(hp), np.sin(hp), np.cos(hy), np.sin(hy)
    return np.stack(
        [
            cy * cp * cr + sy * sp * sr,
            cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr,
        ],
        axis=-1,
    )


def quat_to_euler(q: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Z-Y-X Euler angles ``[roll, pitch, yaw]`` (rad), (..., 3), of unit quaternion(s) ``[w, x, y, z]``.

    roll = atan2(2 (w x + y z), 1 − 2 (x² + y²)), pitch = asin(2 (w y − x z)) (the argument
    clipped to [−1, 1]), yaw = atan2(2 (w z + x y), 1 − 2 (y² + z²)). Roll and yaw lie in
    (-π, π], pitch in [-π/2, π/2]. Each term is formed in ``out`` (a new array when not given;
    it may be a strided view, e.g. the transpose of a (3, N) array) and in two scratch arrays:
    no other temporaries, so a long recording costs three passes of numpy's vectorised arctan2
    and arcsin, not a dozen arrays.
    """
    q = np.asarray(q, dtype=float)
    w, x, y, z = (q[..., i] for i in range(4))
    out = np.empty(q.shape[:-1] + (3,)) if out is None else out
    roll, pitch, yaw = (out[..., i] for i in range(3))
    den, term = np.empty(w.shape), np.empty(w.shape)
    _atan2_of_products(roll, (w, x, y, z), (x, y), den, term)
    np.multiply(w, y, out=pitch)
    np.multiply(x, z, out=term)
    pitch -= term
    pitch *= 2  # 2 (w y − x z)
    np.arcsin(np.clip(pitch, -1.0, 1.0, out=pitch), out=pitch)
    _atan2_of_products(yaw, (w, z, x, y), (y, z), den, term)
    return out


def _atan2_of_products(angle: np.ndarray, products: tuple, squares: tuple, den: np.ndarray, term: np.ndarray) -> None:
    """``angle = atan2(2 (a b + c d), 1 − 2 (e² + f²))`` in place; ``products = (a, b, c, d)``, ``squares = (e, f)``."""
    a, b, c, d = products
    e, f = squares
    np.multiply(a, b, out=angle)
    np.multiply(c, d, out=term)
    angle += term
    angle *= 2
    np.multiply(e, e, out=den)
    np.multiply(f, f, out=term)
    den += term
    den *= 2
    np.subtract(1.0, den, out=den)
    np.arctan2(angle, den, out=angle)


def quat_from_rotvec(rv: np.ndarray) -> np.ndarray:
    """Quaternion exp map of rotation vector(s) ``rv`` (rad, (..., 3))."""
    rv = np.asarray(rv, dtype=float)
    angle = np.linalg.norm(rv, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(half)/angle with its Taylor limit 1/2 at zero
    k = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half), k * rv], axis=-1)


def quat_yaw(q: np.ndarray) -> np.ndarray:
    """Heading ψ (rad) of unit quaternion(s), the Z-Y-X yaw angle."""
    return quat_to_euler(q)[..., 2]


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix ``[v×]`` of a 3-vector, so that ``skew(a) @ b = a × b``."""
    x, y, z = np.asarray(v, dtype=float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap angle(s) to (-π, π]."""
    a = np.asarray(a, dtype=float)
    return -((-a + np.pi) % (2 * np.pi) - np.pi)


def tilt_from_specific_force(f_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roll and pitch (rad) from a specific-force reading ``f_b`` in FRD.

    A body at rest measures ``f_b = R^T [0, 0, -g]``, so with the Z-Y-X sequence
    ``f_b/|f_b| = [sin θ, -cos θ sin φ, -cos θ cos φ]``.
    """
    f = np.asarray(f_b, dtype=float)
    f = f / np.linalg.norm(f, axis=-1, keepdims=True)
    pitch = np.arcsin(np.clip(f[..., 0], -1.0, 1.0))
    roll = np.arctan2(-f[..., 1], -f[..., 2])
    return roll, pitch

