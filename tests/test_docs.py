"""The documentation's code runs: every ```python block of docs/**/*.md and README.md, in order, per file.

Blocks of one file share a namespace (like a notebook) and run in a fresh folder holding a copy
of ``configs/``. A block preceded by the line ``<!-- docs: no-run -->`` is skipped (e.g. one
that needs a Dask scheduler). The files the README's shell examples would create first
(``walk.csv`` from ``footzoo simulate``) are made here, small.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
NO_RUN = "<!-- docs: no-run -->"
FENCE = re.compile(r"^```python[^\n]*\n(.*?)^```", re.S | re.M)


def markdown_files() -> list[Path]:
    """README.md and the hand-written pages of docs/ that have at least one runnable python block."""
    docs = sorted(p for p in (ROOT / "docs").rglob("*.md"))
    return [p for p in [ROOT / "README.md", *docs] if any(run for _, _, run in python_blocks(p.read_text()))]


def python_blocks(text: str) -> list[tuple[int, str, bool]]:
    """``(line, code, runnable)`` of every python fence."""
    out = []
    for m in FENCE.finditer(text):
        before = text[: m.start()].rstrip().splitlines()
        runnable = not (before and before[-1].strip() == NO_RUN)
        out.append((text[: m.start()].count("\n") + 1, m.group(1), runnable))
    return out


def test_block_extraction():
    text = "intro\n```python\nx = 1\n```\n\n<!-- docs: no-run -->\n```python\nraise SystemExit\n```\n```bash\nls\n```\n"
    assert python_blocks(text) == [(2, "x = 1\n", True), (7, "raise SystemExit\n", False)]


@pytest.mark.parametrize("path", markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_code_blocks_run(path, tmp_path, monkeypatch):
    blocks = [b for b in python_blocks(path.read_text()) if b[2]]
    shutil.copytree(ROOT / "configs", tmp_path / "configs")
    if path.name == "README.md":
        from footzoo.io import canonical
        from footzoo.sim import simulate

        canonical.write(simulate(path="straight", n_strides=8, rate=100.0), tmp_path / "walk.csv")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__docs__"}
    for line, code, _ in blocks:
        try:
            exec(compile(code, f"{path.name}:{line}", "exec"), namespace)
        except Exception as err:
            raise AssertionError(f"{path.relative_to(ROOT)}, block at line {line} failed: "
                                 f"{type(err).__name__}: {err}") from err
    import matplotlib.pyplot as plt

    plt.close("all")
