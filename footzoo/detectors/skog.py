"""Shared base of Skog et al.'s (2010) windowed zero-velocity tests: SHOE, ARED, AMVD, MBGTD."""

from __future__ import annotations

import numpy as np

from ..core.conventions import GRAVITY
from ..plugins.base import Detector, Real
from .windows import window_moments, window_statistic

#: Built-in ``test`` methods that :func:`~footzoo.detectors.windows.window_statistic` evaluates in its window pass,
#: by the test code it takes (a subclass that overrides ``test`` gets the moments and its own method).
FUSED_TESTS: dict[object, int] = {}


class SkogTest(Detector):
    """A likelihood-ratio test over a sliding window: stance where ``T_k < γ``.

    Skog, Händel, Nilsson & Rantakokko, "Zero-velocity detection — an algorithm
    evaluation", IEEE TBME 57(11), 2010, Sec. III: each detector is the GLRT of
    "the IMU is stationary" under white Gaussian sensor noise (σ_a, σ_ω) over W
    samples, and differs only in what it assumes known. Subclasses give
    :meth:`test` on the window moments of
    :func:`~footzoo.detectors.windows.window_moments` (centred window, edges
    replicated; a live system knows the result W/2 samples late). W is a
    duration, so the test means the same at any rate; the statistic is a mean
    over the window, so γ does not depend on W either.

    Parameters
    ----------
    threshold : float
        γ (dimensionless).
    window : float
        W as a duration (s); the sample count is ``max(2, round(window · rate))``
        (a variance needs two samples).
    sigma_a : float
        Accelerometer noise σ_a (m/s²).
    sigma_g : float
        Gyro noise σ_ω (rad/s).

    Attributes
    ----------
    statistic_ : (N,) ndarray
        T_k (dimensionless); stance where below ``threshold``.
    stance_, stance_online_ : (N,) bool ndarray
        Stance flag.
    window_samples_ : int
        W in samples at the recording's median rate.
    """

    parameters = {
        "threshold": Real("1", "(0, inf)", "γ: stance where the test statistic T_k is below it"),
        "window": Real("s", "(0, 1]", "W: the window of the test, as a duration",
                       source="Skog's OpenShoe: 5 samples at 200 Hz",
                       why="a window longer than 1 s spans a whole stride and hides its stance"),
        "sigma_a": Real("m/s^2", "[1e-9, 10]", "σ_a: accelerometer noise", source="Skog's OpenShoe",
                        why="10 m/s² of noise is 1 g, beyond any accelerometer"),
        "sigma_g": Real("rad/s", "[1e-9, 1]", "σ_ω: gyroscope noise", source="Skog's OpenShoe: 0.1 °/s",
                        why="1 rad/s (57 °/s) of noise is beyond any gyroscope"),
    }

    def __init__(self, threshold: float, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1))):
        self.threshold = threshold
        self.window = window
        self.sigma_a = sigma_a
        self.sigma_g = sigma_g

    def test(self, m: np.ndarray) -> np.ndarray:
        """T_k from the (N, 6) window moments (see ``window_moments``)."""
        raise NotImplementedError

    def _statistic(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> np.ndarray:
        rate = 1.0 / float(np.median(np.diff(t)))
        self.window_samples_ = max(int(round(self.window * rate)), 2)
        acc = np.ascontiguousarray(acc, dtype=float)
        gyr = np.ascontiguousarray(gyr, dtype=float)
        fused = FUSED_TESTS.get(type(self).test)
        if fused is not None:  # the same numbers as test(window_moments(...)), without the (N, 6) moments
            return window_statistic(acc, gyr, self.window_samples_, GRAVITY, GRAVITY**2, fused, self.sigma_a**2,
                                    self.sigma_g**2)
        return self.test(window_moments(acc, gyr, self.window_samples_, GRAVITY))

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> SkogTest:
        """Evaluate the test over the whole recording.

        Parameters
        ----------
        t : (N,) ndarray
            Time (s).
        acc : (N, 3) ndarray
            Specific force (m/s²).
        gyr : (N, 3) ndarray
            Angular rate (rad/s).
        """
        self.statistic_ = self._statistic(t, acc, gyr)
        self.stance_ = self.statistic_ < self.threshold
        self.stance_online_ = self.stance_.copy()
        return self
