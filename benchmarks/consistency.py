"""Filter consistency per Kalman config: NEES on the simulator, NIS on the real recordings.

Usage: python benchmarks/consistency.py [--data ../shared/data] [--configs recommended,...] [--jobs 2]
                                         [--out benchmarks/consistency.md]

A consistent Kalman filter's errors match its covariance (Bar-Shalom, Li & Kirubarajan 2001,
Sec. 5.4). Two checks, per shipped Kalman config, with ``Pipeline.run(rec, covariance=True)``:

* NEES on the simulator, against its truth: the forward filter's position error normalised by its
  position variances (3 expected for three axes) and the share of samples within 2σ on every axis
  (about 95 % · 95 % · 95 % ≈ 86 % for independent Gaussian axes, 95 % per axis);
* NIS on the 36 PyShoe trials, which needs no truth: each update's normalised innovation squared
  per row, ``Σ νᵀ S⁻¹ ν / Σ rows`` (1 expected; below 1 the filter's noises are larger than the
  data's, above 1 it is over-confident), and the share of updates inside their two-sided 95 % χ²
  region (95 % expected). Per motion class (recording day, as benchmarks/accuracy.py).

Nothing is tuned to this table; it reports the shipped settings as they are.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed

sys.path.insert(0, str(Path(__file__).resolve().parent))
from accuracy import CLASS_ORDER, motion_class, shipped_configs  # noqa: E402

from footzoo.core.errors import FootzooError  # noqa: E402
from footzoo.evaluation.metrics import position_nees  # noqa: E402
from footzoo.runtime.pipeline import Pipeline  # noqa: E402
from footzoo.sim import NoiseModel, simulate  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

SCENARIOS = {"rectangle 100 Hz": {"path": "rectangle", "rate": 100.0},
             "run 200 Hz": {"path": "run", "n_strides": 40, "rate": 200.0},
             "stairs 100 Hz": {"path": "stairs", "n_strides": 6, "landing_strides": 3, "cycle": 1.2,
                               "clearance": 0.1, "rate": 100.0}}


def _run(config: str, rec):
    """The run with covariance, or None where the config does not apply (e.g. no distance sensors)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return Pipeline.from_yaml(config).run(rec, covariance=True)
        except FootzooError:
            return None


def simulator_row(config: str, name: str) -> dict | None:
    """NEES and NIS of one config on one simulated walk."""
    rec = simulate(profile="physical", noise=NoiseModel(scale=1, seed=0), magnetometer=False,
                   distance_sensors=True, **({"clearance": 0.15} | SCENARIOS[name]))
    res = _run(config, rec)
    d = res.diagnostics if res is not None else {}
    if "pos_std" not in d:
        return None
    p = d.get("pos_forward", res.pos)  # the forward filter's positions, whose covariance pos_std is
    tp = rec.truth.pos - rec.truth.pos[0]
    sd = d["pos_std"]
    inside = np.abs(p - p[0] - tp) <= 2 * sd
    c = d["consistency"]
    return {"config": config, "walk": name, "mean NEES (3)": float(np.nanmean(position_nees(p - p[0], tp, sd**2))),
            "within 2σ, all axes": float(inside.all(axis=1).mean()), "NIS per row (1)": c["nis_per_row"],
            "NIS inside 95 %": c["nis_inside"]}


def pyshoe_row(config: str, path: Path) -> dict | None:
    """NIS of one config on one PyShoe trial."""
    from footzoo.io import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load(path)
    res = _run(config, rec)
    d = res.diagnostics if res is not None else {}
    if "consistency" not in d:
        return None
    c = d["consistency"]
    return {"config": config, "trial": path.stem, "class": motion_class(path.stem),
            "NIS per row (1)": c["nis_per_row"], "NIS inside 95 %": c["nis_inside"]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[1].parent / "shared" / "data")
    ap.add_argument("--configs", default="", help="comma-separated shipped configs (default: every Kalman config)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "consistency.md")
    args = ap.parse_args(argv)
    configs = [p.stem for p in shipped_configs(args.configs.split(",") if args.configs else None)]
    files = sorted((args.data / "pyshoe_vicon").glob("*.mat"))
    sim = Parallel(n_jobs=args.jobs)(delayed(simulator_row)(c, s) for c in configs for s in SCENARIOS)
    real = Parallel(n_jobs=args.jobs)(delayed(pyshoe_row)(c, f) for c in configs for f in files)
    sim_t = pd.DataFrame([r for r in sim if r is not None])
    real_t = pd.DataFrame([r for r in real if r is not None])
    lines = ["# Filter consistency: NEES on the simulator, NIS on real recordings", "",
             "Generated by `python benchmarks/consistency.py`, `Pipeline.run(rec, covariance=True)` with every "
             "shipped Kalman config as shipped (nothing tuned to this table). Simulator (physical foot model, "
             "Table II noise and biases): the forward filter's mean position NEES (3 expected) and the share of "
             "samples within 2σ on all three axes (about 86 % for independent Gaussian errors), and the NIS. "
             "PyShoe trials (no truth needed): each update's normalised innovation squared per row, "
             "Σ νᵀ S⁻¹ ν / Σ rows (1 expected; below 1 the filter's noises are larger than the data's, above 1 "
             "it is over-confident), and the share of updates inside their two-sided 95 % χ² region. Flat-floor "
             "height updates on stairs (duong2015_zupt_height) break that config's own assumption: its NEES "
             "there is meant to be huge.",
             "", "## Simulator (NEES against the truth, forward filter)", "", to_markdown(sim_t, digits=3), ""]
    if len(real_t):
        summary = (real_t.groupby(["config", "class"], sort=False)[["NIS per row (1)", "NIS inside 95 %"]]
                   .median().reset_index())
        summary["class"] = pd.Categorical(summary["class"], [*CLASS_ORDER, "other"])
        summary = summary.sort_values(["config", "class"])
        lines += [f"## PyShoe trials (NIS, median per motion class, {len(files)} trials)", "",
                  to_markdown(summary, digits=3), ""]
    else:
        lines += ["PyShoe trials not found: NIS on real data not scored.", ""]
    text = "\n".join(lines)
    from footzoo.core.atomic import write_text

    write_text(args.out, text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
