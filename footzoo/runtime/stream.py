"""Live estimation: push samples, get the newest sample's estimate at once and every sample's final one later.

Every pipeline whose blocks implement the incremental protocol (:mod:`footzoo.plugins.incremental`;
all of footzoo's do) runs live. :meth:`Stream.push` answers at once with a *provisional*
estimate of the newest sample — what the pipeline knows now, its detector's current guess
of the gait phase carried through a copy of the filters — and the *final* estimate of each
sample comes once the pipeline's declared latency has passed (:meth:`Stream.final`): a
centred window's half, a state machine's delay, a swing that is corrected at its end. The
final estimates equal :meth:`footzoo.Pipeline.run` on the whole recording (to 1e-9; the
same blocks run on the same samples), and the stream keeps only the samples still pending:
its memory is bounded by the latency, not by the length of the recording.

The run context (:class:`~footzoo.core.context.RunContext`) is decided when the stream starts:
the ``rate`` given (the sensor's nominal rate; a batch run uses the recording's median rate,
:attr:`Recording.rate` — :meth:`Stream.run` passes it) or the rate measured over the still
start, with a warning. The filter starts from the batch run's alignment: the first still
period of ``init.duration`` seconds, the attitude carried back to the first sample; until
it has been seen (at most ``max_wait`` seconds) :meth:`Stream.push` returns None.

In-situ calibrations (``hard_iron``) are fitted on a whole recording in a batch run. Live, they
take their fit from ``fits`` (the ``Result.diagnostics["calibration"]`` of an earlier run or of
a calibration recording), from parameters that give it (``hard_iron: {offset: [...]}``), or fit
online on the first ``warmup`` seconds; the final estimates then equal the batch run given the
same fit (:meth:`footzoo.Pipeline.with_fits` and :attr:`Stream.fits`).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..core.checks import gap_limit, validate_block, validate_sample
from ..core.context import RunContext
from ..core.data import check_units
from ..core.errors import ConfigError, FootzooWarning, GuardWarning, RecordingError, user_stacklevel
from ..core.sanity import EstimateScan, SignalScan
from ..filters.consistency import ConsistencyScan
from ..filters.engine import ENGINES
from ..plugins.base import checked
from ..plugins.incremental import Chunk, Latency, length, take
from . import stage_inputs as inputs
from .alignment import first_still_window
from .chain import Chain, build_chain, with_init
from .pipeline import STREAM_WARMUP, require_pipeline
from .stage import Queue, Stage
from .stages import GainStage
from .stream_state import check_channel, check_open, check_unused, chunk_sizes

#: Samples the sensor and physics scans are fed at a time, live (a finding comes at most this many samples late).
SCAN_BLOCK = 128
#: Largest relative difference between the rate a stream is made with and the rate of its time stamps over the
#: still start (a nominal 100 Hz sensor at 98–102 Hz is fine; a 50 Hz one declared at 100 Hz is not).
RATE_TOLERANCE = 0.2
#: The per-sample columns of the final estimates.
COLUMNS = ("t", "quat", "pos", "vel", "acc_nav", "stance")


class Stream:
    """Push samples of a live recording; get the current attitude, velocity, position and gait phase.

    Parameters
    ----------
    pipeline : Pipeline
        Any pipeline whose blocks run live; others are refused with the reason.
    rate : float, optional
        Nominal sampling rate (Hz) of the run context; default: measured over the still start.
    engine : {"auto", "fast", "reference"}
        As :meth:`Pipeline.run`.
    max_gap : float, optional
        Longest accepted time between two pushed samples (s); a longer gap is an error. Default: what a
        batch run bridges (:func:`footzoo.core.checks.gap_limit`: 0.25 s, or 5 periods of the rate when
        that is longer), so a recording that runs in batch runs live.
    max_wait : float
        How long the stream waits for the first still period (s) before it gives up with an error.
    fits : list of dict or Result, optional
        The calibrations' fits (``Result.diagnostics["calibration"]``, or a Result that has them).
    warmup : float
        Seconds of data a calibration without a fit is fitted on, online, at the start.
    guess : bool
        Compute the provisional estimate of each new sample (``push`` returns it); off, ``push``
        returns the newest final estimate instead (cheaper, e.g. to replay a recording).
    max_pending : float
        Warn when this many seconds of samples wait for their final estimate (s): a detector that
        finds no stance keeps a dedrift or a smoother waiting, and the memory grows with it.
    keep : bool
        Also keep every final estimate (and the raw signals) for :meth:`result`: a whole
        :class:`~footzoo.Result` at the end, strides and analyses included (memory grows with the
        recording; off by default).

    Examples
    --------
    >>> s = Stream(Pipeline.from_yaml("recommended"), rate=200.0)     # doctest: +SKIP
    >>> est = s.push(t, acc, gyr)        # None until the still start has been seen
    >>> done = s.final()                 # the final estimates that are ready (arrays)
    >>> rest = s.close()                 # at the end of the data: the remaining ones
    """

    def __init__(self, pipeline: Any, rate: float | None = None, engine: str = "auto", max_gap: float | None = None,
                 max_wait: float = 10.0, fits: Any = None, warmup: float = STREAM_WARMUP, guess: bool = True,
                 max_pending: float = 30.0, keep: bool = False):
        require_pipeline(pipeline, "Stream")
        reasons = pipeline.live_problems(fits=_fit_reports(fits))
        pipeline_reasons = len(reasons)
        if rate is not None and not (isinstance(rate, (int, float)) and not isinstance(rate, bool)
                                     and math.isfinite(rate) and rate > 0):
            reasons.append(f"rate must be a positive number of Hz, got {rate!r}")
        for label, value in (("max_gap", max_gap), ("max_wait", max_wait), ("warmup", warmup),
                             ("max_pending", max_pending)):
            if label == "max_gap" and value is None:
                continue
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and 0 < value < np.inf):
                reasons.append(f"{label} must be a positive number of seconds, got {value!r}")
        if engine not in ENGINES:
            reasons.append(f"engine must be one of {list(ENGINES)}, got {engine!r}")
        if reasons:  # the pipeline's own reasons, then the arguments'
            head = "this pipeline cannot run live: " if pipeline_reasons else "Stream: "
            raise ConfigError(head + "; ".join(reasons))
        self.pipeline = pipeline
        self.rate = rate
        self.engine = engine
        self.max_wait, self.warmup, self.max_pending = max_wait, warmup, max_pending
        self._max_gap = max_gap  # as given; the limit in force is max_gap (with the rate once it is known)
        self.guess = guess
        self.init = dict(pipeline.init)
        self._fits = _fit_reports(fits)
        self.ctx: RunContext | None = None
        self.fits: list[dict[str, Any]] | None = None  # the fits the stream's calibrations used
        self._raw = Queue()  # samples before the start
        self._out = Queue()  # final estimates not taken yet
        self._last_final: dict[str, Any] | None = None
        self._chain: Chain | None = None  # the pipeline's stages, made when the stream starts
        self._k = 0
        self._t_prev: float | None = None
        self._dist_width: int | None = None
        self._has_mag: bool | None = None
        self._closed = False
        self._warned: set[str] = set()
        self.keep = bool(keep)
        self._kept: list[Chunk] = []
        self._signals = SignalScan("stream")  # glitches, as a batch run's Recording scans them
        self._estimates: EstimateScan | None = None  # no stance, drift while still (from the start)
        self._axes: ConsistencyScan | None = None  # gyroscope-accelerometer consistency (rate, axis map)
        self._scan_raw = Blocks(self._signals.push)
        self._scan_final: Blocks | None = None
        self.log: list[dict[str, Any]] | None = None
        self._given: tuple[dict[str, Any], Any] | None = None  # meta and truth of the recording run() pushed

    # ------------------------------------------------------------------ public
    @property
    def max_gap(self) -> float:
        """The longest gap between two pushed samples accepted now (s): ``max_gap`` as given, else the batch
        run's limit at the stream's rate (the given one, or the one measured at the start; 0.25 s before)."""
        rate = self.ctx.rate if self.ctx is not None else self.rate
        return gap_limit(1.0 / rate if rate else 0.0, self._max_gap)

    @property
    def latency(self) -> Latency:
        """The pipeline's declared latency at the stream's rate (at its nominal rate before the start)."""
        return self.pipeline.latency(self.ctx or RunContext(rate=self.rate or 100.0, gravity=self.pipeline.gravity))

    def push(self, t: float, acc: Any, gyr: Any, mag: Any = None, dist: Any = None) -> dict[str, Any] | None:
        """Add one sample (FRD, SI; ``dist`` in m with NaN where no reading); the newest sample's estimate.

        Returns None while the initial still period is being collected, then a dict with ``t``,
        ``quat`` (body → NED), ``pos``, ``vel`` (NED), ``stance`` and ``final`` (whether this
        estimate is already the final one) for the newest sample: provisional when the pipeline
        looks ahead (with ``guess``; else the newest final estimate).
        """
        check_open(self, "push")
        t, acc, gyr, mag, dist = validate_sample(t, acc, gyr, mag, dist, self._t_prev, self.max_gap)
        row = {"k": np.array([self._k]), "t": np.array([t]), "acc": acc[None, :], "gyr": gyr[None, :]}
        check_channel(self, "mag", mag is not None, t)
        if self._has_mag is None:
            self._has_mag = mag is not None
        if mag is not None:
            row["mag"] = mag[None, :]
        d = self._distance_row(dist)
        if d is not None:
            row["dist"] = d[None, :]
        self._k += 1
        self._t_prev = t
        self._scan_raw.add(row["t"], row["acc"], row["gyr"])
        return self._take(row)

    def extend(self, t: Any, acc: Any, gyr: Any, mag: Any = None, dist: Any = None) -> dict[str, Any] | None:
        """Add a block of samples (``t`` (n,), ``acc``, ``gyr`` (n, 3), ...: a sensor's packet); the newest estimate.

        The same final estimates as pushing the samples one by one (the blocks run chunk by chunk
        to the same numbers); cheaper per sample.
        """
        check_open(self, "extend")
        if all(np.size(a) == 0 for a in (t, acc, gyr)):
            return None  # an empty packet (a read that found no new sample): nothing to add
        t, acc, gyr, mag, dist = validate_block(t, acc, gyr, mag, dist, self._t_prev, self.max_gap)
        n = t.shape[0]
        rows = {"k": np.arange(self._k, self._k + n), "t": t, "acc": acc, "gyr": gyr}
        check_channel(self, "mag", mag is not None, t[0])
        if self._has_mag is None:
            self._has_mag = mag is not None
        if mag is not None:
            rows["mag"] = mag
        if dist is not None or self._dist_width is not None:
            d = np.full((n, self._dist_width), np.nan) if dist is None else dist
            if self._dist_width is None:
                if self._k:
                    raise RecordingError("distance readings started after the first sample: push dist (NaN where a "
                                         "sensor has no reading) with every sample from the first one")
                self._dist_width = d.shape[1]
            elif d.shape[1] != self._dist_width:
                raise RecordingError(f"dist has {d.shape[1]} readings, earlier samples had {self._dist_width}")
            rows["dist"] = d
        self._k += n
        self._t_prev = float(t[-1])
        self._scan_raw.add(t, acc, gyr)
        return self._take(rows)

    def pending(self) -> int:
        """How many samples the stream holds because their final estimate is not known yet (its memory)."""
        return len(self._raw) + (self._chain.held() if self._chain is not None else 0)

    def final(self) -> dict[str, np.ndarray]:
        """The final estimates that became available since the last call: arrays ``t``, ``quat``, ``pos``,
        ``vel``, ``acc_nav``, ``stance`` (empty arrays when none)."""
        out = self._out.take(np.iinfo(np.int64).max)
        return _columns(out)

    def close(self) -> dict[str, np.ndarray]:
        """End of the data: every remaining sample's final estimate (as :meth:`final`)."""
        if not self._closed:
            self._closed = True
            if self._chain is None and len(self._raw):
                if not self._start(last=True):  # shorter than the still start: never aligned
                    raise RecordingError(self._no_start_message())
                self._feed(self._raw.take(np.iinfo(np.int64).max))
            if self._chain is not None:
                self._feed({}, finish=True)
            self._scan_raw.flush()
            if self._estimates is not None:
                self._scan_final.flush()
                self._estimates.finish()
                self._axes.finish()
        return self.final()

    @property
    def sensor(self) -> dict[str, Any]:
        """The sensor and physics findings so far (as a batch run's ``Result.diagnostics["sensor"]``).

        Glitches (``gyro_glitches``, ``acc_glitches``: sample numbers), drift while still
        (``still_drift``) and, after :meth:`close`, ``no_stance`` (:mod:`footzoo.core.sanity`); each
        was also warned with a :class:`~footzoo.core.errors.SensorWarning` when found.
        """
        self._scan_raw.flush()
        if self._scan_final is not None:
            self._scan_final.flush()
        out = {**self._signals.report, **(self._estimates.report if self._estimates is not None else {})}
        if self._axes is not None and self._axes.report:
            out["consistency"] = self._axes.report
        return out

    def result(self, meta: dict[str, Any] | None = None, truth: Any = None) -> Any:
        """The whole run as a :class:`~footzoo.Result` (after :meth:`close`; needs ``keep=True``).

        Its samples are the final estimates, its steps and analyses computed on them as a batch
        run computes them; ``meta`` describes the recording (``name``, ``foot``, ...: a loaded
        recording's ``rec.meta``). ``truth`` (a :class:`~footzoo.Truth`, e.g. ``rec.truth``, one row
        per pushed sample) is the reference its :attr:`~footzoo.Result.metrics` are scored against,
        as a batch run's are against its recording's. After :meth:`run`, both default to the
        recording's: the result is then the batch run's (``Pipeline.run(rec)``), computed live.

        The stream warned about its samples as they came (:attr:`sensor`); the result does not warn
        again. Bridged gaps in the time stamps are listed in ``recording["diagnostics"]["gaps"]`` and
        warned here unless ``meta`` already lists them (a loaded recording's meta: its loader warned).
        """
        from ..core.data import Recording, Truth, warn_gaps
        from ..core.table import samples_frame
        from ..evaluation.result import Result
        from .pipeline import versions

        if not self.keep:
            raise ConfigError("Stream.result() needs the final estimates kept: Stream(..., keep=True)")
        if not self._closed:
            raise RecordingError("Stream.result(): close() the stream first (the last samples are not final yet)")
        if truth is not None and not isinstance(truth, Truth):
            hint = ": pass the recording's reference, truth=rec.truth" if isinstance(truth, Recording) else ""
            raise ConfigError(f"Stream.result(truth=...) takes a footzoo Truth, got {type(truth).__name__}{hint}")
        from ..plugins.incremental import concat

        k = concat(self._kept)
        if self._given is not None:  # the defaults of a recording pushed by run()
            meta = self._given[0] if meta is None else meta
            truth = self._given[1] if truth is None else truth
        given = dict(meta or {})
        try:
            rec = Recording(t=k["t"], acc=k["acc"], gyr=k["gyr"], mag=k.get("mag"), meta=given, truth=truth,
                            max_gap=self.max_gap, warn=False)
        except RecordingError as e:
            if truth is None:
                raise
            raise RecordingError(f"Stream.result(truth=...): {e} (the stream was pushed {len(k['t'])} samples)") from e
        if "gaps" not in given.get("diagnostics", {}):
            warn_gaps(rec, refuse="footzoo.Stream(pipeline, max_gap=SECONDS)")
        stance = k["stance"].astype(bool)
        steps = self.pipeline.analyse(rec, stance, k["quat"], k["pos"])
        config = {**self.pipeline.to_dict(), "engine": "stream"}
        diagnostics = {"calibration": self.fits} if self.fits is not None else {}
        for stage in self._stages:  # the gain the stream applied to the specific force, as a batch run reports it
            if isinstance(stage, GainStage):
                diagnostics.update(stage.report())
        diagnostics["sensor"] = self.sensor
        return Result(samples=samples_frame(k["t"], k["quat"], k["pos"], k["vel"], k["acc_nav"], stance),
                      steps=steps, config=config, versions=versions(), recording=dict(rec.meta),
                      diagnostics=diagnostics, reference=truth)

    def run(self, rec: Any, chunk: int | np.ndarray = 1) -> dict[str, np.ndarray]:
        """Push a whole recording and close: every sample's final estimate.

        ``chunk`` samples at a time (1: :meth:`push`, sample by sample; more: :meth:`extend`), or
        blocks of the sizes in an array (e.g. random ones, in the tests). Uses the recording's rate
        (:attr:`Recording.rate`) when the stream was made without one, as the batch run does. With
        ``log`` set to a list, each call's returned estimate is appended. With ``keep``, :meth:`result`
        then describes and scores the run with the recording's ``meta`` and ``truth``.
        """
        rec = inputs.recording("Stream.run", rec)
        sizes = chunk_sizes(chunk)
        check_unused(self)
        if self.keep:  # result()'s defaults: the recording's description and reference
            self._given = (rec.meta, rec.truth)
        if self.rate is None and self.ctx is None:
            self.rate = rec.rate
        parts, k, i = [], 0, 0
        while k < rec.n:
            m = int(sizes[i % sizes.size])
            i += 1
            if m == 1:
                est = self.push(rec.t[k], rec.acc[k], rec.gyr[k], None if rec.mag is None else rec.mag[k],
                                None if rec.dist is None else rec.dist[k])
            else:
                sl = slice(k, k + m)
                est = self.extend(rec.t[sl], rec.acc[sl], rec.gyr[sl], None if rec.mag is None else rec.mag[sl],
                                  None if rec.dist is None else rec.dist[sl])
            if self.log is not None:
                self.log.append(est)
            k += m
            if i % 64 == 0:
                parts.append(self.final())
        parts.append(self.close())
        return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}

    # ------------------------------------------------------------------ the chain
    @property
    def _stages(self) -> list[Stage]:
        """The chain's stages (none before the start)."""
        return self._chain.stages if self._chain is not None else []

    def _take(self, row: Chunk) -> dict[str, Any] | None:
        if self._chain is None:
            self._raw.put(row)
            if not self._start():
                return None
            self._feed(self._raw.take(np.iinfo(np.int64).max))
        else:
            self._feed(self._with_init(row))
        return self._estimate()

    def _with_init(self, chunk: Chunk) -> Chunk:
        """The chunk with ``init``: its samples in the still start used for the alignment (Samples.init_window)."""
        return with_init(chunk, self.ctx, self.init["duration"])

    def _feed(self, chunk: Chunk, finish: bool = False) -> None:
        out = self._chain.push(chunk, finish=finish)
        if length(out):
            self._scan_final.add(out["k"], out["t"], out["acc"], out["gyr"], out["stance"], out["pos"])
            self._out.put({k: v for k, v in out.items() if k in ("k", *COLUMNS)})
            if self.keep:
                self._kept.append({k: v for k, v in out.items() if k in ("k", *COLUMNS, "acc", "gyr", "mag")})
            self._last_final = {k: out[k][-1] for k in ("k", "t", "quat", "pos", "vel", "stance")}
        self._check_pending()

    def _estimate(self) -> dict[str, Any] | None:
        if self._last_final is not None and self._last_final["k"] == self._k - 1:
            return {**_copy(self._last_final), "final": True}
        if not self.guess:
            return None if self._last_final is None else {**_copy(self._last_final), "final": False}
        guess = self._chain.guess()
        if not length(guess):
            return None if self._last_final is None else {**_copy(self._last_final), "final": False}
        return {"t": float(guess["t"][-1]), "quat": guess["quat"][-1].copy(), "pos": guess["pos"][-1].copy(),
                "vel": guess["vel"][-1].copy(), "stance": bool(guess["stance"][-1]), "final": False}

    def _check_pending(self) -> None:
        waiting = self._k - (int(self._last_final["k"]) + 1 if self._last_final is not None else 0)
        if self.ctx is not None and waiting / self.ctx.rate > self.max_pending and "pending" not in self._warned:
            self._warned.add("pending")
            warnings.warn(f"Stream: {waiting / self.ctx.rate:.0f} s of samples wait for their final estimate "
                          f"(max_pending = {self.max_pending:g} s): the detector finds no stance, so the dedrift or "
                          "the smoother cannot close the swing; the stream's memory grows until it does",
                          GuardWarning, stacklevel=user_stacklevel())

    # ------------------------------------------------------------------ start
    def _start(self, last: bool = False) -> bool:
        """Start the chain once the buffer holds the still start (and a calibration's warm-up).

        ``last``: the data ends here (close): a calibration's warm-up is what there is.
        """
        b = self._raw.peek()
        t, gyr = b["t"], b["gyr"]
        duration, max_gyr = self.init["duration"], self.init["max_gyr"]
        if t[-1] - t[0] <= duration:
            return False
        try:  # the batch run's alignment: the first still window, the attitude carried back to sample 0
            first_still_window(t, gyr, duration, max_gyr)
        except RecordingError:
            if t[-1] - t[0] <= self.max_wait:
                return False
            raise RecordingError(self._no_start_message()) from None
        check_units(b["acc"], b["gyr"])  # an accelerometer in g, a gyroscope in deg/s: refused as a batch run does
        pipe = self.pipeline
        channels = {"acc", "gyr", *(["mag"] if self._has_mag else []), *(["dist"] if self._dist_width else [])}
        needs_fit = any(not c.is_fitted() and channels & set(c.fits_on) for c in self._calibrations())
        if needs_fit and t[-1] - t[0] < self.warmup and not last:
            return False
        rate = self.rate
        n_init = int(np.searchsorted(t, t[0] + duration, side="right"))
        measured = 1.0 / float(np.median(np.diff(t[:n_init])))
        if rate is not None and abs(measured / rate - 1.0) > RATE_TOLERANCE:
            raise RecordingError(
                f"Stream: the time stamps of the first {t[n_init - 1] - t[0]:.2f} s come at {measured:.4g} Hz, but "
                f"the stream was made with rate={rate:g} Hz: every window and duration would be off by "
                f"{measured / rate:.3g}×. Pass the sensor's real rate (rate={measured:.4g}), or fix the time stamps "
                "(seconds, of each sample)")
        if rate is None:
            rate = measured
            warnings.warn(f"Stream: no rate given; using {rate:.2f} Hz measured over the still start (a batch run "
                          "uses the whole recording's median rate): pass rate= the sensor's nominal rate",
                          FootzooWarning, stacklevel=user_stacklevel())
        self.ctx = RunContext(rate=rate, gravity=pipe.gravity, t0=float(t[0]), name="stream")
        self._estimates = EstimateScan(self.ctx.t0 + duration, pipe.gravity, "stream", pipe.detector.name,
                                       pipe.correction_holds())
        self._axes = ConsistencyScan(rate, pipe.gravity, "stream")
        self._estimates.use_evidence(self._axes)  # the gait's plausibility weighs the evidence of the rate

        def scan_final(k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
                       pos: np.ndarray) -> None:
            self._estimates.dropouts(self._signals.report.get("frozen", []))  # found in the raw data, ahead
            self._estimates.push(k, t, acc, gyr, stance, pos)
            self._axes.push(k, t, acc, gyr)

        self._scan_final = Blocks(scan_final)
        b = self._with_init(take(b, 0))  # a copy, with the still-start flag
        self._raw = Queue()
        self._raw.put(b)
        calibrations = self._calibrations() if pipe.calibration else None
        self._chain = build_chain(pipe, self.ctx, b, self.engine, calibrations=calibrations)
        if pipe.calibration:  # given fits, or fitted online on the warm-up: the start's samples
            self.fits = self._chain.report()["calibration"]
        return True

    def _calibrations(self) -> list[Any]:
        cals = [c.clone() for c in self.pipeline.calibration]
        if self._fits:
            cals = [checked(c.fixed, r) for c, r in zip(cals, self._fits, strict=True)]
        return cals

    def _no_start_message(self) -> str:
        return (f"the stream found no still period: |ω| stayed above init.max_gyr = {self.init['max_gyr']} rad/s in "
                f"every {self.init['duration']} s of the first {self.max_wait} s; start it with the foot at rest "
                "(or raise max_wait)")

    def _distance_row(self, dist: Any) -> np.ndarray | None:
        """Readings of the distance sensors (m); NaN for a sample without them once a stream has them."""
        if dist is None:
            return None if self._dist_width is None else np.full(self._dist_width, np.nan)
        row = np.asarray(dist, dtype=float).reshape(-1)
        if self._dist_width is None:
            if self._k:
                raise RecordingError("distance readings started after the first sample: push dist (NaN where a "
                                     "sensor has no reading) with every sample from the first one")
            self._dist_width = row.size
        elif row.size != self._dist_width:
            raise RecordingError(f"dist has {row.size} readings, earlier samples had {self._dist_width}: push the "
                                 "same sensors every time (NaN where one has no reading)")
        return row


class Blocks:
    """Feeds a scan its samples in blocks of at least ``every`` (the scans' findings do not depend on how the
    samples are chunked, their cost per call does): :meth:`add` the next samples' arrays, :meth:`flush` the rest."""

    def __init__(self, push: Any, every: int = SCAN_BLOCK):
        self.push, self.every = push, every
        self.parts: list[tuple[np.ndarray, ...]] = []
        self.n = 0

    def add(self, *arrays: np.ndarray) -> None:
        self.parts.append(arrays)
        self.n += len(arrays[0])
        if self.n >= self.every:
            self.flush()

    def flush(self) -> None:
        if self.parts:
            parts, self.parts, self.n = self.parts, [], 0
            self.push(*(np.concatenate(column) for column in zip(*parts, strict=True)))


def _fit_reports(fits: Any) -> list[dict[str, Any]] | None:
    if fits is None:
        return None
    if hasattr(fits, "diagnostics"):
        fits = fits.diagnostics.get("calibration")
        if fits is None:
            raise ConfigError("fits: the Result has no calibration fits (its pipeline has no calibration)")
    if not isinstance(fits, (list, tuple)) or not all(isinstance(f, dict) for f in fits):
        raise ConfigError(f"fits must be a list of calibration reports (Result.diagnostics['calibration']) or a "
                          f"Result, got {type(fits).__name__}")
    return list(fits)


def _columns(chunk: Chunk) -> dict[str, np.ndarray]:
    shapes = {"t": (0,), "quat": (0, 4), "pos": (0, 3), "vel": (0, 3), "acc_nav": (0, 3), "stance": (0,)}
    if not length(chunk):
        return {k: np.zeros(s, dtype=bool if k == "stance" else float) for k, s in shapes.items()}
    return {k: chunk[k] for k in shapes}


def _copy(est: dict[str, Any]) -> dict[str, Any]:
    return {k: (v.copy() if isinstance(v, np.ndarray) and v.ndim else (bool(v) if k == "stance" else float(v)))
            for k, v in est.items() if k != "k"}

