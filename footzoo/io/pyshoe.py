"""PyShoe VICON-room trials (Wagstaff et al.), MATLAB ``.mat`` files.

``imu`` (N×6: acc m/s², gyro rad/s) in the sensor frame x forward, y right,
z down (already FRD); ``ts`` (s); ``gt`` (N×3, VICON position, z up). The
reference is mirrored with respect to the IMU frame: a right-handed NED
estimate matches ``gt · [1, 1, −1]`` (negate z only), which is what the
:class:`~footzoo.data.Truth` holds (z down, horizontal axes VICON's, so compare
after a rotation about the vertical). ``zv_vicon_opt`` becomes the stance truth.

The dataset documents the sensor on the right shoe's instep: ``meta["foot"]`` is
``"right"`` (what foot-dependent analyses such as ``huang_fpa`` with ``foot: auto`` read).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import scipy.io as sio

from ..data import Recording, Truth
from ..errors import FormatError

#: Columns of ``trial_error``: PyShoe's ARMSE (m) with each detector at its best threshold.
TRIAL_ERROR_DETECTORS = ("shoe", "ared", "amvd", "mbgtd", "vicon")


def read(path: Path, **options: Any) -> Recording:
    """Read a PyShoe ``.mat`` trial with its VICON reference as truth."""
    try:
        d = sio.loadmat(path)
    except Exception as err:  # scipy raises several types for bad files
        raise FormatError(f"{path}: cannot read as a MATLAB .mat file: {err}") from None
    missing = [k for k in ("imu", "ts") if k not in d]
    if missing:
        raise FormatError(f"{path}: not a PyShoe trial, missing variable(s) {missing}")
    imu = np.asarray(d["imu"], dtype=float)
    t = np.asarray(d["ts"], dtype=float).ravel()
    truth = None
    if "gt" in d:
        stance = np.asarray(d["zv_vicon_opt"]).ravel().astype(bool) if "zv_vicon_opt" in d else None
        mirror = np.array([1.0, 1.0, -1.0])  # VICON z up and mirrored: negate z only
        truth = Truth(pos=np.asarray(d["gt"], dtype=float) * mirror, stance=stance)
    meta: dict[str, Any] = {"name": path.stem, "source": str(path), "format": "pyshoe",
                            "placement": "right shoe instep (LORD MicroStrain)", "foot": "right"}
    if "trial_error" in d:
        errors = np.ravel(d["trial_error"]).astype(float)
        meta["pyshoe_trial_error"] = {k: float(e) for k, e in zip(TRIAL_ERROR_DETECTORS, errors, strict=True)}
    rec = Recording(t=t, acc=imu[:, :3], gyr=imu[:, 3:6], meta=meta, truth=truth, **options)
    return rec
