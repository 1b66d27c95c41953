"""Result archives: :meth:`Result.save` / :meth:`Result.load` (and a session's), lossless and self-describing.

A result is saved as a folder::

    run1/
      manifest.json     what this is (format "footzoo-result", format version, footzoo version, time),
                        the table backend, and every file with what it holds (tables: rows and column dtypes)
                        and its SHA-256 (a file changed after the save is named when it is loaded)
      samples.parquet   per-sample estimates (Result.samples)          .csv without pyarrow
      steps.parquet     per-stride table (Result.steps)                .csv without pyarrow
      metrics.json      Result.metrics with the config, versions and the recording's plain metadata
                        (strict JSON: NaN is null), as ``footzoo run --out`` writes it
      result.json       config, versions, recording metadata, diagnostics and the reference's plain
                        values, losslessly (non-finite floats and tuples are marked, arrays and tables
                        point into the files below)
      arrays.npz        every array (diagnostics, reference positions, stance, footprints ...)
      table_*.parquet   every other table (the reference's steps, tables in diagnostics)

Tables are Parquet when pyarrow is installed (``backend="auto"``), CSV otherwise; CSV columns keep
their dtype through the manifest: floats with 17 significant digits (bit-identical on reload),
booleans, integers, and text as JSON strings (text that looks like a number stays text; an empty
text and a missing one differ). Everything is written into the folder as one
:class:`~footzoo.core.atomic.FileGroup`: a crash or Ctrl-C leaves the earlier result complete; files
of the earlier result that the new one does not have are removed. ``manifest.json`` is the folder's
completion marker: the earlier one is set aside (``.footzoo-incomplete``) before any file is replaced
and the new one is written last, so that even a process killed between two renames leaves a folder
that :func:`read_result` refuses as incomplete, never one that mixes two results. Files saved with a
result (``files=``: the figures of ``footzoo run --plot``) are listed in its manifest and go with it.
The folder may hold other files (they are left alone), but a file with one of the archive's names
that an earlier footzoo result did not write is never replaced: the save is refused. A session (both
feet) is saved the same way, with one result folder per foot (:func:`save_session`).
"""

from __future__ import annotations

import base64
import contextlib
import datetime as _dt
import importlib.util
import io
import json
import math
import os
import re
import shutil
import time
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._version import __version__
from .atomic import INCOMPLETE, FileGroup, check_complete, dumps_json, json_safe, previous_marker
from .data import Truth
from .errors import FootzooWarning, FormatError, OutputError, user_stacklevel
from .files import nul_in_path, sha256

FORMAT = "footzoo-result"
SESSION_FORMAT = "footzoo-session-result"
FORMAT_VERSION = 1
MANIFEST = "manifest.json"
#: Float format of CSV tables: 17 significant digits reload to the same double.
FLOAT_FORMAT = "%.17g"
EXACT_CSV: dict[str, Any] = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
TRUTH_ARRAYS = ("pos", "vel", "quat", "stance", "dist", "footprints")
TRUTH_TABLES = ("steps", "stride_positions")


def parquet_available() -> bool:
    """True when pandas can write Parquet (pyarrow is installed)."""
    return importlib.util.find_spec("pyarrow") is not None


def _backend(backend: str) -> str:
    if backend not in ("auto", "parquet", "csv"):
        raise OutputError(f"backend={backend!r}: use 'auto', 'parquet' or 'csv'")
    if backend == "auto":
        return "parquet" if parquet_available() else "csv"
    if backend == "parquet" and not parquet_available():
        raise OutputError("backend='parquet' needs pyarrow (pip install 'footzoo[parquet]'); or use backend='csv'")
    return backend


# --------------------------------------------------------------------------- tables

def _column_kind(s: pd.Series) -> str:
    dtype = s.dtype
    if isinstance(dtype, pd.CategoricalDtype):
        return "category"
    if pd.api.types.is_bool_dtype(dtype) and dtype == np.dtype(bool):
        return "bool"
    if pd.api.types.is_extension_array_dtype(dtype):
        return "extension"
    if pd.api.types.is_datetime64_any_dtype(dtype):
        return "datetime"
    if pd.api.types.is_float_dtype(dtype):
        return "float"
    if pd.api.types.is_integer_dtype(dtype):
        return "int"
    if dtype == np.dtype(object) or pd.api.types.is_string_dtype(dtype):
        return "json"
    raise TypeError(f"column {s.name!r} has dtype {dtype}, which a result archive cannot hold")


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value)) or value is pd.NA or value is pd.NaT


def _encode_cell(value: Any) -> str:
    if _missing(value):
        return ""
    return json.dumps(_plain(value), allow_nan=False, ensure_ascii=False)


def _plain(value: Any) -> Any:
    """A table cell as plain JSON data (numpy scalars -> numbers; non-finite floats marked)."""
    if isinstance(value, (np.generic,)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return {"$float": repr(value)}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value


def _decode_cell(text: str, missing: str) -> Any:
    if text == "":
        return None if missing == "none" else np.nan
    value = json.loads(text)
    return _unmark_float(value)


def _unmark_float(value: Any) -> Any:
    if isinstance(value, dict) and set(value) == {"$float"}:
        return float(value["$float"])
    if isinstance(value, list):
        return [_unmark_float(v) for v in value]
    return value


def _table_info(df: pd.DataFrame) -> dict[str, Any]:
    index = [n for n in df.index.names] if not isinstance(df.index, pd.RangeIndex) else []
    if isinstance(df.index, pd.RangeIndex) and not (df.index.start == 0 and df.index.step == 1):
        index = [df.index.name]
    frame = df.reset_index() if index else df
    columns = {}
    for name in frame.columns:
        if not isinstance(name, str):
            raise TypeError(f"column names must be text, got {name!r}")
        s = frame[name]
        kind = _column_kind(s)
        info: dict[str, Any] = {"dtype": str(s.dtype), "kind": kind}
        if kind == "json":
            info["missing"] = "nan" if any(isinstance(v, float) for v in s if _missing(v)) else "none"
        columns[name] = info
    return {"rows": int(len(frame)), "index": [None if n is None else str(n) for n in index], "columns": columns}


def _write_table(df: pd.DataFrame, group: FileGroup, folder: Path, stem: str, backend: str) -> tuple[str, dict]:
    info = _table_info(df)
    frame = df.reset_index() if info["index"] else df
    if backend == "parquet":
        name = f"{stem}.parquet"
        tmp = group.path(folder / name)
        try:
            frame.to_parquet(tmp, index=False)
            return name, {"kind": "table", "format": "parquet", **info}
        except Exception:  # pyarrow refuses mixed object columns: this table goes to CSV
            group.forget(folder / name)
    name = f"{stem}.csv"
    out = frame.copy()
    for col, c in info["columns"].items():
        if c["kind"] in ("json", "category", "extension"):
            out[col] = [_encode_cell(v) for v in frame[col].astype(object)]
        elif c["kind"] == "datetime":
            out[col] = frame[col].astype(str).where(frame[col].notna(), "")
    with group.open(folder / name, "w", newline="") as fh:
        out.to_csv(fh, index=False, float_format=FLOAT_FORMAT, lineterminator="\n")
    return name, {"kind": "table", "format": "csv", **info}


def _read_table(folder: Path, name: str, info: dict[str, Any]) -> pd.DataFrame:
    path = folder / name
    columns: dict[str, dict[str, Any]] = info.get("columns", {})
    if not columns:
        return pd.DataFrame(index=pd.RangeIndex(int(info.get("rows", 0))))
    if info.get("format") == "parquet":
        df = pd.read_parquet(path)
    else:
        text = [c for c, i in columns.items() if i["kind"] in ("json", "category", "extension", "datetime", "bool")]
        dtypes: dict[str, Any] = {c: str for c in text}
        dtypes.update({c: i["dtype"] for c, i in columns.items() if i["kind"] in ("float", "int")})
        df = pd.read_csv(path, dtype=dtypes, keep_default_na=False,
                         na_values={c: [""] for c, i in columns.items() if i["kind"] == "float"}, **EXACT_CSV)
        for col, i in columns.items():
            kind = i["kind"]
            if kind == "bool":
                df[col] = df[col].map({"True": True, "False": False}).astype(bool)
            elif kind == "json":
                df[col] = pd.Series([_decode_cell(v, i.get("missing", "none")) for v in df[col]], dtype=object,
                                    index=df.index)
            elif kind in ("category", "extension"):
                values = [_decode_cell(v, "none") for v in df[col]]
                df[col] = pd.Series(values, index=df.index).astype(i["dtype"])
            elif kind == "datetime":
                df[col] = pd.to_datetime(df[col].replace("", None)).astype(i["dtype"])
        df = df[list(columns)]
    if info.get("index"):
        df = df.set_index(info["index"] if len(info["index"]) > 1 else info["index"][0])
    return df


# --------------------------------------------------------------------------- nested values

class _Packer:
    """Nested plain values -> JSON with markers; arrays and tables collected for their own files."""

    def __init__(self) -> None:
        self.arrays: dict[str, np.ndarray] = {}
        self.tables: dict[str, pd.DataFrame] = {}
        self.dropped: list[str] = []

    @staticmethod
    def _key(where: str, taken: dict[str, Any]) -> str:
        """A file-name-safe key from the value's path (``diagnostics.guards.x`` -> ``diagnostics.guards.x``)."""
        base = "".join(c if c.isalnum() or c in "._-" else "_" for c in where).strip("._") or "value"
        key, n = base, 1
        while key in taken or f"table_{key}" in taken:
            n += 1
            key = f"{base}_{n}"
        return key

    def pack(self, value: Any, where: str) -> Any:
        if value is None or isinstance(value, (bool, str)):
            return value
        if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_, np.timedelta64)):
            return int(value)
        if isinstance(value, np.bool_):
            return bool(value)
        if isinstance(value, (float, np.floating)):
            v = float(value)
            return v if math.isfinite(v) else {"$float": repr(v)}
        if isinstance(value, dict):
            if not all(isinstance(k, str) for k in value):
                return {"$items": [[self.pack(k, where), self.pack(v, f"{where}.{k}")] for k, v in value.items()]}
            packed = {k: self.pack(v, f"{where}.{k}") for k, v in value.items()}
            if any(k.startswith("$") for k in packed):
                return {"$dict": packed}
            return packed
        if isinstance(value, list):
            return [self.pack(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, tuple):
            return {"$tuple": [self.pack(v, f"{where}[{i}]") for i, v in enumerate(value)]}
        if isinstance(value, np.ndarray):
            if value.dtype == object:
                self.dropped.append(f"{where}: an array of Python objects")
                return {"$dropped": "object array"}
            key = self._key(where, self.arrays)
            self.arrays[key] = value
            return {"$array": key}
        if isinstance(value, (pd.DataFrame, pd.Series)):
            key = "table_" + self._key(where.replace(".", "_"), self.tables)
            self.tables[key] = value.to_frame() if isinstance(value, pd.Series) else value
            return {"$table": key, **({"series": str(value.name)} if isinstance(value, pd.Series) else {})}
        if isinstance(value, os.PathLike):
            return {"$path": os.fspath(value)}
        if isinstance(value, (bytes, bytearray)):
            return {"$bytes": base64.b64encode(bytes(value)).decode("ascii")}
        for kind in (_dt.datetime, _dt.date, _dt.time):  # a recording's date and time (pd.Timestamp is a datetime)
            if isinstance(value, kind):
                return {f"${kind.__name__}": value.isoformat()}
        if isinstance(value, np.datetime64):
            return {"$datetime64": str(value)}
        if isinstance(value, _dt.timedelta):  # a duration (pd.Timedelta is one): exact in days, seconds, microseconds
            return {"$timedelta": [value.days, value.seconds, value.microseconds]}
        if isinstance(value, np.timedelta64):
            return {"$timedelta64": [int(value.view(np.int64)), np.datetime_data(value.dtype)[0]]}
        self.dropped.append(f"{where}: {type(value).__name__}")
        return {"$dropped": type(value).__name__}


class _Unpacker:
    def __init__(self, arrays: Any, tables: dict[str, pd.DataFrame]):
        self.arrays = arrays
        self.tables = tables

    def unpack(self, value: Any) -> Any:
        if isinstance(value, list):
            return [self.unpack(v) for v in value]
        if not isinstance(value, dict):
            return value
        if len(value) == 1 or "$table" in value:
            (key, inner), = list(value.items())[:1]
            if key == "$float":
                return float(inner)
            if key == "$tuple":
                return tuple(self.unpack(v) for v in inner)
            if key == "$dict":
                return {k: self.unpack(v) for k, v in inner.items()}
            if key == "$items":
                return {self.unpack(k): self.unpack(v) for k, v in inner}
            if key == "$array":
                return np.array(self.arrays[inner])
            if key == "$path":
                return Path(inner)
            if key == "$bytes":
                return base64.b64decode(inner)
            if key in ("$datetime", "$date", "$time"):
                return getattr(_dt, key[1:]).fromisoformat(inner)
            if key == "$datetime64":
                return np.datetime64(inner)
            if key == "$timedelta":
                return _dt.timedelta(days=inner[0], seconds=inner[1], microseconds=inner[2])
            if key == "$timedelta64":
                return np.timedelta64(int(inner[0]), inner[1])
            if key == "$dropped":
                return None
            if key == "$table":
                table = self.tables[inner]
                if "series" in value:
                    series = table.iloc[:, 0]
                    return series.rename(None if value["series"] == "None" else value["series"])
                return table
        return {k: self.unpack(v) for k, v in value.items()}


# --------------------------------------------------------------------------- result archives

def _earlier_files(folder: Path, kind: str) -> set[str] | None:
    """The files an earlier footzoo archive in ``folder`` wrote (None when there is none).

    Read from its manifest, or from the manifest an interrupted save set aside (:data:`INCOMPLETE`).
    """
    data = previous_marker(folder, MANIFEST)
    if not isinstance(data, dict) or data.get("format") not in (FORMAT, SESSION_FORMAT):
        return None
    return {str(f) for f in data.get("files", {})} | {MANIFEST}


@contextlib.contextmanager
def _new_folder(path: str | os.PathLike, what: str) -> Any:
    """The archive folder (created if needed); a folder created here is removed again when the save fails."""
    try:
        existed = (Path(path).is_dir() if isinstance(path, (str, os.PathLike)) and str(path).strip()
                   and not nul_in_path(path) else False)
        folder = _prepare_folder(path, what)
    except OSError as err:  # a name longer than the file system allows, a path it cannot look into
        raise OutputError(f"{what} {str(path)[:120]!r}{'...' if len(str(path)) > 120 else ''}: cannot be used as a "
                          f"folder ({err.strerror or err}); choose a shorter or reachable folder path") from None
    try:
        yield folder
    except BaseException:
        if not existed:
            shutil.rmtree(folder, ignore_errors=True)  # only what this save created: nothing else was in it
        raise


def _prepare_folder(path: str | os.PathLike, what: str) -> Path:
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise OutputError(f"{what}: give a folder path (got {path!r:.80})")
    if nul_in_path(path):
        raise OutputError(f"{what} {nul_in_path(path)}")
    if os.fspath(path).strip() == "-":  # as the command line's --out: not a stream; Path('-') as the text '-'
        raise OutputError(f"{what}: '-' means standard output to most tools, but a result is a folder of tables and "
                          "JSON files; give a folder name (for a folder really named '-', write './-', or "
                          "Path.cwd() / '-' as a Path: Path('./-') is Path('-'))")
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{what} {str(folder)!r} is a file; a result is saved as a folder: choose a folder name")
    if not folder.parent.is_dir():
        raise OutputError(f"{what} {str(folder)!r}: the folder {str(folder.parent)!r} does not exist; create it first")
    try:
        folder.mkdir(exist_ok=True)
    except OSError as err:
        raise OutputError(f"{what} {str(folder)!r} cannot be created: {err.strerror or err}") from None
    return folder


def _refuse_foreign(folder: Path, names: set[str], earlier: set[str] | None, what: str) -> None:
    mine = earlier or set()
    foreign = sorted(n for n in names if (folder / n).exists() and n not in mine)
    if foreign:
        raise OutputError(f"{what} {str(folder)!r} already holds {', '.join(foreign)}, which no earlier footzoo result "
                          "there wrote (no manifest.json lists it); footzoo replaces only its own files: choose an "
                          "empty folder, or move those files away")


def check_folder(path: str | os.PathLike, names: Any, what: str = "--out") -> None:
    """Refuse, before any work, a result folder holding one of ``names`` that no earlier footzoo result there wrote
    (the check :func:`save_result` makes when it writes)."""
    folder = Path(path)
    if folder.is_dir():
        _refuse_foreign(folder, set(names), _earlier_files(folder, FORMAT), what)


def _metrics_payload(result: Any) -> dict[str, Any]:
    notes: dict[str, str] = {}
    try:
        # once, without a second warning of the NaNs the run already warned about: their reasons go into the file
        metrics, notes = result.checked_metrics()
    except Exception as err:  # a failing metric must not lose the result
        warnings.warn(FootzooWarning(f"Result.save: the metrics could not be computed ({type(err).__name__}: {err}); "
                                     "saved without them"), stacklevel=user_stacklevel())
        metrics = {"error": f"{type(err).__name__}: {err}"}
    recording = json_safe(result.recording)  # nested metadata as plain JSON; objects as their text, never dropped
    return {"metrics": metrics, "metric_notes": notes, "config": result.config, "versions": result.versions,
            "recording": recording}


def _result_files(result: Any, folder: Path, group: FileGroup, backend: str) -> dict[str, Any]:
    """Write a result's files into ``folder`` through ``group``; returns the manifest's ``files``."""
    files: dict[str, Any] = {}
    for attr, holds in (("samples", "per-sample estimates (Result.samples)"),
                        ("steps", "per-stride table (Result.steps)")):
        name, info = _write_table(getattr(result, attr), group, folder, attr, backend)
        files[name] = {"holds": holds, **info}
    with group.open(folder / "metrics.json") as fh:
        fh.write(dumps_json(_metrics_payload(result)))
    files["metrics.json"] = {"holds": "Result.metrics (with metric_notes: why a metric is null), config, "
                                      "versions and the recording's plain metadata (strict JSON, NaN as null; "
                                      "recomputed on load)", "kind": "json"}
    packer = _Packer()
    reference = None
    if result.reference is not None:
        ref = result.reference
        reference = {name: packer.pack(getattr(ref, name), f"reference.{name}")
                     for name in (*TRUTH_ARRAYS, *TRUTH_TABLES, "closed_loop", "stride_count", "source")}
    body = {"config": packer.pack(result.config, "config"), "versions": packer.pack(result.versions, "versions"),
            "recording": packer.pack(result.recording, "recording"),
            "diagnostics": packer.pack(result.diagnostics, "diagnostics"), "reference": reference,
            "steps_notes": {str(k): str(v) for k, v in (result.steps.attrs.get("notes") or {}).items()}}
    for key, table in packer.tables.items():
        name, info = _write_table(table, group, folder, key, backend)
        files[name] = {"holds": "a table of result.json (diagnostics or reference)", **info}
        _rename_table_refs(body, key, name)
    if packer.arrays:
        with group.open(folder / "arrays.npz", "wb") as fh:
            np.savez(fh, **packer.arrays)
        files["arrays.npz"] = {
            "holds": "the arrays of result.json (diagnostics, reference)", "kind": "arrays",
            "arrays": {k: {"dtype": str(a.dtype), "shape": list(a.shape)} for k, a in packer.arrays.items()}}
    with group.open(folder / "result.json") as fh:
        fh.write(json.dumps(body, indent=1, allow_nan=False, ensure_ascii=False) + "\n")
    files["result.json"] = {"holds": "config, versions, recording metadata, diagnostics and the reference, "
                                              "lossless (arrays and tables in the files listed here)", "kind": "json"}
    if packer.dropped:
        warnings.warn(FootzooWarning("Result.save: not saved (not plain values, arrays or tables): "
                                     + "; ".join(packer.dropped[:10])), stacklevel=user_stacklevel())
        files["result.json"]["dropped"] = packer.dropped
    return files


def _rename_table_refs(value: Any, key: str, name: str) -> None:
    if isinstance(value, dict):
        if value.get("$table") == key:
            value["$table"] = name
        for v in value.values():
            _rename_table_refs(v, key, name)
    elif isinstance(value, list):
        for v in value:
            _rename_table_refs(v, key, name)


def _manifest(kind: str, backend: str, files: dict[str, Any], **extra: Any) -> str:
    return dumps_json({"format": kind, "format_version": FORMAT_VERSION, "footzoo_version": __version__,
                       "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                       "backend": backend, **extra, "files": files})


def _inputs(result: Any, inputs: Any) -> list[str]:
    rec = getattr(result, "recording", {}) or {}
    found = [str(f) for f in rec.get("input_files") or [] if f]
    if not found and isinstance(rec.get("source"), str) and Path(rec["source"]).exists():
        found.append(rec["source"])
    return found + [str(i) for i in inputs]


def _commit(folder: Path, group: FileGroup, files: dict[str, Any], earlier: set[str] | None) -> None:
    names = set(files) | {MANIFEST}
    for stale in (earlier or set()) - names:
        group.remove(folder / stale)


#: Extensions of single files: a result folder with one of these names is refused (a user expecting one file).
FILE_SUFFIXES = (".csv", ".tsv", ".txt", ".json", ".parquet", ".pq", ".xlsx", ".xls", ".npz", ".npy", ".mat", ".h5",
                 ".hdf5", ".zip", ".pkl", ".pickle")


def _extra_files(group: FileGroup, folder: Path, files: dict[str, bytes] | None) -> dict[str, Any]:
    """Write the extra files of a save (figures: name -> content) into the group; their manifest entries."""
    out: dict[str, Any] = {}
    for name, content in (files or {}).items():
        if not isinstance(name, str) or Path(name).name != name or name in (MANIFEST, INCOMPLETE):
            raise OutputError(f"files: {name!r} is not a plain file name for the archive's folder")
        with group.open(folder / name, "wb") as fh:
            fh.write(content)
        out[name] = {"holds": "written with the result (a figure of the run, the command's log)", "kind": "file"}
    return out


def save_result(result: Any, path: str | os.PathLike, backend: str = "auto", inputs: Any = (),
                files: dict[str, bytes] | None = None) -> Path:
    """Write ``result`` as a result archive folder (see the module doc); returns the folder.

    Parameters
    ----------
    result : Result
        What to save.
    path : str or Path
        The folder (created when missing; its parent must exist).
    backend : {"auto", "parquet", "csv"}
        Table format; ``auto`` is Parquet when pyarrow is installed.
    inputs : iterable of paths
        Files besides the recording's own (``result.recording["input_files"]``) that must not be
        replaced (the config file, for instance).
    files : dict of str to bytes, optional
        More files written with the archive, in the same commit, and listed in its manifest (the
        figures of ``footzoo run --plot``): a later save without them removes them, so a folder
        never keeps an earlier run's figures beside a newer result.

    Raises
    ------
    OutputError
        For an unusable folder, a file in it that footzoo did not write, or a file that is an input.
    """
    backend = _backend(backend)
    what = "Result.save"
    if not isinstance(path, (str, os.PathLike)):
        raise OutputError(f"{what}: the folder is a path (text or pathlib.Path), got {type(path).__name__} "
                          f"{path!r:.60}")
    for name, content in (files or {}).items():
        if not isinstance(name, str) or not isinstance(content, (bytes, bytearray)):
            raise OutputError(f"{what}: files= maps file names (text) to their content (bytes), got {name!r}: "
                              f"{type(content).__name__}; a figure's bytes come from "
                              "footzoo.evaluation.plots.png_bytes, text from str.encode()")
    suffix = Path(path).suffix.lower()
    if suffix in FILE_SUFFIXES and not Path(path).is_dir():
        raise OutputError(f"{what}: {str(path)!r} looks like a file name ({suffix}), but a result is saved as a folder "
                          "of tables and JSON files; give a folder name (e.g. "
                          f"{str(Path(path).with_suffix(''))!r}). To export one table: result.samples.to_csv(...)")
    with _new_folder(path, what) as folder:
        earlier = _earlier_files(folder, FORMAT)
        with FileGroup(inputs=_inputs(result, inputs), what=what, marker=folder / MANIFEST) as group:
            written = _result_files(result, folder, group, backend)
            written.update(_extra_files(group, folder, files))
            _refuse_foreign(folder, set(written) | {MANIFEST}, earlier, what)
            _hash_files(folder, group, written)
            with group.open(folder / MANIFEST) as fh:
                fh.write(_manifest(FORMAT, backend, written))
            _commit(folder, group, written, earlier)
    return folder


#: A SHA-256 as the manifest records it.
_HEX64 = re.compile(r"[0-9a-f]{64}")


def _hash_files(folder: Path, group: FileGroup, files: dict[str, Any]) -> None:
    """Add the SHA-256 of each file of the archive (as written, not yet renamed into place) to its manifest entry;
    the files saved with it (figures, the log: kind ``file``) are not what :func:`read_result` reads."""
    for name, info in files.items():
        if info.get("kind") != "file":
            info["sha256"] = sha256(group.path(folder / name))


def _problems(folder: Path, files: dict[str, Any], loader: str) -> list[str]:
    """What :func:`_verify` warns of: each file whose SHA-256 differs from its manifest's (archives saved without
    hashes: nothing), and each file a hashed manifest gives no well-formed SHA-256 for (its entry was edited)."""
    out = []
    checked = {name: info for name, info in files.items() if info.get("kind") != "file"}
    fix = (f"restore the folder from a copy or save the result again, or {loader}(path, verify=False) to load it "
           "without this check")
    if any("sha256" in info for info in checked.values()):
        unchecked = [name for name, info in checked.items() if not _HEX64.fullmatch(str(info.get("sha256", "")))]
        if unchecked:
            names = ", ".join(repr(str(folder / n)) for n in unchecked)
            out.append(f"{loader}: manifest.json of {str(folder)!r} records no well-formed SHA-256 (64 hexadecimal "
                       f"digits) for {names}, so whether it changed after the save cannot be checked; the manifest "
                       f"was edited: {fix}")
    changed = [name for name, info in checked.items() if isinstance(info.get("sha256"), str)
               and _HEX64.fullmatch(info["sha256"]) and (folder / name).is_file()
               and sha256(folder / name) != info["sha256"]]
    if changed:
        names = ", ".join(repr(str(folder / n)) for n in changed)
        out.append(f"{loader}: {names} changed after the result was saved (the SHA-256 differs from the one its "
                   "manifest.json records): loaded as it is now, edited by hand or by another program, not as "
                   f"footzoo wrote it; {fix}")
    return out


def _verify(folder: Path, files: dict[str, Any], loader: str) -> None:
    """Warn of what :func:`_problems` finds."""
    for message in _problems(folder, files, loader):
        warnings.warn(FootzooWarning(message), stacklevel=user_stacklevel())


def _stamp(folder: Path) -> tuple[Any, ...]:
    """What changes when a save commits into ``folder`` (its manifest is replaced last) or is under way."""
    try:
        st = (folder / MANIFEST).stat()
    except OSError:
        return (None, (folder / INCOMPLETE).exists())
    return (st.st_ino, st.st_mtime_ns, st.st_size, (folder / INCOMPLETE).exists())


#: Reads of an archive that another process saves into meanwhile, before :func:`read_result` gives up.
READ_ATTEMPTS = 5


def _read_manifest(path: str | os.PathLike, kind: str) -> dict[str, Any]:
    what = "a result" if kind == FORMAT else "a session result"
    loader = "Result.load" if kind == FORMAT else "SessionResult.load"
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise FormatError(f"{loader}: give the path of the folder {loader.split('.')[0]}.save wrote (got {path!r:.80})")
    folder = Path(path)
    if not folder.is_dir():
        raise FormatError(f"{str(folder)!r} is not a folder; {what} is loaded from the folder Result.save wrote")
    manifest = folder / MANIFEST
    check_complete(folder, MANIFEST, what)
    try:
        data = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, ValueError) as err:
        raise FormatError(f"{manifest}: cannot be read ({err}); the archive is damaged") from None
    if not isinstance(data, dict) or data.get("format") != kind:
        found = data.get("format") if isinstance(data, dict) else None
        hint = " (use SessionResult.load)" if found == SESSION_FORMAT else \
            " (use Result.load for each foot's folder)" if found == FORMAT and kind == SESSION_FORMAT else ""
        raise FormatError(f"{manifest}: format {found!r}, expected {kind!r}{hint}")
    version = data.get("format_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise FormatError(f"{manifest}: format version {version!r} is not one footzoo writes (whole numbers from 1); "
                          "the manifest is damaged: save the result again or restore the folder from a copy")
    if version > FORMAT_VERSION:
        raise FormatError(f"{manifest}: format version {version!r} is newer than this footzoo reads "
                          f"({FORMAT_VERSION}); upgrade footzoo (footzoo {data.get('footzoo_version')} wrote it)")
    files = data.get("files", {})
    bad = [k for k, v in files.items() if not isinstance(v, dict)] if isinstance(files, dict) else None
    if bad is None or bad:
        got = f"{type(files).__name__}" if bad is None else f"the entry of {', '.join(map(repr, bad[:5]))} is not one"
        raise FormatError(f"{manifest}: its 'files' entry is not a mapping of each file's name to its description "
                          f"({got}); the manifest is damaged: save the result again or restore the folder from a copy")
    missing = [f for f in files if not (folder / f).exists()]
    if missing:
        raise FormatError(f"{str(folder)!r}: the archive lacks {missing}, which its manifest lists; it is incomplete")
    return data


def _result_fields(folder: Path, files: dict[str, Any]) -> dict[str, Any]:
    def table(stem: str) -> pd.DataFrame:
        for suffix in (".parquet", ".csv"):
            if stem + suffix in files:
                return _read_table(folder, stem + suffix, files[stem + suffix])
        raise FormatError(f"{folder}: no {stem} table in the archive")

    body = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    tables = {name: _read_table(folder, name, info) for name, info in files.items()
              if info.get("kind") == "table" and name.startswith("table_")}
    arrays: Any = {}
    if "arrays.npz" in files:
        with np.load(folder / "arrays.npz", allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    unpacker = _Unpacker(arrays, tables)
    reference = None
    if body.get("reference") is not None:
        reference = Truth(**{k: unpacker.unpack(v) for k, v in body["reference"].items()})
    steps = table("steps")
    if body.get("steps_notes"):  # why a column of the stride table is NaN (an analysis said so)
        steps.attrs["notes"] = dict(body["steps_notes"])
    return {"samples": table("samples"), "steps": steps, "config": unpacker.unpack(body["config"]),
            "versions": unpacker.unpack(body["versions"]), "recording": unpacker.unpack(body["recording"]),
            "diagnostics": unpacker.unpack(body["diagnostics"]), "reference": reference}


#: What reading a damaged archive file raises (json, numpy's npz, pandas, pyarrow: ArrowInvalid is a ValueError).
_DAMAGED = (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile)


def read_result(path: str | os.PathLike, verify: bool = True, loader: str = "Result.load") -> dict[str, Any]:
    """The fields of the :class:`~footzoo.evaluation.result.Result` saved in the folder ``path`` (see the module doc):
    ``samples``, ``steps``, ``config``, ``versions``, ``recording``, ``diagnostics`` and ``reference`` (a
    :class:`~footzoo.core.data.Truth` or None); :meth:`Result.load <footzoo.evaluation.result.Result.load>` makes
    the result from them.

    A file of the archive that is truncated, overwritten or otherwise damaged is a FormatError
    naming the folder and the cause (never a raw parser error). A file that reads but whose SHA-256
    differs from the manifest's (edited after the save) is loaded as it is, with a ``FootzooWarning``
    naming it; ``verify=False`` skips that check (archives saved without hashes are not checked).
    """
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        _read_manifest(path, FORMAT)  # the error naming what to give
    folder = Path(path)
    for attempt in range(READ_ATTEMPTS):  # another process saving into the folder meanwhile: read it again
        stamp = _stamp(folder)
        try:
            data = _read_manifest(path, FORMAT)
            fields = _result_fields(folder, data["files"])
            problems = _problems(folder, data["files"], loader) if verify else []
        except (FormatError, *_DAMAGED) as err:
            if attempt + 1 < READ_ATTEMPTS and _stamp(folder) != stamp:  # saved into meanwhile: read it again
                time.sleep(0.05 * (attempt + 1))
                continue
            if isinstance(err, FormatError):
                raise
            raise FormatError(f"{str(folder)!r}: the archive is damaged, a file cannot be read ({type(err).__name__}: "
                              f"{str(err)[:200]}); save the result again or restore the folder from a copy") from None
        if _stamp(folder) == stamp and not stamp[-1]:
            break
        time.sleep(0.05 * (attempt + 1))
    else:
        raise FormatError(f"{str(folder)!r}: another process saved into the folder while it was read, "
                          f"{READ_ATTEMPTS} times; load it again when that save has ended")
    for message in problems:
        warnings.warn(FootzooWarning(message), stacklevel=user_stacklevel())
    return fields


def save_session(session: Any, path: str | os.PathLike, backend: str = "auto", inputs: Any = (),
                 files: dict[str, dict[str, bytes]] | None = None) -> Path:
    """Write a :class:`~footzoo.runtime.session.SessionResult` as a folder: one result folder per foot
    (``left/``, ``right/``), the combined stride table and the bilateral table (both recomputed on load).

    ``files``: per foot, more files written into its folder with the archive (as :func:`save_result`'s); under
    ``"."``, into the session's folder (the command's log).
    """
    backend = _backend(backend)
    what = "SessionResult.save"
    all_inputs = [i for r in session.results.values() for i in _inputs(r, ())] + [str(i) for i in inputs]
    with _new_folder(path, what) as folder, \
            FileGroup(inputs=all_inputs, what=what, marker=Path(path) / MANIFEST) as group:
        earlier = _earlier_files(folder, SESSION_FORMAT)
        files, extra = {}, files or {}
        for foot, result in session.results.items():
            sub = folder / foot
            sub.mkdir(exist_ok=True)
            own = _result_files(result, sub, group, backend)
            own.update(_extra_files(group, sub, extra.get(foot)))
            _hash_files(sub, group, own)
            with group.open(sub / MANIFEST) as fh:
                fh.write(_manifest(FORMAT, backend, own, foot=foot))
            files.update({f"{foot}/{name}": info for name, info in own.items()})
            files[f"{foot}/{MANIFEST}"] = {"holds": f"the {foot} foot's result (Result.load reads this folder)",
                                           "kind": "json"}
        for attr, holds in (("steps", "both feet's strides with step_time_s (SessionResult.steps; derived)"),
                            ("bilateral", "medians per foot and symmetry index (SessionResult.bilateral; derived)")):
            name, info = _write_table(getattr(session, attr), group, folder, attr, backend)
            files[name] = {"holds": holds, **info}
        files.update(_extra_files(group, folder, extra.get(".")))
        _refuse_foreign(folder, set(files) | {MANIFEST}, earlier, what)
        _hash_files(folder, group, {k: v for k, v in files.items() if "/" not in k})
        with group.open(folder / MANIFEST) as fh:
            fh.write(_manifest(SESSION_FORMAT, backend, files, name=session.name, feet=list(session.results)))
        _commit(folder, group, files, earlier)
    return folder


def read_session(path: str | os.PathLike, verify: bool = True) -> tuple[str, dict[str, dict[str, Any]]]:
    """``(name, {foot: the fields of its Result})`` of a session saved by :func:`save_session` (:func:`read_result`;
    ``verify`` as there)."""
    data = _read_manifest(path, SESSION_FORMAT)
    folder = Path(path)
    results = {str(foot): read_result(folder / str(foot), verify, "SessionResult.load")
               for foot in data.get("feet") or []}
    if verify:  # the session's own tables (each foot's files are checked by its read_result)
        _verify(folder, {k: v for k, v in data.get("files", {}).items() if "/" not in k}, "SessionResult.load")
    return str(data.get("name", folder.name)), results


def describe(path: str | os.PathLike) -> str:
    """A short text of what an archive folder holds (from its manifest)."""
    folder = Path(path)
    data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    out = io.StringIO()
    out.write(f"{data['format']} v{data['format_version']} (footzoo {data['footzoo_version']}, "
              f"{data['created_utc']}, {data['backend']} tables)\n")
    for name, info in data["files"].items():
        rows = f", {info['rows']} rows" if "rows" in info else ""
        out.write(f"  {name}: {info['holds']}{rows}\n")
    return out.getvalue()
