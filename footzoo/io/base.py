"""What a reader is: the :class:`Reader` base class, its declared :class:`Option`\\ s, and helpers for text files.

A reader (modelled on xarray's backend entry points) is an object with

* ``guess_can_open(path) -> bool``: a cheap look at the file (extension, first line) that says
  whether the reader recognises it; it must not raise for a file it does not know;
* ``open(path, **options) -> Recording``: the whole conversion into footzoo's conventions
  (FRD axes, SI units), with a :class:`~footzoo.core.data.Truth` where the format has a reference;

and, to be listed and documented, ``description`` (one line), ``extensions`` (the suffixes it
claims, lower case with the dot), ``options`` (name -> :class:`Option` with default, unit and
meaning; every built-in reader declares :func:`frame_options`: ``axes``, ``acc_unit`` and
``gyr_unit``, defaulting to what the format stores) and ``url``. A reader without an ``axes``
option of its own gets one from :func:`footzoo.io.load`, applied to what it returns; one without
unit options may declare ``fixed_units`` (the units the format always stores, e.g.
``{"acc_unit": "g"}``: a matching ``acc_unit=`` is accepted and ignored, another one refused).

Readers are registered under the entry-point group ``footzoo.readers`` (the built-in formats
too, in footzoo's ``setup.cfg``); :func:`footzoo.io.load` finds them there (see
:mod:`footzoo.io.registry`).
"""

from __future__ import annotations

import importlib
import io
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from ..core.data import Recording
from ..core.errors import FootzooWarning, FormatError, user_stacklevel
from ..core.files import SNIFF_BYTES, damaged_text, foreign_encoding, nul_padding

#: Longest line read when looking at a file's header (characters).
HEADER_MAX_CHARS = 64 * 1024
#: Suffixes of compressed files (read through pandas' decompression).
COMPRESSED = (".gz", ".bz2", ".xz", ".zip", ".zst")
#: Most leading blank lines skipped when looking for the header line.
MAX_BLANK_LINES = 1000


class _Required:
    def __repr__(self) -> str:
        return "required"


#: Default of an option that has none (the user must give it).
REQUIRED: Any = _Required()


@dataclass(frozen=True)
class Option:
    """One keyword option of a reader.

    Parameters
    ----------
    default : any
        Value when the option is not given (:data:`REQUIRED` when it must be).
    unit : str
        Unit of a numeric option ("Hz", "s"), empty otherwise.
    doc : str
        What it means (one sentence or two).
    """

    default: Any = None
    unit: str = ""
    doc: str = ""


#: What to do with a MATLAB file no reader knows: no description format reads binary files.
MAT_ROUTE = ("read its variables with scipy.io.loadmat and build the recording with "
             "footzoo.Recording.from_dataframe (columns t, acc_x ... gyr_z, and acc_unit=/gyr_unit=; "
             "docs/readers/index.md, 'Your own logger'), then save it with footzoo.io.canonical.write for the "
             "command line")

#: Options every built-in reader accepts, passed on to :meth:`footzoo.Recording.from_dataframe`.
RECORDING_OPTIONS: dict[str, Option] = {
    "duplicates": Option("error", "", "rows whose time stamp repeats the previous one: 'error' or 'drop' "
                                      "(keep the first, warn with the count)"),
    "nan_policy": Option("error", "", "non-finite IMU values: 'error' or 'interpolate'"),
    "max_gap": Option(None, "s", "largest gap between samples that is bridged (default 0.25 s, or 5 median "
                                 "periods if longer); longer gaps are refused"),
}


def frame_options(axes: str | None, acc_unit: str | None, gyr_unit: str | None, where: str = "") -> dict[str, Option]:
    """The options of every built-in reader that say how the file's numbers become FRD and SI.

    Parameters
    ----------
    axes, acc_unit, gyr_unit : str or None
        The format's own axis map (``[x, -y, -z]``, :mod:`footzoo.io.axes`) and units; None when
        they come from the file (``where`` says from what: "the header", "the description").

    Returns
    -------
    dict
        ``axes``, ``acc_unit`` and ``gyr_unit`` as :class:`Option` s: a value given replaces the
        format's (a sensor mounted otherwise, a logger set to other units).
    """
    def default(value: str | None) -> str:
        return f" (default: {where})" if value is None else ""

    return {
        "axes": Option(axes, "", "sensor axes -> FRD (x toe, y right, z down), written '[x, -y, -z]' or as a "
                                 f"rotation matrix by rows (footzoo.io.axes){default(axes)}"),
        "acc_unit": Option(acc_unit, "", "unit of the accelerometer in the file: 'm/s^2', 'g' or 'mg'"
                                         + default(acc_unit)),
        "gyr_unit": Option(gyr_unit, "", f"unit of the gyroscope in the file: 'rad/s' or 'deg/s'{default(gyr_unit)}"),
    }


class Reader:
    """Base class of a footzoo reader (subclassing is optional: any object with the same methods works).

    Attributes
    ----------
    name : str
        The format's name (``format=`` in :func:`footzoo.load`); set from the entry point's name.
    description : str
        One line: what files it reads.
    extensions : tuple of str
        File suffixes it claims (``(".csv", ".txt")``), for the listings and the default
        :meth:`guess_can_open`.
    options : dict
        Keyword options of :meth:`open`: name -> :class:`Option`.
    fixed_units : dict
        Units the format always stores (``{"acc_unit": "g", "gyr_unit": "deg/s"}``), for a reader
        without ``acc_unit`` / ``gyr_unit`` options (the built-in ones have them, :func:`frame_options`).
    url : str
        Where the format is described.
    reads_metadata_sidecar : bool
        True when :meth:`open` applies the file's metadata sidecar ``<file>.meta.yaml`` itself;
        otherwise :func:`footzoo.load` merges its ``meta`` (without replacing what the reader set)
        and its ``closed_loop`` (:mod:`footzoo.io.metadata`).
    implied_by : tuple of str
        Options that only make sense for this format: given without ``format=``, they choose this
        reader (``sidecar=`` chooses ``generic``).
    """

    name: ClassVar[str] = ""
    reads_metadata_sidecar: ClassVar[bool] = False
    implied_by: ClassVar[tuple[str, ...]] = ()
    description: ClassVar[str] = ""
    extensions: ClassVar[tuple[str, ...]] = ()
    options: ClassVar[dict[str, Option]] = {}
    fixed_units: ClassVar[dict[str, str]] = {}
    url: ClassVar[str] = ""

    def guess_can_open(self, path: Path) -> bool:
        """True when the file looks like this format (default: its suffix is one of :attr:`extensions`)."""
        return Path(path).suffix.lower() in self.extensions

    def open(self, path: Path, **options: Any) -> Recording:
        """Read the file into a :class:`~footzoo.core.data.Recording` (FRD, SI)."""
        raise NotImplementedError(f"{type(self).__name__}.open")

    def companions(self, path: Path, **options: Any) -> list[Path]:
        """The files besides ``path`` that :meth:`open` reads when they exist (a description, a reference), listed
        whether they exist or not: a study's cache key includes them, so that adding, editing or removing one runs
        the file's cells again. The metadata sidecar ``<file>.meta.yaml`` and ``<file>.steps.csv`` count for every
        reader without being listed (:func:`footzoo.io.companion_files`). Default: none."""
        return []

    def __repr__(self) -> str:
        return f"<footzoo reader {self.name or type(self).__name__!r}: {self.description}>"


def input_files(meta: dict[str, Any]) -> list[str]:
    """The files a recording was read from (``meta["input_files"]``, else its ``source`` when that is a file).

    Writers refuse to replace any of them (:func:`footzoo.core.atomic.refuse_inputs`).
    """
    files = [str(f) for f in meta.get("input_files") or [] if f]
    source = meta.get("source")
    if not files and isinstance(source, str) and source and Path(source).exists():
        files.append(source)
    return files


def first_line(path: str | Path) -> str:
    """The first non-blank line of a text file (without its line break); ``""`` when there is none.

    Leading blank lines (a logger's empty first line) are skipped; at most
    :data:`HEADER_MAX_CHARS` characters of the line are read. Bytes that are not UTF-8 are replaced.
    """
    with _open_text(Path(path)) as fh:
        for _ in range(MAX_BLANK_LINES):
            line = fh.readline(HEADER_MAX_CHARS)
            if not line:
                return ""
            if line.strip():
                return line.rstrip("\r\n")
    return ""


def load_mat(path: str | Path, what: str = "a MATLAB .mat file", fix: str = "copy it again from its source") -> dict:
    """``scipy.io.loadmat(path)``; a file it cannot read is a :class:`FormatError` naming the file, scipy's reason and
    the fix (a truncated copy, an interrupted download, a file of another kind under a ``.mat`` name)."""
    import scipy.io as sio  # deferred: loading footzoo's readers does not load scipy

    try:
        return sio.loadmat(path)
    except Exception as err:  # noqa: BLE001 - scipy raises several types for a damaged file
        raise FormatError(f"{path}: cannot read {what} ({type(err).__name__}: {err}): the file is damaged or "
                          f"truncated, or not a MATLAB file; {fix}") from None


def second_line(path: str | Path) -> str:
    """The second non-blank line of a text file (without its line break), as :func:`first_line` reads the first;
    ``""`` when there is none."""
    with _open_text(Path(path)) as fh:
        found = False
        for _ in range(2 * MAX_BLANK_LINES):
            line = fh.readline(HEADER_MAX_CHARS)
            if not line:
                return ""
            if line.strip():
                if found:
                    return line.rstrip("\r\n")
                found = True
    return ""


def _open_text(path: Path) -> Any:
    """The text of a file for sniffing its header: decompressed for ``.gz``, ``.bz2`` and ``.xz`` (as pandas reads
    them), as it is otherwise (a ``.zip`` or ``.zst`` shows its binary start, which no reader claims)."""
    opener = {".gz": "gzip", ".bz2": "bz2", ".xz": "lzma"}.get(path.suffix.lower())
    if opener is None:
        return open(path, encoding="utf-8-sig", errors="replace")
    module = importlib.import_module(opener)
    return module.open(path, "rt", encoding="utf-8-sig", errors="replace")


def data_suffix(path: str | Path) -> str:
    """The extension of the data, lower case: that of the file, or the one before a compression suffix
    (``walk.csv.gz``: ``.csv``), so that a reader of text tables claims their compressed copies too."""
    p = Path(path)
    if p.suffix.lower() in COMPRESSED and len(p.suffixes) >= 2:
        return p.suffixes[-2].lower()
    return p.suffix.lower()


def has_extension(path: str | Path, *suffixes: str) -> bool:
    """True when ``path`` ends with one of ``suffixes`` (case-insensitive)."""
    return Path(path).suffix.lower() in suffixes


def check_encoding(path: Path, what: str = "") -> None:
    """A :class:`FormatError` naming the conversion when a text file is UTF-16 or UTF-32 or starts with NUL bytes
    (:func:`footzoo.core.files.foreign_encoding`); a compressed file is left to its reader."""
    if Path(path).suffix.lower() in COMPRESSED:
        return
    with open(path, "rb") as fh:
        problem = foreign_encoding(fh.read(SNIFF_BYTES))
    if problem:
        raise FormatError(f"{what or path}: {problem}")


def text_source(path: Path, what: str = "") -> Path | io.BytesIO:
    """``path``, or its content without a last line that was cut short or NUL padding, for ``pandas.read_csv``.

    A text table ends with a line break. When the file does not, its last row may have been cut
    in the middle of a number (a logger stopped mid-write, a copy interrupted) and would be read
    as a valid but wrong number: that row is dropped with a :class:`FootzooWarning` quoting it.
    NUL bytes after the last line (a logger that pre-allocates its file) are dropped the same way,
    with a warning; NUL bytes anywhere else, and UTF-16 or UTF-32 text, are a :class:`FormatError`
    that names the place and the fix (:mod:`footzoo.core.files`). A file of one line only is
    returned as it is (its header alone), and so is a compressed file (``.gz``, ``.bz2``, ``.xz``,
    ``.zip``, ``.zst``: pandas decompresses it and its format checks its end).
    """
    if Path(path).suffix.lower() in COMPRESSED:
        return path
    name = what or str(path)
    check_encoding(path, name)
    with open(path, "rb") as fh:
        fh.seek(0, 2)
        size = fh.tell()
        if size == 0:
            return path
        fh.seek(size - 1)
        last_byte = fh.read(1)
        fh.seek(0)
        has_nul = _has_nul(fh)
        if last_byte in (b"\n", b"\r") and not has_nul:
            return path
        fh.seek(0)
        data = fh.read()
    if has_nul:
        damage = damaged_text(name, data)
        if damage:
            raise FormatError(damage)
        padding = nul_padding(data)
        data = data[:len(data) - padding]
        warnings.warn(FootzooWarning(
            f"{name}: the file ends with {padding} NUL bytes (0x00) after its last line (a logger that pre-allocates "
            "its file, or a copy cut short); they were ignored"), stacklevel=user_stacklevel())
        if data.endswith((b"\n", b"\r")) or not data.strip():
            return io.BytesIO(data)
    cut = data.rfind(b"\n")
    if cut < 0 or not data[:cut].strip():
        return io.BytesIO(data) if has_nul else path
    last = data[cut + 1:].decode("utf-8", errors="replace")
    warnings.warn(FootzooWarning(
        f"{name}: the file does not end with a line break, so its last row may have been cut short "
        f"(a logger stopped or a copy interrupted mid-write); dropped that row: {last[:80]!r}. If the file is "
        "complete, end it with a line break"), stacklevel=user_stacklevel())
    return io.BytesIO(data[:cut + 1])


def _has_nul(fh: Any, block: int = 1 << 22) -> bool:
    """Whether the open binary file holds a NUL byte (read in blocks: bounded memory)."""
    for chunk in iter(lambda: fh.read(block), b""):
        if b"\0" in chunk:
            return True
    return False


def check_unique_columns(df: Any, path: str | Path) -> None:
    """A FormatError when the file's header names a column twice (pandas renames the second ``x`` to ``x.1``).

    Reading on would take one of the two silently; the user must say which one holds the data.
    """
    cols = [str(c) for c in df.columns]
    names = set(cols)
    dup = sorted({m.group(1) for c in cols if (m := re.fullmatch(r"(.+)\.(\d+)", c)) and m.group(1) in names})
    if dup:
        raise FormatError(f"{path}: the header names column(s) {dup} more than once; footzoo cannot tell which "
                          "one holds the data: rename or delete the duplicates")
