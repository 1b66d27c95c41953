"""Study outputs: tidy table (Parquet, CSV), summaries per factor level (Markdown, LaTeX), plots."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd


def summarise(table: pd.DataFrame, factor: str) -> pd.DataFrame:
    """Mean, median, standard deviation and count of every metric per level of one factor."""
    ok = table[table["metric"].notna()]
    g = ok.groupby([factor, "metric"], dropna=False)["value"]
    out = g.agg(["mean", "median", "std", "count"]).reset_index()
    return out.sort_values(["metric", factor]).reset_index(drop=True)


def to_markdown(df: pd.DataFrame, digits: int = 4) -> str:
    """A GitHub-style Markdown table."""
    cols = [str(c) for c in df.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for row in df.itertuples(index=False):
        lines.append("| " + " | ".join(_fmt(v, digits) for v in row) + " |")
    return "\n".join(lines) + "\n"


def to_latex(df: pd.DataFrame, digits: int = 4) -> str:
    """A booktabs LaTeX tabular."""
    def esc(v: Any) -> str:
        return _fmt(v, digits).replace("_", r"\_").replace("%", r"\%").replace("&", r"\&")

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
                  step: Callable[[int], Any] | None = None, jobs: int = 1) -> None:
    """Write the tidy table, the trajectories and sweeps (apart from it), summaries and plots into ``out``.

    ``step(1)`` is called after each of the four parts (tables, trajectories, summaries, plots).
    Everything is written into a staging folder first and then moved into ``out`` file by file
    (atomic renames): an interrupted report or two studies writing into one folder never leave a
    half-written file. With ``jobs`` other than 1 the figures are drawn by that many local worker
    processes (see :func:`figure_tasks`) while this process writes the tables.
    """
    step = step or (lambda n: None)
    out.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=out))
    try:
        _write_outputs(table, runs, factors, staging, step, jobs)
        for f in sorted(staging.iterdir()):
            if f.is_file():
                os.replace(f, out / f.name)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def figure_tasks(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str]) -> list[tuple]:
    """:func:`plot_study` split into independent calls whose figures together are the whole call's.

    The trajectories and the threshold sweep need the runs but no metric rows (an empty table);
    the metric plots of one factor need the table but no runs.
    """
    return [(table.iloc[:0], runs, factors)] + [(table, [], [f]) for f in factors]


def _write_outputs(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path,
                   step: Callable[[int], Any], jobs: int = 1) -> None:
    table = table.copy()
    table.attrs = {}  # counts and cache notes describe this execution, not the results
    figures = None
    if jobs != 1:  # started first: the workers draw while this process writes the tables
        from joblib import Parallel, delayed

        figures = Parallel(n_jobs=jobs, return_as="generator_unordered", batch_size=1)(
            delayed(plot_study)(t, r, f, out) for t, r, f in figure_tasks(table, runs, factors))
    table.to_csv(out / "results.csv", index=False)
    _to_parquet(table, out / "results.parquet")
    step(1)
    trajectories, roc = run_frames(runs)
    _to_parquet(trajectories, out / "trajectories.parquet")
    _to_parquet(roc, out / "roc.parquet")
    step(1)
    md, tex = [], []
    for f in ["base", *factors]:
        s = summarise(table, f)
        md.append(f"## {f}\n\n" + to_markdown(s))
        tex.append(f"% {f}\n" + to_latex(s))
    errors = table[table["error"].notna()][["run", "recording", "error"]].drop_duplicates()
    if len(errors):
        md.append("## failed runs\n\n" + to_markdown(errors))
    (out / "summary.md").write_text("\n".join(md))
    (out / "summary.tex").write_text("\n".join(tex))
    step(1)
    if figures is None:
        plot_study(table, runs, factors, out)
    else:
        for _ in figures:
            pass
    step(1)


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
        parts = [(r["key"], r["recording"], np.asarray(r[field], float)) for r in runs if r.get(field)]
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


def _to_parquet(df: pd.DataFrame, path: Path) -> None:
    try:
        df.to_parquet(path, index=False)
    except ImportError:  # pyarrow not installed: CSV only (the README's install has it)
        pass


def plot_study(table: pd.DataFrame, runs: list[dict[str, Any]], factors: list[str], out: Path) -> None:
    """Trajectories per recording, each metric per factor level, ROC of the detectors' threshold sweeps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    label_of = {r["key"]: ", ".join(f"{k}={v}" for k, v in r["levels"].items() if k in factors) or r["base"]
                for r in runs}
    for rec in sorted({r["recording"] for r in runs}):
        fig, ax = plt.subplots(figsize=(6, 6))
        for r in runs:
            if r["recording"] == rec and r["trajectory"]:
                tr = np.asarray(r["trajectory"])
                ax.plot(tr[:, 2], tr[:, 1], lw=1, label=label_of[r["key"]])
        ax.set_xlabel("east (m)")
        ax.set_ylabel("north (m)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(rec)
        if len(ax.lines) <= 12:
            ax.legend(fontsize=6)
        fig.savefig(out / f"trajectories_{_safe(rec)}.png", dpi=100)
        plt.close(fig)
    ok = table[table["metric"].notna()]
    for f in factors:
        for metric in sorted(ok["metric"].unique()):
            d = ok[ok["metric"] == metric]
            levels = list(dict.fromkeys(d[f].astype(str)))
            fig, ax = plt.subplots(figsize=(max(4, 0.8 * len(levels) + 2), 4))
            ax.boxplot([d[d[f].astype(str) == lv]["value"].to_numpy() for lv in levels])
            ax.set_xticks(range(1, len(levels) + 1), levels, rotation=30, ha="right", fontsize=7)
            ax.set_xlabel(f)
            ax.set_ylabel(metric)
            fig.tight_layout()
            fig.savefig(out / f"metric_{_safe(metric)}_by_{_safe(f)}.png", dpi=100)
            plt.close(fig)
    with_roc = [r for r in runs if r.get("roc")]
    if with_roc:
        fig, ax = plt.subplots(figsize=(5, 5))
        for r in with_roc:
            roc = np.asarray(r["roc"])
            ax.plot(roc[:, 2], roc[:, 1], lw=1, label=f"{label_of[r['key']]} / {r['recording']}")
        ax.plot([0, 1], [0, 1], "k:", lw=0.5)
        ax.set_xlabel("false stance rate")
        ax.set_ylabel("true stance rate")
        ax.set_title("detector threshold sweep")
        if len(with_roc) <= 12:
            ax.legend(fontsize=6)
        fig.savefig(out / "roc.png", dpi=100)
        plt.close(fig)


def _safe(s: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in str(s))[:80]
