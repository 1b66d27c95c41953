"""Trajectory metrics: path length, loop closure, ARMSE after yaw alignment, PyShoe's error.

All positions are (N, 3) arrays in NED (m). Horizontal means north-east.
"""

from __future__ import annotations

import numpy as np


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


def intervals(mask: np.ndarray) -> np.ndarray:
    """``(start, stop)`` index pairs (stop exclusive) of the True runs of a boolean mask, (K, 2)."""
    m = np.asarray(mask, dtype=bool).astype(np.int8)
    d = np.diff(np.concatenate([[0], m, [0]]))
    return np.column_stack([np.flatnonzero(d == 1), np.flatnonzero(d == -1)])


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


def match_strides(estimated, reference, tolerance: float = 0.5, min_fraction: float = 0.3):
    """Pair estimated and reference strides by their end times.

    Estimated strides shorter than ``min_fraction`` of the median stride length
    (split stances, shuffles) are left out; each reference stride takes the
    estimated stride whose ``end`` is nearest to its own, within ``tolerance``
    seconds. Returns a DataFrame with the reference columns and ``est_*`` columns.
    """
    import pandas as pd

    est = estimated[estimated["stride_length"] >= min_fraction * estimated["stride_length"].median()]
    rows = []
    ends = est["end"].to_numpy()
    for _, r in reference.iterrows():
        if ends.size == 0:
            break
        j = int(np.argmin(np.abs(ends - r["end"])))
        if abs(ends[j] - r["end"]) <= tolerance:
            rows.append({**r.to_dict(), **{f"est_{k}": v for k, v in est.iloc[j].to_dict().items()}})
    return pd.DataFrame(rows)
