"""Canonical CSV/Parquet: columns ``t, acc_x..z, gyr_x..z[, mag_x..z][, dist_*][, true_*]``.

SI units and FRD axes unless declared otherwise (``acc_unit``, ``gyr_unit``, ``axes``: the
columns' axes -> FRD, :mod:`footzoo.io.axes`).
A file written by ``footzoo simulate`` also carries its ground truth in
``true_*`` columns, a metadata sidecar ``<file>.meta.yaml`` (metadata and the
``closed_loop`` marker, :mod:`footzoo.io.metadata`) and the true steps in
``<file>.steps.csv`` (every true stride: its row count becomes ``truth.stride_count``, unless the sidecar's ``truth:``
gives a hand count). A reference that has only a stride table, a closed-loop marker or a
stride count (gaitmap's strides, x-io's closed loop, Köroğlu's count) round-trips too.
:func:`write` writes the three files as one unit (atomically, never over an input), and
removes the steps sidecar of an earlier file of the same name when the new one has none.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..core.archive import parquet_available
from ..core.atomic import FileGroup, remove_stale_temporaries
from ..core.checks import check_bool
from ..core.conventions import quat_from_matrix, quat_mul
from ..core.data import ACC_COLS, GYR_COLS, MAG_COLS, TRUTH_POS_COLS, TRUTH_QUAT_COLS, TRUTH_VEL_COLS, Recording, Truth
from ..core.errors import FootzooWarning, FormatError, OutputError, did_you_mean, user_stacklevel
from ..core.files import not_utf8
from .axes import describe_axes, parse_axes, rotate_columns
from .base import (
    RECORDING_OPTIONS,
    Option,
    Reader,
    check_unique_columns,
    data_suffix,
    first_line,
    frame_options,
    input_files,
    text_source,
)
from .metadata import facts_text, meta_path, plain_meta, read_facts, sha256, steps_path

#: Float format of every CSV footzoo writes: 17 significant digits reload to the same double.
FLOAT_FORMAT = "%.17g"


def float_text(x: float) -> str:
    """A float as the shortest text that reloads to the same double, always with a ``.`` or an exponent
    (``2.0``, not ``2``), so a column of whole-number floats reloads as floats, not integers."""
    return repr(float(x))


#: ``pd.read_csv`` options that parse those digits back exactly (pandas 3 does by default).
EXACT_CSV: dict[str, Any] = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}
#: File suffixes of the canonical format.
CSV_SUFFIXES = (".csv",)
PARQUET_SUFFIXES = (".parquet", ".pq")


def matches(header: str) -> bool:
    """True for a canonical CSV header."""
    cols = [c.strip().strip('"').strip("'").strip() for c in header.split(",")]
    return "t" in cols and "acc_x" in cols and "gyr_x" in cols


#: Canonical columns are FRD already.
AXES = "[x, y, z]"


def read(path: Path, axes: Any = AXES, **options: Any) -> Recording:
    """Read a canonical CSV or Parquet file (``axes``: :mod:`footzoo.io.axes`; other options go to
    ``Recording.from_dataframe``)."""
    rows = parse_axes(AXES if axes is None else axes, "axes")
    try:
        if path.suffix.lower() in PARQUET_SUFFIXES:
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(text_source(path), comment="#", **EXACT_CSV)
    except UnicodeDecodeError:
        raise FormatError(f"{path}: {not_utf8(path)}") from None
    except FormatError:
        raise
    except (ValueError, OSError, pd.errors.ParserError) as err:
        raise FormatError(f"{path}: cannot read as canonical CSV/Parquet: {err}") from None
    # a header written 't, acc_x, ...' is recognised (matches strips the names): read it with the same names
    df.columns = [c.strip() if isinstance(c, str) else c for c in df.columns]
    check_unique_columns(df, path)
    _warn_unread(df.columns, path)
    if not np.array_equal(rows, np.eye(3)):
        rotate_columns(df, rows)
        _rotate_truth_attitude(df, rows)
    facts = read_facts(path)
    meta: dict[str, Any] = {"name": path.stem, "source": str(path), "format": "canonical",
                            "axes": describe_axes(rows)}
    meta.update(facts.meta)
    meta["input_files"] = [str(path), *map(str, facts.files)]
    rec = Recording.from_dataframe(df, meta=meta, **options)
    if rec.truth is None and (facts.steps is not None or facts.closed_loop or facts.truth):
        rec.truth = Truth()  # a reference without per-sample columns: a stride table, a closed loop, a count
    if rec.truth is not None:
        rec.truth.closed_loop = bool(facts.closed_loop)
        if facts.steps is not None:
            try:
                steps = pd.read_csv(facts.steps, **EXACT_CSV)
            except (UnicodeDecodeError, ValueError, pd.errors.ParserError) as err:
                raise FormatError(f"{facts.steps}: cannot read the true steps: {err}; fix or delete the file") from None
            rec.truth.steps = check_steps(steps, facts.steps, rec.t)
            rec.truth.stride_count = len(rec.truth.steps)  # the sidecar lists every true stride
        if "stride_count" in facts.truth:  # the reference's own count (a hand count, or null: none)
            count = facts.truth["stride_count"]
            rec.truth.stride_count = None if count is None else int(count)
        if meta.get("source") == "footzoo.sim":
            rec.truth.source = "simulator"
        rec.truth.source = str(facts.truth.get("source", rec.truth.source))
    return rec


def _rotate_truth_attitude(df: pd.DataFrame, rows: np.ndarray) -> None:
    """The true attitude ``true_qw..qz`` of a file read with another axis map: body frame FRD, not the file's."""

    if all(c in df.columns for c in TRUTH_QUAT_COLS):
        q = df[TRUTH_QUAT_COLS].to_numpy(dtype=float)
        df[TRUTH_QUAT_COLS] = quat_mul(q, np.broadcast_to(quat_from_matrix(rows.T), q.shape))


#: Columns the canonical reader reads (besides ``dist_*`` and ``true_dist_*``).
COLUMNS = ("t", *ACC_COLS, *GYR_COLS, *MAG_COLS, *TRUTH_POS_COLS, *TRUTH_VEL_COLS, *TRUTH_QUAT_COLS, "true_stance")


def _warn_unread(columns: Any, path: Path) -> None:
    """A warning naming the columns the canonical format does not read (a misspelt reference is not lost silently)."""
    unread = [str(c) for c in columns if str(c) not in COLUMNS and not str(c).startswith(("dist_", "true_dist_"))]
    if unread:
        named = ", ".join(f"{c!r}{did_you_mean(c, list(COLUMNS))}" for c in unread[:8])
        more = f" and {len(unread) - 8} more" if len(unread) > 8 else ""
        warnings.warn(FootzooWarning(
            f"{path.name}: column(s) {named}{more} are not read: the canonical format reads t, acc_x..z, gyr_x..z, "
            "mag_x..z, dist_*, and as the reference true_pos_n..d, true_vel_n..d, true_qw..qz, true_stance, "
            "true_dist_*; rename a column to use it (or drop it to silence this)"), stacklevel=user_stacklevel())


#: Columns of a true-steps sidecar that hold the strides' times (s): footzoo's names and the simulator's older ones.
STEP_TIME_COLUMNS = ("start_s", "to_s", "end_s", "ms_start_s", "ms_end_s", "swing_start", "swing_end", "start", "end")


#: Columns of a true-steps sidecar footzoo reads: the times, the simulator's stride geometry and the steps table's.
STEP_COLUMNS = (*STEP_TIME_COLUMNS, "stride_length", "heading", "fpa", "foot_yaw", "largest_pitch_s",
                "stride_time_s", "stance_time_s", "swing_time_s", "cadence_steps_min", "stride_length_m", "speed_m_s",
                "heading_rad", "fpa_rad", "max_clearance_m", "turn", "notes")


def check_steps(steps: pd.DataFrame, path: Path, t: Any) -> pd.DataFrame:
    """A true-steps sidecar's table, or a FormatError when it is not one (no stride times, or times outside the
    recording): its rows would otherwise count as the reference's strides."""
    fix = f"a true-steps sidecar holds one row per stride with its times in s ({', '.join(STEP_TIME_COLUMNS[:3])}); " \
          f"fix or delete {path.name}"
    names = [str(c) for c in steps.columns]
    twice = sorted({m.group(1) for c in names if (m := re.fullmatch(r"(.+)\.\d+", c)) and m.group(1) in names})
    if twice:  # pandas renames a repeated column 'x' to 'x.1': which one holds the reference would be a guess
        raise FormatError(f"{path}: column(s) {twice} appear more than once; which one holds the reference is "
                          f"unclear: keep one column of each name; {fix}")
    near = [f"{c!r}{did_you_mean(c, list(STEP_COLUMNS))}" for c in names
            if c not in STEP_COLUMNS and did_you_mean(c, list(STEP_COLUMNS))]
    if near:
        warnings.warn(FootzooWarning(
            f"{path.name}: column(s) {', '.join(near)} are not read: a true-steps sidecar's columns are "
            f"{', '.join(STEP_COLUMNS)}; rename a misspelt column to use it (or drop it to silence this)"),
            stacklevel=user_stacklevel())
    times = [c for c in STEP_TIME_COLUMNS if c in steps.columns]
    if not times:
        raise FormatError(f"{path}: not a stride table: its columns {list(steps.columns)[:8]} hold no stride times; "
                          f"{fix}")
    for col in times:
        values = pd.to_numeric(steps[col], errors="coerce")
        text = steps[col].notna() & values.isna()
        if text.any():
            raise FormatError(f"{path}: column {col!r} holds text ({steps[col][text].iloc[0]!r}), not times in s; "
                              f"{fix}")
        finite = values[np.isfinite(values)]
        if not len(finite) or not len(t):
            continue
        lo, hi = float(finite.min()), float(finite.max())
        within = lo >= t[0] - 1.0 and hi <= t[-1] + 1.0  # the recording's clock
        relative = lo >= -1.0 and hi <= t[-1] - t[0] + 1.0  # or seconds from its start
        if not (within or relative):
            raise FormatError(f"{path}: column {col!r} runs from {lo:g} to {hi:g}, but the recording spans "
                              f"{t[0]:g} to {t[-1]:g} s: sample numbers, or another recording's times? {fix}")
    return steps


class CanonicalReader(Reader):
    """footzoo's own format: canonical column names, SI units and FRD axes (or declared units)."""

    reads_metadata_sidecar = True
    description = ("footzoo's canonical CSV/Parquet: columns t, acc_x, acc_y, acc_z, gyr_x, gyr_y, gyr_z (optional "
                   "mag_x..z, dist_*, true_*), SI units unless acc_unit/gyr_unit are declared")
    extensions = (*CSV_SUFFIXES, *PARQUET_SUFFIXES)
    options = {
        **frame_options(AXES, "m/s^2", "rad/s"),
        "dist_unit": Option("m", "", "unit of the dist columns: 'm', 'cm' or 'mm'"),
        **RECORDING_OPTIONS,
    }

    def guess_can_open(self, path: Path) -> bool:
        suffix = data_suffix(path)
        if suffix in PARQUET_SUFFIXES:
            return True
        return suffix in (*CSV_SUFFIXES, ".txt") and matches(first_line(path))

    def open(self, path: Path, **options: Any) -> Recording:
        return read(path, **options)


def written_by_footzoo(path: Path) -> bool:
    """Whether the file ``path`` (a link: the file it names) is as :func:`write` left it: its metadata sidecar names
    its SHA-256."""
    vouched = _vouched(meta_path(path.resolve()), "data_sha256")
    return vouched is not None and vouched == sha256(path)  # the data hashed only when a sidecar names a hash


def _footzoo_sidecar(path: Path, side: Path) -> bool:
    """Whether ``side``, a sidecar of ``path`` whose data file is gone, is one :func:`write` left: a metadata sidecar
    that names its data's SHA-256, or the steps it lists by theirs (a recording deleted by hand leaves these)."""
    if side == meta_path(path):
        return _vouched(side, "data_sha256") is not None
    vouched = _vouched(meta_path(path), "steps_sha256")
    return vouched is not None and vouched == sha256(side)


def _vouched(meta: Path, key: str) -> str | None:
    """The SHA-256 a metadata sidecar :func:`write` left names under ``key`` (``data_sha256``, ``steps_sha256``), or
    None (no such line, or no readable sidecar)."""
    try:
        found = re.search(rf"^{key}:\s*([0-9a-f]{{64}})\s*$", meta.read_text(encoding="utf-8", errors="replace"),
                          re.M)
    except OSError:
        return None
    return None if found is None else found.group(1)


def check_output(path: str | Path) -> Path:
    """``path`` when :func:`write` writes its extension (``.csv``, ``.parquet``, ``.pq``) and may replace what is there
    (nothing, or a recording it wrote: never a user's file), else an OutputError."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (*CSV_SUFFIXES, *PARQUET_SUFFIXES):
        raise OutputError(f"{str(p)!r}: footzoo writes recordings as .csv or .parquet, not "
                          f"{suffix or 'a file without extension'!r}; choose one of these extensions")
    if suffix in PARQUET_SUFFIXES:
        if not parquet_available():
            raise OutputError(f"{str(p)!r}: writing Parquet needs pyarrow (pip install 'footzoo[parquet]'); "
                              "or write .csv")
    if p.is_file() and not written_by_footzoo(p):
        raise OutputError(f"{str(p)!r} exists and is not a recording footzoo wrote (no {meta_path(p).name} describes "
                          "it as it is): footzoo replaces only its own outputs; choose another name, or delete or "
                          "move the file first")
    for side, holds in ((meta_path(p), "its metadata"), (steps_path(p), "its true strides")):
        if side.is_dir():
            raise OutputError(f"{str(p)!r}: its sidecar {side.name} ({holds}, written next to it) cannot be written: "
                              f"{side.name} is a folder; move it away, or choose another name")
        if side.is_file() and not p.exists() and not _footzoo_sidecar(p, side):  # a user's file under that name
            raise OutputError(f"{str(p)!r}: its sidecar {side.name} ({holds}, written next to it) already exists "
                              f"without {p.name}, and footzoo did not write it: move it away, or choose another name")
    return p


def write(rec: Recording, path: str | Path, closed_loop: bool = False) -> Path:
    """Write a recording (with truth columns) as canonical CSV or Parquet plus its sidecars.

    The data file, its metadata sidecar ``<file>.meta.yaml`` and the true-steps sidecar
    ``<file>.steps.csv`` (when the truth has steps) are written as one unit: all or nothing
    replaces an earlier version, and an earlier steps sidecar is removed when the recording has
    none. The recording's own input files are never overwritten, nor a file footzoo did not
    write (:func:`written_by_footzoo`).

    Parameters
    ----------
    rec : Recording
        The recording.
    path : str or Path
        ``.csv``, ``.parquet`` or ``.pq``; another extension is refused (a file named ``.xlsx``
        would not be what it says).
    closed_loop : bool
        Mark the walk as a closed loop (also when ``rec.truth.closed_loop`` says so).

    Raises
    ------
    OutputError
        For another extension, an unwritable place, or a path that is one of the recording's inputs.
    """
    p = check_output(path)
    remove_stale_temporaries(p.parent, f"{p.name}*")  # what a killed earlier write of these files left
    closed_loop = check_bool("closed_loop", closed_loop)
    suffix = p.suffix.lower()
    df = rec.to_dataframe()
    with FileGroup(inputs=input_files(rec.meta), what=f"writing {p.name}") as group:
        tmp = group.path(p)
        if suffix in PARQUET_SUFFIXES:
            df.to_parquet(tmp, index=False)
        else:
            df.to_csv(tmp, index=False, float_format=FLOAT_FORMAT)
        steps_sha = None
        steps = rec.truth.steps if rec.truth is not None else None
        if steps is not None:
            tmp_steps = group.path(steps_path(p))
            steps.to_csv(tmp_steps, index=False, float_format=float_text)  # the table's dtypes reload as written
            steps_sha = sha256(tmp_steps)
        else:
            group.remove(steps_path(p))
        meta, unwritten = plain_meta(rec.meta)
        closed = bool(closed_loop or (rec.truth is not None and rec.truth.closed_loop))
        group.path(meta_path(p)).write_text(facts_text(meta, closed, sha256(tmp), steps_sha, _truth_facts(rec)),
                                            encoding="utf-8")
    _warn_unwritten(rec, p, unwritten)
    return p


def _truth_facts(rec: Recording) -> dict[str, Any]:
    """The reference's scalar facts for the metadata sidecar: its source and a stride count the steps do not give."""
    tr = rec.truth
    if tr is None:
        return {}
    out: dict[str, Any] = {}
    if tr.source:
        out["source"] = str(tr.source)
    if tr.stride_count is None:
        if tr.steps is not None:
            out["stride_count"] = None  # the steps' rows are not a count here
    elif tr.steps is None or int(tr.stride_count) != len(tr.steps):
        out["stride_count"] = int(tr.stride_count)
    return out


def _warn_unwritten(rec: Recording, path: Path, meta: list[str] = ()) -> None:
    """Warn about the metadata and the parts of a reference the canonical files cannot hold (never dropped silently)."""
    if meta:
        warnings.warn(FootzooWarning(
            f"{path.name}: metadata {', '.join(meta[:8])} not written to {path.name}.meta.yaml (not plain text, "
            "numbers, lists or mappings of them, or nested more than 32 deep: a mapping that holds itself); convert "
            "it (e.g. to text) before writing, or keep it apart"),
            stacklevel=user_stacklevel())
    tr = rec.truth
    lost = [name for name in ("footprints", "stride_positions") if tr is not None and getattr(tr, name) is not None]
    if lost:
        warnings.warn(FootzooWarning(
            f"{path.name}: the reference's {' and '.join(lost)} (truth.{', truth.'.join(lost)}) are not written: the "
            "canonical files hold per-sample truth, the steps table, the stride count and the closed-loop marker only. "
            "Keep the original recording for them (footzoo.load reads them from it)"), stacklevel=user_stacklevel())
