"""A learned zero-velocity detector: a small neural network over multi-scale window statistics.

Wagstaff, Peretroukhin & Kelly, "Robust data-driven zero-velocity detection for foot-mounted
inertial navigation", IEEE Sensors Journal 20(2), 2020 (PyShoe) learn the zero-velocity
decision from data (an LSTM over the raw IMU samples, trained on per-trial optimal labels) instead
of fixing one test and one threshold. footzoo's counterpart keeps inference to a few numpy
operations over shipped weights (no deep-learning framework at run time) and keeps every input a
duration, so that it means the same at any rate:

* **features** (per sample, centred windows of :data:`WINDOWS` = 0.025, 0.05, 0.1 and 0.2 s):
  for each window the logarithms of the mean squared angular rate ``mean ‖ω‖²`` (rad²/s²), of the
  specific-force variance ``mean ‖a‖² − ‖mean a‖²`` (m²/s⁴), of the squared deviation of the mean
  specific force from gravity ``(‖mean a‖ − g)²`` (m²/s⁴) and of the mean squared deviation of
  each sample's magnitude from gravity ``mean (‖a‖ − g)²`` (m²/s⁴) — Skog et al.'s (2010) window
  moments, 16 features, all invariant to how the sensor is mounted;
* **network**: the features standardised with the training set's mean and standard deviation,
  one hidden layer of :data:`HIDDEN` tanh units, a logistic output ``p_k``, the probability that
  sample k is a zero-velocity sample;
* **decision**: stance where ``p_k ≥ threshold``, 0.8 by default: a zero-velocity update in a swing
  costs far more than a stance sample left out, and a decision level of 0.8 declares stance only
  where the odds are 4 : 1 (chosen after seeing 6 PyShoe trials with the shipped weights: 0.5
  gave 0.08–0.14 m on walking, 0.8 gave 0.03–0.06 m; ``benchmarks/learned_zv.md`` scores it held out).

Training (``python -m footzoo.detectors.learned_zv_train --all``, numpy and scipy only) fits the
network to PyShoe's per-trial optimal labels (the zero-velocity labels of the detector with the
lowest error on each trial) of the VICON trials in ``../shared/data/pyshoe_vicon``; the shipped
weights (``footzoo/detectors/weights/learned_zv.npz``) are that fit on all 36 trials, and
``benchmarks/learned_zv.py`` scores the detector by leave-one-day-out cross-validation against
the classical detectors and PyShoe's labels.

Parameters
----------
threshold : float
    Decision level on the network's probability (1); 0.8.
weights : str, optional
    A weights file written by the training command (``.npz``); default: the shipped weights.

Attributes
----------
stance_, stance_online_ : (N,) bool ndarray
    Stance flag (final once the largest window's half has passed: 0.1 s).
statistic_ : (N,) ndarray
    ``p_k``, the probability of zero velocity (1).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from ..core.context import RunContext
from ..core.conventions import GRAVITY
from ..core.errors import ConfigError
from ..kernels.views import read_only
from ..plugins.base import Detector, File, Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave, feed
from ..plugins.registry import register
from .windows import window_moments

#: The centred windows of the features (s).
WINDOWS = (0.025, 0.05, 0.1, 0.2)
#: Hidden units of the network.
HIDDEN = 12
#: The shipped weights.
SHIPPED_WEIGHTS = Path(__file__).resolve().parent / "weights" / "learned_zv.npz"
#: Floors under the logarithms of the features (their units), so that a perfectly still synthetic sample stays finite.
FLOORS = (1e-8, 1e-6, 1e-6, 1e-6)
#: What a weights file holds.
WEIGHT_KEYS = ("mean", "std", "w1", "b1", "w2", "b2")


def window_samples(window: float, rate: float) -> int:
    """A window (s) in samples at ``rate`` (Hz): ``max(2, round(window · rate))``."""
    return max(int(round(window * rate)), 2)


def features(acc: np.ndarray, gyr: np.ndarray, rate: float) -> np.ndarray:
    """The (N, 16) features of every sample (see the module docstring), from specific force (m/s²) and rate (rad/s)."""
    acc, gyr = read_only(acc), read_only(gyr)  # one compiled variant for every caller (kernels/views.py)
    cols = []
    for window in WINDOWS:
        m = window_moments(acc, gyr, window_samples(window, rate), GRAVITY)
        mean_norm = np.linalg.norm(m[:, :3], axis=1)
        raw = (m[:, 4], np.maximum(m[:, 3] - mean_norm**2, 0.0), (mean_norm - GRAVITY) ** 2, m[:, 5])
        cols += [np.log(x + floor) for x, floor in zip(raw, FLOORS, strict=True)]
    return np.column_stack(cols)


def probability(x: np.ndarray, weights: dict[str, np.ndarray]) -> np.ndarray:
    """The network's ``p_k`` for the (N, 16) features ``x``."""
    z = (x - weights["mean"]) / weights["std"]
    hidden = np.tanh(z @ weights["w1"] + weights["b1"])
    logit = hidden @ weights["w2"] + weights["b2"]
    return 0.5 * (1.0 + np.tanh(0.5 * logit))  # the logistic function, without overflow


@lru_cache(maxsize=8)
def load_weights(path: str) -> dict[str, np.ndarray]:
    """Read a weights file, checking that it holds the network this module evaluates."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"learned_zv: weights file {p} does not exist: train one with "
                          "'python -m footzoo.detectors.learned_zv_train --all --out FILE.npz', or leave "
                          "'weights' out for the shipped weights")
    try:
        with np.load(p, allow_pickle=False) as data:
            weights = {k: np.asarray(data[k], dtype=float) for k in WEIGHT_KEYS}
    except (OSError, ValueError, KeyError) as err:
        raise ConfigError(f"learned_zv: {p} is not a weights file of footzoo's learned detector ({err}); "
                          "write one with 'python -m footzoo.detectors.learned_zv_train'") from None
    n = 4 * len(WINDOWS)
    shapes = {"mean": (n,), "std": (n,), "w1": (n, HIDDEN), "b1": (HIDDEN,), "w2": (HIDDEN,), "b2": ()}
    for key, shape in shapes.items():
        if weights[key].shape != shape or not np.all(np.isfinite(weights[key])):
            raise ConfigError(f"learned_zv: {p}: {key} must be a finite array of shape {shape}, "
                              f"got {weights[key].shape}; retrain with this version of footzoo")
    if np.any(weights["std"] <= 0):
        raise ConfigError(f"learned_zv: {p}: the feature scales (std) must be positive; retrain")
    return weights


@register
class LearnedZV(Detector):
    __doc__ = __doc__

    name = "learned_zv"
    paper = ("Wagstaff, Peretroukhin & Kelly 2020, IEEE Sensors J. 20(2) (learned zero-velocity detection), "
             "on Skog et al. 2010's window moments")
    parameters = {
        "threshold": Real("1", "(0, 1)", "decision level on the network's probability of zero velocity",
                          source="footzoo's (odds of 4 : 1: a false stance in a swing costs more than a missed one)"),
        "weights": File("weights file written by python -m footzoo.detectors.learned_zv_train",
                        suffixes=(".npz",), optional=True,
                        source="footzoo's shipped weights (all 36 PyShoe VICON trials)"),
    }

    def __init__(self, threshold: float = 0.8, weights: str | None = None):
        self.threshold = threshold
        self.weights = weights

    def _weights(self) -> dict[str, np.ndarray]:
        return load_weights(str(self.weights or SHIPPED_WEIGHTS))

    def _compute(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        p = probability(features(acc, gyr, self.ctx_.rate), self._weights())
        return {"stance": p >= self.threshold, "statistic": p}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> LearnedZV:
        """Evaluate the network over the whole recording (``t`` in s, ``acc`` in m/s², ``gyr`` in rad/s, FRD)."""
        self.begin(run_context(ctx, t))
        out = self._compute(t, acc, gyr)
        self.statistic_, self.stance_ = out["statistic"], out["stance"]
        self.stance_online_ = self.stance_.copy()
        return self

    # ------------------------------------------------------------------ live
    def _reach(self, ctx: RunContext) -> tuple[int, int]:
        """Samples the largest centred window reaches before and after its sample."""
        w = window_samples(max(WINDOWS), ctx.rate)
        return w // 2, w - 1 - w // 2

    def latency(self, ctx: RunContext) -> Latency:
        """Half the largest window (s): 0.1 s."""
        return Latency(ctx.seconds(self._reach(ctx)[1]))

    def begin(self, ctx: RunContext) -> LearnedZV:
        """Fresh state: the features over a window of the recent samples (overlap-save)."""
        super().begin(ctx)
        self._weights()  # a bad weights file fails here, before any sample
        before, after = self._reach(self.ctx_)
        self._stages = [OverlapSave(self._compute, lookahead=after, restart=before, wants=("t", "acc", "gyr"))]
        return self

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """Stance and ``p_k`` of the samples whose windows are now complete."""
        return feed(self._stages, {"t": t, "acc": acc, "gyr": gyr})

    def provisional(self) -> Chunk:
        """Stance from the windows clipped at the newest sample."""
        return self._stages[-1].provisional()

    def finish(self) -> Chunk:
        """The last samples, with the windows clipped at the end of the data (as in the batch run)."""
        return feed(self._stages, {}, finish=True)
