"""The plug-in contract, checked by the caller: read-only inputs, faults named, results checked on return.

A plug-in class is plain Python: footzoo wraps its methods only to check its parameters before they run
(:data:`footzoo.plugins.base.CHECKS_PARAMS`). Whoever calls a plug-in on
footzoo's behalf — :class:`~footzoo.runtime.pipeline.Pipeline`, the stages of a
:class:`~footzoo.Stream`, a study, :func:`~footzoo.apps.testing.check_plugin` — calls it through
:func:`checked` (``checked(detector.detect, t, acc, gyr)`` instead of ``detector.detect(t, acc, gyr)``),
so that every such caller gets the same guarantees:

* **inputs are checked and read-only**: the array arguments of an action method (:data:`ACTIONS`)
  must be numeric and finite (a NaN or inf is a :class:`~footzoo.core.errors.RecordingError` naming
  the input and the first bad sample); every array argument is passed as a ``writeable=False``
  view (and the arrays of a :class:`~footzoo.plugins.base.Samples`). A plug-in that writes into its
  input raises, and the caller's recording never changes; the fix is to copy first
  (``acc = np.array(acc)``).
* **faults are the plug-in's**: any exception raised inside the method (``SystemExit`` and
  other ``BaseException`` included; ``KeyboardInterrupt`` and ``MemoryError`` excepted) becomes
  a :class:`~footzoo.core.errors.PluginError` naming the plug-in, its class and file, the
  method and the original error, chained (``raise ... from err``). footzoo's own errors
  (:class:`~footzoo.core.errors.FootzooError`: a plug-in's deliberate "this recording is too
  short") pass unchanged.
* **results are checked on return**: a method that must return the plug-in (``detect``,
  ``estimate``, ``apply``, ``calibrate``, ``analyze``, ``begin``) and returns ``None`` (a
  forgotten ``return self``) is named; the kind's declared outputs (:class:`Output`, the
  ``outputs`` of each base class) are checked for presence, shape (one row per input sample),
  dtype, finiteness, unit quaternions (:data:`QUAT_NORM_TOL`) and boolean stance (a float
  stance holding NaN, or values other than 0 and 1, is refused: NaN must never read as stance).
  The chunks of ``step``/``finish``/``provisional`` are checked the same way (their length is
  the samples that became final, so only their columns' agreement is checked).

The checks only read; the numbers of a plug-in that keeps its contract are unchanged. A plug-in
method called directly (``detector.detect(t, acc, gyr)`` in a script) runs exactly as written,
without them.
"""

from __future__ import annotations

import contextlib
import contextvars
import copy
import dataclasses
import functools
import inspect
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.errors import FootzooError, PluginError, RecordingError, shown
from ..core.norms import unit_error
from ..filters.measurement import MeasurementModel

#: The action methods whose array inputs :func:`checked` checks (finite, numeric) before the plug-in sees them.
ACTIONS = ("calibrate", "estimate", "detect", "apply", "apply_acceleration", "analyze")
#: Methods that return the plug-in itself (``return self``).
RETURNS_SELF = ("calibrate", "estimate", "detect", "apply", "analyze", "begin")
#: Methods that return a chunk of per-sample outputs (:data:`footzoo.plugins.incremental.Chunk`).
RETURNS_CHUNK = ("step", "step_acceleration", "finish", "provisional")
#: Largest accepted | |q| - 1 | of an attitude quaternion a plug-in returns (numerical drift is fine).
QUAT_NORM_TOL = 1e-6
#: Exceptions that are not a plug-in's fault: passed on unchanged.
PASSED_ON: tuple[type[BaseException], ...] = (FootzooError, KeyboardInterrupt, MemoryError, GeneratorExit)


@dataclass(frozen=True)
class Output:
    """One per-sample output a plug-in kind returns (``stance`` of a detector, ``quat`` of an orientation...).

    Parameters
    ----------
    what : {"float", "bool", "quat"}
        A real array, a stance mask (bool, or 0/1 numbers) or unit quaternions (width 4).
    width : int
        0 for (N,), else the columns of (N, width).
    finite : bool
        Every value finite (no NaN or inf).
    required : bool
        Set by the action method, and a column of every non-empty chunk of ``step``.
    """

    what: str = "float"
    width: int = 0
    finite: bool = True
    required: bool = True


#: Within :func:`inputs_checked_once`: the float arrays proven finite so far (the objects themselves, compared by
#: identity: an array is held while it is listed, so another array can never pass for it).
_PROVEN: contextvars.ContextVar[list[np.ndarray] | None] = contextvars.ContextVar("footzoo_proven_finite",
                                                                                default=None)


@contextlib.contextmanager
def inputs_checked_once() -> Iterator[None]:
    """Within: an array argument already proven finite is not scanned again when the same object comes back.

    A pipeline run hands its recording's arrays to one block after another, and one block's
    checked outputs to the next; :func:`checked` checks each action method's inputs, and without
    this each block would scan the same ``t``, ``acc`` and ``gyr`` (or the calibrated signals, the
    attitude) again. Only the very object proven is skipped (an input checked, or an output that
    passed :func:`check_array`; a new array, a copy or a calibrated signal is checked), and only
    until the ``with`` block ends; outside one, every call checks. Outputs are always checked.
    """
    token = _PROVEN.set([])
    try:
        yield
    finally:
        _PROVEN.reset(token)


def proven_finite(value: Any) -> bool:
    """True within :func:`inputs_checked_once` for the very array object already proven finite."""
    proven = _PROVEN.get()
    return proven is not None and any(value is p for p in proven)


def mark_finite(value: np.ndarray) -> None:
    """Within :func:`inputs_checked_once`: ``value`` (this object) is proven finite."""
    proven = _PROVEN.get()
    if proven is not None and not any(value is p for p in proven):
        proven.append(value)


def all_finite(value: np.ndarray) -> bool:
    """``np.isfinite(value).all()`` without its (N,) temporary: a sum is finite only if every term is.

    A NaN or an infinity makes the sum non-finite; a finite sum therefore proves the array
    finite. Only a non-finite sum (a bad sample, or an overflow of huge values) needs the exact check.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(value.sum()):
            return True
    return bool(np.isfinite(value).all())


def check_inputs(plugin: Any, method: str, names: list[str], args: tuple, kwargs: dict[str, Any]) -> None:
    """An action method's array inputs: a non-finite or non-numeric array argument raises a clear RecordingError."""
    for name, value in [*zip(names, args, strict=False), *kwargs.items()]:
        if not isinstance(value, np.ndarray) or proven_finite(value):
            continue
        if value.dtype.kind in "fc" and not all_finite(value):
            bad = np.flatnonzero(~np.isfinite(value).reshape(len(value), -1).all(axis=1)) if value.ndim else [0]
            raise RecordingError(
                f"{who(plugin)}: input {name!r} has {len(bad)} non-finite sample(s) (NaN or inf), "
                f"first at index {int(bad[0])}; repair or drop them before running (footzoo.Recording does)"
            )
        if value.dtype.kind not in "fcbiu":
            raise RecordingError(f"{who(plugin)}: input {name!r} of {method}() must be numeric, got dtype "
                                 f"{value.dtype}")
        if value.dtype.kind in "fc":
            mark_finite(value)


@functools.lru_cache(maxsize=4096)
def _argument_names(function: Callable[..., Any]) -> tuple[str, ...]:
    """The names of a method's arguments after ``self`` (held by the function object itself)."""
    return tuple(list(inspect.signature(function).parameters)[1:])


def checked(method: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """``method(*args, **kwargs)`` — a bound method of a plug-in — under the contract of this module.

    The action methods' (:data:`ACTIONS`) array inputs are checked first; every array argument is
    passed read-only; an exception of the plug-in becomes a :class:`PluginError` naming it; the
    result is checked on return (see the module docstring).

    Raises
    ------
    RecordingError
        A non-finite or non-numeric array input of an action method.
    PluginError
        A fault of the plug-in, or a result that breaks the contract.
    """
    plugin = getattr(method, "__self__", None)
    function = getattr(method, "__func__", None)
    if plugin is None or function is None:
        raise TypeError(f"checked() takes a bound method of a plug-in (plugin.detect), got {method!r}")
    name = function.__name__
    names = list(_argument_names(function))
    if name in ACTIONS:
        check_inputs(plugin, name, names, args, kwargs)
    originals = (args, kwargs)
    args = tuple(read_only(a) for a in args)
    kwargs = {k: read_only(v) for k, v in kwargs.items()}
    try:
        result = method(*args, **kwargs)
    except PASSED_ON:
        raise
    except BaseException as err:  # noqa: BLE001 - SystemExit in a plug-in is its fault too
        raise fault(plugin, name, err) from err
    changed_inputs(plugin, name, names, originals, (args, kwargs))
    return returned(plugin, name, names, args, kwargs, result, originals)


def read_only(value: Any) -> Any:
    """A ``writeable=False`` view of an array (of each array of a dataclass such as ``Samples``), a copy of a
    mapping (the recording's metadata: a change is found by :func:`changed_inputs`) or of a table; others as
    they are."""
    if isinstance(value, dict):
        return copy.deepcopy(value)
    if isinstance(value, pd.DataFrame):
        return value.copy()
    if isinstance(value, np.ndarray):
        # a view even of a frozen array: a frozen array that owns its data can be made writable again
        # (gyr.setflags(write=True)), a view of it cannot
        view = value.view()
        view.flags.writeable = False
        return view
    if dataclasses.is_dataclass(value) and not isinstance(value, type) and any(
            isinstance(getattr(value, f.name), np.ndarray) for f in dataclasses.fields(value)):
        return dataclasses.replace(value, **{f.name: read_only(getattr(value, f.name))
                                             for f in dataclasses.fields(value) if f.init})
    return value


def who(plugin: Any) -> str:
    """``"<kind> '<name>'"`` of a plug-in."""
    return f"{getattr(plugin, 'kind', '') or 'plug-in'} {getattr(plugin, 'name', '') or type(plugin).__name__!r}"


def _where(plugin: Any) -> str:
    cls = plugin if isinstance(plugin, type) else type(plugin)
    try:
        path = inspect.getsourcefile(cls)
    except (TypeError, OSError):
        path = None
    return f"{cls.__module__}.{cls.__qualname__}" + (f" in {Path(path).name}" if path else "")


def fault(plugin: Any, method: str, err: BaseException) -> PluginError:
    """The :class:`PluginError` for an exception ``err`` raised in ``plugin.method`` (``plugin``: the instance, or its
    class for ``__init__``)."""
    text = f"{type(err).__name__}: {err}" if str(err) else type(err).__name__
    hint = "fix the plug-in"
    if isinstance(err, ValueError) and ("read-only" in str(err) or "WRITEABLE" in str(err)):
        hint = ("it writes into an input array (or makes it writable), which footzoo passes read-only (the caller's "
                "recording must not change): copy it first, e.g. acc = np.array(acc)")
    elif isinstance(err, SystemExit):
        hint = "a plug-in must raise an exception, never exit the process"
    return PluginError(f"{who(plugin)} ({_where(plugin)}) failed in {method}(): {text}; {hint}",
                       plugin=who(plugin), method=method)


def broken(plugin: Any, method: str, problem: str) -> PluginError:
    """A :class:`PluginError` for a result of ``plugin.method`` that breaks the contract."""
    return PluginError(f"{who(plugin)} ({_where(plugin)}): {method}() {problem}", plugin=who(plugin), method=method)


def changed_inputs(plugin: Any, method: str, names: list[str], originals: tuple[tuple, dict[str, Any]],
                   given: tuple[tuple, dict[str, Any]]) -> None:
    """A :class:`PluginError` when the plug-in changed a mapping it was given (the recording's ``meta``).

    It got a copy (:func:`read_only`), so the caller's stays as it was; the change is the plug-in's
    fault all the same: in a study the same recording goes to the next config, which must see it
    unchanged, and a plug-in that relies on its change works by accident.
    """
    (args0, kwargs0), (args1, kwargs1) = originals, given
    pairs = [*zip(names, args0, args1, strict=False), *((k, kwargs0[k], kwargs1[k]) for k in kwargs0)]
    for label, before, after in pairs:
        if isinstance(before, dict) and not same_value(before, after):
            keys = sorted({str(k) for k in {*before, *after}
                           if k not in before or k not in after or not same_value(before[k], after[k])})
            raise broken(plugin, method, f"changed its input {label} (keys {keys[:5]}); footzoo passes inputs "
                                         f"read-only (a study gives the same recording to the next config): copy "
                                         f"it first ({label} = dict({label}))")


def same_value(a: Any, b: Any) -> bool:
    """Whether two plain values (mappings, lists, arrays, numbers, text) are equal; NaN equals NaN."""
    if isinstance(a, dict) or isinstance(b, dict):
        return isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys() and all(
            same_value(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        try:
            return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=np.asarray(a).dtype.kind in "fc")
        except (TypeError, ValueError):
            return False
    if isinstance(a, (pd.DataFrame, pd.Series)) or isinstance(b, (pd.DataFrame, pd.Series)):
        return type(a) is type(b) and a.equals(b)
    try:
        if a == b:
            return True
    except (TypeError, ValueError):
        return a is b
    return isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)


#: Most rows a Kalman correction's measurement model may declare at one sample (``max_rows``).
MAX_MODEL_ROWS = 1000


def check_model(plugin: Any, model: Any, n: int | None) -> None:
    """A Kalman correction's :class:`~footzoo.filters.measurement.MeasurementModel`, checked before the engine
    sizes its buffers with it (a wrong ``max_rows`` would crash or allocate without bound)."""
    if not isinstance(model, MeasurementModel):
        raise broken(plugin, "model", f"returned {type(model).__name__}; it must return a "
                                      "footzoo.filters.measurement.MeasurementModel")
    rows = model.max_rows
    if isinstance(rows, (bool, np.bool_)) or not isinstance(rows, (int, np.integer)) \
            or not 0 <= rows <= MAX_MODEL_ROWS:
        raise broken(plugin, "model", f"declares max_rows={rows!r}; it must be the whole number of rows its measure "
                                      f"function writes at most at one sample, 0 to {MAX_MODEL_ROWS}")
    for fn in ("measure", "feedback", "after"):
        if not callable(getattr(model, fn)):
            raise broken(plugin, "model", f"gives a {fn} that is not a function ({getattr(model, fn)!r:.60})")
    for name in ("par", "mem"):
        try:
            np.asarray(getattr(model, name), dtype=float).ravel()
        except (TypeError, ValueError):
            raise broken(plugin, "model", f"gives {name} that is not an array of numbers") from None
    data = model.data
    if data is not None:
        arr = np.asarray(data)
        if arr.ndim != 2 or (n is not None and arr.shape[0] != n) or arr.dtype.kind not in "biuf":
            raise broken(plugin, "model", f"gives data of shape {arr.shape} and dtype {arr.dtype}; it must be "
                                          f"({'N' if n is None else n}, d) numbers: one row per sample")


def check_annotated(plugin: Any, steps: Any, result: Any) -> None:
    """What an analysis' ``annotate`` returned: every stride it was given, the given columns unchanged."""
    if not isinstance(result, pd.DataFrame):
        raise broken(plugin, "annotate", f"returned {type(result).__name__}; it must return the steps table with "
                                         "its columns added (a pandas DataFrame)")
    if not isinstance(steps, pd.DataFrame):
        return
    if len(result) != len(steps) or not result.index.equals(steps.index):
        lost = len(steps) - len(result)
        what = (f"{lost} of the {len(steps)} strides it was given" if lost > 0 else
                f"{-lost} stride(s) to the {len(steps)} it was given" if lost < 0 else "the order of the strides")
        raise broken(plugin, "annotate", f"{'dropped' if lost > 0 else 'added' if lost < 0 else 'changed'} {what}; an "
                                         "analysis adds columns to every stride and drops none (a stride it cannot "
                                         "analyse gets NaN), or the stride table and its metrics would be wrong")
    for col in steps.columns:
        if col not in result.columns:
            raise broken(plugin, "annotate", f"dropped the column {col!r} of the steps table; an analysis adds "
                                             "columns and keeps the others")
        if not result[col].equals(steps[col]):
            raise broken(plugin, "annotate", f"changed the column {col!r} it was given; an analysis adds its own "
                                             "columns (give yours another name) and keeps the others as they are")


def returned(plugin: Any, method: str, names: list[str], args: tuple, kwargs: dict[str, Any], result: Any,
             originals: tuple[tuple, dict[str, Any]] | None = None) -> Any:
    """Check what ``plugin.method(*args, **kwargs)`` returned (see the module docstring); return it."""
    if method == "model":
        samples = args[0] if args else next(iter(kwargs.values()), None)
        t = getattr(samples, "t", None)
        check_model(plugin, result, len(t) if isinstance(t, np.ndarray) else None)
    elif method == "annotate":
        given = (originals or (args, kwargs))[0]
        check_annotated(plugin, given[0] if given else kwargs.get("steps"), result)
    if method in RETURNS_SELF:
        if result is None:
            raise broken(plugin, method, f"returned None: end {method}() with 'return self'")
        if getattr(result, "kind", None) != plugin.kind or not hasattr(result, "get_params"):
            raise broken(plugin, method, f"returned {type(result).__name__}, not the plug-in: end {method}() with "
                                         "'return self'")
        if result is not plugin:  # another plug-in's results would be read as this one's
            raise broken(plugin, method, f"returned another {type(result).__name__} object, not itself: set the "
                                         f"results on self and end {method}() with 'return self'")
        if method != "begin":
            check_attributes(result, method, _samples(names, args, kwargs))
    elif method in RETURNS_CHUNK:
        check_chunk(plugin, method, result)
    elif method == "apply_acceleration":
        n = _samples(names, args, kwargs)
        check_array(plugin, method, "the returned acceleration", result, Output(width=3), n)
    return result


def _samples(names: list[str], args: tuple, kwargs: dict[str, Any]) -> int | None:
    """The number of samples of a call: the length of its first array argument."""
    for value in [*args, *kwargs.values()]:
        if isinstance(value, np.ndarray) and value.ndim:
            return len(value)
    return None


def check_attributes(plugin: Any, method: str, n: int | None) -> None:
    """The kind's declared outputs, as the attributes ``<name>_`` an action method sets."""
    for key, spec in getattr(plugin, "outputs", {}).items():
        value = getattr(plugin, f"{key}_", None)
        if value is None:
            if spec.required:
                raise broken(plugin, method, f"did not set {key}_ (a {_shape(spec, n)} array)")
            continue
        check_array(plugin, method, f"{key}_", value, spec, n)


def check_chunk(plugin: Any, method: str, chunk: Any) -> None:
    """A chunk of ``step``/``finish``/``provisional``: a dict of the kind's columns, all of one length."""
    if not isinstance(chunk, dict):
        raise broken(plugin, method, f"returned {type(chunk).__name__}; it must return a dict of per-sample arrays "
                                     "(an empty dict when no sample became final)")
    if not chunk:
        return
    outputs = getattr(plugin, "outputs", {})
    if method == "step_acceleration":
        outputs = {"acc_nav": Output(width=3)}
    lengths = {k: len(v) for k, v in chunk.items() if hasattr(v, "__len__")}
    if len(set(lengths.values())) > 1:
        raise broken(plugin, method, f"returned columns of different lengths {lengths}; every column has one row "
                                     "per sample that became final")
    n = next(iter(lengths.values()), None)
    for key, spec in outputs.items():
        if key in chunk and chunk[key] is not None:
            check_array(plugin, method, f"the column {key!r}", chunk[key], spec, n)
        elif spec.required and n and method != "provisional":
            raise broken(plugin, method, f"returned no column {key!r} with its {n} samples")


def _shape(spec: Output, n: int | None) -> str:
    rows = "N" if n is None else str(n)
    return f"({rows},)" if not spec.width else f"({rows}, {spec.width})"


def check_array(plugin: Any, method: str, label: str, value: Any, spec: Output, n: int | None) -> None:
    """One output array against its declaration (raises :class:`PluginError` naming the plug-in)."""
    arr = value if isinstance(value, np.ndarray) else np.asarray(value)
    kind = arr.dtype.kind
    if kind not in "biuf":
        raise broken(plugin, method, f"set {label} of dtype {arr.dtype}; it must be a {_shape(spec, n)} "
                                     f"{'bool' if spec.what == 'bool' else 'float'} array")
    width_ok = arr.ndim == 1 if not spec.width else (arr.ndim == 2 and arr.shape[1] == spec.width)
    if not width_ok or (n is not None and len(arr) != n):
        raise broken(plugin, method, f"set {label} of shape {arr.shape}; it must be {_shape(spec, n)}: one row per "
                                     "input sample")
    if spec.what == "bool":
        if kind != "b" and not np.isin(arr, (0, 1)).all():
            bad = np.flatnonzero(~np.isin(arr, (0, 1)))
            raise broken(plugin, method, f"set {label} with {len(bad)} value(s) that are neither 0 nor 1 (first "
                                         f"{shown(arr[bad[0]])} at sample {int(bad[0])}): "
                                         f"a stance mask is bool; NaN is "
                                         "not stance — decide each sample (stance_ = statistic < threshold)")
        return
    if kind != "f" or not len(arr):
        return
    if (spec.finite or spec.what == "quat") and not math.isfinite(float(arr.sum())) and not np.isfinite(arr).all():
        bad = np.flatnonzero(~np.isfinite(arr).reshape(len(arr), -1).all(axis=1))
        raise broken(plugin, method, f"set {label} with {len(bad)} non-finite sample(s) (NaN or inf), first at sample "
                                     f"{int(bad[0])}")
    if (spec.finite or spec.what == "quat") and value is arr:
        mark_finite(arr)  # finite: a later block given this very array need not scan it again
    if spec.what == "quat":
        err, k = unit_error(arr)  # max ||q|² - 1| ≈ 2 (|q| - 1)
        if err > 2 * QUAT_NORM_TOL:
            raise broken(plugin, method, f"set {label} with non-unit quaternions (|q| = {np.linalg.norm(arr[k]):.9g} "
                                         f"at sample {k}, tolerance {QUAT_NORM_TOL:g}): normalise each attitude "
                                         "(q / |q|)")


def detector_diagnostics(detector: Any, n: int) -> dict[str, Any]:
    """A fitted detector's outputs for ``Result.diagnostics``: ``detector_stance``, ``detector_statistic`` and,
    when the detector sets no statistic (an optional output), NaN in its place and ``detector_statistic_note``
    saying so (never silently: a study then draws no threshold sweep for it)."""
    statistic = getattr(detector, "statistic_", None)
    out = {"detector_statistic": np.full(n, np.nan) if statistic is None else statistic,
           "detector_stance": detector.stance_}
    arr = np.asarray(out["detector_statistic"])
    if arr.dtype.kind == "f" and not np.isfinite(arr).any():
        out["detector_statistic_note"] = no_statistic_note(detector)
    return out


def no_statistic_note(detector: Any) -> str:
    """Why a detector's statistic is NaN: it sets none (``statistic_`` is an optional output)."""
    return (f"{who(detector)} sets no statistic_ (its test statistic is an optional output): detector_statistic is "
            "NaN, and a study draws no threshold sweep (ROC curve) for it; its stance_ is used as it is")
