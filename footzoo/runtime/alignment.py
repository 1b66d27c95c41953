"""Initial attitude, and the accelerometer's gain, from the still period at the start of a recording.

A still sensor measures gravity: the magnitude of its mean specific force over the still start is
g. An accelerometer whose reading there is off by more than :data:`ACC_GAIN_TOLERANCE` has a gain
(scale-factor) error, and :func:`accelerometer_gain` gives the factor that brings it back to g.
Uncorrected, such an error hides every later stand-still from the stance detectors (their test
compares ‖f‖ with g: on the IPOL gait set a left-foot MTw reads 10.04–10.44 m/s² at rest, and the
recommended detector took none of a 6 s stand for stance) and the excess, integrated where no
stance stops it, lifts the track by metres on a flat floor (8-6_lf ended 9.3 m up; scaled, 0.07 m).
Measured on those files, the error is a gain, not an offset: on the 14 trials whose left foot is
scaled, its median stride length was 1.2–7.1 % (mean 3.8 %) longer than the right foot's of the same
walk, and is −2.8 to +2.5 % (mean −0.9 %) scaled.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..core.conventions import GRAVITY, quat_conj, quat_from_rotvec, quat_mul
from ..core.errors import RecordingError, SensorWarning, user_stacklevel
from ..orientation.fqa import fqa_sample


def initial_attitude(
    t: np.ndarray,
    acc: np.ndarray,
    gyr: np.ndarray,
    mag: np.ndarray | None,
    duration: float = 0.5,
    max_gyr: float = 0.6,
) -> np.ndarray:
    """Attitude (body -> NED) at the first sample, from the first still period.

    The first window of ``duration`` seconds in which |ω| stays below
    ``max_gyr`` is found; roll and pitch come from its mean specific force
    (gravity), heading from its mean magnetometer reading when given (FQA),
    otherwise heading 0 (north). When the recording does not start still, the
    attitude is carried back from that window to the first sample by
    integrating the gyro backwards, ``q_{k-1} = q_k ⊗ exp(−ω_k dt_k / 2)``.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    acc, gyr : (N, 3) ndarray
        Specific force (m/s²) and angular rate (rad/s), FRD.
    mag : (N, 3) ndarray or None
        Magnetic field (any unit), FRD.
    duration : float
        Length of the still period used (s).
    max_gyr : float
        Largest |ω| (rad/s) accepted as still during that period.

    Raises
    ------
    RecordingError
        When the recording has no still period of that length.
    """
    start, stop = first_still_window(t, gyr, duration, max_gyr)
    a = acc[start:stop].mean(axis=0)
    m = mag[start:stop].mean(axis=0) if mag is not None else None
    # FQA of this one sample, its per-sample function run as Python: the same arithmetic as the
    # compiled batch kernel, which a first run would otherwise compile (about half a second)
    args = (*a, *m, True) if m is not None else (*a, 0.0, 0.0, 0.0, False)
    q = np.array(getattr(fqa_sample, "py_func", fqa_sample)(*(float(x) for x in args[:6]), args[6]))
    for k in range(start, 0, -1):
        q = quat_mul(q, quat_conj(quat_from_rotvec(gyr[k] * (t[k] - t[k - 1]))))
    return q


#: How long (s) the first samples are looked at to tell a recording that starts in motion.
MOVING_START = 0.05


def warn_moving_start(t: np.ndarray, gyr: np.ndarray, duration: float = 0.5, max_gyr: float = 0.6,
                      name: str = "recording") -> bool:
    """Warn (a :class:`~footzoo.core.errors.SensorWarning`) when the recording starts in motion; whether it does.

    Every pipeline starts from rest: zero velocity at the first sample, its attitude carried back from the first
    still period. A recording cut in the middle of a stride (its first :data:`MOVING_START` s turning faster than
    ``max_gyr`` rad/s, in the median) breaks that: the swing it starts in is integrated from a velocity that is not
    zero, and the whole track is shifted by that swing's error (a simulated walk cut mid-swing: 1.7 m). The 78
    visible recordings (PyShoe, x-io, gaitmap, Köroğlu, IPOL) start at most at 0.11 rad/s. ``t`` (s), ``gyr``
    (rad/s), ``duration`` (s) and ``max_gyr`` (rad/s) as in :func:`first_still_window`.
    """
    n = int(np.searchsorted(t, t[0] + MOVING_START, side="right"))
    rate = float(np.median(np.linalg.norm(gyr[: max(n, 2)], axis=1)))
    if rate <= max_gyr:
        return False
    try:
        start, _ = first_still_window(t, gyr, duration, max_gyr)
    except RecordingError:
        return True  # no still period at all: the alignment's error names it
    where = f"the first still period begins at t = {t[start]:.2f} s"
    warnings.warn(
        f"{name}: the recording starts in motion (the gyroscope turns at {rate:.2f} rad/s over its first "
        f"{MOVING_START * 1e3:.0f} ms; {where}). Every estimate starts from rest, so the velocity of the swing it "
        "starts in is unknown and the whole track is shifted by that swing's error (metres). Start the recording with "
        "the foot at rest, or cut it where the foot stands (a stance)",
        SensorWarning, stacklevel=user_stacklevel())
    return True


#: Largest relative difference between the still start's specific force and g that is left as it is. Calibrated
#: sensors read well inside it (PyShoe's VICON trials, x-io and Köroğlu's recordings: at most 1.8 %, the IPOL set's
#: right feet 0.4–1.6 %); the IPOL set's left-foot MTw reads 2.3–6.4 % above g.
ACC_GAIN_TOLERANCE = 0.03

#: The gains (g over the still start's reading) a scale-factor error can need: a MEMS accelerometer's is a few per
#: cent (the IPOL set's MTw: 6.4 %); a reading 20 % or more off g is a unit or a column, not a gain.
ACC_GAIN_RANGE = (0.8, 1.25)

#: Largest standard deviation of ‖f‖ over the still start, relative to g, for its mean to be taken as gravity: a
#: sensor at rest scatters by its noise (0.1-0.5 % of g for the recordings above), a start whose gyroscope is quiet
#: but whose foot accelerates (a slide, a tap) scatters more and says nothing about the gain.
ACC_GAIN_QUIET = 0.02


def accelerometer_gain(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, gravity: float, duration: float = 0.5,
                       max_gyr: float = 0.6, name: str = "recording") -> float:
    """The factor (dimensionless) that brings the accelerometer's still reading to ``gravity``, or 1.

    The still window is the one of :func:`initial_attitude` (:func:`first_still_window`); the
    gain is ``gravity / ‖mean f‖`` over it when ``‖mean f‖`` differs from ``gravity`` (m/s²) by
    more than :data:`ACC_GAIN_TOLERANCE` and ‖f‖ is quiet there (:data:`ACC_GAIN_QUIET`), with a
    :class:`~footzoo.core.errors.SensorWarning` that names the reading; else exactly 1 (a calibrated
    sensor's samples are used as they are). A start that far off g but not quiet (it may be a moving
    foot) is left uncorrected with a ``SensorWarning`` naming the reading, its scatter and the fix.
    ``t`` (s), ``acc`` (m/s², FRD), ``gyr`` (rad/s), ``duration`` (s), ``max_gyr`` (rad/s).
    """
    start, stop = first_still_window(t, gyr, duration, max_gyr)
    still = float(np.linalg.norm(acc[start:stop].mean(axis=0)))
    if abs(still / gravity - 1.0) <= ACC_GAIN_TOLERANCE:
        return 1.0
    gain = gravity / still if still > 0 else float("inf")
    if not ACC_GAIN_RANGE[0] <= gain <= ACC_GAIN_RANGE[1]:
        warnings.warn(
            f"{name}: the accelerometer reads {still:.3g} m/s² in the still start (t = {t[start]:.2f}-"
            f"{t[stop - 1]:.2f} s), {100.0 * (still / gravity - 1.0):+.1f} % off g = {gravity:g} m/s²: no "
            "scale-factor error is that large, so the specific force is not rescaled. Check the accelerometer's unit "
            "(acc_unit) and which columns are read as acc_* and gyr_*",
            SensorWarning, stacklevel=user_stacklevel())
        return 1.0
    reading = (f"{name}: the accelerometer reads {still:.3f} m/s² in the still start (t = {t[start]:.2f}-"
               f"{t[stop - 1]:.2f} s), {100.0 * (still / gravity - 1.0):+.1f} % off g = {gravity:g} m/s²")
    scatter = float(np.std(np.linalg.norm(acc[start:stop], axis=1)))
    if scatter > ACC_GAIN_QUIET * gravity:  # the foot moves in its "still" start: no measure of the gain
        warnings.warn(
            f"{reading}, but with the gyroscope quiet ‖f‖ scatters by {scatter:.2f} m/s² "
            f"({100.0 * scatter / gravity:.1f} % of g, more than the {100.0 * ACC_GAIN_QUIET:g} % of a sensor at "
            "rest): the start is too restless to tell a gain error from motion, so the gain is not corrected. If "
            "the accelerometer's unit or scale is wrong, declare it (the reader's acc_unit option) or calibrate the "
            f"sensor; otherwise start the recording with the foot at rest for init.duration = {duration:g} s",
            SensorWarning, stacklevel=user_stacklevel())
        return 1.0
    warnings.warn(
        f"{reading}: a gain (scale-factor) error, which would hide the stand-stills from the stance detector and lift "
        f"the track. The run scales the specific force by {gravity / still:.4f} (result.diagnostics['acc_gain']); "
        "calibrate the sensor to remove this",
        SensorWarning, stacklevel=user_stacklevel())
    return gravity / still


def first_still_window(t: np.ndarray, gyr: np.ndarray, duration: float, max_gyr: float) -> tuple[int, int]:
    """Sample range ``[start, stop)`` of the first ``duration`` s with |ω| ≤ ``max_gyr`` throughout.

    Reads the recording from the start in growing chunks and stops at the first such window, so a
    long recording that starts still costs almost nothing.
    """
    n = len(t)
    m = min(n, 4096)
    while True:
        still = np.linalg.norm(gyr[:m], axis=1) <= max_gyr
        edges = np.flatnonzero(still[1:] != still[:-1]) + 1
        bounds = np.concatenate([[0], edges, [m]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            # a run cut by the end of the chunk (b == m < n) may still grow: decided only if already long enough
            if still[a] and t[b - 1] - t[a] >= duration:
                stop = int(np.searchsorted(t, t[a] + duration, side="right"))
                if stop - a >= 2:
                    return int(a), stop
        if m == n:
            break
        m = min(n, 4 * m)
    level = float(np.median(np.linalg.norm(gyr, axis=1))) if n else 0.0
    if abs(level / GRAVITY - 1.0) < 0.15:  # a "gyroscope" that reads g: the accelerometer's columns
        raise RecordingError(
            f"the recording has no still period: its gyroscope turns at {level:.2f} rad/s in the median, which is "
            f"g = {GRAVITY} m/s² in number; the accelerometer's and the gyroscope's columns look swapped. Check which "
            "columns are read as acc_* and gyr_* (a sidecar's columns, the file's header)"
        )
    raise RecordingError(
        f"the recording has no still period of {duration} s (|ω| ≤ init.max_gyr = {max_gyr} rad/s) "
        "to align the initial attitude; record a moment of rest, shorten init.duration or raise init.max_gyr"
    )
