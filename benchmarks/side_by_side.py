"""Two source trees of footzoo timed against each other: every shipped config end to end, alternately.

Usage: python benchmarks/side_by_side.py OTHER [--samples 3e5] [--rounds 4] [--repeat 5] [--configs a,b]

``OTHER`` is another checkout of footzoo (for example an older commit, ``git worktree add
--detach ../footzoo-old <commit>``). Each round runs one new process per tree, this tree and
``OTHER`` in turn, so that load on a shared machine falls on both alike; a process times
``Pipeline.run`` of each config on the same simulated walk (:func:`benchmarks.throughput.walk`)
after a warm-up run (compiled kernels loaded), CPU time, the minimum of ``--repeat`` runs. The
table gives the minimum over the rounds and the speed of this tree relative to ``OTHER``
(above 1: this tree is faster). Configs are read from each tree's own files (``configs/`` in
trees older than footzoo 0.3); only the configs both trees ship are timed.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import gc, json, os, sys, time, warnings
root, names, n, repeat = sys.argv[1], sys.argv[2].split(","), int(float(sys.argv[3])), int(sys.argv[4])
sys.path.insert(0, root)
from benchmarks.throughput import walk
import footzoo
folder = os.path.join(root, "footzoo", "config", "builtin")
folder = folder if os.path.isdir(folder) else os.path.join(root, "configs")
warnings.simplefilter("ignore")
rec, warm = walk(n), walk(20000)
pipes = {c: footzoo.Pipeline.from_yaml(os.path.join(folder, c + ".yaml")) for c in names}
for p in pipes.values():
    p.run(warm)
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


def time_tree(tree: Path, names: list[str], samples: float, repeat: int) -> dict[str, float]:
    """CPU seconds per run of each config, in a new process running ``tree``'s code."""
    proc = subprocess.run([sys.executable, "-c", _CHILD, str(tree), ",".join(names), str(samples), str(repeat)],
                          capture_output=True, text=True, check=True, cwd=tree)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="another footzoo checkout")
    parser.add_argument("--samples", type=float, default=3e5)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--configs", help="only these configs (comma-separated)")
    args = parser.parse_args()
    other = args.other.resolve()
    names = sorted(shipped(ROOT) & shipped(other))
    if args.configs:
        names = [c for c in args.configs.split(",") if c in names]
    runs: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    for _ in range(args.rounds):
        runs["other"].append(time_tree(other, names, args.samples, args.repeat))
        runs["this"].append(time_tree(ROOT, names, args.samples, args.repeat))
    n = int(args.samples)
    print(f"{n} samples of a simulated 100 Hz walk; CPU time per run, minimum over {args.rounds} rounds × "
          f"{args.repeat} runs; OTHER = {other}\n")
    print("| config | OTHER: ms per run | this tree: ms per run | speed of this tree / OTHER |")
    print("|---|---|---|---|")
    for c in names:
        a, b = min(r[c] for r in runs["other"]), min(r[c] for r in runs["this"])
        print(f"| {c} | {1e3 * a:.1f} | {1e3 * b:.1f} | {a / b:.2f} |")


if __name__ == "__main__":
    main()
