"""Dynamic-threshold gait phase detection, DGP (Nguyen & La 2016, Sec. III-A, eqs. 3–15, Algorithm 1)."""

from __future__ import annotations

import math

import numpy as np

from ..core.context import RunContext
from ..core.conventions import GRAVITY
from ..core.norms import row_norms_squared
from ..filters.strapdown import quat_product, rotate, rotvec_quat
from ..kernels.jit import njit
from ..kernels.views import read_only
from ..plugins.base import Detector, Real, run_context
from ..plugins.incremental import Chunk, Latency
from ..plugins.registry import register


def _count(x: float) -> int:
    """Nearest whole number of samples, halves rounded up, immune to the last bits of a median rate."""
    return int(math.floor(x + 0.5 + 1e-6))


def dgp_statistic_state(f: int, n_c: int, lag: int) -> tuple[np.ndarray, ...]:
    """State of :func:`dgp_statistic_kernel`: ring buffers of running sums and of the last ``lag`` samples.

    Running sums (2f + 2 rows) of eq. 8's acceleration, of its means and of their squared
    norms; of ``d_g`` (n_c + 1 rows, eq. 9); the sample count; ``hist`` (lag, 6): time,
    ``a_local``, ``w_m`` and the specific force of the last ``lag`` samples; ``hist_q`` (lag, 4):
    their rotations ``exp(ω dt)``.
    """
    w = 2 * f + 1
    return (np.zeros((w + 1, 3)), np.zeros((w + 1, 3)), np.zeros(w + 1), np.zeros(n_c + 1),
            np.zeros(1, dtype=np.int64), np.zeros((lag, 6)), np.zeros((lag, 4)))


@njit
def _next(i, size):
    """Row after ``i`` in a ring of ``size`` rows."""
    return i + 1 if i + 1 < size else 0


@njit(inline=True)
def _push_mean(ring, cur, old, lo, k, x):
    """Running sum in ``ring``: row ``cur`` = row ``old`` + ``x``; returns the mean ``(c_cur − c_lo)/k``.

    The sums are ``c_k = c_{k−1} + x_k`` and the mean of the last ``k`` values is
    ``(c_k − c_{k−k})/k``: the arithmetic of a cumulative sum over the whole recording.
    """
    ring[cur] = ring[old] + x
    return (ring[cur] - ring[lo]) / k


@njit(inline=True)
def _push_mean3(ring, cur, old, lo, k, x0, x1, x2):
    """:func:`_push_mean` for a 3-vector, component by component, without allocating."""
    ring[cur, 0] = ring[old, 0] + x0
    ring[cur, 1] = ring[old, 1] + x1
    ring[cur, 2] = ring[old, 2] + x2
    return (ring[cur, 0] - ring[lo, 0]) / k, (ring[cur, 1] - ring[lo, 1]) / k, (ring[cur, 2] - ring[lo, 2]) / k


@njit
def dgp_statistic_kernel(t, acc, gyr, window, n_c, scale, ring_acc, ring_ave, ring_sq, ring_dg, count, hist, hist_q):
    """``s_c`` (eq. 9) of ``d_g`` (eq. 3) per sample, resumable: the state arrays carry on between calls.

    Each change in eq. 3 is taken over one sample of the paper's rate, i.e.
    over ``lag`` samples of this recording (``hist`` keeps the last ``lag``
    values), so ``d_g`` means the same at any rate:

    * ``|a_m^{t+1} − a_m^t|``: change of the NED motion acceleration (eqs. 4–6).
      Since ``a_m = C f + g``, the change is ``C_t (ΔC f_{t+1} − f_t)`` and its norm
      ``|ΔC f_{t+1} − f_t|`` depends on the attitude only through the rotation
      between the two samples, which footzoo takes from the gyro (the product
      of ``exp(ω dt)`` over the lag, kept in ``hist_q``) for every orientation source.
    * ``|a_local^{t+1} − a_local^t|``: change of the local acceleration, eq. 7:
      ``a_local^{t+1} = sqrt(mean_j |a_b^{t+1} − a_ave^j|²)`` over the last 2f+1
      running means ``a_ave^j`` (eq. 8, each over 2f+1 samples).
    * ``|w_m^{t+1} − w_m^t|``: change of the angular-rate magnitude.

    The accelerations are taken in g and the rate in rad/s, the units the paper's
    MicroStrain 3DM-GX3-25 reports, for which its thresholds (0.8) were found.
    ``scale`` = (paper's sample interval) / (lag interval) corrects the rest
    when the lag cannot be exactly one paper sample (rates below the paper's,
    or not a multiple of it).

    The state comes from :func:`dgp_statistic_state`. The rows of the rings are found once per
    call and then advanced by one per sample.
    """
    n = t.shape[0]
    lag = hist.shape[0]
    s_c = np.empty(n)
    d_g_out = np.empty(n)
    c = count[0]
    # sample c writes row (c + 1) mod size from row c mod size; its mean starts at row (c + 1 − k) mod size
    size, size_dg = ring_acc.shape[0], ring_dg.shape[0]
    old, lo = c % size, (c + 1 - min(c + 1, window)) % size
    old_dg, lo_dg = c % size_dg, (c + 1 - min(c + 1, n_c)) % size_dg
    slot = c % lag  # row of sample c in hist, hist_q
    for k in range(n):
        cur, cur_dg = _next(old, size), _next(old_dg, size_dg)
        kw = min(c + 1, window)
        a0, a1, a2 = acc[k, 0], acc[k, 1], acc[k, 2]
        v0, v1, v2 = _push_mean3(ring_acc, cur, old, lo, kw, a0, a1, a2)  # eq. 8
        m0, m1, m2 = _push_mean3(ring_ave, cur, old, lo, kw, v0, v1, v2)
        mean_sq = _push_mean(ring_sq, cur, old, lo, kw, (v0 * v0 + v1 * v1) + v2 * v2)
        local_sq = ((a0 * a0 + a1 * a1) + a2 * a2) - 2 * ((a0 * m0 + a1 * m1) + a2 * m2) + mean_sq  # eq. 7
        a_local = math.sqrt(max(local_sq, 0.0))
        g0, g1, g2 = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        w_m = math.sqrt((g0 * g0 + g1 * g1) + g2 * g2)
        dt = t[k] - hist[slot - 1 if slot > 0 else lag - 1, 0] if c > 0 else 0.0
        hist_q[slot, 0], hist_q[slot, 1], hist_q[slot, 2], hist_q[slot, 3] = rotvec_quat(g0 * dt, g1 * dt, g2 * dt)
        if c < lag:
            d_g = 0.0
        else:
            # rotation from the body at k − lag to the body at k: exp(ω dt) of the lag samples, oldest first
            q0, q1, q2, q3 = 1.0, 0.0, 0.0, 0.0
            i = _next(slot, lag)
            for _ in range(lag):
                q0, q1, q2, q3 = quat_product(q0, q1, q2, q3, hist_q[i, 0], hist_q[i, 1], hist_q[i, 2], hist_q[i, 3])
                i = _next(i, lag)
            gx, gy, gz = rotate(q0, q1, q2, q3, a0, a1, a2)
            # the sample lag steps back is in row slot (not yet overwritten)
            dx, dy, dz = gx - hist[slot, 3], gy - hist[slot, 4], gz - hist[slot, 5]
            d_am = math.sqrt(dx * dx + dy * dy + dz * dz)
            d_local, d_w = abs(a_local - hist[slot, 1]), abs(w_m - hist[slot, 2])
            d_g = scale * (d_am / GRAVITY + (d_local / GRAVITY + d_w))  # eq. 3
        d_g_out[k] = d_g
        s_c[k] = _push_mean(ring_dg, cur_dg, old_dg, lo_dg, min(c + 1, n_c), d_g)  # eq. 9
        hist[slot, 0], hist[slot, 1], hist[slot, 2] = t[k], a_local, w_m
        hist[slot, 3], hist[slot, 4], hist[slot, 5] = a0, a1, a2
        c += 1
        old, old_dg, slot = cur, cur_dg, _next(slot, lag)
        if c + 1 > window:  # the windows are full: their first row moves on
            lo = _next(lo, size)
        if c + 1 > n_c:
            lo_dg = _next(lo_dg, size_dg)
    count[0] = c
    return s_c, d_g_out


def dgp_initial_state(s_d0: float, th0: float, delay: int = 2) -> np.ndarray:
    """Recursion state of :func:`dgp_kernel`: th, Mc, Md, in swing, swing length, count, then ``delay`` past s_d."""
    return np.concatenate([[th0, -math.inf, -math.inf, 0.0, 0.0, 0.0], np.full(delay, s_d0)])


@njit
def dgp_kernel(
    s_c: np.ndarray, state: np.ndarray, min_swing: int = 0, max_swing: int = 0,
    moving: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Delayed condition, max changing speed, dynamic threshold and stance (eqs. 10–15).

    ``state`` (from :func:`dgp_initial_state`) is carried in place, so a live
    stream can feed one sample at a time and get what a batch run gets. Eq. 10's
    ``s_d^{t−1}`` is two samples of the paper's rate back (20 ms): ``delay``
    samples here (the ring at the end of ``state``). The threshold is re-learned (eq. 14)
    only after a swing of at least ``min_swing`` samples (0: after every swing,
    as in the paper). A sample where ``moving`` is True is swing whatever ``max_cd``
    (footzoo's rotation bound; None: the paper's eq. 15 alone).
    """
    n = s_c.shape[0]
    s_d = np.empty(n)
    max_cd = np.empty(n)
    th = np.empty(n)
    stance = np.empty(n, dtype=np.bool_)
    threshold, mc, md = state[0], state[1], state[2]
    in_swing = state[3] != 0.0
    swing_len = int(state[4])
    count = int(state[5])
    ring = state[6:]
    size = ring.shape[0]
    for k in range(n):
        slot = count % size
        sd = 0.5 * (ring[slot] + s_c[k])  # eq. 10
        ring[slot] = sd
        count += 1
        m = s_c[k] if sd <= s_c[k] else sd  # eq. 11
        s_d[k] = sd
        max_cd[k] = m
        is_stance = m <= threshold  # eq. 15
        if moving is not None and moving[k]:
            is_stance = False
        if not is_stance:
            if not in_swing:
                mc, md = -math.inf, -math.inf
                swing_len = 0
            in_swing = True
            swing_len += 1
            if max_swing > 0 and swing_len % max_swing == 0:
                threshold *= 2.0  # no stance for longer than any swing: the gait has changed
            mc = max(mc, s_c[k])  # eq. 12
            md = max(md, sd)  # eq. 13
        elif in_swing:
            in_swing = False
            if mc - md > 0.0 and swing_len >= min_swing:
                threshold = mc - md  # eq. 14, for the next step
        th[k] = threshold
        stance[k] = is_stance
    state[0], state[1], state[2] = threshold, mc, md
    state[3] = 1.0 if in_swing else 0.0
    state[4] = swing_len
    state[5] = count
    return s_d, max_cd, th, stance


@register
class DGP(Detector):
    """Dynamic gait phase detection with a threshold learned from each step's swing.

    Nguyen & La 2016, IEEE THMS 46(6), Sec. III-A, eqs. 3–15 and Algorithm 1:
    ``d_g`` sums the changes of NED motion acceleration, local acceleration and
    angular-rate magnitude (eq. 3); the stance condition ``s_c`` averages the last
    5 values (eq. 9); the delayed condition ``s_d^{t+1} = (s_d^{t-1} + s_c^{t+1})/2``
    starts at 0.8 (eq. 10); ``max_cd = max(s_c, s_d)`` (eq. 11); a sample is stance
    when ``max_cd ≤ th`` (eq. 15), with ``th = Mc − Md`` from the maxima of
    ``s_c`` and ``s_d`` over the previous step's swing (eqs. 12–14), 0.8 before the
    first step (a non-positive difference keeps the previous threshold).

    The paper counts samples (f = 15, a 5-sample mean) without naming the rate;
    footzoo takes them at ``reference_rate`` = 100 Hz and converts to seconds:
    the windows, the changes of eq. 3 (taken over one paper sample, 10 ms,
    not over one sample of a faster IMU, where they would shrink while the
    noise in them does not) and eq. 10's delay (two paper samples, 20 ms).
    So ``d_g``, ``s_d`` and the learned threshold mean the same at any rate;
    with the changes over one sample and only a rescaling, DGP's gait-phase
    error on the simulated mixed-speed walk was 2.7 % at 100 Hz but 11 % at
    200 Hz (s_d then lags s_c by half the time, and Mc − Md shrinks).

    The attitude enters only through the rotation between the two samples
    (see :func:`dgp_statistic_kernel`), taken from the gyro whatever the
    orientation source.

    On real recordings ``d_g`` is small in a steady mid-swing rotation (it sums
    *changes*): footzoo's ``max_stance_rate`` keeps such samples in the swing.

    Limitations (measured on footzoo's simulator, physical profile, seed 0). The
    threshold ``Mc − Md`` is large when ``s_c`` rises in short bursts that ``s_d``
    does not follow: a push-off whose rate levels off before its final peak (the
    physical profile's, as on real feet: on gaitmap's example walk the rate stays
    at 0.78–0.87 of its peak over the 75 ms before it) gives thresholds of about
    1.1 on the simulated stairs and mixed-speed walks (2.2–3.1 on gaitmap,
    0.25–0.61 on four PyShoe walks). Any later stretch with ``|ω|`` below
    ``max_stance_rate`` and ``max_cd`` below that threshold is then stance. At
    heel strike the sagittal rate crosses zero, below 1 rad/s for 12–44 ms on
    real feet (medians: IPOL, gaitmap, PyShoe walks; simulator 23–34 ms), but
    the foot also rolls (1.3–1.7 rad/s about the other axes at IC, real and
    simulated), so ``|ω|`` stays above the bound (benchmarks/heel_strike.md)
    and DGP marks no stance there; a foot that only pitched gave a 3-sample
    stance at every heel strike of the simulated stairs. The threshold learned
    when a stance begins applies from the next sample: where the delayed
    condition ``s_d`` is still above the new, lower threshold, that stance is
    split once (the first walking stance of the simulated stairs and mixed-speed
    walk, 0.8 → 0.44: 17 stance phases for 16, 38 for 37 at 100 Hz, 39 at
    200 Hz). On gaitmap's walk, whose heel strikes cross zero with an impact,
    ``max_cd`` at the crossing stays at 1.3 (1–2 false stances in 28–29 swings).
    The stance's end at heel-off is set by eq. 15 only while ``max_cd`` there
    passes the threshold first; otherwise by ``max_stance_rate``, a few ms later.
    On the simulated rectangle walk (seed 0) ``Mc`` and ``Md`` both come from the
    loading response (``Mc`` ≈ 6.2 at 32 ms before foot flat, ``Md`` ≈ 5.5 at foot
    flat, 250 Hz), and the landing's roll raises their difference from 0.44–0.49
    to 0.63–0.66 (100–1000 Hz): ``max_cd`` at 8 ms after heel-off (0.47) no longer
    passes it and the bound ends the stance (the first swing sample 8 → 12 ms
    after heel-off at 250 Hz, 7.5 → 10 ms at 400 Hz, 8 → 9 ms at 1000 Hz; at
    100 Hz 10 ms either way). The last stance sample then turns at 0.5 rad/s
    about the toe, and a ZUPT there costs the INS pipelines a step: ``nguyen2016``
    on the true stance ended at 4 ms after heel-off 0.20 m, at 8 ms 1.07 m (250 Hz,
    seed 0); its mean over 24 seeds with DGP 0.97 / 0.81 / 1.05 m at 250 / 400 /
    1000 Hz, 0.26 m at 100 Hz (benchmarks/accuracy.md). On gaitmap's walk the
    thresholds (2.2–3.1) leave the end to the bound too. The simulated loading
    response turns faster than real ones (plantar-flexion peak within 150 ms of
    IC, median: simulator 12.6–13.0 rad/s, gaitmap 7.08, IPOL 6.72;
    benchmarks/heel_strike.md), so its threshold is no prediction of a real one.

    Parameters
    ----------
    window : float
        Duration of 2f + 1 samples for eqs. 7–8 (s); paper: 31 samples = 0.31 s.
    condition_window : float
        Duration of the ``s_c`` average (s); paper: 5 samples = 0.05 s.
    initial_delay : float
        ``s_d^0``; paper: 0.8.
    initial_threshold : float
        ``th^0``; paper: 0.8.
    reference_rate : float
        Rate (Hz) at which the paper's sample counts and thresholds hold.
    min_swing : float
        Shortest swing (s) from which the threshold is re-learned; 0 (paper):
        every swing. On real recordings a momentary crossing in stance makes a
        "swing" of a few samples whose Mc − Md is tiny; the threshold then
        collapses and the detector never returns to stance (on PyShoe's 36
        trials with 0: 24 trials have a "swing" longer than 3 s, thresholds down
        to 0.004). Default 0.2 s (shorter than any real swing); footzoo's.
    max_swing : float
        Longest swing (s): after every ``max_swing`` of one swing without a
        stance the threshold is doubled; 0 (paper): never. A threshold learned
        on walking is too low for a run that follows (its stances have
        ``max_cd`` of 0.4–0.8), the swing then never ends and eq. 14 never
        runs again (5 of PyShoe's running trials stuck in one "swing" of
        7–34 s with ``min_swing`` alone). Default 2 s, longer than any swing;
        footzoo's.
    max_stance_rate : float
        Fastest rotation (rad/s) a stance sample may have: a sample with
        ``|ω|`` above it is swing whatever eq. 15 says, and the swing it belongs
        to goes on (so eq. 14 learns the threshold from the whole swing); 0
        (paper): no bound. ``d_g`` sums *changes*, so a steady mid-swing rotation
        (|ω| ≈ 5–7 rad/s on PyShoe's walking trials) has ``s_c`` ≈ 0.3, below
        the learned ``Mc − Md`` ≈ 0.3–0.6: without the bound DGP marks parts of
        every swing as stance (on PyShoe's walking trials the false stance runs
        have a median |ω| of 2–6 rad/s) and the INS/ZVU pipeline ends near
        0.9 m of PyShoe's error. A foot turning at |ω| about a ground contact
        point a distance r away moves at |ω| r; at 1 rad/s and an instep
        sensor some 0.1 m from the heel or toe, that is 0.1 m/s, ten times a
        ZUPT's noise (0.01 m/s): no zero-velocity sample rotates faster.
        Default 1 rad/s; footzoo's. With the three guards at 0 the detector
        is the paper's.

    Attributes
    ----------
    statistic_ : (N,) ndarray
        ``max_cd`` (eq. 11); stance where ``≤ threshold_``.
    threshold_ : (N,) ndarray
        Dynamic threshold in force at each sample.
    stance_, stance_online_ : (N,) bool ndarray
        Stance flag (causal: both the same).
    """

    name = "dgp"
    causal = True
    paper = "Nguyen & La 2016, IEEE THMS 46(6), Sec. III-A, eqs. 3-15, Algorithm 1"
    parameters = {
        "window": Real("s", "(0, 2]", "the 2f + 1 samples of eqs. 7-8, as a duration",
                       source="Nguyen & La 2016 (f = 15: 31 samples at 100 Hz)",
                       why="a window over 2 s spans several strides"),
        "condition_window": Real("s", "(0, 1]", "the average of s_c (eq. 9), as a duration",
                                 source="Nguyen & La 2016 (5 samples at 100 Hz)",
                                 why="an average over 1 s spans a whole stance"),
        "initial_delay": Real("1", "[0, inf)", "s_d^0: the delayed condition's start (eq. 10)",
                              source="Nguyen & La 2016"),
        "initial_threshold": Real("1", "(0, inf)", "th^0: the threshold before the first step",
                                  source="Nguyen & La 2016"),
        "reference_rate": Real("Hz", "[1, 10000]", "the rate at which the paper's sample counts hold",
                               source="footzoo's reading: the paper's IMU runs at 100 Hz",
                               why="an IMU's sampling rate: 1 Hz to 10 kHz"),
        "min_swing": Real("s", "[0, 2]", "shortest swing the threshold is re-learned from; 0: every one",
                          source="footzoo's guard (see the docstring); the paper: 0",
                          why="a real swing lasts 0.3-0.6 s"),
        "max_swing": Real("s", "[0, 60]", "the threshold doubles after each max_swing without a stance; 0: never",
                          source="footzoo's guard (see the docstring); the paper: 0",
                          why="no human swing lasts a minute"),
        "max_stance_rate": Real("rad/s", "[0, 10]", "fastest |ω| of a stance sample; 0: no bound",
                                source="footzoo's guard (see the docstring); the paper: 0",
                                why="a foot turns faster than 10 rad/s (573 °/s) only in mid-swing"),
    }

    def __init__(
        self,
        window: float = 0.31,
        condition_window: float = 0.05,
        initial_delay: float = 0.8,
        initial_threshold: float = 0.8,
        reference_rate: float = 100.0,
        min_swing: float = 0.2,
        max_swing: float = 2.0,
        max_stance_rate: float = 1.0,
    ):
        self.window = window
        self.condition_window = condition_window
        self.initial_delay = initial_delay
        self.initial_threshold = initial_threshold
        self.reference_rate = reference_rate
        self.min_swing = min_swing
        self.max_swing = max_swing
        self.max_stance_rate = max_stance_rate

    def begin(self, ctx: RunContext) -> DGP:
        """Fresh state for a run at the context's rate (Hz)."""
        super().begin(ctx)
        rate = self.ctx_.rate
        f = max(_count((self.window * rate - 1) / 2), 1)
        self._n_c = max(_count(self.condition_window * rate), 1)
        self._w = 2 * f + 1
        self._lag = max(_count(rate / self.reference_rate), 1)
        self._scale = rate / (self.reference_rate * self._lag)
        self._min_swing = _count(self.min_swing * rate)
        self._max_swing = _count(self.max_swing * rate)
        self._stat_state = dgp_statistic_state(f, self._n_c, self._lag)
        delay = max(_count(2 * rate / self.reference_rate), 1)
        self._state = dgp_initial_state(self.initial_delay, self.initial_threshold, delay)
        return self

    def latency(self, ctx: RunContext) -> Latency:
        """None: each sample's phase is decided with it (Algorithm 1 is causal)."""
        return Latency()

    def _advance(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray):
        s_c, d_g = dgp_statistic_kernel(read_only(t), read_only(acc), read_only(gyr), self._w, self._n_c, self._scale,
                                        *self._stat_state)
        moving = None
        if self.max_stance_rate > 0.0:
            moving = row_norms_squared(gyr) > self.max_stance_rate**2
        s_d, max_cd, th, stance = dgp_kernel(s_c, self._state, self._min_swing, self._max_swing, moving)
        return s_c, d_g, s_d, max_cd, th, stance

    def step(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> Chunk:
        """The stance (and ``max_cd``, the threshold) of the next samples, from the carried state."""
        s_c, d_g, s_d, max_cd, th, stance = self._advance(
            np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(acc, dtype=float).reshape(-1, 3),
            np.ascontiguousarray(gyr, dtype=float).reshape(-1, 3))
        return {"stance": stance, "statistic": max_cd, "threshold": th, "s_c": s_c, "d_g": d_g, "s_d": s_d}

    def detect(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, ctx: RunContext | None = None) -> DGP:
        """Detect stance over a recording (eqs. 3–15)."""
        out = self.begin(run_context(ctx, t)).step(t, acc, gyr)
        self.s_c_, self.d_g_, self.s_d_ = out["s_c"], out["d_g"], out["s_d"]
        self.statistic_, self.threshold_, self.stance_ = out["statistic"], out["threshold"], out["stance"]
        self.stance_online_ = self.stance_.copy()
        return self
