"""Guards of a pipeline run: what footzoo does when a detector misses stances, and what it reports.

A zero-velocity pipeline lives on its stances: the dedrift removes the velocity drift of
each swing at its end, the Kalman filter's zero-velocity update bounds the velocity error in
every stance. A detector that misses the stances of a motion it was not made for (the
angular-rate machine or the windowed test on running, whose stance holds the foot still
for 0.05–0.1 s) leaves a "swing" of many seconds, and the velocity error grows without
bound: on PyShoe's running trials such pipelines ended 8–38 m from the VICON reference.
Two guards, on by default in every pipeline, whatever its detector (they read only the
stance mask, the angular rate and the result):

* **Maximum swing** (:class:`StanceGuard`) — no foot swings for longer than
  ``max_swing`` (1.5 s; the longest human swing, slow walking included, is about
  0.6 s, and a detector that dates its swings to the heel and toe rolls stretches it
  to about 1.2 s). In every longer swing the guard marks the stillest instants of
  the foot as stance: the local minima of the angular-rate magnitude (averaged
  over ``window``) below ``still_rate`` (1 rad/s: a foot turning about a ground contact
  point about 0.1 m away moves at 0.1 m/s), at least ``min_step`` apart (0.4 s,
  shorter than any stride of one foot). Each is one sample: the guard knows that the
  foot came to rest there, not for how long, and one zero-velocity sample per stride
  is the same information at any sampling rate (``half_width`` widens it to the
  neighbouring samples still below ``still_rate``; 0.05 s made the Kalman pipelines
  worse on PyShoe's running trials: ``duong2015_zupt`` median 0.25 m against 0.19 m).
  A missed stance then degrades the estimate instead of letting it run away. The guard looks at a whole
  swing, so it is a batch step: a live :class:`~footzoo.runtime.stream.Stream` cannot apply
  it and warns instead when its detector reaches ``max_swing``.
* **Speed bound** (:func:`check_speed`) — a foot moves at most about 2.5 times the
  body's speed in its swing, some 20–25 m/s in a sprint; an estimate faster than
  ``max_speed`` (50 m/s, twice that) has diverged.

Both report in ``Result.diagnostics["guards"]`` and, when they fire, with a
:class:`~footzoo.core.errors.GuardWarning` that says why the trajectory is suspect. They
do not fire on the simulator walks that reproduce the papers (their swings are
shorter than 1.5 s). Switch them off with ``guards: {max_swing: 0, max_speed: 0}``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.checks import Settings
from ..core.context import RunContext
from ..core.errors import GuardWarning, user_stacklevel
from ..core.norms import row_norms
from ..core.params import Real
from ..evaluation.metrics import intervals
from ..kernels.jit import njit
from ..plugins.incremental import Chunk, Latency, OverlapSave


@njit
def _still_instants(score: np.ndarray, still: float, sep: int, half: int) -> np.ndarray:
    """Stance mask of the local minima of ``score`` below ``still``, ``sep`` samples apart, widened by ``half``.

    The minima are taken greedily from the stillest up; each blocks its
    neighbours closer than ``sep``. Each marked instant spreads to the
    neighbouring samples still below ``still``, at most ``half`` either side.
    """
    n = score.shape[0]
    out = np.zeros(n, dtype=np.bool_)
    blocked = np.zeros(n, dtype=np.bool_)
    for i in np.argsort(score, kind="mergesort"):
        if score[i] > still:
            break
        if blocked[i]:
            continue
        for j in range(max(i - sep + 1, 0), min(i + sep, n)):
            blocked[j] = True
        out[i] = True
        lo = i
        while lo > 0 and i - lo < half and score[lo - 1] <= still:
            lo -= 1
            out[lo] = True
        hi = i
        while hi < n - 1 and hi - i < half and score[hi + 1] <= still:
            hi += 1
            out[hi] = True
    return out


#: What a guard that found still instants in a long swing says of the detector, and the fixes.
MISSED_STANCE = ("the detector, at its setting, misses the stances of this motion: loosen its threshold (more "
                 "stance), choose a detector made for this motion (running?), or switch the guard off with "
                 "guards: {max_swing: 0}")


@dataclass
class StanceGuard(Settings):
    """Stance at the stillest instants of every swing longer than ``max_swing`` (see the module docstring).

    Parameters
    ----------
    max_swing : float
        Longest swing (s) left as the detector gave it; 0 switches the guard off.
    still_rate : float
        Angular-rate magnitude (rad/s) below which an instant can be stance.
    min_step : float
        Shortest time (s) between two stance instants the guard marks.
    half_width : float
        Widest extent (s) of a marked stance on either side of its instant (0: the instant alone).
    window : float
        Duration (s) of the centred average of the angular-rate magnitude.
    max_speed : float
        Speed (m/s) above which the estimate is reported as diverged; 0: no check.
    """

    max_swing: float = 1.5
    still_rate: float = 1.0
    min_step: float = 0.4
    half_width: float = 0.0
    window: float = 0.04
    max_speed: float = 50.0

    section = "guards"
    example = "{max_swing: 1.5}"
    parameters = {
        "max_swing": Real("s", "[0, 10]", "longest swing left as the detector gave it; 0: the guard is off",
                          source="footzoo's: the longest human swing lasts about 0.6 s (1.2 s dated to the rolls)",
                          why="a swing of 10 s is a detector that found no stance; use 0 to switch the guard off"),
        "still_rate": Real("rad/s", "[0, 10]", "|ω| below which an instant can be stance",
                           source="footzoo's: a foot turning about a contact 0.1 m away moves at 0.1 m/s",
                           why="a foot turns faster than 10 rad/s (573 °/s) only in mid-swing"),
        "min_step": Real("s", "[0, 10]", "shortest time between two stance instants the guard marks",
                         source="footzoo's: shorter than any stride of one foot"),
        "half_width": Real("s", "[0, 1]", "widest extent of a marked stance either side of its instant",
                           source="footzoo's: one sample (0.05 s made the Kalman pipelines worse on PyShoe)"),
        "window": Real("s", "[0, 1]", "duration of the centred average of |ω|", source="footzoo's"),
        "max_speed": Real("m/s", "[0, 1000]", "speed above which the estimate has diverged; 0: no check",
                          source="footzoo's: twice a sprinting foot's 20-25 m/s"),
    }

    def apply(self, t: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
              ctx: RunContext | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        """The stance mask with the over-long swings given stances, and the report.

        Parameters
        ----------
        t : (N,) ndarray
            Time (s).
        gyr : (N, 3) ndarray
            Angular rate (rad/s).
        stance : (N,) bool ndarray
            The detector's stance mask.
        ctx : RunContext, optional
            The run's context (its rate converts the durations); default: from ``t``.

        Returns
        -------
        stance : (N,) bool ndarray
            The guarded mask (a copy; the detector's where the guard did not fire).
        report : dict
            ``long_swings`` ([start, end] s of every swing longer than ``max_swing``),
            ``longest_swing`` (s), ``stances_added``, ``samples_added``.
        """
        s = np.asarray(stance, dtype=bool)
        out = s.copy()
        report: dict[str, Any] = {"long_swings": [], "longest_swing": 0.0, "stances_added": 0, "samples_added": 0}
        n = s.shape[0]
        if n < 2:
            return out, report
        rate = (ctx if ctx is not None else RunContext.from_time(t)).rate
        swings = intervals(~s)
        if len(swings):
            report["longest_swing"] = float(np.max(swings[:, 1] - swings[:, 0]) / rate)
        if self.max_swing <= 0.0 or not len(swings):
            return out, report
        long = swings[(swings[:, 1] - swings[:, 0]) > self.max_swing * rate]
        if not len(long):
            return out, report
        w = row_norms(gyr)
        k = self._half_window(rate)
        score = np.convolve(np.pad(w, k, mode="edge"), np.full(2 * k + 1, 1.0 / (2 * k + 1)), mode="valid")
        sep = max(int(math.floor(self.min_step * rate + 0.5)), 1)
        half = int(math.floor(self.half_width * rate + 0.5))
        for a, b in long:
            added = _still_instants(np.ascontiguousarray(score[a:b]), self.still_rate, sep, half)
            out[a:b] |= added
            report["long_swings"].append([float(t[a]), float(t[b - 1])])
            report["stances_added"] += len(intervals(added))
            report["samples_added"] += int(np.count_nonzero(added))
        return out, report

    def _half_window(self, rate: float) -> int:
        return max(int(math.floor(self.window * rate / 2 + 0.5)), 0)

    # ------------------------------------------------------------------ live
    def latency(self, ctx: RunContext) -> Latency:
        """A swing's stance is final once the swing has ended (and the score's half window after it)."""
        if self.max_swing <= 0.0:
            return Latency()
        return Latency(ctx.seconds(self._half_window(ctx.rate)), ("the end of the swing",))

    def stream(self, ctx: RunContext) -> OverlapSave | None:
        """The guard live (overlap-save over :meth:`apply`): ``step(t=, gyr=, stance=)`` gives ``stance`` and
        ``added`` (the samples it marked) of the samples now final; None when the guard is off."""
        if self.max_swing <= 0.0:
            return None
        k = self._half_window(ctx.rate)

        def compute(t: np.ndarray, gyr: np.ndarray, stance: np.ndarray) -> Chunk:
            out, _ = self.apply(t, gyr, stance, ctx)
            return {"stance": out, "added": out & ~np.asarray(stance, dtype=bool), "t": t}

        def ready(inp: Chunk, start: int) -> int:
            # every swing the guard may still change: the open one, or one without the score's half window after it
            s = inp["stance"]
            swing = np.flatnonzero(~s[max(s.size - k - 1, 0):])
            if not swing.size:  # the last k + 1 samples are stance: every swing before them is final
                return start + s.size
            first = s.size - k - 1 + int(swing[0]) if s.size > k + 1 else int(swing[0])
            before = np.flatnonzero(s[:first])  # the pending swing starts after the last stance sample before it
            return start + (int(before[-1]) + 1 if before.size else 0)

        return OverlapSave(compute, lookahead=ready, restart=lambda out, inp, start, final: final - k - 1,
                           wants=("t", "gyr", "stance"))

    def warn(self, report: dict[str, Any], detector: str, recording: str) -> None:
        """A :class:`GuardWarning` when the maximum-swing guard fired."""
        long = report.get("long_swings") or []
        if not long:
            return
        total = sum(e - s for s, e in long)
        if report["stances_added"]:  # the foot did come to rest there: the detector missed it
            cause = (f"The stance guard marked {report['stances_added']} still instant(s) (|ω| ≤ {self.still_rate:g} "
                     f"rad/s) there as stance: the trajectory in those swings is suspect — {MISSED_STANCE}")
        else:  # nor did the angular rate ever come to rest: no detector would find a stance there
            cause = (f"The angular rate never fell to {self.still_rate:g} rad/s there either, so the guard marked no "
                     "stance and the detector is not shown to be at fault: the foot did not come to rest (not a gait "
                     "the zero-velocity methods follow, or a sensor not on the foot); the trajectory in those swings "
                     "is strapdown drift")
        warnings.warn(
            f"{recording}: detector {detector!r} found no stance for {report['longest_swing']:.1f} s (longest of "
            f"{len(long)} swing(s) over max_swing = {self.max_swing:g} s, {total:.1f} s in all, the first from "
            f"t = {long[0][0]:.2f} s). {cause}. Details in Result.diagnostics['guards']",
            GuardWarning, stacklevel=user_stacklevel(),
        )


def check_speed(t: np.ndarray, vel: np.ndarray, max_speed: float, recording: str) -> dict[str, Any]:
    """Report (and warn about) an estimated speed above ``max_speed`` (m/s): the estimate has diverged.

    Returns
    -------
    dict
        ``max_speed`` (the estimate's, m/s), ``over_max_speed`` (samples above the bound),
        ``first_over_t`` (s, or None).
    """
    speed = row_norms(vel)
    top = float(np.max(speed)) if speed.size and np.all(np.isfinite(speed)) else float("inf")
    over = np.flatnonzero(~(speed <= max_speed)) if max_speed > 0 else np.zeros(0, dtype=int)
    report = {"max_speed": top, "over_max_speed": int(over.size),
              "first_over_t": float(t[over[0]]) if over.size else None}
    if over.size:
        warnings.warn(
            f"{recording}: the estimated foot speed reaches {top:.3g} m/s (above {max_speed:g} m/s from "
            f"t = {t[over[0]]:.2f} s, {over.size} samples): faster than any foot moves, the estimate has diverged "
            "(missed stances or a wrong attitude). Details in Result.diagnostics['guards']",
            GuardWarning, stacklevel=user_stacklevel(),
        )
    return report
