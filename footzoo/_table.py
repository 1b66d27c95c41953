"""The per-sample table of a :class:`~footzoo.data.Result`, built in one compiled pass.

The float columns are written into one ``(17, N)`` block that the DataFrame
wraps without copying (pandas stores a frame's columns as the rows of such a
block), so the table costs 137 bytes per sample and no temporaries.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._jit import njit

FLOAT_COLUMNS = ["t", "qw", "qx", "qy", "qz", "roll", "pitch", "yaw", "pos_n", "pos_e", "pos_d",
                 "vel_n", "vel_e", "vel_d", "acc_n", "acc_e", "acc_d"]


@njit
def _fill(t: np.ndarray, quat: np.ndarray, pos: np.ndarray, vel: np.ndarray, acc: np.ndarray,
          out: np.ndarray) -> None:
    """Copy the signals into ``out`` (17, N) and add the Z-Y-X Euler angles (as ``conventions.quat_to_euler``)."""
    for k in range(t.shape[0]):
        w, x, y, z = quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3]
        out[0, k] = t[k]
        out[1, k], out[2, k], out[3, k], out[4, k] = w, x, y, z
        out[5, k] = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
        out[6, k] = math.asin(min(max(2 * (w * y - x * z), -1.0), 1.0))
        out[7, k] = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        for j in range(3):
            out[8 + j, k] = pos[k, j]
            out[11 + j, k] = vel[k, j]
            out[14 + j, k] = acc[k, j]


def samples_frame(t: np.ndarray, quat: np.ndarray, pos: np.ndarray, vel: np.ndarray, acc_nav: np.ndarray,
                  stance: np.ndarray) -> pd.DataFrame:
    """The ``Result.samples`` table.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    quat : (N, 4) ndarray
        Attitude, body -> NED, scalar first.
    pos, vel, acc_nav : (N, 3) ndarray
        Position (m), velocity (m/s) and motion acceleration (m/s²) in NED.
    stance : (N,) bool ndarray
        Gait phase.

    Returns
    -------
    DataFrame
        Columns ``t, qw, qx, qy, qz, roll, pitch, yaw`` (rad), ``pos_n .. pos_d``,
        ``vel_n .. vel_d``, ``acc_n .. acc_d``, ``stance``.
    """
    n = len(t)
    block = np.empty((len(FLOAT_COLUMNS), n))
    _fill(np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(quat, dtype=float),
          np.ascontiguousarray(pos, dtype=float), np.ascontiguousarray(vel, dtype=float),
          np.ascontiguousarray(acc_nav, dtype=float), block)
    frame = pd.DataFrame(block.T, columns=FLOAT_COLUMNS, copy=False)
    frame["stance"] = np.array(stance, dtype=bool)
    return frame
