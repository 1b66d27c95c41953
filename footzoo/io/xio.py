"""x-io Technologies Gait-Tracking CSV (NGIMU), e.g. ``short_walk.csv``.

Columns ``Time (s), Gyroscope X/Y/Z (deg/s), Accelerometer X/Y/Z (g)``. The
NGIMU's z axis points up, so the axis map to FRD is ``[x, -y, -z]``, a rotation
of 180° about x (a proper rotation: gyro and accelerometer map alike; another
mounting: ``axes=``). The sensor's x axis is taken as the foot's forward axis; it is
tilted on the foot (the still foot reads about 30° of pitch), which the initial
alignment absorbs.

The file has exact duplicate rows (time stamp repeated) and short gaps (up to
17 ms at 400 Hz). Duplicates are dropped with a warning that gives the count;
gaps up to ``max_gap`` (default: the library's, 0.25 s) are bridged by the filters, which use
each sample's own interval, with a warning.

**Closed loop.** Nothing in an x-io file says whether the walk ends where it started. Only
x-io's published example walk (``short_walk.csv``, recognised by its SHA-256, and footzoo's
built-in sample made from it) is known to be a closed loop; for any other file
``truth.closed_loop`` is false unless ``closed_loop=True`` is passed or the file's metadata
sidecar (``<file>.meta.yaml``, :mod:`footzoo.io.metadata`) says ``closed_loop: true``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

from ..core.checks import check_bool
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
    text_source,
)
from .metadata import read_facts, sha256

COLUMNS = {
    "Time (s)": "t",
    "Gyroscope X (deg/s)": "gyr_x",
    "Gyroscope Y (deg/s)": "gyr_y",
    "Gyroscope Z (deg/s)": "gyr_z",
    "Accelerometer X (g)": "acc_x",
    "Accelerometer Y (g)": "acc_y",
    "Accelerometer Z (g)": "acc_z",
}

#: The NGIMU's axes -> FRD: z up -> z down, 180° about x.
AXES = "[x, -y, -z]"
ACC_UNIT = "g"
GYR_UNIT = "deg/s"

#: x-io files known to be closed walks: (size in bytes, SHA-256) -> name. The built-in sample is the first.
KNOWN_CLOSED_LOOPS: dict[tuple[int, str], str] = {
    (1203193, "35abfa9b3224cb69962917e945f2dc299595c8e5a8c427f77019dc09c27710e0"): "x-io Gait-Tracking short_walk.csv",
}


def matches(header: str) -> bool:
    """True for an x-io Gait-Tracking header."""
    return header.startswith("Time (s)") and "Gyroscope X (deg/s)" in header


def known_closed_loop(path: Path) -> str | None:
    """The name of the known closed walk ``path`` is, or None (the hash is computed only when the size matches)."""
    size = path.stat().st_size
    if not any(size == s for s, _ in KNOWN_CLOSED_LOOPS):
        return None
    return KNOWN_CLOSED_LOOPS.get((size, sha256(path)))


def read(
    path: Path, duplicates: str = "drop", max_gap: float | None = None, closed_loop: bool | None = None,
    axes: Any = AXES, acc_unit: str = ACC_UNIT, gyr_unit: str = GYR_UNIT, **options: Any,
) -> Recording:
    """Read an x-io CSV and convert to FRD/SI.

    Parameters
    ----------
    duplicates : {"drop", "error"}
        Repeated time stamps (the example file has about 1 % exact duplicates).
    max_gap : float, optional
        Largest gap bridged (s); default :data:`footzoo.core.checks.DEFAULT_MAX_GAP`.
    closed_loop : bool, optional
        Whether the walk ends where it started. Default: true for x-io's example walk, else what
        the metadata sidecar says, else false.
    axes : str or sequence
        The sensor's axes -> FRD (:mod:`footzoo.io.axes`); default ``[x, -y, -z]``.
    acc_unit, gyr_unit : str
        The file's units (default g and deg/s, as the column names say).
    """
    df = pd.read_csv(text_source(path))
    check_unique_columns(df, path)
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise FormatError(f"{path}: not an x-io Gait-Tracking CSV, missing {missing}")
    rows = parse_axes(AXES if axes is None else axes, "axes")
    df = df.rename(columns=COLUMNS)[list(COLUMNS.values())]
    rotate_columns(df, rows)
    facts = read_facts(path)
    known = known_closed_loop(path)
    if closed_loop is None:
        closed_loop = bool(known) or bool(facts.closed_loop)
        source = f"closed loop ({known})" if known else "closed loop (metadata sidecar)" if closed_loop else ""
    else:
        closed_loop = check_bool("closed_loop", closed_loop)
        source = "closed loop (declared)" if closed_loop else ""
    meta = {"name": path.stem, "source": str(path), "format": "xio", "placement": "foot (NGIMU, tilted ~30°)",
            "axes": describe_axes(rows), **facts.meta, "input_files": [str(path), *map(str, facts.files)]}
    return Recording.from_dataframe(
        df, acc_unit=acc_unit or ACC_UNIT, gyr_unit=gyr_unit or GYR_UNIT, duplicates=duplicates, max_gap=max_gap,
        meta=meta,
        truth=Truth(closed_loop=closed_loop, source=source), **options,
    )


class XioReader(Reader):
    """x-io Technologies Gait-Tracking CSV (NGIMU): g and deg/s, z up."""

    reads_metadata_sidecar = True
    description = "x-io Technologies Gait-Tracking CSV (NGIMU): Time (s), Gyroscope X (deg/s), ..., Accelerometer X (g)"
    extensions = (".csv",)
    url = "https://github.com/xioTechnologies/Gait-Tracking"
    options = {
        **frame_options(AXES, ACC_UNIT, GYR_UNIT),
        **RECORDING_OPTIONS,
        "duplicates": Option("drop", "", "repeated time stamps: 'drop' (keep the first, warn with the count) or "
                                         "'error'"),
        "closed_loop": Option(None, "", "whether the walk ends where it started (default: true for x-io's example "
                                        "walk, else the metadata sidecar's closed_loop, else false)"),
    }

    def guess_can_open(self, path: Path) -> bool:
        return data_suffix(path) in (".csv", ".txt") and matches(first_line(path))

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
