"""Every relative link of README.md and docs/**/*.md resolves to a file of the repository.

The site is built from the same pages (``mkdocs build --strict`` checks its own links); a page the
site generates (a plug-in's, a reader's, the gallery) has a hand-written page of the same name in
docs/, so a link to it works in the repository too, and a link out of docs/ to a file the site
publishes elsewhere (a benchmark's summary) is rewritten by docs/hooks.py for the site.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: ``[text](target)`` and ``![alt](target)`` (an optional title after the target), and ``[label]: target``.
LINK = re.compile(r"\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)|^\s*\[[^\]]+\]:\s*(\S+)", re.M)
FENCE = re.compile(r"^(```|~~~).*?^\1", re.S | re.M)
INLINE_CODE = re.compile(r"`[^`\n]*`")


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_links(text: str) -> list[str]:
    """The link targets of a Markdown text that are relative paths (no URL, no anchor-only), code left out."""
    text = INLINE_CODE.sub("", FENCE.sub("", text))
    out = []
    for m in LINK.finditer(text):
        target = m.group(1) or m.group(2)
        if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith(("#", "/")):
            continue
        out.append(target)
    return out


def test_the_link_finder_on_a_hand_made_page():
    text = ("[a](x.md) ![b](img/p.png \"t\") [c](https://e.org/x) [d](#here) `[e](code.md)`\n"
            "```\n[f](fenced.md)\n```\n[g]: ../up.md\n[h](y.md#part)\n")
    assert relative_links(text) == ["x.md", "img/p.png", "../up.md", "y.md#part"]


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves_to_a_file(page):
    missing = [t for t in relative_links(page.read_text()) if not (page.parent / t.split("#")[0]).exists()]
    assert not missing, f"{page.relative_to(ROOT)} links to files that do not exist: {missing}"


def test_links_out_of_docs_are_rewritten_for_the_site():
    spec = importlib.util.spec_from_file_location("footzoo_docs_hooks", ROOT / "docs" / "hooks.py")
    hooks = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hooks)
    assert hooks.site_link("results.md", "../benchmarks/accuracy.md") == "benchmarks/accuracy.md"
    assert hooks.site_link("readers/index.md", "../../benchmarks/accuracy.png") == "../benchmarks/accuracy.png"
    assert hooks.site_link("readers/index.md", "generic.md") == "generic.md"
    assert hooks.site_link("index.md", "https://example.org/a.md") == "https://example.org/a.md"
    # every page the site generates under a name a page links to exists by hand in docs/
    for uri in ("zoo/index.md", "gallery/index.md", "readers/generic.md"):
        assert (ROOT / "docs" / uri).is_file(), uri
