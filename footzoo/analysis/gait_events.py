"""Gait events per stride from the foot's sagittal angular rate: toe-off (TO) and initial contact (IC).

The events of one stride are features of the foot's sagittal (medio-lateral) angular rate
``ω_ml`` between two stances, positive when the toe lifts (Sabatini et al. 2005, "Assessment of
walking features from foot inertial sensing", IEEE TBME 52(3), 486-494, Sec. II-B; Rampp et al.
2015, "Inertial sensor-based stride parameter calculation from gait sequences in geriatric
patients", IEEE TBME 62(4), 1089-1097, the gait event detection of its Methods section, which
states the rules in prose, without numbered equations). Between two stances the rate has three
landmarks:

* the push-off: the foot rolls over its toe, plantar-flexing ever faster; the toe leaves the
  floor about when the rotation is fastest, and in the air the rate turns, through zero, into
  the swing's dorsi-flexion;
* the mid-swing: the dorsi-flexion's positive peak ``p``;
* the heel strike: the dorsi-flexion stops when the heel lands, ``ω_ml`` goes through zero and
  then negative while the foot rolls flat.

**Definitions.**

* **TO** is the instant the rate, recovering from its push-off peak ``ω_min`` (the fastest
  plantar-flexion, a negative minimum), passes :data:`TO_LEVEL` = half of it, on the rising flank
  between the peak and ``p``. The toe leaves on that flank: after the fastest plantar-flexion
  (the terminal contact of gaitmap's ``HerzerEventDetection``, "roughly at the point of the most
  rapid plantar flexion", after Figueiredo et al. 2018, IEEE TNSRE 26(10), 1945-1956) and before
  the zero crossing (Rampp et al.'s toe-off, gaitmap's ``RamppEventDetection`` terminal contact:
  the change from plantar flexion to dorsal extension). The half-amplitude point times that edge
  independently of the sampling rate and of the peak's size.
* **IC** is the heel's touch-down: its impact after the foot's largest pitch. The largest pitch is
  the first downward zero crossing of ``ω_ml`` after ``p`` (Sabatini et al. 2005's IC landmark,
  where the swing's dorsi-flexion ends); the heel is then still in the air and touches the floor
  about 20 ms later (on gaitmap's example walk, its heel marker's descent stops a median 22 ms
  after it). IC is the instant the foot's acceleration, the specific force in the navigation frame
  ``f_n = C_b^n f_b``, has changed from its value at the largest pitch by :data:`CONTACT_LEVEL`
  (30 %) of its largest change within :data:`CONTACT_WINDOW` (60 ms) after it: the onset of the
  impact (Rampp et al. likewise refine their IC with the acceleration of the impact). In the
  navigation frame the turning of gravity's projection does not count; a largest change below
  :data:`CONTACT_MIN_CHANGE` (2 m/s²) is no impact, and IC is then the largest pitch itself (a
  foot put down softly, or the simulator's idealised ``"paper"`` foot). Without the specific
  force (:func:`detect_gait_events` without ``acc``), IC is the largest pitch.

Checked against four references (docs/gait-events.md, ``benchmarks/accuracy.py --parts
events``): the simulator's truth (the toe leaving the floor, the heel touching it;
:mod:`footzoo.sim.gait`), gaitmap's motion-capture events (``stride_events_sample.csv``) and its
heel marker's touch-down, and the hand-checked IMU events of Voisard et al.'s data set
(:mod:`footzoo.io.xsens`). For TO they agree (the half point lies 5 to 9 ms after each one's
toe-off). For IC, gaitmap's event file marks the largest pitch; its heel marker, the
hand-checked events and the impact put the touch-down about 20 ms later. The simulated foot
touches down at its largest pitch without an impact, so IC finds its loading response's onset
about 5 ms after it.

**Independent of the mounting** (footzoo's choice, :func:`sagittal_rate`): ``ω_ml`` is
not a sensor axis but the angular rate rotated into the navigation frame with the
estimated attitude, ``ω_n = C_b^n ω_b``, projected on the horizontal axis to the right of
each stride's direction of travel, ``r = e_down × d`` with ``d`` the horizontal unit
vector from the mid-stance before the swing to the one after it. A sensor turned on the
foot (or read with a wrong but right-handed axis map) sees the same physical rotation,
so it gives the same events. With a sensor aligned to the foot (x toe, y right, z
down) and a level foot, ``ω_ml`` equals ``gyr_y``; :func:`detect_gait_events` still takes
that body-frame signal when no attitude is given.

footzoo's other choices (not fixed by the papers): the stances come from the pipeline's
stance detector instead of Rampp's DTW stride segmentation; the push-off peak is searched from
the middle of the stance before the swing to ``p``, the largest pitch from ``p`` to the middle of
the next stance, and the impact no later than that middle either; the push-off peak's value is
refined with a parabola through its three samples (so the half level does not depend on where
the samples fall), all three crossings are interpolated linearly between two samples; a sample
stands for the middle of its interval ``(t[k-1], t[k]]`` (footzoo's interval-average convention),
so event times are half a period before the sample times. Where a swing lacks the pattern (no
positive ``ω_ml`` after the push-off, e.g. a shuffle), the events fall back to the detector's
stance edges and ``from_rate`` (the steps table's ``events_from_rate``) says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import RecordingError
from ..filters.strapdown import rotate
from ..kernels.jit import njit
from ..kernels.views import read_only
from .inputs import check_samples, check_stances, check_time

#: Toe-off: the fraction of the push-off peak of ``ω_ml`` to which the rate has recovered (half).
TO_LEVEL = 0.5
#: Initial contact: the heel's impact is searched for this long after the foot's largest pitch (s).
CONTACT_WINDOW = 0.06
#: Initial contact: the fraction of the specific force's largest change in the window it has reached.
CONTACT_LEVEL = 0.3
#: Initial contact: a smaller largest change of the acceleration in the window is no impact (m/s²).
CONTACT_MIN_CHANGE = 2.0


@dataclass
class GaitEvents:
    """Events of the swings between consecutive stances (one entry per swing).

    Attributes
    ----------
    to : (K,) ndarray
        Toe-off time (s).
    ic : (K,) ndarray
        Initial contact ending the swing (s).
    from_rate : (K,) bool ndarray
        True where both events come from the angular rate, False where they fell
        back to the detector's stance edges.
    largest_pitch : (K,) ndarray
        The foot's largest pitch before the contact: the downward zero crossing of
        ``ω_ml`` after the mid-swing peak (s; the stance edge where ``from_rate`` is False).
    """

    to: np.ndarray
    ic: np.ndarray
    from_rate: np.ndarray
    largest_pitch: np.ndarray


def segment_ranges(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the half-open ranges ``[lo_i, hi_i)`` concatenated, and each range's offset in them.

    Every range must be non-empty. Vectorised: no Python loop over ranges.
    """
    lengths = hi - lo
    offsets = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    idx = np.arange(int(lengths.sum()), dtype=np.int64) - np.repeat(offsets - lo, lengths)
    return idx, offsets


def segment_argext(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, largest: bool) -> np.ndarray:
    """Index of the maximum (``largest``) or minimum of ``x`` in each non-empty range ``[lo_i, hi_i)``.

    Ties take the first sample. One compiled pass over the ranges' samples, nothing allocated
    but the result.
    """
    lo = np.asarray(lo, dtype=np.int64)
    out = np.empty(len(lo), dtype=np.int64)
    if len(lo):
        _argext_kernel(read_only(x), lo, np.asarray(hi, dtype=np.int64), bool(largest), out)
    return out


@njit
def _argext_kernel(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, largest: bool, out: np.ndarray) -> None:
    for i in range(lo.shape[0]):
        best = lo[i]
        m = x[best]
        for j in range(lo[i] + 1, hi[i]):
            if (x[j] > m) if largest else (x[j] < m):
                m = x[j]
                best = j
        out[i] = best


@njit
def _first_down_crossing(w: np.ndarray, after: np.ndarray, until: np.ndarray, out: np.ndarray) -> None:
    """``out[i]``: the first ``c`` in ``[after_i + 1, until_i]`` with ``w[c-1] > 0 >= w[c]``, or −1."""
    n = w.shape[0]
    for i in range(after.shape[0]):
        out[i] = -1
        for c in range(after[i] + 1, min(until[i], n - 1) + 1):
            if w[c - 1] > 0.0 and w[c] <= 0.0:
                out[i] = c
                break


@njit
def _first_up_crossing(w: np.ndarray, after: np.ndarray, until: np.ndarray, level: np.ndarray,
                       out: np.ndarray) -> None:
    """``out[i]``: the first ``c`` in ``[after_i + 1, until_i]`` with ``w[c-1] < level_i <= w[c]``, or −1."""
    n = w.shape[0]
    for i in range(after.shape[0]):
        out[i] = -1
        for c in range(after[i] + 1, min(until[i], n - 1) + 1):
            if w[c - 1] < level[i] and w[c] >= level[i]:
                out[i] = c
                break


def _mid_times(ts: np.ndarray, idx: np.ndarray, needed: np.ndarray) -> np.ndarray:
    """Middle of sample ``idx``'s interval, ``t[k] − (t[k] − t[k−1])/2`` (s), the median interval before the first.

    Only the ``needed`` entries are meaningful (the median is computed only if one of them is sample 0).
    """
    d = ts[idx] - ts[np.maximum(idx - 1, 0)]
    first = idx == 0
    if (first & needed).any():
        d[first] = np.median(np.diff(ts))
    return ts[idx] - 0.5 * d


def stride_directions(pos: np.ndarray, stances: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each stride's horizontal unit direction of travel (K, 2) (north, east), and the stances' middles (K + 1,).

    Stride ``i`` runs from the middle of stance ``i`` to the middle of stance ``i + 1``; its
    direction is that of the horizontal displacement between the two middles. A stride that
    does not move (shorter than 1 mm) takes the direction (1, 0).
    """
    pos = np.asarray(pos, dtype=float)
    a, b = stances[:, 0], stances[:, 1]
    mid = (a + b - 1) // 2
    d = pos[mid[1:], :2] - pos[mid[:-1], :2]
    norm = np.hypot(d[:, 0], d[:, 1])
    still = norm < 1e-3
    d = np.where(still[:, None], [1.0, 0.0], d / np.where(still, 1.0, norm)[:, None])
    return d, mid


def travel_directions(pos: np.ndarray, stances: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each sample's stride direction of travel: horizontal unit vector (N, 2) (north, east), and the stride index.

    The directions are those of :func:`stride_directions`. Samples before the first middle
    belong to the first stride, those after the last middle to the last one.
    """
    d, mid = stride_directions(pos, stances)
    stride = np.clip(np.searchsorted(mid, np.arange(len(pos)), side="right") - 1, 0, len(d) - 1)
    return d[stride], stride


@njit
def _sagittal_kernel(quat: np.ndarray, gyr: np.ndarray, mid: np.ndarray, d: np.ndarray, out: np.ndarray) -> None:
    """``out[k] = (C(q_k) ω_k) · (−d_e, d_n, 0)`` with ``d`` the direction of sample ``k``'s stride.

    Sample ``k`` belongs to the last stride ``i`` with ``mid[i] ≤ k`` (the first one before
    ``mid[0]``, the last one after the last middle), as in :func:`travel_directions`; ``C(q) ω``
    is :func:`footzoo.filters.strapdown.rotate`.
    """
    last = d.shape[0] - 1
    i = 0
    for k in range(quat.shape[0]):
        while i < last and mid[i + 1] <= k:
            i += 1
        north, east, _ = rotate(quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3], gyr[k, 0], gyr[k, 1], gyr[k, 2])
        out[k] = -north * d[i, 1] + east * d[i, 0]


def sagittal_rate(quat: np.ndarray, gyr: np.ndarray, pos: np.ndarray, stances: np.ndarray) -> np.ndarray:
    """The foot's sagittal angular rate ``ω_ml`` (N,) (rad/s, positive lifts the toe), whatever the mounting.

    ``ω_ml = (C_b^n ω_b) · (e_down × d)``: the angular rate rotated into NED with the attitude
    ``quat`` (scalar-first, body to NED) and projected on the horizontal axis to the right of
    the stride's direction of travel ``d`` (:func:`travel_directions`); ``e_down × (d_n, d_e, 0)
    = (−d_e, d_n, 0)``. Needs two stances or more. One compiled pass over the samples.

    Parameters
    ----------
    quat : (N, 4) ndarray
        Attitude, body to NED.
    gyr : (N, 3) ndarray
        Angular rate in the sensor frame (rad/s).
    pos : (N, 3) ndarray
        Position in NED (m).
    stances : (K + 1, 2) int ndarray
        ``(start, stop)`` sample indices (stop exclusive) of the stances, in order, K ≥ 1.
    """
    d, mid = stride_directions(pos, stances)
    quat = read_only(quat)
    out = np.empty(len(quat))
    _sagittal_kernel(quat, read_only(gyr), np.ascontiguousarray(mid, dtype=np.int64),
                     np.ascontiguousarray(d), out)
    return out


@njit(inline=True)
def _interval_middle(t: np.ndarray, k: int, first_interval: float) -> float:
    """The middle of sample ``k``'s interval ``(t[k-1], t[k]]`` (s); the first sample's is ``first_interval`` long."""
    return t[k] - 0.5 * (t[k] - t[k - 1]) if k > 0 else t[0] - 0.5 * first_interval


@njit(inline=True)
def _force(acc: np.ndarray, quat: np.ndarray, k: int, out: np.ndarray) -> None:
    """``out = C(q_k) f_k``: sample ``k``'s specific force in NED (as given where ``quat`` has no rows)."""
    fx, fy, fz = acc[k, 0], acc[k, 1], acc[k, 2]
    if quat.shape[0] == 0:
        out[0], out[1], out[2] = fx, fy, fz
    else:
        out[0], out[1], out[2] = rotate(quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3], fx, fy, fz)


@njit
def _contact_kernel(t: np.ndarray, first_interval: float, acc: np.ndarray, quat: np.ndarray, pitch: np.ndarray,
                    start: np.ndarray, stop: np.ndarray, window: float, level: float, least: float,
                    out: np.ndarray) -> None:
    """``out[i]``: when ``‖f_k − f_{a−1}‖`` first reaches ``level`` of its largest value over the samples ``k`` whose
    interval middles lie in ``[pitch_i, pitch_i + window)``, before ``stop_i`` (``a``: the first of them).

    The search for ``a`` starts at ``start_i`` (−1: no largest pitch, ``out[i] = pitch[i]``). Walks back from the
    largest change to the first sample of the run at or above the level and interpolates linearly between the
    interval middles (the change is 0 at ``a − 1``); never before ``pitch[i]``. ``out[i] = pitch[i]`` where the
    window has fewer than two samples or the largest change is below ``least``. Only the windows' samples are
    rotated (``f`` in NED with ``quat``, :func:`_force`).
    """
    n = t.shape[0]
    base, f = np.empty(3), np.empty(3)
    for i in range(pitch.shape[0]):
        out[i] = pitch[i]
        if start[i] < 0:
            continue
        a = start[i]
        while a < n and _interval_middle(t, a, first_interval) < pitch[i]:
            a += 1
        b, lim = a, min(stop[i], n)
        while b < lim and _interval_middle(t, b, first_interval) < pitch[i] + window:
            b += 1
        if a < 1 or b - a < 2:
            continue
        _force(acc, quat, a - 1, base)
        e = np.empty(b - a)
        for k in range(a, b):
            _force(acc, quat, k, f)
            e[k - a] = np.sqrt((f[0] - base[0]) ** 2 + (f[1] - base[1]) ** 2 + (f[2] - base[2]) ** 2)
        top = int(np.argmax(e))
        lev = level * e[top]
        if e[top] < least:
            continue
        k = top
        while k > 0 and e[k - 1] >= lev:
            k -= 1
        prev = e[k - 1] if k > 0 else 0.0
        frac = (lev - prev) / (e[k] - prev) if e[k] > prev else 1.0
        m0 = _interval_middle(t, a + k - 1, first_interval)
        when = m0 + frac * (_interval_middle(t, a + k, first_interval) - m0)
        out[i] = max(pitch[i], when)


def contact_times(t: np.ndarray, acc: np.ndarray, pitch: np.ndarray, stop: np.ndarray,
                  ok: np.ndarray, quat: np.ndarray | None = None) -> np.ndarray:
    """Initial contacts (s): the heel's impact after each swing's largest pitch (see the module docstring).

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    acc : (N, 3) ndarray
        Specific force in the sensor frame (m/s²).
    pitch : (K,) ndarray
        Each swing's largest pitch, the zero crossing of ``ω_ml`` (s).
    stop : (K,) int ndarray
        The search ends before this sample at the latest (the middle of the next stance).
    ok : (K,) bool ndarray
        Swings whose largest pitch was found; the others keep ``pitch``.
    quat : (N, 4) ndarray, optional
        Attitude (scalar-first, body to NED): the change is measured in the navigation frame,
        where the turning of gravity's projection does not count; without it, in the sensor frame.
        Either way only its norm counts, so any mounting gives the same contacts.
    """
    fn = "contact_times"
    ts = check_time(fn, t)
    n = len(ts)
    acc = check_samples(fn, "acc", acc, n, (3,), "(specific force, m/s²)")
    if quat is not None:
        quat = check_samples(fn, "quat", quat, n, (4,), "(attitude quaternions, scalar first)")
    pitch = np.asarray(pitch, dtype=float)
    if not (len(pitch) == len(np.asarray(stop)) == len(np.asarray(ok))):
        raise RecordingError(f"{fn}: pitch, stop and ok must have one entry per swing, got {len(pitch)}, "
                             f"{len(np.asarray(stop))} and {len(np.asarray(ok))}")
    return _contacts(ts, acc, pitch, stop, ok, quat)


def _contacts(ts: np.ndarray, acc: np.ndarray, pitch: np.ndarray, stop: np.ndarray, ok: np.ndarray,
              quat: np.ndarray | None) -> np.ndarray:
    """:func:`contact_times` on arrays already checked."""
    first_interval = float(np.median(np.diff(ts[:101]))) if len(ts) > 1 else 0.0
    start = np.where(ok, np.maximum(np.searchsorted(ts, pitch) - 1, 0), -1).astype(np.int64)
    q = read_only(np.zeros((0, 4)) if quat is None else quat)
    out = np.empty(len(pitch))
    _contact_kernel(read_only(ts), first_interval, read_only(acc), q, read_only(pitch), start,
                    np.asarray(stop, dtype=np.int64), CONTACT_WINDOW, CONTACT_LEVEL, CONTACT_MIN_CHANGE, out)
    return out


def detect_gait_events(t: np.ndarray, gyr: np.ndarray, stances: np.ndarray,
                       acc: np.ndarray | None = None, quat: np.ndarray | None = None) -> GaitEvents:
    """TO and IC of each swing between consecutive stances (see the module docstring for the definitions).

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    gyr : (N,) or (N, 3) ndarray
        The sagittal angular rate ``ω_ml`` (rad/s, positive lifts the toe; :func:`sagittal_rate`),
        or the angular rate in FRD (rad/s) of a sensor aligned with the foot, whose ``gyr[:, 1]``
        is then taken as ``ω_ml``.
    stances : (K + 1, 2) int ndarray
        ``(start, stop)`` sample indices (stop exclusive) of the stances, in order.
    acc : (N, 3) ndarray, optional
        Specific force in the sensor frame (m/s²). IC is the heel's impact after the largest
        pitch (:func:`contact_times`); without it, the largest pitch itself (about 20 ms early
        on real walks).
    quat : (N, 4) ndarray, optional
        Attitude (scalar-first, body to NED) in which the impact is measured (:func:`contact_times`).

    Returns
    -------
    GaitEvents
        One TO and one IC per swing (K of each).
    """
    fn = "detect_gait_events"
    # a sample is the mean over (t[k-1], t[k]] (footzoo's interval convention): it belongs to the middle
    # of its interval, computed for the event samples only (_mid_times)
    ts = check_time(fn, t)
    n = len(ts)
    w = check_samples(fn, "gyr", gyr, n, (0, 3), "(the sagittal rate, or the angular rate in FRD, rad/s)")
    w = np.ascontiguousarray(w if w.ndim == 1 else w[:, 1])
    stances = check_stances(fn, stances, n)
    if acc is not None:
        acc = check_samples(fn, "acc", acc, n, (3,), "(specific force, m/s²)")
    if quat is not None:
        quat = check_samples(fn, "quat", quat, n, (4,), "(attitude quaternions, scalar first)")
    k = len(stances) - 1
    if k < 1:
        empty = np.zeros(0)
        return GaitEvents(empty, empty, np.zeros(0, bool), empty)
    a, b = stances[:, 0], stances[:, 1]
    mid = (a + b - 1) // 2
    sw0, sw1 = b[:-1], a[1:]  # swing samples [sw0, sw1)
    # mid-swing peak p of the dorsi-flexion
    p = segment_argext(w, np.minimum(sw0, n - 1), np.maximum(sw1, sw0 + 1), largest=True).astype(np.int64)
    # push-off peak j: the fastest plantar-flexion between the previous mid-stance and p
    to_lo = np.minimum(mid[:-1], p)
    j = segment_argext(w, to_lo, np.maximum(p, to_lo + 1), largest=False)
    # its value at sub-sample resolution: the vertex of the parabola through the three samples around j
    jl, jr = np.maximum(j - 1, 0), np.minimum(j + 1, n - 1)
    den = w[jl] - 2.0 * w[j] + w[jr]
    inner = (den > 0) & (jl < j) & (j < jr)
    peak = np.where(inner, w[j] - (w[jl] - w[jr]) ** 2 / (8.0 * np.where(inner, den, 1.0)), w[j])
    # TO: the rate recovers to TO_LEVEL of the push-off peak, on the flank between j and p
    level = TO_LEVEL * np.minimum(peak, w[j])
    r = np.empty(k, dtype=np.int64)
    _first_up_crossing(read_only(w), j.astype(np.int64), p, level, r)
    # IC: first downward zero crossing after p, before the next mid-stance
    c = np.empty(k, dtype=np.int64)
    _first_down_crossing(read_only(w), p, mid[1:].astype(np.int64), c)
    ok = (c >= 0) & (r >= 0) & (w[p] > 0.0) & (w[j] < 0.0)
    c, r = np.where(ok, c, 1), np.where(ok, r, 1)
    # sub-sample times: linear interpolation between the middles of the two samples around each crossing
    ic = _crossing_times(ts, w, c, np.zeros(k), ok)
    to = _crossing_times(ts, w, r, level, ok)
    to = np.where(ok, to, ts[np.minimum(sw0, n - 1)])  # fall back to the stance edges (sample times)
    pitch = np.where(ok, ic, ts[np.minimum(sw1, n - 1)])
    ic = pitch if acc is None else np.where(ok, _contacts(ts, acc, pitch, mid[1:], ok, quat), pitch)
    return GaitEvents(to=to, ic=ic, from_rate=ok, largest_pitch=pitch)


def _crossing_times(ts: np.ndarray, w: np.ndarray, c: np.ndarray, level: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """When ``w`` passes ``level`` between samples ``c − 1`` and ``c`` (s): linear between their interval middles."""
    den = w[c] - w[c - 1]
    frac = np.where(ok, (level - w[c - 1]) / np.where(ok & (den != 0), den, 1.0), 0.0)
    t0, t1 = _mid_times(ts, c - 1, ok), _mid_times(ts, c, ok)
    return t0 + np.clip(frac, 0.0, 1.0) * (t1 - t0)
