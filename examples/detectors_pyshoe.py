"""Every detector in the zupt / ekf_zupt / zvu_dedrift pipelines on PyShoe's 36 VICON trials, per motion class.

Usage: python examples/detectors_pyshoe.py [DATA_DIR] [--grid]
(default DATA_DIR: ../shared/data/pyshoe_vicon)

Prints PyShoe's 2-D error (m), median per motion class (walking 2017-11-22, running 2017-11-27 and
2017-12-15, slow 2018-02-09, inverted 2018-02-22), the median ratio to PyShoe's per-trial best and
the worst trial, for each pipeline × detector at the detectors' defaults. With ``--grid`` it also
sweeps the thresholds and picks a setting per held-out motion class from the other classes
(leave-one-class-out cross-validation on the mean log median ratio), the way the defaults were chosen.
"""

from __future__ import annotations

import itertools
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import footzoo
from footzoo.evaluation.metrics import pyshoe_error

CLASSES = ("walking", "running", "slow", "inverted")
PIPELINES = {
    "duong2015_zupt (zupt)": "duong2015_zupt",
    "ekf_zupt (biases, no hdr)": {"name": "ekf_zupt", "orientation": {"type": "ins"},
                                  "corrections": [{"type": "ekf_zupt", "gyro_bias": True, "accel_bias": True,
                                                   "zero_rate": True}]},
    "nguyen2016 (ekf_zupt + hdr)": "nguyen2016",
    "yun2012 (zvu_dedrift)": "yun2012",
}
DETECTORS = [{"type": "adaptive_shoe"}, {"type": "shoe"}, {"type": "ared"}, {"type": "amvd"}, {"type": "mbgtd"},
             {"type": "dgp", "min_swing": 0.2}, {"type": "angular_rate_fsm"}, {"type": "huang_stance"},
             {"type": "windowed"}, {"type": "oracle"}]


def motion_class(trial: str) -> str:
    """Motion class of a PyShoe trial from its date (see ../shared/data/README.md)."""
    if trial.startswith("2017-11-22"):
        return "walking"
    if trial.startswith(("2017-11-27", "2017-12-15")):
        return "running"
    return "slow" if trial.startswith("2018-02-09") else "inverted"


def grid() -> list[dict]:
    """Threshold sweep of the classic detectors and the adaptive one."""
    dets = [{"type": "adaptive_shoe", "threshold": g, "time_constant": tc, "max_threshold": gm}
            for g, tc, gm in itertools.product([1e4, 3e4], [0.3, 0.5, 0.7, 1.0], [1e5, 3e5, 5e5])]
    dets += [{"type": "shoe", "threshold": g} for g in (1e4, 3e4, 1e5, 3e5)]
    dets += [{"type": "ared", "threshold": g} for g in (3e3, 1e4, 3e4, 1e5)]
    dets += [{"type": k, "threshold": g} for k in ("amvd", "mbgtd") for g in (10.0, 30.0, 100.0, 300.0, 1e3)]
    return dets


def run(root: Path, pipelines: dict, detectors: list[dict]) -> pd.DataFrame:
    """PyShoe's error of every pipeline × detector on every trial (tidy)."""
    trials = pd.read_csv(root / "trials.csv")
    recs = {tr: footzoo.load(root / f"{tr}.mat") for tr in trials.trial}
    rows = []
    for pname, cfg in pipelines.items():
        base = footzoo.config.load_yaml(cfg) if isinstance(cfg, str) else cfg
        for det in detectors:
            pipe = footzoo.Pipeline.from_dict({**base, "detector": det})
            for _, tr in trials.iterrows():
                rec = recs[tr.trial]
                try:
                    err = pyshoe_error(pipe.run(rec).pos, rec.truth.pos)
                except footzoo.FootzooError:
                    err = float("nan")
                rows.append({"pipeline": pname, "detector": str(det), "trial": tr.trial,
                             "class": motion_class(tr.trial), "error_m": err, "pyshoe_best_m": tr.best_error_m})
    df = pd.DataFrame(rows)
    df["ratio"] = df.error_m / df.pyshoe_best_m
    return df


def summary(df: pd.DataFrame) -> pd.DataFrame:
    """Median error per class, median ratio to PyShoe's best and worst trial, per pipeline × detector."""
    med = df.pivot_table(index=["pipeline", "detector"], columns="class", values="error_m", aggfunc="median")
    out = med[list(CLASSES)].copy()
    out["median_ratio"] = df.groupby(["pipeline", "detector"]).ratio.median()
    out["max_m"] = df.groupby(["pipeline", "detector"]).error_m.max()
    return out


def cross_validate(df: pd.DataFrame) -> pd.DataFrame:
    """Leave one motion class out: choose on the others' mean log median ratio, report the held-out median."""
    df = df[~df.detector.str.contains("oracle")]
    rows = []
    for pname, g in df.groupby("pipeline"):
        ratio = g.pivot_table(index="detector", columns="class", values="ratio", aggfunc="median")
        err = g.pivot_table(index="detector", columns="class", values="error_m", aggfunc="median")
        for held in CLASSES:
            others = [c for c in CLASSES if c != held]
            best = np.log(ratio[others]).mean(axis=1).idxmin()
            rows.append({"pipeline": pname, "held_out": held, "chosen": best, "held_out_median_m": err.loc[best, held]})
    return pd.DataFrame(rows)


def main() -> None:
    warnings.simplefilter("ignore")
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    root = Path(args[0] if args else "../shared/data/pyshoe_vicon")
    if not (root / "trials.csv").exists():
        print(f"no PyShoe data at {root}")
        return
    pd.set_option("display.width", 250)
    pd.set_option("display.max_colwidth", 120)
    df = run(root, PIPELINES, DETECTORS)
    print(summary(df).round(3).to_string())
    best = df.drop_duplicates("trial").groupby("class").pyshoe_best_m.median()
    print("PyShoe's per-trial best, median per class:", best.round(3).to_dict())
    if "--grid" in sys.argv:
        sweep = run(root, {k: PIPELINES[k] for k in ("duong2015_zupt (zupt)", "yun2012 (zvu_dedrift)")}, grid())
        print(cross_validate(sweep).to_string(index=False))


if __name__ == "__main__":
    main()
