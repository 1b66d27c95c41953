"""Time stamps at half or twice the sensor's rate: the gyroscope–accelerometer consistency scan, made relative.

:class:`~footzoo.filters.consistency.ConsistencyScan` names a fault when most swings are
inconsistent (their residual ``|v| / (g T)`` above
:data:`~footzoo.filters.consistency.RESIDUAL_LIMIT`) and undoing the fault halves it. Stamps at
*twice* the real rate (a 100 Hz sensor stamped at 200 Hz) halve every rotation, and in a slow
walk or on stairs the swings' residual stays below that limit (0.15–0.2 on a simulated slow walk
and on PyShoe and gaitmap walks restamped so); a short walk has fewer than
:data:`~footzoo.filters.consistency.MIN_SWINGS` swings and is never decided on. Either way the
trajectory is wildly wrong (a quarter of the distance, or four times it: 67 m for a 12 m walk).

:class:`TimeScaleScan` runs the same scan (same swings, same numbers, batch and live) and adds
one relative rule for the two time-scale candidates: when the median residual over *all* swings
is above :data:`RATE_FLOOR` and the time scaled by 2 or 1/2 divides it by at least
:data:`~footzoo.filters.consistency.EXPLAINED_RATIO` (2), the time stamps are at the wrong rate
by that factor. At the end of the data it also decides on as few as :data:`MIN_RATE_SWINGS`
swings (both rules). On the real recordings in the data folder (PyShoe walking, running and
stairs, x-io, gaitmap, Köroğlu) the best rescaled time lowers the median residual by at most
1.14× (never 2×), and none is named; restamped at half or twice their rate, 69 of the 84 are named
(60 by the absolute rule alone), where undoing the factor lowers it 2.3–14×; not the unusual-motion
and upside-down trials, two walks, and runs with too few quasi-static instants.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..core.conventions import GRAVITY
from ..core.errors import SensorWarning
from ..filters.consistency import (
    _SCALE,
    _SIGNS,
    CANDIDATES,
    EXPLAINED_RATIO,
    MAX_SWINGS,
    MIN_SWINGS,
    SWING_RANGE,
    ConsistencyScan,
    _residuals,
)

#: Median residual (as given) above which a time-scale fault is considered (a noisy simulation: 0.006).
RATE_FLOOR = 0.02
#: Fewest swings decided on at the end of the data (a walk of four strides).
MIN_RATE_SWINGS = 4
#: Columns of the residuals (0: as given) whose candidate rescales the time.
_RATE_COLUMNS = tuple(i + 1 for i, c in enumerate(CANDIDATES) if c[1] != 1.0)
#: The time-scale faults by name, and the scale that undoes each.
_RATE_CAUSES = {c[0]: c[1] for c in CANDIDATES if c[1] != 1.0}
#: ... and what each means ("the sensor samples twice as fast as the time stamps say").
_RATE_MEANING = {c[0]: c[3].split(":")[0] for c in CANDIDATES if c[1] != 1.0}


class TimeScaleScan(ConsistencyScan):
    """:class:`~footzoo.filters.consistency.ConsistencyScan` with the relative rate rule (module docstring).

    Parameters
    ----------
    rate : float
        Nominal sampling rate (Hz): the shortest quasi-static run in samples.
    gravity : float
        g (m/s²).
    name : str
        The recording's name, for the warning.
    """

    def __init__(self, rate: float, gravity: float = GRAVITY, name: str = "recording"):
        super().__init__(rate, gravity, name)
        self.rate = float(rate)

    def _swings(self, buf: dict[str, np.ndarray], first: np.ndarray, last: np.ndarray) -> None:
        """The residuals of the swings ``first[i]``–``last[i]`` of ``buf``, every candidate on every swing."""
        duration = buf["t"][last] - buf["t"][first]
        ok = (duration >= SWING_RANGE[0]) & (duration <= SWING_RANGE[1])
        first, last = first[ok].astype(np.int64), last[ok].astype(np.int64)
        first, last = first[:MAX_SWINGS - len(self.residuals)], last[:MAX_SWINGS - len(self.residuals)]
        if not len(first):
            return
        out = np.empty((len(first), len(_SCALE)))
        _residuals(buf["t"], buf["acc"], buf["gyr"], first, last, _SCALE, _SIGNS, self.gravity, out)
        before = len(self.residuals)
        self.residuals.extend(out)
        self.swings.extend(zip(buf["k"][first].tolist(), buf["k"][last].tolist(), strict=True))
        for m in range((before // MIN_SWINGS + 1) * MIN_SWINGS, len(self.residuals) + 1, MIN_SWINGS):
            if not self.report:  # the same swings decide, batch and live
                self._decide(m)

    def _decide(self, m: int) -> None:
        """Decide on the first ``m`` swings: the absolute rule, then the relative rate rule.

        A rate named by either rule is reported with the likely factor and rate (``rate_factor``,
        ``likely_rate``) and one warning that gives the fix; the other faults as the absolute rule words them.
        """
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            super()._decide(m)
        if self.report and self.report["cause"] in _RATE_CAUSES:
            self._rate_finding(self.report)
            return
        for w in caught:  # an axis of the wrong sign: the absolute rule's own warning, under the caller's filters
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if self.report:
            return
        residuals = np.asarray(self.residuals[:m])
        r = np.median(residuals, axis=0)
        best = min(_RATE_COLUMNS, key=lambda c: r[c])
        if not (r[0] > RATE_FLOOR and r[best] * EXPLAINED_RATIO <= r[0]):
            return
        explained = residuals[:, best] * EXPLAINED_RATIO <= residuals[:, 0]
        self._rate_finding({"cause": CANDIDATES[best - 1][0], "residual": float(r[0]),
                            "explained_residual": float(r[best]), "swings": len(residuals),
                            "inconsistent_swings": int(np.count_nonzero(explained)),
                            "first_swings": [list(s) for s in self.swings[:3]]})

    def _rate_finding(self, report: dict[str, Any]) -> None:
        """Report time stamps at the wrong rate (``report``: cause, residuals, swings) with the factor and the fix."""
        scale = _RATE_CAUSES[report["cause"]]
        factor = 1.0 / scale  # the sensor's rate over the stamps' rate
        likely = self.rate * factor
        self.report = {**report, "rate_factor": factor, "likely_rate": likely}
        shown = ", ".join(f"{a}–{b}" for a, b in report["first_swings"])
        warnings.warn(
            f"{self.name}: the time stamps say {self.rate:.4g} Hz but the sensor most likely samples at "
            f"{factor:g}× that, about {likely:.4g} Hz ({_RATE_MEANING[report['cause']]}): over "
            f"{report['inconsistent_swings']} of {report['swings']} swings (samples {shown}, ...) the gyroscope's "
            "attitude leaves a velocity of "
            f"{report['residual']:.2f} g × the swing's duration where the foot stops, and "
            f"{report['explained_residual']:.2f} with the time scaled by {scale:g}. Every rotation and duration is "
            f"off by that factor, and the distances by about {factor ** 2:g}×. Give the reader the real rate "
            f"(footzoo.load(path, rate={likely:.4g}) where the reader has a rate option; a generic sidecar's "
            f"time: {{rate: {likely:.4g}}}), or fix the time column (t × {scale:g}). "
            "Details in diagnostics['sensor']['consistency']",
            SensorWarning, stacklevel=6,
        )

    def finish(self) -> dict[str, Any]:
        """End of the data: decide on every swing seen, from :data:`MIN_RATE_SWINGS` on; the finding."""
        super().finish()
        if not self.report and MIN_RATE_SWINGS <= len(self.residuals) < MIN_SWINGS:
            self._decide(len(self.residuals))
        return self.report
