"""Readers: every supported format converted once to a :class:`~footzoo.core.data.Recording` (FRD, SI).

``load(path, format=None, **options)`` picks the reader from ``format`` or, when
``format`` is None, from the file's extension and header.

Formats and their axis maps (sensor axes -> FRD):

============== ============================== ============================================
format         units in the file              axis map
============== ============================== ============================================
canonical      SI (t s, acc m/s², gyr rad/s)  already FRD
xio            g, deg/s                       NGIMU z up: (x, −y, −z), 180° about x
pyshoe         m/s², rad/s                    already x fwd, y right, z down; VICON ``gt``
                                              is mirrored: truth = gt · [1, 1, −1]
gaitmap        m/s², deg/s                    foot frame x toe, y left, z up: (x, −y, −z)
                                              for both feet (see gaitmap.py)
sensorconnect  g, rad/s, Gauss                MicroStrain x fwd, y right, z down: identity
============== ============================== ============================================
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..core.data import Recording
from ..core.errors import FootzooError, FormatError, did_you_mean
from . import canonical, gaitmap, pyshoe, sensorconnect, xio

READERS: dict[str, Callable[..., Recording]] = {
    "canonical": canonical.read,
    "xio": xio.read,
    "pyshoe": pyshoe.read,
    "gaitmap": gaitmap.read,
    "sensorconnect": sensorconnect.read,
}


#: What each CSV reader expects on the first line (shown when a header is not recognised).
EXPECTED_HEADERS: dict[str, str] = {
    "canonical": "columns t, acc_x, acc_y, acc_z, gyr_x, gyr_y, gyr_z (optional mag_x..z, dist_*, true_*), "
                 "SI units unless acc_unit/gyr_unit are declared",
    "xio": "Time (s), Gyroscope X (deg/s), ..., Accelerometer X (g), ...",
    "gaitmap": "two header rows: sensor,left_sensor,...,right_sensor,... then ,acc_x,...,gyr_z",
    "sensorconnect": "Time, <device>:scaledAccelX, ..., <device>:scaledGyroX, ...",
}


#: Longest header line read when detecting a format (characters).
HEADER_MAX_CHARS = 64 * 1024


def check_input_file(path: str | Path, what: str = "recording") -> Path:
    """The path of an existing, readable, non-empty regular file, or a :class:`FormatError` saying why not."""
    if not isinstance(path, (str, os.PathLike)):
        raise FormatError(f"{what} must be a file path (str or Path), got {type(path).__name__} {path!r:.80}")
    p = Path(path)
    try:
        if not p.exists():
            raise FormatError(f"{what} {str(p)!r}: no such file; check the path")
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


def detect_format(path: str | Path) -> str:
    """Guess a file's format from its extension and first line."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".mat":
        return "pyshoe"
    if suffix in (".parquet", ".pq"):
        return "canonical"
    if suffix in (".csv", ".txt"):
        with open(p, encoding="utf-8", errors="replace") as fh:
            head = fh.readline(HEADER_MAX_CHARS)
        if not head.strip():
            raise FormatError(f"{p}: the file is empty (no header line)")
        if xio.matches(head):
            return "xio"
        if gaitmap.matches(head):
            return "gaitmap"
        if sensorconnect.matches(head):
            return "sensorconnect"
        if canonical.matches(head):
            return "canonical"
        raise FormatError(
            f"{p}: cannot tell the format from the header {head.strip()[:80]!r}. Expected one of: "
            + "; ".join(f"{k}: {v}" for k, v in EXPECTED_HEADERS.items())
            + f". Rename the columns, or pass format= one of {sorted(READERS)} (command line: --format)"
        )
    raise FormatError(f"{p}: unknown extension {suffix!r}; pass format= one of {sorted(READERS)}")


def load(path: str | Path, format: str | None = None, **options: Any) -> Recording:
    """Read a recording and convert it to footzoo's conventions.

    Parameters
    ----------
    path : str or Path
        File to read.
    format : str, optional
        One of ``canonical``, ``xio``, ``pyshoe``, ``gaitmap``, ``sensorconnect``;
        detected from the file when omitted.
    **options
        Reader options, e.g. ``foot="left"`` for gaitmap (which sensor to read;
        for other formats it declares the foot, and must agree with a format
        that knows it: PyShoe's sensor is on the right foot), ``acc_unit="g"``
        and ``gyr_unit="deg/s"`` for canonical files (the other formats fix
        their units), ``duplicates="drop"``.
    """
    p = check_input_file(path)
    if format is not None and format not in READERS:
        raise FormatError(
            f"unknown format {format!r}{did_you_mean(str(format), list(READERS))}; valid: {sorted(READERS)}"
        )
    fmt = format or detect_format(p)
    if fmt not in READERS:
        raise FormatError(f"unknown format {fmt!r}{did_you_mean(fmt, list(READERS))}; valid: {sorted(READERS)}")
    for key in ("acc_unit", "gyr_unit"):
        fixed = FIXED_UNITS.get(fmt, {}).get(key)
        if key in options and fixed is not None:
            if options[key] != fixed:
                raise FormatError(f"{p}: {fmt} files store {key.split('_')[0]} in {fixed}; "
                                  f"{key}={options[key]!r} cannot apply (drop the option)")
            del options[key]
    foot = options.pop("foot", None) if fmt != "gaitmap" else None
    if foot is not None and foot not in ("left", "right"):
        raise FormatError(f"foot={foot!r} is not a foot; use 'left' or 'right'")
    try:
        rec = READERS[fmt](p, **options)
    except FootzooError:
        raise
    except TypeError as err:
        if "unexpected keyword argument" in str(err):
            raise FormatError(f"{fmt} reader: {err}; see help(footzoo.io.{fmt}.read) for its options") from err
        raise FormatError(f"{p}: cannot read as {fmt}: {type(err).__name__}: {err}") from err
    except UnicodeDecodeError as err:
        raise FormatError(
            f"{p}: not UTF-8 text (byte offset {err.start}); is it really a {fmt} file? Pass format= if not"
        ) from err
    except Exception as err:  # parsing untrusted bytes: any library error means "not this format"
        raise FormatError(
            f"{p}: cannot read as {fmt}: {type(err).__name__}: {str(err)[:300]}; check the file, or pass the "
            f"right format= (one of {sorted(READERS)})"
        ) from err
    if foot is not None:
        known = rec.meta.get("foot")
        if known is not None and known != foot:
            raise FormatError(f"{p}: this {fmt} recording is from the {known} foot; drop --foot {foot} "
                              f"(or pass --foot {known})")
        rec.meta["foot"] = foot
    return rec


#: Units a format fixes (a reader converts them itself); canonical files take acc_unit/gyr_unit.
FIXED_UNITS: dict[str, dict[str, str]] = {
    "xio": {"acc_unit": "g", "gyr_unit": "deg/s"},
    "pyshoe": {"acc_unit": "m/s^2", "gyr_unit": "rad/s"},
    "gaitmap": {"acc_unit": "m/s^2", "gyr_unit": "deg/s"},
    "sensorconnect": {"acc_unit": "g", "gyr_unit": "rad/s"},
}


__all__ = ["READERS", "builtin_sample", "check_input_file", "detect_format", "load"]


def builtin_sample() -> Recording:
    """The built-in sample recording: x-io's ``short_walk.csv`` (MIT), a closed walk."""
    import warnings
    from importlib.resources import as_file, files

    with as_file(files("footzoo.samples") / "xio_short_walk.csv.gz") as p, warnings.catch_warnings():
        # the file's 205 exact duplicate rows are dropped on purpose; the count is in meta
        warnings.simplefilter("ignore", UserWarning)
        rec = xio.read(Path(p))
    rec.meta.update(name="xio_short_walk", source="footzoo built-in sample (x-io Technologies, MIT)")
    return rec
