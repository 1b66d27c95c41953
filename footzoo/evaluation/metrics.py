"""Trajectory metrics: path length, loop closure, ARMSE after yaw alignment, PyShoe's error.

All positions are (N, 3) arrays in NED (m). Horizontal means north-east.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pandas as pd

from ..kernels.jit import njit


def path_length(pos: np.ndarray, horizontal: bool = True) -> float:
    """Length (m) of the travelled path: sum of distances between samples.

    ``horizontal`` uses north and east only (the walked distance on a floor).
    """
    p = np.asarray(pos, dtype=float)[:, : 2 if horizontal else 3]
    return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))


def loop_closure(pos: np.ndarray) -> dict[str, float]:
    """End-to-start distance of a walk that should end where it started.

    Returns
    -------
    dict
        ``loop_closure_3d_m``, ``loop_closure_xy_m`` (m), ``path_length_m``
        (horizontal, m) and ``loop_closure_xy_pct`` / ``loop_closure_3d_pct`` (%
        of the horizontal path length).
    """
    p = np.asarray(pos, dtype=float)
    d = p[-1] - p[0]
    length = path_length(p)
    e3, exy = float(np.linalg.norm(d)), float(np.linalg.norm(d[:2]))
    def pct(e):
        return (100.0 * e / length if length > 0 else float("nan"))
    return {
        "loop_closure_3d_m": e3,
        "loop_closure_xy_m": exy,
        "path_length_m": length,
        "loop_closure_3d_pct": pct(e3),
        "loop_closure_xy_pct": pct(exy),
    }


def yaw_alignment(est: np.ndarray, ref: np.ndarray) -> float:
    """Rotation ψ (rad) about the vertical that best maps ``est`` onto ``ref``.

    Both start at the origin; ψ minimises ``Σ |R_z(ψ) e_i − r_i|²`` over the
    horizontal components, whose closed form is
    ``ψ = atan2(Σ (e_n r_e − e_e r_n), Σ (e_n r_n + e_e r_e))``.
    """
    e = np.asarray(est, dtype=float) - est[0]
    r = np.asarray(ref, dtype=float) - ref[0]
    num = np.sum(e[:, 0] * r[:, 1] - e[:, 1] * r[:, 0])
    den = np.sum(e[:, 0] * r[:, 0] + e[:, 1] * r[:, 1])
    return float(np.arctan2(num, den))


def rotate_about_vertical(pos: np.ndarray, psi: float) -> np.ndarray:
    """Rotate positions (N, 3) by ψ (rad) about the NED z axis (north toward east)."""
    c, s = np.cos(psi), np.sin(psi)
    p = np.asarray(pos, dtype=float).copy()
    n, e = p[:, 0].copy(), p[:, 1].copy()
    p[:, 0] = c * n - s * e
    p[:, 1] = s * n + c * e
    return p


def armse(est: np.ndarray, ref: np.ndarray) -> float:
    """3-D RMS position error (m) after both start at the origin and a least-squares yaw alignment.

    ``sqrt(mean_i |R_z(ψ*) (e_i − e_0) − (r_i − r_0)|²)`` with ψ* from
    :func:`yaw_alignment`. Vertical axes are not rotated.
    """
    e = np.asarray(est, dtype=float) - est[0]
    r = np.asarray(ref, dtype=float) - ref[0]
    _check_same_length(e, r)
    e = rotate_about_vertical(e, yaw_alignment(e, r))
    return float(np.sqrt(np.mean(np.sum((e - r) ** 2, axis=1))))


def pyshoe_error(est: np.ndarray, ref: np.ndarray, align_distance: float = 0.8) -> float:
    """PyShoe's 2-D trial error (m), as defined by Wagstaff et al.'s evaluation code.

    Both trajectories start at the origin. The estimate is rotated about the
    vertical once, so that its position at the first sample whose horizontal
    straight-line distance from the start reaches ``align_distance`` (0.8 m)
    points in the same direction as the reference at that sample (sample 300
    when it never gets that far, as PyShoe does). The error is the mean over
    samples of ``sqrt((dn² + de²) / 2)``.
    """
    e = np.asarray(est, dtype=float) - est[0]
    r = np.asarray(ref, dtype=float) - ref[0]
    _check_same_length(e, r)
    dist = np.linalg.norm(e[:, :2], axis=1)
    far = np.flatnonzero(dist >= align_distance)
    k = int(far[0]) if far.size else min(300, len(e) - 1)
    psi = np.arctan2(r[k, 1], r[k, 0]) - np.arctan2(e[k, 1], e[k, 0])
    e = rotate_about_vertical(e, psi)
    d = e[:, :2] - r[:, :2]
    return float(np.mean(np.sqrt(np.mean(d**2, axis=1))))


def _check_same_length(e: np.ndarray, r: np.ndarray) -> None:
    if e.shape != r.shape:
        raise ValueError(f"estimate {e.shape} and reference {r.shape} must have the same shape")


def trajectory_metrics(pos: np.ndarray, truth_pos: np.ndarray | None, closed_loop: bool) -> dict[str, float]:
    """The metrics a run can compute: loop closure (closed walks) and ARMSE/PyShoe error (with a reference)."""
    out: dict[str, float] = {"path_length_m": path_length(pos)}
    if closed_loop:
        out.update(loop_closure(pos))
    if truth_pos is not None:
        out["armse_3d_m"] = armse(pos, truth_pos)
        out["pyshoe_error_m"] = pyshoe_error(pos, truth_pos)
    return out


# --------------------------------------------------------------------------- stance detection


@njit
def _runs_kernel(mask: np.ndarray, out: np.ndarray) -> int:
    """The True runs of ``mask`` as ``(start, stop)`` rows of ``out``; returns their count."""
    k = 0
    n = mask.shape[0]
    for i in range(n):
        if mask[i] and (i == 0 or not mask[i - 1]):
            out[k, 0] = i
        if mask[i] and (i == n - 1 or not mask[i + 1]):
            out[k, 1] = i + 1
            k += 1
    return k


def intervals(mask: np.ndarray) -> np.ndarray:
    """``(start, stop)`` index pairs (stop exclusive) of the True runs of a boolean mask, (K, 2) int."""
    m = np.ascontiguousarray(mask, dtype=bool).reshape(-1)
    out = np.empty(((len(m) + 1) // 2, 2), dtype=np.int64)
    return out[:_runs_kernel(m, out)].copy()


def stance_scores(stance: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """Per-sample precision, recall and F1 of a stance mask (stance = positive class)."""
    s, r = np.asarray(stance, bool), np.asarray(truth, bool)
    tp = float(np.sum(s & r))
    precision = tp / max(float(s.sum()), 1.0)
    recall = tp / max(float(r.sum()), 1.0)
    f1 = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    return {"precision": precision, "recall": recall, "f1": f1, "accuracy": float(np.mean(s == r))}


def step_detection(stance: np.ndarray, truth: np.ndarray, t: np.ndarray) -> dict[str, float]:
    """Step-level comparison of detected and true stance phases (the gait-phase error rate).

    Matching rule: a true stance phase is detected correctly when exactly one
    detected stance phase overlaps it and that detected phase overlaps no other
    true stance phase. Every other true phase is an error (missed: no overlap;
    split: two or more overlap; merged: its detected phase spans two true
    phases), and so is every detected phase that overlaps no true phase
    (false step). ``error_rate = (wrong true phases + false steps) / true phases``,
    the measure of Nguyen & La's "1 wrong in 36 steps". Timing errors are over
    the correct matches (detected − true, s): onset at the phase's first sample,
    offset at its last.
    """
    det, ref = intervals(stance), intervals(truth)
    overlap = (det[:, None, 0] < ref[None, :, 1]) & (ref[None, :, 0] < det[:, None, 1])
    per_ref = overlap.sum(axis=0)
    per_det = overlap.sum(axis=1)
    correct, onset, offset = 0, [], []
    for j in range(len(ref)):
        if per_ref[j] == 1:
            i = int(np.flatnonzero(overlap[:, j])[0])
            if per_det[i] == 1:
                correct += 1
                onset.append(t[det[i, 0]] - t[ref[j, 0]])
                offset.append(t[det[i, 1] - 1] - t[ref[j, 1] - 1])
    false_steps = int(np.sum(per_det == 0))
    n = len(ref)
    return {
        "true_steps": n,
        "detected_steps": len(det),
        "correct": correct,
        "missed": int(np.sum(per_ref == 0)),
        "split": int(np.sum(per_ref > 1)),
        "false_steps": false_steps,
        "step_count_error": len(det) - n,
        "error_rate": (n - correct + false_steps) / n if n else float("nan"),
        "onset_error_mean_s": float(np.mean(onset)) if onset else float("nan"),
        "offset_error_mean_s": float(np.mean(offset)) if offset else float("nan"),
        "onset_error_abs_max_s": float(np.max(np.abs(onset))) if onset else float("nan"),
        "offset_error_abs_max_s": float(np.max(np.abs(offset))) if offset else float("nan"),
    }


# --------------------------------------------------------------------------- strides


#: Older simulator step tables (before unit names) -> reference column names.
_LEGACY_STEP_NAMES = {"swing_start": "to_s", "swing_end": "end_s", "stride_length": "stride_length_m",
                      "heading": "heading_rad", "fpa": "fpa_rad"}


def reference_steps(steps: pd.DataFrame) -> pd.DataFrame:
    """A reference stride table with footzoo's column names (see :class:`footzoo.core.data.Truth`).

    The simulator's step table (``swing_start`` = toe-off, ``swing_end`` =
    initial contact, ``stride_length``, ``heading``, ``fpa``) is renamed and given
    ``start_s``, the previous stride's initial contact (NaN for the first).
    """
    renames = {k: v for k, v in _LEGACY_STEP_NAMES.items() if k in steps.columns and v not in steps.columns}
    if not renames and "swing_end" not in steps.columns:
        return steps  # footzoo's names already: nothing to copy
    out = steps.rename(columns=renames)
    if "swing_end" in steps.columns:  # simulator table: its own start/end are heel-off and foot-flat
        out = out.drop(columns=[c for c in ("start", "end") if c in out.columns])
        ic = out["end_s"].to_numpy(dtype=float)
        out.insert(0, "start_s", np.concatenate([[np.nan], ic[:-1]]))
    return out


def nearest_index(sorted_values: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """Index of the nearest element of the non-empty ascending ``sorted_values`` for each query (vectorised)."""
    v = np.asarray(sorted_values, dtype=float)
    q = np.asarray(queries, dtype=float)
    if len(v) == 1:
        return np.zeros(len(q), dtype=np.int64)
    k = np.clip(np.searchsorted(v, q), 1, len(v) - 1)
    return np.where(np.abs(v[k - 1] - q) <= np.abs(v[k] - q), k - 1, k)


#: Events that must agree for two strides to pair: the borders of the swing (toe-off, initial contact).
MATCH_ON = ("to_s", "end_s")


def match_strides(estimated: pd.DataFrame, reference: pd.DataFrame, on: str | tuple[str, ...] = MATCH_ON,
                  tolerance: float = 0.3) -> pd.DataFrame:
    """Pair the estimated and reference strides that cover the same swing, one to one.

    Each reference stride is paired with the estimated stride nearest in time on
    the first column of ``on``; the pair counts only when every column of ``on``
    that both tables have (by default the toe-off ``to_s`` and the initial
    contact ``end_s`` that border the swing) differs by at most ``tolerance``
    (s), as gaitmap's stride matching requires of both borders
    (``gaitmap.evaluation_utils.match_stride_lists``). So a reference stride
    that spans two estimated ones (a stance the reference missed, or a swing
    the estimate split) stays unpaired instead of being compared with one of
    them, and an estimated stride pairs with one reference stride at most (the
    nearest). A border missing (NaN) on either side is not checked. Vectorised.

    Parameters
    ----------
    estimated, reference : DataFrame
        Stride tables (:func:`footzoo.analysis.strides.segment_steps`; the
        reference with footzoo's column names or the simulator's, see
        :func:`reference_steps`).
    on : str or tuple of str
        Event columns (s) that must agree; the first one pairs the strides. A
        reference without the first column pairs on ``end_s``.
    tolerance : float
        Largest time difference (s) of each event of a pair.

    Returns
    -------
    DataFrame
        The paired reference rows, in the reference's order, with the
        estimate's columns added as ``est_<column>``.
    """
    est = estimated.reset_index(drop=True)
    ref = reference_steps(reference).reset_index(drop=True)
    cols = [on] if isinstance(on, str) else list(on)
    if cols[0] not in ref.columns and "end_s" in ref.columns:
        cols[0] = "end_s"
    cols = list(dict.fromkeys(c for c in cols if c in ref.columns and c in est.columns))
    if not cols or len(est) == 0 or len(ref) == 0:
        return pd.DataFrame(columns=[*ref.columns, *(f"est_{c}" for c in est.columns)])
    e = est[cols[0]].to_numpy(dtype=float)
    r = ref[cols[0]].to_numpy(dtype=float)
    order = np.argsort(e)
    pick = order[nearest_index(e[order], r)]  # row of est paired with each reference stride
    gap = np.abs(e[pick] - r)
    ok = gap <= tolerance
    for c in cols[1:]:
        d = np.abs(est[c].to_numpy(dtype=float)[pick] - ref[c].to_numpy(dtype=float))
        ok &= ~(d > tolerance)  # NaN: not checked
    # one to one: an estimated stride taken by several reference strides keeps the nearest
    cand = np.flatnonzero(ok)
    first = cand[np.lexsort((gap[cand], pick[cand]))]
    keep = first[np.concatenate([[True], pick[first][1:] != pick[first][:-1]])] if len(first) else first
    ok = np.zeros(len(ref), bool)
    ok[keep] = True
    matched = est.iloc[pick[ok]].reset_index(drop=True).add_prefix("est_")
    return pd.concat([ref[ok].reset_index(drop=True), matched], axis=1)


def stride_errors(estimated: pd.DataFrame, reference: pd.DataFrame, tolerance: float = 0.3) -> dict[str, float]:
    """Per-stride errors (estimate − reference) of the matched strides (:func:`match_strides`).

    The one implementation of the stride comparison: :attr:`footzoo.evaluation.result.Result.metrics`,
    :class:`footzoo.Session` and the accuracy benchmark all report these values.

    Parameters
    ----------
    estimated : DataFrame
        Estimated stride table (:func:`footzoo.analysis.strides.segment_steps`).
    reference : DataFrame
        Reference stride table (see :class:`footzoo.core.data.Truth`); an optional
        boolean ``turn`` column flags the strides that change direction.
    tolerance : float
        Largest time difference (s) of a pair (:func:`match_strides`).

    Returns
    -------
    dict
        The count of reference and matched strides, and where both sides have
        the column: median absolute error of the initial contact
        (``ic_error_median_abs_s``, on ``end_s``) and toe-off
        (``to_error_median_abs_s``), mean and median signed errors (``ic_error_mean_s``,
        ``ic_error_median_s``, ``to_error_mean_s``, ``to_error_median_s``), the same of the foot's
        largest pitch before IC where the reference marks it (``largest_pitch_error_median_abs_s``,
        ``largest_pitch_error_mean_s``, ``largest_pitch_error_median_s``), stride-time error;
        stride-length RMS and mean error (m) over every matched stride
        (``stride_length_rms_error_m``, ``stride_length_mean_error_m``) and over
        the straight ones only (``stride_length_rms_error_straight_m``,
        ``stride_length_mean_error_straight_m``, all strides when the reference
        flags no turns); FPA mean and RMS error (deg) over the straight strides
        (the line of progression of a turn stride is not defined).
    """
    m = match_strides(estimated, reference, tolerance=tolerance)
    out: dict[str, float] = {"ref_strides": float(len(reference)), "matched_strides": float(len(m))}
    if len(m) == 0:
        return out
    straight = ~m["turn"].to_numpy(dtype=bool) if "turn" in m.columns else np.ones(len(m), bool)

    def diff(col: str, mask=None) -> np.ndarray | None:
        if col not in m.columns or f"est_{col}" not in m.columns:
            return None
        d = m[f"est_{col}"].to_numpy(dtype=float) - m[col].to_numpy(dtype=float)
        d = d[mask] if mask is not None else d
        return d[np.isfinite(d)]

    def put(name: str, d: np.ndarray, stat) -> None:  # NaN when no matched stride has both values
        out[name] = float(stat(d)) if d.size else float("nan")

    for col, name in (("end_s", "ic"), ("to_s", "to"), ("largest_pitch_s", "largest_pitch")):
        d = diff(col)
        if d is not None:
            put(f"{name}_error_median_abs_s", d, lambda v: np.median(np.abs(v)))
            put(f"{name}_error_mean_s", d, np.mean)
            put(f"{name}_error_median_s", d, np.median)
    if "end_s" in m.columns and "start_s" in m.columns:
        ref_time = m["end_s"].to_numpy(float) - m["start_s"].to_numpy(float)
        d = m["est_stride_time_s"].to_numpy(float) - ref_time
        put("stride_time_error_median_abs_s", d[np.isfinite(d)], lambda v: np.median(np.abs(v)))
    for suffix, mask in (("", None), ("_straight", straight)):
        d = diff("stride_length_m", mask)
        if d is not None:
            put(f"stride_length_rms_error{suffix}_m", d, lambda v: np.sqrt(np.mean(v**2)))
            put(f"stride_length_mean_error{suffix}_m", d, np.mean)
    d = diff("fpa_rad", straight)
    if d is not None:
        d = np.degrees(d)
        put("fpa_mean_error_deg", d, np.mean)
        put("fpa_rms_error_deg", d, lambda v: np.sqrt(np.mean(v**2)))
    return out


class RigidTransform2D(NamedTuple):
    """A 2-D rigid transform (rotation, translation, optionally a reflection of the second axis) of points (m)."""

    rot: np.ndarray
    mirror: bool
    source_centre: np.ndarray
    target_centre: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        """``points`` (N, 2 or more; the first two columns are transformed) in the target's frame, (N, 2)."""
        p = np.asarray(points, float)[:, :2]
        if self.mirror:
            p = p * np.array([1.0, -1.0])
        return (p - self.source_centre) @ self.rot.T + self.target_centre


def rigid_transform_2d(est: np.ndarray, ref: np.ndarray, reflection: bool = True) -> RigidTransform2D:
    """Least-squares 2-D rotation + translation of ``est`` onto ``ref`` (Kabsch), optionally a reflection (taken
    only when it fits better: datasets such as Köroğlu's flip an axis)."""
    e = np.asarray(est, float)[:, :2]
    r = np.asarray(ref, float)[:, :2]
    best = None
    for mirror in ((False, True) if reflection else (False,)):
        ee = e * np.array([1.0, -1.0]) if mirror else e
        ce, cr = ee.mean(axis=0), r.mean(axis=0)
        h = (ee - ce).T @ (r - cr)
        u, _, vt = np.linalg.svd(h)
        d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
        rot = vt.T @ np.diag([1.0, d]) @ u.T
        err = float(np.sum(((ee - ce) @ rot.T + cr - r) ** 2))
        if best is None or err < best[0]:
            best = (err, RigidTransform2D(rot, mirror, ce, cr))
    return best[1]


def rigid_align_2d(est: np.ndarray, ref: np.ndarray, reflection: bool = True) -> tuple[np.ndarray, bool]:
    """``est`` aligned onto ``ref`` by :func:`rigid_transform_2d`, and whether a reflection was used."""
    tf = rigid_transform_2d(est, ref, reflection)
    return tf.apply(est), tf.mirror


def estimated_footprints(steps: pd.DataFrame) -> np.ndarray:
    """The estimated footprints (mid-stance positions; m, north and east): the first stride's start and every
    stride's end, K + 1 points (rows) for K strides; none without strides."""
    if len(steps) == 0:
        return np.zeros((0, 2))
    return np.vstack([steps[["start_n_m", "start_e_m"]].to_numpy()[:1], steps[["end_n_m", "end_e_m"]].to_numpy()])


def footprint_pairs(steps: pd.DataFrame, footprints: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The estimated footprints (:func:`estimated_footprints`) and the measured ones (K, 2; m) when they can be
    compared: as many of each, at least two (a rigid alignment needs them) and all finite (a footprint not
    measured, a run that diverged: no alignment is defined); None otherwise."""
    fp = np.asarray(footprints, float)[:, :2]
    est = estimated_footprints(steps)
    if len(est) != len(fp) or len(fp) < 2 or not (np.isfinite(fp).all() and np.isfinite(est).all()):
        return None
    return est, fp


def footprint_errors(steps: pd.DataFrame, footprints: np.ndarray) -> dict[str, float]:
    """Error of every footprint (mid-stance position) against measured footprints, e.g. Köroğlu's GCPs.

    The estimated footprints are :func:`estimated_footprints`. Compared only when :func:`footprint_pairs`
    pairs them; after a 2-D rigid alignment (reflection allowed, see :func:`rigid_align_2d`)
    the mean and RMS distances (m) and the end-point distance are returned.
    """
    fp = np.asarray(footprints, float)
    out: dict[str, float] = {"footprints_ref": float(len(fp))}
    if len(steps) == 0:
        return out
    out["footprints_est"] = float(len(estimated_footprints(steps)))
    pairs = footprint_pairs(steps, fp)
    if pairs is None:
        return out
    est, fp = pairs
    aligned, _ = rigid_align_2d(est, fp)
    d = np.linalg.norm(aligned - fp, axis=1)
    out.update(footprint_error_mean_m=float(d.mean()), footprint_error_rms_m=float(np.sqrt(np.mean(d**2))),
               footprint_error_end_m=float(d[-1]))
    return out


def stride_path_errors(t: np.ndarray, pos: np.ndarray, stride_positions: pd.DataFrame,
                       turn: np.ndarray | None = None) -> dict[str, float]:
    """3-D RMS error (m) of the estimated trajectory over each reference stride, after a yaw alignment.

    Per stride the estimate (NED, interpolated at the reference times) is turned
    into a right-handed z-up frame (east, north, up), both are zeroed at the
    stride's first sample, the estimate is rotated about the vertical
    (:func:`yaw_alignment`) and the RMS of the 3-D difference is taken.
    Returns the median over the strides (``stride_path_rms_error_median_m``),
    over the strides not flagged in ``turn`` when it is given.
    """
    enu = np.column_stack([pos[:, 1], pos[:, 0], -pos[:, 2]])
    rms = []
    for k, g in stride_positions.groupby("stride"):
        if turn is not None and bool(turn[int(k)]):
            continue
        tt = g["t_s"].to_numpy(dtype=float)
        if tt[0] < t[0] or tt[-1] > t[-1] or len(tt) < 2:
            continue
        e = np.column_stack([np.interp(tt, t, enu[:, i]) for i in range(3)])
        r = g[["pos_x_m", "pos_y_m", "pos_up_m"]].to_numpy(dtype=float)
        e, r = e - e[0], r - r[0]
        e = rotate_about_vertical(e, yaw_alignment(e, r))
        rms.append(float(np.sqrt(np.mean(np.sum((e - r) ** 2, axis=1)))))
    if not rms:
        return {}
    return {"stride_path_rms_error_median_m": float(np.median(rms)), "stride_paths": float(len(rms))}


#: The per-stride columns of a stride table that every run summarises by their median (``median_<column>``).
STRIDE_QUANTITIES = ("stride_time_s", "cadence_steps_min", "stride_length_m", "stance_time_s", "swing_time_s",
                     "speed_m_s", "max_clearance_m")


def stance_metrics(t: np.ndarray, stance: np.ndarray, truth_stance: np.ndarray) -> dict[str, float]:
    """A stance mask against a reference stance mask: per sample and per step (:func:`step_detection`).

    Returns ``stance_precision``, ``stance_recall``, ``stance_f1``, ``stance_accuracy``,
    ``gait_phase_error_rate``, ``step_count_error`` (detected minus reference stance phases) and
    ``stance_onset_error_mean_s`` / ``stance_offset_error_mean_s`` (detected minus reference, s, over
    the correctly detected phases).
    """
    out = {f"stance_{k}": v for k, v in stance_scores(stance, truth_stance).items()}
    sd = step_detection(stance, truth_stance, t)
    out["gait_phase_error_rate"] = float(sd["error_rate"])
    out["step_count_error"] = float(sd["step_count_error"])
    out["stance_onset_error_mean_s"] = float(sd["onset_error_mean_s"])
    out["stance_offset_error_mean_s"] = float(sd["offset_error_mean_s"])
    return out


def run_metrics(t: np.ndarray, pos: np.ndarray, steps: pd.DataFrame, stance: np.ndarray | None = None,
                reference=None) -> dict[str, float]:
    """Every metric of one run: :func:`result_metrics` (what ``footzoo run`` prints) and, with a reference
    stance mask, :func:`stance_metrics`. A study's metrics are these, by the same names (:data:`METRICS`)."""
    out = result_metrics(t, pos, steps, reference)
    if stance is not None and reference is not None and reference.stance is not None:
        out.update(stance_metrics(t, stance, reference.stance))
    return out


#: Every metric a run can report, with its meaning: the keys of :func:`run_metrics`, of
#: :attr:`footzoo.evaluation.result.Result.metrics` (all but the stance ones) and of a study's table.
METRICS: dict[str, str] = {
    "duration_s": "duration of the recording (s)",
    "path_length_m": "horizontal path length (m)",
    "loop_closure_xy_m": "horizontal end-to-start distance of a closed walk (m)",
    "loop_closure_3d_m": "3-D end-to-start distance of a closed walk (m)",
    "loop_closure_xy_pct": "horizontal end-to-start distance, % of the path length",
    "loop_closure_3d_pct": "3-D end-to-start distance, % of the path length",
    "armse_3d_m": "RMS position error after yaw alignment, against the reference (m)",
    "pyshoe_error_m": "PyShoe's position error against the reference (m)",
    "strides": "number of detected strides",
    **{f"median_{c}": f"median over the strides of {c}" for c in STRIDE_QUANTITIES},
    "fpa_mean_deg": "mean foot progression angle (deg)",
    "median_fpa_deg": "median foot progression angle (deg)",
    "stride_count_ref": "strides counted by hand in the reference",
    "stride_count_error": "detected minus hand-counted strides",
    "ref_strides": "strides of the reference stride table",
    "matched_strides": "reference strides paired with an estimated stride",
    "ic_error_median_abs_s": "median absolute initial-contact timing error (s)",
    "ic_error_mean_s": "mean initial-contact timing error, estimate minus reference (s)",
    "ic_error_median_s": "median initial-contact timing error, estimate minus reference (s)",
    "largest_pitch_error_median_abs_s": "median absolute timing error of the foot's largest pitch before IC (s)",
    "largest_pitch_error_mean_s": "mean timing error of the foot's largest pitch before IC (s)",
    "largest_pitch_error_median_s": "median timing error of the foot's largest pitch before IC (s)",
    "to_error_median_abs_s": "median absolute toe-off timing error (s)",
    "to_error_mean_s": "mean toe-off timing error, estimate minus reference (s)",
    "to_error_median_s": "median toe-off timing error, estimate minus reference (s)",
    "stride_time_error_median_abs_s": "median absolute stride-time error (s)",
    "stride_length_rms_error_m": "stride-length RMS error over the matched strides (m)",
    "stride_length_mean_error_m": "stride-length mean error over the matched strides (m)",
    "stride_length_rms_error_straight_m": "stride-length RMS error over the straight matched strides (m)",
    "stride_length_mean_error_straight_m": "stride-length mean error over the straight matched strides (m)",
    "fpa_mean_error_deg": "FPA mean error over the straight matched strides (deg)",
    "fpa_rms_error_deg": "FPA RMS error over the straight matched strides (deg)",
    "footprints_ref": "measured footprints",
    "footprints_est": "estimated footprints",
    "footprint_error_mean_m": "mean footprint error after a 2-D rigid alignment (m)",
    "footprint_error_rms_m": "RMS footprint error after a 2-D rigid alignment (m)",
    "footprint_error_end_m": "last footprint's error after a 2-D rigid alignment (m)",
    "stride_path_rms_error_median_m": "median per-stride 3-D path RMS error after a yaw alignment (m)",
    "stride_paths": "reference strides with a per-stride trajectory",
    "stance_precision": "per-sample stance precision against the reference stance",
    "stance_recall": "per-sample stance recall against the reference stance",
    "stance_f1": "per-sample stance F1 against the reference stance",
    "stance_accuracy": "per-sample stance accuracy against the reference stance",
    "gait_phase_error_rate": "wrong or missed stance phases per reference stance phase",
    "step_count_error": "detected minus reference stance phases",
    "stance_onset_error_mean_s": "mean stance-onset (initial contact) error against the reference stance (s)",
    "stance_offset_error_mean_s": "mean stance-offset (toe-off) error against the reference stance (s)",
}

#: The metrics a study draws a box plot of when its file names neither ``figures:`` nor ``metrics:``:
#: one error per question a study asks (position, loop closure, stride count, stride length, gait
#: events, foot progression angle, footprints, stance detection). The table and the summaries keep
#: every metric; a box plot of each of the 48 per factor would bury these few.
FIGURE_METRICS: tuple[str, ...] = (
    "armse_3d_m", "pyshoe_error_m", "loop_closure_xy_pct", "stride_count_error", "stride_length_rms_error_m",
    "ic_error_median_abs_s", "to_error_median_abs_s", "fpa_rms_error_deg", "footprint_error_rms_m", "stance_f1",
    "gait_phase_error_rate",
)

def result_metrics(t: np.ndarray, pos: np.ndarray, steps: pd.DataFrame, reference=None) -> dict[str, float]:
    """The numbers ``footzoo run`` prints: a summary of the run and its errors against the reference.

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    pos : (N, 3) ndarray
        Estimated position, NED (m).
    steps : DataFrame
        The stride table (:func:`footzoo.analysis.strides.segment_steps`).
    reference : Truth, optional
        The recording's reference.

    Returns
    -------
    dict
        Keys carry their unit; see :attr:`footzoo.evaluation.result.Result.metrics`.
    """
    ref = reference
    closed = bool(ref is not None and ref.closed_loop)
    out: dict[str, float] = {"duration_s": float(t[-1] - t[0])}
    out.update(trajectory_metrics(pos, ref.pos if ref is not None else None, closed))
    out["strides"] = float(len(steps))
    for col in STRIDE_QUANTITIES:
        if col in steps.columns:
            v = steps[col].to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            out[f"median_{col}"] = float(np.median(v)) if v.size else float("nan")
    if "fpa_rad" in steps.columns:  # NaN when no stride has one (the analysis says why: steps.attrs["notes"])
        fpa = steps["fpa_rad"].to_numpy(dtype=float)
        fpa = fpa[np.isfinite(fpa)]
        out["fpa_mean_deg"] = float(np.degrees(fpa.mean())) if fpa.size else float("nan")
        out["median_fpa_deg"] = float(np.degrees(np.median(fpa))) if fpa.size else float("nan")
    if ref is None:
        return out
    if ref.stride_count is not None:
        out["stride_count_ref"] = float(ref.stride_count)
        out["stride_count_error"] = float(len(steps) - ref.stride_count)
    if ref.steps is not None and len(ref.steps):
        out.update(stride_errors(steps, ref.steps))
    if ref.footprints is not None:
        out.update(footprint_errors(steps, ref.footprints))
    if ref.stride_positions is not None:
        turn = ref.steps["turn"].to_numpy(dtype=bool) if ref.steps is not None and "turn" in ref.steps else None
        out.update(stride_path_errors(t, pos, ref.stride_positions, turn))
    return out


def event_stance_mask(t: np.ndarray, to: np.ndarray, ic: np.ndarray) -> np.ndarray:
    """Stance flag per sample from gait events: False in every swing ``[TO, IC)``, True elsewhere.

    Parameters
    ----------
    t : (N,) ndarray
        Sample times (s).
    to, ic : (K,) ndarray
        Toe-off and the initial contact ending the same swing (s); pairs with a NaN are skipped.
    """
    t = np.asarray(t, dtype=float)
    to, ic = np.asarray(to, dtype=float), np.asarray(ic, dtype=float)
    ok = np.isfinite(to) & np.isfinite(ic) & (ic > to)
    edges = np.zeros(len(t) + 1, dtype=np.int64)
    np.add.at(edges, np.searchsorted(t, to[ok]), 1)
    np.add.at(edges, np.searchsorted(t, ic[ok]), -1)
    return np.cumsum(edges[:-1]) <= 0


def gait_phase_errors(t: np.ndarray, estimated: pd.DataFrame, reference: pd.DataFrame,
                      max_swing: float = 1.0, margin: float = 0.3) -> dict[str, float]:
    """Gait phases (stance from IC to TO, swing from TO to IC) of two stride tables compared on the samples ``t``.

    Both tables' events (``to_s``, ``end_s``) become stance masks (:func:`event_stance_mask`); the
    scored samples run from ``margin`` (s) before the reference's first toe-off to ``margin`` after its
    last initial contact, without the reference swings longer than ``max_swing`` (s), which span
    more than one step (e.g. gaitmap's 180° turn stride): there both masks are set to swing, so a
    stance of the estimate inside such a swing is not counted. The step-level error rate is Nguyen &
    La's ("1 wrong in 36 steps", :func:`step_detection`).

    Returns
    -------
    dict
        ``gait_phase_error_rate`` (wrong stance phases / reference stance phases),
        ``gait_phase_sample_error`` (fraction of scored samples whose phase differs) and
        ``stance_phases`` (reference count). The timing of the phase borders is that of the
        events: stance starts at IC and ends at TO (:func:`stride_errors`, ``ic_error_mean_s``,
        ``to_error_mean_s``).
    """
    t = np.asarray(t, dtype=float)
    to_r, ic_r = reference["to_s"].to_numpy(float), reference["end_s"].to_numpy(float)
    est = event_stance_mask(t, estimated["to_s"].to_numpy(float), estimated["end_s"].to_numpy(float))
    ref = event_stance_mask(t, to_r, ic_r)
    scored = (t >= np.nanmin(to_r) - margin) & (t <= np.nanmax(ic_r) + margin)
    long = (ic_r - to_r) > max_swing
    scored &= event_stance_mask(t, to_r[long], ic_r[long])
    est &= scored
    ref &= scored
    s = step_detection(est, ref, t)
    return {"gait_phase_error_rate": s["error_rate"],
            "gait_phase_sample_error": float(np.mean(est[scored] != ref[scored])) if scored.any() else float("nan"),
            "stance_phases": float(s["true_steps"])}


def vertical_errors(pos: np.ndarray, ref: np.ndarray | None = None) -> dict[str, float]:
    """Height error at the end of a walk and per distance walked; against a reference or, without one, a closed loop.

    Both trajectories start at the origin. Heights are up positive (``−d`` of NED).

    Parameters
    ----------
    pos : (N, 3) ndarray
        Estimated position, NED (m).
    ref : (N, 3) ndarray, optional
        Reference position, NED (m); without it the walk is taken to end at its start's height.

    Returns
    -------
    dict
        ``height_end_error_m`` (estimate − reference at the last sample, m), ``height_end_error_pct``
        (its absolute value in % of the horizontal path length of the estimate) and
        ``height_rms_error_m`` (RMS over the samples, m; with a reference only).
    """
    e = np.asarray(pos, dtype=float)
    up = -(e[:, 2] - e[0, 2])
    ref_up = np.zeros_like(up) if ref is None else -(np.asarray(ref, dtype=float)[:, 2] - ref[0, 2])
    if ref is not None:
        _check_same_length(e, np.asarray(ref))
    d = up - ref_up
    length = path_length(e)
    out = {"height_end_error_m": float(d[-1]),
           "height_end_error_pct": 100.0 * abs(float(d[-1])) / length if length > 0 else float("nan")}
    if ref is not None:
        out["height_rms_error_m"] = float(np.sqrt(np.mean(d**2)))
    return out


def nis_summary(nis: np.ndarray, rows: np.ndarray, confidence: float = 0.95) -> dict[str, float]:
    """The Kalman filter's innovation consistency over a run (Bar-Shalom et al. 2001, Sec. 5.4.2–5.4.3).

    Each update's normalised innovation squared ``ε_ν = νᵀ S⁻¹ ν`` is χ²-distributed with as many
    degrees of freedom as it has rows for a consistent filter; it needs no ground truth, so it is the
    consistency check on real recordings.

    Parameters
    ----------
    nis : (N,) ndarray
        Per sample, the update's NIS (0 without an update).
    rows : (N,) ndarray
        Per sample, the update's number of rows (its degrees of freedom).
    confidence : float
        The two-sided χ² acceptance region of one update.

    Returns
    -------
    dict
        ``nis_per_row``: ``Σ ε_ν / Σ rows`` (1 expected; above 1 the filter is over-confident, below
        it is too cautious), ``nis_inside``: the share of updates inside the acceptance region
        (``confidence`` expected), ``updates`` and ``rows``.
    """
    # deferred: scipy, only for the consistency summary (covariance=True)
    from scipy.stats import chi2

    nis, rows = np.asarray(nis, dtype=float), np.asarray(rows, dtype=float)
    used = rows > 0
    total = float(rows[used].sum())
    if not used.any():
        return {"nis_per_row": float("nan"), "nis_inside": float("nan"), "updates": 0, "rows": 0}
    tail = (1.0 - confidence) / 2.0
    lo, hi = chi2.ppf(tail, rows[used]), chi2.ppf(1.0 - tail, rows[used])
    inside = (nis[used] >= lo) & (nis[used] <= hi)
    return {"nis_per_row": float(nis[used].sum() / total), "nis_inside": float(inside.mean()),
            "updates": int(used.sum()), "rows": int(total)}


def position_nees(pos: np.ndarray, ref: np.ndarray, var: np.ndarray) -> np.ndarray:
    """Normalised estimation error squared of the position per sample (Bar-Shalom et al. 2001, Sec. 5.4.2).

    ``ε_k = Σ_i (p̂_ki − p_ki)² / σ²_ki`` over the three axes, with the filter's position variances
    only (the diagonal of the covariance: the cross terms are not kept). A consistent filter has
    ``E[ε] = 3`` (χ² with 3 degrees of freedom for Gaussian errors). Both trajectories are compared
    as given (no alignment): the simulator's truth shares the estimate's frame and start.

    Parameters
    ----------
    pos, ref : (N, 3) ndarray
        Estimated and true position (m).
    var : (N, 3) ndarray
        The filter's position variances (m²).
    """
    d = np.asarray(pos, dtype=float) - np.asarray(ref, dtype=float)
    v = np.asarray(var, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sum(np.where(v > 0, d**2 / v, np.nan), axis=1)
