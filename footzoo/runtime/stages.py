"""The stages of a live run: each wraps one block of a pipeline behind the same four calls.

``push(chunk)`` gives the stage the next samples' inputs (final ones: the upstream stage's
final outputs, with the raw signals of the same samples) and returns the outputs that became
final; ``finish()`` the rest at the end of the data; ``guess(extra)`` the stage's current guess
for every sample after its final outputs — its own pending samples, then the ``extra`` samples
whose inputs are themselves only guesses (computed on a copy: the stage's state is untouched).
:class:`footzoo.Stream` chains them; :meth:`footzoo.Pipeline.run` runs the same blocks on the
whole recording, so the final outputs of a stream equal the batch run.

Chunks are dicts of per-sample arrays (:data:`footzoo.plugins.incremental.Chunk`), all with the
samples' absolute index in ``k``.
"""

from __future__ import annotations

import copy
import warnings
from typing import Any

import numpy as np

from ..core.context import RunContext
from ..core.errors import GuardWarning
from ..filters.recorders import ROW_KEYS, SAMPLE_KEYS
from ..filters.smoothing import smoothing as smoother_named
from ..filters.strapdown import Integrator, motion_acceleration
from ..plugins.base import (
    AccelerationCorrection,
    Calibration,
    Detector,
    KalmanCorrection,
    Orientation,
    Samples,
    VelocityCorrection,
    checked,
)
from ..plugins.incremental import Chunk, Columns, concat, length, take
from .guards import StanceGuard

#: Raw signals every chunk carries (``mag``, ``dist`` only when the recording has them).
RAW = ("k", "t", "acc", "gyr", "mag", "dist")


def raw(chunk: Chunk) -> Chunk:
    """The raw-signal columns of a chunk."""
    return {k: v for k, v in chunk.items() if k in RAW}


def with_columns(chunk: Chunk, outputs: Chunk, names: tuple[str, ...]) -> Chunk:
    """The samples of ``outputs`` (a prefix of ``chunk``'s, by ``k``) with the named columns of ``chunk``."""
    m = length(outputs)
    return {**{k: v[:m] for k, v in chunk.items() if k in names}, **outputs}


def pad_to(guess: Chunk, samples: Chunk, name: str, last: Any) -> np.ndarray:
    """``guess[name]`` for the first samples, then ``last`` repeated up to the length of ``samples``."""
    have = guess.get(name, np.zeros(0))
    n = length(samples)
    if len(have) >= n:
        return np.asarray(have[:n])
    fill = np.repeat(np.asarray([last]), n - len(have), axis=0)
    return np.concatenate([np.asarray(have), fill]) if len(have) else fill


class Queue:
    """Samples waiting between stages: appended at the end, taken from the front, by absolute index ``k``.

    Backed by :class:`~footzoo.plugins.incremental.Columns`: appending and taking cost the samples
    moved, not the samples held.
    """

    def __init__(self) -> None:
        self._columns = Columns()

    def put(self, chunk: Chunk) -> None:
        if length(chunk):
            self._columns.append(chunk)

    def take(self, stop_k: int) -> Chunk:
        """The samples with absolute index below ``stop_k`` (removed)."""
        if not len(self._columns):
            return {}
        view = self._columns.view()
        n = int(np.searchsorted(view["k"], stop_k))
        out = take(view, 0, n)
        self._columns.drop(n)
        return out

    def peek(self) -> Chunk:
        """The samples held (views: read them before the next change)."""
        return self._columns.view() if len(self._columns) else {}

    def __len__(self) -> int:
        return len(self._columns)


class CalibrationStage:
    """In-situ calibrations with their fit known (given, or fitted online on the stream's first seconds).

    :meth:`fit` fits every calibration whose parameters do not give its fit on a chunk (the
    stream's warm-up) and keeps the report; then :meth:`push` applies the fits sample by sample.
    """

    def __init__(self, calibrations: list[Calibration], ctx: RunContext, warmup: float):
        self.blocks = calibrations
        self.ctx, self.warmup = ctx, warmup
        self.reports: list[dict[str, Any]] = []

    def fit(self, chunk: Chunk) -> None:
        """Fit the calibrations that need it on ``chunk`` (their ``calibrate``), as a batch run fits on a recording."""
        for i, c in enumerate(self.blocks):
            if c.is_fitted():
                self.reports.append({"type": c.name, "applied": True, "given": True, **_fit_of(c)})
            else:
                fitted = checked(c.clone().calibrate, chunk["t"], chunk["acc"], chunk["gyr"], chunk.get("mag"))
                self.reports.append({"type": c.name, **fitted.report_})
                self.blocks[i] = checked(c.fixed, fitted.report_)

    def apply(self, chunk: Chunk) -> Chunk:
        """The chunk with the calibrated signals."""
        out = dict(chunk)
        for c in self.blocks:
            res = checked(c.step, out["t"], out["acc"], out["gyr"], out.get("mag"))
            out.update({k: v for k, v in res.items() if k in ("acc", "gyr", "mag")})
        return out

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        return self.apply(chunk) if length(chunk) else {}

    def held(self) -> int:
        return 0

    def finish(self) -> Chunk:
        return {}


def _fit_of(c: Calibration) -> dict[str, Any]:
    """A given fit's parameters, for the stream's report (the calibration's non-default parameters)."""
    return {k: v for k, v in c.get_params().items() if v != c.defaults().get(k)}


class DetectorStage:
    """The detector (its ``begin``/``step``/``finish``) and the maximum-swing guard after it."""

    def __init__(self, detector: Detector, guard: StanceGuard, ctx: RunContext):
        self.detector = checked(detector.clone().begin, ctx)
        self.guard = guard.stream(ctx)
        self.ctx, self.max_swing = ctx, guard.max_swing
        self.raw = Queue()  # samples pushed whose detector stance is not final
        self.guarding = Queue()  # samples with their detector stance, whose guarded stance is not final
        self.last = True

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        self.raw.put(chunk)
        out = checked(self.detector.step, chunk["t"], chunk["acc"], chunk["gyr"]) if length(chunk) else {}
        if finish:
            out = concat([out, checked(self.detector.finish)])
        done = self._decided(self.raw, out)
        if self.guard is not None:
            self.guarding.put(done)
            out = self.guard.step(t=done["t"], gyr=done["gyr"], stance=done["stance"]) if length(done) else {}
            if finish:
                out = concat([out, self.guard.finish()])
            done = self._decided(self.guarding, out)
            if length(out) and out["added"].any():
                self._warn(out)
        if length(done):
            self.last = bool(done["stance"][-1])
        return done

    def _warn(self, out: Chunk) -> None:
        """The guard's warning of a batch run (:meth:`StanceGuard.warn`) for the long swings it closed here."""
        added = out["added"]
        starts = np.flatnonzero(added & ~np.concatenate([[False], added[:-1]]))
        t_first = float(out["t"][starts[0]])
        warnings.warn(f"{self.ctx.name}: detector {self.detector.name!r} found no stance for more than "
                      f"{self.max_swing:g} s (guards.max_swing) before t = {float(out['t'][-1]):.2f} s. The stance "
                      f"guard marked {starts.size} still instant(s) there as stance, the first at t = {t_first:.2f} s: "
                      "the trajectory in that swing is suspect — the detector misses the stances of this motion "
                      "(running?); choose one made for it, or switch the guard off with guards: {max_swing: 0}",
                      GuardWarning, stacklevel=6)

    def held(self) -> int:
        """Samples waiting for the detector's or the guard's final stance."""
        return len(self.raw) + len(self.guarding)

    @staticmethod
    def _decided(queue: Queue, out: Chunk) -> Chunk:
        if not length(out):
            return {}
        rows = queue.take(queue.peek()["k"][0] + length(out))
        return {**rows, "stance": np.asarray(out["stance"], dtype=bool)}

    def finish(self) -> Chunk:
        return self.push({}, finish=True)

    def guess(self) -> Chunk:
        """Every sample after the final ones, with the guard's and the detector's current stance guess."""
        guarding, pending = self.guarding.peek(), self.raw.peek()
        parts = []
        if length(guarding):
            mine = self.guard.provisional().get("stance", np.zeros(0, bool))[:length(guarding)]
            parts.append({**guarding, "stance": np.concatenate([mine, guarding["stance"][len(mine):]])})
        if length(pending):
            last = bool(parts[-1]["stance"][-1]) if parts else self.last
            parts.append({**pending, "stance": pad_to(checked(self.detector.provisional), pending, "stance", last)})
        return concat(parts)


class OrientationStage:
    """An orientation filter (``begin(ctx, q0)``/``step``): the attitude of every sample once its stance is final."""

    def __init__(self, orientation: Orientation, ctx: RunContext, q0: np.ndarray, use_mag: bool):
        self.block = checked(orientation.clone().begin, ctx, q0)
        self.use_mag = use_mag
        self.waiting = Queue()  # samples of the filter's warm-up
        self.last_q = np.asarray(q0, dtype=float)

    def _step(self, block: Orientation, chunk: Chunk, finish: bool = False) -> Chunk:
        out = checked(block.step, chunk["t"], chunk["acc"], chunk["gyr"], chunk.get("mag") if self.use_mag else None,
                         chunk["stance"]) if length(chunk) else {}
        if finish:
            out = concat([out, checked(block.finish)])
        return out

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        self.waiting.put(chunk)
        out = self._step(self.block, chunk, finish)
        if not length(out):
            return {}
        rows = self.waiting.take(self.waiting.peek()["k"][0] + length(out))
        self.last_q = out["quat"][-1]
        return {**rows, "quat": out["quat"]}

    def finish(self) -> Chunk:
        return self.push({}, finish=True)

    def held(self) -> int:
        """Samples of the filter's warm-up, not given an attitude yet."""
        return len(self.waiting)

    def guess(self, extra: Chunk) -> Chunk:
        samples = concat([self.waiting.peek(), extra])
        if not length(samples):
            return {}
        if not length(extra):
            return {**samples, "quat": np.repeat(self.last_q[None], length(samples), axis=0)}
        fork = copy.deepcopy(self.block)
        out = self._step(fork, extra)
        quat = pad_to(out, samples, "quat", out["quat"][-1] if length(out) else self.last_q)
        return {**samples, "quat": quat}


class KalmanStage:
    """The error-state Kalman engine, advanced sample by sample from its carried state.

    With ``smoother="stepwise"`` (:mod:`footzoo.filters.stepwise`) the engine also records each
    sample for the backward pass; the samples wait in the open segment until the segment closes
    (the first sample after a stance has been seen, or the end of the data), are smoothed as
    the batch run smooths them (the segments of :class:`footzoo.filters.smoothing.Stepwise`, the
    same kernel) and become final. Their provisional estimates are the forward filter's.
    """

    def __init__(self, engine: Any, corrections: list[KalmanCorrection], q0: np.ndarray, external_attitude: bool,
                 smoother: str = "none"):
        self.engine = engine
        self.corrections = corrections
        nav0 = np.zeros(16)
        nav0[:4] = q0
        self.state = engine.start(nav0)
        self.external = external_attitude
        self.prev: Chunk | None = None  # the last sample the engine has processed (its row 0 of a chunk)
        self.smoothing = smoother_named(smoother)
        self.stepwise = bool(self.smoothing)
        self.open = Columns()  # step-wise smoother: the open segment's samples, forward estimates and record
        self.open_rows = Columns()  # ... and its update rows (record_first: absolute row numbers)
        self.rows_before = 0  # rows of the samples released (the absolute number of open_rows' first row)

    def _advance(self, state: Any, chunk: Chunk, prev: Chunk | None, record: bool = False) -> dict[str, np.ndarray]:
        """Run the engine over ``chunk`` from ``state`` (the state of ``prev``, or the initial one)."""
        rows = concat([prev, chunk]) if prev is not None else chunk
        samples = Samples(rows["t"], rows["acc"], rows["gyr"], rows.get("mag"), rows.get("dist"),
                          rows["init"].astype(bool))
        data = [np.ascontiguousarray(checked(c.sample_data, samples), dtype=float) for c in self.corrections]
        out = self.engine.advance(state, rows["t"], rows["acc"], rows["gyr"], rows["stance"].astype(bool),
                                  rows["quat"] if self.external else None, data, int(rows["k"][0]), covariance=False,
                                  record=record)
        skip = 0 if prev is None else 1
        keys = ("quat", "vel", "pos", "acc_nav", *(("gyro_bias", "acc_bias", *SAMPLE_KEYS) if record else ()))
        done = {k: out[k][skip:] for k in keys}
        if record:
            used = int(out["record_first"][-1] + out["record_count"][-1])
            rows_kept = int(out["record_first"][skip]) if skip < len(out["record_first"]) else used
            done.update({k: out[k][rows_kept:used] for k in ROW_KEYS})
            done["record_first"] = done["record_first"] - rows_kept
        return done

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        if length(chunk):
            out = self._advance(self.state, chunk, self.prev, record=self.stepwise)
            self.prev = take(chunk, length(chunk) - 1)
            if not self.stepwise:
                return {**chunk, **out}
            rows = {k: out.pop(k) for k in ROW_KEYS}
            out["record_first"] = out["record_first"] + (self.rows_before + len(self.open_rows))
            self.open.append({**chunk, **out})
            self.open_rows.append(rows)
        return self._close_segments(finish) if self.stepwise else {}

    def _close_segments(self, closed: bool) -> Chunk:
        """The samples of the segments that have closed, smoothed (``closed``: the data ends here)."""
        if not len(self.open):
            return {}
        rows = self.open.view()
        ends = self.smoothing.ends(rows["stance"].astype(bool), rows["t"], closed)
        if not ends.size:  # most packets end no stance: nothing to do
            return {}
        held = {**rows, "record_first": rows["record_first"] - self.rows_before, **self._open_rows()}
        self.engine.smooth(held, ends, self.smoothing)
        n_final = int(ends[-1]) + 1
        done = take(_public(rows), 0, n_final)
        released = int(held["record_first"][n_final - 1] + held["record_count"][n_final - 1])
        self.open.drop(n_final)
        self.open_rows.drop(released)
        self.rows_before += released
        return done

    def _open_rows(self) -> dict[str, np.ndarray]:
        """The open segment's update rows (empty columns when there are none)."""
        if len(self.open_rows):
            return self.open_rows.view()
        n = self.engine.layout.n
        return {"row_h": np.zeros((0, n)), "row_gain": np.zeros((0, n)), "row_scaled": np.zeros(0),
                "row_nu": np.zeros(0), "row_s": np.zeros(0)}

    def finish(self) -> Chunk:
        return self._close_segments(True) if self.stepwise else {}

    def held(self) -> int:
        """Samples of the open segment (step-wise smoother), waiting for the end of the next stance."""
        return len(self.open)

    def guess(self, extra: Chunk) -> Chunk:
        parts = [_public(self.open.view())] if len(self.open) else []
        if length(extra):
            state = self.engine.fork(self.state)
            parts.append({**extra, **self._advance(state, extra, self.prev)})
        if len(parts) > 1:
            keys = set(parts[0]) & set(parts[1])
            parts = [{k: v for k, v in p.items() if k in keys} for p in parts]
        return concat(parts)


def _public(rows: Chunk) -> Chunk:
    """The columns of a sample (without the step-wise smoother's record and the bias estimates)."""
    return {k: v for k, v in rows.items() if k not in SAMPLE_KEYS and k not in ("gyro_bias", "acc_bias")}


class BatchNavigationStage:
    """Without a Kalman filter: motion acceleration, the acceleration corrections, then a velocity correction
    (or plain integration)."""

    def __init__(self, corrections: list[Any], ctx: RunContext, gravity: float):
        self.ctx, self.gravity = ctx, gravity
        self.accel = [checked(c.clone().begin, ctx) for c in corrections if isinstance(c, AccelerationCorrection)]
        velocity = [c for c in corrections if isinstance(c, VelocityCorrection)]
        self.velocity = checked(velocity[0].clone().begin, ctx) if velocity else None
        self.integrator = None if velocity else Integrator()
        self.waiting = Queue()
        self.q_prev: np.ndarray | None = None  # the last attitude (the mid-interval rotation needs it)

    def _acc_nav(self, chunk: Chunk, q_prev: np.ndarray | None, accel: list[AccelerationCorrection]) -> np.ndarray:
        quat = chunk["quat"]
        if q_prev is None:
            a = motion_acceleration(quat, chunk["acc"], self.gravity)
        else:
            a = motion_acceleration(np.vstack([q_prev[None], quat]), np.vstack([chunk["acc"][:1], chunk["acc"]]),
                                    self.gravity)[1:]
        for c in accel:
            a = checked(c.step_acceleration, quat, a, chunk["stance"])["acc_nav"]
        return a

    def _navigate(self, chunk: Chunk, velocity: Any, integrator: Any, q_prev: np.ndarray | None,
                  accel: list[AccelerationCorrection], finish: bool) -> tuple[Chunk, Chunk]:
        """(final outputs, the chunk's rows with acc_nav)."""
        rows = {**chunk, "acc_nav": self._acc_nav(chunk, q_prev, accel)} if length(chunk) else {}
        if velocity is not None:
            out = checked(velocity.step, rows["t"], rows["acc_nav"], rows["stance"]) if length(rows) else {}
            if finish:
                out = concat([out, checked(velocity.finish)])
        elif length(rows):
            vel = integrator.velocity(rows["acc_nav"], rows["t"])
            out = {"vel": vel, "pos": integrator.position(vel, rows["t"])}
        else:
            out = {}
        return out, rows

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        out, rows = self._navigate(chunk, self.velocity, self.integrator, self.q_prev, self.accel, finish)
        if length(rows):
            self.q_prev = rows["quat"][-1]
        self.waiting.put(rows)
        if not length(out):
            return {}
        done = self.waiting.take(self.waiting.peek()["k"][0] + length(out))
        return {**done, "vel": out["vel"], "pos": out["pos"]}

    def finish(self) -> Chunk:
        return self.push({}, finish=True)

    def held(self) -> int:
        """Samples of the open swing, waiting for the velocity correction."""
        return len(self.waiting)

    def guess(self, extra: Chunk) -> Chunk:
        velocity, integrator, accel = copy.deepcopy((self.velocity, self.integrator, self.accel))
        out, rows = self._navigate(extra, velocity, integrator, self.q_prev, accel, False)
        samples = concat([self.waiting.peek(), rows])
        if not length(samples):
            return {}
        if velocity is not None:
            out = concat([out, checked(velocity.provisional)])
        if not length(out):
            return {}
        return {**samples, "vel": pad_to(out, samples, "vel", out["vel"][-1]),
                "pos": pad_to(out, samples, "pos", out["pos"][-1])}
