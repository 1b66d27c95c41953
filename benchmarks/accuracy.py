"""Accuracy of every shipped pipeline on every recording with a reference, and on simulator scenarios.

Usage: python benchmarks/accuracy.py [--jobs 2] [--quick] [--results benchmarks/results/]
                                     [--data ../shared/data] [--configs yun2012,nguyen2016]
                                     [--summary benchmarks/accuracy.md]
                                     [--parts configs,pyshoe3d,rates,events,consistency,mounting,stillness]

``--parts`` chooses what runs (default all): ``configs`` is the table of every shipped config below;
the others score the flagship on every axis (benchmarks/accuracy_parts.py: 3-D and height on PyShoe
per motion class, rate independence, gait events, filter consistency, 24 mountings, a foot standing
still). Only the chosen parts' blocks of the existing summary's flagship section are rewritten; the
others are kept, with or without ``configs``.

Every config in ``configs/`` that is a pipeline (not ``study_*.yaml``) runs, through footzoo's
ablation runner (one study per dataset: parallel with ``--jobs``, cached in
``RESULTS/<dataset>/cache`` so a rerun only computes what changed), on:

* the 36 PyShoe VICON trials (Wagstaff et al.): PyShoe's own 2-D metric (``pyshoe_error_m``,
  :func:`footzoo.evaluation.metrics.pyshoe_error`) beside PyShoe's per-trial best (``trial_error``, the minimum
  over its five detectors, each at a threshold re-tuned for that trial), and a 3-D ARMSE after a
  least-squares yaw alignment; medians per motion class;
* x-io's short walk, a closed loop: horizontal end-to-start distance;
* gaitmap's example walk, each foot: stride lengths (and foot progression angles where the config
  computes them) against the motion-capture reference (:mod:`footzoo.io.gaitmap_reference`);
* Köroğlu's experiments 31–33: the number of strides against the count measured on the floor, and,
  when it is exact, the footprint error after a 2-D rigid alignment that may include a reflection;
* simulated walks (footzoo.sim, physical foot model, Table II noise): a hallway walk, a run, stairs,
  mixed speeds at 100 and 200 Hz, and a one-hour walk (ten laps of a 437.5 m track).

Datasets that are absent are skipped. Outputs: ``RESULTS/accuracy.parquet`` and ``.csv`` (tidy:
one row per dataset × recording × config × metric), the Markdown summary (default
``benchmarks/accuracy.md``) and its figure (``benchmarks/accuracy.png``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import accuracy_parts  # noqa: E402

from footzoo.config import BUILTIN  # noqa: E402
from footzoo.studies import Study, run_cell, run_study, tidy  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

DEFAULT_DATA = ROOT.parent / "shared" / "data"
DEFAULT_RESULTS = ROOT / "benchmarks" / "results"
DEFAULT_SUMMARY = ROOT / "benchmarks" / "accuracy.md"
#: Where the flagship section starts in the summary (a rerun of some parts replaces their blocks in it).
FLAGSHIP_MARK = "<!-- flagship parts: everything below is rewritten by --parts -->"

#: PyShoe trials by recording day (the dataset does not label them; see ../shared/data/README.md).
MOTION_CLASSES = {
    "2017-11-22": "walking",
    "2017-11-27": "running/fast",
    "2017-12-15": "running/fast",
    "2018-02-09": "slow unusual",
    "2018-02-22": "inverted",
}
CLASS_ORDER = ["walking", "running/fast", "slow unusual", "inverted"]
QUICK_PYSHOE = ["2017-11-22-11-22-03", "2017-11-27-11-12-18", "2018-02-22-10-09-36"]


def _sim(**spec: Any) -> dict[str, Any]:
    """A simulator scenario: physical foot model, Table II noise and biases, VL6180-like distance sensors
    (Duong & Suh 2015, so that ``duong2015`` runs too), 0.15 m swing clearance, unless ``spec`` says otherwise."""
    return {"profile": "physical", "clearance": 0.15, "noise": {"scale": 1}, "distance_sensors": True, **spec}


#: Simulator scenarios: name -> simulate() arguments.
SIM_SCENARIOS: dict[str, dict[str, Any]] = {
    "walk": _sim(path="rectangle", rate=100),
    "run": _sim(path="run", n_strides=40, rate=200),
    "stairs": _sim(path="stairs", n_strides=6, landing_strides=3, cycle=1.2, clearance=0.1, rate=100),
    "mixed_speed_100hz": _sim(path="mixed_speed", rate=100),
    "mixed_speed_200hz": _sim(path="mixed_speed", rate=200),
    "walk_1h": _sim(path="track", laps=10, rate=100),
}
QUICK_SIM = {"walk_short": _sim(path="rectangle", length=10.0, width=5.0, rate=100)}

#: Targets of the issue (recommended config unless said otherwise).
TARGETS = {
    "median_ratio": 1.3, "walking_median_m": 0.040, "running_median_m": 0.10, "max_trial_m": 0.5,
    "every_config_max_m": 1.0, "xio_loop_xy_m": 0.050, "gaitmap_stride_rms_m": 0.05, "walk_1h_pct": 1.0,
}


def shipped_configs(names: list[str] | None = None) -> list[Path]:
    """The pipeline configs in ``configs/`` (not the study files), optionally only ``names``."""
    paths = sorted(p for p in BUILTIN.glob("*.yaml") if not p.stem.startswith("study"))
    if names:
        unknown = sorted(set(names) - {p.stem for p in paths})
        if unknown:
            raise SystemExit(f"unknown config(s) {unknown}; shipped: {[p.stem for p in paths]}")
        paths = [p for p in paths if p.stem in names]
    return paths


def motion_class(trial: str) -> str:
    """Motion class of a PyShoe trial from its recording day."""
    return MOTION_CLASSES.get(trial[:10], "other")


# ----------------------------------------------------------------------------------------- datasets


def pyshoe_reference(folder: Path) -> pd.DataFrame:
    """Per trial: PyShoe's best ``trial_error`` (m) and the detector that reached it, hand-counted strides."""
    csv = folder / "trials.csv"
    if csv.exists():
        t = pd.read_csv(csv)
        return t.set_index("trial")[["best_error_m", "best_detector", "n_strides_manual_koroglu"]]
    from scipy.io import loadmat

    from footzoo.io.pyshoe import TRIAL_ERROR_DETECTORS

    rows = {}
    for p in sorted(folder.glob("*.mat")):
        err = np.ravel(loadmat(p, variable_names=["trial_error"])["trial_error"])
        rows[p.stem] = {"best_error_m": float(err.min()), "best_detector": TRIAL_ERROR_DETECTORS[int(err.argmin())],
                        "n_strides_manual_koroglu": np.nan}
    return pd.DataFrame.from_dict(rows, orient="index")


def recordings(data: Path, quick: bool, sim: dict[str, dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """Study recordings per dataset, only for the datasets that are present."""
    out: dict[str, list[dict[str, Any]]] = {}
    pyshoe = data / "pyshoe_vicon"
    if pyshoe.is_dir() and any(pyshoe.glob("*.mat")):
        files = [pyshoe / f"{n}.mat" for n in QUICK_PYSHOE] if quick else sorted(pyshoe.glob("*.mat"))
        out["pyshoe"] = [{"path": str(p), "format": "pyshoe"} for p in files if p.exists()]
    xio = data / "xio_gait_tracking" / "short_walk.csv"
    if xio.exists():
        out["xio"] = [{"path": str(xio), "format": "xio"}]
    gaitmap = data / "gaitmap_example"
    if not quick and (gaitmap / "imu_sample.csv").exists() and (gaitmap / "mocap_sample.csv").exists():
        for foot in ("left", "right"):
            out[f"gaitmap_{foot}"] = [{"path": str(gaitmap / "imu_sample.csv"), "format": "gaitmap", "foot": foot}]
    koroglu = sorted((data / "koroglu_gcp").glob("SensorConnectData_*.csv"))
    if not quick and koroglu:
        out["koroglu"] = [{"path": str(p), "format": "sensorconnect"} for p in koroglu
                          if p.with_suffix(".mat").exists()]
    for name, spec in sim.items():
        out[f"sim_{name}"] = [{"simulate": spec, "seeds": [0], "label": f"sim_{name}"}]
    return {k: v for k, v in out.items() if v}


def run_cached(study: Study, folder: Path, jobs: int = 1, plots: bool = False, progress: bool = False) -> pd.DataFrame:
    """A study's tidy table through the ablation runner, cached in ``folder/cache``.

    ``plots`` also writes the runner's report (tables and one plot per recording, slow for
    thousands of runs); without it the cells go through :func:`footzoo.studies.run_cell`
    with the same cache, so a rerun only computes what changed.
    """
    if plots:
        return run_study(study, jobs=jobs, out=folder, progress=progress)
    cache = folder / "cache"
    cache.mkdir(parents=True, exist_ok=True)
    cells = study.cells()
    if jobs == 1:
        runs = [run_cell(c, str(cache), study.metrics) for c in cells]
    else:
        from joblib import Parallel, delayed

        runs = Parallel(n_jobs=jobs)(delayed(run_cell)(c, str(cache), study.metrics) for c in cells)
    return tidy(runs, list(study.factors))


def run_dataset(name: str, recs: list[dict[str, Any]], configs: list[Path], results: Path, jobs: int,
                progress: bool, plots: bool = False) -> pd.DataFrame:
    """Every config on one dataset's recordings, through the ablation runner (cached)."""
    study = Study.from_dict({"name": name, "base": [str(c) for c in configs], "recordings": recs})
    table = run_cached(study, results / name, jobs, plots, progress)
    table = table.rename(columns={"base": "config"})
    table.insert(0, "dataset", name)
    return table[["dataset", "recording", "config", "metric", "value", "error"]]


# ------------------------------------------------------------------------- per-stride references


#: Per dataset: benchmark metric <- key of :attr:`footzoo.evaluation.result.Result.metrics`, which compares the
#: stride table with the reference the reader loads (:func:`footzoo.evaluation.metrics.stride_errors` for
#: gaitmap's motion capture, :func:`footzoo.evaluation.metrics.footprint_errors` for Köroğlu's footprints):
#: the benchmark, ``footzoo run`` and :class:`footzoo.Session` report the same numbers.
REFERENCE_METRICS: dict[str, dict[str, str]] = {
    "gaitmap": {
        "strides_matched": "matched_strides", "strides_reference": "ref_strides",
        "stride_length_rms_m": "stride_length_rms_error_m",
        "stride_length_rms_straight_m": "stride_length_rms_error_straight_m",
        "fpa_bias_deg": "fpa_mean_error_deg", "fpa_rms_deg": "fpa_rms_error_deg",
    },
    "koroglu": {
        "strides_detected": "strides", "strides_reference": "stride_count_ref",
        "stride_count_error": "stride_count_error", "footprint_error_mean_m": "footprint_error_mean_m",
        "footprint_error_rms_m": "footprint_error_rms_m", "footprint_error_end_m": "footprint_error_end_m",
    },
}


def stride_metrics(dataset: str, spec: dict[str, Any], config: Path) -> list[dict[str, Any]]:
    """Per-stride comparisons (gaitmap mocap, Köroğlu footprints): the run's ``Result.metrics``."""
    from footzoo.io import load
    from footzoo.runtime.pipeline import Pipeline

    label = Path(spec["path"]).stem
    rows: list[dict[str, Any]] = []
    try:
        options = {k: v for k, v in spec.items() if k not in ("path", "format")}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rec = load(spec["path"], format=spec["format"], **options)
            metrics = Pipeline.from_yaml(config).run(rec).metrics
        names = REFERENCE_METRICS["gaitmap" if dataset.startswith("gaitmap") else "koroglu"]
        rows += [{"dataset": dataset, "recording": label, "config": config.stem, "metric": name,
                  "value": float(metrics[key]), "error": None} for name, key in names.items() if key in metrics]
    except Exception as err:  # one failing run is reported, not fatal (as in the ablation runner)
        rows.append({"dataset": dataset, "recording": label, "config": config.stem, "metric": None,
                     "value": np.nan, "error": f"{type(err).__name__}: {err}"})
    return rows


def run_stride_references(datasets: dict[str, list[dict[str, Any]]], configs: list[Path], jobs: int) -> pd.DataFrame:
    """Stride-level references for the datasets that have them."""
    from joblib import Parallel, delayed

    work = [(name, spec, c) for name, recs in datasets.items() if name.startswith(("gaitmap", "koroglu"))
            for spec in recs for c in configs]
    if not work:
        return pd.DataFrame(columns=["dataset", "recording", "config", "metric", "value", "error"])
    out = Parallel(n_jobs=jobs)(delayed(stride_metrics)(*w) for w in work)
    return pd.DataFrame([r for rows in out for r in rows])


# --------------------------------------------------------------------------------------- summary


def metric(table: pd.DataFrame, dataset: str, name: str) -> pd.DataFrame:
    """``recording × config`` values of one metric of one dataset."""
    t = table[(table["dataset"] == dataset) & (table["metric"] == name)]
    return t.pivot_table(index="recording", columns="config", values="value", aggfunc="first")


def failures(table: pd.DataFrame, dataset_prefix: str) -> pd.DataFrame:
    """Runs that raised (config, recording, error)."""
    t = table[table["dataset"].str.startswith(dataset_prefix) & table["error"].notna()]
    return t[["config", "recording", "error"]].drop_duplicates()


def pyshoe_summary(table: pd.DataFrame, ref: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Per-config summary and per-trial table of PyShoe's metric."""
    err = metric(table, "pyshoe", "pyshoe_error_m")
    armse = metric(table, "pyshoe", "armse_3d_m")
    if err.empty:
        return pd.DataFrame(), pd.DataFrame()
    best = ref["best_error_m"].reindex(err.index)
    classes = pd.Series([motion_class(t) for t in err.index], index=err.index)
    rows = []
    for cfg in err.columns:
        e = err[cfg]
        ratio = e / best
        row: dict[str, Any] = {"config": cfg, "trials run": f"{int(e.notna().sum())}/{len(e)}"}
        for c in CLASS_ORDER:
            if (classes == c).any():
                row[f"{c} median (m)"] = e[classes == c].median()
        row["all median (m)"] = e.median()
        row["median ratio to best"] = ratio.median()
        row["worst (m)"] = e.max()
        row["worst trial"] = e.idxmax() if e.notna().any() else ""
        row["trials > 1 m"] = int((e > 1.0).sum())
        row["3-D ARMSE median (m)"] = armse[cfg].median() if cfg in armse else np.nan
        rows.append(row)
    best_row: dict[str, Any] = {"config": "PyShoe per-trial best", "trials run": f"{len(best)}/{len(best)}"}
    for c in CLASS_ORDER:
        if (classes == c).any():
            best_row[f"{c} median (m)"] = best[classes == c].median()
    best_row.update({"all median (m)": best.median(), "median ratio to best": 1.0, "worst (m)": best.max(),
                     "worst trial": best.idxmax(), "trials > 1 m": int((best > 1.0).sum())})
    summary = pd.DataFrame([best_row, *rows])
    per_trial = err.copy()
    per_trial.insert(0, "PyShoe best", best)
    per_trial.insert(0, "class", classes)
    per_trial = per_trial.sort_values(["class", "PyShoe best"], key=lambda s: s.map(
        {c: i for i, c in enumerate(CLASS_ORDER)}) if s.name == "class" else s)
    return summary, per_trial.reset_index().rename(columns={"recording": "trial"})


def sim_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Simulator scenarios: the headline metric of each (config × scenario)."""
    t = table[table["dataset"].str.startswith("sim_") & table["metric"].notna()]
    if t.empty:
        return pd.DataFrame()
    keep = ["armse_3d_m", "loop_closure_3d_pct", "loop_closure_xy_pct", "gait_phase_error_rate", "step_count_error"]
    t = t[t["metric"].isin(keep)]
    out = t.pivot_table(index=["dataset", "metric"], columns="config", values="value", aggfunc="first")
    return out.reset_index()


def targets(table: pd.DataFrame, ref: pd.DataFrame, recommended: str) -> pd.DataFrame:
    """The issue's targets, with the measured value and whether it is met (n/a when the data is absent)."""
    rows = []

    def add(what: str, target: str, value: float | str, met: bool | None) -> None:
        rows.append({"target": what, "bound": target,
                     "measured": value if isinstance(value, str) else f"{value:.3f}",
                     "met": "n/a" if met is None else ("yes" if met else "**no**")})

    err = metric(table, "pyshoe", "pyshoe_error_m")
    if not err.empty and recommended in err:
        e = err[recommended]
        best = ref["best_error_m"].reindex(err.index)
        classes = pd.Series([motion_class(t) for t in err.index], index=err.index)
        r = (e / best).median()
        add(f"{recommended}: median ratio to PyShoe's per-trial best", f"≤ {TARGETS['median_ratio']}", r,
            r <= TARGETS["median_ratio"])
        w = e[classes == "walking"].median()
        add(f"{recommended}: walking median", f"≤ {TARGETS['walking_median_m']} m", w, w <= TARGETS["walking_median_m"])
        rr = e[classes == "running/fast"].median()
        add(f"{recommended}: running/fast median", f"≤ {TARGETS['running_median_m']} m", rr,
            rr <= TARGETS["running_median_m"])
        add(f"{recommended}: worst trial", f"≤ {TARGETS['max_trial_m']} m", e.max(), e.max() <= TARGETS["max_trial_m"])
    ps = table[table["dataset"] == "pyshoe"]
    for cfg in sorted(ps["config"].unique()):
        e = err[cfg] if cfg in err else pd.Series(dtype=float)
        errors = ps.loc[(ps["config"] == cfg) & ps["error"].notna(), "error"]
        if errors.empty:
            add(f"{cfg}: every PyShoe trial runs, worst", f"≤ {TARGETS['every_config_max_m']} m", e.max(),
                bool(e.max() <= TARGETS["every_config_max_m"]))
        elif errors.str.contains("distance-sensor").all():  # the config needs sensors PyShoe's IMU lacks
            add(f"{cfg}: every PyShoe trial runs", "runs", "needs distance sensors (PyShoe has none)", None)
        else:
            add(f"{cfg}: every PyShoe trial runs", "runs", f"{errors.size} trial(s) fail: {errors.iloc[0][:80]}",
                False)
    xio = metric(table, "xio", "loop_closure_xy_m")
    if not xio.empty and recommended in xio:
        v = float(xio[recommended].iloc[0])
        add(f"{recommended}: x-io short loop, horizontal closure", f"≤ {TARGETS['xio_loop_xy_m']} m", v,
            v <= TARGETS["xio_loop_xy_m"])
    for foot in ("left", "right"):
        g = metric(table, f"gaitmap_{foot}", "stride_length_rms_m")
        if not g.empty and recommended in g:
            v = float(g[recommended].iloc[0])
            add(f"{recommended}: gaitmap {foot} stride length RMS", f"≤ {TARGETS['gaitmap_stride_rms_m']} m", v,
                v <= TARGETS["gaitmap_stride_rms_m"])
    k = metric(table, "koroglu", "stride_count_error")
    if not k.empty and recommended in k:
        v = k[recommended]
        add(f"{recommended}: Köroğlu 31–33 stride counts", "exact",
            ", ".join(f"{int(x):+d}" for x in v), bool((v == 0).all()))
    h = metric(table, "sim_walk_1h", "loop_closure_3d_pct")
    if not h.empty and "yun2012" in h:
        v = float(h["yun2012"].iloc[0])
        add("yun2012: one-hour simulated walk, 3-D end error", f"< {TARGETS['walk_1h_pct']} % of distance", v,
            v < TARGETS["walk_1h_pct"])
    return pd.DataFrame(rows)


def figure(per_trial: pd.DataFrame, path: Path) -> None:
    """PyShoe's metric per trial (log scale): every config beside PyShoe's per-trial best."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    configs = [c for c in per_trial.columns if c not in ("trial", "class", "PyShoe best")]
    x = np.arange(len(per_trial))
    fig, ax = plt.subplots(figsize=(12, 5))
    for c in configs:
        bold = c == "recommended"
        ax.plot(x, per_trial[c].clip(upper=100), marker="o", ms=4 if bold else 3, lw=2.0 if bold else 0.8,
                label=c, zorder=3 if bold else 2)
    ax.plot(x, per_trial["PyShoe best"], "k-", lw=2.5, label="PyShoe per-trial best (re-tuned per trial)")
    ax.set_yscale("log")
    ax.axhline(1.0, color="grey", ls=":", lw=1)
    ax.set_xticks(x)
    ax.set_xticklabels(per_trial["trial"].str[5:], rotation=90, fontsize=7)
    ax.set_ylabel("PyShoe error (m, log)")
    ax.set_title("footzoo configs on the 36 PyShoe VICON trials (lower is better)")
    bounds = per_trial["class"].ne(per_trial["class"].shift()).to_numpy().nonzero()[0]
    for b, cls in zip(bounds, per_trial["class"].iloc[bounds], strict=True):
        ax.axvline(b - 0.5, color="grey", lw=0.5)
        ax.text(b - 0.3, ax.get_ylim()[1] * 0.6, cls, fontsize=8, va="top", rotation=90)
    ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_summary(table: pd.DataFrame, ref: pd.DataFrame, path: Path, recommended: str, elapsed: float,
                  quick: bool) -> None:
    """The Markdown summary (and the figure beside it)."""
    lines = ["# footzoo accuracy benchmark", "",
             f"Generated by `python benchmarks/accuracy.py{' --quick' if quick else ''}` "
             f"({elapsed / 60:.1f} min; runs already in the results cache are read back, not recomputed). "
             "Metrics in metres unless said otherwise; lower is better.", ""]
    tg = targets(table, ref, recommended)
    if not tg.empty:
        lines += ["## Targets", "", to_markdown(tg), ""]
    summary, per_trial = pyshoe_summary(table, ref)
    if not summary.empty:
        lines += ["## PyShoe VICON trials (PyShoe's 2-D metric)", "",
                  "PyShoe's `trial_error` is a per-trial best: the detector threshold was re-tuned on each trial "
                  "against VICON. footzoo runs one fixed setting per config. Motion classes by recording day: "
                  "walking 2017-11-22, running/fast 2017-11-27 and 2017-12-15, slow unusual 2018-02-09, "
                  "inverted sensor 2018-02-22.", "", to_markdown(summary, digits=3), ""]
        fig = path.with_suffix(".png")
        figure(per_trial, fig)
        lines += [f"![PyShoe error per trial]({fig.name})", "", "### Per trial", "",
                  to_markdown(per_trial, digits=3), ""]
        bad = failures(table, "pyshoe")
        if not bad.empty:
            lines += ["Runs that did not complete:", "", to_markdown(bad.groupby(["config", "error"]).size()
                                                                     .rename("trials").reset_index()), ""]
    xio = table[(table["dataset"] == "xio") & table["metric"].isin(["loop_closure_xy_m", "loop_closure_3d_m",
                                                                     "path_length_m"])]
    if not xio.empty:
        lines += ["## x-io short walk (closed loop; x-io's own result: 82 mm)", "",
                  to_markdown(xio.pivot_table(index="config", columns="metric", values="value").reset_index(), 3), ""]
    # the per-stride comparisons and the path (a study also reports every other metric of the run)
    g = table[table["dataset"].str.startswith("gaitmap")
              & table["metric"].isin([*REFERENCE_METRICS["gaitmap"], "path_length_m", "steps"])]
    if not g.empty:
        gp = g.pivot_table(index=["config", "dataset"], columns="metric", values="value").reset_index()
        lines += ["## gaitmap example walk: strides against motion capture", "",
                  "Stride length RMS over all matched strides and over the straight ones (turn strides change "
                  "direction by more than 20°); FPA bias and RMS (deg) where the config computes it. Strides pair "
                  "one to one when their toe-off and initial contact both agree within 0.3 s "
                  "(footzoo.evaluation.metrics.match_strides):\n"
                   "the left foot's turn, one reference stride over two steps, "
                  "stays unpaired. Where the stride-length error comes from (bias and scatter, the stride's "
                  "definition, the recording itself): benchmarks/gaitmap_strides.md.", "",
                  to_markdown(gp, 3), ""]
    k = table[(table["dataset"] == "koroglu")
              & table["metric"].isin([*REFERENCE_METRICS["koroglu"], "path_length_m", "steps"])]
    if not k.empty:
        kp = k.pivot_table(index=["config", "recording"], columns="metric", values="value").reset_index()
        lines += ["## Köroğlu experiments 31–33: strides and footprints", "",
                  "Footprint error after a 2-D rigid alignment (reflection allowed), only when the stride count "
                  "is exact.", "", to_markdown(kp, 3), ""]
    s = sim_summary(table)
    if not s.empty:
        lines += ["## Simulator scenarios", "",
                  "Physical foot model, Table II noise and biases. walk: 120 m hallway loop; run: 40 strides at "
                  "3.2 m/s (200 Hz); stairs: 6 strides (12 steps) up, a landing, 6 down; mixed_speed: 0.85 to "
                  "3.2 m/s; walk_1h: ten laps of a 437.5 m track (4.4 km, one hour).", "", to_markdown(s, 3), ""]
    bad = table[table["error"].notna() & ~table["dataset"].eq("pyshoe")]
    if not bad.empty:
        lines += ["## Runs that did not complete", "",
                  to_markdown(bad[["dataset", "recording", "config", "error"]].drop_duplicates()), ""]
    path.write_text("\n".join(lines))


# ------------------------------------------------------------------------------------------ main


def run(data: Path, results: Path, configs: list[Path], jobs: int = 1, quick: bool = False,
        progress: bool = False, sim: dict[str, dict[str, Any]] | None = None, plots: bool = False) -> pd.DataFrame:
    """Run the benchmark and return the tidy table (also written to ``results``)."""
    results.mkdir(parents=True, exist_ok=True)
    sim = (QUICK_SIM if quick else SIM_SCENARIOS) if sim is None else sim
    datasets = recordings(data, quick, sim)
    tables = []
    for name, recs in datasets.items():
        t0 = time.time()
        tables.append(run_dataset(name, recs, configs, results, jobs, progress, plots))
        print(f"{name}: {len(recs)} recording(s) x {len(configs)} config(s) in {time.time() - t0:.0f} s", flush=True)
    tables.append(run_stride_references(datasets, configs, jobs))
    table = pd.concat([t for t in tables if not t.empty], ignore_index=True)
    table["motion_class"] = [motion_class(r) if d == "pyshoe" else "" for d, r in
                             zip(table["dataset"], table["recording"], strict=True)]
    table.to_csv(results / "accuracy.csv", index=False)
    try:
        table.to_parquet(results / "accuracy.parquet", index=False)
    except ImportError:  # pyarrow is optional
        pass
    return table


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    ap.add_argument("--quick", action="store_true", help="3 PyShoe trials, x-io and a short simulated walk")
    ap.add_argument("--results", type=Path, default=DEFAULT_RESULTS, help="folder for the tables and the cache")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="folder of the reference recordings")
    ap.add_argument("--configs", default="", help="comma-separated config names (default: every shipped one)")
    ap.add_argument("--summary", type=Path, default=None,
                    help="Markdown summary (default benchmarks/accuracy.md; with --quick RESULTS/accuracy_quick.md)")
    ap.add_argument("--recommended", default="recommended", help="config the targets are checked for")
    ap.add_argument("--progress", action="store_true", help="progress bars")
    ap.add_argument("--plots", action="store_true", help="also the ablation runner's report per dataset (slow)")
    ap.add_argument("--parts", default=None,
                    help="comma-separated parts (default all; with --quick: configs): configs,"
                         + ",".join(accuracy_parts.PARTS))
    args = ap.parse_args(argv)
    parts = [p for p in (args.parts or ("configs" if args.quick else
                                        ",".join(["configs", *accuracy_parts.PARTS]))).split(",") if p]
    unknown = sorted(set(parts) - {"configs", *accuracy_parts.PARTS})
    if unknown:
        raise SystemExit(f"unknown part(s) {unknown}; known: configs, {', '.join(accuracy_parts.PARTS)}")
    # readers warn about what they repair (x-io's duplicate rows): expected here, and workers inherit this
    os.environ.setdefault("PYTHONWARNINGS", "ignore::UserWarning")
    warnings.simplefilter("ignore", UserWarning)
    configs = shipped_configs([c for c in args.configs.split(",") if c] or None)
    t0 = time.time()
    ref = pyshoe_reference(args.data / "pyshoe_vicon") if (args.data / "pyshoe_vicon").is_dir() else \
        pd.DataFrame(columns=["best_error_m", "best_detector", "n_strides_manual_koroglu"])
    summary = args.summary or (args.results / "accuracy_quick.md" if args.quick else DEFAULT_SUMMARY)
    flagship = [p for p in parts if p != "configs"]
    blocks = accuracy_parts.run_parts(flagship, args.data, ref["best_error_m"], MOTION_CLASSES, CLASS_ORDER,
                                      args.jobs) if flagship else {}
    kept = summary.read_text().partition(FLAGSHIP_MARK)[2] if summary.exists() else ""  # the parts not rerun
    if "configs" in parts:
        table = run(args.data, args.results, configs, args.jobs, args.quick, args.progress, plots=args.plots)
        write_summary(table, ref, summary, args.recommended, time.time() - t0, args.quick)
        print(f"tables in {args.results}, summary {summary}")
    if blocks or kept:
        head = summary.read_text().partition(FLAGSHIP_MARK)[0] if summary.exists() else ""
        merged = {**accuracy_parts.read_parts(kept), **blocks}  # the parts not rerun keep their blocks
        section = "\n".join(accuracy_parts.flagship_section(merged))
        summary.parent.mkdir(parents=True, exist_ok=True)
        summary.write_text(f"{head.rstrip()}\n\n{FLAGSHIP_MARK}\n\n{section.rstrip()}\n")
        print(f"flagship parts {flagship} in {summary}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
