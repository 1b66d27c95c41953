"""SHOE (Skog et al. 2010) and Huang et al.'s stance identification built on it."""

from __future__ import annotations

import math

import numpy as np

from ..core.context import RunContext
from ..plugins.base import Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave
from ..plugins.registry import register
from .runs import after_long_stance, dated_and_online_states
from .skog import FUSED_TESTS, SkogTest
from .windows import SHOE_TEST


@register
class SHOE(SkogTest):
    """Stance hypothesis optimal detector (generalised likelihood ratio test).

    Skog, Händel, Nilsson & Rantakokko, "Zero-velocity detection — an algorithm
    evaluation", IEEE TBME 57(11), 2010 (cited by Yun 2012 and Huang 2016): stance
    where the windowed statistic (see :class:`~footzoo.detectors.skog.SkogTest`;
    a sliding, centred window) is below γ. Defaults from Skog's OpenShoe: σ_a = 0.01 m/s²,
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
    paper = "Skog et al. 2010, IEEE TBME 57(11), Sec. III (cited by Yun 2012 and Huang 2016)"
    parameters = {"threshold": SkogTest.parameters["threshold"].replace(source="Skog's OpenShoe")}

    def __init__(self, threshold: float = 3e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1))):
        super().__init__(threshold, window, sigma_a, sigma_g)

    def test(self, m: np.ndarray) -> np.ndarray:
        """``T_k = (1/W) Σ ‖y_a − g ȳ_a/‖ȳ_a‖‖²/σ_a² + ‖y_ω‖²/σ_ω²``, expanded in the window moments.

        ``(1/W) Σ ‖y_a − g u‖² = mean ‖y_a‖² − 2 g ‖ȳ_a‖ + g²`` for the unit vector ``u = ȳ_a/‖ȳ_a‖``.
        """
        g = self.gravity_
        acc_term = m[:, 3] - 2.0 * g * np.linalg.norm(m[:, :3], axis=1) + g**2
        return np.maximum(acc_term, 0.0) / self.sigma_a**2 + m[:, 4] / self.sigma_g**2


FUSED_TESTS[SHOE.test] = SHOE_TEST


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
    parameters = {
        "threshold": SkogTest.parameters["threshold"].replace(source="Skog's OpenShoe (Huang gives no value)"),
        "min_duration": Real("s", "[0, 1]", "Γ_th: how long the SHOE decision must hold before a switch",
                             source="footzoo's (Huang gives no value)",
                             why="a switch held back for over 1 s would miss every walking stance (≈ 0.6 s)"),
    }

    def __init__(self, threshold: float = 3e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1)), min_duration: float = 0.05):
        super().__init__(threshold, window, sigma_a, sigma_g)
        self.min_duration = min_duration

    def min_samples(self, ctx: RunContext) -> int:
        """Γ_th in samples at the run's rate."""
        return max(1, int(math.floor(self.min_duration * ctx.rate + 0.5)))

    def _machine(self, statistic: np.ndarray) -> Chunk:
        stance, online = dated_and_online_states(statistic < self.threshold, self.min_samples(self.ctx_))
        return {"stance": stance, "online": online, "statistic": statistic}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> HuangStance:
        """SHOE, then the state machine (dated back)."""
        self.begin(run_context(ctx, t))
        out = self._machine(self._statistic(t, acc, gyr))
        self.statistic_, self.stance_, self.stance_online_ = out["statistic"], out["stance"], out["online"]
        onsets = np.flatnonzero(self.stance_[1:] & ~self.stance_[:-1]) + 1
        self.heel_strikes_ = onsets
        return self

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """SHOE's half window, then twice Γ_th for the state machine."""
        return super().latency(ctx) + Latency(ctx.seconds(2 * self.min_samples(ctx)))

    def begin(self, ctx: RunContext) -> HuangStance:
        """Fresh state: SHOE's window, then the machine, restarted at the end of every stance."""
        super().begin(ctx)
        g = self.min_samples(self.ctx_)
        machine = OverlapSave(self._machine, lookahead=2 * g, wants=("statistic",),
                              restart=lambda out, inp, start, final: after_long_stance(
                                  inp["statistic"] < self.threshold, start, final, g))
        self._stages = [*self._stages, machine]
        return self
