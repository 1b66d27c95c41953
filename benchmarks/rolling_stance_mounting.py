"""Does ``rolling_stance``'s lever prior fail on a sensor mounted tilted on the foot?

Usage: python benchmarks/rolling_stance_mounting.py [--jobs 2] [--data ../shared/data]
       [--out benchmarks/rolling_stance_mounting.md]

``rolling_stance`` starts its heel and toe levers at (−0.10, 0, 0.07) and (0.10, 0, 0.07) m in the sensor's
body frame (FRD): right for a sensor whose axes are the foot's. The question measured here: on a sensor tilted
on the foot (x-io's about 30°), does that prior, held with σ 0.02 m, pull the levers to the wrong place, and is
that why ``rolling_stance`` closes x-io's loop worse than ``recommended``?

Per recording, from ``recommended`` as shipped:

* the sensor's tilt at rest (roll and pitch of the initial attitude, the foot flat) and the walking
  direction in the sensor frame (median over strides of the mid-stance-to-mid-stance displacement,
  horizontal, seen in the sensor frame at the first mid-stance): the **foot frame** (x the walking
  direction made horizontal, z down along gravity) in sensor axes (:func:`foot_frame`);
* ``rolling_stance`` (its levers learnt with σ 0.05 and 0.02 m, and fixed) from three priors: the
  shipped one (sensor frame), the same vectors rotated by the tilt at rest only (``level``: x along
  the sensor's own heading) and by the whole mounting (``mount``: tilt and walking direction; this
  one is an oracle, it needs the walk), scored on each reference, its learnt levers in the foot frame;
* a check that uses no filter's lever: the contact point that best explains, as a rotation about a
  fixed point (``a = α × r + ω × (ω × r)``, ``r`` the sensor from the contact), the sensor's motion
  acceleration in a window just before each detected stance (the heel rock after initial contact)
  and just after it (the roll over the toes), by least squares over the recording
  (:func:`contact_fit`), in the foot frame, with the share of the acceleration it explains;
* x-io's loop closure over the 12 zero-velocity settings of the nested selection's grid
  (``benchmarks/select_nested.py``): how much one loop's closure moves between settings that differ
  only in the detector's threshold and the zero-velocity update's rolling noise;
* on the simulator's physical foot (its contact phases taken as stance, as in
  ``tests/corrections/test_rolling_stance.py``), the levers learnt from the shipped prior with the
  sensor pitched by 0 and ±30° on the foot, against the simulator's geometry.
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from accuracy import DEFAULT_DATA, motion_class  # noqa: E402
from rolling_stance import _load, over_pyshoe, stance_updates_only  # noqa: E402

from footzoo.core.conventions import quat_from_euler, quat_to_euler, quat_to_matrix, skew  # noqa: E402
from footzoo.evaluation.metrics import armse, loop_closure, pyshoe_error, stride_errors  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

#: The shipped prior (m, sensor frame FRD).
HEEL, TOE = np.array([-0.10, 0.0, 0.07]), np.array([0.10, 0.0, 0.07])
#: ``rolling_stance`` settings: name -> parameters besides the levers.
SETTINGS = {"σ 0.05": {}, "σ 0.02": {"lever_std": 0.02}, "fixed": {"lever_std": 0.0, "lever_noise": 0.0}}
#: The windows before and after each detected stance in which the contact point is fitted (s), and the
#: smallest rate a sample needs to take part (rad/s): a foot that hardly turns tells nothing of the point.
FIT_WINDOW, FIT_MIN_RATE = 0.05, 1.0
#: Stance runs shorter than this (s) are left out of the mounting and the fit: a detector's brief stance in a swing
#: is not a foot on the floor.
MIN_STANCE = 0.05
#: Sensor pitch on the simulated foot (degrees).
SIM_PITCH = (0.0, -30.0, 30.0)


def config(corrections: list[dict[str, Any]] | None) -> dict[str, Any]:
    """``recommended.yaml``'s stance updates (without ``height_level``), its corrections replaced when given."""
    cfg = stance_updates_only()
    if corrections is not None:
        cfg["corrections"] = copy.deepcopy(corrections)
    return cfg


def run(rec: Any, corrections: list[dict[str, Any]] | None = None, **changes: dict[str, Any]) -> Any:
    """A pipeline run of ``recommended`` with ``corrections`` and the sections' ``changes``."""
    from footzoo.runtime.pipeline import Pipeline

    cfg = config(corrections)
    for section, values in changes.items():
        cfg[section].update(values)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Pipeline.from_dict(cfg).run(rec)


def stance_runs(t: np.ndarray, stance: np.ndarray, min_duration: float = MIN_STANCE) -> list[tuple[int, int]]:
    """First and one-past-last sample of every stance run at least ``min_duration`` s long."""
    d = np.diff(np.r_[0, stance.astype(int), 0])
    return [(int(a), int(b)) for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True)
            if t[b - 1] - t[a] >= min_duration]


def foot_frame(result: Any, min_stride: float = 0.5) -> np.ndarray:
    """The foot frame's axes in the sensor frame, columns (forward, right, down), from a walk's estimate.

    Down: gravity at the mid-stances (median; stances of at least :data:`MIN_STANCE` s). Forward: the median
    over strides (mid-stance to the next, longer than ``min_stride`` m) of the horizontal displacement seen in
    the sensor frame at the first mid-stance, made orthogonal to down.
    """
    C = quat_to_matrix(result.quat)
    mids = [(a + b) // 2 for a, b in stance_runs(result.samples["t"].to_numpy(), result.stance)]
    dirs = []
    for i, j in zip(mids[:-1], mids[1:], strict=True):
        d = result.pos[j] - result.pos[i]
        d[2] = 0.0
        if np.linalg.norm(d) > min_stride:
            dirs.append(C[i].T @ (d / np.linalg.norm(d)))
    down = np.median(C[mids][:, 2, :], axis=0)
    down /= np.linalg.norm(down)
    fwd = np.median(dirs, axis=0)
    fwd -= down * (fwd @ down)
    fwd /= np.linalg.norm(fwd)
    return np.column_stack([fwd, np.cross(down, fwd), down])


def level_frame(result: Any) -> np.ndarray:
    """The level frame's axes in the sensor frame: the tilt at rest (roll, pitch of the first attitude) undone."""
    e = quat_to_euler(result.quat[:1])[0]
    return quat_to_matrix(quat_from_euler(np.array([e[0]]), np.array([e[1]]), np.array([0.0])))[0].T


def contact_fit(rec: Any, result: Any, phase: str, window: float = FIT_WINDOW,
                min_rate: float = FIT_MIN_RATE) -> tuple[np.ndarray, float, int]:
    """The fixed point whose rotation best explains the sensor's acceleration around the detected stances.

    In the ``window`` s before each stance (``phase`` "heel") or after it ("toe"), samples turning faster than
    ``min_rate`` rad/s: the estimate's motion acceleration (gravity removed) seen in the sensor frame, ``a``,
    ``α`` from the gyro by central differences; ``a = ([α×] + [ω×]²) r`` solved for ``r`` by least squares.
    Returns the contact point ``c = −r`` (m, sensor frame), the share of ``Σ|a|²`` it explains, and the samples.
    """
    t, w = rec.t, rec.gyr
    C = quat_to_matrix(result.quat)
    a = np.einsum("nji,nj->ni", C, result.samples[["acc_n", "acc_e", "acc_d"]].to_numpy())
    alpha = np.gradient(w, t, axis=0)
    n = int(round(window / np.median(np.diff(t))))
    idx = []
    for lo, hi in stance_runs(t, result.stance):
        k = np.arange(max(lo - n, 0), lo + 1) if phase == "heel" else np.arange(hi - 1, min(hi + n, len(t)))
        idx.append(k[np.linalg.norm(w[k], axis=1) > min_rate])
    k = np.concatenate(idx) if idx else np.zeros(0, int)
    if len(k) < 10:
        return np.full(3, np.nan), np.nan, len(k)
    A = np.concatenate([skew(alpha[i]) + skew(w[i]) @ skew(w[i]) for i in k])
    b = a[k].reshape(-1)
    r, *_ = np.linalg.lstsq(A, b, rcond=None)
    res = b - A @ r
    return -r, float(1.0 - res @ res / (b @ b)), len(k)


def _rounded(v: Any) -> list[float]:
    return np.round(np.asarray(v, float), 3).tolist()


def recordings(data: Path) -> list[tuple[str, str, Any]]:
    """(label, kind, recording) of x-io's walk, Köroğlu 31–33 and gaitmap's two feet, those present."""
    out = []
    xio = data / "xio_gait_tracking" / "short_walk.csv"
    if xio.exists():
        out.append(("x-io", "loop", _load(xio, format="xio")))
    for path in sorted((data / "koroglu_gcp").glob("SensorConnectData_*.csv")):
        out.append((f"Köroğlu {path.stem[-2:]}", "footprints", _load(path, format="sensorconnect")))
    gaitmap = data / "gaitmap_example" / "imu_sample.csv"
    for foot in ("left", "right") if gaitmap.exists() else ():
        out.append((f"gaitmap {foot}", "strides", _load(gaitmap, format="gaitmap", foot=foot)))
    return out


def score(kind: str, rec: Any, result: Any) -> float:
    """The reference's figure (m): x-io's horizontal loop closure, Köroğlu's footprint RMS, gaitmap's stride RMS."""
    if kind == "loop":
        return loop_closure(result.pos)["loop_closure_xy_m"]
    key = "footprint_error_rms_m" if kind == "footprints" else "stride_length_rms_error_m"
    return result.metrics.get(key, np.nan)


def prior_rows(label: str, kind: str, rec: Any) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The mounting of one recording, and every prior × setting on it."""
    base = run(rec)
    foot, level = foot_frame(base), level_frame(base)
    e = np.degrees(quat_to_euler(base.quat[:1])[0])
    mounting = {"recording": label, "roll at rest (°)": e[0], "pitch at rest (°)": e[1],
                "walking direction (sensor frame)": _rounded(foot[:, 0])}
    for phase in ("heel", "toe"):
        c, share, n = contact_fit(rec, base, phase)
        mounting[f"{phase} fit (foot frame, m)"] = _rounded(foot.T @ c)
        mounting[f"{phase} fit explains"] = round(share, 2)
    rows = [{"recording": label, "prior": "recommended (zupt)", "setting": "", "value": score(kind, rec, base)}]
    for prior, frame in (("sensor frame (shipped)", np.eye(3)), ("level (tilt at rest)", level),
                         ("mount (oracle)", foot)):
        heel, toe = (frame @ HEEL).tolist(), (frame @ TOE).tolist()
        for setting, extra in SETTINGS.items():
            r = run(rec, [{"type": "rolling_stance", "heel": heel, "toe": toe, **extra}])
            lv = r.diagnostics["contact_levers"]
            rows.append({"recording": label, "prior": prior, "setting": setting, "value": score(kind, rec, r),
                         "heel learnt (foot frame, m)": _rounded(foot.T @ lv["heel"]),
                         "toe learnt (foot frame, m)": _rounded(foot.T @ lv["toe"])})
    return mounting, rows


def pyshoe_rows(path: Path) -> list[dict[str, Any]]:
    """The shipped and the level prior on one PyShoe trial (the tilt at rest with it)."""
    rec = _load(path, format="pyshoe")
    base = run(rec)
    level = level_frame(base)
    e = np.degrees(quat_to_euler(base.quat[:1])[0])
    rows = []
    for prior, frame in (("sensor frame (shipped)", np.eye(3)), ("level (tilt at rest)", level)):
        for setting, extra in SETTINGS.items():
            r = run(rec, [{"type": "rolling_stance", "heel": (frame @ HEEL).tolist(), "toe": (frame @ TOE).tolist(),
                           **extra}])
            rows.append({"trial": path.stem, "class": motion_class(path.stem), "prior": prior, "setting": setting,
                         "roll": e[0], "pitch": e[1], "2-D (m)": pyshoe_error(r.pos, rec.truth.pos),
                         "3-D (m)": armse(r.pos, rec.truth.pos)})
    return rows


def xio_grid(rec: Any) -> list[dict[str, Any]]:
    """x-io's loop closure over the nested selection's 12 zero-velocity settings."""
    rows = []
    for th in (2000.0, 3000.0):
        for scale in (0.8, 1.0):
            for roll in (0.0, 0.1, 0.2):
                zupt = [{"type": "zupt", "velocity_std": 0.03, "roll_lever": roll}]
                r = run(rec, zupt, detector={"threshold": th, "speed_scale": scale})
                rows.append({"threshold": th, "speed_scale": scale, "roll_lever (m)": roll,
                             "horizontal closure (m)": loop_closure(r.pos)["loop_closure_xy_m"]})
    return rows


def sim_rows() -> list[dict[str, Any]]:
    """Levers learnt from the shipped prior on the simulator's rolling foot, the sensor pitched on the foot."""
    from footzoo.runtime.pipeline import Pipeline
    from footzoo.sim import NoiseModel, simulate
    from footzoo.sim.gait import FootGeometry

    rows = []
    for deg in SIM_PITCH:
        walk = simulate(n_strides=16, profile="physical", rate=200.0, noise=NoiseModel(seed=2),
                        mount_pitch=np.radians(deg))
        contact = walk.truth.stance.copy()
        for _, s in walk.truth.steps.iterrows():
            contact |= (walk.t > s["start"]) & (walk.t <= s["swing_start"])
            contact |= (walk.t > s["swing_end"]) & (walk.t <= s["end"] + 1e-9)
        rec = dataclasses.replace(walk, truth=dataclasses.replace(walk.truth, stance=contact))
        geometry = FootGeometry(mount_pitch=np.radians(deg))
        to_sensor = quat_to_matrix(geometry.mount_quat()).T
        heel, toe = to_sensor @ geometry.heel, to_sensor @ geometry.toe
        for setting, extra in SETTINGS.items():
            if setting == "fixed":
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = Pipeline.from_dict({"orientation": {"type": "ins"}, "detector": {"type": "oracle"},
                                        "corrections": [{"type": "rolling_stance", **extra}]}).run(rec)
            lv = r.diagnostics["contact_levers"]
            rows.append({"sensor pitch on the foot (°)": deg, "setting": setting,
                         "true heel (sensor frame, m)": _rounded(heel), "heel error (m)": _rounded(lv["heel"] - heel),
                         "true toe (sensor frame, m)": _rounded(toe), "toe error (m)": _rounded(lv["toe"] - toe),
                         "stride length mean error (m)": stride_errors(r.steps, walk.truth.steps)[
                             "stride_length_mean_error_m"]})
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=1, help="worker processes for PyShoe's trials (default 1)")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="folder of the reference recordings")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "rolling_stance_mounting.md",
                    help="Markdown summary")
    args = ap.parse_args(argv)
    t0 = time.time()
    mountings, rows, grid = [], [], []
    for label, kind, rec in recordings(args.data):
        m, r = prior_rows(label, kind, rec)
        mountings.append(m)
        rows += r
        if kind == "loop":
            grid = xio_grid(rec)
    pyshoe = over_pyshoe(pyshoe_rows, args.data, args.jobs)
    sim = pd.DataFrame(sim_rows())
    lines = ["# rolling_stance's lever prior on a tilted sensor", "",
             f"Generated by `python benchmarks/rolling_stance_mounting.py` ({(time.time() - t0) / 60:.1f} min). "
             "What is measured and how: the script's docstring. Lower is better for every reference figure (m).", ""]
    if mountings:
        lines += ["## The sensors' mounting and the contact points their accelerations show", "",
                  "Tilt at rest: roll and pitch of `recommended`'s initial attitude. Walking direction: unit vector in "
                  "the sensor frame. Fit: the contact point whose rotation best explains the sensor's motion "
                  f"acceleration {FIT_WINDOW * 1000:.0f} ms before each detected stance (heel) and after it (toe), "
                  f"samples turning faster than {FIT_MIN_RATE} rad/s, in the foot frame (x forward, y right, z down, "
                  "from the sensor), with the share of the acceleration it explains.", "",
                  to_markdown(pd.DataFrame(mountings), digits=3), ""]
    if rows:
        t = pd.DataFrame(rows)
        wide = t.pivot_table(index=["prior", "setting"], columns="recording", values="value", sort=False)
        lines += ["## The references with each prior", "",
                  "`rolling_stance` in place of `zupt` in `recommended`; its prior: the shipped vectors in the sensor "
                  "frame, rotated by the tilt at rest (x along the sensor's own heading), or by the whole mounting "
                  "(an oracle: it needs the walk). x-io: horizontal loop closure; Köroğlu: footprint RMS; gaitmap: "
                  "stride-length RMS (m).", "",
                  to_markdown(wide.reset_index(), digits=4), "",
                  "Levers learnt, in the foot frame (m):", "",
                  to_markdown(t[t["setting"] != "fixed"].dropna(subset=["heel learnt (foot frame, m)"])
                              .drop(columns="value")), ""]
    if grid:
        lines += ["## x-io's loop over the 12 zero-velocity settings of the nested selection", "",
                  to_markdown(pd.DataFrame(grid), digits=4), ""]
    if not pyshoe.empty:
        summ = pyshoe.groupby(["prior", "setting"], sort=False).agg(
            **{"2-D median": ("2-D (m)", "median"), "2-D worst": ("2-D (m)", "max"),
               "3-D median": ("3-D (m)", "median"), "3-D worst": ("3-D (m)", "max")}).reset_index()
        tilt = pyshoe.drop_duplicates("trial")
        lines += ["## PyShoe's 36 VICON trials", "",
                  f"Tilt at rest over the trials: pitch median {tilt['pitch'].median():.1f}° (range "
                  f"{tilt['pitch'].min():.1f}° to {tilt['pitch'].max():.1f}°), roll median "
                  f"{tilt['roll'].median():.1f}° (the inverted trial's about 176°). 2-D: PyShoe's metric; 3-D: "
                  "ARMSE after a least-squares yaw alignment (m).", "", to_markdown(summ, digits=4), ""]
    lines += ["## The simulator's rolling foot, the sensor pitched on the foot", "",
              "The shipped prior (sensor frame) against the simulator's geometry seen from the pitched sensor; the "
              "contact phases as stance (oracle detector), 16 strides at 200 Hz.", "", to_markdown(sim, digits=4), ""]
    args.out.write_text("\n".join(lines))
    print(f"{args.out} ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
