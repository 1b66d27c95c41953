"""Windowed gyro/accelerometer zero-velocity test (Duong & Suh 2015, eq. 21)."""

from __future__ import annotations

import numpy as np

from ..core.context import RunContext
from ..core.norms import row_norms
from ..plugins.base import Detector, Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave
from ..plugins.registry import register
from .windows import window_max


@register
class Windowed(Detector):
    """Stationary when the gyro and the accelerometer's changes stay small around the sample.

    Duong & Suh 2015, Sensors 15, eq. 21: sample k is in a zero-velocity
    interval when ``‖y_g,i‖ ≤ B_g`` for all i in ``[k − N_g/2, k + N_g/2]`` and
    ``‖y_a,i − y_a,i−1‖ ≤ B_a`` for all i in ``[k − N_a/2, k + N_a/2]`` (N even).
    The paper gives no values; footzoo's defaults: B_g = 0.6 rad/s, windows of
    0.1 s (N = 10 at the paper's 100 Hz), B_a = 0.5 m/s² between consecutive
    samples at the paper's 100 Hz. The window is centred: a live system
    knows the result N/2 samples late.

    Rates (footzoo's reading, documented): the accelerometer change is taken
    over one sample of the paper's rate (``reference_rate``, 10 ms), i.e. over
    ``L = round(rate / reference_rate)`` samples of this recording, and scaled
    by ``(1 / reference_rate) / (L dt)`` when L samples are not exactly 10 ms
    (rates below 100 Hz or not a multiple of it). Between consecutive samples
    of a faster IMU the change of a smooth motion shrinks (at 1000 Hz, to a
    tenth) while the bound did not, so the test loosened with the rate.

    Parameters
    ----------
    gyro_threshold : float
        B_g (rad/s).
    acc_diff_threshold : float
        B_a (m/s², between consecutive samples).
    gyro_window, acc_window : float
        N_g and N_a as durations (s); the sample counts are the nearest even numbers.
    reference_rate : float
        Rate (Hz) at which B_a is a change between consecutive samples; paper: 100.

    Attributes
    ----------
    gyro_statistic_ : (N,) ndarray
        Windowed max of ‖y_g‖ (rad/s).
    acc_statistic_ : (N,) ndarray
        Windowed max of ‖Δy_a‖ (m/s² per 1/``reference_rate`` s).
    statistic_ : (N,) ndarray
        ``max(gyro_statistic_/B_g, acc_statistic_/B_a)``: stance where ≤ 1, so a
        threshold sweep scales both bounds together.
    stance_, stance_online_ : (N,) bool ndarray
        Zero-velocity flag.
    """

    name = "windowed"
    paper = "Duong & Suh 2015, Sensors 15, eq. 21"
    parameters = {
        "gyro_threshold": Real("rad/s", "(0, 10]", "B_g: the bound on |ω| over the window",
                               source="footzoo's (the paper gives no value)",
                               why="a foot turns faster than 10 rad/s (573 °/s) only in mid-swing"),
        "acc_diff_threshold": Real("m/s^2", "(0, 50]", "B_a: the bound on |Δa| between samples at reference_rate",
                                   source="footzoo's (the paper gives no value)",
                                   why="a change of 50 m/s² in 10 ms is a heel strike, not a stance"),
        "gyro_window": Real("s", "[0, 1]", "N_g as a duration", source="footzoo's: 10 samples at the paper's 100 Hz",
                            why="a window longer than 1 s spans a whole stride and hides its stance"),
        "acc_window": Real("s", "[0, 1]", "N_a as a duration", source="footzoo's: 10 samples at the paper's 100 Hz",
                           why="a window longer than 1 s spans a whole stride and hides its stance"),
        "reference_rate": Real("Hz", "[1, 10000]", "the rate at which B_a is a change between consecutive samples",
                               source="Duong & Suh 2015's IMU (100 Hz)", why="an IMU's sampling rate: 1 Hz to 10 kHz"),
    }

    def __init__(
        self,
        gyro_threshold: float = 0.6,
        acc_diff_threshold: float = 0.5,
        gyro_window: float = 0.1,
        acc_window: float = 0.1,
        reference_rate: float = 100.0,
    ):
        self.gyro_threshold = gyro_threshold
        self.acc_diff_threshold = acc_diff_threshold
        self.gyro_window = gyro_window
        self.acc_window = acc_window
        self.reference_rate = reference_rate

    def _counts(self, ctx: RunContext) -> tuple[int, int, int, float]:
        """Half windows (samples), the lag of the accelerometer change (samples) and its scale, at the run's rate."""
        half_g = int(round(self.gyro_window * ctx.rate / 2))
        half_a = int(round(self.acc_window * ctx.rate / 2))
        lag = max(int(round(ctx.rate / self.reference_rate)), 1)
        return half_g, half_a, lag, ctx.rate / (self.reference_rate * lag)

    def _compute(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """Eq. 21 over arrays: ``stance``, ``statistic``, ``gyro_statistic``, ``acc_statistic``."""
        half_g, half_a, lag, scale = self._counts(self.ctx_)
        acc = np.ascontiguousarray(acc, dtype=float)
        dacc = np.zeros(acc.shape[0])
        dacc[lag:] = scale * row_norms(np.ascontiguousarray(acc[lag:] - acc[:-lag]))
        gyro = window_max(row_norms(np.ascontiguousarray(gyr, dtype=float)), half_g)
        accs = window_max(dacc, half_a)
        with np.errstate(over="ignore"):  # a threshold near 0 overflows the ratio to inf: no stance, as it should
            statistic = np.maximum(gyro / self.gyro_threshold, accs / self.acc_diff_threshold)
        return {"stance": statistic <= 1.0, "statistic": statistic, "gyro_statistic": gyro, "acc_statistic": accs}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> Windowed:
        """Evaluate eq. 21 over the whole recording (vectorised)."""
        self.begin(run_context(ctx, t))
        out = self._compute(t, acc, gyr)
        self.gyro_statistic_, self.acc_statistic_ = out["gyro_statistic"], out["acc_statistic"]
        self.statistic_, self.stance_ = out["statistic"], out["stance"]
        self.stance_online_ = self.stance_.copy()
        return self

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """The larger half window (s)."""
        half_g, half_a, _, _ = self._counts(ctx)
        return Latency(ctx.seconds(max(half_g, half_a)))

    def begin(self, ctx: RunContext) -> Windowed:
        """Fresh state: the windows of the recent samples (overlap-save)."""
        super().begin(ctx)
        half_g, half_a, lag, _ = self._counts(self.ctx_)
        # the accelerometer change of the window's first sample reaches lag samples further back
        self._live = OverlapSave(self._compute, lookahead=max(half_g, half_a), restart=max(half_g, half_a + lag))
        return self

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """The stance of the samples whose windows are now complete."""
        return self._live.step(t=t, acc=acc, gyr=gyr)

    def provisional(self) -> Chunk:
        """The test over the windows so far."""
        return self._live.provisional()

    def finish(self) -> Chunk:
        """The last samples, windows clipped at the end of the data."""
        return self._live.finish()
