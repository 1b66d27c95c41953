"""Nguyen & La 2016 with footzoo: DGP across speeds, the three systems on a hallway loop and on PyShoe.

Usage: python examples/nguyen2016.py [--seeds 3] [--pyshoe ../shared/data/pyshoe_vicon]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

import footzoo
from footzoo.detectors import DGP, AdaptiveSHOE, AngularRateFSM
from footzoo.evaluation.metrics import loop_closure, pyshoe_error, step_detection
from footzoo.sim import MagneticDisturbance, NoiseModel, simulate

CONFIGS = ("nguyen2016_ins_zvu", "nguyen2016_ins_zvu_hdr", "nguyen2016")


def detection_table(seeds: int) -> pd.DataFrame:
    """Gait-phase error rate of DGP, the adaptive SHOE and the angular-rate FSM on walking and running."""
    rows = []
    for rate in (100.0, 200.0):
        for seed in range(seeds):
            rec = simulate(path="mixed_speed", profile="physical", rate=rate, noise=NoiseModel(seed=seed), seed=seed)
            for det in (DGP(min_swing=0.2), AdaptiveSHOE(), AngularRateFSM()):
                d = det.detect(rec.t, rec.acc, rec.gyr)
                r = step_detection(d.stance_, rec.truth.stance, rec.t)
                rows.append({"rate_hz": rate, "seed": seed, "detector": det.name, **r})
    return pd.DataFrame(rows)


def hallway_table(seeds: int) -> pd.DataFrame:
    """Loop closure of the three systems on a 120 m rectangle with Table II biases and a disturbed leg."""
    rows = []
    for seed in range(seeds):
        rec = simulate(path="rectangle", profile="physical", rate=100.0, noise=NoiseModel(seed=seed), seed=seed,
                       disturbance=MagneticDisturbance(field=(0.0, 0.1, 0.0), north=(10.0, 30.0), east=(-1.0, 1.0)))
        for name in CONFIGS:
            res = footzoo.Pipeline.from_yaml(name).run(rec)
            rows.append({"seed": seed, "config": name, **loop_closure(res.pos)})
    return pd.DataFrame(rows)


def pyshoe_table(root: Path) -> pd.DataFrame:
    """PyShoe's error for the three configs (plus the EKF with other detectors, as ablation rows)."""
    trials = pd.read_csv(root / "trials.csv")
    pipelines = {name: footzoo.Pipeline.from_yaml(name) for name in CONFIGS}
    base = footzoo.config.load_yaml("nguyen2016")
    for det in ("angular_rate_fsm", "oracle"):
        pipelines[f"nguyen2016[{det}]"] = footzoo.Pipeline.from_dict({**base, "detector": {"type": det}})
    rows = []
    for _, tr in trials.iterrows():
        rec = footzoo.load(root / f"{tr.trial}.mat")
        row = {"trial": tr.trial, "tag": tr.bipedal_tag_koroglu, "pyshoe_best": tr.best_error_m}
        for name, p in pipelines.items():
            row[name] = pyshoe_error(p.run(rec).pos, rec.truth.pos)
        rows.append(row)
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--pyshoe", default="../shared/data/pyshoe_vicon")
    args = parser.parse_args()
    pd.set_option("display.width", 200)
    det = detection_table(args.seeds)
    print("== gait-phase detection, mixed speeds (0.85, 1.38, 1.92 m/s walking, 3.2 m/s running) ==")
    print("paper: DGP 1 wrong in 36 steps (2.78 %)")
    cols = ["true_steps", "detected_steps", "correct", "error_rate", "onset_error_mean_s", "offset_error_mean_s"]
    print(det.groupby(["rate_hz", "detector"])[cols].mean().round(4).to_string())
    hall = hallway_table(args.seeds)
    print("\n== 120 m hallway loop, Table II biases, 0.1 G disturbance on 20 m of the first leg ==")
    print("paper: INS/EKF+ZVU+HDR 0.45 m over 120 m = 0.375 %, the best of the three")
    print(hall.groupby("config")[["loop_closure_xy_m", "loop_closure_xy_pct"]].mean().round(4).to_string())
    root = Path(args.pyshoe)
    if (root / "trials.csv").exists():
        ps = pyshoe_table(root)
        print("\n== PyShoe VICON trials, PyShoe's 2-D error (m) ==")
        print(ps.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
        cols = [c for c in ps.columns if c not in ("trial", "tag")]
        walking = ps[(ps.tag == 1) & ps.trial.str.startswith("2017-11-22")]
        fast = ps[ps.trial.str.startswith("2017-11-27")]
        print("median, walking (tag 1, 2017-11-22):", walking[cols].median().round(3).to_dict())
        print("median, faster 2017-11-27 trials:", fast[cols].median().round(3).to_dict())
        print("median, all tag 1:", ps[ps.tag == 1][cols].median().round(3).to_dict())
    else:
        print(f"\n(no PyShoe data at {root}; skipped)")


if __name__ == "__main__":
    main()
