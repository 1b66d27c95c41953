"""Where the stride-length error on gaitmap's example walk comes from.

Usage: python benchmarks/gaitmap_strides.py [--data ../shared/data] [--configs recommended,yun2012,huang2016]
                                            [--out benchmarks/gaitmap_strides.md]

The accuracy benchmark scores each config's stride lengths on gaitmap's example walk against the motion
capture (``stride_length_rms_error_m`` of :func:`footzoo.evaluation.metrics.stride_errors`). This script
takes the same matched strides (:func:`footzoo.evaluation.metrics.match_strides`) and measures, per foot:

1. **The split of the error**: mean signed error (bias) and standard deviation (scatter); straight and
   turn strides; without the first and last matched strides; the correlation of consecutive strides'
   errors (a footprint misplaced by the estimate lengthens one stride and shortens the next: negative).
2. **The definitions**: footzoo's stride length is the horizontal distance the *sensor* moved between the
   *middles of two detected stances*; the reference's (:mod:`footzoo.io.gaitmap_reference`, gaitmap's
   ``SpatialParameterCalculation``) is the horizontal distance the *heel marker* moved between the event
   file's *minimum-velocity instants*. Each difference is swapped in turn: the estimate read at the
   reference's instants; the reference from the toe marker, the fifth-metatarsal marker or the three
   markers' centroid (nearer the sensor); the reference in 3-D instead of 2-D.
3. **The filter**: every stride integrated again without footzoo's filter, detector or smoother
   (:func:`integrate_stride`: attitude from gravity at the first mid-stance, gyroscope strapdown, velocity
   dedrifted linearly to zero at the second mid-stance, as gaitmap's own forward integration does). If its
   per-stride errors follow the configs', the scatter is in the recording, not in the pipeline.
4. **The sensor's range**: the strides whose heel impact reaches the accelerometer's ±16 g range (an axis
   above 150 m/s²) against the others.
5. **The gyroscope's scale**: the least-squares ratio of the pitch rate of two marker axes (heel→toe,
   heel→fifth metatarsal) to the gyroscope's sagittal rate (gaitmap's ``gyr_y``, sign turned so that both
   agree), and the integration of part 3 again with the gyroscope scaled by 1.07.
6. **The components**: one config's stance detector swapped for another's (:data:`SWAPS`), RMS and bias.

Nothing here changes a config; the numbers are measurements.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from footzoo.core.conventions import (  # noqa: E402
    GRAVITY,
    gravity_ned,
    quat_from_euler,
    quat_from_rotvec,
    quat_mul,
    quat_rotate,
    tilt_from_specific_force,
)
from footzoo.io.gaitmap_reference import IMU_RATE, MOCAP_RATE  # noqa: E402

if TYPE_CHECKING:
    from footzoo.core.data import Recording

FOLDER = "gaitmap_example"
CONFIGS = ("recommended", "yun2012", "huang2016")
#: Marker sets the reference may be computed from (gaitmap's names, per foot "L_"/"R_").
MARKERS = {"heel (FCC)": ("FCC",), "toe": ("TOE",), "5th metatarsal (FM5)": ("FM5",),
           "centroid of the three": ("FCC", "TOE", "FM5")}
#: An accelerometer axis above this (m/s²) is at the ±16 g range (the file's peaks stop at 156-158).
AT_RANGE = 150.0
#: Gyroscope scale tried in part 5 (the heel→toe axis's pitch rate against the gyroscope's).
GYRO_SCALE = 1.07
#: Part 6: (config, the config lending its stance detector).
SWAPS = (("recommended", "huang2016"), ("yun2012", "huang2016"), ("huang2016", "yun2012"))
#: Half-width (s) of the window a still position or a still specific force is averaged over.
HALF_WINDOW = 0.05


def rms(x: np.ndarray) -> float:
    """Root mean square of the finite values (NaN when there is none)."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x**2))) if x.size else float("nan")


def integrate_stride(t: np.ndarray, acc: np.ndarray, gyr: np.ndarray, t0: float, t1: float,
                     g: float = GRAVITY) -> np.ndarray:
    """Horizontal displacement (m, north and east) of the sensor from a still instant ``t0`` to the next ``t1``.

    No filter: roll and pitch from the mean specific force within :data:`HALF_WINDOW` of ``t0`` (yaw 0),
    the attitude propagated by the gyroscope (one rotation vector per sample), the specific force turned
    into NED and gravity added, the velocity integrated from zero and dedrifted linearly so that it is
    zero again at ``t1``, then integrated into position (rectangle rule).

    Parameters
    ----------
    t : (N,) ndarray
        Time (s), uniform.
    acc, gyr : (N, 3) ndarray
        Specific force (m/s²) and angular rate (rad/s), FRD sensor frame.
    t0, t1 : float
        Two instants (s) the sensor is still at, ``t0 < t1``.
    g : float
        Gravity (m/s²).
    """
    if not t0 < t1:
        raise ValueError(f"integrate_stride: t0 must come before t1, got t0={t0} s, t1={t1} s")
    i0, i1 = (int(i) for i in np.searchsorted(t, [t0, t1]))
    dt = float(np.median(np.diff(t)))
    half = max(int(round(HALF_WINDOW / dt)), 1)
    roll, pitch = tilt_from_specific_force(acc[max(i0 - half, 0):i0 + half].mean(axis=0))
    steps = quat_from_rotvec(gyr[i0:i1] * dt)
    q = [quat_from_euler(np.array(roll), np.array(pitch), np.array(0.0))]
    for dq in steps:
        q.append(quat_mul(q[-1], dq))
    a = quat_rotate(np.array(q), acc[i0:i1 + 1]) + gravity_ned(g)
    v = np.cumsum(a, axis=0) * dt
    v -= np.linspace(0.0, 1.0, len(v))[:, None] * v[-1]
    return (np.sum(v, axis=0) * dt)[:2]


def pitch_rate_ratio(folder: Path, foot: str, toward: str) -> float:
    """Least-squares ratio of the pitch rate of the heel→``toward`` marker axis to the gyroscope's sagittal rate."""
    imu = pd.read_csv(folder / "imu_sample.csv", header=[0, 1], index_col=0)
    axis = marker_positions(folder, foot, (toward,)) - marker_positions(folder, foot, ("FCC",))
    pitch = np.unwrap(np.arctan2(axis[:, 2], np.hypot(axis[:, 0], axis[:, 1])))
    marker = np.gradient(pitch, 1.0 / MOCAP_RATE)
    t = np.arange(len(axis)) / MOCAP_RATE
    gyro = np.radians(np.interp(t, np.arange(len(imu)) / IMU_RATE, -imu[f"{foot}_sensor"]["gyr_y"].to_numpy()))
    ok = np.isfinite(marker)
    return float(np.sum(gyro[ok] * marker[ok]) / np.sum(gyro[ok] ** 2))


def marker_positions(folder: Path, foot: str, names: tuple[str, ...]) -> np.ndarray:
    """Mean position (m, lab frame, z up, 100 Hz) of the named markers of one foot."""
    mocap = pd.read_csv(folder / "mocap_sample.csv", header=[0, 1], index_col=0)
    side = "L" if foot == "left" else "R"
    return np.mean([mocap[f"{side}_{n}"][["x", "y", "z"]].to_numpy() / 1000.0 for n in names], axis=0)


def displacement(pos: np.ndarray, t0: np.ndarray, t1: np.ndarray, rate: float) -> np.ndarray:
    """Displacements (K, 3) of ``pos`` (sampled at ``rate`` Hz) between the :data:`HALF_WINDOW` means at t0 and t1."""
    half = max(int(round(HALF_WINDOW * rate)), 1)

    def at(t: float) -> np.ndarray:
        k = int(round(t * rate))
        return pos[max(k - half, 0):k + half].mean(axis=0)

    return np.array([at(b) - at(a) for a, b in zip(t0, t1, strict=True)])


def config_with_detector(config: str, donor: str | None = None) -> dict:
    """A shipped config as a dict, with ``donor``'s stance detector when given (its analysis plug-ins dropped)."""
    import yaml

    def read(name: str) -> dict:
        return yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())

    cfg = read(config)
    if donor is not None:
        cfg = {k: v for k, v in cfg.items() if k != "analysis"}
        cfg["detector"] = read(donor)["detector"]
        cfg["name"] = f"{config}+{donor}_detector"
    return cfg


def matched(rec: Recording, config: str, donor: str | None = None) -> pd.DataFrame:
    """The matched strides of one config on one foot (with ``donor``'s stance detector when given), with
    ``err`` = estimated − reference length (m)."""
    from footzoo.evaluation.metrics import match_strides
    from footzoo.runtime.pipeline import Pipeline

    res = Pipeline.from_dict(config_with_detector(config, donor)).run(rec)
    m = match_strides(res.steps, rec.truth.steps)
    m["err"] = m["est_stride_length_m"] - m["stride_length_m"]
    m.attrs["pos"] = res.pos
    return m


def split(err: np.ndarray, m: pd.DataFrame) -> dict[str, float]:
    """Part 1: bias, scatter, straight/turn, inner strides, consecutive correlation."""
    turn = m["turn"].to_numpy(bool)
    shared = np.isclose(m["ms_end_s"].to_numpy()[:-1], m["ms_start_s"].to_numpy()[1:])
    return {"RMS": rms(err), "bias": float(np.mean(err)), "scatter (SD)": float(np.std(err)),
            "RMS straight": rms(err[~turn]), "RMS turns": rms(err[turn]), "turns": float(turn.sum()),
            "RMS without first/last": rms(err[1:-1]),
            "consecutive corr": float(np.corrcoef(err[:-1][shared], err[1:][shared])[0, 1])}


def fmt(v: float) -> str:
    """A number for the tables: 4 decimals, integers as such."""
    return "" if not np.isfinite(v) else f"{v:.0f}" if float(v).is_integer() and abs(v) >= 1 else f"{v:.4f}"


def table(rows: dict[str, dict[str, float]]) -> list[str]:
    """Markdown table: one column per key of ``rows``, one row per metric."""
    cols = list(rows)
    names = list(next(iter(rows.values())))
    out = ["| | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    return out + [f"| {n} | " + " | ".join(fmt(rows[c][n]) for c in cols) + " |" for n in names]


def measure(folder: Path, configs: list[str]) -> list[str]:
    """Every part, as Markdown lines."""
    from footzoo.io import load

    parts: dict[str, dict[str, dict[str, float]]] = {k: {} for k in ("split", "definitions", "filter", "range",
                                                                       "gyro", "swaps")}
    for foot in ("left", "right"):
        rec = load(folder / "imu_sample.csv", format="gaitmap", foot=foot)
        runs = {c: matched(rec, c) for c in configs}
        at_range = np.abs(rec.acc) > AT_RANGE
        for c, m in runs.items():
            key = f"{c} {foot}"
            err = m["err"].to_numpy()
            t0, t1 = m["ms_start_s"].to_numpy(), m["ms_end_s"].to_numpy()
            hit = np.array([at_range[(rec.t >= a) & (rec.t <= b)].any() for a, b in zip(t0, t1, strict=True)])
            free = np.array([np.hypot(*integrate_stride(rec.t, rec.acc, rec.gyr, a, b))
                             for a, b in zip(t0, t1, strict=True)])
            free_err = free - m["stride_length_m"].to_numpy()
            scaled = np.array([np.hypot(*integrate_stride(rec.t, rec.acc, rec.gyr * GYRO_SCALE, a, b))
                               for a, b in zip(t0, t1, strict=True)]) - m["stride_length_m"].to_numpy()
            parts["split"][key] = split(err, m)
            pos = m.attrs["pos"]
            k0, k1 = np.searchsorted(rec.t, t0), np.searchsorted(rec.t, t1)
            d = {"as benchmarked (heel, 2-D, footzoo's instants)": rms(err),
                 "estimate at the reference's instants": rms(np.hypot(*(pos[k1, :2] - pos[k0, :2]).T)
                                                             - m["stride_length_m"])}
            for label, names in MARKERS.items():
                disp = displacement(marker_positions(folder, foot, names), t0, t1, MOCAP_RATE)
                d[f"reference: {label}, 2-D"] = rms(m["est_stride_length_m"] - np.hypot(disp[:, 0], disp[:, 1]))
                if label == "heel (FCC)":
                    d["reference: heel, 3-D"] = rms(m["est_stride_length_m"] - np.linalg.norm(disp, axis=1))
            parts["definitions"][key] = d
            parts["filter"][key] = {"config RMS": rms(err), "no-filter RMS": rms(free_err),
                                    "no-filter bias": float(np.mean(free_err)),
                                    "no-filter SD": float(np.std(free_err)),
                                    "corr(config, no-filter)": float(np.corrcoef(err, free_err)[0, 1])}
            parts["range"][key] = {"strides at ±16 g": float(hit.sum()), "their RMS": rms(err[hit]),
                                   "their bias": float(np.mean(err[hit])), "others": float((~hit).sum()),
                                   "others' RMS": rms(err[~hit]), "others' bias": float(np.mean(err[~hit]))}
            for base, donor in SWAPS:
                if base == c:
                    e = matched(rec, base, donor)["err"].to_numpy()
                    parts["swaps"].setdefault(f"{base} with {donor}'s detector", {}).update(
                        {f"RMS {foot}": rms(e), f"bias {foot}": float(np.mean(e))})
            parts["gyro"][key] = {"heel→toe pitch rate / gyro": pitch_rate_ratio(folder, foot, "TOE"),
                                  "heel→FM5 pitch rate / gyro": pitch_rate_ratio(folder, foot, "FM5"),
                                  f"no-filter bias, gyro × {GYRO_SCALE}": float(np.mean(scaled)),
                                  f"no-filter SD, gyro × {GYRO_SCALE}": float(np.std(scaled))}
    titles = {"split": "1. Bias and scatter (m)", "definitions": "2. Stride-length RMS (m) under each definition",
              "filter": "3. The same strides integrated without a filter (m)",
              "range": "4. Strides whose impact reaches the accelerometer's range (m)",
              "gyro": "5. The gyroscope's scale against the markers",
              "swaps": "6. One config with another's stance detector (m)"}
    lines: list[str] = []
    for name, rows in parts.items():
        if rows:
            lines += [f"### {titles[name]}", "", *table(rows), ""]
    return lines


FINDINGS = """## Findings (from the tables below)

* **Not the definition.** Reading the estimate at the reference's minimum-velocity instants instead of the
  middles of the detected stances, computing the reference from the toe, the fifth metatarsal or the three
  markers' centroid instead of the heel, or in 3-D instead of horizontally, moves each RMS by at most 2 mm
  (table 2): while the foot stands, every point of it stays put, and the foot's heading barely changes
  between two stances of a straight stride. The benchmark already compares like with like; no definitional
  fix applies.
* **Mostly scatter, and the same in every pipeline.** ``recommended``'s error is a bias of −0.026 m (left)
  and −0.006 m (right) on a scatter (SD) of 0.046 and 0.050 m (table 1). Without its bias the left foot would
  be at 0.046 m: the left foot misses the 0.05 m target by its bias, which ``yun2012`` shares (−0.025 m) and
  ``huang2016`` does not (−0.004 m); the right foot's scatter alone is at the target. Turn strides and the
  first and last strides do not carry it (RMS of the straight strides and of the inner strides within
  2 mm of the whole), and consecutive strides' errors hardly anti-correlate (−0.20 to −0.25 left, +0.03 to
  +0.06 right), so it is not one misplaced footprint shortening one stride and lengthening the next.
* **In the recording, not in the filter.** Integrating each stride without any filter, stance detector or
  smoother gives errors correlated 0.95-0.99 with each config's (table 3), with a larger scatter (SD 0.061
  and 0.068 m): the stride-to-stride error is in the inertial signal between two mid-stances; the configs'
  stance updates reduce it but do not remove it.
* **The accelerometer's range does not explain it.** Heel impacts reach the ±16 g range on the sensor's
  vertical axis in 6 of 27 left and 7 of 29 right strides (the peaks stop at 156-158 m/s²). On the right
  those strides are 4.5-6 cm short, on the left they are the better ones (table 4): no consistent effect.
* **The gyroscope's scale cannot be told from the markers** (table 5): the heel→toe axis pitches 6-8 %
  faster than the gyroscope's sagittal rate, the heel→fifth-metatarsal axis 4-5 % slower (the shoe bends
  between them). Scaling the gyroscope by 1.07 moves the filter-free bias by +1.5 to +1.8 cm and leaves its
  scatter as it is: a scale error would explain part of a bias, never the scatter.

* **Part of it is the stance detector** (table 6). ``recommended`` with ``huang2016``'s stance detector
  (``huang_stance``) instead of its own scores 0.0436 m left and 0.0456 m right (left bias −0.018 m instead of
  −0.026 m); ``huang2016`` with ``yun2012``'s detector gets worse (0.0449, 0.0510 m). With the same detector
  and correction, ``yun2012``'s attitude filter leaves a left bias of −0.018 m where ``huang2016``'s Madgwick
  filter leaves −0.004 m: the rest of the left bias goes with the attitude filter (and its initialisation).

So ``recommended`` misses the target on this walk by a left-foot bias of −2.6 cm, on top of a stride-to-stride
scatter of about 5 cm that every pipeline inherits from the recording; its stance detector accounts for
about a third of that bias. This is a measurement on one recording, not a candidate setting: a change of
``recommended`` goes through the nested cross-validation on PyShoe (benchmarks/select_nested.py). There,
``huang_stance`` in the shipped pipeline (six settings of its threshold and Γ_th) is chosen by no outer fold:
on PyShoe's running and fast trials it misses stances and the trajectories run away (2-D worst 29-53 m on the
36 trials, benchmarks/recommended_selection.md), so the gain on this walk does not generalise.
"""


def main(argv: list[str] | None = None) -> int:
    from accuracy import DEFAULT_DATA

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--configs", default=",".join(CONFIGS))
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "gaitmap_strides.md")
    args = ap.parse_args(argv)
    folder = args.data / FOLDER
    if not (folder / "imu_sample.csv").exists():
        print(f"{folder / 'imu_sample.csv'} not found: nothing to measure (pass --data)")
        return 1
    warnings.simplefilter("ignore")
    start = time.time()
    body = measure(folder, args.configs.split(","))
    lines = ["# gaitmap's example walk: where the stride-length error comes from", "",
             f"Generated by `python benchmarks/gaitmap_strides.py --configs {args.configs}` "
             f"in {time.time() - start:.0f} s. Each column is a config and a foot; see the script's docstring "
             "for each method.", "", FINDINGS, *body]
    args.out.write_text("\n".join(lines))
    print(args.out.read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
