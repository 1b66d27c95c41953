"""Data model: :class:`Recording` and :class:`Truth` (a pipeline's output is :class:`footzoo.evaluation.result.Result`).

A :class:`Recording` holds signals already converted to footzoo's conventions
(FRD body frame, SI units, see :mod:`footzoo.core.conventions`). It is validated on
construction; every problem raises :class:`~footzoo.core.errors.RecordingError`
with a message that names the column and the fix.
"""

from __future__ import annotations

import warnings
from dataclasses import InitVar, dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from .checks import check_positive, gap_limit
from .conventions import ACC_UNITS, DIST_UNITS, GRAVITY, GYR_UNITS, TIME_UNITS
from .errors import FootzooWarning, RecordingError, shown, user_stacklevel
from .norms import row_norms, unit_error
from .sanity import check_impossible, scan
from .usage import fix

ACC_COLS = ["acc_x", "acc_y", "acc_z"]
GYR_COLS = ["gyr_x", "gyr_y", "gyr_z"]
MAG_COLS = ["mag_x", "mag_y", "mag_z"]
TRUTH_POS_COLS = ["true_pos_n", "true_pos_e", "true_pos_d"]
TRUTH_VEL_COLS = ["true_vel_n", "true_vel_e", "true_vel_d"]
TRUTH_QUAT_COLS = ["true_qw", "true_qx", "true_qy", "true_qz"]

#: The name of a recording given none (``footzoo.load`` names it after its file instead).
DEFAULT_NAME = "recording"
#: Shortest recording footzoo accepts (s): the initial alignment needs still samples.
MIN_DURATION = 1.0
#: A bridged gap longer than this (s) is named in the warning: in a swing it loses motion.
LOSSY_GAP = 0.1
#: Largest resolution of the time stamps' float type, as a fraction of the median period (a float32 clock far from 0
#: rounds them).
MAX_TIME_ROUNDING = 0.01
#: Plausible median sampling rate of a foot-mounted IMU (Hz); outside it the time stamps are not in seconds.
RATE_RANGE = (10.0, 20_000.0)
#: An interval longer than this many median periods is a gap (at least one sample missing).
GAP_PERIODS = 1.5
#: Gyro peak (in the declared unit rad/s) above which the data must be in deg/s.
GYRO_DEG_S_SUSPICION = 50.0
#: Largest ``| |q|² − 1 |`` of a reference quaternion read from a file (4-decimal exports stay well inside).
TRUTH_QUAT_TOLERANCE = 0.01


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
        Reference strides, one row per stride, columns as in
        :func:`footzoo.analysis.strides.segment_steps` where known: ``start_s``,
        ``to_s``, ``end_s`` (IC, toe-off, next IC; s), ``stride_length_m``,
        ``heading_rad``, ``fpa_rad``, ``turn`` (bool). Simulator files written
        before the unit names (``swing_start``/``swing_end``, ``stride_length``,
        ``heading``, ``fpa``) are read too (:func:`footzoo.evaluation.metrics.reference_steps`).
    closed_loop : bool
        The walk ends where it started (loop-closure metrics apply).
    dist : (N, k) ndarray or None
        True range of each distance sensor (m), NaN where it has no sample.
    stride_count : int or None
        Strides counted by hand (PyShoe's trials, Köroğlu's ``numberOfStrides``).
    footprints : (K, 2) ndarray or None
        Horizontal position of every footprint (m), first one included, in the
        dataset's own floor axes (compare after a 2-D rigid alignment, reflection
        allowed), e.g. Köroğlu's ground control points ``GCP_meters``.
    stride_positions : DataFrame or None
        Per-stride trajectories (e.g. gaitmap's ``position_sample.csv``):
        ``stride`` (row of ``steps``), ``t_s`` (s), ``pos_x_m``, ``pos_y_m``,
        ``pos_up_m`` (m, zeroed at the stride's start, right-handed with z up;
        compare after a rotation about the vertical).
    source : str
        What the reference is (e.g. "VICON", "motion capture", "simulator").
    """

    pos: np.ndarray | None = None
    vel: np.ndarray | None = None
    quat: np.ndarray | None = None
    stance: np.ndarray | None = None
    steps: pd.DataFrame | None = None
    closed_loop: bool = False
    dist: np.ndarray | None = None
    stride_count: int | None = None
    footprints: np.ndarray | None = None
    stride_positions: pd.DataFrame | None = None
    source: str = ""

    def __repr__(self) -> str:
        have = [k for k in ("pos", "vel", "quat", "stance", "steps", "dist", "footprints", "stride_positions")
                if getattr(self, k) is not None]
        extra = f", stride_count={self.stride_count}" if self.stride_count is not None else ""
        src = f"{self.source!r}, " if self.source else ""
        return f"Truth({src}{', '.join(have) or 'nothing'}{extra}, closed_loop={self.closed_loop})"


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
        ``max(DEFAULT_MAX_GAP, 5 median periods)`` = 0.25 s above 20 Hz. Shorter
        gaps are kept as they are (no samples invented: every filter integrates
        over each sample's own interval, which is what the sensor measured) and
        reported with a :class:`~footzoo.core.errors.FootzooWarning` and in
        ``meta["diagnostics"]["gaps"]``; longer gaps are refused.
    warn : bool
        Warn about the bridged gaps and the sensor findings (saturation, glitches, dropouts); off,
        they are only listed in ``meta`` (for samples that were checked and warned about already, e.g.
        the kept samples of a :class:`~footzoo.Stream`). Errors are raised either way.
    """

    t: np.ndarray
    acc: np.ndarray
    gyr: np.ndarray
    mag: np.ndarray | None = None
    dist: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    truth: Truth | None = None
    max_gap: float | None = None
    warn: InitVar[bool] = True

    def __post_init__(self, warn: bool = True) -> None:
        _check_time_precision(self.t)
        self.t = _floats("t", self.t)
        self.acc = _floats("acc", self.acc)
        self.gyr = _floats("gyr", self.gyr)
        if self.mag is not None:
            self.mag = _floats("mag", self.mag)
        if self.dist is not None:
            self.dist = _floats("dist", self.dist)
            if self.dist.ndim == 1:
                self.dist = self.dist[:, None]
        if not isinstance(self.meta, dict):
            raise RecordingError(f"meta must be a dict, got {type(self.meta).__name__}")
        if self.truth is not None and not isinstance(self.truth, Truth):
            raise RecordingError(f"truth must be a footzoo Truth, got {type(self.truth).__name__}")
        validate_recording(self)
        self.meta = dict(self.meta)
        _report_gaps(self, warn)
        self.meta.setdefault("name", DEFAULT_NAME)
        self.meta["rate"] = float(1.0 / np.median(np.diff(self.t)))
        findings = scan(self.t, self.acc, self.gyr, str(self.meta["name"]), warn=warn)
        if findings:
            self.meta["sanity"] = findings

    def __repr__(self) -> str:
        channels = ["acc", "gyr"] + [k for k in ("mag", "dist") if getattr(self, k) is not None]
        truth = "" if self.truth is None else f", truth={self.truth!r}"
        return (f"Recording({self.name!r}, n={self.n}, rate={self.rate:.1f} Hz, "
                f"duration={self.t[-1] - self.t[0]:.2f} s, channels={channels}{truth})")

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
        return str(self.meta.get("name", DEFAULT_NAME))

    @classmethod
    def from_dataframe(
        cls,
        df: pd.DataFrame,
        *,
        acc_unit: str = "m/s^2",
        gyr_unit: str = "rad/s",
        dist_unit: str = "m",
        time_col: str = "t",
        rate: float | None = None,
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
        time_col : str
            The time column (s).
        rate : float, optional
            Sampling rate (Hz) of a table with no time column: ``t = row / rate`` (a logger that writes no time
            stamps). Refused when the table has the time column too.
        duplicates : {"error", "drop"}
            What to do with rows whose time stamp repeats the previous one.
            ``"drop"`` keeps the first and warns with the count.
        nan_policy : {"error", "interpolate"}
            What to do with non-finite IMU values (``dist`` may always be NaN).
        max_gap : float, optional
            Largest gap bridged (s); default 0.25 s (or 5 median periods if longer).
        """
        if not isinstance(df, pd.DataFrame):
            raise RecordingError(f"from_dataframe expects a pandas DataFrame, got {type(df).__name__}")
        if isinstance(df.columns, pd.MultiIndex):
            raise RecordingError(f"from_dataframe: the table has {df.columns.nlevels} levels of column names (e.g. "
                                 f"{df.columns[0]!r}); give one level named t, acc_x, ..., gyr_z: flatten them first, "
                                 "e.g. df.columns = ['_'.join(map(str, c)).strip('_') for c in df.columns]")
        _check_choice("acc_unit", acc_unit, ACC_UNITS)
        _check_choice("gyr_unit", gyr_unit, GYR_UNITS)
        _check_choice("dist_unit", dist_unit, DIST_UNITS)
        _check_choice("duplicates", duplicates, ("error", "drop"))
        _check_choice("nan_policy", nan_policy, ("error", "interpolate"))
        if len(df) == 0:
            raise RecordingError("the recording is empty (0 rows); check the file and its header")
        if rate is not None:
            rate = check_positive("rate", rate, unit="Hz")
            if time_col in df.columns:
                raise RecordingError(f"the table has a time column {time_col!r} and rate={rate:g} Hz is given too: "
                                     "give rate only for a table with no time column (t = row / rate)")
            df = df.assign(**{time_col: np.arange(len(df)) / rate})
        required = [time_col, *ACC_COLS, *GYR_COLS]
        missing = [c for c in required if c not in df.columns]
        if missing:
            raise RecordingError(
                f"missing column(s) {missing}; a recording needs {required} "
                f"(found {list(df.columns)[:12]}). Rename the columns or use a reader from footzoo.io"
                + (f"; a table with no time column: Recording.from_dataframe(..., rate=HZ) makes {time_col!r} = row / "
                   "rate" if time_col in missing else "")
            )
        has_mag = all(c in df.columns for c in MAG_COLS)
        partial_mag = [c for c in MAG_COLS if c in df.columns]
        if partial_mag and not has_mag:
            raise RecordingError(f"magnetometer columns incomplete: found {partial_mag}, need {MAG_COLS}")
        dist_cols = sorted(c for c in df.columns if isinstance(c, str) and c.startswith("dist_"))

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
                    FootzooWarning, stacklevel=user_stacklevel(),
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
                if bad[:, col].all():
                    raise RecordingError(
                        f"column {cols[col]!r} holds no numbers (first value {shown(df[cols[col]].iloc[0])}); "
                        f"check the "
                        "file's delimiter and decimal separator (footzoo reads ',' between values and '.' in numbers)"
                    )
                empty = df.iloc[row].isna().to_numpy()
                filled = int(np.argmax(empty)) if empty.any() else len(empty)
                if filled < len(empty) - 1 and empty[filled:].all():  # the row stops short of its columns
                    raise RecordingError(
                        f"row {row} (t = {float(t[row]):.6f} s) has values in only its first {filled} of "
                        f"{len(empty)} columns: the file is cut short there, or the row is damaged; remove or "
                        "repair that row (a file still being written? copy it once it is complete)")
                text = df[cols[col]].iloc[row]
                if isinstance(text, str) and text.strip():  # text where a number belongs, not a NaN the file holds
                    cells = [str(v).strip() for v in df.iloc[row]]
                    if cells[:len(df.columns)] == [str(c).strip() for c in df.columns]:
                        raise RecordingError(
                            f"row {row} repeats the header line (two files joined into one?); remove that line, or "
                            "split the file there into two recordings")
                    raise RecordingError(
                        f"column {cols[col]!r} holds the text {text[:40]!r} at row {row} (t = {float(t[row]):.6f} s), "
                        "not a number; repair or drop that row, or interpolate it: "
                        + option_fix("nan_policy", "interpolate"))
                raise RecordingError(
                    f"column {cols[col]!r} has {int(bad[:, col].sum())} non-finite value(s), "
                    f"first at row {row} (t = {float(t[row]):.6f} s); drop or repair those rows, "
                    f"or interpolate them: {option_fix('nan_policy', 'interpolate')}"
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


def writable_array(value: Any, dtype: Any = float) -> np.ndarray:
    """``value`` as a C-contiguous, writable array of ``dtype`` (copied only if it must be).

    numba types a read-only array apart from a writable one: kernels handed read-only inputs (pandas'
    copy-on-write views, a study's frozen recordings) would compile a second time instead of loading
    the code already compiled (or shipped) for writable ones.
    """
    array = np.ascontiguousarray(value, dtype=dtype)
    return array if array.flags.writeable else array.copy()


def _check_time_precision(t: Any) -> None:
    """A RecordingError when ``t`` comes in a float type too coarse for its values: float32 resolves 7.8 ms at
    10⁵ s (a day's clock), which rounds every time stamp of a 100 Hz recording to a step of 0 or 7.8 ms."""
    if not isinstance(t, np.ndarray) or t.dtype.kind != "f" or t.dtype.itemsize >= 8 or t.ndim != 1 or len(t) < 3:
        return
    finite = t[np.isfinite(t)]
    if len(finite) < 3:
        return  # the checks of the values say what is wrong
    step = float(np.spacing(np.max(np.abs(finite))))  # the resolution of the type where the values are largest
    period = float(np.median(np.abs(np.diff(finite.astype(np.float64)))))
    if step > MAX_TIME_ROUNDING * period:
        share = "more than" if period == 0 else f"{step / period:.0%} of"
        raise RecordingError(
            f"t is {t.dtype} (a {8 * t.dtype.itemsize}-bit float): at t = {np.max(np.abs(finite)):.6g} s it resolves "
            f"only {step * 1e3:.3g} ms, {share} the sampling period "
            f"({period * 1e3:.3g} ms): the time stamps were rounded. Keep them as float64 (np.float64), or subtract "
            "the start time before converting them to a shorter type"
        )


def _floats(name: str, value: Any) -> np.ndarray:
    """``value`` as a contiguous, writable float array, or a RecordingError naming the input.

    Writable always (a copy of a read-only input, such as pandas' copy-on-write views): the
    compiled kernels then see one array type whatever the reader, and compile once.
    """
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):  # ragged: the conversion below says so
        kind = ""
    if kind == "c":  # float() would drop the imaginary parts without a word
        raise RecordingError(f"{name} holds complex numbers; footzoo needs real samples (a float array): pass "
                             f"{name}.real if the imaginary parts are zero, else check how the array was made")
    try:
        return writable_array(value)
    except (TypeError, ValueError) as err:
        raise RecordingError(
            f"{name} must be numbers (an array of floats), got {type(value).__name__}: {err}"
        ) from None


def _truth_from_columns(df: pd.DataFrame) -> Truth | None:
    def get(cols: list[str]) -> np.ndarray | None:
        found = [c for c in cols if c in df.columns]
        if found and len(found) < len(cols):  # a reference that lost a column would be dropped without a word
            raise RecordingError(f"reference columns incomplete: found {found}, need all of {cols}; add the missing "
                                 "one(s) or drop these")
        return df[cols].to_numpy(dtype=float) if found else None

    pos, vel, quat = get(TRUTH_POS_COLS), get(TRUTH_VEL_COLS), get(TRUTH_QUAT_COLS)
    if quat is not None:  # rows without a reference (NaN) are allowed; a reference that is no rotation is not
        known = np.isfinite(quat).all(axis=1)
        worst, k = unit_error(quat[known])
        if worst > TRUTH_QUAT_TOLERANCE:
            row = int(np.flatnonzero(known)[k])
            raise RecordingError(
                f"columns {TRUTH_QUAT_COLS}: row {row} holds {np.round(quat[row], 4).tolist()}, of length "
                f"{float(np.linalg.norm(quat[row])):.4g}, not a unit quaternion (the reference attitude body -> NED, "
                "scalar first); fix the reference (normalise it, or leave a row without one empty) or drop these "
                "columns")
    stance = None
    if "true_stance" in df.columns:
        flags = pd.to_numeric(df["true_stance"], errors="coerce").to_numpy(dtype=float)
        if not np.isin(flags, (0.0, 1.0)).all():
            k = int(np.argmax(~np.isin(flags, (0.0, 1.0))))
            value = df["true_stance"].iloc[k]
            value = value.item() if isinstance(value, np.generic) else value
            raise RecordingError(
                f"column 'true_stance' must hold 0 or 1 in every row, got {value!r} at row {k}; "
                "fix the column or drop it"
            )
        stance = flags.astype(bool)
    dist_cols = sorted(c for c in df.columns if c.startswith("true_dist_"))
    dist = df[dist_cols].to_numpy(dtype=float) if dist_cols else None
    if pos is None and vel is None and quat is None and stance is None and dist is None:
        return None
    return Truth(pos=pos, vel=vel, quat=quat, stance=stance, dist=dist)


def _check_choice(name: str, value: str, allowed) -> None:
    if not isinstance(value, str) or value not in allowed:
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
            flipped = "; it looks transposed: pass " + name + ".T" if arr.shape == (3, n) else ""
            raise RecordingError(f"{name} must have shape ({n}, 3) to match t, got {arr.shape}{flipped}")
    if rec.dist is not None and rec.dist.shape[0] != n:
        raise RecordingError(f"dist must have {n} rows to match t, got {rec.dist.shape[0]}")
    if n < 3:
        raise RecordingError(f"the recording has only {n} sample(s); at least {MIN_DURATION} s is needed")
    if rec.truth is not None:
        _check_truth(rec.truth, n)
    if rec.max_gap is not None:
        rec.max_gap = check_positive("max_gap", rec.max_gap, unit="s")
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
            "remove them, or drop the repeated rows (a warning gives the count): " + option_fix("duplicates", "drop")
        )
    period = float(np.median(dt))
    if not RATE_RANGE[0] <= 1.0 / period <= RATE_RANGE[1]:
        raise RecordingError(
            f"the median sampling rate is {1.0 / period:.6g} Hz (period {period:.6g}), outside the plausible "
            f"{RATE_RANGE[0]:g}-{RATE_RANGE[1]:g} Hz of a foot-mounted IMU: {_time_unit_hint(period, t[-1] - t[0])}"
        )
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
        longer = duration * TIME_UNITS["min"] >= MIN_DURATION and RATE_RANGE[0] <= 1.0 / (period * 60.0)
        raise RecordingError(
            f"the recording is too short to align: {duration:.3f} s at {1.0 / period:.6g} Hz; footzoo needs at least "
            f"{MIN_DURATION} s, starting with the foot still"
            + (f"; or {_time_unit_hint(period, duration)}" if longer else "")
        )
    _check_units(rec)
    check_impossible(t, acc, gyr)


def _time_unit_hint(period: float, duration: float) -> str:
    """The units of ``t`` under which a median ``period`` and a ``duration`` (both read as s) are a plausible IMU's,
    with the fix (the time column's unit, or the factor to seconds)."""
    fits = [(unit, scale) for unit, scale in TIME_UNITS.items() if unit != "µs" and scale != 1.0
            and RATE_RANGE[0] <= 1.0 / (period * scale) <= RATE_RANGE[1] and duration * scale >= MIN_DURATION]
    counter = ("if t counts samples, declare the rate instead (a sidecar's time: {rate: HZ}, or the reader's rate "
               "option)")
    if not fits:
        return f"footzoo needs t in seconds; check the time column: {counter}"
    said = "; ".join(f"in {unit}, it is {1.0 / (period * scale):.4g} Hz over {duration * scale:.4g} s "
                     f"({'multiply' if scale > 1 else 'divide'} t by {scale if scale > 1 else 1.0 / scale:g})"
                     for unit, scale in fits)
    return (f"are the time stamps in {' or '.join(unit for unit, _ in fits)}? footzoo needs t in seconds: {said}; "
            f"a sidecar declares it as time: {{column: NAME, unit: {fits[0][0]}}}"
            + (f"; {counter}" if abs(period - 1.0) < 1e-9 else ""))


def _check_truth(truth: Truth, n: int) -> None:
    """Ground truth must cover the IMU samples one to one (checked at load, not after a run)."""
    for name, arr, width in (("pos", truth.pos, 3), ("vel", truth.vel, 3), ("quat", truth.quat, 4),
                             ("stance", truth.stance, None), ("dist", truth.dist, None)):
        if arr is None:
            continue
        shape = np.shape(arr)
        if len(shape) == 0 or shape[0] != n:
            rows = shape[0] if len(shape) else 0
            raise RecordingError(
                f"ground truth {name} has {rows} rows but the IMU has {n} samples: truth must have one row per "
                f"IMU sample. {'Shorter: the reference stops early' if rows < n else 'Longer'}; trim both to the "
                "common time span, or drop the truth"
            )
        if width is not None and (len(shape) != 2 or shape[1] != width):
            raise RecordingError(f"ground truth {name} must have shape ({n}, {width}), got {shape}")
        if width is not None:
            bad = ~np.isfinite(np.asarray(arr, dtype=float)).all(axis=1)
            if bad.any():
                k = int(np.argmax(bad))
                where = (f"the reference stops at sample {k} while the IMU has {n} samples" if bad[k:].all()
                         else f"{int(bad.sum())} row(s) are not finite, the first at sample {k}")
                raise RecordingError(
                    f"ground truth {name}: {where}; truth must cover every IMU sample: trim the recording to the "
                    "reference's time span, or drop the truth columns"
                )


def _max_gap(rec: Recording, period: float) -> float:
    """Largest gap bridged (s): the recording's ``max_gap`` or the default."""
    return gap_limit(period, rec.max_gap)


def _report_gaps(rec: Recording, warn: bool = True) -> None:
    """Warn about the short gaps that are bridged (with ``warn``) and list them in ``meta["diagnostics"]["gaps"]``.

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
    if warn:
        warn_gaps(rec)


def warn_gaps(rec: Recording, refuse: str | None = None) -> None:
    """The warning of the bridged gaps listed in ``rec.meta["diagnostics"]["gaps"]`` (none: no warning).

    ``refuse``: how to refuse them where the samples came from (default: the loader's ``max_gap`` option).
    """
    gaps = rec.meta.get("diagnostics", {}).get("gaps")
    if not gaps:
        return
    period = float(np.median(np.diff(rec.t)))
    durations = np.asarray(gaps["duration_s"])
    longest = int(np.argmax(durations))
    long_gaps = int(np.sum(durations > LOSSY_GAP))
    lossy = (f" {long_gaps} of them longer than {LOSSY_GAP:g} s: one in a swing loses part of the swing's motion, so "
             "check the strides around them;" if long_gaps else "")
    warnings.warn(
        FootzooWarning(
            f"{rec.name}: bridged {gaps['count']} gap(s) in the time stamps (intervals over {GAP_PERIODS:g} median "
            f"periods of {period * 1e3:.2f} ms), the longest {durations[longest] * 1e3:.1f} ms at "
            f"t = {gaps['start_s'][longest]:.3f} s;{lossy} the filters integrate over each sample's real interval. "
            "The list is in meta['diagnostics']['gaps']; to refuse them, a smaller max_gap: "
            f"{refuse or option_fix('max_gap', 'SECONDS', number=True)}"
        ),
        stacklevel=user_stacklevel(),
    )


def option_fix(key: str, value: str, number: bool = False) -> str:
    """How to pass a reader option, in Python and on the command line, or in a study (for the messages of the data's
    checks; :mod:`footzoo.core.usage`)."""
    return fix(python=f"footzoo.load(path, {key}={value if number else repr(value)}), on the command line "
                      f"--option {key}={value}", study=_entry_fix(key, value))


def unit_fix(key: str, value: str) -> str:
    """How to declare a unit, in each place footzoo reads one (every reader takes ``acc_unit`` and ``gyr_unit``)."""
    return fix(python=f"footzoo.load(path, {key}='{value}'), on the command line --option {key}={value}, "
                      f"Recording.from_dataframe(..., {key}='{value}')", study=_entry_fix(key, value))


def _entry_fix(key: str, value: str) -> str:
    """A reader option in a study: a key of the recording's entry."""
    return f"the recording entry's {key}: {value} key in the study (recordings: [{{path: ..., {key}: {value}}}])"


def _check_units(rec: Recording) -> None:
    check_units(rec.acc, rec.gyr)


#: A foot's specific force peaks at a few g (up to 16 g at a running heel strike): the 99th percentile of ‖f‖ over its
#: reading at rest stays below this in any unit; above it, a unit error (which scales both alike) does not explain the
#: reading at rest.
REST_TO_PEAK_MAX = 50.0


def check_units(acc: np.ndarray, gyr: np.ndarray) -> None:
    """Refuse an accelerometer or a gyroscope in another unit than the one declared (a RecordingError with the fix).

    The accelerometer at rest reads g: in g or mg declared as m/s² it reads about 1 or 1000; in m/s²
    declared as g or mg, about 96 or 0.096; in g declared as mg or the reverse, 0.0098 or 9807. Each
    is named with the declaration that reads g. A gyroscope in deg/s declared as rad/s turns faster
    than any foot (99th percentile above :data:`GYRO_DEG_S_SUSPICION`). The reverse (rad/s declared as
    deg/s: a foot that moves but does not turn) needs motion to be seen, and is named by the gait
    scan (:mod:`footzoo.core.plausibility`). Run on every recording and, live, on a stream's first
    samples (:class:`footzoo.Stream`).
    """
    acc_norm = row_norms(acc)
    gyr_norm = row_norms(gyr)
    # the stillest tenth of the samples tells the unit of the accelerometer
    still = gyr_norm <= np.quantile(gyr_norm, 0.1)
    rest = float(np.median(acc_norm[still]))
    if 0.5 < rest < 2.0:
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.3f}: this looks like g, not m/s²; "
            f"declare acc_unit: g ({unit_fix('acc_unit', 'g')})"
        )
    if 500.0 < rest < 2000.0:
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.1f}: this looks like mg; declare acc_unit: mg "
            f"({unit_fix('acc_unit', 'mg')})"
        )
    if not 0.5 * GRAVITY < rest < 1.5 * GRAVITY:
        peak = float(np.quantile(acc_norm, 0.99))
        if rest > 0 and peak / rest > REST_TO_PEAK_MAX:  # motion in a sane unit, rest far below g: not a unit error
            spans = ", ".join(f"acc_{a} {float(r):.3g}" for a, r in zip("xyz", np.ptp(acc, axis=0), strict=True))
            raise RecordingError(
                f"accelerometer magnitude at rest is {rest:.3g} m/s² as declared, far from g, but {peak:.3g} m/s² in "
                f"motion (99th percentile): a unit error scales both alike, so no unit explains it. An axis may be "
                f"dead or unconnected, or a column may not be the accelerometer's (ranges: {spans}); check the "
                "sensor and which columns are read as acc_x, acc_y, acc_z"
            )
        for true, declared in (("m/s^2", "g"), ("m/s^2", "mg"), ("g", "mg"), ("mg", "g")):
            read = GRAVITY * ACC_UNITS[declared] / ACC_UNITS[true]  # what g in `true` reads as `declared`, in m/s²
            if abs(np.log(rest / read)) < np.log(1.3):
                raise RecordingError(
                    f"accelerometer magnitude at rest is {rest:.4g} m/s² as declared, {rest / GRAVITY:.4g} g: this "
                    f"is what g reads in {true} declared as {declared}; declare acc_unit: {true} "
                    f"({unit_fix('acc_unit', true)})"
                )
        raise RecordingError(
            f"accelerometer magnitude at rest is {rest:.3f} m/s², far from g = {GRAVITY}; "
            "check the unit (acc_unit) and the sensor's calibration"
        )
    # 99th percentile, not the maximum: a few corrupt samples are reported as such (sanity.check_impossible)
    peak = float(np.quantile(gyr_norm, 0.99))
    if peak > GYRO_DEG_S_SUSPICION:
        raise RecordingError(
            f"gyroscope 99th-percentile rate is {peak:.1f}, too fast for rad/s (a foot turns below ~20 rad/s): "
            f"this looks like deg/s; declare gyr_unit: deg/s ({unit_fix('gyr_unit', 'deg/s')})"
        )
