"""One config with each smoother (none, rts, stepwise) on PyShoe's 36 VICON trials: PyShoe's 2-D error per motion class.

Usage: python benchmarks/smoother_accuracy.py [--config recommended] [--data ../shared/data] [--out FILE.md]

The metric and the motion classes are :mod:`benchmarks.accuracy`'s (PyShoe's own 2-D error,
:func:`footzoo.evaluation.metrics.pyshoe_error`; classes by recording day); the table gives the
median per class, the worst trial and the median ratio to PyShoe's per-trial best.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from benchmarks.accuracy import CLASS_ORDER, DEFAULT_DATA, motion_class, pyshoe_reference  # noqa: E402
from footzoo.evaluation.metrics import pyshoe_error  # noqa: E402

SMOOTHERS = ("none", "rts", "stepwise")


def per_trial(config: str, folder: Path) -> pd.DataFrame:
    """PyShoe's error (m) of ``config`` with each smoother, one row per trial."""
    ref = pyshoe_reference(folder)
    base = footzoo.Pipeline.from_yaml(config).to_dict()
    pipes = {s: footzoo.Pipeline.from_dict({**base, "smoother": s}) for s in SMOOTHERS}
    rows = []
    for path in sorted(folder.glob("*.mat")):
        rec = footzoo.load(path, format="pyshoe")
        row = {"trial": path.stem, "class": motion_class(path.stem), "best": float(ref.loc[path.stem, "best_error_m"])}
        row.update({s: pyshoe_error(p.run(rec).pos, rec.truth.pos) for s, p in pipes.items()})
        rows.append(row)
    return pd.DataFrame(rows)


def summary(t: pd.DataFrame) -> list[str]:
    lines = ["| motion class | trials | " + " | ".join(SMOOTHERS) + " |", "|---|---|" + "---|" * len(SMOOTHERS)]
    for cls in [c for c in CLASS_ORDER if c in set(t["class"])]:
        part = t[t["class"] == cls]
        lines.append(f"| {cls} | {len(part)} | " + " | ".join(f"{part[s].median():.4f}" for s in SMOOTHERS) + " |")
    lines.append(f"| worst trial | {len(t)} | " + " | ".join(f"{t[s].max():.3f}" for s in SMOOTHERS) + " |")
    lines.append(f"| median ratio to PyShoe's best | {len(t)} | "
                 + " | ".join(f"{np.median(t[s] / t['best']):.3f}" for s in SMOOTHERS) + " |")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="recommended")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--out", type=Path)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    folder = args.data / "pyshoe_vicon"
    if not any(folder.glob("*.mat")):
        raise SystemExit(f"no PyShoe trials in {folder}")
    lines = [f"### {args.config}: PyShoe's 2-D error (m), median per motion class, by smoother", "",
             *summary(per_trial(args.config, folder))]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
