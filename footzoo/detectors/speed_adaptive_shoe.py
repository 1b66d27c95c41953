"""SHOE with a threshold that follows the foot's speed in each stride (motion-adaptive thresholding)."""

from __future__ import annotations

import math

import numpy as np

from ..core.context import RunContext
from ..filters.strapdown import quat_product, rotate, rotvec_quat
from ..kernels.jit import njit
from ..kernels.views import read_only
from ..plugins.base import Real, run_context
from ..plugins.incremental import Chunk, Latency, OverlapSave, run_starts
from ..plugins.registry import register
from .adaptive_shoe import AdaptiveSHOE, adaptive_threshold_kernel
from .runs import close_short_swings


@njit
def swing_speeds(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
                 lead: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The foot's speed in every swing, by a zero-velocity-reset strapdown.

    For each run of ``stance == False`` (a swing, samples ``[s, e)``): the attitude at
    ``s`` is levelled on the mean specific force of the stance samples in the last
    ``lead`` seconds before it (yaw zero: a speed does not depend on it), the rate is
    integrated (``q ← q ⊗ exp(ω Δt)``), the specific force rotated to NED (with the attitude at
    the sample's end, not mid-interval as :mod:`footzoo.filters.strapdown` does: for a speed
    feature the half-sample lag is negligible and absorbed by the dedrift) and gravity
    (the mean ‖f‖ of the same stance samples, so an accelerometer scale error cancels)
    removed, the velocity integrated from zero and linearly dedrifted to zero at the
    next stance sample ``e`` (Yun 2012's correction). A swing that starts or ends the
    recording has no stance on that side and gets no speed.

    Parameters
    ----------
    t : (N,) s; acc : (N, 3) m/s²; gyr : (N, 3) rad/s; stance : (N,) bool
        Body-frame signals and a provisional gait phase.
    lead : float
        Stance time used for the levelling (s).

    Returns
    -------
    starts, ends : (M,) int
        Sample ranges ``[s, e)`` of the swings.
    peaks : (M,) float
        Peak 3-D speed of each swing (m/s), NaN where it cannot be estimated.
    speed : (N,) float
        The dedrifted speed at every swing sample (m/s); zero in stance and in the
        swings without a speed.
    """
    n = t.shape[0]
    m = 0
    longest = run = 0
    for k in range(n):
        if not stance[k] and (k == 0 or stance[k - 1]):
            m += 1
        run = 0 if stance[k] else run + 1
        longest = max(longest, run)
    starts = np.empty(m, dtype=np.int64)
    ends = np.empty(m, dtype=np.int64)
    peaks = np.full(m, np.nan)
    speed = np.zeros(n)
    vel = np.empty((longest + 1, 3))  # one swing's velocity at a time
    j = 0
    k = 0
    while k < n:
        if stance[k]:
            k += 1
            continue
        s = k
        while k < n and not stance[k]:
            k += 1
        e = k
        starts[j], ends[j] = s, e
        if s > 0 and e < n:
            fx = fy = fz = 0.0
            c = 0
            i = s - 1
            while i >= 0 and stance[i] and t[s - 1] - t[i] <= lead:
                fx += acc[i, 0]
                fy += acc[i, 1]
                fz += acc[i, 2]
                c += 1
                i -= 1
            fx, fy, fz = fx / c, fy / c, fz / c
            g = math.sqrt(fx * fx + fy * fy + fz * fz)
            # levelled attitude: the shortest rotation taking u = −f/g (down, at rest) to NED's (0, 0, 1)
            ux, uy, uz = -fx / g, -fy / g, -fz / g
            qw, qx, qy, qz = 1.0 + uz, uy, -ux, 0.0
            nq = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
            if nq < 1e-9:  # u points straight up (sensor upside down): half a turn about x
                qw, qx, qy, qz = 0.0, 1.0, 0.0, 0.0
            else:
                qw, qx, qy, qz = qw / nq, qx / nq, qy / nq, qz / nq
            vx = vy = vz = 0.0
            for i in range(s, e + 1):
                dt = t[i] - t[i - 1]
                dw, dx, dy, dz = rotvec_quat(gyr[i, 0] * dt, gyr[i, 1] * dt, gyr[i, 2] * dt)
                qw, qx, qy, qz = quat_product(qw, qx, qy, qz, dw, dx, dy, dz)
                an0, an1, an2 = rotate(qw, qx, qy, qz, acc[i, 0], acc[i, 1], acc[i, 2])
                vx += an0 * dt
                vy += an1 * dt
                vz += (an2 + g) * dt
                vel[i - s, 0], vel[i - s, 1], vel[i - s, 2] = vx, vy, vz
            span = t[e] - t[s - 1]
            peak = 0.0
            for i in range(s, e):
                r = (t[i] - t[s - 1]) / span
                ex, ey, ez = vel[i - s, 0] - r * vx, vel[i - s, 1] - r * vy, vel[i - s, 2] - r * vz
                speed[i] = math.sqrt(ex * ex + ey * ey + ez * ez)
                peak = max(peak, speed[i])
            peaks[j] = peak
        j += 1
    return starts, ends, peaks, speed


def speed_per_sample(t: np.ndarray, starts: np.ndarray, ends: np.ndarray, peaks: np.ndarray,
                     reach: float) -> np.ndarray:
    """The speed each sample's threshold follows (m/s).

    The largest peak speed of the swings that sample ``k`` lies in or within ``reach``
    seconds of (zero where there is none: a still period). A stance thus takes the speed
    of the swings that bound it, and a brief provisional "swing" inside a stance (the
    heel rocking after a strike) does not lower it. A swing without a speed (at an end
    of the recording) takes its nearest neighbour's.
    """
    out = np.zeros(len(t))
    known = np.flatnonzero(np.isfinite(peaks))
    if known.size == 0:
        return out
    i = np.arange(len(peaks))
    pos = np.clip(np.searchsorted(known, i), 0, known.size - 1)
    before, after = known[np.maximum(pos - 1, 0)], known[pos]
    nearest = np.where(np.abs(before - i) < np.abs(after - i), before, after)
    p = np.where(np.isfinite(peaks), peaks, peaks[nearest])
    lo = np.searchsorted(t, t[starts] - reach, side="left")
    hi = np.searchsorted(t, t[np.maximum(ends - 1, 0)] + reach, side="right")
    _paint(out, lo, hi, p, np.argsort(p, kind="stable"))  # ascending: the larger peak wins where reaches overlap
    return out


@njit
def _paint(out: np.ndarray, lo: np.ndarray, hi: np.ndarray, value: np.ndarray, order: np.ndarray) -> None:
    """``out[lo[j]:hi[j]] = value[j]`` for j in ``order``."""
    for j in order:
        out[lo[j]:hi[j]] = value[j]


@njit
def close_still_gaps(stance: np.ndarray, min_samples: int, speed: np.ndarray, still_speed: float) -> np.ndarray:
    """Close the swings shorter than ``min_samples`` in which the foot stayed slower than ``still_speed`` (m/s).

    Only swings with a stance on both sides (as :func:`~footzoo.detectors.runs.close_short_swings`);
    a short gap where the foot moved (the push-off before a pause of the test) is a real swing and
    stays open.
    """
    n = stance.shape[0]
    out = stance.copy()
    k = 0
    while k < n:
        if stance[k]:
            k += 1
            continue
        a = k
        fastest = 0.0
        while k < n and not stance[k]:
            fastest = max(fastest, speed[k])
            k += 1
        if a > 0 and k < n and k - a < min_samples and fastest <= still_speed:
            out[a:k] = True
    return out


@njit
def drop_pauses(stance: np.ndarray, min_samples: int) -> np.ndarray:
    """Of two stance runs less than ``min_samples`` apart, remove the shorter if it is shorter than that.

    What is left of such a pair after :func:`close_still_gaps` is a foot that moved in the
    gap: a stance and a pause in the air (the end of the push-off, or just before the
    landing), not two stances, which are a swing apart. The runs are judged as they come from
    :func:`close_still_gaps` (a removed run does not merge its neighbours' gaps).
    """
    n = stance.shape[0]
    out = stance.copy()
    starts = np.empty(n + 1, dtype=np.int64)
    r = 0
    for k in range(n):
        if k == 0 or stance[k] != stance[k - 1]:
            starts[r] = k
            r += 1
    starts[r] = n
    for i in range(1, r - 1):  # a swing run with a stance run on each side
        if stance[starts[i]] or starts[i + 1] - starts[i] >= min_samples:
            continue
        la = starts[i] - starts[i - 1]
        lb = starts[i + 2] - starts[i + 1]
        j, length = (i - 1, la) if la <= lb else (i + 1, lb)
        if length < min_samples:
            out[starts[j]:starts[j] + length] = False
    return out


@register
class SpeedAdaptiveSHOE(AdaptiveSHOE):
    """SHOE whose threshold follows the foot's speed in each stride.

    Motion-adaptive thresholding after Wagstaff, Peretroukhin & Kelly, "Improving
    foot-mounted inertial navigation through real-time motion classification",
    IPIN 2017: the zero-velocity threshold that works best grows with the speed of
    the motion (walking, running, ...). Wagstaff et al. classify the motion and switch
    between per-class thresholds; footzoo's form is continuous and needs no classifier:

    1. a provisional gait phase from Wahlström et al.'s 2019 adaptive SHOE (see
       ``adaptive_shoe``; parameters ``threshold``, ``time_constant``, ``min_swing``);
    2. the peak speed of every provisional swing by a zero-velocity-reset strapdown
       (:func:`swing_speeds`; yaw-free, levelled on the stance before it);
    3. the final test ``T_k < γ_k`` with ``γ_k = min(γ_0 exp(v_k / v_s), γ_max)``, where
       ``v_k`` is the largest peak speed of the swings within ``REACH`` (0.5 s) of
       sample k (:func:`speed_per_sample`), for samples the strapdown does not see moving
       faster than ``still_speed`` (a dip of the test in mid-swing is no stance); swings shorter than ``min_swing`` are
       closed where the foot stayed slower than ``still_speed`` (:func:`close_still_gaps`),
       and of two stances closer than ``min_swing`` the shorter, if shorter than that, is
       a pause in the air (:func:`drop_pauses`).

    Why: on PyShoe's 36 VICON trials the SHOE threshold that reproduces PyShoe's
    per-trial optimal labels grows about exponentially with the foot's speed, from
    1e3–1e4 for slow motion to 3e5–2e6 for running: a running stance is short and
    rolling and needs the whole ground contact, while in a walk a high threshold eats
    into the swing. Defaults: the setting ``benchmarks/select_recommended.py`` selects
    on those trials (scored per motion class, never per trial); leaving one motion class
    out selects settings from the same neighbourhood (γ_0 2e3–3e3, v_s 0.8–1 m/s; see
    ``benchmarks/recommended_selection.md``). On the simulator it finds every stride at
    50–1000 Hz from 0.3 to 4 m/s, and ignores the simulated foot's pauses in the air.

    The detector looks at the next swing, so it is not causal (offline only).

    Parameters
    ----------
    threshold : float
        γ_0, the threshold at zero speed (dimensionless, as for ``shoe``).
    window, sigma_a, sigma_g : float
        As for ``shoe`` (s, m/s², rad/s).
    time_constant : float
        τ of the provisional pass (s).
    max_threshold : float
        γ_max (dimensionless).
    speed_scale : float
        v_s (m/s): the threshold grows by e per v_s of swing speed.
    still_speed : float
        Fastest a stance sample can move by the provisional swing's strapdown (m/s); a short
        swing is closed only if the foot stayed slower. 1 m/s: 0.5 m/s rejected real running
        stances, where the dedrift of a swing with missed stances leaves that much error.
    min_swing : float
        Shortest swing (s), as for ``adaptive_shoe``.
    provisional_min_swing : float or None
        Shortest swing of the provisional pass (s); None: ``min_swing``. Closing a short
        provisional swing sets the strapdown speed in it to zero, so the speed test can no
        longer see that the foot moved there: a foot that stops in the air and moves again
        before landing (stairs) was taken as standing from the stop on at 250 Hz and above,
        where the stop spans enough samples to pass the adaptive test. With 0 the speed test
        alone closes the short gaps where the foot stayed slower than ``still_speed``.

    Attributes
    ----------
    statistic_ : (N,) ndarray
        SHOE's T_k.
    speed_ : (N,) ndarray
        v_k (m/s).
    threshold_ : (N,) ndarray
        γ_k.
    stance_, stance_online_ : (N,) bool ndarray
        Stance flag (offline: ``stance_online_`` is the same).
    """

    name = "speed_adaptive_shoe"
    paper = ("Wagstaff, Peretroukhin & Kelly 2017, IPIN (motion-adaptive zero-velocity threshold), "
             "on SHOE (Skog et al. 2010) and Wahlström et al. 2019")
    causal = False
    parameters = {
        "threshold": AdaptiveSHOE.parameters["threshold"].replace(
            doc="γ_0: the threshold at zero swing speed",
            source="footzoo's: benchmarks/select_recommended.py on PyShoe's 36 trials, per motion class"),
        "time_constant": AdaptiveSHOE.parameters["time_constant"].replace(
            doc="τ of the provisional pass", source="footzoo's: benchmarks/select_recommended.py"),
        "max_threshold": AdaptiveSHOE.parameters["max_threshold"].replace(
            source="footzoo's: benchmarks/select_recommended.py"),
        "speed_scale": Real("m/s", "[0.001, 100]", "v_s: the threshold grows by e per v_s of swing speed",
                            source="footzoo's: benchmarks/select_recommended.py"),
        "still_speed": Real("m/s", "[0, 100]", "fastest a stance sample may move by the provisional strapdown",
                            source="footzoo's: 0.5 m/s rejected real running stances (see the docstring)"),
        "provisional_min_swing": Real("s", "[0, 1]", "shortest swing of the provisional pass (null: min_swing)",
                                      optional=True,
                                      source="footzoo's: 0 in recommended (benchmarks/recommended_selection.md)",
                                      why="closing a short provisional swing hides the foot's motion in it from "
                                          "the speed test: at 250 Hz and above a foot that stops in the air "
                                          "before landing was taken as standing from the stop on"),
    }

    #: Stance time used to level the attitude at the start of a swing (s).
    LEVELLING = 0.1
    #: How far before and after a swing its speed sets the threshold (s): about a stance.
    REACH = 0.5

    def __init__(self, threshold: float = 3e3, window: float = 0.025, sigma_a: float = 0.01,
                 sigma_g: float = float(np.radians(0.1)), time_constant: float = 0.2, max_threshold: float = 1e6,
                 speed_scale: float = 1.0, still_speed: float = 1.0, min_swing: float = 0.15,
                 provisional_min_swing: float | None = None):
        super().__init__(threshold, window, sigma_a, sigma_g, time_constant, max_threshold, min_swing)
        self.speed_scale = speed_scale
        self.still_speed = still_speed
        self.provisional_min_swing = provisional_min_swing

    def provisional_gap_samples(self, ctx: RunContext) -> int:
        """``provisional_min_swing`` (default ``min_swing``) in samples at the run's rate."""
        if self.provisional_min_swing is None:
            return self.min_swing_samples(ctx)
        return int(math.floor(self.provisional_min_swing * ctx.rate + 0.5))

    def _speed_test(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, statistic: np.ndarray,
                    provisional: np.ndarray) -> dict[str, np.ndarray]:
        """Steps 2–3 over arrays: the swings' speeds, the speed-dependent test, the closing of gaps and pauses."""
        m = self.min_swing_samples(self.ctx_)
        g_max = max(self.max_threshold, self.threshold)
        starts, ends, peaks, speed = swing_speeds(read_only(t), read_only(acc), read_only(gyr),
                                                   read_only(provisional, np.bool_), self.LEVELLING)
        speed_k = speed_per_sample(t, starts, ends, peaks, self.REACH)
        with np.errstate(over="ignore"):  # a tiny speed_scale overflows exp to inf: the threshold is then g_max
            threshold = np.minimum(self.threshold * np.exp(speed_k / self.speed_scale), g_max)
        # a sample the strapdown sees moving faster than still_speed is no stance, whatever the test says
        candidate = (statistic < threshold) & (speed <= self.still_speed)
        closed = close_still_gaps(candidate, m, speed, self.still_speed)
        return {"stance": drop_pauses(closed, m), "speed": speed_k, "threshold": threshold, "statistic": statistic}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray,
               ctx: RunContext | None = None) -> SpeedAdaptiveSHOE:
        """Provisional adaptive SHOE, swing speeds, then the speed-dependent test."""
        t = np.ascontiguousarray(t, dtype=float)
        acc = np.ascontiguousarray(acc, dtype=float)
        gyr = np.ascontiguousarray(gyr, dtype=float)
        self.begin(run_context(ctx, t))
        self.statistic_ = self._statistic(t, acc, gyr)
        g_max = max(self.max_threshold, self.threshold)
        provisional, _, _ = adaptive_threshold_kernel(t, self.statistic_, self.threshold, self.time_constant, g_max,
                                                      float(t[0]))
        provisional = close_short_swings(provisional, self.provisional_gap_samples(self.ctx_))
        out = self._speed_test(t, acc, gyr, self.statistic_, provisional)
        self.speed_, self.threshold_, self.stance_ = out["speed"], out["threshold"], out["stance"]
        self.stance_online_ = self.stance_.copy()
        return self

    # ------------------------------------------------------------------ live
    def _margins(self, ctx: RunContext) -> tuple[int, int, int]:
        """Samples of REACH, of LEVELLING and of the gap and pause filters' reach (three shortest swings)."""
        return (int(math.ceil(self.REACH * ctx.rate)) + 1, int(math.ceil(self.LEVELLING * ctx.rate)) + 1,
                3 * self.min_swing_samples(ctx) + 2)

    def latency(self, ctx: RunContext) -> Latency:
        """The adaptive pass's latency, then the swings within REACH after a sample must have ended."""
        reach, _, gaps = self._margins(ctx)
        return super().latency(ctx) + Latency(ctx.seconds(reach + gaps), ("the end of the next swing",))

    def begin(self, ctx: RunContext) -> SpeedAdaptiveSHOE:
        """Fresh state: SHOE's window, the adaptive pass, then the speed test over the recent strides."""
        super().begin(ctx)
        reach, lead, gaps = self._margins(self.ctx_)

        def ready(inp: Chunk, start: int) -> int:
            prov = inp["provisional"]
            open_swing = start + (int(run_starts(prov)[-1]) if prov.size and not prov[-1] else prov.size)
            return open_swing - reach - gaps

        def restart(out: Chunk, inp: Chunk, start: int, final: int) -> int:
            # two whole provisional strides of context before the first sample a swing can still reach
            prov = inp["provisional"]
            starts = run_starts(prov)
            stance_starts = start + starts[prov[starts]] if prov.size else np.zeros(0, int)
            before = stance_starts[stance_starts < final - reach - gaps - lead]
            return int(before[-3]) if before.size >= 3 else start

        speed = OverlapSave(self._speed_test, lookahead=ready, restart=restart,
                            wants=("t", "acc", "gyr", "statistic", "provisional"))
        self._stages = [self.window_stage(keep=("t", "acc", "gyr")), self.threshold_stage(keep=("acc", "gyr")),
                        _Renamed(self.gap_stage(keep=("t", "acc", "gyr"),
                                                samples=self.provisional_gap_samples(self.ctx_)),
                                 {"stance": "provisional"}), speed]
        return self


class _Renamed:
    """A stage whose output ``stance`` is the next stage's ``provisional``."""

    def __init__(self, stage: OverlapSave, names: dict[str, str]):
        self.stage, self.names, self.wants = stage, names, stage.wants

    def _rename(self, chunk: Chunk) -> Chunk:
        return {self.names.get(k, k): v for k, v in chunk.items()}

    def step(self, **chunk: np.ndarray) -> Chunk:
        return self._rename(self.stage.step(**chunk))

    def finish(self) -> Chunk:
        return self._rename(self.stage.finish())

    def provisional(self) -> Chunk:
        return self._rename(self.stage.provisional())
