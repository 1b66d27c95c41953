"""Choose ``configs/recommended.yaml``: one setting, by leave-one-motion-class-out cross-validation.

Usage: python benchmarks/select_recommended.py [--jobs 2] [--results benchmarks/results/]
                                               [--data ../shared/data] [--write]

A small grid of settings (stance detector type and threshold, :data:`THRESHOLDS`, × zero-velocity
Kalman filter noise, :data:`NOISE_GRID`, × velocity noise growing with the acceleration or not,
:data:`IMPACT`, × offline RTS smoothing or not, :data:`SMOOTHERS`, × the maximum-swing guard on or
off, :data:`GUARDS`) runs on the 36 PyShoe VICON trials through footzoo's
ablation runner
(cached). The score of a setting on a set of trials is the mean, over the motion classes in the
set, of the geometric mean over the class's trials of ``error / PyShoe's per-trial best``
(PyShoe's 2-D metric): every motion class weighs the same whatever its number of trials, and a
trial that runs away counts more than under a median.

Every setting must also pass a rate check (PyShoe's trials are all 200 Hz): ARMSE at most 0.5 m on
the simulated mixed-speed walk (0.85 to 3.2 m/s, Table II noise) at 100 and at 200 Hz; the
selection is among those that pass.

Cross-validation (never per trial): for each motion class c (walking, running/fast, slow
unusual, inverted), the setting with the best score on the other classes is chosen and its
errors on c's trials are kept. Those held-out errors are the cross-validated figure (median
ratio to PyShoe's best, medians per class, worst trial). The recommended setting is then the
best on all classes; ``--write`` writes it to ``configs/recommended.yaml`` with the procedure
and the figures in its header. The selection and the figures go to
``benchmarks/recommended_selection.md``.
"""

from __future__ import annotations

import argparse
import copy
import itertools
import json
import os
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from accuracy import (  # noqa: E402
    CLASS_ORDER,
    DEFAULT_DATA,
    DEFAULT_RESULTS,
    motion_class,
    pyshoe_reference,
    run_cached,
)

from footzoo.plugins.registry import available  # noqa: E402
from footzoo.studies import Study, tune  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

#: The filter every candidate shares: INS attitude in a 9-state error-state Kalman filter with
#: zero-velocity updates (Duong & Suh 2015's, Table 1 noise), whose noise is a grid factor.
BASE = {
    "name": "recommended",
    "init": {"duration": 0.5, "max_gyr": 0.6},
    "orientation": {"type": "ins"},
    "navigation": {"attitude_noise": 1.7e-6, "velocity_noise": 8.3e-5, "initial_attitude_std": 0.063},
    "detector": {"type": "shoe"},
    "corrections": [{"type": "zupt", "velocity_std": 0.01}],
}


def detector_grid() -> list[dict[str, Any]]:
    """Detector settings: type and threshold around each detector's default (only detectors this footzoo has)."""
    have = set(available("detector"))
    grid: list[dict[str, Any]] = []
    for name, values in THRESHOLDS.items():
        if name in have:
            key, settings = values
            grid += [{"type": name, **({key: v} if isinstance(v, float) else v)} for v in settings]
    return grid


#: Detector type -> (threshold parameter, values tried); adaptive_shoe also varies its time constant.
THRESHOLDS: dict[str, tuple[str, list[Any]]] = {
    "shoe": ("threshold", [1e4, 3e4, 1e5, 3e5, 1e6]),
    "adaptive_shoe": ("threshold", [{"threshold": th, "time_constant": tau} for th in (3e3, 1e4, 3e4)
                                    for tau in (0.3, 0.5)]),
    "ared": ("threshold", [1e4, 3e4, 1e5]),
    "amvd": ("threshold", [3e1, 1e2, 3e2]),
    "mbgtd": ("threshold", [3e1, 1e2, 3e2]),
    "angular_rate_fsm": ("threshold", [0.6, 1.0, 1.5]),
    "windowed": ("gyro_threshold", [0.6, 1.0]),
    "dgp": ("min_swing", [0.2]),
    "speed_adaptive_shoe": ("threshold", [{"threshold": th, "speed_scale": vs} for th in (2e3, 3e3, 5e3)
                                          for vs in (0.8, 1.0, 1.2)]),
}


#: Kalman noise settings: (attitude_noise rad²/s, velocity_noise (m/s)²/s, zupt velocity_std m/s): Duong & Suh's
#: Table 1 values, a larger attitude and velocity noise with a loose zero-velocity measurement, and a velocity
#: noise large enough for a foot's unmodelled jerks (0.03 (m/s)²/s: on PyShoe's per-trial labels the error
#: no longer changes above 0.01).
NOISE_GRID = [(1.7e-6, 8.3e-5, 0.01), (1e-5, 1e-3, 0.05), (1e-6, 0.03, 0.03)]

#: ``navigation.impact_noise`` (s): velocity noise uniform in time (0), or growing with the squared
#: acceleration (heel strikes; on gaitmap's walk the stride-length error follows the impact's velocity error).
IMPACT = [0.0, 1e-5, 3e-5]

#: Offline smoothing: the forward filter alone, or with the RTS backward pass.
SMOOTHERS = ["none", "rts"]

#: The pipeline's maximum-swing guard (docs/guards.md): on (footzoo's default) or off.
GUARDS = ["on", "off"]


#: The rate check every candidate must pass: ARMSE (m) on the simulated mixed-speed walk at 100 and 200 Hz.
RATE_CHECK_SIM = {"path": "mixed_speed", "profile": "physical", "clearance": 0.15, "noise": {"scale": 1}}
RATE_CHECK_M = 0.5


def rate_check(cands: list[dict[str, Any]], folder: Path, jobs: int) -> pd.Series:
    """Per setting, the worse ARMSE (m) of the simulated mixed-speed walk at 100 and 200 Hz (the rate check).

    PyShoe is all 200 Hz; a setting qualifies only if it also tracks the simulated mixed-speed walk (0.85 to
    3.2 m/s, Table II noise) at 100 and at 200 Hz within :data:`RATE_CHECK_M`.
    """
    sim = Study.from_dict({"name": "select_recommended_rates", "base": cands, "metrics": ["armse_3d_m"],
                           "recordings": [{"simulate": {**RATE_CHECK_SIM, "rate": r}, "seeds": [0],
                                           "label": f"mixed_speed_{r}hz"} for r in (100, 200)]})
    st = run_cached(sim, folder, jobs)
    sim_err = st[st["metric"] == "armse_3d_m"].pivot_table(index="recording", columns="base", values="value")
    return sim_err.max().reindex([c["name"] for c in cands])


def candidates() -> list[dict[str, Any]]:
    """Every grid setting as a full config."""
    return [build(*c) for c in itertools.product(detector_grid(), NOISE_GRID, IMPACT, SMOOTHERS, GUARDS)]


#: ``--refine``: the speed-adaptive detector's grid × its provisional pass's shortest swing (None: min_swing,
#: the setting before; 0: no closing, the speed test alone closes the still gaps) × the zero-velocity update's
#: roll lever (m; 0: constant noise, ``zupt``'s ``roll_lever``), the other factors at the full grid's choice
#: (benchmarks/recommended_selection.md, "Chosen on all classes").
REFINE_PROVISIONAL = [None, 0.0]
REFINE_ROLL = [0.0, 0.1, 0.2, 0.3]
#: The shipped setting before the roll lever (the first refinement's choice: provisional_min_swing 0, threshold
#: 3000, speed_scale 1), which the refinement's report compares with.
PREVIOUS_PROVISIONAL = 0.0
REFINE_FIXED = {"noise": (1e-6, 0.03, 0.03), "impact": 0.0, "smoother": "rts", "guard": "off"}
#: ``--refine`` also reports the height at the top of the simulated stairs at these rates (not a selection check).
REFINE_STAIRS = {"path": "stairs", "n_strides": 6, "landing_strides": 3, "cycle": 1.2, "clearance": 0.1,
                 "profile": "physical", "noise": {"scale": 1}}
REFINE_MARK = "<!-- refinement: written by select_recommended.py --refine -->"
#: Where ``--nested``'s section starts (a ``--refine`` run keeps it).
NESTED_MARK = "<!-- nested: written by select_recommended.py --nested -->"


def build(det: dict[str, Any], noise: tuple[float, float, float], impact: float, smoother: str,
          guard: str, roll: float = 0.0) -> dict[str, Any]:
    """One full config of the grid."""
    att, vel, vstd = noise
    cfg = copy.deepcopy(BASE)
    cfg["detector"] = det
    cfg["navigation"].update(attitude_noise=att, velocity_noise=vel)
    if impact:
        cfg["navigation"]["impact_noise"] = impact
    cfg["corrections"][0]["velocity_std"] = vstd
    if roll:
        cfg["corrections"][0]["roll_lever"] = roll
    if smoother != "none":
        cfg["smoother"] = smoother
    if guard == "off":
        cfg["guards"] = {"max_swing": 0.0}
    cfg["name"] = setting_name(cfg)
    return cfg


def refine_candidates() -> list[dict[str, Any]]:
    """The ``--refine`` grid (see :data:`REFINE_PROVISIONAL`)."""
    _, settings = THRESHOLDS["speed_adaptive_shoe"]
    f = REFINE_FIXED
    return [build({"type": "speed_adaptive_shoe", **v, **({} if pm is None else {"provisional_min_swing": pm})},
                  f["noise"], f["impact"], f["smoother"], f["guard"], roll)
            for v in settings for pm in REFINE_PROVISIONAL for roll in REFINE_ROLL]


def setting_name(cfg: dict[str, Any]) -> str:
    """A readable, unique name of a setting."""
    det = cfg["detector"]
    params = ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in det.items() if k != "type")
    o = cfg["navigation"]
    return (f"{det['type']}({params})|att={o['attitude_noise']:g},vel={o['velocity_noise']:g},"
            f"zupt={cfg['corrections'][0]['velocity_std']:g}"
            + (f",roll={cfg['corrections'][0]['roll_lever']:g}" if cfg["corrections"][0].get("roll_lever") else "")
            + (f",impact={o['impact_noise']:g}" if o.get("impact_noise") else "")
            + ("|rts" if cfg.get("smoother") == "rts" else "")
            + ("|no swing guard" if "guards" in cfg else ""))


def score(log_ratio: pd.Series, classes: pd.Series) -> float:
    """Mean over classes of the class's mean log ratio (a geometric mean per class, classes weighted equally)."""
    per_class = log_ratio.groupby(classes).mean()
    return float(per_class.mean())


def class_score(best: pd.Series):
    """The score of a setting on a set of trials: :func:`score` of ``log(error / PyShoe's best)``, a failed run
    counting as 1000 times PyShoe's best (a :data:`footzoo.studies.tune.Score`)."""
    def scored(values: pd.Series, classes: pd.Series) -> float:
        ratio = np.log(values / best.reindex(values.index)).fillna(np.log(1e3))
        return score(ratio, classes)

    return scored


def cross_validate(err: pd.DataFrame, best: pd.Series) -> tuple[pd.DataFrame, pd.Series, str]:
    """Leave-one-motion-class-out selection (:func:`footzoo.studies.tune.cross_validate` with :func:`class_score`).

    Returns the per-fold choices, the held-out error of every trial and the setting chosen on all classes.
    """
    from footzoo.studies.tune import cross_validate as leave_one_group_out_choice

    classes = pd.Series([motion_class(t) for t in err.index], index=err.index)
    rank = classes.map({c: i for i, c in enumerate(CLASS_ORDER)}).fillna(len(CLASS_ORDER))
    err, classes = err.loc[rank.sort_values(kind="stable").index], classes.loc[rank.sort_values(kind="stable").index]
    folds, held_out, final = leave_one_group_out_choice(err, classes, class_score(best))
    return _fold_table(folds, err, held_out, best), held_out, final


def _fold_table(folds: pd.DataFrame, err: pd.DataFrame, held_out: pd.Series, best: pd.Series) -> pd.DataFrame:
    """The folds as the selection report shows them (held-out medians in m and as ratios to PyShoe's best)."""
    classes = pd.Series([motion_class(t) for t in err.index], index=err.index)
    rows = []
    for f in folds.itertuples():
        if f.group not in CLASS_ORDER:
            continue
        test = classes == f.group
        rows.append({"held-out class": f.group, "trials": int(test.sum()), "chosen on the other classes": f.chosen,
                     "held-out median (m)": err.loc[test, f.chosen].median(),
                     "held-out median ratio": float((err.loc[test, f.chosen] / best[test]).median())})
    return pd.DataFrame(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--results", type=Path, default=DEFAULT_RESULTS)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--write", action="store_true", help="write configs/recommended.yaml")
    ap.add_argument("--progress", action="store_true")
    ap.add_argument("--refine", action="store_true",
                    help="only the speed-adaptive detector x its provisional pass's shortest swing x the roll lever "
                         "(REFINE_*)")
    ap.add_argument("--nested", action="store_true",
                    help="nested cross-validation of the selection procedure on the NESTED_* candidates and the "
                         "decision rule (with --write: recommended.yaml and recommended_live.yaml if it says so)")
    args = ap.parse_args(argv)
    os.environ.setdefault("PYTHONWARNINGS", "ignore::UserWarning")
    warnings.simplefilter("ignore", UserWarning)
    folder = args.data / "pyshoe_vicon"
    if not folder.is_dir():
        print(f"no PyShoe trials in {folder}: nothing to select on")
        return 1
    if args.nested:
        from select_nested import nested

        return nested(args)
    cands = refine_candidates() if args.refine else candidates()
    worst_sim = rate_check(cands, args.results / "select_recommended_rates", args.jobs)
    qualified = set(worst_sim[worst_sim <= RATE_CHECK_M].index)
    print(f"{len(qualified)} of {len(cands)} settings pass the rate check")
    # the selection: footzoo.tune, leave-one-motion-class-out, among the settings that pass the rate check
    study = Study.from_dict({"name": "select_recommended", "base": cands,
                             "recordings": [{"path": str(folder / "*.mat"), "format": "pyshoe"}],
                             "max_cells": len(cands) * 40})
    best = pyshoe_reference(folder)["best_error_m"]
    result = tune(study, {"objective": "pyshoe_error_m"}, score=class_score(best), eligible=qualified.__contains__,
                  groups=motion_class, jobs=args.jobs, out=args.results / "select_recommended", quiet=True)
    err_all = result.values_
    err = err_all[[c for c in err_all.columns if c in qualified]]
    best = best.reindex(err.index)
    final, held_out = result.best_, result.held_out_.reindex(err.index)
    folds = _fold_table(result.folds_, err, held_out, best)
    err3 = None
    if args.refine:  # the refinement's report shows the 3-D error too: the same runs, read from the cache
        study3 = Study.from_dict({"name": "select_recommended_3d", "base": cands,
                                  "recordings": [{"path": str(folder / "*.mat"), "format": "pyshoe"}],
                                  "metrics": ["armse_3d_m"], "max_cells": len(cands) * 40})
        t3 = run_cached(study3, args.results / "select_recommended_3d", args.jobs)
        err3 = t3[t3["metric"] == "armse_3d_m"].pivot_table(index="recording", columns="base", values="value",
                                                          aggfunc="first")
    classes = pd.Series([motion_class(x) for x in err.index], index=err.index)
    cv = {"median ratio": float((held_out / best).median()),
          **{f"{c} median (m)": float(held_out[classes == c].median()) for c in CLASS_ORDER if (classes == c).any()},
          "worst (m)": float(held_out.max()), "worst trial": str(held_out.idxmax())}
    fin = err[final]
    insample = {"median ratio": float((fin / best).median()),
                **{f"{c} median (m)": float(fin[classes == c].median()) for c in CLASS_ORDER if (classes == c).any()},
                "worst (m)": float(fin.max()), "worst trial": str(fin.idxmax())}
    ranking = pd.DataFrame({
        "setting": err_all.columns,
        "score": [score(np.log(err_all[s] / best).fillna(np.log(1e3)), classes) for s in err_all.columns],
        **{f"{c} median": [err_all.loc[classes == c, s].median() for s in err_all.columns] for c in CLASS_ORDER},
        "worst": [err_all[s].max() for s in err_all.columns],
        "sim 100/200 Hz worst ARMSE": worst_sim.to_numpy(),
        "passes rate check": [s in qualified for s in err_all.columns],
    }).sort_values("score")
    lines = ["# Selection of `configs/recommended.yaml`", "",
             (__doc__ or "").split("\n\n", 2)[2].strip().replace("\n", " "), "",
             f"Grid: {len(cands)} settings × {len(err)} trials (detector settings: "
             f"{len(detector_grid())}, Kalman noise settings: {len(NOISE_GRID)}, impact noise: {len(IMPACT)}, "
             f"smoothing: {len(SMOOTHERS)}, "
             f"swing guard: {len(GUARDS)}); "
             f"{len(qualified)} pass the rate "
             f"check (simulated mixed-speed walk, ARMSE ≤ {RATE_CHECK_M} m at both 100 and 200 Hz) and are "
             "selected among.", "",
             "## Cross-validated figure (each class predicted by a setting chosen without it)", "",
             to_markdown(pd.DataFrame([cv]), 3), "", to_markdown(folds, 3), "",
             "## Chosen on all classes", "", f"`{final}`", "", "In-sample (optimistic) figures:", "",
             to_markdown(pd.DataFrame([insample]), 3), "",
             "## Fifteen best settings by score (all, rate check shown)", "",
             to_markdown(ranking.head(15), 3), ""]
    out = ROOT / "benchmarks" / "recommended_selection.md"
    if args.refine:
        lines = refine_section(cands, err, err3, best, classes, folds, cv, final, insample, args)
        text = out.read_text() if out.exists() else ""
        head = text.split(REFINE_MARK)[0].split(NESTED_MARK)[0].rstrip("\n")
        nested = f"\n\n{NESTED_MARK}{text.split(NESTED_MARK, 1)[1]}" if NESTED_MARK in text else ""
        out.write_text(f"{head}\n\n{REFINE_MARK}\n\n" + "\n".join(lines) + nested)
    else:
        out.write_text("\n".join(lines))
    print("\n".join(lines))
    if args.write:
        cfg = next(c for c in cands if c["name"] == final)
        write_config(cfg, cv)
    return 0


def refine_section(cands: list[dict[str, Any]], err: pd.DataFrame, err3: pd.DataFrame, best: pd.Series,
                   classes: pd.Series,
                   folds: pd.DataFrame, cv: dict[str, Any], final: str, insample: dict[str, Any],
                   args: argparse.Namespace) -> list[str]:
    """The ``--refine`` section: the cross-validation on the small grid, the per-class comparison, the stairs."""
    previous = next(c["name"] for c in cands if c["detector"].get("provisional_min_swing") == PREVIOUS_PROVISIONAL
                    and c["detector"]["threshold"] == 3000.0 and c["detector"]["speed_scale"] == 1.0
                    and not c["corrections"][0].get("roll_lever"))
    per_class = pd.DataFrame([{"class": c, "trials": int((classes == c).sum()),
                               "before: median (m)": err.loc[classes == c, previous].median(),
                               "chosen: median (m)": err.loc[classes == c, final].median(),
                               "before: worst (m)": err.loc[classes == c, previous].max(),
                               "chosen: worst (m)": err.loc[classes == c, final].max(),
                               "before: 3-D median (m)": err3.loc[classes == c, previous].median(),
                               "chosen: 3-D median (m)": err3.loc[classes == c, final].median(),
                               "before: 3-D worst (m)": err3.loc[classes == c, previous].max(),
                               "chosen: 3-D worst (m)": err3.loc[classes == c, final].max()}
                              for c in CLASS_ORDER if (classes == c).any()])
    stairs = Study.from_dict({"name": "select_recommended_stairs", "base": [c for c in cands if c["name"] in
                                                                            (previous, final)],
                              "metrics": ["armse_3d_m"],
                              "recordings": [{"simulate": {**REFINE_STAIRS, "rate": r}, "seeds": [0],
                                              "label": f"stairs_{r}hz"} for r in (100, 250, 400)]})
    st = run_cached(stairs, args.results / "select_recommended_stairs", args.jobs)
    st = st[st["metric"] == "armse_3d_m"].pivot_table(index="recording", columns="base", values="value")
    return ["## Refinement: the provisional pass's shortest swing and the roll lever (`--refine`)", "",
            "On the simulator at 250 and 400 Hz the speed-adaptive detector took a foot that stops in the air "
            "before landing on a stair as standing from the stop on: its provisional pass (adaptive SHOE) closed "
            "the short swing after the stop, which set the strapdown speed there to zero and hid the motion from "
            "the speed test (benchmarks/accuracy.md, rate independence). `provisional_min_swing: 0` leaves the "
            "provisional swings as the adaptive test gives them; the speed test still closes the short gaps where "
            "the foot stayed slower than `still_speed` (a first refinement chose it: PyShoe's trials unchanged to "
            "1e-6 m). The zero-velocity update's `roll_lever` ℓ (m) then weighs each stance sample by how fast "
            "the foot turns, σ² = σ_v² + (ℓ |ω|)²: a foot rolling over its heel or its toes moves a sensor ℓ "
            "from the pivot at ℓ |ω|, and a detected stance includes the heel rock and the toe roll. Grid: the "
            "speed-adaptive detector's 9 settings × provisional_min_swing ∈ {min_swing, 0} × roll_lever ∈ "
            f"{{{', '.join(f'{v:g}' for v in REFINE_ROLL)}}} m, the other factors at the full grid's choice "
            f"({REFINE_FIXED}); the same leave-one-motion-class-out cross-validation and rate check. "
            "`before` is the setting shipped before the roll lever.", "",
            "### Cross-validated figure", "", to_markdown(pd.DataFrame([cv]), 3), "", to_markdown(folds, 3), "",
            f"Chosen on all classes: `{final}`; before: `{previous}`.", "",
            "In-sample (optimistic) figures of the chosen setting:", "", to_markdown(pd.DataFrame([insample]), 3),
            "", "### Per motion class, before and chosen (PyShoe's 2-D metric; 3-D ARMSE after a yaw alignment)",
            "", to_markdown(per_class, 4), "",
            "### Simulated stairs (2.2 m up, a landing, down), 3-D ARMSE (m)", "", to_markdown(st.reset_index(), 3),
            ""]


def shipped_height() -> list[dict[str, Any]]:
    """The level-stance height correction(s) of the shipped ``configs/recommended.yaml`` (chosen apart, by
    ``benchmarks/select_height.py``): every selection here keeps them after its stance updates."""
    import yaml

    shipped = yaml.safe_load((ROOT / "configs" / "recommended.yaml").read_text())
    return [c for c in shipped["corrections"] if c["type"] == "height_level"]


def write_config(cfg: dict[str, Any], cv: dict[str, Any]) -> None:
    """``configs/recommended.yaml`` with the selection procedure in its header (the shipped height update kept)."""
    import yaml

    cfg = copy.deepcopy(cfg)
    cfg["name"] = "recommended"
    cfg["corrections"] += [h for h in shipped_height() if h not in cfg["corrections"]]
    header = [
        "# footzoo's recommended setting for foot-mounted IMUs (not a paper's): one fixed setting for walking,",
        "# running, slow unusual motion and any sensor mounting. Chosen by benchmarks/select_recommended.py:",
        "# a small grid (detector type and threshold x Kalman filter noise x impact noise x RTS smoothing x",
        "# swing guard)",
        "# on the 36 PyShoe VICON trials, scored per motion class, selected by leave-one-motion-class-out",
        "# cross-validation (never per trial); see benchmarks/recommended_selection.md.",
        f"# Cross-validated: median ratio to PyShoe's per-trial best {cv['median ratio']:.2f}, "
        f"worst trial {cv['worst (m)']:.3f} m.",
        "# Filter: INS attitude in a 9-state error-state Kalman filter with zero-velocity updates",
        "# (Duong & Suh 2015, eq. 23)" + (", smoothed offline (RTS)." if cfg.get("smoother") == "rts" else "."),
        *(["# The maximum-swing guard (docs/guards.md) is off: it did worse on the slow unusual motion, and",
           "# the adaptive detector's own threshold growth (Wahlstrom et al. 2019) already bounds its swings."]
          if "guards" in cfg else []),
    ]
    body = yaml.safe_dump(json.loads(json.dumps(cfg)), sort_keys=False, default_flow_style=None, width=120)
    (ROOT / "configs" / "recommended.yaml").write_text("\n".join(header) + "\n" + body)


if __name__ == "__main__":
    raise SystemExit(main())
