"""The metadata sidecar ``<file>.meta.yaml``: facts about a recording that its data file cannot hold.

Any recording file may have one, next to it::

    # walk.csv.meta.yaml
    meta:                 # merged into Recording.meta (text stays text: '1e3' is the string '1e3')
      subject: S07
      foot: left
    closed_loop: true     # the walk ends where it started: loop-closure metrics apply
    truth:                # facts of the reference that have no per-sample column (optional)
      source: motion capture (gaitmap)
      stride_count: 12    # strides counted by hand (null: none; absent: the rows of the steps file)

``footzoo simulate`` and :func:`footzoo.io.canonical.write` write it for every recording, with
``data_sha256`` (the SHA-256 of the data file it describes) and, when there is a true-steps
sidecar ``<file>.steps.csv``, ``steps_sha256``. A sidecar whose ``data_sha256`` does not match
the data file is **stale** (left over from an earlier file of the same name): it is ignored,
together with the steps file, with a warning. A steps file is read only when the metadata
sidecar vouches for it (its ``steps_sha256`` matches) or when the sidecar carries no hashes at
all (a hand-written sidecar, or one written before footzoo 0.3). A reference with no per-sample
column (only a stride table, a closed-loop marker or a hand count) is still a reference: the
reader builds its :class:`~footzoo.core.data.Truth` from the sidecars alone.
"""

from __future__ import annotations

import datetime
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import FootzooWarning, FormatError, user_stacklevel
from ..core.files import sha256
from ..core.yamlsafe import dump_text, load_file

#: Keys of a metadata sidecar.
KEYS = ("meta", "closed_loop", "truth", "data_sha256", "steps_sha256")
#: Keys of a sidecar's ``truth`` mapping: the reference's scalar facts.
TRUTH_KEYS = ("source", "stride_count")


def meta_path(path: Path) -> Path:
    """The metadata sidecar of a data file: ``<file>.meta.yaml``."""
    return path.with_name(path.name + ".meta.yaml")


def steps_path(path: Path) -> Path:
    """The true-steps sidecar of a data file: ``<file>.steps.csv``."""
    return path.with_name(path.name + ".steps.csv")


@dataclass
class Facts:
    """What a metadata sidecar says about its data file.

    Attributes
    ----------
    meta : dict
        Metadata to merge into ``Recording.meta``.
    closed_loop : bool or None
        Whether the walk is a closed loop (None: the sidecar does not say).
    steps : Path or None
        The true-steps sidecar to read, when there is a valid one.
    files : list of Path
        The sidecar files that were used (inputs of the run).
    truth : dict
        The reference's scalar facts (:data:`TRUTH_KEYS`: ``source`` text, ``stride_count`` a
        whole number, or None for "no count"), empty when the sidecar has none.
    """

    meta: dict[str, Any] = field(default_factory=dict)
    closed_loop: bool | None = None
    truth: dict[str, Any] = field(default_factory=dict)
    steps: Path | None = None
    files: list[Path] = field(default_factory=list)


def read_facts(path: Path) -> Facts:
    """The facts of ``path``'s sidecars (empty when there are none, or when they are stale)."""
    side, steps = meta_path(path), steps_path(path)
    facts = Facts()
    if not side.exists():
        if steps.exists():
            facts.steps = steps
            facts.files.append(steps)
        return facts
    raw = load_file(side, FormatError, "metadata sidecar")
    raw = {} if raw is None else raw
    fix = f"fix or delete {side.name} (see footzoo.io.metadata: meta: {{...}}, closed_loop: true|false)"
    if not isinstance(raw, dict):
        raise FormatError(f"{side}: expected a mapping with 'meta' and 'closed_loop', got {raw!r:.80}; {fix}")
    unknown = [k for k in raw if k not in KEYS]
    if unknown:
        raise FormatError(f"{side}: unknown key(s) {unknown}; a metadata sidecar holds {list(KEYS)}; {fix}")
    meta = raw.get("meta", {}) or {}
    if not isinstance(meta, dict):
        raise FormatError(f"{side}: 'meta' must be a mapping, got {raw['meta']!r:.80}; {fix}")
    closed_loop = raw.get("closed_loop")
    if closed_loop is not None and not isinstance(closed_loop, bool):
        raise FormatError(f"{side}: closed_loop must be true or false, got {closed_loop!r}; {fix}")
    truth = _truth_facts(raw.get("truth"), side, fix)
    for key in ("data_sha256", "steps_sha256"):
        if raw.get(key) is not None and not isinstance(raw[key], str):
            raise FormatError(f"{side}: {key} must be a hex digest (text), got {raw[key]!r:.80}; {fix}")
    if raw.get("data_sha256") and raw["data_sha256"] != sha256(path):
        warnings.warn(FootzooWarning(
            f"{side.name} describes an earlier {path.name} (its data_sha256 does not match the file): stale, ignored"
            + (f" together with {steps.name}" if steps.exists() else "")
            + "; delete it, or write the recording again with footzoo.io.canonical.write"),
            stacklevel=user_stacklevel())
        return Facts()
    facts = Facts(meta=dict(meta), closed_loop=closed_loop, truth=truth, files=[side])
    if steps.exists():
        vouched = raw.get("steps_sha256")
        hashed = raw.get("data_sha256") is not None
        if vouched is not None and vouched == sha256(steps) or (vouched is None and not hashed):
            facts.steps = steps
            facts.files.append(steps)
        else:
            why = "belongs to an earlier file (its hash does not match)" if vouched else \
                "is not listed in the metadata sidecar"
            warnings.warn(FootzooWarning(f"{steps.name} {why}: stale, not used as the reference; delete it"),
                          stacklevel=user_stacklevel())
    return facts


def _truth_facts(raw: Any, side: Path, fix: str) -> dict[str, Any]:
    """The sidecar's ``truth`` mapping, checked (empty when absent)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise FormatError(f"{side}: 'truth' must be a mapping ({', '.join(TRUTH_KEYS)}), got {raw!r:.80}; {fix}")
    unknown = [k for k in raw if k not in TRUTH_KEYS]
    if unknown:
        raise FormatError(f"{side}: unknown truth key(s) {unknown}; 'truth' holds {list(TRUTH_KEYS)}; {fix}")
    if raw.get("source") is not None and not isinstance(raw["source"], str):
        raise FormatError(f"{side}: truth.source must be text, got {raw['source']!r:.80}; {fix}")
    count = raw.get("stride_count")
    if count is not None and (isinstance(count, bool) or not isinstance(count, int) or count < 0):
        raise FormatError(f"{side}: truth.stride_count must be a whole number of strides (0 or more) or null, got "
                          f"{count!r:.80}; {fix}")
    # stride_count: null says "no count" (the steps file's rows are then not taken for one)
    return {k: v for k, v in raw.items() if v is not None or k == "stride_count"}


#: Metadata footzoo derives when it reads a recording: not written to a sidecar (recomputed on reading).
DERIVED_META = ("input_files", "sanity", "diagnostics")
#: Largest array (values) written into a sidecar as a list; a larger one is named as not written.
MAX_META_ARRAY = 1000


def plain_meta(meta: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
    """The metadata a sidecar can hold as plain YAML, and the keys it cannot (named, never dropped silently).

    Text, numbers, booleans and None are kept; mappings with text keys and lists (tuples) are kept
    with their plain values; numpy numbers become numbers, small numpy arrays lists, paths text,
    dates ISO text. Anything else (an object, a large array) is listed in the second value.
    The keys footzoo derives on reading (:data:`DERIVED_META`) are left out.
    """
    kept: dict[str, Any] = {}
    dropped: list[str] = []
    for key, value in meta.items():
        if key in DERIVED_META:
            continue
        ok, plain = _plain(value)
        if ok and isinstance(key, str):
            kept[key] = plain
        else:
            dropped.append(f"{key!s} ({type(value).__name__})")
    return kept, dropped


#: Deepest nesting of metadata a sidecar holds: deeper (or a mapping that holds itself) is named as not written.
MAX_META_DEPTH = 32


def _plain(value: Any, depth: int = 0) -> tuple[bool, Any]:
    if depth > MAX_META_DEPTH:
        return False, None
    if value is None or isinstance(value, (str, bool)):
        return True, value
    if isinstance(value, (int, np.integer)) and not isinstance(value, np.bool_):
        return True, int(value)
    if isinstance(value, np.bool_):
        return True, bool(value)
    if isinstance(value, (float, np.floating)):
        return True, float(value)  # YAML's .nan and .inf read back as floats
    if isinstance(value, (datetime.date, datetime.time)):
        return True, value.isoformat()
    if isinstance(value, os.PathLike):
        return True, os.fspath(value)
    if isinstance(value, np.ndarray):
        if value.size > MAX_META_ARRAY or value.dtype.kind not in "biufU":
            return False, None
        value = value.tolist()
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            ok, plain = _plain(v, depth + 1)
            if not ok or not isinstance(k, (str, int)):
                return False, None
            out[k] = plain
        return True, out
    if isinstance(value, (list, tuple)):
        items = [_plain(v, depth + 1) for v in value]
        return (True, [v for _, v in items]) if all(ok for ok, _ in items) else (False, None)
    return False, None


def facts_text(meta: dict[str, Any], closed_loop: bool, data_sha256: str, steps_sha256: str | None,
               truth: dict[str, Any] | None = None) -> str:
    """YAML text of a metadata sidecar (metadata values that are text stay text).

    Parameters
    ----------
    meta : dict
        Scalar metadata.
    closed_loop : bool
        The closed-loop marker.
    data_sha256, steps_sha256 : str
        Hashes of the data file and of the steps file (None: no steps file).
    truth : dict, optional
        The reference's scalar facts (:data:`TRUTH_KEYS`); written when not empty.
    """
    side: dict[str, Any] = {"meta": meta, "closed_loop": bool(closed_loop), "data_sha256": data_sha256}
    if truth:
        side["truth"] = dict(truth)
    if steps_sha256 is not None:
        side["steps_sha256"] = steps_sha256
    return dump_text(side)
