"""gaitmap example data (mad-lab-fau/gaitmap): ``imu_sample.csv``.

Two header rows (sensor, axis); ``left_sensor`` and ``right_sensor`` with
``acc_x..z`` (m/s²) and ``gyr_x..z`` (**deg/s**); no time column: samples are at
204.8 Hz. The data are in gaitmap's foot frame, x toward the toe, y left, z up.

* Both feet: to FRD by 180° about x, ``(x, −y, −z)`` for accelerometer and
  gyroscope alike.

The data README calls the right foot's frame mirrored. Checked on the file,
the right foot's data nevertheless behave as a right-handed frame: (1) gyro
integration over each stride predicts the next stance's gravity direction to
1.5° with this map (a mirror applied to the gyro as a polar vector gives 16°),
and (2) with this map the estimated trajectory of the right foot turns the same
way as the left foot's and as the motion-capture markers (an un-mirroring map
makes the right foot turn the other way). So both feet use the same map.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.checks import check_range
from ..core.data import Recording, Truth
from ..core.errors import FormatError
from .gaitmap_reference import has_reference, reference_stride_positions, reference_strides

RATE_HZ = 204.8
FEET = ("left", "right")
AXES = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
#: Sign applied to each column (acc_x..z, gyr_x..z) to reach FRD.
TO_FRD = {
    "left": np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0]),
    "right": np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0]),  # see the module docstring
}


def matches(header: str) -> bool:
    """True for gaitmap's two-row header."""
    return header.startswith("sensor,") and "_sensor" in header


def feet(path: Path) -> list[str]:
    """The feet a gaitmap file holds (``left``, ``right``), from its first header row."""
    with open(path, encoding="utf-8", errors="replace") as fh:
        head = fh.readline()
    return [f for f in FEET if f"{f}_sensor" in head]


def read(path: Path, foot: str | None = None, rate: float = RATE_HZ, **options: Any) -> Recording:
    """Read one foot of a gaitmap ``imu_sample.csv``.

    When the folder also holds gaitmap's ``mocap_sample.csv`` and
    ``stride_events_sample.csv``, their per-stride events, stride lengths and
    foot progression angles become ``truth.steps``
    (:func:`footzoo.io.gaitmap_reference.reference_strides`) and the per-stride
    trajectories of ``position_sample.csv`` ``truth.stride_positions``.

    Parameters
    ----------
    foot : {"left", "right"}
        Which sensor to read (required: the file holds both feet).
    rate : float
        Sampling rate (Hz), 204.8 for the example data.
    """
    if foot not in FEET:
        raise FormatError(
            f"{path}: a gaitmap file holds both feet; choose one with foot='left' or foot='right', "
            "or read both with footzoo.Session.load(path) (command line: both feet unless --foot left|right)"
        )
    rate = check_range("rate", rate, 0.0, 100_000.0, "Hz", lo_open=True)
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
    truth = None
    if has_reference(path.parent):
        truth = Truth(steps=reference_strides(path.parent, foot),
                      stride_positions=reference_stride_positions(path.parent, foot),
                      source="motion capture (gaitmap)")
    return Recording.from_dataframe(frame, acc_unit="m/s^2", gyr_unit="deg/s", meta=meta, truth=truth, **options)
