"""x-io Technologies Gait-Tracking CSV (NGIMU), e.g. ``short_walk.csv``.

Columns ``Time (s), Gyroscope X/Y/Z (deg/s), Accelerometer X/Y/Z (g)``. The
NGIMU's z axis points up, so the axis map to FRD is ``(x, −y, −z)``, a rotation
of 180° about x (a proper rotation: gyro and accelerometer map alike). The
sensor's x axis is taken as the foot's forward axis; it is tilted on the foot
(the still foot reads about 30° of pitch), which the initial alignment absorbs.

The file has exact duplicate rows (time stamp repeated) and short gaps (up to
17 ms at 400 Hz). Duplicates are dropped with a warning that gives the count;
gaps up to ``max_gap`` (default: the library's, 0.1 s) are bridged by the filters, which use
each sample's own interval, with a warning. The walk is a closed loop: ``truth.closed_loop``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

from ..core.checks import check_bool
from ..core.data import Recording, Truth
from ..core.errors import FormatError

COLUMNS = {
    "Time (s)": "t",
    "Gyroscope X (deg/s)": "gyr_x",
    "Gyroscope Y (deg/s)": "gyr_y",
    "Gyroscope Z (deg/s)": "gyr_z",
    "Accelerometer X (g)": "acc_x",
    "Accelerometer Y (g)": "acc_y",
    "Accelerometer Z (g)": "acc_z",
}


def matches(header: str) -> bool:
    """True for an x-io Gait-Tracking header."""
    return header.startswith("Time (s)") and "Gyroscope X (deg/s)" in header


def read(
    path: Path, duplicates: str = "drop", max_gap: float | None = None, closed_loop: bool = True, **options: Any
) -> Recording:
    """Read an x-io CSV and convert to FRD/SI.

    Parameters
    ----------
    duplicates : {"drop", "error"}
        Repeated time stamps (the file has about 1 % exact duplicates).
    max_gap : float, optional
        Largest gap bridged (s); default :data:`footzoo.core.data.DEFAULT_MAX_GAP`.
    closed_loop : bool
        Whether the walk ends where it started (true for ``short_walk.csv``).
    """
    closed_loop = check_bool("closed_loop", closed_loop)
    df = pd.read_csv(path)
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise FormatError(f"{path}: not an x-io Gait-Tracking CSV, missing {missing}")
    df = df.rename(columns=COLUMNS)[list(COLUMNS.values())]
    for c in ("acc_y", "acc_z", "gyr_y", "gyr_z"):  # z up -> z down: 180° about x
        df[c] = -df[c]
    meta = {"name": path.stem, "source": str(path), "format": "xio", "placement": "foot (NGIMU, tilted ~30°)"}
    return Recording.from_dataframe(
        df, acc_unit="g", gyr_unit="deg/s", duplicates=duplicates, max_gap=max_gap, meta=meta,
        truth=Truth(closed_loop=closed_loop, source="closed loop (x-io)" if closed_loop else ""), **options,
    )
