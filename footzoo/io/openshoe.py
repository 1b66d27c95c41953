"""OpenShoe text exports ``data_inert.txt`` (Nilsson, Skog, Händel et al.'s open-source foot-mounted INS).

OpenShoe's MATLAB tools read the IMU from a whitespace-separated text file, after a header of
32 words. Two variants exist:

* **First-generation OpenShoe** (a MicroStrain 3DM-GX3-25 in the heel, 250 Hz), written by its
  logging software: the lines ``Inertial data.`` and ``Header: a_x [g]: a_y [g]: a_z [g]:
  ar_x [rad/s]: ... Counter: Checksum: Nr: Filtered ts[s]: Unfiltered ts[s]: Pred. ts[s]:
  Freq. [Hz]: m_x [G]: m_y [G]: m_z [G]:``, then per sample 17 columns: packet byte (hex),
  specific force (g), angular rate (rad/s), the device timer, a checksum (hex), the sample number,
  three host time stamps (s), the host's rate estimate (Hz) and the magnetic field (Gauss, ``+nan``
  when the packet had none). Files without the three magnetometer columns (14 columns) are read too.
* **OpenShoe boards** (MPU-9150 arrays): OpenShoe's ``logging_inertial_data.m`` writes the same
  17 columns after a header of 32 ``dummy_header`` words, with specific force in **m/s²**, angular
  rate in rad/s and every other column 0 (no time stamps: pass ``rate=``).

The units are read from the header (``[g]`` or ``[m/s^2]``, ``[rad/s]`` or ``[deg/s]``);
``acc_unit=`` / ``gyr_unit=`` replace them when the header is wrong.

**Time.** When the device timer is there, ``t`` is the timer in seconds (the 3DM-GX3's timer counts
19 660 800 ticks per second: 78 720 ticks per 250 Hz sample in OpenShoe's published measurements,
whose host clock gives the same rate to 0.01 %); a restart of the timer (it is reset when logging
starts) is bridged with the median interval and a warning. Without a timer the filtered host time
stamps are used, and without those ``rate=`` (Hz) must be given: ``t = row / rate``. An explicit
``rate=`` always wins.

**Axis map.** OpenShoe's published measurements read +1 g on the sensor's z axis when the foot
stands still: the sensor sits z up in the heel. The default map is ``[x, -y, -z]``, a 180° rotation
about x that brings z down, with the sensor's x axis taken as the toe direction (check it on your
own mounting; ``axes=`` takes any proper rotation, see :mod:`footzoo.io.axes`). Missing
magnetometer readings are filled by linear interpolation (their count is in
``meta["mag_interpolated"]``).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.checks import check_bool, check_range
from ..core.data import Recording
from ..core.errors import FootzooWarning, FormatError, user_stacklevel
from .axes import apply_axes, describe_axes, parse_axes
from .base import RECORDING_OPTIONS, Option, Reader, check_encoding, frame_options, text_source

#: Ticks per second of the MicroStrain 3DM-GX3 timer in the ``Counter`` column.
TIMER_HZ = 19_660_800.0
#: Default axis map: z up in the heel -> FRD, 180° about x.
DEFAULT_AXES = "[x, -y, -z]"
#: Lines searched for the header.
HEADER_LINES = 50
COLUMNS_17 = ["packet", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z", "counter", "checksum", "nr",
              "ts_filtered", "ts_unfiltered", "ts_predicted", "freq", "mag_x", "mag_y", "mag_z"]
COLUMNS_14 = COLUMNS_17[:14]
_UNIT = re.compile(r"a_x\s*\[([^\]]+)\]|ar_x\s*\[([^\]]+)\]")
ACC_UNIT_NAMES = {"g": "g", "m/s^2": "m/s^2", "m/s2": "m/s^2", "mg": "mg"}
GYR_UNIT_NAMES = {"rad/s": "rad/s", "deg/s": "deg/s", "°/s": "deg/s"}


def find_header(path: Path) -> tuple[int, str] | None:
    """``(line number, header line)`` of an OpenShoe ``data_inert.txt``, or None when it is not one."""
    with open(path, encoding="utf-8", errors="replace") as fh:
        for k in range(HEADER_LINES):
            line = fh.readline(64 * 1024)
            if not line:
                return None
            text = line.strip()
            if text.startswith("Header:") and "a_x" in text and "ar_x" in text:
                return k, text
            words = text.split()
            if words and len(words) >= 8 and all(w == "dummy_header" for w in words):
                return k, text
            if text and text != "Inertial data.":
                return None
    return None


def header_units(header: str, path: Path) -> tuple[str, str]:
    """``(acc_unit, gyr_unit)`` named in the header; a ``dummy_header`` one means m/s² and rad/s."""
    if header.split()[0] == "dummy_header":
        return "m/s^2", "rad/s"
    acc = gyr = None
    for a, g in _UNIT.findall(header):
        acc = acc or a
        gyr = gyr or g
    if acc not in ACC_UNIT_NAMES or gyr not in GYR_UNIT_NAMES:
        raise FormatError(f"{path}: the header names the units [{acc}] and [{gyr}]; footzoo knows "
                          f"{sorted(ACC_UNIT_NAMES)} and {sorted(GYR_UNIT_NAMES)}; fix the header")
    return ACC_UNIT_NAMES[acc], GYR_UNIT_NAMES[gyr]


def _time_base(df: pd.DataFrame, rate: float | None, path: Path) -> tuple[np.ndarray, str]:
    """Sample times (s) and where they come from (see the module doc)."""
    n = len(df)
    if rate is not None:
        return np.arange(n) / rate, f"row / rate ({rate:g} Hz)"
    counter = pd.to_numeric(df["counter"], errors="coerce").to_numpy(dtype=float)
    if np.isfinite(counter).all() and np.count_nonzero(counter) > n // 2:
        step = np.diff(counter)
        good = step > 0
        if good.sum() > n // 2:
            median = float(np.median(step[good]))
            restarts = int((~good).sum())
            if restarts:
                k = int(np.argmax(~good))
                warnings.warn(FootzooWarning(
                    f"{path}: the device timer restarted {restarts} time(s) (the first after row {k}); each of those "
                    f"intervals is taken as the median period ({median / TIMER_HZ * 1e3:.3f} ms)"),
                    stacklevel=user_stacklevel())
                step = np.where(good, step, median)
            return np.concatenate([[0.0], np.cumsum(step)]) / TIMER_HZ, "device timer (3DM-GX3, 19.6608 MHz)"
    host = pd.to_numeric(df.get("ts_filtered", pd.Series(dtype=float)), errors="coerce").to_numpy(dtype=float)
    if host.size == n and np.isfinite(host).all() and np.all(np.diff(host) > 0):
        return host - host[0], "host time stamps (filtered)"
    raise FormatError(f"{path}: the file has no usable time stamps (its timer and time-stamp columns are empty, as "
                      "in files written by OpenShoe's logging_inertial_data.m); pass the sampling rate, e.g. "
                      "rate=820 (command line: --option rate=820)")


def read(path: Path, rate: float | None = None, axes: Any = DEFAULT_AXES, magnetometer: bool = True,
         acc_unit: str | None = None, gyr_unit: str | None = None, **options: Any) -> Recording:
    """Read an OpenShoe ``data_inert.txt`` and convert it to FRD/SI.

    Parameters
    ----------
    rate : float, optional
        Sampling rate (Hz); required for files without time stamps, and then ``t = row / rate``.
    axes : str or sequence, optional
        Sensor axes -> FRD (:func:`footzoo.io.axes.parse_axes`); default ``[x, -y, -z]``.
    magnetometer : bool
        Read the magnetometer columns when the file has them.
    acc_unit, gyr_unit : str, optional
        The file's units; default: those its header names.
    """
    check_encoding(path)  # a UTF-16 export is named as such, not as another format
    found = find_header(path)
    if found is None:
        raise FormatError(f"{path}: not an OpenShoe data_inert.txt (no 'Header: a_x [...]' or dummy_header line in "
                          f"the first {HEADER_LINES} lines)")
    line, header = found
    if rate is not None:
        rate = check_range("rate", rate, 0.0, 100_000.0, "Hz", lo_open=True)
    magnetometer = check_bool("magnetometer", magnetometer)
    rows = parse_axes(DEFAULT_AXES if axes is None else axes, "axes")
    header_acc, header_gyr = header_units(header, path)
    acc_unit, gyr_unit = acc_unit or header_acc, gyr_unit or header_gyr
    src = text_source(path)
    df = pd.read_csv(src, sep=r"\s+", header=None, skiprows=line + 1, dtype={0: str, 8: str},
                     na_values=["+nan", "-nan"], skip_blank_lines=True)
    if df.shape[1] not in (14, 17):
        raise FormatError(f"{path}: OpenShoe rows have 14 or 17 columns (acc, gyro, timer, ..., [mag]), this file "
                          f"has {df.shape[1]}; is it a data_inert.txt?")
    df.columns = COLUMNS_17 if df.shape[1] == 17 else COLUMNS_14
    for c in df.columns:
        if c not in ("packet", "checksum") and df[c].dtype == object:
            df[c] = pd.to_numeric(df[c], errors="coerce")
    t, time_source = _time_base(df, rate, path)
    frame = pd.DataFrame({"t": t})
    for block in ("acc", "gyr"):
        cols = [f"{block}_{a}" for a in "xyz"]
        frame[cols] = apply_axes(rows, df[cols].to_numpy(dtype=float))
    meta: dict[str, Any] = {"name": path.stem if path.stem != "data_inert" else path.parent.name or path.stem,
                            "source": str(path), "format": "openshoe", "axes": describe_axes(rows),
                            "time_base": time_source, "input_files": [str(path)]}
    if magnetometer and "mag_x" in df.columns:
        mag = df[["mag_x", "mag_y", "mag_z"]].to_numpy(dtype=float)
        have = np.isfinite(mag).all(axis=1)
        if have.sum() >= 2:
            missing = int((~have).sum())
            if missing:
                mag = pd.DataFrame(mag).interpolate(limit_direction="both").to_numpy()
            frame[["mag_x", "mag_y", "mag_z"]] = apply_axes(rows, mag)
            meta.update(mag_unit="Gauss", mag_interpolated=missing)
    return Recording.from_dataframe(frame, acc_unit=acc_unit, gyr_unit=gyr_unit, meta=meta, **options)


class OpenShoeReader(Reader):
    """OpenShoe ``data_inert.txt`` (first-generation MicroStrain loggers and OpenShoe boards)."""

    description = "OpenShoe data_inert.txt (whitespace-separated; 'Header: a_x [g]: ...' or dummy_header line)"
    extensions = (".txt",)
    url = "http://www.openshoe.org"
    options = {
        "rate": Option(None, "Hz", "sampling rate; needed when the file has no time stamps (t = row / rate)"),
        **frame_options(DEFAULT_AXES, None, None, where="the units the header names"),
        "magnetometer": Option(True, "", "read the magnetometer columns when the file has them"),
        **RECORDING_OPTIONS,
    }

    def guess_can_open(self, path: Path) -> bool:
        return Path(path).suffix.lower() in (".txt", ".dat") and find_header(Path(path)) is not None

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
