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
from .base import (
    RECORDING_OPTIONS,
    Option,
    Reader,
    check_unique_columns,
    data_suffix,
    first_line,
    frame_options,
    load_mat,
    text_source,
)

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


def devices(columns: Any) -> list[str]:
    """The devices of a SensorConnect export, in column order (``inertial-6253.76535`` of ``...:scaledAccelX``)."""
    found: list[str] = []
    for col in map(str, columns):
        device, sep, signal = col.rpartition(":")
        if signal in SIGNALS and device not in found:
            found.append(device)
    return found


def read(path: Path, axes: Any = AXES, acc_unit: str = ACC_UNIT, gyr_unit: str = GYR_UNIT, device: str | None = None,
         **options: Any) -> Recording:
    """Read a SensorConnect CSV and convert to FRD/SI (``axes``: :mod:`footzoo.io.axes`; one device of a
    multi-device export: ``device=``)."""
    rows = parse_axes(AXES if axes is None else axes, "axes")
    df = pd.read_csv(text_source(path))
    check_unique_columns(df, path)
    names = devices(df.columns)
    if device is not None and device not in names:
        raise FormatError(f"{path}: no device {device!r} in this export; its devices are {names}")
    if device is None and len(names) > 1:
        raise FormatError(f"{path}: a multi-device export ({len(names)} devices: {', '.join(names)}); footzoo reads "
                          f"one sensor at a time: choose one with device= (command line: --option device={names[0]})")
    device = device if device is not None else (names[0] if names else "")
    rename = {"Time": "t"}
    for col in df.columns:
        dev, _, key = str(col).rpartition(":")
        if key in SIGNALS and dev == device:
            rename[col] = SIGNALS[key]
    df = df.rename(columns=rename)
    ours = [c for c in rename.values() if c != "t" and c in df.columns]
    if len(names) > 1 and ours:  # the other devices' rows (this device's columns all empty) are not its samples
        df = df[df[ours].notna().any(axis=1)]
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
    if len(names) > 1:
        meta["device"] = device
    return Recording.from_dataframe(frame, acc_unit=acc_unit or ACC_UNIT, gyr_unit=gyr_unit or GYR_UNIT, meta=meta,
                                    truth=footprint_reference(gcp), **options)


def footprint_reference(path: Path) -> Truth | None:
    """Köroğlu's ground control points (``GCP_meters``, ``numberOfStrides``) from a ``.mat`` file, if present."""
    if not path.exists():
        return None
    d = load_mat(path, "the ground-control-point file", "copy it again from its source, or move it away (the "
                 "recording is then read without its footprints)")
    if "GCP_meters" not in d:
        return None
    fix = f"fix {path.name} (GCP_meters K x 2 in m, numberOfStrides, GCP_exist_and_correct) or move it away"
    if "GCP_exist_and_correct" in d and not _scalar(d["GCP_exist_and_correct"], path, "GCP_exist_and_correct", fix):
        return None
    count = _scalar(d["numberOfStrides"], path, "numberOfStrides", fix) if "numberOfStrides" in d else None
    if count is not None and (count != int(count) or count < 0):
        raise FormatError(f"{path}: numberOfStrides is {count!r}, not a whole number of strides; {fix}")
    try:
        gcp = np.asarray(d["GCP_meters"], dtype=float)
    except (TypeError, ValueError):
        raise FormatError(f"{path}: GCP_meters must hold numbers; {fix}") from None
    if gcp.ndim != 2 or gcp.shape[1] != 2 or not len(gcp) or not np.isfinite(gcp).all():
        raise FormatError(f"{path}: GCP_meters has shape {gcp.shape}"
                          f"{'' if np.isfinite(gcp).all() else ' with non-finite values'}; it must be K x 2 finite "
                          f"footprint positions (m); {fix}")
    return Truth(footprints=gcp, stride_count=None if count is None else int(count),
                 source="ground control points (Köroğlu)")


def _scalar(value: Any, path: Path, name: str, fix: str) -> float:
    """One number of a MATLAB file (a 1 x 1 array), or a FormatError naming it."""
    try:
        flat = np.ravel(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise FormatError(f"{path}: {name} must be a number; {fix}") from None
    if flat.size != 1 or not np.isfinite(flat[0]):
        raise FormatError(f"{path}: {name} must be one finite number, got {flat.size} value(s); {fix}")
    return float(flat[0])


class SensorConnectReader(Reader):
    """MicroStrain SensorConnect CSV: g, rad/s, Gauss, already FRD; Köroğlu's ground control points as truth."""

    description = "MicroStrain SensorConnect CSV (Time, <device>:scaledAccelX, ..., scaledGyroX, ..., scaledMagX, ...)"
    extensions = (".csv",)
    url = "https://www.microstrain.com/software/sensorconnect"
    options = {"device": Option(None, "", "the device to read from a multi-device export (the name before ':' in "
                                          "its columns, e.g. inertial-6253.76535); required when there are several"),
               **frame_options(AXES, ACC_UNIT, GYR_UNIT), **RECORDING_OPTIONS}

    def guess_can_open(self, path: Path) -> bool:
        return data_suffix(path) in (".csv", ".txt") and matches(first_line(path))

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """Köroğlu's ground control points ``<file>.mat`` next to the export."""
        return [Path(path).with_suffix(".mat")]

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
