"""The rolling-foot stance update (``rolling_stance``) against ``recommended`` as shipped, on every visible reference.

Usage: python benchmarks/rolling_stance.py [--jobs 2] [--data ../shared/data] [--out benchmarks/rolling_stance.md]

Each candidate is ``configs/recommended.yaml`` with its stance update changed (detector, navigation noise,
smoother unchanged); "recommended (as shipped)" and every candidate leave out its level-stance height update
(``height_level``, measured in ``benchmarks/height_level.md``), so the heights compared are the stance updates'
own:

* ``rolling_stance`` alone in place of ``zupt`` (its defaults: σ_r 0.03 m/s as recommended's
  zero-velocity σ, the heel and toe levers learnt from an instep prior);
* ``zupt`` as shipped, then ``rolling_stance`` (its hold off: zupt's holds);
* the same two with a wider contact spread (ℓ_s 0.05 m instead of 0.02);
* ``rolling_stance`` alone with its levers fixed at the prior (no lever states learnt), and with a
  tighter lever prior (σ 0.02 m instead of 0.05).

Measured: PyShoe's 36 VICON trials (2-D with PyShoe's metric, 3-D ARMSE after a least-squares yaw
alignment, height RMS and end height per distance against VICON; medians per motion class, worst
trial), gaitmap's stride lengths against motion capture (both feet), x-io's closed loop (horizontal
and vertical closure) and Köroğlu's footprints (experiments 31–33). Nothing here chooses a setting:
the lead's nested cross-validation (issue 44 item 5) does, with these as candidates.
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

from accuracy import CLASS_ORDER, DEFAULT_DATA, motion_class  # noqa: E402

from footzoo.evaluation.metrics import armse, loop_closure, pyshoe_error, vertical_errors  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

RECOMMENDED = ROOT / "configs" / "recommended.yaml"
ZUPT = {"type": "zupt", "velocity_std": 0.03, "roll_lever": 0.2}
#: Candidate stance updates: name -> the ``corrections`` list that replaces recommended's.
CANDIDATES: dict[str, list[dict[str, Any]] | None] = {
    "recommended (as shipped)": None,
    "rolling_stance": [{"type": "rolling_stance"}],
    "zupt + rolling_stance": [ZUPT, {"type": "rolling_stance", "hold_after": 0.0}],
    "rolling_stance, ℓ_s 0.05": [{"type": "rolling_stance", "contact_spread": 0.05}],
    "rolling_stance, levers fixed": [{"type": "rolling_stance", "lever_std": 0.0, "lever_noise": 0.0}],
    "rolling_stance, lever σ 0.02": [{"type": "rolling_stance", "lever_std": 0.02}],
    "zupt + rolling_stance, ℓ_s 0.05": [ZUPT, {"type": "rolling_stance", "contact_spread": 0.05, "hold_after": 0.0}],
}


def stance_updates_only() -> dict[str, Any]:
    """``recommended.yaml`` without its level-stance height update (``height_level``): the candidates here are
    stance updates, compared on the height they make themselves (``benchmarks/height_level.md`` adds it)."""
    cfg = yaml.safe_load(RECOMMENDED.read_text())
    cfg["corrections"] = [c for c in cfg["corrections"] if c["type"] != "height_level"]
    return cfg


def config(name: str) -> dict[str, Any]:
    """``recommended.yaml``'s stance updates (:func:`stance_updates_only`) or the candidate's corrections."""
    cfg = stance_updates_only()
    if CANDIDATES[name] is not None:
        cfg["corrections"] = copy.deepcopy(CANDIDATES[name])
    cfg["name"] = name
    return cfg


def _result(name: str, rec: Any) -> Any:
    from footzoo.runtime.pipeline import Pipeline

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Pipeline.from_dict(config(name)).run(rec)


def _load(path: Path, **options: Any) -> Any:
    from footzoo.io import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(path, **options)


def over_pyshoe(rows_of: Any, data: Path, jobs: int) -> pd.DataFrame:
    """The rows ``rows_of(path)`` gives for each of PyShoe's trials in ``data``, in ``jobs`` processes, as one table."""
    files = sorted((data / "pyshoe_vicon").glob("*.mat"))
    if jobs > 1:
        from joblib import Parallel, delayed

        parts = Parallel(n_jobs=jobs)(delayed(rows_of)(f) for f in files)
    else:
        parts = [rows_of(f) for f in files]
    return pd.DataFrame([r for rows in parts for r in rows])


def pyshoe_rows(path: Path) -> list[dict[str, Any]]:
    """Every candidate on one PyShoe trial."""
    rec = _load(path, format="pyshoe")
    ref = rec.truth.pos
    rows = []
    for name in CANDIDATES:
        r = _result(name, rec)
        v = vertical_errors(r.pos, ref)
        rows.append({"trial": path.stem, "class": motion_class(path.stem), "candidate": name,
                     "2-D (m)": pyshoe_error(r.pos, ref), "3-D (m)": armse(r.pos, ref),
                     "height RMS (m)": v["height_rms_error_m"], "end height (% dist)": v["height_end_error_pct"],
                     "levers": r.diagnostics.get("contact_levers")})
    return rows


def other_rows(data: Path) -> list[dict[str, Any]]:
    """gaitmap's strides, x-io's loop and Köroğlu's footprints for every candidate."""
    rows: list[dict[str, Any]] = []
    gaitmap = data / "gaitmap_example" / "imu_sample.csv"
    for foot in ("left", "right") if gaitmap.exists() else ():
        rec = _load(gaitmap, format="gaitmap", foot=foot)
        for name in CANDIDATES:
            m = _result(name, rec).metrics
            rows.append({"reference": f"gaitmap {foot}: stride length RMS (m)", "candidate": name,
                         "value": m.get("stride_length_rms_error_m", np.nan)})
    xio = data / "xio_gait_tracking" / "short_walk.csv"
    if xio.exists():
        rec = _load(xio, format="xio")
        for name in CANDIDATES:
            r = _result(name, rec)
            c, v = loop_closure(r.pos), vertical_errors(r.pos)
            rows.append({"reference": "x-io loop: horizontal closure (m)", "candidate": name,
                         "value": c["loop_closure_xy_m"]})
            rows.append({"reference": "x-io loop: end height (m)", "candidate": name,
                         "value": v["height_end_error_m"]})
    for path in sorted((data / "koroglu_gcp").glob("SensorConnectData_*.csv")):
        rec = _load(path, format="sensorconnect")
        for name in CANDIDATES:
            m = _result(name, rec).metrics
            rows.append({"reference": f"Köroğlu {path.stem[-2:]}: footprint RMS (m)", "candidate": name,
                         "value": m.get("footprint_error_rms_m", np.nan)})
            rows.append({"reference": f"Köroğlu {path.stem[-2:]}: stride count error", "candidate": name,
                         "value": m.get("stride_count_error", np.nan)})
    return rows


def summary(t: pd.DataFrame) -> pd.DataFrame:
    """Per candidate: medians per motion class and over all trials, the worst trial."""
    out = []
    for name in CANDIDATES:
        c = t[t["candidate"] == name]
        row: dict[str, Any] = {"candidate": name}
        for cls in CLASS_ORDER:
            row[f"2-D {cls}"] = c.loc[c["class"] == cls, "2-D (m)"].median()
        row.update({"2-D median": c["2-D (m)"].median(), "2-D worst": c["2-D (m)"].max(),
                    "3-D median": c["3-D (m)"].median(), "3-D worst": c["3-D (m)"].max(),
                    "height RMS median": c["height RMS (m)"].median(),
                    "end height median (% dist)": c["end height (% dist)"].median()})
        out.append(row)
    return pd.DataFrame(out)


def levers(t: pd.DataFrame) -> pd.DataFrame:
    """The heel and toe levers ``rolling_stance`` learnt, median over the trials of each motion class."""
    out = []
    for name in CANDIDATES:
        c = t[(t["candidate"] == name) & t["levers"].notna()]
        for cls in CLASS_ORDER:
            part = c[c["class"] == cls]
            if len(part):
                heel = np.median(np.array([lv["heel"] for lv in part["levers"]]), axis=0)
                toe = np.median(np.array([lv["toe"] for lv in part["levers"]]), axis=0)
                out.append({"candidate": name, "class": cls, "heel (m)": np.round(heel, 3).tolist(),
                            "toe (m)": np.round(toe, 3).tolist()})
    return pd.DataFrame(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="folder of the reference recordings")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "rolling_stance.md", help="Markdown summary")
    args = ap.parse_args(argv)
    t0 = time.time()
    t = over_pyshoe(pyshoe_rows, args.data, args.jobs)
    others = pd.DataFrame(other_rows(args.data))
    lines = ["# Rolling-foot stance update against recommended", "",
             f"Generated by `python benchmarks/rolling_stance.py` ({(time.time() - t0) / 60:.1f} min). "
             "Each candidate is `configs/recommended.yaml` with its stance update changed, all without its "
             "level-stance height update (`height_level`, in `benchmarks/height_level.md`); lower is better. "
             "The candidates are listed in the script's docstring; nothing here selects one.", ""]
    if not t.empty:
        lines += ["## PyShoe's 36 VICON trials", "",
                  "2-D: PyShoe's metric; 3-D: ARMSE after a least-squares yaw alignment; height against VICON "
                  "(RMS over the trial, end height in % of the distance walked). Medians (m) per motion class "
                  "unless said otherwise.", "", to_markdown(summary(t), digits=3), "",
                  "Levers learnt (sensor to contact point, body frame FRD, m; medians over the trials):", "",
                  to_markdown(levers(t)), "",
                  "### Per trial, 2-D (m)", "",
                  to_markdown(t.pivot_table(index=["class", "trial"], columns="candidate", values="2-D (m)")
                              .reset_index(), digits=3), ""]
    if not others.empty:
        lines += ["## gaitmap, x-io, Köroğlu", "",
                  to_markdown(others.pivot_table(index="reference", columns="candidate", values="value",
                                                 sort=False).reset_index(), digits=3), ""]
    args.out.write_text("\n".join(lines))
    print(f"{args.out} ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
