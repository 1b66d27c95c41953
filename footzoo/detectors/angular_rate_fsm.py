"""Angular-rate finite-state gait-phase detector (Yun et al. 2012, Sec. II-C/D)."""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_range
from ..plugin import Detector
from ..registry import register
from .runs import dated_and_online_states


@register
class AngularRateFSM(Detector):
    """Two-state STANCE/SWING machine on the angular-rate magnitude |ω|.

    Yun et al. 2012, IEEE TIM 61(7), Sec. II-C (Figs. 5–6) and II-D. The machine
    leaves its state only after |ω| has stayed on the other side of Ω_th for Γ_th
    consecutive samples; the switch is then dated back to where that run began
    (what the paper's two FIFOs achieve). The paper gives no values for Ω_th and
    Γ_th; the defaults (0.6 rad/s, 0.1 s = 5 samples at the paper's 50 Hz) follow
    footzoo's design notes. Γ_th is given in seconds and converted at the
    recording's median rate.

    Parameters
    ----------
    threshold : float
        Ω_th (rad/s).
    min_duration : float
        Γ_th (s); the sample count is ``max(1, round(min_duration * rate))``.

    Attributes
    ----------
    statistic_ : (N,) ndarray
        |ω| (rad/s); stance where below ``threshold`` (for threshold sweeps).
    stance_ : (N,) bool ndarray
        Gait phase with switches dated back (True = stance).
    stance_online_ : (N,) bool ndarray
        Gait phase as the live machine knows it at each sample, before the
        FIFO delay dates the switches back.
    min_samples_ : int
        Γ_th in samples.
    """

    name = "angular_rate_fsm"
    paper = "Yun et al. 2012, IEEE TIM 61(7), Sec. II-C/II-D, Figs. 5-6"
    units = {"threshold": "rad/s", "min_duration": "s"}

    def __init__(self, threshold: float = 0.6, min_duration: float = 0.1):
        self.threshold = check_range("threshold", threshold, 0.0, 50.0, "rad/s", lo_open=True)
        self.min_duration = check_range("min_duration", min_duration, 0.0, 10.0, "s")

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> AngularRateFSM:
        """Detect stance over a whole recording (vectorised).

        Parameters
        ----------
        t : (N,) ndarray
            Time (s).
        acc : (N, 3) ndarray
            Specific force (m/s²), unused.
        gyr : (N, 3) ndarray
            Angular rate (rad/s).
        """
        rate = 1.0 / float(np.median(np.diff(t)))
        self.min_samples_ = max(1, int(math.floor(self.min_duration * rate + 0.5)))
        self.statistic_ = np.linalg.norm(gyr, axis=1)
        self.stance_, self.stance_online_ = dated_and_online_states(
            self.statistic_ < self.threshold, self.min_samples_, initial=True
        )
        return self
