"""Live estimation: push one sample, get the current estimate.

For pipelines whose output at a sample depends only on the samples up to it —
the strapdown INS with Kalman-filter corrections (``ekf_zupt``, ``zupt``,
``hdr``, ``height_flat_floor``, ``height_distance``) and the causal ``dgp``
detector, i.e. Nguyen & La's real-time system — :class:`Stream` gives exactly
what :meth:`Pipeline.run` gives on the whole recording. It holds the filter's
state between samples and feeds the same compiled loop two samples at a time.

DGP and the filter run their compiled loops from carried state, one sample at
a time. The stream needs the foot still for ``init.duration`` seconds at the start
(the batch run can also look later and carry the attitude back; a live
system cannot), and takes the sampling rate for DGP's windows from that
still period (the batch run from the whole recording: the same for a
regular clock).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .checks import validate_sample
from .errors import ConfigError, RecordingError
from .orientation.fqa import fqa


class Stream:
    """Push samples of a live recording; get the current attitude, velocity, position and gait phase.

    Parameters
    ----------
    pipeline : Pipeline
        A causal pipeline (see the module docstring); others are rejected with the reason.

    Examples
    --------
    >>> s = Stream(Pipeline.from_yaml("configs/nguyen2016.yaml"))      # doctest: +SKIP
    >>> est = s.push(t, acc, gyr)          # None until the still start has been seen
    """

    def __init__(self, pipeline):
        self.pipeline = pipeline
        reasons = []
        if pipeline.orientation.name != "ins":
            reasons.append(f"orientation {pipeline.orientation.name!r} (live: orientation ins)")
        if pipeline.detector.name != "dgp":
            reasons.append(f"detector {pipeline.detector.name!r} looks ahead or dates switches back (live: dgp)")
        for c in pipeline.corrections:
            if c.role not in ("kalman", "heading"):
                reasons.append(f"correction {c.name!r} corrects a swing after it ends")
        if not any(c.role == "kalman" for c in pipeline.corrections):
            reasons.append("no Kalman-filter correction")
        if pipeline.analysis:
            reasons.append("analysis plug-ins run on whole recordings")
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
        t, acc, gyr, mag, dist = validate_sample(t, acc, gyr, mag, dist, previous, getattr(self, "max_gap", None))
        acc = np.asarray(acc, dtype=float).reshape(3)
        gyr = np.asarray(gyr, dtype=float).reshape(3)
        if not (np.isfinite(acc).all() and np.isfinite(gyr).all()):
            raise RecordingError(f"non-finite sample at t = {t}: repair it before pushing")
        mag = None if mag is None else np.asarray(mag, dtype=float).reshape(3)
        dist = None if dist is None else np.asarray(dist, dtype=float).reshape(-1)
        if self._buffer and t <= self._buffer[-1][0]:
            raise RecordingError(f"time went from {self._buffer[-1][0]} to {t}: samples must arrive in order")
        self._buffer.append((float(t), acc, gyr, mag, dist))
        if not self._ready:
            if t - self._buffer[0][0] <= self.init["duration"]:
                return None
            self._start()
            out = None
            for sample in self._buffer[self._n_init:]:
                out = self._step(*sample)
            self._buffer = self._buffer[-1:]
            return out
        self._buffer = self._buffer[-1:]
        return self._step(float(t), acc, gyr, mag, dist)

    def _start(self) -> None:
        from .pipeline import _clone, _run_kalman_setup

        b = self._buffer
        t = np.array([s[0] for s in b])
        t0 = t[0]
        window = t <= t0 + self.init["duration"]
        self._n_init = int(window.sum())
        gyr = np.array([s[2] for s in b[: self._n_init]])
        if np.linalg.norm(gyr, axis=1).max() > self.init["max_gyr"]:
            raise RecordingError(
                f"the stream did not start still: |ω| exceeds init.max_gyr = {self.init['max_gyr']} rad/s within "
                f"the first {self.init['duration']} s; start it with the foot at rest"
            )
        acc = np.array([s[1] for s in b[: self._n_init]])
        use_mag = b[0][3] is not None
        mag = np.array([s[3] for s in b[: self._n_init]]) if use_mag else None
        q0 = fqa(acc.mean(axis=0)[None, :], None if mag is None else mag.mean(axis=0)[None, :])[0]
        rate = 1.0 / float(np.median(np.diff(t[: self._n_init])))
        self._dgp = _clone(self.pipeline.detector)
        self._dgp.begin(rate)
        dist = np.array([s[4] if s[4] is not None else np.zeros(0) for s in b[: self._n_init]], dtype=float)
        corrections = [_clone(c) for c in self.pipeline.corrections]
        # the batch order: Kalman corrections, then the heading reduction
        measurements = [c for c in corrections if c.role == "kalman"] + [c for c in corrections if c.role == "heading"]
        k_sensors = next((m.k for m in measurements if m.name == "height_distance"), 0)
        dist = dist[:, :k_sensors] if dist.ndim == 2 and dist.shape[1] >= k_sensors else np.zeros((len(dist), 0))
        if k_sensors and dist.shape[1] < k_sensors:
            raise RecordingError(f"height_distance needs {k_sensors} distance readings per sample")
        self._setup = _run_kalman_setup(self.pipeline.orientation, measurements, dist, self.pipeline.gravity, q0)
        self._ready = True
        self._prev = None
        for sample in b[: self._n_init]:
            self._step(*sample)

    def _step(self, t, acc, gyr, mag, dist) -> dict[str, Any]:
        from .filters.eskf_fast import eskf_kernel

        self.k += 1
        stance = bool(self._dgp.step(np.array([t]), acc[None, :], gyr[None, :])[-1][0])
        s = self._setup
        in_init = self.k < self._n_init
        row = np.full((1, s["k_sensors"]), np.nan) if dist is None else dist[None, : s["k_sensors"]]
        valid = np.isfinite(row) & (row <= s["max_range"])
        if self._prev is None:
            self._prev = (t, acc, gyr, stance, row, valid, in_init)
            return self._emit({"t": t, "quat": s["nav"][:4].copy(), "pos": np.zeros(3), "vel": np.zeros(3),
                               "stance": stance})
        pt, pa, pg, ps, prow, pvalid, pinit = self._prev
        res = eskf_kernel(
            np.array([pt, t]), np.vstack([pa, acc]), np.vstack([pg, gyr]), np.array([ps, stance]),
            s["ext"], s["use_ext"], s["idx"], s["n"], s["q"], s["gravity"], s["order"],
            *s["par"], np.vstack([prow, row]).astype(float), np.vstack([pvalid, valid]),
            np.array([pinit, in_init]), s["init_dist"], s["init_valid"], s["r_d"], s["n_d"], *s["dist_par"],
            s["nav"], s["P"], s["scal"], self.k - 1,
        )
        self._prev = (t, acc, gyr, stance, row, valid, in_init)
        return self._emit({"t": t, "quat": res[0][1], "pos": res[2][1], "vel": res[1][1], "stance": stance})

    def _emit(self, est: dict[str, Any]) -> dict[str, Any]:
        if self.log is not None:
            self.log.append(est)
        return est

    def run(self, rec) -> dict[str, np.ndarray]:
        """Push a whole recording sample by sample; every sample's estimate (for tests and latency)."""
        self.log = []
        for k in range(rec.n):
            self.push(rec.t[k], rec.acc[k], rec.gyr[k], None if rec.mag is None else rec.mag[k],
                      None if rec.dist is None else rec.dist[k])
        out = {key: np.array([e[key] for e in self.log]) for key in ("t", "quat", "pos", "vel", "stance")}
        self.log = None
        return out
