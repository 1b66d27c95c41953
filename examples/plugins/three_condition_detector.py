"""A stance detector as a footzoo plug-in: the three-condition detector of Jiménez et al. (2009).

Jiménez, Seco, Prieto & Guevara, "A comparison of Pedestrian Dead-Reckoning algorithms using a
low-cost MEMS IMU", IEEE WISP 2009 (stance-phase detection): a sample is in stance when

* C1: the specific-force magnitude is near gravity, ``a_min < |a_k| < a_max``;
* C2: the local standard deviation of ``|a|`` over a window is small, ``σ_a,k < σ_max``;
* C3: the angular-rate magnitude is small, ``|ω_k| < ω_max``;

and the logical AND of the three is smoothed by a median filter. The paper counts windows in
samples (15 and 11 at its rate); here they are seconds, so one setting works at any rate.

Use it from YAML after listing this file under ``plugins:`` (or importing it)::

    plugins: [examples/plugins/three_condition_detector.py]
    detector: {type: three_condition, gyro_max: 0.87}
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import median_filter, uniform_filter1d

import footzoo
from footzoo.plugins.base import Detector, Real


@footzoo.register
class ThreeCondition(Detector):
    """Stance where |a| is near g, |a| varies little and |ω| is small (Jiménez et al. 2009, C1–C3).

    Parameters
    ----------
    acc_min, acc_max : float
        Bounds of C1 on the specific-force magnitude (m/s²); paper: 9 and 11.
    acc_std_max : float
        Bound of C2 on the local standard deviation of |a| (m/s²); paper: 3.
    gyro_max : float
        Bound of C3 on |ω| (rad/s); paper: 50 °/s = 0.87 rad/s.
    window : float
        Window of C2's standard deviation (s); paper: 15 samples.
    median : float
        Length of the median filter on the AND of C1–C3 (s); paper: 11 samples.

    Attributes
    ----------
    stance_ : (N,) bool ndarray
        Stance per sample.
    statistic_ : (N,) ndarray
        σ_a,k, the local standard deviation of |a| (m/s²).
    """

    name = "three_condition"
    paper = "Jiménez, Seco, Prieto & Guevara 2009, IEEE WISP (stance conditions C1-C3)"
    # one declaration per parameter: unit, accepted range, meaning, source of the default
    parameters = {
        "acc_min": Real("m/s^2", "[5, 15]", "C1: lower bound of |a|", source="the paper"),
        "acc_max": Real("m/s^2", "[5, 15]", "C1: upper bound of |a|", source="the paper"),
        "acc_std_max": Real("m/s^2", "(0, 10]", "C2: bound on the local σ of |a|", source="the paper"),
        "gyro_max": Real("rad/s", "(0, 10]", "C3: bound on |ω|", source="the paper: 50 °/s"),
        "window": Real("s", "(0, 1]", "C2's window", source="the paper: 15 samples (at 100 Hz)"),
        "median": Real("s", "(0, 1]", "median filter on C1-C3", source="the paper: 11 samples (at 100 Hz)"),
    }

    def __init__(self, acc_min: float = 9.0, acc_max: float = 11.0, acc_std_max: float = 3.0,
                 gyro_max: float = 0.87, window: float = 0.15, median: float = 0.11):
        # footzoo has checked each value against its declaration; what is left is the rule between two
        if acc_min >= acc_max:
            raise footzoo.ConfigError(f"acc_min ({acc_min} m/s²) must be below acc_max ({acc_max} m/s²)")
        self.acc_min = acc_min
        self.acc_max = acc_max
        self.acc_std_max = acc_std_max
        self.gyro_max = gyro_max
        self.window = window
        self.median = median

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> ThreeCondition:
        """Stance per sample from time (s), specific force (m/s²) and angular rate (rad/s)."""
        rate = 1.0 / float(np.median(np.diff(t)))
        a = np.linalg.norm(acc, axis=1)
        width = max(int(round(self.window * rate)), 1)
        mean = uniform_filter1d(a, width, mode="nearest")
        std = np.sqrt(np.maximum(uniform_filter1d(a * a, width, mode="nearest") - mean * mean, 0.0))
        c1 = (a > self.acc_min) & (a < self.acc_max)
        c2 = std < self.acc_std_max
        c3 = np.linalg.norm(gyr, axis=1) < self.gyro_max
        size = max(int(round(self.median * rate)) | 1, 1)  # odd, so the filter is centred
        self.stance_ = median_filter((c1 & c2 & c3).astype(np.uint8), size=size, mode="nearest").astype(bool)
        self.statistic_ = std
        return self
