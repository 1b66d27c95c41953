"""Typed, bounded validation of parameters and live samples (bottom layer: footzoo.core.errors and numpy only).

Every check returns the value converted to its Python type, or raises a footzoo
error whose message names the input, the problem and the fix. Plug-ins and the
settings blocks of a config (:class:`Settings`) declare their parameters
(:mod:`footzoo.core.params`); :func:`check_positive`, :func:`check_range`,
:func:`check_bool` and :func:`check_vector` are the same checks for other values
(and for plug-ins written before declarations); :func:`validate_sample` guards
``Stream.push``.

Physical bounds (SI units) shared by the recording checks and the stream:

* :data:`GRAVITY_RANGE` — 9.7 to 9.9 m/s²: Earth's surface gravity lies between
  about 9.76 m/s² (high mountains near the equator) and 9.834 m/s² (poles), so a
  value outside this range is a unit or typing error (``98.1``, ``1.0``).
* :data:`ACC_MAX` — 2000 m/s² (≈ 204 g): above the full range of any body-worn
  IMU (high-g parts end at ±200 g); a larger value is a corrupt sample.
* :data:`GYR_MAX` — 50 rad/s (≈ 2900 °/s): above any foot's angular rate
  (≲ 20 rad/s when sprinting) and the ±2000 °/s range of common gyroscopes.
"""

from __future__ import annotations

import math
from dataclasses import asdict, fields
from typing import Any, ClassVar

import numpy as np

from .errors import ConfigError, RecordingError, did_you_mean, shown
from .params import Boolean, Declared, Interval, Param, Real, Vector, declared

#: Plausible gravity magnitude g on the Earth's surface (m/s²), inclusive bounds.
GRAVITY_RANGE = (9.7, 9.9)
#: Largest plausible |specific force| component of a body-worn IMU (m/s²).
ACC_MAX = 2000.0
#: Largest plausible |angular rate| component (rad/s).
GYR_MAX = 50.0
#: Default largest gap between samples that is bridged (s), in a recording and in a live stream; longer gaps are
#: refused. A logger that drops a tenth of a second now and then (110-120 ms gaps in annotated 100 Hz gait
#: recordings) is read with a warning; a gap this long in a swing loses the swing's motion, which the warning says.
DEFAULT_MAX_GAP = 0.25
#: ... or this many median sample periods, when that is longer (slow loggers).
DEFAULT_MAX_GAP_PERIODS = 5.0


def gap_limit(period: float, max_gap: float | None = None) -> float:
    """Largest gap bridged (s): ``max_gap`` when given, else ``max(DEFAULT_MAX_GAP, 5 periods)``.

    Parameters
    ----------
    period : float
        Median (or nominal) sample period (s).
    max_gap : float, optional
        The user's limit (s).
    """
    return max_gap if max_gap is not None else max(DEFAULT_MAX_GAP, DEFAULT_MAX_GAP_PERIODS * period)


def check_positive(name: str, value: Any, allow_zero: bool = False, unit: str = "") -> float:
    """A finite number ``> 0`` (or ``>= 0`` with ``allow_zero``), as float.

    Raises
    ------
    ConfigError
        For a non-number (strings, booleans, None), NaN, ±inf or a value out of bounds.
    """
    return Real(unit, "[0, inf)" if allow_zero else "(0, inf)").validate(name, value)


def check_range(
    name: str, value: Any, lo: float, hi: float, unit: str = "", lo_open: bool = False, hi_open: bool = False
) -> float:
    """A finite number in ``[lo, hi]`` (ends open with ``lo_open`` / ``hi_open``), as float.

    A plug-in declares its parameters instead (:mod:`footzoo.core.params`); this is the same check
    for a value that is not a declared parameter.

    Parameters
    ----------
    name : str
        The parameter's name, as the user wrote it (e.g. ``init.duration``).
    value : any
        The value to check.
    lo, hi : float
        Bounds, in ``unit``.
    unit : str
        Unit of the value, shown in the message (e.g. ``"m/s^2"``).
    """
    return Real(unit, Interval(float(lo), float(hi), lo_open, hi_open)).validate(name, value)


def check_bool(name: str, value: Any) -> bool:
    """A real boolean; strings such as ``'no'`` or ``'false'`` (truthy in Python) are rejected."""
    return Boolean().validate(name, value)


def check_vector(name: str, value: Any, size: int = 3, nonzero: bool = False, unit: str = "") -> list[float]:
    """A list of ``size`` finite numbers (and not all zero with ``nonzero``)."""
    return Vector(size, unit, nonzero=nonzero).validate(name, value)


def _sample_vector(name: str, value: Any, t: float, bound: float | None, unit: str) -> np.ndarray:
    if value is None:  # a channel that dropped out: said so, not as a shape
        raise RecordingError(f"{name} is missing (None) at t = {shown(t)}: "
                             f"every sample needs {name} ({unit}, 3 numbers); "
                             "a sensor that dropped out cannot be bridged: repair the gap or end the stream there")
    raw = value if isinstance(value, np.ndarray) else None
    if raw is None and isinstance(value, (list, tuple)):
        raw = np.asarray(value, dtype=object)
    if raw is not None and (np.iscomplexobj(raw) or raw.dtype == bool
                            or (raw.dtype == object and any(isinstance(v, (bool, complex, np.bool_, np.complexfloating))
                                                            for v in raw.ravel().tolist()))):
        raise RecordingError(f"{name} at t = {shown(t)} must be 3 real numbers ({unit}), got {value!r} "
                             "(booleans or complex numbers are not samples)")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise RecordingError(f"{name} at t = {shown(t)} must be 3 numbers ({unit}), got {value!r}") from None
    if arr.shape != (3,):
        extra = ""
        if arr.ndim == 2 and arr.shape[-1] == 3:
            extra = (f": that is {arr.shape[0]} samples; push them one at a time "
                     "(for k in range(n): stream.push(t[k], acc[k], gyr[k])) or use Stream.run(recording)")
        raise RecordingError(f"{name} at t = {shown(t)} must have shape (3,), got {arr.shape}{extra}")
    if not np.isfinite(arr).all():
        raise RecordingError(f"non-finite sample at t = {shown(t)}: {name} = {arr.tolist()}; repair or drop the sample")
    if bound is not None and np.abs(arr).max() > bound:
        raise RecordingError(
            f"{name} at t = {shown(t)} is {arr.tolist()} {unit}: "
            f"beyond any body-worn IMU (|value| <= {bound:g} {unit}); "
            "the sample is corrupt, or the unit is wrong (footzoo expects SI, FRD)"
        )
    return arr


def validate_sample(
    t: Any,
    acc: Any,
    gyr: Any,
    mag: Any = None,
    dist: Any = None,
    previous_t: float | None = None,
    max_gap: float | None = None,
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Check one live sample; return it as ``(t, acc, gyr, mag, dist)`` floats/arrays.

    Parameters
    ----------
    t : float
        Time stamp (s); finite and later than ``previous_t``.
    acc : (3,) array_like
        Specific force, FRD (m/s²), each component within ±:data:`ACC_MAX`.
    gyr : (3,) array_like
        Angular rate, FRD (rad/s), each component within ±:data:`GYR_MAX`.
    mag : (3,) array_like, optional
        Magnetic field (any unit), finite.
    dist : (k,) array_like, optional
        Ranges (m); NaN means "no reading", ±inf is rejected.
    previous_t : float, optional
        Time stamp of the previous sample (s).
    max_gap : float, optional
        Largest accepted interval to the previous sample (s); default :data:`DEFAULT_MAX_GAP`.

    Raises
    ------
    RecordingError
        Naming the sample's time, the problem and the fix. One sample per call:
        a block of samples (shape ``(n, 3)``) is rejected with how to push it.
    """
    if isinstance(t, (bool, str)) or np.ndim(t) != 0:
        raise RecordingError(f"t must be one time stamp in s (a number), got {shown(t)}; push one sample per call")
    try:
        tf = float(t)
    except (TypeError, ValueError):
        raise RecordingError(f"t must be a time stamp in s, got {shown(t)}") from None
    if not math.isfinite(tf):
        raise RecordingError(f"time stamp t = {shown(t)} is not finite; give each sample its real time in s")
    if previous_t is not None:
        if tf <= previous_t:
            raise RecordingError(
                f"time went from {shown(previous_t)} s to {shown(tf)} s: samples must arrive in order (increasing time)"
            )
        gap = DEFAULT_MAX_GAP if max_gap is None else max_gap
        if tf - previous_t > gap:
            raise RecordingError(
                f"gap of {tf - previous_t:.6g} s before t = {shown(tf)} s exceeds the stream's limit of {gap:g} s: "
                "the filter cannot bridge it; start a new Stream after the gap"
            )
    a = _sample_vector("acc", acc, tf, ACC_MAX, "m/s^2")
    g = _sample_vector("gyr", gyr, tf, GYR_MAX, "rad/s")
    m = None if mag is None else _sample_vector("mag", mag, tf, None, "")
    d = None
    if dist is not None:
        try:
            d = np.asarray(dist, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise RecordingError(
                f"dist at t = {shown(tf)} must be numbers in m (NaN for no reading), got {dist!r}"
            ) from None
        if np.isinf(d).any():
            raise RecordingError(f"dist at t = {shown(tf)} is infinite ({d.tolist()}); "
                                 f"use NaN where there is no reading")
    return tf, a, g, m, d


def _swapped(acc: np.ndarray, gyr: np.ndarray) -> str:
    """A hint when a block's acc and gyr look swapped: |gyr| about gravity (m/s^2), |acc| far below it."""
    g, a = float(np.median(np.linalg.norm(gyr, axis=1))), float(np.median(np.linalg.norm(acc, axis=1)))
    if 7.0 < g < 13.0 and a < 5.0:
        return (f"; acc and gyr look swapped: the median |gyr| is {g:.3g}, as gravity in m/s^2, the median |acc| "
                f"{a:.3g}: give acc first, then gyr")
    return ""


def validate_block(
    t: Any,
    acc: Any,
    gyr: Any,
    mag: Any = None,
    dist: Any = None,
    previous_t: float | None = None,
    max_gap: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Check a block of live samples at once, as :func:`validate_sample` checks one: ``(t, acc, gyr, mag, dist)``.

    ``t`` (n,) s, ``acc`` (n, 3) m/s², ``gyr`` (n, 3) rad/s, ``mag`` (n, 3) or None, ``dist`` (n, k) m or None.

    Raises
    ------
    RecordingError
        Naming the first bad sample's time, the problem and the fix.
    """
    try:
        tf = np.asarray(t, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise RecordingError(f"t must be time stamps in s (numbers), got {t!r:.80}") from None
    n = tf.shape[0]
    if n == 0:
        raise RecordingError("an empty block: give at least one sample")
    arrays = []
    for name, value, bound, unit in (("acc", acc, ACC_MAX, "m/s^2"), ("gyr", gyr, GYR_MAX, "rad/s"),
                                     ("mag", mag, None, "")):
        if value is None and name != "mag":  # a sensor that stopped sending it: not an optional channel
            raise RecordingError(f"{name} is missing (None) in the block from t = {shown(tf[0])}: every sample "
                                 f"needs {name} ({unit}, 3 numbers, here ({n}, 3)); a sensor that dropped out cannot "
                                 "be bridged: repair the gap or end the stream there")
        if value is None:
            arrays.append(None)
            continue
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise RecordingError(f"{name} must be numbers ({unit}), got {value!r:.80}") from None
        if arr.shape != (n, 3):
            raise RecordingError(f"{name} must have shape ({n}, 3) for {n} time stamps, got {arr.shape}")
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            raise RecordingError(f"non-finite sample at t = {shown(tf[k])}: {name} = {arr[k].tolist()}; "
                                 f"repair or drop it")
        if bound is not None and (np.abs(arr) > bound).any():
            k = int(np.argmax((np.abs(arr) > bound).any(axis=1)))
            raise RecordingError(
                f"{name} at t = {shown(tf[k])} is {arr[k].tolist()} {unit}: beyond any body-worn IMU (|value| <= "
                f"{bound:g} {unit}); the sample is corrupt, or the unit is wrong (footzoo expects SI, FRD)"
                + (_swapped(arrays[0], arr) if name == "gyr" else ""))
        arrays.append(arr)
    if not np.isfinite(tf).all():
        k = int(np.argmax(~np.isfinite(tf)))
        raise RecordingError(f"time stamp {k} of the block is {shown(tf[k])}: give each sample its real time in s")
    steps = np.diff(np.concatenate([[previous_t], tf])) if previous_t is not None else np.diff(tf)
    first = tf[0] if previous_t is None else previous_t
    if (steps <= 0).any():
        k = int(np.argmax(steps <= 0))
        before = (np.concatenate([[first], tf]) if previous_t is not None else tf)[k]
        raise RecordingError(f"time went from {shown(before)} s to {shown(before + steps[k])} s: "
                             f"samples must arrive in order "
                             "(increasing time)")
    gap = DEFAULT_MAX_GAP if max_gap is None else max_gap
    if (steps > gap).any():
        k = int(np.argmax(steps > gap))
        raise RecordingError(f"gap of {steps[k]:.6g} s in the block exceeds the stream's limit of {gap:g} s: the "
                             "filter cannot bridge it; start a new Stream after the gap")
    d = None
    if dist is not None:
        try:
            d = np.asarray(dist, dtype=float).reshape(n, -1)
        except (TypeError, ValueError):
            raise RecordingError(f"dist must be ({n}, k) numbers in m (NaN for no reading), got {dist!r:.80}") from None
        if np.isinf(d).any():
            raise RecordingError("dist holds infinite values; use NaN where there is no reading")
    return tf, arrays[0], arrays[1], arrays[2], d


class Settings:
    """Base of a config's settings blocks (``init:``, ``navigation:``, ``guards:``): a dataclass of numbers.

    A subclass is a ``@dataclass`` whose fields are the keys (with their defaults); it sets
    ``section`` (the config key), ``example`` (a valid mapping, for the error message) and
    ``parameters``, the declaration of every field (:mod:`footzoo.core.params`, as for a plug-in).
    Values are validated on construction; :meth:`from_dict` refuses unknown keys with the valid ones;
    :meth:`to_dict` gives every value.
    """

    section: ClassVar[str] = ""
    example: ClassVar[str] = ""
    parameters: ClassVar[dict[str, Param]] = {}

    def __post_init__(self) -> None:
        for name, d in self.declaration().items():
            setattr(self, name, d.validate(getattr(self, name), f"{self.section}.{name}"))

    @classmethod
    def declaration(cls) -> dict[str, Declared]:
        """``{key: Declared}`` of every field, in order (a field without a declaration is a TypeError)."""
        defaults = {f.name: f.default for f in fields(cls)}  # type: ignore[arg-type]
        out = declared(cls, defaults)
        missing = [k for k in defaults if k not in out]
        if missing:
            raise TypeError(f"{cls.__name__}: declare {missing} in its parameters")
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> Any:
        """Build from the config's mapping (None or missing keys: the defaults)."""
        if d is None:
            return cls()
        if not isinstance(d, dict):
            raise ConfigError(f"{cls.section} must be a mapping like {cls.example}, got {d!r}")
        valid = [f.name for f in fields(cls)]  # type: ignore[arg-type]
        for key in d:
            if key not in valid:
                raise ConfigError(f"unknown {cls.section} key {key!r}{did_you_mean(str(key), valid)}; "
                                  f"valid: {valid}")
        return cls(**d)

    def to_dict(self) -> dict[str, float]:
        """Every value, explicit (for ``Result.config``)."""
        return asdict(self)  # type: ignore[call-overload]
