"""Which foot the sensor is on, from the trajectory: the swing foot arcs outward.

A method that needs the foot side (the sign of the foot progression angle, Huang et al. 2016)
takes it from the recording (``meta["foot"]``) or its config; when neither names it, this module
reads it from the walk, and says how sure it is.

**The cue.** Walking straight, the swinging foot does not travel along the straight line between
its two footprints: it arcs outward, away from the walker's midline, and comes back. For stride
``i`` (the middle of stance ``i`` to the middle of stance ``i + 1``, a chord of direction ``d_i``)
the *swing arc* is the mean, over the swing's samples, of the sensor's horizontal offset from the
chord, to the right of ``d_i`` (m): positive for a right foot, negative for a left foot. It
depends on the trajectory alone (NED positions), not on how the sensor sits on the foot, and it
needs no magnetometer.

**Straight strides only.** On a curved path the chord cuts the curve, and the path's own
curvature (a sagitta of ``L²κ/8``: 10 cm for a 1.4 m stride on a 2.5 m radius) swamps the 1–3 cm
arc. A stride is used when the direction of the stride before it and that of the stride after it
differ by less than :data:`MAX_TURN` and all three are at least :data:`MIN_STRIDE_LENGTH` long.

**How sure.** Each straight stride whose arc is at least :data:`MIN_ARC` votes with the sign of
its arc (the others abstain); the side is named when at
least :data:`MIN_STRIDES` strides voted and at least :data:`MIN_AGREEMENT` of them agree, and the
evidence (``k`` of ``n`` strides, the median arc) is reported with it; otherwise no side is named,
with the reason. Measured (``benchmarks/foot_side.md``, the ``recommended`` config, each
recording's side hidden): gaitmap's example (both feet) and the 36 foot recordings of ipol_gait
(3 walkers, 6 trials, both feet): 38 of 38 read right, at least 88 % of each recording's votes
agreeing (a median of 10 voting strides per ipol recording, 23 per gaitmap foot, arcs of 0.5–3 cm);
PyShoe's 36 trials, walked in a small room that they circle all the time: no side
named on any (0 or 1 straight stride each), none wrong. Four walkers are few: a walker whose swing
does not arc outward (a circumducting or a shuffling gait) would be read wrongly, so a side read
from the data is always reported with its evidence, and a declared one always wins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .gait_events import stride_directions
from .strides import real_stances

#: Shortest stride (m, horizontal) that counts: a turn on the spot or a shuffle has no direction.
MIN_STRIDE_LENGTH = 0.5
#: Largest change of direction (rad) between the stride before and the stride after a straight stride (6°).
MAX_TURN = np.radians(6.0)
#: Smallest swing arc (m) that votes: a walk whose swing does not arc (a simulated one, a shuffle) leaves a few
#: tenths of a millimetre of systematic error, which must not name a side.
MIN_ARC = 0.002
#: Fewest straight strides that vote.
MIN_STRIDES = 5
#: Smallest share of the votes that must agree to name a side.
MIN_AGREEMENT = 0.8


@dataclass
class FootSide:
    """The foot side read from a walk, and the evidence.

    Attributes
    ----------
    side : {"left", "right"} or None
        None when the walk does not tell (``reason`` says why).
    strides : int
        Straight strides that voted.
    agreeing : int
        Of those, the ones whose arc points to ``side`` (to the right when no side is named).
    arc_m : float
        Median swing arc over the voting strides (m, positive: to the right of travel).
    reason : str
        The evidence in words, or why no side is named.
    """

    side: str | None
    strides: int
    agreeing: int
    arc_m: float
    reason: str

    @property
    def agreement(self) -> float:
        """Share of the voting strides that agree (NaN without votes)."""
        return self.agreeing / self.strides if self.strides else float("nan")

    def as_dict(self) -> dict[str, object]:
        """The fields and the agreement, for diagnostics and tables."""
        return {"side": self.side, "strides": self.strides, "agreeing": self.agreeing,
                "agreement": self.agreement, "arc_m": self.arc_m, "reason": self.reason}


def swing_arcs(pos: np.ndarray, stances: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each stride's swing arc (K,) (m, positive: to the right of travel) and whether it is straight (K,) bool.

    Parameters
    ----------
    pos : (N, 3) ndarray
        Position, NED (m).
    stances : (K + 1, 2) int ndarray
        The real stances ``(start, stop)`` (:func:`footzoo.analysis.strides.real_stances`).
    """
    pos = np.asarray(pos, dtype=float)
    k = len(stances) - 1
    if k < 1:
        return np.zeros(0), np.zeros(0, dtype=bool)
    d, mid = stride_directions(pos, stances)
    length = np.hypot(*(pos[mid[1:], :2] - pos[mid[:-1], :2]).T)
    lo, hi = stances[:-1, 1], stances[1:, 0]  # the swings: after stance i, before stance i + 1
    sums = np.concatenate([np.zeros((1, 2)), np.cumsum(pos[:, :2], axis=0)])
    count = np.maximum(hi - lo, 1)
    mean = (sums[hi] - sums[lo]) / count[:, None]
    right = np.column_stack([-d[:, 1], d[:, 0]])
    arc = np.einsum("ij,ij->i", mean - pos[mid[:-1], :2], right)
    arc[hi <= lo] = np.nan
    straight = np.zeros(k, dtype=bool)
    if k >= 3:
        before, after = d[:-2], d[2:]
        turn = np.abs(np.arctan2(before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0],
                                 np.einsum("ij,ij->i", before, after)))
        long = (length[:-2] >= MIN_STRIDE_LENGTH) & (length[1:-1] >= MIN_STRIDE_LENGTH) & \
               (length[2:] >= MIN_STRIDE_LENGTH)
        straight[1:-1] = (turn < MAX_TURN) & long
    return arc, straight & np.isfinite(arc)


def infer_foot(pos: np.ndarray, stance: np.ndarray, stances: np.ndarray | None = None) -> FootSide:
    """The foot side of a walk from its swing arcs (see the module docstring).

    Parameters
    ----------
    pos : (N, 3) ndarray
        Position, NED (m).
    stance : (N,) bool ndarray
        Stance flag.
    stances : (K + 1, 2) int ndarray, optional
        The real stances when the caller has them.
    """
    st = real_stances(np.asarray(stance, dtype=bool), pos) if stances is None else stances
    arc, straight = swing_arcs(pos, st)
    votes = arc[straight & (np.abs(arc) >= MIN_ARC)]
    n = int(votes.size)
    n_right = int(np.sum(votes > 0))
    median = float(np.median(votes)) if n else float("nan")
    if n < MIN_STRIDES:
        return FootSide(None, n, n_right, median,
                        f"too few straight strides to tell the foot from the swing arc ({n} of {max(len(st) - 1, 0)} "
                        f"strides are straight with an arc of {MIN_ARC * 1000:.0f} mm or more; at least {MIN_STRIDES} "
                        "needed)")
    share = n_right / n
    if share >= MIN_AGREEMENT or share <= 1 - MIN_AGREEMENT:
        side = "right" if share >= MIN_AGREEMENT else "left"
        agreeing = n_right if side == "right" else n - n_right
        return FootSide(side, n, agreeing, median,
                        f"the swing arcs to the {side} on {agreeing} of {n} straight strides "
                        f"(median {abs(median) * 100:.1f} cm)")
    return FootSide(None, n, n_right, median,
                    f"the swing arc does not tell the foot: it points to the right on {n_right} and to the left on "
                    f"{n - n_right} of {n} straight strides (at least {MIN_AGREEMENT:.0%} must agree)")
