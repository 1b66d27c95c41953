"""MkDocs hooks: pages generated at build time from the code, so they cannot go stale.

* ``zoo/``: one page per registered plug-in (summary, paper, a table of its declared
  parameters: name, type, unit, accepted range, default, source of the default and
  meaning; YAML snippet, full docstring), an index table and ``zoo/settings.md``
  (the config's settings blocks, from the same declarations); a plug-in registered
  tomorrow gets its page without any edit here.
* ``readers/<format>.md``: one page per built-in reader (``footzoo.io.registry.BUILTIN``; and per
  other module of ``footzoo/io``, e.g. reference-data loaders), from the module
  docstring and the reader's options.
* ``gallery/``: every ``docs/gallery/*.py`` script is run; the figures it saves
  into ``$FOOTZOO_GALLERY_OUT`` are shown with its docstring and source.
* ``benchmarks/``: every summary a benchmark script writes into ``benchmarks/`` (``*.md``, with the
  figures it links) becomes a page as it is, so the site shows the numbers of the last benchmark run.

The ``nav`` entries ``zoo/index.md``, ``readers/index.md`` and
``gallery/index.md`` in ``mkdocs.yml`` are expanded into sections here.

**Links work in the repository and in the site.** A generated page with a hand-written page of
the same name in ``docs/`` (``zoo/index.md``, ``gallery/index.md``, ``readers/generic.md``) is
that page with the generated part appended, so the pages link to files that exist; a link to a
file the site publishes under another name (``../benchmarks/accuracy.md`` -> ``benchmarks/accuracy.md``)
is rewritten for the site (:func:`site_link`). ``tests/docs/test_links.py`` resolves every relative
link of README.md and docs/ in the repository.
"""

from __future__ import annotations

import importlib
import inspect
import logging
import os
import pkgutil
import re
import runpy
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def use_checkout() -> None:
    """Document the checkout being built, not another installed copy of footzoo.

    Called from the events (mkdocs removes the first ``sys.path`` entry after loading a hook file).
    """
    if not sys.path or sys.path[0] != str(ROOT):
        sys.path.insert(0, str(ROOT))
    mod = sys.modules.get("footzoo")
    if mod is not None and not str(getattr(mod, "__file__", "")).startswith(str(ROOT)):
        raise RuntimeError(f"footzoo was imported from {mod.__file__} before the docs hook could use {ROOT}")
    from footzoo.kernels.installed import use_installed_kernels

    use_installed_kernels()  # the gallery loads an installed wheel's machine code where the source is the same

log = logging.getLogger("mkdocs.hooks.footzoo")

KIND_TITLES = {"calibration": "Calibration", "orientation": "Orientation", "detector": "Stance detectors",
               "correction": "Corrections", "analysis": "Analysis"}
#: Class attributes of a plug-in that are not capabilities.
NOT_CAPABILITIES = {"kind", "name", "paper", "units", "parameters"}

_gallery_dir: Path | None = None


# --------------------------------------------------------------------------- docstring helpers


def numpy_section(doc: str, name: str) -> dict[str, str]:
    """``{parameter: description}`` of a numpy-style docstring section (``a, b : type`` lines share one)."""
    lines = doc.splitlines()
    out: dict[str, str] = {}
    for i in range(len(lines) - 1):
        if lines[i].strip() == name and set(lines[i + 1].strip()) == {"-"}:
            j, current = i + 2, []
            while j < len(lines):
                line = lines[j]
                underlined = j + 1 < len(lines) and set(lines[j + 1].strip()) == {"-"}
                if underlined and line.strip() and not line.startswith(" "):
                    break  # next section
                if line and not line.startswith(" "):
                    current = [p.strip() for p in line.split(":")[0].split(",")]
                    for p in current:
                        out[p] = ""
                elif line.strip():
                    for p in current:
                        out[p] = (out[p] + " " + line.strip()).strip()
                j += 1
            break
    return out


def capabilities(cls: type) -> dict[str, str]:
    """The declared class attributes (``causal``, ``needs_magnetometer``, ``observes`` ...) of a plug-in class.

    Every annotated class attribute of its bases that holds a flag, a name or a tuple of names,
    so a capability added to the base classes appears without an edit here.
    """
    names: list[str] = []
    for base in reversed(cls.__mro__):
        for n in vars(base).get("__annotations__", {}):
            if n not in names and n not in NOT_CAPABILITIES and not n.startswith("_"):
                names.append(n)
    out = {}
    for n in names:
        v = getattr(cls, n, None)
        if isinstance(v, bool):
            out[n] = "yes" if v else "no"
        elif isinstance(v, str) and v:
            out[n] = f"`{v}`"
        elif isinstance(v, tuple) and v and all(isinstance(x, str) for x in v):
            out[n] = ", ".join(f"`{x}`" for x in v)
    return out


def first_line(doc: str) -> str:
    return doc.strip().splitlines()[0] if doc.strip() else ""


def md_cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def yaml_value(v: Any) -> Any:
    """A default as YAML would write it (tuples and arrays as lists), or None when it has no YAML form."""
    import numpy as np

    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, tuple):
        return [yaml_value(x) for x in v]
    if isinstance(v, (str, int, float, bool, list, dict)) or v is None:
        return v
    return None


def committed(uri: str) -> str | None:
    """The hand-written page ``docs/<uri>``, or None."""
    path = ROOT / "docs" / uri
    return path.read_text() if path.is_file() else None


def with_committed(uri: str, generated: str) -> str:
    """The hand-written page ``docs/<uri>`` with ``generated`` appended (a heading of its own when it has none)."""
    text = committed(uri)
    if text is None:
        return generated
    return text.rstrip() + "\n\n" + generated


#: Folders of the repository whose files the site publishes under another path: repository folder -> site folder.
PUBLISHED = {"benchmarks": "benchmarks"}
_LINK = re.compile(r"(\]\()([^)\s#]+)(#[^)\s]*)?(\))")


def site_link(page_uri: str, target: str) -> str:
    """``target`` (a link of the page ``docs/<page_uri>``, relative) as the site needs it.

    A link that leaves ``docs/`` for a file the site publishes (``../benchmarks/accuracy.md``, a
    summary a benchmark wrote) points at the published page; every other link stays as it is.
    """
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("/"):
        return target
    page_dir = (ROOT / "docs" / page_uri).parent
    resolved = (page_dir / target).resolve()
    for folder, site in PUBLISHED.items():
        base = (ROOT / folder).resolve()
        if resolved.is_relative_to(base) and not resolved.is_relative_to((ROOT / "docs").resolve()):
            published = (ROOT / "docs" / site / resolved.relative_to(base))
            return os.path.relpath(published, page_dir).replace(os.sep, "/")
    return target


def on_page_markdown(markdown, page, **_):
    """Links to files the site publishes under another path (:func:`site_link`) point at the published page."""
    uri = page.file.src_uri
    return _LINK.sub(lambda m: m.group(1) + site_link(uri, m.group(2)) + (m.group(3) or "") + m.group(4), markdown)


# --------------------------------------------------------------------------- plug-in pages


def plugin_pages() -> dict[str, str]:
    """``{src_uri: markdown}`` of the plug-in zoo."""
    import yaml

    from footzoo.plugins import registry

    pages: dict[str, str] = {}
    rows = []
    for kind in registry.KINDS:
        for name, cls in sorted(registry.available(kind).items()):
            uri = f"zoo/{kind}/{name}.md"
            doc = inspect.getdoc(cls) or ""
            params = numpy_section(doc, "Parameters")
            sig = inspect.signature(cls.__init__)
            units = getattr(cls, "units", {}) or {}
            lines = [f"# `{name}` ({kind})", "", first_line(doc), ""]
            paper = getattr(cls, "paper", "")
            if paper:
                lines += [f"**Paper:** {paper}", ""]
            lines += [f"**Class:** `{cls.__module__}.{cls.__qualname__}`", ""]
            caps = capabilities(cls)
            if caps:
                lines += ["**Capabilities:** " + ", ".join(f"`{c}`: {v}" for c, v in caps.items()), ""]
            names = [p for p in sig.parameters if p != "self" and sig.parameters[p].kind not in
                     (inspect.Parameter.VAR_KEYWORD, inspect.Parameter.VAR_POSITIONAL)]
            spec: dict[str, Any] = {"type": name}
            if names:
                lines += ["## Parameters", "", *parameter_table(cls, names, sig, units, params), ""]
                for p in names:
                    default = sig.parameters[p].default
                    if default is not inspect.Parameter.empty and yaml_value(default) is not None:
                        spec[p] = yaml_value(default)
            slot = {"orientation": "orientation", "detector": "detector"}.get(kind)
            snippet = {slot: spec} if slot else {"corrections" if kind == "correction" else kind: [spec]}
            lines += ["## In a config", "", "With every default written out:", "", "```yaml",
                      yaml.safe_dump(snippet, sort_keys=False, default_flow_style=None, width=100).strip(), "```", "",
                      "## Description", "", f"::: {cls.__module__}.{cls.__qualname__}",
                      "    options:", "      show_root_heading: false", "      show_root_toc_entry: false",
                      "      members: false", "      show_docstring_parameters: false", ""]
            pages[uri] = "\n".join(lines)
            rows.append(f"| {kind} | [`{name}`]({kind}/{name}.md) | {md_cell(first_line(doc))} | "
                        f"{md_cell(paper)} |")
    table = ["| kind | name | what it does | paper |", "|---|---|---|---|", *rows, ""]
    pages["zoo/index.md"] = with_committed("zoo/index.md", "\n".join(table))
    pages["zoo/settings.md"] = settings_page()
    return pages


PARAMETER_HEADER = ["| parameter | type | unit | accepted | default | source of the default | meaning |",
                    "|---|---|---|---|---|---|---|"]


def declared_row(name: str, d: Any) -> str:
    """A table row of one declared parameter (``footzoo.core.params.Declared``)."""
    p = d.param
    accepted = p.range_text + (f" ({p.why})" if p.why else "")
    return (f"| `{name}` | {md_cell(p.type_text)} | {md_cell(p.unit)} | {md_cell(accepted)} | "
            f"`{md_cell(d.default_text)}` | {md_cell(p.source)} | {md_cell(p.doc)} |")


def parameter_table(cls: type, names: list[str], sig: inspect.Signature, units: dict[str, str],
                    described: dict[str, str]) -> list[str]:
    """The parameters of a plug-in as a table: from its declarations, else from its signature and docstring."""
    declaration = cls.declaration()
    rows = list(PARAMETER_HEADER)
    for p in names:
        if p in declaration:
            rows.append(declared_row(p, declaration[p]))
            continue
        default = sig.parameters[p].default
        shown = "required" if default is inspect.Parameter.empty else f"`{default!r}`"
        rows.append(f"| `{p}` | | {md_cell(units.get(p, ''))} | | {md_cell(shown)} | | "
                    f"{md_cell(described.get(p, ''))} (not declared) |")
    return rows


def settings_page() -> str:
    """``zoo/settings.md``: the top-level settings of a pipeline config, from their declarations."""
    from footzoo.runtime.validate import settings_declarations

    rows = [declared_row(name, d) for name, d in settings_declarations().items()]
    return "\n".join([
        "# Config settings", "",
        "The top-level settings of a pipeline config, declared and validated like a plug-in's parameters "
        "(`footzoo list --kind settings` prints the same). Each is refused outside its accepted range, with the "
        "reason and, for a value that looks like one in another unit, the conversion.", "",
        "```yaml", "gravity: 9.81", "init: {duration: 0.5, max_gyr: 0.6}", "navigation: {velocity_noise: 0.01}",
        "guards: {max_swing: 1.5, max_speed: 50}", "```", "", *PARAMETER_HEADER, *rows, ""])


def plugin_nav() -> list[Any]:
    from footzoo.plugins import registry

    nav: list[Any] = ["zoo/index.md", {"Config settings": "zoo/settings.md"}]
    for kind in registry.KINDS:
        names = sorted(registry.available(kind))
        if names:
            nav.append({KIND_TITLES.get(kind, kind): [{n: f"zoo/{kind}/{n}.md"} for n in names]})
    return nav


# --------------------------------------------------------------------------- reader pages


def reader_modules() -> tuple[dict[str, str], list[str]]:
    """``({format: module name}, [other io module names])`` of footzoo's own readers (not installed plug-ins)."""
    import footzoo.io as fio
    from footzoo.io.registry import BUILTIN

    readers = {fmt: target.split(":")[0] for fmt, target in BUILTIN.items()}
    used = set(readers.values())
    others = [f"footzoo.io.{m.name}" for m in pkgutil.iter_modules(fio.__path__)
              if f"footzoo.io.{m.name}" not in used and not m.name.startswith("_")]
    return readers, sorted(others)


def reader_pages() -> dict[str, str]:
    from footzoo.io.registry import BUILTIN, _load_target

    readers, others = reader_modules()
    pages = {}
    for fmt, modname in readers.items():
        mod = importlib.import_module(modname)
        reader = _load_target(BUILTIN[fmt])()
        lines = [f"# `{fmt}`: {first_line(inspect.getdoc(mod) or '')}", "",
                 "```bash", f"footzoo run yun2012 --data FILE --format {fmt}", "```", "",
                 "```python", "import footzoo", "", f'rec = footzoo.load("FILE", format="{fmt}")', "```", "",
                 "The format is also detected from the file when `format` is left out: "
                 f"{md_cell(inspect.getdoc(reader.guess_can_open) or 'by its extension')}",
                 "", f"Extensions: {', '.join(f'`{e}`' for e in reader.extensions) or 'any'}."]
        if reader.fixed_units:
            lines += ["", "Units the format fixes: " + ", ".join(f"`{k}={v}`" for k, v in reader.fixed_units.items())
                      + " (a matching option is accepted, another one refused)."]
        options = reader_options_section(reader)
        uri = f"readers/{fmt}.md"
        if committed(uri) is not None:  # a hand-written page: it, with the options as declared
            pages[uri] = with_committed(uri, "\n".join(options))
            continue
        lines += ["", *options, "## Format, units, axis map and reference data", "",
                  f"::: {modname}", "    options:", "      show_root_heading: false",
                  "      show_root_toc_entry: false", "      members: false", ""]
        pages[uri] = "\n".join(lines)
    for modname in others:
        mod = importlib.import_module(modname)
        short = modname.rsplit(".", 1)[-1]
        pages[f"readers/{short}.md"] = "\n".join([
            f"# `{short}`: {first_line(inspect.getdoc(mod) or '')}", "",
            f"::: {modname}", "    options:", "      show_root_heading: false", "      show_root_toc_entry: false",
            "      heading_level: 2", ""])
    return pages


def reader_options_section(reader: Any) -> list[str]:
    """The ``## Options`` section of a reader's page: its declared options, as ``footzoo formats`` lists them."""
    if not reader.options:
        return []
    lines = ["## Options", "", "Keyword arguments of `footzoo.load` for this format (command line: "
             "`--option NAME=VALUE`):", "", "| option | default | unit | meaning |", "|---|---|---|---|"]
    for name, opt in reader.options.items():
        lines.append(f"| `{name}` | {md_cell(f'`{opt.default!r}`')} | {md_cell(opt.unit)} | {md_cell(opt.doc)} |")
    return [*lines, ""]


def reader_nav() -> list[Any]:
    readers, others = reader_modules()
    nav: list[Any] = ["readers/index.md"] + [{fmt: f"readers/{fmt}.md"} for fmt in readers]
    nav += [{m.rsplit(".", 1)[-1]: f"readers/{m.rsplit('.', 1)[-1]}.md"} for m in others]
    return nav


# --------------------------------------------------------------------------- gallery


def gallery_scripts() -> list[Path]:
    return sorted((ROOT / "docs" / "gallery").glob("*.py"))


def run_gallery(out: Path) -> dict[str, str]:
    """Run every gallery script; ``{src_uri: markdown}`` of the gallery page, figures left in ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sections: list[str] = []
    for script in gallery_scripts():
        target = out / script.stem
        target.mkdir(parents=True, exist_ok=True)
        source = script.read_text()
        mod_doc = ""
        m = re.match(r'\s*"""(.*?)"""\s*\n', source, re.S)
        if m:
            mod_doc, body = m.group(1).strip(), source[m.end():]
        else:
            body = source
        t0 = time.perf_counter()
        old_argv, old_cwd = sys.argv, os.getcwd()
        sys.argv = [str(script), str(target)]
        try:
            os.chdir(ROOT)
            runpy.run_path(str(script), run_name="__main__")
        finally:
            sys.argv = old_argv
            os.chdir(old_cwd)
            plt.close("all")
        log.info("gallery: %s ran in %.1f s", script.name, time.perf_counter() - t0)
        title, _, text = mod_doc.partition("\n")
        sections += [f"## {title.strip() or script.stem}", "", text.strip(), ""]
        for png in sorted(target.glob("*.png"), key=lambda f: (f.stat().st_mtime_ns, f.name)):  # as drawn
            sections += [f"![{script.stem}: {png.stem}]({script.stem}/{png.name})", ""]
        sections += [f'??? example "Source: docs/gallery/{script.name}"', "", "    ```python"]
        sections += [("    " + line).rstrip() for line in body.strip("\n").splitlines()]
        sections += ["    ```", ""]
    return {"gallery/index.md": with_committed("gallery/index.md", "\n".join(sections))}


# --------------------------------------------------------------------------- mkdocs events


def _expand(nav: list[Any], table: dict[str, list[Any]]) -> list[Any]:
    out = []
    for item in nav:
        if isinstance(item, dict):
            (title, value), = item.items()
            if isinstance(value, str) and value in table:
                out.append({title: table[value]})
            elif isinstance(value, list):
                out.append({title: _expand(value, table)})
            else:
                out.append(item)
        else:
            out.append(item)
    return out


def on_config(config, **_):
    use_checkout()
    config["nav"] = _expand(config["nav"], {"zoo/index.md": plugin_nav(), "readers/index.md": reader_nav()})
    return config


BENCHMARKS = ROOT / "benchmarks"


def benchmark_pages() -> dict[str, str]:
    """``benchmarks/<name>.md`` for every summary in ``benchmarks/``, and an index of them."""
    pages, rows = {}, []
    for md in sorted(BENCHMARKS.glob("*.md")):
        text = md.read_text()
        title = next((line.lstrip("# ").strip() for line in text.splitlines() if line.startswith("#")), md.stem)
        pages[f"benchmarks/{md.name}"] = text if text.startswith("#") else f"# {title}\n\n{text}"
        rows.append(f"* [{title}]({md.name}) (`benchmarks/{md.name}`)")
    intro = "The summaries the scripts in `benchmarks/` wrote at their last run (each script's `--help` tells how)"
    pages["benchmarks/index.md"] = f"# Benchmarks\n\n{intro}:\n\n" + "\n".join(rows) + "\n"
    return pages


def on_files(files, config, **_):
    from mkdocs.structure.files import File

    global _gallery_dir
    use_checkout()
    pages = {**plugin_pages(), **reader_pages(), **benchmark_pages()}
    for png in sorted(BENCHMARKS.glob("*.png")):
        files.append(File.generated(config, f"benchmarks/{png.name}", abs_src_path=str(png)))
    if os.environ.get("FOOTZOO_DOCS_NO_GALLERY"):
        pages["gallery/index.md"] = with_committed("gallery/index.md", "*Not rendered in this build "
                                                   "(`FOOTZOO_DOCS_NO_GALLERY` is set).*\n")
    else:
        _gallery_dir = Path(tempfile.mkdtemp(prefix="footzoo-gallery-"))
        pages.update(run_gallery(_gallery_dir))
        for png in sorted(_gallery_dir.rglob("*.png")):
            files.append(File.generated(config, f"gallery/{png.relative_to(_gallery_dir).as_posix()}",
                                        abs_src_path=str(png)))
    for uri, text in pages.items():
        existing = files.get_file_from_path(uri)
        if existing is not None:
            files.remove(existing)
        files.append(File.generated(config, uri, content=text))
    return files


_ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|obj):(<code>)~?")


def on_page_content(html, **_):
    """Docstrings use Sphinx roles (``:func:`name```), which Markdown renders as text: keep the code only."""
    return _ROLE.sub(r"\1", html)
