"""Figures of one pipeline run, ready for a thesis (matplotlib, imported only when plotting).

Every function returns a :class:`matplotlib.figure.Figure` (to restyle or save as
PDF/SVG); :func:`plot_run` writes the whole set as PNG files. Positions are shown
in metres, angles in degrees, times in seconds. Where the recording has a
reference (simulator truth, VICON, mocap), it is drawn in black dashes after a
least-squares yaw alignment (``metrics.yaw_alignment``), since a foot-mounted IMU
without magnetometer cannot know its absolute heading.
"""

from __future__ import annotations

import functools
import io
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ParamSpec, TypeVar

import numpy as np
import pandas as pd

from ..core.atomic import OutputError, atomic_path
from ..core.conventions import quat_to_euler
from ..core.data import Recording
from ..core.errors import ConfigError, RecordingError
from .metrics import footprint_pairs, match_strides, rigid_align_2d, rotate_about_vertical, yaw_alignment
from .result import Result

P = ParamSpec("P")
R = TypeVar("R")

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Colour of the reference (truth) in every figure.
REFERENCE_STYLE: dict[str, Any] = {"color": "k", "ls": "--", "lw": 1.0}
#: How measured footprints (Köroğlu's ground control points) are drawn: black crosses.
FOOTPRINT_STYLE: dict[str, Any] = {"marker": "x", "ls": "none", "color": REFERENCE_STYLE["color"], "ms": 6, "mew": 1.2}
#: Shade of stance periods.
STANCE_COLOR = "0.88"
#: Smallest span of the FPA axis (deg).
MIN_FPA_SPAN = 6.0
#: Largest number of points drawn per line; longer series are decimated for drawing only.
MAX_POINTS = 20000


#: Figure style (applied while a figure is built, the user's own rcParams stay untouched).
STYLE: dict[str, Any] = {
    "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False, "axes.spines.right": False,
    "font.size": 9, "axes.titlesize": 10, "axes.labelsize": 9, "legend.fontsize": 8,
    "legend.frameon": False, "figure.dpi": 100, "savefig.dpi": 150,
}


def pyplot():
    """``matplotlib.pyplot``, on the non-interactive Agg backend unless pyplot was already imported."""
    # deferred: matplotlib, loaded at the first figure (footzoo runs without it)
    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def styled(func: Callable[P, R]) -> Callable[P, R]:
    """Decorator: build the figure under :data:`STYLE`."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with pyplot().rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


def _bbox(fig: Figure) -> str | None:
    """``"tight"`` (fit the saved area to what was drawn, so no legend is cut off), unless the figure's
    layout engine already fitted it: a constrained layout places the legends inside the figure, and
    ``"tight"`` would draw the whole figure a second time to measure it."""
    return None if fig.get_layout_engine() is not None else "tight"


def save(fig: Figure, path: str | Path) -> Path:
    """Save ``fig`` (format from the suffix; no legend cut off, see :func:`_bbox`) and close it.

    The file is written under a temporary name and renamed into place (:func:`footzoo.core.atomic.atomic_path`):
    an interrupted save leaves the previous figure, never a truncated one.
    """
    out = Path(path)
    fmt = out.suffix.lstrip(".").lower() or "png"
    formats = fig.canvas.get_supported_filetypes()
    if fmt not in formats:
        # deferred: matplotlib, loaded at the first figure (footzoo runs without it)
        import matplotlib.pyplot as plt

        plt.close(fig)
        raise OutputError(f"figure {str(out)!r}: matplotlib writes no '.{fmt}' files; end the name with one of "
                          f"{', '.join('.' + f for f in sorted(formats))} (e.g. {str(out.with_suffix('.png'))!r})")
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out, what="figure") as tmp:
        fig.savefig(tmp, format=fmt, dpi=STYLE["savefig.dpi"], bbox_inches=_bbox(fig))
    # deferred: matplotlib, loaded at the first figure (footzoo runs without it)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return out


def png_bytes(fig: Figure) -> bytes:
    """The PNG file :func:`save` would write for ``fig`` (same settings), in memory; closes the figure.

    For figures drawn by workers that cannot see the output folder (a Dask cluster): they send
    the bytes and the client writes them.
    """

    # deferred: matplotlib, loaded at the first figure (footzoo runs without it)
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=STYLE["savefig.dpi"], bbox_inches=_bbox(fig))
    plt.close(fig)
    return buf.getvalue()


# --------------------------------------------------------------------------- helpers


def _stride(n: int) -> int:
    return max(1, int(np.ceil(n / MAX_POINTS)))


def check_pair(result: Result, recording: Recording | None) -> None:
    """Refuse a recording that is not the one the result was computed from (their samples must match)."""
    if recording is None:
        return
    n = len(result.samples)
    if recording.n != n:
        raise RecordingError(
            f"the recording {recording.name!r} has {recording.n} samples but the result has {n}: pass the "
            "recording the result was computed from (the one given to Pipeline.run)"
        )


def aligned_reference(result: Result, recording: Recording | None) -> np.ndarray | None:
    """The reference positions (N, 3, m) in the estimate's frame: same start, yaw-aligned; None without one.

    Samples where the reference is missing (NaN, e.g. occluded markers) stay NaN.
    """
    check_pair(result, recording)
    if recording is None or recording.truth is None or recording.truth.pos is None:
        return None
    ref = np.asarray(recording.truth.pos, dtype=float)
    pos = result.pos
    ok = np.all(np.isfinite(ref), axis=1) & np.all(np.isfinite(pos), axis=1)
    if ok.sum() < 2:
        return None
    first = int(np.flatnonzero(ok)[0])
    e, r = pos[ok] - pos[first], ref[ok] - ref[first]
    psi = yaw_alignment(e, r)
    return rotate_about_vertical(ref - ref[first], -psi) + pos[first]


def aligned_footprints(result: Result, recording: Recording | None) -> np.ndarray | None:
    """The recording's measured footprints (K, 2; m, north and east) in the estimate's frame; None without them.

    Measured footprints (Köroğlu's ground control points) are in the dataset's own axes: they are aligned
    onto the estimated footprints (:func:`~footzoo.evaluation.metrics.estimated_footprints`) by the 2-D
    rigid alignment that the footprint metric uses the other way round (reflection allowed). None also when
    :func:`~footzoo.evaluation.metrics.footprint_pairs` does not pair them: the metric compares nothing then
    either (its ``footprints_est`` says how many).
    """
    check_pair(result, recording)
    if recording is None or recording.truth is None or recording.truth.footprints is None:
        return None
    pairs = footprint_pairs(result.steps, recording.truth.footprints)
    if pairs is None:
        return None
    est, fp = pairs
    return rigid_align_2d(fp, est)[0]


def broken_at_wraps(angle_deg: np.ndarray) -> np.ndarray:
    """An angle (deg, within ±180°) for a line plot: NaN where it wraps (a step over 180°), so the line breaks there.

    Unwrapping instead would add 360° at every wrap, and a foot whose pitch passes ±90° (a sensor pitched on the
    foot, at push-off) flips roll and yaw by 180° at each stride: unwrapped, they climb by thousands of degrees.
    """
    y = np.array(angle_deg, dtype=float)
    y[1:][np.abs(np.diff(angle_deg)) > 180.0] = np.nan
    return y


def _shade_stance(ax: Axes, t: np.ndarray, stance: np.ndarray, label: str | None = "stance",
                  max_bands: int = 60) -> None:
    """Grey bands behind the curves where ``stance`` is True (none when there are over ``max_bands``)."""
    stance = np.asarray(stance, dtype=bool)
    if not stance.any():
        return
    d = np.diff(np.concatenate([[0], stance.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    if len(starts) > max_bands:
        return
    for i, (a, b) in enumerate(zip(starts, stops, strict=True)):
        ax.axvspan(t[a], t[b], color=STANCE_COLOR, lw=0, zorder=0, label=label if i == 0 else None)


def step_column(steps: pd.DataFrame, name: str) -> tuple[np.ndarray, str] | None:
    """Values of a per-stride quantity and its display unit, whatever the column's unit suffix.

    ``name`` is the quantity without unit (``stride_length``, ``fpa``, ``stance_time``...);
    columns ``name``, ``name_m``, ``name_s``, ``name_deg``, ``name_rad``,
    ``name_pct``, ``name_m_s`` and ``name_steps_min`` are recognised. Angles are returned in degrees (a plain
    ``heading`` or ``fpa`` column is in radians, footzoo's internal unit).
    """
    angles = ("fpa", "heading")
    for suffix, unit in (("_deg", "deg"), ("_rad", "rad"), ("_m", "m"), ("_s", "s"), ("_pct", "%"),
                         ("_m_s", "m/s"), ("_m_per_s", "m/s"), ("_steps_min", "steps/min"), ("_per_min", "1/min"),
                         ("", "")):
        col = name + suffix
        if col in steps.columns:
            v = pd.to_numeric(steps[col], errors="coerce").to_numpy(dtype=float)
            if unit == "rad" or (unit == "" and name in angles):
                return np.degrees(v), "deg"
            return v, unit or DEFAULT_UNITS.get(name, "")
    return None


#: Units of the per-stride columns that carry none in their name.
DEFAULT_UNITS = {"stride_length": "m", "stride_time": "s", "duration": "s", "speed": "m/s", "cadence": "1/min",
                 "max_clearance": "m", "stance_time": "s", "swing_time": "s", "ic": "s", "to": "s",
                 "start": "s", "end": "s"}
#: Per-stride quantities drawn by :func:`strides_figure`, with their axis labels.
STRIDE_QUANTITIES = (("stride_length", "stride length"), ("stride_time", "stride time"),
                     ("stance_time", "stance time"), ("swing_time", "swing time"), ("speed", "speed"),
                     ("max_clearance", "max. foot clearance"), ("fpa", "foot progression angle"))


def robust_limits(values: np.ndarray, k: float = 6.0, rel: float = 0.5) -> tuple[float, float] | None:
    """Axis limits covering the bulk of ``values``, or None when no value is an outlier.

    An outlier lies farther from the median than both ``k`` robust standard
    deviations (1.4826 · MAD) and ``rel`` times the median's magnitude, so a
    precise series (tiny MAD) keeps all its points while a 16 s first "stride"
    among 1.1 s strides is set aside.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size < 4:
        return None
    med = float(np.median(v))
    mad = 1.4826 * float(np.median(np.abs(v - med)))
    half = max(k * mad, rel * abs(med))
    if half <= 0:
        return None
    lo, hi = med - half, med + half
    if v.min() >= lo and v.max() <= hi:
        return None
    inside = v[(v >= lo) & (v <= hi)]
    pad = max(0.1 * float(inside.max() - inside.min()), mad, 0.02 * abs(med), 1e-9)
    return float(inside.min() - pad), float(inside.max() + pad)


def _clip_outliers(ax: Axes, x: np.ndarray, y: np.ndarray, color: str, also: np.ndarray | None = None) -> int:
    """Limit the y axis to the bulk of ``y`` (and of ``also``, e.g. the reference values, which it keeps in view);
    draw the outliers of ``y`` as triangles at the edge. Returns their count."""
    both = y if also is None else np.concatenate([y, np.asarray(also, dtype=float)])
    lim = robust_limits(both)
    if lim is None:
        return 0
    lo, hi = lim
    ax.set_ylim(lo, hi)
    above, below = y > hi, y < lo
    edge = 0.04 * (hi - lo)
    ax.plot(x[above], np.full(above.sum(), hi - edge), "^", color=color, ms=6)
    ax.plot(x[below], np.full(below.sum(), lo + edge), "v", color=color, ms=6)
    n = int(above.sum() + below.sum())
    ax.annotate(f"{n} off scale (▲▼)", (0.99, 0.97), xycoords="axes fraction", ha="right", va="top",
                fontsize=7, color="0.3")
    return n


def time_column(steps: pd.DataFrame, *names: str) -> str | None:
    """The first of ``name_s`` / ``name`` (for each of ``names``) that ``steps`` has, or None."""
    for name in names:
        for col in (f"{name}_s", name):
            if col in steps.columns:
                return col
    return None


def _stride_ends(result: Result) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Stride numbers, end times (s) and end positions (K, 3) of the strides whose end is known."""
    steps = result.steps
    end = time_column(steps, "end")
    if len(steps) == 0 or end is None:
        return None
    times = steps[end].to_numpy(float)
    number = np.flatnonzero(np.isfinite(times))
    times = times[number]
    t = result.samples["t"].to_numpy()
    pos = result.pos
    return number, times, np.column_stack([np.interp(times, t, pos[:, i]) for i in range(3)])


def reference_strides(steps: pd.DataFrame, recording: Recording | None) -> tuple[np.ndarray, pd.DataFrame] | None:
    """The recording's reference strides paired with the estimated ones, and the stride number of each pair.

    Pairs by time with :func:`footzoo.evaluation.metrics.match_strides`; None without reference strides or
    when the tables lack the columns to pair them by.
    """
    ref = recording.truth.steps if recording is not None and recording.truth is not None else None
    if ref is None or len(ref) == 0 or len(steps) == 0:
        return None

    try:
        matched = match_strides(steps, ref)
    except (KeyError, ValueError, TypeError):  # tables without the columns to pair strides by
        return None
    end, est_end = time_column(steps, "end"), time_column(matched, "est_end")
    if len(matched) == 0 or end is None or est_end is None:
        return None
    return np.searchsorted(steps[end].to_numpy(float), matched[est_end].to_numpy(float)), matched


def _legend_below(ax: Axes, ncol: int = 4) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=min(ncol, len(labels)))


def _title(result: Result, recording: Recording | None) -> str:
    name = result.config.get("name", "") if isinstance(result.config, dict) else ""
    rec = recording.name if recording is not None else result.recording.get("name", "")
    return f"{name} on {rec}" if rec else str(name)


# --------------------------------------------------------------------------- figures


@styled
def trajectory_figure(result: Result, recording: Recording | None = None) -> Figure:
    """Top view (east vs north) with the stride ends numbered, and height over time with stance shaded.

    The reference (``recording.truth.pos``), when present, is drawn yaw-aligned in black dashes; measured
    footprints (``recording.truth.footprints``) as black crosses, aligned onto the estimated ones
    (:func:`aligned_footprints`).
    """
    plt = pyplot()
    pos = result.pos
    t = result.samples["t"].to_numpy()
    s = _stride(len(t))
    fig, (top, height) = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [1.25, 1]})
    ref = aligned_reference(result, recording)
    if ref is not None:
        top.plot(ref[::s, 1], ref[::s, 0], **REFERENCE_STYLE, label="reference (yaw-aligned)")
        height.plot(t[::s], -ref[::s, 2], **REFERENCE_STYLE, label="reference")
    top.plot(pos[::s, 1], pos[::s, 0], color="C0", lw=1.3, label="estimate")
    footprints = aligned_footprints(result, recording)
    if footprints is not None:
        top.plot(footprints[:, 1], footprints[:, 0], **FOOTPRINT_STYLE, label="measured footprints (aligned)")
    ends = _stride_ends(result)
    if ends is not None:
        number, _, p = ends
        top.plot(p[:, 1], p[:, 0], "o", ms=3.5, mfc="white", mec="C0", mew=1,
                 label=f"stride ends, numbered ({len(result.steps)} strides)")
        every = max(1, int(np.ceil(len(p) / 12)))
        for k in range(0, len(p), every):
            top.annotate(str(number[k]), (p[k, 1], p[k, 0]), textcoords="offset points", xytext=(3, 3),
                         fontsize=7, color="C0")
    top.plot(pos[0, 1], pos[0, 0], "^", color="C2", ms=8, label="start")
    top.plot(pos[-1, 1], pos[-1, 0], "s", color="C3", ms=7, label="end")
    top.set_xlabel("east (m)")
    top.set_ylabel("north (m)")
    top.set_aspect("equal", adjustable="datalim")
    top.set_title("top view")
    _legend_below(top, ncol=3)
    _shade_stance(height, t, result.stance)
    height.plot(t[::s], -pos[::s, 2], color="C0", lw=1.0, label="estimate")
    height.set_xlabel("time (s)")
    height.set_ylabel("height, up (m)")
    height.set_title("height")
    _legend_below(height, ncol=3)
    fig.suptitle(_title(result, recording))
    return fig


@styled
def errors_figure(result: Result, recording: Recording) -> Figure | None:
    """Position error against the reference over time: horizontal and vertical (m); None without a reference.

    Both trajectories start at the first sample where both are known and the
    estimate is yaw-aligned to the reference (least squares); ARMSE in the title.
    """
    ref = aligned_reference(result, recording)
    if ref is None:
        return None
    plt = pyplot()
    t = result.samples["t"].to_numpy()
    s = _stride(len(t))
    err = result.pos - ref
    horiz = np.hypot(err[:, 0], err[:, 1])
    fig, (ax_h, ax_v) = plt.subplots(2, 1, figsize=(9, 4.8), sharex=True)
    _shade_stance(ax_h, t, result.stance)
    ax_h.plot(t[::s], horiz[::s], color="C3", lw=1.0, label="horizontal |Δn, Δe|")
    ax_h.set_ylabel("horizontal error (m)")
    _shade_stance(ax_v, t, result.stance, label=None)
    ax_v.plot(t[::s], err[::s, 2] * -1, color="C4", lw=1.0, label="vertical (estimate − reference, up)")
    ax_v.axhline(0, color="0.4", lw=0.6)
    ax_v.set_ylabel("vertical error (m)")
    ax_v.set_xlabel("time (s)")
    ax_h.legend(loc="upper left")
    ax_v.legend(loc="upper left")
    ok = np.all(np.isfinite(err), axis=1)
    rms = float(np.sqrt(np.mean(np.sum(err[ok] ** 2, axis=1)))) if ok.any() else float("nan")
    fig.suptitle(f"{_title(result, recording)}: position error (3-D RMS {rms:.3f} m)")
    return fig


@styled
def states_figure(result: Result, recording: Recording | None = None,
                  window: tuple[float, float] | None = None) -> Figure:
    """Attitude (deg), velocity (m/s) and gait phase over time, stance shaded; truth dashed where known.

    Parameters
    ----------
    window : (t0, t1), optional
        Time span to show (s); default: the whole recording. A few strides read best.
    """

    check_pair(result, recording)
    plt = pyplot()
    smp = result.samples
    t = smp["t"].to_numpy()
    sel = np.ones(len(t), dtype=bool) if window is None else (t >= window[0]) & (t <= window[1])
    if not sel.any():
        raise ConfigError(f"window {window} (s) is outside the recording ({t[0]:.2f}–{t[-1]:.2f} s); "
                          "give (t0, t1) in seconds within it, or None for the whole recording")
    idx = np.flatnonzero(sel)[:: _stride(int(sel.sum()))]
    truth = recording.truth if recording is not None else None
    stance = result.stance
    stat = result.diagnostics.get("detector_statistic") if isinstance(result.diagnostics, dict) else None
    has_truth_stance = truth is not None and truth.stance is not None and len(truth.stance) == len(t)
    has_stat = stat is not None and len(stat) == len(t)
    ratios = [3, 3] + ([2] if has_stat else []) + [0.5 + 0.35 * has_truth_stance]
    fig, axes = plt.subplots(len(ratios), 1, figsize=(10, 1.9 * sum(ratios) / 2.4 + 1.2), sharex=True,
                             gridspec_kw={"height_ratios": ratios}, layout="constrained")
    ax_att, ax_vel, ax_bars = axes[0], axes[1], axes[-1]
    euler = np.degrees(smp[["roll", "pitch", "yaw"]].to_numpy()[sel])
    true_euler = None
    if truth is not None and truth.quat is not None and len(truth.quat) == len(t):
        true_euler = np.degrees(quat_to_euler(np.asarray(truth.quat)[sel]))
    j = idx - np.flatnonzero(sel)[0]
    for ax in axes[:2]:
        _shade_stance(ax, t[sel], stance[sel], label=None)
    for i, name in enumerate(("roll", "pitch", "yaw")):
        ax_att.plot(t[idx], broken_at_wraps(euler[j, i]), color=f"C{i}", lw=1.0, label=name)
        if true_euler is not None:
            ax_att.plot(t[idx], broken_at_wraps(true_euler[j, i]), color=f"C{i}", ls="--", lw=0.8)
    ax_att.set_ylabel("attitude (deg)")
    vel = result.vel
    for i, name in enumerate(("north", "east", "down")):
        ax_vel.plot(t[idx], vel[idx, i], color=f"C{i}", lw=1.0, label=f"v {name}")
        if truth is not None and truth.vel is not None and len(truth.vel) == len(t):
            ax_vel.plot(t[idx], np.asarray(truth.vel)[idx, i], color=f"C{i}", ls="--", lw=0.8)
    ax_vel.set_ylabel("velocity (m/s)")
    if has_stat:
        ax_stat = axes[2]
        st = np.asarray(stat, dtype=float)
        _shade_stance(ax_stat, t[sel], stance[sel], label=None)
        ax_stat.plot(t[idx], st[idx], color="0.25", lw=0.8, label="detector statistic")
        v = st[sel][np.isfinite(st[sel])]
        if v.size and v.min() > 0 and v.max() / v.min() > 100:
            ax_stat.set_yscale("log")
        ax_stat.set_ylabel("detector\nstatistic")
    bars = [("estimated stance", stance, "C0")]
    if has_truth_stance:
        bars.append(("true stance", np.asarray(truth.stance, dtype=bool), "k"))
    for k, (_, mask, color) in enumerate(bars[::-1]):
        ax_bars.fill_between(t[sel], k + 0.1, k + 0.9, where=mask[sel], step="mid", color=color, alpha=0.45, lw=0)
    # gait events of the stride table (initial contact = a stride's end; toe-off when the table has it)
    steps = result.steps
    top = len(bars) - 0.05
    t0, t1 = t[sel][0], t[sel][-1]
    for names, marker, label in ((("ic", "end"), "v", "initial contact"), (("to", "toe_off"), "^", "toe-off")):
        col = time_column(steps, *names) if len(steps) else None
        if col is not None:
            ev = steps[col].to_numpy(float)
            ev = ev[np.isfinite(ev) & (ev >= t0) & (ev <= t1)]
            if ev.size:
                ax_bars.plot(ev, np.full(ev.size, top), marker, color="C3" if marker == "v" else "C2", ms=5,
                             ls="none", label=label, clip_on=False)
    if ax_bars.get_legend_handles_labels()[0]:
        ax_bars.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax_bars.set_ylim(0, len(bars))
    ax_bars.set_yticks([k + 0.5 for k in range(len(bars))], [b[0] for b in bars[::-1]])
    ax_bars.grid(False)
    ax_bars.set_xlabel("time (s)")
    ax_att.set_title("attitude, velocity and gait phase (grey: estimated stance" +
                     ("; dashed: truth)" if true_euler is not None else ")"), loc="left")
    for ax in (ax_att, ax_vel):
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(_title(result, recording))
    return fig


@styled
def strides_figure(result: Result, recording: Recording | None = None) -> Figure | None:
    """Per-stride parameters against stride number, one panel each; reference strides where known.

    Draws every quantity of :data:`STRIDE_QUANTITIES` that ``result.steps`` has
    (extra columns such as gait events are used when present, whatever their
    unit suffix). Outliers (e.g. a first stride that includes the initial
    standing) are drawn as triangles on the axis edge so they do not flatten the
    rest. None when the run found no stride.
    """
    check_pair(result, recording)
    steps = result.steps
    if len(steps) == 0:
        return None
    found = [(name, label, *col) for name, label in STRIDE_QUANTITIES if (col := step_column(steps, name)) is not None]
    if not found:
        return None
    plt = pyplot()
    reference = reference_strides(steps, recording)
    n = len(found)
    ncol = 2 if n > 2 else 1
    nrow = int(np.ceil(n / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 2.0 * nrow + 0.8), sharex=True, squeeze=False,
                             layout="constrained")
    x = np.arange(len(steps))
    for ax, (name, label, values, unit) in zip(axes.flat, found, strict=False):
        ax.plot(x, values, "o-", color="C0", ms=3.5, lw=0.8, label="estimate")
        finite = values[np.isfinite(values)]
        med = f": median {np.median(finite):.3g}" if finite.size else ""
        ref = step_column(reference[1], name) if reference is not None else None
        if ref is not None:
            ax.plot(reference[0], ref[0], "x", color="k", ms=5, label="reference")
        _clip_outliers(ax, x, values, "C0", also=ref[0] if ref is not None else None)
        lo, hi = ax.get_ylim()
        if finite.size and hi - lo < 0.05 * abs(float(np.median(finite))):  # mm on a metre is not a swing
            half = 0.025 * abs(float(np.median(finite)))
            ax.set_ylim((lo + hi) / 2 - half, (lo + hi) / 2 + half)
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.set_ylabel(unit)
        ax.set_title(f"{label}{med}{' ' + unit if unit and med else ''}", loc="left")
    for ax in axes[-1]:
        ax.set_xlabel("stride number")
        ax.xaxis.set_tick_params(labelbottom=True)
    for i, ax in enumerate(axes.flat):
        if i >= n:
            ax.set_visible(False)
            above = axes.flat[i - ncol]
            above.set_xlabel("stride number")
            above.xaxis.set_tick_params(labelbottom=True)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    for ax in list(axes.flat)[1:n]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="outside lower center", ncol=len(labels))
    fig.suptitle(f"{_title(result, recording)}: {len(steps)} strides")
    return fig


@styled
def fpa_figure(result: Result, recording: Recording | None = None) -> Figure | None:
    """Foot progression angle per stride (deg, toe-out positive) and its distribution; None without FPA."""
    col = step_column(result.steps, "fpa")
    if col is None or not np.isfinite(col[0]).any():
        return None
    plt = pyplot()
    fpa = col[0]
    fig, (ax, hist) = plt.subplots(1, 2, figsize=(9, 3.8), gridspec_kw={"width_ratios": [2.2, 1]}, sharey=True,
                                   layout="constrained")
    x = np.arange(len(fpa))
    ax.plot(x, fpa, "o-", ms=3.5, lw=0.8, color="C1", label="estimate")
    reference = reference_strides(result.steps, recording)
    ref = step_column(reference[1], "fpa") if reference is not None else None
    if ref is not None:
        ax.plot(reference[0], ref[0], "x", color="k", ms=5, label="reference")
    finite = fpa[np.isfinite(fpa)]
    if finite.min() < 0 < finite.max():
        ax.axhline(0, color="0.4", lw=0.6)
    ax.set_xlabel("stride number")
    ax.set_ylabel("foot progression angle (deg, toe-out +)")
    _clip_outliers(ax, x, fpa, "C1", also=ref[0] if ref is not None else None)
    lo, hi = ax.get_ylim()
    if hi - lo < MIN_FPA_SPAN:  # do not blow sensor noise up to a full axis
        mid = (lo + hi) / 2
        lo, hi = mid - MIN_FPA_SPAN / 2, mid + MIN_FPA_SPAN / 2
        ax.set_ylim(lo, hi)
    hist.hist(finite, bins=np.linspace(lo, hi, 31), orientation="horizontal", color="C1", alpha=0.7)
    med = float(np.median(finite))
    hist.axhline(med, color="k", lw=0.8, label=f"median {med:.1f}°")
    hist.set_xlabel("strides")
    fig.legend(loc="outside lower center", ncol=3)
    fig.suptitle(f"{_title(result, recording)}: foot progression angle")
    return fig


def plot_trajectory(result: Result, path: str | Path, recording: Recording | None = None) -> Path:
    """Write :func:`trajectory_figure` to ``path`` (PNG, PDF or SVG by suffix)."""
    return save(trajectory_figure(result, recording), path)


def plot_run(result: Result, out: str | Path, recording: Recording | None = None,
             window: tuple[float, float] | None = None) -> list[Path]:
    """Write the run's figures into the folder ``out``; returns the files written.

    ``trajectory.png`` (top view with numbered stride ends and reference, height),
    ``states.png`` (attitude, velocity, gait phase; ``window`` in s limits it),
    ``errors.png`` (only with a reference), ``strides.png`` and ``fpa.png``
    (only when the run found strides / foot progression angles).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return [save(fig, out / name) for name, fig in run_figures(result, recording, window).items()]


def run_figures(result: Result, recording: Recording | None = None,
                window: tuple[float, float] | None = None) -> dict[str, Figure]:
    """The figures of :func:`plot_run` by file name (``trajectory.png``, ...), not saved.

    ``footzoo run --plot --out`` saves them with the result archive, as one unit
    (:meth:`footzoo.Result.save` ``files=``, each as :func:`png_bytes`).
    """
    figures = {"trajectory.png": trajectory_figure(result, recording),
               "states.png": states_figure(result, recording, window)}
    for name, fig in (("errors", errors_figure(result, recording) if recording is not None else None),
                      ("strides", strides_figure(result, recording)), ("fpa", fpa_figure(result, recording))):
        if fig is not None:
            figures[f"{name}.png"] = fig
    return figures
