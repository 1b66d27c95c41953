"""When a reference can score a metric: explicit rules, a reason for every metric they refuse.

A metric compared with a reference that cannot support it (stance labels broken into fragments,
a stride table without toe-offs, two strides) would still give a number, and a wrong one: a
PyShoe running trial's VICON stance labels are 49 segments, 47 of them 5–85 ms fragments, so every
detector gets ``step_count_error`` ≈ −30. Such a metric is NaN with the reason instead.

The rules (each applies to the reference of one recording):

``fragmented stance``
    More than :data:`MAX_FRAGMENT_SHARE` of the reference stance phases last less than
    :data:`MIN_STANCE_S`: the step-level stance metrics (:data:`STEP_METRICS`) are refused; the
    per-sample scores stay (a sample is still labelled).
``no stance``
    The reference stance mask has no stance sample, or no swing sample: every stance metric is refused.
``too few stance phases``
    Fewer than :data:`MIN_REFERENCE_PHASES` reference stance phases: the step-level stance metrics are refused.
``too few strides``
    Fewer than :data:`MIN_REFERENCE_PHASES` strides in the reference stride table: every stride
    comparison (:data:`STRIDE_COMPARISONS`) is refused.
``missing events``
    A reference event column (``to_s``, ``end_s``, ``start_s``) is absent, or it or a quantity column
    (``stride_length_m``, ``fpa_rad``) is NaN in more than :data:`MAX_MISSING_SHARE` of the strides:
    the comparisons that need it are refused (:data:`NEEDS`). A quantity the reference does not
    have at all is simply not compared.
``no matched stride``
    The reference has strides but no estimated stride pairs with one
    (:func:`footzoo.evaluation.metrics.match_strides`): the per-stride errors are NaN (the estimate's
    fault, not the reference's, but a number would be made up all the same).
``the estimate says why``
    An analysis that leaves a column of the stride table NaN says why in ``steps.attrs["notes"]``
    (column -> reason; the foot progression angle of a recording whose foot side is unknown): the
    metrics computed from that column are NaN with that reason (:func:`estimate_problems`).

A metric a study asks for (``metrics:``) that a run cannot compute at all (no reference of that
kind, no analysis that gives it) is never dropped either: it is NaN with the reason
(:func:`missing_reason`).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..core.errors import FootzooWarning, user_stacklevel
from .metrics import intervals, reference_steps, result_metrics

MIN_STANCE_S = 0.1  #: shortest plausible stance phase (s); a running stance lasts about 0.2 s
MAX_FRAGMENT_SHARE = 0.25  #: largest share of reference stance phases shorter than MIN_STANCE_S
MIN_REFERENCE_PHASES = 3  #: fewest reference stance phases or strides a comparison needs
MAX_MISSING_SHARE = 0.5  #: largest share of strides whose reference event may be missing (NaN)

#: Stance metrics that count or time stance phases (refused on fragmented or too few phases).
STEP_METRICS = ("gait_phase_error_rate", "step_count_error", "stance_onset_error_mean_s",
                "stance_offset_error_mean_s")
#: Stance metrics per sample.
SAMPLE_METRICS = ("stance_precision", "stance_recall", "stance_f1", "stance_accuracy")
#: Reference event column -> the stride comparisons that need it.
NEEDS: dict[str, tuple[str, ...]] = {
    "end_s": ("ic_error_median_abs_s", "ic_error_mean_s", "ic_error_median_s", "stride_time_error_median_abs_s"),
    "start_s": ("stride_time_error_median_abs_s",),
    "to_s": ("to_error_median_abs_s", "to_error_mean_s", "to_error_median_s"),
    "stride_length_m": ("stride_length_rms_error_m", "stride_length_mean_error_m",
                        "stride_length_rms_error_straight_m", "stride_length_mean_error_straight_m"),
    "fpa_rad": ("fpa_mean_error_deg", "fpa_rms_error_deg"),
    "largest_pitch_s": ("largest_pitch_error_median_abs_s", "largest_pitch_error_mean_s",
                        "largest_pitch_error_median_s"),
}
#: The gait events a reference stride table is expected to have (an absent quantity column is no comparison).
EVENTS = ("start_s", "to_s", "end_s")
#: Every per-stride comparison with a reference stride table (not the counts).
STRIDE_COMPARISONS = tuple(dict.fromkeys(m for ms in NEEDS.values() for m in ms))


#: A column of the estimated stride table -> the metrics computed from it.
FROM_COLUMN: dict[str, tuple[str, ...]] = {"fpa_rad": ("fpa_mean_deg", "median_fpa_deg", "fpa_mean_error_deg",
                                                       "fpa_rms_error_deg")}


class MetricWarning(FootzooWarning):
    """A metric was refused (NaN) because the recording's reference cannot score it; the reason says why."""


def reference_problems(t: np.ndarray, reference: Any) -> dict[str, str]:
    """The metrics a recording's reference cannot score, each with the reason (the rules of this module).

    Parameters
    ----------
    t : (N,) ndarray
        Time (s).
    reference : Truth or None
        The recording's reference.

    Returns
    -------
    dict
        Metric name -> reason; empty when every metric the reference has is usable.
    """
    out: dict[str, str] = {}
    if reference is None:
        return out
    stance = getattr(reference, "stance", None)
    if stance is not None:
        out.update(_stance_problems(np.asarray(t, float), np.asarray(stance, bool)))
    steps = getattr(reference, "steps", None)
    if steps is not None:
        out.update(_stride_problems(reference_steps(steps)))
    return out


def _stance_problems(t: np.ndarray, stance: np.ndarray) -> dict[str, str]:
    if not stance.any() or stance.all():
        why = "the reference stance mask has no " + ("stance" if not stance.any() else "swing") + " sample"
        return dict.fromkeys((*SAMPLE_METRICS, *STEP_METRICS), why)
    phases = intervals(stance)
    dt = float(np.median(np.diff(t)))
    durations = np.round((phases[:, 1] - phases[:, 0]) * dt, 6)  # samples x the median period (to 1 µs)
    short = int(np.sum(durations < MIN_STANCE_S))
    if short > MAX_FRAGMENT_SHARE * len(phases):
        return dict.fromkeys(STEP_METRICS, (
            f"fragmented stance reference: {short} of its {len(phases)} stance phases last less than "
            f"{MIN_STANCE_S * 1e3:.0f} ms (at most {MAX_FRAGMENT_SHARE:.0%} may)"))
    if len(phases) < MIN_REFERENCE_PHASES:
        return dict.fromkeys(STEP_METRICS, f"too few reference stance phases: {len(phases)} "
                                           f"(at least {MIN_REFERENCE_PHASES} needed)")
    return {}


def _stride_problems(steps) -> dict[str, str]:
    if len(steps) < MIN_REFERENCE_PHASES:
        return dict.fromkeys(STRIDE_COMPARISONS, f"too few reference strides: {len(steps)} "
                                                 f"(at least {MIN_REFERENCE_PHASES} needed)")
    out: dict[str, str] = {}
    for col, metrics in NEEDS.items():
        if col not in steps.columns and col not in EVENTS:
            continue  # a quantity the reference does not measure: no comparison, nothing to refuse
        if col not in steps.columns:
            why = f"the reference stride table has no {col!r} column"
        else:
            missing = int(np.sum(~np.isfinite(steps[col].to_numpy(dtype=float))))
            if col == "start_s":
                missing -= 1  # the first stride's start is unknown by construction
            if missing <= MAX_MISSING_SHARE * len(steps):
                continue
            why = f"reference {col!r} is missing in {missing} of {len(steps)} strides"
        for m in metrics:
            out.setdefault(m, why)
    return out


def estimate_problems(steps: Any, reference: Any = None) -> dict[str, str]:
    """The metrics an analysis left NaN, with its reason (``steps.attrs["notes"]``: column -> reason).

    The errors against a reference column (``fpa_mean_error_deg``) only where the reference has that column.
    """
    notes = (getattr(steps, "attrs", None) or {}).get("notes") or {}
    ref_steps = getattr(reference, "steps", None)
    out: dict[str, str] = {}
    for column, why in notes.items():
        for name in FROM_COLUMN.get(column, ()):
            if "error" in name and (ref_steps is None or column not in ref_steps.columns):
                continue
            out[name] = str(why)
    return out


#: Metric -> what it needs, for :func:`missing_reason`: (the reference's attribute, its column or None, the words).
_NEEDS_REFERENCE: dict[str, tuple[str, str | None, str]] = {
    **dict.fromkeys(("armse_3d_m", "pyshoe_error_m"), ("pos", None, "reference positions")),
    **dict.fromkeys(("stride_count_ref", "stride_count_error"),
                    ("stride_count", None, "a stride count (hand-counted)")),
    **dict.fromkeys(("ref_strides", "matched_strides", "ic_error_median_abs_s", "ic_error_mean_s",
                     "stride_time_error_median_abs_s"), ("steps", "end_s", "a stride table with initial contacts")),
    **dict.fromkeys(("to_error_median_abs_s", "to_error_mean_s"), ("steps", "to_s", "a stride table with toe-offs")),
    **dict.fromkeys(("stride_length_rms_error_m", "stride_length_mean_error_m", "stride_length_rms_error_straight_m",
                     "stride_length_mean_error_straight_m"),
                    ("steps", "stride_length_m", "a stride table with stride lengths")),
    **dict.fromkeys(("fpa_mean_error_deg", "fpa_rms_error_deg"),
                    ("steps", "fpa_rad", "a stride table with foot progression angles")),
    **dict.fromkeys(("largest_pitch_error_median_abs_s", "largest_pitch_error_mean_s", "largest_pitch_error_median_s"),
                    ("steps", "largest_pitch_s", "a stride table with the foot's largest pitch before IC")),
    **dict.fromkeys(("footprints_ref", "footprints_est", "footprint_error_mean_m", "footprint_error_rms_m",
                     "footprint_error_end_m"), ("footprints", None, "measured footprints")),
    **dict.fromkeys(("stride_path_rms_error_median_m", "stride_paths"),
                    ("stride_positions", None, "per-stride trajectories")),
    **dict.fromkeys((*SAMPLE_METRICS, *STEP_METRICS), ("stance", None, "a stance mask (stance or swing per sample)")),
}


def missing_reason(name: str, reference: Any = None, steps: Any = None) -> str:
    """Why a run has no value for the metric ``name`` (one a study asked for): the reference or the analysis it needs.

    Parameters
    ----------
    name : str
        A metric (:data:`footzoo.evaluation.metrics.METRICS`).
    reference : Truth, optional
        The recording's reference.
    steps : DataFrame, optional
        The run's stride table.
    """
    source = getattr(reference, "source", "") or ""
    which = f"the recording's reference ({source})" if source else "the recording's reference"
    if name.startswith("loop_closure"):
        return ("the recording is not known to be a closed walk (declare closed_loop: true in its metadata sidecar "
                "<file>.meta.yaml if it ends where it started)")
    if name in ("fpa_mean_deg", "median_fpa_deg") or (name in FROM_COLUMN["fpa_rad"] and steps is not None
                                                      and "fpa_rad" not in getattr(steps, "columns", ())):
        return "the pipeline has no foot-progression-angle analysis (add analysis: [{type: huang_fpa}])"
    if name in _NEEDS_REFERENCE:
        attr, column, words = _NEEDS_REFERENCE[name]
        if reference is None:
            return f"the recording has no reference; this metric needs {words}"
        value = getattr(reference, attr, None)
        if value is None:
            return f"{which} has no {words.removeprefix('a ').removeprefix('an ')}"
        if column is not None and column not in getattr(value, "columns", ()):
            return f"{which} has a stride table without {column!r}; this metric needs {words}"
        if attr == "steps" and len(value) == 0:
            return f"{which} has an empty stride table"
    if name.startswith("median_") and steps is not None and len(steps) == 0:
        return "no stride was detected"
    return "the run did not compute it (no reference or analysis gives it)"


def checked_metrics(values: dict[str, float], problems: dict[str, str], reference: Any = None,
                    t: np.ndarray | None = None) -> tuple[dict[str, float], dict[str, str]]:
    """``values`` with every refused metric NaN, and the reasons (metric -> reason) of the NaN ones.

    A metric of ``problems`` becomes NaN whether or not it was computed. With a reference stride
    table that has strides and none matched, the per-stride comparisons are NaN too; with the
    recording's time stamps ``t`` (s), a reference whose strides all lie outside them is named as
    such (another clock or time origin).
    """
    out, notes = dict(values), {}
    for name, why in problems.items():
        out[name] = float("nan")
        notes[name] = why
    if (reference is not None and getattr(reference, "steps", None) is not None and len(reference.steps)
            and values.get("matched_strides", 1.0) == 0.0):
        why = "no estimated stride matched a reference stride" + _outside(reference.steps, t)
        for name in STRIDE_COMPARISONS:
            if name not in notes:
                out[name] = float("nan")
                notes[name] = why
    return out, notes


def _outside(steps: Any, t: np.ndarray | None) -> str:
    """``": the reference's strides ... lie outside the recording ..."`` when they all do, else ``""``."""
    steps = reference_steps(steps)  # the simulator's older column names too
    times = np.concatenate([np.asarray(steps[c], dtype=float) for c in ("start_s", "to_s", "end_s")
                            if c in steps.columns] or [np.array([])])
    times = times[np.isfinite(times)]
    if t is None or not len(t) or not times.size or ((times >= t[0]) & (times <= t[-1])).any():
        return ""
    return (f": the reference's strides (t = {times.min():.2f}-{times.max():.2f} s) all lie outside the recording "
            f"(t = {float(t[0]):.2f}-{float(t[-1]):.2f} s); the reference and the samples are stamped by different "
            "clocks or from different origins: give both the same time base")


def result_metrics_checked(t: np.ndarray, pos: np.ndarray, steps: Any,
                           reference: Any = None) -> tuple[dict[str, float], dict[str, str]]:
    """:func:`footzoo.evaluation.metrics.result_metrics` under this module's rules, and the reasons of the NaN ones.

    What :attr:`footzoo.evaluation.result.Result.metrics` reports: the same keys as the unchecked metrics
    (a refused metric is NaN, never dropped nor added), the same rules and reasons as a study's.
    """

    values = result_metrics(t, pos, steps, reference)
    found = {**reference_problems(t, reference), **estimate_problems(steps, reference)}
    problems = {k: why for k, why in found.items() if k in values}
    return checked_metrics(values, problems, reference, t)


def warn_refused(label: str, notes: dict[str, str]) -> None:
    """One :class:`MetricWarning` listing the refused metrics of one recording and their distinct reasons."""
    if not notes:
        return
    by_reason: dict[str, list[str]] = {}
    for name, why in notes.items():
        by_reason.setdefault(why, []).append(name)
    text = "; ".join(f"{', '.join(names)}: {why}" for why, names in by_reason.items())
    warnings.warn(f"{label}: metrics refused (NaN): {text}", MetricWarning, stacklevel=user_stacklevel())
