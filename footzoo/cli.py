"""Command line: ``footzoo run | simulate | calibrate | ablate | list | validate``."""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path
from typing import Any

from .errors import FootzooError


def _load_recording(args: argparse.Namespace):
    from .io import builtin_sample, load

    if args.data is None:
        return builtin_sample()
    options: dict[str, Any] = {}
    if args.foot:
        options["foot"] = args.foot
    return load(args.data, format=args.format, **options)


def cmd_run(args: argparse.Namespace) -> int:
    """Run a pipeline on a recording; print metrics; optionally write outputs."""
    from .metrics import trajectory_metrics
    from .pipeline import Pipeline

    pipeline = Pipeline.from_yaml(args.config)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = _load_recording(args)
    for w in caught:
        print(f"note: {w.message}", file=sys.stderr)
    result = pipeline.run(rec)
    truth = rec.truth
    closed = bool(truth is not None and truth.closed_loop)
    metrics = trajectory_metrics(result.pos, truth.pos if truth is not None else None, closed)
    metrics["steps"] = int(len(result.steps))
    metrics["duration_s"] = float(rec.t[-1] - rec.t[0])
    if "pyshoe_trial_error" in rec.meta:
        metrics["pyshoe_published_best_m"] = min(rec.meta["pyshoe_trial_error"].values())
    print(f"pipeline  {pipeline.name}  on  {rec.name}  ({rec.n} samples, {rec.rate:.1f} Hz)")
    for key, value in metrics.items():
        print(f"  {key:26s} {value:.4f}" if isinstance(value, float) else f"  {key:26s} {value}")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        result.samples.to_csv(out / "samples.csv", index=False, float_format="%.9g")
        result.steps.to_csv(out / "steps.csv", index=False, float_format="%.9g")
        payload = {"metrics": metrics, "config": result.config, "versions": result.versions,
                   "recording": {k: v for k, v in rec.meta.items() if isinstance(v, (str, int, float, bool))}}
        (out / "metrics.json").write_text(json.dumps(payload, indent=2, default=str))
        written = ["samples.csv", "steps.csv", "metrics.json"]
        if args.plot:
            from .plots import plot_trajectory

            plot_trajectory(result, out / "trajectory.png", rec)
            written.append("trajectory.png")
        print(f"wrote {', '.join(written)} to {out}")
    elif args.plot:
        print("--plot needs --out DIR (where trajectory.png is written)", file=sys.stderr)
        return 2
    return 0


def cmd_list(args: argparse.Namespace) -> int:
    """Print every plug-in with its parameters, defaults, units and paper."""
    from .registry import describe

    print(describe(args.kind), end="")
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    """Check a config without running it."""
    from .pipeline import Pipeline

    pipeline = Pipeline.from_yaml(args.config)
    print(f"{args.config}: valid")
    print(json.dumps(pipeline.to_dict(), indent=2))
    return 0


def cmd_simulate(args: argparse.Namespace) -> int:
    """Simulate a recording with ground truth and write it as canonical CSV/Parquet."""
    import numpy as np

    from .io.canonical import write
    from .sim import DistanceSensors, MagneticDisturbance, NoiseModel, simulate, simulate_calibration, simulate_pendulum

    biases = () if args.biases in ("", "none") else tuple(b.strip() for b in args.biases.split(","))
    noise = NoiseModel(scale=args.noise_scale, biases=biases, seed=args.seed)
    if args.scenario == "pendulum":
        rec = simulate_pendulum(rate=args.rate, noise=noise, sampling=args.sampling)
    elif args.scenario == "calibration":
        rec = simulate_calibration(mount_yaw=np.radians(args.mount_yaw), foot=args.foot, rate=args.rate, noise=noise)
    else:
        rec = simulate(
            path=args.scenario, n_strides=args.strides, stride_length=args.stride_length, rate=args.rate,
            profile=args.profile, sampling=args.sampling, noise=noise, seed=args.seed,
            fpa=np.radians(args.fpa), mount_yaw=np.radians(args.mount_yaw), foot=args.foot,
            distance_sensors=DistanceSensors() if args.distance_sensors else False,
            disturbance=MagneticDisturbance() if args.disturbance else None,
        )
    out = write(rec, args.out)
    closed = "closed loop" if rec.truth.closed_loop else "open path"
    print(f"wrote {out} ({rec.n} samples at {rec.rate:.0f} Hz, {rec.t[-1]:.1f} s, {closed}, "
          f"{0 if rec.truth.steps is None else len(rec.truth.steps)} steps)")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Foot vector from a calibration recording (Huang et al. 2016, eq. 11), saved as YAML."""
    import numpy as np

    from .analysis.foot_vector import calibrate_foot_vector

    rec = _load_recording(args)
    fv = calibrate_foot_vector(rec, still=tuple(args.still) if args.still else None,
                               flex=tuple(args.flex) if args.flex else None)
    fv.save(args.out)
    yaw = np.degrees(np.arctan2(-fv.vector[1], fv.vector[0]))
    print(f"foot vector (sensor frame, FRD): {np.round(fv.vector, 4).tolist()}  "
          f"(sensor yawed {yaw:.2f}° on the foot)")
    print(f"still {fv.still[0]:.2f}-{fv.still[1]:.2f} s, flexions {fv.flex[0]:.2f}-{fv.flex[1]:.2f} s")
    print(f"wrote {args.out}; use it with analysis: [{{type: huang_fpa, calibration: {args.out}}}]")
    return 0


def cmd_ablate(args: argparse.Namespace) -> int:
    """Run a study: every config × recording cell, in parallel, cached, with tables and plots."""
    from .ablation import run_study
    from .ablation.report import summarise, to_markdown

    out = args.out or f"ablation_{Path(args.study).stem}"
    table = run_study(args.study, jobs=args.jobs, scheduler=args.scheduler, out=out, progress=not args.quiet)
    a = table.attrs
    notes = [f"{len(a['recomputed'])} damaged cache entries run again (see {out}/cache_report.log)"
             if a["recomputed"] else "", f"{len(a['retried'])} failed runs retried" if a["retried"] else ""]
    notes = "".join(f", {n}" for n in notes if n)
    print(f"{a['computed'] + a['cached']} runs ({a['computed']} computed, {a['cached']} from the cache, "
          f"{a['failed']} failed{notes}); results in {out}/")
    factors = [c for c in table.columns if c not in ("run", "base", "recording", "metric", "value", "error")]
    for f in factors[:3]:
        s = summarise(table, f)
        keep = s[s["metric"].isin(args.show.split(","))] if args.show else s
        print(f"\n{f}:")
        print(to_markdown(keep), end="")
    return 0


def cmd_list_compat(args: argparse.Namespace) -> int:
    """Print which orientation × correction combinations validate, with the reasons for the others."""
    from .compat import compatibility_matrix

    print(compatibility_matrix(), end="")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``footzoo`` command."""
    parser = argparse.ArgumentParser(
        prog="footzoo", description="Foot-mounted IMU motion estimation: a zoo of published building blocks."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a pipeline config on a recording (default: the built-in walk)")
    run.add_argument("config", help="pipeline YAML, e.g. configs/yun2012.yaml")
    run.add_argument("--data", help="recording file (default: built-in x-io short walk)")
    run.add_argument("--format", help="canonical, xio, pyshoe, gaitmap or sensorconnect (default: detect)")
    run.add_argument("--foot", choices=["left", "right"], help="foot to read from a two-foot file (gaitmap)")
    run.add_argument("--out", help="directory for samples.csv, steps.csv, metrics.json")
    run.add_argument("--plot", action="store_true", help="also write trajectory.png (needs --out)")
    run.set_defaults(func=cmd_run)

    sim = sub.add_parser("simulate", help="simulate a foot-mounted IMU recording with ground truth")
    sim.add_argument("scenario", choices=["straight", "rectangle", "track", "figure_eight", "mixed_speed", "pendulum",
                                          "calibration"])
    sim.add_argument("--out", required=True, help="output file (.csv or .parquet); truth in true_* columns")
    sim.add_argument("--strides", type=int, default=100, help="strides of a straight walk (default 100)")
    sim.add_argument("--stride-length", type=float, default=1.2, help="stride length in m (default 1.2)")
    sim.add_argument("--rate", type=float, default=50.0, help="sampling rate in Hz (default 50)")
    sim.add_argument("--profile", choices=["paper", "physical"], default="paper", help="stance kinematics")
    sim.add_argument("--sampling", choices=["interval", "instantaneous"], default="interval")
    sim.add_argument("--noise-scale", type=float, default=1.0, help="factor on Table II noise σ (default 1)")
    sim.add_argument("--biases", default="acc,gyr,mag", help="Table II biases to include, or 'none'")
    sim.add_argument("--seed", type=int, default=0)
    sim.add_argument("--fpa", type=float, default=0.0, help="foot progression angle in deg (toe-out +)")
    sim.add_argument("--mount-yaw", type=float, default=0.0, help="sensor yaw on the foot in deg")
    sim.add_argument("--foot", choices=["right", "left"], default="right")
    sim.add_argument("--distance-sensors", action="store_true", help="add two VL6180-like range sensors")
    sim.add_argument("--disturbance", action="store_true", help="add a magnetic disturbance (first 10 m north)")
    sim.set_defaults(func=cmd_simulate)

    cal = sub.add_parser("calibrate", help="foot vector from a still period and slow dorsi-/plantar-flexions")
    cal.add_argument("--data", required=True, help="calibration recording")
    cal.add_argument("--format", help="reader format (default: detect)")
    cal.add_argument("--foot", choices=["left", "right"], help="foot to read from a two-foot file (gaitmap)")
    cal.add_argument("--still", nargs=2, type=float, metavar=("T0", "T1"), help="still period (s); default: found")
    cal.add_argument("--flex", nargs=2, type=float, metavar=("T0", "T1"), help="flexion period (s); default: found")
    cal.add_argument("--out", required=True, help="YAML file to write")
    cal.set_defaults(func=cmd_calibrate)

    abl = sub.add_parser("ablate", help="run an ablation study (configs x recordings) and write tables and plots")
    abl.add_argument("study", help="study YAML, e.g. configs/study_quick.yaml")
    abl.add_argument("--jobs", type=int, default=1, help="local worker processes (joblib); -1 = all cores")
    abl.add_argument("--scheduler", help="address of an existing Dask scheduler, e.g. tcp://10.0.0.5:8786")
    abl.add_argument("--out", help="output folder (default: ablation_<study>); its cache/ makes reruns resume")
    abl.add_argument("--show", help="comma-separated metrics to print (default: all)")
    abl.add_argument("--quiet", action="store_true", help="no progress bar")
    abl.set_defaults(func=cmd_ablate)

    lst = sub.add_parser("list", help="list plug-ins with their parameters, defaults, units and papers")
    lst.add_argument("--kind", choices=["orientation", "detector", "correction", "analysis"], help="only this kind")
    lst.add_argument("--compatibility", action="store_true",
                     help="print which orientation x correction combinations validate, and why not")
    lst.set_defaults(func=lambda a: cmd_list_compat(a) if a.compatibility else cmd_list(a))

    val = sub.add_parser("validate", help="check a pipeline config without running it")
    val.add_argument("config", help="pipeline YAML")
    val.set_defaults(func=cmd_validate)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``footzoo`` console script."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except FootzooError as err:
        print(f"footzoo: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
