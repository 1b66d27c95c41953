"""The per-sample table of a :class:`~footzoo.evaluation.result.Result`, wrapped around the stages' outputs.

The attitude, position, velocity and acceleration arrays that the stages wrote are
the table's columns as they are (the DataFrame keeps a view of each column, no
copy); only the Z-Y-X Euler angles are new (:func:`footzoo.core.conventions.quat_to_euler`,
block by block, so its temporaries stay small), and the time and stance columns are copied
so the table does not alias the recording. A table costs 33 bytes per sample beyond the
stages' outputs, and no pass over them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .conventions import quat_to_euler

FLOAT_COLUMNS = ["t", "qw", "qx", "qy", "qz", "roll", "pitch", "yaw", "pos_n", "pos_e", "pos_d",
                 "vel_n", "vel_e", "vel_d", "acc_n", "acc_e", "acc_d"]


#: Samples per block of the Euler angles: numpy's vectorised arctan2 and arcsin (faster than a
#: compiled loop over the math library's scalar functions) with scratch arrays of this size.
EULER_BLOCK = 1 << 14


def euler_columns(quat: np.ndarray) -> np.ndarray:
    """Z-Y-X Euler angles (rad), (3, N): roll, pitch, yaw of the (N, 4) attitudes, block by block."""
    out = np.empty((3, len(quat)))
    for s in range(0, len(quat), EULER_BLOCK):
        quat_to_euler(quat[s:s + EULER_BLOCK], out=out[:, s:s + EULER_BLOCK].T)
    return out


def _as_float(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.shape != shape:
        raise ValueError(f"samples_frame: expected an array of shape {shape}, got {a.shape}")
    return a


def samples_frame(t: np.ndarray, quat: np.ndarray, pos: np.ndarray, vel: np.ndarray, acc_nav: np.ndarray,
                  stance: np.ndarray) -> pd.DataFrame:
    """The ``Result.samples`` table.

    ``quat``, ``pos``, ``vel`` and ``acc_nav`` become the table's columns without a copy
    (pass arrays nothing else writes to afterwards).

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
    q = _as_float(quat, (n, 4))
    euler = euler_columns(q)
    columns = [np.array(t, dtype=float), *q.T, *euler, *_as_float(pos, (n, 3)).T, *_as_float(vel, (n, 3)).T,
               *_as_float(acc_nav, (n, 3)).T]
    data = dict(zip(FLOAT_COLUMNS, columns, strict=True))
    data["stance"] = np.array(stance, dtype=bool)
    return pd.DataFrame(data, copy=False)
