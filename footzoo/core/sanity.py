"""Sensor sanity: impossible values, saturated (clipped) axes and isolated gyroscope spikes.

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
* **Gyro glitches** — a single sample whose angular rate differs from both
  neighbours by more than :data:`GLITCH_JUMP` (15 rad/s) while the neighbours
  agree (the spike height above the neighbours' change exceeds 15 rad/s). On the
  real recordings the largest such single-sample peak is 5.7 rad/s (gaitmap
  example, 204.8 Hz; PyShoe ≤ 1.7 rad/s, x-io 1.0 rad/s); one 40 rad/s spike in a
  walk turns the attitude by 0.2–0.4 rad and misplaces the end by metres.
  Reported with a :class:`~footzoo.core.errors.SensorWarning` listing the samples.

Findings also go to ``Recording.meta["sanity"]`` (and so to ``Result.recording``).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from .checks import ACC_MAX, GYR_MAX
from .conventions import GRAVITY
from .errors import RecordingError, SensorWarning

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
GLITCH_MAX_LEN = 3
_AXES = "xyz"


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


def find_bursts(x: np.ndarray, jump: float, max_len: int = GLITCH_MAX_LEN) -> np.ndarray:
    """Samples of bursts of 1 to ``max_len`` samples that stand out from the samples around them by more than ``jump``.

    A burst ``x[k:k+L]`` is a glitch when every one of its samples differs from both the sample
    before (``x[k-1]``) and the sample after (``x[k+L]``) by more than ``jump`` plus the change
    between those two (a real peak rises and falls over its samples; a glitch jumps and returns).
    For ``L = 1`` this is the single-sample spike test.

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
    big = np.einsum("ij,ij->i", step, step) > jump**2  # big[i]: x jumps between samples i and i+1
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
        for j in range(length):
            mid = x[k + j]
            height = np.minimum(height, np.minimum(np.linalg.norm(mid - before, axis=1),
                                                   np.linalg.norm(mid - after, axis=1)))
        k = k[height - np.linalg.norm(after - before, axis=1) > jump]
        found.extend((k[:, None] + np.arange(length)).ravel().tolist())
    return np.unique(np.asarray(found, dtype=int))


def find_glitches(gyr: np.ndarray) -> np.ndarray:
    """Samples of gyroscope bursts (1 to :data:`GLITCH_MAX_LEN` samples) above :data:`GLITCH_JUMP` (indices)."""
    return find_bursts(gyr, GLITCH_JUMP)


def find_acc_glitches(acc: np.ndarray) -> np.ndarray:
    """Samples of accelerometer bursts (1 to :data:`GLITCH_MAX_LEN` samples) above :data:`ACC_GLITCH_JUMP`."""
    return find_bursts(acc, ACC_GLITCH_JUMP)


def scan(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, name: str = "recording") -> dict[str, Any]:
    """Warn about saturation and glitches in a recording's signals (FRD, SI); return the findings.

    Impossible values are checked before, by :func:`check_impossible` (an error).
    """
    report: dict[str, Any] = {}
    saturated = find_saturation(t, acc, gyr)
    if saturated:
        report["saturation"] = saturated
        parts = [f"{s['axis']} at {s['value']:.6g} for {s['samples']} samples in {len(s['runs'])} run(s), "
                 f"first at sample {s['runs'][0][0]} (t = {s['first_t']:.3f} s)" for s in saturated]
        warnings.warn(
            f"{name}: sensor saturated (clipped): {'; '.join(parts)}. Velocity and position are "
            "underestimated there; use a sensor with a larger range. Details in meta['sanity']",
            SensorWarning, stacklevel=4,
        )
    report.update(warn_glitches(t, acc, gyr, name, stacklevel=5))
    return report


def warn_glitches(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, name: str = "recording",
                  offset: int = 0, stacklevel: int = 4) -> dict[str, list[int]]:
    """Warn about gyroscope and accelerometer glitches (:func:`find_bursts`); ``{"gyro_glitches": [...], ...}``.

    ``offset`` is added to the sample numbers (a live chunk's first sample's index in the stream).
    """
    report: dict[str, list[int]] = {}
    for key, label, arr, bound, unit in (("gyro_glitches", "gyroscope", gyr, GLITCH_JUMP, "rad/s"),
                                         ("acc_glitches", "accelerometer", acc, ACC_GLITCH_JUMP, "m/s²")):
        found = find_bursts(arr, bound)
        if not len(found):
            continue
        report[key] = [int(k) + offset for k in found]
        shown = ", ".join(f"{int(k) + offset} (t = {t[k]:.3f} s, |{'ω' if key[0] == 'g' else 'a'}| = "
                          f"{np.linalg.norm(arr[k]):.1f} {unit})" for k in found[:5])
        more = f" and {len(found) - 5} more" if len(found) > 5 else ""
        effect = ("a glitch turns the attitude and misplaces the track" if key[0] == "g" else
                  "a glitch kicks the velocity and misplaces the track")
        warnings.warn(
            f"{name}: {len(found)} isolated {label} spike(s) above {bound:g} {unit} at sample(s) {shown}{more} "
            f"(bursts of 1 to {GLITCH_MAX_LEN} samples): {effect}. Repair those samples (e.g. replace them by the "
            "neighbours' mean). Details in meta['sanity']",
            SensorWarning, stacklevel=stacklevel,
        )
    return report
