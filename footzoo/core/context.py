"""The run context: what a run decides once about its recording and hands to every stage.

A batch run builds it from the recording (:meth:`RunContext.of`); a live stream from the
sensor's nominal rate (or the rate it measures over the still start) when it starts. Every
stage reads the rate, the sample period and gravity from here: none recomputes them from
the time stamps, so a live and a batch run of the same recording use the same numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .conventions import GRAVITY
from .errors import ConfigError


@dataclass(frozen=True)
class RunContext:
    """Rate, gravity and time base of one run (batch or live).

    Parameters
    ----------
    rate : float
        Sampling rate (Hz) the stages convert their durations with: a batch run takes the
        recording's median rate (:attr:`footzoo.Recording.rate`), a stream the sensor's nominal one.
    gravity : float
        g (m/s²) of the pipeline.
    t0 : float
        Time of the run's first sample (s).
    name : str
        The recording's name, for messages.
    """

    rate: float
    gravity: float = GRAVITY
    t0: float = 0.0
    name: str = "recording"

    def __post_init__(self) -> None:
        if not (isinstance(self.rate, (int, float, np.floating)) and math.isfinite(self.rate) and self.rate > 0):
            raise ConfigError(f"the run's rate must be a positive number of Hz, got {self.rate!r}")
        object.__setattr__(self, "rate", float(self.rate))
        object.__setattr__(self, "gravity", float(self.gravity))
        object.__setattr__(self, "t0", float(self.t0))

    @property
    def period(self) -> float:
        """Nominal sample period (s)."""
        return 1.0 / self.rate

    def samples(self, seconds: float, minimum: int = 0) -> int:
        """A duration (s) as the nearest whole number of samples (halves up), at least ``minimum``."""
        return max(int(minimum), int(math.floor(seconds * self.rate + 0.5)))

    def seconds(self, samples: int) -> float:
        """A number of samples as a duration (s)."""
        return samples / self.rate

    def with_(self, **changes: Any) -> RunContext:
        """A copy with some fields changed."""
        return replace(self, **changes)

    @classmethod
    def of(cls, recording: Any, gravity: float = GRAVITY) -> RunContext:
        """The context of a batch run over ``recording`` (a :class:`footzoo.Recording`)."""
        return cls(rate=recording.rate, gravity=gravity, t0=float(recording.t[0]), name=recording.name)

    @classmethod
    def from_time(cls, t: np.ndarray, gravity: float = GRAVITY, name: str = "recording") -> RunContext:
        """The context of time stamps ``t`` (s) alone: median rate, for a plug-in called outside a pipeline."""
        t = np.asarray(t, dtype=float)
        if t.ndim != 1 or t.shape[0] < 2:
            raise ConfigError("a run context needs at least two time stamps to know the rate; pass a RunContext")
        return cls(rate=float(1.0 / np.median(np.diff(t))), gravity=gravity, t0=float(t[0]), name=name)
