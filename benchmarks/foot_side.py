"""Which foot the sensor is on, read from the walk (footzoo.analysis.foot_side), against the recordings' known sides.

Usage: python benchmarks/foot_side.py [--config recommended] [--data ../shared/data] [--out benchmarks/foot_side.md]

Every visible recording runs through the config with its foot side hidden; the side read from the
swing arcs (:func:`footzoo.analysis.foot_side.infer_foot`) is compared with the known one:
gaitmap's example (both feet), ipol_gait (3 walkers × 6 trials, both feet; read with footzoo's
Xsens reader when there is one, else with a small loader here: time = PacketCounter / 100 s),
PyShoe's 36 trials (right foot), Köroğlu's three walks and x-io's example (side not documented:
reported, not scored). The table counts, per dataset, the recordings read right, read wrong and
left undecided, with the straight strides that voted and their agreement.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from footzoo.analysis.foot_side import infer_foot  # noqa: E402
from footzoo.runtime.pipeline import Pipeline  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

DEFAULT_DATA = ROOT.parent / "shared" / "data"


def ipol(path: Path) -> footzoo.Recording:
    """One foot of an ipol_gait trial: footzoo's reader for the format when it has one, else a small loader."""
    if "xsens" in footzoo.io.READERS:
        return footzoo.load(path, format="xsens")
    df = pd.read_csv(path, sep="\t", skiprows=1)
    return footzoo.Recording(t=df["PacketCounter"].to_numpy(float) / 100.0,
                             acc=df[["Acc_X", "Acc_Y", "Acc_Z"]].to_numpy(float),
                             gyr=df[["Gyr_X", "Gyr_Y", "Gyr_Z"]].to_numpy(float), meta={"name": path.stem})


def cases(data: Path) -> list[tuple[str, str, str | None, object]]:
    """``(dataset, name, known side or None, loader)`` of every visible recording."""
    out: list[tuple[str, str, str | None, object]] = []
    gaitmap = data / "gaitmap_example" / "imu_sample.csv"
    if gaitmap.exists():
        out += [("gaitmap", f"imu_sample_{f}", f, lambda f=f: footzoo.load(gaitmap, foot=f)) for f in ("left", "right")]
    for p in sorted((data / "ipol_gait").glob("*_[lr]f.txt")):
        out.append(("ipol_gait", p.stem, "left" if p.stem.endswith("_lf") else "right", lambda p=p: ipol(p)))
    for p in sorted((data / "pyshoe_vicon").glob("*.mat")):
        out.append(("pyshoe", p.stem, "right", lambda p=p: footzoo.load(p)))
    for p in sorted((data / "koroglu_gcp").glob("*.csv")):
        out.append(("koroglu", p.stem, None, lambda p=p: footzoo.load(p)))
    xio = data / "xio_gait_tracking" / "short_walk.csv"
    if xio.exists():
        out.append(("xio", xio.stem, None, lambda: footzoo.load(xio)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="recommended")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "foot_side.md")
    args = ap.parse_args()
    pipeline = Pipeline.from_yaml(args.config)
    rows = []
    start = time.perf_counter()
    for dataset, name, known, load in cases(args.data):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rec = load()
            rec.meta.pop("foot", None)
            res = pipeline.run(rec)
        found = infer_foot(res.pos, res.stance)
        verdict = "undecided" if found.side is None else "not scored" if known is None else \
            "right" if found.side == known else "WRONG"
        rows.append({"dataset": dataset, "recording": name, "known": known or "?", "inferred": found.side or "-",
                     "verdict": verdict, "straight_strides": found.strides,
                     "agreement": np.nan if found.side is None else found.agreement,
                     "median_arc_cm": found.arc_m * 100})
        print(f"{dataset:10s} {name:28s} known {known or '?':5s} -> {found.side or '-':5s} ({found.reason})",
              flush=True)
    table = pd.DataFrame(rows)
    summary = table.groupby("dataset", sort=False).agg(
        recordings=("recording", "size"), read_right=("verdict", lambda v: int((v == "right").sum())),
        read_wrong=("verdict", lambda v: int((v == "WRONG").sum())),
        undecided=("verdict", lambda v: int((v == "undecided").sum())),
        not_scored=("verdict", lambda v: int((v == "not scored").sum())),
        median_straight_strides=("straight_strides", "median"),
        min_agreement=("agreement", "min")).reset_index()
    text = ["# Foot side from the swing arc\n",
            f"`python benchmarks/foot_side.py` (config `{args.config}`, {time.perf_counter() - start:.0f} s): every "
            "visible recording with its foot side hidden; the side read from the swing arcs of its straight strides "
            "(`footzoo.analysis.foot_side.infer_foot`) against the known side. `min_agreement`: the smallest share of "
            "a recording's voting strides that agreed with the side named.\n",
            "## Per dataset\n", to_markdown(summary), "\n## Per recording\n", to_markdown(table)]
    args.out.write_text("\n".join(text))
    print(to_markdown(summary))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
