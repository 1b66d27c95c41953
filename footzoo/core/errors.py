"""Exceptions footzoo raises; every message names the problem and the fix."""

import copy
import difflib
import inspect
import os
from pathlib import Path

#: footzoo's package folder: a warning's stack level counts the frames inside it (:func:`user_stacklevel`).
_PACKAGE = str(Path(__file__).resolve().parents[1]) + os.sep


class FootzooError(Exception):
    """Base class of footzoo's own errors."""


class RecordingError(FootzooError, ValueError):
    """A recording is malformed: missing columns, bad time stamps, wrong units, …"""


class ConfigError(FootzooError, ValueError):
    """A pipeline configuration is invalid: unknown keys, types or values."""


class FormatError(FootzooError, ValueError):
    """A file cannot be read in the requested (or detected) format."""


class ReaderOptionError(FormatError, ConfigError):
    """A reader option is unknown, missing or given a value it cannot take (``axes=[x, y, w]``, ``foot=middle``).

    An argument's problem, not the file's (the command line's exit code 2), and a :class:`FormatError` for code
    that catches what a reader raises."""


class NotARecordingError(RecordingError, TypeError):
    """An argument that must be a footzoo :class:`~footzoo.Recording` is something else (a path, an array, None).

    Both a :class:`RecordingError` (catch footzoo's errors by subject) and a :class:`TypeError` (Python's
    convention for an argument of the wrong type); the message says how to build the recording.
    """


class NotAPipelineError(ConfigError, TypeError):
    """An argument that must be a footzoo :class:`~footzoo.Pipeline` is something else (a config name, None).

    Both a :class:`ConfigError` and a :class:`TypeError`, as :class:`NotARecordingError`; the message says how
    to build the pipeline.
    """


class OutputError(FootzooError, OSError):
    """An output cannot be written: an unwritable or missing location, or it would replace an input."""


class PluginError(FootzooError):
    """A plug-in broke its contract or raised: the fault is the plug-in's, not footzoo's nor the data's.

    Attributes
    ----------
    plugin : str
        ``"<kind> '<name>'"`` of the plug-in (e.g. ``"correction 'my_update'"``).
    method : str
        The method that failed (``detect``, ``measure``, ...).
    """

    def __init__(self, message: str, plugin: str = "", method: str = ""):
        super().__init__(message)
        self.plugin = plugin
        self.method = method


class PluginImportError(PluginError, ConfigError):
    """A plug-in module or file listed under ``plugins:`` failed while it was imported (raised, or exited).

    Both a :class:`PluginError` (the fault is in the plug-in's code; the command line exits with
    the plug-in error's code) and a :class:`ConfigError` (the config names it: ``footzoo
    validate`` and a study report it as a problem of the config).
    """


class FootzooWarning(UserWarning):
    """A warning from footzoo: the result is computed but something in the input deserves a look."""


class SensorWarning(FootzooWarning):
    """Suspicious sensor data: saturated (clipped) axes, isolated spikes (glitches)."""


class CalibrationWarning(FootzooWarning):
    """An in-situ calibration could not be fitted reliably and was not applied (:mod:`footzoo.calibration`)."""


class GuardWarning(FootzooWarning):
    """A pipeline guard fired: the detector missed stances, or the estimate diverged (:mod:`footzoo.runtime.guards`)."""


def shown(value: object) -> str:
    """``value`` as a message quotes it: a NumPy number as the plain Python number (``2.99``, not
    ``np.float64(2.99)``), anything else as its ``repr``."""
    item = getattr(value, "item", None)
    if callable(item) and getattr(value, "ndim", None) == 0:
        value = item()
    return repr(value)


def did_you_mean(word: str, options: list[str]) -> str:
    """`` (did you mean 'x'?)`` when a close option exists, else an empty string."""
    close = difflib.get_close_matches(str(word), options, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def prefixed(err: FootzooError, where: object) -> FootzooError:
    """The same error (its class and attributes kept) with ``where: `` before its message.

    Raise it ``from err.__cause__`` to keep the original cause (a plug-in's exception).
    """
    out = copy.copy(err)
    out.args = (f"{where}: {err}",)
    return out


def user_stacklevel() -> int:
    """The ``stacklevel`` for :func:`warnings.warn` that points at the first frame outside footzoo.

    A warning then names the user's line (the script's ``footzoo.load(...)`` or ``pipe.run(rec)``), not a
    line inside footzoo, however deep in footzoo it was raised: pass ``stacklevel=user_stacklevel()``.
    """
    frame = inspect.currentframe()
    level = 0
    # footzoo's frames, and the methods a dataclass generates (``Recording.__init__``, file ``<string>``)
    while frame is not None and (frame.f_code.co_filename.startswith(_PACKAGE)
                                 or frame.f_code.co_filename == "<string>"):
        frame = frame.f_back
        level += 1
    return max(level, 1)
