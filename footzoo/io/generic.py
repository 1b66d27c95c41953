"""Any delimited text file, described by a small YAML sidecar: columns, units and the axis map.

For a logger footzoo has no reader for, write ``<file>.footzoo.yaml`` next to the data file
(``walk.csv`` -> ``walk.csv.footzoo.yaml``), or one description for many files passed as
``sidecar=``. ``footzoo.load("walk.csv")`` then finds the sidecar and reads the file::

    # walk.csv.footzoo.yaml: how footzoo reads walk.csv
    time: {column: timestamp, unit: ms}       # or {rate: 100} (Hz) when there is no time column
    acc: {columns: [AccX, AccY, AccZ], unit: g}
    gyr: {columns: [GyrX, GyrY, GyrZ], unit: deg/s}
    mag: {columns: [MagX, MagY, MagZ]}        # optional, any unit
    axes: [x, -y, -z]                         # sensor axes -> FRD (footzoo.io.axes): here z up -> z down
    delimiter: ","                            # optional: "," (default), ";", "\\t" or " " (any whitespace)
    decimal: "."                              # optional: "." (default) or ","
    skip_rows: 0                              # optional: lines before the header line
    header: true                              # optional: false when the file has no header line
    comment: "#"                              # optional: lines starting with it are skipped
    meta: {subject: S07, foot: left}          # optional: merged into Recording.meta
    closed_loop: false                        # optional: the walk ends where it started

Columns are named as in the header line, or given by position (0 is the first column) when
``header: false`` (positions work with a header too). Units: time ``s``, ``ms``, ``us``, ``ns``, ``min``, ``h``, or
``datetime`` for date-time text such as ``2025-01-01T10:00:00.125`` (seconds since the Unix epoch;
a double holds them to about 0.2 µs); acc ``m/s^2``, ``g``, ``mg``; gyr
``rad/s``, ``deg/s``; mag any (direction only). The axis map is a signed permutation or a
rotation matrix; a left-handed map (determinant −1) is refused with the fix, because with it
every turn would come out mirrored. Everything is converted once, here, to FRD and SI.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.conventions import ACC_UNITS, GYR_UNITS
from ..core.conventions import TIME_UNITS as SECONDS_PER_UNIT
from ..core.data import Recording, Truth
from ..core.errors import FormatError, did_you_mean
from ..core.yamlsafe import load_file
from .axes import apply_axes, describe_axes, parse_axes
from .base import RECORDING_OPTIONS, Option, Reader, check_unique_columns, first_line, frame_options, text_source

#: Suffix of a data file's description: ``<file>.footzoo.yaml``.
SIDECAR_SUFFIX = ".footzoo.yaml"
#: Keys of a description.
KEYS = ("time", "acc", "gyr", "mag", "axes", "delimiter", "decimal", "skip_rows", "header", "comment", "meta",
        "closed_loop")
TIME_UNITS: dict[str, float | None] = {**SECONDS_PER_UNIT, "datetime": None}
DELIMITERS = {",": ",", ";": ";", "\t": "\t", "\\t": "\t", "tab": "\t", " ": r"\s+", "whitespace": r"\s+"}

#: Where the description format is documented, for the messages.
FORMAT_DOCS = "the format: docs/readers/generic.md, or help(footzoo.io.generic)"


def sidecar_of(path: Path) -> Path:
    """The description of a data file: ``<file>.footzoo.yaml``."""
    return path.with_name(path.name + SIDECAR_SUFFIX)


class _Spec:
    """A validated description (every problem a FormatError naming the sidecar and the key).

    ``given``: the options that replace the description's keys (``axes``, ``acc_unit``, ``gyr_unit``, and
    ``rate``, which replaces ``time``: ``t = row / rate``); a key an option gives may be left out of the description.
    """

    def __init__(self, raw: Any, source: Path, given: dict[str, Any] | None = None):
        given = {k: v for k, v in (given or {}).items() if v is not None}
        self.source = source
        if not isinstance(raw, dict):
            self.fail("", f"expected a mapping with time, acc, gyr and axes, got {raw!r:.80}")
        for key in raw:
            if key not in KEYS:
                self.fail(str(key), f"unknown key{did_you_mean(str(key), list(KEYS))}; valid: {list(KEYS)}")
        for key in ("time", "acc", "gyr", "axes"):
            if key not in raw and not (key == "axes" and "axes" in given) and not (key == "time" and "rate" in given):
                hint = (": the file's axes in footzoo's forward-right-down frame, e.g. axes: [x, y, z] for a sensor "
                        "already FRD, [x, -y, -z] for forward-left-up" if key == "axes" else "")
                self.fail(key, f"missing: a description needs time, acc, gyr and axes{hint} ({FORMAT_DOCS})")
        self.raw = raw
        self.header = self._bool("header", True)
        self.delimiter = self._choice("delimiter", ",", DELIMITERS)
        self.decimal = self._choice("decimal", ".", {".": ".", ",": ","})
        if self.delimiter == self.decimal:
            self.fail("decimal", "the decimal mark cannot be the delimiter too; use delimiter: ';' with decimal: ','")
        self.skip_rows = raw.get("skip_rows", 0)
        if isinstance(self.skip_rows, bool) or not isinstance(self.skip_rows, int) or self.skip_rows < 0:
            self.fail("skip_rows", f"must be a whole number >= 0, got {self.skip_rows!r}")
        self.comment = raw.get("comment")
        if self.comment is not None and (not isinstance(self.comment, str) or len(self.comment) != 1):
            self.fail("comment", f"must be one character such as '#', got {self.comment!r}")
        self.rows = (parse_axes(given["axes"], "axes") if "axes" in given else
                     parse_axes(raw["axes"], f"{source}: axes"))
        if "rate" in given:
            rate = given["rate"]
            if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0 < rate < 1e5:
                raise FormatError(f"rate={rate!r}: must be the sampling rate in Hz (a number > 0), e.g. rate=100")
            self.time = {"rate": float(rate)}
        else:
            self.time = self._time(raw["time"])
        self.acc = self._block("acc", ACC_UNITS, required_unit="acc_unit" not in given)
        self.gyr = self._block("gyr", GYR_UNITS, required_unit="gyr_unit" not in given)
        for key, block, units in (("acc_unit", self.acc, ACC_UNITS), ("gyr_unit", self.gyr, GYR_UNITS)):
            if key in given:
                if given[key] not in units:
                    raise FormatError(f"{key}={given[key]!r} is not supported; use one of {list(units)}")
                block.update(scale=units[given[key]], unit=given[key])
        self.mag = self._block("mag", None, required_unit=False) if raw.get("mag") is not None else None
        self.meta = raw.get("meta") or {}
        if not isinstance(self.meta, dict):
            self.fail("meta", f"must be a mapping, got {self.meta!r:.80}")
        self.closed_loop = self._bool("closed_loop", False)

    def fail(self, key: str, problem: str) -> None:
        where = f"{self.source}" + (f": {key}" if key else "")
        raise FormatError(f"{where}: {problem}; fix the description")

    def _bool(self, key: str, default: bool) -> bool:
        value = self.raw.get(key, default)
        if not isinstance(value, bool):
            self.fail(key, f"must be true or false, got {value!r}")
        return value

    def _choice(self, key: str, default: str, table: dict[str, str]) -> str:
        value = self.raw.get(key, default)
        if value not in table:
            self.fail(key, f"{value!r} is not supported; use one of {list(table)}")
        return table[value]

    def _column(self, key: str, value: Any) -> str | int:
        if self.header and isinstance(value, str) and value:
            return value
        if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
            return value  # a position (resolved to the header's name when there is a header)
        kind = "a column name from the header line, or a position (0 = first)" if self.header else \
            "a position (0 = first column), since header: false"
        self.fail(key, f"{value!r} is not {kind}")
        raise AssertionError  # unreachable

    def _time(self, spec: Any) -> dict[str, Any]:
        if not isinstance(spec, dict):
            self.fail("time", f"expected {{column: NAME, unit: s}} or {{rate: HZ}}, got {spec!r:.80}")
        if "rate" in spec:
            extra = [k for k in spec if k != "rate"]
            rate = spec["rate"]
            if extra:
                self.fail("time", f"{{rate: ...}} takes no other key, got {extra}")
            if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0 < rate < 1e5:
                self.fail("time.rate", f"must be the sampling rate in Hz (a number > 0), got {rate!r}")
            return {"rate": float(rate)}
        extra = [k for k in spec if k not in ("column", "unit")]
        if extra or "column" not in spec:
            self.fail("time", f"expected {{column: NAME, unit: s|ms|us|ns|min|h}} or {{rate: HZ}}, got {spec!r:.80}")
        unit = spec.get("unit", "s")
        if unit not in TIME_UNITS:
            self.fail("time.unit", f"{unit!r} is not a time unit; use one of {list(TIME_UNITS)}")
        return {"column": self._column("time.column", spec["column"]), "scale": TIME_UNITS[unit]}

    def _block(self, key: str, units: dict[str, float] | None, required_unit: bool) -> dict[str, Any]:
        spec = self.raw[key]
        if not isinstance(spec, dict) or "columns" not in spec:
            self.fail(key, f"expected {{columns: [X, Y, Z], unit: ...}}, got {spec!r:.80}")
        extra = [k for k in spec if k not in ("columns", "unit")]
        if extra:
            self.fail(key, f"unknown key(s) {extra}; a block has columns and unit")
        cols = spec["columns"]
        if not isinstance(cols, list) or len(cols) != 3:
            self.fail(f"{key}.columns", f"must list 3 columns (the sensor's x, y and z), got {cols!r:.80}")
        columns = [self._column(f"{key}.columns", c) for c in cols]
        if len(set(columns)) != 3:
            self.fail(f"{key}.columns", f"lists a column twice: {cols}")
        scale = 1.0
        if units is not None:
            unit = spec.get("unit")
            if unit is None and required_unit:
                self.fail(f"{key}.unit", f"missing; say which unit the file stores: one of {list(units)}")
            if unit is not None and unit not in units:
                self.fail(f"{key}.unit", f"{unit!r} is not supported; use one of {list(units)}")
            scale = units.get(unit, 1.0)
        return {"columns": columns, "scale": scale, "unit": spec.get("unit", "")}


def read_description(path: Path, **given: Any) -> _Spec:
    """The validated description in ``path`` (``given``: options replacing its ``axes``, units and time)."""
    return _Spec(load_file(path, FormatError, "data description"), path, given)


def read(path: Path, sidecar: str | Path | None = None, axes: Any = None, acc_unit: str | None = None,
         gyr_unit: str | None = None, rate: float | None = None, **options: Any) -> Recording:
    """Read a delimited text file as its description (``<file>.footzoo.yaml`` or ``sidecar=``) says.

    Parameters
    ----------
    sidecar : path, optional
        The description to use (default: ``<file>.footzoo.yaml`` next to the file).
    axes, acc_unit, gyr_unit : optional
        Replace the description's ``axes``, ``acc.unit`` and ``gyr.unit``.
    rate : float, optional
        Sampling rate (Hz): replaces the description's ``time`` (``t = row / rate``), e.g. the real rate
        of a file whose description declares another one.
    """
    side = Path(sidecar) if sidecar is not None else sidecar_of(path)
    if sidecar is not None and not side.is_file():
        what = "is a folder" if side.is_dir() else "does not exist"
        raise FormatError(f"{path}: its description sidecar={side} {what}; pass the path of a description file "
                          f"({FORMAT_DOCS})")
    if not side.exists():
        raise FormatError(f"{path}: no description {side.name} next to it; write one ({FORMAT_DOCS}"
                          f"{_first_line_hint(path)}) or pass sidecar= (the path of a description shared by several "
                          "files)")
    spec = read_description(side, axes=axes, acc_unit=acc_unit, gyr_unit=gyr_unit, rate=rate)
    source = text_source(path)
    try:
        df = pd.read_csv(source, sep=spec.delimiter, decimal=spec.decimal, skiprows=spec.skip_rows,
                         header=0 if spec.header else None, comment=spec.comment,
                         engine="python" if spec.delimiter == r"\s+" and spec.comment else "c")
    except (ValueError, pd.errors.ParserError) as err:
        raise FormatError(f"{path}: cannot read as described in {side.name}: {err}") from None
    check_unique_columns(df, path)
    df.columns = [c.strip() if isinstance(c, str) else c for c in df.columns]
    names = list(df.columns)

    def resolve(col: Any) -> Any:
        if spec.header and isinstance(col, int) and col < len(names):
            return names[col]
        return col

    spec.time = {**spec.time, "column": resolve(spec.time.get("column"))} if "column" in spec.time else spec.time
    for block in (spec.acc, spec.gyr, *([spec.mag] if spec.mag else [])):
        block["columns"] = [resolve(c) for c in block["columns"]]
    wanted = [spec.time.get("column"), *spec.acc["columns"], *spec.gyr["columns"],
              *(spec.mag["columns"] if spec.mag else [])]
    missing = [c for c in wanted if c is not None and c not in df.columns]
    if missing:
        found = [str(c) for c in df.columns][:20]
        close = "".join(did_you_mean(str(m), found) for m in missing if isinstance(m, str))
        raise FormatError(f"{path}: column(s) {missing} named in {side.name} are not in the file{close}; "
                          f"its columns are {found}{_delimiter_hint(found, spec.delimiter)}")

    def numbers(cols: list[Any]) -> np.ndarray:
        return df[cols].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)

    frame = pd.DataFrame()
    if "rate" in spec.time:
        frame["t"] = np.arange(len(df)) / spec.time["rate"]
    elif spec.time["scale"] is None:
        frame["t"] = _epoch_seconds(df[spec.time["column"]], path, side)
    else:
        frame["t"] = numbers([spec.time["column"]])[:, 0] * spec.time["scale"]
    frame[["acc_x", "acc_y", "acc_z"]] = apply_axes(spec.rows, numbers(spec.acc["columns"]) * spec.acc["scale"])
    frame[["gyr_x", "gyr_y", "gyr_z"]] = apply_axes(spec.rows, numbers(spec.gyr["columns"]) * spec.gyr["scale"])
    if spec.mag is not None:
        frame[["mag_x", "mag_y", "mag_z"]] = apply_axes(spec.rows, numbers(spec.mag["columns"]))
    meta = {"name": path.stem, "source": str(path), "format": "generic", "axes": describe_axes(spec.rows),
            "units_declared": {"acc": spec.acc["unit"], "gyr": spec.gyr["unit"]},
            **spec.meta, "input_files": [str(path), str(side)]}
    if spec.mag is not None and spec.mag["unit"]:
        meta.setdefault("mag_unit", spec.mag["unit"])
    truth = Truth(closed_loop=True, source="closed loop (description)") if spec.closed_loop else None
    return Recording.from_dataframe(frame, meta=meta, truth=truth, **options)


def _first_line_hint(path: Path) -> str:
    """The file's first line, for a description to be written: the column names it will name."""
    try:
        head = first_line(path).strip()
    except (OSError, UnicodeError):
        return ""
    return (f"; the file begins {head[:120]!r}: name its columns under time (or time: {{rate: HZ}} without a "
            "time column), acc and gyr, with their units, and the axes") if head and head.isprintable() else ""


def _delimiter_hint(columns: list[str], delimiter: str) -> str:
    """The fix when the header split into one column that holds another delimiter: the description's ``delimiter``."""
    if len(columns) != 1:
        return ""
    for key, sep in (('";"', ";"), ('"\\t"', "\t"), ('" "', " "), ('","', ",")):
        if sep != delimiter and sep in columns[0].strip():
            return (f": the header line did not split, its names are separated by {sep!r}; "
                    f"add delimiter: {key} to the description")
    return ""


def _epoch_seconds(column: pd.Series, path: Path, side: Path) -> np.ndarray:
    """Date-time text as seconds since the Unix epoch (integer nanoseconds first: no digit is lost)."""
    try:
        stamps = pd.to_datetime(column, utc=True, format="ISO8601")
    except (ValueError, TypeError) as err:
        raise FormatError(f"{path}: the time column {column.name!r} is not date-time text as {side.name} says "
                          f"(time.unit: datetime): {err}") from None
    ns = stamps.dt.as_unit("ns").astype("int64").to_numpy()
    whole = ns // 1_000_000_000
    return whole.astype(float) + (ns - whole * 1_000_000_000) * 1e-9


class GenericReader(Reader):
    """Any delimited text file described by ``<file>.footzoo.yaml``: columns, units, axis map."""

    description = "any delimited text file with a description <file>.footzoo.yaml (columns, units, axis map)"
    implied_by = ("sidecar",)
    extensions = (".csv", ".txt", ".tsv", ".dat")
    options = {
        "sidecar": Option(None, "", "the description to use (default: <file>.footzoo.yaml next to the file); "
                                    "giving it implies this format"),
        **frame_options(None, None, None, where="the description's"),
        "rate": Option(None, "Hz", "sampling rate: replaces the description's time (t = row / rate)"),
        **RECORDING_OPTIONS,
    }

    def guess_can_open(self, path: Path) -> bool:
        """A file with a description ``<file>.footzoo.yaml`` next to it."""
        return sidecar_of(Path(path)).exists()

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """The description: ``sidecar=``, else ``<file>.footzoo.yaml`` next to the file."""
        sidecar = options.get("sidecar")
        return [Path(sidecar) if sidecar is not None else sidecar_of(Path(path))]

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)
