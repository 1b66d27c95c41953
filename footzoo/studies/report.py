"""Study outputs: tidy table (Parquet, CSV), summaries per factor level (Markdown, LaTeX), plots."""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import re
import shutil
import tempfile
import textwrap
import threading
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.errors import FootzooWarning, user_stacklevel
from ..evaluation.metrics import rotate_about_vertical, yaw_alignment
from ..evaluation.plots import FOOTPRINT_STYLE, REFERENCE_STYLE, png_bytes, pyplot, save, styled
from .cache import HEAVY, with_heavy


def summarise(table: pd.DataFrame, factor: str) -> pd.DataFrame:
    """Mean, median, standard deviation and count of every metric per level of one factor, and why values are missing.

    The levels are the table's own values (a plug-in spec as JSON text); :func:`readable` labels them.
    A metric NaN in every run of a level (refused) has count 0; ``reason`` then gives the table's
    ``note`` of those runs (each distinct one once), and ``"k of n runs: ..."`` when only some runs have
    no value; it is empty where every run has one.
    """
    ok = table[table["metric"].notna()]
    if "note" not in ok.columns:  # a table written before the notes
        ok = ok.assign(note=None)
    g = ok.groupby([factor, "metric"], dropna=False)
    out = g["value"].agg(["mean", "median", "std", "count"])
    out["reason"] = [_missing_reason(d["value"], d["note"]) for _, d in g[["value", "note"]]] if len(ok) else []
    return out.reset_index().sort_values(["metric", factor]).reset_index(drop=True)


#: A number in a message (``12``, ``-0.77``, ``1e+06``): messages that differ only in these are alike.
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def alike(text: str, labels: Iterable[str] = ()) -> str:
    """The shape of a message: its text with the recordings' names (``labels``) and every number blanked."""
    for label in labels:
        text = text.replace(label, "<recording>")
    return _NUMBER.sub("#", text)


def grouped(counts: dict[str, int]) -> list[tuple[str, int, int]]:
    """Distinct messages with their counts, those alike but for their numbers merged: ``(first, total count,
    how many distinct messages it stands for)``, in the order of their first appearance."""
    groups: dict[str, list[tuple[str, int]]] = {}
    for text, n in counts.items():
        groups.setdefault(alike(text), []).append((text, n))
    return [(members[0][0], sum(n for _, n in members), len(members)) for members in groups.values()]


def _missing_reason(values: pd.Series, notes: pd.Series) -> str:
    """Why a summary's metric lacks values in some runs: their distinct notes, those alike but for their numbers
    given once with how many more there are (empty when no value is missing)."""
    missing = values.isna().to_numpy()
    if not missing.any():
        return ""
    distinct = dict.fromkeys((str(n) for n in notes[missing] if isinstance(n, str) and n), 1)
    why = "; ".join(text if k == 1 else f"{text} (and {k - 1} alike, with other numbers)"
                    for text, _, k in grouped(distinct)) or "no reason recorded"
    return why if missing.all() else f"{int(missing.sum())} of {len(values)} runs: {why}"


def compared(table: pd.DataFrame, factors: list[str]) -> list[str]:
    """What a study compares: ``base`` first when it has several base configs, then its factors.

    A comparison of configs gets what a factor gets: a box plot per metric and a summary.
    """
    several = "base" in table.columns and table["base"].nunique(dropna=True) > 1
    return (["base"] if several else []) + [f for f in factors if f != "base"]


def readable(summary: pd.DataFrame, factor: str) -> pd.DataFrame:
    """A summary (:func:`summarise`) with its levels labelled as the plots label them (:func:`level_labels`).

    A plug-in spec ``{"type": "shoe", "threshold": 1e5}`` becomes ``shoe (threshold=1e+05)``, showing
    only what differs between the levels; a number keeps its value. The levels stay as they are
    when two would get one label.
    """
    text = _level_text(factor, summary[factor])
    out = summary.copy()
    out[factor] = [text[str(v)] for v in summary[factor]]
    return out


def _level_text(factor: str, values: pd.Series) -> dict[str, str]:
    """Each level of ``factor`` among ``values`` (by ``str(level)``) as a table cell under the factor's name: its
    :func:`level_labels` label without the factor's own name (``static_gain=``), or the level as it is when two
    would get one label."""
    levels = list(dict.fromkeys(values.tolist()))
    leaf = factor.split(".")[-1] + "="  # the column names the factor already
    text = {k: v.removeprefix(leaf) for k, v in level_labels(factor, levels).items()}
    return text if len(set(text.values())) == len(levels) else {str(v): str(v) for v in levels}


def crossed(table: pd.DataFrame, rows: str, columns: str) -> pd.DataFrame:
    """The median of every metric over the runs of each pair of levels of two factors: one row per metric and level
    of ``rows``, one column per level of ``columns``.

    The median over the recordings and seeds of a cell, as :func:`summarise`'s; a cell whose runs all lack a
    value (refused, or failed) is NaN. Levels are labelled as :func:`readable` labels them.
    """
    ok = table[table["metric"].notna()]
    wide = ok.pivot_table(index=["metric", rows], columns=columns, values="value", aggfunc="median", dropna=False)
    wide = wide.reindex(columns=list(dict.fromkeys(ok[columns].tolist())))
    names = {f: _level_text(f, ok[f]) for f in (rows, columns)}
    wide.columns = [names[columns][str(c)] for c in wide.columns]
    out = wide.reset_index()
    out[rows] = [names[rows][str(v)] for v in out[rows]]
    return out.rename(columns={rows: f"{rows} \\ {columns}"})


def to_markdown(df: pd.DataFrame, digits: int = 4) -> str:
    """A GitHub-style Markdown table."""
    cols = [str(c) for c in df.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for row in df.itertuples(index=False):
        lines.append("| " + " | ".join(_fmt(v, digits).replace("|", r"\|") for v in row) + " |")  # a note's "|"
    return "\n".join(lines) + "\n"


#: The characters a LaTeX table escapes, with their escape.
LATEX_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
                 "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}


def to_latex(df: pd.DataFrame, digits: int = 4) -> str:
    """A booktabs LaTeX tabular."""
    def esc(v: Any) -> str:  # every character LaTeX gives a meaning (a reason is free text)
        return "".join(LATEX_ESCAPES.get(c, c) for c in _fmt(v, digits))

    cols = list(df.columns)
    lines = [r"\begin{tabular}{" + "l" * len(cols) + "}", r"\toprule",
             " & ".join(esc(c) for c in cols) + r" \\", r"\midrule"]
    lines += [" & ".join(esc(v) for v in row) + r" \\" for row in df.itertuples(index=False)]
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines) + "\n"


def _fmt(v: Any, digits: int) -> str:
    if isinstance(v, float):
        return "" if np.isnan(v) else f"{v:.{digits}g}"
    return str(v)


def write_outputs(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path,
                  step: Callable[[int], Any] | None = None, jobs: int = 1, scheduler: Any = None,
                  figures: list[str] | None = None) -> list[str]:
    """Write the tidy table, the trajectories and sweeps (apart from it), summaries and plots into ``out``;
    return the names of the files written.

    ``step(1)`` is called after each of the four parts (tables, trajectories, summaries, plots).
    Everything is written into a staging folder first and then moved into ``out`` file by file
    (atomic renames): an interrupted report or two studies writing into one folder never leave a
    half-written file. With ``jobs`` other than 1 the figures are drawn by that many local worker
    processes (see :func:`figure_tasks`) while this process writes the tables; with ``scheduler``
    (a Dask scheduler's address, or a connected ``Client``) the cluster's workers draw them in memory
    (:func:`render_figure`) and this process writes the files, since the workers may not see ``out``.
    ``figures`` names the metrics drawn as a box plot per factor (default: every metric of the table).
    """
    step = step or (lambda n: None)
    out.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=out))
    try:
        _write_outputs(table, runs, factors, staging, step, jobs, scheduler, figures)
        written = [f.name for f in sorted(staging.iterdir()) if f.is_file()]
        for name in written:
            os.replace(staging / name, out / name)
        return written
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def figure_tasks(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str],
                 figures: list[str] | None = None) -> list[tuple]:
    """:func:`plot_study` as independent one-figure tasks for :func:`draw_figure`, in its order.

    Each task carries only what its figure reads (the runs of one recording, the rows of one
    metric, the threshold sweeps), so the tasks are cheap to send to worker processes and can
    be shared out evenly; their figures together are the whole call's, labels included. A box plot
    is drawn per factor for each metric of the table that ``figures`` names (default: every one) and at
    least one run could compute (a metric NaN in every run would be an empty plot: the table's ``note`` says why).
    """
    tasks: list[tuple] = []
    labels = run_labels(runs, factors)
    for rec in sorted({r["recording"] for r in runs}):
        mine = [r for r in runs if r["recording"] == rec]
        tasks.append(("trajectories", mine, {r["key"]: labels[r["key"]] for r in mine}, rec))
    ok = table[table["metric"].notna()]
    scored = ok.groupby("metric")["value"].apply(lambda v: bool(np.isfinite(v.to_numpy(float)).any()))
    ok = ok[ok["metric"].map(scored)]  # a metric no run could compute (NaN, its reason in the note) has no figure
    for f in compared(table, factors):
        for metric in sorted(m for m in ok["metric"].unique() if figures is None or m in figures):
            tasks.append(("metric", ok[ok["metric"] == metric], f, metric))
    detector_factors = [f for f in factors if f == "detector" or f.startswith("detector.")]
    sweeps = [{k: r[k] for k in ("key", "recording", "roc", "entry") if k in r} for r in runs]
    tasks.append(("roc", sweeps, run_labels(runs, factors, only=detector_factors or None)))
    return tasks


#: the figure tasks' kinds, most expensive first: the ROC draws every run's sweep, a trajectory plot the
#: runs of one recording, a metric plot one box per level
_COST_RANK = {"roc": 0, "trajectories": 1, "metric": 2}


def _largest_first(tasks: list[tuple]) -> list[tuple]:
    """The tasks in the order workers should take them: the longest first, so none is left alone at the end."""
    return sorted(tasks, key=lambda task: _COST_RANK.get(task[0], 1))


def _figure(task: tuple) -> tuple[Any, str]:
    """The figure of one task of :func:`figure_tasks` (None: nothing to draw) and its file name."""
    kind = task[0]
    task = loaded(task)
    if kind == "trajectories":
        _, runs, labels, rec = task
        return trajectories_figure(runs, labels, rec), f"trajectories_{_safe(rec)}.png"
    if kind == "metric":
        _, rows, factor, metric = task
        return metric_figure(rows, factor, metric), f"metric_{_safe(metric)}_by_{_safe(factor)}.png"
    _, runs, labels = task
    return roc_figure(runs, labels), "roc.png"


def loaded(task: tuple) -> tuple:
    """A figure task with its runs' trajectories or sweeps read back from the cache (a study keeps them
    on disk, :func:`footzoo.studies.cache.light`); a task that has them is returned as it is."""
    if task[0] == "trajectories":
        return (task[0], with_heavy(task[1], TRAJECTORY_FIELDS), *task[2:])
    if task[0] == "roc":
        return (task[0], with_heavy(task[1], ("roc",)), *task[2:])
    return task


def draw_figure(task: tuple, out: Path) -> Path | None:
    """Draw and save one task of :func:`figure_tasks` into ``out``; the file written, or None (nothing to draw)."""

    fig, name = _figure(task)
    return None if fig is None else save(fig, Path(out) / name)


#: pyplot and its rcParams are per process, not per thread: a worker with several threads draws one figure at a time.
_DRAWING = threading.Lock()


def render_figure(task: tuple) -> tuple[str, bytes] | None:
    """One task of :func:`figure_tasks` drawn in memory: its file name and the bytes :func:`draw_figure` would write."""

    with _DRAWING:
        fig, name = _figure(task)
        return None if fig is None else (name, png_bytes(fig))


def _write_outputs(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path,
                   step: Callable[[int], Any], jobs: int = 1, scheduler: Any = None,
                   figures: list[str] | None = None) -> None:
    table = table.copy()
    table.attrs = {}  # counts and cache notes describe this execution, not the results
    if scheduler is not None:
        # deferred: dask, an optional extra (footzoo[distributed])
        from dask.distributed import Client, as_completed

        connected = contextlib.nullcontext(scheduler) if isinstance(scheduler, Client) else Client(scheduler)
        with connected as client:  # the workers draw while this process writes the tables
            # the workers may not see the cache: each task is sent with its runs' trajectories, a few at a time
            tasks = iter(_largest_first(figure_tasks(table, runs, factors, figures)))
            window = max(2, 2 * len(client.scheduler_info().get("workers", {})))
            pending = as_completed([client.submit(render_figure, loaded(t), pure=False)
                                    for t in itertools.islice(tasks, window)])
            _write_tables(table, runs, factors, out, step)
            for fut in pending:
                drawn = fut.result()
                if drawn is not None:
                    (out / drawn[0]).write_bytes(drawn[1])
                nxt = next(tasks, None)
                if nxt is not None:
                    pending.add(client.submit(render_figure, loaded(nxt), pure=False))
        step(1)
        return
    drawn = None
    if jobs != 1:  # started first: the workers draw while this process writes the tables
        # deferred: joblib, only for parallel figures
        from joblib import Parallel, delayed

        drawn = Parallel(n_jobs=jobs, return_as="generator_unordered", batch_size=1)(
            delayed(draw_figure)(task, out) for task in _largest_first(figure_tasks(table, runs, factors, figures)))
    _write_tables(table, runs, factors, out, step)
    if drawn is None:
        plot_study(table, runs, factors, out, figures)
    else:
        for _ in drawn:
            pass
    step(1)


#: The report's tables, as :func:`_write_tables` names them (its figures aside): in a study's folder, an earlier
#: study's report lists them (the runner refuses a folder holding one that no study wrote).
REPORT_TABLES = ("results.csv", "results.parquet", "summary.md", "summary.tex", "trajectories.parquet", "roc.parquet")


def _write_tables(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path,
                  step: Callable[[int], Any]) -> None:
    """The tidy table, the trajectories and sweeps, the summaries (``step(1)`` after each)."""
    table.to_csv(out / "results.csv", index=False)
    skipped = _to_parquet(table, out / "results.parquet")
    step(1)
    skipped += _write_frames(runs, out)
    if skipped:  # one warning for the missing package, naming every file it costs
        warnings.warn(f"pyarrow is not installed: {', '.join(skipped)} not written (results.csv has the table; "
                      "pip install 'footzoo[parquet]' or pyarrow to get them)", FootzooWarning,
                      stacklevel=user_stacklevel())
    step(1)
    md, tex = [], []
    for f in ["base", *factors]:
        s = readable(summarise(table, f), f)
        md.append(f"## {f}\n\n" + to_markdown(s))
        tex.append(f"% {f}\n" + to_latex(s))
    for a, b in itertools.combinations(compared(table, factors), 2):  # two factors: the median of each pair of levels
        s = crossed(table, a, b)
        md.append(f"## {a} × {b} (median)\n\n" + to_markdown(s))
        tex.append(f"% {a} x {b} (median)\n" + to_latex(s))
    errors = table[table["error"].notna()][["run", "recording", "error"]].drop_duplicates()
    if len(errors):
        md.append("## failed runs\n\n" + to_markdown(errors))
    (out / "summary.md").write_text("\n".join(md))
    (out / "summary.tex").write_text("\n".join(tex))
    step(1)


#: Runs whose trajectories are read back from the cache and written at a time (bounded memory).
FRAME_BATCH = 200


def _write_frames(runs: list[dict[str, Any]], out: Path) -> list[str]:
    """``trajectories.parquet`` and ``roc.parquet``, written :data:`FRAME_BATCH` runs at a time; the names of
    those not written (no pyarrow)."""
    if len(runs) <= FRAME_BATCH:
        trajectories, roc = run_frames(with_heavy(runs, HEAVY))
        return _to_parquet(trajectories, out / "trajectories.parquet") + _to_parquet(roc, out / "roc.parquet")
    try:
        # deferred: pyarrow, an optional extra (footzoo[parquet])
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return ["trajectories.parquet", "roc.parquet"]
    writers: dict[str, Any] = {}
    try:
        for k in range(0, len(runs), FRAME_BATCH):
            frames = run_frames(with_heavy(runs[k:k + FRAME_BATCH], HEAVY))
            for name, frame in zip(("trajectories", "roc"), frames, strict=True):
                if len(frame) == 0 and (name in writers or k + FRAME_BATCH < len(runs)):
                    continue
                t = pa.Table.from_pandas(frame, preserve_index=False)
                if name not in writers:
                    writers[name] = pq.ParquetWriter(out / f"{name}.parquet", t.schema)
                writers[name].write_table(t.cast(writers[name].schema))
    finally:
        for w in writers.values():
            w.close()
    return []


def run_frames(runs: list[dict[str, Any]]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The runs' stored trajectories and threshold sweeps as two tidy tables, apart from the results table.

    Returns
    -------
    trajectories : DataFrame
        ``run``, ``recording``, ``t_s``, ``north_m``, ``east_m``, ``down_m`` (one row per stored point).
    roc : DataFrame
        ``run``, ``recording``, ``threshold``, ``true_stance_rate``, ``false_stance_rate``.
    """
    def frame(field: str, cols: list[str]) -> pd.DataFrame:
        parts = [(r["key"], r["recording"], np.asarray(r[field], float)) for r in runs if _has(r, field)]
        if not parts:
            return pd.DataFrame({c: pd.Series(dtype=float if i > 1 else object) for i, c in enumerate(cols)})
        values = np.concatenate([a for _, _, a in parts])
        return pd.DataFrame({
            cols[0]: np.repeat([k for k, _, _ in parts], [len(a) for _, _, a in parts]),
            cols[1]: np.repeat([rec for _, rec, _ in parts], [len(a) for _, _, a in parts]),
            **{c: values[:, j] for j, c in enumerate(cols[2:])},
        })

    return (frame("trajectory", ["run", "recording", "t_s", "north_m", "east_m", "down_m"]),
            frame("roc", ["run", "recording", "threshold", "true_stance_rate", "false_stance_rate"]))


def _has(record: dict[str, Any], field: str) -> bool:
    """Whether a run record holds a non-empty ``field`` (a list, or an array read back from the cache)."""
    value = record.get(field)
    return value is not None and len(value) > 0


def _to_parquet(df: pd.DataFrame, path: Path) -> list[str]:
    """Write ``df`` as Parquet; ``[path.name]`` when pyarrow is not installed (the caller says so), else ``[]``."""
    try:
        df.to_parquet(path, index=False)
    except ImportError:  # pyarrow not installed: CSV only
        return [path.name]
    return []


# --------------------------------------------------------------------------- human labels


def _flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    """``{"a.b": 1, ...}`` of nested dicts and lists (list items keyed by position)."""
    if isinstance(value, dict):
        out: dict[str, Any] = {}
        for k, v in value.items():
            out.update(_flatten(v, f"{prefix}{k}."))
        return out
    if isinstance(value, list):
        out = {}
        for i, v in enumerate(value):
            out.update(_flatten(v, f"{prefix}{i}."))
        return out
    return {prefix.rstrip("."): value}


def _fmt_value(v: Any) -> str:
    if isinstance(v, bool):
        return "on" if v else "off"
    if isinstance(v, float):
        return f"{v:.3g}"
    return str(v)


def _describe(value: Any, keep: set[str], path: str = "") -> str:
    """Short text of a factor level: plug-in types by name, only the parameters in ``keep``."""
    if isinstance(value, dict):
        name = str(value.get("type", ""))
        params = [f"{k}={_fmt_value(v)}" for k, v in value.items()
                  if k != "type" and f"{path}{k}" in keep and not isinstance(v, (dict, list))]
        params += [f"{k}: {_describe(v, keep, f'{path}{k}.')}" for k, v in value.items()
                   if isinstance(v, (dict, list)) and any(q.startswith(f"{path}{k}.") for q in keep)]
        inner = ", ".join(params)
        return f"{name} ({inner})" if name and inner else name or inner
    if isinstance(value, list):
        parts = [_describe(v, keep, f"{path}{i}.") for i, v in enumerate(value)]
        return " + ".join(p for p in parts if p) or "none"
    return _fmt_value(value)


def _parse(value: Any) -> Any:
    """A table cell back to its value (lists and dicts are stored as JSON text)."""
    if isinstance(value, str) and value[:1] in "[{":
        try:
            return json.loads(value)
        except ValueError:
            return value
    return value


def level_labels(factor: str, levels: list[Any]) -> dict[str, str]:
    """Human label of each level of one factor, keyed by ``str(level)``.

    Plug-in specs become their type names (``[{'type': 'zupt'}]`` -> ``zupt``), a
    list of corrections is joined with ``+``, and only the parameters that differ
    between the levels are shown (``ekf_zupt (gyro_bias=off)``). Plain numbers
    get the factor's last name (``static_gain=1.05``) unless the factor picks a
    plug-in type.
    """
    parsed = [_parse(v) for v in levels]
    flat = [_flatten(v) for v in parsed]
    paths = set().union(*flat) if flat else set()
    differing = {p for p in paths if len({json.dumps(f.get(p), sort_keys=True, default=str) for f in flat}) > 1}
    leaf = factor.split(".")[-1]
    out = {}
    for raw, value in zip(levels, parsed, strict=True):
        if isinstance(value, (dict, list)):
            text = _describe(value, differing)
        elif leaf == "type" or isinstance(value, str):
            text = _fmt_value(value)
        else:
            text = f"{leaf}={_fmt_value(value)}"
        out[str(raw)] = text
    return out


def run_labels(runs: list[dict[str, Any]], factors: list[str], only: list[str] | None = None) -> dict[str, str]:
    """Human label of each run's configuration (by run key) from its factor levels and base.

    ``only`` restricts the label to some factors (e.g. the detector's, for threshold sweeps).
    """
    use = [f for f in factors if only is None or f in only]
    names: dict[str, dict[str, str]] = {}
    for f in use:
        distinct: dict[str, Any] = {}
        for r in runs:
            v = r["levels"].get(f)
            distinct.setdefault(json.dumps(v, sort_keys=True, default=str), v)
        text = level_labels(f, list(distinct.values()))
        names[f] = {k: text[str(v)] for k, v in distinct.items()}
    several_bases = len({str(r.get("base", "")) for r in runs}) > 1
    out = {}
    for r in runs:
        parts = [Path(str(r.get("base", ""))).stem] if several_bases or not use else []
        parts += [names[f][json.dumps(r["levels"].get(f), sort_keys=True, default=str)] for f in use]
        out[r["key"]] = ", ".join(p for p in parts if p) or str(r.get("base", ""))
    return out


def metric_label(metric: str) -> str:
    """``loop_closure_xy_pct`` -> ``loop closure xy (%)``: the unit suffix in brackets."""
    units = {"m": "m", "pct": "%", "deg": "deg", "s": "s", "rad": "rad", "m_s": "m/s"}
    for suffix, unit in sorted(units.items(), key=lambda kv: -len(kv[0])):
        if metric.endswith("_" + suffix):
            return f"{metric[: -len(suffix) - 1].replace('_', ' ')} ({unit})"
    return metric.replace("_", " ")


# --------------------------------------------------------------------------- plots


def plot_study(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path,
               figures: list[str] | None = None) -> list[Path]:
    """Trajectories per recording, metrics per factor level, ROC of the detectors' threshold sweeps.

    Returns the files written. The figures are the tasks of :func:`figure_tasks`, drawn in order;
    ``figures`` names the metrics drawn (default: every metric of ``table``).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = figure_tasks(table, runs, factors, figures)
    return [p for p in (draw_figure(task, out) for task in tasks) if p is not None]


def _grid(plt, n: int, size: float = 2.6, max_cols: int = 8):
    """``n`` small panels in rows of at most ``max_cols`` (the caller gives them equal limits)."""
    ncol = min(max_cols, max(1, int(np.ceil(np.sqrt(n)))))
    nrow = int(np.ceil(n / ncol))
    # a fixed layout: constrained layout costs seconds per figure with a hundred panels
    w, h = size * ncol + 0.6, size * nrow + 1.0
    fig, axes = plt.subplots(nrow, ncol, figsize=(w, h), squeeze=False)
    fig.subplots_adjust(left=0.5 / w, right=1 - 0.1 / w, bottom=0.4 / h, top=1 - 1.2 / h, wspace=0.3, hspace=0.5)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


#: Up to this many configurations share one axis (legend below it); more get one panel each.
MAX_OVERLAID = 8


#: The run-record fields a trajectories figure reads back from the cache.
TRAJECTORY_FIELDS = ("trajectory", "reference", "footprints", "trajectory_on_footprints")


def _curves(runs: list[dict[str, Any]], labels: dict[str, str]
            ) -> tuple[list[tuple[str, np.ndarray]], np.ndarray | None, np.ndarray | None, str]:
    """Each run's top-view curve (label, (N, 3) NED m) in one common frame, the reference path, the measured
    footprints (K, 2) and the frame's name (see :func:`trajectories_figure`)."""
    ref = next((np.asarray(r["reference"], float) for r in runs if _has(r, "reference")), None)
    footprints = next((np.asarray(r["footprints"], float) for r in runs if _has(r, "footprints")), None)
    curves = []
    if ref is not None:
        ref = ref[:, 1:4] - ref[0, 1:4]
        for r in runs:
            tr = np.asarray(r["trajectory"], float)[:, 1:4]
            tr = tr - tr[0]
            if len(ref) == len(tr):
                ok = np.all(np.isfinite(ref), axis=1) & np.all(np.isfinite(tr), axis=1)
                if ok.sum() > 2:
                    tr = rotate_about_vertical(tr, yaw_alignment(tr[ok], ref[ok]))
            curves.append((labels.get(r["key"], r["key"]), tr))
        return curves, ref, None, "estimates yaw-aligned to the reference"
    if footprints is not None:
        unpaired = 0
        for r in runs:
            if _has(r, "trajectory_on_footprints"):
                on = np.asarray(r["trajectory_on_footprints"], float)[:, 1:4]
                curves.append((labels.get(r["key"], r["key"]), on))
            else:
                unpaired += 1
        frame = "estimates aligned on the measured footprints (×)"
        if unpaired:
            frame += f"; {unpaired} run(s) whose footprints do not pair with them not drawn"
        return curves, None, footprints, frame
    for r in runs:
        tr = np.asarray(r["trajectory"], float)[:, 1:4]
        curves.append((labels.get(r["key"], r["key"]), tr - tr[0]))
    return curves, None, None, "estimates as computed"


def trajectories_figure(runs: list[dict[str, Any]], labels: dict[str, str], recording: str):
    """Top views of every configuration on one recording, the reference (if stored) in black dashes.

    With a reference, each estimate is yaw-aligned to it (least squares), so all
    share the reference's frame. With measured footprints instead (Köroğlu's ground
    control points), each estimate is drawn in their frame, moved there by the 2-D
    rigid alignment of its estimated footprints that the footprint metric uses, and
    the footprints are black crosses; a run whose footprints do not pair with them
    is left out (the title says how many). Up to :data:`MAX_OVERLAID` configurations
    share one axis with the legend below it; more get one small panel each (same
    scale), the reference repeated in every panel.
    """

    runs = [r for r in runs if _has(r, "trajectory")]
    if not runs:
        return None

    @styled
    def build():
        plt = pyplot()
        curves, ref, footprints, frame = _curves(runs, labels)
        if len(curves) <= MAX_OVERLAID:
            fig, ax = plt.subplots(figsize=(6.5, 6), layout="constrained")
            if ref is not None:
                ax.plot(ref[:, 1], ref[:, 0], **REFERENCE_STYLE, label="reference", zorder=5)
            if footprints is not None:
                ax.plot(footprints[:, 1], footprints[:, 0], **FOOTPRINT_STYLE, label="measured footprints", zorder=5)
            for label, tr in curves:
                ax.plot(tr[:, 1], tr[:, 0], lw=1.2, label=label)
            ax.set_xlabel("east (m)")
            ax.set_ylabel("north (m)")
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_title(f"{recording}: {frame}")
            extra = (ref is not None) + (footprints is not None)
            fig.legend(loc="outside lower center", ncol=2 if len(curves) > 3 else len(curves) + extra)
            return fig
        fig, axes = _grid(plt, len(curves))
        marks = None if footprints is None else np.column_stack([footprints, np.zeros(len(footprints))])
        mid, half = _common_frame([tr for _, tr in curves], ref if ref is not None else marks)
        for ax, (label, tr) in zip(axes, curves, strict=True):
            if ref is not None:
                ax.plot(ref[:, 1], ref[:, 0], **REFERENCE_STYLE)
            if footprints is not None:
                ax.plot(footprints[:, 1], footprints[:, 0], **{**FOOTPRINT_STYLE, "ms": 4})
            ax.plot(tr[:, 1], tr[:, 0], lw=1.0, color="C0")
            ax.set_xlim(mid[1] - half, mid[1] + half)
            ax.set_ylim(mid[0] - half, mid[0] + half)
            ax.set_aspect("equal")
            ax.set_title(label, fontsize=8)
            ax.tick_params(labelsize=7)
            finite = tr[np.all(np.isfinite(tr), axis=1)]
            if finite.size and np.any(np.abs(finite[:, :2] - mid[:2]) > half):
                ax.annotate("leaves the frame", (0.98, 0.02), xycoords="axes fraction", ha="right", va="bottom",
                            fontsize=7, color="C3")
        fig.suptitle(f"{recording}: {frame}" + (" (dashed: reference)" if ref is not None else "") +
                     "; axes in m, north up")
        return fig

    return build()


def _common_frame(curves: list[np.ndarray], ref: np.ndarray | None) -> tuple[np.ndarray, float]:
    """Centre and half-width (m) of one square frame for all panels, robust to diverging runs.

    The frame covers the reference (or, without one, every run whose extent is at
    most three times the median extent), with a margin; a run that diverges far
    beyond it would otherwise shrink every other panel to a dot.
    """
    def box(p: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        p = p[np.all(np.isfinite(p), axis=1)]
        return (p.min(axis=0), p.max(axis=0)) if len(p) else None

    boxes = [b for b in (box(c) for c in curves) if b is not None]
    if ref is not None and box(ref) is not None:
        keep = [box(ref)]
    else:
        extent = np.array([float(np.max(hi[:2] - lo[:2])) for lo, hi in boxes]) if boxes else np.array([1.0])
        keep = [b for b, e in zip(boxes, extent, strict=True) if e <= 3 * np.median(extent)] or boxes
    if not keep:
        return np.zeros(3), 1.0
    lo = np.min([b[0] for b in keep], axis=0)
    hi = np.max([b[1] for b in keep], axis=0)
    half = 0.65 * max(float(hi[0] - lo[0]), float(hi[1] - lo[1]), 1e-3)
    return (lo + hi) / 2, half


def _scale(ax, values: np.ndarray, axis: str = "y") -> str:
    """Log scale when the largest value is over 20 times the median (symlog with zeros); returns the scale."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size < 3:
        return "linear"
    med = float(np.median(np.abs(v)))
    big = float(np.max(np.abs(v)))
    if med <= 0 or big / med <= 20:
        return "linear"
    setter = ax.set_yscale if axis == "y" else ax.set_xscale
    if np.all(v > 0):
        setter("log")
        return "log"
    positive = np.abs(v[v != 0])
    setter("symlog", linthresh=float(np.min(positive)) if positive.size else 1.0)
    return "symlog"


def metric_figure(d: pd.DataFrame, factor: str, metric: str):
    """Box plot of one metric per level of one factor, every run as a dot; log scale when outliers dominate."""

    @styled
    def build():
        plt = pyplot()
        raw = list(dict.fromkeys(d[factor].tolist()))
        names = level_labels(factor, raw)
        groups = [d[d[factor].astype(str) == str(lv)]["value"].to_numpy(float) for lv in raw]
        leaf = factor.split(".")[-1] + "="  # the axis label names the factor already
        ticks = [textwrap.fill(names[str(v)].removeprefix(leaf), 22) for v in raw]
        horizontal = len(raw) > 25  # many levels: one row each, readable labels
        if horizontal:
            fig, ax = plt.subplots(figsize=(7, 0.22 * len(raw) + 1.2), layout="constrained")
        else:
            width = max(4.5, 0.9 * len(raw) + 2)
            fig, ax = plt.subplots(figsize=(width, 4), layout="constrained")
        # deferred: matplotlib (loaded by pyplot above), for its ticker
        import matplotlib

        # matplotlib 3.10 renamed vert= to orientation=
        new_api = tuple(int(x) for x in matplotlib.__version__.split(".")[:2]) >= (3, 10)
        turn = {"orientation": "horizontal" if horizontal else "vertical"} if new_api else {"vert": not horizontal}
        ax.boxplot([g[np.isfinite(g)] for g in groups], showfliers=False, widths=0.6, **turn)
        rng = np.random.default_rng(0)
        for i, g in enumerate(groups, start=1):
            jitter = i + rng.uniform(-0.15, 0.15, g.size)
            ax.plot(*((g, jitter) if horizontal else (jitter, g)), "o", ms=3, color="C0", alpha=0.6)
        values = np.concatenate(groups) if groups else np.array([])
        scale = _scale(ax, values, axis="x" if horizontal else "y")
        label = metric_label(metric) + (" (log scale)" if scale != "linear" else "")
        if horizontal:
            ax.set_yticks(range(1, len(raw) + 1), ticks, fontsize=7)
            ax.invert_yaxis()
            ax.set_ylabel(factor)
            ax.set_xlabel(label)
        else:
            slanted = sum(min(len(t), 22) for t in ticks) * 0.075 > width - 1
            ax.set_xticks(range(1, len(raw) + 1), ticks, rotation=30 if slanted else 0,
                          ha="right" if slanted else "center", fontsize=8)
            ax.set_xlabel(factor)
            ax.set_ylabel(label)
        ax.set_title(f"{metric_label(metric)} by {factor} (dots: runs)", loc="left")
        return fig

    return build()


def _auc(fpr: np.ndarray, tpr: np.ndarray) -> float:
    order = np.argsort(fpr, kind="stable")
    x, y = fpr[order], tpr[order]
    return float(np.sum(np.diff(x) * (y[1:] + y[:-1]) / 2))


#: Smallest false stance rate shown on a logarithmic ROC axis.
FPR_FLOOR = 1e-3


def roc_figure(runs: list[dict[str, Any]], labels: dict[str, str], log_fpr: bool | None = None):
    """Stance-detection ROC of the threshold sweeps, one curve per detector configuration.

    Runs that differ only outside the detector have the same sweep and are
    shown once. The curve of a configuration is the mean true-stance rate over
    its recordings at each false-stance rate (recordings as thin lines); the
    legend gives the mean area under the curve. Up to :data:`MAX_OVERLAID`
    configurations share one axis with the legend below it, more get a panel each.
    ``log_fpr`` puts the false stance rate on a log scale (from :data:`FPR_FLOOR`);
    by default it does when every curve's AUC exceeds 0.9, i.e. when the curves
    crowd into the top-left corner.
    """

    groups: dict[str, dict[str, np.ndarray]] = {}
    for r in runs:
        if r.get("roc"):
            label = labels.get(r["key"], r["key"])
            groups.setdefault(label, {}).setdefault(r["recording"], np.asarray(r["roc"], float))
    if not groups:
        return None
    grid = np.concatenate([[0.0], np.logspace(np.log10(FPR_FLOOR), 0.0, 120)])

    def mean_curve(curves: dict[str, np.ndarray]) -> tuple[np.ndarray, float]:
        tprs = []
        for c in curves.values():
            order = np.argsort(c[:, 2], kind="stable")
            tprs.append(np.interp(grid, c[order, 2], c[order, 1]))
        return np.mean(tprs, axis=0), float(np.mean([_auc(c[:, 2], c[:, 1]) for c in curves.values()]))

    means = {name: mean_curve(curves) for name, curves in groups.items()}
    log = all(auc > 0.9 for _, auc in means.values()) if log_fpr is None else log_fpr

    def fx(x: np.ndarray) -> np.ndarray:
        return np.maximum(x, FPR_FLOOR) if log else x

    @styled
    def build():
        plt = pyplot()
        names = list(groups)  # in the study's order of levels
        if len(names) <= MAX_OVERLAID:
            fig, ax = plt.subplots(figsize=(6, 6), layout="constrained")
            for i, name in enumerate(names):
                m, auc = means[name]
                ax.plot(fx(grid), m, lw=1.5, color=f"C{i}", label=f"{name} (AUC {auc:.3f})")
                if len(groups[name]) > 1:
                    for c in groups[name].values():
                        ax.plot(fx(c[:, 2]), c[:, 1], lw=0.5, color=f"C{i}", alpha=0.35)
            axes = [ax]
            fig.legend(loc="outside lower center", ncol=2 if len(names) > 2 else len(names))
            ax.set_title("stance detection: threshold sweep" +
                         (" (thin: single recordings)" if any(len(g) > 1 for g in groups.values()) else ""), loc="left")
        else:
            fig, axes = _grid(plt, len(names), size=2.3)
            for ax, name in zip(axes, names, strict=True):
                for c in groups[name].values():
                    ax.plot(fx(c[:, 2]), c[:, 1], lw=0.5, color="0.6")
                m, auc = means[name]
                ax.plot(fx(grid), m, lw=1.5, color="C0")
                ax.set_title(f"{name}\nAUC {auc:.3f}", fontsize=8)
                ax.tick_params(labelsize=7)
            fig.suptitle("stance detection: threshold sweeps (grey: single recordings, blue: mean); "
                         "x false stance rate, y true stance rate")
        for ax in axes:
            ax.plot(fx(grid), grid, ":", color="0.5", lw=0.6)  # chance
            ax.set_ylim(0, 1.02)
            if log:
                ax.set_xscale("log")
                ax.set_xlim(FPR_FLOOR, 1)
            else:
                ax.set_xlim(0, 1)
                ax.set_aspect("equal")
        if len(axes) == 1:
            axes[0].set_xlabel("false stance rate" + (f" (log scale, below {FPR_FLOOR:g} at the edge)" if log else ""))
            axes[0].set_ylabel("true stance rate")
        elif log:
            fig.text(0.5, 0.005, f"false stance rate on a log scale (below {FPR_FLOOR:g} at the edge)", ha="center",
                     fontsize=8)
        return fig

    return build()


def _safe(s: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in str(s))[:80]
