"""Shared base of Skog et al.'s (2010) windowed zero-velocity tests: SHOE, ARED, AMVD, MBGTD."""

from __future__ import annotations

import numpy as np

from ..core.context import RunContext
from ..core.conventions import GRAVITY
from ..kernels.views import read_only
from ..plugins.base import Detector, Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave, feed
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
    gravity_ : float
        g (m/s²) the tests compare the specific force with: the run's gravity (the pipeline's
        ``gravity``, which the accelerometer-gain stage scales a still start to), so the detector and
        the rest of the run agree on what a still sensor reads. Skog et al. take g as the known local
        gravity (OpenShoe computes it from latitude and altitude), not a fixed constant.
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

    def window_samples(self, ctx: RunContext) -> int:
        """W in samples at the run's rate: ``max(2, round(window · rate))``."""
        return max(int(round(self.window * ctx.rate)), 2)

    def _statistic(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> np.ndarray:
        self.window_samples_ = self.window_samples(self.ctx_)
        acc, gyr = read_only(acc), read_only(gyr)  # one compiled variant for every caller (kernels/views.py)
        g = self.gravity_
        fused = FUSED_TESTS.get(type(self).test)
        if fused is not None:  # the same numbers as test(window_moments(...)), without the (N, 6) moments
            return window_statistic(acc, gyr, self.window_samples_, g, g**2, fused, self.sigma_a**2, self.sigma_g**2)
        return self.test(window_moments(acc, gyr, self.window_samples_, g))

    @property
    def gravity_(self) -> float:
        """g (m/s²) of the tests: the run's (:attr:`RunContext.gravity`, the pipeline's ``gravity``), the paper's
        "magnitude of the local gravity vector"; 9.81 before a run (:data:`~footzoo.core.conventions.GRAVITY`)."""
        ctx = getattr(self, "ctx_", None)
        return GRAVITY if ctx is None else ctx.gravity

    def _compute(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """The batch test over arrays: ``stance`` and ``statistic``."""
        statistic = self._statistic(t, acc, gyr)
        return {"stance": statistic < self.threshold, "statistic": statistic}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> SkogTest:
        """Evaluate the test over the whole recording.

        Parameters
        ----------
        t : (N,) ndarray
            Time (s).
        acc : (N, 3) ndarray
            Specific force (m/s²).
        gyr : (N, 3) ndarray
            Angular rate (rad/s).
        ctx : RunContext, optional
            The run's context (rate); default: from ``t``.
        """
        self.begin(run_context(ctx, t))
        out = self._compute(t, acc, gyr)
        self.statistic_, self.stance_ = out["statistic"], out["stance"]
        self.stance_online_ = self.stance_.copy()
        return self

    # ------------------------------------------------------------------ live
    def _window_reach(self, ctx: RunContext) -> tuple[int, int]:
        """Samples of the centred window before and after its sample (``W//2`` and ``W − 1 − W//2``)."""
        w = self.window_samples(ctx)
        return w // 2, w - 1 - w // 2

    def latency(self, ctx: RunContext) -> Latency:
        """The window's half after the sample (s)."""
        return Latency(ctx.seconds(self._window_reach(ctx)[1]))

    def begin(self, ctx: RunContext) -> SkogTest:
        """Fresh state: a window of the last W samples (overlap-save, see :mod:`footzoo.plugins.incremental`)."""
        super().begin(ctx)
        self._stages = [self.window_stage()]
        return self

    def window_stage(self, keep: tuple[str, ...] = ()) -> OverlapSave:
        """The test over a window of the recent samples; its outputs also carry the inputs named in ``keep``.

        For a detector built on the test (a later stage takes the statistic and, e.g., ``t``).
        """
        before, after = self._window_reach(self.ctx_)

        def compute(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
            given = {"t": t, "acc": acc, "gyr": gyr}
            return {**self._compute(t, acc, gyr), **{k: given[k] for k in keep}}

        return OverlapSave(compute, lookahead=after, restart=before, wants=("t", "acc", "gyr"))

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """The stance (and statistic) of the samples whose outputs are now final.

        The test's window, then any stage a subclass adds (``_stages``, fed one into the next).
        """
        return feed(self._stages, {"t": t, "acc": acc, "gyr": gyr})

    def provisional(self) -> Chunk:
        """The last stage's current outputs for the samples it has seen but not finalised."""
        return self._stages[-1].provisional()

    def finish(self) -> Chunk:
        """The last samples, with the window clipped at the end of the data (as in the batch test)."""
        return feed(self._stages, {}, finish=True)
