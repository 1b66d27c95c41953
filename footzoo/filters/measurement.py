"""The contract between a Kalman correction and the error-state engine.

A Kalman correction owns its measurement model: a few plain-array functions
and the arrays they work on, collected in a :class:`MeasurementModel`. The
compiled loop (:mod:`footzoo.filters.forward`), the filterpy reference loop
(:mod:`footzoo.filters.reference`) and the live stream all call the same
functions; the engine knows no correction by name.

The three functions (compile them with :func:`measurement_function`,
:func:`feedback_function` and :func:`after_function`)::

    measure(ctx, rows) -> m_new      # this sample's measurement rows
    feedback(ctx, dx) -> None        # after an update: the correction's own error states
    after(ctx) -> None               # once per sample, after the update

``ctx`` is a :class:`Context`, the sample as the correction sees it:

``ctx.k`` (int)
    Index of the sample in the whole recording (or stream).
``ctx.t`` (float, s)
    Its time.
``ctx.nav`` ((16,) float)
    The nominal state: ``nav[Q:Q+4]`` attitude quaternion (body → NED, scalar
    first), ``nav[P:P+3]`` position (m, NED), ``nav[V:V+3]`` velocity (m/s),
    ``nav[BG:BG+3]`` gyro bias and ``nav[BA:BA+3]`` accelerometer bias
    estimates (rad/s, m/s²). Read only. ``measure`` sees the prediction,
    ``feedback`` and ``after`` the corrected state.
``ctx.w``, ``ctx.f`` ((3,) float)
    Bias-corrected angular rate (rad/s) and specific force (m/s²), body frame.
``ctx.stance`` (bool)
    The detector's gait phase at this sample.
``ctx.idx`` ((5 + b,) int)
    Offsets of the error-state blocks: ``idx[ATT]``, ``idx[GYRO_BIAS]``,
    ``idx[POS]``, ``idx[VEL]``, ``idx[ACC_BIAS]`` (−1 where the block is
    absent), then the offsets of the correction's own blocks in the order of
    its :meth:`state_blocks`.
``ctx.par`` ((p,) float)
    The correction's constants (read only).
``ctx.mem`` ((s,) float)
    The correction's memory, carried from sample to sample (read/write).
``ctx.data`` ((d,) float)
    This sample's row of the correction's per-sample inputs.

``rows`` is a :class:`Rows`, the buffers of this sample's stacked measurement:

``rows.z``, ``rows.H``, ``rows.R``
    Write rows ``m, m+1, …`` of the residual ``z`` (measured − predicted, with
    the engine's sign: the error state is estimate − truth), the **nonzero**
    entries of the measurement matrix ``H`` (the engine keeps every other entry
    zero) and the measurement noise variance ``R`` (diagonal: rows are
    independent; a correlated measurement can be whitened first). They end
    after row ``m + max_rows − 1``: write at most the model's ``max_rows``
    rows. A plug-in's functions are compiled with bounds checks, so a write
    past the end (or outside ``par``, ``mem``, ``data``) is refused, and so is
    a returned row count outside ``[m, m + max_rows]``: both are the plug-in's
    :class:`~footzoo.core.errors.PluginError`. So is a row no update can use:
    an ``R`` that is not a positive finite number, a ``z`` or an ``H`` entry
    that is NaN or infinite (:func:`row_problem`).
``rows.m`` (int)
    The first free row; ``measure`` returns the next free row (``rows.m`` when
    there is nothing to measure).

``dx`` ((n,) float) is the error estimated by the update, fed back by the
engine to the core states; ``feedback`` applies the correction's own blocks to
its memory. ``after`` does bookkeeping that needs the corrected state (e.g. the
heading at the end of a stance).

The compiled loop calls the functions through a calling convention of plain
positional arguments, the fields of ``ctx`` and then those of ``rows`` (or
``dx``), into which numba compiles each function (:mod:`footzoo.kernels.functions`);
:func:`convention` gives it in Python. A function that takes anything but this
contract's parameters is refused with a :class:`~footzoo.core.errors.PluginError`.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..core.errors import PluginError
from ..kernels.functions import NotCompilable, compile_model_function
from ..kernels.jit import njit

#: Offsets in ``nav``: quaternion, position, velocity, gyro bias, accelerometer bias.
Q, P, V, BG, BA = 0, 4, 7, 10, 13
NAV_SIZE = 16
#: Positions in ``idx`` of the core blocks' offsets; a correction's own blocks follow from ``OWN``.
ATT, GYRO_BIAS, POS, VEL, ACC_BIAS, OWN = 0, 1, 2, 3, 4, 5
CORE_BLOCKS = ("att", "gyro_bias", "pos", "vel", "acc_bias")


class Context(NamedTuple):
    """One sample as a correction's functions see it (the fields are described in the module docstring)."""

    k: int
    t: float
    nav: np.ndarray
    w: np.ndarray
    f: np.ndarray
    stance: bool
    idx: np.ndarray
    par: np.ndarray
    mem: np.ndarray
    data: np.ndarray


class Rows(NamedTuple):
    """The buffers a ``measure`` function writes its rows into, from row ``m`` on (see the module docstring)."""

    z: np.ndarray
    H: np.ndarray
    R: np.ndarray
    m: int


#: The parameters of each function of a measurement model.
PARAMETERS = {"measure": ("ctx", "rows"), "feedback": ("ctx", "dx"), "after": ("ctx",)}


def convention(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """The engine's calling convention for ``fn``: a function of the positional arguments that calls ``fn``.

    The arguments are the fields of :class:`Context`, then those of :class:`Rows` (``measure``) or
    ``dx`` (``feedback``). Plain Python; :mod:`footzoo.kernels.functions` compiles ``fn`` into it.
    """
    if role == "measure":
        def measure(k, t, nav, w, f, stance, idx, par, mem, data, z, H, R, m):
            return fn(Context(k, t, nav, w, f, stance, idx, par, mem, data), Rows(z, H, R, m))

        return measure
    if role == "feedback":
        def feedback(k, t, nav, w, f, stance, idx, par, mem, data, dx):
            fn(Context(k, t, nav, w, f, stance, idx, par, mem, data), dx)

        return feedback

    def after(k, t, nav, w, f, stance, idx, par, mem, data):
        fn(Context(k, t, nav, w, f, stance, idx, par, mem, data))

    return after


def check_parameters(fn: Callable[..., Any], role: str) -> None:
    """Raise :class:`~footzoo.core.errors.PluginError` unless ``fn`` takes this contract's parameters for ``role``."""
    py = getattr(fn, "py_func", fn)
    names = PARAMETERS[role]
    try:
        params = [p for p in inspect.signature(py).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):  # no signature to read: taken as this contract's
        return
    if len(params) != len(names):
        where = f"{getattr(py, '__module__', '?')}.{getattr(py, '__qualname__', py)}"
        raise PluginError(f"{role} function {where} takes {len(params)} argument(s); a {role} function takes "
                          f"({', '.join(names)}): see footzoo.filters.measurement for what they hold")


def _compile(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """``fn`` compiled to the engine's calling convention for ``role`` (:mod:`footzoo.kernels.functions`)."""
    if isinstance(fn, ModelFunction):
        return fn.compiled()
    if getattr(fn, "footzoo_convention", None) == role:  # already compiled to it
        return fn
    check_parameters(fn, role)
    return _compiled_convention(fn, role)


def _compiled_convention(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """``fn`` compiled into :func:`convention`."""
    compiled = compile_model_function(fn, role, lambda g: convention(g, role))
    with contextlib.suppress(AttributeError, TypeError):  # a plain function without numba: marked as well
        compiled.footzoo_convention = role
    return compiled


#: The attributes of numba's dispatcher a :class:`ModelFunction` hands on (compiling itself first).
DISPATCHER_ATTRIBUTES = frozenset({
    "signatures", "nopython_signatures", "overloads", "targetoptions", "stats", "get_compile_result", "get_overload",
    "inspect_types", "inspect_llvm", "inspect_asm", "inspect_cfg", "get_call_template", "typeof_pyval",
})


class ModelFunction:
    """A measurement model's function, compiled to the engine's calling convention at its first use.

    Calling it runs the function as written (``measure(ctx, rows)``...), in Python. Asking for
    :meth:`compiled`, or for one of numba's dispatcher attributes of :data:`DISPATCHER_ATTRIBUTES`
    (``signatures``, ``targetoptions``, ...), compiles it into the calling convention (or loads it from
    numba's cache); :func:`calling` gives what the engines call. Nothing is imported or compiled before:
    importing a correction's module stays cheap, and so does looking at the function (``hasattr``, ``dir``,
    a test collector's or a documentation tool's probes: any other name is an ``AttributeError`` at once).
    """

    def __init__(self, fn: Callable[..., Any], role: str):
        functools.update_wrapper(self, fn)
        check_parameters(fn, role)
        self.py_func = fn
        self.role = role
        self._dispatcher: Any = None
        self._error: str | None = None

    def compiled(self) -> Any:
        """numba's dispatcher of the calling convention (compiled once); raises :class:`NotCompilable` with the
        reason (tried once)."""
        if self._dispatcher is None:
            if self._error is not None:
                raise NotCompilable(self._error)
            try:
                self._dispatcher = _compiled_convention(self.py_func, self.role)
            except NotCompilable as err:
                self._error = str(err)
                raise
        return self._dispatcher

    def conventional(self) -> Callable[..., Any]:
        """The calling convention: compiled, or in Python where it does not compile (the reference engine's)."""
        try:
            return self.compiled()
        except NotCompilable:
            return convention(self.py_func, self.role)

    def __call__(self, *args: Any) -> Any:
        return self.py_func(*args)

    def __getattr__(self, name: str) -> Any:
        if name not in DISPATCHER_ATTRIBUTES:  # a probe of an attribute it does not have: no compile for it
            raise AttributeError(f"footzoo model function has no attribute {name!r}")  # no repr: it reads attributes
        return getattr(self.compiled(), name)

    def __repr__(self) -> str:
        return f"<footzoo {self.role} function {self.py_func.__module__}.{self.py_func.__qualname__}>"


def calling(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    """``fn`` as the engines call it: a function of the calling convention's positional arguments.

    A function marked with :func:`measurement_function` (or its siblings) compiled, where it compiles;
    an unmarked one in Python.
    """
    if isinstance(fn, ModelFunction):
        return fn.conventional()
    if getattr(fn, "footzoo_convention", None) == role:
        return fn
    check_parameters(fn, role)
    return convention(fn, role)


def _lazy(fn: Callable[..., Any], role: str) -> Callable[..., Any]:
    if isinstance(fn, ModelFunction):
        return fn
    return ModelFunction(fn, role)


def measurement_function(fn: Callable[..., int]) -> Callable[..., int]:
    """Mark a ``measure(ctx, rows)`` function for compilation to the engine's calling convention.

    Use as a decorator in a correction's module (without numba the engines run it in Python). The
    function is compiled at its first use by the engine's compiled loop (or :meth:`ModelFunction.compiled`),
    not when the module is imported; calling it runs it as written, in Python. A function that
    creates no array is compiled without numba's reference counting (cheaper calls from the
    compiled loop). A function that does not compile raises :class:`NotCompilable` with numba's
    reason at its first use; the engine then runs the reference loop under ``engine="auto"``
    (leave the decorator off to get there without trying).
    """
    return _lazy(fn, "measure")


def feedback_function(fn: Callable[..., None]) -> Callable[..., None]:
    """Mark a ``feedback(ctx, dx)`` function for compilation to the engine's calling convention."""
    return _lazy(fn, "feedback")


def after_function(fn: Callable[..., None]) -> Callable[..., None]:
    """Mark an ``after(ctx)`` function for compilation to the engine's calling convention."""
    return _lazy(fn, "after")


def _no_rows(ctx, rows):  # noqa: ARG001 - the signature is the contract
    return rows.m


def _no_feedback(ctx, dx):  # noqa: ARG001
    return None


def _no_after(ctx):  # noqa: ARG001
    return None


NO_MEASURE = measurement_function(_no_rows)
NO_FEEDBACK = feedback_function(_no_feedback)
NO_AFTER = after_function(_no_after)


def is_no_op(fn: Any) -> bool:
    """Whether ``fn`` is :data:`NO_FEEDBACK` or :data:`NO_AFTER`, compiled or not (the engine skips its calls)."""
    return any(fn is f or fn is getattr(f, "_dispatcher", None) for f in (NO_FEEDBACK, NO_AFTER))


@dataclass
class StateBlock:
    """An error-state block a correction adds (or a core bias block it switches on).

    Parameters
    ----------
    name : str
        Block name; ``gyro_bias`` and ``acc_bias`` enable the core bias blocks, any other name
        is the correction's own.
    size : int
        Number of states.
    initial_variance : float
        Initial variance of each state (unit² of the state).
    noise : float
        Variance growth per second of each state (unit²/s).
    """

    name: str
    size: int
    initial_variance: float
    noise: float = 0.0


@dataclass
class MeasurementModel:
    """What a Kalman correction hands the engine (see the module docstring for the function contract).

    Attributes
    ----------
    measure, feedback, after : callable
        The model's functions.
    max_rows : int
        Most rows ``measure`` writes at one sample.
    par : (p,) ndarray
        Constants.
    mem : (s,) ndarray
        Initial memory (the engine works on a copy).
    data : (N, d) ndarray
        Per-sample inputs, one row per sample (``d`` may be 0).
    block_names : list of str
        The correction's own blocks, in ``idx`` order after the core ones.
    diagnostics : callable, optional
        ``diagnostics(mem) -> dict`` of results to keep in ``Result.diagnostics`` after the run.
    """

    measure: Callable[..., int]
    max_rows: int
    par: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mem: np.ndarray = field(default_factory=lambda: np.zeros(0))
    data: np.ndarray | None = None
    feedback: Callable[..., None] = NO_FEEDBACK
    after: Callable[..., None] = NO_AFTER
    block_names: list[str] = field(default_factory=list)
    diagnostics: Callable[[np.ndarray], dict[str, Any]] | None = None

    def compiled(self) -> MeasurementModel:
        """The same model with its functions compiled; raises :class:`NotCompilable` with the reason."""
        return MeasurementModel(
            measure=_compile(self.measure, "measure"), max_rows=self.max_rows, par=self.par, mem=self.mem,
            data=self.data, feedback=_compile(self.feedback, "feedback"), after=_compile(self.after, "after"),
            block_names=self.block_names, diagnostics=self.diagnostics,
        )


#: ``Fault.rows`` of a model that wrote a row no update can use: ``BAD_ROW + ROWS_PER_PROBLEM * problem + row``
#: (never a row count); the problems are :data:`ROW_PROBLEMS`' keys.
BAD_ROW = 1 << 40
ROWS_PER_PROBLEM = 1 << 20
#: What :func:`row_problem`'s codes mean, as the error names them.
ROW_PROBLEMS = {
    1: "R (the row's measurement variance) that is not a positive number",
    2: "R that is NaN or infinite",
    3: "z (the residual) that is NaN or infinite",
    4: "H (the measurement matrix) with a NaN or infinite entry",
}


@njit(inline=True)
def row_problem(z: np.ndarray, H: np.ndarray, R: np.ndarray, m0: int, m1: int) -> tuple[int, int]:
    """The first row of ``m0 … m1 − 1`` no Kalman update can use and its problem (a key of :data:`ROW_PROBLEMS`);
    ``(0, -1)`` when every row is usable."""
    for i in range(m0, m1):
        r = R[i]
        if not math.isfinite(r):
            return 2, i
        if r <= 0.0:
            return 1, i
        if not math.isfinite(z[i]):
            return 3, i
        for c in range(H.shape[1]):
            if not math.isfinite(H[i, c]):
                return 4, i
    return 0, -1


@njit(inline=True)
def row_fault(problem: int, row: int) -> int:
    """``Fault.rows`` for ``problem`` in ``row`` (see :data:`BAD_ROW`)."""
    return BAD_ROW + ROWS_PER_PROBLEM * problem + row


@njit(inline=True)
def gated_row(rows, column: int, d: float, threshold: float, std: float) -> int:
    """A heuristic's scalar row: ``z = d`` on state ``column`` with ``R = std²`` when ``|d| ≤ threshold`` (a larger
    change is taken as real, not drift: HDR's gate, Nguyen & La 2016, eq. 24); the next free row either way.
    Usable inside compiled measurement functions."""
    z, H, R, m = rows
    if abs(d) > threshold:
        return m
    H[m, column] = 1.0
    z[m] = d
    R[m] = std * std
    return m + 1


@njit(inline=True)
def stance_ended(ctx, was_stance: int) -> bool:
    """In an ``after`` function: whether this sample is the first after a stance, ``ctx.mem[was_stance]`` holding
    whether the previous sample was stance (0/1); that entry is then set to this sample's."""
    ended = ctx.mem[was_stance] != 0.0 and not ctx.stance and ctx.k > 1
    ctx.mem[was_stance] = 1.0 if ctx.stance else 0.0
    return ended


@njit(inline=True)
def yaw_of(nav: np.ndarray) -> float:
    """Z-Y-X heading of ``nav``'s attitude (rad); usable inside compiled measurement functions."""
    w, x, y, z = nav[Q], nav[Q + 1], nav[Q + 2], nav[Q + 3]
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))

