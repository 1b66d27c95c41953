"""Do the gyroscope and the accelerometer describe the same motion? A wrong axis map, and the rate's evidence.

Between two quasi-static instants of a foot (still, ‖f‖ ≈ g: the end of one stance, the start
of the next) the velocity changes by zero. Strapdown integration over the swing from the
attitude the accelerometer gives at its start (tilt; the heading does not matter),

    q ← q ⊗ exp(ω dt / 2),        v ← v + (R(q) f + [0, 0, g]) dt        (NED, FRD),

must therefore end near v = 0. The residual ``|v| / (g T)`` of a swing of duration ``T`` is
the mean tilt error of the integrated attitude in radians, roughly: 0.02–0.11 (median over a
recording's swings) on the real recordings in the data folder (PyShoe walking, running and
stairs, x-io, gaitmap, Köroğlu, IPOL; 0.23 on PyShoe's crawl), 0.004–0.007 on a noisy
simulation. A gyroscope axis of the wrong sign (a left-handed axis map), or time stamps at the
wrong rate (a 100 Hz recording stamped at 50 Hz turns every rotation by twice its angle), turns
the attitude by tens of degrees in every swing: up to 1.6.

Each swing starts at the stillest sample of the last :data:`ANCHOR_WINDOW` s of a quasi-static
run, where the foot is flat on the ground (its tilt is the accelerometer's), and ends at the
second sample of the next run.

:class:`ConsistencyScan` integrates every swing with the signals as given, with each axis
fault of :data:`CANDIDATES` undone (an axis negated), and with the time scaled by each factor of
:data:`TIME_SCALES` (½ to 2 in steps of 2^(1/8)). When most swings' residuals exceed
:data:`RESIDUAL_LIMIT` and negating one axis halves their median, that axis is reported (a
:class:`~footzoo.core.errors.SensorWarning` naming it, the swings and the fix); one compiled pass
per swing over the first :data:`MAX_SWINGS` swings. It runs in batch (one push of the recording)
and live (:class:`footzoo.Stream`, chunk by chunk), on the same swings.

The time-scale residuals are the evidence of the rate (:meth:`ConsistencyScan.time_scales`): on
the real recordings in the data folder (IPOL's included) the median residual is lowest within
0.92–1.09× of the declared time scale; relabelled at ×2, ×½ or ×1.5 their rate, it is lowest
within a step (2^(1/8)) of the factor that undoes it on 218 of 231 (walks, runs and stairs with
a residual), 4.7–13× below the declared one in the median (``benchmarks/relabel.md``,
``benchmarks/relabel_misses.md``). Slow, short-stepped walks turn the foot little, and their
residuals depend little on the scale. So the rate is not named here but by
:mod:`footzoo.core.plausibility`, which weighs this evidence with the gait the run estimated
(cadence, stride length, clearance, the foot's rotation per metre) and names one corrected rate.

A fast run's foot is hardly ever that still (PyShoe's fastest run: one or two swings within the
walking foot's bounds). Until a scan has :data:`MIN_RATE_SWINGS` swings of its own it also feeds
a second one (:attr:`ConsistencyScan.running_scan`) whose quasi-static bounds are a running
foot's (:data:`RUNNING_STATIC_GYR`, :data:`RUNNING_STATIC_ACC`), and where it has fewer swings its
rate evidence is that scan's: a tilt up to 0.3 rad off at each start raises the floor of every
time scale's residual (0.13 on that run as recorded), far below what a wrong scale leaves
(0.5–1.3 at ×2, ×½ or ×1.5 there). Those swings never name an axis map, and their evidence is
withheld when a negated axis explains them.

Each swing also gives the gait between the foot's quiet instants, without the stance detector
(:func:`_swing_gait`): its horizontal length and clearance, by the same strapdown with its
velocity error taken to grow linearly from zero to what is left at the end (as a zero-velocity
update takes it), the foot's rotation ∫|ω| dt and its peak rate; two swings that share a
quasi-static run make a stride (the time between their starts). On the recordings of the data
folder as recorded these strides are human: 0.23–0.40 m per radian the foot turns on the 42 of
PyShoe, gaitmap, x-io and Köroğlu but the crawl (0.06), 0.23–0.40 on IPOL's; quiet instants can
split a stride (the shortest-stepped PyShoe walk: 171 steps/min where its detector counts 139;
``benchmarks/relabel_misses.md``). :mod:`footzoo.core.plausibility` weighs
them only when the detector gives too few strides (a detector tuned in seconds merges a run's
strides when the rate is wrong).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..core.conventions import GRAVITY
from ..core.errors import SensorWarning, user_stacklevel
from ..core.norms import row_norms, row_norms_squared
from ..core.plausibility import MAX_STRIDE_TIME
from ..kernels.jit import njit
from ..kernels.views import read_only
from .strapdown import quat_product, rotate, rotvec_quat, series_rotvec_quat

#: (name, gyroscope axis signs, the fix) of each axis fault the scan can name.
CANDIDATES: tuple[tuple[str, tuple[float, float, float], str], ...] = (
    ("gyr_x has the wrong sign", (-1.0, 1.0, 1.0), "negate gyr_x (check the axis map: FRD, right-handed)"),
    ("gyr_y has the wrong sign", (1.0, -1.0, 1.0), "negate gyr_y (check the axis map: FRD, right-handed)"),
    ("gyr_z has the wrong sign", (1.0, 1.0, -1.0), "negate gyr_z (check the axis map: FRD, right-handed)"),
)
#: Factors by which the time is scaled to test the rate: ½ to 2 in steps of 2^(1/8), 1 (the declared rate) excluded.
TIME_SCALES: tuple[float, ...] = tuple(float(2.0 ** (k / 8.0)) for k in range(-8, 9) if k)
#: Median swing residual above which the signals are inconsistent: the real recordings of the data folder give
#: 0.02–0.11 (0.23 a crawl, whose residual no axis fault halves). With the swings anchored at still samples
#: (:data:`ANCHOR_WINDOW`) a negated gyroscope axis gives 0.06–1.6 (the least about an axis the foot hardly turns
#: about): at 0.15, 112 of the 126 negated axes of PyShoe, x-io, gaitmap and Köroğlu are named (98 with the runs'
#: last samples as anchors and 0.25), and 98 of the 162 of IPOL and the simulator (63), none wrongly, none as
#: recorded (``benchmarks/relabel_misses.md``).
RESIDUAL_LIMIT = 0.15
#: A fault is named when undoing it divides the median residual by at least this.
EXPLAINED_RATIO = 2.0
#: Fewest swings the scan decides on (and it decides again after each as many more).
MIN_SWINGS = 8
#: Swings after which a consistent recording is not scanned further (a rate or an axis map does not change
#: within a recording): the scan's cost is bounded, whatever the recording's length.
MAX_SWINGS = 64
#: Samples per push when a batch run feeds a whole recording (:meth:`ConsistencyScan.push_recording`).
BATCH_BLOCK = 4096
#: Quasi-static sample: |ω| below this (rad/s) and |‖f‖ − g| below :data:`STATIC_ACC` (m/s²), for :data:`STATIC_MIN` s
#: (at least 3 samples). A running foot is that still for a few hundredths of a second only (PyShoe's runs: 0.6 rad/s,
#: 1.5 m/s² and 0.04 s found no swing in three of its ten runs, and almost none once they are read at twice their
#: rate). With 0.8 rad/s, 2 m/s² and 0.02 s every run but one has 12 swings or more.
STATIC_GYR = 0.8
STATIC_ACC = 2.0
STATIC_MIN = 0.02
#: A running foot's bounds (rad/s, m/s²), for the rate's evidence when the walking bounds above find fewer than
#: :data:`MIN_RATE_SWINGS` swings: a foot that lands at several m/s is on the ground for 0.2–0.3 s and its quietest
#: instants still turn at about 1 rad/s and read 2–3 m/s² off g (PyShoe's fastest run, 2017-12-15-18-03-05: one or
#: two swings within the walking bounds, 19 within these). Their tilt is off by up to atan(3 / g) = 0.3 rad, a floor
#: under every time scale's residual (0.13 on that run as recorded, 0.5–1.3 relabelled at ×2, ×½ or ×1.5), so they
#: serve the rate only, never the axis map, and only where the walking bounds leave the rate unjudged: on a walk they
#: start swings on a rising heel again (``benchmarks/relabel_misses.md``).
RUNNING_STATIC_GYR = 1.2
RUNNING_STATIC_ACC = 3.0
#: A swing starts at the stillest sample (lowest (|ω| / STATIC_GYR)² + ((‖f‖ − g) / STATIC_ACC)²) of the last
#: ANCHOR_WINDOW s of its quasi-static run, not at the run's last sample: there a walking foot's heel already rises,
#: and the tilt the accelerometer gives is off by the heel's acceleration (1.5 m/s² forward: 0.15 rad, which the
#: swing's residual then is). On the real recordings of the data folder the median residual at the declared rate
#: falls from 0.07–0.28 to 0.02–0.11 (IPOL's, never used to choose it: from 0.07–0.23 to 0.03–0.10), and it is
#: lowest within 0.92–1.09× of the right time scale, where it was up to 2× it on slow walks
#: (``benchmarks/relabel_misses.md``; 0.05 s or 0.25 s name about as many relabelled rates).
ANCHOR_WINDOW = 0.1
#: The accepted swing durations (s).
SWING_RANGE = (0.15, 3.0)
#: Fewest swings decided on at the end of the data (a walk of four strides).
MIN_RATE_SWINGS = 4


#: Largest half-angle (rad) of one sample's rotation, at the largest time scale, for which a swing is integrated with
#: :func:`~footzoo.filters.strapdown.series_rotvec_quat` in every column (its omitted terms below 1e-15); a swing
#: that turns faster in one sample is integrated with the closed form.
SERIES_HALF_ANGLE = 0.5


@njit(inline="always")
def _integrate(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, a: int, b: int, scale: np.ndarray,
               axes: np.ndarray, g: float, state: np.ndarray, series: bool) -> None:
    """Strapdown over samples ``a``–``b`` of every column ``c`` of ``state`` (rows w, x, y, z, vx, vy, vz) at once,
    one sample at a time: the velocity by the specific force, then the attitude by the rotation vector (by
    :func:`~footzoo.filters.strapdown.series_rotvec_quat`, or by the closed form where ``series`` is False);
    ``axes`` (3, columns) the gyroscope axes' signs."""
    for i in range(a, b):
        dt0, fx, fy, fz = t[i + 1] - t[i], acc[i, 0], acc[i, 1], acc[i, 2]
        for c in range(scale.shape[0]):  # independent columns: this loop vectorises
            dt = dt0 * scale[c]
            w, x, y, z = state[0, c], state[1, c], state[2, c], state[3, c]
            nx, ny, nz = rotate(w, x, y, z, fx, fy, fz)
            state[4, c] += nx * dt
            state[5, c] += ny * dt
            state[6, c] += (nz + g) * dt
            rx, ry, rz = gyr[i, 0] * axes[0, c] * dt, gyr[i, 1] * axes[1, c] * dt, gyr[i, 2] * axes[2, c] * dt
            if series:
                d0, d1, d2, d3 = series_rotvec_quat(rx, ry, rz)
                w, x, y, z = quat_product(w, x, y, z, d0, d1, d2, d3)
                m = 1.5 - 0.5 * (w * w + x * x + y * y + z * z)  # back to unit length (a Newton step of 1/√n)
            else:
                d0, d1, d2, d3 = rotvec_quat(rx, ry, rz)
                w, x, y, z = quat_product(w, x, y, z, d0, d1, d2, d3)
                m = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
            state[0, c], state[1, c], state[2, c], state[3, c] = w * m, x * m, y * m, z * m


@njit
def _tilt(fx: float, fy: float, fz: float) -> tuple[float, float, float, float]:
    """The attitude (scalar-first quaternion, body to NED, heading 0) whose roll and pitch make the still
    specific force ``(fx, fy, fz)`` (FRD, m/s²) point up."""
    roll = math.atan2(-fy, -fz)
    pitch = math.atan2(fx, math.sqrt(fy * fy + fz * fz))
    cr, sr, cp, sp = math.cos(roll / 2), math.sin(roll / 2), math.cos(pitch / 2), math.sin(pitch / 2)
    return cp * cr, cp * sr, sp * cr, -sp * sr


@njit
def _residuals(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, first: np.ndarray, last: np.ndarray,
               scale: np.ndarray, signs: np.ndarray, g: float, out: np.ndarray) -> None:
    """``out[s, c] = |v| / (g T)`` of swing ``s``: strapdown from sample ``first[s]`` (tilt from its ``acc``) to
    ``last[s]``, with the time scaled by ``scale[c]`` and the gyroscope axes signed by ``signs[c]``.

    Every column advances one sample at a time (independent columns side by side: the loop over
    them vectorises); a swing whose rotations stay within :data:`SERIES_HALF_ANGLE` per sample at
    the largest scale by the series (:func:`~footzoo.filters.strapdown.series_rotvec_quat`), another by the closed
    form.
    """
    state = np.empty((7, scale.shape[0]))
    axes = np.ascontiguousarray(signs.T)  # (3, columns): each axis's signs side by side, as the columns advance
    reach = np.max(np.abs(scale))
    for s in range(first.shape[0]):
        a, b = first[s], last[s]
        state[0], state[1], state[2], state[3] = _tilt(acc[a, 0], acc[a, 1], acc[a, 2])
        state[4:] = 0.0
        turn = 0.0
        for i in range(a, b):
            turn = max(turn, (gyr[i, 0] ** 2 + gyr[i, 1] ** 2 + gyr[i, 2] ** 2) * (t[i + 1] - t[i]) ** 2)
        series = 0.5 * math.sqrt(turn) * reach <= SERIES_HALF_ANGLE
        if series:  # two copies of the loop, each without a branch inside
            _integrate(t, acc, gyr, a, b, scale, axes, g, state, True)
        else:
            _integrate(t, acc, gyr, a, b, scale, axes, g, state, False)
        for c in range(scale.shape[0]):
            v = math.sqrt(state[4, c] ** 2 + state[5, c] ** 2 + state[6, c] ** 2)
            out[s, c] = v / (g * (t[b] - t[a]) * scale[c])


@njit
def _swing_gait(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, first: np.ndarray, last: np.ndarray, g: float,
                out: np.ndarray) -> None:
    """``out[s]`` = (length (m, horizontal), clearance (m), rotation ∫|ω| dt (rad), peak |ω| (rad/s)) of swing ``s``:
    strapdown from sample ``first[s]`` (tilt from its ``acc``) to ``last[s]`` with the signals as given, its velocity
    error taken to grow linearly from zero to what is left at the end (the foot stops there), as a zero-velocity update
    takes it: the position is corrected by ``v_end τ² / (2 T)`` at the time ``τ`` into the swing of duration ``T``."""
    for s in range(first.shape[0]):
        a, b = first[s], last[s]
        w, x, y, z = _tilt(acc[a, 0], acc[a, 1], acc[a, 2])
        vx = vy = vz = px = py = pz = 0.0
        turned = peak = 0.0
        heights = np.empty(b - a)  # the height (m, up) after each sample, before the correction
        for i in range(a, b):
            dt = t[i + 1] - t[i]
            nx, ny, nz = rotate(w, x, y, z, acc[i, 0], acc[i, 1], acc[i, 2])
            vx, vy, vz = vx + nx * dt, vy + ny * dt, vz + (nz + g) * dt
            px, py, pz = px + vx * dt, py + vy * dt, pz + vz * dt
            heights[i - a] = -pz
            rate = math.sqrt(gyr[i, 0] ** 2 + gyr[i, 1] ** 2 + gyr[i, 2] ** 2)
            turned += rate * dt
            peak = max(peak, rate)
            d0, d1, d2, d3 = rotvec_quat(gyr[i, 0] * dt, gyr[i, 1] * dt, gyr[i, 2] * dt)
            w, x, y, z = quat_product(w, x, y, z, d0, d1, d2, d3)
            m = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
            w, x, y, z = w * m, x * m, y * m, z * m
        duration = t[b] - t[a]
        half = 0.5 * duration  # the correction at the end: v_end T / 2
        clearance = 0.0
        for i in range(a, b):
            tau = t[i + 1] - t[a]
            clearance = max(clearance, heights[i - a] + vz * tau * tau / (2.0 * duration))
        out[s, 0] = math.hypot(px - vx * half, py - vy * half)
        out[s, 1], out[s, 2], out[s, 3] = clearance, turned, peak


def _stillest(stillness: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The index of the lowest ``stillness`` in each range ``[lo[i], hi[i])`` (the first of equal ones); the ranges
    are disjoint, in order and not empty."""
    if not len(lo):
        return np.zeros(0, dtype=np.int64)
    n = hi - lo
    offsets = np.cumsum(n) - n  # where each range starts among the samples of all of them
    at = np.arange(int(n.sum())) + np.repeat(lo - offsets, n)  # the samples of the ranges, one after the other
    values = stillness[at]
    lowest = np.flatnonzero(values == np.repeat(np.minimum.reduceat(values, offsets), n))
    return at[lowest[np.searchsorted(lowest, offsets)]].astype(np.int64)


#: Columns of the residuals: 0 the signals as given, then each axis fault undone, then each time scale.
_SCALE = np.array([1.0] * (1 + len(CANDIDATES)) + list(TIME_SCALES))
_SIGNS = np.array([(1.0, 1.0, 1.0)] + [c[1] for c in CANDIDATES] + [(1.0, 1.0, 1.0)] * len(TIME_SCALES))
#: The columns of the time scales, and the scales (1 first: the signals as given).
_RATE_COLUMNS = (0, *range(1 + len(CANDIDATES), len(_SCALE)))
_RATE_SCALES = _SCALE[list(_RATE_COLUMNS)]


def _explaining_fault(r: np.ndarray) -> int | None:
    """The column of the axis fault that, undone, divides the median residual ``r[0]`` by :data:`EXPLAINED_RATIO`
    (``r``: one median per column of the residuals); None when none does or a time scale explains it better."""
    best = int(np.argmin(r[1:])) + 1
    return None if best > len(CANDIDATES) or r[best] * EXPLAINED_RATIO > r[0] else best


class ConsistencyScan:
    """Gyroscope–accelerometer consistency over the swings, fed chunk by chunk (see the module docstring).

    Parameters
    ----------
    rate : float
        Nominal sampling rate (Hz): the shortest quasi-static run in samples.
    gravity : float
        g (m/s²).
    name : str
        The recording's name, for the warning.
    running : bool
        Quasi-static within a running foot's bounds (:data:`RUNNING_STATIC_GYR`, :data:`RUNNING_STATIC_ACC`) instead of
        a walking foot's (:data:`STATIC_GYR`, :data:`STATIC_ACC`): the evidence of the rate only, no axis fault is
        named. A walking scan feeds one such scan (:attr:`running_scan`) until it has :data:`MIN_RATE_SWINGS` swings
        of its own, and gives its evidence where it has fewer (:meth:`time_scales`).
    """

    def __init__(self, rate: float, gravity: float = GRAVITY, name: str = "recording", running: bool = False):
        self.gravity, self.name, self.rate = gravity, name, float(rate)
        self.running = running
        self.bounds = (RUNNING_STATIC_GYR, RUNNING_STATIC_ACC) if running else (STATIC_GYR, STATIC_ACC)
        self.running_scan = None if running else ConsistencyScan(rate, gravity, name, running=True)
        self.min_static = max(3, int(math.ceil(STATIC_MIN * rate)))
        self.anchor_window = max(self.min_static, round(ANCHOR_WINDOW * rate))  # samples
        self.residuals: list[np.ndarray] = []
        self.swings: list[tuple[int, int]] = []
        #: per swing: its start (s, as declared), duration (s), length (m), clearance (m), rotation (rad), peak (rad/s)
        self.gait_rows: list[np.ndarray] = []
        self._chained: list[bool] = []  # per swing: it starts in the quasi-static run the swing before it ends in
        self._open = False  # the last swing measured ends in the run the buffer starts with
        self.report: dict[str, Any] = {}
        self._buf: dict[str, np.ndarray] | None = None
        self._anchored = False  # the buffer starts with a confirmed quasi-static run
        self.seen = 0  # samples pushed so far (the next sample's index)
        self._closed = False

    @property
    def done(self) -> bool:
        """Whether the scan has a finding or has seen :data:`MAX_SWINGS` swings: more samples change nothing."""
        return bool(self.report) or len(self.residuals) >= MAX_SWINGS

    def push(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> None:
        """The next samples (absolute indices ``k``, time (s), FRD specific force (m/s²), rate (rad/s))."""
        if not len(t) or self.done:
            return
        if self.running_scan is not None and len(self.residuals) < MIN_RATE_SWINGS:
            self.running_scan.push(k, t, acc, gyr)  # the rate's evidence while this scan has too few swings
        self._push(k, t, acc, gyr)

    def _push(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> None:
        """:meth:`push` to this scan alone."""
        self.seen = int(k[-1]) + 1
        gyr_bound, acc_bound = self.bounds
        turn, off_g = row_norms_squared(gyr) / gyr_bound**2, ((row_norms(acc) - self.gravity) / acc_bound) ** 2
        static, stillness = (turn < 1.0) & (off_g < 1.0), turn + off_g
        new = {"k": np.asarray(k), "t": t, "acc": acc, "gyr": gyr, "static": static, "stillness": stillness}
        self._buf = new if self._buf is None else {n: np.concatenate([self._buf[n], v]) for n, v in new.items()}
        self._scan()

    def _scan(self) -> None:
        buf = self._buf
        s = buf["static"]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], s.astype(np.int8), [0]])))
        starts, ends = edges[::2], edges[1::2]
        keep = ends - starts >= self.min_static
        starts, ends = starts[keep], ends[keep]
        cut = 0
        if len(starts):
            if not self._anchored:
                self._anchored, cut, self._open = True, int(starts[0]), False
                starts, ends = starts - cut, ends - cut
                buf = {n: v[cut:] for n, v in buf.items()}
            elif starts[0] != 0:  # the anchor's run was shorter than it looked: start from this run
                cut, self._open = int(starts[0]), False
                starts, ends = starts - cut, ends - cut
                buf = {n: v[cut:] for n, v in buf.items()}
            # the swings: from the stillest of the last samples of each run to the sample after the first of the next
            first = _stillest(buf["stillness"], np.maximum(starts[:-1], ends[:-1] - self.anchor_window), ends[:-1])
            self._swings(buf, first, np.minimum(starts[1:] + 1, len(buf["t"]) - 1))
            # keep the last run's last samples only (the next swing's anchor is among them, open or closed): a long
            # stillness kept whole would make the buffer look too long to be a swing, and lose the swing after it
            last = max(int(starts[-1]), int(ends[-1]) - self.anchor_window)
            buf = {n: v[last:] for n, v in buf.items()}
        elif not self._anchored:  # no quasi-static run yet: only the samples a run could start with
            buf = {n: v[-self.min_static:] for n, v in buf.items()}
        if self._anchored and buf["t"][-1] - buf["t"][0] > SWING_RANGE[1] + 1.0:
            # too long to be a swing: start afresh at the next quasi-static run
            buf = {n: v[-self.min_static:] for n, v in buf.items()}
            self._anchored = False
        self._buf = buf

    def _swings(self, buf: dict[str, np.ndarray], first: np.ndarray, last: np.ndarray) -> None:
        """The residuals of the swings ``first[i]``–``last[i]`` of ``buf``, every candidate on every swing."""
        duration = buf["t"][last] - buf["t"][first]
        ok = (duration >= SWING_RANGE[0]) & (duration <= SWING_RANGE[1])
        chained = (ok & np.concatenate([[self._open], ok[:-1]]))[ok]  # each swing's start run ends the one before
        if len(ok):
            self._open = bool(ok[-1])
        first, last = first[ok].astype(np.int64), last[ok].astype(np.int64)
        first, last = first[:MAX_SWINGS - len(self.residuals)], last[:MAX_SWINGS - len(self.residuals)]
        if not len(first):
            return
        t, acc, gyr = (read_only(buf[n]) for n in ("t", "acc", "gyr"))  # one compiled variant for every caller
        out = np.empty((len(first), len(_SCALE)))
        _residuals(t, acc, gyr, first, last, _SCALE, _SIGNS, self.gravity, out)
        gait = np.empty((len(first), 4))
        _swing_gait(t, acc, gyr, first, last, self.gravity, gait)
        before = len(self.residuals)
        self.residuals.extend(out)
        self.gait_rows.extend(np.column_stack([buf["t"][first], buf["t"][last] - buf["t"][first], gait]))
        self._chained.extend(chained[:len(first)].tolist())
        self.swings.extend(zip(buf["k"][first].tolist(), buf["k"][last].tolist(), strict=True))
        for m in range((before // MIN_SWINGS + 1) * MIN_SWINGS, len(self.residuals) + 1, MIN_SWINGS):
            if not self.report and not self.running:  # the same swings decide, batch and live
                self._decide(m)

    def _decide(self, m: int) -> None:
        """Decide on the first ``m`` swings whether a gyroscope axis has the wrong sign (module docstring)."""
        residuals = np.asarray(self.residuals[:m])
        bad = residuals[residuals[:, 0] > RESIDUAL_LIMIT]
        if 2 * len(bad) <= len(residuals):
            return
        r = np.median(bad, axis=0)  # the median swing is inconsistent: which fault, undone, explains it?
        best = _explaining_fault(r)
        if best is None:
            return  # a time scale explains it best (the rate: core.plausibility), or nothing does
        self.report = {"cause": CANDIDATES[best - 1][0], "residual": float(r[0]),
                       "explained_residual": float(r[best]), "swings": len(residuals),
                       "inconsistent_swings": len(bad), "first_swings": [list(s) for s in self.swings[:3]]}
        self._axis_finding(self.report, CANDIDATES[best - 1][2])

    def _axis_finding(self, report: dict[str, Any], fix: str) -> None:
        """Warn about a gyroscope axis of the wrong sign (``report``: cause, residuals, swings) with the fix."""
        cause = report["cause"]
        shown = ", ".join(f"{a}–{b}" for a, b in report["first_swings"])
        warnings.warn(
            f"{self.name}: the gyroscope and the accelerometer disagree: integrated over "
            f"{report['inconsistent_swings']} of {report['swings']} swings (samples {shown}, ...), the gyroscope's "
            f"attitude leaves a velocity of {report['residual']:.2f} g × the swing's duration where the foot stops "
            f"(real sensors: below {RESIDUAL_LIMIT:g}); with {cause.replace('has the', 'of the')} undone it is "
            f"{report['explained_residual']:.2f}. Most likely {cause}: {fix}. "
            "Details in diagnostics['sensor']['consistency']",
            SensorWarning, stacklevel=user_stacklevel(),
        )

    def ready(self, until: int) -> bool:
        """Whether every swing ending at or before sample ``until`` has been measured (or none will be any more)."""
        return self.done or self._closed or self.seen > until + self.min_static

    def time_scales(self, until: int | None = None) -> dict[str, Any] | None:
        """The evidence of the rate: the median residual at each time scale over the swings ending by sample ``until``.

        Returns
        -------
        dict or None
            ``scales`` (1 first, then :data:`TIME_SCALES`: the factor by which the time is scaled),
            ``residual`` (the median residual at each, same order), ``swings`` (how many), ``anchors``
            (``"walking"``, or ``"running"``: the swings of :attr:`running_scan`, where this scan has
            fewer than :data:`MIN_RATE_SWINGS` by ``until`` and that one at least as many); None
            without any swing, or after a gyroscope axis fault (the residuals then say nothing
            about the rate).
        """
        if self.report:
            return None
        rows = np.asarray(self.residuals).reshape(-1, len(_SCALE))
        if until is not None:
            rows = rows[np.array([b for _, b in self.swings], dtype=np.int64) <= until]
        if len(rows) < MIN_RATE_SWINGS and self.running_scan is not None:
            running = self.running_scan.time_scales(until)
            if running is not None and running["swings"] >= MIN_RATE_SWINGS:
                return running
        if not len(rows):
            return None
        if self.running and _explaining_fault(np.median(rows, axis=0)) is not None:
            return None  # an axis fault explains these swings (named by a walking scan, if it has the swings)
        return {"scales": _RATE_SCALES, "residual": np.median(rows[:, list(_RATE_COLUMNS)], axis=0),
                "swings": len(rows), "anchors": "running" if self.running else "walking",
                "strides": self._strides(len(rows))}

    def _strides(self, m: int) -> np.ndarray:
        """The strides between the quiet instants of the first ``m`` swings, as
        :attr:`footzoo.core.plausibility.GaitScan.strides` gives the detector's (n, 6): T (s, from the start of a swing
        to the start of the next, when that one starts in the quasi-static run this one ends in), the swing's L (m),
        h (m), θ (rad), peak |ω| (rad/s) and duration (s)."""
        if m < 2:
            return np.empty((0, 6))
        rows = np.asarray(self.gait_rows[:m])
        period = np.diff(rows[:, 0])
        ok = np.asarray(self._chained[1:m]) & (period <= MAX_STRIDE_TIME)
        return np.column_stack([period, rows[:-1, 2:6], rows[:-1, 1]])[ok]

    def push_recording(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, block: int = BATCH_BLOCK) -> None:
        """A whole recording, pushed ``block`` samples at a time until the scan is :attr:`done`.

        The same finding as one push of everything (the scan is the live one, fed chunk by chunk), at
        the cost of the samples that decide it rather than of the recording's length. :attr:`running_scan`
        is then given what a stream would have given it and :meth:`time_scales` may ask of it: the samples up to
        this scan's fourth swing (all of them if it has fewer).
        """
        for lo in range(0, len(t), block):
            if self.done:
                break
            hi = min(lo + block, len(t))
            self._push(np.arange(lo, hi), t[lo:hi], acc[lo:hi], gyr[lo:hi])
        if self.running_scan is not None:
            stop = self.seen
            if len(self.swings) >= MIN_RATE_SWINGS:  # a stream feeds it until that swing is confirmed
                stop = min(stop, self.swings[MIN_RATE_SWINGS - 1][1] + self.min_static + 1)
            self.running_scan.push_recording(t[:stop], acc[:stop], gyr[:stop], block)

    def finish(self) -> dict[str, Any]:
        """End of the data: decide on every swing seen, from :data:`MIN_RATE_SWINGS` on; the finding (empty: none)."""
        self._closed = True
        if self.running_scan is not None:
            self.running_scan.finish()
        if not self.report and not self.running and len(self.residuals) >= MIN_RATE_SWINGS:
            self._decide(len(self.residuals))
        return self.report
