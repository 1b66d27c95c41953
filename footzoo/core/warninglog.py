"""The log of a command that writes a folder: ``footzoo.log``, every warning the command gave.

A study or a tune writes its log into its output folder as one of its outputs, inside the folder's
lock and before the folder's completion marker, so a folder that looks complete never holds another
run's log. :class:`WarningLog` collects the warnings of such a call while it works and passes them
on to the caller when it ends (the caller sees, records or filters them as it would have), and
:func:`log_text` gives the file's content.

Usage::

    with WarningLog() as log:
        ...                                   # warnings issued here are collected
        log.keep(["FootzooWarning: ..."])     # a warning for the log only (not passed on)
        write_bytes(out / LOG, log_text(log.texts()))
"""

from __future__ import annotations

import threading
import warnings
from typing import Any

#: The log of a command that writes a folder: every warning it gave.
LOG = "footzoo.log"


def warning_texts(caught: list[warnings.WarningMessage]) -> list[str]:
    """``"Category: message"`` of each distinct warning caught, in order."""
    return list(dict.fromkeys(f"{type(w.message).__name__ if isinstance(w.message, Warning) else w.category.__name__}"
                              f": {w.message}" for w in caught))


def log_text(texts: list[str]) -> bytes:
    """The content of ``footzoo.log``: every warning of the command, one per line (or that there was none)."""
    return (("\n".join(texts) if texts else "no warnings") + "\n").encode("utf-8")


_OPEN = threading.local()  # the innermost WarningLog open in this thread


class WarningLog:
    """Collect the warnings of a block for its folder's log; pass them on to the caller when the block ends.

    Inside the block the warnings are recorded (the filters in force stay: what is ignored stays
    ignored, what is an error raises); at its end each one is issued again, with its category, text
    and origin, to whatever the caller does with warnings (shows, records or filters them). Texts
    given to :meth:`keep` are in the log only; a log opened inside another one (a tune's studies)
    hands them on to the enclosing log.
    """

    def __enter__(self) -> WarningLog:
        self._outer: WarningLog | None = getattr(_OPEN, "log", None)
        self._ctx = warnings.catch_warnings(record=True)
        self.caught: list[warnings.WarningMessage] = self._ctx.__enter__()
        self.kept: list[str] = []
        self.unlogged: set[str] = set()
        _OPEN.log = self
        return self

    def keep(self, texts: list[str]) -> None:
        """Add ``"Category: message"`` texts to the log without issuing them as warnings."""
        self.kept += texts

    def not_logged(self, texts: list[str]) -> None:
        """Leave these ``"Category: message"`` texts out of the log (a summary of warnings the log lists each of);
        they are still passed on to the caller."""
        self.unlogged.update(texts)

    def texts(self) -> list[str]:
        """Every distinct warning so far, ``"Category: message"``, in order (those kept for the log last)."""
        return [t for t in dict.fromkeys([*warning_texts(self.caught), *self.kept]) if t not in self.unlogged]

    def __exit__(self, *exc: Any) -> None:
        self._ctx.__exit__(*exc)
        _OPEN.log = self._outer
        if self._outer is not None:
            self._outer.keep(self.kept)
            self._outer.not_logged(sorted(self.unlogged))
        for w in self.caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)


__all__ = ["LOG", "WarningLog", "log_text", "warning_texts"]
