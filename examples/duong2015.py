"""Duong & Suh 2015 with footzoo: Table 2 and Table 3 on the simulator, ZUPT on PyShoe.

Usage: python examples/duong2015.py [--seeds 3] [--pyshoe ../shared/data/pyshoe_vicon]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

import footzoo
from footzoo.core.conventions import quat_from_euler, quat_rotate
from footzoo.corrections.height import TABLE1_DIRECTIONS, TABLE1_POSITIONS
from footzoo.evaluation.metrics import pyshoe_error
from footzoo.sim import NoiseModel, simulate

CONFIGS = {"duong2015": "proposed method", "duong2015_zupt": "K.F. (zero velocity)",
           "duong2015_zupt_height": "K.F. (zero velocity + height updating)"}
PAPER_TABLE2_WALKING = {"duong2015": (0.0208, 0.0118, 0.0030), "duong2015_zupt": (0.0243, 0.0131, 0.0121),
                        "duong2015_zupt_height": (0.0247, 0.0130, 0.0095)}
BASE = {"orientation": {"type": "ins"}, "detector": {"type": "windowed"},
        "navigation": {"attitude_noise": 1.7e-6, "velocity_noise": 8.3e-5, "initial_attitude_std": 0.063}}


def walk(seed: int):
    return simulate(n_strides=40, profile="physical", rate=100.0, noise=NoiseModel(seed=seed), seed=seed,
                    distance_sensors=True, clearance=0.1)


def rms(res, rec) -> np.ndarray:
    return np.sqrt(np.mean((res.pos - rec.truth.pos) ** 2, axis=0))


def table2(seeds: int) -> pd.DataFrame:
    rows = []
    for seed in range(seeds):
        rec = walk(seed)
        for name, label in CONFIGS.items():
            e = rms(footzoo.Pipeline.from_yaml(name).run(rec), rec)
            rows.append({"method": label, "E_rms_x": e[0], "E_rms_y": e[1], "E_rms_z": e[2], "sum": e.sum()})
    out = pd.DataFrame(rows).groupby("method", sort=False).mean()
    out["paper_z"] = [PAPER_TABLE2_WALKING[n][2] for n in CONFIGS]
    return out


def _distance_run(rec, positions, directions, calibrate: bool, **kw):
    corr = {"type": "height_distance", "positions": np.asarray(positions).tolist(),
            "directions": np.asarray(directions).tolist(), "calibrate": calibrate, **kw}
    return footzoo.Pipeline.from_dict({**BASE, "corrections": [{"type": "zupt"}, corr]}).run(rec)


def table3(seeds: int) -> pd.DataFrame:
    true_r, true_n = np.array(TABLE1_POSITIONS), np.array(TABLE1_DIRECTIONS)
    off_r = true_r + np.array([[0.004, 0.0, 0.003], [-0.003, 0.0, -0.003]])
    off_n = quat_rotate(quat_from_euler(0.0, np.radians(3.0), 0.0), true_n)
    rows = []
    for seed in range(seeds):
        rec = walk(seed)

        res21 = _distance_run(rec, off_r, off_n, True, position_std=0.005, direction_std=0.05)
        cal = res21.diagnostics["distance_calibration"]
        runs = (("21-state (calibrating)", res21),
                ("9-state, perturbed parameters", _distance_run(rec, off_r, off_n, False)),
                ("9-state, recovered parameters", _distance_run(rec, cal["positions"], cal["directions"], False)),
                ("9-state, true parameters", _distance_run(rec, true_r, true_n, False)))
        for label, res in runs:
            e = rms(res, rec)
            rows.append({"method": label, "E_rms_x": e[0], "E_rms_y": e[1], "E_rms_z": e[2], "sum": e.sum()})
        err = np.array(cal["positions"]) - true_r
        rows.append({"method": "recovered - true r_A, r_B (mm)", "E_rms_x": 1000 * np.abs(err[:, 0]).mean(),
                     "E_rms_y": 1000 * np.abs(err[:, 1]).mean(), "E_rms_z": 1000 * np.abs(err[:, 2]).mean()})
    return pd.DataFrame(rows).groupby("method", sort=False).mean()


def pyshoe(root: Path) -> pd.DataFrame:
    trials = pd.read_csv(root / "trials.csv")
    p = footzoo.Pipeline.from_yaml("duong2015_zupt")
    rows = []
    for _, tr in trials.iterrows():
        rec = footzoo.load(root / f"{tr.trial}.mat")
        rows.append({"trial": tr.trial, "tag": tr.bipedal_tag_koroglu, "pyshoe_best": tr.best_error_m,
                     "duong2015_zupt": pyshoe_error(p.run(rec).pos, rec.truth.pos)})
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--pyshoe", default="../shared/data/pyshoe_vicon")
    args = parser.parse_args()
    pd.set_option("display.width", 200)
    print("== Table 2 (walking, simulated, 40 strides, two VL6180 sensors), RMS position error (m) ==")
    print(table2(args.seeds).round(4).to_string())
    print("\n== Table 3: calibration from mounting perturbed by 3-4 mm and 3 deg (m; last row mm) ==")
    print(table3(args.seeds).round(4).to_string())
    root = Path(args.pyshoe)
    if (root / "trials.csv").exists():
        ps = pyshoe(root)
        print("\n== PyShoe VICON trials: windowed detector + ZUPT, PyShoe's 2-D error (m) ==")
        print(ps.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
        walking = ps[(ps.tag == 1) & ps.trial.str.startswith("2017-11-22")]
        medians = walking[["pyshoe_best", "duong2015_zupt"]].median().round(3).to_dict()
        print("median, walking (tag 1, 2017-11-22):", medians)


if __name__ == "__main__":
    main()
