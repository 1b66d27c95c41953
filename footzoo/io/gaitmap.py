"""gaitmap example data (mad-lab-fau/gaitmap): ``imu_sample.csv``.

Two header rows (sensor, axis); ``left_sensor`` and ``right_sensor`` with
``acc_x..z`` (m/s²) and ``gyr_x..z`` (**deg/s**); no time column: samples are at
204.8 Hz. The data are in gaitmap's foot frame, x toward the toe, y left, z up.

* Left foot: a right-handed frame; to FRD by 180° about x: ``(x, −y, −z)`` for
  both accelerometer and gyroscope.
* Right foot: mirrored about the sagittal plane (y points right), with the gyro
  transformed as an axial vector (``ω' = −M ω``, ``M = diag(1, −1, 1)``). Undoing
  the mirror and then turning to FRD gives acc ``(x, y, −z)`` and gyro
  ``(−x, −y, z)``. Checked on the file: gyro integration over each stride then
  predicts the next stance's gravity direction to about 1.5° (a polar-vector
  reading of the gyro gives 16°), and both feet turn the same way in the turns.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..data import Recording
from ..errors import FormatError

RATE_HZ = 204.8
FEET = ("left", "right")
AXES = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
#: Sign applied to each column (acc_x..z, gyr_x..z) to reach FRD.
TO_FRD = {
    "left": np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0]),
    "right": np.array([1.0, 1.0, -1.0, -1.0, -1.0, 1.0]),
}


def matches(header: str) -> bool:
    """True for gaitmap's two-row header."""
    return header.startswith("sensor,") and "_sensor" in header


def read(path: Path, foot: str | None = None, rate: float = RATE_HZ, **options: Any) -> Recording:
    """Read one foot of a gaitmap ``imu_sample.csv``.

    Parameters
    ----------
    foot : {"left", "right"}
        Which sensor to read (required: the file holds both feet).
    rate : float
        Sampling rate (Hz), 204.8 for the example data.
    """
    if foot not in FEET:
        raise FormatError(
            f"{path}: a gaitmap file holds both feet; choose one with foot='left' or foot='right' "
            "(command line: --foot left)"
        )
    df = pd.read_csv(path, header=[0, 1], index_col=0)
    sensor = f"{foot}_sensor"
    if sensor not in df.columns.get_level_values(0):
        raise FormatError(f"{path}: no {sensor!r} columns; found {sorted(set(df.columns.get_level_values(0)))}")
    block = df[sensor]
    missing = [c for c in AXES if c not in block.columns]
    if missing:
        raise FormatError(f"{path}: {sensor} lacks columns {missing}")
    values = block[AXES].to_numpy(dtype=float) * TO_FRD[foot]
    frame = pd.DataFrame(values, columns=AXES)
    frame.insert(0, "t", np.arange(len(frame)) / rate)
    meta = {"name": f"{path.stem}_{foot}", "source": str(path), "format": "gaitmap", "foot": foot,
            "placement": f"{foot} foot instep"}
    return Recording.from_dataframe(frame, acc_unit="m/s^2", gyr_unit="deg/s", meta=meta, **options)
