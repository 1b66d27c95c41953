"""The compiled implementation of the Kalman engine: the loop of :mod:`footzoo.filters.forward`, called directly.

Each smoother runs the one forward loop with its own recorder (:mod:`footzoo.filters.recorders`),
chosen by the smoother's type (:data:`CompiledEngine.RUNS`):

* ``none``: no recorder;
* ``stepwise``: a :class:`~footzoo.filters.structures.SegmentRecord`, each stride smoothed by the loop
  as soon as it has closed (while its record is in the processor's cache), the last one after;
* ``rts``: a :class:`~footzoo.filters.structures.CheckpointRecord`, then the backward pass of
  :mod:`footzoo.filters.checkpointed` in bounded memory.

The loop is called through :func:`footzoo.kernels.functions.direct`: its arguments (tuples of the
models' compiled functions among them) are typed when their types change, not at every call.

numba compiles the loop once per type of its arguments, and a tuple of functions is typed by its
length: the models' functions are padded with no-op functions to :func:`slots` of them (the loop calls
only the models' own), so that configs of one and of two corrections run one compiled loop per
recorder, instead of two (about 12 s of compiling each).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..core.data import writable_array
from ..kernels.functions import capture_faults, direct, fixed_address
from . import checkpointed, forward, recorders
from .implementation import TRAJECTORY, Implementation, Setup, model_fault
from .measurement import BA, BG, NO_AFTER, NO_FEEDBACK, NO_MEASURE, is_no_op
from .smoothing import NoSmoothing, Rts, Smoothing, Stepwise
from .stepwise import smooth_copy
from .structures import (
    Core,
    FilterState,
    ForwardPass,
    FreeSpanWork,
    ModelArrays,
    ModelFunctions,
    Models,
    Outputs,
    Signals,
    Trajectory,
    Workspace,
)


def slots(n_models: int) -> int:
    """How many functions of each role the loop is given for ``n_models`` models: the next power of two, at least 2."""
    return max(2, 1 << max(n_models - 1, 0).bit_length())


@dataclasses.dataclass
class CompiledState:
    """The compiled engine's state between chunks: the filter's, the models' arrays (without their per-sample
    inputs), the loop's buffers and the loop as this state calls it."""

    filter: FilterState
    arrays: ModelArrays
    work: Workspace
    loop: Any


class CompiledEngine(Implementation):
    """The compiled loop (module docstring)."""

    name = "fast"

    def __init__(self, setup: Setup):
        super().__init__(setup)
        models = setup.models
        self.core = Core(setup.offsets, setup.noise, setup.gravity, not setup.carries_attitude, setup.m_max)
        pad = slots(len(models)) - len(models)
        self.functions = ModelFunctions(
            tuple(fixed_address(f) for f in [*(m.measure for m in models), *[NO_MEASURE.compiled()] * pad]),
            tuple(fixed_address(f) for f in [*(m.feedback for m in models), *[NO_FEEDBACK.compiled()] * pad]),
            tuple(fixed_address(f) for f in [*(m.after for m in models), *[NO_AFTER.compiled()] * pad]))
        self.RUNS = {NoSmoothing: self._run_forward, Stepwise: self._run_stepwise, Rts: self._run_rts}

    # ------------------------------------------------------------------ state
    def start(self, nav0: np.ndarray) -> CompiledState:
        s, models = self.setup, self.setup.models
        width = max((len(i) for i in s.idx), default=0)
        idx = np.full((len(models), width), -1, dtype=np.int64)
        for j, ix in enumerate(s.idx):
            idx[j, : len(ix)] = ix
        par = np.concatenate([np.asarray(m.par, float).ravel() for m in models] + [np.zeros(0)])
        mems = np.concatenate([np.asarray(m.mem, float).ravel() for m in models] + [np.zeros(0)])
        widths = [0 if m.data is None else m.data.shape[1] for m in models]
        arrays = ModelArrays(idx, par, _offsets([np.asarray(m.par).size for m in models]),
                             _offsets([np.asarray(m.mem).size for m in models]), np.zeros((0, 0)), _offsets(widths),
                             np.array([not is_no_op(m.feedback) for m in models], dtype=np.bool_),
                             np.array([not is_no_op(m.after) for m in models], dtype=np.bool_),
                             np.array([int(m.max_rows) for m in models], dtype=np.int64))
        state = FilterState(np.array(nav0, float), np.diag(s.p0).astype(float), mems)
        return CompiledState(state, arrays, recorders.workspace(s.layout.n, s.m_max), direct(forward.run))

    def fork(self, state: CompiledState) -> CompiledState:
        f = state.filter
        return CompiledState(FilterState(f.nav.copy(), f.P.copy(), f.mems.copy()), state.arrays,
                             recorders.workspace(self.setup.layout.n, self.setup.m_max), direct(forward.run))

    def memories(self, state: CompiledState) -> list[np.ndarray]:
        off = state.arrays.mem_off
        return [state.filter.mems[off[j]:off[j + 1]] for j in range(len(self.setup.models))]

    # ------------------------------------------------------------------ chunks
    def advance(self, state: CompiledState, t, acc, gyr, stance, quat_ext, data, k0: int, covariance: bool,
                record: bool) -> dict[str, np.ndarray]:
        n = len(t)
        out = self.outputs(n, covariance)
        rec = recorders.record(n, self.setup.layout.n, self.setup.m_max) if record else None
        self.step(state, signals(t, acc, gyr, stance, quat_ext), stack_data(data, n), out, k0, rec)
        if rec is not None:
            per_sample, per_row = recorders.columns(rec, n, int(rec.first[-1] + rec.count[-1]))
            out.update(per_sample, **per_row)
        return out

    def step(self, state: CompiledState, sig: Signals, data: np.ndarray, out: dict[str, np.ndarray], k0: int,
             recorder: Any) -> None:
        """The loop over a chunk from ``state`` into ``out`` (a dict of :meth:`outputs`), keeping ``recorder``.

        A model function that breaks its contract inside the loop (a row count it did not declare,
        or a write outside its arrays, which a plug-in's bounds-checked code turns into an exception)
        is raised here as that correction's :class:`~footzoo.core.errors.PluginError`.
        """
        models = Models(self.functions, state.arrays._replace(data=data))
        with capture_faults() as caught:
            state.loop(sig, self.core, state.filter, models, as_outputs(out), k0, state.work, recorder)
        self.raise_fault(state.work, caught)
        self.constant_biases(state, out)

    def outputs(self, n: int, covariance: bool) -> dict[str, np.ndarray]:
        """Empty per-sample outputs, ``n`` rows (``P_diag``, ``nis``: only with ``covariance``)."""
        nx = self.setup.layout.n
        return {"quat": np.empty((n, 4)), "vel": np.empty((n, 3)), "pos": np.empty((n, 3)),
                "acc_nav": np.empty((n, 3)), "gyro_bias": np.zeros((n, 3)), "acc_bias": np.zeros((n, 3)),
                "P_diag": np.empty((n if covariance else 0, nx)), "nis": np.zeros(n if covariance else 0),
                "nis_rows": np.zeros(n if covariance else 0, np.int64)}

    def constant_biases(self, state: CompiledState, out: dict[str, np.ndarray]) -> None:
        """A bias without its error-state block: the loop leaves its output at 0; it is the state's (constant) value."""
        nav = state.filter.nav
        for key, at in (("gyro_bias", BG), ("acc_bias", BA)):
            if not self.setup.layout.has(key) and np.any(nav[at:at + 3]):
                out[key][:] = nav[at:at + 3]

    # ------------------------------------------------------------------ whole recordings
    def run(self, t, acc, gyr, stance, q0, quat_ext, covariance: bool, smoothing: Smoothing) -> dict[str, Any]:
        state = self.start(self.initial_nav(q0, quat_ext))
        sig = signals(t, acc, gyr, stance, quat_ext)
        data = stack_data([m.data for m in self.setup.models], len(t))
        out = self.outputs(len(t), covariance)
        self.RUNS[type(smoothing)](state, sig, data, out)
        out["diagnostics"] = self.diagnostics(state)
        return out

    def _run_forward(self, state: CompiledState, sig: Signals, data: np.ndarray, out: dict[str, np.ndarray]) -> None:
        self.step(state, sig, data, out, 0, None)

    def _run_stepwise(self, state: CompiledState, sig: Signals, data: np.ndarray, out: dict[str, np.ndarray]) -> None:
        """The step-wise smoother in the loop: each stride smoothed as it closes, the last one after the loop."""
        n = len(sig.t)
        ends = Stepwise().ends(sig.stance, sig.t, True)
        longest = int(np.max(np.diff(ends, prepend=-1))) if ends.size else max(n, 1)
        rec = recorders.segment_record(longest, self.setup.layout.n, self.setup.m_max, n)
        self.step(state, sig, data, out, 0, rec)
        lo = int(rec.record.offset[0])
        smooth_copy(rec.record, rec.smoothed, lo, n - 1, lo, self.core.offsets, self.core.use_ext, trajectory(out),
                    sig.t, rec.work)
        self.keep_forward(out, rec.smoothed)

    def _run_rts(self, state: CompiledState, sig: Signals, data: np.ndarray, out: dict[str, np.ndarray]) -> None:
        """RTS over the whole recording in bounded memory (:mod:`footzoo.filters.checkpointed`)."""
        nx, n_mem = self.setup.layout.n, state.filter.mems.size
        recorder = checkpointed.checkpoint_record(sig.stance, nx, n_mem, checkpointed.BLOCK, checkpointed.MIN_GAP)
        self.step(state, sig, data, out, 0, recorder)
        for key in ("quat", "vel", "pos"):
            out[f"{key}_forward"] = out[key].copy()
        spans = checkpointed.pieces(recorder, len(sig.t))
        rows = checkpointed.BLOCK + 1
        rec = checkpointed.replay_record(nx, self.setup.m_max, rows)
        scratch = self.start(np.zeros(16))  # each piece from a copy of its checkpoint
        scratch.arrays = state.arrays
        models = Models(self.functions, state.arrays._replace(data=data))
        replay = direct(checkpointed.replay)

        def run(j0: int, j1: int) -> None:
            with capture_faults() as caught:
                replay(sig, self.core, scratch.filter, models, 0, scratch.work, rec, recorder.checkpoints, spans,
                       j0, j1)
            self.raise_fault(scratch.work, caught)

        fwd = ForwardPass(sig.t, out["quat_forward"], out["acc_nav"], sig.acc)
        work = FreeSpanWork(np.empty((rows, nx)), recorders.transitions(rows), np.empty(nx), np.empty(nx),
                            np.empty((3, 3)))
        lam = np.zeros(nx)  # λ carried from piece to piece, zero after the last sample
        smoothed = trajectory(out)

        def smooth(j0: int, j1: int) -> None:
            checkpointed.smooth_pieces(rec, spans, j0, j1, lam, fwd, self.core.noise, self.core.gravity,
                                       self.core.offsets, self.core.use_ext, smoothed, work)

        checkpointed.backward(run, spans, smooth, rows)

    def keep_forward(self, out: dict[str, np.ndarray], smoothed: Trajectory) -> None:
        """The smoothed trajectory into ``out``, the forward ``quat``, ``vel``, ``pos`` kept as ``*_forward``."""
        for key, value in zip(TRAJECTORY, smoothed, strict=True):
            if key in ("quat", "vel", "pos"):
                out[f"{key}_forward"] = out[key]
                out[key] = value
            elif self.setup.layout.has(key):  # a bias without its block stays the forward (constant) value
                out[key] = value

    # ------------------------------------------------------------------ faults
    def raise_fault(self, work: Workspace, caught: list[BaseException]) -> None:
        """Raise a model's fault the loop recorded in ``work`` or an exception caught in its functions."""
        fault = work.fault
        if fault.model[0] >= 0 or caught:
            raise model_fault(self.setup, int(fault.model[0]), int(fault.rows[0]), int(fault.sample[0]), caught,
                              "the compiled Kalman loop")


def _offsets(sizes: list[int]) -> np.ndarray:
    """Where each of consecutive parts of these sizes starts, and the end: (len + 1,) int."""
    return np.cumsum([0, *sizes]).astype(np.int64)


def signals(t, acc, gyr, stance, quat_ext) -> Signals:
    """The loop's :class:`~footzoo.filters.structures.Signals` (contiguous, writable float and bool arrays)."""
    ext = writable_array(quat_ext, float) if quat_ext is not None else np.zeros((1, 4))
    return Signals(writable_array(t, float), writable_array(acc, float), writable_array(gyr, float),
                   writable_array(stance, np.bool_), ext)


def stack_data(datas: list[np.ndarray | None], n: int) -> np.ndarray:
    """The models' per-sample inputs side by side, (n, Σd)."""
    cols = [d for d in datas if d is not None and d.shape[1]]
    return np.ascontiguousarray(np.hstack(cols), dtype=float) if cols else np.zeros((n, 0))


def trajectory(out: dict[str, np.ndarray]) -> Trajectory:
    """The :class:`~footzoo.filters.structures.Trajectory` of a dict of outputs (the same arrays)."""
    return Trajectory(*(out[k] for k in TRAJECTORY))


def as_outputs(out: dict[str, np.ndarray]) -> Outputs:
    """The loop's :class:`~footzoo.filters.structures.Outputs` of a dict of outputs (the same arrays)."""
    return Outputs(trajectory(out), out["acc_nav"], out["P_diag"], out["nis"], out["nis_rows"])
