"""Gait events against three references, for benchmarks/accuracy.py ``--parts events``.

* the simulator's truth (the toe leaving the floor, the heel touching it): a 10 m × 5 m rectangle walk
  (physical foot model, Table II noise, seed 0) at 100, 250 and 400 Hz;
* gaitmap's motion capture, both feet: TO from its event file (``stride_events_sample.csv``), IC from its heel
  marker's touch-down (``footzoo.io.gaitmap_reference.heel_touchdowns``), and the event file's IC, which marks the
  foot's largest pitch about 20 ms before it, against footzoo's ``largest_pitch_s``;
* the hand-checked IMU events of Voisard et al.'s IPOL data set (``ipol_gait``, 18 trials, both feet),
  compared inside the trial and outside the U-turn (:mod:`footzoo.io.xsens`).

Every pipeline config that runs without distance sensors is scored (``recommended`` against the targets);
the table of landmarks shows where each reference puts its events on the sagittal rate, which is where
the references disagree.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from footzoo.analysis.gait_events import contact_times, sagittal_rate, segment_argext
from footzoo.analysis.strides import real_stances
from footzoo.evaluation.metrics import gait_phase_errors, match_strides, reference_steps, stride_errors
from footzoo.runtime.pipeline import Pipeline
from footzoo.sim import NoiseModel, simulate
from footzoo.studies.report import to_markdown

#: Sampling rates of the simulated walk.
SIM_RATES = (100.0, 250.0, 400.0)
#: The configs scored (every shipped one that runs without distance sensors); the first is checked against the targets.
EVENT_CONFIGS = ("recommended", "yun2012", "huang2016", "nguyen2016", "nguyen2016_ins_zvu", "nguyen2016_ins_zvu_hdr",
                 "duong2015_zupt", "duong2015_zupt_height")
#: Targets: simulator and motion capture, median absolute error (s); hand-checked events, median bias (s).
TARGETS = {"sim_s": 0.010, "mocap_s": 0.010, "ipol_bias_s": 0.015, "gait_phase": 0.03}
#: A reference event pairs with a landmark within this distance (s).
PAIR_S = 0.15


def recordings(data: Path) -> list[tuple[str, str, dict[str, Any]]]:
    """``(reference, group, spec)`` for every recording with reference events; ``spec`` says how to make it."""
    out = [("simulator", f"{rate:g} Hz", {"simulate": {"path": "rectangle", "length": 10.0, "width": 5.0,
                                                        "rate": rate, "profile": "physical", "clearance": 0.15}})
           for rate in SIM_RATES]
    gaitmap = data / "gaitmap_example" / "imu_sample.csv"
    if gaitmap.exists() and (gaitmap.parent / "stride_events_sample.csv").exists():
        out += [("motion capture (gaitmap)", foot, {"path": gaitmap, "foot": foot}) for foot in ("left", "right")]
    for f in sorted((data / "ipol_gait").glob("*_?f.txt")):
        if f.with_name(f.stem[:-3] + ".json").exists():
            out.append(("hand-checked (IPOL)", "left" if f.stem.endswith("_lf") else "right", {"path": f}))
    return out


def _load(spec: dict[str, Any]):
    from footzoo.io import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the IPOL files' dropped packets are bridged with a warning
        if "simulate" in spec:
            return simulate(noise=NoiseModel(seed=0), **spec["simulate"])
        return load(spec["path"], **{k: v for k, v in spec.items() if k != "path"})


def _mid(t: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The middle of sample ``k``'s interval (footzoo's interval-average convention)."""
    return t[k] - 0.5 * (t[k] - t[np.maximum(k - 1, 0)])


def _crossing(t: np.ndarray, w: np.ndarray, lo: int, hi: int, level: float, up: bool) -> float:
    """When ``w`` first passes ``level`` (up or down) in samples ``(lo, hi]``, linear between interval middles."""
    for c in range(lo + 1, hi + 1):
        if (w[c - 1] < level <= w[c]) if up else (w[c - 1] > level >= w[c]):
            t0, t1 = _mid(t, np.array([c - 1, c]))
            return float(t0 + (t1 - t0) * (level - w[c - 1]) / (w[c] - w[c - 1]))
    return float("nan")


def landmarks(rec, res) -> pd.DataFrame:
    """Per swing, landmarks of the navigation-frame sagittal rate (s): the push-off peak, half-way back from it
    (footzoo's TO), its zero crossing (Rampp et al.'s terminal contact), the zero crossing after the mid-swing
    peak (the foot's largest pitch) and the rate's minimum after that (Rampp et al.'s IC, before their
    refinement); and footzoo's IC, the heel's impact after the largest pitch (``contact_times``)."""
    q = res.samples[["qw", "qx", "qy", "qz"]].to_numpy()
    pos = res.samples[["pos_n", "pos_e", "pos_d"]].to_numpy()
    st = real_stances(res.samples["stance"].to_numpy(bool), pos)
    if len(st) < 2:
        return pd.DataFrame()
    w = sagittal_rate(q, rec.gyr, pos, st)
    t, n = rec.t, rec.n
    mid = (st[:, 0] + st[:, 1] - 1) // 2
    p = segment_argext(w, np.minimum(st[:-1, 1], n - 1), np.maximum(st[1:, 0], st[:-1, 1] + 1), largest=True)
    lo = np.minimum(mid[:-1], p)
    j = segment_argext(w, lo, np.maximum(p, lo + 1), largest=False)
    mids = _mid(t, np.arange(n))
    rows = []
    for i in range(len(p)):
        if not (w[p[i]] > 0 > w[j[i]]):
            continue
        ic = _crossing(t, w, p[i], mid[i + 1], 0.0, up=False)
        k = int(np.searchsorted(mids, ic)) if np.isfinite(ic) else mid[i + 1]
        m = k + int(np.argmin(w[k:min(k + int(0.15 * rec.rate), mid[i + 1]) + 1])) if k < mid[i + 1] else k
        contact = float(contact_times(t, rec.acc, np.array([ic]), mid[i + 1:i + 2], np.array([True]), q)[0]) \
            if np.isfinite(ic) else np.nan
        rows.append({"push-off peak": float(_mid(t, np.array([j[i]]))[0]),
                     "half-way back (TO)": _crossing(t, w, j[i], p[i], 0.5 * w[j[i]], up=True),
                     "zero crossing after it": _crossing(t, w, j[i], p[i], 0.0, up=True),
                     "largest pitch (zero crossing)": ic, "minimum after it": float(_mid(t, np.array([m]))[0]),
                     "contact (IC)": contact})
    return pd.DataFrame(rows)


def _offsets(marks: pd.DataFrame, ref: pd.DataFrame) -> dict[str, np.ndarray]:
    """Reference event − landmark (s) for each landmark, paired with the nearest reference event within PAIR_S."""
    out = {}
    for col in marks.columns:
        ic_like = ("largest pitch (zero crossing)", "minimum after it", "contact (IC)")
        events = ref["end_s" if col in ic_like else "to_s"].to_numpy(float)
        x = marks[col].to_numpy(float)
        x = x[np.isfinite(x)]
        if not len(x) or not len(events):
            out[col] = np.zeros(0)
            continue
        d = events[:, None] - x[None, :]
        best = d[np.arange(len(events)), np.argmin(np.abs(d), axis=1)]
        out[col] = best[np.abs(best) <= PAIR_S]
    return out


def event_cell(reference: str, group: str, spec: dict[str, Any], config: str) -> dict[str, Any]:
    """One recording and config: paired IC and TO errors (s), counts, and (first config) the landmark offsets."""
    rec = _load(spec)
    ref = reference_steps(rec.truth.steps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = Pipeline.from_yaml(config).run(rec)
    m = match_strides(res.steps, ref)
    out = {"reference": reference, "group": group, "config": config, "strides": len(ref), "paired": len(m),
           "ic": (m["est_end_s"] - m["end_s"]).to_numpy(float), "to": (m["est_to_s"] - m["to_s"]).to_numpy(float)}
    if "largest_pitch_s" in m:  # gaitmap's event file: its IC is the foot's largest pitch
        out["largest_pitch"] = (m["est_largest_pitch_s"] - m["largest_pitch_s"]).to_numpy(float)
    if config == EVENT_CONFIGS[0]:
        out["offsets"] = _offsets(landmarks(rec, res), ref)
        if reference.startswith("motion"):
            e = stride_errors(res.steps, rec.truth.steps)
            g = gait_phase_errors(rec.t, res.steps, rec.truth.steps)
            out["gaitmap"] = {"stride length RMS (m)": e["stride_length_rms_error_m"],
                              "straight strides RMS (m)": e["stride_length_rms_error_straight_m"],
                              "gait-phase error rate": g["gait_phase_error_rate"],
                              "samples in the wrong phase": g["gait_phase_sample_error"]}
    return out


def _summary(cells: list[dict[str, Any]], by_group: bool) -> pd.DataFrame:
    """Median bias and median absolute error (ms) of IC and TO, pooled per reference × config (× group)."""
    keys = ["reference", "config"] + (["group"] if by_group else [])
    frame = pd.DataFrame(cells)
    rows = []
    for key, part in frame.groupby(keys, sort=False):
        ic, to = np.concatenate(part["ic"].tolist()), np.concatenate(part["to"].tolist())
        row = dict(zip(keys, key if isinstance(key, tuple) else (key,), strict=True))
        row.update({"IC bias (ms)": 1e3 * np.median(ic), "TO bias (ms)": 1e3 * np.median(to),
                    "IC median abs (ms)": 1e3 * np.median(np.abs(ic)),
                    "TO median abs (ms)": 1e3 * np.median(np.abs(to)),
                    "paired": f"{int(part['paired'].sum())}/{int(part['strides'].sum())}",
                    "paired (%)": 100.0 * part["paired"].sum() / max(part["strides"].sum(), 1)})
        pitch = [x for x in part.get("largest_pitch", pd.Series(dtype=object)).tolist() if isinstance(x, np.ndarray)]
        d = np.concatenate(pitch) if pitch else np.zeros(0)
        row["largest pitch − file IC, median abs (ms)"] = 1e3 * np.median(np.abs(d)) if len(d) else np.nan
        rows.append(row)
    return pd.DataFrame(rows)


def heel_marker(data: Path) -> pd.DataFrame:
    """gaitmap's foot markers around each motion-capture IC (ms after it, and speeds in m/s).

    Through cubic splines of the 100 Hz markers: when the foot's pitch (the heel→toe marker axis,
    ``FCC`` → ``TOE``, against the horizontal) is largest within ±60 ms of the IC; when the heel marker's
    descent is fastest (the minimum of its vertical velocity within ±60 ms) and when it stops (the reference's
    contact, ``footzoo.io.gaitmap_reference.heel_touchdowns``); the heel marker's horizontal speed at the IC
    and when it first falls below 0.5 m/s (a heel on the floor does not slide forward at walking speed).
    """
    from scipy.interpolate import CubicSpline

    from footzoo.io.gaitmap_reference import IMU_RATE, MOCAP_RATE, heel_touchdowns

    folder = data / "gaitmap_example"
    if not (folder / "mocap_sample.csv").exists():
        return pd.DataFrame()
    mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
    events = pd.read_csv(folder / "stride_events_sample.csv")
    rows = []
    for foot, side in (("left", "L"), ("right", "R")):
        heel = mocap[f"{side}_FCC"][["x", "y", "z"]].to_numpy() / 1000.0
        axis = mocap[f"{side}_TOE"][["x", "y", "z"]].to_numpy() / 1000.0 - heel
        t = np.arange(len(heel)) / MOCAP_RATE
        velocity = CubicSpline(t, heel).derivative()
        pitch = CubicSpline(t, np.arctan2(axis[:, 2], np.hypot(axis[:, 0], axis[:, 1])))
        for ic in events.loc[events.foot == foot, "ic"].to_numpy() / IMU_RATE:
            fine = ic + np.arange(-0.06, 0.1, 0.001)
            v = velocity(fine)
            k = int(np.argmin(np.where(fine <= ic + 0.06, v[:, 2], np.inf)))
            touchdown = heel_touchdowns(heel[:, 2], np.array([ic]))[0]  # the reference's IC (the reader's rule)
            horizontal = np.hypot(v[:, 0], v[:, 1])
            slow = int(np.argmax((fine >= ic) & (horizontal < 0.5)))
            near = fine <= ic + 0.06
            rows.append({"foot": foot, "largest pitch (ms)": 1e3 * (fine[near][np.argmax(pitch(fine[near]))] - ic),
                         "fastest descent (ms)": 1e3 * (fine[k] - ic), "speed (m/s)": -v[k, 2],
                         "stopped (ms)": 1e3 * (touchdown - ic),
                         "horizontal speed at IC (m/s)": float(np.hypot(*velocity(ic)[:2])),
                         "below 0.5 m/s (ms)": 1e3 * (fine[slow] - ic)})
    return pd.DataFrame(rows)


def _target(rows: list[dict[str, str]], what: str, bound: str, value: float, met: bool) -> None:
    rows.append({"target": what, "bound": bound, "measured": f"{value:+.1f}" if "bias" in what else f"{value:.1f}",
                 "met": "yes" if met else "**no**"})


def events(data: Path, jobs: int = 1) -> list[str]:
    """The events part's Markdown: targets, errors per reference and config, landmarks, gaitmap's strides."""
    from joblib import Parallel, delayed

    recs = recordings(data)
    cells = Parallel(n_jobs=jobs)(delayed(event_cell)(r, g, s, c) for r, g, s in recs for c in EVENT_CONFIGS)
    flagship = [c for c in cells if c["config"] == EVENT_CONFIGS[0]]
    per_group = _summary(flagship, by_group=True)
    pooled = _summary(cells, by_group=False)
    tg: list[dict[str, str]] = []
    for _, r in per_group.iterrows():
        ms = 1e3 * TARGETS["sim_s"]
        if r["reference"] == "simulator":
            for ev in ("IC", "TO"):
                v = r[f"{ev} median abs (ms)"]
                _target(tg, f"simulator {r['group']}: {ev} median abs error (ms)", f"≤ {ms:.0f} ms", v, v <= ms)
        elif r["reference"].startswith("motion"):
            for ev in ("IC", "TO"):
                v = r[f"{ev} median abs (ms)"]
                _target(tg, f"motion capture, {r['group']} foot: {ev} median abs error (ms)",
                        f"≤ {1e3 * TARGETS['mocap_s']:.0f} ms", v, v <= 1e3 * TARGETS["mocap_s"])
            cell = next(c for c in flagship if c["reference"] == r["reference"] and c["group"] == r["group"])
            v = 1e3 * np.median(np.abs(cell["largest_pitch"]))
            _target(tg, f"motion capture, {r['group']} foot: largest pitch against the event file's IC, median abs "
                    "error (ms)", f"≤ {1e3 * TARGETS['mocap_s']:.0f} ms", v, v <= 1e3 * TARGETS["mocap_s"])
        else:
            for ev in ("IC", "TO"):
                v = r[f"{ev} bias (ms)"]
                b = 1e3 * TARGETS["ipol_bias_s"]
                _target(tg, f"hand-checked (IPOL), {r['group']} foot: {ev} median bias (ms)", f"within ±{b:.0f} ms",
                        v, abs(v) <= b)
    gm = [dict(c["gaitmap"], foot=c["group"]) for c in flagship if "gaitmap" in c]
    for g in gm:
        v = g["gait-phase error rate"]
        _target(tg, f"gaitmap {g['foot']}: gait-phase error rate (Nguyen & La), %",
                f"≤ {100 * TARGETS['gait_phase']:.0f} %", 100 * v, v <= TARGETS["gait_phase"])
    marks = []
    for reference in dict.fromkeys(c["reference"] for c in flagship):
        offsets = [c["offsets"] for c in flagship if c["reference"] == reference and (
            reference != "simulator" or c["group"] == f"{SIM_RATES[0]:g} Hz")]
        row: dict[str, Any] = {"reference": reference if reference != "simulator" else f"simulator {SIM_RATES[0]:g} Hz"}
        for col in offsets[0]:
            d = np.concatenate([o[col] for o in offsets])
            row[col] = 1e3 * np.median(d) if len(d) else np.nan
        marks.append(row)
    lines = [
        "### Gait events against three references", "",
        "Events from the navigation-frame sagittal rate and the specific force (docs/gait-events.md): TO where "
        "the rate, recovering from its push-off peak, is back at half of it; IC at the heel's impact after the "
        "foot's largest pitch (the rate's zero crossing after the mid-swing peak). References: the simulator's "
        "truth (the toe leaving the floor, the heel touching it; a 10 m × 5 m rectangle, physical foot model, "
        "Table II noise), gaitmap's motion capture (TO from its event file, IC from its heel marker's touch-down, "
        "the event file's IC against footzoo's largest pitch), and the "
        "hand-checked IMU events of Voisard et al.'s IPOL data set (18 trials, both feet, inside the trial and "
        "outside the U-turn). Errors are "
        "estimate − reference; strides pair when both their TO and IC agree within 0.3 s.", "",
        f"`{EVENT_CONFIGS[0]}` against the targets:", "", to_markdown(pd.DataFrame(tg)), "",
        "#### Per reference and group", "", to_markdown(per_group.drop(columns="config"), digits=3), "",
        "#### Every config, pooled per reference", "",
        "The simulator rows pool the three rates, the others both feet.", "", to_markdown(pooled, digits=3), "",
        "#### Where each reference puts its events on the sagittal rate", "",
        "Median of reference event − landmark (ms; positive: the reference is later), landmarks of the rate "
        f"`{EVENT_CONFIGS[0]}` estimates: TO against the push-off peak, the half-way point (footzoo's TO) and "
        "the zero crossing after it (Rampp et al.'s terminal contact); IC against the zero crossing after the "
        "mid-swing peak (the foot's largest pitch), the rate's minimum after it (Rampp et al.'s IC before its "
        "acceleration refinement) and the heel's impact (footzoo's IC). The simulated push-off holds its peak "
        "rate over the last 60 % of the pre-swing, so its peak sample falls anywhere in it. The references "
        "agree on TO. On IC, the hand-checked events and the motion capture's heel marker put the touch-down "
        "about 20 ms after the largest pitch, at the impact; gaitmap's event file marks the largest pitch itself "
        "(footzoo's `largest_pitch_s` against it: the targets above; its markers: below). The "
        "simulated foot touches down at its largest pitch and lands without an impact, so footzoo's IC "
        "finds the loading response's onset a few milliseconds after it.", "",
        to_markdown(pd.DataFrame(marks), digits=3), ""]
    heel = heel_marker(data)
    if len(heel):
        med = heel.median(numeric_only=True)
        lines += ["#### gaitmap's foot markers at the event file's IC", "",
                  f"Median over {len(heel)} initial contacts (`heel_marker`): the foot's pitch is largest "
                  f"{med['largest pitch (ms)']:+.0f} ms from the event file's IC (the rate's zero crossing); "
                  f"there the heel marker still moves forward at "
                  f"{med['horizontal speed at IC (m/s)']:.1f} m/s and goes down, fastest "
                  f"{med['fastest descent (ms)']:.0f} ms after the IC ({med['speed (m/s)']:.2f} m/s); its descent "
                  f"stops {med['stopped (ms)']:.0f} ms after it, and its horizontal speed falls below 0.5 m/s "
                  f"{med['below 0.5 m/s (ms)']:.0f} ms after it. The event file's IC marks the end of the "
                  "swing's dorsi-flexion, not the heel's touch-down: the markers put the touch-down about 20 ms "
                  "later, where the hand-checked events and footzoo's IC (the impact) put it.", ""]
    if gm:
        lines += ["#### gaitmap's walk: strides and gait phases", "",
                  "Gait phases: stance IC → TO, scored from 0.3 s before the first reference toe-off to 0.3 s after "
                  "the last contact, without the left foot's turn stride (one reference stride over two steps).", "",
                  to_markdown(pd.DataFrame(gm)[["foot", *[k for k in gm[0] if k != "foot"]]], digits=3), ""]
    return lines
