"""Two source trees of footzoo timed against each other: every shipped config end to end, alternately.

Usage: python benchmarks/side_by_side.py OTHER [--samples 3e5] [--rounds 6] [--repeat 5] [--configs a,b]

``OTHER`` is another checkout of footzoo (for example an older commit, ``git worktree add
--detach ../footzoo-old <commit>``). Each round runs one new process per tree, this tree and
``OTHER`` in turn, so that load on a shared machine falls on both alike; a process times
``Pipeline.run`` of each config on the same simulated walk (:func:`benchmarks.throughput.walk`,
simulated once by this tree and handed to both as arrays, so that a change in the simulator does not
change what is timed) after a warm-up run of every config on that same walk (below), CPU time, the
minimum of ``--repeat`` runs. Per-process differences in the same code (measured up to 20 % on one
kernel) make the minimum over several rounds the figure to read (the default: 6). The table gives the
minimum over the rounds and the speed of this tree relative to ``OTHER`` (above 1: this tree is
faster). Configs are read from each tree's own files (``configs/`` in trees older than footzoo 0.3);
only the configs both trees ship are timed.

Why the warm-up is the timed walk itself: it loads the compiled kernels and grows the memory allocator
to the run's size. After a warm-up on a shorter walk, glibc's allocator can go on returning and
refetching pages at every run, and how many depends on the allocation history of the process, not on
the code timed: measured on nguyen2016_ins_zvu_hdr (1e5 samples, all ten configs in one process, after
a 2e4-sample warm-up), 586 minor page faults per run in one tree and 2 898 in another, 28.8 against 32.1 ms;
after a warm-up on the timed walk, 0 faults in both, 26.2 against 24.9 ms.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import gc, json, os, sys, time, warnings
root, names, arrays, repeat = sys.argv[1], sys.argv[2].split(","), sys.argv[3], int(sys.argv[4])
sys.path.insert(0, root)
import numpy as np
import footzoo
def walk(path):
    with np.load(path) as a:
        return footzoo.Recording(t=a["t"], acc=a["acc"], gyr=a["gyr"], mag=a["mag"], dist=a["dist"],
                                 meta={"foot": "right", "name": "bench"})
folder = os.path.join(root, "footzoo", "config", "builtin")
folder = folder if os.path.isdir(folder) else os.path.join(root, "configs")
warnings.simplefilter("ignore")
rec = walk(arrays)
pipes = {c: footzoo.Pipeline.from_yaml(os.path.join(folder, c + ".yaml")) for c in names}
for p in pipes.values():
    p.run(rec)
best = {c: float("inf") for c in names}
for _ in range(repeat):
    for c, p in pipes.items():
        gc.collect()
        t0 = time.process_time()
        p.run(rec)
        best[c] = min(best[c], time.process_time() - t0)
print(json.dumps(best))
"""


def shipped(tree: Path) -> set[str]:
    """The pipeline configs a tree ships (not the study files)."""
    folder = tree / "footzoo" / "config" / "builtin"
    folder = folder if folder.is_dir() else tree / "configs"
    return {p.stem for p in folder.glob("*.yaml") if not p.stem.startswith("study")}


def write_walk(samples: float, path: Path) -> None:
    """This tree's timed walk (:func:`benchmarks.throughput.walk`) as arrays in ``path`` (.npz)."""
    sys.path.insert(0, str(ROOT))
    from benchmarks.throughput import walk

    r = walk(int(samples))
    np.savez(path, t=r.t, acc=r.acc, gyr=r.gyr, mag=r.mag, dist=r.dist)


def time_tree(tree: Path, names: list[str], arrays: Path, repeat: int) -> dict[str, float]:
    """CPU seconds per run of each config, in a new process running ``tree``'s code on ``arrays``."""
    proc = subprocess.run([sys.executable, "-c", _CHILD, str(tree), ",".join(names), str(arrays), str(repeat)],
                          capture_output=True, text=True, check=True, cwd=tree)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="another footzoo checkout")
    parser.add_argument("--samples", type=float, default=3e5)
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--configs", help="only these configs (comma-separated)")
    args = parser.parse_args()
    other = args.other.resolve()
    names = sorted(shipped(ROOT) & shipped(other))
    if args.configs:
        names = [c for c in args.configs.split(",") if c in names]
    runs: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    with tempfile.TemporaryDirectory() as folder:
        arrays = Path(folder) / "walk.npz"
        write_walk(args.samples, arrays)
        for _ in range(args.rounds):
            runs["other"].append(time_tree(other, names, arrays, args.repeat))
            runs["this"].append(time_tree(ROOT, names, arrays, args.repeat))
    n = int(args.samples)
    print(f"{n} samples of one simulated 100 Hz walk (this tree's simulator), the same for both trees; "
          f"CPU time per run, minimum over {args.rounds} rounds × {args.repeat} runs; OTHER = {other}\n")
    print("| config | OTHER: ms per run | this tree: ms per run | speed of this tree / OTHER |")
    print("|---|---|---|---|")
    for c in names:
        a, b = min(r[c] for r in runs["other"]), min(r[c] for r in runs["this"])
        print(f"| {c} | {1e3 * a:.1f} | {1e3 * b:.1f} | {a / b:.2f} |")


if __name__ == "__main__":
    main()
