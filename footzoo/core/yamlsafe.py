"""The one YAML loader footzoo uses: bounded, strict, safe.

Every YAML file footzoo reads (pipeline configs, studies, calibration files,
the ``.meta.yaml`` sidecars of canonical recordings) goes through
:func:`load_file` or :func:`load_text`:

* **Bounded**: at most :data:`MAX_BYTES` bytes are read (a device such as
  ``/dev/zero`` or a huge file fails fast), nesting at most :data:`MAX_DEPTH`
  levels, at most :data:`MAX_ALIASES` aliases, and at most :data:`MAX_NODES`
  nodes once aliases are expanded (an alias bomb — "billion laughs" — fails
  before anything is built).
* **Strict**: YAML 1.2 core-schema scalars: only ``true``/``false`` are
  booleans (``yes``, ``no``, ``on``, ``off`` stay text, so a plug-in's boolean
  parameter rejects them instead of taking a non-empty string as true); no
  sexagesimal numbers (``1:30`` is text, not 90), no octal from a leading zero,
  ``1e-3`` is a float; dates stay text. Duplicate keys in one mapping are an
  error (not "the last one wins"). Merge keys (``<<: *base``) may be overridden.
* **Safe**: PyYAML's safe constructor; no ``!!python/...`` tag is executed.
* **Text**: the file must be UTF-8 (a UTF-8 byte-order mark is accepted).

Every failure raises the caller's footzoo error class (default
:class:`~footzoo.core.errors.ConfigError`) naming the file, the problem and the fix.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import yaml
from yaml.constructor import ConstructorError
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from .errors import ConfigError
from .files import damaged_text, foreign_encoding, nul_in_path, nul_padding, why_missing

#: Largest YAML file read (bytes).
MAX_BYTES = 1 << 20
#: Deepest nesting of mappings and sequences.
MAX_DEPTH = 64
#: Most aliases (``*name``) in one document.
MAX_ALIASES = 256
#: Most nodes in a document once every alias is expanded.
MAX_NODES = 100_000

_BOOL = "tag:yaml.org,2002:bool"
_INT = "tag:yaml.org,2002:int"
_FLOAT = "tag:yaml.org,2002:float"
_TIMESTAMP = "tag:yaml.org,2002:timestamp"
_MERGE = "tag:yaml.org,2002:merge"


class _LimitError(yaml.YAMLError):
    """A document exceeds one of the loader's limits."""


class StrictLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 core scalars, duplicate-key errors, depth and alias limits."""

    def __init__(self, stream: str):
        super().__init__(stream)
        self._depth = 0
        self._aliases = 0

    def compose_node(self, parent: Node | None, index: Any) -> Node:
        if self.check_event(yaml.AliasEvent):
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise _LimitError(f"more than {MAX_ALIASES} aliases (*name); expand them or simplify the file")
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise _LimitError(f"nested deeper than {MAX_DEPTH} levels")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node: MappingNode, deep: bool = False) -> dict[Any, Any]:
        if isinstance(node, MappingNode):
            seen: dict[Any, Any] = {}
            for key_node, _ in node.value:
                if key_node.tag == _MERGE:
                    continue
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                except TypeError:
                    raise ConstructorError("while constructing a mapping", node.start_mark,
                                           f"unhashable key {key!r}", key_node.start_mark) from None
                if duplicate:
                    raise ConstructorError(
                        "while constructing a mapping", node.start_mark,
                        f"duplicate key {key!r} (first at line {seen[key].line + 1}); keep only one",
                        key_node.start_mark,
                    )
                seen[key] = key_node.start_mark
        return super().construct_mapping(node, deep=deep)


def _construct_bool(loader: StrictLoader, node: ScalarNode) -> bool:
    value = loader.construct_scalar(node)
    if value.lower() not in ("true", "false"):
        raise ConstructorError(None, None, f"{value!r} is not a boolean (true or false)", node.start_mark)
    return value.lower() == "true"


def _construct_int(loader: StrictLoader, node: ScalarNode) -> int:
    value = loader.construct_scalar(node)
    if value.startswith("0o"):
        return int(value[2:], 8)
    if value.startswith("0x"):
        return int(value[2:], 16)
    return int(value, 10)


def _construct_float(loader: StrictLoader, node: ScalarNode) -> float:
    value = loader.construct_scalar(node).lower()
    if value in (".inf", "+.inf"):
        return math.inf
    if value == "-.inf":
        return -math.inf
    if value == ".nan":
        return math.nan
    return float(value)


# YAML 1.2 core schema: replace PyYAML's YAML 1.1 bool/int/float resolvers, drop timestamps
StrictLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag not in (_BOOL, _INT, _FLOAT, _TIMESTAMP)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
StrictLoader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
StrictLoader.add_implicit_resolver(
    _INT, re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"), list("-+0123456789")
)
StrictLoader.add_implicit_resolver(
    _FLOAT,
    re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
               r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+.0123456789"),
)
StrictLoader.add_constructor(_BOOL, _construct_bool)
StrictLoader.add_constructor(_INT, _construct_int)
StrictLoader.add_constructor(_FLOAT, _construct_float)
StrictLoader.add_constructor(_TIMESTAMP, StrictLoader.construct_yaml_str)


def _expanded_size(root: Node) -> int:
    """Number of nodes with every alias expanded; stops early above :data:`MAX_NODES`."""
    sizes: dict[int, int] = {}
    active: set[int] = set()

    def size(node: Node) -> int:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in active:
            raise _LimitError("an alias refers to a node that contains it (recursive structure)")
        active.add(key)
        total = 1
        if isinstance(node, SequenceNode):
            for child in node.value:
                total += size(child)
                if total > MAX_NODES:
                    break
        elif isinstance(node, MappingNode):
            for k, v in node.value:
                total += size(k) + size(v)
                if total > MAX_NODES:
                    break
        active.discard(key)
        sizes[key] = total
        if total > MAX_NODES:
            raise _LimitError(
                f"more than {MAX_NODES} values once aliases are expanded (an alias bomb?); simplify the file"
            )
        return total

    return size(root)


def load_text(text: str, source: str = "<string>", error: type[Exception] = ConfigError) -> Any:
    """Parse one YAML document from text with the strict, bounded loader.

    Parameters
    ----------
    text : str
        The document.
    source : str
        Where it came from, for messages (a path).
    error : exception class
        The footzoo error to raise (ConfigError for configs, FormatError for data sidecars).
    """
    if len(text) > MAX_BYTES:
        raise error(f"{source}: the YAML text is larger than {MAX_BYTES} characters; footzoo reads no larger file")
    loader = None
    try:
        loader = StrictLoader(text)  # the reader rejects control characters here already
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_size(node)
        return loader.construct_document(node)
    except _LimitError as err:
        raise error(f"{source}: YAML refused: {err}") from None
    except yaml.YAMLError as err:
        raise error(f"{source}: not valid YAML: {err}{_tab_hint(err)}") from None
    except (ValueError, TypeError, OverflowError) as err:
        raise error(f"{source}: not valid YAML: bad value: {err}") from None
    except RecursionError:
        raise error(f"{source}: YAML refused: nested too deeply") from None
    finally:
        if loader is not None:
            loader.dispose()


#: Extensions of recordings, named when one is given where a YAML file is expected.
RECORDING_SUFFIXES = (".csv", ".txt", ".tsv", ".parquet", ".pq", ".mat", ".gz", ".zip", ".npz", ".h5")


def _tab_hint(err: yaml.YAMLError) -> str:
    """The fix of the most common YAML mistake, a tab in the indentation (YAML forbids tabs there)."""
    mark = getattr(err, "problem_mark", None)
    if "'\\t'" not in str(err) or mark is None:
        return ""
    return (f"\nYAML allows no tab there (it indents with spaces only): replace the tab at line {mark.line + 1}, "
            f"column {mark.column + 1} by spaces")


def load_file(path: str | Path, error: type[Exception] = ConfigError, what: str = "YAML file") -> Any:
    """Read and parse a YAML file: at most :data:`MAX_BYTES`, UTF-8, strict and bounded (see the module doc).

    Parameters
    ----------
    path : str or Path
        The file.
    error : exception class
        The footzoo error raised for any problem.
    what : str
        What the file is, for messages ("config file", "study file", …).
    """
    if isinstance(path, str) and not path.strip():
        raise error(f"{what} is an empty path ('' would read the current folder); give the path of a YAML file")
    if nul_in_path(path):
        raise error(f"{what} {nul_in_path(path)}")
    p = Path(path)
    if p.suffix.lower() in RECORDING_SUFFIXES and p.suffix.lower() != ".txt":
        raise error(f"{str(p)!r} is a recording ({p.suffix} file), not a {what} (YAML): a recording goes to --data, "
                    f"e.g. footzoo run CONFIG --data {p}")
    try:
        if not p.exists():
            problem = why_missing(p)
            raise error(f"{what} {str(p)!r} {problem}; check the path")
        if p.is_dir():
            raise error(f"{what} {str(p)!r} is a directory; give the path of a YAML file")
        if not p.is_file():
            raise error(f"{what} {str(p)!r} is not a regular file (a device or pipe?); give the path of a YAML file")
        with open(p, "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
    except PermissionError:
        raise error(f"{what} {str(p)!r} is not readable (permission denied); fix its permissions") from None
    except OSError as err:
        raise error(f"{what} {str(p)!r} cannot be read: {err.strerror or err}") from None
    if len(raw) > MAX_BYTES:
        hint = (f" ({p.suffix} is a recording's extension: a recording goes to --data, the {what} is YAML)"
                if p.suffix.lower() in RECORDING_SUFFIXES else "")
        raise error(f"{p}: larger than {MAX_BYTES} bytes; a {what} this large is not accepted{hint}")
    encoding = foreign_encoding(raw)
    if encoding:
        raise error(f"{p}: {encoding}")
    if b"\0" in raw:
        raise error(damaged_text(str(p), raw) or f"{p}: ends with {nul_padding(raw)} NUL bytes (0x00) after its text: "
                    "the file was damaged while it was written; delete them (or write the file again)")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise error(
            f"{p}: not UTF-8 text (byte 0x{raw[err.start]:02x} at offset {err.start}); "
            "save the file as UTF-8 (e.g. iconv -f latin1 -t utf-8)"
        ) from None
    return load_text(text, str(p), error)


class StrictDumper(yaml.SafeDumper):
    """PyYAML's safe dumper, quoting every text that :class:`StrictLoader` would read as something else.

    PyYAML writes YAML 1.1: ``'1e3'``, ``'0o17'`` or ``'.5'`` come out unquoted and a YAML 1.2
    loader reads them back as numbers. Here any string that the strict loader would resolve to
    a non-string (number, boolean, null) is written quoted, so text stays text.
    """


def _represent_str(dumper: StrictDumper, value: str) -> yaml.ScalarNode:
    tag = StrictLoader.resolve(StrictLoader, ScalarNode, value, (True, False))  # type: ignore[arg-type]
    node = dumper.represent_scalar("tag:yaml.org,2002:str", value)
    if any(c in value for c in "\x85\u2028\u2029") or not all(c.isprintable() or c in "\n\t" for c in value):
        node.style = '"'  # line breaks YAML folds (NEL, LS, PS) and control characters: escaped, so they read back
    elif tag != "tag:yaml.org,2002:str" and node.style is None:
        node.style = "'"
    return node


StrictDumper.add_representer(str, _represent_str)


def dump_text(data: Any) -> str:
    """YAML text of ``data`` that :func:`load_text` reads back to equal values (text stays text)."""
    return yaml.dump(data, Dumper=StrictDumper, allow_unicode=True, sort_keys=False)
