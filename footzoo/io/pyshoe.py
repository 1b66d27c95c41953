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
from .base import RECORDING_OPTIONS, Reader, frame_options

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
    import scipy.io as sio  # here: loading footzoo's readers does not load scipy

    try:
        d = sio.loadmat(path)
    except Exception as err:  # scipy raises several types for bad files
        raise FormatError(f"{path}: cannot read as a MATLAB .mat file: {err}") from None
    missing = [k for k in ("imu", "ts") if k not in d]
    if missing:
        raise FormatError(f"{path}: not a PyShoe trial, missing variable(s) {missing}")
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
        stance = np.asarray(d["zv_vicon_opt"]).ravel().astype(bool) if "zv_vicon_opt" in d else None
        mirror = np.array([1.0, 1.0, -1.0])  # VICON z up and mirrored: negate z only
        truth = Truth(pos=np.asarray(d["gt"], dtype=float) * mirror, stance=stance)
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
        errors = np.ravel(d["trial_error"]).astype(float)
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

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)


def _trial_row(path: Path) -> dict[str, Any] | None:
    """The trial's row of the dataset's ``trials.csv`` (next to the ``.mat``), if any."""
    table = path.with_name("trials.csv")
    if not table.exists():
        return None

    df = pd.read_csv(table, dtype={"trial": str})
    rows = df[df["trial"] == path.stem]
    needed = {"n_strides_manual_koroglu", "bipedal_tag_koroglu"}
    if rows.empty or not needed <= set(df.columns):
        return None
    return rows.iloc[0].to_dict()
