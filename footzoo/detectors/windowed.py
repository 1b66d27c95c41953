"""Windowed gyro/accelerometer zero-velocity test (Duong & Suh 2015, eq. 21)."""

from __future__ import annotations

import numpy as np

from ..core.checks import check_range
from ..plugins.base import Detector
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
    units = {"gyro_threshold": "rad/s", "acc_diff_threshold": "m/s^2", "gyro_window": "s", "acc_window": "s",
             "reference_rate": "Hz"}

    def __init__(
        self,
        gyro_threshold: float = 0.6,
        acc_diff_threshold: float = 0.5,
        gyro_window: float = 0.1,
        acc_window: float = 0.1,
        reference_rate: float = 100.0,
    ):
        self.gyro_threshold = check_range("gyro_threshold", gyro_threshold, 0.0, 50.0, "rad/s", lo_open=True)
        self.acc_diff_threshold = check_range("acc_diff_threshold", acc_diff_threshold, 0.0, 2000.0, "m/s^2",
                                              lo_open=True)
        self.gyro_window = check_range("gyro_window", gyro_window, 0.0, 10.0, "s")
        self.acc_window = check_range("acc_window", acc_window, 0.0, 10.0, "s")
        self.reference_rate = check_range("reference_rate", reference_rate, 0.0, 100000.0, "Hz", lo_open=True)

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
