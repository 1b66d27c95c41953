"""Recordings relabelled with a wrong rate or unit: does each end in a warning or an error naming the right fix?

Usage: python benchmarks/relabel.py [--data ../shared/data] [--configs recommended,yun2012]
                                    [--out benchmarks/relabel.md] [--only pyshoe,gaitmap,xio,koroglu,ipol]

Every visible recording with a reader (PyShoe's 36 VICON trials, gaitmap's example walk with each
foot, x-io's short walk, Köroğlu's experiments 31–33, IPOL's 18 trials with each foot) and simulated walks,
runs and stairs (:data:`SIMULATED`, each at 100, 250 and 400 Hz, with the simulator's sensor noise) are run
by each config. The table is given for three groups: the 42 recordings the checks were designed on (PyShoe,
gaitmap, x-io, Köroğlu), IPOL's 36 (Xsens MTw at 100 Hz, other subjects: never used to choose a rule or a
number) and the simulated ones. The cases:

* **as recorded** — a warning or an error that names a wrong rate or unit here is a false positive;
* **rate ×F** — declared at ``F`` times its real rate, for F = 2, ½, 1.5 (the cases the checks must
  name) and 2/3, 1.2 (beyond them): *with time stamps* the recording's time stamps divided by ``F``;
  *without* (``rate only``) the time is the row number over the declared rate, as a sidecar's
  ``time: {rate: ...}`` or a reader's ``rate`` option gives it (gaps and repeated rows then vanish);
* **gyroscope unit** — the values in the recording's gyroscope unit declared in the other one
  (rad/s as deg/s, or deg/s as rad/s);
* **accelerometer unit** — the values in the recording's accelerometer unit declared in each other
  one of m/s², g and mg.

A case is *caught* when a :class:`~footzoo.core.errors.SensorWarning` of the gait's plausibility
(:mod:`footzoo.core.plausibility`) names a rate or a gyroscope unit, or building the recording
raises a :class:`~footzoo.core.errors.RecordingError` about a unit; the fix is *right* when the
named rate is the real one within 3 % (``likely_rate``; *right, as the alternative* when it is the
``alternative_rate``) or the message declares the real unit. The table also counts the other
warnings of each case (mounting, gaps, drift while still, ...), which are not fixes.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from footzoo.core import plausibility  # noqa: E402
from footzoo.core.conventions import ACC_UNITS, GYR_UNITS  # noqa: E402
from footzoo.core.data import Recording  # noqa: E402
from footzoo.core.errors import FootzooError  # noqa: E402
from footzoo.core.plausibility import likely_rate  # noqa: E402
from footzoo.sim import NoiseModel, simulate  # noqa: E402

DEFAULT_DATA = ROOT.parent / "shared" / "data"
DEFAULT_OUT = ROOT / "benchmarks" / "relabel.md"
#: The rate factors the checks must name, and those beyond.
REQUIRED = (2.0, 0.5, 1.5)
BEYOND = (2.0 / 3.0, 1.2)
#: The units each dataset's files hold (accelerometer, gyroscope).
NATIVE = {"pyshoe": ("m/s^2", "rad/s"), "gaitmap": ("m/s^2", "deg/s"), "xio": ("g", "deg/s"),
          "koroglu": ("g", "rad/s"), "ipol": ("m/s^2", "rad/s"), "sim": ("m/s^2", "rad/s")}
#: Simulated recordings: name -> simulate() arguments; each at every rate of SIMULATED_RATES (Hz).
#: Walking at the simulator's slow, normal and fast speeds, a short-stepped shuffle (0.5 m strides, 3 cm of
#: clearance), a run at 3.2 m/s and stairs (up, a landing, down), with the physical foot model.
SIMULATED = {"slow walk": {"path": "mixed_speed", "speeds": [("slow", 16)]},
             "walk": {"path": "mixed_speed", "speeds": [("normal", 16)]},
             "fast walk": {"path": "mixed_speed", "speeds": [("fast", 16)]},
             "shuffle": {"n_strides": 24, "stride_length": 0.5, "cycle": 1.1, "clearance": 0.03},
             "run": {"path": "run", "n_strides": 24},
             "stairs": {"path": "stairs", "n_strides": 6, "landing_strides": 3, "cycle": 1.2, "clearance": 0.1}}
SIMULATED_RATES = (100.0, 250.0, 400.0)
#: The groups of datasets the tables are given for.
GROUPS = {"the 42 recordings the checks were designed on": ("pyshoe", "gaitmap", "xio", "koroglu"),
          "IPOL's 36 recordings (held out: never used to choose a rule or a number)": ("ipol",),
          "simulated (18)": ("sim",)}
ACC_CHOICES = ("m/s^2", "g", "mg")
GYR_CHOICES = ("rad/s", "deg/s")


def simulated() -> Iterator[tuple[str, Recording]]:
    """("sim", recording) of each simulated walk of :data:`SIMULATED` at each rate of :data:`SIMULATED_RATES`."""
    for seed, (name, kwargs) in enumerate(SIMULATED.items()):
        for rate in SIMULATED_RATES:
            rec = simulate(profile="physical", rate=rate, noise=NoiseModel(seed=seed), magnetometer=False, **kwargs)
            yield "sim", Recording(t=rec.t, acc=rec.acc, gyr=rec.gyr, meta={"name": f"{name} {rate:g} Hz"})


def recordings(data: Path, only: set[str] | None = None) -> Iterator[tuple[str, Recording]]:
    """(dataset, recording) of every visible recording, read by footzoo's readers (absent datasets skipped), and
    the simulated ones (dataset ``sim``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if (only is None or "pyshoe" in only) and (data / "pyshoe_vicon").is_dir():
            for f in sorted((data / "pyshoe_vicon").glob("*.mat")):
                yield "pyshoe", footzoo.load(f)
        if (only is None or "gaitmap" in only) and (data / "gaitmap_example" / "imu_sample.csv").exists():
            for foot in ("left", "right"):
                yield "gaitmap", footzoo.load(data / "gaitmap_example" / "imu_sample.csv", foot=foot)
        if (only is None or "xio" in only) and (data / "xio_gait_tracking" / "short_walk.csv").exists():
            yield "xio", footzoo.load(data / "xio_gait_tracking" / "short_walk.csv")
        if (only is None or "koroglu" in only) and (data / "koroglu_gcp").is_dir():
            for f in sorted((data / "koroglu_gcp").glob("SensorConnectData_*.csv")):
                yield "koroglu", footzoo.load(f)
        if (only is None or "ipol" in only) and (data / "ipol_gait").is_dir():
            for f in sorted((data / "ipol_gait").glob("*_[lr]f.txt")):
                yield "ipol", footzoo.load(f)
    if only is None or "sim" in only:
        yield from simulated()


def cases(dataset: str, rec: Recording) -> Iterator[dict[str, Any]]:
    """Every relabelling of ``rec``: ``case``, ``kind``, the arrays as declared and what the right fix is."""
    nominal = likely_rate(rec.rate, 1.0)
    base = {"t": rec.t, "acc": rec.acc, "gyr": rec.gyr}
    yield {"case": "as recorded", "kind": "clean", **base, "rate": nominal}
    for f in (*REQUIRED, *BEYOND):
        label = f"{f:.3g}" if f not in (0.5, 2.0 / 3.0) else {0.5: "½", 2.0 / 3.0: "2/3"}[f]
        yield {"case": f"rate ×{label}, time stamps", "kind": "rate", "factor": f, "rate": nominal,
               **base, "t": rec.t / f}
        yield {"case": f"rate ×{label}, rate only", "kind": "rate", "factor": f, "rate": nominal,
               **base, "t": np.arange(rec.n) / (nominal * f)}
    acc_unit, gyr_unit = NATIVE[dataset]
    for declared in GYR_CHOICES:
        if declared != gyr_unit:
            scale = GYR_UNITS[declared] / GYR_UNITS[gyr_unit]
            yield {"case": f"gyroscope {gyr_unit} declared {declared}", "kind": "gyr", "unit": gyr_unit,
                   "rate": nominal, **base, "gyr": rec.gyr * scale}
    for declared in ACC_CHOICES:
        if declared != acc_unit:
            scale = ACC_UNITS[declared] / ACC_UNITS[acc_unit]
            yield {"case": f"accelerometer {acc_unit} declared {declared}", "kind": "acc", "unit": acc_unit,
                   "rate": nominal, **base, "acc": rec.acc * scale}


def classify(message: str) -> str:
    """The kind of a warning, by its wording."""
    for key, words in (("rate", "is probably sampled at"), ("gyro unit", "look like rad/s declared as deg/s"),
                       ("axis sign", "has the wrong sign"), ("mounting", "Result.diagnostics['mounting']"),
                       ("gaps", "gap(s) in the time stamps"), ("still drift", "misses this stillness"),
                       ("still creep", "so the detector is not the cause"), ("no stance", "no stance from"),
                       ("acc scale", "its unit or scale is wrong"), ("guard", "found no stance for"),
                       ("speed", "the estimated foot speed"), ("glitch", "spike(s)"), ("saturation", "saturated"),
                       ("duplicates", "whose time stamp repeats"), ("restless start", "too restless to tell a gain")):
        if words in message:
            return key
    return "other"


@contextmanager
def judgements() -> Iterator[list[tuple[Any, Any, dict[str, Any]]]]:
    """Every judgement of the rate while the block runs: (strides, gyroscope–accelerometer evidence, verdict) of
    each call of :func:`footzoo.core.plausibility.judge_rate` (what the checks measured, named or not)."""
    calls: list[tuple[Any, Any, dict[str, Any]]] = []
    judge = plausibility.judge_rate

    def recorded(gait: Any, evidence: Any) -> dict[str, Any]:
        verdict = judge(gait, evidence)
        calls.append((gait, evidence, verdict))
        return verdict

    plausibility.judge_rate = recorded
    try:
        yield calls
    finally:
        plausibility.judge_rate = judge


def measured(calls: list[tuple[Any, Any, dict[str, Any]]], factor: float) -> dict[str, Any]:
    """What the last judgement of a run measured, for a case declared at ``factor`` times the real rate (1: as
    recorded): the strides' medians, the residuals at the declared and the real time scale and where they are
    lowest, and why no rate (or another one) was named."""
    if not calls:
        return {"why": "no judgement: fewer than 6 strides and 4 swings"}
    gait, evidence, verdict = calls[-1]
    out: dict[str, Any] = {}
    if gait is not None:
        out.update(strides=gait["strides"], cadence=gait["cadence_steps_min"], length=gait["stride_length_m"],
                   clearance=gait["clearance_m"], rolling=gait["rolling_m_rad"], peak=gait["peak_rate_rad_s"])
    costs, fit = verdict["costs"], plausibility.consistency_costs(evidence)
    if evidence is not None:
        order = np.argsort(evidence["scales"])
        scales, residual = evidence["scales"][order], evidence["residual"][order]
        out.update(swings=evidence["swings"], residual=float(residual[np.searchsorted(scales, 1.0)]),
                   at_real=float(np.exp(np.interp(np.log(factor), np.log(scales), np.log(residual)))),
                   lowest_at=float(scales[np.argmin(residual)]))
    best = min(plausibility.FACTORS, key=costs.get)
    if verdict["factor"] is not None:
        why = f"named ×{verdict['factor']:.3g}: its residual is the lowest on that side of 1"
    elif evidence is None:
        why = f"{'no' if gait is None else 'fewer than 4'} swings: the gait alone names no rate"
    elif costs[1.0] <= costs[best]:
        why = "the declared rate costs the least"
    elif costs[1.0] - costs[best] < plausibility.MARGIN:
        why = (f"the declared rate costs {costs[1.0] - costs[best]:.1f} more than the best (×{best:.3g}), "
               f"below the margin {plausibility.MARGIN:g}")
    else:
        why = (f"×{best:.3g} costs {costs[1.0] - costs[best]:.1f} less, but the residuals prefer it by "
               f"{fit[1.0] - fit[best]:.1f} only (support {plausibility.SUPPORT:g})")
    if gait is not None and not verdict["gait_informative"]:
        why += "; no rate makes the gait human (the gait is no evidence)"
    return {**out, "why": why}


def run_case(pipeline: footzoo.Pipeline, name: str, case: dict[str, Any]) -> dict[str, Any]:
    """Run one case; what was named and whether it is the right fix, and what the checks measured."""
    row = {"recording": name, "case": case["case"], "kind": case["kind"], "caught": False, "right": False,
           "alternative": False, "named": "", "others": ""}
    with warnings.catch_warnings(record=True) as found, judgements() as calls:
        warnings.simplefilter("always")
        try:
            rec = Recording(t=case["t"], acc=case["acc"], gyr=case["gyr"], meta={"name": name})
            result = pipeline.run(rec)
        except FootzooError as err:
            text = str(err)
            row["named"] = text[:160]
            row["caught"] = "unit" in text or "looks like" in text
            if case["kind"] in ("acc", "gyr"):
                row["right"] = f"declare {case['kind']}_unit: {case['unit']}" in text
            return row
    messages = [str(w.message) for w in found if w.category.__module__.startswith("footzoo")]
    kinds = [classify(m) for m in messages]
    plaus = result.diagnostics.get("sensor", {}).get("plausibility", {})
    if "rate" in plaus:
        finding = plaus["rate"]
        row.update(caught=True, named=f"rate {finding['likely_rate']:g} Hz"
                   + (f" (or {finding['alternative_rate']:g})" if "alternative_rate" in finding else ""))
        if case["kind"] == "rate":
            real = case["rate"]
            row["right"] = abs(finding["likely_rate"] / real - 1.0) <= 0.03
            row["alternative"] = (not row["right"] and "alternative_rate" in finding
                                  and abs(finding["alternative_rate"] / real - 1.0) <= 0.03)
    if "gyro_unit" in plaus:
        row.update(caught=True, named="gyroscope rad/s declared deg/s")
        row["right"] = case["kind"] == "gyr" and case["unit"] == "rad/s"
    row["others"] = ", ".join(f"{k}×{n}" if n > 1 else k
                              for k, n in sorted(Counter(k for k in kinds if k not in ("rate", "gyro unit")).items()))
    if case["kind"] in ("clean", "rate"):
        row.update(measured(calls, case.get("factor", 1.0)))
    return row


def summarise(table: pd.DataFrame) -> pd.DataFrame:
    """Per case: recordings, false positives (as recorded) or caught, right fix (of them as the alternative), wrong
    fix, missed, and the cases with other warnings."""
    rows = []
    for case, g in table.groupby("case", sort=False):
        clean = g["kind"].iloc[0] == "clean"
        right = int((g["right"] | g["alternative"]).sum())
        alternative = int(g["alternative"].sum())
        rows.append({"case": case, "recordings": len(g),
                     "false positives": int(g["caught"].sum()) if clean else "",
                     "caught": "" if clean else int(g["caught"].sum()),
                     "right fix": "" if clean else f"{right}" + (f" ({alternative} as the alternative)"
                                                                 if alternative else ""),
                     "wrong fix": "" if clean else int((g["caught"] & ~g["right"] & ~g["alternative"]).sum()),
                     "missed": "" if clean else int((~g["caught"]).sum()),
                     "other warnings": int((g["others"] != "").sum())})
    return pd.DataFrame(rows, dtype=object)


def markdown(df: pd.DataFrame) -> str:
    """A DataFrame as a Markdown table."""
    head = "| " + " | ".join(map(str, df.columns)) + " |\n|" + "---|" * len(df.columns) + "\n"
    return head + "".join("| " + " | ".join(str(v) for v in row) + " |\n" for row in df.itertuples(index=False))


#: The columns of what the checks measured (:func:`measured`) and their headings.
MEASURED = {"strides": "strides", "cadence": "steps/min", "length": "stride (m)", "clearance": "clearance (m)",
            "rolling": "m/rad", "peak": "peak ω (rad/s)", "swings": "swings", "residual": "residual as declared",
            "at_real": "at the real rate", "lowest_at": "lowest at scale", "why": "why"}


def measurements(table: pd.DataFrame, rows: pd.Series) -> pd.DataFrame:
    """What the checks measured on the cases ``rows`` and on the same recordings as recorded (first)."""
    names = set(table.loc[rows, "recording"])
    shown = table[rows | ((table["kind"] == "clean") & table["recording"].isin(names))]
    shown = shown.sort_values("recording", kind="stable").reindex(columns=["recording", "case", *MEASURED])

    def cell(column: str, value: Any) -> str:
        if not isinstance(value, str) and pd.isna(value):
            return ""
        if column in ("strides", "swings"):
            return f"{int(value)}"
        return value if isinstance(value, str) else f"{value:.3g}"

    return pd.DataFrame([{"recording": r["recording"], "case": r["case"],
                          **{MEASURED[c]: cell(c, r[c]) for c in MEASURED}} for _, r in shown.iterrows()],
                        dtype=object)


def write(tables: dict[str, pd.DataFrame], path: Path, elapsed: float) -> None:
    lines = ["# Relabelled recordings: a wrong rate or unit, named with its fix",
             "",
             "Written by `python benchmarks/relabel.py` (see its docstring for the cases and the rules); "
             f"{elapsed:.0f} s. Every visible recording with a reader, as recorded and relabelled: *rate ×F* is "
             "declared at F times its real rate, with its time stamps divided by F (*time stamps*) or with the time "
             "given only by the declared rate (*rate only*); a unit case declares the values in another unit. "
             "*Caught*: a warning of the gait's plausibility names a rate or a gyroscope unit, or an error names a "
             "unit; *right fix*: the named rate is the real one within 3 % (or the named alternative is), or the "
             "message declares the real unit. *Other warnings*: cases with any other footzoo warning (mounting, "
             "gaps, drift while still, ...), counted, not fixes.",
             "",
             "For each required case without the right fix, the last table of a config gives what the checks "
             "measured (the last judgement of the run, `footzoo.core.plausibility`), and the same recording as "
             "recorded: the strides' medians as declared (cadence, length, clearance, length per radian the foot "
             "turns, peak angular rate), the swings of the gyroscope–accelerometer scan and their median residual "
             "(`footzoo.filters.consistency`) with the time as declared, scaled to the real rate and where it is "
             "lowest, and why no rate or another one was named. The analysis of these cases is in "
             "`benchmarks/relabel_misses.md`.", ""]
    for config, table in tables.items():
        lines += [f"## `{config}`", ""]
        for group, datasets in GROUPS.items():
            part = table[table["dataset"].isin(datasets)]
            if not len(part):
                continue
            clean = part[part["kind"] == "clean"]
            lines += [f"### {group}", "",
                      f"False positives on the {len(clean)} recordings as recorded: **{int(clean['caught'].sum())}**.",
                      "", markdown(summarise(part)), ""]
        unright = (table["kind"] != "clean") & ~(table["right"] | table["alternative"])
        required = table["kind"].isin(["acc", "gyr"]) | table["case"].str.contains("|".join(
            f"×{label}," for label in ("2", "½", "1.5")))
        for title, rows in (("The required cases (×2, ×½, ×1.5, units) without the right fix:", unright & required),
                            ("A wrong fix named in the other cases:", unright & ~required & table["caught"])):
            if rows.any():
                bad = table[rows].assign(named=lambda d: d["named"].where(d["named"] != "", "(nothing)"))
                lines += [title, "", markdown(bad[["recording", "case", "named", "others"]].rename(
                    columns={"named": "named instead", "others": "other warnings"})), ""]
        clean = table[table["kind"] == "clean"]
        fp = clean[clean["caught"]]
        if len(fp):
            lines += ["False positives:", "", markdown(fp[["recording", "named", "others"]]), ""]
        if (unright & required).any():
            lines += ["What the checks measured on the required cases without the right fix (and as recorded):", "",
                      markdown(measurements(table, unright & required)), ""]
    path.write_text("\n".join(lines))


def run(data: Path, configs: list[str], only: set[str] | None = None) -> dict[str, pd.DataFrame]:
    """Every case of every recording, for each config: one row per case."""
    recs = list(recordings(data, only))
    out = {}
    for config in configs:
        pipeline = footzoo.Pipeline.from_yaml(config)
        rows = []
        for dataset, rec in recs:
            for case in cases(dataset, rec):
                rows.append({"dataset": dataset, **run_case(pipeline, rec.name, case)})
            print(f"{config}: {rec.name}", file=sys.stderr, flush=True)
        out[config] = pd.DataFrame(rows)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--configs", default="recommended,yun2012", help="comma-separated shipped configs or files")
    ap.add_argument("--only", default=None, help="comma-separated datasets: pyshoe, gaitmap, xio, koroglu, ipol, sim")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--csv", type=Path, default=None, help="a folder for one CSV per config: every case's row")
    args = ap.parse_args(argv)
    start = time.perf_counter()
    tables = run(args.data, args.configs.split(","), set(args.only.split(",")) if args.only else None)
    if not any(len(t) for t in tables.values()):
        print(f"no recordings under {args.data}", file=sys.stderr)
        return 1
    write(tables, args.out, time.perf_counter() - start)
    for config, table in tables.items():
        if args.csv is not None:
            table.to_csv(args.csv / f"relabel_{Path(config).stem}.csv", index=False)
        print(config)
        print(summarise(table).to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
