"""Windowed gyro/accelerometer zero-velocity test (Duong & Suh 2015, eq. 21)."""

from __future__ import annotations

import numpy as np

from ..plugins.base import Detector, Real
from ..plugins.registry import register
from .windows import row_norms, window_max


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

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Windowed:
        """Evaluate eq. 21 over the whole recording (vectorised)."""
        rate = 1.0 / float(np.median(np.diff(t)))
        half_g = int(round(self.gyro_window * rate / 2))
        half_a = int(round(self.acc_window * rate / 2))
        acc = np.ascontiguousarray(acc, dtype=float)
        lag = max(int(round(rate / self.reference_rate)), 1)
        scale = rate / (self.reference_rate * lag)
        dacc = np.zeros(t.shape[0])
        dacc[lag:] = scale * row_norms(np.ascontiguousarray(acc[lag:] - acc[:-lag]))
        self.gyro_statistic_ = window_max(row_norms(np.ascontiguousarray(gyr, dtype=float)), half_g)
        self.acc_statistic_ = window_max(dacc, half_a)
        self.statistic_ = np.maximum(self.gyro_statistic_ / self.gyro_threshold,
                                     self.acc_statistic_ / self.acc_diff_threshold)
        self.stance_ = self.statistic_ <= 1.0
        self.stance_online_ = self.stance_.copy()
        return self
