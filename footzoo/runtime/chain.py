"""The chain of stages of a run, made in one place for a batch run and a live stream.

:func:`build_chain` decides which stages a pipeline has — its calibrations (if any), the
detector and its guard, the orientation filter (unless the Kalman filter carries the
attitude), then the Kalman engine or batch navigation — and makes them for a run's start:
the whole recording (:meth:`footzoo.Pipeline.run` pushes it as one finished chunk) or a
stream's first seconds (:class:`footzoo.Stream` pushes chunk after chunk). The start gives the
calibrations' fit, the initial attitude and the Kalman models.
"""

from __future__ import annotations

import copy
import operator
from typing import Any

import numpy as np

from ..core.context import RunContext
from ..core.data import Recording
from ..plugins.base import Calibration, Samples
from ..plugins.incremental import Chunk, length
from .alignment import accelerometer_gain, initial_attitude, warn_moving_start
from .stage import Stage
from .stages import (
    BatchNavigationStage,
    CalibrationStage,
    DetectorStage,
    GainStage,
    KalmanStage,
    OrientationStage,
)


class Chain:
    """Stages in series: each stage's final outputs are the next one's inputs."""

    def __init__(self, stages: list[Stage]):
        self.stages = stages

    def push(self, chunk: Chunk, finish: bool = False) -> Chunk:
        """The next samples (``finish``: the data ends after them); the samples whose outputs became final."""
        out = chunk
        for stage in self.stages:
            out = stage.push(out, finish=finish) if (length(out) or finish) else {}
        return out

    def held(self) -> int:
        """Samples the stages hold, their outputs not final yet."""
        return sum(stage.held() for stage in self.stages)

    def guess(self) -> Chunk:
        """The current guess for every sample after the final ones (each stage's guess fed to the next)."""
        out: Chunk = {}
        for stage in self.stages:
            out = stage.guess(out)
        return out

    def report(self) -> dict[str, Any]:
        """The stages' reports, in order (for ``Result.diagnostics``)."""
        out: dict[str, Any] = {}
        for stage in self.stages:
            out.update(stage.report())
        return out

    @property
    def engine(self) -> str:
        """The Kalman engine that runs (``"fast"``, ``"reference"``), or ``"none"`` without a filter."""
        kalman = [stage for stage in self.stages if isinstance(stage, KalmanStage)]
        return kalman[0].engine.engine if kalman else "none"


def with_init(chunk: Chunk, ctx: RunContext, duration: float) -> Chunk:
    """The chunk with ``init``: its samples in the still start used for the alignment (Samples.init_window)."""
    return {**chunk, "init": chunk["t"] <= ctx.t0 + duration}


class SampleIndices:
    """The sample indices ``start … stop − 1`` of a whole recording's chunk, as ``np.arange`` gives them, made only
    where they are read (a slice, one index, or the whole as an array): a batch run of 10⁶ samples keeps 8 MB less.

    A batch run's stages read the first index (the calibrations, the Kalman stage) and the estimate's
    scans read them block by block (:class:`footzoo.core.plausibility.GaitScan`); a stream's chunks carry arrays.
    """

    __slots__ = ("start", "stop")

    def __init__(self, start: int, stop: int):
        self.start, self.stop = int(start), int(stop)

    def __len__(self) -> int:
        return self.stop - self.start

    def __getitem__(self, i: int | slice) -> np.ndarray | np.int64:
        if isinstance(i, slice):
            lo, hi, step = i.indices(len(self))
            return np.arange(self.start + lo, self.start + hi, step)
        j = operator.index(i)
        j = j + len(self) if j < 0 else j
        if not 0 <= j < len(self):
            raise IndexError(f"sample index {i} out of range for {len(self)} samples")
        return np.int64(self.start + j)

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> np.ndarray:
        return np.arange(self.start, self.stop, dtype=dtype)


def recording_chunk(rec: Recording, ctx: RunContext, duration: float) -> Chunk:
    """A whole recording as one chunk (its arrays, not copies; the sample indices :class:`SampleIndices`), with
    ``init`` (``duration``: s of the still start)."""
    chunk = {"k": SampleIndices(0, rec.n), "t": rec.t, "acc": rec.acc, "gyr": rec.gyr}
    if rec.mag is not None:
        chunk["mag"] = rec.mag
    if rec.dist is not None:
        chunk["dist"] = rec.dist
    return with_init(chunk, ctx, duration)


def with_signals(rec: Recording, out: Chunk) -> Recording:
    """A copy of ``rec`` with the signals of ``out`` (the calibrated ones; ``rec`` stays)."""
    calibrated = copy.copy(rec)
    calibrated.acc, calibrated.gyr, calibrated.mag = out["acc"], out["gyr"], out.get("mag")
    return calibrated


def build_chain(pipeline: Any, ctx: RunContext, start: Chunk, engine: str = "auto", covariance: bool = False,
                truth: Any = None, calibrations: list[Calibration] | None = None, whole: bool = False,
                prepared: bool = False) -> Chain:
    """The stages of ``pipeline`` (a :class:`footzoo.Pipeline`) for a run that starts with ``start``.

    Parameters
    ----------
    pipeline : Pipeline
        The blocks and settings.
    ctx : RunContext
        The run's context.
    start : Chunk
        The run's first samples, with ``init`` (:func:`with_init`): the calibrations are fitted on
        them, the initial attitude is aligned on their still start and the Kalman models are
        built from them.
    engine : {"auto", "fast", "reference"}
        The Kalman engine (:meth:`footzoo.Pipeline.run`).
    covariance : bool
        Keep the Kalman filter's variances and innovations (a whole recording's run).
    truth : Truth, optional
        The reference, for a detector that ``needs_truth`` (a batch run).
    calibrations : list of Calibration, optional
        The calibrations to fit (default: the pipeline's; a stream passes them with given fits).
    whole : bool
        ``start`` is the whole recording (a batch run): every calibration is fitted on it.
    prepared : bool
        The signals are already prepared (:meth:`footzoo.Pipeline.prepare`): no input stage runs again.
    """
    stages, calibrated = ([], start) if prepared else input_stages(pipeline, ctx, start, calibrations, whole)
    q0, use_mag = aligned(pipeline, calibrated)
    stages.append(DetectorStage(pipeline.detector, pipeline.guards, ctx, truth))
    if not (pipeline.filter_corrections and pipeline.orientation.carried_by_filter):
        stages.append(OrientationStage(pipeline.orientation, ctx, q0, use_mag))
    stages.append(navigation_stage(pipeline, ctx, calibrated, q0, engine, covariance))
    return Chain(stages)


def input_stages(pipeline: Any, ctx: RunContext, start: Chunk, calibrations: list[Calibration] | None = None,
                 whole: bool = False) -> tuple[list[Stage], Chunk]:
    """The stages that prepare the signals, before the detector, made on the run's start, and ``start`` as they
    give it.

    The accelerometer's gain (:class:`GainStage`, when the still start reads more than
    :data:`~footzoo.runtime.alignment.ACC_GAIN_TOLERANCE` off g: a ``SensorWarning``), then the
    pipeline's calibrations (:class:`CalibrationStage`, fitted on ``start``). A batch run, a stream
    and :meth:`footzoo.Pipeline.prepare` (the step-by-step API) all prepare the signals here.
    ``calibrations`` and ``whole`` as in :func:`build_chain`.
    """
    stages: list[Stage] = []
    out = start
    warn_moving_start(start["t"], start["gyr"], name=ctx.name, **pipeline.init)
    gain = accelerometer_gain(start["t"], start["acc"], start["gyr"], pipeline.gravity, name=ctx.name, **pipeline.init)
    if gain != 1.0:
        stage = GainStage(gain, pipeline.gravity / gain, pipeline.gravity)
        out = stage.whole(start)
        stages.append(stage)
    if pipeline.calibration:
        cal = CalibrationStage(pipeline.calibration if calibrations is None else calibrations, ctx)
        out = cal.fit(out, whole=whole)
        stages.append(cal)
    return stages, out


def aligned(pipeline: Any, prepared: Chunk) -> tuple[np.ndarray, bool]:
    """The initial attitude (body -> NED quaternion) of a run from its prepared start, and whether the orientation
    reads the magnetometer (then the heading is the magnetometer's, else north)."""
    use_mag = "mag" in prepared and bool(getattr(pipeline.orientation, "use_magnetometer", False))
    q0 = initial_attitude(prepared["t"], prepared["acc"], prepared["gyr"], prepared["mag"] if use_mag else None,
                          **pipeline.init)
    return q0, use_mag


def navigation_stage(pipeline: Any, ctx: RunContext, start: Chunk, q0: np.ndarray, engine: str = "auto",
                     covariance: bool = False) -> Stage:
    """The velocity and position stage of ``pipeline``: the Kalman engine (its models built from ``start``),
    or batch navigation without a filter."""
    kalman = [c.clone() for c in pipeline.filter_corrections]
    if not kalman:
        return BatchNavigationStage(pipeline.corrections, ctx, pipeline.gravity)
    samples = Samples(start["t"], start["acc"], start["gyr"], start.get("mag"), start.get("dist"), start["init"])
    eng = pipeline.kalman_engine(kalman, samples, engine)
    return KalmanStage(eng, kalman, q0, external_attitude=not pipeline.orientation.carried_by_filter,
                       smoother=pipeline.smoother, covariance=covariance)


def recorded_forward(pipeline: Any, rec: Recording, engine: str = "fast") -> tuple[Any, np.ndarray, dict[str, Any]]:
    """The Kalman filter of ``pipeline`` run forward over ``rec`` alone, with a record of every sample: for a smoother
    applied by hand (:mod:`footzoo.filters.smoother`, :mod:`footzoo.filters.stepwise`) in a test or a benchmark.

    ``rec`` is prepared as a run prepares it (:meth:`~footzoo.Pipeline.prepare`: the accelerometer's
    gain, the calibrations); no orientation stage runs (the filter carries the attitude, from the
    initial attitude of the still start, heading north); the positions are in the engine's frame (NED, m), before a
    run's output frame is applied.

    Returns
    -------
    engine : KalmanEngine
        The engine (its ``setup.offsets`` index the records' state blocks).
    stance : (N,) bool array
        The pipeline's detector on ``rec``.
    records : dict
        :meth:`~footzoo.filters.engine.KalmanEngine.advance` with ``record=True``: the trajectory
        (``quat``, ``vel``, ``pos``, biases) and each sample's record.
    """
    rec = pipeline.prepare(rec).recording
    stance = pipeline.detect(rec).stance_
    q0 = initial_attitude(rec.t, rec.acc, rec.gyr, None, **pipeline.init)
    samples = Samples(rec.t, rec.acc, rec.gyr, rec.mag, rec.dist, rec.t <= rec.t[0] + pipeline.init["duration"])
    eng = pipeline.kalman_engine([c.clone() for c in pipeline.filter_corrections], samples, engine)
    nav0 = np.zeros(16)
    nav0[:4] = q0
    records = eng.advance(eng.start(nav0), rec.t, rec.acc, rec.gyr, stance, None, [m.data for m in eng.setup.models],
                          0, False, record=True)
    return eng, stance, records
