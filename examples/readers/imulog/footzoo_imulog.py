"""A footzoo reader for 'imulog' files, the text format of a (fictitious) lab's foot logger.

An imulog file is whitespace-separated text after a few ``#`` header lines::

    # imulog 1.0
    # device: FootLogger-3 serial 0042
    # columns: time_us ax_mg ay_mg az_mg gx_mdps gy_mdps gz_mdps
    0 12 -3 1002 150 -20 7
    5000 11 -2 1001 180 -25 9

Time in microseconds, specific force in milli-g, angular rate in milli-degrees per second, in
the logger's axes: x toward the toe, y to the left, z up when it is strapped on the instep. The
reader converts all of it once, here, into footzoo's conventions (FRD axes, SI units), as every
reader must: footzoo's filters never guess units or axes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from footzoo import FormatError, Recording
from footzoo.core.conventions import GRAVITY
from footzoo.io import Option, Reader
from footzoo.io.base import RECORDING_OPTIONS, first_line

#: The first line of every imulog file is ``# imulog VERSION``; this reader reads the versions of VERSIONS.
SIGNATURE = ("#", "imulog")
VERSIONS = ("1.0",)
#: Logger axes -> FRD: strapped on the instep the logger's y points left and z up (180° about x); mounted
#: under the sole (upside down, toe still forward) its z points down and y right already.
AXES = {"instep": np.diag([1.0, -1.0, -1.0]), "sole": np.eye(3)}


def version_of(path: Path) -> str | None:
    """The version an imulog file's first line names (``""``: none named); None when it is no imulog file."""
    words = first_line(path).split()
    return " ".join(words[2:]) if tuple(words[:2]) == SIGNATURE else None


class ImuLogReader(Reader):
    """imulog text files (time in µs, milli-g, milli-deg/s; logger axes x toe, y left, z up)."""

    description = "imulog text file of the FootLogger-3 ('# imulog 1.0' first line)"
    extensions = (".imulog", ".txt")
    options = {
        "mounting": Option("instep", "", "where the logger sits: 'instep' (z up) or 'sole' (z down)"),
        "max_gap": RECORDING_OPTIONS["max_gap"],
    }
    url = "https://example.org/footlogger-3"

    def guess_can_open(self, path: Path) -> bool:
        """A file whose first line is ``# imulog VERSION``, of any version (cheap: one line is read); :meth:`open`
        refuses a version it does not read, by name."""
        return Path(path).suffix.lower() in self.extensions and version_of(path) is not None

    def open(self, path: Path, mounting: str = "instep", max_gap: float | None = None) -> Recording:
        """Read the file into a footzoo Recording (FRD, SI)."""
        version = version_of(path)
        if version not in VERSIONS:
            raise FormatError(f"{path}: an imulog file of version {version or '(none given)'!r}; this reader "
                              f"(footzoo-imulog) reads version(s) {', '.join(VERSIONS)}: update footzoo-imulog, or "
                              "export the file from the logger as version 1.0")
        if mounting not in AXES:
            raise FormatError(f"{path}: mounting={mounting!r}: use one of {sorted(AXES)}")
        table = pd.read_csv(path, sep=r"\s+", comment="#", header=None).to_numpy(dtype=float)
        if table.ndim != 2 or table.shape[1] != 7:
            raise FormatError(f"{path}: an imulog row has 7 numbers (time_us, 3 acc, 3 gyro), found "
                              f"{table.shape[1] if table.ndim == 2 else 0}")
        rotation = AXES[mounting]
        return Recording(
            t=table[:, 0] * 1e-6,                                            # µs -> s
            acc=table[:, 1:4] * (GRAVITY / 1000.0) @ rotation.T,             # milli-g -> m/s², then FRD
            gyr=np.radians(table[:, 4:7] / 1000.0) @ rotation.T,             # milli-deg/s -> rad/s, then FRD
            meta={"name": path.stem, "source": str(path), "format": "imulog", "mounting": mounting},
            max_gap=max_gap,
        )
