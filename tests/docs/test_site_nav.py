"""Every page of the docs site is in its navigation (mkdocs.yml ``nav``): none is reachable only by a link."""

from __future__ import annotations

from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
#: Folders whose nav entry (their index.md) docs/hooks.py expands into one page per plug-in or reader.
EXPANDED = ("zoo/", "readers/")


def nav_pages(entries) -> set[str]:
    """The page paths of a mkdocs ``nav`` (nested lists of titles and pages)."""
    pages: set[str] = set()
    for entry in entries:
        if isinstance(entry, str):
            pages.add(entry)
        elif isinstance(entry, dict):
            for value in entry.values():
                pages |= nav_pages(value) if isinstance(value, list) else {value}
    return pages


def test_every_docs_page_and_benchmark_summary_is_in_the_nav():
    nav = nav_pages(yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))["nav"])
    docs = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    published = {f"benchmarks/{p.name}" for p in (ROOT / "benchmarks").glob("*.md")}  # docs/hooks.py publishes them
    expanded = {p for p in docs if p.startswith(EXPANDED)}  # in the nav the hook builds
    missing = sorted((docs | published) - nav - expanded)
    assert not missing, f"pages outside mkdocs.yml's nav (add them there): {missing}"
    assert not sorted(nav - docs - published - {"benchmarks/index.md"}), "nav entries that are no page"
