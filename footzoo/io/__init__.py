"""Readers: every supported format converted once to a :class:`~footzoo.core.data.Recording` (FRD, SI).

``load(path, format=None, **options)`` picks the reader from ``format`` or, when ``format`` is
None, asks every reader whether it recognises the file (:mod:`footzoo.io.registry`). Readers
are plug-ins of the entry-point group ``footzoo.readers`` (:mod:`footzoo.io.base`): the formats
below are registered there by footzoo itself, and an installed package adds its own the same way.

Every reader takes the options ``axes`` (sensor axes -> FRD, :mod:`footzoo.io.axes`),
``acc_unit`` and ``gyr_unit``, defaulting to what its format stores (a reader plug-in without an
``axes`` option of its own gets it here, applied to what it returns). The defaults:

============== ============================== ============================================
format         units in the file              axis map (``axes``)
============== ============================== ============================================
canonical      SI (t s, acc m/s², gyr rad/s)  ``[x, y, z]``: already FRD
xio            g, deg/s                       ``[x, -y, -z]``: NGIMU z up, 180° about x
pyshoe         m/s², rad/s                    ``[x, y, z]``: x fwd, y right, z down; VICON
                                              ``gt`` is mirrored: truth = gt · [1, 1, −1]
gaitmap        m/s², deg/s                    ``[x, -y, -z]``: foot frame x toe, y left, z up,
                                              for both feet (see gaitmap.py)
sensorconnect  g, rad/s, Gauss                ``[x, y, z]``: MicroStrain x fwd, y right, z down
openshoe       header's: g or m/s², rad/s     ``[x, -y, -z]``: z up in the heel
xsens          m/s², rad/s, normalised (a.u.) ``[-x, y, -z]``: IPOL's MTw, x to the heel, z up
generic        the description's              the description's ``axes:``
============== ============================== ============================================
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator, Mapping
from importlib.resources import as_file, files
from pathlib import Path
from typing import Any

import numpy as np

from ..core.conventions import ACC_UNITS, DIST_UNITS, GYR_UNITS, quat_from_matrix, quat_mul
from ..core.data import DEFAULT_NAME, Recording, Truth
from ..core.errors import FootzooError, FormatError, PluginError, ReaderOptionError, RecordingError, did_you_mean
from ..core.files import not_utf8, nul_in_path, why_missing
from . import xio
from .axes import apply_axes, describe_axes, parse_axes
from .base import REQUIRED, Option, Reader
from .metadata import meta_path, read_facts, steps_path
from .registry import GROUP, available, refresh


class _ReaderTable(Mapping[str, Any]):
    """``READERS``: the available readers by name (discovered at first use)."""

    def __getitem__(self, name: str) -> Any:
        return available()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(available())

    def __len__(self) -> int:
        return len(available())

    def __repr__(self) -> str:
        return repr(available())


#: Every available reader by format name, built-in and installed (see :mod:`footzoo.io.registry`).
READERS: Mapping[str, Any] = _ReaderTable()


def check_input_file(path: str | Path, what: str = "recording") -> Path:
    """The path of an existing, readable, non-empty regular file, or a :class:`FormatError` saying why not."""
    if not isinstance(path, (str, os.PathLike)):
        raise FormatError(f"{what} must be a file path (str or Path), got {type(path).__name__} {path!r:.80}")
    if not str(path).strip():
        raise FormatError(f"{what} is an empty path; give the path of a recording file")
    if nul_in_path(path):
        raise FormatError(f"{what} {nul_in_path(path)}")
    p = Path(path)
    try:
        if not p.exists():
            problem = why_missing(p)
            raise FormatError(f"{what} {str(p)!r}: no such file; check the path" if problem == "does not exist"
                              else f"{what} {str(p)!r} {problem}")
        if p.is_dir():
            raise FormatError(f"{what} {str(p)!r} is a directory; give the path of a recording file inside it")
        if not p.is_file():
            raise FormatError(f"{what} {str(p)!r} is not a regular file (a device or pipe?); save the data to a file")
        if p.stat().st_size == 0:
            raise FormatError(f"{what} {str(p)!r}: the file is empty (0 bytes)")
        with open(p, "rb") as fh:
            fh.read(1)
    except PermissionError:
        raise FormatError(f"{what} {str(p)!r} is not readable (permission denied); fix its permissions") from None
    except OSError as err:
        raise FormatError(f"{what} {str(p)!r} cannot be read: {err.strerror or err}") from None
    return p


def detect_format(path: str | Path, options: Mapping[str, Any] | None = None) -> str:
    """The format of a file: the one reader an option implies (``sidecar=``: ``generic``, a reader's
    ``implied_by``), else the one whose ``guess_can_open`` accepts it (:meth:`Readers.detect`)."""
    readers = available()
    implied = [name for name, r in readers.items() if set(getattr(r, "implied_by", ()) or ()) & set(options or {})]
    if len(implied) == 1:
        return implied[0]
    return readers.detect(Path(path))


def companion_files(path: str | Path, format: str | None = None, **options: Any) -> list[Path]:
    """The files besides ``path`` that reading it may use, whether they exist or not: its metadata sidecar
    ``<file>.meta.yaml`` and true steps ``<file>.steps.csv`` (:mod:`footzoo.io.metadata`), and what its
    reader's ``companions(path, **options)`` lists (a description, a reference). A study's cache key holds
    their content, so that a reference or description added, edited or removed runs the file's cells again.
    A file no reader takes (its runs fail when they read it) has the two sidecars only.
    """
    p = Path(path)
    files = [meta_path(p), steps_path(p)]
    try:
        fmt = detect_format(p, options) if format is None else format
        listed = getattr(available().get_reader(fmt), "companions", None)
        if callable(listed):
            files += [Path(f) for f in listed(p, **options)]
    except Exception:  # noqa: BLE001 - an unreadable file or a reader's bug: its runs fail when they read it
        pass
    return list(dict.fromkeys(files))


def _options_for(reader: Any, fmt: str, path: Path, options: dict[str, Any]) -> tuple[dict[str, Any], Any, Any]:
    """The options to pass to ``reader.open``, the declared foot and the axis map to apply after the reader
    (both handled here when the reader has no such option)."""
    declared: dict[str, Option] = dict(getattr(reader, "options", None) or {})
    fixed: dict[str, str] = dict(getattr(reader, "fixed_units", None) or {})
    out: dict[str, Any] = {}
    foot = axes = None
    for key, value in options.items():
        if key == "axes":
            try:
                parsed = parse_axes(value, "axes")  # refused before the file is read
            except FormatError as e:
                raise ReaderOptionError(str(e)) from None
            if key in declared:
                out[key] = value
            else:
                axes = parsed
        elif key in declared:
            out[key] = value
        elif key in fixed:
            if not _same_unit(key, value, fixed[key]):
                raise ReaderOptionError(f"{path}: {fmt} files store {key.split('_')[0]} in {fixed[key]}; "
                                        f"{key}={value!r} cannot apply (drop the option)")
        elif key == "foot":
            foot = value
        else:
            valid = sorted({*declared, "foot", "axes"})

            elsewhere = (" (sidecar= is the generic reader's option: it reads a delimited file as a description "
                         "says; drop the format, or give format=generic)" if key == "sidecar" else "")
            raise ReaderOptionError(f"{fmt} reader: unknown option {key!r}{did_you_mean(key, valid)}{elsewhere}; its "
                                    f"options are {valid} (see footzoo.io.READERS[{fmt!r}].options)")
    missing = [k for k, o in declared.items() if o.default is REQUIRED and k not in out]
    if missing:
        raise ReaderOptionError(f"{path}: the {fmt} reader needs the option(s) {missing}: "
                                + "; ".join(f"{k}: {declared[k].doc}" for k in missing))
    if foot is not None and foot not in ("left", "right"):
        raise ReaderOptionError(f"foot={foot!r} is not a foot; use 'left' or 'right'")
    return out, foot, axes


def _same_unit(key: str, value: Any, fixed: str) -> bool:
    """True when ``value`` names the unit ``fixed`` (``m/s2`` is ``m/s^2``)."""

    table = {"acc_unit": ACC_UNITS, "gyr_unit": GYR_UNITS, "dist_unit": DIST_UNITS}.get(key, {})
    if isinstance(value, str) and value in table and fixed in table:
        return table[value] == table[fixed]
    return value == fixed


def load(path: str | Path, format: str | None = None, **options: Any) -> Recording:
    """Read a recording and convert it to footzoo's conventions.

    Parameters
    ----------
    path : str or Path
        File to read.
    format : str, optional
        A reader's name (``canonical``, ``xio``, ``pyshoe``, ``gaitmap``, ``sensorconnect``,
        ``openshoe``, ``xsens``, ``generic`` or an installed reader's, see ``footzoo.io.READERS``); when
        omitted, the one reader that recognises the file.
    **options
        Reader options (``footzoo.io.READERS[format].options``), e.g. ``foot="left"`` for gaitmap
        (which sensor to read; for other formats it declares the foot, and must agree with a
        format that knows it: PyShoe's sensor is on the right foot), ``axes="[x, -y, -z]"`` (the
        sensor's axes -> FRD, :mod:`footzoo.io.axes`: every reader takes it), ``acc_unit="g"`` and
        ``gyr_unit="deg/s"`` (the file's units, where they differ from the format's), ``duplicates="drop"``,
        ``sidecar=`` (a description for the ``generic`` format, which it implies).

    Raises
    ------
    FormatError
        For a file no reader (or more than one) recognises, an unknown option, or a file the
        reader cannot read; :class:`~footzoo.core.errors.RecordingError` for data that fails validation.
    """
    p = check_input_file(path)
    readers = available()
    fmt = detect_format(p, options) if format is None else format
    reader = readers.get_reader(fmt)
    kwargs, foot, axes = _options_for(reader, fmt, p, options)
    origin = readers.origins.get(fmt, "footzoo")
    try:
        rec = reader.open(p, **kwargs)
    except RecordingError as err:
        if str(p) in str(err) or p.name in str(err):
            raise
        raise RecordingError(f"{p}: {err}") from None  # name the file: a study reads many
    except FootzooError:
        raise
    except UnicodeDecodeError as err:
        raise FormatError(
            f"{p}: {not_utf8(p) if p.is_file() else 'not UTF-8 text'}; is it really a {fmt} file? Pass format= if not"
        ) from err
    except (KeyboardInterrupt, MemoryError):
        raise
    except (SystemExit, GeneratorExit) as err:  # never a parse failure: the reader's own fault
        raise PluginError(f"the {fmt} reader ({origin}) called sys.exit() / raised {type(err).__name__} while reading "
                          f"{p}; a reader must raise an exception, never exit the process (fix the reader)",
                          plugin=f"reader {fmt!r}", method="open") from err
    except Exception as err:  # parsing untrusted bytes: any library error means "not this format"
        who = f"{fmt}" if origin == "footzoo" else f"{fmt} (reader from {origin})"
        raise FormatError(
            f"{p}: cannot read as {who}: {type(err).__name__}: {str(err)[:300]}; check the file, or pass the "
            f"right format= (one of {sorted(readers)})"
        ) from err
    if not isinstance(rec, Recording):
        raise FormatError(f"the {fmt} reader ({origin}) returned {type(rec).__name__}, not a footzoo Recording; "
                          "its open() must return footzoo.Recording (fix the reader)")
    _complete_meta(rec, p, fmt, reader)
    if axes is not None:
        _rotate(rec, axes)
    if foot is not None:
        known = rec.meta.get("foot")
        if known is not None and known != foot:
            raise FormatError(f"{p}: this {fmt} recording is from the {known} foot; drop --foot {foot} "
                              f"(or pass --foot {known})")
        rec.meta["foot"] = foot
    return rec


def _rotate(rec: Recording, rows: Any) -> None:
    """Apply ``axes`` to what a reader without that option returned: its signals, and its true attitude."""

    rec.acc, rec.gyr = apply_axes(rows, rec.acc), apply_axes(rows, rec.gyr)
    if rec.mag is not None:
        rec.mag = apply_axes(rows, rec.mag)
    if rec.truth is not None and rec.truth.quat is not None:
        rec.truth.quat = quat_mul(rec.truth.quat, np.broadcast_to(quat_from_matrix(rows.T), rec.truth.quat.shape))
    rec.meta["axes"] = describe_axes(rows)


def _complete_meta(rec: Recording, path: Path, fmt: str, reader: Any) -> None:
    """Name, source, format and input files in ``rec.meta``; a metadata sidecar's facts for readers that ignore it."""
    if rec.meta.get("name", DEFAULT_NAME) == DEFAULT_NAME:  # a reader that names nothing: the file's stem
        rec.meta["name"] = path.stem
    rec.meta.setdefault("source", str(path))
    rec.meta.setdefault("format", fmt)
    files = [str(f) for f in rec.meta.get("input_files") or []]
    if str(path) not in files:
        files.insert(0, str(path))
    if not getattr(reader, "reads_metadata_sidecar", False):
        facts = read_facts(path)
        for key, value in facts.meta.items():
            rec.meta.setdefault(key, value)
        if facts.closed_loop is not None:
            if rec.truth is None:
                rec.truth = Truth(source="closed loop (metadata sidecar)")
            rec.truth.closed_loop = facts.closed_loop
        files += [str(f) for f in facts.files if str(f) not in files]
    rec.meta["input_files"] = files


__all__ = ["GROUP", "READERS", "Option", "Reader", "builtin_sample", "check_input_file", "companion_files",
           "detect_format", "load", "refresh"]


def builtin_sample() -> Recording:
    """The built-in sample recording: x-io's ``short_walk.csv`` (MIT), a closed walk."""

    with as_file(files("footzoo.samples") / "xio_short_walk.csv.gz") as p, warnings.catch_warnings():
        # the file's 205 exact duplicate rows are dropped on purpose; the count is in meta
        warnings.simplefilter("ignore", UserWarning)
        rec = xio.read(Path(p), closed_loop=True)
    rec.meta.update(name="xio_short_walk", source="footzoo built-in sample (x-io Technologies, MIT)")
    rec.truth.source = "closed loop (x-io Gait-Tracking short_walk.csv)"
    return rec
