"""A study's cache: one checked entry per run, written atomically, read back, pruned; the heavy parts on disk.

Each entry is a header line (format, key, SHA-256 and size of the record) and the run record as
JSON, its arrays (trajectories, threshold sweeps) as float64 bytes in base64. :func:`read_entry`
never raises: a damaged, truncated, edited or foreign entry comes back as the problem, and the
runner runs that cell again (:class:`CacheWarning`). A study keeps the heavy parts of its run
records (:data:`HEAVY`) in their entries only (:func:`light`) and the report reads them back a few
runs at a time (:func:`with_heavy`), so that its memory stays bounded whatever its size.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import FootzooWarning

CACHE_FORMAT = "footzoo-ablation-cache/3"


class CacheWarning(FootzooWarning):
    """A cache entry was damaged, truncated, edited or foreign; its cell was run again."""


def write_entry(path: Path, key: str, record: dict[str, Any]) -> None:
    """Write one cache entry atomically: a header line (format, key, checksum, size) then the JSON record."""
    payload = json.dumps(record, sort_keys=True, separators=(",", ":"), default=_pack).encode()
    header = {"format": CACHE_FORMAT, "key": key, "sha256": hashlib.sha256(payload).hexdigest(),
              "bytes": len(payload)}
    tmp = path.with_suffix(f".{os.getpid()}.{time.monotonic_ns()}.tmp")
    tmp.write_bytes(json.dumps(header).encode() + b"\n" + payload)
    tmp.replace(path)  # atomic: an interrupted study leaves only complete entries


def _pack(value: Any) -> Any:
    """JSON for an array of a run record (a trajectory): its float64 bytes in base64, exact and fast."""
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value, dtype="<f8")
        return {"__array__": base64.b64encode(a.tobytes()).decode(), "shape": list(a.shape)}
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def _unpack(d: dict[str, Any]) -> Any:
    if "__array__" in d and "shape" in d and len(d) == 2:
        return np.frombuffer(base64.b64decode(d["__array__"]), dtype="<f8").reshape(d["shape"])
    return d


def read_entry(path: Path, key: str) -> tuple[dict[str, Any] | None, str | None]:
    """``(record, None)`` for a sound entry of this cell, ``(None, problem)`` otherwise; never raises."""
    try:
        raw = path.read_bytes()
    except OSError as err:
        return None, f"unreadable ({err.strerror or err})"
    line, _, payload = raw.partition(b"\n")
    try:
        header = json.loads(line)
    except ValueError:
        header = None
    if not isinstance(header, dict) or header.get("format") != CACHE_FORMAT:
        return None, "not a footzoo cache entry of this version (foreign file or older format)"
    if header.get("key") != key:
        return None, f"belongs to another cell (key {str(header.get('key'))[:24]!r})"
    if len(payload) != header.get("bytes"):
        return None, f"truncated or extended ({len(payload)} of {header.get('bytes')} bytes)"
    if hashlib.sha256(payload).hexdigest() != header.get("sha256"):
        return None, "checksum mismatch (edited or damaged)"
    try:
        record = json.loads(payload, object_hook=_unpack)
    except ValueError:
        return None, "checksum matches but the content is not JSON"
    if not isinstance(record, dict) or record.get("key") != key:
        return None, "checksum matches but the record is not this cell's"
    return record, None


#: Cache entries no study used for this many days are removed after a study (``run_study(prune=...)``).
CACHE_MAX_AGE_DAYS = 30.0


def prune_cache(cache_dir: str | Path, keep: set[str] | frozenset[str] = frozenset(),
                max_age_days: float | None = CACHE_MAX_AGE_DAYS, max_bytes: int | None = None) -> dict[str, int]:
    """Remove old cache entries: those not in ``keep`` and unused for ``max_age_days``, then, while the
    cache is larger than ``max_bytes``, the least recently used ones not in ``keep``.

    An entry's age is the time since a study last wrote or read it (its modification time; a study
    touches every entry it reads). ``max_age_days=0`` removes every entry not in ``keep``.

    Returns
    -------
    dict
        ``removed`` (entries), ``kept`` (entries), ``bytes`` (the cache's size after pruning).
    """
    folder = Path(cache_dir)
    entries = []
    for f in folder.glob("*.json"):
        try:
            st = f.stat()
        except OSError:
            continue
        entries.append((st.st_mtime, st.st_size, f))
    for f in folder.glob("*.tmp"):  # left by a killed writer
        with contextlib.suppress(OSError):
            if time.time() - f.stat().st_mtime > 3600:
                f.unlink()
    entries.sort()  # oldest first
    now, removed = time.time(), 0
    alive = []
    for mtime, size, f in entries:
        old = max_age_days is not None and now - mtime >= max_age_days * 86400.0
        if old and f.stem not in keep:
            with contextlib.suppress(OSError):
                f.unlink()
                removed += 1
                continue
        alive.append((mtime, size, f))
    total = sum(size for _, size, _ in alive)
    if max_bytes is not None:
        for i, (_, size, f) in enumerate(list(alive)):
            if total <= max_bytes:
                break
            if f.stem not in keep:
                with contextlib.suppress(OSError):
                    f.unlink()
                    removed += 1
                    total -= size
                    alive[i] = (0, 0, None)
    return {"removed": removed, "kept": sum(1 for *_, f in alive if f is not None), "bytes": total}


def touch(path: Path) -> None:
    """Mark a cache entry as used now (its age for :func:`prune_cache`)."""
    with contextlib.suppress(OSError):
        os.utime(path)


#: The parts of a run record that grow with the recording: kept in its cache entry, not in memory.
HEAVY = ("trajectory", "reference", "footprints", "trajectory_on_footprints", "roc")


def light(record: dict[str, Any], keep: bool = True) -> dict[str, Any]:
    """A run record without its trajectories and sweeps, which its cache entry (``record["entry"]``) holds.

    A study's memory then stays bounded whatever its size: the report reads them back a few runs at a
    time (:func:`with_heavy`). A record without an entry keeps them when ``keep`` (the report needs
    them), else they are dropped (nothing reads them).
    """
    if "entry" not in record and keep:
        return record
    return {k: v for k, v in record.items() if k not in HEAVY}


def with_heavy(runs: list[dict[str, Any]], fields: tuple[str, ...] = HEAVY) -> list[dict[str, Any]]:
    """The runs with their ``fields`` read back from their cache entries (see :func:`light`)."""
    out = []
    for r in runs:
        if "entry" in r and any(f not in r for f in fields):
            record, _ = read_entry(Path(r["entry"]), r["key"])
            if record is not None:
                r = {**r, **{f: record.get(f, []) for f in fields if f not in r}}
        out.append(r)
    return out
