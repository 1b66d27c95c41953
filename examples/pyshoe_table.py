"""Run a pipeline on every PyShoe VICON trial and compare with PyShoe's published best.

Usage: python examples/pyshoe_table.py [CONFIG] [DATA_DIR]
(defaults: yun2012, ../shared/data/pyshoe_vicon)
"""

import sys
from pathlib import Path

import pandas as pd

import footzoo
from footzoo.evaluation.metrics import armse, pyshoe_error


def main() -> None:
    cfg = sys.argv[1] if len(sys.argv) > 1 else "yun2012"
    root = Path(sys.argv[2] if len(sys.argv) > 2 else "../shared/data/pyshoe_vicon")
    trials = pd.read_csv(root / "trials.csv")
    pipeline = footzoo.Pipeline.from_yaml(cfg)
    rows = []
    for _, tr in trials.iterrows():
        rec = footzoo.load(root / f"{tr.trial}.mat")
        try:
            res = pipeline.run(rec)
            err, err3 = pyshoe_error(res.pos, rec.truth.pos), armse(res.pos, rec.truth.pos)
        except footzoo.FootzooError as exc:
            err = err3 = float("nan")
            print(f"{tr.trial}: {exc}")
        rows.append({"trial": tr.trial, "bipedal_tag": tr.bipedal_tag_koroglu, "footzoo_pyshoe_m": err,
                     "footzoo_armse3d_m": err3, "pyshoe_best_m": tr.best_error_m, "pyshoe_best": tr.best_detector})
    df = pd.DataFrame(rows)
    print(df.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    walking = df[df.bipedal_tag == 1]
    med = walking[["footzoo_pyshoe_m", "pyshoe_best_m", "footzoo_armse3d_m"]].median()
    print(f"walking trials (tag 1): {len(walking)}; median footzoo {med.footzoo_pyshoe_m:.3f} m, "
          f"PyShoe best {med.pyshoe_best_m:.3f} m, footzoo 3-D ARMSE {med.footzoo_armse3d_m:.3f} m")


if __name__ == "__main__":
    main()
