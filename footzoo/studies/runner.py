"""Run a study's cells serially, on local cores (joblib) or on a Dask cluster, with a checked, resumable cache.

How a study runs:

1. the study is parsed, its plug-ins loaded, each recording identified once (content hash of a file,
   or the simulator spec and seed) and every cell keyed by the hash of its resolved config, the data's
   identity, footzoo's version and the plug-ins' source hash;
2. cached cells are read back after checking their checksum; a damaged, truncated, edited or foreign
   entry is reported (warning, ``table.attrs["recomputed"]``, ``cache_report.log``) and run again; a
   cell that failed is run again once footzoo's source changed (a changed config, plug-in, version or
   recording changes its key anyway);
3. the remaining cells are grouped by recording and sent in chunks to the workers: each worker loads
   the study's plug-ins, then loads or simulates each recording once and runs every config of the chunk
   on it (a small per-process cache shares a recording between chunks);
4. the tidy table is built from the run records; trajectories and threshold sweeps stay in the run
   records and in ``trajectories.parquet`` / ``roc.parquet``, never in ``table.attrs``.
"""

from __future__ import annotations

import builtins
import contextlib
import hashlib
import json
import math
import os
import re
import threading
import time
import traceback
import warnings
from collections import OrderedDict
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core import errors
from ..core.archive import MANIFEST as RESULT_MANIFEST
from ..core.atomic import begin_folder, check_complete, end_folder, folder_lock, previous_marker, write_bytes
from ..core.errors import ConfigError, FootzooWarning, OutputError, user_stacklevel
from ..core.files import sha256
from ..core.usage import used_from
from ..core.warninglog import LOG, WarningLog, log_text
from ..evaluation.metrics import footprint_pairs, reference_steps, rigid_transform_2d, run_metrics
from ..evaluation.validity import MetricWarning, checked_metrics, estimate_problems, missing_reason, reference_problems
from ..plugins.contract import checked, no_statistic_note
from ..plugins.extensions import load_plugins
from ..plugins.registry import build
from ..runtime.pipeline import Pipeline
from .cache import (
    CACHE_MAX_AGE_DAYS,
    CacheWarning,
    light,
    prune_cache,
    read_entry,
    touch,
    write_entry,
)
from .report import REPORT_TABLES, alike, grouped, write_outputs
from .study import Cell, Study, check_jobs, code_fingerprint

TRAJECTORY_STEP = 0.1  # s between stored trajectory points (for the overlay plots)
RECORDINGS_PER_PROCESS = 2  # recordings a worker process keeps in memory for the next chunk
CHUNKS_PER_WORKER = 4  # aim for this many chunks per worker (load balance vs. loading a recording again)


# --------------------------------------------------------------------------- metrics of one run


_PROBLEMS: list[tuple[Any, dict[str, str]]] = []  # (truth, its refused metrics), per process, found by identity


def _reference_problems(rec) -> dict[str, str]:
    """:func:`footzoo.evaluation.validity.reference_problems` of a recording, once per recording and process."""

    with _RECORDINGS_LOCK:
        known = next((problems for truth, problems in _PROBLEMS if truth is rec.truth), None)
    if known is not None:
        return known
    problems = reference_problems(rec.t, rec.truth)
    with _RECORDINGS_LOCK:
        if len(_PROBLEMS) > 4 * RECORDINGS_PER_PROCESS:
            _PROBLEMS.clear()
        _PROBLEMS.append((rec.truth, problems))
    return problems


def _metrics(rec, res, pos: np.ndarray, metric_names: list[str] | None) -> tuple[dict[str, float], dict[str, str]]:
    """Every metric of a run (the names of ``footzoo run``), the refused ones NaN, and the reasons of those."""

    m = run_metrics(rec.t, pos, res.steps, res.stance, rec.truth)
    m, notes = checked_metrics(m, {**_reference_problems(rec), **estimate_problems(res.steps, rec.truth)}, rec.truth,
                               rec.t)
    if metric_names:
        m = {k: v for k, v in m.items() if k in metric_names}
        notes = {k: v for k, v in notes.items() if k in metric_names}
        for name in metric_names:  # a metric asked for is never dropped: NaN, and why
            if name not in m:
                m[name] = float("nan")
                notes[name] = missing_reason(name, rec.truth, res.steps)
    return {k: float(v) for k, v in m.items()}, notes


def _roc(rec, detector_spec: dict[str, Any], points: int, label: str) -> list[list[float]]:
    """Threshold sweep from the detector's statistic (stance where the statistic is below the threshold); ``label``
    the recording's name in the study."""

    if rec.truth is None or rec.truth.stance is None:
        warnings.warn(FootzooWarning(f"sweep: recording {label!r} has no reference stance, so no ROC curve is drawn "
                                     "for it (a sweep needs one: a simulated recording, PyShoe's trials)"),
                      stacklevel=user_stacklevel())
        return []
    det = build("detector", dict(detector_spec))
    if getattr(det, "needs_truth", False):
        warnings.warn(FootzooWarning(f"sweep: detector {det.name!r} reads the reference stance itself, so it has no "
                                     "threshold to sweep and no ROC curve"), stacklevel=user_stacklevel())
        return []
    checked(det.detect, rec.t, rec.acc, rec.gyr)
    stat, truth = np.asarray(getattr(det, "statistic_", None) if getattr(det, "statistic_", None) is not None
                             else np.full(rec.n, np.nan), float), rec.truth.stance
    if not np.isfinite(stat).any():  # the detector has no statistic (an optional output): no ROC curve, said so
        warnings.warn(FootzooWarning(no_statistic_note(det)), stacklevel=user_stacklevel())
        return []
    out = []
    for th in np.quantile(stat, np.linspace(0.0, 1.0, points)):
        pred = stat <= th
        tpr = float(np.sum(pred & truth) / max(truth.sum(), 1))
        fpr = float(np.sum(pred & ~truth) / max((~truth).sum(), 1))
        out.append([float(th), tpr, fpr])
    return out


# --------------------------------------------------------------------------- one cell, one chunk

_RECORDINGS: OrderedDict[str, Any] = OrderedDict()  # identity -> (Recording, its reader's warnings), per process
_RECORDINGS_LOCK = threading.Lock()


def _recording(cell: Cell, identity: str) -> tuple[Any, list[str]]:
    """The cell's recording, loaded or simulated once per process and shared by the configs that use it, with
    the warnings its reader gave (``"Category: message"``): every run on it carries them back to the study,
    which shows or logs them as ``--quiet`` says, rather than a worker process printing them."""
    with _RECORDINGS_LOCK:  # Dask workers may run several chunks in threads of one process
        got = _RECORDINGS.get(identity)
        if got is not None:
            _RECORDINGS.move_to_end(identity)
            return got
    with warnings.catch_warnings(record=True) as caught, used_from("study"):
        warnings.simplefilter("always")
        rec = _read_only(cell.recording.load())
    if rec.truth is not None and rec.truth.steps is not None:  # footzoo's column names once, not per run

        rec.truth.steps = reference_steps(rec.truth.steps)
    got = (rec, list(dict.fromkeys(f"{type(w.message).__name__}: {w.message}" for w in caught)))
    with _RECORDINGS_LOCK:
        _RECORDINGS[identity] = got
        while len(_RECORDINGS) > RECORDINGS_PER_PROCESS:
            _RECORDINGS.popitem(last=False)
    return got


def _read_only(rec):
    """Freeze a shared recording's arrays: a plug-in writing into its input fails loudly instead of
    silently changing the input of the configs that run after it."""
    for obj in (rec, rec.truth):
        for value in vars(obj).values() if obj is not None else ():
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
    return rec


def _new_record(cell: Cell, key: str) -> dict[str, Any]:
    return {"key": key, "base": cell.base, "levels": cell.levels, "recording": cell.recording.label,
            "error": None, "metrics": {}, "notes": {}, "trajectory": [], "roc": [],
            "code_fingerprint": code_fingerprint()}


def _fail(out: dict[str, Any], err: BaseException) -> dict[str, Any]:
    out["error"] = f"{type(err).__name__}: {err}"
    if isinstance(err, ValueError) and "read-only" in str(err):
        out["error"] += ("; a plug-in wrote into the recording's arrays, which a study shares between configs: "
                         "the plug-in must copy its input before changing it")
    out["traceback"] = "".join(traceback.format_exception(type(err), err, err.__traceback__, limit=3))
    return out


def _compute(cell: Cell, key: str, rec, metric_names: list[str] | None, sweep_points: int) -> dict[str, Any]:
    out = _new_record(cell, key)
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught, used_from("study"):  # caught: sent back with the record
            warnings.simplefilter("always")  # (see _replay_warnings); a message names the study's fix
            # wall and CPU seconds of the pipeline itself and of its metrics (benchmarks/study_scaling.py)
            start, cpu = time.perf_counter(), time.process_time()
            res = Pipeline.from_dict(cell.config).run(rec)
            out["run_s"], out["run_cpu_s"] = _since(start, cpu)
            start, cpu = time.perf_counter(), time.process_time()
            pos = res.pos
            out["metrics"], out["notes"] = _metrics(rec, res, pos, metric_names)
            out["metrics_s"], out["metrics_cpu_s"] = _since(start, cpu)
        step = max(int(round(TRAJECTORY_STEP * rec.rate)), 1)
        out["trajectory"] = np.column_stack([rec.t, pos])[::step].round(4)
        if rec.truth is not None and rec.truth.pos is not None:  # reference path for the overlay plots
            out["reference"] = np.column_stack([rec.t, rec.truth.pos])[::step].round(4)
        out.update(_on_footprints(rec, res, pos, step))
        if sweep_points:
            with warnings.catch_warnings(record=True) as swept:
                warnings.simplefilter("always")
                out["roc"] = _roc(rec, cell.config["detector"], sweep_points, cell.recording.label)
            caught += swept
    except Exception as err:  # one failing run is reported, not fatal
        _fail(out, err)
    out["warnings"] = list(dict.fromkeys(f"{type(w.message).__name__}: {w.message}" for w in caught))[:5]
    return out


def _on_footprints(rec, res, pos: np.ndarray, step: int) -> dict[str, np.ndarray]:
    """For a recording with measured footprints (Köroğlu's ground control points): the footprints and the run's
    trajectory in their frame (t, north, east, down), by the 2-D rigid transform of its estimated footprints onto
    them that the footprint metric uses; nothing when the counts do not pair (the metric compares nothing then)."""
    fp = None if rec.truth is None else rec.truth.footprints
    if fp is None:
        return {}
    fp = np.asarray(fp, float)[:, :2]
    pairs = footprint_pairs(res.steps, fp)
    if pairs is None:
        return {"footprints": fp}
    on = rigid_transform_2d(*pairs).apply(pos)
    return {"footprints": fp, "trajectory_on_footprints": np.column_stack([rec.t, on, pos[:, 2]])[::step].round(4)}


def _since(wall: float, cpu: float) -> tuple[float, float]:
    return round(time.perf_counter() - wall, 6), round(time.process_time() - cpu, 6)


def run_chunk(cells: list[Cell], keys: list[str], identity: str, plugins: list[str], cache_dir: str | None,
              metric_names: list[str] | None = None, sweep_points: int = 0,
              on_cell: Callable[[], None] | None = None) -> list[dict[str, Any]]:
    """Run cells that share one recording (in a worker): load the plug-ins, the recording once, run each config.

    Never raises: a plug-in, recording or run failure is recorded in the cells it concerns. Each
    finished cell is written to the cache at once, so an interrupted study keeps it.
    """

    setup_error: BaseException | None = None
    rec, read_warnings = None, []
    start = time.process_time()
    try:
        load_plugins(plugins)
        rec, read_warnings = _recording(cells[0], identity)
    except Exception as err:  # a plug-in, reader or simulator failure fails this recording's cells only
        setup_error = err
    out = []
    for cell, key in zip(cells, keys, strict=True):
        if setup_error is not None:
            record = _fail(_new_record(cell, key), setup_error)
        else:
            record = _compute(cell, key, rec, metric_names, sweep_points)
            record["warnings"] = list(dict.fromkeys([*read_warnings, *record["warnings"]]))
        # CPU seconds of this run in its worker (the first run of a chunk includes loading the recording)
        record["cpu_s"] = round(time.process_time() - start, 6)
        start = time.process_time()
        if cache_dir is not None:
            try:
                write_entry(Path(cache_dir) / f"{key}.json", key, record)
                record["entry"] = str(Path(cache_dir) / f"{key}.json")
            except OSError as err:  # a full or read-only cache costs the resume, not the result
                warnings.warn(f"could not write the cache entry of run {key}: {err}", CacheWarning,
                              stacklevel=user_stacklevel())
        record["cached"] = False
        out.append(record)
        if on_cell is not None:
            on_cell()
    return out


def run_cell(cell: Cell, cache_dir: str | None = None, metric_names: list[str] | None = None,
             sweep_points: int = 0) -> dict[str, Any]:
    """Run one cell, or read it from the cache when a sound entry exists; never raises: errors are recorded."""
    identity = cell.recording.identity()
    key = cell.key(identity)
    if cache_dir is not None and (Path(cache_dir) / f"{key}.json").exists():
        record, problem = read_entry(Path(cache_dir) / f"{key}.json", key)
        if record is not None:
            return {**record, "base": cell.base, "levels": cell.levels, "recording": cell.recording.label,
                    "cached": True}
        warnings.warn(f"cache entry {key} {problem}; running it again", CacheWarning, stacklevel=user_stacklevel())
    plugins = [p for p in cell.config.get("plugins") or []]
    return run_chunk([cell], [key], identity, plugins, cache_dir, metric_names, sweep_points)[0]


# --------------------------------------------------------------------------- the study


def run_study(
    study: Study | Mapping[str, Any] | str | Path,
    jobs: int | None = None,
    scheduler: str | None = None,
    out: str | Path | None = None,
    progress: bool = False,
    max_runs: int | None = None,
    max_cells: int | None = None,
    quiet: bool = False,
    report: bool = True,
    prune: dict[str, Any] | None = None,
) -> pd.DataFrame:
    """Run every cell of a study and return the tidy table (one row per run × metric).

    Parameters
    ----------
    study : Study, mapping or path
        The study, its YAML file, or the mapping such a file holds (paths relative to the working folder).
    jobs : int, optional
        Local worker processes (joblib); 1 runs serially, -1 uses every core. Default: the
        study file's ``jobs``, else 1.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); the runs go
        to its workers through ``dask.distributed``.
    out : path, optional
        Output folder: ``cache/`` (one checked file per run, keyed by the hash of the
        resolved config, the data, footzoo's version and the plug-ins' source, so a rerun
        resumes), ``results.parquet``, ``results.csv``, ``trajectories.parquet``,
        ``roc.parquet``, ``summary.md``, ``summary.tex``, plots and ``footzoo.log`` (every
        warning of the call, the workers' included, or ``no warnings``). ``outputs.json``,
        written last, records each of them with its checksum. A rerun whose table, runs and
        footzoo source are unchanged, and whose outputs are all present and intact, leaves
        them as they are (its log replaced when its warnings differ).
    progress : bool
        Show one progress bar over the whole command (loading, runs, report).
    max_runs : int, optional
        Stop after this many new runs (what an interruption leaves behind).
    max_cells : int, optional
        Largest grid allowed (default: the study's ``max_cells``, else
        :data:`footzoo.studies.study.MAX_CELLS`); a larger one is refused before anything runs.
    prune : dict, optional
        Keyword arguments of :func:`prune_cache` applied to ``out/cache`` after the study (the
        study's own entries are always kept). Default: ``{"max_age_days": CACHE_MAX_AGE_DAYS}``,
        entries unused for 30 days go; ``{"max_age_days": 0}`` keeps only this study's entries;
        ``{"max_age_days": None}`` keeps everything.
    report : bool
        Write the report into ``out`` (tables, summaries, plots); False keeps only the cache
        (what :func:`footzoo.studies.tune.tune` needs).
    quiet : bool
        Do not repeat the runs' warnings (each distinct warning of the workers is otherwise
        issued once here, with the number of runs that gave it); they stay in ``attrs["warnings"]``
        and in ``out/footzoo.log``. Every warning of the call reaches the caller when the call
        ends (after the progress bar), once the log is written.

    Returns
    -------
    pandas.DataFrame
        Columns ``run``, ``base``, one per factor, ``recording``, ``metric``, ``value``,
        ``error``. ``attrs`` holds counts only: ``computed``, ``cached``, ``failed``, and
        ``recomputed`` (damaged cache entries: key -> problem), ``retried`` (failed
        cells run again because footzoo's source changed: keys), ``causes`` (the distinct
        errors of the failed runs, most frequent first), ``refused`` (the distinct reasons of
        refused metrics, :mod:`footzoo.evaluation.validity`) and ``warnings`` (the distinct
        warnings of the runs computed now, ``"Category: message"`` -> number of runs; kept with
        ``quiet`` too, and in each run's cache entry). Every config and reader option is
        validated before any run (:meth:`Study.check`): an invalid study raises ConfigError. Trajectories and
        threshold sweeps are in ``out`` (see :func:`read_trajectories`).
    """
    with WarningLog() as log:  # the study's warnings, for its footzoo.log; the caller gets them at the end
        if isinstance(study, Mapping):  # the study file's mapping, paths relative to the working folder
            study = Study.from_dict(study, max_cells=max_cells)
        elif not isinstance(study, (str, os.PathLike)) and not isinstance(study, Study):
            hint = (": a pipeline runs on a recording with pipeline.run(rec); a study of it names it as its base, "
                    "e.g. run_study({'name': 's', 'base': 'yun2012', 'recordings': [...]})"
                    if hasattr(study, "run") and hasattr(study, "detector") else "")
            raise ConfigError(f"run_study takes a Study, a study file's path or name, or its mapping; got "
                              f"{type(study).__name__}{hint}")
        elif not isinstance(study, Study):
            study = Study.from_yaml(study, max_cells=max_cells)
        if jobs is None:
            jobs = study.jobs or 1
        check_jobs(jobs)
        if scheduler is not None:
            scheduler = check_scheduler(scheduler)
        study.check(max_cells)
        bar = _Progress(progress, "study")
        lock = contextlib.nullcontext() if out is None else folder_lock(out, "study output folder",
                                                                         f"study {study.name!r}", study_identity(study))
        options = {"max_runs": max_runs, "report": report, "prune": prune, "quiet": quiet, "log": log}
        try:
            with lock:
                if scheduler is None:
                    table = _run_study(study, jobs, None, out, bar, **options)
                else:
                    cluster = _Cluster(scheduler)  # one connection for the runs and the report's figures, when needed
                    try:
                        table = _run_study(study, jobs, cluster, out, bar, **options)
                    finally:
                        cluster.close()
        finally:
            bar.close()
    return table


def study_identity(study: Study) -> str:
    """What makes two studies the same (their definition): the same study started twice shares its folder."""
    spec = [study.name, study.bases, study.factors, study.metrics, study.sweep_points, study.plugins,
            [[r.label, r.path, r.format, r.options, r.simulate, r.seed] for r in study.recordings]]
    return hashlib.sha256(json.dumps(spec, sort_keys=True, default=str).encode()).hexdigest()


def _replay_warnings(worker: dict[str, int], refused: dict[str, int], log: WarningLog, quiet: bool,
                     labels: list[str] = ()) -> None:
    """Issue each distinct warning of the runs once, with the number of runs that gave it (``quiet``: into the
    study's log only). Warnings that differ only in their numbers and recordings (a guard's finding on every
    recording, in every setting of a tune) are issued as one, with the count and the first as the example; the
    log keeps each of them."""

    labels = sorted({str(x) for x in labels if str(x)}, key=len, reverse=True)
    groups: dict[str, list[tuple[str, int]]] = {}
    for text, n in worker.items():
        groups.setdefault(alike(text, labels), []).append((text, n))
    replayed = []
    for members in groups.values():
        name, _, message = members[0][0].partition(": ")
        category = MetricWarning if name == "MetricWarning" else (getattr(errors, name, None)
                                                                  or getattr(builtins, name, None))
        if not (isinstance(category, type) and issubclass(category, Warning)):
            category = UserWarning
        if len(members) == 1:
            n = members[0][1]
            replayed.append((category, f"{n} run(s): {message}" if n > 1 else message))
            continue
        log.keep([f"{name}: {n} run(s): {text.partition(': ')[2]}" if n > 1 else text for text, n in members])
        if not quiet:  # a summary on the terminal only: the log lists each
            total = sum(n for _, n in members)
            summary = (f"{total} run(s) gave {len(members)} warnings like this one, with other numbers or recordings "
                       f"(each is in footzoo.log or the table's attrs['warnings']): {message}")
            log.not_logged([f"{category.__name__}: {summary}"])
            replayed.append((category, summary))
    if refused:
        text = "; ".join(f"{why} ({n} run(s))" if k == 1 else f"{why} ({n} run(s), with {k - 1} alike reasons: other "
                         "numbers)" for why, n, k in grouped(refused))
        replayed.append((MetricWarning, f"metrics refused (NaN, see the table's note column): {text}"))
    for category, message in replayed:
        if quiet:
            log.keep([f"{category.__name__}: {message}"])
        else:  # named at the line that called run_study
            warnings.warn(message, category, stacklevel=user_stacklevel())


def _counts(values) -> dict[str, int]:
    out: dict[str, int] = {}
    for v in values:
        out[v] = out.get(v, 0) + 1
    return dict(sorted(out.items(), key=lambda kv: -kv[1]))


def _run_study(study, jobs, scheduler, out, bar: _Progress, max_runs: int | None, report: bool,
               prune: dict[str, Any] | None, quiet: bool, log: WarningLog) -> pd.DataFrame:
    bar.phase("loading")
    bar.set_description(study.name)
    cells = study.cells()
    report_steps = 4 if out is not None and report else 0
    bar.add(len(study.recordings) + len(cells) + report_steps)
    bar.update(1)

    bar.phase("hashing data")
    identity: dict[int, str] = {}
    for rec in study.recordings:
        identity[id(rec)] = rec.identity()
        bar.update(1)
    keys = [c.key(identity[id(c.recording)]) for c in cells]

    cache_dir = None
    if out is not None:
        cache = Path(out) / "cache"
        cache.mkdir(parents=True, exist_ok=True)
        cache_dir = str(cache)
        if report:  # until the new report is complete, the folder's report is marked incomplete
            _check_report_folder(Path(out), study)
            begin_folder(out, MANIFEST)

    bar.phase("reading cache")
    results: dict[int, dict[str, Any]] = {}
    todo: list[int] = []
    recomputed: dict[str, str] = {}
    retried: list[str] = []
    for i, key in enumerate(keys):
        path = Path(cache_dir) / f"{key}.json" if cache_dir else None
        if path is None or not (path.exists() or path.is_symlink()):
            todo.append(i)
            continue
        record, problem = read_entry(path, key)
        if record is None:
            recomputed[key] = problem
            todo.append(i)
        elif record.get("error") and record.get("code_fingerprint") != code_fingerprint():
            retried.append(key)
            todo.append(i)
        else:  # the same run may be shared by cells with other labels (e.g. two copies of one file)
            touch(path)
            cell = cells[i]
            results[i] = light({**record, "base": cell.base, "levels": cell.levels, "recording": cell.recording.label,
                                "cached": True, "entry": str(path)}, keep=out is not None and report)
            bar.update(1)
    if recomputed:
        warnings.warn(f"{len(recomputed)} damaged cache entr{'y' if len(recomputed) == 1 else 'ies'} "
                      f"(e.g. {next(iter(recomputed))}: {next(iter(recomputed.values()))}) will be run again"
                      + (f"; see {Path(out) / 'cache_report.log'}" if out is not None else ""),
                      CacheWarning, stacklevel=user_stacklevel())
    if max_runs is not None:
        bar.add(-(len(todo) - min(len(todo), max_runs)))
        todo = todo[:max_runs]

    bar.phase("running")
    args = (study.plugins, cache_dir, study.metrics, study.sweep_points)
    for idx, records in _execute(todo, cells, keys, identity, args, jobs, scheduler, bar):
        for i, r in zip(idx, records, strict=True):
            results[i] = light(r, keep=out is not None and report)  # the heavy parts stay on disk
    runs = [results[i] for i in sorted(results)]
    table = tidy(runs, list(study.factors))
    table.attrs["computed"] = sum(1 for r in runs if not r.get("cached"))
    table.attrs["cached"] = sum(1 for r in runs if r.get("cached"))
    table.attrs["failed"] = sum(1 for r in runs if r.get("error"))
    table.attrs["recomputed"] = dict(recomputed)
    table.attrs["retried"] = list(retried)
    table.attrs["causes"] = _counts(r["error"] for r in runs if r.get("error"))
    table.attrs["refused"] = _counts(why for r in runs for why in set((r.get("notes") or {}).values()))
    table.attrs["warnings"] = _counts(w for r in runs if not r.get("cached") for w in r.get("warnings") or [])
    if cache_dir is not None:
        table.attrs["pruned"] = prune_cache(cache_dir, keep=set(keys),
                                            **({"max_age_days": CACHE_MAX_AGE_DAYS} if prune is None else prune))
    _replay_warnings(table.attrs["warnings"], table.attrs["refused"], log, quiet,  # before the log is written
                     [r.label for r in study.recordings])
    # the cached runs warned when they ran (not again here); the folder's log still lists what its results carry
    cached = _counts(w for r in runs if r.get("cached") for w in r.get("warnings") or [])
    log.keep([f"{text} (from {n} cached run{'s' if n > 1 else ''}: warned when {'they' if n > 1 else 'it'} ran)"
              for text, n in cached.items()])
    if out is not None and report:
        if recomputed:
            _log_damaged(Path(out), recomputed)
        bar.phase("report")
        figures = study.figure_metrics()
        digest = _outputs_digest(table, runs, list(study.factors), figures)
        kept = _outputs_current(Path(out), digest)
        if kept is not None:
            bar.update(report_steps)  # nothing changed since the outputs were written: keep them
            written = [name for name in kept if name != LOG]
        else:
            # figures on the local workers with jobs: N; on the Dask workers, in memory, written here
            written = write_outputs(table, runs, list(study.factors), Path(out), step=bar.update,
                                    jobs=jobs if scheduler is None else 1,
                                    scheduler=scheduler.client if isinstance(scheduler, _Cluster) else scheduler,
                                    figures=figures)
        # the command's log, with every warning it gave, then the completion marker that lists it
        logged = _write_log(Path(out), log.texts())
        if kept is not None and kept.get(LOG) == logged:
            end_folder(out, MANIFEST)  # the earlier marker back, as it was
        else:
            _write_manifest(Path(out), digest, [*written, LOG], _base_names(study))
    return table


MANIFEST = "outputs.json"


def _base_names(study: Study) -> list[str]:
    return sorted(name for name, _ in study.bases)


def _check_report_folder(out: Path, study: Study) -> None:
    """Before any run: refuse a folder holding a report table no earlier study there wrote (a user's
    ``results.csv``), which the study's report would replace; warn when the folder's report is that of a study
    of other base configs (it is replaced; its cached runs stay, so that study run again rebuilds it)."""
    try:
        manifest = previous_marker(out, MANIFEST)
        earlier = set(manifest["files"]) if isinstance(manifest, dict) else set()
    except (OSError, ValueError, KeyError, TypeError):
        manifest, earlier = None, set()
    foreign = [n for n in REPORT_TABLES if (out / n).exists() and n not in earlier]
    if (out / LOG).exists() and LOG not in earlier and (out / RESULT_MANIFEST).exists():
        raise OutputError(f"study {study.name!r}: the output folder {str(out)!r} holds a saved result (its "
                          f"{RESULT_MANIFEST}, e.g. of footzoo run --out) whose {LOG} the study's log would replace: "
                          "choose another --out for the study")
    if foreign:
        raise OutputError(f"study {study.name!r}: the output folder {str(out)!r} already holds {', '.join(foreign)}, "
                          f"which no earlier study there wrote (its {MANIFEST} does not list them); the study's report "
                          "would replace them: choose another --out, or move those files away")
    before = manifest.get("bases") if isinstance(manifest, dict) else None
    if isinstance(before, list) and sorted(map(str, before)) != _base_names(study):
        warnings.warn(f"study {study.name!r}: the output folder {str(out)!r} holds the report of a study of base "
                      f"config(s) {sorted(map(str, before))}; this study's ({_base_names(study)}) replaces it. That "
                      "study's runs stay in the folder's cache: running it again rebuilds its report without "
                      "recomputing. Give this study another --out to keep both reports", FootzooWarning,
                      stacklevel=user_stacklevel())


def _outputs_digest(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str],
                    figures: list[str] | None) -> str:
    """What the report depends on: the table, the runs (keys and labels), the factors, the metrics drawn
    and footzoo's source."""
    h = hashlib.sha256(json.dumps([[r["key"], r["base"], r["recording"]] for r in runs]).encode())
    h.update(json.dumps([factors, figures, code_fingerprint()]).encode())
    h.update(pd.util.hash_pandas_object(table.astype(str), index=True).to_numpy().tobytes())
    return h.hexdigest()


def _outputs_current(out: Path, digest: str) -> dict[str, str] | None:
    """The files of the earlier report in ``out`` (name -> SHA-256) when it has this digest and each output (the
    log aside: every command writes its own) still has its recorded content; else None."""
    try:
        manifest = previous_marker(out, MANIFEST)  # set aside while this study runs (begin_folder)
        current = manifest["digest"] == digest and all(
            sha256(out / name) == sha for name, sha in manifest["files"].items() if name != LOG)
        return dict(manifest["files"]) if current else None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def _write_log(out: Path, texts: list[str]) -> str:
    """``out/footzoo.log`` listing ``texts`` (:func:`~footzoo.core.warninglog.log_text`), written atomically unless
    it already says that; its SHA-256."""
    text = log_text(texts)
    try:
        same = (out / LOG).read_bytes() == text
    except OSError:
        same = False
    if not same:
        write_bytes(out / LOG, text, what="the study's log")
    return hashlib.sha256(text).hexdigest()


def _write_manifest(out: Path, digest: str, written: list[str], bases: list[str]) -> None:
    """Record the report's files (``written``) with their content, last (the folder's completion marker);
    remove the files the previous report wrote and this one did not (a figure of a metric no longer
    drawn), so none is taken for current."""
    try:
        old = previous_marker(out, MANIFEST)
        # only a manifest of report files: older ones listed every file of the folder, the user's too
        before = set(old["files"]) if old.get("lists") == "report files" else set()
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        before = set()
    for name in sorted(before - set(written)):
        if Path(name).name == name:  # a file of this folder, as every report writes
            (out / name).unlink(missing_ok=True)
    files = {name: sha256(out / name) for name in sorted(written)}
    end_folder(out, MANIFEST, json.dumps({"digest": digest, "lists": "report files", "files": files, "bases": bases},
                                         indent=1))


def _chunks(todo: list[int], cells: list[Cell], identity: dict[int, str], workers: int) -> list[list[int]]:
    """Group the cells to run by recording, then split each group so every worker gets several chunks."""
    groups: dict[str, list[int]] = {}
    for i in todo:
        groups.setdefault(identity[id(cells[i].recording)], []).append(i)
    if workers <= 1:
        return list(groups.values())
    want = CHUNKS_PER_WORKER * workers
    per_group = max(1, math.ceil(want / max(len(groups), 1)))
    chunks = []
    for idx in groups.values():
        n = min(per_group, len(idx))
        size = math.ceil(len(idx) / n)
        chunks += [idx[k:k + size] for k in range(0, len(idx), size)]
    return chunks


def _execute(todo, cells, keys, identity, args, jobs, scheduler, bar):
    """Yield ``(indices, records)`` per finished chunk, from the chosen back end."""
    def task(idx):
        first = cells[idx[0]]
        return ([cells[i] for i in idx], [keys[i] for i in idx], identity[id(first.recording)], *args)

    if not todo:
        return
    if scheduler is not None:
        # deferred: dask, an optional extra (footzoo[distributed])
        from dask.distributed import as_completed

        with _connected(scheduler) as client:
            workers = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
            chunks = _chunks(todo, cells, identity, max(workers, 1))
            futures = {client.submit(run_chunk, *task(idx), pure=False): idx for idx in chunks}
            for fut in as_completed(futures):
                records = fut.result()
                idx = futures.pop(fut)  # released: the cluster and the client forget the chunk's records
                fut.release()
                bar.update(len(records))
                yield idx, records
    elif jobs != 1:
        # deferred: joblib, only for parallel runs
        from joblib import Parallel, delayed

        chunks = _chunks(todo, cells, identity, (os.cpu_count() or 1) if jobs < 0 else int(jobs))
        gen = Parallel(n_jobs=jobs, return_as="generator_unordered", batch_size=1)(
            delayed(_indexed)(k, *task(idx)) for k, idx in enumerate(chunks))
        for k, records in gen:
            bar.update(len(records))
            yield chunks[k], records
    else:
        for idx in _chunks(todo, cells, identity, 1):
            yield idx, run_chunk(*task(idx), on_cell=lambda: bar.update(1))


class _Cluster:
    """A Dask scheduler's address and the client connected to it at the first use, closed by :meth:`close`."""

    def __init__(self, address: str):
        self.address = address
        self._client: Any = None

    @property
    def client(self) -> Any:
        if self._client is None:
            self._client = _connect(self.address)
        return self._client

    def close(self) -> None:
        if self._client is not None and isinstance(self.address, str):  # a client passed in stays open
            self._client.close()
        self._client = None


def _connected(scheduler: Any) -> Any:
    """A context giving a Dask client: the study's (left open) for a :class:`_Cluster`, else a new one."""
    if isinstance(scheduler, _Cluster):
        return contextlib.nullcontext(scheduler.client)
    client = _connect(scheduler)
    return client if isinstance(scheduler, str) else contextlib.nullcontext(client)  # the caller's client stays open


def _connect(address: Any) -> Any:
    """A Dask client of the scheduler at ``address`` (a client as it is); a ConfigError when none answers."""
    # deferred: dask, an optional extra (footzoo[distributed])
    from dask.distributed import Client

    address = check_scheduler(address)
    if not isinstance(address, str):  # a connected Client
        return address
    try:
        return Client(address)
    except (OSError, TimeoutError) as err:
        raise ConfigError(f"scheduler {address}: no Dask scheduler answers there ({err}); start one (dask scheduler, "
                          "then dask worker ADDRESS on each machine), check the address and the firewall, or leave "
                          "the scheduler out to run on this machine") from None
    except Exception as err:  # something answers, but not in Dask's protocol (a web server, a proxy): garbage frames
        raise ConfigError(f"scheduler {address}: what answers there is not a Dask scheduler ({type(err).__name__}: "
                          f"{str(err)[:120]}); check the address and the port (a scheduler listens on 8786 by default, "
                          "its dashboard on 8787), or leave the scheduler out to run on this machine") from None


def _indexed(k: int, *args: Any) -> tuple[int, list[dict[str, Any]]]:
    return k, run_chunk(*args)


def _log_damaged(out: Path, recomputed: dict[str, str]) -> None:
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S")
    with open(out / "cache_report.log", "a") as f:
        for key, problem in recomputed.items():
            f.write(f"{stamp} cache entry {key}.json {problem}: run again\n")


def tidy(runs: list[dict[str, Any]], factors: list[str]) -> pd.DataFrame:
    """One row per run × metric (a failed run gives one row with its error).

    ``note`` gives the reason of a metric refused (NaN) because the recording's reference cannot
    score it (:mod:`footzoo.evaluation.validity`); it is empty for every other row.
    """
    rows = []
    for r in runs:
        base = {"run": r["key"], "base": r["base"], **{f: _cell_value(r["levels"].get(f)) for f in factors},
                "recording": r["recording"]}
        if r["error"]:
            rows.append({**base, "metric": None, "value": np.nan, "error": r["error"], "note": None})
        notes = r.get("notes") or {}
        for name, value in sorted(r["metrics"].items()):
            rows.append({**base, "metric": name, "value": value, "error": None, "note": notes.get(name)})
    cols = ["run", "base", *factors, "recording", "metric", "value", "error", "note"]
    return pd.DataFrame(rows, columns=cols)


def read_trajectories(out: str | Path) -> pd.DataFrame:
    """The stored trajectories of a study's runs (``out/trajectories.parquet``): one row per stored point.

    Raises
    ------
    FormatError
        When the study's report in ``out`` is incomplete (a study was interrupted while writing it,
        or is writing it now: ``outputs.json``, written last, is missing).
    """
    check_complete(out, MANIFEST, "a study's report")
    return pd.read_parquet(Path(out) / "trajectories.parquet")


def check_scheduler(address: Any) -> Any:
    """A Dask scheduler's address (``tcp://HOST:PORT``) or a client as it is; a ConfigError for a malformed one.

    Checked before any work (Dask's own parser fails late, with a bare ValueError).
    """
    if not isinstance(address, str):
        if hasattr(address, "submit") and hasattr(address, "scheduler_info"):  # a connected Client
            return address
        raise ConfigError(f"scheduler must be a Dask scheduler's address such as tcp://10.0.0.5:8786, got "
                          f"{type(address).__name__} {address!r:.80}")
    text = address.strip()
    fix = ("give the address the scheduler printed when it started, e.g. tcp://10.0.0.5:8786 (or leave the "
           "scheduler out to run on this machine)")
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if scheme not in SCHEDULER_SCHEMES:
        raise ConfigError(f"scheduler {address!r}: unknown protocol {scheme!r} (Dask speaks "
                          f"{', '.join(SCHEDULER_SCHEMES)}); {fix}")
    if scheme == "inproc":  # a LocalCluster(processes=False) of this process: inproc://HOST/PID/N
        if not re.fullmatch(r"[^/\s]+/\d+/\d+", rest):
            raise ConfigError(f"scheduler {address!r} is not an in-process address (inproc://HOST/PID/N, as "
                              f"LocalCluster(processes=False) gives); {fix}")
        return f"inproc://{rest}"
    host, colon, port = rest.rstrip("/").rpartition(":")
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ConfigError(f"scheduler {address!r} is not HOST:PORT with a port in 1-65535; {fix}")
    if host.startswith("[") != host.endswith("]"):
        raise ConfigError(f"scheduler {address!r}: the IPv6 host must be in brackets, e.g. tcp://[::1]:8786")
    return f"{scheme}://{host}:{int(port)}"


#: Protocols of a Dask scheduler's address footzoo can connect to.
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")


def _cell_value(v: Any) -> Any:
    return v if isinstance(v, (str, int, float, bool)) or v is None else json.dumps(v, sort_keys=True)


class _Progress:
    """One tqdm bar over the whole command; its total grows as the work becomes known."""

    def __init__(self, show: bool, name: str):
        self.bar = None
        if show:
            try:
                # deferred: tqdm, optional (a progress bar when installed)
                from tqdm import tqdm
            except ImportError:  # tqdm is a dependency, but a bar is not worth failing for
                return
            self.bar = tqdm(total=1, desc=name, unit="step")
        self.name = name

    def set_description(self, name: str) -> None:
        self.name = name

    def phase(self, what: str) -> None:
        if self.bar is not None:
            self.bar.set_description(f"{self.name}: {what}")

    def add(self, n: int) -> None:
        if self.bar is not None:
            self.bar.total += n
            self.bar.refresh()

    def update(self, n: int = 1) -> None:
        if self.bar is not None:
            self.bar.update(n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
