"""The documentation's code runs: every ```python block of docs/**/*.md and README.md, in order, per file.

The blocks of one file run as one script (like a notebook), in a fresh process (a plug-in defined
in the docs must not meet one registered by another test) and a fresh folder holding a copy of
``configs/``. A block preceded by the line ``<!-- docs: no-run -->`` is skipped (e.g. one that
needs a Dask scheduler); a line ``--8<-- "path"`` includes that file, as in the built site. The
files the README's shell examples would create first (``walk.csv`` from ``footzoo simulate``)
are made here, small; gaitmap's example files are copied from ``../shared/data`` (the README
test skips without them).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ..conftest import DATA, data_file

ROOT = Path(__file__).resolve().parents[2]
NO_RUN = "<!-- docs: no-run -->"
FENCE = re.compile(r"^```python[^\n]*\n(.*?)^```", re.S | re.M)
SNIPPET = re.compile(r'^--8<-- "([^"]+)"\s*$', re.M)
#: Runs the blocks one by one in one namespace (each compiled on its own: ``from __future__`` may open any).
RUNNER = """import json
namespace = {"__name__": "__main__"}
for name in json.load(open("blocks.json")):
    with open(name) as fh:
        exec(compile(fh.read(), name, "exec"), namespace)
"""


def python_blocks(text: str) -> list[tuple[int, str, bool]]:
    """``(line, code, runnable)`` of every python fence, snippet includes expanded."""
    out = []
    for m in FENCE.finditer(text):
        before = text[: m.start()].rstrip().splitlines()
        runnable = not (before and before[-1].strip() == NO_RUN)
        code = SNIPPET.sub(lambda s: (ROOT / s.group(1)).read_text(), m.group(1))
        out.append((text[: m.start()].count("\n") + 1, code, runnable))
    return out


def markdown_files() -> list[Path]:
    """README.md and the hand-written pages of docs/ that have at least one runnable python block."""
    docs = sorted(p for p in (ROOT / "docs").rglob("*.md"))
    return [p for p in [ROOT / "README.md", *docs] if any(run for _, _, run in python_blocks(p.read_text()))]


def test_block_extraction():
    text = "intro\n```python\nx = 1\n```\n\n<!-- docs: no-run -->\n```python\nraise SystemExit\n```\n```bash\nls\n```\n"
    assert python_blocks(text) == [(2, "x = 1\n", True), (7, "raise SystemExit\n", False)]
    assert python_blocks('```python\n--8<-- "pyproject.toml"\n```\n')[0][1] == (ROOT / "pyproject.toml").read_text()


#: The pages whose code takes longest (a study, the tutorial's several runs: about 10 s each; a live run kept and
#: scored, the uncertainty page's runs, the guards' and the generic reader's: 4-6 s each): with the slow tests.
SLOW_PAGES = ("docs/getting-started.md", "docs/studies.md", "docs/live.md", "docs/uncertainty.md", "docs/guards.md",
              "docs/readers/generic.md")


def _page(path: Path) -> object:
    name = str(path.relative_to(ROOT))
    return pytest.param(path, id=name, marks=[pytest.mark.slow] if name in SLOW_PAGES else [])


@pytest.mark.parametrize("path", [_page(p) for p in markdown_files()])
def test_code_blocks_run(path, tmp_path):
    blocks = [b for b in python_blocks(path.read_text()) if b[2]]
    if path.name == "README.md":
        from footzoo.io import canonical
        from footzoo.sim import simulate

        canonical.write(simulate(path="straight", n_strides=8, rate=100.0), tmp_path / "walk.csv")
        if "imu_sample.csv" in path.read_text():  # gaitmap's example with its mocap reference files
            for f in data_file("gaitmap_example", "imu_sample.csv").parent.iterdir():
                if f.is_file():
                    shutil.copy(f, tmp_path / f.name)
    if "pyshoe_vicon" in "".join(code for _, code, _ in blocks):  # a tutorial on PyShoe's trials
        data_file("pyshoe_vicon")
    files = []
    for line, code, _ in blocks:  # real files: numba's cache and tracebacks need them
        f = tmp_path / f"{path.stem}_block_at_line_{line}.py"
        f.write_text(code)
        files.append(f.name)
    (tmp_path / "blocks.json").write_text(json.dumps(files))
    (tmp_path / "blocks.py").write_text(RUNNER)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
           "MPLBACKEND": "Agg", "FOOTZOO_DATA": str(DATA)}
    run = subprocess.run([sys.executable, "blocks.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, (
        f"{path.relative_to(ROOT)}: a code block failed (the blocks run as {tmp_path / 'blocks.py'}):\n"
        + run.stderr[-3000:]
    )
