"""Live estimation: push one sample, get the current estimate.

For pipelines whose output at a sample depends only on the samples up to it — an orientation
the Kalman filter carries (the INS), a ``causal`` detector and Kalman corrections only, i.e.
Nguyen & La's real-time system — :class:`Stream` gives exactly what :meth:`Pipeline.run` gives
on the whole recording. It holds the filter's state between samples and advances the same
engine (compiled, or the reference for a correction that does not compile) two samples at a
time, with the same measurement models, built by the same :meth:`Pipeline.kalman_engine`.

The filter starts from the batch run's alignment: the first still period of ``init.duration``
seconds, the attitude carried back to the first sample. Until that period has been seen (at most
``max_wait`` seconds), :meth:`Stream.push` buffers the samples and returns None; then it runs
through the buffer and answers for the newest sample. A detector's windows in
seconds become samples at the sampling ``rate``: give the sensor's nominal rate (the batch run
uses the recording's median rate, :attr:`Recording.rate`; :meth:`Stream.run` passes it), or
leave it out and the stream measures it over the still start, with a warning.

The maximum-swing guard of a batch run (:mod:`footzoo.runtime.guards`) looks at a whole swing once it
has ended; live, the stream cannot, and warns (:class:`~footzoo.core.errors.GuardWarning`) when its
detector has found no stance for ``guards.max_swing`` seconds. Where the guard does not fire in
the batch run, the stream gives exactly its result.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..core.checks import validate_sample
from ..core.errors import ConfigError, FootzooWarning, GuardWarning, RecordingError
from ..plugins.base import KalmanCorrection, Samples
from .alignment import first_still_window, initial_attitude


class Stream:
    """Push samples of a live recording; get the current attitude, velocity, position and gait phase.

    Parameters
    ----------
    pipeline : Pipeline
        A causal pipeline (see the module docstring); others are rejected with the reason.
    rate : float, optional
        Nominal sampling rate (Hz) for the detector's windows; default: measured over the still start.
    engine : {"auto", "fast", "reference"}
        As :meth:`Pipeline.run`.
    max_gap : float
        Longest accepted time between two pushed samples (s); a longer gap is an error.
    max_wait : float
        How long the stream waits for the first still period (s) before it gives up with an error.

    Examples
    --------
    >>> s = Stream(Pipeline.from_yaml("nguyen2016"), rate=100.0)   # doctest: +SKIP
    >>> est = s.push(t, acc, gyr)          # None until the still start has been seen
    """

    def __init__(self, pipeline, rate: float | None = None, engine: str = "auto", max_gap: float = 0.1,
                 max_wait: float = 10.0):
        self.pipeline = pipeline
        self.rate = rate
        self.engine = engine
        self.max_gap = max_gap
        self.max_wait = max_wait
        self._dist_width: int | None = None
        reasons = []
        if not pipeline.orientation.carried_by_filter:
            reasons.append(f"orientation {pipeline.orientation.name!r} is not carried by the Kalman filter "
                           "(live: an orientation such as ins)")
        det = pipeline.detector
        if not (det.causal and hasattr(det, "begin") and hasattr(det, "step")):
            reasons.append(f"detector {det.name!r} looks ahead or dates switches back (live: a causal detector "
                           "such as dgp)")
        for c in pipeline.corrections:
            if not (isinstance(c, KalmanCorrection) and c.causal):
                reasons.append(f"correction {c.name!r} corrects a swing after it ends")
        if not pipeline.filter_corrections:
            reasons.append("no Kalman-filter correction")
        if pipeline.analysis:
            reasons.append("analysis plug-ins run on whole recordings")
        if pipeline.calibration:
            reasons.append(f"calibration {[c.name for c in pipeline.calibration]} is fitted on the whole recording "
                           "(live: remove it)")
        if pipeline.smoother != "none":
            reasons.append(f"smoother {pipeline.smoother!r} runs backwards over the whole recording "
                           "(live: smoother: none)")
        if rate is not None and not (isinstance(rate, (int, float)) and np.isfinite(rate) and rate > 0):
            reasons.append(f"rate must be a positive number of Hz, got {rate!r}")
        for label, value in (("max_gap", max_gap), ("max_wait", max_wait)):
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and 0 < value < np.inf):
                reasons.append(f"{label} must be a positive number of seconds, got {value!r}")
        if reasons:
            raise ConfigError("this pipeline cannot run live: " + "; ".join(reasons))
        self.init = dict(pipeline.init)
        self.log: list[dict[str, Any]] | None = None
        self._buffer: list[tuple[float, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]] = []
        self._ready = False
        self.k = -1

    def push(self, t: float, acc, gyr, mag=None, dist=None) -> dict[str, Any] | None:
        """Add one sample (FRD, SI; ``dist`` in m with NaN where no reading) and return the estimate.

        Returns None while the initial still period is being collected, then a
        dict with ``t``, ``quat`` (body -> NED), ``pos``, ``vel`` (NED) and
        ``stance`` for the newest sample.
        """
        previous = self._buffer[-1][0] if self._buffer else None
        t, acc, gyr, mag, dist = validate_sample(t, acc, gyr, mag, dist, previous, self.max_gap)
        acc = np.asarray(acc, dtype=float).reshape(3)
        gyr = np.asarray(gyr, dtype=float).reshape(3)
        mag = None if mag is None else np.asarray(mag, dtype=float).reshape(3)
        dist = self._distance_row(dist)
        self._buffer.append((float(t), acc, gyr, mag, dist))
        if not self._ready:
            if t - self._buffer[0][0] <= self.init["duration"] or not self._start():
                return None
            out = None
            for sample in self._buffer[self._n_init:]:
                out = self._step(*sample)
            self._buffer = self._buffer[-1:]
            return out
        self._buffer = self._buffer[-1:]
        return self._step(float(t), acc, gyr, mag, dist)

    def _distance_row(self, dist) -> np.ndarray | None:
        """Readings of the distance sensors (m); NaN for a sample without them once a stream has them."""
        if dist is None:
            return None if self._dist_width is None else np.full(self._dist_width, np.nan)
        row = np.asarray(dist, dtype=float).reshape(-1)
        if self._dist_width is None:
            if self._buffer:
                raise RecordingError("distance readings started after the first sample: push dist (NaN where a "
                                     "sensor has no reading) with every sample from the first one")
            self._dist_width = row.size
        elif row.size != self._dist_width:
            raise RecordingError(f"dist has {row.size} readings, earlier samples had {self._dist_width}: push the "
                                 "same sensors every time (NaN where one has no reading)")
        return row

    def _start(self) -> bool:
        """Start the filter once the buffer holds the first still period; False while it does not yet."""
        b = self._buffer
        t = np.array([s[0] for s in b])
        gyr_all = np.array([s[2] for s in b])
        duration, max_gyr = self.init["duration"], self.init["max_gyr"]
        try:  # the batch run's alignment: the first still window, the attitude carried back to sample 0
            first_still_window(t, gyr_all, duration, max_gyr)
        except RecordingError:
            if t[-1] - t[0] <= self.max_wait:
                return False
            raise RecordingError(
                f"the stream found no still period: |ω| stayed above init.max_gyr = {max_gyr} rad/s in every "
                f"{duration} s of the first {self.max_wait} s; start it with the foot at rest (or raise max_wait)"
            ) from None
        acc_all = np.array([s[1] for s in b])
        mag_all = np.array([s[3] for s in b]) if b[0][3] is not None else None
        use_mag = mag_all is not None and bool(getattr(self.pipeline.orientation, "use_magnetometer", False))
        q0 = initial_attitude(t, acc_all, gyr_all, mag_all if use_mag else None, duration, max_gyr)
        self._n_init = n = int(np.sum(t <= t[0] + duration))
        gyr, acc = gyr_all[:n], acc_all[:n]
        mag = None if mag_all is None else mag_all[:n]
        dist = np.array([s[4] for s in b[:n]]) if b[0][4] is not None else None
        rate = self.rate
        if rate is None:
            rate = 1.0 / float(np.median(np.diff(t[:n])))
            warnings.warn(f"Stream: no rate given; using {rate:.2f} Hz measured over the still start (a batch run "
                          "uses the whole recording's median rate): pass rate= the sensor's nominal rate",
                          FootzooWarning, stacklevel=3)
        self._detector = self.pipeline.detector.clone()
        self._detector.begin(rate)
        self._swing = 0
        self._max_swing = int(round(self.pipeline.guards.max_swing * rate))
        self._corrections = [c.clone() for c in self.pipeline.filter_corrections]
        samples = Samples(t[:n], acc, gyr, mag, dist, np.ones(n, dtype=bool))
        self._engine = self.pipeline.kalman_engine(self._corrections, samples, self.engine)
        nav0 = np.zeros(16)
        nav0[:4] = q0
        self._state = self._engine.live(self._engine.start(nav0))
        self._ready = True
        self._prev = None
        for sample in b[:n]:
            self._step(*sample)
        return True

    def _step(self, t, acc, gyr, mag, dist) -> dict[str, Any]:
        self.k += 1
        stance = bool(self._detector.step(np.array([t]), acc[None, :], gyr[None, :])[0])
        self._swing = 0 if stance else self._swing + 1
        if self._swing == self._max_swing > 0:
            warnings.warn(f"Stream: detector {self._detector.name!r} has found no stance for "
                          f"{self.pipeline.guards.max_swing:g} s (guards.max_swing) at t = {t:.2f} s: it misses the "
                          "stances of this motion and the estimate drifts until it finds one. A batch run would mark "
                          "the swing's stillest instants as stance (footzoo.runtime.guards);"
                          " live, they cannot be known yet",
                          GuardWarning, stacklevel=3)
        in_init = self.k < self._n_init
        sample = (t, acc, gyr, mag, dist, stance, in_init)
        if self._prev is None:
            self._prev = sample
            nav = self._state["nav"] if isinstance(self._state, dict) else self._state.nav
            return self._emit({"t": t, "quat": nav[:4].copy(), "pos": np.zeros(3), "vel": np.zeros(3),
                               "stance": stance})
        pair = list(zip(self._prev, sample, strict=True))
        self._prev = sample
        ts, accs, gyrs = np.array(pair[0]), np.vstack(pair[1]), np.vstack(pair[2])
        mags = None if mag is None else np.vstack(pair[3])
        dists = None if dist is None else np.vstack(pair[4])
        chunk = Samples(ts, accs, gyrs, mags, dists, np.array(pair[6], dtype=bool))
        data = [np.ascontiguousarray(c.sample_data(chunk), dtype=float) for c in self._corrections]
        out = self._engine.advance(self._state, ts, accs, gyrs, np.array(pair[5], dtype=bool), None, data,
                                   self.k - 1, covariance=False)
        return self._emit({"t": t, "quat": out["quat"][1], "pos": out["pos"][1], "vel": out["vel"][1],
                           "stance": stance})

    def _emit(self, est: dict[str, Any]) -> dict[str, Any]:
        if self.log is not None:
            self.log.append(est)
        return est

    def run(self, rec) -> dict[str, np.ndarray]:
        """Push a whole recording sample by sample; every sample's estimate (for tests and latency).

        Uses the recording's rate (:attr:`Recording.rate`) when the stream was made without one, as
        the batch run does.
        """
        if self.rate is None and not self._ready:
            self.rate = rec.rate
        self.log = []
        for k in range(rec.n):
            self.push(rec.t[k], rec.acc[k], rec.gyr[k], None if rec.mag is None else rec.mag[k],
                      None if rec.dist is None else rec.dist[k])
        out = {key: np.array([e[key] for e in self.log]) for key in ("t", "quat", "pos", "vel", "stance")}
        self.log = None
        return out
