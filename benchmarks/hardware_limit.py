"""The hardware limit of this machine for foot-mounted INS: a minimal compiled strapdown loop.

Per sample: the exact quaternion increment of a constant rate over the interval, attitude
update and normalisation, the specific force rotated into NED, gravity added, velocity and
position integrated; attitude (4), velocity (3) and position (3) stored for every sample in
arrays allocated per call (as a pipeline must). Nothing else: no gait phase, no corrections.
Only for benchmarks/throughput.py (not part of the package).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _loop(t, acc, gyr, q0, g, quat, vel, pos):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    vx = vy = vz = px = py = pz = 0.0
    for k in range(t.shape[0]):
        h = t[k] - t[k - 1] if k > 0 else 0.0
        gx, gy, gz = gyr[k, 0] * h, gyr[k, 1] * h, gyr[k, 2] * h
        ang = math.sqrt(gx * gx + gy * gy + gz * gz)
        if ang > 1e-12:
            s = math.sin(0.5 * ang) / ang
            dw, dx, dy, dz = math.cos(0.5 * ang), gx * s, gy * s, gz * s
        else:
            dw, dx, dy, dz = 1.0, 0.5 * gx, 0.5 * gy, 0.5 * gz
        w, x, y, z = (w * dw - x * dx - y * dy - z * dz, w * dx + x * dw + y * dz - z * dy,
                      w * dy - x * dz + y * dw + z * dx, w * dz + x * dy - y * dx + z * dw)
        nrm = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w * nrm, x * nrm, y * nrm, z * nrm
        fx, fy, fz = acc[k, 0], acc[k, 1], acc[k, 2]
        an = (1 - 2 * (y * y + z * z)) * fx + 2 * (x * y - w * z) * fy + 2 * (x * z + w * y) * fz
        ae = 2 * (x * y + w * z) * fx + (1 - 2 * (x * x + z * z)) * fy + 2 * (y * z - w * x) * fz
        ad = 2 * (x * z - w * y) * fx + 2 * (y * z + w * x) * fy + (1 - 2 * (x * x + y * y)) * fz + g
        px += (vx + 0.5 * an * h) * h
        py += (vy + 0.5 * ae * h) * h
        pz += (vz + 0.5 * ad * h) * h
        vx += an * h
        vy += ae * h
        vz += ad * h
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = w, x, y, z
        vel[k, 0], vel[k, 1], vel[k, 2] = vx, vy, vz
        pos[k, 0], pos[k, 1], pos[k, 2] = px, py, pz


def strapdown(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, q0: np.ndarray,
              g: float = 9.81) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Attitude (N, 4), velocity (N, 3, m/s) and position (N, 3, m) from t (s), acc (m/s²), gyr (rad/s)."""
    n = t.shape[0]
    quat, vel, pos = np.empty((n, 4)), np.empty((n, 3)), np.empty((n, 3))
    _loop(t, acc, gyr, np.asarray(q0, dtype=float), float(g), quat, vel, pos)
    return quat, vel, pos
