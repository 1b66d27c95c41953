"""Compose plug-ins into a pipeline and run it on a recording.

``Pipeline.run`` pushes the whole recording, as one finished chunk, through the chain of stages
a live :class:`footzoo.Stream` runs (:func:`footzoo.runtime.chain.build_chain`: the
accelerometer's gain and the calibrations, detector and guard, orientation unless the Kalman
filter carries it, the Kalman engine or batch navigation), then adds the steps and analyses
(:meth:`~Pipeline.analyse`) and the checks of the estimate. Each stage alone is a public method:
:meth:`~Pipeline.prepare` (the gain, the calibrations and the initial attitude, through the same
stage code as ``run``), :meth:`~Pipeline.detect` and :meth:`~Pipeline.guard`,
:meth:`~Pipeline.orient`, :meth:`~Pipeline.navigate`, which prepare a raw recording the same way
first: on the same recording they give what ``run`` gives. The stages read the plug-ins' base classes and declared
capabilities, never their names.
"""

from __future__ import annotations

import contextlib
import copy
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from .._version import __version__
from ..analysis.gait_events import sagittal_rate
from ..analysis.mounting import mounting_report, warn_mounting
from ..analysis.strides import real_stances, segment_steps
from ..config.library import resolve
from ..config.schema import GRAVITY_PARAMETER, Init, check_init, check_top_level, load_yaml
from ..core.context import RunContext
from ..core.conventions import GRAVITY
from ..core.data import Recording
from ..core.errors import ConfigError, NotAPipelineError, NotARecordingError, RecordingError, prefixed
from ..core.sanity import EstimateScan
from ..core.table import samples_frame
from ..evaluation.result import Result
from ..filters.consistency import ConsistencyScan
from ..filters.engine import KalmanEngine, NavigationNoise
from ..filters.stepwise import WAITS_FOR as STEPWISE_WAIT
from ..plugins.base import (
    AccelerationCorrection,
    Analysis,
    Calibration,
    Detector,
    KalmanCorrection,
    Orientation,
    Plugin,
    Samples,
    VelocityCorrection,
    check_parameters,
    checked,
    inputs_checked_once,
)
from ..plugins.extensions import load_plugins
from ..plugins.incremental import WHOLE_RECORDING, Chunk, Latency, total
from ..plugins.registry import build
from . import stage_inputs as inputs
from .chain import Chain, aligned, build_chain, input_stages, navigation_stage, recording_chunk, with_signals
from .guards import StanceGuard, check_speed
from .stage_inputs import engine as checked_engine
from .stage_inputs import flag as checked_flag
from .stages import GainStage, detected, estimate_attitude, guarded

#: Default seconds a live stream fits an unfitted calibration on (:class:`footzoo.Stream`'s ``warmup``).
STREAM_WARMUP = 30.0

#: The ``meta`` key of a recording :meth:`Pipeline.prepare` made: what its preparation depended on.
PREPARED = "prepared"


class Prepared(NamedTuple):
    """A recording as :meth:`Pipeline.prepare` gives it (see there): ``recording``, ``q0``, ``diagnostics``."""

    recording: Recording
    q0: np.ndarray
    diagnostics: dict[str, Any]


@contextlib.contextmanager
def _read_only(rec: Any) -> Iterator[None]:
    """The recording's arrays read-only while a run uses them: a plug-in that reaches them by another way than its
    arguments (a global, a closure) fails in its own code, named (the contract's "writes into an input array"),
    instead of changing the caller's recording and misleading the blocks after it."""
    arrays = [a for a in (getattr(rec, k, None) for k in ("t", "acc", "gyr", "mag", "dist"))
              if isinstance(a, np.ndarray) and a.flags.writeable]
    for a in arrays:
        a.flags.writeable = False
    try:
        yield
    finally:
        for a in arrays:
            a.flags.writeable = True


class Pipeline:
    """An orientation filter, a stance detector, corrections and analyses.

    Parameters
    ----------
    orientation : Orientation
        Attitude source.
    detector : Detector
        Stance detector.
    corrections : list of corrections
        Applied in order; Kalman corrections stack their rows in this order.
    name : str
        Pipeline name.
    gravity : float
        g (m/s²), within :data:`footzoo.core.checks.GRAVITY_RANGE` (9.7–9.9).
    init : dict
        ``duration`` (s) and ``max_gyr`` (rad/s) of the still start used for alignment.
    analysis : list of Analysis
        Run on the finished trajectory.
    navigation : NavigationNoise or dict, optional
        Process noise and initial uncertainty of the INS core of the Kalman filter.
    smoother : {"none", "rts", "stepwise"}
        ``rts``: after the Kalman filter's forward pass, a Rauch–Tung–Striebel backward pass
        over the whole recording (:mod:`footzoo.filters.smoother`, without a gain or an
        inverse: about the forward pass's cost; offline only). ``stepwise``:
        the same backward pass over each stride, from the last sample of a stance back to the
        previous one (Colomar, Nilsson & Händel 2012; :mod:`footzoo.filters.stepwise`): it runs
        live, each stride final once the stance after it has ended. The forward trajectory
        stays in ``Result.diagnostics['pos_forward']`` (and ``vel_forward``, ``quat_forward``).
    plugins : list of str, optional
        External plug-in modules or ``.py`` files (absolute paths) the config needs; recorded in
        :meth:`to_dict` (loading them is :meth:`from_dict`'s job, see :mod:`footzoo.plugins.extensions`).
    guards : StanceGuard or dict, optional
        What a run does when the detector misses stances (stance at the stillest instants of a
        swing longer than ``max_swing``) and the speed bound of the estimate; see
        :mod:`footzoo.runtime.guards`. On by default.
    calibration : list of Calibration, optional
        In-situ sensor calibrations (:mod:`footzoo.calibration`), fitted on each recording and
        applied in order before every other stage; their reports are in
        ``Result.diagnostics["calibration"]``.
    """

    SMOOTHERS = ("none", "rts", "stepwise")

    def __init__(
        self,
        orientation: Orientation,
        detector: Detector | None = None,
        corrections: list[Plugin] | None = None,
        name: str = "pipeline",
        gravity: float = GRAVITY,
        init: dict[str, float] | None = None,
        analysis: list[Analysis] | None = None,
        navigation: NavigationNoise | dict[str, Any] | None = None,
        smoother: str = "none",
        plugins: list[str] | None = None,
        guards: StanceGuard | dict[str, Any] | None = None,
        calibration: list[Calibration] | None = None,
    ):
        self.calibration = list(calibration or [])
        for i, c in enumerate(self.calibration):
            if not isinstance(c, Calibration):
                raise ConfigError(f"calibration[{i}] must be a footzoo.plugins.Calibration, got {type(c).__name__}")
        if detector is None or isinstance(orientation, (str, os.PathLike, dict)):
            how = ("Pipeline.from_dict(mapping)" if isinstance(orientation, dict) else
                   f"Pipeline.from_yaml({str(orientation)!r})" if isinstance(orientation, (str, os.PathLike)) else
                   "Pipeline.from_yaml(name) or Pipeline.from_dict(mapping)")
            raise ConfigError(f"Pipeline(orientation, detector, ...) builds a pipeline from plug-in objects; a config "
                              f"is read with {how}")
        self.orientation = orientation
        self.detector = detector
        self.corrections = list(corrections or [])
        self.analysis = list(analysis or [])
        self.name = name
        self.gravity = GRAVITY_PARAMETER.validate(gravity)
        self.init = check_init(init or {})
        self.navigation = (navigation if isinstance(navigation, NavigationNoise)
                           else NavigationNoise.from_dict(navigation))
        self.plugins = list(plugins or [])
        self.guards = guards if isinstance(guards, StanceGuard) else StanceGuard.from_dict(guards)
        check_parameters([*self.calibration, orientation, detector, *self.corrections, *self.analysis])
        check_compatibility(orientation, detector, self.corrections)
        fits = [c.name for c in self.calibration]
        if len(set(fits)) < len(fits):  # the second fit would calibrate the signals the first already calibrated
            raise ConfigError(f"calibration: {sorted({n for n in fits if fits.count(n) > 1})} listed more than once; "
                              "keep one of each")
        if smoother not in self.SMOOTHERS:
            raise ConfigError(f"smoother must be one of {list(self.SMOOTHERS)}, got {smoother!r}")
        if smoother != "none" and not self.filter_corrections:
            raise ConfigError(f"smoother: {smoother} smooths the Kalman filter, and this pipeline has none; "
                              "add a Kalman correction (e.g. zupt) or remove smoother")
        default = NavigationNoise().to_dict()
        if not self.filter_corrections and self.navigation.to_dict() != default:
            changed = sorted(k for k, v in self.navigation.to_dict().items() if default[k] != v)
            raise ConfigError(f"navigation: {', '.join(changed)} set(s) the Kalman filter's noises, and this pipeline "
                              "has none, so it would change nothing; add a Kalman correction (e.g. zupt) or remove "
                              "navigation")
        self.smoother = smoother

    # ----------------------------------------------------------------- build
    @classmethod
    def from_dict(cls, d: dict[str, Any], base_dir: str | Path | None = None) -> Pipeline:
        """Build and validate a pipeline from a config mapping (see :mod:`footzoo.config`).

        A ``plugins:`` list (module names or ``.py`` paths, relative to ``base_dir``, default the
        working directory) is loaded first, so the config can use the plug-ins it registers.
        """
        check_top_level(d)
        return cls(**pipeline_arguments(d, base_dir))

    @classmethod
    def from_yaml(cls, path: str | Path) -> Pipeline:
        """Build a pipeline from a YAML file, or a shipped config by name (``"recommended"``, see ``footzoo configs``).

        Plug-in paths in the file are relative to its folder.
        """
        path = resolve(path)
        d = load_yaml(path)
        try:
            return cls.from_dict(d, base_dir=path.parent)
        except ConfigError as err:
            raise prefixed(err, path) from err.__cause__

    def to_dict(self) -> dict[str, Any]:
        """The resolved configuration, every parameter explicit."""
        out = {
            "name": self.name,
            "gravity": self.gravity,
            "init": dict(self.init),
            "navigation": self.navigation.to_dict(),
            "smoother": self.smoother,
            "guards": self.guards.to_dict(),
            "calibration": [c.spec() for c in self.calibration],
            "orientation": self.orientation.spec(),
            "detector": self.detector.spec(),
            "corrections": [c.spec() for c in self.corrections],
            "analysis": [a.spec() for a in self.analysis],
        }
        if self.plugins:
            out["plugins"] = list(self.plugins)
        return out

    # ------------------------------------------------------------ structure
    @property
    def filter_corrections(self) -> list[KalmanCorrection]:
        """The corrections acting inside the Kalman filter (empty: no filter).

        A filter runs when a correction can only act inside one; corrections that have both a
        filter and a batch form (heading reduction) then act inside it too.
        """
        kalman = [c for c in self.corrections if isinstance(c, KalmanCorrection)]
        needs_filter = any(not isinstance(c, (AccelerationCorrection, VelocityCorrection)) for c in kalman)
        return kalman if needs_filter else []

    # ------------------------------------------------------------------ live
    def blocks(self) -> list[Plugin]:
        """The blocks a sample passes through, in order (calibrations, detector, orientation, corrections)."""
        kalman = self.filter_corrections
        orientation = [] if (kalman and self.orientation.carried_by_filter) else [self.orientation]
        return [*self.calibration, self.detector, *orientation, *self.corrections]

    def latency(self, ctx: RunContext) -> Latency:
        """How long after a sample its final estimate comes, live (:class:`~footzoo.plugins.incremental.Latency`).

        The blocks' look-aheads add up: the detector's, the guard's, the orientation filter's (a
        warm-up at most), the corrections' and the smoother's.
        """
        parts = [checked(self.detector.latency, ctx), self.guards.latency(ctx)]
        parts += [checked(b.latency, ctx) for b in self.blocks() if b is not self.detector
                  and not isinstance(b, Calibration)]
        if self.smoother == "rts":
            parts.append(Latency(until=(WHOLE_RECORDING,)))
        elif self.smoother == "stepwise":  # a stride closes at its stance's last sample, seen at the next one
            parts.append(Latency(ctx.seconds(1), (STEPWISE_WAIT,)))
        if any(not c.is_fitted() for c in self.calibration):
            parts.append(Latency(warmup=STREAM_WARMUP))
        return total(parts)

    def live_problems(self, fits: list[dict[str, Any]] | None = None) -> list[str]:
        """Why this pipeline cannot run live (empty: it can), each reason with the fix."""
        reasons = []
        for block in self.blocks():
            if isinstance(block, Calibration):
                continue
            if block.needs_truth:
                reasons.append(f"{block.kind} {block.name!r} reads the reference (truth), which a live stream does "
                               "not have")
            elif isinstance(block, KalmanCorrection) and block in self.filter_corrections:
                continue
            elif not block.incremental():
                reasons.append(f"{block.kind} {block.name!r} does not implement the incremental protocol "
                               "(begin/step/finish): it runs on whole recordings only (to run it live, write them: "
                               "docs/plugins.md, 'Example 3: a detector that runs live')")
        if fits is not None and len(fits) != len(self.calibration):
            reasons.append(f"fits: {len(fits)} calibration fit(s) for {len(self.calibration)} calibration(s)")
        if self.smoother == "rts":
            reasons.append("smoother 'rts' runs backwards over the whole recording: use smoother: stepwise (it "
                           "closes each stride once the next stance has been seen; the shipped 'recommended_live' is "
                           "'recommended' so) or smoother: none")
        return reasons

    def with_fits(self, fits: Any) -> Pipeline:
        """This pipeline with its calibrations' fits fixed (from ``Result.diagnostics["calibration"]`` or a Result):
        a batch run of it equals a stream given the same fits."""
        reports = fits.diagnostics.get("calibration") if hasattr(fits, "diagnostics") else fits
        if reports is None or len(reports) != len(self.calibration):
            raise ConfigError(f"with_fits: give one fit per calibration ({len(self.calibration)}), got {reports!r:.80}")
        out = copy.copy(self)
        out.calibration = [checked(c.fixed, r) for c, r in zip(self.calibration, reports, strict=True)]
        return out

    # ------------------------------------------------------------------- run
    def run(self, rec: Recording, engine: str = "auto", covariance: bool = False) -> Result:
        """Estimate attitude, velocity, position and steps for one recording.

        Parameters
        ----------
        rec : Recording
            The input.
        engine : {"auto", "fast", "reference"}
            For Kalman-filter pipelines: the compiled loop (:mod:`footzoo.filters.compiled`)
            or the reference loop on filterpy's ``KalmanFilter``; ``auto`` takes the compiled
            one when every correction's measurement model compiles, else the reference with a
            warning. Both give the same numbers.
        covariance : bool
            Keep the Kalman filter's variances per sample in ``Result.diagnostics['P_diag']``
            ((N, n), n × 8 bytes per sample; off by default) and the position's standard deviation
            (m, north, east, down) in ``Result.diagnostics['pos_std']`` (N, 3) and in the samples'
            columns ``pos_std_n``, ``pos_std_e``, ``pos_std_d``. Both are the forward
            filter's: with the RTS smoother the smoothed positions are at least as certain, so
            ``pos_std`` bounds their error from above (see benchmarks/accuracy.md, consistency).
            Also each update's normalised innovation squared (``diagnostics['nis']``, with its rows
            in ``diagnostics['nis_rows']``) and their summary ``diagnostics['consistency']``
            (:func:`footzoo.evaluation.metrics.nis_summary`: 1 per row for a consistent filter).
        """
        if not isinstance(self, Pipeline):  # Pipeline.run(rec, pipe): the class's method with the arguments swapped
            raise NotAPipelineError(f"Pipeline.run was called on a {type(self).__name__}: call it on a pipeline, "
                                    "pipeline.run(rec) (e.g. footzoo.Pipeline.from_yaml('yun2012').run(rec))")
        checked_engine("Pipeline.run", engine)
        covariance = checked_flag("Pipeline.run", "covariance", covariance)
        with inputs_checked_once(), _read_only(rec):  # each array is scanned for NaN once; none is written meanwhile
            return self._run(rec, engine, covariance)

    def _run(self, rec: Recording, engine: str, covariance: bool) -> Result:
        if not isinstance(rec, Recording):
            hint = (f": load it first, Pipeline.run(footzoo.load({str(rec)!r}))" if isinstance(rec, (str, os.PathLike))
                    else ": build one with footzoo.Recording.from_dataframe(df) (columns t, acc_x, ..., gyr_z)"
                    if isinstance(rec, pd.DataFrame)
                    else ": build one with footzoo.load(path) or footzoo.Recording(t=..., acc=..., gyr=...)")
            raise NotARecordingError(f"Pipeline.run expects a footzoo Recording, got {type(rec).__name__}{hint}")
        self._check_inputs(rec)
        ctx = self.context(rec)
        chunk = recording_chunk(rec, ctx, self.init["duration"])
        prepared = rec.meta.get(PREPARED) == self._preparation()  # from prepare(): its gain and calibrations hold
        chain = build_chain(self, ctx, chunk, engine, covariance, truth=rec.truth, whole=True, prepared=prepared)
        out = chain.push(chunk, finish=True)  # the whole recording, in one finished chunk
        if self.calibration or any(isinstance(stage, GainStage) for stage in chain.stages):
            rec = with_signals(rec, out)  # the checks of the estimate read the signals the run used, as a stream's do
        return self._result(rec, ctx, out, chain.report(), chain.engine)

    def _result(self, rec: Recording, ctx: RunContext, out: Chunk, reports: dict[str, Any], engine: str) -> Result:
        """The Result of a batch run from the chain's outputs and reports: steps, analyses and the checks of the
        estimate."""
        stance, quat, pos = out["stance"], out["quat"], out["pos"]
        stances = real_stances(stance, pos)  # the steps and the mounting report share them and the rate
        sagittal = sagittal_rate(quat, rec.gyr, pos, stances) if len(stances) >= 2 else None
        steps = self.analyse(rec, stance, quat, pos, stances, sagittal)
        reports["guards"].update(check_speed(rec.t, out["vel"], self.guards.max_speed, rec.name))
        scan = EstimateScan(ctx.t0 + self.init["duration"], self.gravity, rec.name, self.detector.name,
                            self.correction_holds())
        scan.dropouts(rec.meta.get("sanity", {}).get("frozen", []))  # a frozen channel explains what follows it
        scan.push(out["k"], rec.t, rec.acc, rec.gyr, stance, pos)
        axes = ConsistencyScan(ctx.rate, self.gravity, rec.name)
        axes.push_recording(rec.t, rec.acc, rec.gyr)
        scan.use_evidence(axes)  # the gait's plausibility weighs the gyroscope-accelerometer evidence of the rate
        sensor = {**rec.meta.get("sanity", {}), **scan.finish()}
        fault = axes.finish()  # a gyroscope axis of the wrong sign turns the attitude the mounting is measured from
        if fault:
            sensor["consistency"] = fault
        calibration = reports.pop("calibration", None)
        diagnostics = {**reports, "sensor": sensor}  # a missing detector statistic is NaN, with a note
        if calibration is not None:
            diagnostics["calibration"] = calibration
        diagnostics["mounting"] = mounting_report(quat, rec.gyr, pos, stances, sagittal)
        warn_mounting(diagnostics["mounting"], rec.name, rec.meta.get("axes"), fault.get("cause"))
        config = self.to_dict()
        config["engine"] = engine
        samples = samples_frame(rec.t, quat, pos, out["vel"], out["acc_nav"], stance)
        if "pos_std" in diagnostics:  # covariance=True: the position's standard deviation beside the position
            for j, axis in enumerate("ned"):
                samples[f"pos_std_{axis}"] = diagnostics["pos_std"][:, j]
        return Result(samples=samples, steps=steps, config=config, versions=versions(),
                      recording=dict(rec.meta), diagnostics=diagnostics, reference=rec.truth)

    def correction_holds(self) -> list[tuple[str, float | None]]:
        """Each correction's name and its stillness hold's ``hold_after`` (s; None: it has none), for the checks
        that word why a standing foot moved (:class:`footzoo.core.sanity.EstimateScan`)."""
        return [(c.name, float(c.hold_after) if "hold_after" in c.param_names() else None) for c in self.corrections]

    def context(self, rec: Recording) -> RunContext:
        """The run context of a batch run over ``rec``: its median rate, this pipeline's gravity, its start."""
        return RunContext.of(rec, self.gravity)

    def _use_mag(self, rec: Recording) -> bool:
        return rec.mag is not None and bool(getattr(self.orientation, "use_magnetometer", False))

    def _check_inputs(self, rec: Recording) -> None:
        """Refuse, before any work, a recording that a block cannot use (a missing sensor, an unknown foot)."""
        for p in [*self.calibration, self.orientation, self.detector, *self.corrections, *self.analysis]:
            if p.needs_magnetometer and rec.mag is None:
                raise RecordingError(f"{p.kind} {p.name!r} needs a magnetometer; the recording {rec.name!r} has none: "
                                     f"load one with mag_x, mag_y, mag_z or choose another {p.kind}")
        for a in self.analysis:
            checked(a.check, dict(rec.meta))

    # ------------------------------------------------------- the stages alone
    def prepare(self, rec: Recording) -> Prepared:
        """Stage 0: the recording as :meth:`run` prepares it for the other stages, its initial attitude and reports.

        The same stages as :meth:`run` (:func:`footzoo.runtime.chain.input_stages`): the
        accelerometer's gain, when the still start reads more than 3 % off g (scaled back to g, with a
        :class:`~footzoo.core.errors.SensorWarning`), then the calibrations, fitted on the whole
        recording. The step-by-step methods (:meth:`detect`, :meth:`guard`, :meth:`orient`,
        :meth:`navigate`) prepare a raw recording themselves (each call again, with its warning) and
        take one from here as it is, as :meth:`run` does (its result's diagnostics then lack this
        preparation's, which are here): prepare once and pass the prepared recording on::

            rec, q0, diagnostics = pipe.prepare(raw)
            stance, _ = pipe.guard(rec, pipe.detect(rec))
            nav = pipe.navigate(rec, stance, q0, pipe.orient(rec, stance, q0))  # nav["pos"] == pipe.run(raw).pos

        Returns
        -------
        Prepared
            ``recording``: a copy of ``rec`` with the prepared signals (``rec`` stays; its arrays are
            shared when nothing changes them); ``q0``: the attitude at the first sample (body -> NED
            quaternion), aligned on the prepared still start as :meth:`run` aligns it (heading from the
            magnetometer when the orientation reads it); ``diagnostics``: the entries :meth:`run` puts in
            ``Result.diagnostics`` for these stages, ``acc_gain`` (when scaled) and ``calibration`` (with
            calibrations).
        """
        rec = inputs.recording("Pipeline.prepare", rec)
        ctx = self.context(rec)
        stages, out = input_stages(self, ctx, recording_chunk(rec, ctx, self.init["duration"]), whole=True)
        q0, _ = aligned(self, out)
        prepared = with_signals(rec, out)
        prepared.meta = {**rec.meta, PREPARED: self._preparation()}
        return Prepared(prepared, q0, Chain(stages).report())

    def _preparation(self) -> dict[str, Any]:
        """What the preparation of a recording depends on (a prepared recording's ``meta["prepared"]``)."""
        return {"gravity": self.gravity, "init": dict(self.init), "calibration": [c.spec() for c in self.calibration]}

    def _prepared(self, rec: Recording) -> Recording:
        """``rec`` when this pipeline's :meth:`prepare` made it (or one prepared alike), else ``rec`` prepared."""
        if isinstance(rec, Recording) and rec.meta.get(PREPARED) == self._preparation():
            return rec
        return self.prepare(rec).recording

    def calibrate(self, rec: Recording) -> tuple[Recording, list[dict[str, Any]]]:
        """The recording as :meth:`prepare` gives it (the gain and the calibrations applied) and the calibrations'
        reports (``Result.diagnostics["calibration"]``; empty without calibrations)."""
        prepared = self.prepare(rec)
        return prepared.recording, prepared.diagnostics.get("calibration", [])

    def detect(self, rec: Recording, ctx: RunContext | None = None) -> Detector:
        """Stage 1: the fitted detector (``stance_``, ``statistic_``) on the recording as :meth:`run` prepares it.

        ``rec``: the recording, raw or from :meth:`prepare` (a raw one is prepared here: the same
        stance as :meth:`run`'s detector stage, and the same ``SensorWarning`` for a gain error).
        """
        ctx = inputs.context("Pipeline.detect", ctx)
        rec = self._prepared(rec)
        return detected(self.detector, rec.t, rec.acc, rec.gyr, ctx or self.context(rec), rec.truth)

    def guard(self, rec: Recording, detector: Detector,
              ctx: RunContext | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        """Stage 1b: the stance mask the rest of the run uses, after the maximum-swing guard, and its report.

        ``rec``: raw or from :meth:`prepare` (see :meth:`detect`).
        """
        ctx = inputs.context("Pipeline.guard", ctx)
        rec = self._prepared(rec)
        detector = inputs.fitted_detector("Pipeline.guard", detector, rec)
        return guarded(self.guards, rec.t, rec.gyr, detector, ctx or self.context(rec), rec.name)

    def orient(self, rec: Recording, stance: np.ndarray, q0: np.ndarray,
               ctx: RunContext | None = None) -> np.ndarray | None:
        """Stage 2: the attitude (N, 4), or None when the Kalman filter carries it.

        ``rec``: raw or from :meth:`prepare` (see :meth:`detect`); ``q0``: the initial attitude, as
        :meth:`prepare` gives it for the result of :meth:`run`.
        """
        where = "Pipeline.orient"
        stance = inputs.stance(where, stance, inputs.recording(where, rec))
        q0 = inputs.initial_attitude(where, q0)
        ctx = inputs.context(where, ctx)
        if self.orientation.carried_by_filter and self.filter_corrections:
            return None
        rec = self._prepared(rec)
        mag = rec.mag if self._use_mag(rec) else None
        return estimate_attitude(self.orientation, rec.t, rec.acc, rec.gyr, mag, stance, q0, ctx or self.context(rec))

    def navigate(self, rec: Recording, stance: np.ndarray, q0: np.ndarray, quat: np.ndarray | None,
                 engine: str = "auto", covariance: bool = False, ctx: RunContext | None = None) -> dict[str, Any]:
        """Stage 3: velocity and position (and the filter's attitude): the Kalman engine or batch corrections.

        ``rec``: raw or from :meth:`prepare` (see :meth:`detect`); ``q0``: the initial attitude, as
        :meth:`prepare` gives it for the result of :meth:`run`.
        A dict of ``quat``, ``vel``, ``pos``, ``acc_nav`` (the samples'), ``diagnostics`` and ``engine``.
        """
        where = "Pipeline.navigate"
        stance = inputs.stance(where, stance, inputs.recording(where, rec))
        q0 = inputs.initial_attitude(where, q0)
        if quat is not None:
            quat = inputs.attitude(where, quat, rec, "pipe.orient(rec, stance, q0) gives it (None when the filter "
                                   "carries the attitude)")
        checked_engine(where, engine)
        ctx = inputs.context(where, ctx)
        rec = self._prepared(rec)
        ctx = ctx or self.context(rec)
        chunk = {**recording_chunk(rec, ctx, self.init["duration"]), "stance": stance}
        if quat is not None:
            chunk["quat"] = quat
        stage = navigation_stage(self, ctx, chunk, q0, engine, covariance)
        out = stage.push(chunk, finish=True)
        return {**{k: out[k] for k in ("quat", "vel", "pos", "acc_nav")}, "diagnostics": stage.report(),
                "engine": Chain([stage]).engine}

    def kalman_engine(self, kalman: list[KalmanCorrection], samples: Samples, engine: str = "auto") -> KalmanEngine:
        """The error-state engine for these (fresh) corrections, with their models built from ``samples``."""
        models = []
        for c in kalman:
            m = checked(c.model, samples)
            m.data = np.ascontiguousarray(checked(c.sample_data, samples), dtype=float)
            models.append(m)
        blocks = [b for c in kalman for b in checked(c.state_blocks)]
        return KalmanEngine(self.orientation.carried_by_filter, blocks, models, self.navigation, self.gravity, engine,
                            names=[f"correction {c.name!r}" for c in kalman])

    def analyse(self, rec: Recording, stance: np.ndarray, quat: np.ndarray, pos: np.ndarray,
                stances: np.ndarray | None = None, sagittal: np.ndarray | None = None) -> pd.DataFrame:
        """Stage 4: the steps table, with the analysis plug-ins' columns.

        ``stances`` and ``sagittal``: the real stances and the sagittal rate when the caller has them
        (:func:`footzoo.analysis.strides.segment_steps`).
        """
        where = "Pipeline.analyse"
        rec = inputs.recording(where, rec)
        stance = inputs.stance(where, stance, rec)
        quat = inputs.attitude(where, quat, rec, "pipe.navigate(...)['quat'] gives it")
        pos = inputs.positions(where, pos, rec)
        steps = segment_steps(rec.t, stance, pos, rec.gyr, quat=quat, stances=stances, sagittal=sagittal,
                              acc=rec.acc)
        for a in self.analysis:
            steps = checked(checked(a.clone().analyze, rec.t, quat, pos, stance, rec.meta).annotate, steps, rec.t)
        return steps


def pipeline_arguments(d: dict[str, Any], base_dir: str | Path | None = None,
                       errors: list[str] | None = None) -> dict[str, Any]:
    """The keyword arguments of :class:`Pipeline` for a config mapping: its plug-ins loaded and built.

    The one way a config becomes a pipeline, for :meth:`Pipeline.from_dict` (``footzoo run``) and
    :func:`footzoo.runtime.validate.config_errors` (``footzoo validate``) alike: the ``plugins:``
    list first (paths relative to ``base_dir``, the config file's folder; default the working
    directory), then each plug-in section.

    Parameters
    ----------
    d : dict
        The config mapping (its top-level keys already checked).
    base_dir : path, optional
        Folder the ``plugins:`` paths are relative to.
    errors : list of str, optional
        Collect every problem here (each section on its own, the settings blocks too) instead of
        raising the first.

    Raises
    ------
    ConfigError
        Without ``errors``: the first problem.
    """

    def attempt(action, *args):
        if errors is None:
            return action(*args)
        try:
            return action(*args)
        except ConfigError as err:
            errors.append(str(err))
            return None

    def listed(key: str) -> list[Any]:
        items = d.get(key) or []
        return items if isinstance(items, list) else []  # not a list: a top-level error already

    loaded = attempt(load_plugins, d.get("plugins"), base_dir) or []
    calibration = [attempt(build, "calibration", c, f"calibration[{i}]") for i, c in enumerate(listed("calibration"))]
    parts = {key: attempt(build, key, d[key], key) for key in ("orientation", "detector") if key in d}
    corrections = [attempt(build, "correction", c, f"corrections[{i}]") for i, c in enumerate(listed("corrections"))]
    analysis = [attempt(build, "analysis", a, f"analysis[{i}]") for i, a in enumerate(listed("analysis"))]
    if errors is not None:  # each settings block on its own, so that one error does not hide another
        attempt(GRAVITY_PARAMETER.validate, d.get("gravity", GRAVITY))
        for block, key in ((Init, "init"), (NavigationNoise, "navigation"), (StanceGuard, "guards")):
            attempt(block.from_dict, d.get(key))
    return dict(
        orientation=parts.get("orientation"),
        detector=parts.get("detector"),
        corrections=corrections,
        name=str(d.get("name", "pipeline")),
        gravity=d.get("gravity", GRAVITY),
        init=d.get("init") or {},
        analysis=analysis,
        navigation=d.get("navigation"),
        smoother=d.get("smoother", "none"),
        plugins=[p["spec"] for p in loaded],
        guards=d.get("guards"),
        calibration=calibration,
    )


def require_pipeline(pipeline: Any, caller: str) -> None:
    """Raise a :class:`NotAPipelineError` unless ``pipeline`` is a :class:`Pipeline`, saying how to build one
    (``caller``: what needs it, e.g. ``"Stream"``, ``"Session.run"``)."""
    if isinstance(pipeline, Pipeline):
        return
    hint = (f" ({caller}(Pipeline.from_yaml({pipeline!r})) builds it from a config)"
            if isinstance(pipeline, (str, os.PathLike))
            else "; build one with footzoo.Pipeline.from_yaml(name), name a shipped config or a YAML file")
    raise NotAPipelineError(f"{caller} needs a footzoo Pipeline, got {type(pipeline).__name__} {pipeline!r:.80}{hint}")


def check_compatibility(orientation: Plugin, detector: Plugin, corrections: list[Plugin]) -> None:
    """Reject plug-in combinations that cannot work together, with the reason and the fix."""
    names = [c.name for c in corrections]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ConfigError(f"corrections: {dupes} listed more than once; keep one of each")
    velocity = [c.name for c in corrections if isinstance(c, VelocityCorrection)]
    if len(velocity) > 1:
        raise ConfigError(f"corrections {velocity}: only one velocity correction can be applied")
    kalman = [c for c in corrections if isinstance(c, KalmanCorrection)]
    filter_only = [c.name for c in kalman if not isinstance(c, (AccelerationCorrection, VelocityCorrection))]
    if filter_only and velocity:
        raise ConfigError(
            f"corrections: {velocity} corrects the velocity after the strapdown, and {filter_only} runs in the "
            f"error-state Kalman filter, which corrects it too; choose one: drop {velocity}, and give the filter "
            "its stance update (zupt or ekf_zupt), or drop the Kalman corrections"
        )
    if not filter_only:
        return
    seen: dict[str, str] = {}
    for c in kalman:
        for quantity in c.observes:
            if quantity in seen:
                raise ConfigError(f"corrections {[seen[quantity], c.name]}: both measure the {quantity} in the same "
                                  "filter; keep one")
            seen[quantity] = c.name
    if not orientation.carried_by_filter:
        for c in kalman:
            if checked(c.requires_attitude_state):
                raise ConfigError(
                    f"{c.name}: inside the Kalman filter {filter_only} it observes the attitude error, which is a "
                    f"filter state only with an orientation the filter carries (orientation: ins); got "
                    f"{orientation.name!r}: use orientation: {{type: ins}}"
                    + (" or set gyro_bias: false and zero_rate: false" if "gyro_bias" in c.param_names() else "")
                )


def versions() -> dict[str, str]:
    """Versions of footzoo and its numerical dependencies (for reproducibility)."""
    import platform

    import scipy

    return {
        "footzoo": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
    }
