"""SHOE (Skog et al. 2010) and Huang et al.'s stance identification built on it."""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from ..checks import check_range
from ..conventions import GRAVITY
from ..plugin import Detector
from ..registry import check_positive, register
from .runs import dated_and_online_states


@njit
def shoe_statistic(acc: np.ndarray, gyr: np.ndarray, window: int, sigma_a: float, sigma_g: float,
                   g: float = GRAVITY) -> np.ndarray:
    """SHOE test statistic per sample (centred window of ``window`` samples, edges replicated).

    ``T_k = (1/W) Σ_l [ ‖y_a,l − g ȳ_a/‖ȳ_a‖‖² / σ_a² + ‖y_ω,l‖² / σ_ω² ]`` with ``ȳ_a``
    the window's mean specific force (Skog et al. 2010, the GLRT's SHOE statistic).
    """
    n = acc.shape[0]
    out = np.empty(n)
    start = -(window // 2)
    for k in range(n):
        mx = my = mz = 0.0
        for j in range(k + start, k + start + window):
            i = min(max(j, 0), n - 1)
            mx += acc[i, 0]
            my += acc[i, 1]
            mz += acc[i, 2]
        norm = math.sqrt(mx * mx + my * my + mz * mz)
        ux, uy, uz = g * mx / norm, g * my / norm, g * mz / norm
        total = 0.0
        for j in range(k + start, k + start + window):
            i = min(max(j, 0), n - 1)
            dx, dy, dz = acc[i, 0] - ux, acc[i, 1] - uy, acc[i, 2] - uz
            total += (dx * dx + dy * dy + dz * dz) / sigma_a**2
            total += (gyr[i, 0] ** 2 + gyr[i, 1] ** 2 + gyr[i, 2] ** 2) / sigma_g**2
        out[k] = total / window
    return out


@register
class SHOE(Detector):
    """Stance hypothesis optimal detector (generalised likelihood ratio test).

    Skog, Händel, Nilsson & Rantakokko, "Zero-velocity detection — an algorithm
    evaluation", IEEE TBME 57(11), 2010 (cited by Yun 2012 and Huang 2016): stance
    where the windowed statistic of :func:`shoe_statistic` (a sliding, centred
    window) is below γ. Defaults from Skog's OpenShoe: σ_a = 0.01 m/s²,
    σ_ω = 0.1 °/s, γ = 3e4, and a window of 0.025 s (5 samples at 200 Hz). PyShoe's
    thresholds are not comparable: it sums over non-overlapping blocks.

    Parameters
    ----------
    threshold : float
        γ (dimensionless).
    window : float
        W as a duration (s).
    sigma_a : float
        Accelerometer noise σ_a (m/s²).
    sigma_g : float
        Gyro noise σ_ω (rad/s).

    Attributes
    ----------
    statistic_ : (N,) ndarray
        T_k; stance where below ``threshold``.
    stance_, stance_online_ : (N,) bool ndarray
        Stance flag (the centred window makes it W/2 samples late when live).
    """

    name = "shoe"
    paper = "Skog et al. 2010, IEEE TBME 57(11) (cited by Yun 2012 and Huang 2016)"
    units = {"threshold": "1", "window": "s", "sigma_a": "m/s^2", "sigma_g": "rad/s"}

    def __init__(self, threshold: float = 3e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1))):
        self.threshold = check_positive("threshold", threshold)
        self.window = check_range("window", window, 0.0, 10.0, "s", lo_open=True)
        self.sigma_a = check_range("sigma_a", sigma_a, 1e-9, 100.0, "m/s^2")
        self.sigma_g = check_range("sigma_g", sigma_g, 1e-9, 50.0, "rad/s")

    def _statistic(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> np.ndarray:
        rate = 1.0 / float(np.median(np.diff(t)))
        w = max(int(round(self.window * rate)), 1)
        return shoe_statistic(np.ascontiguousarray(acc, dtype=float), np.ascontiguousarray(gyr, dtype=float), w,
                              self.sigma_a, self.sigma_g, GRAVITY)

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> SHOE:
        """Evaluate the test over the whole recording (vectorised)."""
        self.statistic_ = self._statistic(t, acc, gyr)
        self.stance_ = self.statistic_ < self.threshold
        self.stance_online_ = self.stance_.copy()
        return self


@register
class HuangStance(SHOE):
    """Stance identification of Huang et al. 2016: SHOE plus a Yun-like state machine.

    Huang et al. 2016, IEEE TBME, Sec. II-B: "zero-velocity estimation [Skog]
    based on acceleration and gyroscope information ... and a state-machine
    based approach similar to Yun et al. for improved identification accuracy".
    The SHOE decision is passed through the two-state machine of
    :class:`~footzoo.detectors.AngularRateFSM` (switch after ``min_duration``,
    dated back). Heel strikes are the stance onsets; Huang's stance of 60 % of
    the stride time after each heel strike is used by the foot-progression-angle
    analysis, not here.

    Parameters
    ----------
    threshold, window, sigma_a, sigma_g : float
        As for ``shoe``.
    min_duration : float
        Γ_th of the state machine (s).

    Attributes
    ----------
    heel_strikes_ : (M,) ndarray
        Sample indices of the stance onsets.
    """

    name = "huang_stance"
    paper = "Huang et al. 2016, IEEE TBME, Sec. II-B (SHOE [Skog 2010] + state machine [Yun 2012])"
    units = {**SHOE.units, "min_duration": "s"}

    def __init__(self, threshold: float = 3e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1)), min_duration: float = 0.05):
        super().__init__(threshold, window, sigma_a, sigma_g)
        self.min_duration = check_range("min_duration", min_duration, 0.0, 10.0, "s")

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> HuangStance:
        """SHOE, then the state machine (dated back)."""
        rate = 1.0 / float(np.median(np.diff(t)))
        self.statistic_ = self._statistic(t, acc, gyr)
        n_min = max(1, int(math.floor(self.min_duration * rate + 0.5)))
        self.stance_, self.stance_online_ = dated_and_online_states(self.statistic_ < self.threshold, n_min)
        onsets = np.flatnonzero(self.stance_[1:] & ~self.stance_[:-1]) + 1
        self.heel_strikes_ = onsets
        return self
