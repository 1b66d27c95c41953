"""Speed-up of an ablation study from two local workers (joblib) and from a local Dask cluster.

Usage: python benchmarks/study_scaling.py [--repeat 2] [--strides 0] [--no-report]
       python benchmarks/study_scaling.py --scale [--settings 50] [--recordings 40]

``--scale``: a study of ``settings`` x ``recordings`` cells (default 50 x 40 = 2 000: the
recommended config with 10 detector thresholds x 5 velocity noises, or ``--base yun2012`` with 10
thresholds x 5 complementary-filter gains, on simulated straight walks of 30 strides at 100 Hz,
about 32 s each, seeds 0..39), run serially and on a Dask LocalCluster (2 processes), each from an empty
output folder without the figures (``report=False``; the runs and the cache only). It prints the
main process's peak memory growth, and footzoo's overhead per cell: the wall time of the serial
study minus the time of the pipeline runs themselves (``run_s`` in each cache entry), of the
metrics (``metrics_s``) and of loading or simulating the recordings, as a share of the pipeline
runs' time (cache lookups, keys, validation, bookkeeping and writing the entries). That share is
the figure the study runner must keep under 20 %; the metrics' cost is printed apart.

The study: 4 configs (angular-rate FSM or SHOE detector x ZVU dedrift or ZUPT, on yun2012.yaml)
x 8 simulated recordings (the hallway rectangle at 100 Hz, physical foot model, seeds 0-7), with
a threshold sweep. Each back end runs the whole study from an empty output folder (runs, cache
writes, tables, summaries and plots; ``--no-report`` leaves out the output folder). Runs are
interleaved (serial, joblib, Dask, serial, ...) and the minimum and median wall times are printed
with the speed-ups against serial, and whether the three tables are identical. Worker processes
are started and warmed by one untimed run of the study per back end (imports and compiled kernels
loaded), as a user's second study in one session would find them.

On a machine shared with other work, wall times say little about scaling, so the CPU time is
measured too: the main process's (``time.process_time``) and each run's in its worker (``cpu_s``
in the cache entries, loading the recording included). From them, the time the same work would
take on two otherwise idle cores: the main process's CPU plus the makespan of the chunks
dispatched to two workers in order (each to the first free worker, as joblib and Dask do); with
joblib and Dask the figures are drawn by the workers while the main process writes the tables
(with Dask in memory, the main process writing the files), so the figure tasks are timed again
one by one afterwards and scheduled the same way.
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from footzoo.config import load_yaml  # noqa: E402
from footzoo.studies import Study, run_study  # noqa: E402


def study(strides: int) -> Study:
    sim = {"path": "rectangle", "rate": 100, "profile": "physical", "clearance": 0.15, "noise": {"scale": 1}}
    if strides:
        sim = {"path": "straight", "n_strides": strides, "rate": 100, "profile": "physical", "noise": {"scale": 1}}
    return Study.from_dict({
        "name": "scaling",
        "base": {**load_yaml(ROOT / "configs" / "yun2012.yaml"), "name": "yun2012"},
        "factors": {"detector.type": ["angular_rate_fsm", "shoe"],
                    "corrections": [[{"type": "zvu_dedrift"}], [{"type": "zupt"}]]},
        "recordings": [{"simulate": sim, "seeds": list(range(8))}],
        "metrics": ["loop_closure_xy_m", "armse_3d_m", "gait_phase_error_rate", "stance_f1", "strides"],
        "sweep": {"points": 25},
    })


def _spin(n: int) -> int:
    total = 0
    for i in range(n):
        total += i * i
    return total


def machine_check(n: int = 3_000_000, tasks: int = 8) -> float:
    """Speed-up two joblib processes give a pure-Python loop right now: what the machine lets scale at all."""
    from joblib import Parallel, delayed

    Parallel(n_jobs=2)(delayed(_spin)(10) for _ in range(2))
    t0 = time.perf_counter()
    for _ in range(tasks):
        _spin(n)
    serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    Parallel(n_jobs=2, batch_size=1)(delayed(_spin)(n) for _ in range(tasks))
    return serial / (time.perf_counter() - t0)


def scale_study(settings: int, recordings: int, strides: int = 30, base: str = "recommended") -> Study:
    """``settings`` configs x ``recordings`` simulated walks: for ``recommended`` (a Kalman filter with
    RTS smoothing) detector thresholds x velocity noises, for ``yun2012`` (a complementary filter,
    footzoo's cheapest pipeline) detector thresholds x filter gains."""
    if base == "yun2012":
        second = ("orientation.static_gain", [0.5, 0.75, 1.05, 1.3, 1.6])
        thresholds = [round(0.3 + 0.1 * k, 2) for k in range(max(1, settings // 5))]
        cfg = {**load_yaml(ROOT / "configs" / "yun2012.yaml"), "name": "yun2012",
               "calibration": []}
    else:
        second = ("navigation.velocity_noise", [0.003, 0.01, 0.03, 0.1, 0.3])
        thresholds = [round(1000.0 + 500.0 * k, 1) for k in range(max(1, settings // 5))]
        cfg = {**load_yaml(ROOT / "configs" / "recommended.yaml"), "name": "recommended"}
    return Study.from_dict({
        "name": "scale",
        "base": cfg,
        "factors": {"detector.threshold": thresholds, second[0]: second[1][: max(1, min(5, settings))]},
        "recordings": [{"simulate": {"path": "straight", "n_strides": strides, "rate": 100, "noise": {"scale": 1}},
                        "seeds": list(range(recordings))}],
        "max_cells": 100_000,
    })


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def scale(settings: int, recordings: int, base: str = "recommended") -> None:
    """The large-study figures: peak memory, overhead per cell, serial and on a Dask LocalCluster."""
    import json

    from dask.distributed import LocalCluster

    s = scale_study(settings, recordings, base=base)
    n = s.size
    print(f"{n} cells ({n // recordings} settings of {base} x {recordings} recordings), {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f} at start", flush=True)
    run_study(scale_study(2, 1, 4, base), quiet=True)  # imports and compiled kernels, untimed
    tmp = Path(tempfile.mkdtemp(prefix="footzoo_scale_"))
    try:
        rss0 = _peak_rss_mb()
        t0, c0 = time.perf_counter(), time.process_time()
        serial = run_study(s, out=tmp / "serial", report=False, quiet=True)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        rss1 = _peak_rss_mb()
        entries = [json.loads(f.read_bytes().partition(b"\n")[2]) for f in (tmp / "serial" / "cache").glob("*.json")]
        t1, c1 = time.perf_counter(), time.process_time()
        for rec in s.recordings:  # what loading (simulating) the recordings costs, once each
            rec.load()
        load = {"wall": time.perf_counter() - t1, "CPU": time.process_time() - c1}
        print(f"serial: {wall:.1f} s wall, {cpu:.1f} s CPU for {n} cells", flush=True)
        for clock, total, suffix in (("wall", wall, ""), ("CPU", cpu, "_cpu")):
            run_s = sum(e.get(f"run{suffix}_s", 0.0) for e in entries)
            metrics_s = sum(e.get(f"metrics{suffix}_s", 0.0) for e in entries)
            overhead = total - run_s - metrics_s - load[clock]
            print(f"  {clock:4s}: pipeline runs {run_s:.1f} s, metrics {metrics_s:.1f} s "
                  f"({100 * metrics_s / run_s:.0f} % of the runs), recordings {load[clock]:.1f} s; footzoo's "
                  f"overhead {overhead:.1f} s = {1e3 * overhead / n:.2f} ms per cell = "
                  f"{100 * overhead / run_s:.1f} % of the pipeline runs", flush=True)
        print(f"  peak memory of the main process grew by {rss1 - rss0:.0f} MB (peak {rss1:.0f} MB); "
              f"cache {sum(f.stat().st_size for f in (tmp / 'serial' / 'cache').glob('*.json')) / 1e6:.0f} MB "
              f"on disk; {serial.attrs['failed']} failed", flush=True)
        t0 = time.perf_counter()
        again = run_study(s, out=tmp / "serial", report=False, quiet=True)
        print(f"  rerun from the cache: {time.perf_counter() - t0:.1f} s ({again.attrs['cached']} cached)", flush=True)
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                          silence_logs=logging.CRITICAL) as cluster:
            run_study(scale_study(2, 1, 4, base), scheduler=cluster.scheduler_address, quiet=True)  # warm
            t0 = time.perf_counter()
            dask = run_study(s, scheduler=cluster.scheduler_address, out=tmp / "dask", report=False, quiet=True)
            print(f"dask LocalCluster (2 processes): {time.perf_counter() - t0:.1f} s wall; peak memory of the "
                  f"main process {_peak_rss_mb():.0f} MB; same table as serial: {dask.equals(serial)}", flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2, help="interleaved repetitions per back end")
    ap.add_argument("--strides", type=int, default=0, help="a straight walk of this many strides instead of "
                                                           "the rectangle (0: rectangle)")
    ap.add_argument("--no-report", action="store_true", help="no output folder: runs only")
    ap.add_argument("--scale", action="store_true", help="the large study: memory and overhead per cell")
    ap.add_argument("--settings", type=int, default=50, help="--scale: settings (default 50)")
    ap.add_argument("--recordings", type=int, default=40, help="--scale: recordings (default 40)")
    ap.add_argument("--base", choices=["recommended", "yun2012"], default="recommended",
                    help="--scale: the pipeline (default recommended; yun2012 is footzoo's cheapest)")
    args = ap.parse_args()
    if args.scale:
        scale(args.settings, args.recordings, args.base)
        return
    from dask.distributed import LocalCluster

    from footzoo.studies import report

    report.write_outputs = _timed_report(report.write_outputs)
    s = study(args.strides)
    print(f"{len(s.cells())} cells ({len(s.cells()) // len(s.recordings)} configs x {len(s.recordings)} recordings), "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start")
    tmp = Path(tempfile.mkdtemp(prefix="footzoo_scaling_"))
    times: dict[str, list[float]] = {"serial": [], "joblib, 2 jobs": [], "dask, 2 processes": []}
    tables = {}
    idle: dict[str, list[float]] = {name: [] for name in times}
    runs_only: dict[str, list[float]] = {name: [] for name in times}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.CRITICAL) as cluster:
        for kw in ({}, {"jobs": 2}, {"scheduler": cluster.scheduler_address}):
            run_study(s, **kw)  # untimed: imports and compiled kernels loaded in every process
        for r in range(args.repeat):
            for name, kw in (("serial", {}), ("joblib, 2 jobs", {"jobs": 2}),
                             ("dask, 2 processes", {"scheduler": cluster.scheduler_address})):
                out = None if args.no_report else tmp / f"{r}_{name.split(',')[0]}"
                t0, c0 = time.perf_counter(), time.process_time()
                tables[name] = run_study(s, out=out, **kw)
                times[name].append(time.perf_counter() - t0)
                main_cpu = time.process_time() - c0
                if out is not None:
                    workers = 1 if name == "serial" else 2
                    runs = main_cpu - REPORT_CPU[-1] + (makespan(s, out, workers) if workers > 1 else 0.0)
                    report_time = REPORT_CPU[-1]
                    if workers > 1:  # the workers draw the figures while the main process writes the tables
                        report_time = max(report_time, lpt(figure_cpu(s, out, tables[name]), workers))
                    idle[name].append(runs + report_time)
                    runs_only[name].append(runs)
                print(f"  {name:18s} run {r + 1}: {times[name][-1]:6.2f} s wall, main process {main_cpu:6.2f} s CPU"
                      + (f" (report {REPORT_CPU[-1]:.2f} s)" if out is not None else ""), flush=True)
    shutil.rmtree(tmp, ignore_errors=True)
    base = min(times["serial"])
    print(f"\n{'back end':18s} {'min (s)':>8s} {'median (s)':>10s} {'speed-up (min)':>15s} {'same table':>11s}"
          + ("" if args.no_report else f" {'idle-machine estimate (s)':>26s} {'speed-up':>9s}"))
    for name, ts in times.items():
        same = tables[name].equals(tables["serial"])
        line = f"{name:18s} {min(ts):8.2f} {statistics.median(ts):10.2f} {base / min(ts):15.2f} {str(same):>11s}"
        if idle[name]:
            line += f" {min(idle[name]):26.2f} {min(idle['serial']) / min(idle[name]):9.2f}"
        print(line)
    if any(runs_only.values()):
        print("\nidle-machine estimate without the report (tables and figures, after the runs):")
        for name, ts in runs_only.items():
            print(f"{name:18s} {min(ts):8.2f} s, speed-up {min(runs_only['serial']) / min(ts):5.2f}")
    print(f"load average {os.getloadavg()[0]:.1f} at the end; a pure-Python loop gets {machine_check():.2f}x from "
          f"two joblib processes on this machine now (about 2 when two cores are free)")


REPORT_CPU: list[float] = []


def _timed_report(write_outputs):
    """Wrap the report writer to record its CPU time in the main process."""
    def timed(*args, **kwargs):
        c0 = time.process_time()
        try:
            return write_outputs(*args, **kwargs)
        finally:
            REPORT_CPU.append(time.process_time() - c0)

    return timed


def makespan(s: Study, out: Path, workers: int) -> float:
    """CPU seconds until the last worker is done, the chunks handed out in order to the first free one."""
    from footzoo.studies import cache, runner

    cells = s.cells()
    identity = {id(r): r.identity() for r in s.recordings}
    keys = [c.key(identity[id(c.recording)]) for c in cells]
    cpu = {k: cache.read_entry(out / "cache" / f"{k}.json", k)[0]["cpu_s"] for k in set(keys)}
    chunks = runner._chunks(list(range(len(cells))), cells, identity, workers)
    return lpt([sum(cpu[keys[i]] for i in chunk) for chunk in chunks], workers)


def lpt(costs: list[float], workers: int) -> float:
    """Finish time of tasks handed out in order, each to the first free worker."""
    free = [0.0] * workers
    for c in costs:
        free[free.index(min(free))] += c
    return max(free)


def figure_cpu(s: Study, out: Path, table) -> list[float]:
    """CPU seconds of each figure task the workers drew, measured again here one after the other."""
    from footzoo.studies import cache, report

    runs = []
    for key, (_, row) in zip(table["run"], table.iterrows(), strict=True):
        if not runs or runs[-1]["key"] != key:
            rec = cache.read_entry(out / "cache" / f"{key}.json", key)[0]
            runs.append({**rec, "recording": row["recording"], "base": row["base"]})
    costs = []
    with tempfile.TemporaryDirectory() as tmp:
        for task in report.figure_tasks(table, runs, list(s.factors), s.figure_metrics()):
            c0 = time.process_time()
            report.draw_figure(task, Path(tmp))
            costs.append(time.process_time() - c0)
    return costs


if __name__ == "__main__":
    main()
