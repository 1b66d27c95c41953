"""The error-state Kalman engine: state layout, measurement models, compiled or reference loop.

The engine takes what the plug-ins hand it — whether the attitude is a filter state, the
corrections' :class:`~footzoo.filters.measurement.StateBlock` lists and
:class:`~footzoo.filters.measurement.MeasurementModel` objects — and the INS core's noise
(:class:`NavigationNoise`). It knows no plug-in by name. ``engine="fast"`` runs the compiled
loop, ``"reference"`` the filterpy loop, ``"auto"`` the compiled one when every model compiles
(else the reference, with a one-line warning saying which model and why).
"""

from __future__ import annotations

import copy
import dataclasses
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.checks import Settings
from ..core.data import writable_array
from ..core.errors import ConfigError, FootzooWarning, PluginError
from ..core.params import Real
from ..kernels import jit as _jit
from ..kernels.functions import bind, capture_faults, fixed_address, trusted
from .eskf import ErrorStateFilter, Layout
from .measurement import BA, BG, CORE_BLOCKS, MeasurementModel, NotCompilable, StateBlock, is_no_op
from .smoother import RECORD_KEYS, ROWS_KEY, record_tuple
from .stepwise import segment_ends

ENGINES = ("auto", "fast", "reference")
# the compiled loop takes the models' functions as first-class function values, which numba marks
# "experimental" (stable since numba 0.53 for functions with an explicit signature, as here)
warnings.filterwarnings("ignore", message=".*First-class function type feature is experimental")


@dataclass
class NavigationNoise(Settings):
    """Process noise and initial uncertainty of the INS core of the error-state filter.

    Set in a pipeline's YAML under ``navigation:``, whatever the orientation source. Nguyen &
    La 2016 (Sec. VI) set ``Q = diag(1e-4·I, 0, 0, 1e-4·I, 0)`` per sample; at the 100 Hz
    their sample counts assume that is 0.01 per second for attitude (rad²) and velocity
    ((m/s)²) — the defaults. Duong & Suh 2015 (Table 1) give per-sample sensor variances;
    their config converts them.

    Parameters
    ----------
    attitude_noise : float
        Attitude error variance growth (rad²/s); used when the attitude is a filter state.
    velocity_noise : float
        Velocity error variance growth ((m/s)²/s).
    position_noise : float
        Position error variance growth (m²/s); paper: 0.
    initial_attitude_std : float
        Standard deviation of the initial attitude error (rad).
    initial_velocity_std : float
        Standard deviation of the initial velocity error (m/s); the start is still: 0.
    initial_position_std : float
        Standard deviation of the initial position error (m); the origin is the start: 0.
    impact_noise : float
        Velocity error variance growth per squared motion acceleration (s, i.e. ((m/s)²/s) per
        (m/s²)²): each velocity axis grows by ``(velocity_noise + impact_noise·|a|²)·dt``, with
        ``a`` the NED motion acceleration of the sample. Accelerometer scale-factor, misalignment
        and clipping errors grow with the acceleration, most at the heel strike (footzoo's; a
        white-noise stand-in for them; 0, the default: uniform in time, as in the papers).
    integration_noise : float
        κ (1): each velocity axis of sample k grows by ``(κ·|f_k − f_{k−1}|·dt)²``, ``f`` the
        specific force as sampled: a change of the specific force at an unknown instant within
        the interval, which a heel strike shorter than the interval makes on an accelerometer
        that is not band-limited below the Nyquist rate; 1/√12 ≈ 0.29 when that instant is
        uniform in the interval (:mod:`footzoo.filters.velocity_noise`). 0, the default: the
        samples resolve the motion, as the papers assume.
    """

    attitude_noise: float = 0.01
    velocity_noise: float = 0.01
    position_noise: float = 0.0
    initial_attitude_std: float = 0.01
    initial_velocity_std: float = 0.0
    initial_position_std: float = 0.0
    impact_noise: float = 0.0
    integration_noise: float = 0.0

    section = "navigation"
    example = "{velocity_noise: 0.01}"
    parameters = {
        "attitude_noise": Real("rad^2/s", "[0, 1]", "attitude error variance growth",
                               source="Nguyen & La 2016, Sec. VI: 1e-4 per sample at 100 Hz"),
        "velocity_noise": Real("(m/s)^2/s", "[0, 100]", "velocity error variance growth",
                               source="Nguyen & La 2016, Sec. VI: 1e-4 per sample at 100 Hz"),
        "position_noise": Real("m^2/s", "[0, 100]", "position error variance growth", source="Nguyen & La 2016: 0"),
        "initial_attitude_std": Real("rad", "[0, pi]", "σ of the initial attitude error",
                                     source="footzoo's: 0.57° after the still-start alignment"),
        "initial_velocity_std": Real("m/s", "[0, 10]", "σ of the initial velocity error",
                                     source="the start is still: 0"),
        "initial_position_std": Real("m", "[0, 100]", "σ of the initial position error",
                                     source="the origin is the start: 0"),
        "impact_noise": Real("s", "[0, 0.01]", "velocity variance growth per squared motion acceleration",
                             source="footzoo's: 0 (uniform in time, as in the papers)",
                             why="0.01 s: at a heel strike's 100 m/s² that is 100 (m/s)²/s"),
        "integration_noise": Real("1", "[0, 1]", "velocity σ per sample per |Δf|·dt (an impact the samples do not "
                                  "resolve)", source="footzoo's: 0 (the samples resolve the motion, as in the papers); "
                                  "1/√12 ≈ 0.29: the change at a uniform instant within the interval",
                                  why="1: the whole change |Δf|·dt of one interval as one σ"),
    }


def assemble(carries_attitude: bool, blocks: list[StateBlock], noise: NavigationNoise):
    """Error-state layout, initial variances and variance growth per second.

    Order (Nguyen & La eq. 31): ``att`` (when the filter carries the attitude), ``gyro_bias``,
    ``pos``, ``vel``, ``acc_bias`` (each bias only when a correction switches it on), then the
    corrections' own blocks in the order they are listed.
    """
    core: dict[str, StateBlock] = {}
    extra: list[StateBlock] = []
    for b in blocks:
        if b.name in ("gyro_bias", "acc_bias"):
            if b.size != 3:
                raise ConfigError(f"state block {b.name!r} has 3 states, a correction declared {b.size}")
            core.setdefault(b.name, b)
        elif b.name in CORE_BLOCKS:
            raise ConfigError(f"state block {b.name!r} belongs to the INS core; name a correction's block otherwise")
        else:
            extra.append(b)
    order: list[StateBlock] = []
    if carries_attitude:
        order.append(StateBlock("att", 3, noise.initial_attitude_std**2, noise.attitude_noise))
    if "gyro_bias" in core:
        order.append(core["gyro_bias"])
    order.append(StateBlock("pos", 3, noise.initial_position_std**2, noise.position_noise))
    order.append(StateBlock("vel", 3, noise.initial_velocity_std**2, noise.velocity_noise))
    if "acc_bias" in core:
        order.append(core["acc_bias"])
    order += extra
    layout = Layout([(b.name, b.size) for b in order])
    p0 = np.concatenate([np.full(b.size, float(b.initial_variance)) for b in order])
    q = np.concatenate([np.full(b.size, float(b.noise)) for b in order])
    return layout, p0, q


def block_offsets(layout: Layout, own: list[str]) -> np.ndarray:
    """``idx`` of one model: the core blocks' offsets (−1 if absent), then its own blocks'."""
    names = list(CORE_BLOCKS) + list(own)
    return np.array([layout[b].start if layout.has(b) else -1 for b in names], dtype=np.int64)


@dataclass
class Packed:
    """Everything the compiled loop needs besides the signals; carried between stream steps."""

    core: tuple
    nav: np.ndarray
    P: np.ndarray
    mems: np.ndarray
    functions: tuple
    arrays: tuple
    bound: Any = None  # the compiled loop with the functions bound in (live use): see KalmanEngine.live
    work: tuple | None = None  # the loop's buffers (kalman_fast.scratch), allocated at the first step


class KalmanEngine:
    """One error-state filter run (or stream) over a recording.

    Parameters
    ----------
    carries_attitude : bool
        The attitude error is a state (INS orientation); otherwise ``quat_ext`` is used.
    blocks : list of StateBlock
        All blocks the corrections declare, in order.
    models : list of MeasurementModel
        The corrections' measurement models, in stacking order.
    own_blocks : list of list of str
        Each model's own block names.
    noise : NavigationNoise
        INS core noise.
    gravity : float
        g (m/s²).
    engine : {"auto", "fast", "reference"}
        Which loop.
    """

    def __init__(self, carries_attitude: bool, blocks: list[StateBlock], models: list[MeasurementModel],
                 noise: NavigationNoise, gravity: float, engine: str = "auto", names: list[str] | None = None):
        if engine not in ENGINES:
            raise ConfigError(f"engine must be one of {list(ENGINES)}, got {engine!r}")
        self.layout, self.p0, self.q = assemble(carries_attitude, blocks, noise)
        self.impact = float(noise.impact_noise)
        self.integration = float(noise.integration_noise)
        self.carries_attitude = carries_attitude
        self.gravity = float(gravity)
        self.names = names or [f"correction {i}" for i in range(len(models))]
        self.idx = [block_offsets(self.layout, m.block_names) for m in models]
        self.models = models
        self.engine = self._choose(engine)

    def _choose(self, engine: str) -> str:
        if engine == "reference":
            return engine
        compiled = []
        for name, m in zip(self.names, self.models, strict=True):
            try:
                compiled.append(m.compiled())
            except NotCompilable as err:
                if engine == "fast":
                    raise ConfigError(f"engine='fast': {name} cannot be compiled ({err}); use engine='reference' "
                                      "or make its measurement functions numba-compilable") from None
                warnings.warn(f"{name}: measurement model not compilable ({err}); running the reference engine",
                              FootzooWarning, stacklevel=4)
                return "reference"
        self.models = compiled
        return "fast"

    # ------------------------------------------------------------------ runs
    def run(self, t, acc, gyr, stance, q0, quat_ext=None, covariance: bool = True,
            smoother: bool | str = False) -> dict[str, Any]:
        """Filter a whole recording; returns the trajectories and each model's diagnostics.

        With ``smoother`` (``"rts"`` or True: :mod:`footzoo.filters.smoother`, in bounded memory with
        the compiled loop, :mod:`footzoo.filters.checkpointed`; ``"stepwise"``:
        :mod:`footzoo.filters.stepwise`) the trajectories are the smoothed ones and the forward
        pass's are kept as ``quat_forward``, ``vel_forward``, ``pos_forward``.
        """
        smoother = {True: "rts", False: "none"}.get(smoother, smoother)
        nav0 = np.zeros(16)
        nav0[:4] = quat_ext[0] if quat_ext is not None else q0
        state = self.start(nav0)
        in_loop = smoother == "stepwise" and self.engine != "reference"  # the loop smooths each stride as it closes
        checkpointed = smoother == "rts" and self.engine != "reference"  # RTS in bounded memory
        datas = [m.data for m in self.models]
        if checkpointed:
            out = self.outputs(len(t), covariance)
            self.smooth_checkpointed(state, t, acc, gyr, stance, quat_ext, self.stack_data(datas, len(t)), out)
            self._constant_biases(state, out)
        else:
            record = self._whole_recording_record(state, stance, t) if in_loop else smoother != "none"
            out = self.advance(state, t, acc, gyr, stance, quat_ext, datas, 0, covariance, record=record)
        out["diagnostics"] = self.diagnostics(state)
        if in_loop:  # every segment but the last is smoothed, into record[6]
            from .stepwise import smooth_copy

            lo = int(record[5][1])
            smooth_copy(record, lo, len(t) - 1, lo, self.core_offsets(), not self.carries_attitude, out["quat"],
                        out["vel"], out["pos"], out["gyro_bias"], out["acc_bias"])
            for key, smoothed in zip(("quat", "vel", "pos", "gyro_bias", "acc_bias"), record[6], strict=True):
                if key in ("quat", "vel", "pos"):
                    out[f"{key}_forward"] = out[key]
                    out[key] = smoothed
                elif self.layout.has(key):  # else the forward value (the state's, constant)
                    out[key] = smoothed
        elif smoother != "none" and not checkpointed:  # the record of every sample (reference loop), after the loop
            for key in ("quat", "vel", "pos"):
                out[f"{key}_forward"] = out[key].copy()
            ends = segment_ends(stance, t, True) if smoother == "stepwise" else np.array([len(t) - 1])
            self.smooth(out, ends)
        for key in ("record", ROWS_KEY, *RECORD_KEYS):
            out.pop(key, None)
        return out

    def _whole_recording_record(self, state: Any, stance: np.ndarray, t: np.ndarray) -> tuple:
        """The step-wise smoother's record for a whole recording, smoothed in the loop: the longest segment's rows."""
        from .smoother import record_arrays

        ends = segment_ends(stance, t, True)
        longest = int(np.max(np.diff(ends, prepend=-1))) if ends.size else max(len(stance), 1)
        return record_arrays(longest, self.layout.n, state.core[4], in_loop=len(stance))

    def core_offsets(self) -> np.ndarray:
        """Offsets of the INS core's blocks (att, gyro_bias, pos, vel, acc_bias; −1 if absent)."""
        return np.array([self.layout[b].start if self.layout.has(b) else -1 for b in CORE_BLOCKS], np.int64)

    def smooth_stepwise(self, rows: dict[str, np.ndarray], stance: np.ndarray, t: np.ndarray, closed: bool) -> int:
        """Step-wise smoothing of the segments that have closed in ``rows`` (in place); how many rows are final.

        ``rows``: per-sample ``quat``, ``vel``, ``pos``, ``gyro_bias``, ``acc_bias`` and the record
        (:meth:`advance` with ``record``; ``record_first`` indexing ``record_rows``), its row 0 the
        first sample after the last segment end, aligned with ``stance`` and ``t`` (s). The segments end where
        :func:`footzoo.filters.stepwise.segment_ends` says (``closed``: the data ends at the last row);
        the rows up to the last end are final. A live stream's stage calls it (the batch run smooths
        in the loop, by the same rule and kernel).
        """
        ends = segment_ends(stance, t, closed)
        if not ends.size:
            return 0
        self.smooth(rows, ends)
        return int(ends[-1]) + 1

    def smooth(self, rows: dict[str, np.ndarray], ends: np.ndarray) -> None:
        """Smooth ``rows`` (as in :meth:`smooth_stepwise`) in place, span by span up to each of ``ends`` (increasing).

        One end at the last row is the RTS smoother over the whole recording
        (:mod:`footzoo.filters.smoother`); the ends of :func:`footzoo.filters.stepwise.segment_ends`
        are the step-wise smoother.
        """
        from .smoother import smooth_segments

        smooth_segments(record_tuple(rows, self.layout.n), np.asarray(ends, np.int64), 0, 0, self.core_offsets(),
                        not self.carries_attitude, rows["quat"], rows["vel"], rows["pos"], rows["gyro_bias"],
                        rows["acc_bias"])

    def start(self, nav0: np.ndarray) -> Any:
        """The filter's state before sample 0 (resumable with :meth:`advance`)."""
        if self.engine == "reference":
            kf = ErrorStateFilter(self.layout, self.p0, self.q, self.impact, self.integration)
            models = [MeasurementModel(**{**m.__dict__, "mem": np.array(m.mem, dtype=float)}) for m in self.models]
            return {"kf": kf, "models": models, "nav": np.array(nav0, dtype=float)}
        return self.pack(nav0)

    def advance(self, state: Any, t, acc, gyr, stance, quat_ext, data: list[np.ndarray | None], k0: int,
                covariance: bool = True, record: bool | tuple = False) -> dict[str, np.ndarray]:
        """Run samples 1… of a chunk from ``state`` (updated); row 0 of the outputs is the incoming state.

        ``record``: also a smoother's record of every row (``record_cov``, ``record_phi``,
        ``record_first``, ``record_count``, ``record_rows``: :func:`footzoo.filters.smoother.record_arrays`),
        or the loop writes into the record given (one the step-wise smoother made ``in_loop``).
        """
        n = len(t)
        if self.engine == "reference":
            from .kalman_reference import ModelFault, run_reference
            from .smoother import record_arrays

            arrays = record_arrays(n, self.layout.n, sum(m.max_rows for m in state["models"])) if record else None
            try:
                out = run_reference(t, acc, gyr, stance, quat_ext, self.layout, state["kf"], state["models"],
                                    self.idx, state["nav"], self.gravity, data, k0, arrays)
            except ModelFault as err:
                raise self.fault(err.j, err.rows, err.k, [err.error] if err.error else []) from err.error
            if record:
                out.update(zip(RECORD_KEYS, (arrays[0], arrays[1], arrays[3], arrays[4]), strict=True))
                out[ROWS_KEY] = arrays[2]
            return out
        out = self.outputs(n, covariance)
        if record is True:
            from .smoother import record_arrays

            cov, phi, rows, first, count, *_ = record_arrays(n, self.layout.n, state.core[4])
            out.update(zip(RECORD_KEYS, (cov, phi, first, count), strict=True))
            out[ROWS_KEY] = rows
        out["record"] = record_tuple(out, self.layout.n) if record is True else record or None
        self.step(state, t, acc, gyr, stance, quat_ext, self.stack_data(data, n), out, k0)
        self._constant_biases(state, out)
        return out

    def outputs(self, n: int, covariance: bool) -> dict[str, np.ndarray]:
        """Empty per-sample outputs of the compiled loop, ``n`` rows (``P_diag``, ``nis``: only with ``covariance``)."""
        nx = self.layout.n
        return {"quat": np.empty((n, 4)), "vel": np.empty((n, 3)), "pos": np.empty((n, 3)),
                "acc_nav": np.empty((n, 3)), "gyro_bias": np.zeros((n, 3)), "acc_bias": np.zeros((n, 3)),
                "P_diag": np.empty((n if covariance else 0, nx)), "nis": np.zeros((n if covariance else 0, 2))}

    def _constant_biases(self, state: Packed, out: dict[str, np.ndarray]) -> None:
        """A bias without its error-state block: the loop leaves its output at 0; it is the state's (constant) value."""
        for key, at in (("gyro_bias", BG), ("acc_bias", BA)):
            if not self.layout.has(key) and np.any(state.nav[at:at + 3]):
                out[key][:] = state.nav[at:at + 3]

    def fork(self, state: Any) -> Any:
        """An independent copy of a state from :meth:`start` (a live stream's guess runs ahead on it)."""
        if self.engine == "reference":
            return copy.deepcopy(state)
        return dataclasses.replace(state, nav=state.nav.copy(), P=state.P.copy(), mems=state.mems.copy())

    def diagnostics(self, state: Any) -> dict[str, Any]:
        """The models' results (e.g. a calibration) from their memory."""
        mems = [m.mem for m in state["models"]] if self.engine == "reference" else self.unpack_mems(state)
        diag: dict[str, Any] = {}
        for m, mem in zip(self.models, mems, strict=True):
            if m.diagnostics is not None:
                diag.update(m.diagnostics(mem))
        return diag

    # -------------------------------------------------------- compiled pieces
    def pack(self, nav0: np.ndarray) -> Packed:
        """Initial state and the models' arrays in the compiled loop's structured form."""
        models = self.models
        core = (np.array([self.layout[b].start if self.layout.has(b) else -1 for b in CORE_BLOCKS], np.int64),
                np.ascontiguousarray(self.q, dtype=float), self.gravity, not self.carries_attitude,
                max(1, sum(m.max_rows for m in models)), self.impact, self.integration)
        width = max(len(i) for i in self.idx)
        m_idx = np.full((len(models), width), -1, dtype=np.int64)
        for j, ix in enumerate(self.idx):
            m_idx[j, : len(ix)] = ix
        par = np.concatenate([np.asarray(m.par, float).ravel() for m in models] + [np.zeros(0)])
        par_off = np.cumsum([0] + [np.asarray(m.par).size for m in models]).astype(np.int64)
        mems = np.concatenate([np.asarray(m.mem, float).ravel() for m in models] + [np.zeros(0)])
        mem_off = np.cumsum([0] + [np.asarray(m.mem).size for m in models]).astype(np.int64)
        widths = [0 if m.data is None else m.data.shape[1] for m in models]
        data_off = np.cumsum([0] + widths).astype(np.int64)
        functions = (tuple(fixed_address(m.measure) for m in models), tuple(fixed_address(m.feedback) for m in models),
                     tuple(fixed_address(m.after) for m in models))
        hooks = np.array([[not is_no_op(m.feedback), not is_no_op(m.after)] for m in models], dtype=np.int64)
        rows = np.array([int(m.max_rows) for m in models], dtype=np.int64)
        arrays = (m_idx, par, par_off, mem_off, data_off, hooks, rows)
        return Packed(core, np.array(nav0, float), np.diag(self.p0).astype(float), mems, functions, arrays)

    @staticmethod
    def stack_data(datas: list[np.ndarray | None], n: int) -> np.ndarray:
        """The models' per-sample inputs side by side, (n, Σd)."""
        cols = [d for d in datas if d is not None and d.shape[1]]
        return np.ascontiguousarray(np.hstack(cols), dtype=float) if cols else np.zeros((n, 0))

    def unpack_mems(self, packed: Packed) -> list[np.ndarray]:
        """Each model's memory after a run."""
        off = packed.arrays[3]
        return [packed.mems[off[j]:off[j + 1]] for j in range(len(self.models))]

    def live(self, state: Any) -> Any:
        """Prepare a state from :meth:`start` for many short :meth:`advance` calls (a live stream).

        Passing the models' functions to the compiled loop costs about a millisecond per call (numba
        types them each time); live, they are bound into a small compiled wrapper once (about a
        second, at the stream's start) and each call passes arrays only.
        """
        if self.engine == "fast" and _jit.HAVE_NUMBA:
            from .kalman_fast import eskf_loop

            state.bound = bind(eskf_loop, state.functions)
        return state

    def step(self, packed: Packed, t, acc, gyr, stance, quat_ext, data, out, k0: int, loop: Any = None) -> None:
        """Run the compiled loop over samples 1… of the given chunk, from ``packed``'s state.

        ``loop``: how to call :func:`~footzoo.filters.kalman_fast.eskf_loop` (a
        :class:`~footzoo.kernels.functions.DirectCall` of it for many calls of the same types; by
        default the kernel itself).

        A model function that breaks its contract inside the loop (a row count it did not declare,
        or a write outside its arrays, which a plug-in's bounds-checked code turns into an exception)
        is raised here as that correction's :class:`~footzoo.core.errors.PluginError`.
        """
        from .kalman_fast import eskf_loop

        signals, arrays, outputs = self._loop_arguments(packed, t, acc, gyr, stance, quat_ext, data, out)
        state, work = (packed.nav, packed.P, packed.mems), packed.work
        record = out.get("record")  # a smoother's
        with capture_faults() as caught:
            if packed.bound is not None:
                packed.bound(signals, packed.core, state, arrays, outputs, k0, work, record)
            else:
                (loop or eskf_loop)(signals, packed.core, state, (packed.functions, arrays), outputs, k0, work, record)
        self._raise_fault(work, caught)

    def _loop_arguments(self, packed: Packed, t, acc, gyr, stance, quat_ext, data, out) -> tuple:
        """The compiled loop's ``signals``, model ``arrays`` and ``out`` (kalman_fast's module docstring)."""
        from .kalman_fast import scratch

        ext = writable_array(quat_ext, float) if quat_ext is not None else np.zeros((1, 4))
        m_idx, par, par_off, mem_off, data_off, hooks, rows = packed.arrays
        arrays = (m_idx, par, par_off, mem_off, data, data_off, hooks, rows)
        signals = (writable_array(t, float), writable_array(acc, float), writable_array(gyr, float),
                   writable_array(stance, np.bool_), ext)
        outputs = (out["quat"], out["vel"], out["pos"], out["acc_nav"], out["gyro_bias"], out["acc_bias"],
                   out["P_diag"], out["nis"])
        if packed.work is None:
            packed.work = scratch(packed.P.shape[0], packed.core[4])
        return signals, arrays, outputs

    def _raise_fault(self, work: tuple, caught: list[BaseException]) -> None:
        fault = work[-1]
        if fault[0] >= 0 or caught:
            raise self.fault(int(fault[0]), int(fault[1]), int(fault[2]), caught)

    def smooth_checkpointed(self, packed: Packed, t, acc, gyr, stance, quat_ext, data, out) -> None:
        """RTS over the whole recording in bounded memory (:mod:`footzoo.filters.checkpointed`), compiled loop.

        ``out``: empty outputs of :meth:`outputs`; filled with the forward pass, whose ``quat``,
        ``vel`` and ``pos`` are kept as ``*_forward``, then smoothed in place. ``packed`` ends in
        the forward filter's final state.
        """
        from ..kernels.functions import DirectCall
        from . import checkpointed as cp
        from .kalman_fast import eskf_loop
        from .smoother import PHI_WIDTH

        nx, n_mem, block = packed.P.shape[0], packed.mems.size, cp.BLOCK
        forward_record = cp.checkpoint_record(stance, nx, n_mem, block, cp.MIN_GAP)
        self.step(packed, t, acc, gyr, stance, quat_ext, data, {**out, "record": forward_record}, 0)
        for key in ("quat", "vel", "pos"):
            out[f"{key}_forward"] = out[key].copy()
        spans = cp.pieces(forward_record, len(t))
        record = cp.replay_record(forward_record, nx, packed.core[4], block + 1)
        # each piece from a copy of its checkpoint; the outputs are not written
        replay = dataclasses.replace(packed, nav=np.empty(16), P=np.empty((nx, nx)), mems=np.empty(n_mem))
        scratch = self.outputs(1, False)
        loop = DirectCall(eskf_loop)  # one call per batch, every one with the same argument types

        def run() -> None:
            self.step(replay, t, acc, gyr, stance, quat_ext, data, {**scratch, "record": record}, 0, loop)

        core = packed.core  # (idx, q, gravity, use_ext, m_max, impact, integration): the loop's noise and gravity
        noise = (core[1], core[5], core[2], core[6])  # q, impact, gravity, integration (smooth_free_span's order)
        lam = np.zeros(nx)  # λ carried from piece to piece, zero after the last sample
        forward = (writable_array(t, float), out["quat_forward"], out["acc_nav"], writable_array(acc, float))
        buffers = (np.empty((block + 1, nx)), np.empty((block + 1, PHI_WIDTH)), np.empty(nx), np.empty(nx),
                   np.empty((3, 3)))
        smoothed = (out["quat"], out["vel"], out["pos"], out["gyro_bias"], out["acc_bias"])

        def smooth(j0: int, j1: int) -> None:
            cp.smooth_pieces(record, spans, j0, j1, lam, forward, noise, self.core_offsets(),
                             not self.carries_attitude, smoothed, buffers)

        cp.backward(run, record, spans, smooth, block)

    def fault(self, j: int, rows: int, k: int, caught: list[BaseException]) -> PluginError:
        """The :class:`PluginError` for a model that broke its contract in the loop (see :meth:`step`)."""
        suspects = [name for name, m in zip(self.names, self.models, strict=True)
                    if not all(trusted(fn) for fn in (m.measure, m.feedback, m.after))] or self.names
        who = self.names[j] if j >= 0 else suspects[0] if len(suspects) == 1 else "one of " + ", ".join(suspects)
        fix = "return m plus the rows written (at most max_rows), or raise max_rows in its MeasurementModel"
        if caught:  # a bounds-checked write failed (the call then returns 0, which may also look like a row count)
            err = caught[0]
            text = f"{type(err).__name__}: {err}" if str(err) else type(err).__name__
            where = "the reference Kalman loop" if self.engine == "reference" else "the compiled Kalman loop"
            hint = "" if self.engine == "reference" else ", or run engine='reference' to see the failing line"
            return PluginError(f"{who}: a measurement function failed inside {where} ({text}) at sample {k} or "
                               "before; a write outside the rows its model declares (max_rows) or outside its "
                               f"par/mem/data arrays is refused: fix the function{hint}", plugin=who, method="measure")
        m = self.models[j]
        if rows >= 0:
            problem = f"returned {rows} rows at sample {k}, but its model declares max_rows={m.max_rows}"
        else:
            problem = f"returned a row count {-rows} below the first free row it was given (sample {k})"
        return PluginError(f"{who}: its measure function {problem}; {fix}", plugin=who, method="measure")
