"""How the sensor sits on the foot, measured from the gait: a wrong (right-handed) axis map is named with its fix.

A right-handed but wrong axis map is physically the data of another mounting: the attitude,
the trajectory and footzoo's gait events (navigation-frame sagittal rate,
:func:`footzoo.analysis.gait_events.sagittal_rate`) come out the same. What it breaks is every
reading of a *sensor axis* as a foot axis: the foot walks backwards along the sensor's x axis,
or ``gyr_y`` turns negative when the toe lifts, which reverses the heel-strike/toe-off sequence of
any body-frame method (Rampp et al. 2015 on ``gyr_y``, a foot-flat detector on one axis, a
heading taken from the sensor's x axis).

The foot frame of stride ``i`` is ``F_i = [d_i, e_down × d_i, e_down]`` (forward along the
stride's direction of travel ``d_i``, right, down, in NED; :func:`travel_directions`). At the
middle of each stance (foot flat) the sensor's axes in it are ``A_i = F_iᵀ C_b^n``, so that
``v_foot = A_i · v_sensor``: the rows of ``A_i`` are the FRD axes of the foot in sensor
coordinates, the same form as an axis map (:mod:`footzoo.io.axes`). Its element-wise median over
the stances before the strides of at least 0.5 m (a turn on the spot has no direction of travel),
made orthonormal again (nearest rotation, SVD), is the measured mounting. Three
symptoms are flagged:

* **walks backwards**: the sensor's x axis points against the direction of travel,
  ``A[0, 0] < −0.5`` (more than 120° away);
* **x across**: the sensor's x axis is more than 75° away from the direction of travel either way,
  ``|A[0, 0]| < cos 75°``, while ``gyr_y`` is not the foot's pitch rate (``|correlation| < 0.8``, below):
  an axis map that takes a vertical or sideways sensor axis for x. On the visible recordings read with
  their own maps ``|A[0, 0]|`` is at least 0.48 (a sensor turned on the foot by a few tens of degrees is
  not flagged). With ``gyr_y`` the pitch rate (0.92 in such runs) a direction of travel across x comes
  from a track that went wrong (a detector with no velocity correction: strides of 4.6 m on a 1.2 m
  simulated walk), not from the map, and is not named as the map;
* **pitch reversed**: the sensor's y axis points left, ``A[1, 1] < −0.5``: ``gyr_y`` turns
  negative when the toe lifts. The report gives the correlation of ``gyr_y`` with the sagittal
  rate ``ω_ml`` over the swings too (near −1 for a reversed pitch); it is not the criterion,
  because a sensor turned on the foot by a few tens of degrees sees a scaled pitch rate with the
  same shape (correlation ±0.6 on gaitmap's example turned 90° about z).

The fix is the proper signed permutation nearest to ``A`` (:func:`nearest_axis_map`): the axis map
that, applied on top of the one used, makes the sensor's axes the foot's FRD axes. A sensor
mounted upside down on purpose (PyShoe's 2018-02-22 trial) shows the same symptom as a map that
flips y and z: the warning says so.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..core.conventions import axis_map_text, proper_axis_maps, quat_to_matrix
from ..core.errors import FormatError, SensorWarning, user_stacklevel
from ..io.axes import axes_fix, parse_axes
from ..kernels.jit import njit
from .gait_events import sagittal_rate, stride_directions

#: Fewest strides for a mounting estimate.
MIN_STRIDES = 3
#: Shortest stride (m, horizontal) whose direction of travel counts: a turn on the spot or a shuffle has none.
MIN_STRIDE_LENGTH = 0.5
#: ``A[0, 0]`` (``A[1, 1]``) below this: the sensor's x axis points backwards (its y axis left), cos 120°.
REVERSED_COS = -0.5
#: ``|A[0, 0]|`` below this: the sensor's x axis is more than 75° from the direction of travel either way (cos 75°).
ACROSS_COS = math.cos(math.radians(75.0))
#: ``|corr(gyr_y, ω_ml)|`` at or above this: ``gyr_y`` is the foot's pitch rate, so the map's y axis is right.
PITCH_AXIS_CORRELATION = 0.8
#: ``trace(Pᵀ A)`` of the nearest axis map at least this far ahead of the runner-up, else no map is named (0.1:
#: about 4° nearer, for maps 40-60° away; ``d trace / dθ = 2 sin θ``).
AMBIGUOUS_TRACE = 0.1


def nearest_rotation(a: np.ndarray) -> np.ndarray:
    """The rotation matrix nearest to ``a`` (3, 3) in the Frobenius norm (SVD, determinant +1)."""
    u, _, vt = np.linalg.svd(a)
    s = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    return u @ s @ vt


def nearest_axis_map(a: np.ndarray) -> np.ndarray | None:
    """The proper signed permutation nearest to the rotation ``a`` (3, 3), or None if two are about as near.

    Nearest in the Frobenius norm among the 24 (:func:`footzoo.core.conventions.proper_axis_maps`): the
    largest ``trace(Pᵀ a) = 1 + 2 cos θ``, ``θ`` the angle between them. A sensor tilted on the foot by a few tens
    of degrees (the IPOL set's MTw sits 30-45° pitched) may have two axes nearest the same foot axis; the
    permutation nearest as a whole then still names its map, unless the runner-up is less than
    :data:`AMBIGUOUS_TRACE` behind (a sensor turned about 45°, halfway between two maps): None. When each row's
    largest entry is in its own column, that permutation is the nearest.
    """
    maps = proper_axis_maps()
    score = np.array([float(np.sum(p * a)) for p in maps])
    order = np.argsort(score)[::-1]
    best = maps[order[0]]
    k = np.argmax(np.abs(a), axis=1)
    if np.array_equal(np.abs(best).argmax(axis=1), k):  # each row's largest entry: no axis is in doubt
        return best
    return best if score[order[0]] - score[order[1]] >= AMBIGUOUS_TRACE else None


@njit
def swing_correlation(gyr: np.ndarray, w: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Pearson's correlation of ``gyr[:, 1]`` (rad/s) with ``w`` (rad/s) over the samples ``lo[i] … hi[i] − 1``.

    The swings: disjoint, increasing. Two passes (the means, then the centred sums), as
    ``np.corrcoef``; NaN with fewer than 3 samples or a constant ``gyr_y``.
    """
    m, sx, sy = 0, 0.0, 0.0
    for i in range(lo.shape[0]):
        for k in range(lo[i], hi[i]):
            sx += gyr[k, 1]
            sy += w[k]
            m += 1
    if m < 3:
        return math.nan
    mx, my = sx / m, sy / m
    sxx, syy, sxy = 0.0, 0.0, 0.0
    for i in range(lo.shape[0]):
        for k in range(lo[i], hi[i]):
            dx, dy = gyr[k, 1] - mx, w[k] - my
            sxx += dx * dx
            syy += dy * dy
            sxy += dx * dy
    if not (sxx > 0.0 and syy > 0.0):
        return math.nan
    return min(max(sxy / math.sqrt(sxx) / math.sqrt(syy), -1.0), 1.0)


def mounting_report(quat: np.ndarray, gyr: np.ndarray, pos: np.ndarray, stances: np.ndarray,
                    sagittal: np.ndarray | None = None) -> dict[str, Any]:
    """The sensor's mounting on the foot measured from the strides (see the module docstring).

    Parameters
    ----------
    quat : (N, 4) ndarray
        Attitude, body (sensor) to NED, scalar first.
    gyr : (N, 3) ndarray
        Angular rate in the sensor frame (rad/s).
    pos : (N, 3) ndarray
        Position in NED (m).
    stances : (K + 1, 2) int ndarray
        The real stances ``(start, stop)`` (:func:`footzoo.analysis.strides.real_stances`).
    sagittal : (N,) ndarray, optional
        ``sagittal_rate(quat, gyr, pos, stances)`` (rad/s) when the caller has it already.

    Returns
    -------
    dict
        ``strides``, ``strides_used`` (those of at least :data:`MIN_STRIDE_LENGTH`); with at
        least :data:`MIN_STRIDES` used also ``sensor_in_foot`` (3 × 3 list,
        ``v_foot = A · v_sensor``), ``x_forward`` (``A[0, 0]``), ``pitch_rate_correlation``
        (``gyr_y`` against the sagittal rate, over the swings), ``walks_backwards``, ``x_across``,
        ``pitch_reversed`` (bool) and ``suggested_axes`` (the proper signed permutation nearest
        to ``A``, ``[x, y, z]`` when the axes are right, None when no permutation is near).
    """
    k = len(stances) - 1
    out: dict[str, Any] = {"strides": int(max(k, 0))}
    if k < MIN_STRIDES:
        return out
    a0, b0 = stances[:, 0], stances[:, 1]
    mid = (a0 + b0 - 1) // 2
    pos = np.asarray(pos, dtype=float)
    d, _ = stride_directions(pos, stances)  # d[i]: stride i, from the middle of stance i
    # the stance before each long stride, with that stride's direction (turns on the spot and shuffles left out)
    long = np.hypot(*(pos[mid[1:], :2] - pos[mid[:-1], :2]).T) >= MIN_STRIDE_LENGTH
    out["strides_used"] = int(long.sum())
    if long.sum() < MIN_STRIDES:
        return out
    mid, d = mid[:-1][long], d[long]
    fwd = np.column_stack([d, np.zeros(len(mid))])
    right = np.column_stack([-d[:, 1], d[:, 0], np.zeros(len(mid))])
    down = np.broadcast_to([0.0, 0.0, 1.0], fwd.shape)
    foot = np.stack([fwd, right, down], axis=1)  # rows: foot axes in NED
    a = nearest_rotation(np.median(foot @ quat_to_matrix(np.asarray(quat, dtype=float)[mid]), axis=0))
    w = sagittal_rate(quat, gyr, pos, stances) if sagittal is None else sagittal
    swings = np.ascontiguousarray(b0[:-1], dtype=np.int64), np.ascontiguousarray(a0[1:], dtype=np.int64)
    corr = swing_correlation(np.ascontiguousarray(gyr, dtype=float), np.ascontiguousarray(w, dtype=float), *swings)
    p = nearest_axis_map(a)
    out.update(sensor_in_foot=np.round(a, 4).tolist(), x_forward=float(a[0, 0]), y_right=float(a[1, 1]),
               pitch_rate_correlation=corr, walks_backwards=bool(a[0, 0] < REVERSED_COS),
               x_across=bool(abs(a[0, 0]) < ACROSS_COS and abs(corr) < PITCH_AXIS_CORRELATION),
               pitch_reversed=bool(a[1, 1] < REVERSED_COS),
               suggested_axes=None if p is None else axis_map_text(p))
    return out


def warn_mounting(report: dict[str, Any], name: str | None = None, axes: str | None = None,
                  axis_fault: str | None = None) -> None:
    """A :class:`SensorWarning` when the report finds the foot walking backwards, across the sensor's x axis, or
    its pitch reversed.

    ``axis_fault``: the gyroscope axis fault the gyroscope–accelerometer scan named
    (:class:`footzoo.filters.consistency.ConsistencyScan`, e.g. ``"gyr_y has the wrong sign"``), if any. Such an
    axis turns the attitude the mounting is measured from, so no axis map is named then: the report
    records why under ``withheld`` and the scan's own warning gives the fix.

    ``axes`` is the axis map the recording was read with (``Recording.meta["axes"]``): the fix is the
    map to read the file with instead, spelled as the ``axes`` option every reader takes
    (:func:`footzoo.io.axes.axes_fix`).
    """
    symptoms = []
    if report.get("walks_backwards"):
        symptoms.append(f"the foot walks backwards along the sensor's x axis (x · direction of travel = "
                        f"{report['x_forward']:+.2f})")
    if report.get("x_across"):
        angle = math.degrees(math.acos(min(1.0, abs(report["x_forward"]))))
        symptoms.append(f"the sensor's x axis is not along the foot: it is {angle:.0f}° from the direction of travel "
                        f"(x · direction of travel = {report['x_forward']:+.2f})")
    if report.get("pitch_reversed"):
        symptoms.append(f"the sensor's y axis points left (y · right = {report['y_right']:+.2f}): gyr_y is negative "
                        "when the toe lifts, so heel strike and toe-off swap places for a method reading gyr_y")
    if not symptoms:
        return
    if axis_fault:
        report["withheld"] = (f"{'; '.join(symptoms)}: not warned, because {axis_fault} (see "
                              "diagnostics['sensor']['consistency']), which turns the attitude this is measured from")
        return
    where = f"recording {name!r}: " if name else ""
    suggested = report.get("suggested_axes")
    how = ""
    if suggested:
        try:  # the map to read the raw file with: the fix applied after the map used
            rows = parse_axes(suggested) @ (parse_axes(axes) if axes else np.eye(3))
            suggested, how = axis_map_text(rows), f": {axes_fix(rows)}"
        except FormatError:
            suggested = f"{suggested} on top of the axis map it was read with ({axes})"
    motion = (" and the foot did not really move so (walking backwards or sideways, measured on "
              f"{report.get('strides_used', 0)} of {report.get('strides', 0)} strides)"
              if report.get("walks_backwards") or report.get("x_across") else "")
    fix = (f"if the sensor is not mounted so on purpose (e.g. upside down){motion}, the axis map is wrong: read it "
           f"with the axis map {suggested} (x toward the toe, y right, z down, in sensor axes){how}"
           if suggested else "check the axis map (x toward the toe, y right, z down) and read the file with the "
                             "right one: --option 'axes=[...]' on the command line, footzoo.load(path, axes=...)")
    warnings.warn(f"{where}{'; '.join(symptoms)}. footzoo's strides and gait events do not depend on the "
                  f"mounting; {fix}. Details in Result.diagnostics['mounting']", SensorWarning,
                  stacklevel=user_stacklevel())
