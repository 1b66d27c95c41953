"""Run a study's cells serially, on local cores (joblib) or on a Dask cluster, with a resumable cache."""

from __future__ import annotations

import json
import os
import traceback
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .study import Cell, Study

TRAJECTORY_STEP = 0.1  # s between stored trajectory points (for the overlay plots)


def _metrics(rec, res, metric_names: list[str] | None) -> dict[str, float]:
    from ..metrics import stance_scores, step_detection, trajectory_metrics

    truth = rec.truth
    closed = bool(truth is not None and truth.closed_loop)
    m = trajectory_metrics(res.pos, truth.pos if truth is not None else None, closed)
    m["steps"] = float(len(res.steps))
    if truth is not None and truth.stance is not None:
        m.update({f"stance_{k}": v for k, v in stance_scores(res.stance, truth.stance).items()})
        sd = step_detection(res.stance, truth.stance, rec.t)
        m["gait_phase_error_rate"] = sd["error_rate"]
        m["step_count_error"] = float(sd["step_count_error"])
    if "fpa_rad" in res.steps:
        fpa = res.steps["fpa_rad"].dropna()
        if len(fpa):
            m["fpa_mean_deg"] = float(np.degrees(fpa.mean()))
    if metric_names:
        m = {k: v for k, v in m.items() if k in metric_names}
    return {k: float(v) for k, v in m.items()}


def _roc(rec, detector_spec: dict[str, Any], points: int) -> list[list[float]]:
    """Threshold sweep from the detector's statistic (stance where the statistic is below the threshold)."""
    from ..registry import build

    if rec.truth is None or rec.truth.stance is None:
        return []
    det = build("detector", dict(detector_spec))
    if getattr(det, "needs_truth", False):
        return []
    det.detect(rec.t, rec.acc, rec.gyr)
    stat, truth = np.asarray(det.statistic_, float), rec.truth.stance
    out = []
    for th in np.quantile(stat, np.linspace(0.0, 1.0, points)):
        pred = stat <= th
        tpr = float(np.sum(pred & truth) / max(truth.sum(), 1))
        fpr = float(np.sum(pred & ~truth) / max((~truth).sum(), 1))
        out.append([float(th), tpr, fpr])
    return out


def run_cell(cell: Cell, cache_dir: str | None = None, metric_names: list[str] | None = None,
             sweep_points: int = 0) -> dict[str, Any]:
    """Run one cell (or read it from the cache); never raises: errors are recorded."""
    key = cell.key()
    path = Path(cache_dir) / f"{key}.json" if cache_dir else None
    if path is not None and path.exists():
        out = json.loads(path.read_text())
        out["cached"] = True
        return out
    out: dict[str, Any] = {"key": key, "base": cell.base, "levels": cell.levels, "recording": cell.recording.label,
                           "error": None, "metrics": {}, "trajectory": [], "roc": []}
    try:
        from ..pipeline import Pipeline

        pipeline = Pipeline.from_dict(cell.config)
        rec = cell.recording.load()
        res = pipeline.run(rec)
        out["metrics"] = _metrics(rec, res, metric_names)
        step = max(int(round(TRAJECTORY_STEP * rec.rate)), 1)
        out["trajectory"] = np.column_stack([rec.t, res.pos])[::step].round(4).tolist()
        if rec.truth is not None and rec.truth.pos is not None:  # reference path for the overlay plots
            out["reference"] = np.column_stack([rec.t, rec.truth.pos])[::step].round(4).tolist()
        if sweep_points:
            out["roc"] = _roc(rec, cell.config["detector"], sweep_points)
    except Exception as err:  # one failing run is reported, not fatal
        out["error"] = f"{type(err).__name__}: {err}"
        out["traceback"] = traceback.format_exc(limit=3)
    if path is not None:
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps(out))
        tmp.replace(path)  # atomic: an interrupted study leaves only complete entries
    out["cached"] = False
    return out


def run_study(
    study: Study | str | Path,
    jobs: int = 1,
    scheduler: str | None = None,
    out: str | Path | None = None,
    progress: bool = False,
    max_runs: int | None = None,
) -> pd.DataFrame:
    """Run every cell of a study and return the tidy table (one row per run × metric).

    Parameters
    ----------
    study : Study or path
        The study (or its YAML file).
    jobs : int
        Local worker processes (joblib); 1 runs serially.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); the runs go
        to its workers through ``dask.distributed``.
    out : path, optional
        Output folder: ``cache/`` (one file per run, keyed by the hash of the
        resolved config and the data, so a rerun resumes), ``results.parquet``,
        ``results.csv``, ``summary.md``, ``summary.tex`` and plots.
    progress : bool
        Show a progress bar.
    max_runs : int, optional
        Stop after this many new runs (what an interruption leaves behind).

    Returns
    -------
    DataFrame
        The tidy table. Its ``attrs`` hold ``computed`` and ``cached`` run counts and the
        per-run records (``runs``) with trajectories and threshold sweeps.
    """
    if not isinstance(study, Study):
        study = Study.from_yaml(study)
    cells = study.cells()
    cache_dir = None
    if out is not None:
        cache = Path(out) / "cache"
        cache.mkdir(parents=True, exist_ok=True)
        cache_dir = str(cache)
    keys = [c.key() for c in cells]
    missing = _all_missing(keys, cache_dir)
    new = set(missing if max_runs is None else missing[:max_runs])
    # cached cells are read back, missing ones run (all of them unless max_runs stops early)
    work = [i for i in range(len(cells)) if i in new or i not in set(missing)]
    args = (cache_dir, study.metrics, study.sweep_points)
    results: dict[int, dict[str, Any]] = {}
    bar = _progress(len(work), progress, study.name)
    if scheduler is not None:
        from dask.distributed import Client, as_completed

        with Client(scheduler) as client:
            futures = {client.submit(run_cell, cells[i], *args, pure=False): i for i in work}
            for fut in as_completed(futures):
                results[futures[fut]] = fut.result()
                bar.update(1)
    elif jobs != 1:
        from joblib import Parallel, delayed

        gen = Parallel(n_jobs=jobs, return_as="generator")(delayed(run_cell)(cells[i], *args) for i in work)
        for i, r in zip(work, gen, strict=True):
            results[i] = r
            bar.update(1)
    else:
        for i in work:
            results[i] = run_cell(cells[i], *args)
            bar.update(1)
    bar.close()
    runs = [results[i] for i in sorted(results)]
    table = tidy(runs, list(study.factors))
    table.attrs["computed"] = sum(1 for r in runs if not r.get("cached"))
    table.attrs["cached"] = sum(1 for r in runs if r.get("cached"))
    table.attrs["runs"] = runs
    if out is not None:
        from .report import write_outputs

        write_outputs(table, runs, list(study.factors), Path(out))
    return table


def _all_missing(keys: list[str], cache_dir: str | None) -> list[int]:
    """Indices not in the cache (all when there is no cache)."""
    if cache_dir is None:
        return list(range(len(keys)))
    return [i for i, k in enumerate(keys) if not (Path(cache_dir) / f"{k}.json").exists()]


def tidy(runs: list[dict[str, Any]], factors: list[str]) -> pd.DataFrame:
    """One row per run × metric (a failed run gives one row with its error)."""
    rows = []
    for r in runs:
        base = {"run": r["key"], "base": r["base"], **{f: _cell_value(r["levels"].get(f)) for f in factors},
                "recording": r["recording"]}
        if r["error"]:
            rows.append({**base, "metric": None, "value": np.nan, "error": r["error"]})
        for name, value in sorted(r["metrics"].items()):
            rows.append({**base, "metric": name, "value": value, "error": None})
    cols = ["run", "base", *factors, "recording", "metric", "value", "error"]
    return pd.DataFrame(rows, columns=cols)


def _cell_value(v: Any) -> Any:
    return v if isinstance(v, (str, int, float, bool)) or v is None else json.dumps(v, sort_keys=True)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


def _progress(total: int, show: bool, name: str):
    if not show:
        return _NoBar()
    try:
        from tqdm import tqdm
    except ImportError:
        return _NoBar()
    return tqdm(total=total, desc=name, unit="run")
