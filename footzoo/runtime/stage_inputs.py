"""Checks of what the step-by-step methods of :class:`~footzoo.Pipeline` are given.

:meth:`~footzoo.Pipeline.guard`, :meth:`~footzoo.Pipeline.orient`, :meth:`~footzoo.Pipeline.navigate`
and :meth:`~footzoo.Pipeline.analyse` take the pieces of a run one by one: a fitted detector, a stance
mask, the initial attitude ``q0`` (scalar-first body -> NED quaternion), the attitude and the positions.
Pieces of another recording (another length), of another shape or not fitted yet would otherwise run
silently on misaligned samples or fail deep inside a plug-in; each is refused here with a
:class:`~footzoo.core.errors.RecordingError` that names the method, the input, what is wrong and the fix.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.context import RunContext
from ..core.data import Recording
from ..core.errors import ConfigError, NotARecordingError, RecordingError
from ..core.params import Boolean
from ..filters.engine import ENGINES

FIX_STANCE = "pipe.guard(rec, pipe.detect(rec))[0] gives the stance of a recording"
FIX_Q0 = "pipe.prepare(rec).q0 gives it"


def recording(where: str, rec: Any) -> Recording:
    """``rec`` when it is a :class:`Recording`, else a :class:`NotARecordingError` naming ``where``."""
    if not isinstance(rec, Recording):
        raise NotARecordingError(f"{where} expects a footzoo Recording, got {type(rec).__name__}: build one with "
                                 "footzoo.load(path) or footzoo.Recording(t=..., acc=..., gyr=...)")
    return rec


def context(where: str, ctx: Any) -> RunContext | None:
    """``ctx`` when it is a :class:`RunContext` or None, else an error naming ``where``."""
    if ctx is not None and not isinstance(ctx, RunContext):
        raise ConfigError(f"{where}: ctx must be a footzoo RunContext (pipe.context(rec)) or None, got "
                          f"{type(ctx).__name__} {ctx!r:.60}; leave it out to use the recording's")
    return ctx


def _array(where: str, name: str, value: Any, fix: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise RecordingError(f"{where}: {name} must be a numeric array, got {type(value).__name__}; {fix}") from None
    return arr


def _samples(where: str, name: str, arr: np.ndarray, rec: Recording, fix: str) -> None:
    if arr.shape[0] != rec.n:
        raise RecordingError(f"{where}: {name} has {arr.shape[0]} samples but the recording {rec.name!r} has "
                             f"{rec.n}: it belongs to another recording (or was cut); {fix}")


def stance(where: str, value: Any, rec: Recording) -> np.ndarray:
    """The stance mask (N,) of ``rec`` as booleans: True/False or 1/0 per sample, one per sample of ``rec``."""
    if value is None:
        raise RecordingError(f"{where}: stance is None; {FIX_STANCE}")
    arr = _array(where, "stance", value, FIX_STANCE)
    if arr.ndim != 1:
        raise RecordingError(f"{where}: stance must be a 1-D mask (one value per sample), got shape {arr.shape}; "
                             f"{FIX_STANCE}")
    _samples(where, "stance", arr, rec, FIX_STANCE)
    bad = np.flatnonzero((arr != 0) & (arr != 1))
    if bad.size:
        raise RecordingError(f"{where}: stance must be True/False (or 1/0) per sample, got {float(arr[bad[0]]):g} at "
                             f"sample {bad[0]} ({bad.size} such); {FIX_STANCE}")
    return arr.astype(bool)


#: A q0 whose norm is this far from 1 or farther is refused; nearer, it is normalised (rounding of a printed one).
Q0_NORM_TOLERANCE = 0.01


def initial_attitude(where: str, q0: Any) -> np.ndarray:
    """The initial attitude: a finite quaternion (4,) of norm 1 within 1 %, scalar first (body -> NED), normalised."""
    arr = _array(where, "q0", q0, FIX_Q0)
    if arr.shape != (4,):
        raise RecordingError(f"{where}: q0 must be one quaternion (4,) [w, x, y, z], body -> NED, got shape "
                             f"{arr.shape}; {FIX_Q0}")
    if not np.all(np.isfinite(arr)) or np.linalg.norm(arr) < 1e-6:
        raise RecordingError(f"{where}: q0 = {arr.tolist()} is not a rotation (a finite quaternion of norm 1); "
                             f"{FIX_Q0}")
    norm = float(np.linalg.norm(arr))
    if abs(norm - 1.0) >= Q0_NORM_TOLERANCE:
        raise RecordingError(f"{where}: q0 = {arr.tolist()} has norm {norm:.4g}, not 1: a rotation is a unit "
                             "quaternion [w, x, y, z] (scalar first); not an attitude, or not normalised "
                             f"(q0 / np.linalg.norm(q0) if it is one); {FIX_Q0}")
    return arr / norm


def attitude(where: str, quat: Any, rec: Recording, fix: str) -> np.ndarray:
    """An attitude series (N, 4) of ``rec``: finite, non-zero quaternions, scalar first."""
    if quat is None:
        raise RecordingError(f"{where}: quat is None; {fix}")
    arr = _array(where, "quat", quat, fix)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise RecordingError(f"{where}: quat must be (N, 4) quaternions [w, x, y, z], got shape {arr.shape}; {fix}")
    _samples(where, "quat", arr, rec, fix)
    norm = np.linalg.norm(arr, axis=1)
    bad = np.flatnonzero(~np.isfinite(norm) | (norm < 1e-6))
    if bad.size:
        raise RecordingError(f"{where}: quat at sample {bad[0]} is {arr[bad[0]].tolist()}, not a rotation "
                             f"({bad.size} such); {fix}")
    return arr


def positions(where: str, pos: Any, rec: Recording) -> np.ndarray:
    """Positions (N, 3) of ``rec`` (NED, m)."""
    fix = "pipe.navigate(...)['pos'] gives them"
    arr = _array(where, "pos", pos, fix)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise RecordingError(f"{where}: pos must be (N, 3) positions (NED, m), got shape {arr.shape}; {fix}")
    _samples(where, "pos", arr, rec, fix)
    return arr


def fitted_detector(where: str, detector: Any, rec: Recording) -> Any:
    """A detector fitted on ``rec`` (its ``stance_`` one value per sample)."""
    fix = "pipe.detect(rec) gives the detector fitted on rec"
    if not hasattr(detector, "stance_"):
        what = "a detector not fitted yet (no stance_)" if hasattr(detector, "detect") else type(detector).__name__
        raise RecordingError(f"{where}: detector must be a fitted detector, got {what}; {fix}")
    if np.shape(detector.stance_) != (rec.n,):
        raise RecordingError(f"{where}: the detector's stance_ has shape {np.shape(detector.stance_)} but the "
                             f"recording {rec.name!r} has {rec.n} samples: it was fitted on another recording; {fix}")
    return detector


def flag(where: str, name: str, value: Any) -> bool:
    """``value`` when it is True or False (a text such as ``'no'``, truthy in Python, or 0/1 is refused)."""
    return Boolean(name).check(f"{where}: {name}", value, False)


def engine(where: str, value: Any) -> str:
    """``value`` when it names an engine (:data:`footzoo.filters.engine.ENGINES`)."""
    if value not in ENGINES:
        raise ConfigError(f"{where}: engine must be one of {list(ENGINES)}, got {value!r}")
    return value
