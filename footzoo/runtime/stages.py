"""The stages of a run: each wraps one block of a pipeline behind one interface, :class:`Stage`.

``push(chunk)`` gives the stage the next samples' inputs (final ones: the upstream stage's
final outputs, with the raw signals of the same samples) and returns the outputs that became
final; ``finish()`` the rest at the end of the data; ``guess(extra)`` the stage's current guess
for every sample after its final outputs — its own pending samples, then the ``extra`` samples
whose inputs are themselves only guesses (computed on a copy: the stage's state is untouched);
``report()`` what the stage adds to ``Result.diagnostics``.

A stream pushes chunk after chunk; a batch run (:meth:`footzoo.Pipeline.run`) pushes the whole
recording as one chunk with ``finish``, and a stage given that runs its block's batch code on
it (the block's ``detect``, ``estimate``, ``apply``; the Kalman engine's ``run``, which the
RTS smoother needs). :func:`footzoo.runtime.chain.build_chain` makes the stages of a pipeline
for both, so the final outputs of a stream equal the batch run.
"""

from __future__ import annotations

import copy
import warnings
from typing import Any

import numpy as np

from ..core.context import RunContext
from ..core.errors import GuardWarning, PluginError, user_stacklevel
from ..evaluation.metrics import nis_summary
from ..filters.recorders import ROW_KEYS, SAMPLE_KEYS
from ..filters.smoothing import smoothing as smoother_named
from ..filters.strapdown import (
    Integrator,
    integrate_position,
    integrate_velocity,
    motion_acceleration,
    sample_intervals,
)
from ..plugins.base import (
    AccelerationCorrection,
    Calibration,
    Detector,
    KalmanCorrection,
    Orientation,
    Samples,
    VelocityCorrection,
    call,
    checked,
)
from ..plugins.contract import detector_diagnostics
from ..plugins.incremental import Chunk, Columns, concat, length, take
from .guards import MISSED_STANCE, StanceGuard
from .stage import Queue, Stage, pad_to


class GainStage(Stage):
    """The specific force times the accelerometer's gain (dimensionless), before every other stage.

    The gain comes from the run's still start (:func:`footzoo.runtime.alignment.accelerometer_gain`);
    a gain of 1 leaves the chunks as they are.
    """

    def __init__(self, gain: float, still: float, gravity: float):
        self.gain, self.still, self.gravity = float(gain), float(still), float(gravity)

    def _scaled(self, chunk: Chunk) -> Chunk:
        if self.gain == 1.0 or not length(chunk):
            return chunk
        return {**chunk, "acc": chunk["acc"] * self.gain}

    def whole(self, chunk: Chunk) -> Chunk:
        return self._scaled(chunk)

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
        return self._scaled(chunk) if length(chunk) else {}

    def held(self) -> int:
        return 0

    def provisional(self, extra: Chunk) -> Chunk:
        return self._scaled(extra) if length(extra) else {}

    def report(self) -> dict[str, Any]:
        """``acc_gain``: the factor applied and the still start's reading it corrects (m/s²), against g."""
        return {"acc_gain": {"gain": self.gain, "still_m_s2": self.still, "gravity_m_s2": self.gravity}}


def _reissue_naming(caught: list[warnings.WarningMessage], name: str | None) -> None:
    """Issue the warnings a plug-in gave again, each prefixed with the recording's ``name`` (a plug-in sees only
    arrays: in a study or a session, a warning without the recording's name cannot be traced)."""
    for w in caught:
        text = str(w.message)
        try:
            message = w.category(f"{name}: {text}") if name and not text.startswith(f"{name}:") else w.message
        except Exception:  # a warning class with another constructor: as it was
            message = w.message
        warnings.warn(message, stacklevel=user_stacklevel())


class CalibrationStage(Stage):
    """In-situ calibrations, applied in order before every other stage.

    :meth:`fit` fits them on the run's start — a batch run's whole recording, or a stream's
    first seconds (its warm-up), where calibrations whose parameters give their fit are taken
    as given and the others are fixed to the fit for the samples to come — and keeps their
    reports; the samples fitted on are released as the fit calibrated them, later samples are
    calibrated by the fits (:meth:`step`).
    """

    def __init__(self, calibrations: list[Calibration], ctx: RunContext):
        self.blocks = list(calibrations)
        self.ctx = ctx
        self.reports: list[dict[str, Any]] = []
        self._fitted: Chunk = {}  # the samples fitted on, calibrated, until they are pushed

    def fit(self, chunk: Chunk, whole: bool = False) -> Chunk:
        """Fit the calibrations on ``chunk``, each on the signals the ones before it calibrated; the chunk calibrated.

        ``whole``: ``chunk`` is the whole recording (a batch run): every calibration is fitted on
        it (``calibrate``). Else a calibration that is fitted already is applied as it is (its
        report says ``given``), and the others are fitted and then fixed to their fit.
        """
        out = dict(chunk)
        for i, c in enumerate(self.blocks):
            if c.is_fitted() and not whole:
                self.reports.append({"type": c.name, "applied": True, "given": True, **_fit_of(c)})
                out.update(_applied(c, out))
                continue
            with warnings.catch_warnings(record=True) as caught:  # re-issued below, naming the recording
                warnings.simplefilter("always")
                fitted = checked(c.clone().calibrate, out["t"], out["acc"], out["gyr"], out.get("mag"))
            _reissue_naming(caught, self.ctx.name)
            out.update(calibrated_signals(c, out, fitted, self.ctx.name))
            self.reports.append({"type": c.name, **fitted.report_})
            if not whole:
                self.blocks[i] = checked(c.fixed, fitted.report_)
        self._fitted = out
        return out

    def whole(self, chunk: Chunk) -> Chunk:
        return self._released(chunk) or self.fit(chunk, whole=True)

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
        return (self._released(chunk) or self.apply(chunk)) if length(chunk) else {}

    def _released(self, chunk: Chunk) -> Chunk:
        """The chunk as the fit calibrated it when its samples are the ones fitted on (else empty)."""
        done, self._fitted = self._fitted, {}
        same = length(done) == length(chunk) and length(chunk) and done["k"][0] == chunk["k"][0]
        return done if same else {}

    def apply(self, chunk: Chunk) -> Chunk:
        """The chunk with the calibrated signals."""
        out = dict(chunk)
        for c in self.blocks:
            out.update(_applied(c, out))
        return out

    def held(self) -> int:
        return 0

    def provisional(self, extra: Chunk) -> Chunk:
        return self.apply(extra) if length(extra) else {}

    def report(self) -> dict[str, Any]:
        """The calibrations' reports (``Result.diagnostics["calibration"]``)."""
        return {"calibration": self.reports}


def _applied(c: Calibration, chunk: Chunk) -> Chunk:
    """A fitted calibration's signals for ``chunk`` (its ``step``)."""
    res = checked(c.step, chunk["t"], chunk["acc"], chunk["gyr"], chunk.get("mag"))
    return {k: v for k, v in res.items() if k in ("acc", "gyr", "mag")}


def _fit_of(c: Calibration) -> dict[str, Any]:
    """A given fit's parameters, for the stream's report (the calibration's non-default parameters)."""
    return {k: v for k, v in c.get_params().items() if v != c.defaults().get(k)}


def calibrated_signals(c: Calibration, chunk: Chunk, fitted: Calibration, recording: str) -> Chunk:
    """A fitted calibration's signals, checked: same shapes as the input, finite (a plug-in error names the plug-in)."""
    out = {}
    for name in ("acc", "gyr", "mag"):
        before, after = chunk.get(name), getattr(fitted, f"{name}_", None)
        if before is None and after is None:
            continue
        after = None if after is None else np.asarray(after, dtype=float)
        if after is None or after.shape != np.shape(before) or not np.isfinite(after).all():
            what = ("missing" if after is None else f"shape {after.shape}" if after.shape != np.shape(before)
                    else "NaN/inf")
            raise PluginError(f"calibration {c.name!r} on {recording!r}: {name}_ is {what}; it must be a finite "
                              f"array shaped like the input {np.shape(before)} (fix the calibration plug-in)",
                              plugin=f"calibration {c.name!r}", method="calibrate")
        out[name] = after
    return out


def detected(detector: Detector, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext,
             truth: Any = None) -> Detector:
    """A fresh copy of ``detector`` fitted on a whole recording (``detect``; given ``truth`` when it needs it)."""
    fitted = detector.clone()
    if fitted.needs_truth:
        return checked(fitted.detect, t, acc, gyr, truth)
    return call(fitted.detect, t, acc, gyr, ctx=ctx)


def guarded(guards: StanceGuard, t: np.ndarray, gyr: np.ndarray, detector: Detector, ctx: RunContext,
            recording: str) -> tuple[np.ndarray, dict[str, Any]]:
    """The stance mask after the maximum-swing guard over a whole recording, and its report (warned once)."""
    stance, report = guards.apply(t, gyr, detector.stance_, ctx)
    guards.warn(report, detector.name, recording)
    return stance, report


class DetectorStage(Stage):
    """The detector and the maximum-swing guard after it.

    Whole recording: the detector's ``detect`` (given the reference when it ``needs_truth``) and
    the guard's ``apply``; live: the detector's ``begin``/``step``/``finish`` and the guard's stream.
    """

    def __init__(self, detector: Detector, guard: StanceGuard, ctx: RunContext, truth: Any = None):
        self.block, self.guards, self.truth = detector, guard, truth
        self.ctx, self.max_swing = ctx, guard.max_swing
        self.raw = Queue()  # samples pushed whose detector stance is not final
        self.guarding = Queue()  # samples with their detector stance, whose guarded stance is not final
        self.last = True
        self.fitted: Detector | None = None  # the detector fitted on a whole recording
        self.guard_report: dict[str, Any] = {}

    def begin(self) -> None:
        self.detector = checked(self.block.clone().begin, self.ctx)
        self.guard = self.guards.stream(self.ctx)

    def whole(self, chunk: Chunk) -> Chunk:
        self.fitted = detected(self.block, chunk["t"], chunk["acc"], chunk["gyr"], self.ctx, self.truth)
        stance, self.guard_report = guarded(self.guards, chunk["t"], chunk["gyr"], self.fitted, self.ctx,
                                            self.ctx.name)
        self.n = length(chunk)
        return {**chunk, "stance": stance}

    def report(self) -> dict[str, Any]:
        """The detector's stance and statistic and the guard's report (of a whole recording; live: none)."""
        if self.fitted is None:
            return {}
        return {**detector_diagnostics(self.fitted, self.n), "guards": self.guard_report}

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
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
                      f"the trajectory in that swing is suspect — {MISSED_STANCE}",
                      GuardWarning, stacklevel=user_stacklevel())

    def held(self) -> int:
        """Samples waiting for the detector's or the guard's final stance."""
        return len(self.raw) + len(self.guarding)

    @staticmethod
    def _decided(queue: Queue, out: Chunk) -> Chunk:
        if not length(out):
            return {}
        rows = queue.take(queue.peek()["k"][0] + length(out))
        return {**rows, "stance": np.asarray(out["stance"], dtype=bool)}

    def provisional(self, extra: Chunk) -> Chunk:
        """Every sample after the final ones, with the guard's and the detector's current stance guess.

        ``extra`` must be empty: the stages before the detector (calibrations) hold no samples.
        """
        if length(extra):
            raise ValueError("DetectorStage.guess: the detector holds every sample pushed; it takes no extra samples")
        guarding, pending = self.guarding.peek(), self.raw.peek()
        parts = []
        if length(guarding):
            mine = self.guard.provisional().get("stance", np.zeros(0, bool))[:length(guarding)]
            parts.append({**guarding, "stance": np.concatenate([mine, guarding["stance"][len(mine):]])})
        if length(pending):
            last = bool(parts[-1]["stance"][-1]) if parts else self.last
            parts.append({**pending, "stance": pad_to(checked(self.detector.provisional), pending, "stance", last)})
        return concat(parts)


def estimate_attitude(orientation: Orientation, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray,
                      mag: np.ndarray | None, stance: np.ndarray, q0: np.ndarray, ctx: RunContext) -> np.ndarray:
    """The attitude (N, 4) of a whole recording from a fresh copy of ``orientation`` (its ``estimate``)."""
    return call(orientation.clone().estimate, t, acc, gyr, mag, stance, q0, ctx=ctx).quat_


class OrientationStage(Stage):
    """An orientation filter: the attitude of every sample once its stance is final.

    Whole recording: its ``estimate``; live: ``begin(ctx, q0)``/``step``/``finish``.
    """

    def __init__(self, orientation: Orientation, ctx: RunContext, q0: np.ndarray, use_mag: bool):
        self.orientation, self.ctx, self.q0 = orientation, ctx, q0
        self.use_mag = use_mag
        self.waiting = Queue()  # samples of the filter's warm-up
        self.last_q = np.asarray(q0, dtype=float)

    def begin(self) -> None:
        self.block = checked(self.orientation.clone().begin, self.ctx, self.q0)

    def whole(self, chunk: Chunk) -> Chunk:
        mag = chunk.get("mag") if self.use_mag else None
        quat = estimate_attitude(self.orientation, chunk["t"], chunk["acc"], chunk["gyr"], mag, chunk["stance"],
                                 self.q0, self.ctx)
        return {**chunk, "quat": quat}

    def _step(self, block: Orientation, chunk: Chunk, finish: bool = False) -> Chunk:
        out = checked(block.step, chunk["t"], chunk["acc"], chunk["gyr"], chunk.get("mag") if self.use_mag else None,
                      chunk["stance"]) if length(chunk) else {}
        if finish:
            out = concat([out, checked(block.finish)])
        return out

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
        self.waiting.put(chunk)
        out = self._step(self.block, chunk, finish)
        if not length(out):
            return {}
        rows = self.waiting.take(self.waiting.peek()["k"][0] + length(out))
        self.last_q = out["quat"][-1]
        return {**rows, "quat": out["quat"]}

    def held(self) -> int:
        """Samples of the filter's warm-up, not given an attitude yet."""
        return len(self.waiting)

    def provisional(self, extra: Chunk) -> Chunk:
        samples = concat([self.waiting.peek(), extra])
        if not length(samples):
            return {}
        if not length(extra):
            return {**samples, "quat": np.repeat(self.last_q[None], length(samples), axis=0)}
        fork = copy.deepcopy(self.block)
        out = self._step(fork, extra)
        quat = pad_to(out, samples, "quat", out["quat"][-1] if length(out) else self.last_q)
        return {**samples, "quat": quat}


class KalmanStage(Stage):
    """The error-state Kalman engine.

    Whole recording: the engine's ``run`` with the pipeline's smoother (the RTS smoother needs
    the whole recording) and ``covariance``; its diagnostics are the stage's :meth:`report`.
    Live: advanced sample by sample from its carried state. With ``smoother="stepwise"``
    (:mod:`footzoo.filters.stepwise`) the engine also records each sample for the backward pass;
    the samples wait in the open segment until the segment closes (the first sample after a
    stance has been seen, or the end of the data), are smoothed as the batch run smooths them
    (the segments of :class:`footzoo.filters.smoothing.Stepwise`, the same kernel) and become
    final. Their provisional estimates are the forward filter's.
    """

    def __init__(self, engine: Any, corrections: list[KalmanCorrection], q0: np.ndarray, external_attitude: bool,
                 smoother: str = "none", covariance: bool = False):
        self.engine = engine
        self.corrections = corrections
        self.q0 = q0
        self.external = external_attitude
        self.smoother, self.covariance = smoother, covariance
        self.diagnostics: dict[str, Any] = {}
        self.prev: Chunk | None = None  # the last sample the engine has processed (its row 0 of a chunk)
        self.smoothing = smoother_named(smoother)
        self.stepwise = bool(self.smoothing)
        self.open = Columns()  # step-wise smoother: the open segment's samples, forward estimates and record
        self.open_rows = Columns()  # ... and its update rows (record_first: absolute row numbers)
        self.rows_before = 0  # rows of the samples released (the absolute number of open_rows' first row)

    def begin(self) -> None:
        nav0 = np.zeros(16)
        nav0[:4] = self.q0
        self.state = self.engine.start(nav0)

    def whole(self, chunk: Chunk) -> Chunk:
        out = self.engine.run(chunk["t"], chunk["acc"], chunk["gyr"], chunk["stance"], self.q0,
                              chunk["quat"] if self.external else None, self.covariance, smoother=self.smoother)
        self.diagnostics = kalman_diagnostics(out, self.engine, self.covariance)
        return {**chunk, **{k: out[k] for k in ("quat", "vel", "pos", "acc_nav")}}

    def report(self) -> dict[str, Any]:
        """The engine's diagnostics of a whole recording (:func:`kalman_diagnostics`; live: none)."""
        return self.diagnostics

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

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
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

    def held(self) -> int:
        """Samples of the open segment (step-wise smoother), waiting for the end of the next stance."""
        return len(self.open)

    def provisional(self, extra: Chunk) -> Chunk:
        parts = [_public(self.open.view())] if len(self.open) else []
        if length(extra):
            state = self.engine.fork(self.state)
            parts.append({**extra, **self._advance(state, extra, self.prev)})
        if len(parts) > 1:
            keys = set(parts[0]) & set(parts[1])
            parts = [{k: v for k, v in p.items() if k in keys} for p in parts]
        return concat(parts)


def kalman_diagnostics(out: dict[str, Any], engine: Any, covariance: bool) -> dict[str, Any]:
    """A whole run's Kalman diagnostics: the models', the bias estimates, with ``covariance`` the variances, the
    innovations and the position's standard deviation, and the forward pass of a smoothed run."""
    diagnostics = out["diagnostics"]
    diagnostics.update(gyro_bias=out["gyro_bias"], acc_bias=out["acc_bias"])
    if covariance:
        diagnostics["P_diag"] = out["P_diag"]
        diagnostics["nis"] = out["nis"]
        diagnostics["nis_rows"] = out["nis_rows"]
        diagnostics["consistency"] = nis_summary(out["nis"], out["nis_rows"])
        if engine.layout.has("pos"):  # the forward filter's position standard deviation (m), N, E, D
            diagnostics["pos_std"] = np.sqrt(out["P_diag"][:, engine.layout["pos"]])
    diagnostics.update({k: out[k] for k in ("quat_forward", "vel_forward", "pos_forward") if k in out})
    return diagnostics


def _public(rows: Chunk) -> Chunk:
    """The columns of a sample (without the step-wise smoother's record and the bias estimates)."""
    return {k: v for k, v in rows.items() if k not in SAMPLE_KEYS and k not in ("gyro_bias", "acc_bias")}


class BatchNavigationStage(Stage):
    """Without a Kalman filter: motion acceleration, the acceleration corrections, then a velocity correction
    (or plain integration).

    Whole recording: the corrections' ``apply_acceleration`` and ``apply``; live: their
    ``begin``/``step_acceleration``/``step``/``finish``.
    """

    def __init__(self, corrections: list[Any], ctx: RunContext, gravity: float):
        self.ctx, self.gravity = ctx, gravity
        self.corrections = corrections
        self.waiting = Queue()
        self.q_prev: np.ndarray | None = None  # the last attitude (the mid-interval rotation needs it)

    def begin(self) -> None:
        self.accel = [checked(c.clone().begin, self.ctx) for c in self.corrections
                      if isinstance(c, AccelerationCorrection)]
        velocity = [c for c in self.corrections if isinstance(c, VelocityCorrection)]
        self.velocity = checked(velocity[0].clone().begin, self.ctx) if velocity else None
        self.integrator = None if velocity else Integrator()

    def whole(self, chunk: Chunk) -> Chunk:
        quat, stance = chunk["quat"], chunk["stance"]
        acc_nav = motion_acceleration(quat, chunk["acc"], self.gravity)
        for c in self.corrections:
            if isinstance(c, AccelerationCorrection):
                acc_nav = call(c.clone().apply_acceleration, quat, acc_nav, stance, ctx=self.ctx)
        velocity = [c for c in self.corrections if isinstance(c, VelocityCorrection)]
        if velocity:
            corr = call(velocity[0].clone().apply, chunk["t"], acc_nav, stance, ctx=self.ctx)
            vel, pos = corr.vel_, corr.pos_
        else:
            dt = sample_intervals(chunk["t"])
            vel = integrate_velocity(acc_nav, dt)
            pos = integrate_position(vel, dt)
        return {**chunk, "acc_nav": acc_nav, "vel": vel, "pos": pos}

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

    def step(self, chunk: Chunk, finish: bool) -> Chunk:
        out, rows = self._navigate(chunk, self.velocity, self.integrator, self.q_prev, self.accel, finish)
        if length(rows):
            self.q_prev = rows["quat"][-1]
        self.waiting.put(rows)
        if not length(out):
            return {}
        done = self.waiting.take(self.waiting.peek()["k"][0] + length(out))
        return {**done, "vel": out["vel"], "pos": out["pos"]}

    def held(self) -> int:
        """Samples of the open swing, waiting for the velocity correction."""
        return len(self.waiting)

    def provisional(self, extra: Chunk) -> Chunk:
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
