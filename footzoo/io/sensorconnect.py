"""MicroStrain SensorConnect CSV (e.g. Köroğlu's 3DM-GX5-25 recordings).

Columns ``Time`` (s) and ``<device>:scaledAccelX/Y/Z`` (g),
``scaledGyroX/Y/Z`` (rad/s), ``scaledMagX/Y/Z`` (Gauss). The MicroStrain frame
is x forward, y right, z down (at rest acc_z ≈ −1 g): the axis map is the
identity. The sensor's own roll/pitch/yaw columns are kept in ``meta`` only
as column names; footzoo does not use them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

from ..data import Recording
from ..errors import FormatError

SIGNALS = {
    "scaledAccelX": "acc_x", "scaledAccelY": "acc_y", "scaledAccelZ": "acc_z",
    "scaledGyroX": "gyr_x", "scaledGyroY": "gyr_y", "scaledGyroZ": "gyr_z",
    "scaledMagX": "mag_x", "scaledMagY": "mag_y", "scaledMagZ": "mag_z",
}


def matches(header: str) -> bool:
    """True for a SensorConnect header."""
    return "scaledAccelX" in header


def read(path: Path, **options: Any) -> Recording:
    """Read a SensorConnect CSV and convert to FRD/SI."""
    df = pd.read_csv(path)
    rename = {"Time": "t"}
    for col in df.columns:
        key = col.split(":")[-1]
        if key in SIGNALS:
            rename[col] = SIGNALS[key]
    df = df.rename(columns=rename)
    needed = ["t", *[v for v in SIGNALS.values() if not v.startswith("mag")]]
    missing = [c for c in needed if c not in df.columns]
    if missing:
        raise FormatError(f"{path}: not a SensorConnect export with scaled signals, missing {missing}")
    keep = [c for c in ["t", *SIGNALS.values()] if c in df.columns]
    meta = {"name": path.stem, "source": str(path), "format": "sensorconnect", "mag_unit": "Gauss"}
    return Recording.from_dataframe(df[keep], acc_unit="g", gyr_unit="rad/s", meta=meta, **options)
