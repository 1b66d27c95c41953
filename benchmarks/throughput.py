"""footzoo's speed against the hardware limit and other libraries, side by side in one run.

Usage: python benchmarks/throughput.py [--samples 1e6] [--repeat 5] [--slow-samples 20000]
                                        [--scaling] [--cold] [--import-time] [--no-table] [--out FILE.md]
                                        [--configs recommended,...]

Every item runs on the same simulated 100 Hz walk (distance sensors included), interleaved:
each repetition runs every item once, in the same order, so load on the machine hits all of
them alike; the table gives the minimum and the median over the repetitions, in samples per
second of wall-clock time, and each item's speed as a fraction of (a) measured in the same
run (from the minima; also from CPU time, which other processes on a shared machine disturb
less). Items:

* (a) the hardware limit: a minimal compiled strapdown loop that stores attitude, velocity
  and position for every sample (benchmarks/hardware_limit.py);
* every config shipped with footzoo end to end (``Pipeline.run``: detector, alignment, orientation,
  corrections, the sample table and the step table); a config with a smoother also with the other
  smoother (RTS over the whole recording, step-wise) and with its forward filter alone;
* each orientation filter and each detector alone;
* (b) plain filterpy loops: a 9-state (position, velocity, attitude) and a 15-state (plus gyro
  and accelerometer biases) zero-velocity-aided error-state filter written directly on
  ``filterpy.kalman.KalmanFilter``;
* (c) gaitmap's ``RtsKalman``, ahrs' Madgwick and Mahony filters and imufusion's AHRS, when
  installed (never dependencies of footzoo).

The pure-Python baselines (b, c) run on the first ``--slow-samples`` samples of the same walk
(their cost per sample does not depend on the length). Optional sections: ``--scaling`` (µs per
sample and peak memory beyond the input, 1e5 to 1e7 samples, one new process per size; again
with numpy's huge-page hint off),
``--cold`` (a new process with an empty numba cache: import, build and first run of a config on a
simulated 80-stride walk; from the source tree and from a wheel built from it, which ships the
kernels of the shipped configs), ``--import-time``. The ``met`` column judges the CPU-time fraction
("wall-clock only": met by the wall-clock minima alone).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import footzoo  # noqa: E402
from footzoo.sim import NoiseModel, simulate  # noqa: E402

CONFIGS = sorted(p.stem for p in footzoo.config.BUILTIN.glob("*.yaml") if not p.stem.startswith("study"))
#: Targets of issue 16 as the fraction of (a)'s speed, by kind of item.
TARGETS = {"no Kalman filter": 1 / 8, "9-state Kalman": 1 / 10, "15-state Kalman": 1 / 20,
           "21-state Kalman": 1 / 50, "orientation filter": 1 / 3, "detector": 1 / 2}


def walk(samples: int) -> footzoo.Recording:
    """A simulated 100 Hz walk with distance sensors, tiled to ``samples``."""
    r = simulate(n_strides=200, rate=100.0, profile="physical", noise=NoiseModel(seed=0), distance_sensors=True,
                 clearance=0.1)
    reps = int(np.ceil(samples / r.n))
    n = min(samples, r.n * reps)
    tile = (lambda a: np.tile(a, (reps, 1))[:n])  # noqa: E731
    return footzoo.Recording(t=np.arange(n) / 100.0, acc=tile(r.acc), gyr=tile(r.gyr), mag=tile(r.mag),
                             dist=tile(r.dist), meta={"foot": "right", "name": "bench"})


# ------------------------------------------------------------------------------------------ items
class Item:
    """One thing to time: ``fn()`` processes ``n`` samples."""

    def __init__(self, name: str, kind: str, fn: Callable[[], object], n: int, note: str = ""):
        self.name, self.kind, self.fn, self.n, self.note = name, kind, fn, n, note
        self.wall: list[float] = []
        self.cpu: list[float] = []

    def run(self) -> None:
        c0, w0 = time.process_time(), time.perf_counter()
        self.fn()
        self.wall.append(time.perf_counter() - w0)
        self.cpu.append(time.process_time() - c0)


def hardware_item(rec) -> Item:
    from benchmarks.hardware_limit import strapdown

    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    strapdown(rec.t[:100], rec.acc[:100], rec.gyr[:100], q0)  # compile
    return Item("(a) minimal compiled strapdown loop", "hardware limit",
                lambda: strapdown(rec.t, rec.acc, rec.gyr, q0), rec.n)


def kalman_states(p) -> int:
    """Error-state size of a Kalman pipeline (0 without one)."""
    from footzoo.filters.engine import assemble

    kalman = p.filter_corrections
    if not kalman:
        return 0
    blocks = [b for c in kalman for b in c.state_blocks()]
    return int(assemble(p.orientation.carried_by_filter, blocks, p.navigation)[0].n)


#: The smoothers a config with one is also timed with (label).
SMOOTHERS = {"rts": "RTS", "stepwise": "step-wise"}


def config_items(rec, warm, names: list[str] | None = None) -> list[Item]:
    items = []
    for name in names or CONFIGS:
        p = footzoo.Pipeline.from_yaml(ROOT / "configs" / f"{name}.yaml")
        p.run(warm)  # compile / load the compiled kernels
        n_states = kalman_states(p)
        kind = "no Kalman filter" if n_states == 0 else f"{min((9, 15, 21), key=lambda s: abs(s - n_states))}" \
            "-state Kalman"
        label = f"config {name}" + (f" ({n_states} states)" if n_states else "")
        if p.smoother != "none":
            # a smoother adds a backward pass the targets do not cover: shown apart (the config's
            # own and the other one), with the same config's forward filter alone judged against its kind's target
            for smoother in (p.smoother, *(s for s in SMOOTHERS if s != p.smoother)):
                q = footzoo.Pipeline.from_dict({**p.to_dict(), "smoother": smoother})
                q.run(warm)
                items.append(Item(f"{label} + {SMOOTHERS[smoother]} smoother", f"{kind} + smoother",
                                  lambda q=q: q.run(rec), rec.n))
            d = p.to_dict()
            d["smoother"] = "none"
            p = footzoo.Pipeline.from_dict(d)
            p.run(warm)
            label += ", forward filter only"
        items.append(Item(label, kind, lambda p=p: p.run(rec), rec.n))
    return items


def plugin_items(rec, warm) -> list[Item]:
    from footzoo.plugins.registry import available, build

    t, acc, gyr, mag = rec.t, rec.acc, rec.gyr, rec.mag
    stance = build("detector", {"type": "windowed"}).detect(t, acc, gyr).stance_
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    items = []
    for name, cls in sorted(available("orientation").items()):
        o = cls()
        o.estimate(warm.t, warm.acc, warm.gyr, warm.mag, stance[: warm.n], q0)
        items.append(Item(f"orientation {name}", "orientation filter",
                          lambda o=o: o.estimate(t, acc, gyr, mag, stance, q0), rec.n))
    for name, cls in sorted(available("detector").items()):
        if getattr(cls, "needs_truth", False) or name == "oracle":
            continue
        d = cls()
        d.detect(warm.t, warm.acc, warm.gyr)
        items.append(Item(f"detector {name}", "detector", lambda d=d: d.detect(t, acc, gyr), rec.n))
    return items


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def filterpy_zupt(t, acc, gyr, stance, q0, biases: bool, g: float = 9.81) -> np.ndarray:
    """A plain zero-velocity-aided error-state filter on ``filterpy.kalman.KalmanFilter``.

    Error state ``[δp, δv, δθ]`` (9) or ``[δp, δv, δθ, δb_g, δb_a]`` (15); per sample a
    strapdown step, ``F``/``Q`` set and ``predict()``, in stance ``update()`` with the velocity
    as the measurement of ``δv``, then the error fed back into the nominal state. Returns the
    positions (N, 3).
    """
    from filterpy.kalman import KalmanFilter

    from footzoo.core.conventions import quat_from_rotvec, quat_mul, quat_to_matrix

    n_x = 15 if biases else 9
    kf = KalmanFilter(dim_x=n_x, dim_z=3)
    kf.P = np.diag([0.0] * 6 + [1e-4] * 3 + ([1e-6] * 6 if biases else []))
    kf.R = np.eye(3) * 1e-4
    h = np.zeros((3, n_x))
    h[:, 3:6] = np.eye(3)
    q, v, p = np.asarray(q0, float), np.zeros(3), np.zeros(3)
    bg, ba = np.zeros(3), np.zeros(3)
    out = np.empty((len(t), 3))
    eye = np.eye(n_x)
    for k in range(len(t)):
        dt = t[k] - t[k - 1] if k else 0.0
        q = quat_mul(q, quat_from_rotvec((gyr[k] - bg) * dt))
        c = quat_to_matrix(q)
        f_n = c @ (acc[k] - ba)
        a = f_n + np.array([0.0, 0.0, g])
        p = p + v * dt + 0.5 * a * dt * dt
        v = v + a * dt
        f = eye.copy()
        f[0:3, 3:6] = np.eye(3) * dt
        f[3:6, 6:9] = -_skew(f_n) * dt
        qn = np.zeros(n_x)
        qn[3:6], qn[6:9] = 1e-4 * dt, 1e-6 * dt
        if biases:
            f[6:9, 9:12] = -c * dt
            f[3:6, 12:15] = -c * dt
            qn[9:] = 1e-10 * dt
        kf.F, kf.Q = f, np.diag(qn)
        kf.predict()
        if stance[k]:
            kf.update(v.reshape(3, 1), H=h)
            x = kf.x.ravel()
            p, v = p - x[0:3], v - x[3:6]
            q = quat_mul(quat_from_rotvec(-x[6:9]), q)
            if biases:
                bg, ba = bg + x[9:12], ba + x[12:15]
            kf.x = np.zeros((n_x, 1))
        out[k] = p
    return out


def baseline_items(rec, slow: int) -> list[Item]:
    """(b) plain filterpy loops and (c) other libraries, on the first ``slow`` samples."""
    from footzoo.plugins.registry import build
    from footzoo.runtime.alignment import initial_attitude

    s = slice(0, slow)
    t, acc, gyr, mag = rec.t[s], rec.acc[s], rec.gyr[s], rec.mag[s]
    stance = build("detector", {"type": "windowed"}).detect(t, acc, gyr).stance_
    q0 = initial_attitude(t, acc, gyr, None)
    items = []
    try:
        import filterpy  # noqa: F401

        for biases, states in ((False, 9), (True, 15)):
            items.append(Item(f"(b) filterpy loop, {states} states", f"{states}-state Kalman",
                              lambda b=biases: filterpy_zupt(t, acc, gyr, stance, q0, b), slow))
    except ImportError:
        pass
    try:
        from ahrs.filters import Madgwick, Mahony

        items.append(Item("(c) ahrs Madgwick (MARG)", "orientation filter",
                          lambda: Madgwick(gyr=gyr, acc=acc, mag=mag, frequency=100.0), slow))
        items.append(Item("(c) ahrs Mahony (IMU)", "orientation filter",
                          lambda: Mahony(gyr=gyr, acc=acc, frequency=100.0), slow))
    except ImportError:
        pass
    try:
        import imufusion

        def fusion():
            ahrs = imufusion.Ahrs()
            g_deg, a_g = np.degrees(gyr), acc / -9.81
            for k in range(len(t)):
                ahrs.update(g_deg[k], a_g[k], mag[k], 0.01)

        items.append(Item("(c) imufusion Ahrs", "orientation filter", fusion, slow))
    except ImportError:
        pass
    try:
        import pandas as pd
        from gaitmap.trajectory_reconstruction import RtsKalman

        data = pd.DataFrame(np.column_stack([acc, np.degrees(gyr)]),
                            columns=["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"])
        items.append(Item("(c) gaitmap RtsKalman", "9-state Kalman",
                          lambda: RtsKalman().estimate(data, sampling_rate_hz=100.0), slow))
    except ImportError:
        pass
    return items


def main_table(n: int, repeat: int, slow: int, configs: list[str] | None = None) -> tuple[list[str], dict]:
    rec = walk(n)
    warm = walk(20_000)
    hw = hardware_item(rec)
    items = [hw] + config_items(rec, warm, configs)
    if not configs:
        items += plugin_items(rec, warm) + baseline_items(rec, min(slow, n))
    for it in items[1:]:
        if it.n < n:
            it.note = f"first {it.n // 1000} k samples"
    for _ in range(repeat):
        for it in items:
            it.run()
    lim_wall = hw.n / min(hw.wall)
    lim_cpu = hw.n / min(hw.cpu)
    lines = [
        f"{n} samples of a simulated 100 Hz walk, {repeat} interleaved repetitions, one core; "
        f"numba {'on' if footzoo.kernels.jit.HAVE_NUMBA else 'off'}.",
        "",
        "| item | kind | M samples/s (min time) | M samples/s (median) | fraction of (a), wall | "
        "fraction of (a), CPU | target | met (CPU) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    results = {}
    for it in items:
        best, med, cpu = it.n / min(it.wall), it.n / statistics.median(it.wall), it.n / min(it.cpu)
        frac, frac_cpu = best / lim_wall, cpu / lim_cpu
        target = TARGETS.get(it.kind)
        if it is hw or it.name.startswith("(") or target is None:
            met = ""
        else:
            met = "yes" if frac_cpu >= target else ("wall-clock only" if frac >= target else "no")
        tgt = f"1/{round(1 / target)}" if target and not it.name.startswith("(") else ""
        label = it.name + (f" ({it.note})" if it.note else "")
        lines.append(f"| {label} | {it.kind} | {best / 1e6:.3g} | {med / 1e6:.3g} | {_frac(frac)} | "
                     f"{_frac(frac_cpu)} | {tgt} | {met} |")
        results[it.name] = {"per_s_min": best, "per_s_median": med, "per_s_cpu": cpu, "fraction": frac,
                            "fraction_cpu": frac_cpu}
    return lines + smoother_cost(items, lim_cpu), results


#: Issue 23: a smoother adds at most this much of its forward pass's time; the smoothed flagship runs at
#: least at this fraction of the minimal strapdown loop.
SMOOTHER_COST, FLAGSHIP_FRACTION = 1.5, 1 / 10


def smoother_cost(items: list[Item], lim_cpu: float) -> list[str]:
    """What each smoother adds to its config's forward filter, from the same run's minimum CPU times."""
    forward = {it.name.removesuffix(", forward filter only"): it for it in items
               if it.name.endswith(", forward filter only")}
    lines = ["", "Smoother cost (minimum CPU time of the same run): the time a smoother adds, as a multiple of "
             "the same config's forward filter alone, and the smoothed config's fraction of (a).", "",
             "| config | smoother | adds × the forward filter | target | met | fraction of (a), CPU | target | met |",
             "|---|---|---|---|---|---|---|---|"]
    for it in items:
        base, _, smoother = it.name.partition(" + ")
        if base not in forward or not smoother.endswith(" smoother"):
            continue
        added = min(it.cpu) / min(forward[base].cpu) - 1.0
        frac = it.n / min(it.cpu) / lim_cpu
        met_cost, met_frac = ("yes" if ok else "no" for ok in (added <= SMOOTHER_COST, frac >= FLAGSHIP_FRACTION))
        name = smoother.removesuffix(" smoother")
        lines.append(f"| {base} | {name} | {added:.2f} | ≤ {SMOOTHER_COST} | {met_cost} | {_frac(frac)} | "
                     f"1/{round(1 / FLAGSHIP_FRACTION)} | {met_frac} |")
    return lines if len(lines) > 5 else []


def _frac(x: float) -> str:
    return "1" if x >= 0.95 else f"1/{1 / x:.3g}" if x > 0 else "-"


# --------------------------------------------------------------------------- scaling and memory
_SCALING_CHILD = """
import gc, json, resource, sys, time
sys.path.insert(0, {root!r})
from benchmarks.throughput import walk
import footzoo
n, name, repeat = {n}, {name!r}, {repeat}
if name == "(a)":
    import numpy as np
    from benchmarks.hardware_limit import strapdown
    class p:
        run = staticmethod(lambda r: strapdown(r.t, r.acc, r.gyr, np.array([1.0, 0.0, 0.0, 0.0])))
else:
    p = footzoo.Pipeline.from_yaml({root!r} + f"/configs/{{name}}.yaml")
p.run(walk(3000))  # load the compiled kernels, on little memory
rec = walk(n)
gc.collect()
with open("/proc/self/statm") as f:
    base = int(f.read().split()[1]) * resource.getpagesize()
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")  # reset the peak resident set size to the current one
res = p.run(rec)  # the first run on this input: its memory is new to the process
with open("/proc/self/status") as f:
    peak = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmHWM"))
del res
gc.collect()
runs = []
for _ in range(repeat):
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    p.run(rec)
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    runs.append((r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, r1.ru_stime - r0.ru_stime,
                 r1.ru_minflt - r0.ru_minflt))
cpu, sys_, faults = min(runs)
print(json.dumps({{"us_per_sample": cpu / n * 1e6, "sys_us_per_sample": sys_ / n * 1e6,
                   "faults_per_sample": faults / n, "bytes_per_sample": (peak - base) / n}}))
"""


def scaling(names: list[str], sizes=(100_000, 1_000_000, 10_000_000), repeat: int = 5,
            env: dict[str, str] | None = None) -> list[str]:
    """µs per sample (CPU time, min over runs) and peak RSS beyond the input; a new process per config and size.

    The system part of the CPU time is given apart: it is the kernel's work for memory the run
    touches for the first time (page faults, zeroing), which grows with the recording's length
    once its arrays are too large for the allocator to recycle. ``env``: extra environment
    variables of the child processes (e.g. ``NUMPY_MADVISE_HUGEPAGE=0``).
    """
    rows: dict[str, list[tuple[float, float]]] = {c: [] for c in names}
    for n in sizes:
        for c in names:
            code = _SCALING_CHILD.format(root=str(ROOT), n=n, name=c, repeat=repeat if n < 10**7 else 3)
            proc = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True,
                                  cwd=ROOT, env={**os.environ, **(env or {})})
            if proc.returncode != 0:
                raise RuntimeError(proc.stderr[-2000:])
            res = json.loads(proc.stdout.strip().splitlines()[-1])
            rows[c].append((res["us_per_sample"], res["bytes_per_sample"], res["sys_us_per_sample"]))
    head = " / ".join(f"{n:.0e}" for n in sizes)
    lines = [f"| config ((a): the strapdown loop) | µs/sample at {head} | max / min | of which in the kernel "
             f"(system time, page faults), µs/sample | peak memory beyond the input (B/sample) at {head} |",
             "|---|---|---|---|---|"]
    for c, r in rows.items():
        us = [x[0] for x in r]
        lines.append(f"| {c} | " + " / ".join(f"{x:.3f}" for x in us) + f" | {max(us) / min(us):.2f} | "
                     + " / ".join(f"{x[2]:.3f}" for x in r) + " | " + " / ".join(f"{x[1]:.0f}" for x in r) + " |")
    return lines


# ------------------------------------------------------------------------------ cold start, import
def cold_start(names: list[str], wheel: bool = True) -> list[str]:
    """A new process, an empty numba cache: import, build and the first run of one config on a simulated 80-stride walk.

    Twice: from the source tree (every kernel compiled at its first call), and, with ``wheel``, from
    a wheel built from this tree (``pip wheel``, which runs setup.py's kernel precompilation) and
    installed into a temporary folder, with its shipped kernels. Wall-clock and CPU seconds (the
    CPU time of the process, which load from other processes on a shared machine does not
    inflate). The build (``Pipeline.from_yaml``) is timed apart: work done there (importing numba,
    compiling) is not in the first run, so the total adds the three.
    """
    lines = ["| config | installed as | import footzoo, wall / CPU (s) | build the pipeline, wall / CPU (s) | "
             "first run, empty cache, wall / CPU (s) | import + build + first run, wall / CPU (s) | "
             "first run, a second process with the cache filled, wall / CPU (s) |", "|---|---|---|---|---|---|---|"]
    code = ("import time; c0, w0 = time.process_time(), time.perf_counter(); import footzoo;"
            "c1, w1 = time.process_time(), time.perf_counter();"
            "from footzoo.sim import simulate; rec = simulate(n_strides=80, rate=100.0, profile='physical');"
            "c2, w2 = time.process_time(), time.perf_counter(); p = footzoo.Pipeline.from_yaml({config!r});"
            "c3, w3 = time.process_time(), time.perf_counter(); p.run(rec);"
            "print(w1 - w0, c1 - c0, w3 - w2, c3 - c2, time.perf_counter() - w3, time.process_time() - c3)")
    with tempfile.TemporaryDirectory() as tmp:
        setups = [("source tree (compiled at first use)", ROOT, {})]
        if wheel:
            setups.append(("wheel (kernels shipped)", Path(tmp), {"PYTHONPATH": _installed_wheel(Path(tmp))}))
        for c in names:
            for label, cwd, extra in setups:
                with tempfile.TemporaryDirectory() as cache:
                    env = {**os.environ, **extra, "NUMBA_CACHE_DIR": cache}
                    out = []
                    script = code.format(config=str(ROOT / "configs" / f"{c}.yaml"))
                    for _ in range(2):
                        proc = subprocess.run([sys.executable, "-W", "ignore", "-c", script], capture_output=True,
                                              text=True, cwd=cwd, env=env)
                        if proc.returncode != 0:
                            raise RuntimeError(proc.stderr[-2000:])
                        out.append([float(x) for x in proc.stdout.split()])
                first = out[0]
                lines.append(f"| {c} | {label} | {first[0]:.2f} / {first[1]:.2f} | {first[2]:.2f} / {first[3]:.2f} | "
                             f"{first[4]:.2f} / {first[5]:.2f} | {first[0] + first[2] + first[4]:.2f} / "
                             f"{first[1] + first[3] + first[5]:.2f} | {out[1][4]:.2f} / {out[1][5]:.2f} |")
    return lines


def _installed_wheel(tmp: Path) -> str:
    """Build a wheel of this tree as pip does (precompiling its kernels) and install it into ``tmp``."""
    pip = [sys.executable, "-m", "pip", "-q"]
    subprocess.run([*pip, "wheel", "--no-deps", "-w", str(tmp / "dist"), str(ROOT)], check=True)
    site = tmp / "site"
    subprocess.run([*pip, "install", "--no-deps", "--target", str(site), *map(str, (tmp / "dist").glob("*.whl"))],
                   check=True)
    if not list(site.glob("footzoo/_compiled/*/*.nbi")):
        raise RuntimeError("the wheel carries no compiled kernels: see the output of setup.py above")
    return str(site)


def import_time(repeat: int = 5) -> list[str]:
    lines = ["| statement | wall (s), min | CPU (s), min |", "|---|---|---|"]
    for stmt in ("import footzoo", "from footzoo import Pipeline", "from footzoo import Pipeline, load"):
        code = (f"import time; c = time.process_time(); w = time.perf_counter(); {stmt};"
                "print(time.perf_counter() - w, time.process_time() - c)")
        res = [[float(x) for x in subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                                 cwd=ROOT).stdout.split()] for _ in range(repeat)]
        lines.append(f"| `{stmt}` | {min(r[0] for r in res):.3f} | {min(r[1] for r in res):.3f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=float, default=1e6)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--slow-samples", type=int, default=20_000, help="samples for the pure-Python baselines")
    parser.add_argument("--scaling", action="store_true", help="1e5..1e7 samples: µs/sample and memory")
    parser.add_argument("--cold", action="store_true", help="first run with an empty numba cache")
    parser.add_argument("--import-time", action="store_true")
    parser.add_argument("--no-table", action="store_true", help="only the optional sections")
    parser.add_argument("--out", type=Path, help="also write the Markdown here")
    parser.add_argument("--configs", help="only these configs (comma-separated), in every section; the main table "
                        "then leaves out the plug-ins and libraries, the scaling keeps its reference (a)")
    parser.add_argument("--json", type=Path, help="write the main table's numbers here")
    args = parser.parse_args()
    chosen = args.configs.split(",") if args.configs else None
    sections = []
    if not args.no_table:
        lines, results = main_table(int(args.samples), args.repeat, args.slow_samples, chosen)
        sections.append(("Throughput", lines))
        _emit(sections[-1])
        if args.json:
            args.json.write_text(json.dumps(results, indent=1))
    if args.scaling:
        names = ["(a)", *(chosen or ["yun2012", "huang2016", "nguyen2016_ins_zvu"])]
        sections.append(("Scaling and memory (CPU time, min of runs; peak RSS beyond the input)", scaling(names)))
        _emit(sections[-1])
        # numpy asks Linux for transparent huge pages for large arrays; where a huge-page fault costs
        # more than the 512 small ones it replaces (some virtual machines), that alone breaks linearity
        sections.append(("The same with NUMPY_MADVISE_HUGEPAGE=0 (numpy gives the kernel no huge-page hint)",
                         scaling(names, env={"NUMPY_MADVISE_HUGEPAGE": "0"})))
        _emit(sections[-1])
    if args.cold:
        sections.append(("Cold start (new process, empty numba cache; source tree and installed wheel)",
                         cold_start(chosen or ["yun2012", "huang2016", "duong2015_zupt", "nguyen2016"])))
        _emit(sections[-1])
    if args.import_time:
        sections.append(("Import time (new process, min of 5)", import_time()))
        _emit(sections[-1])
    if args.out:
        args.out.write_text("\n\n".join(f"### {title}\n\n" + "\n".join(lines) for title, lines in sections) + "\n")


def _emit(section: tuple[str, list[str]]) -> None:
    print(f"\n### {section[0]}\n")
    print("\n".join(section[1]), flush=True)


if __name__ == "__main__":
    main()
