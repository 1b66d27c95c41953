"""PyShoe VICON-room trials (Wagstaff et al.), MATLAB ``.mat`` files.

``imu`` (N×6: acc m/s², gyro rad/s) in the sensor frame x forward, y right,
z down (already FRD: the axis map is ``[x, y, z]``; a trial recorded with the
sensor mounted otherwise, such as the upside-down 2018-02-22 trial, is read
with ``axes=``); ``ts`` (s); ``gt`` (N×3, VICON position, z up). The
reference is mirrored with respect to the IMU frame: a right-handed NED
estimate matches ``gt · [1, 1, −1]`` (negate z only), which is what the
:class:`~footzoo.core.data.Truth` holds (z down, horizontal axes VICON's, so compare
after a rotation about the vertical). ``zv_vicon_opt`` becomes the stance truth.
The sensor is on the right shoe: ``meta["foot"] = "right"``. When the folder
holds the dataset's ``trials.csv``, the trial's hand-counted strides
(``n_strides_manual_koroglu``) become ``truth.stride_count`` and its walking tag
(``bipedal_tag_koroglu``: 1 walking, 0 not bipedal, −1 doubtful) goes to
``meta["bipedal_tag"]``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.data import Recording, Truth
from ..core.errors import FormatError
from .axes import describe_axes, parse_axes, rotate_columns
from .base import MAT_ROUTE, RECORDING_OPTIONS, Reader, frame_options, load_mat, text_source

#: Columns of ``trial_error``: PyShoe's ARMSE (m) with each detector at its best threshold.
TRIAL_ERROR_DETECTORS = ("shoe", "ared", "amvd", "mbgtd", "vicon")
#: The LORD MicroStrain's frame is FRD already; PyShoe stores SI units.
AXES = "[x, y, z]"
ACC_UNIT = "m/s^2"
GYR_UNIT = "rad/s"


def read(path: Path, axes: Any = AXES, acc_unit: str = ACC_UNIT, gyr_unit: str = GYR_UNIT,
         **options: Any) -> Recording:
    """Read a PyShoe ``.mat`` trial with its VICON reference as truth (``axes``: :mod:`footzoo.io.axes`)."""
    rows = parse_axes(AXES if axes is None else axes, "axes")
    d = load_mat(path, "it as a MATLAB .mat file")
    missing = [k for k in ("imu", "ts") if k not in d]
    if missing:
        have = sorted(k for k in d if not k.startswith("__"))
        raise FormatError(f"{path}: not a PyShoe trial, missing variable(s) {missing} (it has {have[:12]}); "
                          f"for a MATLAB file of another layout, {MAT_ROUTE}")
    try:
        imu = np.asarray(d["imu"], dtype=float)
        t = np.asarray(d["ts"], dtype=float).ravel()
    except (TypeError, ValueError):
        raise FormatError(f"{path}: 'imu' and 'ts' must be numeric arrays") from None
    if imu.ndim != 2 or imu.shape[1] < 6 or imu.shape[0] != t.shape[0]:
        raise FormatError(f"{path}: 'imu' must be N x 6 (acc m/s², gyro rad/s) with N = len(ts) = {t.shape[0]}, "
                          f"got shape {imu.shape}")
    truth = None
    if "gt" in d:
        stance = _flags(d["zv_vicon_opt"], len(t), path, "zv_vicon_opt") if "zv_vicon_opt" in d else None
        mirror = np.array([1.0, 1.0, -1.0])  # VICON z up and mirrored: negate z only
        gt = _numbers(d["gt"], path, "gt", "the VICON position, N x 3 in m")
        if gt.ndim != 2 or gt.shape != (len(t), 3):
            raise FormatError(f"{path}: 'gt' (the VICON position) has shape {gt.shape}, expected ({len(t)}, 3): one "
                              "row per IMU sample; fix the file or delete 'gt' to read it without the reference")
        truth = Truth(pos=gt * mirror, stance=stance)
    meta: dict[str, Any] = {"name": path.stem, "source": str(path), "format": "pyshoe", "foot": "right",
                            "placement": "right shoe instep (LORD MicroStrain)", "axes": describe_axes(rows)}
    meta["input_files"] = [str(path)]
    trial = _trial_row(path)
    if trial is not None:
        meta["input_files"].append(str(path.with_name("trials.csv")))
        truth = truth or Truth()
        truth.stride_count = int(trial["n_strides_manual_koroglu"])
        meta["bipedal_tag"] = int(trial["bipedal_tag_koroglu"])
    if truth is not None:
        truth.source = "VICON (PyShoe)"
    if "trial_error" in d:
        errors = _numbers(d["trial_error"], path, "trial_error", "PyShoe's error per detector, 1 x 5 in m").ravel()
        if errors.size != len(TRIAL_ERROR_DETECTORS):
            raise FormatError(f"{path}: 'trial_error' holds {errors.size} value(s), expected "
                              f"{len(TRIAL_ERROR_DETECTORS)} (PyShoe's error with {', '.join(TRIAL_ERROR_DETECTORS)}); "
                              "fix the file or delete the variable")
        meta["pyshoe_trial_error"] = {k: float(e) for k, e in zip(TRIAL_ERROR_DETECTORS, errors, strict=True)}
    frame = pd.DataFrame(imu[:, :6], columns=["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"])
    frame.insert(0, "t", t)
    rotate_columns(frame, rows)
    return Recording.from_dataframe(frame, acc_unit=acc_unit or ACC_UNIT, gyr_unit=gyr_unit or GYR_UNIT, meta=meta,
                                    truth=truth, **options)


class PyShoeReader(Reader):
    """PyShoe's VICON-room trials (MATLAB .mat): m/s², rad/s, already FRD; VICON reference as truth."""

    description = "PyShoe VICON-room trial (MATLAB .mat with imu, ts, gt, zv_*_opt, trial_error)"
    extensions = (".mat",)
    url = "https://github.com/utiasSTARS/pyshoe"
    options = {**frame_options(AXES, ACC_UNIT, GYR_UNIT), **RECORDING_OPTIONS}

    def guess_can_open(self, path: Path) -> bool:
        """A ``.mat`` file with the variables ``imu`` and ``ts`` (its directory is read, not its data).

        A ``.mat`` file that MATLAB's format cannot even list is claimed too, so that the error
        says what is wrong with it; a valid one without ``imu`` and ``ts`` is left to other readers.
        """
        if Path(path).suffix.lower() != ".mat":
            return False
        # deferred: scipy, only for .mat files
        import scipy.io as sio

        try:
            names = {name for name, _, _ in sio.whosmat(path)}
        except Exception:  # not a readable MATLAB file: open() says why
            return True
        return {"imu", "ts"} <= names

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """The dataset's ``trials.csv`` next to the trial (its hand-counted strides)."""
        return [Path(path).with_name("trials.csv")]

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)


#: Columns of the dataset's ``trials.csv`` the reader uses.
TRIAL_COLUMNS = ("trial", "n_strides_manual_koroglu", "bipedal_tag_koroglu")


def _trial_row(path: Path) -> dict[str, Any] | None:
    """The trial's row of the dataset's ``trials.csv`` (next to the ``.mat``), if any; checked.

    A ``trials.csv`` that cannot be read, lacks the columns, lists the trial twice or holds
    something other than whole numbers there is a :class:`FormatError` naming the file and the fix
    (its counts would otherwise be taken for the reference's).
    """
    table = path.with_name("trials.csv")
    if not table.exists():
        return None

    fix = (f"fix {table} (one row per trial: {', '.join(TRIAL_COLUMNS)}), or move it away to read the trial "
           "without the hand counts")
    try:
        df = pd.read_csv(text_source(table), dtype={"trial": str})
    except FormatError:
        raise
    except (UnicodeDecodeError, ValueError, pd.errors.ParserError) as err:
        raise FormatError(f"{table}: cannot be read as a table ({type(err).__name__}: {err}); {fix}") from None
    missing = [c for c in TRIAL_COLUMNS if c not in df.columns]
    if missing:
        raise FormatError(f"{table}: lacks the column(s) {missing}; {fix}")
    rows = df[df["trial"].astype(str).str.strip() == path.stem]
    if rows.empty:
        return None
    if len(rows) > 1:
        raise FormatError(f"{table}: lists the trial {path.stem!r} {len(rows)} times; {fix}")
    row = rows.iloc[0].to_dict()
    for col in TRIAL_COLUMNS[1:]:
        value = pd.to_numeric(pd.Series([row[col]]), errors="coerce").iloc[0]
        if not np.isfinite(value) or value != int(value) or (col.startswith("n_") and value < 0):
            raise FormatError(f"{table}: {col} of trial {path.stem!r} is {row[col]!r}, not a whole number; {fix}")
        row[col] = int(value)
    return row


def _numbers(value: Any, path: Path, name: str, what: str) -> np.ndarray:
    """A MATLAB variable as a float array, or a FormatError naming it."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise FormatError(f"{path}: {name!r} must hold numbers ({what}); fix the file") from None


def _flags(value: Any, n: int, path: Path, name: str) -> np.ndarray:
    """A 0/1 MATLAB variable with one value per sample as a bool array, or a FormatError naming it."""
    flags = _numbers(value, path, name, "1 = still, 0 = moving, one per sample").ravel()
    if flags.size != n or not np.isin(flags, (0.0, 1.0)).all():
        raise FormatError(f"{path}: {name!r} must hold 0 or 1 for each of the {n} samples, got {flags.size} value(s)"
                          f"{'' if np.isin(flags, (0.0, 1.0)).all() else ' with others than 0 and 1'}; fix the file "
                          "or delete the variable")
    return flags.astype(bool)
