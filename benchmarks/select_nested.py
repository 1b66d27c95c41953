"""``select_recommended.py --nested``: the selection of ``recommended`` under nested cross-validation, and the rule.

Usage: python benchmarks/select_recommended.py --nested [--jobs 2] [--write]

The rule for changing a shipped default: a change ships only if, under nested cross-validation on
PyShoe's 36 VICON trials, the selection procedure's held-out errors improve on the fixed baseline
(the shipped setting) *and* on the setting the last refinements started from (:data:`START`), in
pooled median *and* worst (PyShoe's 2-D metric), and only if the setting the procedure then picks on
all 36 trials is no worse than the baseline on every other visible reference (:data:`CHECKS`: x-io's
closed loop, gaitmap's stride lengths, both feet, and gait events against motion capture, Köroğlu's
footprints and stride counts). If the procedure does not pass, the rule goes back to what it supports:
:data:`START` replaces the baseline if it alone improves the pooled median and worst and is no worse
elsewhere; otherwise the baseline stays.

Candidates (a small grid, every other part of the pipeline as shipped: INS attitude, the 9-state
error-state Kalman filter's noises, RTS smoothing, no swing guard, the speed-adaptive detector's
``provisional_min_swing`` 0, the zero-velocity update's σ 0.03 m/s and its stillness hold, and the shipped
level-stance height update :data:`HEIGHT` after the stance updates, chosen by ``benchmarks/select_height.py``):

* the speed-adaptive SHOE detector's ``threshold`` ∈ {2000, 3000} × ``speed_scale`` ∈ {0.8, 1.0} × the
  zero-velocity update's ``roll_lever`` ∈ {0, 0.1, 0.2} m: 12 settings, among them the shipped one
  (:data:`BASELINE`: 2000, 0.8, 0.2) and the refinements' start (:data:`START`: 3000, 1.0, 0);
* the rolling-foot stance update (``rolling_stance``, benchmarks/rolling_stance.md) with the shipped
  detector: alone in place of ``zupt`` with its defaults, with a wider contact spread (ℓ_s 0.05 m) and with a
  tighter lever prior (σ 0.02 m); after the shipped ``zupt`` (its own hold off) with its defaults and with
  ℓ_s 0.05 m: 5 settings (:data:`ROLLING`);
* the shipped pipeline (its ``zupt`` with ``roll_lever`` 0.2 m included) with Huang et al.'s stance detector
  (``huang_stance``: SHOE and a state machine that switches only after ``min_duration``) in place of the
  speed-adaptive one: ``threshold`` ∈ {1.5e4, 3e4, 6e4} × ``min_duration`` ∈ {0.05, 0.1} s, its defaults
  (3e4, 0.05 s) among them: 6 settings (:data:`HUANG`). On gaitmap's walk this swap brought the stride-length
  RMS from 0.053/0.050 to 0.044/0.046 m (benchmarks/gaitmap_strides.md, table 6): one recording, tested here.

Outer folds: 6, stratified by motion class (:func:`nested_cv.stratified_folds`, seed :data:`SEED`): every
fold holds 6 trials, 3 or 4 walking and 1 or 2 running/fast, and the slow unusual and inverted trials sit
in three different folds (the folds are listed in the report). Stratified k-fold, not leave-one-class-out:
the question is how the procedure does on new trials of the kinds it was chosen on (more recordings of the
same lab, other labs' walks), and leaving a whole class out would hold out 23 walking trials in one fold and
a single trial in another, and score both slow trials by a choice that saw no slow motion (the one inverted
trial is scored without an inverted trial either way). The inner choice is the existing
selection on the training trials only: among the settings that pass the rate check (simulated
mixed-speed walk at 100 and 200 Hz, :func:`select_recommended.rate_check`), the best score (per motion
class the geometric mean of error / PyShoe's per-trial best, classes weighted equally,
:func:`select_recommended.class_score`). A failed run counts as infinitely wrong in the held-out figures.
The report also cross-validates the same procedure among the 12 zero-velocity candidates alone (``zupt
grid``: the refinement's own choice, held out).
"""

from __future__ import annotations

import argparse
import copy
import hashlib
import json
import re
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from accuracy import (  # noqa: E402
    CLASS_ORDER,
    motion_class,
    pyshoe_reference,
    recordings,
    run_cached,
    run_dataset,
    run_stride_references,
)
from nested_cv import held_out_of, improves, nested_choice, stratified_folds  # noqa: E402
from select_recommended import (  # noqa: E402
    NESTED_MARK,
    RATE_CHECK_M,
    REFINE_FIXED,
    build,
    class_score,
    rate_check,
    shipped_height,
)

from footzoo.studies import Study  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402
from footzoo.studies.study import code_fingerprint  # noqa: E402

#: Outer folds and the seed of their shuffle.
FOLDS = 6
SEED = 0
THRESHOLDS = [2000.0, 3000.0]
SPEED_SCALES = [0.8, 1.0]
ROLL_LEVERS = [0.0, 0.1, 0.2]
#: The shipped zero-velocity update (the rolling candidates that keep it).
ZUPT = {"type": "zupt", "velocity_std": 0.03, "roll_lever": 0.2}
#: The rolling-foot stance candidates: name -> the ``corrections`` that replace the shipped ``zupt``.
ROLLING: dict[str, list[dict[str, Any]]] = {
    "rolling_stance": [{"type": "rolling_stance"}],
    "rolling_stance spread 0.05": [{"type": "rolling_stance", "contact_spread": 0.05}],
    "rolling_stance lever_std 0.02": [{"type": "rolling_stance", "lever_std": 0.02}],
    "zupt + rolling_stance": [ZUPT, {"type": "rolling_stance", "hold_after": 0.0}],
    "zupt + rolling_stance spread 0.05": [ZUPT, {"type": "rolling_stance", "contact_spread": 0.05,
                                                 "hold_after": 0.0}],
}
#: The Huang stance candidates: name -> the ``detector`` that replaces the shipped speed-adaptive one.
HUANG: dict[str, dict[str, Any]] = {
    f"huang_stance th {th:g} min {md:g}": {"type": "huang_stance", "threshold": th, "min_duration": md}
    for th in (1.5e4, 3e4, 6e4) for md in (0.05, 0.1)
}
#: The shipped height correction(s) every candidate keeps after its stance updates (benchmarks/height_level.md).
HEIGHT: list[dict[str, Any]] = shipped_height()
#: The fixed baseline (the shipped setting) and the setting the refinements started from.
BASELINE = "th 2000 vs 0.8 roll 0.2"
START = "th 3000 vs 1 roll 0"

#: The other visible references: column -> ``min`` (lower is better) or ``max``; a candidate is no worse than the
#: baseline when it is on the right side of (or equal to) the baseline's value on every one.
CHECKS = {
    "x-io loop closure (m)": "min",
    "gaitmap left stride RMS (m)": "min",
    "gaitmap right stride RMS (m)": "min",
    "gaitmap IC median abs (ms)": "min",
    "gaitmap TO median abs (ms)": "min",
    "gaitmap strides paired": "max",
    "Köroğlu footprint RMS, mean of 31-33 (m)": "min",
    "Köroğlu stride count errors (sum of abs)": "min",
}


#: x-io's 3-D end-to-start distance (m): reported with the other references, not one of :data:`CHECKS` here (a height
#: update's selection, ``benchmarks/select_height.py``, checks it).
XIO_3D = "x-io 3-D closure (m)"
#: What a cached row of :func:`other_references` holds (part of its cache key: a row of fewer columns is not reused).
OTHER_COLUMNS = "checks + x-io 3-D"


def name_of(th: float, vs: float, roll: float) -> str:
    """A zero-velocity candidate's name."""
    return f"th {th:g} vs {vs:g} roll {roll:g}"


def candidates() -> list[dict[str, Any]]:
    """The nested selection's candidates as full configs (see the module's docstring)."""
    f = REFINE_FIXED
    out = []
    for th in THRESHOLDS:
        for vs in SPEED_SCALES:
            for roll in ROLL_LEVERS:
                det = {"type": "speed_adaptive_shoe", "threshold": th, "speed_scale": vs, "provisional_min_swing": 0.0}
                cfg = build(det, f["noise"], f["impact"], f["smoother"], f["guard"], roll)
                cfg["name"] = name_of(th, vs, roll)
                out.append(cfg)
    shipped = next(c for c in out if c["name"] == BASELINE)
    for name, corrections in ROLLING.items():
        cfg = copy.deepcopy(shipped)
        cfg["corrections"] = copy.deepcopy(corrections)
        cfg["name"] = name
        out.append(cfg)
    for name, detector in HUANG.items():
        cfg = copy.deepcopy(shipped)
        cfg["detector"] = copy.deepcopy(detector)
        cfg["name"] = name
        out.append(cfg)
    for cfg in out:
        cfg["corrections"] += copy.deepcopy(HEIGHT)
    return out


def slug(name: str) -> str:
    """A file-name-safe form of a candidate's name."""
    return re.sub(r"[^A-Za-z0-9.]+", "_", name).strip("_")


# ------------------------------------------------------------------------------- other references


def other_references(cands: list[dict[str, Any]], data: Path, folder: Path, jobs: int) -> pd.DataFrame:
    """Per candidate (rows): x-io's loop, gaitmap's stride lengths and events, Köroğlu's footprints and counts.

    Computed with benchmarks/accuracy.py's and accuracy_events.py's functions on each candidate written as a YAML
    file; cached per candidate in ``folder/other_cache`` under a key of its config and footzoo's source.
    """
    cfg_dir, cache = folder / "configs", folder / "other_cache"
    cfg_dir.mkdir(parents=True, exist_ok=True)
    cache.mkdir(parents=True, exist_ok=True)
    code = code_fingerprint()
    rows: dict[str, dict[str, Any]] = {}
    todo: dict[str, tuple[Path, Path]] = {}
    for c in cands:
        path = cfg_dir / f"{slug(c['name'])}.yaml"
        path.write_text(yaml.safe_dump(json.loads(json.dumps(c)), sort_keys=False))
        key = hashlib.sha256((json.dumps(c, sort_keys=True) + code + OTHER_COLUMNS).encode()).hexdigest()[:24]
        entry = cache / f"{key}.json"
        if entry.exists():
            rows[c["name"]] = json.loads(entry.read_text())
        else:
            todo[c["name"]] = (path, entry)
    if todo:
        computed = _other_rows({n: p for n, (p, _) in todo.items()}, data, folder, jobs)
        for name, (_, entry) in todo.items():
            rows[name] = computed[name]
            entry.write_text(json.dumps(computed[name]))
    return pd.DataFrame.from_dict(rows, orient="index").reindex([c["name"] for c in cands])


def _other_rows(paths: dict[str, Path], data: Path, folder: Path, jobs: int) -> dict[str, dict[str, Any]]:
    """:func:`other_references` for the candidates not cached: name -> {reference column: value}."""
    from accuracy_events import event_cell
    from accuracy_events import recordings as event_recordings
    from joblib import Parallel, delayed

    recs = recordings(data, quick=False, sim={})
    by_stem = {p.stem: n for n, p in paths.items()}
    configs = list(paths.values())
    out: dict[str, dict[str, Any]] = {n: {} for n in paths}
    if "xio" in recs:
        t = run_dataset("xio", recs["xio"], configs, folder / "xio", jobs, False)
        for metric, column in (("loop_closure_xy_m", "x-io loop closure (m)"), ("loop_closure_3d_m", XIO_3D)):
            for _, r in t[t["metric"] == metric].iterrows():
                out[by_stem[r["config"]]][column] = float(r["value"])
    strides = run_stride_references({k: v for k, v in recs.items() if k.startswith(("gaitmap", "koroglu"))},
                                    configs, jobs)
    for n in paths:
        s = strides[strides["config"] == slug(n)]
        for foot in ("left", "right"):
            v = s.loc[(s["dataset"] == f"gaitmap_{foot}") & (s["metric"] == "stride_length_rms_m"), "value"]
            out[n][f"gaitmap {foot} stride RMS (m)"] = float(v.iloc[0]) if len(v) else np.inf
        k = s[s["dataset"] == "koroglu"]
        fp = k[k["metric"] == "footprint_error_rms_m"].set_index("recording")["value"]
        ce = k[k["metric"] == "stride_count_error"].set_index("recording")["value"]
        for rec in sorted(ce.index):
            out[n][f"Köroğlu {rec[-2:]} footprint RMS (m)"] = float(fp.get(rec, np.inf))
            out[n][f"Köroğlu {rec[-2:]} stride count error"] = float(ce[rec])
        out[n]["Köroğlu footprint RMS, mean of 31-33 (m)"] = float(np.mean([fp.get(r, np.inf) for r in ce.index])) \
            if len(ce) else np.inf
        out[n]["Köroğlu stride count errors (sum of abs)"] = float(ce.abs().sum()) if len(ce) else np.inf
    mocap = [r for r in event_recordings(data) if r[0].startswith("motion")]
    cells = Parallel(n_jobs=jobs)(delayed(event_cell)(ref, grp, spec, str(p)) for ref, grp, spec in mocap
                                  for p in configs)
    for n, p in paths.items():
        mine = [c for c in cells if c["config"] == str(p)]
        if not mine:
            continue
        ic, to = np.concatenate([c["ic"] for c in mine]), np.concatenate([c["to"] for c in mine])
        out[n]["gaitmap IC median abs (ms)"] = 1e3 * float(np.median(np.abs(ic))) if len(ic) else np.inf
        out[n]["gaitmap TO median abs (ms)"] = 1e3 * float(np.median(np.abs(to))) if len(to) else np.inf
        out[n]["gaitmap strides paired"] = int(sum(c["paired"] for c in mine))
        out[n]["gaitmap strides (reference)"] = int(sum(c["strides"] for c in mine))
    return out


def no_worse(other: pd.DataFrame, name: str, baseline: str) -> pd.DataFrame:
    """Every check of :data:`CHECKS`: the candidate's value, the baseline's, and whether it is no worse."""
    rows = []
    for col, direction in CHECKS.items():
        v, b = float(other.at[name, col]), float(other.at[baseline, col])
        ok = v <= b if direction == "min" else v >= b
        rows.append({"reference": col, name: v, f"{baseline} (baseline)": b, "no worse": "yes" if ok else "**no**"})
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------------------- the run


def nested(args: argparse.Namespace) -> int:
    """Run the candidates, the nested cross-validation and the rule; write the report (and, with --write, configs)."""
    warnings.simplefilter("ignore", UserWarning)
    folder = args.data / "pyshoe_vicon"
    out = args.results / "select_recommended_nested"
    cands = candidates()
    names = [c["name"] for c in cands]
    worst_sim = rate_check(cands, out / "rates", args.jobs)
    qualified = [n for n in names if worst_sim[n] <= RATE_CHECK_M]
    study = Study.from_dict({"name": "select_recommended_nested", "base": cands,
                             "metrics": ["pyshoe_error_m", "armse_3d_m"],
                             "recordings": [{"path": str(folder / "*.mat"), "format": "pyshoe"}],
                             "max_cells": len(cands) * 40})
    t = run_cached(study, out / "pyshoe", args.jobs)
    err2, err3 = (t[t["metric"] == m].pivot_table(index="recording", columns="base", values="value",
                                                 aggfunc="first").reindex(columns=names)
                  for m in ("pyshoe_error_m", "armse_3d_m"))
    err3 = err3.reindex(err2.index)
    best = pyshoe_reference(folder)["best_error_m"].reindex(err2.index)
    classes = pd.Series([motion_class(x) for x in err2.index], index=err2.index)
    folds = stratified_folds(classes, FOLDS, SEED)
    scored = class_score(best)
    zupt_grid = [n for n in names if n not in ROLLING and n not in HUANG]
    procedures = {"procedure": chooser(scored, qualified), "zupt grid": chooser(scored, [n for n in qualified
                                                                                         if n in zupt_grid])}
    runs = {}
    for who, choose in procedures.items():
        chosen, held2 = nested_choice(err2, classes, folds, choose)
        runs[who] = (chosen, held2, held_out_of(chosen, folds, err3), choose(err2, classes))
    other = other_references(cands, args.data, out, args.jobs)
    lines, decision = report(err2, err3, classes, folds, runs, worst_sim, qualified, other, scored)
    path = ROOT / "benchmarks" / "recommended_selection.md"
    head = path.read_text().split(NESTED_MARK)[0].rstrip("\n") if path.exists() else ""
    path.write_text(f"{head}\n\n{NESTED_MARK}\n\n" + "\n".join(lines) + "\n")
    print("\n".join(lines))
    if args.write and decision != BASELINE:
        cfg = next(c for c in cands if c["name"] == decision)
        write_configs(cfg, _stats(err2[decision], err3[decision]), _stats(*runs["procedure"][1:3]),
                      ROOT / "configs")
        print(f"configs/recommended.yaml and recommended_live.yaml: {decision}")
    return 0


def chooser(scored: Any, pool: list[str]) -> Any:
    """The inner choice: among ``pool``, the candidate with the best :func:`select_recommended.class_score`."""
    def choose(e: pd.DataFrame, strata: pd.Series) -> str:
        scores = {s: scored(e[s], strata) for s in pool}
        return min(scores, key=scores.get)

    return choose


def _stats(e2: pd.Series, e3: pd.Series) -> dict[str, float]:
    """2-D median and worst, 3-D median (m); a failed run counts as infinitely wrong."""
    e2, e3 = e2.fillna(np.inf), e3.fillna(np.inf)
    return {"2-D median": float(e2.median()), "2-D worst": float(e2.max()), "3-D median": float(e3.median())}


def decide(held2: pd.Series, err2: pd.DataFrame, final: str, other: pd.DataFrame) -> tuple[str, str]:
    """The rule (module docstring): the setting that ships and why."""
    held, base, start = held2, err2[BASELINE], err2[START]
    if improves(held, base) and improves(held, start) and final != BASELINE \
            and (no_worse(other, final, BASELINE)["no worse"] == "yes").all():
        return final, (f"the procedure improves on both fixed settings and its choice on all 36 trials, `{final}`, "
                       "is no worse on the other references: it ships")
    if improves(start, base) and (no_worse(other, START, BASELINE)["no worse"] == "yes").all():
        return START, (f"the procedure does not pass; `{START}` improves on the baseline's pooled median and worst "
                       "and is no worse elsewhere: the refinement is reverted")
    return BASELINE, f"neither the procedure nor `{START}` passes the rule: the baseline `{BASELINE}` stays"


def report(err2: pd.DataFrame, err3: pd.DataFrame, classes: pd.Series, folds: pd.Series,
           runs: dict[str, tuple[pd.Series, pd.Series, pd.Series, str]], worst_sim: pd.Series, qualified: list[str],
           other: pd.DataFrame, scored: Any) -> tuple[list[str], str]:
    """The report's lines and the decision (the name of the setting the rule ships)."""
    chosen, held2, held3, final = runs["procedure"]
    zchosen, zheld2, zheld3, zfinal = runs["zupt grid"]
    series = {"procedure": (held2, held3), "zupt grid": (zheld2, zheld3),
              "baseline": (err2[BASELINE], err3[BASELINE]), "start": (err2[START], err3[START])}
    rows = []
    for f in sorted(chosen.index):
        m = folds == f
        row: dict[str, Any] = {"fold": str(f), "chosen (all candidates)": chosen[f], "chosen (zupt grid)": zchosen[f]}
        for who, (e2, e3) in series.items():
            row.update({f"{who}: {k}": v for k, v in _stats(e2[m], e3[m]).items()})
        rows.append(row)
    pooled: dict[str, Any] = {"fold": "pooled", "chosen (all candidates)": "", "chosen (zupt grid)": ""}
    for who, (e2, e3) in series.items():
        pooled.update({f"{who}: {k}": v for k, v in _stats(e2, e3).items()})
    per_fold = pd.DataFrame([*rows, pooled])
    membership = pd.DataFrame([{
        "fold": str(f),
        "classes": ", ".join(f"{int((classes[folds == f] == c).sum())} {c}" for c in CLASS_ORDER
                             if (classes[folds == f] == c).any()),
        "trials": ", ".join(t[5:] for t in folds.index[folds == f])} for f in sorted(chosen.index)])
    times = chosen.value_counts()
    ranking = pd.DataFrame([{"candidate": n, "passes rate check": n in qualified,
                             "sim 100/200 Hz worst ARMSE (m)": worst_sim[n],
                             "score on all 36": scored(err2[n], classes),
                             **_stats(err2[n], err3[n]), "chosen by outer folds": int(times.get(n, 0))}
                            for n in err2.columns])
    decision, why = decide(held2, err2, final, other)

    def verdict(a: pd.Series, b: pd.Series) -> str:
        a, b = a.fillna(np.inf), b.fillna(np.inf)
        return (f"median {a.median():.4f} vs {b.median():.4f} m, worst {a.max():.3f} vs {b.max():.3f} m: "
                + ("improves" if improves(a, b) else "does **not** improve"))

    lines = [
        "## Nested cross-validation (`--nested`): the rule for changing `recommended`", "",
        "A shipped default changes only if the selection procedure, under nested cross-validation, improves on the "
        "fixed baseline (the shipped setting) and on the setting the refinements started from in the outer folds' "
        "pooled held-out median **and** worst (PyShoe's 2-D metric), and its choice on all 36 trials is no worse "
        "than the baseline on x-io's loop, gaitmap's stride lengths (both feet) and events, Köroğlu's footprints "
        "and stride counts. Candidates, folds and the inner choice: `benchmarks/select_nested.py`'s docstring. "
        f"`baseline` = `{BASELINE}` (speed-adaptive SHOE threshold 2000, speed_scale 0.8, zupt roll_lever 0.2 m); "
        f"`start` = `{START}` (threshold 3000, speed_scale 1.0, no roll lever); `procedure` = on each outer fold's "
        "trials, the candidate the inner choice picked on the other folds; `zupt grid` = the same procedure "
        "among the 12 zero-velocity candidates only (the refinement's own choice, cross-validated). "
        f"{FOLDS} folds, stratified by motion class, seed {SEED}.", "",
        "The baseline and the start are fixed settings, but both were chosen on these 36 trials: their figures here "
        "are in-sample (optimistic), the procedure's are held out.", "",
        "### Outer folds", "", to_markdown(membership), "",
        "### Held-out errors per outer fold (m)", "", to_markdown(per_fold, 4), "",
        "### Decision", "",
        f"* procedure vs baseline, pooled over the outer folds: {verdict(held2, err2[BASELINE])}",
        f"* procedure vs start: {verdict(held2, err2[START])}",
        f"* the procedure's choice on all 36 trials: `{final}`" + (" (the baseline)" if final == BASELINE else ""),
        f"* zupt grid vs baseline: {verdict(zheld2, err2[BASELINE])}; vs start: {verdict(zheld2, err2[START])}; "
        f"its choice on all 36 trials: `{zfinal}`",
        f"* start vs baseline: {verdict(err2[START], err2[BASELINE])}", "",
    ]
    if final != BASELINE:
        lines += ["The procedure's choice on the other references:", "", to_markdown(no_worse(other, final, BASELINE),
                                                                                     4), ""]
    lines += [f"`{START}` on the other references:", "", to_markdown(no_worse(other, START, BASELINE), 4), "",
              f"**Decision: `{decision}`** ({why}).", "",
              "### Targets (visible PyShoe, outer folds pooled; gaitmap; x-io and Köroğlu against the baseline)", "",
              to_markdown(targets(decision, held2, held3, err2, err3, other), 4), "",
              "### Every candidate on all 36 trials (in-sample), and how often an outer fold chose it", "",
              to_markdown(ranking, 4), "",
              "### Per motion class: the baseline and the Huang stance candidates (in-sample, 2-D, m)", "",
              "Medians per class, the worst trial and how many trials exceed 0.2 m.", "",
              to_markdown(by_class(err2, classes, [BASELINE, *HUANG]), 4), "",
              "### Every candidate on the other references", "",
              to_markdown(other.reset_index().rename(columns={"index": "candidate"}), 4)]
    return lines, decision


def by_class(err2: pd.DataFrame, classes: pd.Series, names: list[str]) -> pd.DataFrame:
    """Per candidate in ``names``: its 2-D median per motion class, its worst trial, the trials over 0.2 m."""
    rows = []
    for n in names:
        e = err2[n].fillna(np.inf)
        medians = {c: float(e[classes == c].median()) for c in CLASS_ORDER if (classes == c).any()}
        rows.append({"candidate": n, **medians,
                     "worst trial": str(e.idxmax())[5:], "worst (m)": float(e.max()),
                     "trials over 0.2 m": int((e > 0.2).sum())})
    return pd.DataFrame(rows)


def targets(decision: str, held2: pd.Series, held3: pd.Series, err2: pd.DataFrame, err3: pd.DataFrame,
            other: pd.DataFrame) -> pd.DataFrame:
    """The issue's targets for the procedure's held-out figures and for the setting the rule ships."""
    rows = []

    def add(what: str, bound: str, value: float, met: bool) -> None:
        rows.append({"target": what, "bound": bound, "measured": value, "met": "yes" if met else "**no**"})

    for who, e2, e3 in (("procedure (outer folds)", held2, held3), (f"`{decision}`", err2[decision], err3[decision])):
        s = _stats(e2, e3)
        add(f"{who}: 2-D median (m)", "≤ 0.045", s["2-D median"], s["2-D median"] <= 0.045)
        add(f"{who}: 2-D worst (m)", "≤ 0.2", s["2-D worst"], s["2-D worst"] <= 0.2)
        add(f"{who}: 3-D median (m)", "≤ 0.10", s["3-D median"], s["3-D median"] <= 0.10)
    for foot in ("left", "right"):
        v = float(other.at[decision, f"gaitmap {foot} stride RMS (m)"])
        add(f"`{decision}`: gaitmap {foot} stride-length RMS (m)", "≤ 0.05", v, v <= 0.05)
    for col in ("x-io loop closure (m)", "Köroğlu footprint RMS, mean of 31-33 (m)"):
        v, b = float(other.at[decision, col]), float(other.at[BASELINE, col])
        add(f"`{decision}`: {col}", f"≤ baseline {b:.4f}", v, v <= b)
    return pd.DataFrame(rows)


def write_configs(cfg: dict[str, Any], insample: dict[str, float], held: dict[str, float], folder: Path) -> None:
    """``recommended.yaml`` and its live twin (the same but ``smoother: stepwise``) in ``folder`` for ``cfg``."""
    header = [
        "# footzoo's recommended setting for foot-mounted IMUs (not a paper's): one fixed setting for walking,",
        "# running, slow unusual motion and any sensor mounting. Chosen by benchmarks/select_recommended.py --nested",
        f"# (nested cross-validation on PyShoe's 36 VICON trials, {FOLDS} outer folds stratified by motion class,",
        "# seed 0; a change ships only if the outer folds' pooled median and worst improve and no other visible",
        "# reference gets worse; see benchmarks/recommended_selection.md). Outer folds, pooled held-out: 2-D median",
        f"# {held['2-D median']:.4f} m, worst {held['2-D worst']:.3f} m, 3-D median {held['3-D median']:.3f} m; "
        f"this setting on all 36: {insample['2-D median']:.4f}, {insample['2-D worst']:.3f}, "
        f"{insample['3-D median']:.3f} m.",
    ]
    live = ["# Live: recommended.yaml with smoother: stepwise (each stride smoothed once its stance has ended, so",
            "# footzoo.Stream runs it with a stride of latency; docs/live.md)."]
    for name, extra in (("recommended", []), ("recommended_live", live)):
        body = {**copy.deepcopy(cfg), "name": name}
        if extra:
            body["smoother"] = "stepwise"
        text = yaml.safe_dump(json.loads(json.dumps(body)), sort_keys=False, default_flow_style=None, width=120)
        (folder / f"{name}.yaml").write_text("\n".join(header + extra) + "\n" + text)
