"""The cost of the sensor and physics checks and of the plug-in contract, on a long simulated walk.

Usage: python benchmarks/sanity_overhead.py [--strides 1000] [--repeat 5] [--config yun2012]

Batch: each scan alone over the whole walk (µs per sample: the glitch and saturation scan of a
Recording, the estimate scan — no stance, drift while still — and the gyroscope–accelerometer
consistency over the swings) against ``Pipeline.run`` of the config end to end, which runs
them all; and the contract around one action method (read-only views, result checks) against
the method without it. Live: ``Stream.run`` sample by sample and in packets of 50, with the
scans and with them replaced by no-ops, interleaved. Minimum over the repetitions (wall-clock
in batch, CPU time live).
"""

from __future__ import annotations

import argparse
import time
import warnings
from typing import Any

import numpy as np


def best(fn: Any, repeat: int, clock: Any = time.perf_counter) -> float:
    """The minimum time of ``fn()`` over ``repeat`` runs (s), on ``clock``."""
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strides", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--config", default="yun2012")
    args = parser.parse_args()
    warnings.simplefilter("ignore")

    import footzoo.runtime.stream as stream_module
    from footzoo import Pipeline
    from footzoo.core import sanity
    from footzoo.filters.consistency import ConsistencyScan
    from footzoo.plugins.contract import checked
    from footzoo.runtime.stream import Stream
    from footzoo.sim import NoiseModel, simulate

    rec = simulate(n_strides=args.strides, rate=100.0, noise=NoiseModel(seed=1))
    n = rec.n
    pipe = Pipeline.from_yaml(args.config)
    pipe.run(simulate(n_strides=3, rate=100.0))  # compile
    stance = np.linalg.norm(rec.gyr, axis=1) < 0.6
    pos = np.zeros((n, 3))

    def estimate_scan() -> None:
        s = sanity.EstimateScan(rec.t[0] + 0.5, name="bench")
        s.push(np.arange(n), rec.t, rec.acc, rec.gyr, stance, pos)
        s.finish()

    def consistency() -> None:
        s = ConsistencyScan(rec.rate, name="bench")
        s.push(np.arange(n), rec.t, rec.acc, rec.gyr)
        s.finish()

    detector = pipe.detector.clone()
    rows = [
        ("Recording scan (glitches, saturation)", best(lambda: sanity.scan(rec.t, rec.acc, rec.gyr, "bench"),
                                                       args.repeat)),
        ("estimate scan (no stance, drift while still)", best(estimate_scan, args.repeat)),
        ("gyroscope-accelerometer consistency", best(consistency, args.repeat)),
        (f"detect of {detector.name!r} with the contract (checked)",
         best(lambda: checked(detector.clone().detect, rec.t, rec.acc, rec.gyr), args.repeat)),
        (f"detect of {detector.name!r} as written", best(lambda: detector.clone().detect(rec.t, rec.acc, rec.gyr),
                                                          args.repeat)),
        (f"Pipeline.run({args.config!r}), all included", best(lambda: pipe.run(rec), args.repeat)),
    ]
    print(f"batch, {n} samples ({args.strides} strides at 100 Hz):")
    for label, seconds in rows:
        print(f"  {label:52s} {seconds / n * 1e6:8.3f} µs/sample")

    live = simulate(n_strides=max(args.strides // 20, 10), rate=100.0, noise=NoiseModel(seed=2))

    class Off:
        report: dict[str, Any] = {}

        def __init__(self, *a: Any, **k: Any) -> None:
            pass

        def push(self, *a: Any, **k: Any) -> dict[str, Any]:
            return {}

        def finish(self) -> dict[str, Any]:
            return {}

        def use_evidence(self, *a: Any) -> None:
            pass

        def dropouts(self, *a: Any) -> None:
            pass

    print(f"live ({live.n} samples, guess=False):")
    for chunk in (1, 50):
        timing: dict[str, list[float]] = {"with the scans": [], "scans off": []}
        for _ in range(max(args.repeat // 2, 1)):  # interleaved: load on the machine hits both alike
            for label in timing:
                saved = (stream_module.SignalScan, stream_module.EstimateScan, stream_module.ConsistencyScan)
                if label == "scans off":
                    stream_module.SignalScan = stream_module.EstimateScan = stream_module.ConsistencyScan = Off
                try:
                    timing[label].append(best(lambda c=chunk: Stream(pipe, rate=live.rate, guess=False).run(
                        live, chunk=c), 1, time.process_time))
                finally:
                    stream_module.SignalScan, stream_module.EstimateScan, stream_module.ConsistencyScan = saved
        on, off = min(timing["with the scans"]), min(timing["scans off"])
        print(f"  chunk {chunk:3d}: {on / live.n * 1e6:8.1f} µs/sample with the scans, {off / live.n * 1e6:8.1f} "
              f"without ({(on - off) / off:+.1%}; CPU time)")


if __name__ == "__main__":
    main()
