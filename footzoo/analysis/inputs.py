"""Checks of the arrays the public analysis functions take, before any compiled loop reads them.

The compiled loops (:mod:`footzoo.analysis.gait_events`) read without bounds checks, so a
stance index beyond the samples, an array shorter than ``t`` or a time that runs backwards
must be refused here, with an error naming the function, the argument, the problem and the fix.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.errors import RecordingError


def _numbers(fn: str, name: str, value: Any) -> np.ndarray:
    """``value`` as a real number array (no bools, complex, strings or objects)."""
    try:
        arr = np.asarray(value)
    except Exception as err:  # noqa: BLE001 (a ragged list, an unconvertible object)
        raise RecordingError(f"{fn}: {name} must be an array of real numbers, got {type(value).__name__}: "
                             f"{err}") from None
    if arr.dtype == bool or not (np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)):
        raise RecordingError(f"{fn}: {name} must be an array of real numbers (floats), got dtype {arr.dtype}: "
                             f"convert it with np.asarray({name}, dtype=float) if its values are numbers")
    return arr


def check_time(fn: str, t: Any) -> np.ndarray:
    """Time (N,) in s: finite and strictly increasing, as float."""
    ts = _numbers(fn, "t", t).astype(float, copy=False)
    if ts.ndim != 1:
        raise RecordingError(f"{fn}: t must be 1-D (N,) time stamps in s, got shape {ts.shape}")
    if not np.isfinite(ts).all():
        raise RecordingError(f"{fn}: t holds {int((~np.isfinite(ts)).sum())} NaN/inf time stamp(s); "
                             "give finite time stamps in s")
    back = np.flatnonzero(np.diff(ts) <= 0)
    if len(back):
        k = int(back[0]) + 1
        raise RecordingError(f"{fn}: t must increase strictly, but t[{k}] = {ts[k]:g} s follows t[{k - 1}] = "
                             f"{ts[k - 1]:g} s ({len(back)} such sample(s)); sort the samples and drop repeated "
                             "time stamps (footzoo.Recording does both checks)")
    return ts


def check_samples(fn: str, name: str, value: Any, n: int, cols: tuple[int, ...], what: str) -> np.ndarray:
    """One row per sample of ``t``, as float: shape ``(n, c)`` for a width ``c`` in ``cols`` (``0``: ``(n,)``)."""
    arr = _numbers(fn, name, value).astype(float, copy=False)
    ok = (arr.ndim == 1 and 0 in cols) or (arr.ndim == 2 and arr.shape[1] in cols)
    if not ok or len(arr) != n:
        shapes = " or ".join("(N,)" if c == 0 else f"(N, {c})" for c in cols)
        raise RecordingError(f"{fn}: {name} must be {shapes} {what}, one row per sample of t (N = {n}), "
                             f"got shape {arr.shape}")
    return arr


def check_mask(fn: str, name: str, value: Any, n: int) -> np.ndarray:
    """A boolean mask (N,): bools, or numbers that are all 0 or 1."""
    arr = np.asarray(value)
    if arr.dtype != bool:
        arr = _numbers(fn, name, arr)
        if not np.isin(arr, (0, 1)).all():
            raise RecordingError(f"{fn}: {name} must be a boolean mask (True in stance), got dtype {arr.dtype} with "
                                 "values other than 0 and 1; threshold it first (e.g. stance = p > 0.5)")
        arr = arr.astype(bool)
    if arr.shape != (n,):
        raise RecordingError(f"{fn}: {name} must be (N,), one flag per sample of t (N = {n}), got shape {arr.shape}")
    return arr


def check_stances(fn: str, stances: Any, n: int) -> np.ndarray:
    """Stance intervals ``(start, stop)`` (K, 2) of sample indices, stop exclusive, in order, within ``[0, n]``."""
    arr = _numbers(fn, "stances", stances)
    if arr.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise RecordingError(f"{fn}: stances must be (K, 2) (start, stop) sample indices, got shape {arr.shape}; "
                             "footzoo.analysis.real_stances(stance, pos) gives them")
    if not np.issubdtype(arr.dtype, np.integer):
        if not (np.isfinite(arr).all() and (arr == np.round(arr)).all()):
            raise RecordingError(f"{fn}: stances must be whole sample indices, got non-integer values "
                                 f"(dtype {arr.dtype}); footzoo.analysis.real_stances(stance, pos) gives them")
    arr = arr.astype(np.int64)
    a, b = arr[:, 0], arr[:, 1]
    bad = np.flatnonzero((a < 0) | (b > n) | (a >= b) | np.r_[False, a[1:] < b[:-1]])
    if len(bad):
        i = int(bad[0])
        raise RecordingError(f"{fn}: stance {i} = ({a[i]}, {b[i]}) is not a non-empty interval of the N = {n} samples "
                             "in order (0 <= start < stop <= N, each after the previous stop); "
                             "footzoo.analysis.real_stances(stance, pos) gives valid ones")
    return arr
