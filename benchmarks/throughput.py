"""Throughput, cold start, peak memory and linearity of footzoo's pipelines and plug-ins.

Usage: python benchmarks/throughput.py [--samples 1000000] [--quick]

Prints, for every config in configs/ and for each plug-in alone, samples per second on one
core for a simulated 100 Hz walk (reading excluded, all outputs produced), next to the
reference path measured in the same run (the filterpy loop for Kalman pipelines, the
uncompiled Python kernels otherwise), as ratios; the cold start of a new process (import +
first run on 10 k samples, compilation cache warm); the peak memory beyond the input; and the
cost at 10 k, 100 k and 1 M samples.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from footzoo.sim import NoiseModel, simulate  # noqa: E402

CONFIGS = sorted(p.stem for p in (ROOT / "configs").glob("*.yaml") if not p.stem.startswith("study"))


def walk(samples: int) -> footzoo.Recording:
    """A simulated 100 Hz walk with distance sensors, tiled to ``samples``."""
    r = simulate(n_strides=200, rate=100.0, profile="physical", noise=NoiseModel(seed=0), distance_sensors=True,
                 clearance=0.1)
    reps = int(np.ceil(samples / r.n))
    n = min(samples, r.n * reps)
    tile = (lambda a: np.tile(a, (reps, 1))[:n])  # noqa: E731
    return footzoo.Recording(t=np.arange(n) / 100.0, acc=tile(r.acc), gyr=tile(r.gyr), mag=tile(r.mag),
                             dist=tile(r.dist), meta={"foot": "right", "name": "bench"})


def rate_of(fn, n: int, repeat: int = 1) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return n / best


def config_rates(rec: footzoo.Recording, ref_rec: footzoo.Recording) -> list[dict]:
    rows = []
    for name in CONFIGS:
        p = footzoo.Pipeline.from_yaml(ROOT / "configs" / f"{name}.yaml")
        p.run(ref_rec)  # compile / warm up
        fast = rate_of(lambda p=p: p.run(rec), rec.n, repeat=3)
        kalman = bool(p.filter_corrections)
        if kalman:
            ref = rate_of(lambda p=p: p.run(ref_rec, engine="reference"), ref_rec.n)
            ref_name = "filterpy loop"
        else:
            ref = _python_rate(name, ref_rec)
            ref_name = "uncompiled"
        rows.append({"config": name, "samples_per_s": fast, "reference": ref_name, "reference_per_s": ref,
                     "ratio": fast / ref})
    return rows


def _python_rate(name: str, rec: footzoo.Recording) -> float:
    """The same config with FOOTZOO_DISABLE_JIT=1, in a new process (the no-compiler install)."""
    config = str(ROOT / "configs" / f"{name}.yaml")
    code = (
        f"import time, numpy as np, footzoo, sys; sys.path.insert(0, {str(ROOT)!r});"
        f"from benchmarks.throughput import walk; rec = walk({rec.n});"
        f"p = footzoo.Pipeline.from_yaml({config!r}); t0 = time.perf_counter(); p.run(rec);"
        "print(rec.n / (time.perf_counter() - t0))"
    )
    env = {**os.environ, "FOOTZOO_DISABLE_JIT": "1"}
    out = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, env=env,
                         cwd=ROOT)
    return float(out.stdout.strip().splitlines()[-1]) if out.returncode == 0 else float("nan")


def plugin_rates(rec: footzoo.Recording) -> list[dict]:
    from footzoo.registry import available

    t, acc, gyr, mag = rec.t, rec.acc, rec.gyr, rec.mag
    stance = footzoo.registry.build("detector", {"type": "windowed"}).detect(t, acc, gyr).stance_
    q0 = np.array([1.0, 0, 0, 0])
    rows = []
    for name, cls in sorted(available("orientation").items()):
        o = cls()
        o.estimate(t[:2000], acc[:2000], gyr[:2000], mag[:2000], stance[:2000], q0)
        rows.append({"plugin": f"orientation/{name}",
                     "samples_per_s": rate_of(lambda o=o: o.estimate(t, acc, gyr, mag, stance, q0), rec.n, 2)})
    for name, cls in sorted(available("detector").items()):
        if name == "oracle":
            continue
        d = cls()
        d.detect(t[:2000], acc[:2000], gyr[:2000])
        rows.append({"plugin": f"detector/{name}",
                     "samples_per_s": rate_of(lambda d=d: d.detect(t, acc, gyr), rec.n, 2)})
    return rows


def cold_start() -> float:
    code = ("import time; t0 = time.perf_counter(); import footzoo, numpy as np;"
            "from footzoo.sim import simulate; rec = simulate(n_strides=80, rate=100.0, profile='physical');"
            "t1 = time.perf_counter(); [footzoo.Pipeline.from_yaml(f'configs/{c}.yaml').run(rec) for c in "
            "('yun2012', 'nguyen2016', 'duong2015_zupt', 'huang2016')]; print(time.perf_counter() - t0 - 0*(t1))")
    out = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, cwd=ROOT)
    return float(out.stdout.strip().splitlines()[-1])


def peak_memory(rec: footzoo.Recording, name: str) -> float:
    p = footzoo.Pipeline.from_yaml(ROOT / "configs" / f"{name}.yaml")
    tracemalloc.start()
    p.run(rec)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / rec.n


def stream_latency(rec: footzoo.Recording, n: int = 20_000) -> tuple[float, float]:
    """Mean and 99th-percentile time (s) of one ``Stream.push`` with the nguyen2016 config."""
    from footzoo.stream import Stream

    stream = Stream(footzoo.Pipeline.from_yaml(ROOT / "configs" / "nguyen2016.yaml"))
    times = []
    for k in range(min(n, rec.n)):
        t0 = time.perf_counter()
        stream.push(rec.t[k], rec.acc[k], rec.gyr[k], rec.mag[k])
        times.append(time.perf_counter() - t0)
    lat = np.array(times[200:])  # after the still start has been collected
    return float(lat.mean()), float(np.percentile(lat, 99))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=float, default=1e6)
    parser.add_argument("--quick", action="store_true", help="100 k samples, no linearity check")
    args = parser.parse_args()
    n = int(1e5 if args.quick else args.samples)
    rec = walk(n)
    ref_rec = walk(min(n, 50_000))
    print(f"footzoo {footzoo.__version__}, numba: {footzoo._jit.HAVE_NUMBA}, {n} samples at 100 Hz, one core\n")
    print("== configs (end to end) ==")
    for r in config_rates(rec, ref_rec):
        print(f"{r['config']:26s} {r['samples_per_s'] / 1e3:9.1f} k/s   {r['reference']:14s} "
              f"{r['reference_per_s'] / 1e3:8.1f} k/s   ratio {r['ratio']:7.1f}")
    print("\n== plug-ins alone ==")
    for r in plugin_rates(rec):
        print(f"{r['plugin']:32s} {r['samples_per_s'] / 1e6:8.2f} M/s")
    mean, p99 = stream_latency(rec)
    print(f"\n== streaming (nguyen2016, push one sample) == mean {mean * 1e6:.0f} us, p99 {p99 * 1e6:.0f} us")
    print(f"\n== cold start (new process: import + 4 configs on 8 k samples, cache warm) == {cold_start():.2f} s")
    print("\n== peak memory beyond the input (bytes per sample) ==")
    for name in ("yun2012", "nguyen2016", "duong2015"):
        print(f"{name:26s} {peak_memory(rec, name):8.0f}")
    if not args.quick:
        print("\n== linearity (seconds for 10 k, 100 k, 1 M samples) ==")
        sizes = (10_000, 100_000, 1_000_000)
        recs = {m: walk(m) for m in sizes}
        for name in ("yun2012", "nguyen2016"):
            p = footzoo.Pipeline.from_yaml(ROOT / "configs" / f"{name}.yaml")
            times = [m / rate_of(lambda p=p, m=m: p.run(recs[m]), m) for m in sizes]
            per = [round(x / m * 1e6, 2) for x, m in zip(times, sizes, strict=True)]
            print(f"{name:26s} " + "  ".join(f"{x:7.3f}" for x in times) + f"   per sample: {json.dumps(per)} us")


if __name__ == "__main__":
    main()
