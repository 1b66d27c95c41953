"""Sensor sanity: impossible values, saturated (clipped) axes, glitches; the physics of a run's estimate.

Run by :func:`footzoo.core.data.validate_recording` on every :class:`~footzoo.core.data.Recording`
(FRD, SI) after the time and unit checks:

* **Impossible values** — any acc component beyond ±:data:`~footzoo.core.checks.ACC_MAX`
  (2000 m/s²) or gyr component beyond ±:data:`~footzoo.core.checks.GYR_MAX` (50 rad/s):
  no body-worn IMU measures them, the sample is corrupt. Error
  (:class:`~footzoo.core.errors.RecordingError`) naming the axis, sample and time;
  no result could be trusted, and a compiled kernel would divide by them.
* **Saturation** — a sensor that clips reads its full-scale value, exactly, for
  as long as the true signal stays beyond it. An axis whose largest (or smallest)
  value repeats on at least :data:`SATURATION_MIN_RUN` consecutive samples, and
  lies beyond :data:`SATURATION_FLOOR` of its sensor (2 g, 2 rad/s, so that a
  still or constant axis is not flagged), is reported — unless the axis is
  piecewise constant elsewhere too (more than :data:`PLATEAU_FRACTION` of its
  other consecutive samples repeat exactly: a noise-free simulation whose
  profile has flat tops; real recordings repeat at most 7 %): a
  :class:`~footzoo.core.errors.SensorWarning` naming the axis, the value, the sample
  and time ranges; the estimate is computed but its velocity and position
  underestimate the motion in those samples.
* **Glitches** — a burst of 1 to :data:`GLITCH_MAX_LEN` (20) samples whose angular rate jumps
  into it and out of it and stands more than :data:`GLITCH_JUMP` (15 rad/s) above the signal
  around it (up to 3 samples: above both neighbours plus the change between them; longer: off the
  chord between them, :func:`find_bursts`); the same for the specific force with
  :data:`ACC_GLITCH_JUMP` (400 m/s²). On the real recordings the largest
  such single-sample peak is 5.7 rad/s (gaitmap example, 204.8 Hz; PyShoe ≤ 1.7 rad/s, x-io
  1.0 rad/s) and no burst of any length up to 20 is found in any; one 40 rad/s spike in a walk turns the attitude by
  0.2–0.4 rad and misplaces the end by metres. Reported with a
  :class:`~footzoo.core.errors.SensorWarning` listing the samples.

Findings also go to ``Recording.meta["sanity"]`` (and so to ``Result.recording`` and
``Result.diagnostics["sensor"]``). Live, :class:`SignalScan` finds the same glitches chunk by
chunk, and saturation against each axis's extremes so far. :class:`EstimateScan` checks a
run's estimate (batch and live): no stance at all, drift while the data say still (its cause
checked against what the detector marked), and the gait against the ranges of human gait
(:mod:`footzoo.core.plausibility`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..kernels.jit import njit
from ..kernels.views import read_only
from .checks import ACC_MAX, GYR_MAX
from .conventions import GRAVITY
from .errors import RecordingError, SensorWarning, user_stacklevel
from .norms import row_norms, row_norms_squared
from .plausibility import MOTION_ACC, GaitScan, RateEvidence

#: Fewest consecutive samples at an axis's exact extreme reported as saturation.
SATURATION_MIN_RUN = 3
#: |value| below which an axis's extreme is never called saturation: acc (m/s²), gyr (rad/s).
SATURATION_FLOOR = {"acc": 2.0 * GRAVITY, "gyr": 2.0}
#: Fraction of exactly repeated consecutive samples (away from the rail) above which an axis is piecewise constant.
PLATEAU_FRACTION = 0.25
#: Height of a single-sample gyroscope spike above its neighbours' change reported as a glitch (rad/s).
GLITCH_JUMP = 15.0
#: Height of an accelerometer burst above its surroundings reported as a glitch (m/s²): above any foot impact
#: a body-worn sensor measures (the largest jump between two samples of the real recordings in the data
#: folder — PyShoe walking, running and stairs, x-io, gaitmap, Köroğlu — is 256 m/s², gaitmap's heel strikes).
ACC_GLITCH_JUMP = 400.0
#: Longest burst of samples reported as a glitch (a longer excursion is motion, or saturation).
GLITCH_MAX_LEN = 20
#: Longest burst measured against its two neighbours (:func:`find_bursts`); a longer one against the chord between them.
SHORT_GLITCH_LEN = 3
_AXES = "xyz"
_SQRT3 = math.sqrt(3.0)


def check_impossible(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> None:
    """Raise :class:`RecordingError` for any acc/gyr component no body-worn IMU can measure."""
    for name, arr, bound, unit in (("acc", acc, ACC_MAX, "m/s²"), ("gyr", gyr, GYR_MAX, "rad/s")):
        if arr.max() <= bound and arr.min() >= -bound:
            continue
        bad = np.abs(arr) > bound
        if bad.any():
            k, j = (int(v) for v in np.argwhere(bad)[0])
            raise RecordingError(
                f"{name}_{_AXES[j]} is {arr[k, j]:.6g} {unit} at sample {k} (t = {t[k]:.6f} s), and "
                f"{int(bad.any(axis=1).sum())} sample(s) in all exceed ±{bound:g} {unit}: beyond any body-worn IMU. "
                "Those samples are corrupt: drop or repair them (or check the declared unit)"
            )


def _runs(mask: np.ndarray, min_len: int) -> list[tuple[int, int]]:
    """``[start, end)`` sample ranges where ``mask`` is True for at least ``min_len`` samples."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    starts, ends = edges[::2], edges[1::2]
    keep = ends - starts >= min_len
    return [(int(s), int(e)) for s, e in zip(starts[keep], ends[keep], strict=True)]


def find_saturation(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> list[dict[str, Any]]:
    """Axes that sit at their exact extreme for :data:`SATURATION_MIN_RUN` samples or more.

    Returns
    -------
    list of dict
        One per axis and rail: ``axis`` (e.g. ``"acc_z"``), ``value`` (m/s² or
        rad/s), ``samples`` (count in runs), ``runs`` (list of [first, last] sample),
        ``first_t`` (s).
    """
    found = []
    for name, arr in (("acc", acc), ("gyr", gyr)):
        for j, x in enumerate(np.ascontiguousarray(arr.T)):
            for rail in {float(x.max()), float(x.min())}:  # a constant axis has one rail
                if abs(rail) < SATURATION_FLOOR[name]:
                    continue
                at_rail = x == rail
                if np.count_nonzero(at_rail) < SATURATION_MIN_RUN:
                    continue
                runs = _runs(at_rail, SATURATION_MIN_RUN)
                away = ~(at_rail[1:] | at_rail[:-1])
                if runs and away.any() and np.mean((x[1:] == x[:-1])[away]) > PLATEAU_FRACTION:
                    continue  # flat tops are the signal's shape (noise-free simulation), not clipping
                if runs:
                    found.append({"axis": f"{name}_{_AXES[j]}", "value": rail,
                                  "samples": int(sum(e - s for s, e in runs)),
                                  "runs": [[s, e - 1] for s, e in runs], "first_t": float(t[runs[0][0]])})
    return found


#: Fewest samples, and shortest time (s), of one sensor repeating its exact reading that are called a dropout.
FROZEN_MIN_SAMPLES = 10
FROZEN_MIN_DURATION = 0.1
_SENSORS = {"acc": "accelerometer", "gyr": "gyroscope"}


def find_frozen(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, offset: int = 0,
                history: dict[str, tuple[int, int]] | None = None) -> list[dict[str, Any]]:
    """Dropouts: one sensor repeats its exact three-axis reading while the other one moves.

    A sensor's noise changes every reading (the real recordings in the data folder repeat one at
    most twice in a row); a run of at least :data:`FROZEN_MIN_SAMPLES` samples and
    :data:`FROZEN_MIN_DURATION` s of one exact reading, while the other sensor's readings change
    in most of it, is a channel that dropped out (a lost connection, a logger that repeats the
    last value or fills zeros). Not reported: both sensors frozen together (a noise-free
    simulation at rest), and a sensor that repeats its readings exactly elsewhere too (more than
    :data:`PLATEAU_FRACTION` of its other consecutive samples: a noise-free signal with flat tops).
    ``history``: per sensor, ``(repeats, pairs)`` of the samples before these (live). Returns one dict
    per run: ``sensor`` (``"acc"``/``"gyr"``), ``first``, ``last`` (sample numbers, plus ``offset``),
    ``t0``, ``t1`` (s), ``value`` (the repeated reading).
    """
    found: list[dict[str, Any]] = []
    if len(t) < FROZEN_MIN_SAMPLES:
        return found
    same = {"acc": np.all(acc[1:] == acc[:-1], axis=1), "gyr": np.all(gyr[1:] == gyr[:-1], axis=1)}
    for name, other in (("acc", "gyr"), ("gyr", "acc")):
        before_repeats, before_pairs = (history or {}).get(name, (0, 0))
        repeats = before_repeats + int(same[name].sum())
        pairs = before_pairs + len(same[name])
        for s, e in _runs(same[name], FROZEN_MIN_SAMPLES - 1):  # pairs s..e-1: samples s..e
            if t[e] - t[s] < FROZEN_MIN_DURATION or np.mean(same[other][s:e]) > 0.5:
                continue
            away = pairs - (e - s)
            if away > 0 and (repeats - (e - s)) / away > PLATEAU_FRACTION:
                continue  # flat stretches are this signal's shape (noise-free), not a dropout
            found.append({"sensor": name, "first": s + offset, "last": e + offset, "t0": float(t[s]),
                          "t1": float(t[e]), "value": (acc if name == "acc" else gyr)[s].tolist()})
    return found


def warn_frozen(found: list[dict[str, Any]], name: str) -> None:
    """The warning of the dropouts :func:`find_frozen` found."""
    if not found:
        return
    parts = [f"the {_SENSORS[f['sensor']]} repeats one reading {np.round(f['value'], 4).tolist()} exactly from "
             f"t = {f['t0']:.3f} s to {f['t1']:.3f} s (samples {f['first']}–{f['last']}) while the "
             f"{_SENSORS['gyr' if f['sensor'] == 'acc' else 'acc']} moves" for f in found[:3]]
    more = f" and {len(found) - 3} more" if len(found) > 3 else ""
    warnings.warn(
        f"{name}: {'; '.join(parts)}{more}: that channel dropped out (a lost connection, or a logger that repeats its "
        "last value); every estimate from there is wrong. Cut the recording before the dropout, or repair it. "
        "Details in meta['sanity']['frozen']", SensorWarning, stacklevel=user_stacklevel())


def find_bursts(x: np.ndarray, jump: float, max_len: int = GLITCH_MAX_LEN) -> np.ndarray:
    """Samples of bursts of 1 to ``max_len`` samples that stand out from the samples around them by more than ``jump``.

    A burst ``x[k:k+L]`` starts with a jump into it and ends with one out of it (``x`` changes by
    more than ``jump`` from ``x[k-1]`` to ``x[k]`` and from ``x[k+L-1]`` to ``x[k+L]``). Up to
    :data:`SHORT_GLITCH_LEN` samples, it is a glitch when every one of its samples differs from both
    the sample before (``x[k-1]``) and the sample after (``x[k+L]``) by more than ``jump`` plus the
    change between those two (a real peak rises and falls over its samples; a glitch jumps and
    returns); for ``L = 1`` this is the single-sample spike test. A longer burst (4 to ``max_len``
    samples) is a glitch when every one of its samples lies more than ``jump`` off the straight
    line from ``x[k-1]`` to ``x[k+L]``: the signal under it keeps moving (a swing's angular rate
    changes by several rad/s in 0.1 s), the glitch stands on it. A clipped axis (flat at its
    sensor's full scale, reached without a jump) is not a burst: :func:`find_saturation` reports it.

    Parameters
    ----------
    x : (N, 3) array
        Angular rate (rad/s) or specific force (m/s²).
    jump : float
        Height above the surrounding change, in the unit of ``x``.
    max_len : int
        Longest burst (samples).

    Returns
    -------
    (k,) int array
        The glitch samples, sorted.
    """
    n = len(x)
    if n < 3:
        return np.zeros(0, dtype=int)
    step = np.diff(x, axis=0)
    big = row_norms_squared(step) > jump**2  # big[i]: x jumps between samples i and i+1
    found = []
    for length in range(1, max_len + 1):
        if n < length + 2:
            break
        # a burst starts with a jump into it (k-1 -> k) and ends with one out of it (k+L-1 -> k+L)
        k = np.flatnonzero(big[: n - length - 1] & big[length:]) + 1
        if not len(k):
            continue
        before, after = x[k - 1], x[k + length]
        height = np.full(len(k), np.inf)
        if length <= SHORT_GLITCH_LEN:  # above both neighbours, beyond the change between them
            for j in range(length):
                mid = x[k + j]
                height = np.minimum(height, np.minimum(np.linalg.norm(mid - before, axis=1),
                                                       np.linalg.norm(mid - after, axis=1)))
            height -= np.linalg.norm(after - before, axis=1)
        else:  # a longer burst rides on a signal that moves meanwhile: off the chord from before to after
            for j in range(length):
                chord = before + (after - before) * ((j + 1) / (length + 1))
                height = np.minimum(height, np.linalg.norm(x[k + j] - chord, axis=1))
        k = k[height > jump]
        found.extend((k[:, None] + np.arange(length)).ravel().tolist())
    return np.unique(np.asarray(found, dtype=int))


def find_glitches(gyr: np.ndarray) -> np.ndarray:
    """Samples of gyroscope bursts (1 to :data:`GLITCH_MAX_LEN` samples) above :data:`GLITCH_JUMP` (indices)."""
    return find_bursts(gyr, GLITCH_JUMP)


def find_acc_glitches(acc: np.ndarray) -> np.ndarray:
    """Samples of accelerometer bursts (1 to :data:`GLITCH_MAX_LEN` samples) above :data:`ACC_GLITCH_JUMP`."""
    return find_bursts(acc, ACC_GLITCH_JUMP)


def scan(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, name: str = "recording", warn: bool = True) -> dict[str, Any]:
    """Warn about saturation and glitches in a recording's signals (FRD, SI); return the findings.

    Impossible values are checked before, by :func:`check_impossible` (an error). ``warn=False``: the findings
    only, for signals whose findings were warned already (a stream's scans warn as the samples come).
    """
    report: dict[str, Any] = {}
    saturated = find_saturation(t, acc, gyr)
    if saturated:
        report["saturation"] = saturated
    if saturated and warn:
        parts = [f"{s['axis']} at {s['value']:.6g} for {s['samples']} samples in {len(s['runs'])} run(s), "
                 f"first at sample {s['runs'][0][0]} (t = {s['first_t']:.3f} s)" for s in saturated]
        warnings.warn(
            f"{name}: sensor saturated (clipped): {'; '.join(parts)}. Velocity and position are "
            "underestimated there; use a sensor with a larger range. Details in meta['sanity']",
            SensorWarning, stacklevel=user_stacklevel(),
        )
    glitches = _glitches(t, acc, gyr)
    report.update(glitches)
    if warn:
        _warn_found(t, acc, gyr, glitches, name)
    frozen = find_frozen(t, acc, gyr)
    if frozen:
        report["frozen"] = frozen
    if frozen and warn:
        warn_frozen(frozen, name)
    return report


def warn_glitches(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, name: str = "recording") -> dict[str, list[int]]:
    """Warn about gyroscope and accelerometer glitches (:func:`find_bursts`); ``{"gyro_glitches": [...], ...}``."""
    found = _glitches(t, acc, gyr)
    _warn_found(t, acc, gyr, found, name)
    return found


def _warn_found(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, found: dict[str, list[int]], name: str,
                offset: int = 0) -> None:
    """The warnings of glitches ``found`` (absolute sample numbers; ``offset``: that of the arrays' first sample)."""
    for key, label, arr, bound, unit in (("gyro_glitches", "gyroscope", gyr, GLITCH_JUMP, "rad/s"),
                                         ("acc_glitches", "accelerometer", acc, ACC_GLITCH_JUMP, "m/s²")):
        ks = found.get(key)
        if not ks:
            continue
        local = np.asarray(ks[:5]) - offset
        off = burst_heights(arr, np.asarray(ks) - offset)[: len(local)]
        shown = ", ".join(f"{k} (t = {t[j]:.3f} s, |{'ω' if key[0] == 'g' else 'a'}| = "
                          f"{np.linalg.norm(arr[j]):.1f} {unit}, {h:.1f} {unit} off)"
                          for k, j, h in zip(ks[:5], local, off, strict=True))
        more = f" and {len(ks) - 5} more" if len(ks) > 5 else ""
        effect = ("a glitch turns the attitude and misplaces the track" if key[0] == "g" else
                  "a glitch kicks the velocity and misplaces the track")
        warnings.warn(
            f"{name}: {len(ks)} isolated {label} spike(s) standing more than {bound:g} {unit} off the signal around "
            f"them (bursts of 1 to {GLITCH_MAX_LEN} samples, measured from the line between the samples before and "
            f"after) at sample(s) {shown}{more}: {effect}. Repair those samples (e.g. replace them by the "
            "neighbours' mean). Details in meta['sanity']",
            SensorWarning, stacklevel=user_stacklevel(),
        )


def burst_heights(x: np.ndarray, ks: np.ndarray) -> np.ndarray:
    """How far each glitch sample ``x[k]`` lies off the line between the samples around its burst (unit of ``x``).

    ``ks``: the sorted glitch samples (:func:`find_bursts`); consecutive ones form a burst, measured
    against the sample before it and the sample after it (the burst's own samples excluded).
    """
    ks = np.asarray(ks, dtype=int)
    out = np.zeros(len(ks))
    if not len(ks):
        return out
    breaks = np.flatnonzero(np.diff(ks) != 1) + 1
    for run in np.split(np.arange(len(ks)), breaks):
        a, b = ks[run[0]], ks[run[-1]]
        before, after = x[max(a - 1, 0)], x[min(b + 1, len(x) - 1)]
        for j, i in enumerate(run):
            chord = before + (after - before) * ((j + 1) / (len(run) + 1))
            out[i] = np.linalg.norm(x[ks[i]] - chord)
    return out


# --------------------------------------------------------------------------- the scans of a run (batch and live)
#: Still by the data: |ω| below this (rad/s) and |‖f‖ − g| below :data:`STILL_ACC` (m/s²).
STILL_GYR = 0.2
#: Largest |‖f‖ − g| of a still sample (m/s²).
STILL_ACC = 0.5
#: Shortest still period (s) whose estimated displacement is checked.
STILL_MIN_DURATION = 5.0
#: Displacement of the estimate over a still period above which it is reported as drift (m).
STILL_MAX_DRIFT = 0.25
#: Share of a drifting still period's samples taken for stance above which the drift is the correction's, not the
#: detector's.
STILL_STANCE_SHARE = 0.9
#: Below this distance (m) a run without any stance did not move: a velocity correction held it (a dedrift of a
#: swing that never ended), rather than drifting.
NO_STANCE_STILL_M = 0.05
#: Shortest motion after the still start (s) for which "no stance at all" is reported.
NO_STANCE_MIN_DURATION = 5.0
#: Share of the samples after the still start taken for stance from which, with the accelerometer showing
#: ALL_STANCE_MOTION s of motion (|‖f‖ − g| above MOTION_ACC), "stance all along" is reported: a walk is 60 % stance,
#: standing with a few steps less than 99 %.
ALL_STANCE_SHARE = 0.99
ALL_STANCE_MOTION = 1.0
#: Shortest quiet period (s) whose specific force far from g (outside [0.5 g, 1.5 g]) is reported as a scale fault.
SCALE_MIN_DURATION = 0.2
#: ... when ‖f‖ is steady there: its 10th to 90th percentiles within this fraction of its level (a still sensor
#: read in the wrong unit is steady; a moving foot whose gyroscope reads too little is not).
SCALE_STEADY = 0.25
#: ... and its direction steady: the mean of its unit vectors at least this long (about 11° around their mean).
SCALE_STEADY_DIRECTION = 0.98


class SignalScan:
    """Glitches and saturation in the signals, chunk by chunk (live), as :func:`scan` finds them in a recording.

    Each chunk is scanned for glitches with the last :data:`GLITCH_MAX_LEN` + 1 samples of the one
    before (a burst needs the sample before it and the one after it); each glitch is reported
    once, with the batch run's numbers. Saturation live: an axis that sits at its largest (or
    smallest) value so far, exactly, for :data:`SATURATION_MIN_RUN` samples, beyond
    :data:`SATURATION_FLOOR`, while the axis is not piecewise constant (the exact repeats of its
    consecutive samples elsewhere are at most :data:`PLATEAU_FRACTION`) — the batch rule with
    "so far" for the whole recording; reported once per axis.
    """

    def __init__(self, name: str = "stream"):
        self.name = name
        self.report: dict[str, Any] = {}
        self._t = np.zeros(0)  # the last GLITCH_MAX_LEN + 1 samples: time, and [acc | gyr] (m, 6)
        self._x = np.zeros((0, 6))
        self._k0 = 0  # absolute index of the tail's first sample
        self._done = -1  # last sample already reported
        # per axis (acc x, y, z, gyr x, y, z): the rails so far and the run at each ending at the last sample;
        # consecutive pairs and exact repeats seen (for the plateau rule)
        self._rails = [[-math.inf] * 6, [math.inf] * 6]
        self._runs = [[0] * 6, [0] * 6]
        self._pairs = 0
        self._repeats = [0] * 6
        self._saturated = [[False] * 6, [False] * 6]
        self._floor = [SATURATION_FLOOR["acc"]] * 3 + [SATURATION_FLOOR["gyr"]] * 3
        self._frozen_tail = np.zeros(0)  # time of the samples since the last change of either sensor's reading
        self._frozen_x = np.zeros((0, 6))
        self._frozen_k0 = 0
        self._frozen_open: dict[str, int | None] = {}  # per sensor: the first sample of its reported, open dropout
        self._vector_repeats = {"acc": 0, "gyr": 0}  # consecutive samples repeating a sensor's whole reading
        self._vector_pairs = 0

    def push(self, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray) -> dict[str, Any]:
        """Scan the next samples; the new findings (also added to :attr:`report`)."""
        x = np.hstack([acc, gyr])
        k0 = self._k0 + len(self._t)  # absolute index of the chunk's first sample
        joined_t, joined = np.concatenate([self._t, t]), np.vstack([self._x, x])
        step = joined[max(len(self._t) - 1, 0):]
        step = np.abs(step[1:] - step[:-1])
        new = self._saturation(t, x, k0, step)
        # a burst jumps by more than its height into it: some component by more than height / √3
        if len(step) and (step[:, 3:].max() > GLITCH_JUMP / _SQRT3 or step[:, :3].max() > ACC_GLITCH_JUMP / _SQRT3):
            fresh = {key: [k for k in ks if k > self._done]
                     for key, ks in _glitches(joined_t, joined[:, :3], joined[:, 3:], self._k0).items()}
            fresh = {key: ks for key, ks in fresh.items() if ks}
            if fresh:
                _warn_found(joined_t, joined[:, :3], joined[:, 3:], fresh, self.name, self._k0)
                for key, ks in fresh.items():
                    self.report.setdefault(key, []).extend(ks)
                self._done = max(max(ks) for ks in fresh.values())
                new.update(fresh)
        keep = GLITCH_MAX_LEN + 1
        self._k0 += max(len(joined_t) - keep, 0)
        self._t, self._x = joined_t[-keep:], joined[-keep:]
        pairs = np.vstack([self._frozen_x[-1:], x]) if len(self._frozen_x) else x
        if len(pairs) > 1:
            self._vector_pairs += len(pairs) - 1
            self._vector_repeats["acc"] += self._tail_repeats(pairs, slice(0, 3))
            self._vector_repeats["gyr"] += self._tail_repeats(pairs, slice(3, 6))
        frozen = self._frozen(t, x, k0)
        if frozen:
            new["frozen"] = frozen
        return new

    @staticmethod
    def _tail_repeats(x: np.ndarray, cols: slice) -> int:
        return int(np.all(x[1:, cols] == x[:-1, cols], axis=1).sum()) if len(x) > 1 else 0

    def _frozen(self, t: np.ndarray, x: np.ndarray, k0: int) -> list[dict[str, Any]]:
        """Dropouts (:func:`find_frozen`) live, each reported once while it lasts.

        The samples since the start of each sensor's current streak of one exact reading are kept
        (until the streak is reported or ends: bounded), so a dropout spread over many pushes is found.
        """
        tail_t, tail_x = np.concatenate([self._frozen_tail, t]), np.vstack([self._frozen_x, x])
        base = self._frozen_k0 if len(self._frozen_tail) else k0
        history = {name: (self._vector_repeats[name] - self._tail_repeats(tail_x, cols),
                          self._vector_pairs - max(len(tail_t) - 1, 0))
                   for name, cols in (("acc", slice(0, 3)), ("gyr", slice(3, 6)))}
        found = [f for f in find_frozen(tail_t, tail_x[:, :3], tail_x[:, 3:], base, history)
                 if self._frozen_open.get(f["sensor"]) is None]
        for f in found:
            self._frozen_open[f["sensor"]] = f["first"]
        keep = len(tail_t) - 1
        for name, cols in (("acc", slice(0, 3)), ("gyr", slice(3, 6))):
            flags = np.all(tail_x[1:, cols] == tail_x[:-1, cols], axis=1)
            streak = len(flags)
            while streak > 0 and flags[streak - 1]:
                streak -= 1
            if streak == len(flags):  # its reading changed at the last sample: any dropout of it is over
                self._frozen_open[name] = None
            elif self._frozen_open.get(name) is None:
                keep = min(keep, streak)  # an open streak not reported yet: keep its samples
        self._frozen_tail, self._frozen_x, self._frozen_k0 = tail_t[keep:], tail_x[keep:], base + keep
        if found:
            self.report.setdefault("frozen", []).extend(found)
            warn_frozen(found, self.name)
        return found

    def _saturation(self, t: np.ndarray, x: np.ndarray, k0: int, step: np.ndarray) -> dict[str, Any]:
        """Runs at each axis's rails so far (vectorised over the chunk and the axes; one sample: scalar)."""
        self._pairs += len(step)
        found: list[dict[str, Any]] = []
        if len(x) == 1:  # a pushed sample: the same rule in scalars (numpy's per-call cost dominates here)
            row, rails, runs = x[0].tolist(), self._rails, self._runs
            for j, d in enumerate(step[0].tolist() if len(step) else ()):
                if d == 0.0:
                    self._repeats[j] += 1
            for side in (0, 1):
                for j in range(6):
                    v, r = row[j], rails[side][j]
                    if (v > r) if side == 0 else (v < r):
                        rails[side][j], runs[side][j] = v, 1
                    elif v == r:
                        runs[side][j] += 1
                    else:
                        runs[side][j] = 0
                    if runs[side][j] >= SATURATION_MIN_RUN and not self._saturated[side][j]:
                        self._hit(side, j, v, runs[side][j], k0, t[0], found)
        else:
            self._repeats = [n + int(c) for n, c in zip(self._repeats, (step == 0).sum(axis=0), strict=True)]
            for side, pick in ((0, np.maximum), (1, np.minimum)):
                rail = pick(np.asarray(self._rails[side]), (x.max(axis=0) if side == 0 else x.min(axis=0)))
                before = np.asarray(self._runs[side])
                before[rail != np.asarray(self._rails[side])] = 0
                at = x == rail
                touched = np.flatnonzero(at.any(axis=0))  # only the axes with a sample at the rail have a run
                self._rails[side] = rail.tolist()
                runs = [0] * 6
                if len(touched):
                    idx = np.arange(len(x))[:, None]
                    # the run at the rail ending at each sample: its index minus that of the last sample off it
                    run = idx - np.maximum.accumulate(np.where(at[:, touched], -1 - before[None, touched], idx),
                                                      axis=0)
                    for c, j in enumerate(touched.tolist()):
                        runs[j] = int(run[-1, c])
                        longest = int(run[:, c].max())
                        if longest >= SATURATION_MIN_RUN and not self._saturated[side][j]:
                            i = int(np.argmax(run[:, c] >= SATURATION_MIN_RUN))
                            self._hit(side, j, float(rail[j]), longest, k0 + i, t[i], found)
                self._runs[side] = runs
        if not found:
            return {}
        self.report.setdefault("saturation", []).extend(found)
        parts = [f"{f['axis']} at {f['value']:.6g} for {SATURATION_MIN_RUN} samples or more from sample {f['first']} "
                 f"(t = {f['t']:.3f} s at sample {f['first'] + SATURATION_MIN_RUN - 1})" for f in found]
        warnings.warn(
            f"{self.name}: sensor saturated (clipped): {'; '.join(parts)}. Velocity and position are "
            "underestimated there; use a sensor with a larger range. Details in Stream.sensor",
            SensorWarning, stacklevel=user_stacklevel(),
        )
        return {"saturation": found}

    def _hit(self, side: int, j: int, rail: float, longest: int, k: int, t: float, found: list[dict[str, Any]]) -> None:
        """Report axis ``j`` at its rail (sample ``k`` the run's third, at time ``t``) unless the floor or the
        plateau rule excuses it."""
        if abs(rail) < self._floor[j]:
            return
        away = self._pairs - longest
        if away > 0 and (self._repeats[j] - (longest - 1)) / away > PLATEAU_FRACTION:
            return  # flat tops are the signal's shape (noise-free simulation), not clipping
        self._saturated[side][j] = True
        found.append({"axis": f"{'acc' if j < 3 else 'gyr'}_{_AXES[j % 3]}", "value": rail,
                      "first": k - (SATURATION_MIN_RUN - 1), "t": float(t)})


def _glitches(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, offset: int = 0) -> dict[str, list[int]]:
    out = {}
    for key, arr, bound in (("gyro_glitches", gyr, GLITCH_JUMP), ("acc_glitches", acc, ACC_GLITCH_JUMP)):
        found = find_bursts(arr, bound)
        if len(found):
            out[key] = [int(k) + offset for k in found]
    return out


@njit
def _quiet_runs(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray, t_start: float,
                gravity: float) -> tuple[np.ndarray, np.ndarray, int, int]:
    """One pass over a chunk for :class:`EstimateScan`: its still runs, its quiet runs off g, its stances.

    A sample is quiet when |ω|² < :data:`STILL_GYR`²; a quiet sample is still when |‖f‖ − g| <
    :data:`STILL_ACC`, and off g when |‖f‖ − g| > 0.5 g (the squares summed in column order, as
    :func:`~footzoo.core.norms.row_norms` does). Returns the runs ``[s, e)`` of the still samples and
    of the off-g ones, (2, M) and (2, K) sample indices into the chunk; the stance samples after
    ``t_start`` (s) and the first sample after it (−1: none). 1 byte per sample of scratch.
    """
    n = acc.shape[0]
    flags = np.empty(n, np.uint8)  # 0: neither, 1: still, 2: quiet and off g
    counts = np.zeros(3, np.int64)
    stances, first, prev = 0, -1, 0
    for i in range(n):
        w = 0.0
        for j in range(gyr.shape[1]):
            w += gyr[i, j] * gyr[i, j]
        f = 0
        if w < STILL_GYR * STILL_GYR:
            a = 0.0
            for j in range(acc.shape[1]):
                a += acc[i, j] * acc[i, j]
            off = abs(math.sqrt(a) - gravity)
            f = 1 if off < STILL_ACC else (2 if off > 0.5 * gravity else 0)
        flags[i] = f
        if f != prev and f:
            counts[f] += 1
        prev = f
        if t[i] > t_start:
            stances += stance[i]
            if first < 0:
                first = i
    still = np.empty((2, counts[1]), np.int64)
    off_g = np.empty((2, counts[2]), np.int64)
    filled = np.zeros(3, np.int64)
    prev = 0
    for i in range(n + 1):
        f = flags[i] if i < n else 0
        if f != prev:
            if prev:  # a run of prev ends at i
                (still if prev == 1 else off_g)[1, filled[prev] - 1] = i
            if f:
                (still if f == 1 else off_g)[0, filled[f]] = i
                filled[f] += 1
        prev = f
    return still, off_g, stances, first


class EstimateScan:
    """Physics of the estimate, fed the final estimates chunk by chunk (a batch run: one chunk of all).

    * **no stance at all** — no stance sample after the still start, over more than
      :data:`NO_STANCE_MIN_DURATION` s of motion: the velocity was never reset and the track is
      pure strapdown drift (a detector that never fires on this motion, with the guard off).
    * **stance all along** — at least :data:`ALL_STANCE_SHARE` of the samples after the still start
      taken for stance while the accelerometer shows :data:`ALL_STANCE_MOTION` s of motion: the
      velocity is held at zero through the swings (a threshold far too high).
    * **drift while still** — the data say the sensor lies still (|ω| < :data:`STILL_GYR`,
      |‖f‖ − g| < :data:`STILL_ACC`) for :data:`STILL_MIN_DURATION` s or longer, and the estimate
      moves more than :data:`STILL_MAX_DRIFT` m meanwhile: the detector misses that stillness, or
      (when it takes at least :data:`STILL_STANCE_SHARE` of those samples for stance) the velocity
      correction does not hold a standing foot.
    * **accelerometer scale** — the gyroscope is quiet (|ω| < :data:`STILL_GYR`) for
      :data:`SCALE_MIN_DURATION` s or longer while ‖f‖ stays outside [0.5 g, 1.5 g]: a foot that
      does not turn does not fall or push at half or twice g for that long, steadily (10th–90th
      percentiles of ‖f‖ within :data:`SCALE_STEADY` of its level, its direction within about 11°:
      :data:`SCALE_STEADY_DIRECTION`), so the accelerometer's unit or scale is wrong there (e.g. a
      stream whose unit changed to g mid-way).
    * **human gait** — the strides against the ranges of human gait, and the wrong rate or
      gyroscope unit that explains them (:class:`~footzoo.core.plausibility.GaitScan`; the
      gyroscope–accelerometer evidence of the rate comes with :meth:`use_evidence`).

    Findings are warned (:class:`~footzoo.core.errors.SensorWarning`, with the samples and the
    fix) as soon as they are known, and kept in :attr:`report`.
    """

    def __init__(self, t_start: float, gravity: float = GRAVITY, name: str = "recording", detector: str = "detector",
                 corrections: Sequence[tuple[str, float | None]] | None = None):
        """``corrections``: the pipeline's corrections as ``(name, hold_after)``, ``hold_after`` the stillness hold's
        duration (s) where the correction has one (:mod:`footzoo.corrections.stillness`), else None; they word the
        fix of a drift while still that the detector did mark. None: not known."""
        self.t_start, self.gravity, self.name, self.detector = t_start, gravity, name, detector
        self.corrections = None if corrections is None else list(corrections)
        self.report: dict[str, Any] = {}
        self._stance = 0
        self._after = 0  # samples after the still start
        self._moving = 0.0  # seconds of them with |‖f‖ − g| above MOTION_ACC
        self._t_prev: float | None = None
        self._first: tuple[float, np.ndarray] | None = None  # (t, pos) of the first sample after the still start
        self._last: tuple[float, np.ndarray] | None = None
        self._run: dict[str, Any] | None = None  # the still run open at the end of the last chunk
        self._off: tuple[int, float] | None = None  # a quiet run off g open at the chunk's end: (k, t)
        self.gait = GaitScan(name, gravity)  # the strides against the ranges of human gait (core.plausibility)

    def push(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, stance: np.ndarray,
             pos: np.ndarray) -> None:
        """The next final estimates: sample indices ``k``, time (s), signals (FRD, SI), stance, position (m)."""
        if not len(t):
            return
        # read-only views, whoever passes them (a batch run its recording's arrays, a stream its buffers):
        # the scan then needs one compiled variant, the one a wheel ships
        t, acc, gyr, ok = (read_only(a, d) for a, d in ((t, float), (acc, float), (gyr, float), (stance, bool)))
        self.gait.push(k, t, acc, gyr, ok, pos)
        self._plausibility()
        still, off_g, stances, first = _quiet_runs(t, acc, gyr, ok, float(self.t_start), float(self.gravity))
        self._stance += stances
        self._count_motion(t, acc)
        if first >= 0 and self._first is None:
            self._first = (float(t[first]), pos[first].copy())
        self._last = (float(t[-1]), pos[-1].copy())
        self._scale(k, t, acc, gyr, off_g)
        starts, ends = still
        if self._run is not None and not (len(starts) and starts[0] == 0):  # the open run ended at the chunk's start
            self._close(self._run)
            self._run = None
        # only the runs that can be long enough: the open ones at either end, and the long ones in between
        long = (t[ends - 1] - t[starts] >= STILL_MIN_DURATION) | (starts == 0) | (ends == len(t))
        for s, e in zip(starts[long].tolist(), ends[long].tolist(), strict=True):
            run = self._run if (s == 0 and self._run is not None) else {
                "first": int(k[s]), "t0": float(t[s]), "pos0": pos[s].copy(), "drift": 0.0, "stance": 0, "n": 0}
            run["stance"] += int(np.count_nonzero(ok[s:e]))
            run["n"] += e - s
            moved = pos[s:e] - run["pos0"]
            run["drift"] = max(run["drift"], float(row_norms(moved).max()))
            run["last"], run["t1"] = int(k[e - 1]), float(t[e - 1])
            if e == len(t):
                self._run = run
            else:
                self._close(run)
                if s == 0:
                    self._run = None

    def _count_motion(self, t: np.ndarray, acc: np.ndarray) -> None:
        """Count the samples after the still start and the seconds of them that move (for "stance all along")."""
        dt = np.diff(t, prepend=t[0] if self._t_prev is None else self._t_prev)
        self._t_prev = float(t[-1])
        after = t > self.t_start
        self._after += int(np.count_nonzero(after))
        moving = after & (np.abs(row_norms(acc) - self.gravity) > MOTION_ACC)
        self._moving += float(np.sum(dt[moving]))

    def _all_stance(self) -> None:
        """Report a detector that took (nearly) every sample for stance while the foot moved."""
        if not self._after or self._first is None or self._last is None or "gyro_unit" in self.gait.report:
            return  # a gyroscope that reads 57 times too little keeps any |ω| detector in stance: named as such
        share = self._stance / self._after
        if share < ALL_STANCE_SHARE or self._moving < ALL_STANCE_MOTION:
            return
        moved = float(np.linalg.norm(self._last[1] - self._first[1]))
        self.report["all_stance"] = {"stance_share": share, "moving_s": self._moving, "distance_m": moved}
        warnings.warn(
            f"{self.name}: the detector {self.detector!r} takes {share:.1%} of the samples after the still start for "
            f"stance, while the accelerometer shows {self._moving:.1f} s of motion (|‖f‖ − g| above {MOTION_ACC:g} "
            f"m/s²): the velocity is held at zero through the swings, so the track ({moved:.2f} m) and the strides "
            "are not the foot's. Lower its threshold, or choose a detector made for this motion. Details in "
            "diagnostics['sensor']",
            SensorWarning, stacklevel=user_stacklevel(),
        )

    def _scale(self, k: np.ndarray, t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, runs: np.ndarray) -> None:
        """Report (once) a quiet gyroscope with a specific force far from g for SCALE_MIN_DURATION s.

        ``runs``: (2, K) the chunk's runs ``[s, e)`` of quiet samples (|ω| < STILL_GYR) with ‖f‖
        outside [0.5 g, 1.5 g] (:func:`_quiet_runs`); ``acc`` the chunk's specific force (m/s²). A
        gyroscope that repeats one exact reading there is not quiet but dropped out (:func:`find_frozen`
        names it): not a scale fault.
        """
        if "acc_scale" in self.report:
            return
        if not runs.shape[1] and self._off is None:
            return
        carried, self._off = self._off, None
        slow = self.gait.report.get("gyro_unit", {}).get("sample")  # from there on the gyroscope reads too little
        for s, e in zip(runs[0].tolist(), runs[1].tolist(), strict=True):
            start = carried if (s == 0 and carried is not None) else (int(k[s]), float(t[s]))
            if slow is not None and slow <= start[0]:
                return  # its quiet says nothing of the foot: the gait scan named the gyroscope's unit
            if e - s > 1 and np.all(gyr[s + 1:e] == gyr[s:e - 1]):  # a frozen gyroscope, not a quiet one
                continue
            if t[e - 1] - start[1] >= SCALE_MIN_DURATION:
                norms = row_norms(acc[s:e])
                level = float(np.median(norms - self.gravity)) + self.gravity  # ‖f‖ there
                heading = np.linalg.norm(np.mean(acc[s:e] / np.maximum(norms, 1e-12)[:, None], axis=0))
                if (np.percentile(norms, 90) - np.percentile(norms, 10) > SCALE_STEADY * level
                        or heading < SCALE_STEADY_DIRECTION):
                    continue  # f swings: a foot in motion whose gyroscope reads too little, not a scale
                self._warn_scale(start, float(t[e - 1]), level)
                return
            if e == len(t):  # open at the chunk's end: the next chunk may continue it
                self._off = start

    def _warn_scale(self, start: tuple[int, float], t1: float, level: float) -> None:
        self.report["acc_scale"] = {"first": start[0], "t0": start[1], "magnitude": level}
        unit = (" (≈ 1: in g? convert to m/s² by × 9.81)" if abs(level - 1.0) < 0.1 else
                " (≈ 1000: in mg? × 0.00981)" if abs(level - 1000.0) < 100.0 else "")
        warnings.warn(
            f"{self.name}: from t = {start[1]:.2f} s (sample {start[0]}) the gyroscope is quiet for "
            f"{t1 - start[1]:.1f} s while the accelerometer reads {level:.3g}{unit}, far from g = "
            f"{self.gravity:.2f} m/s²: its unit or scale is wrong from there. Check the unit of the samples "
            "(live: every packet in m/s²). Details in diagnostics['sensor']",
            SensorWarning, stacklevel=user_stacklevel(),
        )

    def _close(self, run: dict[str, Any]) -> None:
        duration = run["t1"] - run["t0"]
        if duration < STILL_MIN_DURATION or run["drift"] <= STILL_MAX_DRIFT:
            return
        share = run["stance"] / max(run["n"], 1)
        finding = {"first": run["first"], "last": run["last"], "t0": run["t0"], "t1": run["t1"],
                   "duration_s": duration, "drift_m": run["drift"], "stance_share": share}
        self.report.setdefault("still_drift", []).append(finding)
        if share >= STILL_STANCE_SHARE:
            why = f"the detector {self.detector!r} takes {share:.0%} of these samples for stance, yet " + self._held()
        else:
            why = (f"the detector {self.detector!r} misses this stillness ({share:.0%} of these samples are stance), "
                   "so the velocity drifts. Raise its threshold, choose another detector, or keep the stance guard "
                   "on (guards.max_swing)")
        warnings.warn(
            f"{self.name}: the sensor lies still from t = {run['t0']:.2f} s to {run['t1']:.2f} s (samples "
            f"{run['first']}–{run['last']}, {duration:.1f} s: |ω| < {STILL_GYR:g} rad/s, |a| ≈ g) but the estimate "
            f"moves {run['drift']:.2f} m meanwhile: {why}. Details in diagnostics['sensor']",
            SensorWarning, stacklevel=user_stacklevel(),
        )

    def use_evidence(self, evidence: RateEvidence) -> None:
        """Weigh the gyroscope–accelerometer evidence of the rate (a ConsistencyScan fed the same samples) in the
        plausibility of the gait (:class:`~footzoo.core.plausibility.GaitScan`)."""
        self.gait.use_evidence(evidence)
        self._plausibility()

    def dropouts(self, found: list[dict[str, Any]]) -> None:
        """Sensor dropouts (:func:`find_frozen`'s findings): the gait's plausibility judges the rate before them."""
        if found:
            self.gait.exclude_from(min(int(d["first"]) for d in found))

    def _plausibility(self) -> None:
        if self.gait.report:
            self.report["plausibility"] = self.gait.report

    def _held(self) -> str:
        """Why a foot the detector marked as standing still moved, and the fix, from the corrections."""
        hold = "the stillness hold (hold_after > 0 s, footzoo.corrections.stillness)"
        if self.corrections == []:
            return ("no velocity correction uses the stances, so nothing stops the velocity's drift: add one "
                    f"(corrections: e.g. zupt, which also has {hold})")
        if self.corrections is None:
            return f"the velocity correction does not hold the standing foot: use a correction with {hold}"
        off = [n for n, h in self.corrections if h is not None and h <= 0]
        names = ", ".join(n for n, _ in self.corrections)
        if off:
            return f"{names} does not hold the standing foot: its stillness hold is off; set hold_after > 0 on {off[0]}"
        on = [(n, h) for n, h in self.corrections if h is not None]
        if on:
            return (f"{names} does not hold the standing foot, though its stillness hold is on (hold_after = "
                    f"{on[0][1]:g} s on {on[0][0]}): compare hold_std with this drift (footzoo.corrections.stillness)")
        return f"{names} does not hold the standing foot: add or use a correction with {hold}"

    def finish(self) -> dict[str, Any]:
        """End of the data: the still run open at the end, no stance at all, the gait's plausibility; the findings."""
        if self._run is not None:
            self._close(self._run)
            self._run = None
        self.gait.finish()
        self._plausibility()
        self._all_stance()
        if self._first is not None and self._last is not None and self._stance == 0:
            duration = self._last[0] - self._first[0]
            if duration > NO_STANCE_MIN_DURATION:
                moved = float(np.linalg.norm(self._last[1] - self._first[1]))
                self.report["no_stance"] = {"t0": self._first[0], "t1": self._last[0], "distance_m": moved}
                track = (f"so the track ({moved:.1f} m from there to the end) is pure drift"
                         if moved >= NO_STANCE_STILL_M else
                         f"so the track stays where it was ({moved:.2f} m from there to the end): the velocity "
                         "correction had no stance to end a swing with, and the foot's motion is lost")
                warnings.warn(
                    f"{self.name}: no stance from t = {self._first[0]:.2f} s to the end ({duration:.1f} s): the "
                    f"detector {self.detector!r} never fired after the still start and the velocity was never "
                    f"reset, {track}. Choose a detector made "
                    "for this motion or tune its threshold, and keep the stance guard on (guards.max_swing). Details "
                    "in diagnostics['sensor']",
                    SensorWarning, stacklevel=user_stacklevel(),
                )
        return self.report
