"""Data model: :class:`Recording`, :class:`Truth` and :class:`Result`.

A :class:`Recording` holds signals already converted to footzoo's conventions
(FRD body frame, SI units, see :mod:`footzoo.conventions`). It is validated on
construction; every problem raises :class:`~footzoo.errors.RecordingError`
with a message that names the column and the fix.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .conventions import ACC_UNITS, DIST_UNITS, GRAVITY, GYR_UNITS
from .errors import FootzooWarning, RecordingError

ACC_COLS = ["acc_x", "acc_y", "acc_z"]
GYR_COLS = ["gyr_x", "gyr_y", "gyr_z"]
MAG_COLS = ["mag_x", "mag_y", "mag_z"]
TRUTH_POS_COLS = ["true_pos_n", "true_pos_e", "true_pos_d"]
TRUTH_VEL_COLS = ["true_vel_n", "true_vel_e", "true_vel_d"]
TRUTH_QUAT_COLS = ["true_qw", "true_qx", "true_qy", "true_qz"]

#: Shortest recording footzoo accepts (s): the initial alignment needs still samples.
MIN_DURATION = 1.0
#: Default largest gap between samples that is bridged (s); longer gaps are refused.
DEFAULT_MAX_GAP = 0.1
#: ... or this many median sample periods, when that is longer (slow loggers).
DEFAULT_MAX_GAP_PERIODS = 5.0
#: An interval longer than this many median periods is a gap (at least one sample missing).
GAP_PERIODS = 1.5
#: Gyro peak (in the declared unit rad/s) above which the data must be in deg/s.
GYRO_DEG_S_SUSPICION = 50.0


@dataclass
class Truth:
    """Reference values that no estimator produced (simulator or dataset).

    Attributes
    ----------
    pos : (N, 3) ndarray or None
        Sensor position in NED (m); the horizontal axes may be rotated about
        the vertical with respect to the estimate (compare after alignment).
    vel : (N, 3) ndarray or None
        Sensor velocity in NED (m/s).
    quat : (N, 4) ndarray or None
        Body -> NED attitude, scalar first.
    stance : (N,) bool ndarray or None
        True where the sensor's velocity is zero.
    steps : DataFrame or None
        One row per step (start, end in s; stride length in m; heading and
        foot progression angle in rad), where known.
    closed_loop : bool
        The walk ends where it started (loop-closure metrics apply).
    dist : (N, k) ndarray or None
        True range of each distance sensor (m), NaN where it has no sample.
    """

    pos: np.ndarray | None = None
    vel: np.ndarray | None = None
    quat: np.ndarray | None = None
    stance: np.ndarray | None = None
    steps: pd.DataFrame | None = None
    closed_loop: bool = False
    dist: np.ndarray | None = None


@dataclass
class Recording:
    """IMU signals in FRD/SI, validated.

    Parameters
    ----------
    t : (N,) ndarray
        Sample times (s), strictly increasing.
    acc : (N, 3) ndarray
        Specific force in the FRD body frame (m/s²); at rest ≈ ``[0, 0, -g]``.
    gyr : (N, 3) ndarray
        Angular rate in FRD (rad/s).
    mag : (N, 3) ndarray, optional
        Magnetic field in FRD (any unit).
    dist : (N, k) ndarray, optional
        Distance-sensor ranges (m); NaN where the slower sensor has no sample.
    meta : dict
        ``name``, ``source``, ``rate`` (Hz, derived), ``placement`` …
    truth : Truth, optional
        Reference values, if any.
    max_gap : float, optional
        Largest gap between two samples that is bridged (s); default
        ``max(DEFAULT_MAX_GAP, 5 median periods)`` = 0.1 s above 50 Hz. Shorter
        gaps are kept as they are (no samples invented: every filter integrates
        over each sample's own interval, which is what the sensor measured) and
        reported with a :class:`~footzoo.errors.FootzooWarning` and in
        ``meta["diagnostics"]["gaps"]``; longer gaps are refused.
    """

    t: np.ndarray
    acc: np.ndarray
    gyr: np.ndarray
    mag: np.ndarray | None = None
    dist: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    truth: Truth | None = None
    max_gap: float | None = None

    def __post_init__(self) -> None:
        self.t = np.ascontiguousarray(self.t, dtype=float)
        self.acc = np.ascontiguousarray(self.acc, dtype=float)
        self.gyr = np.ascontiguousarray(self.gyr, dtype=float)
        if self.mag is not None:
            self.mag = np.ascontiguousarray(self.mag, dtype=float)
        if self.dist is not None:
            self.dist = np.ascontiguousarray(self.dist, dtype=float)
            if self.dist.ndim == 1:
                self.dist = self.dist[:, None]
        validate_recording(self)
        self.meta = dict(self.meta)
        _report_gaps(self)
        self.meta.setdefault("name", "recording")
        self.meta["rate"] = float(1.0 / np.median(np.diff(self.t)))

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.t.shape[0]

    @property
    def rate(self) -> float:
        """Median sampling rate (Hz)."""
        return self.meta["rate"]

    @property
    def name(self) -> str:
        """The recording's name (file stem or given)."""
        return str(self.meta.get("name", "recording"))

    @classmethod
    def from_dataframe(
        cls,
        df: pd.DataFrame,
        *,
        acc_unit: str = "m/s^2",
        gyr_unit: str = "rad/s",
        dist_unit: str = "m",
        time_col: str = "t",
        duplicates: str = "error",
        nan_policy: str = "error",
        max_gap: float | None = None,
        meta: dict[str, Any] | None = None,
        truth: Truth | None = None,
    ) -> Recording:
        """Build a recording from a DataFrame with canonical column names.

        Columns: ``t`` (s), ``acc_x..acc_z``, ``gyr_x..gyr_z``, optionally
        ``mag_x..mag_z`` and ``dist_a``, ``dist_b``, …, all already in the FRD
        body frame. ``true_pos_n..d``, ``true_vel_n..d``, ``true_qw..qz`` and
        ``true_stance`` columns, when present, become the :class:`Truth`.

        Parameters
        ----------
        acc_unit : {"m/s^2", "g", "mg"}
            Unit of the acc columns.
        gyr_unit : {"rad/s", "deg/s"}
            Unit of the gyr columns.
        dist_unit : {"m", "cm", "mm"}
            Unit of the dist columns.
        duplicates : {"error", "drop"}
            What to do with rows whose time stamp repeats the previous one.
            ``"drop"`` keeps the first and warns with the count.
        nan_policy : {"error", "interpolate"}
            What to do with non-finite IMU values (``dist`` may always be NaN).
        max_gap : float, optional
            Largest gap bridged (s); default 0.1 s (or 5 median periods if longer).
        """
        _check_choice("acc_unit", acc_unit, ACC_UNITS)
        _check_choice("gyr_unit", gyr_unit, GYR_UNITS)
        _check_choice("dist_unit", dist_unit, DIST_UNITS)
        _check_choice("duplicates", duplicates, ("error", "drop"))
        _check_choice("nan_policy", nan_policy, ("error", "interpolate"))
        if len(df) == 0:
            raise RecordingError("the recording is empty (0 rows); check the file and its header")
        required = [time_col, *ACC_COLS, *GYR_COLS]
        missing = [c for c in required if c not in df.columns]
        if missing:
            raise RecordingError(
                f"missing column(s) {missing}; a recording needs {required} "
                f"(found {list(df.columns)[:12]}). Rename the columns or use a reader from footzoo.io"
            )
        has_mag = all(c in df.columns for c in MAG_COLS)
        partial_mag = [c for c in MAG_COLS if c in df.columns]
        if partial_mag and not has_mag:
            raise RecordingError(f"magnetometer columns incomplete: found {partial_mag}, need {MAG_COLS}")
        dist_cols = sorted(c for c in df.columns if c.startswith("dist_"))

        df = df.reset_index(drop=True)
        t = pd.to_numeric(df[time_col], errors="coerce").to_numpy(dtype=float)
        meta = dict(meta or {})
        if duplicates == "drop":
            dup = np.zeros(len(t), dtype=bool)
            dup[1:] = np.diff(t) == 0
            meta["dropped_duplicates"] = int(dup.sum())
            if dup.any():
                warnings.warn(
                    f"dropped {int(dup.sum())} row(s) whose time stamp repeats the previous one",
                    stacklevel=2,
                )
                df = df.loc[~dup].reset_index(drop=True)
                t = t[~dup]

        def block(cols: list[str], scale: float, allow_nan: bool = False) -> np.ndarray:
            values = df[cols].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float) * scale
            if allow_nan:
                return values
            bad = ~np.isfinite(values)
            if bad.any():
                if nan_policy == "interpolate":
                    frame = pd.DataFrame(values).interpolate(limit_direction="both")
                    return frame.to_numpy(dtype=float)
                row, col = np.argwhere(bad)[0]
                raise RecordingError(
                    f"column {cols[col]!r} has {int(bad[:, col].sum())} non-finite value(s), "
                    f"first at row {row} (t = {t[row]!r}); drop or repair those rows, "
                    "or pass nan_policy='interpolate'"
                )
            return values

        acc = block(ACC_COLS, ACC_UNITS[acc_unit])
        gyr = block(GYR_COLS, GYR_UNITS[gyr_unit])
        mag = block(MAG_COLS, 1.0) if has_mag else None
        dist = block(dist_cols, DIST_UNITS[dist_unit], allow_nan=True) if dist_cols else None
        if truth is None:
            truth = _truth_from_columns(df)
        meta.setdefault("units_declared", {"acc": acc_unit, "gyr": gyr_unit})
        if dist_cols:
            meta.setdefault("dist_columns", dist_cols)
        return cls(t=t, acc=acc, gyr=gyr, mag=mag, dist=dist, meta=meta, truth=truth, max_gap=max_gap)

    def to_dataframe(self) -> pd.DataFrame:
        """Canonical DataFrame (SI, FRD) with truth columns where known."""
        cols: dict[str, np.ndarray] = {"t": self.t}
        cols.update(zip(ACC_COLS, self.acc.T, strict=True))
        cols.update(zip(GYR_COLS, self.gyr.T, strict=True))
        if self.mag is not None:
            cols.update(zip(MAG_COLS, self.mag.T, strict=True))
        if self.dist is not None:
            names = self.meta.get("dist_columns") or [f"dist_{chr(97 + i)}" for i in range(self.dist.shape[1])]
            cols.update(zip(names, self.dist.T, strict=True))
        tr = self.truth
        if tr is not None:
            if tr.pos is not None:
                cols.update(zip(TRUTH_POS_COLS, tr.pos.T, strict=True))
            if tr.vel is not None:
                cols.update(zip(TRUTH_VEL_COLS, tr.vel.T, strict=True))
            if tr.quat is not None:
                cols.update(zip(TRUTH_QUAT_COLS, tr.quat.T, strict=True))
            if tr.stance is not None:
                cols["true_stance"] = tr.stance.astype(int)
            if tr.dist is not None:
                cols.update({f"true_dist_{chr(97 + i)}": d for i, d in enumerate(tr.dist.T)})
        return pd.DataFrame(cols)


def _truth_from_columns(df: pd.DataFrame) -> Truth | None:
    def get(cols: list[str]) -> np.ndarray | None:
        return df[cols].to_numpy(dtype=float) if all(c in df.columns for c in cols) else None

    pos, vel, quat = get(TRUTH_POS_COLS), get(TRUTH_VEL_COLS), get(TRUTH_QUAT_COLS)
    stance = df["true_stance"].to_numpy().astype(bool) if "true_stance" in df.columns else None
    dist_cols = sorted(c for c in df.columns if c.startswith("true_dist_"))
    dist = df[dist_cols].to_numpy(dtype=float) if dist_cols else None
    if pos is None and vel is None and quat is None and stance is None:
        return None
    return Truth(pos=pos, vel=vel, quat=quat, stance=stance, dist=dist)


def _check_choice(name: str, value: str, allowed) -> None:
    if value not in allowed:
        raise RecordingError(f"{name}={value!r} is not supported; use one of {list(allowed)}")


def validate_recording(rec: Recording) -> None:
    """Check shapes, time stamps, finiteness and plausible units of a recording.

    Raises
    ------
    RecordingError
        With a message naming the problem and how to fix it.
    """
    t, acc, gyr = rec.t, rec.acc, rec.gyr
    n = t.shape[0] if t.ndim == 1 else -1
    if t.ndim != 1:
        raise RecordingError(f"t must be one-dimensional, got shape {t.shape}")
    if n == 0:
        raise RecordingError("the recording is empty (0 samples)")
    for name, arr in (("acc", acc), ("gyr", gyr), ("mag", rec.mag)):
        if arr is not None and arr.shape != (n, 3):
            raise RecordingError(f"{name} must have shape ({n}, 3) to match t, got {arr.shape}")
    if rec.dist is not None and rec.dist.shape[0] != n:
        raise RecordingError(f"dist must have {n} rows to match t, got {rec.dist.shape[0]}")
    if n < 3:
        raise RecordingError(f"the recording has only {n} sample(s); at least {MIN_DURATION} s is needed")
    for name, arr in (("t", t), ("acc", acc), ("gyr", gyr), ("mag", rec.mag)):
        if arr is None:
            continue
        bad = ~np.isfinite(arr)
        if bad.any():
            idx = int(np.argwhere(bad)[0][0])
            raise RecordingError(
                f"{name} has {int(bad.sum())} non-finite value(s), first at sample {idx}; "
                "drop or repair those samples (Recording.from_dataframe(..., nan_policy='interpolate'))"
            )
    dt = np.diff(t)
    if np.any(dt < 0):
        k = int(np.argmax(dt < 0))
        raise RecordingError(
            f"time stamps go backwards at sample {k + 1} (t = {t[k]:.6f} s -> {t[k + 1]:.6f} s); "
            "sort the rows by time or fix the clock"
        )
    if np.any(dt == 0):
        k = int(np.argmax(dt == 0))
        raise RecordingError(
            f"{int(np.sum(dt == 0))} duplicate time stamp(s), first at sample {k + 1} (t = {t[k]:.6f} s); "
            "remove them, or pass duplicates='drop' to drop repeated rows (a warning gives the count)"
        )
    period = float(np.median(dt))
    max_gap = _max_gap(rec, period)
    if np.any(dt > max_gap):
        k = int(np.argmax(dt > max_gap))
        raise RecordingError(
            f"{int(np.sum(dt > max_gap))} gap(s) longer than {max_gap * 1e3:.1f} ms, the first "
            f"{dt[k] * 1e3:.1f} ms at t = {t[k]:.3f} s (median period {period * 1e3:.2f} ms); "
            "split the recording there, or raise max_gap if the filters may bridge it"
        )
    duration = t[-1] - t[0]
    if duration < MIN_DURATION:
        raise RecordingError(
            f"the recording is too short to align: {duration:.3f} s; footzoo needs at least "
            f"{MIN_DURATION} s, starting with the foot still"
        )
    _check_units(rec)


def _max_gap(rec: Recording, period: float) -> float:
    """Largest gap bridged (s): the recording's ``max_gap`` or the default."""
    return rec.max_gap if rec.max_gap is not None else max(DEFAULT_MAX_GAP, DEFAULT_MAX_GAP_PERIODS * period)


def _report_gaps(rec: Recording) -> None:
    """Warn about the short gaps that are bridged and list them in ``meta["diagnostics"]["gaps"]``.

    A gap is an interval longer than ``GAP_PERIODS`` median periods. The
    samples are kept as they are: the filters integrate each sample over its
    own interval (the sensor's last reading held across the gap), which adds
    no invented data; interpolating would invent a motion the sensor did not
    measure and hide the gap from the detectors' windows. A gap in a stance
    costs nothing; a gap in a swing loses the motion in it, which neither
    holding nor interpolating recovers (on a simulated 30 m loop, 1–3 lost
    samples mid-swing at 100 Hz cost 1–40 cm of loop closure either way).
    """
    dt = np.diff(rec.t)
    period = float(np.median(dt))
    k = np.flatnonzero(dt > GAP_PERIODS * period)
    if k.size == 0:
        return
    longest = int(k[np.argmax(dt[k])])
    diag = rec.meta.setdefault("diagnostics", {})
    diag["gaps"] = {
        "count": int(k.size),
        "start_s": rec.t[k].tolist(),
        "duration_s": dt[k].tolist(),
        "longest_s": float(dt[longest]),
        "max_gap_s": float(_max_gap(rec, period)),
    }
    warnings.warn(
        FootzooWarning(
            f"{rec.name}: bridged {k.size} gap(s) in the time stamps (intervals over {GAP_PERIODS:g} median periods "
            f"of {period * 1e3:.2f} ms), the longest {dt[longest] * 1e3:.1f} ms at t = {rec.t[longest]:.3f} s; "
            "the filters integrate over each sample's real interval. The list is in meta['diagnostics']['gaps']; "
            "pass a smaller max_gap to refuse them"
        ),
        stacklevel=4,
    )


def _check_units(rec: Recording) -> None:
    acc_norm = np.linalg.norm(rec.acc, axis=1)
    gyr_norm = np.linalg.norm(rec.gyr, axis=1)
    # the stillest tenth of the samples tells the unit of the accelerometer
    still = gyr_norm <= np.quantile(gyr_norm, 0.1)
    rest = float(np.median(acc_norm[still]))
    if 0.5 < rest < 2.0:
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.3f}: this looks like g, not m/s²; "
            "declare acc_unit: g (Recording.from_dataframe(..., acc_unit='g'))"
        )
    if 500.0 < rest < 2000.0:
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.1f}: this looks like mg; declare acc_unit: mg"
        )
    if not 0.5 * GRAVITY < rest < 1.5 * GRAVITY:
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.3f} m/s², far from g = {GRAVITY}; "
            "check the unit (acc_unit) and the sensor's calibration"
        )
    peak = float(gyr_norm.max())
    if peak > GYRO_DEG_S_SUSPICION:
        raise RecordingError(
            f"gyroscope peak is {peak:.1f}, too fast for rad/s (a foot turns below ~20 rad/s): "
            "this looks like deg/s; declare gyr_unit: deg/s"
        )


@dataclass
class Result:
    """What a pipeline produced for one recording.

    Attributes
    ----------
    samples : DataFrame
        Per sample: ``t`` (s), ``qw..qz`` (body -> NED), ``roll, pitch, yaw``
        (rad, Z-Y-X), ``pos_n, pos_e, pos_d`` (m), ``vel_n, vel_e, vel_d`` (m/s),
        ``acc_n, acc_e, acc_d`` (motion acceleration, gravity removed, m/s²),
        ``stance`` (bool).
    steps : DataFrame
        Per step (one swing between two stances): ``start``, ``end`` (s),
        ``duration`` (s), ``stride_length`` (m, horizontal), ``heading`` (rad),
        ``start_n, start_e, end_n, end_e`` (m).
    config : dict
        The resolved configuration (every parameter, defaults filled in).
    versions : dict
        Versions of footzoo and its numerical dependencies.
    recording : dict
        The recording's metadata.
    diagnostics : dict
        Plug-in statistics (e.g. detector test statistic), arrays by name.
    """

    samples: pd.DataFrame
    steps: pd.DataFrame
    config: dict[str, Any]
    versions: dict[str, str]
    recording: dict[str, Any] = field(default_factory=dict)
    diagnostics: dict[str, Any] = field(default_factory=dict)

    @property
    def pos(self) -> np.ndarray:
        """Position (N, 3) in NED (m)."""
        return self.samples[["pos_n", "pos_e", "pos_d"]].to_numpy()

    @property
    def vel(self) -> np.ndarray:
        """Velocity (N, 3) in NED (m/s)."""
        return self.samples[["vel_n", "vel_e", "vel_d"]].to_numpy()

    @property
    def quat(self) -> np.ndarray:
        """Attitude (N, 4), body -> NED, scalar first."""
        return self.samples[["qw", "qx", "qy", "qz"]].to_numpy()

    @property
    def stance(self) -> np.ndarray:
        """Stance flag (N,), bool."""
        return self.samples["stance"].to_numpy(dtype=bool)
