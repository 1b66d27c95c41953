"""Xsens MT Manager text exports (MTw Awinda and other MTi/MTw sensors), e.g. Voisard et al.'s gait data set.

A tab-separated table whose header line starts with ``PacketCounter``, after a few lines that
say how it was recorded; the IPOL healthy-gait data set (Voisard et al., "A reference data set
for the study of healthy subject gait with inertial measurement units", IPOL 2023) writes one::

    Acquisition frequency: 100 Hz
    PacketCounter   Acc_X   Acc_Y   Acc_Z   Gyr_X   Gyr_Y   Gyr_Z   Mag_X   Mag_Y   Mag_Z
    0.0             5.119   0.695   8.586   -0.0088 0.0042  -0.0205 -0.641  0.064   -0.492

and MT Manager's own export has ``//`` comment lines with ``Update Rate: 100.00Hz``. Columns:
``Acc_*`` specific force (m/s²), ``Gyr_*`` angular rate (rad/s), ``Mag_*`` the magnetic field
normalised to the one at calibration (arbitrary units, about 1; footzoo uses its direction
only). Other columns (``SampleTimeFine``, ``Quat_*``, ``FreeAcc_*`` …) are not read.

**Time** is ``PacketCounter / rate`` (s), with the rate from the ``Acquisition frequency`` or
``Update Rate`` line (``rate=`` overrides it or stands in for it). The counter is 16 bits: it
wraps from 65535 to 0 (every 655 s at 100 Hz), and a wrap is unwrapped (65 536 added to every
later packet). A wireless sensor drops packets: the counter then skips values (the IPOL file
``6-1_lf`` has 2 847 rows over 3 130 packets, 191 gaps of up to 8 packets). The rows keep their
true time stamps; nothing is invented in a gap: like any recording with missing samples, a gap
up to ``max_gap`` (default 0.25 s) is bridged by the filters, which integrate over each sample's
own interval, with a :class:`~footzoo.core.errors.FootzooWarning` that counts the gaps (and names
the longest), and a longer gap is refused with the rows around it
(:class:`~footzoo.core.data.Recording`). A counter that goes back without wrapping (rows out of
order, two files joined) is a :class:`~footzoo.core.errors.FormatError`; a repeated packet
follows ``duplicates``.

**Axis map.** No mounting is written in the file. The default ``[-x, y, -z]`` (a rotation of 180°
about y) is the one of the IPOL data set's MTw on the dorsum of each foot, judged from the data:
at rest the sensor reads about (5.1, 0.7, 8.6) m/s² (its z axis points up, its x axis 31° above
the horizontal); reading every file of the data set (18 trials, both feet) with ``[x, -y, -z]``
and running ``recommended``, the measured mounting (``result.diagnostics["mounting"]``) names
``[-x, -y, z]`` on top of it, i.e. ``[-x, y, -z]`` from the sensor's axes: its x axis points to
the heel (up the instep), its y axis to the foot's right on both feet. With it footzoo's
stance-phase measure of the mounting (:mod:`footzoo.analysis.mounting`) reports no backward walk
and no reversed pitch on any of the 36 files, and ``gyr_y`` is the foot's pitch rate (toe up
positive) as in Voisard et al.'s detector, which reads ``Gyr_Y``. For another mounting pass
``axes=`` (any proper rotation, :mod:`footzoo.io.axes`); the same map turns the accelerometer, the
gyroscope and the magnetometer.

**Foot and reference events.** ``_lf`` / ``_rf`` at the end of the file name say the foot
(``meta["foot"]``). When ``<trial>.json`` lies beside the file (``6-1.json`` for ``6-1_lf.txt``),
its annotations become the recording's reference (``truth.steps``, the form of gaitmap's motion
capture events, :mod:`footzoo.io.gaitmap_reference`): ``LeftFootEvents`` / ``RightFootEvents``
hold one ``[toe-off, heel-strike]`` pair per swing, in packets from the file's first packet; each
swing is a reference stride with ``to_s`` (toe-off), ``end_s`` (the heel strike ending it) and
``start_s`` (the heel strike of the swing before, NaN for the first). An annotation names a
sample, so it is placed, like footzoo's own events (:mod:`footzoo.analysis.gait_events`), at the
middle of that sample's interval: ``(first packet + count − ½) / rate``, 5 ms before the sample's
time stamp at 100 Hz. The annotations come from two IMU-based event detectors checked by hand
(Barrois et al. 2017; Voisard et al.), not from motion capture; the authors advise comparing
inside ``TrialBoundaries`` and outside ``UTurnBoundaries``, so only the swings inside the trial
whose toe-off and heel strike both lie outside the U-turn are kept (``uturn=True`` keeps the
U-turn's swings too, with ``turn`` true). The boundaries (s) and the subject's age, sex, height
and weight are in ``meta``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.checks import check_bool, check_range
from ..core.data import Recording, Truth
from ..core.errors import FormatError, shown
from .axes import apply_axes, describe_axes, parse_axes
from .base import RECORDING_OPTIONS, Option, Reader, check_encoding, check_unique_columns, frame_options, text_source

#: Default axis map: the IPOL data set's MTw on the dorsum of the foot, x to the heel, z up (180° about y).
DEFAULT_AXES = "[-x, y, -z]"
#: The 16-bit packet counter wraps from 65535 to 0.
COUNTER_WRAP = 65536
#: Lines searched for the header.
HEADER_LINES = 50
ACC = ["Acc_X", "Acc_Y", "Acc_Z"]
GYR = ["Gyr_X", "Gyr_Y", "Gyr_Z"]
MAG = ["Mag_X", "Mag_Y", "Mag_Z"]
_RATE = re.compile(r"(?:Acquisition frequency|Update Rate)\s*:\s*([0-9.]+)\s*Hz", re.IGNORECASE)
_FOOT = {"lf": "left", "rf": "right"}


def find_header(path: Path) -> tuple[int, str, float | None] | None:
    """``(line number, header line, rate in Hz or None)`` of an Xsens text export, or None when it is not one."""
    rate = None
    with open(path, encoding="utf-8-sig", errors="replace") as fh:
        for k in range(HEADER_LINES):
            line = fh.readline(64 * 1024)
            if not line:
                return None
            text = line.strip()
            found = _RATE.search(text)
            if found:
                if rate is not None and float(found.group(1)) != rate:
                    raise FormatError(f"{path}: the header says two sampling rates, {rate:g} Hz and "
                                      f"{float(found.group(1)):g} Hz (line {k + 1}); footzoo cannot tell which one "
                                      "timed the packets: pass the true one, e.g. rate=100 (command line: --option "
                                      "rate=100)")
                rate = float(found.group(1))
            if text.startswith("PacketCounter"):
                names = re.split(r"[\t,;]|\s+", text)
                return (k, text, rate) if {"Acc_X", "Gyr_X"} <= set(names) else None
    return None


def _delimiter(header: str) -> str:
    return next((d for d in ("\t", ";", ",") if d in header), r"\s+")


def packet_times(counter: np.ndarray, rate: float, path: Path) -> np.ndarray:
    """``PacketCounter / rate`` (s), the 16-bit counter's wraps unwrapped.

    Raises
    ------
    FormatError
        For a counter that is not whole numbers, or that goes back without wrapping.
    """
    pc = np.asarray(counter, dtype=float)
    bad = ~np.isfinite(pc) | (pc != np.round(pc)) | (pc < 0)
    if bad.any():
        k = int(np.argmax(bad))
        raise FormatError(f"{path}: PacketCounter must hold whole numbers >= 0; "
                          f"data row {k} holds {shown(counter[k])}; "
                          "repair the file (footzoo reads t = PacketCounter / rate)")
    step = np.diff(pc)
    wrap = (step < 0) & (pc[:-1] - pc[1:] > COUNTER_WRAP / 2) & (pc[:-1] < COUNTER_WRAP)
    back = (step < 0) & ~wrap
    if back.any():
        k = int(np.argmax(back))
        raise FormatError(f"{path}: PacketCounter goes back from {int(pc[k])} to {int(pc[k + 1])} at data row {k + 1} "
                          "(not a wrap of the 16-bit counter at 65536): rows out of order or two files joined; "
                          "sort the rows or split the file")
    unwrapped = pc + COUNTER_WRAP * np.concatenate([[0], np.cumsum(wrap)])
    return unwrapped / rate


def trial_annotations(path: Path) -> Path | None:
    """The annotation file ``<trial>.json`` beside an IPOL foot file ``<trial>_lf.txt`` / ``<trial>_rf.txt``."""
    stem = path.stem
    if stem[-3:].lower() not in ("_lf", "_rf"):
        return None
    candidate = path.with_name(stem[:-3] + ".json")
    return candidate if candidate.exists() else None


def _bounds(annotations: dict[str, Any], key: str, default: tuple[float, float]) -> tuple[float, float]:
    """``annotations[key]`` as two packet counts ``(first, last)``; the default when it is absent."""
    if key not in annotations:
        return default
    try:
        lo, hi = (float(v) for v in annotations[key])
    except (TypeError, ValueError):
        raise FormatError(f"{key} must be two packet counts [first, last], got {annotations[key]!r:.80}; repair the "
                          "annotations") from None
    return lo, hi


def reference_events(annotations: dict[str, Any], foot: str, first: float, rate: float,
                     uturn: bool = False, packets: float | None = None) -> pd.DataFrame:
    """The reference strides (``start_s``, ``to_s``, ``end_s``, ``turn``) of one foot from IPOL annotations.

    Parameters
    ----------
    annotations : dict
        The ``<trial>.json`` content (``LeftFootEvents`` / ``RightFootEvents``: ``[toe-off, heel-strike]``
        packet counts from the first packet; ``TrialBoundaries``, ``UTurnBoundaries``).
    foot : {"left", "right"}
    first : float
        The file's first packet (unwrapped counter).
    rate : float
        Sampling rate (Hz).
    uturn : bool
        Keep the swings in the U-turn (``turn`` true); by default they are left out.
    packets : float, optional
        The packets the file spans (last − first); an event beyond them is a :class:`FormatError`.
    """
    key = "LeftFootEvents" if foot == "left" else "RightFootEvents"
    try:
        pairs = np.asarray(annotations[key], dtype=float).reshape(-1, 2)
    except (KeyError, TypeError, ValueError):
        raise FormatError(f"the annotations have no readable {key} (a list of [toe-off, heel-strike] pairs)") from None
    lo, hi = _bounds(annotations, "TrialBoundaries", (-np.inf, np.inf))
    u0, u1 = _bounds(annotations, "UTurnBoundaries", (np.inf, -np.inf))
    bad = np.flatnonzero(~np.isfinite(pairs).all(axis=1) | (pairs[:, 0] >= pairs[:, 1]))
    if bad.size:
        raise FormatError(f"{key}[{bad[0]}] = {pairs[bad[0]].tolist()}: a swing is [toe-off, heel-strike] packet "
                          f"counts with the toe-off first ({bad.size} pair(s) are not); repair the annotations")
    if packets is not None and pairs.size and (pairs.min() < 0 or pairs.max() > packets):
        raise FormatError(f"{key} names packets {pairs.min():.0f}-{pairs.max():.0f}, but the file holds packets 0-"
                          f"{packets:.0f} from its first: these annotations belong to another trial or file; "
                          "check the pairing of the .json and .txt files")
    times = (first + pairs - 0.5) / rate  # the middle of the annotated sample's interval
    start = np.concatenate([[np.nan], times[:-1, 1]])
    turn = (pairs[:, 0] <= u1) & (pairs[:, 1] >= u0)
    keep = (pairs[:, 0] >= lo) & (pairs[:, 1] <= hi) & (uturn | ~turn)
    return pd.DataFrame({"start_s": start, "to_s": times[:, 0], "end_s": times[:, 1], "turn": turn})[keep] \
        .reset_index(drop=True)


def read(path: Path, rate: float | None = None, axes: Any = DEFAULT_AXES, magnetometer: bool = True,
         uturn: bool = False, acc_unit: str | None = None, gyr_unit: str | None = None, **options: Any) -> Recording:
    """Read an Xsens text export and convert it to FRD/SI (see the module documentation).

    Parameters
    ----------
    rate : float, optional
        Sampling rate (Hz); default the file's ``Acquisition frequency`` / ``Update Rate`` line.
    axes : str or sequence, optional
        Sensor axes -> FRD (:func:`footzoo.io.axes.parse_axes`); default ``[-x, y, -z]``.
    magnetometer : bool
        Read ``Mag_X..Z`` when the file has them.
    uturn : bool
        Keep the reference swings inside the U-turn (IPOL annotations).
    acc_unit, gyr_unit : str, optional
        The file's units; default MT Manager's, m/s² and rad/s.
    """
    check_encoding(path)  # a UTF-16 export is named as such, not as another format
    found = find_header(path)
    if found is None:
        raise FormatError(f"{path}: not an Xsens text export (no header line starting with PacketCounter and naming "
                          f"Acc_X and Gyr_X in the first {HEADER_LINES} lines)")
    line, header, file_rate = found
    if rate is None and file_rate is None:
        raise FormatError(f"{path}: the file does not say its sampling rate (no 'Acquisition frequency: ... Hz' or "
                          "'Update Rate: ...Hz' line); pass it, e.g. rate=100 (command line: --option rate=100)")
    if rate is None and not 0.0 < file_rate <= 100_000.0:
        raise FormatError(f"{path}: the header says a sampling rate of {file_rate:g} Hz, which no sensor has; pass the "
                          "true one, e.g. rate=100 (command line: --option rate=100)")
    rate = check_range("rate", rate if rate is not None else file_rate, 0.0, 100_000.0, "Hz", lo_open=True)
    magnetometer = check_bool("magnetometer", magnetometer)
    uturn = check_bool("uturn", uturn)
    rows = parse_axes(DEFAULT_AXES if axes is None else axes, "axes")
    df = pd.read_csv(text_source(path), sep=_delimiter(header), skiprows=line, header=0, engine="python")
    check_unique_columns(df, path)
    missing = [c for c in ["PacketCounter", *ACC, *GYR] if c not in df.columns]
    if missing:
        raise FormatError(f"{path}: the Xsens header lacks {missing}; found {list(df.columns)[:12]}")
    counter = pd.to_numeric(df["PacketCounter"], errors="coerce").to_numpy(dtype=float)
    t = packet_times(counter, rate, path)
    frame = pd.DataFrame({"t": t})
    for cols, names in ((ACC, ["acc_x", "acc_y", "acc_z"]), (GYR, ["gyr_x", "gyr_y", "gyr_z"])):
        frame[names] = apply_axes(rows, df[cols].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float))
    stem = path.stem
    foot = _FOOT.get(stem[-2:].lower()) if stem[-3:-2] == "_" else None
    meta: dict[str, Any] = {"name": stem, "source": str(path), "format": "xsens", "axes": describe_axes(rows),
                            "time_base": f"PacketCounter / {rate:g} Hz", "input_files": [str(path)],
                            "placement": f"{foot + ' ' if foot else ''}foot (Xsens, axis map {describe_axes(rows)})"}
    if foot:
        meta["foot"] = foot
    if magnetometer and all(c in df.columns for c in MAG):
        frame[["mag_x", "mag_y", "mag_z"]] = apply_axes(rows, df[MAG].apply(pd.to_numeric, errors="coerce")
                                                        .to_numpy(dtype=float))
        meta["mag_unit"] = "a.u. (normalised to the field at calibration)"
    truth = None
    notes = trial_annotations(path)
    if notes is not None and foot is not None:
        try:
            annotations = json.loads(notes.read_text())
        except (OSError, ValueError) as err:
            raise FormatError(f"{notes}: the annotation file cannot be read as JSON ({err}); repair or move "
                              "it") from None
        first = float(np.round(t[0] * rate))
        packets = float(np.round(t[-1] * rate)) - first
        try:
            steps = reference_events(annotations, foot, first, rate, uturn, packets=packets)
        except FormatError as err:
            raise FormatError(f"{notes}: {err}") from None
        meta["input_files"].append(str(notes))
        for key, name in (("TrialBoundaries", "trial_s"), ("UTurnBoundaries", "uturn_s")):
            if key in annotations:
                meta[name] = [float((first + v - 0.5) / rate) for v in annotations[key]]
        subject = {k.lower(): annotations[k] for k in ("Subject", "Age", "Gender", "Height", "Weight")
                   if k in annotations}
        if subject:
            meta["subject"] = subject
        truth = Truth(steps=steps, source="hand-checked IMU events (Voisard et al. 2023, IPOL)")
    return Recording.from_dataframe(frame, acc_unit=acc_unit or "m/s^2", gyr_unit=gyr_unit or "rad/s", meta=meta,
                                    truth=truth, **options)


class XsensReader(Reader):
    """Xsens MT Manager text export (PacketCounter, Acc_X.., Gyr_X.., Mag_X..): m/s², rad/s, a.u."""

    description = "Xsens MT Manager text export (a header line 'PacketCounter<TAB>Acc_X ... Gyr_X ...')"
    extensions = (".txt", ".csv", ".tsv")
    url = "https://github.com/CyrilVoisard/ipol_dataset_1"
    options = {
        "rate": Option(None, "Hz", "sampling rate; default the file's 'Acquisition frequency' / 'Update Rate' line "
                                   "(t = PacketCounter / rate)"),
        **frame_options(DEFAULT_AXES, "m/s^2", "rad/s"),
        "magnetometer": Option(True, "", "read Mag_X..Z when the file has them"),
        "uturn": Option(False, "", "keep the reference swings inside the U-turn (IPOL annotations; flagged turn)"),
        **RECORDING_OPTIONS,
    }

    def guess_can_open(self, path: Path) -> bool:
        return Path(path).suffix.lower() in self.extensions and find_header(Path(path)) is not None

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """IPOL's annotations ``<trial>.json`` beside a foot file ``<trial>_lf.txt`` / ``<trial>_rf.txt``."""
        stem = Path(path).stem
        return [Path(path).with_name(stem[:-3] + ".json")] if stem[-3:].lower() in ("_lf", "_rf") else []

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
