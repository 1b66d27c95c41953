"""MicroStrain SensorConnect CSV (e.g. Köroğlu's 3DM-GX5-25 recordings).

Columns ``Time`` (s) and ``<device>:scaledAccelX/Y/Z`` (g),
``scaledGyroX/Y/Z`` (rad/s), ``scaledMagX/Y/Z`` (Gauss). The MicroStrain frame
is x forward, y right, z down (at rest acc_z ≈ −1 g): the axis map is the
identity ``[x, y, z]``; a sensor mounted otherwise on the foot (upside down, turned)
is read with ``axes=``, and an export in other units with ``acc_unit=`` / ``gyr_unit=``.
Köroğlu's experiments 31–33 were recorded with the sensor's x axis toward the heel: the run's
mounting warning says so, and read with ``axes="[-x, -y, z]"`` they give none.
The sensor's own roll/pitch/yaw columns are not read.

Köroğlu's experiments ship a ``<name>.mat`` next to the CSV with the ground
control points: ``GCP_meters`` (K×2, every footprint measured on the floor
tiles, m), ``numberOfStrides`` and ``GCP_exist_and_correct``. When it is there
the reader loads it into ``truth.footprints`` and ``truth.stride_count``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.data import Recording, Truth
from ..core.errors import FormatError
from .axes import describe_axes, parse_axes, rotate_columns
from .base import RECORDING_OPTIONS, Reader, check_unique_columns, first_line, frame_options, text_source

SIGNALS = {
    "scaledAccelX": "acc_x", "scaledAccelY": "acc_y", "scaledAccelZ": "acc_z",
    "scaledGyroX": "gyr_x", "scaledGyroY": "gyr_y", "scaledGyroZ": "gyr_z",
    "scaledMagX": "mag_x", "scaledMagY": "mag_y", "scaledMagZ": "mag_z",
}
#: The MicroStrain frame is FRD already; the units SensorConnect's scaled channels use.
AXES = "[x, y, z]"
ACC_UNIT = "g"
GYR_UNIT = "rad/s"


def matches(header: str) -> bool:
    """True for a SensorConnect header."""
    return "scaledAccelX" in header


def read(path: Path, axes: Any = AXES, acc_unit: str = ACC_UNIT, gyr_unit: str = GYR_UNIT,
         **options: Any) -> Recording:
    """Read a SensorConnect CSV and convert to FRD/SI (``axes``: :mod:`footzoo.io.axes`)."""
    rows = parse_axes(AXES if axes is None else axes, "axes")
    df = pd.read_csv(text_source(path))
    check_unique_columns(df, path)
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
    frame = df[keep].copy()
    rotate_columns(frame, rows)
    gcp = path.with_suffix(".mat")
    meta = {"name": path.stem, "source": str(path), "format": "sensorconnect", "mag_unit": "Gauss",
            "axes": describe_axes(rows), "input_files": [str(path), *([str(gcp)] if gcp.exists() else [])]}
    return Recording.from_dataframe(frame, acc_unit=acc_unit or ACC_UNIT, gyr_unit=gyr_unit or GYR_UNIT, meta=meta,
                                    truth=footprint_reference(gcp), **options)


def footprint_reference(path: Path) -> Truth | None:
    """Köroğlu's ground control points (``GCP_meters``, ``numberOfStrides``) from a ``.mat`` file, if present."""
    if not path.exists():
        return None
    # deferred: scipy, only for .mat files
    import scipy.io as sio

    try:
        d = sio.loadmat(path)
    except Exception as err:  # scipy raises several types for bad files
        raise FormatError(f"{path}: cannot read the ground-control-point file: {err}") from None
    if "GCP_meters" not in d:
        return None
    if "GCP_exist_and_correct" in d and not bool(np.ravel(d["GCP_exist_and_correct"])[0]):
        return None
    count = int(np.ravel(d["numberOfStrides"])[0]) if "numberOfStrides" in d else None
    return Truth(footprints=np.asarray(d["GCP_meters"], dtype=float), stride_count=count,
                 source="ground control points (Köroğlu)")


class SensorConnectReader(Reader):
    """MicroStrain SensorConnect CSV: g, rad/s, Gauss, already FRD; Köroğlu's ground control points as truth."""

    description = "MicroStrain SensorConnect CSV (Time, <device>:scaledAccelX, ..., scaledGyroX, ..., scaledMagX, ...)"
    extensions = (".csv",)
    url = "https://www.microstrain.com/software/sensorconnect"
    options = {**frame_options(AXES, ACC_UNIT, GYR_UNIT), **RECORDING_OPTIONS}

    def guess_can_open(self, path: Path) -> bool:
        return Path(path).suffix.lower() in (".csv", ".txt") and matches(first_line(path))

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
