"""gaitmap example data (mad-lab-fau/gaitmap): ``imu_sample.csv``.

Two header rows (sensor, axis); ``left_sensor`` and ``right_sensor`` with
``acc_x..z`` (m/s²) and ``gyr_x..z`` (**deg/s**); no time column: the first column is the
sample index, at 204.8 Hz, so ``t = index / rate``. A jump in the index (rows missing) is a gap
in time: a short one is bridged with a warning, a longer one (over ``max_gap``) refused with
the rows that are missing. The data are in gaitmap's foot frame, x toward the toe, y left, z up.

* Both feet: to FRD by 180° about x, ``[x, -y, -z]`` for accelerometer and
  gyroscope alike (``axes=`` replaces it, for both feet).

The data README calls the right foot's frame mirrored. Checked on the file,
the right foot's data nevertheless behave as a right-handed frame: (1) gyro
integration over each stride predicts the next stance's gravity direction to
1.5° with this map (a mirror applied to the gyro as a polar vector gives 16°),
and (2) with this map the estimated trajectory of the right foot turns the same
way as the left foot's and as the motion-capture markers (an un-mirroring map
makes the right foot turn the other way). So both feet use the same map.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.checks import check_positive, check_range, gap_limit
from ..core.data import Recording, Truth
from ..core.errors import FootzooWarning, FormatError, user_stacklevel
from .axes import apply_axes, describe_axes, parse_axes
from .base import RECORDING_OPTIONS, Option, Reader, data_suffix, first_line, frame_options, text_source
from .gaitmap_reference import REFERENCE_FILES, has_reference, reference_stride_positions, reference_strides

RATE_HZ = 204.8
FEET = ("left", "right")
COLUMNS = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"]
#: gaitmap's foot frame (x toe, y left, z up) -> FRD, the same for both feet (see the module docstring).
AXES = "[x, -y, -z]"
ACC_UNIT = "m/s^2"
GYR_UNIT = "deg/s"


def matches(header: str) -> bool:
    """True for gaitmap's two-row header."""
    return header.startswith("sensor,") and "_sensor" in header


def feet(path: Path) -> list[str]:
    """The feet a gaitmap file holds (``left``, ``right``), from its first header row."""
    head = first_line(path)
    return [f for f in FEET if f"{f}_sensor" in head]


def sample_times(index: pd.Index, rate: float, path: Path, max_gap: float | None = None) -> np.ndarray:
    """``index / rate`` (s), after checking that the sample index counts up; a long jump is refused.

    Raises
    ------
    FormatError
        For an index that is not whole numbers counting up, or that jumps by more than ``max_gap``.
    """
    idx = pd.to_numeric(pd.Series(index), errors="coerce").to_numpy(dtype=float)
    bad = ~np.isfinite(idx) | (idx != np.round(idx))
    if bad.any():
        k = int(np.argmax(bad))
        raise FormatError(f"{path}: the first column (sample index) must hold whole numbers; row {k} holds "
                          f"{index[k]!r}; repair the file (footzoo reads t = index / {rate:g} Hz)")
    step = np.diff(idx)
    if np.any(step <= 0):
        k = int(np.argmax(step <= 0))
        raise FormatError(f"{path}: the sample index goes from {int(idx[k])} to {int(idx[k + 1])} at row {k + 1}: "
                          "it must count up; sort the rows or repair the file")
    limit = gap_limit(1.0 / rate, max_gap)
    jumps = np.flatnonzero(step * (1.0 / rate) > limit)
    if jumps.size:
        k = int(jumps[0])
        lost = int(step[k]) - 1
        more = f" and at {jumps.size - 1} more place(s)" if jumps.size > 1 else ""
        raise FormatError(
            f"{path}: {lost} rows are missing from the sample index (it jumps from {int(idx[k])} to "
            f"{int(idx[k + 1])}: {lost / rate:.2f} s at {rate:g} Hz){more}; "
            f"footzoo bridges gaps up to {limit:g} s. Restore the rows, split the file at the jump, or pass a "
            "larger max_gap if the filters may bridge it"
        )
    return idx / rate


def read(path: Path, foot: str | None = None, rate: float = RATE_HZ, axes: Any = AXES, acc_unit: str = ACC_UNIT,
         gyr_unit: str = GYR_UNIT, **options: Any) -> Recording:
    """Read one foot of a gaitmap ``imu_sample.csv``.

    When the folder also holds gaitmap's ``mocap_sample.csv`` and
    ``stride_events_sample.csv``, their per-stride events, stride lengths and
    foot progression angles become ``truth.steps``
    (:func:`footzoo.io.gaitmap_reference.reference_strides`) and the per-stride
    trajectories of ``position_sample.csv`` ``truth.stride_positions``.

    Parameters
    ----------
    foot : {"left", "right"}
        Which sensor to read (required when the file holds both feet; a file of one foot is read as that foot).
    rate : float
        Sampling rate (Hz), 204.8 for the example data.
    axes : str or sequence
        gaitmap's foot frame -> FRD (:mod:`footzoo.io.axes`); default ``[x, -y, -z]``.
    acc_unit, gyr_unit : str
        The file's units (default m/s² and deg/s).
    """
    if foot is None and len(feet(path)) == 1:
        foot = feet(path)[0]  # a file of one foot: no choice to make
    if foot not in FEET:
        raise FormatError(
            f"{path}: a gaitmap file holds both feet; choose one with foot='left' or foot='right', "
            "or read both with footzoo.Session.load(path) (command line: both feet unless --foot left|right)"
        )
    rate = check_range("rate", rate, 0.0, 100_000.0, "Hz", lo_open=True)
    rows = parse_axes(AXES if axes is None else axes, "axes")
    max_gap = options.get("max_gap")
    if max_gap is not None:
        max_gap = check_positive("max_gap", max_gap, unit="s")
    df = pd.read_csv(text_source(path), header=[0, 1], index_col=0)
    sensor = f"{foot}_sensor"
    if sensor not in df.columns.get_level_values(0):
        raise FormatError(f"{path}: no {sensor!r} columns; found {sorted(set(df.columns.get_level_values(0)))}")
    others = sorted({str(c) for c in df.columns.get_level_values(0)} - {f"{f}_sensor" for f in FEET})
    if others:  # a multi-sensor export: footzoo reads the feet, and says what it leaves
        warnings.warn(FootzooWarning(
            f"{path.name}: sensor(s) {others} are not read: footzoo reads the feet (left_sensor, right_sensor) of a "
            "gaitmap file; export another sensor as a file of its own (canonical or generic) to read it"),
            stacklevel=user_stacklevel())
    block = df[sensor]
    missing = [c for c in COLUMNS if c not in block.columns]
    if missing:
        raise FormatError(f"{path}: {sensor} lacks columns {missing}")
    values = block[COLUMNS].to_numpy(dtype=float)
    frame = pd.DataFrame(np.hstack([apply_axes(rows, values[:, :3]), apply_axes(rows, values[:, 3:])]),
                         columns=COLUMNS)
    frame.insert(0, "t", sample_times(df.index, rate, path, max_gap))
    meta = {"name": f"{path.stem}_{foot}", "source": str(path), "format": "gaitmap", "foot": foot,
            "placement": f"{foot} foot instep", "axes": describe_axes(rows), "input_files": [str(path)]}
    truth = None
    if has_reference(path.parent):
        meta["input_files"] += [str(path.parent / f) for f in REFERENCE_FILES if (path.parent / f).exists()]
        truth = Truth(steps=reference_strides(path.parent, foot),
                      stride_positions=reference_stride_positions(path.parent, foot),
                      source="motion capture (gaitmap)")
    return Recording.from_dataframe(frame, acc_unit=acc_unit or ACC_UNIT, gyr_unit=gyr_unit or GYR_UNIT, meta=meta,
                                    truth=truth, **options)


class GaitmapReader(Reader):
    """gaitmap's example IMU file: both feet, m/s² and deg/s, gaitmap's foot frame; mocap reference as truth."""

    description = "gaitmap example IMU CSV (two header rows: sensor, axis; left_sensor and right_sensor)"
    extensions = (".csv",)
    url = "https://github.com/mad-lab-fau/gaitmap"
    options = {
        "foot": Option(None, "", "which sensor to read: 'left' or 'right' (required when the file holds both feet)"),
        "rate": Option(RATE_HZ, "Hz", "sampling rate: the time base is the sample index / rate"),
        **frame_options(AXES, ACC_UNIT, GYR_UNIT),
        **RECORDING_OPTIONS,
    }

    def guess_can_open(self, path: Path) -> bool:
        return data_suffix(path) in (".csv", ".txt") and matches(first_line(path))

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """gaitmap's motion-capture reference files in the file's folder (its truth when they are there)."""
        return [Path(path).parent / f for f in REFERENCE_FILES]

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
