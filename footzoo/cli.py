"""Command line: ``footzoo run | list | validate``."""

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

    lst = sub.add_parser("list", help="list plug-ins with their parameters, defaults, units and papers")
    lst.add_argument("--kind", choices=["orientation", "detector", "correction"], help="only this kind")
    lst.set_defaults(func=cmd_list)

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
