"""Is it human gait? A run's strides against the ranges of human gait, and the declaration that explains them.

A wrong sampling rate passes every check of the signals themselves when no time stamp
contradicts it: a 60 Hz walk declared as 120 Hz reads at twice its rate, every duration
halves, every rotation the gyroscope integrates halves and every distance shrinks by about
four (a double integral of the same accelerations over half the time). What betrays it is
the gait the run estimates: strides of 0.17 m at 163 steps/min with 6 mm of foot clearance
are what a walk of 0.7 m strides at 81 steps/min gives when read at twice its rate.

:class:`GaitScan` is fed a run's final estimates (batch: once; live: chunk by chunk, by
:class:`~footzoo.core.sanity.EstimateScan`) and measures every stride between the middles of
two consecutive stances of the detector: its duration ``T`` (s), length ``L`` (m, horizontal),
the foot's clearance ``h`` (m, the highest point of the swing above the first stance), the
foot's rotation in the swing ``θ = ∫|ω| dt`` (rad) and its peak rate (rad/s). A declared rate
``F`` times the real one (``F = 2``: read at twice its rate) changes them as ``T/F``, ``L/F²``,
``h/F²``, ``θ/F``, cadence ``×F``, speed ``/F``; the angular rate the gyroscope measures does not
change. Each hypothesis ``F`` of :data:`FACTORS` (and ``F = 1``, the declaration) is scored by
how far the strides, with ``F`` undone, fall outside the ranges of human gait:

========================  ===============  ====================================================
quantity (``F`` undone)   range            source
========================  ===============  ====================================================
cadence (steps/min)       35–300           slow walking of the elderly (Murakami & Otaka 2017,
                                           J Phys Ther Sci 29:722) to sprinting at 4.5–5 steps/s
                                           (Weyand et al. 2000, J Appl Physiol 89:1991)
stride length (m)         0.1–6            shuffling steps to elite sprint strides of
                                           2 × 2.5–2.7 m (Weyand et al. 2000)
speed (m/s)               0.05–12          a stroll to Bolt's 12.3 m/s peak
foot clearance (m)        0.01–1           minimum toe clearance 1.3 cm in walking (Winter
                                           1992, Phys Ther 72:45); the heel at the buttocks in
                                           a sprint swing
cadence vs speed          ≤ 150 + 15 v     walkers step at 95–160 steps/min (pedestrians:
                                           Sato et al. via Murakami & Otaka 2017); runners
                                           raise their cadence with speed, to 3.0 ± 0.2 steps/s
                                           at 65–70 % of their top speed and 4.5–5 at the top
                                           (Ae et al., PMC8523042; Weyand et al. 2000)
rolling ratio L/θ (m/rad) 0.24–0.45        footzoo's measurement: the stride length per radian
                                           the foot turns in its swing is 0.26–0.40 m/rad on
                                           every walk and run of the data folder, 0.21–0.40
                                           (median 0.34) on all 42 real recordings, crawling
                                           and shuffling included (``benchmarks/relabel.md``)
========================  ===============  ====================================================

The cost of a hypothesis is the sum, over these quantities, of the squared distance outside
the range in units of :data:`TOLERANCE` (25 %), each capped at :data:`CAP` (a run that is no
gait at all — crawling, a pipeline whose detector missed most stances — cannot outvote the
rest; a gait that no hypothesis brings within :data:`GAIT_INFORMATIVE` is no evidence at all),
plus the gyroscope–accelerometer evidence of the rate
(:meth:`footzoo.filters.consistency.ConsistencyScan.time_scales`: the swings integrated with the
time scaled by ``F``, whose residual is lowest where the rate is right — on real recordings
0.92–1.09 times the right scale, so the lowest residual within :data:`SCALE_WINDOW` of ``F``
counts; its excess over the lowest in units of :data:`CONSISTENCY_TOLERANCE`, 30 %), plus
:data:`PRIOR` for any hypothesis but the declared one. When the best hypothesis costs
:data:`MARGIN` less than the declared rate, one :class:`~footzoo.core.errors.SensorWarning`
names it, with the strides as declared and as corrected, the likely rate (the declared one
divided by ``F``, rounded to a common rate of :data:`COMMON_RATES` within 3 %) and the fix.
The gait alone never names a rate: a detector that splits or merges strides changes cadence and
length as a wrong rate does (a four-stride walk with a badly tuned detector gave 0.03 m at 240
steps/min), so a rate is named only if the residuals prefer it by :data:`SUPPORT`, and the factor
named is the one, on that side of 1, whose residual is lowest (the gait's ranges tell that the
rate is wrong more than by how much; they name one of the 42 real walks relabelled at ×2 and
one at ×1.5 that the residuals alone leave below the margin).
When the detector gives fewer than :data:`MIN_STRIDES` strides (a detector tuned in seconds merges
a run's strides when the rate is wrong), the gait weighed is the strides between the foot's quiet
instants, measured by the gyroscope–accelerometer scan itself (the finding's ``strides`` then say
``between: quiet instants``); and a foot never as still as a walking one (a fast run) is timed
between its quietest instants (:mod:`footzoo.filters.consistency`).
As recorded, none of the 78 real recordings of the data folder is named (the 42 the checks were
designed on and IPOL's 36, held out), nor any of 18 simulated walks, runs, a shuffle and stairs
at 100, 250 and 400 Hz; relabelled at ×2, ×½ or ×1.5 (time stamps divided by the factor), 41,
39 and 40 of the 42 are named with the real rate, all 36 of IPOL's, and 16, 18 and 15 of the 18
simulated ones (``recommended``; ``benchmarks/relabel.md``). What is left — a crawl, a slow walk
whose foot hardly turns, the shortest-stepped walk at half its rate, the simulated shuffle — is
analysed in ``benchmarks/relabel_misses.md``.

A gyroscope in rad/s declared as deg/s reads 57.3 times too slow: the accelerometer shows a
foot that moves (|‖f‖ − g| above :data:`MOTION_ACC` for :data:`MOTION_TIME` s) while the
gyroscope never turns it (fewer than :data:`TURN_FRACTION` of those samples above
:data:`TURN_RATE`); a moving foot turns at 5–20 rad/s. A recording that ends before
:data:`MOTION_TIME` s of motion (four strides of a walk) is judged at its end, on a stricter test
for less evidence: at least :data:`SHORT_MOTION_TIME` s of motion and a gyroscope that never
exceeds :data:`SHORT_TURN_RATE` (20 °/s) anywhere. That is named too (and the rate is then
not judged). An accelerometer in g or mg declared as m/s², or the reverse, and a gyroscope in
deg/s declared as rad/s are refused when the recording is built
(:func:`footzoo.core.data.check_units`).

Findings are kept in ``Result.diagnostics["sensor"]["plausibility"]`` (and ``Stream.sensor``):
the strides' medians as declared, the hypotheses' costs, ``rate_factor``, ``likely_rate``.
Decided on the first :data:`CHECKPOINTS` strides as soon as they are measured (live) and on
every stride at the end of the data: batch and live give the same finding.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, Protocol

import numpy as np

from .conventions import GRAVITY
from .errors import SensorWarning, user_stacklevel
from .norms import row_norms

#: Hypotheses of a wrong rate: the declared rate is ``F`` times the real one (2: read at twice its rate).
FACTORS = (2.0, 1.5, 1.25, 1.2, 1.0 / 1.2, 0.8, 2.0 / 3.0, 0.5)
#: Ranges of human gait (walking to sprinting) with ``F`` undone: cadence (steps/min), stride length (m), speed
#: (m/s), foot clearance (m), rolling ratio (m/rad); see the module docstring for the sources.
CADENCE_RANGE = (35.0, 300.0)
STRIDE_LENGTH_RANGE = (0.1, 6.0)
SPEED_RANGE = (0.05, 12.0)
CLEARANCE_RANGE = (0.01, 1.0)
ROLLING_RANGE = (0.24, 0.45)
#: Highest cadence at a speed v (m/s): ``CADENCE_AT_REST + CADENCE_PER_SPEED * v`` steps/min.
CADENCE_AT_REST = 150.0
CADENCE_PER_SPEED = 15.0
#: One unit of cost: a quantity 25 % outside its range costs 1 (squared: 2 units cost 4).
TOLERANCE = math.log(1.25)
#: Largest cost of one quantity (three units): a run that is no gait cannot outvote the rest.
CAP = 9.0
#: One unit of cost of the gyroscope-accelerometer evidence: a residual 30 % above the lowest.
CONSISTENCY_TOLERANCE = math.log(1.3)
#: The residual counted for a time scale is the lowest between these multiples of it (real recordings: lowest at
#: 0.92–1.09× the right scale, 1.0 in the median over the 42 real recordings as recorded, 1.09 over IPOL's 36;
#: a simulation: at it).
SCALE_WINDOW = (0.98, 1.12)
#: With the gyroscope-accelerometer evidence, a rate is named only if it lowers that evidence's cost by this much
#: (the gait alone does not overrule residuals that do not depend on the time scale).
SUPPORT = 1.0
#: Cost of any declaration but the one made, and the margin by which another must win to be named.
PRIOR = 2.0
MARGIN = 4.0
#: The gait is evidence only when some hypothesis (the declared one included) costs at most this.
GAIT_INFORMATIVE = 4.0
#: A second hypothesis within this cost of the best is named as the alternative.
AMBIGUOUS = 2.0
#: Fewest strides and swings the rate is judged on.
MIN_STRIDES = 6
MIN_SWINGS = 4
#: The strides after which the rate is judged live (then at the end of the data on every stride measured).
CHECKPOINTS = (12, 24, 48)
#: Most strides measured (the scan's memory is bounded; a rate does not change within a recording).
MAX_STRIDES = 256
#: Samples per block in which a long chunk (a batch run's recording) is scanned.
BLOCK = 16384
#: Longest stride, stance and swing (s) measured: a longer one is a pause or a missed stance.
MAX_STRIDE_TIME = 4.0
MAX_STANCE_TIME = 3.0
#: Longest stretch (s) kept while waiting for the first stance to end (the memory of the scan is bounded).
MAX_PENDING = 10.0
#: Sampling rates of common IMUs (Hz): the likely rate is rounded to one of them (:data:`SNAP`).
COMMON_RATES = (10.0, 12.5, 20.0, 25.0, 30.0, 40.0, 50.0, 60.0, 64.0, 100.0, 102.4, 104.0, 120.0, 125.0, 128.0,
                200.0, 204.8, 208.0, 240.0, 250.0, 256.0, 400.0, 416.0, 500.0, 512.0, 800.0, 833.0, 1000.0, 1024.0,
                1600.0, 2000.0)
#: Largest relative distance from the rate ``declared / F`` to the common rate it is rounded to.
SNAP = 0.03
#: Gyroscope unit: a moving sample has |‖f‖ − g| above MOTION_ACC (m/s²); after MOTION_TIME (s) of them, fewer
#: than TURN_FRACTION above TURN_RATE (rad/s) is a foot that does not turn.
MOTION_ACC = 3.0
MOTION_TIME = 2.0
TURN_RATE = 1.0
TURN_FRACTION = 0.01
#: A recording that ends before MOTION_TIME s of motion (a few strides: a simulated walk moves 0.34 s of each
#: stride) is judged at its end if it moved at least SHORT_MOTION_TIME (s, about one stride): a gyroscope that never
#: exceeds SHORT_TURN_RATE (rad/s) in the whole recording is then named. SHORT_TURN_RATE read as deg/s is 20 rad/s,
#: the fastest a foot turns; a foot's peak of 3–11 rad/s (the data folder's walks and runs) declared as deg/s reads
#: 0.05–0.19. (A crawl of the data folder moves 0.31 s in its first 12 s and peaks at 0.97 rad/s: not named.)
SHORT_MOTION_TIME = 0.3
SHORT_TURN_RATE = 20.0 * math.pi / 180.0
DEG = math.pi / 180.0
#: A gyroscope that reads too little is named as rad/s declared as deg/s only when its peak read as rad/s would be a
#: moving foot's (at least UNIT_PEAK_MIN rad/s: the data folder's crawl, its slowest-turning foot, peaks at 1.6 rad/s
#: over its first 2 s of motion): a dead or disconnected gyroscope reads too little in any unit (zeros; a MEMS
#: gyroscope's noise alone, about 0.1 °/s RMS at 100 Hz, peaks near 0.006 rad/s, 0.35 read as rad/s).
UNIT_PEAK_MIN = 0.5

#: How the message names swings anchored at a running foot's quietest instants (the foot is never still).
_RUNNING = " (anchored at its quietest instants by a running foot's bounds: it is never quite still)"
_WORDS = {2.0: "twice", 1.5: "1.5 times", 1.25: "1.25 times", 1.2: "1.2 times", 1.0 / 1.2: "five sixths of",
          0.8: "0.8 times", 2.0 / 3.0: "two thirds of", 0.5: "half"}


class RateEvidence(Protocol):
    """The gyroscope–accelerometer evidence of the rate (:class:`footzoo.filters.consistency.ConsistencyScan`)."""

    rate: float  # the declared rate (Hz)

    def ready(self, until: int) -> bool: ...

    def time_scales(self, until: int | None = None) -> dict[str, Any] | None: ...


def stride_summary(strides: np.ndarray) -> dict[str, float]:
    """Medians of the strides (rows of :attr:`GaitScan.strides`), as declared: cadence, length, speed, ...

    Returns
    -------
    dict
        ``strides``, ``cadence_steps_min``, ``stride_length_m``, ``speed_m_s``, ``clearance_m``,
        ``swing_time_s`` (the detector's swing), ``rotation_rad`` (∫|ω| dt over the swing),
        ``rolling_m_rad`` (length per radian of rotation) and ``peak_rate_rad_s``.
    """
    T, L, rot = strides[:, 0], strides[:, 1], strides[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):  # the medians of every column at once
        m = np.median(np.column_stack([strides[:, :6], L / T, L / np.maximum(rot, 1e-9)]), axis=0)
        cadence = float(120.0 / m[0])
    m = m.tolist()
    return {"strides": int(len(strides)), "cadence_steps_min": cadence, "stride_length_m": m[1],
            "speed_m_s": m[6], "clearance_m": m[2], "swing_time_s": m[5], "rotation_rad": m[3],
            "rolling_m_rad": m[7], "peak_rate_rad_s": m[4]}


def _outside(x: float, lo: float, hi: float) -> float:
    """Squared distance of ``x`` outside ``[lo, hi]`` in units of :data:`TOLERANCE`, capped at :data:`CAP`."""
    if not (x > 0 and math.isfinite(x)):
        return CAP
    d = max(0.0, math.log(lo / x), math.log(x / hi)) / TOLERANCE
    return min(CAP, d * d)


def gait_costs(gait: dict[str, float], factor: float) -> dict[str, float]:
    """The cost of each quantity of the strides ``gait`` (:func:`stride_summary`) with the factor ``factor`` undone."""
    f = factor
    cadence, speed = gait["cadence_steps_min"] / f, gait["speed_m_s"] * f
    return {"cadence": _outside(cadence, *CADENCE_RANGE),
            "stride_length": _outside(gait["stride_length_m"] * f * f, *STRIDE_LENGTH_RANGE),
            "speed": _outside(speed, *SPEED_RANGE),
            "clearance": _outside(gait["clearance_m"] * f * f, *CLEARANCE_RANGE),
            "cadence_for_speed": _outside(cadence, 1.0, CADENCE_AT_REST + CADENCE_PER_SPEED * max(speed, 0.0)),
            "rolling": _outside(gait["rolling_m_rad"] * f, *ROLLING_RANGE)}


#: log of the multiples of a time scale whose lowest residual counts (:data:`SCALE_WINDOW`), the scale itself last.
_WINDOW = np.append(np.linspace(math.log(SCALE_WINDOW[0]), math.log(SCALE_WINDOW[1]), 9), 0.0)
#: The hypotheses in the order :func:`judge_rate` scores them: the declared rate (1), then :data:`FACTORS`.
_HYPOTHESES = (1.0, *FACTORS)
_LOG_HYPOTHESES = np.array([math.log(f) for f in _HYPOTHESES])


def consistency_costs(evidence: dict[str, Any] | None) -> dict[float, float]:
    """Cost of each hypothesis (1, then :data:`FACTORS`) by the gyroscope–accelerometer residuals (0 without evidence).

    The lowest residual between the factor times the ends of :data:`SCALE_WINDOW` counts: on real
    recordings the residual is lowest within 0.92–1.09× the right time scale (1.0× it in the median
    over the 42 real recordings as recorded, 1.09× over IPOL's 36), on a simulation at it.
    """
    if evidence is None:
        return dict.fromkeys(_HYPOTHESES, 0.0)
    scales, residual = np.log(evidence["scales"]), np.log(np.maximum(evidence["residual"], 1e-12))
    order = np.argsort(scales)
    at = np.interp(_LOG_HYPOTHESES[:, None] + _WINDOW, scales[order], residual[order]).min(axis=1)
    cost = ((at - float(residual.min())) / CONSISTENCY_TOLERANCE) ** 2
    return dict(zip(_HYPOTHESES, cost.tolist(), strict=True))


def likely_rate(declared: float, factor: float) -> float:
    """The rate (Hz) a recording declared at ``declared`` Hz has if the declaration is ``factor`` times too high,
    rounded to the nearest common rate of :data:`COMMON_RATES` within :data:`SNAP`."""
    rate = declared / factor
    near = min(COMMON_RATES, key=lambda r: abs(math.log(r / rate)))
    return near if abs(math.log(near / rate)) <= math.log(1.0 + SNAP) else float(f"{rate:.4g}")


def judge_rate(gait: dict[str, float] | None, evidence: dict[str, Any] | None) -> dict[str, Any]:
    """Score the declared rate and each hypothesis of :data:`FACTORS`; the verdict (module docstring).

    Parameters
    ----------
    gait : dict or None
        :func:`stride_summary` of at least :data:`MIN_STRIDES` strides, or None.
    evidence : dict or None
        :meth:`~footzoo.filters.consistency.ConsistencyScan.time_scales` of at least :data:`MIN_SWINGS` swings, or None.

    Returns
    -------
    dict
        ``costs`` ({factor: cost}, 1 the declared rate), ``gait_informative``, ``factor`` (the named
        factor of :data:`FACTORS`, or None: named when the declared rate costs :data:`MARGIN` more
        than the best and the gyroscope–accelerometer residuals prefer that one by :data:`SUPPORT`;
        the factor on its side of 1 whose residual is lowest), ``alternative`` (a second one almost
        as likely, or None).
    """
    gaits = {f: sum(gait_costs(gait, f).values()) for f in _HYPOTHESES} if gait is not None else None
    informative = gaits is not None and min(gaits.values()) <= GAIT_INFORMATIVE
    fit = consistency_costs(evidence)
    costs = {f: fit[f] + (gaits[f] if informative else 0.0) + (0.0 if f == 1.0 else PRIOR) for f in _HYPOTHESES}
    best, out = min(FACTORS, key=costs.get), {"costs": costs, "gait_informative": informative, "factor": None,
                                              "alternative": None}
    if costs[1.0] - costs[best] < MARGIN or evidence is None:
        return out  # the gait alone never names a rate: a detector that splits strides mimics one read too fast
    if fit[1.0] - fit[best] < SUPPORT:
        return out  # the gyroscope and the accelerometer do not prefer it
    # which factor: the residuals, which depend on it directly (the gait's ranges tell that the rate is wrong)
    order = sorted((f for f in FACTORS if (f > 1.0) == (best > 1.0)), key=lambda f: (fit[f], costs[f]))
    out["factor"] = order[0]
    if len(order) > 1 and fit[order[1]] - fit[order[0]] < AMBIGUOUS:
        out["alternative"] = order[1]
    return out


@dataclasses.dataclass
class Motion:
    """What :class:`GaitScan` has seen of the motion before it decides the gyroscope's unit."""

    seconds: float = 0.0  #: moving time (s): |‖f‖ − g| above MOTION_ACC
    samples: int = 0  #: moving samples
    turning: int = 0  #: of them, turning faster than TURN_RATE
    peak_moving: float = 0.0  #: largest |ω| of the moving samples (rad/s)
    peak_all: float = 0.0  #: largest |ω| of all samples (rad/s)


class GaitScan:
    """The strides of a run and their plausibility, fed its final estimates chunk by chunk (module docstring).

    Parameters
    ----------
    name : str
        The recording's name, for the warnings.
    gravity : float
        g (m/s²).
    evidence : RateEvidence, optional
        The gyroscope–accelerometer scan of the same samples (:meth:`use_evidence`).
    """

    def __init__(self, name: str = "recording", gravity: float = GRAVITY, evidence: RateEvidence | None = None):
        self.name, self.gravity, self.evidence = name, gravity, evidence
        self.report: dict[str, Any] = {}
        # per stride: T, L, h, rot, peak, swing, last sample, samples spanned (the first ``_count`` rows)
        self._table = np.empty((MAX_STRIDES, 8))
        self._count = 0
        self._buf: dict[str, np.ndarray] | None = None
        self._pending: list[int] | None = list(CHECKPOINTS)  # None once judged at the end
        self._motion = Motion()  # until MOTION_TIME s of motion are seen (then the gyroscope's unit is decided)
        self._unit_decided = False
        self._t_last: float | None = None
        self._k_last = 0  # the last sample seen (where a short recording's gyroscope unit is decided)
        self._cut: int | None = None  # the first sample of a sensor dropout: the rate is judged before it

    def exclude_from(self, sample: int) -> None:
        """A sensor dropped out from ``sample`` on (:func:`footzoo.core.sanity.find_frozen`): its data say nothing
        of the rate, so the rate is judged on the strides and swings before it only."""
        self._cut = sample if self._cut is None else min(self._cut, sample)

    @property
    def strides(self) -> np.ndarray:
        """(n, 6): per stride T (s), L (m), h (m), θ (rad), peak |ω| (rad/s), the detector's swing (s)."""
        return self._rows[:, :6].copy()

    @property
    def _rows(self) -> np.ndarray:
        """The strides measured so far (n, 8): a read-only view of the table."""
        view = self._table[:self._count]
        view.flags.writeable = False
        return view

    def push(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
             pos: np.ndarray) -> None:
        """The next final estimates: sample indices ``k``, time (s), signals (FRD, SI), stance, position (m, NED)."""
        # a long chunk (a batch run's whole recording) in blocks, as a stream would feed it, until the gyroscope's
        # unit is decided and every stride the scan judges is measured: the rest of the data changes nothing, and
        # the scan's cost is bounded whatever the recording's length
        for lo in range(0, len(t), BLOCK):
            if self._unit_decided and self._count >= MAX_STRIDES:
                return
            hi = lo + BLOCK
            self._push(np.asarray(k[lo:hi]), t[lo:hi], acc[lo:hi], gyr[lo:hi], stance[lo:hi], pos[lo:hi])

    def _push(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
              pos: np.ndarray) -> None:
        """One block of :meth:`push`: the gyroscope's unit until decided, then the strides and the rate's verdict."""
        w = row_norms(gyr)
        if not self._unit_decided:
            self._gyro_unit(k, t, acc, w)
        if self._count >= MAX_STRIDES:
            return
        new = {"k": k, "t": np.asarray(t, dtype=float), "w": w, "stance": np.asarray(stance, dtype=bool),
               "pos": np.asarray(pos, dtype=float)}
        self._buf = new if self._buf is None else {n: np.concatenate([self._buf[n], v]) for n, v in new.items()}
        self._strides()
        self._decide(final=False)

    def use_evidence(self, evidence: RateEvidence) -> None:
        """Weigh the gyroscope–accelerometer evidence of the rate (a ConsistencyScan fed the same samples)."""
        self.evidence = evidence
        self._decide(final=False)

    def finish(self) -> dict[str, Any]:
        """End of the data: judge what is still pending, then every stride measured; the finding (empty: none)."""
        if not self._unit_decided:
            self._short_gyro_unit()
        if self._pending is not None:
            self._decide(final=True)
            self._pending = None  # judged once
        return self.report

    # ------------------------------------------------------------------ strides
    def _strides(self) -> None:
        """Measure every stride whose two stances have ended; keep the samples from the last ended stance on
        (vectorised over the strides of the chunk)."""
        b = self._buf
        t, w, pos, k = b["t"], b["w"], b["pos"], b["k"]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], b["stance"].astype(np.int8), [0]])))
        starts, ends = edges[::2], edges[1::2]
        closed = ends < len(t)  # a stance still going on at the chunk's end has no middle yet
        starts, ends = starts[closed], ends[closed]
        if len(starts) >= 2:
            a0, b0, a1, b1 = starts[:-1], ends[:-1], starts[1:], ends[1:]
            m0, m1 = (a0 + b0 - 1) // 2, (a1 + b1 - 1) // 2
            T, stance = t[m1] - t[m0], t[b0 - 1] - t[a0]
            ok = np.flatnonzero((T <= MAX_STRIDE_TIME) & (stance <= MAX_STANCE_TIME))  # else a pause, a missed stance
            ok = ok[:MAX_STRIDES - self._count]
            if len(ok):
                a0, b0, a1, m0, m1, T = a0[ok], b0[ok], a1[ok], m0[ok], m1[ok], T[ok]
                # the swing of each stride: samples b0 - 1 .. a1 (the last stance sample to the first of the next)
                swing = np.column_stack([b0 - 1, a1 + 1]).ravel()  # a1 + 1 <= b1 < len(t): closed stances
                turned = np.concatenate([[0.0], np.cumsum(w[:-1] * np.diff(t))])  # ∫|ω| dt from the buffer's start
                rows = np.column_stack([
                    T, np.hypot(*(pos[m1, :2] - pos[m0, :2]).T),
                    pos[m0, 2] - np.minimum.reduceat(pos[:, 2], swing)[::2], turned[a1] - turned[b0 - 1],
                    np.maximum.reduceat(w, swing)[::2], t[a1] - t[b0 - 1], k[m1], k[m1] - k[m0]])
                self._table[self._count:self._count + len(rows)] = rows
                self._count += len(rows)
        if len(starts) and t[-1] - t[(starts[-1] + ends[-1] - 1) // 2] <= MAX_STRIDE_TIME:
            keep = int(starts[-1])  # the next stride starts at the middle of the last stance that ended
        else:  # no stride can end in what follows (or no stance has ended yet): keep the stance going on, if any
            moving = np.flatnonzero(~b["stance"])
            keep = int(moving[-1]) + 1 if len(moving) else 0
            if not len(starts) and t[-1] - t[0] <= MAX_PENDING:
                keep = 0  # the first stance is still to end
            keep = min(keep, len(t) - 1)
        self._buf = {n: v[keep:] for n, v in b.items()}

    # ------------------------------------------------------------------ gyroscope unit
    def _gyro_unit(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, w: np.ndarray) -> None:
        """Count the moving samples and how many of them turn; decide once MOTION_TIME s of motion are seen."""
        dt = np.diff(t, prepend=t[0] if self._t_last is None else self._t_last)
        self._t_last, self._k_last = float(t[-1]), int(k[-1])
        moving = np.abs(row_norms(acc) - self.gravity) > MOTION_ACC
        if not moving.any():
            self._motion.peak_all = max(self._motion.peak_all, float(np.max(w)))
            return
        time = self._motion.seconds + np.cumsum(np.where(moving, dt, 0.0))
        reached = np.flatnonzero(time >= MOTION_TIME)
        upto = int(reached[0]) + 1 if len(reached) else len(t)
        count = self._motion.samples + int(np.count_nonzero(moving[:upto]))
        turning = self._motion.turning + int(np.count_nonzero(moving[:upto] & (w[:upto] > TURN_RATE)))
        self._motion = Motion(float(time[upto - 1]), count, turning,
                              max(self._motion.peak_moving, float(np.max(w[:upto][moving[:upto]], initial=0.0))),
                              max(self._motion.peak_all, float(np.max(w[:upto]))))
        if not len(reached):
            return
        self._unit_decided = True  # on the first MOTION_TIME s of motion
        if turning >= TURN_FRACTION * count:
            return
        self._name_gyro_unit(int(k[upto - 1]), self._motion.peak_moving if turning == count else self._motion.peak_all,
                             "")

    def _short_gyro_unit(self) -> None:
        """At the end of a recording too short for MOTION_TIME s of motion: named if it moved SHORT_MOTION_TIME s and
        the gyroscope never exceeded TURN_RATE anywhere (a stricter test for less evidence)."""
        self._unit_decided = True
        m = self._motion
        if m.seconds >= SHORT_MOTION_TIME and m.peak_all < SHORT_TURN_RATE:
            self._name_gyro_unit(self._k_last, m.peak_all, f" (in the whole recording, which moves for less than "
                                                           f"{MOTION_TIME:g} s: it never exceeds "
                                                           f"{SHORT_TURN_RATE:.2f} rad/s)")

    def _name_gyro_unit(self, sample: int, peak: float, short: str) -> None:
        """Keep the finding of a gyroscope in rad/s declared as deg/s and warn with its fix."""
        m = self._motion
        count, turning = m.samples, m.turning
        unit = peak / DEG >= UNIT_PEAK_MIN
        self.report["gyro_unit"] = {"sample": sample, "moving_s": m.seconds,
                                    "moving_samples": count, "turning_samples": turning, "peak_rate_rad_s": peak,
                                    "peak_if_rad_s": peak / DEG, "unit_explains": unit}
        if unit:
            cause = (f"The gyroscope's values look like rad/s declared as deg/s (read as rad/s they peak at "
                     f"{peak / DEG:.3g} rad/s): declare gyr_unit: rad/s (footzoo.load(path, gyr_unit='rad/s'), on the "
                     "command line --option gyr_unit=rad/s, a sidecar's gyr: {..., unit: rad/s}), or check that the "
                     "gyroscope works")
        else:
            cause = (f"No unit explains it (even read as rad/s instead of deg/s they would peak at {peak / DEG:.3g} "
                     "rad/s): the gyroscope does not measure the foot's rotation. Check that it works and that the "
                     "columns read as the gyroscope are its own")
        warnings.warn(
            f"{self.name}: the accelerometer shows {m.seconds:.1f} s of motion (|‖f‖ − g| above "
            f"{MOTION_ACC:g} m/s², {count} samples) but the gyroscope turns faster than {TURN_RATE:g} rad/s in "
            f"only {turning} of them, at most {peak:.3g} rad/s{short}: a moving foot turns at 5–20 rad/s. {cause}. "
            "Details in diagnostics['sensor']['plausibility']",
            SensorWarning, stacklevel=user_stacklevel(),
        )

    # ------------------------------------------------------------------ the rate
    def _decide(self, final: bool) -> None:
        """Judge the rate at each checkpoint whose evidence is complete (all of them at the end, then every stride)."""
        if self._pending is None or "rate" in self.report or "gyro_unit" in self.report or not (self._pending or final):
            return
        rows = self._rows
        if self._cut is not None:
            rows = rows[rows[:, 6] < self._cut]
        while self._pending and len(rows) >= self._pending[0]:
            m = self._pending[0]
            until = int(rows[m - 1, 6])
            if not final and self.evidence is not None and not self.evidence.ready(until):
                return  # the gyroscope-accelerometer scan has not measured these strides' swings yet
            if not final and self.evidence is None:
                return  # batch: the evidence comes with finish()
            self._pending.pop(0)
            if self._judge(rows[:m], until):
                return
        if final:  # every stride, or the gyroscope-accelerometer evidence alone when the detector found too few
            self._judge(rows, int(rows[-1, 6]) if len(rows) >= MIN_STRIDES else None)

    def _judge(self, rows: np.ndarray, until: int | None) -> bool:
        """Judge the rate on the strides ``rows`` and the swings ending by sample ``until`` (None: every stride and
        swing; the strides are then too few to count); warn if a rate is named."""
        gait = stride_summary(rows[:, :6]) if until is not None else None
        last = until if until is not None or self._cut is None else self._cut - 1
        evidence = self.evidence.time_scales(last) if self.evidence is not None else None
        if evidence is not None and evidence["swings"] < MIN_SWINGS:
            evidence = None
        quiet = gait is None and evidence is not None and len(evidence.get("strides", ())) >= MIN_STRIDES
        if quiet:  # too few strides from the detector: the strides between the foot's quiet instants
            gait = {**stride_summary(evidence["strides"]), "between": "quiet instants"}
        if gait is None and evidence is None:
            return False
        verdict = judge_rate(gait, evidence)
        factor = verdict["factor"]
        if factor is None:
            return False
        # the declared rate: the gyroscope-accelerometer scan's (the run's), else samples per second over the strides
        declared = float(getattr(self.evidence, "rate", 0.0)) or float(np.sum(rows[:, 7]) / np.sum(rows[:, 0]))
        likely = likely_rate(declared, factor)
        factor = declared / likely  # the factor to the rounded rate
        finding = {"cause": f"the rate is declared {factor:.3g} times the real one", "rate_factor": factor,
                   "declared_rate": declared, "likely_rate": likely, "strides": gait, "until_sample": until,
                   "costs": {f"{f:.3g}": c for f, c in verdict["costs"].items()},
                   "gait_informative": verdict["gait_informative"]}
        if verdict["alternative"] is not None:
            finding["alternative_rate"] = likely_rate(declared, verdict["alternative"])
        if evidence is not None:
            finding["time_scale_residual"] = {f"{s:.3g}": float(r) for s, r in zip(evidence["scales"],
                                                                                   evidence["residual"], strict=True)}
        self.report["rate"] = finding
        warnings.warn(self._message(finding, evidence, verdict), SensorWarning, stacklevel=user_stacklevel())
        return True

    def _message(self, finding: dict[str, Any], evidence: dict[str, Any] | None, verdict: dict[str, Any]) -> str:
        f, g = finding["rate_factor"], finding["strides"] or {}
        likely, declared = finding["likely_rate"], finding["declared_rate"]
        words = next((w for k, w in _WORDS.items() if abs(math.log(f / k)) < 0.02), f"{f:.3g} times")
        kind = "run" if g and g["cadence_steps_min"] / f > 140.0 and g["speed_m_s"] * f > 2.0 else "walk"
        parts = []
        if g and verdict["gait_informative"]:
            between = (f" (between the foot's quiet instants: the detector found fewer than {MIN_STRIDES} strides)"
                       if "between" in g else "")
            parts.append(
                f"strides{between} of {g['stride_length_m']:.2f} m at {g['cadence_steps_min']:.0f} steps/min, "
                f"{g['clearance_m'] * 1e3:.0f} mm of foot clearance and {g['rolling_m_rad']:.2f} m per radian the "
                f"foot turns are what a {kind} of {g['stride_length_m'] * f * f:.2f} m strides at "
                f"{g['cadence_steps_min'] / f:.0f} steps/min gives when read at {words} its rate")
        if evidence is not None:
            residual = dict(zip(evidence["scales"].tolist(), evidence["residual"].tolist(), strict=True))
            at = float(np.exp(np.interp(math.log(f), np.log(sorted(residual)),
                                        np.log([residual[s] for s in sorted(residual)]))))
            parts.append(
                f"the gyroscope and the accelerometer agree best with the time scaled by about {f:.3g}: integrated "
                f"over {evidence['swings']} swings{_RUNNING if evidence.get('anchors') == 'running' else ''}, the "
                f"gyroscope's attitude leaves a speed of {residual[1.0]:.2f} g "
                f"× the swing's duration where the foot stops as declared, and {at:.2f} with the time × {f:.3g}")
        also = (f" (or {finding['alternative_rate']:g} Hz)" if "alternative_rate" in finding else "")
        return (
            f"{self.name}: {'; '.join(parts)}. The recording is probably sampled at {likely:g} Hz{also}, not "
            f"{declared:.4g} Hz: every duration is off by {f:.3g}× and every distance by about {f * f:.3g}×. Declare "
            f"the real rate (a sidecar's time: {{rate: {likely:g}}}; --option rate={likely:g} or "
            f"footzoo.load(path, rate={likely:g}) where the reader has a rate option), or, with a time column, fix "
            f"its unit or scale (t × {f:.3g}); the run's other findings (swings without a stance, drift, the "
            "mounting) may follow from it. Details in diagnostics['sensor']['plausibility']")
