"""Continuity of the step-wise smoother: ``recommended_live`` (stepwise) against ``recommended`` (RTS), offline.

Usage: python benchmarks/stepwise_continuity.py [--data ../shared/data] [--jobs 2]
                                                [--out benchmarks/stepwise_continuity.md]

Per visible recording (PyShoe's 36 VICON trials, x-io's short walk, gaitmap's example walk (each
foot), Köroğlu's experiments 31–33, the simulator's walk, run and stairs of
:data:`benchmarks.accuracy.SIM_SCENARIOS`), both configs run on the whole recording
(:meth:`footzoo.Pipeline.run`; they differ only in ``smoother:``) and the table gives:

* the largest per-sample position move ``max_k |p_k − p_{k−1}|`` (m, 3-D) of each, and their ratio
  (the target: stepwise ≤ 2 × RTS); ``alone``: the same filter with each stride smoothed alone, its
  start not pinned (the step-wise smoother without :func:`footzoo.filters.stepwise.pin_start`, as it
  was), its largest move and its largest distance from RTS;
* the largest and the median distance ``|p_k^stepwise − p_k^RTS|`` (m, 3-D; the target: ≤ 0.05 m);
* ``filtered_at_ends_m``: the largest distance from the RTS estimate of the forward filter's estimate at
  the segments' ends (the last sample of each stance, :func:`footzoo.filters.stepwise.segment_ends`),
  ``|E[p_s | data up to s] − E[p_s | all data]|``: what the data after the end of a stance (the
  whole-recording smoother's later information) moves that sample by. A smoother that emits a
  stride at the end of the next stance has seen no more than this filter;
* where the step-wise estimate's largest move is: ``toe-off`` (the move from the last stance sample
  to the first swing sample: where a segment starts), ``heel-strike`` (swing to stance), ``stance``
  or ``swing`` (inside one), by the run's own stance.

With ``--lags`` (default 1, 2, 4, 8), for each recording where the step-wise estimate is more than 0.05 m
from RTS: how much a smoother allowed to wait L more strides would still differ. For up to
:data:`LAG_ENDS` stance ends s_i spread over the recording, the recording is cut at the end of the stance
L strides later and smoothed whole (``recommended``, RTS), and its estimate at s_i is compared with the
whole recording's: ``|E[p_s | data up to s_{i+L}] − E[p_s | all data]|``, the largest and the median (m).
If it stays far above 0.05 m as L grows, no smoother with a bounded latency reaches the target.

Nothing here is tuned to the table: both shipped configs as they are.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from accuracy import DEFAULT_DATA, SIM_SCENARIOS  # noqa: E402

import footzoo  # noqa: E402
from footzoo.filters import smoother  # noqa: E402
from footzoo.filters.implementation import TRAJECTORY  # noqa: E402
from footzoo.filters.recorders import SAMPLE_KEYS, from_columns  # noqa: E402
from footzoo.filters.stepwise import segment_ends  # noqa: E402
from footzoo.filters.structures import Trajectory  # noqa: E402
from footzoo.runtime.chain import recorded_forward  # noqa: E402
from footzoo.sim import simulate  # noqa: E402
from footzoo.studies.report import to_markdown  # noqa: E402

CONFIGS = {"rts": "recommended", "stepwise": "recommended_live"}
SIM = ("walk", "run", "stairs")


def recordings(data: Path) -> list[tuple[str, str, dict[str, Any]]]:
    """(dataset, name, how to load it) of every visible recording, and the simulator's."""
    out: list[tuple[str, str, dict[str, Any]]] = []
    out += [("pyshoe", p.stem, {"path": str(p)}) for p in sorted((data / "pyshoe_vicon").glob("*.mat"))]
    xio = data / "xio_gait_tracking" / "short_walk.csv"
    if xio.exists():
        out.append(("xio", "short_walk", {"path": str(xio)}))
    gaitmap = data / "gaitmap_example" / "imu_sample.csv"
    if gaitmap.exists():
        out += [("gaitmap", f"imu_sample_{foot}", {"path": str(gaitmap), "foot": foot}) for foot in ("left", "right")]
    out += [("koroglu", p.stem, {"path": str(p)}) for p in sorted((data / "koroglu_gcp").glob("*.csv"))]
    out += [("sim", name, {"simulate": SIM_SCENARIOS[name]}) for name in SIM]
    return out


def load(how: dict[str, Any]) -> footzoo.Recording:
    if "simulate" in how:
        return simulate(**how["simulate"])
    return footzoo.load(how["path"], **{k: v for k, v in how.items() if k != "path"})


def where(stance: np.ndarray, k: int) -> str:
    """What the move from sample k − 1 to sample k crosses."""
    a, b = bool(stance[k - 1]), bool(stance[k])
    return {(True, False): "toe-off", (False, True): "heel-strike", (True, True): "stance"}.get((a, b), "swing")


def strides_alone(rec: footzoo.Recording, forward: np.ndarray) -> np.ndarray:
    """The positions of ``recommended_live``'s filter with each stride smoothed alone, its start not pinned: the
    step-wise smoother before :func:`footzoo.filters.stepwise.pin_start` (the same forward pass and segments),
    in the frame of the run's ``forward`` positions (N, 3) m (:func:`same_frame`)."""
    eng, stance, full = recorded_forward(footzoo.Pipeline.from_yaml(CONFIGS["stepwise"]), rec)
    moved = same_frame(full["pos"], forward)
    traj = Trajectory(*(full[k] for k in TRAJECTORY))
    # through the module: a compiled function pickled into a worker by value would lose its dispatcher
    smoother.smooth_segments(from_columns({k: full[k] for k in SAMPLE_KEYS}, full), segment_ends(stance, rec.t, True),
                             0, 0, eng.setup.offsets, False, traj)
    return moved(traj.pos)


def same_frame(a: np.ndarray, b: np.ndarray):
    """The rotation and shift that take the positions ``a`` onto ``b`` (N, 3) m (Kabsch; the pipeline turns the
    engine's frame into its output frame), as a function; refused unless they fit to 1 µm."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    r = u @ np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))]) @ vt
    if np.abs((a - ca) @ r + cb - b).max() > 1e-6:
        raise RuntimeError("the engine's forward positions are not a rotation of the run's")
    return lambda p: (p - ca) @ r + cb


def row(dataset: str, name: str, how: dict[str, Any]) -> dict[str, Any]:
    """The continuity of one recording (module docstring)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load(how)
        res = {s: footzoo.Pipeline.from_yaml(c).run(rec) for s, c in CONFIGS.items()}
        forward = res["stepwise"].diagnostics["pos_forward"]
        pos = {**{s: r.pos for s, r in res.items()}, "alone": strides_alone(rec, forward)}
    move = {s: np.linalg.norm(np.diff(p, axis=0), axis=1) for s, p in pos.items()}
    dist = np.linalg.norm(res["stepwise"].pos - res["rts"].pos, axis=1)
    k = int(np.argmax(move["stepwise"])) + 1
    stance = np.asarray(res["stepwise"].stance, bool)
    ends = segment_ends(stance, np.asarray(rec.t, float), True)
    seen = np.linalg.norm(res["stepwise"].diagnostics["pos_forward"][ends] - res["rts"].pos[ends], axis=1)
    t = np.asarray(rec.t, float)
    return {"dataset": dataset, "recording": name, "seconds": float(t[-1] - t[0]),
            "rts_move_m": float(move["rts"].max()), "alone_move_m": float(move["alone"].max()),
            "alone_dist_m": float(np.linalg.norm(pos["alone"] - pos["rts"], axis=1).max()),
            "stepwise_move_m": float(move["stepwise"].max()),
            "move_ratio": float(move["stepwise"].max() / move["rts"].max()),
            "max_dist_m": float(dist.max()), "median_dist_m": float(np.median(dist)),
            "filtered_at_ends_m": float(seen.max()), "largest_move_at": where(stance, k),
            "largest_move_t_s": float(t[k] - t[0])}


#: Stance ends per recording at which the fixed-lag distance is measured (spread evenly over the recording).
LAG_ENDS = 12


def cut(rec: footzoo.Recording, n: int) -> footzoo.Recording:
    """The first ``n`` samples of ``rec``, every channel (the magnetometer sets the initial heading), no truth."""
    import dataclasses

    def head(a: Any) -> Any:
        return None if a is None else a[:n]

    return dataclasses.replace(rec, t=rec.t[:n], acc=rec.acc[:n], gyr=rec.gyr[:n], mag=head(rec.mag),
                               dist=head(rec.dist), truth=None)


def _lag_distance(pipe: footzoo.Pipeline, rec: footzoo.Recording, full: np.ndarray, k: int, upto: int
                  ) -> float | None:
    """``|E[p_k | data up to upto] − E[p_k | all data]|`` (m); None when the cut holds no still start to align on."""
    try:
        return float(np.linalg.norm(pipe.run(cut(rec, upto + 1)).pos[k] - full[k]))
    except footzoo.RecordingError:
        return None


def lag_row(dataset: str, name: str, how: dict[str, Any], lags: tuple[int, ...]) -> dict[str, Any]:
    """The fixed-lag distances of one recording (module docstring)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = load(how)
        pipe = footzoo.Pipeline.from_yaml(CONFIGS["rts"])
        full = pipe.run(rec)
        stance = np.asarray(full.stance, bool)
        ends = np.flatnonzero(stance[:-1] & ~stance[1:])
        out: dict[str, Any] = {"dataset": dataset, "recording": name, "stance ends": len(ends)}
        for lag in lags:
            usable = np.arange(1, len(ends) - lag)  # not the still start's end
            picks = usable[np.unique(np.linspace(0, len(usable) - 1, min(LAG_ENDS, len(usable))).astype(int))] \
                if len(usable) else usable
            d = [x for x in (_lag_distance(pipe, rec, full.pos, int(ends[i]), int(ends[i + lag])) for i in picks)
                 if x is not None]
            out[f"lag {lag}: largest (m)"] = float(max(d)) if d else float("nan")
            out[f"lag {lag}: median (m)"] = float(np.median(d)) if d else float("nan")
    return out


def summary(table: pd.DataFrame) -> list[str]:
    def worst(col: str) -> str:
        return str(table.loc[table[col].idxmax(), "recording"])

    cols = ["dataset", "recording", "seconds", "rts_move_m", "alone_move_m", "alone_dist_m", "stepwise_move_m",
            "move_ratio", "max_dist_m", "median_dist_m", "filtered_at_ends_m", "largest_move_at", "largest_move_t_s"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, r in table.iterrows():
        lines.append("| " + " | ".join(f"{r[c]:.4f}" if isinstance(r[c], float) else str(r[c]) for c in cols) + " |")
    ok_move = table["move_ratio"] <= 2.0
    ok_dist = table["max_dist_m"] <= 0.05
    lines += ["", f"Recordings: {len(table)}; largest move ≤ 2 × RTS's: {int(ok_move.sum())}; "
              f"stepwise–RTS ≤ 0.05 m: {int(ok_dist.sum())}.",
              f"Worst move ratio {table['move_ratio'].max():.2f} ({worst('move_ratio')}); strides alone "
              f"{(table['alone_move_m'] / table['rts_move_m']).max():.2f}; "
              f"largest distance {table['max_dist_m'].max():.3f} m ({worst('max_dist_m')}).",
              f"Of the {int((~ok_dist).sum())} recordings where stepwise–RTS exceeds 0.05 m, the forward filter "
              f"at the end of a stance is already more than 0.05 m from RTS on "
              f"{int((table.loc[~ok_dist, 'filtered_at_ends_m'] > 0.05).sum())}.",
              "Largest step-wise moves at: " + ", ".join(f"{k} {v}" for k, v in
                                                         table["largest_move_at"].value_counts().items()) + "."]
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--only", help="comma-separated datasets (pyshoe, xio, gaitmap, koroglu, sim)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "stepwise_continuity.md")
    ap.add_argument("--lags", default="1,2,4,8", help="strides of extra latency to measure ('' for none)")
    args = ap.parse_args()
    recs = recordings(args.data)
    if args.only:
        recs = [r for r in recs if r[0] in args.only.split(",")]
    from joblib import Parallel, delayed

    if args.jobs > 1:
        rows = Parallel(n_jobs=args.jobs)(delayed(row)(*r) for r in recs)
    else:
        rows = [row(*r) for r in recs]
    table = pd.DataFrame(rows)
    parts = ["### Step-wise smoother (recommended_live) against RTS (recommended), per-sample continuity", "",
             *summary(table)]
    lags = tuple(int(x) for x in args.lags.split(",") if x.strip())
    far = [r for r, (_, row_) in zip(recs, table.iterrows(), strict=True) if row_["max_dist_m"] > 0.05]
    if lags and far:
        if args.jobs > 1:
            lag_rows = Parallel(n_jobs=args.jobs)(delayed(lag_row)(*r, lags) for r in far)
        else:
            lag_rows = [lag_row(*r, lags) for r in far]
        parts += ["", "### A smoother that waits longer: RTS on the data up to L strides after a stance end", "",
                  "The recordings above where the step-wise estimate is more than 0.05 m from RTS; distances "
                  f"at up to {LAG_ENDS} stance ends each (module docstring).", "",
                  to_markdown(pd.DataFrame(lag_rows))]
    text = "\n".join(parts) + "\n"
    print(text)
    args.out.write_text(text)


if __name__ == "__main__":
    main()
