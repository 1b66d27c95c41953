"""Should ``recommended`` hold level stances? ``height_level`` under nested cross-validation, and the rule.

Usage: python benchmarks/select_height.py [--jobs 2] [--data ../shared/data] [--results DIR]
                                          [--out benchmarks/height_level.md]

Candidates: ``configs/recommended.yaml`` as shipped (the baseline) and the same with the level-stance height
update (``height_level``, σ 0.01 m) after its ``zupt``, threshold ∈ :data:`THRESHOLDS` (m; 0.1 is the lowest
stair riser building codes allow, the plug-in's default).

The nested cross-validation is ``select_recommended.py --nested``'s: PyShoe's 36 VICON trials in the same 6
outer folds (stratified by motion class, seed 0, :func:`nested_cv.stratified_folds`), the inner choice on
the other folds' trials only. A height update can only change the height, so the inner choice scores the 3-D
error (ARMSE after a yaw alignment): per motion class the geometric mean, classes weighted equally
(:func:`select_recommended.score`), a failed run counting as 1000 m.

Two procedures are cross-validated: the plug-in's default threshold, fixed before any fold was run (0.1 m,
from building codes: a fixed setting's held-out errors are its plain errors), and the threshold chosen by
the inner folds among :data:`THRESHOLDS` (how sensitive the choice is).

The rule for a height update: a procedure ships only if its held-out 3-D median *and* worst improve on the
baseline's, its held-out 2-D median and worst (PyShoe's metric) are no worse, and its setting on all 36 trials
is no worse than the baseline on every other visible reference (``select_nested.CHECKS``: x-io's loop,
gaitmap's stride lengths and events, Köroğlu's footprints and stride counts) nor on x-io's 3-D closure and
the simulated stairs' climb (100, 250, 400 Hz). "No worse" allows :data:`RESOLUTION` of the baseline's value
(a height row moves the horizontal estimate only through the filter's correlations: micrometres on a 5 cm
stride RMS), counts exactly. The simulated 437.5 m track at the same rates shows what it does to a long flat
walk.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from accuracy import DEFAULT_DATA, motion_class, run_cached  # noqa: E402
from height_drift import sim_case  # noqa: E402
from nested_cv import held_out_of, improves, nested_choice, stratified_folds  # noqa: E402
from select_nested import CHECKS, FOLDS, SEED, XIO_3D, other_references  # noqa: E402
from select_recommended import score  # noqa: E402

from footzoo.studies import Study  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

THRESHOLDS = (0.05, 0.08, 0.1, 0.12, 0.15)
#: The plug-in's default threshold (m): the fixed procedure's setting.
DEFAULT = 0.1
#: "No worse" on another reference: within this fraction of the baseline's value (counts: exactly).
RESOLUTION = 1e-3
BASELINE = "recommended"
SIM_RATES = (100.0, 250.0, 400.0)
DEFAULT_OUT = ROOT / "benchmarks" / "height_level.md"


def name_of(threshold: float) -> str:
    """A candidate's name."""
    return f"height_level {threshold:g}"


def candidates() -> list[dict[str, Any]]:
    """The baseline (``recommended`` as shipped) and one candidate per threshold."""
    base = yaml.safe_load((ROOT / "configs" / "recommended.yaml").read_text())
    base["corrections"] = [c for c in base["corrections"] if c["type"] != "height_level"]
    base["name"] = BASELINE
    out = [base]
    for th in THRESHOLDS:
        cfg = copy.deepcopy(base)
        cfg["corrections"].append({"type": "height_level", "threshold": th, "height_std": 0.01})
        cfg["name"] = name_of(th)
        out.append(cfg)
    return out


def log_score(values: pd.Series, classes: pd.Series) -> float:
    """The inner choice's score of a candidate's 3-D errors: per class the mean log error, classes weighted equally."""
    return score(np.log(values.fillna(1e3)), classes)


def choose(errors: pd.DataFrame, classes: pd.Series) -> str:
    """The inner choice: the candidate with the lowest :func:`log_score` (first in order on a tie)."""
    scores = {c: log_score(errors[c], classes) for c in errors.columns}
    return min(scores, key=scores.get)


def pyshoe(cands: list[dict[str, Any]], data: Path, results: Path, jobs: int) -> tuple[pd.DataFrame, pd.DataFrame]:
    """2-D and 3-D errors (m): one row per PyShoe trial, one column per candidate."""
    names = [c["name"] for c in cands]
    study = Study.from_dict({"name": "select_height", "base": cands, "metrics": ["pyshoe_error_m", "armse_3d_m"],
                             "recordings": [{"path": str(data / "pyshoe_vicon" / "*.mat"), "format": "pyshoe"}],
                             "max_cells": len(cands) * 40})
    t = run_cached(study, results / "pyshoe", jobs)
    return tuple(t[t["metric"] == m].pivot_table(index="recording", columns="base", values="value",
                                                 aggfunc="first").reindex(columns=names)
                 for m in ("pyshoe_error_m", "armse_3d_m"))


def simulated(cands: list[dict[str, Any]], data: Path, jobs: int) -> pd.DataFrame:
    """The simulated track (one 437.5 m lap) and stairs at each rate of :data:`SIM_RATES`, per candidate."""
    from joblib import Parallel, delayed

    cells = [(kind, rate, c) for kind in ("track", "stairs") for rate in SIM_RATES for c in cands]
    rows = Parallel(n_jobs=jobs)(delayed(sim_case)(kind, rate, c["name"], data, c) for kind, rate, c in cells)
    return pd.DataFrame(rows)


def no_worse(value: float, baseline: float, direction: str, count: bool = False) -> bool:
    """``value`` on the right side of the baseline's, or within :data:`RESOLUTION` of it (a count: exactly)."""
    slack = 0.0 if count else RESOLUTION * abs(baseline)
    return bool(value <= baseline + slack if direction == "min" else value >= baseline - slack)


def run(args: argparse.Namespace) -> list[str]:
    """Run everything; the report's lines."""
    warnings.simplefilter("ignore", UserWarning)
    cands = candidates()
    names = [c["name"] for c in cands]
    err2, err3 = pyshoe(cands, args.data, args.results, args.jobs)
    err3 = err3.reindex(err2.index)
    classes = pd.Series([motion_class(x) for x in err2.index], index=err2.index)
    folds = stratified_folds(classes, FOLDS, SEED)
    procedures = {f"default {DEFAULT:g} (fixed)": lambda e, c: name_of(DEFAULT), "threshold chosen": choose}
    runs = {}
    for who, pick in procedures.items():
        chosen, held3 = nested_choice(err3, classes, folds, pick)
        runs[who] = (chosen, held_out_of(chosen, folds, err2), held3, pick(err3, classes))
    other = other_references(cands, args.data, args.results, args.jobs)
    sim = simulated(cands, args.data, args.jobs)
    return report(err2, err3, classes, folds, runs, other, sim, names)


def _fold_rows(err2: pd.DataFrame, err3: pd.DataFrame, folds: pd.Series,
               runs: dict[str, tuple[pd.Series, pd.Series, pd.Series, str]]) -> pd.DataFrame:
    """Per outer fold and pooled: each procedure's choice and held-out medians and worsts, and the baseline's."""
    def stats(who: str, e2: pd.Series, e3: pd.Series) -> dict[str, float]:
        return {f"{who} 2-D median": e2.median(), f"{who} 2-D worst": e2.max(),
                f"{who} 3-D median": e3.median(), f"{who} 3-D worst": e3.max()}

    rows = []
    fold_of = folds.reindex(err2.index)
    for f in sorted(pd.unique(fold_of.to_numpy())):
        m = (fold_of == f).to_numpy()
        row: dict[str, Any] = {"fold": f}
        for who, (chosen, h2, h3, _) in runs.items():
            row[f"{who}: chosen"] = chosen[f]
            row.update(stats(who, h2[m], h3[m]))
        rows.append({**row, **stats("baseline", err2.loc[m, BASELINE], err3.loc[m, BASELINE])})
    pooled: dict[str, Any] = {"fold": "pooled"}
    for who, (_, h2, h3, _) in runs.items():
        pooled[f"{who}: chosen"] = ""
        pooled.update(stats(who, h2, h3))
    rows.append({**pooled, **stats("baseline", err2[BASELINE], err3[BASELINE])})
    return pd.DataFrame(rows)


def references(other: pd.DataFrame, sim: pd.DataFrame, name: str) -> pd.DataFrame:
    """Every other reference: ``name``'s value, the baseline's and whether it is no worse (:func:`no_worse`)."""
    checks = {**CHECKS, XIO_3D: "min"}
    rows = []
    for col, direction in checks.items():
        if col not in other.columns:
            continue
        v, b = float(other.at[name, col]), float(other.at[BASELINE, col])
        ok = no_worse(v, b, direction, count=col.endswith(("paired", "(sum of abs)")))
        rows.append({"reference": col, name: v, f"{BASELINE} (baseline)": b, "no worse": "yes" if ok else "**no**"})
    stairs = sim[sim["walk"] == "stairs"].set_index(["setting", "rate (Hz)"])["climb error (% climb)"]
    for rate in SIM_RATES:
        v, b = abs(stairs[(name, rate)]), abs(stairs[(BASELINE, rate)])
        rows.append({"reference": f"simulated stairs at {rate:g} Hz: |climb error| (% climb)", name: v,
                     f"{BASELINE} (baseline)": b, "no worse": "yes" if no_worse(v, b, "min") else "**no**"})
    return pd.DataFrame(rows)


def report(err2: pd.DataFrame, err3: pd.DataFrame, classes: pd.Series, folds: pd.Series,
           runs: dict[str, tuple[pd.Series, pd.Series, pd.Series, str]], other: pd.DataFrame, sim: pd.DataFrame,
           names: list[str]) -> list[str]:
    """The report's lines (markdown)."""
    base2, base3 = err2[BASELINE].fillna(np.inf), err3[BASELINE].fillna(np.inf)
    lines = [
        "# `height_level` in `recommended`: nested cross-validation and the rule",
        "",
        f"Written by `python benchmarks/select_height.py` (its docstring gives the candidates, the two procedures "
        f"and the rule). Baseline: `configs/recommended.yaml` without `height_level`; candidates: the same with "
        f"`height_level` (σ 0.01 m) at each threshold (m). {FOLDS} outer folds, stratified by motion class, seed "
        f"{SEED} (the folds of `benchmarks/recommended_selection.md`).",
        "",
        "## Held-out errors per outer fold (m)",
        "",
        to_markdown(_fold_rows(err2, err3, folds, runs)),
        "",
        "## Decision",
        "",
    ]
    decision = None
    for who, (_, h2, h3, final) in runs.items():
        h2, h3 = h2.fillna(np.inf), h3.fillna(np.inf)
        better3 = improves(h3, base3)
        same2 = h2.median() <= base2.median() and h2.max() <= base2.max()
        refs = references(other, sim, final)
        elsewhere = bool((refs["no worse"] == "yes").all())
        passes = final != BASELINE and better3 and same2 and elsewhere
        if passes and decision is None:
            decision = final
        lines += [
            f"### {who}",
            "",
            f"* held-out 3-D vs baseline: median {h3.median():.4f} vs {base3.median():.4f} m, worst "
            f"{h3.max():.4f} vs {base3.max():.4f} m: {'improves' if better3 else 'does **not** improve'}",
            f"* held-out 2-D vs baseline: median {h2.median():.4f} vs {base2.median():.4f} m, worst "
            f"{h2.max():.4f} vs {base2.max():.4f} m: {'no worse' if same2 else '**worse**'}",
            f"* its setting on all 36 trials: `{final}`",
            "",
            to_markdown(refs),
            "",
            f"Passes the rule: **{'yes' if passes else 'no'}**.",
            "",
        ]
    lines += [f"**Decision: {'`' + decision + '` ships' if decision else 'no change'}.**", ""]
    chosen_counts = runs["threshold chosen"][0].value_counts().reindex(names).fillna(0).astype(int)
    insample = pd.DataFrame({"2-D median": err2.median(), "2-D worst": err2.max(), "3-D median": err3.median(),
                             "3-D worst": err3.max(),
                             "inner score (mean log 3-D)": {n: log_score(err3[n], classes) for n in names},
                             "chosen by outer folds (threshold chosen)": chosen_counts})
    per_class = pd.DataFrame({n: err3[n].groupby(classes).median() for n in names}).T
    track = sim[sim["walk"] == "track"].pivot_table(index="setting", columns="rate (Hz)",
                                                    values="end height (% dist)", aggfunc="first").reindex(names)
    stairs = sim[sim["walk"] == "stairs"].pivot_table(index="setting", columns="rate (Hz)",
                                                      values="climb error (% climb)", aggfunc="first").reindex(names)
    lines += [
        "## Every candidate on all 36 trials (in-sample)",
        "",
        to_markdown(insample.rename_axis("candidate").reset_index()),
        "",
        "### 3-D median per motion class (m)",
        "",
        to_markdown(per_class.rename_axis("candidate").reset_index()),
        "",
        "## The other references, every candidate",
        "",
        to_markdown(other.rename_axis("candidate").reset_index()),
        "",
        "## Simulated walks (the simulator's noise, seed 0)",
        "",
        "End height of one 437.5 m lap of the track (% of the distance, signed), per rate (Hz):",
        "",
        to_markdown(track.rename_axis("candidate").reset_index(), 3),
        "",
        "The stairs' climb error at the top (% of the 2.2 m climb, signed), per rate (Hz):",
        "",
        to_markdown(stairs.rename_axis("candidate").reset_index(), 3),
        "",
        "### Every trial: 3-D error (m)",
        "",
        to_markdown(err3.assign(**{"class": classes}).rename_axis("trial").reset_index(), 3),
    ]
    return lines


def report_main(argv: list[str] | None, doc: str, make: Any, name: str, out: Path, shown: int = 40) -> int:
    """A PyShoe report's command line: ``--data``, ``--results`` (``benchmarks/results/<name>``), ``--out``, ``--jobs``;
    ``make(args)`` gives its Markdown lines, written to ``--out`` with the run time as the third line."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--results", type=Path, default=ROOT / "benchmarks" / "results" / name)
    ap.add_argument("--out", type=Path, default=out)
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    if not (args.data / "pyshoe_vicon").is_dir():
        print(f"no PyShoe trials in {args.data}: nothing to measure on", file=sys.stderr)
        return 1
    t0 = time.perf_counter()
    lines = make(args)
    lines.insert(2, f"Run time: {(time.perf_counter() - t0) / 60:.1f} min.")
    lines.insert(3, "")
    args.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines[:shown]))
    return 0


def main(argv: list[str] | None = None) -> int:
    return report_main(argv, __doc__, run, "select_height", DEFAULT_OUT)


if __name__ == "__main__":
    raise SystemExit(main())
