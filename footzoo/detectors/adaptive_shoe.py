"""SHOE with a Bayesian threshold growing with the time since the last zero-velocity update (Wahlström 2019)."""

from __future__ import annotations

import math

import numpy as np

from ..core.context import RunContext
from ..kernels.jit import njit
from ..plugins.base import Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave, after_stance
from ..plugins.registry import register
from .runs import close_short_swings
from .shoe import SHOE


@njit
def adaptive_threshold_kernel(t: np.ndarray, statistic: np.ndarray, gamma0: float, tau: float,
                              gamma_max: float, t_last: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Causal test ``T_k < γ_k`` with ``γ_k = min(γ_0 exp((t_k − t_last)/τ), γ_max)``.

    ``t_last`` is the time of the last sample declared stationary (s; the start of the recording
    before the first). Returns the stance flag, γ_k and ``t_last`` after the samples (to resume).
    """
    n = t.shape[0]
    stance = np.empty(n, dtype=np.bool_)
    gamma = np.empty(n)
    log_max = math.log(gamma_max)
    for k in range(n):
        g = math.exp(min(math.log(gamma0) + (t[k] - t_last) / tau, log_max))
        gamma[k] = g
        s = statistic[k] < g
        stance[k] = s
        if s:
            t_last = t[k]
    return stance, gamma, t_last


class AdaptiveThreshold:
    """The live form of :func:`adaptive_threshold_kernel`: it carries ``t_last`` from chunk to chunk.

    Takes ``t`` (s) and ``statistic``; gives ``test`` (stance flag) and ``threshold`` (γ_k), plus the
    inputs named in ``keep``.
    """

    wants = ("t", "statistic", "acc", "gyr")

    def __init__(self, gamma0: float, tau: float, gamma_max: float, keep: tuple[str, ...] = ()):
        self.gamma0, self.tau, self.gamma_max, self.keep = gamma0, tau, gamma_max, keep
        self.t_last: float | None = None

    def step(self, t: np.ndarray, statistic: np.ndarray, **given: np.ndarray) -> dict[str, np.ndarray]:
        t = np.ascontiguousarray(t, dtype=float)
        if self.t_last is None:
            self.t_last = float(t[0])
        test, gamma, self.t_last = adaptive_threshold_kernel(t, np.ascontiguousarray(statistic, dtype=float),
                                                             self.gamma0, self.tau, self.gamma_max, self.t_last)
        return {"test": test, "threshold": gamma, "statistic": statistic, "t": t,
                **{k: given[k] for k in self.keep}}

    def finish(self) -> dict[str, np.ndarray]:
        return {}

    def provisional(self) -> dict[str, np.ndarray]:
        return {}


@register
class AdaptiveSHOE(SHOE):
    """Zero-velocity detection with a threshold that adapts to the gait (Bayesian thresholding).

    Wahlström, Skog, Gustafsson, Markham & Trigoni, "Zero-velocity detection —
    a Bayesian approach to adaptive thresholding", IEEE Sensors Letters 3(6),
    2019: the likelihood-ratio test of Skog et al. 2010 (here SHOE, see
    ``shoe``) compared with a Bayes threshold, the ratio of the hypotheses'
    prior probabilities times the ratio of the costs of a false alarm and a
    missed detection. The cost of a missed detection grows exponentially with
    the time Δt since the last zero-velocity update (the longer without an
    update, the more an update is worth), so the threshold is
    ``γ_k = γ_0 exp(Δt_k / τ)``: in a long walking stance it stays at γ_0, while a
    brief, shaky running stance, which comes after a swing of about the same
    duration, meets a threshold that has grown meanwhile. The paper also
    derives a prior from the navigation filter's velocity estimate; footzoo's
    detectors run before the filter, so that prior is flat here (documented
    simplification). ``γ_max`` caps the growth (footzoo's guard: without it, any
    long motion would end in a false stance).

    Defaults (footzoo's): γ_0 = 1e4, τ = 0.5 s, γ_max = 5e5, min_swing = 0.15 s,
    chosen on PyShoe's 36 VICON trials (PyShoe's 2-D error, pipelines
    ``yun2012`` and ``duong2015_zupt`` with this detector) by the mean over the
    motion classes (walking, running, slow, inverted) of the log median ratio to
    PyShoe's per-trial best, never per trial. Leaving one class out, the
    adaptive settings chosen on the rest stay in the same family (τ 0.5–1 s,
    γ_max 1e5–5e5); but over all detectors, leaving running out picks a fixed
    SHOE (γ = 1e4) that fails on running (median 3.9–7.6 m): the setting needs
    running data to be chosen (``examples/detectors_pyshoe.py --grid``). On
    the simulator the defaults give 0 % gait-phase error on the mixed-speed
    walk at 100 and 200 Hz.

    Parameters
    ----------
    threshold : float
        γ_0, the threshold right after an update (dimensionless, as for ``shoe``).
    window, sigma_a, sigma_g : float
        As for ``shoe`` (s, m/s², rad/s).
    time_constant : float
        τ (s): the threshold grows by e every τ without an update.
    max_threshold : float
        γ_max (dimensionless).
    min_swing : float
        Shortest swing (s): a shorter run of "moving" between two stationary
        samples is a momentary spike of the test and counts as stance
        (footzoo's, against split stances). Stances are kept however short: a
        running stance can last a few samples.

    Attributes
    ----------
    statistic_ : (N,) ndarray
        SHOE's T_k.
    threshold_ : (N,) ndarray
        γ_k in force at each sample.
    stance_, stance_online_ : (N,) bool ndarray
        Stance flag (a live system knows it ``min_swing`` + W/2 late).
    """

    name = "adaptive_shoe"
    paper = "Wahlström et al. 2019, IEEE Sensors Letters 3(6) (Bayesian adaptive threshold) on SHOE (Skog et al. 2010)"
    parameters = {
        "threshold": SHOE.parameters["threshold"].replace(
            doc="γ_0: the threshold right after a zero-velocity update",
            source="footzoo's: chosen on PyShoe's 36 trials per motion class (see the docstring)"),
        "time_constant": Real("s", "(0, 60]", "τ: the threshold grows by e every τ without an update",
                              source="footzoo's: chosen on PyShoe's 36 trials per motion class",
                              why="with τ over a minute the threshold never grows within a stride"),
        "max_threshold": Real("1", "(0, inf)", "γ_max: the cap of the threshold's growth",
                              source="footzoo's: chosen on PyShoe's 36 trials per motion class"),
        "min_swing": Real("s", "[0, 1]", "shortest swing: a shorter run of 'moving' counts as stance",
                          source="footzoo's, against split stances",
                          why="a real swing lasts 0.3-0.6 s"),
    }

    def __init__(self, threshold: float = 1e4, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1)), time_constant: float = 0.5, max_threshold: float = 5e5,
                 min_swing: float = 0.15):
        super().__init__(threshold, window, sigma_a, sigma_g)
        self.time_constant = time_constant
        self.max_threshold = max_threshold
        self.min_swing = min_swing

    def min_swing_samples(self, ctx: RunContext) -> int:
        """``min_swing`` in samples at the run's rate."""
        return int(math.floor(self.min_swing * ctx.rate + 0.5))

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> AdaptiveSHOE:
        """Evaluate SHOE, then the adaptive test sample by sample."""
        self.begin(run_context(ctx, t))
        self.statistic_ = self._statistic(t, acc, gyr)
        t = np.ascontiguousarray(t, dtype=float)
        test, self.threshold_, _ = adaptive_threshold_kernel(t, self.statistic_, self.threshold, self.time_constant,
                                                             max(self.max_threshold, self.threshold), float(t[0]))
        self.stance_ = close_short_swings(test, self.min_swing_samples(self.ctx_))
        self.stance_online_ = self.stance_.copy()
        return self

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """SHOE's half window, then ``min_swing`` (a short swing is filled once it has ended)."""
        return super().latency(ctx) + Latency(ctx.seconds(self.min_swing_samples(ctx)))

    def threshold_stage(self, keep: tuple[str, ...] = ()) -> AdaptiveThreshold:
        """The adaptive test, carrying the time of the last stance sample."""
        return AdaptiveThreshold(self.threshold, self.time_constant, max(self.max_threshold, self.threshold), keep)

    def gap_stage(self, keep: tuple[str, ...] = (), samples: int | None = None) -> OverlapSave:
        """:func:`close_short_swings` over the recent test (swings shorter than ``samples``, default
        ``min_swing``), restarted at a stance sample."""
        m = self.min_swing_samples(self.ctx_) if samples is None else samples

        def compute(test: np.ndarray, **given: np.ndarray) -> Chunk:
            return {"stance": close_short_swings(test, m), **{k: given[k] for k in ("statistic", "threshold", *keep)}}

        return OverlapSave(compute, lookahead=m, wants=("test", "statistic", "threshold", *keep),
                           restart=lambda out, inp, start, final: after_stance(inp["test"], start, final))

    def begin(self, ctx: RunContext) -> AdaptiveSHOE:
        """Fresh state: SHOE's window, the adaptive test, the closing of short swings."""
        super().begin(ctx)
        self._stages = [self.window_stage(keep=("t",)), self.threshold_stage(), self.gap_stage()]
        return self
