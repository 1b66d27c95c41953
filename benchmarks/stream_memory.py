"""Memory of a live stream over a long walk: bounded by the pipeline's latency, not by the length of the walk.

Usage: python benchmarks/stream_memory.py [--minutes 60] [--rate 100] [--packet 10] [--configs a,b] [--out FILE.md]

A simulated walk of ``--minutes`` (laps of a 437.5 m track) is pushed into a :class:`footzoo.Stream` in packets of
``--packet`` samples (as a wireless sensor delivers them), the final estimates taken after
every packet. Every ``--every`` simulated minutes the benchmark records the samples the stream
holds (``Stream.pending()``) and the Python heap it has allocated beyond the start
(``tracemalloc``, which sees numpy's buffers); the table gives the first and the last reading
and the largest: a bounded stream's memory stops growing once the walk is under way. The
recording itself is generated before the measurement starts and is not counted.
"""

from __future__ import annotations

import argparse
import sys
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from footzoo.sim import NoiseModel, simulate  # noqa: E402

#: ``recommended`` runs live with the step-wise smoother (its whole-recording RTS smoother is offline).
DEFAULT = ["nguyen2016", "yun2012", "duong2015_zupt", "recommended"]


def live_pipeline(name: str) -> footzoo.Pipeline:
    p = footzoo.Pipeline.from_yaml(name)
    if p.smoother == "rts":  # the whole-recording smoother is offline: live, the step-wise one
        p.smoother = "stepwise"
    return p


def measure(name: str, rec: footzoo.Recording, packet: int, every: int) -> dict[str, float]:
    pipeline = live_pipeline(name)
    stream = footzoo.Stream(pipeline, rate=rec.rate, guess=False, warmup=60.0)
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    readings = []
    t0 = time.perf_counter()
    for k in range(0, rec.n, packet):
        stream.extend(rec.t[k:k + packet], rec.acc[k:k + packet], rec.gyr[k:k + packet],
                      None if rec.mag is None else rec.mag[k:k + packet])
        stream.final()
        if (k // packet) % every == 0:
            readings.append((rec.t[k], stream.pending(), tracemalloc.get_traced_memory()[0] - base))
    stream.close()
    elapsed = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    held = np.array([r[1] for r in readings[2:]])
    heap = np.array([r[2] for r in readings[2:]])
    label = name + (f" (smoother: {pipeline.smoother})" if pipeline.smoother != "none" else "")
    return {"config": label, "minutes": rec.t[-1] / 60, "held_first": int(held[0]), "held_last": int(held[-1]),
            "held_max": int(held.max()), "heap_first_kB": heap[0] / 1e3, "heap_last_kB": heap[-1] / 1e3,
            "heap_max_kB": heap.max() / 1e3, "peak_kB": peak / 1e3, "us_per_sample": elapsed / rec.n * 1e6}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--rate", type=float, default=100.0)
    ap.add_argument("--packet", type=int, default=10, help="samples per push (extend)")
    ap.add_argument("--configs", default=",".join(DEFAULT))
    ap.add_argument("--out", type=Path)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    lap = simulate(path="track", rate=args.rate, profile="physical", noise=NoiseModel(seed=0))  # one lap, 437.5 m
    laps = max(int(np.ceil(args.minutes * 60 / lap.t[-1])), 1)
    rec = simulate(path="track", laps=laps, rate=args.rate, profile="physical", noise=NoiseModel(seed=0))
    every = max(int(60 * args.rate / args.packet), 1)  # one reading per simulated minute
    rows = [measure(name, rec, args.packet, every) for name in args.configs.split(",")]
    lines = [f"### Live stream memory: {rec.t[-1] / 60:.0f} min simulated walk at {args.rate:g} Hz, packets of "
             f"{args.packet} samples", "",
             "| config | samples held: after 2 min / at the end / most | heap beyond the start (kB): after 2 min / "
             "at the end / most | µs per sample |", "|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['config']} | {r['held_first']} / {r['held_last']} / {r['held_max']} | "
                     f"{r['heap_first_kB']:.0f} / {r['heap_last_kB']:.0f} / {r['heap_max_kB']:.0f} | "
                     f"{r['us_per_sample']:.1f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
